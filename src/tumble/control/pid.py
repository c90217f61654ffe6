"""A cascaded PID flight controller, as the flight stacks of small drones. Reached as ``tumble.control.CascadedPID``."""

from __future__ import annotations

import numpy as np

from .._validate import as_float
from .autopilot import Autopilot
from .se3 import _gains, _Integral, _reference_of, _vehicle

__all__ = ["CascadedPID"]


class CascadedPID:
    """A cascaded PID flight controller, as the flight stacks of small drones (PX4, the Crazyflie's): each loop
    commands the next, faster one.

        v_c = v_d + k_p,pos (x_d − x)                                   position → velocity [1/s]
        a_c = a_d + k_p,vel (v_c − v) + k_i,vel ∫(v_c − v) dt           velocity → acceleration [1/s, 1/s²]
        f, R_c from m (a_c − g) and ψ_d                                  (as :class:`SE3Controller`)
        Ω_c = −k_att e_R + Rᵀ R_c (0, 0, ψ̇_d)                            attitude → body rates [1/s]
        M   = J k_rate (Ω_c − Ω) + Ω × J Ω                              body rates → moments [1/s]

    The defaults give the SE(3) controller's stiffness (``k_p,vel k_p,pos`` = (6.4, 6.4, 15.3) s⁻², ``k_p,vel`` =
    (4, 4, 9) s⁻¹, and the attitude and rate loops of :class:`Autopilot`, the vehicle's attitude PD).
    ``update(t, reference)`` returns rotor speeds (4,) [rad/s].
    """

    def __init__(self, quad, kp_pos=(1.6, 1.6, 1.7), kp_vel=(4.0, 4.0, 9.0), ki_vel=0.0, kp_att=None,
                 kp_rate=None, integral_limit=3.0):  # fmt: skip
        self.quad = _vehicle(quad)
        self.kp_pos = _gains("kp_pos", kp_pos, 3)
        self.ki_vel = _gains("ki_vel", ki_vel, 3)
        self._loops = Autopilot(quad, kp_rate, kp_att, kp_vel)
        self.integral_limit = as_float("integral_limit", integral_limit, nonnegative=True)
        self._integral = _Integral(self.ki_vel, self.integral_limit)

    # The inner loops' gains are the autopilot's.
    kp_vel = property(lambda self: self._loops.kp_vel, doc="velocity gain [1/s] (3,)")
    kp_att = property(lambda self: self._loops.kp_att, doc="attitude gain [1/s]")
    kp_rate = property(lambda self: self._loops.kp_rate, doc="body-rate gain [1/s]")

    def reset(self) -> None:
        """Forget the integral of the velocity error."""
        self._integral.reset()

    def update(self, t: float, reference) -> np.ndarray:
        """Rotor speeds (4,) [rad/s] that steer the vehicle towards ``reference``."""
        t = as_float("t", t)
        (position, velocity, acceleration, _), yaw, yaw_rate = _reference_of(reference)
        body = self.quad.body
        velocity_error = velocity + self.kp_pos * (position - body.position) - body.velocity
        acceleration = acceleration + self._loops.kp_vel * velocity_error + self._integral.update(t, velocity_error)
        return self._loops._acceleration_to_speeds(acceleration, yaw, yaw_rate)
