"""The bridge from a ``tumble.Articulation`` (a tree of links) to a Lagrangian :class:`System`.

Each link's frame is placed from its parent's (the fixed base for ``parent is None``) by the joint, with
``R_o, p_o`` the link frame's pose in the parent frame at zero displacement and ``a`` the joint axis in
the link frame:

    revolute:   R = R_parent R_o Rot(a, q),   p = p_parent + R_parent p_o
    prismatic:  R = R_parent R_o,             p = p_parent + R_parent (p_o + R_o a q)
    fixed:      R = R_parent R_o,             p = p_parent + R_parent p_o

(forward kinematics of a serial chain: course deck 004, video 2.3, ``r_OC = r_OB + R r_BC``). Each
revolute and prismatic link gets one coordinate, a ``dynamicsymbols`` named after the link (or
``q{index}`` when the name is not an identifier); joint damping ``d`` becomes the generalised force
``-d q̇``. Ball and free joints are not supported here: their orientation coordinates (quaternions) do
not fit a Lagrangian in minimal angles without singularities; nor are loop closures.

Only the articulation's public description is used (``links`` with ``index``, ``name``, ``parent``,
``joint``, ``position``, ``orientation``, ``mass_properties``; ``gravity``, ``base_position``,
``base_orientation``), so this module does not import ``tumble.articulation``.
"""

from __future__ import annotations

import keyword

import numpy as np
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

from ..rotation import quat_to_matrix
from ._checks import exact_number, show
from .bodies import RigidBody
from .kinematics import rotation_about
from .system import System

__all__ = ["from_articulation"]

_MOVING = ("Revolute", "Prismatic")
_SUPPORTED = (*_MOVING, "Fixed")


def from_articulation(articulation, gravity=None, *, parameters=None) -> System:
    """A :class:`System` with one coordinate per revolute or prismatic joint of ``articulation``.

    Args:
        articulation: a ``tumble.Articulation`` (or any object with the same ``links``, ``gravity``,
            ``base_position`` and ``base_orientation``).
        gravity: overrides ``articulation.gravity`` (3 numbers or expressions).
        parameters: as for :class:`System` (only needed if ``gravity`` has symbols).

    Returns:
        the system; its ``coordinates`` follow the order of ``articulation.links`` (the articulation's
        ``q`` for revolute and prismatic joints) and its ``bodies`` are the links with mass (fixed links
        included) as :class:`RigidBody`.
    """
    links = _links_by_index(articulation)
    if len(getattr(articulation, "loop_closures", ())):
        raise NotImplementedError(
            "lagrange.from_articulation does not translate loop closures; write them as constraints= of a "
            "System built with System.from_bodies"
        )
    names = _coordinate_names(links)
    base_R = _matrix(quat_to_matrix(_array("articulation.base_orientation", articulation.base_orientation, 4)))
    base_p = _vector(_array("articulation.base_position", articulation.base_position, 3))
    poses: dict[int, tuple[sp.Matrix, sp.Matrix]] = {}
    coordinates = {index: dynamicsymbols(name) for index, name in names.items()}

    def pose(index: int, path: tuple = ()) -> tuple[sp.Matrix, sp.Matrix]:
        if index in poses:
            return poses[index]
        if index in path:
            raise ValueError(f"articulation.links has a cycle through link {index} (parents {list(path)})")
        link = links[index]
        if link.parent is None:
            parent_R, parent_p = base_R, base_p
        else:
            if link.parent not in links:
                raise ValueError(f"link {_label(link)} has parent {link.parent!r}, which is not a link index")
            parent_R, parent_p = pose(link.parent, (*path, index))
        poses[index] = _place(link, parent_R, parent_p, coordinates.get(index))
        return poses[index]

    bodies = []
    for index, link in links.items():
        R, p = pose(index)
        if link.mass_properties is not None:  # a massless link only carries its children
            bodies.append(RigidBody(link.mass_properties, p, R, name=link.name))
    if not bodies:
        raise ValueError("articulation has no link with mass_properties: there is nothing to move")
    for link in links.values():
        if getattr(link, "armature", 0.0) != 0.0 or getattr(link, "stiffness", 0.0) != 0.0:
            raise ValueError(f"link {_label(link)} has joint armature or stiffness, which the symbolic derivation "
                             "does not model yet")  # fmt: skip
    for link in links.values():
        if getattr(link, "limits", None) is not None or getattr(link, "frictionloss", 0.0) != 0.0:
            raise ValueError(f"link {_label(link)} has joint limits or frictionloss, constraints that the symbolic "
                             "derivation does not model")  # fmt: skip
    if getattr(articulation, "geoms", ()):
        raise ValueError(f"articulation has {len(articulation.geoms)} geoms: contacts are not part of the symbolic "
                         "derivation")  # fmt: skip
    if getattr(articulation, "tendons", ()):
        raise ValueError(f"articulation has {len(articulation.tendons)} tendons, which the symbolic derivation does "
                         "not model yet")  # fmt: skip
    if getattr(articulation, "actuators", ()):
        raise ValueError(f"articulation has {len(articulation.actuators)} actuators, which the symbolic derivation "
                         "does not model yet: give their forces as generalised forces instead")  # fmt: skip
    damping = [-float(getattr(links[index], "damping", 0.0)) * q.diff() for index, q in coordinates.items()]
    g = articulation.gravity if gravity is None else gravity
    forces = damping if any(d != 0 for d in damping) else None
    return System.from_bodies(list(coordinates.values()), bodies, gravity=g, forces=forces, parameters=parameters)


