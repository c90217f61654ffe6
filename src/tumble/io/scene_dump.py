"""A world written back as a scene (``World.to_scene()``): the same structure as a scene file, at the current
state, so that ``load`` of it builds the same bodies, shapes, materials and joints where they are now.

Joints are re-created at the bodies' current poses, so their limits and spring targets are shifted by the
current angle or translation (a hinge 0.3 rad into its range keeps its stops where they were). Meshes are
written out as vertices and faces; bodies without a name get one (``body7``) so that joints can refer to them.
"""

from __future__ import annotations

import math

import numpy as np

from .. import wind as winds
from ..control import CascadedPID, Circle, Hover, Lissajous, MinimumSnap, SE3Controller
from ..rotation import quat_multiply, quat_rotate
from ..shapes import Box, Capsule, ConvexHull, Cylinder, Plane, Sphere, TriMesh
from ..vehicles import Quadrotor, quadrotors

__all__ = [
    "CONTROLLERS",
    "REFERENCES",
    "body_names",
    "joint_entry",
    "vehicle_to_scene",
    "wind_to_scene",
    "world_to_scene",
]


def _floats(values) -> list:
    return np.asarray(values, dtype=float).tolist()


def _shape(shape) -> dict:
    if isinstance(shape, Sphere):
        return {"type": "sphere", "radius": float(shape.radius)}
    if isinstance(shape, Box):
        return {"type": "box", "extents": _floats(shape.extents)}
    if isinstance(shape, Capsule):
        return {"type": "capsule", "radius": float(shape.radius), "length": float(shape.length)}
    if isinstance(shape, Cylinder):
        return {"type": "cylinder", "radius": float(shape.radius), "height": float(shape.height)}
    if isinstance(shape, Plane):
        return {"type": "plane", "normal": _floats(shape.normal), "offset": float(shape.offset)}
    if isinstance(shape, ConvexHull):
        return {"type": "hull", "points": _floats(shape.vertices)}
    if isinstance(shape, TriMesh):
        return {"type": "mesh", "vertices": _floats(shape.vertices), "faces": np.asarray(shape.faces).tolist()}
    raise TypeError(f"cannot write shape {shape!r} to a scene")  # pragma: no cover - every shape is handled


def _geometry(specs) -> dict:
    if len(specs) == 1 and not np.any(specs[0].position) and np.allclose(specs[0].quat, (1.0, 0.0, 0.0, 0.0)):
        return {"shape": _shape(specs[0].shape)}
    return {"shapes": [{"shape": _shape(s.shape), "position": _floats(s.position), "orientation": _floats(s.quat)}
                       for s in specs]}  # fmt: skip


def body_names(world) -> list[str]:
    """Every body's name, a made-up unique one (``body7``) for a body without."""
    taken = {b.name for b in world.bodies if b.name is not None}
    names = []
    for body in world.bodies:
        name = body.name
        if name is None:
            name, k = f"body{body.index}", 0
            while name in taken:
                k += 1
                name = f"body{body.index}_{k}"
            taken.add(name)
        names.append(name)
    return names


def _placed(world, body, name: str) -> dict:
    row = world._builder.rows[body.index]
    entry = {"name": name, **(_geometry(row.shapes) if row.shapes else {})}
    entry["position"], entry["orientation"] = _floats(body.position), _floats(body.orientation)
    if row.shapes:
        first = row.shapes[0]
        entry.update(friction=first.friction, restitution=first.restitution,
                     rolling_resistance=first.rolling_resistance, collision_group=int(first.group),
                     collision_mask=int(first.mask))  # fmt: skip
    return entry


def _body(world, body, name: str) -> dict:
    row = world._builder.rows[body.index]
    entry = _placed(world, body, name)
    mp = row.mass_properties
    entry.update(mass=float(mp.mass), inertia=_floats(mp.inertia), velocity=_floats(body.velocity),
                 angular_velocity=_floats(body.angular_velocity), linear_damping=float(row.linear_damping),
                 angular_damping=float(row.angular_damping))  # fmt: skip
    if np.any(row.constant_force) or np.any(row.constant_torque):
        entry.update(constant_force=_floats(row.constant_force), constant_torque=_floats(row.constant_torque))
    return entry


