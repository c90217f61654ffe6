"""Builders: a :class:`~tumble.models.description.ModelDescription` into tumble objects.

``to_articulation``: the generalised-coordinate view. Each body becomes one link per joint: a body with several
joints is a chain whose intermediate links are massless and whose last link carries the body's name and mass
properties; a body without joints is welded to its parent (``Fixed``). tumble's link frame is the joint frame, so a
joint at ``pos`` in its body puts the link's origin there; the body's mass properties and its children are placed
relative to it. MuJoCo measures a hinge or slide from its ``ref`` (the coordinate at the model's pose), so the link
frame is turned (moved) back by ``ref``: ``q`` then equals MuJoCo's ``qpos`` and ``qd`` its ``qvel``, entry by entry,
and the articulation starts at MuJoCo's ``qpos0``. The model's actuators drive the links of their joints, ``art.ctrl``
in the model's order.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..articulation import Articulation, Ball, Fixed, Free, Prismatic, Revolute, SoftConstraint
from ..rotation import quat_from_axis_angle, quat_multiply, quat_rotate
from .description import GeomDescription, JointDescription, ModelDescription
from .mjcf import MJCFWarning

__all__ = ["to_articulation"]

_IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
_WELD = JointDescription(None, "fixed", np.zeros(3), np.zeros(3), None, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0)


def _link_joint(joint: JointDescription, position: np.ndarray, orientation: np.ndarray):
    """tumble's joint for ``joint`` and its link frame, turned (or moved) back by ``ref``."""
    if joint.type == "hinge":
        if joint.ref != 0.0:
            orientation = quat_multiply(orientation, quat_from_axis_angle(joint.axis, -joint.ref))
        return Revolute(joint.axis), position, orientation
    if joint.type == "slide":
        return Prismatic(joint.axis), position - joint.ref * quat_rotate(orientation, joint.axis), orientation
    if joint.type == "ball":
        return Ball(), position, orientation
    if joint.type == "free":
        return Free(), position, orientation
    return Fixed(), position, orientation


