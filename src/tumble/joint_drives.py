"""Actuators on a world's hinges and sliders, driven by ``world.ctrl``: MJCF's ``motor``, ``position``, ``velocity``
and ``general`` actuators once ``tumble.load_mjcf`` has put the model into a world.

Each pulls along its length ``l = gear · q`` with ``f = gain · c + bias₀ + bias₁ l + bias₂ l̇`` (``c`` the control
clipped to its range, ``q`` MuJoCo's joint coordinate: ``ref`` plus the world joint's angle or translation) and
pushes its joint with ``gear · f``: a torque about the hinge's axis (a force along the slider's) on the moving body,
the opposite on the other. The forces are worked out from the joints' coordinates before each step by a world
controller, and held through the step (explicitly: a stiff servo wants small steps, as it does in MuJoCo's Euler).
The bodies an actuator drives do not fall asleep.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["JointDrive", "JointDrives"]


@dataclass(frozen=True, eq=False)
class JointDrive:
    """One actuator on a world joint (read-only): its entry ``index`` in ``world.ctrl``, and its force law."""

    index: int
    name: str | None
    joint: object  # a tumble.Joint handle: a hinge or a slider
    gear: float
    gain: float
    bias: np.ndarray  # (3,)
    ctrl_range: tuple[float, float] | None
    ref: float  # the joint's MuJoCo coordinate when the world joint reads zero


class JointDrives:
    """A world's joint actuators and their controls; the controller that applies them is added with the first."""

    def __init__(self) -> None:
        self.drives: list[JointDrive] = []
        self.ctrl = np.zeros(0)

    def add(self, world, joint, *, gear, gain, bias, ctrl_range, ref, name=None) -> JointDrive:
        if joint.kind not in ("hinge", "slider"):
            raise ValueError(f"a joint actuator drives a hinge or a slider, got a {joint.kind} joint")
        drive = JointDrive(len(self.drives), name, joint, float(gear), float(gain), np.asarray(bias, float),
                           ctrl_range, float(ref))  # fmt: skip
        if not self.drives:
            world.add_controller(self.apply, name="joint actuators")
        self.drives.append(drive)
        self.ctrl = np.append(self.ctrl, 0.0)
        return drive

    def forces(self, world) -> np.ndarray:
        """Each actuator's force ``f`` along its length now (before its gear)."""
        from .dynamics.joint_solver import joint_coordinates

        state = world.state
        coordinates = np.zeros((len(world.joints), 5))  # every joint's (coordinate, rate, ...) in one call
        joint_coordinates(world.model.joints, state.body_pos, state.body_quat, state.body_linvel,
                          world.angular_velocities(), 0, len(coordinates), coordinates)  # fmt: skip
        out = np.zeros(len(self.drives))
        for k, d in enumerate(self.drives):
            q, qd = coordinates[d.joint.index, :2]
            c = float(self.ctrl[d.index])
            if d.ctrl_range is not None:
                c = min(max(c, d.ctrl_range[0]), d.ctrl_range[1])
            out[k] = d.gain * c + d.bias @ (1.0, d.gear * (d.ref + q), d.gear * qd)
        return out

    def apply(self, world, t) -> None:
        """Before a step: each actuator's torque (or force) on its two bodies, added to the step's loads at once."""
        loads = np.array([d.gear for d in self.drives]) * self.forces(world)
        state, inputs = world.state, world.inputs
        specs = [world._builder.joints[d.joint.index] for d in self.drives]
        # the joint's axis: the x axis of its frame, kept in the first body's frame (the world's, if that is it)
        frames = np.array([spec.local_frame_a for spec in specs])
        first = np.array([spec.body_a for spec in specs])
        held = first >= 0
        frames[held] = _multiply(state.body_quat[first[held]], frames[held])
        loads = loads[:, None] * _x_axis(frames)
        hinge = np.array([d.joint.kind == "hinge" for d in self.drives])
        # the coordinate is the second body's motion relative to the first (or to the world)
        for bodies, sign in (([spec.body_b for spec in specs], 1.0), (first, -1.0)):
            for k, body in enumerate(bodies):
                if body < 0 or world._builder.rows[body].mass_properties is None:
                    continue
                target = inputs.body_torque if hinge[k] else inputs.body_force
                target[body] += sign * loads[k]
                # a driven body stays awake, as every body does in MuJoCo: a servo settling slowly must not have
                # its speed zeroed by falling asleep
                if state.body_sleeping[body]:
                    island = state.body_island == state.body_island[body]
                    state.body_sleeping[island] = False
                state.body_sleep_time[body] = 0.0


def _multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products ``a ⊗ b`` of (n, 4) quaternions, row by row."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], axis=1)  # fmt: skip


def _x_axis(q: np.ndarray) -> np.ndarray:
    """The x axes of the frames the (n, 4) unit quaternions turn to: the first columns of their rotation matrices."""
    w, x, y, z = q.T
    return np.stack([1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y)], axis=1)
