"""Builder: a :class:`~tumble.models.description.ModelDescription` into a :class:`~tumble.World`: bodies that collide,
the world's joints, the ground.

Every body with a joint becomes a world body at its pose in the model (MuJoCo's ``qpos0``), carrying the geoms and
mass of the jointless bodies welded to it; bodies welded to the world are static geometry with the world's own
geoms. A hinge, slide or ball joint to the parent becomes a :class:`~tumble.HingeJoint`,
:class:`~tumble.SliderJoint` or :class:`~tumble.BallJoint` (a hinge's or slide's ``range`` its limits); a free joint
leaves the body free. Several joints of one body become the one world joint that moves the body as they do: two
hinges through one point with perpendicular axes a :class:`~tumble.UniversalJoint` (the first axis carried by the
parent, the second by the body, as MuJoCo composes them), three hinges through one point with independent axes a
:class:`~tumble.BallJoint`, two slides and a hinge normal to both a :class:`~tumble.PlanarJoint` (the root of
the 2-D walkers); their actuators drive the joint's angles (a planar joint's are left out with a warning), their
ranges are left out with a warning. Any other set is refused
(``tumble.articulation.from_mjcf`` loads every model). Geoms become shapes (a mesh its convex hull, as MuJoCo
collides it; an ellipsoid the hull of 162 points on it); geoms that collide with nothing (``contype = conaffinity =
0``) are left out. MuJoCo lets two geoms touch when ``contype₁ & conaffinity₂`` or ``contype₂ & conaffinity₁``;
tumble's filter asks both of ``group₁ & mask₂`` and ``group₂ & mask₁``, so each distinct pair ``(contype,
conaffinity)`` gets a bit of its own as its group, and its mask holds the bits of the pairs it touches: the same
pairs collide.
"""

from __future__ import annotations

import warnings

import numpy as np

from .. import portable
from ..joints import BallJoint, HingeJoint, PlanarJoint, SliderJoint, UniversalJoint
from ..mass import require_invertible
from ..math3d import quat_mul, quat_rotate
from ..shapes import Box, Capsule, ConvexHull, Cylinder, Plane, Sphere
from .description import GeomDescription, ModelDescription
from .mjcf import MJCFWarning

__all__ = ["load_mjcf", "load_urdf", "to_world"]

_IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def _rotate(quat, vector) -> np.ndarray:
    """``vector`` turned by the unit ``quat``: ``math3d``'s tuple helper (5 µs a call from Python; the validated
    ``rotation.quat_rotate`` costs 0.4 ms, which made a 1000-body model take 6 s to load)."""
    return np.array(quat_rotate(tuple(float(q) for q in quat), tuple(float(v) for v in vector)))


def _compose(a, b):
    """The pose ``b`` (in ``a``'s frame) in ``a``'s parent's frame."""
    return a[0] + _rotate(a[1], b[0]), np.array(quat_mul(tuple(a[1]), tuple(b[1])))


def _relative(a, b):
    """The pose ``b`` (world) in frame ``a`` (world)."""
    inverse = a[1] * np.array([1.0, -1.0, -1.0, -1.0])
    return _rotate(inverse, b[0] - a[0]), np.array(quat_mul(tuple(inverse), tuple(b[1])))


def _ellipsoid_points(size) -> np.ndarray:
    """162 points on an ellipsoid of half axes ``size``: a subdivided icosahedron's vertices, scaled."""
    t = (1.0 + 5.0**0.5) / 2.0
    points = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
              (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]  # fmt: skip
    cloud = np.array(points, float)
    for _ in range(2):  # midpoints of every close pair: 12 -> 42 -> 162
        unit = cloud / np.linalg.norm(cloud, axis=1)[:, None]
        gaps = np.linalg.norm(unit[:, None] - unit[None], axis=2)
        edge = np.min(gaps[gaps > 1e-9])
        i, j = np.nonzero(np.triu(gaps < 1.01 * edge, 1))
        cloud = np.vstack([unit, unit[i] + unit[j]])
    return cloud / np.linalg.norm(cloud, axis=1)[:, None] * size


def _shape(model: ModelDescription, geom: GeomDescription, moving: bool):
    """The tumble shape of a geom, or None (with a warning) for one tumble cannot collide."""
    r, h = geom.size[0], geom.size[1]
    if geom.type == "sphere":
        return Sphere(r)
    if geom.type == "capsule":
        return Capsule(r, 2.0 * h)
    if geom.type == "cylinder":
        return Cylinder(r, 2.0 * h)
    if geom.type == "box":
        return Box(2.0 * geom.size)
    if geom.type == "ellipsoid":
        return ConvexHull(_ellipsoid_points(geom.size))
    if geom.type == "mesh":
        return ConvexHull(model.meshes[geom.mesh].vertices)
    if geom.type == "plane" and not moving:
        return Plane()
    warnings.warn(
        f"{model.source}: <geom> type={geom.type!r} (line {geom.line}) does not collide in a tumble World "
        f"{'on a moving body ' if geom.type == 'plane' else ''}(yet); left out",
        MJCFWarning,
        stacklevel=4,
    )
    return None


