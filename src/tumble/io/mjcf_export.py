"""A world written as MJCF (``World.to_mjcf()``), so that a tumble scene can be cross-checked in MuJoCo.

The joints become MuJoCo's tree: every body reached from the world through joints is nested in the body it is
joined to (a joint to the world or to a static body hangs it from the world), with the joint in the child (``ball``,
``hinge``, ``slide``; a ``fixed`` joint welds the child); the bodies no joint reaches from the world are roots of
their own trees with a free joint. A joint that closes a loop becomes an equality constraint: a ball joint a
``connect``, a fixed joint a ``weld``, a hinge two ``connect`` on its axis. Each body carries its exact mass
properties (``inertial`` with ``fullinertia``) and its shapes as geoms (a convex hull as a mesh of its points);
static bodies are the world's geoms (a plane as a ``plane`` geom). Every body is where it is now, so ``qpos0`` is
the present pose, and the present velocities are a keyframe named ``now``
(``mujoco.mj_resetDataKeyframe(model, data, 0)``).

Where the engines differ, the file keeps MuJoCo's meaning: friction is MuJoCo's per geom (MuJoCo takes the larger
of two geoms', tumble their geometric mean), ``collision_group``/``collision_mask`` become ``contype``/``conaffinity``,
and the world's joint actuators (``world.ctrl``) become ``<general>`` actuators on their joints (a driven joint counts
from its ``ref``, so the actuators' lengths agree; the keyframe holds the controls). What MJCF cannot say is refused
with a ``ValueError`` naming it: vehicles, rotors and thrusters, distance joints,
sliders that close a loop, triangle meshes (MuJoCo collides a mesh as its convex hull), joint motors and springs,
ball-joint cones. Restitution, rolling resistance and body damping have no MJCF counterpart and are left out.
"""

from __future__ import annotations

from xml.sax.saxutils import quoteattr

import numpy as np

from ..models.mjcf.frames import quat_z_to
from ..rotation import quat_conjugate, quat_multiply, quat_rotate, quat_to_matrix
from ..shapes import Box, Capsule, ConvexHull, Cylinder, Plane, Sphere
from ..vehicles import quadrotors
from .scene_dump import body_names, joint_entry

__all__ = ["world_to_mjcf"]

_WORLD = -1
_ALL = 0xFFFFFFFF


def _num(values) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def _geom(spec, name: str, position, quat, assets: list[str]) -> str:
    """One shape as a ``<geom>`` at ``position``/``quat`` in its body's frame (a hull adds a mesh asset)."""
    shape = spec.shape
    if isinstance(shape, Sphere):
        kind = f"type='sphere' size='{_num([shape.radius])}'"
    elif isinstance(shape, Box):
        kind = f"type='box' size='{_num(0.5 * np.asarray(shape.extents))}'"
    elif isinstance(shape, Capsule):
        kind = f"type='capsule' size='{_num([shape.radius, 0.5 * shape.length])}'"
    elif isinstance(shape, Cylinder):
        kind = f"type='cylinder' size='{_num([shape.radius, 0.5 * shape.height])}'"
    elif isinstance(shape, ConvexHull):
        assets.append(f"<mesh name={quoteattr(name)} vertex='{_num(shape.vertices)}'/>")
        kind = f"type='mesh' mesh={quoteattr(name)}"
    elif isinstance(shape, Plane):
        normal = quat_rotate(quat, shape.normal)
        position, quat = position + normal * shape.offset, quat_z_to(normal)
        kind = "type='plane' size='0 0 1'"
    else:
        raise ValueError(f"to_mjcf: body {name.rsplit('/', 1)[0]!r} has a {type(shape).__name__}, which MuJoCo "
                         "collides as its convex hull; only spheres, boxes, capsules, cylinders, hulls and planes "
                         "are written")  # fmt: skip
    filters = ""
    if int(spec.group) != 1 or int(spec.mask) != _ALL:
        filters = f" contype='{int(spec.group) & 0x7FFFFFFF}' conaffinity='{int(spec.mask) & 0x7FFFFFFF}'"
    return (f"<geom name={quoteattr(name)} {kind} pos='{_num(position)}' quat='{_num(quat)}' "
            f"friction='{_num([spec.friction, 0.005, 0.0001])}'{filters}/>")  # fmt: skip


def _geoms(world, body, name: str, assets: list[str], pose=None) -> str:
    """A body's shapes as geoms, in its frame (or, with ``pose``, moved by it: a static body's in the world)."""
    out = []
    for k, spec in enumerate(world._builder.rows[body.index].shapes):
        position, quat = np.asarray(spec.position, float), np.asarray(spec.quat, float)
        if pose is not None:
            position, quat = pose[0] + quat_rotate(pose[1], position), quat_multiply(pose[1], quat)
        out.append(_geom(spec, f"{name}/{k}", position, quat, assets))
    return "".join(out)


