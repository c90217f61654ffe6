"""Actuators that drive an articulation's hinges, slides and tendons from a control vector ``ctrl``.

An actuator pulls along its length ``l = gear · L`` (``L`` the joint's coordinate or the tendon's length) with the
force

    f = gain · c + bias₀ + bias₁ · l + bias₂ · l̇,    c = ctrl clipped to ctrl_range,

clipped to ``force_range``, and pushes along ``L`` with ``gear · f``: MuJoCo's general actuator with a joint or
tendon transmission, fixed gain, affine bias and no activation dynamics. Its shortcuts are special cases: a motor is
``gain = 1, bias = 0`` (the force ``gear · ctrl``), a position servo ``gain = kp, bias = (0, -kp, -kv)`` (it pulls
``l`` towards ``ctrl``), a velocity servo ``gain = kv, bias = (0, 0, -kv)``. The controls are held between calls,
as joint forces are; the kernels evaluate each actuator at every stage of a step (``constraints.applied_forces``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Actuator", "actuator_forces"]


@dataclass(frozen=True, eq=False)
class Actuator:
    """One actuator (read-only); see the module docstring for its force.

    Attributes:
        index: its entry in ``ctrl``; name: optional label; link: the link whose (Revolute or Prismatic) joint it
            drives, or ``None``; tendon: the tendon it pulls instead, or ``None``; gear: the transmission ratio;
            gain, bias (3,): the force law; ctrl_range: ``(low, high)`` the control is clipped to, or ``None``;
            force_range: ``(low, high)`` the force is clipped to, or ``None``.
    """

    index: int
    name: str | None
    link: int | None
    gear: float
    gain: float
    bias: np.ndarray
    ctrl_range: tuple[float, float] | None
    tendon: int | None = None
    force_range: tuple[float, float] | None = None

    def control(self, ctrl: np.ndarray) -> float:
        """This actuator's control from the whole vector, clipped to its range."""
        value = float(ctrl[self.index])
        return value if self.ctrl_range is None else min(max(value, self.ctrl_range[0]), self.ctrl_range[1])


def actuator_forces(actuators, lengths, speeds, ctrl: np.ndarray) -> np.ndarray:
    """Each actuator's force ``f`` along its length (not yet times its gear), with ``lengths``/``speeds`` the ``L``
    and ``L̇`` of each actuator's joint or tendon."""
    forces = np.zeros(len(actuators))
    for a, (actuator, length, speed) in enumerate(zip(actuators, lengths, speeds, strict=True)):
        bias = actuator.bias
        force = (actuator.gain * actuator.control(ctrl) + bias[0] + bias[1] * (actuator.gear * length)
                 + bias[2] * (actuator.gear * speed))  # fmt: skip
        if actuator.force_range is not None:
            force = min(max(force, actuator.force_range[0]), actuator.force_range[1])
        forces[a] = force
    return forces