def _filters(model: ModelDescription) -> dict[tuple[int, int], tuple[int, int]]:
    """``(collision_group, collision_mask)`` for each ``(contype, conaffinity)`` in the model (module docstring)."""
    pairs = sorted({(g.contype, g.conaffinity) for b in model.bodies for g in b.geoms} |
                   {(g.contype, g.conaffinity) for g in model.world_geoms})  # fmt: skip
    pairs = [p for p in pairs if p != (0, 0)]
    if len(pairs) > 32:
        raise ValueError(f"{model.source}: {len(pairs)} distinct (contype, conaffinity) pairs; tumble's collision "
                         "filter holds 32")  # fmt: skip
    bits = {pair: 1 << k for k, pair in enumerate(pairs)}
    return {p: (bits[p], sum(bits[q] for q in pairs if (p[0] & q[1]) or (q[0] & p[1]))) for p in pairs}


def _composite(model, body) -> str | None:
    """What several joints of ``body`` make in a World (``"universal"``, ``"ball"``, ``"planar"``; None for one
    joint), or a ValueError naming the body and its joints."""
    joints = body.joints
    if len(joints) < 2:
        return None
    types = sorted(j.type for j in joints)
    hinges = [j.axis for j in joints if j.type == "hinge"]
    slides = [j.axis for j in joints if j.type == "slide"]
    concurrent = all(np.allclose(j.pos, joints[0].pos, rtol=0.0, atol=1e-9) for j in joints)
    if types == ["hinge", "hinge"] and concurrent and abs(float(portable.dot(hinges[0], hinges[1]))) <= 1e-6:
        return "universal"
    if types == ["hinge"] * 3 and concurrent and abs(float(portable.det(np.array(hinges)))) > 1e-6:
        return "ball"
    if (types == ["hinge", "slide", "slide"] and portable.norm(np.cross(*slides)) > 1e-6
            and max(abs(float(portable.dot(hinges[0], axis))) for axis in slides) <= 1e-6):  # fmt: skip
        return "planar"
    listed = ", ".join(f"{j.type} {j.name!r}" for j in joints)
    raise ValueError(
        f"{model.source}, line {body.line}: body {body.name!r} has joints {listed}; a tumble World joins two bodies "
        "with one joint, which several make only as two hinges through one point with perpendicular axes, three "
        "through one point with independent axes, or two slides and a hinge normal to both "
        "(tumble.articulation.from_mjcf loads every model)"
    )


def _joint(model, body, world_body, parent, anchor, rotation_quat):
    """The world joint of ``body`` (its hinge, slide or ball, or what its joints make together, :func:`_composite`)
    to ``parent`` (a world body, or None)."""
    joint = body.joints[0]
    axis = _rotate(rotation_quat, joint.axis)
    composite = _composite(model, body)
    a, b = (parent, world_body) if parent is not None else (world_body, None)
    if composite == "ball":
        return BallJoint(a, b, anchor)
    if composite == "universal":  # the first hinge's axis turns with the parent, the second's with the body
        first, second = axis, _rotate(rotation_quat, body.joints[1].axis)
        return UniversalJoint(a, b, anchor, *((first, second) if b is not None else (second, first)))
    if composite == "planar":
        normal = next(j.axis for j in body.joints if j.type == "hinge")
        return PlanarJoint(a, b, _rotate(rotation_quat, normal), anchor=anchor)
    bounds = {}
    if joint.range is not None and joint.type in ("hinge", "slide"):
        # zero at the model's pose, where MuJoCo's coordinate is ``ref``; tumble measures the child's turn (or
        # travel) relative to its parent or, joined to the world, relative to the world: MuJoCo's sense both ways
        bounds = {"lower": joint.range[0] - joint.ref, "upper": joint.range[1] - joint.ref}
    if joint.type == "hinge":
        return HingeJoint(a, b, anchor, axis, damping=joint.damping, **bounds)
    if joint.type == "slide":
        return SliderJoint(a, b, axis, anchor=anchor, damping=joint.damping, **bounds)
    return BallJoint(a, b, anchor)


def _orthonormal(axes) -> bool:
    axes = np.asarray(axes)
    return bool(np.allclose(axes @ axes.T, np.eye(len(axes)), rtol=0.0, atol=1e-6))