def _bounds(lower: float, upper: float, shift: float) -> dict:
    out = {}
    if math.isfinite(lower):
        out["lower"] = lower - shift
    if math.isfinite(upper):
        out["upper"] = upper - shift
    return out


def joint_entry(joint, names: list[str]) -> dict:
    """A joint as its scene entry at the bodies' present poses (``names``: :func:`body_names`)."""
    spec = joint._world._builder.joints[joint.index]
    lower, upper, speed, max_motor, hertz, ratio, target, cone, damping = (float(v) for v in spec.drive)
    a, b = joint.body_a, joint.body_b
    entry = {"type": joint.kind, "a": names[a.index], "b": None if b is None else names[b.index]}
    if spec.collide_connected:
        entry["collide_connected"] = True
    anchor = _floats(joint.anchor_a)
    # The joint frame's x axis (the hinge or slider axis, a ball joint's twist axis) in the world now.
    frame = spec.local_frame_a
    if spec.body_a >= 0:
        frame = quat_multiply(joint._world.state.body_quat[spec.body_a], frame)
    axis = _floats(quat_rotate(frame, (1.0, 0.0, 0.0)))
    if joint.kind == "ball":
        entry["anchor"] = anchor
        if math.isfinite(cone) or math.isfinite(lower) or math.isfinite(upper):
            entry["axis"] = axis
            entry.update({f"twist_{k}": v for k, v in _bounds(lower, upper, joint.twist).items()})
            if math.isfinite(cone):
                entry["cone_angle"] = cone
    elif joint.kind in ("hinge", "slider"):
        shift = joint.angle if joint.kind == "hinge" else joint.translation
        entry.update(anchor=anchor, axis=axis, motor_speed=speed, spring_hertz=hertz, spring_damping_ratio=ratio,
                     spring_target=target - shift, **_bounds(lower, upper, shift))  # fmt: skip
        if damping > 0.0:
            entry["damping"] = damping
        entry["max_motor_torque" if joint.kind == "hinge" else "max_motor_force"] = max_motor
    elif joint.kind == "fixed":
        entry["anchor"] = anchor
    elif joint.kind == "planar":
        entry.update(anchor=anchor, normal=axis)
    elif joint.kind == "universal":
        # the solver's a carries the frame's x axis, its b the y axis (joined to the world: the world carries x)
        frame_b = spec.local_frame_b
        if spec.body_b >= 0:
            frame_b = quat_multiply(joint._world.state.body_quat[spec.body_b], frame_b)
        carried_b = _floats(quat_rotate(frame_b, (0.0, 1.0, 0.0)))
        # perpendicular as the joint holds them to its tolerance; written so to round-off, as UniversalJoint asks
        carried_b = np.asarray(carried_b) - (np.asarray(carried_b) @ np.asarray(axis)) * np.asarray(axis)
        carried_b = _floats(carried_b / np.linalg.norm(carried_b))
        axes = (axis, carried_b) if not spec.to_world else (carried_b, axis)
        entry.update(anchor=anchor, axis_a=axes[0], axis_b=axes[1])
    else:
        entry.update(anchor_a=anchor, anchor_b=_floats(joint.anchor_b), length=target, min_length=lower,
                     max_length=upper, spring_hertz=hertz, spring_damping_ratio=ratio)  # fmt: skip
    return entry


def world_to_scene(world, *, dt: float | None = None, duration: float | None = None) -> dict:
    """The scene dict of ``world`` now (``dt`` and ``duration`` default to the scene defaults)."""
    names = body_names(world)
    solver = world.solver
    settings = {
        "gravity": _floats(world.gravity),
        "integrator": world.integrator,
        "substeps": int(solver.substeps),
        "contact_hertz": float(solver.contact_hertz),
        "contact_damping_ratio": float(solver.contact_damping_ratio),
        "joint_damping_ratio": float(solver.joint_damping_ratio),
        "sleep": bool(solver.sleep),
    }
    if math.isfinite(solver.joint_hertz):  # else the default: as stiff as the substeps allow
        settings["joint_hertz"] = float(solver.joint_hertz)
    if dt is not None:
        settings["dt"] = float(dt)
    if duration is not None:
        settings["duration"] = float(duration)
    vehicles = {quad.body.index: quad for quad in quadrotors(world)}
    scene = {
        "world": settings,
        "bodies": [
            _body(world, b, names[b.index]) for b in world.bodies if not b.is_static and b.index not in vehicles
        ],  # fmt: skip
        "static": [_placed(world, b, names[b.index]) for b in world.bodies if b.is_static],
        "joints": [joint_entry(j, names) for j in world.joints],
        "vehicles": [vehicle_to_scene(quad, names[index]) for index, quad in vehicles.items()],
    }
    wind = wind_to_scene(world.wind)
    if wind is not None:
        scene["wind"] = wind
    return scene


