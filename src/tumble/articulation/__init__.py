"""Articulations: trees of rigid links in generalised coordinates, with loop closures for closed chains.

>>> from tumble.articulation import Articulation, Revolute
>>> pendulum = Articulation(gravity=(0.0, 0.0, -9.81))
>>> bob = pendulum.add_link(Revolute((0.0, 1.0, 0.0)), mass=1.0, shape_position=(1.0, 0.0, 0.0))
>>> trajectory = pendulum.simulate(1.0, 1e-3)
>>> trajectory.q.shape
(1001, 1)

Inverse dynamics by RNEA, the mass matrix by CRBA, forward dynamics by its sparse LTDL factorisation
(Featherstone, *Rigid Body Dynamics Algorithms*, 2008, ch. 5-6), all in Numba kernels over flat arrays.
``docs/articulation.md`` describes the coordinates, the algorithms and the limits.
"""

from __future__ import annotations

from .actuators import Actuator
from .articulation import Articulation, ArticulationContacts, ArticulationTrajectory, Link
from .batch import ArticulationBatch
from .collision import Geom
from .joint_view import ArticulationJoint
from .joints import Ball, Fixed, Free, Joint, JointType, Prismatic, Revolute
from .limits import SoftConstraint, Tendon
from .loops import LoopClosure


def from_mjcf(path_or_xml) -> Articulation:
    """The articulation of an MJCF model (a file path, or XML text starting with ``<``): its bodies, joints and
    mass properties in generalised coordinates, ``q``/``qd`` in MuJoCo's ``qpos``/``qvel`` order and conventions,
    starting at ``qpos0``; its actuators on hinges and slides driven by ``ctrl`` in MuJoCo's order; no contacts.
    What tumble does not simulate is named in one warning per element and attribute
    (:class:`tumble.models.mjcf.MJCFWarning`); a file that cannot be read raises
    :class:`tumble.models.mjcf.MJCFError` naming the file, element and line. See docs/model_files.md."""
    from ..models.build import to_articulation
    from ..models.mjcf import read_mjcf

    return to_articulation(read_mjcf(path_or_xml))


def from_urdf(path, *, package_dirs=(), floating_base: bool = False) -> Articulation:
    """The articulation of a URDF robot: a link per URDF link with a moving joint (``fixed`` ones weld a link to its
    parent), ``q`` in the order the links are met breadth first from the root; the root welded to the world, or
    free with ``floating_base=True``; no contacts. A file that cannot be read raises
    :class:`tumble.models.urdf.URDFError` naming the file, element and line. See docs/model_files.md."""
    from ..models.build import to_articulation
    from ..models.urdf import read_urdf

    if not isinstance(floating_base, bool):
        raise TypeError(f"floating_base must be True or False, got {floating_base!r}")
    return to_articulation(read_urdf(path, package_dirs=package_dirs, floating_base=floating_base))


__all__ = [
    "Actuator",
    "Articulation",
    "ArticulationBatch",
    "ArticulationContacts",
    "ArticulationJoint",
    "ArticulationTrajectory",
    "Ball",
    "Fixed",
    "Free",
    "Geom",
    "Joint",
    "JointType",
    "Link",
    "LoopClosure",
    "Prismatic",
    "Revolute",
    "SoftConstraint",
    "Tendon",
    "from_mjcf",
    "from_urdf",
]