def _refuse_what_mjcf_cannot_say(world, joints: list[dict]) -> None:
    if quadrotors(world) or world.actuators:
        raise ValueError("to_mjcf: the world has vehicles or rotors and thrusters, which are not written to MJCF (yet)")
    drives = [] if world._joint_drives is None else world._joint_drives.drives
    for drive in drives:
        if drive.joint.kind in ("universal", "ball"):
            raise ValueError(f"to_mjcf: actuator {drive.index} drives a {drive.joint.kind} joint's angle, which is not "
                             "written to MJCF (yet)")  # fmt: skip
    for entry in joints:
        label = f"the {entry['type']} joint of {entry['a']!r} and {entry['b']!r}"
        if entry["type"] == "distance":
            raise ValueError(f"to_mjcf: {label} is a distance joint, which MJCF has no joint for")
        if entry.get("spring_hertz", 0.0) > 0.0 or entry.get("max_motor_torque", entry.get("max_motor_force", 0.0)):
            raise ValueError(f"to_mjcf: {label} has a motor or spring, which are not written to MJCF (yet)")
        if "cone_angle" in entry or "twist_lower" in entry or "twist_upper" in entry:
            raise ValueError(f"to_mjcf: {label} has a cone or twist limit, which MJCF's ball joint cannot hold")


def _tree(world, joints) -> tuple[dict, dict, list[int]]:
    """``parent`` and ``via`` (the joint entry, None for a free root) of every dynamic body, in the breadth-first
    order that nests them, and the joints that close loops."""
    dynamic = [b.index for b in world.bodies if not b.is_static]
    index = {name: i for i, name in enumerate(body_names(world))}
    static = {b.index for b in world.bodies if b.is_static}
    adjacent: dict[int, list[tuple[int, int]]] = {_WORLD: [], **{i: [] for i in dynamic}}
    for k, entry in enumerate(joints):
        a = index[entry["a"]]
        b = _WORLD if entry["b"] is None or index[entry["b"]] in static else index[entry["b"]]
        a = _WORLD if a in static else a
        adjacent[a].append((b, k))
        adjacent[b].append((a, k))
    parent, via, loops, used = {}, {}, [], set()
    for root in [_WORLD, *dynamic]:
        if root != _WORLD and root in parent:
            continue
        if root != _WORLD:
            parent[root], via[root] = _WORLD, None
        queue = [root]
        while queue:
            node = queue.pop(0)
            for other, k in adjacent[node]:
                if k in used:
                    continue
                used.add(k)
                if other == _WORLD or other in parent:
                    loops.append(k)
                    continue
                parent[other], via[other] = node, joints[k]
                queue.append(other)
    return parent, via, loops


def _pose(world, i: int) -> tuple[np.ndarray, np.ndarray]:
    if i == _WORLD:
        return np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])
    body = world.bodies[i]
    return np.asarray(body.position, float), np.asarray(body.orientation, float)


def _velocity(world, i: int, point) -> tuple[np.ndarray, np.ndarray]:
    """The (linear velocity at ``point``, angular velocity) of body ``i`` (zero for the world)."""
    if i == _WORLD:
        return np.zeros(3), np.zeros(3)
    body = world.bodies[i]
    return np.asarray(body.point_velocity(point), float), np.asarray(body.angular_velocity, float)