def _check(model: ModelDescription) -> set[str]:
    """Refuse what a World cannot hold, warn of what it leaves out; returns the names of the joints whose actuators
    are left out: those of a planar joint, and of a ball joint whose hinges are not orthonormal."""
    undriven, limited = set(), []
    for body in model.bodies:
        composite = _composite(model, body)
        if composite is not None:
            limited += [j.name or f"line {j.line}" for j in body.joints if j.range is not None]
        if composite == "planar" or (composite == "ball" and not _orthonormal([j.axis for j in body.joints])):
            undriven |= {j.name for j in body.joints}
    if limited:
        warnings.warn(f"{model.source}: the ranges of joints {', '.join(map(repr, limited))} are not enforced: each "
                      "is one of several joints of a body, which a World joins as one joint (universal, ball or "
                      "planar) without limits (yet)", MJCFWarning, stacklevel=3)  # fmt: skip
    driving = [a.name or a.joint for a in model.actuators if a.joint in undriven]
    if driving:
        warnings.warn(f"{model.source}: actuators {', '.join(map(repr, driving))} are left out: their joints make a "
                      "planar joint, or a ball joint of hinges that are not orthonormal, which a World's actuators "
                      "do not drive (yet)", MJCFWarning, stacklevel=3)  # fmt: skip
    # a body's one hinge or slide keeps its damping (its world joint's); the rest is left out
    notes = sorted({name for b in model.bodies for j in b.joints for name in ("damping", "armature", "stiffness",
                    "frictionloss") if getattr(j, name)
                    and not (name == "damping" and len(b.joints) == 1 and j.type in ("hinge", "slide"))})  # fmt: skip
    if notes:
        warnings.warn(f"{model.source}: a tumble World's joints do not simulate joint {', '.join(notes)} (yet; a "
                      "body's one hinge or slide keeps its damping); ignored", MJCFWarning, stacklevel=3)  # fmt: skip
    if model.tendons:
        warnings.warn(f"{model.source}: a tumble World does not simulate tendons (yet; tumble.articulation.from_mjcf "
                      "does), nor the actuators that pull them; ignored", MJCFWarning, stacklevel=3)  # fmt: skip
    forced = [a.name or a.joint for a in model.actuators if a.force_range is not None]
    if forced:
        warnings.warn(f"{model.source}: a tumble World does not clip the forces of actuators "
                      f"{', '.join(map(repr, forced))} to their forcerange (yet); ignored", MJCFWarning,
                      stacklevel=3)  # fmt: skip
    return undriven | {None}


def _moving_body(model: ModelDescription, index: int, welded: list[int], poses, filters):
    """``(shapes, mass properties, friction, (group, mask))`` of the world body that body ``index`` and the bodies
    ``welded`` to it (itself included) make, in its frame."""
    frame = poses[index]
    shapes, mass, first = [], None, None
    for k in welded:
        local = _relative(frame, poses[k])
        for geom in model.bodies[k].geoms:
            shape = None if (geom.contype, geom.conaffinity) == (0, 0) else _shape(model, geom, True)
            if shape is not None:
                shapes.append((shape, *_compose(local, (geom.pos, geom.quat))))
                first = first or geom
        mp = model.bodies[k].mass_properties
        if mp is not None:
            moved = mp.transformed(rotation=local[1], translation=local[0])
            mass = moved if mass is None else mass + moved
    body = model.bodies[index]
    if mass is None:
        raise ValueError(f"{model.source}, line {body.line}: body {body.name!r} moves but has no mass")
    try:
        require_invertible(mass)
    except ValueError as error:
        raise ValueError(f"{model.source}, line {body.line}: body {body.name!r}: {error}") from None
    if first is None:
        return shapes, mass, 0.5, (1, 0)
    return shapes, mass, float(first.friction[0]), filters[(first.contype, first.conaffinity)]


