"""The map between a quadrotor's rotor speeds and the wrench they make, and its allocation under saturation."""

from __future__ import annotations

import numpy as np

from .. import portable
from .._validate import as_array, as_float, as_vector3
from ..control.kernels import allocate_speeds

__all__ = ["Mixer"]


class Mixer:
    """The map between the rotors' squared speeds ``ω²`` (4,) and the wrench ``(T, Mx, My, Mz)`` they make: the
    collective thrust along the body's ``z`` [N] and the moments about the centre of mass, body frame [N m].

    ``matrix`` has columns ``k_thrust (1, p_y, −p_x, 0) + spin k_moment (0, 0, 0, 1)`` (the moment of a force
    ``F ẑ`` at ``p`` is ``p × F ẑ = F (p_y, −p_x, 0)``); ``inverse`` is its inverse."""

    def __init__(self, positions: np.ndarray, spins: np.ndarray, k_thrust: float, k_moment: float,
                 speed_min: float, speed_max: float):  # fmt: skip
        matrix = np.vstack([np.ones(4), positions[:, 1], -positions[:, 0], spins * (k_moment / k_thrust)])
        self.matrix = k_thrust * matrix
        self.inverse = portable.inverse(self.matrix)
        for array in (self.matrix, self.inverse):
            array.flags.writeable = False
        self.k_thrust = k_thrust
        self.squared_limits = (speed_min**2, speed_max**2)  # the bounds of each ω²

    def wrench(self, rotor_speeds) -> np.ndarray:
        """``(T, Mx, My, Mz)`` of the rotors at ``rotor_speeds`` (4,) [rad/s]."""
        speeds = as_array("rotor_speeds", rotor_speeds, (4,), batch=False)
        return portable.matvec(self.matrix, speeds**2)

    def allocate(self, thrust, moments) -> np.ndarray:
        """Rotor speeds (4,) [rad/s] that make the collective ``thrust`` [N] and body ``moments`` (3,) [N m].

        Within the motors' limits this is ``√(inverse @ (T, M))``. Beyond them the demand is cut in order of
        priority: the thrust first (clipped to what four rotors between their limits can give), then roll and pitch
        together (scaled down, keeping the direction of the tilting moment), then yaw; what is kept is met
        exactly."""
        speeds = np.empty(4)
        allocate_speeds(self.inverse, self.k_thrust, *self.squared_limits, as_float("thrust", thrust),
                        as_vector3("moments", moments), speeds)  # fmt: skip
        return speeds