def _composite_xml(entry, local: str, rotation_t, child_is_a: bool, w_rel, v_rel, qpos: list, qvel: list) -> str:
    """A planar joint as two slides and a hinge, a universal joint as two hinges (the parent's axis first, as
    MuJoCo composes a body's joints), each zero at the present pose."""
    if entry["type"] == "planar":
        normal = np.asarray(entry["normal"], float)
        helper = np.array([0.0, 0.0, 1.0]) if abs(normal[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        u = np.cross(helper, normal)
        u /= np.linalg.norm(u)
        axes = [("slide", u), ("slide", np.cross(normal, u)), ("hinge", normal)]
    else:
        first, second = np.asarray(entry["axis_a"], float), np.asarray(entry["axis_b"], float)
        second = second - (second @ first) * first  # perpendicular as the joint holds them, to round-off
        second /= np.linalg.norm(second)
        axes = [("hinge", second), ("hinge", first)] if child_is_a else [("hinge", first), ("hinge", second)]
    out = []
    for kind, axis in axes:
        qpos.append(0.0)
        qvel.append(float(axis @ (w_rel if kind == "hinge" else v_rel)))
        out.append(f"<joint type='{kind}' {local} axis='{_num(rotation_t @ axis)}'/>")
    return "".join(out)


def _joint_xml(world, child: int, parent: int, entry, qpos: list, qvel: list, driven=None, child_is_a=True) -> str:
    """The child's joint element (and its keyframe coordinates): the present pose is the joint's zero, or, for a
    joint that actuators drive (``driven``: its name, MuJoCo's sense against the world joint's, and its ``ref``),
    that ``ref``, so that the actuators' lengths are the same in both engines."""
    position, quat = _pose(world, child)
    rotation_t = quat_to_matrix(quat).T
    if entry is None:  # a free root
        v, w = _velocity(world, child, position)
        qpos += [*position, *quat]
        qvel += [*v, *(rotation_t @ w)]
        return "<freejoint/>"
    kind = {"ball": "ball", "hinge": "hinge", "slider": "slide", "fixed": None}.get(entry["type"], entry["type"])
    if kind is None:
        return ""
    anchor = np.asarray(entry["anchor"], float)
    v_child, w_child = _velocity(world, child, anchor)
    v_parent, w_parent = _velocity(world, parent, anchor)
    local = f"pos='{_num(rotation_t @ (anchor - position))}'"
    if kind in ("planar", "universal"):
        return _composite_xml(entry, local, rotation_t, child_is_a, w_child - w_parent, v_child - v_parent, qpos,
                              qvel)  # fmt: skip
    if kind == "ball":
        qpos += [1.0, 0.0, 0.0, 0.0]
        qvel += list(rotation_t @ (w_child - w_parent))
        return f"<joint type='ball' {local}/>"
    axis = np.asarray(entry["axis"], float)
    name, sense, ref = driven if driven is not None else (None, 1.0, 0.0)
    qpos.append(ref)
    qvel.append(float(axis @ ((w_child - w_parent) if kind == "hinge" else (v_child - v_parent))))
    bounds = ""
    if "lower" in entry or "upper" in entry:
        low, high = sorted(ref + sense * np.array([entry.get("lower", -1e10), entry.get("upper", 1e10)]))
        bounds = f" range='{_num([low, high])}'"
    named = "" if name is None else f" name={quoteattr(name)} ref='{_num([ref])}'"
    damped = f" damping='{_num([entry['damping']])}'" if entry.get("damping", 0.0) > 0.0 else ""
    return f"<joint type='{kind}'{named} {local} axis='{_num(rotation_t @ axis)}'{bounds}{damped}/>"


def _loop_xml(world, entry, index: dict[str, int]) -> str:
    """The equality constraint of a joint that closes a loop (a static body's end is the world's)."""
    ends = [name for name in (entry["a"], entry["b"]) if name is not None and not world.bodies[index[name]].is_static]
    first = f"body1={quoteattr(ends[0])}" + (f" body2={quoteattr(ends[1])}" if len(ends) > 1 else "")
    position, quat = _pose(world, index[ends[0]])
    rotation_t = quat_to_matrix(quat).T
    anchor = np.asarray(entry["anchor"], float)
    if entry["type"] == "ball":
        return f"<connect {first} anchor='{_num(rotation_t @ (anchor - position))}'/>"
    if entry["type"] == "hinge":  # two points of the axis held: a hinge
        ends = (anchor, anchor + 0.1 * np.asarray(entry["axis"], float))
        return "".join(f"<connect {first} anchor='{_num(rotation_t @ (p - position))}'/>" for p in ends)
    if entry["type"] == "fixed":
        return f"<weld {first}/>"
    raise ValueError(f"to_mjcf: the {entry['type']} joint of {entry['a']!r} and {entry['b']!r} closes a loop, which "
                     "MJCF's equality constraints cannot hold")  # fmt: skip


def _driven_joints(world, via: dict, names: list[str]) -> dict[int, tuple[str, float, float]]:
    """For each world joint that actuators drive: its MJCF name, MuJoCo's sense against the world joint's (-1 where
    the tree hangs the joint's first body from its second) and its ``ref``."""
    drives = [] if world._joint_drives is None else world._joint_drives.drives
    child_of = {entry["_index"]: child for child, entry in via.items() if entry is not None}  # joint -> its child
    out = {}
    for drive in drives:
        k = drive.joint.index
        spec = world._builder.joints[k]
        entry_child = child_of.get(k)
        if entry_child is None:
            raise ValueError(f"to_mjcf: actuator {drive.index} drives a joint that closes a loop, which MJCF's "
                             "equality constraints cannot carry")  # fmt: skip
        sense = 1.0 if entry_child == spec.body_b else -1.0
        coordinate = drive.joint.angle if drive.joint.kind == "hinge" else drive.joint.translation
        ref = sense * (drive.ref + coordinate)
        if k in out and abs(out[k][2] - ref) > 0.0:
            raise ValueError(f"to_mjcf: the actuators on joint {k} count its coordinate from different refs")
        out[k] = (f"{names[entry_child]}/joint", sense, ref)
    return out


def _actuators_xml(world, driven: dict) -> str:
    """Each joint actuator as a ``<general>`` on its joint (the gear carries MuJoCo's sense)."""
    out = []
    for drive in [] if world._joint_drives is None else world._joint_drives.drives:
        name, sense, _ = driven[drive.joint.index]
        label = "" if drive.name is None else f" name={quoteattr(drive.name)}"
        limits = "ctrllimited='false'" if drive.ctrl_range is None else f"ctrlrange='{_num(drive.ctrl_range)}'"
        out.append(
            f"<general{label} joint={quoteattr(name)} gear='{_num([sense * drive.gear])}' "
            f"gainprm='{_num([drive.gain])}' biastype='affine' biasprm='{_num(drive.bias)}' {limits}/>"
        )
    return "".join(out)


def world_to_mjcf(world, *, timestep: float | None = None, model: str = "tumble") -> str:
    """The MJCF text of ``world`` now (module docstring); ``timestep`` [s] goes into ``<option>`` if given."""
    names = body_names(world)
    joints = [joint_entry(joint, names) for joint in world.joints]
    _refuse_what_mjcf_cannot_say(world, joints)
    for k, entry in enumerate(joints):
        entry["_index"] = k
    parent, via, loops = _tree(world, joints)
    driven = _driven_joints(world, via, names)
    children: dict[int, list[int]] = {}
    for child, p in parent.items():
        children.setdefault(p, []).append(child)
    assets: list[str] = []
    qpos: list[float] = []
    qvel: list[float] = []

    def body_open(i: int) -> str:
        """A body's opening tag, joint, inertial and geoms; its children and ``</body>`` follow."""
        position, quat = _pose(world, i)
        parent_position, parent_quat = _pose(world, parent[i])
        inverse = quat_conjugate(parent_quat)
        local_position, local_quat = quat_rotate(inverse, position - parent_position), quat_multiply(inverse, quat)
        mp = world._builder.rows[i].mass_properties
        inertia = mp.inertia
        full = [inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]]
        entry = via[i]
        drive = None if entry is None else driven.get(entry["_index"])
        joint = _joint_xml(world, i, parent[i], entry, qpos, qvel, drive, entry is not None and entry["a"] == names[i])
        return (f"<body name={quoteattr(names[i])} pos='{_num(local_position)}' quat='{_num(local_quat)}'>{joint}"
                f"<inertial pos='{_num(mp.com)}' mass='{_num([mp.mass])}' fullinertia='{_num(full)}'/>"
                f"{_geoms(world, world.bodies[i], names[i], assets)}")  # fmt: skip

    statics = "".join(_geoms(world, b, names[b.index], assets, pose=_pose(world, b.index))
                      for b in world.bodies if b.is_static)  # fmt: skip
    # depth first, parents before children (MuJoCo's joint order, the keyframe's), on a stack of its own: a chain of
    # a thousand links is past Python's recursion limit
    parts, stack = [], [(i, False) for i in reversed(children.get(_WORLD, []))]
    while stack:
        i, close = stack.pop()
        if close:
            parts.append("</body>")
            continue
        parts.append(body_open(i))
        stack.append((i, True))
        stack.extend((c, False) for c in reversed(children.get(i, [])))
    bodies = "".join(parts)
    index = {name: i for i, name in enumerate(names)}
    equality = "".join(_loop_xml(world, joints[k], index) for k in loops)
    option = f"<option gravity='{_num(world.gravity)}'" + (f" timestep='{_num([timestep])}'/>" if timestep else "/>")
    ctrl = f" ctrl='{_num(world.ctrl)}'" if len(world.ctrl) else ""
    keyframe = f"<keyframe><key name='now' qpos='{_num(qpos)}' qvel='{_num(qvel)}'{ctrl}/></keyframe>" if qpos else ""
    actuators = _actuators_xml(world, driven)
    return (f"<mujoco model={quoteattr(model)}><compiler angle='radian' autolimits='true'/>{option}"
            + (f"<asset>{''.join(assets)}</asset>" if assets else "")
            + f"<worldbody>{statics}{bodies}</worldbody>"
            + (f"<equality>{equality}</equality>" if equality else "")
            + (f"<actuator>{actuators}</actuator>" if actuators else "")
            + f"{keyframe}</mujoco>")  # fmt: skip
