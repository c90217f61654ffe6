"""Actuators on a world's hinges, sliders, universal and ball joints, driven by ``world.ctrl``: MJCF's ``motor``,
``position``, ``velocity`` and ``general`` actuators once ``tumble.load_mjcf`` has put the model into a world.

Each pulls along its length ``l = gear · q`` with ``f = gain · c + bias₀ + bias₁ l + bias₂ l̇`` (``c`` the control
clipped to its range, ``q`` MuJoCo's joint coordinate: ``ref`` plus the world joint's angle or translation) and
pushes its joint with ``gear · f``: a torque about the hinge's axis (a force along the slider's) on the moving body,
the opposite on the other. The forces are worked out from the joints' coordinates before each step by a world
controller, and held through the step (explicitly: a stiff servo wants small steps, as it does in MuJoCo's Euler).
The bodies an actuator drives do not fall asleep.

A universal or ball joint has several coordinates, as the hinges MuJoCo composes in one body have: the relative
rotation of the joint's second body (in the solver: ``b`` relative to ``a``) is ``R(u₁, q₁) R(u₂, q₂)`` about its two
axes (the first carried by ``a``, the second by ``b``), or ``R(u₁, q₁) R(u₂, q₂) R(u₃, q₃)`` about three orthonormal
axes given for a ball joint (Euler angles: in the axes' own basis ``B``, ``Bᵀ R B = R_x(σq₁) R_y(σq₂) R_z(σq₃)``,
``σ = det B``, read off the matrix). Their rates solve ``ω_b − ω_a = Σ q̇ᵢ uᵢ`` with the axes ``uᵢ`` where they are
now (``u₂`` turned by ``q₁``), and generalised forces ``τ`` are the moment ``M`` with ``uᵢ·M = τᵢ`` on ``b``, ``−M``
on ``a`` (the virtual work of the coordinates).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import portable
from ._validate import as_array, as_float
from .handles import Joint
from .math3d import quat_mul, quat_to_mat33

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
    coordinate: int = 0  # which of a universal (0: about axis_a) or ball joint's angles
    axes: np.ndarray | None = None  # (3, 3) a ball joint's hinge axes as rows, in the joint's frame on a


class JointDrives:
    """A world's joint actuators and their controls; the controller that applies them is added with the first."""

    def __init__(self) -> None:
        self.drives: list[JointDrive] = []
        self.ctrl = np.zeros(0)
        self._kinds: list[str] = []  # each drive's joint kind and coordinate in the solver's order, read once
        self._components: list[int] = []

    def add(self, world, joint, *, gear, gain, bias, ctrl_range, ref, name=None, coordinate=0,
            axes=None) -> JointDrive:  # fmt: skip
        if joint.kind not in ("hinge", "slider", "universal", "ball"):
            raise ValueError(f"a joint actuator drives a hinge, slider, universal or ball joint, got a {joint.kind} "
                             "joint")  # fmt: skip
        drive = JointDrive(len(self.drives), name, joint, float(gear), float(gain), np.asarray(bias, float),
                           ctrl_range, float(ref), coordinate, axes)  # fmt: skip
        if not self.drives:
            world.add_controller(self.apply, name="joint actuators")
        self.drives.append(drive)
        self.ctrl = np.append(self.ctrl, 0.0)
        self._kinds.append(joint.kind)
        # a universal joint to the world has the world as the solver's a, which carries its frame's x axis: axis_b
        flipped = joint.kind == "universal" and world._builder.joints[joint.index].to_world
        self._components.append(1 - coordinate if flipped else coordinate)
        return drive

    def forces(self, world) -> np.ndarray:
        """Each actuator's force ``f`` along its length now (before its gear)."""
        return self._forces(world, world.angular_velocities())[0]

    def _forces(self, world, angular_velocities) -> tuple[np.ndarray, dict]:
        """Each actuator's force, and the coordinates' frames of the universal and ball joints they drive."""
        from .dynamics.joint_solver import joint_coordinates

        state = world.state
        coordinates = np.zeros((len(world.joints), 5))  # every joint's (coordinate, rate, ...) in one call
        joint_coordinates(world.model.joints, state.body_pos, state.body_quat, state.body_linvel,
                          angular_velocities, 0, len(coordinates), coordinates)  # fmt: skip
        multi = {}  # each universal or ball joint's angles, rates and axes, once however many actuators drive it
        for d, kind in zip(self.drives, self._kinds, strict=True):
            if kind in ("universal", "ball") and d.joint.index not in multi:
                multi[d.joint.index] = _angles(world, d, angular_velocities)
        out = np.zeros(len(self.drives))
        for k, d in enumerate(self.drives):
            if d.joint.index in multi:
                q, qd, _ = multi[d.joint.index]
                q, qd = q[self._components[k]], qd[self._components[k]]
            else:
                q, qd = coordinates[d.joint.index, :2]
            c = float(self.ctrl[d.index])
            if d.ctrl_range is not None:
                c = min(max(c, d.ctrl_range[0]), d.ctrl_range[1])
            out[k] = d.gain * c + portable.dot(d.bias, (1.0, d.gear * (d.ref + q), d.gear * qd))
        return out, multi

    def apply(self, world, t) -> None:
        """Before a step: each actuator's torque (or force) on its two bodies, added to the step's loads at once."""
        forces, multi = self._forces(world, world.angular_velocities())
        loads = np.array([d.gear for d in self.drives]) * forces
        state, inputs = world.state, world.inputs
        specs = [world._builder.joints[d.joint.index] for d in self.drives]
        # the joint's axis: the x axis of its frame, kept in the first body's frame (the world's, if that is it)
        frames = np.array([spec.local_frame_a for spec in specs])
        first = np.array([spec.body_a for spec in specs])
        held = first >= 0
        frames[held] = _multiply(state.body_quat[first[held]], frames[held])
        loads = loads[:, None] * _x_axis(frames)
        # a universal or ball joint's generalised force as the moment M with uᵢ·M = τᵢ (module docstring): for a
        # universal joint the one in the plane of its two axes
        for k, d in enumerate(self.drives):
            if d.joint.index in multi:
                inverse = multi[d.joint.index][2]  # uᵢ·M = τᵢ: M = (the axes' rows)⁺ τ
                loads[k] = d.gear * forces[k] * inverse[:, self._components[k]]
        hinge = [kind != "slider" for kind in self._kinds]
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