# The controllers and trajectories a scene file names (tumble.scene_file builds them by these names).
CONTROLLERS = {"se3": SE3Controller, "cascaded_pid": CascadedPID}
REFERENCES = {"hover": Hover, "circle": Circle, "lissajous": Lissajous, "minimum_snap": MinimumSnap}


def _spec_of(obj, kinds: dict, fields: tuple[str, ...]) -> dict | None:
    """``{"type": name, field: value, ...}`` for an instance of one of ``kinds``; None for anything else."""
    for name, kind in kinds.items():
        if type(obj) is kind:
            out = {"type": name}
            for field in fields:
                value = getattr(obj, field, None)
                if value is not None:
                    out[field] = value.tolist() if isinstance(value, np.ndarray) else value
            return out
    return None


_CONTROLLER_FIELDS = ("kp_pos", "kd_pos", "ki_pos", "kp_att", "kd_att", "feedforward", "kp_vel", "ki_vel", "kp_rate",
                      "integral_limit")  # fmt: skip
_REFERENCE_FIELDS = ("position", "center", "radius", "frequency", "A", "B", "a", "b", "delta", "waypoints", "times",
                     "yaw")  # fmt: skip


def vehicle_to_scene(quad: Quadrotor, name: str) -> dict:
    """The ``[[vehicles]]`` entry of ``quad`` now. A controller or trajectory that is not one of
    ``tumble.control``'s is left out (the vehicle is then written with its motors' present commands)."""
    body = quad.body
    params = {name: (_floats(value) if isinstance(value, np.ndarray) else value)
              for name, value in quad.params.items()}  # fmt: skip
    params["rotor_directions"] = [int(d) for d in quad.params["rotor_directions"]]
    entry = {"type": "quadrotor", "params": params, "layout": quad.layout, "position": _floats(body.position),
             "orientation": _floats(body.orientation), "velocity": _floats(body.velocity),
             "angular_velocity": _floats(body.angular_velocity), "rotor_speeds": _floats(quad.rotor_speeds),
             "name": name}  # fmt: skip
    flight = quad._flight
    controller = trajectory = None
    if flight is not None and flight.handle in quad.world.controllers:
        controller = _spec_of(flight.controller, CONTROLLERS, _CONTROLLER_FIELDS)
        trajectory = _spec_of(flight.trajectory, REFERENCES, _REFERENCE_FIELDS)
    if controller is not None and trajectory is not None:
        if flight.rate is not None:
            controller["rate"] = flight.rate
        entry.update(controller=controller, trajectory=trajectory)
    else:
        entry["commands"] = _floats(quad.commanded_rotor_speeds)
    return entry


def wind_to_scene(wind) -> dict | None:
    """The ``[wind]`` table of a world's wind (None for still air or a wind model of the user's own)."""
    if isinstance(wind, winds.Constant):
        return {"type": "constant", "velocity": _floats(wind.v)}
    if isinstance(wind, winds.Sinusoid):
        return {"type": "sinusoid", "mean": _floats(wind.mean), "amplitude": _floats(wind.amplitude),
                "frequency": wind.frequency}  # fmt: skip
    if isinstance(wind, winds.Dryden):
        out = {"type": "dryden", "mean": _floats(wind.mean), "sigma": _floats(wind.sigma),
               "length_scale": _floats(wind.length_scale)}  # fmt: skip
        if wind.seed is not None:
            out["seed"] = wind.seed
        return out
    return None