def to_articulation(model: ModelDescription) -> Articulation:
    """The articulation of ``model``'s bodies (no contacts): gravity from the model, base at the world origin."""
    art = Articulation(gravity=model.gravity, name=model.name)
    last_link: dict[int, tuple[int | None, np.ndarray]] = {-1: (None, np.zeros(3))}
    initial: list[tuple[int, float]] = []
    joint_links: dict[str, int] = {}
    body_links: dict[int, int] = {}
    skipped: dict[str, int] = {}
    for geom in model.world_geoms:
        _add_geom(art, None, geom, np.zeros(3), skipped)
    for index, body in enumerate(model.bodies):
        parent, parent_anchor = last_link[body.parent]
        joints = body.joints or (_WELD,)
        for k, joint in enumerate(joints):
            last = k == len(joints) - 1
            if k == 0:  # the body frame in the parent's last link frame, then the joint's anchor in it
                position = body.pos - parent_anchor + quat_rotate(body.quat, joint.pos)
                orientation = body.quat
            else:  # the previous joint's link frame is the body frame moved to that joint's anchor
                position, orientation = joint.pos - joints[k - 1].pos, _IDENTITY
            link_joint, position, orientation = _link_joint(joint, position, orientation)
            properties = body.mass_properties
            if last and properties is not None:
                properties = properties.transformed(translation=-joint.pos)
            name = body.name if last else _chain_name(body.name, joint.name, k)
            parent = art.add_link(link_joint, parent=parent, position=position, orientation=orientation,
                                  mass_properties=properties if last else None, damping=joint.damping,
                                  name=name, armature=joint.armature, stiffness=_spring(joint),
                                  springref=joint.springref, frictionloss=joint.frictionloss,
                                  limits=joint.range if joint.type in ("hinge", "slide") else None,
                                  margin=joint.margin, limit_softness=_softness(joint.limit_softness),
                                  friction_softness=_softness(joint.friction_softness),
                                  joint_name=joint.name)  # fmt: skip
            if joint.type in ("hinge", "slide") and joint.ref != 0.0:
                initial.append((parent, joint.ref))
            if joint.name is not None:
                joint_links[joint.name] = parent
        last_link[index] = (parent, joints[-1].pos)
        body_links[index] = parent
        for geom in body.geoms:
            _add_geom(art, parent, geom, joints[-1].pos, skipped)
    for link, ref in initial:
        art.set_joint(link, q=ref)
    for first, second in model.excludes:
        art.exclude_contacts(*(None if name == "world" else body_links[model.body_index(name)]
                               for name in (first, second)))  # fmt: skip
    art.impratio = model.impratio
    if skipped:
        warnings.warn(f"{model.source}: an articulation collides planes, spheres and capsules; "
                      f"{', '.join(f'{n} {kind} geom(s)' for kind, n in sorted(skipped.items()))} do not touch "
                      "anything (yet)", MJCFWarning, stacklevel=3)  # fmt: skip
    tendons = {}
    for tendon in model.tendons:
        tendons[tendon.name] = art.add_tendon(
            [joint_links[joint] for joint in tendon.joints], tendon.coefficients, limits=tendon.range,
            margin=tendon.margin, frictionloss=tendon.frictionloss, limit_softness=_softness(tendon.limit_softness),
            friction_softness=_softness(tendon.friction_softness), stiffness=tendon.stiffness, damping=tendon.damping,
            springlength=tendon.springlength, name=tendon.name,
        )  # fmt: skip
    for actuator in model.actuators:
        link = None if actuator.joint is None else joint_links[actuator.joint]
        art.add_actuator(link, tendon=None if actuator.tendon is None else tendons[actuator.tendon],
                         gear=actuator.gear, gain=actuator.gain, bias=actuator.bias, ctrl_range=actuator.ctrl_range,
                         force_range=actuator.force_range, name=actuator.name)  # fmt: skip
    return art


def _softness(settings) -> SoftConstraint | None:
    """MJCF's ``(solref, solimp)`` as a :class:`SoftConstraint` (``None``: MuJoCo's defaults)."""
    return None if settings is None else SoftConstraint(*settings)


def _add_geom(art: Articulation, link: int | None, geom: GeomDescription, anchor: np.ndarray, skipped) -> None:
    """Geom ``geom`` of a body on its link (whose frame is the body's moved to the joint's ``anchor``), as MuJoCo's
    contact settings say; one that can touch nothing is left out, one of a type not collided counted in
    ``skipped``."""
    if geom.contype == 0 and geom.conaffinity == 0:
        return
    if geom.type not in ("plane", "sphere", "capsule") or (geom.type == "plane" and link is not None):
        skipped[geom.type] = skipped.get(geom.type, 0) + 1
        return
    size = {"plane": (), "sphere": geom.size[:1], "capsule": geom.size[:2]}[geom.type]
    art.add_geom(link, geom.type, size, position=geom.pos - anchor, orientation=geom.quat, contype=geom.contype,
                 conaffinity=geom.conaffinity, condim=1 if geom.condim == 1 else 3, friction=float(geom.friction[0]),
                 margin=geom.margin, softness=SoftConstraint(*geom.softness), solmix=geom.solmix,
                 name=geom.name)  # fmt: skip


def _spring(joint: JointDescription) -> float:
    """A hinge's or slide's stiffness (tumble has no spring on a ball joint; the reader warns about one)."""
    return joint.stiffness if joint.type in ("hinge", "slide") else 0.0


def _chain_name(body: str | None, joint: str | None, k: int) -> str | None:
    """The name of an intermediate link of a body's chain: ``body/joint`` (``body/joint0`` for an unnamed joint)."""
    if body is None:
        return None
    return f"{body}/{joint if joint is not None else f'joint{k}'}"