def checked_drive(world, joint, gear, gain, bias, ctrl_range, ref, coordinate, axes) -> dict:
    """``World.add_joint_actuator``'s arguments checked, as :meth:`JointDrives.add` takes them (``axes`` turned into
    the joint's frame on its first body)."""
    if not isinstance(joint, Joint) or joint._world is not world:
        raise TypeError(f"joint must be a joint of this world, got {joint!r}")
    gear, gain, ref = as_float("gear", gear), as_float("gain", gain), as_float("ref", ref)
    bias = as_array("bias", bias, (3,), batch=False)
    if ctrl_range is not None:
        low, high = (float(v) for v in as_array("ctrl_range", ctrl_range, (2,), batch=False))
        if not low <= high:
            raise ValueError(f"ctrl_range must be (low, high) with low <= high, got {ctrl_range!r}")
        ctrl_range = (low, high)
    count = {"universal": 2, "ball": 3}.get(joint.kind, 1)
    if isinstance(coordinate, bool) or not isinstance(coordinate, (int, np.integer)) or not 0 <= coordinate < count:
        raise ValueError(f"coordinate must be an integer in 0 to {count - 1} for a {joint.kind} joint, got "
                         f"{coordinate!r}")  # fmt: skip
    if (axes is None) != (joint.kind != "ball"):
        raise ValueError(f"axes must be given for a ball joint's actuator and only for it, got {axes!r} for a "
                         f"{joint.kind} joint")  # fmt: skip
    if axes is not None:
        axes = as_array("axes", axes, (3, 3), batch=False)
        if not np.allclose(portable.matmul(axes, axes.T), np.eye(3), rtol=0.0, atol=1e-6):
            raise ValueError(f"axes must be three orthonormal rows, got {axes.tolist()}")
        axes = portable.matmul(
            axes, joint_frames(world, joint.index)[0]
        )  # in the joint's frame on its (solver's) first body
    return {
        "gear": gear,
        "gain": gain,
        "bias": bias,
        "ctrl_range": ctrl_range,
        "ref": ref,
        "coordinate": int(coordinate),
        "axes": axes,
    }


def joint_frames(world, index: int) -> tuple[np.ndarray, np.ndarray]:
    """The rotation matrices of joint ``index``'s frames now, carried by the solver's ``a`` and ``b``."""
    spec, quats = world._builder.joints[index], world.state.body_quat
    frame_a = spec.local_frame_a if spec.body_a < 0 else quat_mul(tuple(quats[spec.body_a]), tuple(spec.local_frame_a))
    frame_b = quat_mul(tuple(quats[spec.body_b]), tuple(spec.local_frame_b))
    return np.reshape(quat_to_mat33(frame_a), (3, 3)), np.reshape(quat_to_mat33(frame_b), (3, 3))


def _angles(world, drive: JointDrive, angular_velocities) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A universal or ball joint's angles, their rates, and the (pseudo-)inverse of its axes where they are now
    (rows ``uᵢ``, world frame): the matrix ``P`` with ``q̇ = Pᵀ (ω_b − ω_a)`` and ``M = P τ``."""
    index = drive.joint.index
    spec = world._builder.joints[index]
    frame_a, frame_b = joint_frames(world, index)
    relative = portable.matmul(frame_a.T, frame_b)  # b's joint frame in a's
    if drive.axes is None:  # universal: R_x(q₁) R_y(q₂), x carried by a, y by b
        q = np.array(
            [portable.arctan2(relative[2, 1], relative[1, 1]), portable.arctan2(relative[0, 2], relative[0, 0])]
        )
        inverse = np.column_stack([frame_a[:, 0], frame_b[:, 1]])  # orthonormal rows: their transpose
    else:
        basis = drive.axes.T  # columns: the three axes in a's joint frame
        sense = np.sign(portable.det(basis))
        r = portable.matmul(portable.matmul(basis.T, relative), basis)  # R_x(σq₁) R_y(σq₂) R_z(σq₃)
        q = sense * np.array([portable.arctan2(-r[1, 2], r[2, 2]), portable.arcsin(np.clip(r[0, 2], -1.0, 1.0)),
                              portable.arctan2(-r[0, 1], r[0, 0])])  # fmt: skip
        (ux, uy, uz), v = basis[:, 0], basis[:, 1]  # v turned about u by q₁ (Rodrigues; u ⊥ v)
        u_cross_v = np.array([uy * v[2] - uz * v[1], uz * v[0] - ux * v[2], ux * v[1] - uy * v[0]])
        turned = portable.cos(q[0]) * v + portable.sin(q[0]) * u_cross_v
        inverse = portable.inverse(
            portable.matvec(np.array([frame_a, frame_a, frame_b]), np.array([basis[:, 0], turned, basis[:, 2]]))
        )
    spin_a = np.zeros(3) if spec.body_a < 0 else angular_velocities[spec.body_a]
    return q, portable.matvec(inverse.T, angular_velocities[spec.body_b] - spin_a), inverse


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
