"""The inner loops of a quadrotor's flight stack: thrust and moments, body rates, attitude and velocity commands
(``quad.autopilot``). Reached as ``tumble.control.Autopilot``."""

from __future__ import annotations

import numpy as np

from .. import portable
from .._validate import as_float, as_quaternion, as_vector3
from ..rotation import quat_to_matrix
from .se3 import _attitude_gains, _gains, _vehicle, attitude_error, desired_rotation

__all__ = ["Autopilot"]


class Autopilot:
    """The inner loops of a flight stack for one quadrotor: the command levels below trajectory tracking, each
    held by loops that run before every step of the world until the next command (``quad.autopilot``).

    - ``thrust_moments(thrust, moments)``: collective thrust [N] and body moments [N m], through the mixer;
    - ``thrust_rates(thrust, rates)``: body rates [rad/s] held by ``M = J k_rate (Ω_c − Ω) + Ω × J Ω``;
    - ``thrust_attitude(thrust, orientation)``: an attitude held by the rate loop on ``Ω_c = −k_att e_R``;
    - ``velocity(velocity, yaw=0)``: a world velocity [m/s] held by ``a = k_vel (v_c − v)``, the thrust and attitude
      that give it (as the SE(3) controller), and the loops above.

    ``quad.command_rotor_speeds`` ends the held command. Gains: ``kp_rate`` [1/s], ``kp_att`` [1/s], ``kp_vel``
    [1/s], attributes that may be changed; by default the rate and attitude loops together are the vehicle's
    attitude PD (``k_rate = kd_att``, ``k_att = kp_att / kd_att``, from ``quad.params``).
    """

    def __init__(self, quad, kp_rate=None, kp_att=None, kp_vel=(4.0, 4.0, 9.0)):
        self.quad = _vehicle(quad)
        pd_kp, pd_kd = _attitude_gains(self.quad, None, None)
        self.kp_rate = pd_kd if kp_rate is None else as_float("kp_rate", kp_rate, nonnegative=True)
        self.kp_att = pd_kp / pd_kd if kp_att is None else as_float("kp_att", kp_att, nonnegative=True)
        self.kp_vel = _gains("kp_vel", kp_vel, 3)
        self._hold = None  # the held command: a function of no argument that commands the rotors
        self._controller = None

    # The loops, innermost first; each returns rotor speeds (4,).
    def _rates_to_speeds(self, thrust: float, rates_commanded: np.ndarray) -> np.ndarray:
        inertia = self.quad.params["inertia"]
        rates = self.quad.body.angular_velocity_body
        moments = portable.matvec(inertia, self.kp_rate * (rates_commanded - rates)) + np.cross(
            rates, portable.matvec(inertia, rates)
        )
        return self.quad.mixer.allocate(thrust, moments)

    def _attitude_to_speeds(self, thrust: float, desired: np.ndarray, rates_feedforward=(0.0, 0.0, 0.0)):
        rotation = self.quad.body.rotation
        rates = -self.kp_att * attitude_error(rotation, desired) + portable.matvec(
            portable.matmul(rotation.T, desired), np.asarray(rates_feedforward, np.float64)
        )
        return self._rates_to_speeds(thrust, rates)

    def _acceleration_to_speeds(self, acceleration: np.ndarray, yaw: float, yaw_rate: float = 0.0):
        """The thrust along the body's z and the attitude that give the world ``acceleration`` against gravity."""
        force = self.quad.params["mass"] * (acceleration - self.quad.world.gravity)
        rotation = self.quad.body.rotation
        desired = desired_rotation(force, yaw)
        return self._attitude_to_speeds(float(portable.dot(force, rotation[:, 2])), desired, (0.0, 0.0, yaw_rate))

    # The command levels.
    def thrust_moments(self, thrust, moments) -> None:
        """Command the collective thrust [N] and body moments (3,) [N m] (no loop: held as rotor speeds)."""
        speeds = self.quad.mixer.allocate(thrust, moments)
        self.quad.command_rotor_speeds(speeds)

    def thrust_rates(self, thrust, rates) -> None:
        """Command the collective thrust [N] and the body rates (3,) [rad/s], held by the rate loop."""
        thrust, rates = as_float("thrust", thrust), as_vector3("rates", rates)
        self._start(lambda: self._rates_to_speeds(thrust, rates))

    def thrust_attitude(self, thrust, orientation) -> None:
        """Command the collective thrust [N] and the attitude (a quaternion w, x, y, z), held by the attitude loop."""
        thrust = as_float("thrust", thrust)
        desired = quat_to_matrix(as_quaternion("orientation", orientation))
        self._start(lambda: self._attitude_to_speeds(thrust, desired))

    def velocity(self, velocity, yaw=0.0) -> None:
        """Command the world velocity (3,) [m/s] and the heading ``yaw`` [rad], held by the velocity loop."""
        velocity, yaw = as_vector3("velocity", velocity), as_float("yaw", yaw)
        self._start(lambda: self._acceleration_to_speeds(self.kp_vel * (velocity - self.quad.body.velocity), yaw))

    def _start(self, hold) -> None:
        self._hold = hold
        self.quad._command(hold())
        if self._controller is None:
            self._controller = self.quad.world.add_controller(self._run, name=f"autopilot of {self.quad!r}")

    def _run(self, world, t) -> None:
        self.quad._command(self._hold())

    @property
    def active(self) -> bool:
        """Whether a command is being held by the loops."""
        return self._controller is not None

    def stop(self) -> None:
        """Stop holding the command (the rotors keep their last commanded speeds)."""
        if self._controller is not None:
            self._controller.remove()
            self._controller = self._hold = None