def _place(link, parent_R: sp.Matrix, parent_p: sp.Matrix, q) -> tuple[sp.Matrix, sp.Matrix]:
    kind = type(link.joint).__name__
    origin_R = _matrix(quat_to_matrix(_array(f"link {_label(link)} orientation", link.orientation, 4)))
    origin_p = _vector(_array(f"link {_label(link)} position", link.position, 3))
    if kind == "Revolute":
        axis = _vector(_array(f"link {_label(link)} joint axis", link.joint.axis, 3))
        return parent_R * origin_R * rotation_about(axis, q), parent_p + parent_R * origin_p
    if kind == "Prismatic":
        axis = _vector(_array(f"link {_label(link)} joint axis", link.joint.axis, 3))
        return parent_R * origin_R, parent_p + parent_R * (origin_p + origin_R * axis * q)
    return parent_R * origin_R, parent_p + parent_R * origin_p


def _links_by_index(articulation) -> dict:
    links = getattr(articulation, "links", None)
    if links is None:
        raise TypeError(f"articulation must have links (a tumble.Articulation), got {type(articulation).__name__}")
    out = {}
    for position, link in enumerate(links):
        index = getattr(link, "index", position)
        kind = type(getattr(link, "joint", None)).__name__
        if kind not in _SUPPORTED:
            raise NotImplementedError(
                f"link {_label(link)} has a {kind} joint; lagrange.from_articulation supports Revolute, "
                "Prismatic and Fixed joints (ball and free joints need quaternion coordinates)"
            )
        if index in out:
            raise ValueError(f"articulation.links has two links with index {index}")
        out[index] = link
    if not out:
        raise ValueError("articulation has no links")
    return out


def _coordinate_names(links: dict) -> dict[int, str]:
    names: dict[int, str] = {}
    taken: set[str] = set()
    for index, link in links.items():
        if type(link.joint).__name__ not in _MOVING:
            continue
        name = getattr(link, "name", None)
        usable = isinstance(name, str) and name.isidentifier() and not keyword.iskeyword(name)
        if not usable or name in taken or name.startswith("lam"):
            name = f"q{index}"
        taken.add(name)
        names[index] = name
    if not names:
        raise ValueError("articulation has no revolute or prismatic joint: there is no coordinate to move")
    return names


def _label(link) -> str:
    name = getattr(link, "name", None)
    index = getattr(link, "index", "?")
    return f"{index} ({name!r})" if name else str(index)


def _array(name: str, value, size: int) -> np.ndarray:
    array = np.asarray(value, dtype=np.float64).reshape(-1)
    if array.shape != (size,) or not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be {size} finite numbers, got {show(value)}")
    return array


def _matrix(array: np.ndarray) -> sp.Matrix:
    return sp.Matrix(3, 3, [exact_number(float(x)) for x in array.ravel()])


def _vector(array: np.ndarray) -> sp.Matrix:
    return sp.Matrix([exact_number(float(x)) for x in array])
