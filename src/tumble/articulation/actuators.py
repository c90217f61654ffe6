"""Actuators that drive an articulation's hinges and slides from a control vector ``ctrl``.

An actuator pulls along its length ``l = gear · q`` (``q`` the joint's coordinate) with the force

    f = gain · c + bias₀ + bias₁ · l + bias₂ · l̇,    c = ctrl clipped to ctrl_range,

and pushes the joint with ``gear · f``: MuJoCo's general actuator with a joint transmission, fixed gain, affine
bias and no activation dynamics. Its shortcuts are special cases: a motor is ``gain = 1, bias = 0`` (the torque
``gear · ctrl``), a position servo ``gain = kp, bias = (0, -kp, -kv)`` (it pulls ``l`` towards ``ctrl``), a
velocity servo ``gain = kv, bias = (0, 0, -kv)``. The controls are held between calls, as joint forces are, so
each joint's actuators add up to one affine drive ``D + D_q q + D_qd q̇`` that the kernels evaluate at every
stage of a step (``model.DRIVE``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import portable

__all__ = ["Actuator", "actuator_forces", "drive_columns"]


@dataclass(frozen=True, eq=False)
class Actuator:
    """One actuator (read-only); see the module docstring for its force.

    Attributes:
        index: its entry in ``ctrl``; name: optional label; link: the link whose (Revolute or Prismatic) joint
            it drives; gear: the transmission ratio; gain, bias (3,): the force law; ctrl_range: ``(low, high)``
            the control is clipped to, or ``None``.
    """

    index: int
    name: str | None
    link: int
    gear: float
    gain: float
    bias: np.ndarray
    ctrl_range: tuple[float, float] | None

    def control(self, ctrl: np.ndarray) -> float:
        """This actuator's control from the whole vector, clipped to its range."""
        value = float(ctrl[self.index])
        return value if self.ctrl_range is None else min(max(value, self.ctrl_range[0]), self.ctrl_range[1])


def drive_columns(actuators, dofs: list[int], ctrl: np.ndarray, nv: int) -> np.ndarray:
    """(nv, 3): each degree of freedom's drive ``D, D_q, D_qd`` from the actuators on it (``dofs[a]`` is actuator
    ``a``'s degree of freedom)."""
    drives = np.zeros((nv, 3))
    for actuator, k in zip(actuators, dofs, strict=True):
        g = actuator.gear
        drives[k, 0] += g * (actuator.gain * actuator.control(ctrl) + actuator.bias[0])
        drives[k, 1] += g * g * actuator.bias[1]
        drives[k, 2] += g * g * actuator.bias[2]
    return drives


def actuator_forces(actuators, dofs: list[int], q_rows: list[int], ctrl: np.ndarray, q, qd) -> np.ndarray:
    """Each actuator's force ``f`` along its length (not yet times its gear), at the state ``q``, ``qd``."""
    forces = np.zeros(len(actuators))
    for a, (actuator, k, row) in enumerate(zip(actuators, dofs, q_rows, strict=True)):
        length, speed = actuator.gear * q[row], actuator.gear * qd[k]
        forces[a] = actuator.gain * actuator.control(ctrl) + portable.dot(actuator.bias, (1.0, length, speed))
    return forces