def to_world(model: ModelDescription, world=None, position=(0.0, 0.0, 0.0), orientation=_IDENTITY):
    """The model's bodies, joints and geoms in ``world`` (a new one with the model's gravity if None), the whole
    model placed at ``position``/``orientation``; returns the world."""
    from ..world import World

    left_out = _check(model)
    world = World(gravity=model.gravity) if world is None else world
    place = (np.asarray(position, float), np.asarray(orientation, float))
    filters = _filters(model)
    poses, movers = [], []  # each body's world pose, and the index of the body it moves with (-1: the world)
    for index, body in enumerate(model.bodies):
        parent = place if body.parent < 0 else poses[body.parent]
        poses.append(_compose(parent, (body.pos, body.quat)))
        movers.append(index if body.joints else (-1 if body.parent < 0 else movers[body.parent]))
    groups: dict[int, list[int]] = {}  # each moving body and the bodies welded to it, in one pass
    for k, mover in enumerate(movers):
        groups.setdefault(mover, []).append(k)
    # everything worked out and checked before the world changes: a model that cannot be built leaves it as it was
    planned, static_geoms = [], [(place, geom) for geom in model.world_geoms]
    for index, body in enumerate(model.bodies):
        if movers[index] < 0:
            static_geoms += [(poses[index], geom) for geom in body.geoms]
        elif movers[index] == index:
            planned.append((index, *_moving_body(model, index, groups[index], poses, filters)))
    statics = []
    for pose, geom in static_geoms:
        if (geom.contype, geom.conaffinity) != (0, 0) and (shape := _shape(model, geom, False)) is not None:
            statics.append(
                (shape, _compose(pose, (geom.pos, geom.quat)), geom, filters[(geom.contype, geom.conaffinity)])
            )
    names = [model.bodies[index].name for index, *_ in planned] + [geom.name for _, _, geom, _ in statics]
    taken = {body.name for body in world.bodies if body.name is not None}
    for name in (name for name in names if name is not None):
        if name in taken:
            raise ValueError(f"{model.source}: the name {name!r} is taken in the world (load the model into another "
                             "world, or rename it there)")  # fmt: skip
        taken.add(name)
    handles: dict[int, object] = {}
    for index, shapes, mass, friction, (group, mask) in planned:
        frame = poses[index]
        handles[index] = world.add_body(shapes or None, mass_properties=mass, position=frame[0], orientation=frame[1],
                                        friction=friction, collision_group=group, collision_mask=mask,
                                        name=model.bodies[index].name)  # fmt: skip
    for shape, at, geom, (group, mask) in statics:
        world.add_static(shape, position=at[0], orientation=at[1], friction=float(geom.friction[0]),
                         collision_group=group, collision_mask=mask, name=geom.name)  # fmt: skip
    joints = {}
    for index, handle in handles.items():
        body = model.bodies[index]
        if body.joints[0].type == "free":
            continue
        parent = movers[body.parent] if body.parent >= 0 else -1
        frame = poses[index]
        anchor = frame[0] + _rotate(frame[1], body.joints[0].pos)
        joint = world.add_joint(_joint(model, body, handle, handles.get(parent), anchor, frame[1]))
        composite = _composite(model, body)
        for k, description in enumerate(body.joints):
            # which of the world joint's coordinates this MJCF joint is: a universal joint to the world has the
            # body's axis (the second hinge) as its axis_a; a ball joint's angles are about the hinges' axes
            coordinate = (1 - k if parent < 0 else k) if composite == "universal" else k
            axes = np.array([_rotate(frame[1], j.axis) for j in body.joints]) if composite == "ball" else None
            joints[description.name] = (joint, description, coordinate, axes)
    for actuator in (a for a in model.actuators if a.joint not in left_out):
        joint, description, coordinate, axes = joints[actuator.joint]
        world.add_joint_actuator(joint, gear=actuator.gear, gain=actuator.gain, bias=actuator.bias,
                                 ctrl_range=actuator.ctrl_range, ref=description.ref, name=actuator.name,
                                 coordinate=coordinate, axes=axes)  # fmt: skip
    return world


def _placement(world, position, orientation):
    """The checked ``world``, ``position`` and ``orientation`` of a model loaded into a world."""
    from .._validate import as_quaternion, as_vector3
    from ..world import World

    if world is not None and not isinstance(world, World):
        raise TypeError(f"world must be a tumble.World or None, got {world!r}")
    return world, as_vector3("position", position), as_quaternion("orientation", orientation)


def load_mjcf(path_or_xml, *, world=None, position=(0.0, 0.0, 0.0), orientation=_IDENTITY):
    """``tumble.load_mjcf``: validate the placement, read the model, build it into ``world`` (or a new one)."""
    from .mjcf import read_mjcf

    world, position, orientation = _placement(world, position, orientation)
    return to_world(read_mjcf(path_or_xml), world, position, orientation)


def load_urdf(path, *, package_dirs=(), floating_base=False, world=None, position=(0.0, 0.0, 0.0),
              orientation=_IDENTITY):  # fmt: skip
    """``tumble.load_urdf``: as :func:`load_mjcf`, for a URDF file."""
    from .urdf import read_urdf

    if not isinstance(floating_base, bool):
        raise TypeError(f"floating_base must be True or False, got {floating_base!r}")
    world, position, orientation = _placement(world, position, orientation)
    return to_world(read_urdf(path, package_dirs=package_dirs, floating_base=floating_base), world, position,
                    orientation)  # fmt: skip
