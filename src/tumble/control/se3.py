"""The geometric SE(3) tracking controller of a :class:`~tumble.vehicles.Quadrotor`, and what the other flight
controllers share with it (the desired attitude and its error, gains, the integral, a reference's vectors).
Reached as ``tumble.control.*``.

Notation: the package's (``tumble.control``).
"""

from __future__ import annotations

import math

import numpy as np

from .. import portable
from .._validate import as_array, as_float
from . import kernels

__all__ = ["SE3Controller", "attitude_error", "bad_rotor_speeds", "desired_rotation"]


def desired_rotation(force, yaw: float) -> np.ndarray:
    """The rotation whose ``z`` axis is along ``force`` and whose ``x`` axis is the heading ``yaw`` projected on the
    plane normal to it (Lee et al. 2010, section IV; :func:`tumble.control.kernels.desired_axes`)."""
    return np.column_stack(kernels.desired_axes((float(force[0]), float(force[1]), float(force[2])), float(yaw)))


def attitude_error(rotation: np.ndarray, desired: np.ndarray) -> np.ndarray:
    """``e_R = ½ vee(R_dᵀ R − Rᵀ R_d)`` (Lee et al. 2010, eq. 10): for a small error, the rotation vector from the
    desired attitude to the present one, body frame."""
    axes = tuple(tuple(float(x) for x in desired[:, k]) for k in range(3))
    return np.array(kernels.attitude_error(tuple(float(x) for x in rotation.ravel()), *axes))


def _gains(name: str, value, size: int) -> np.ndarray:
    """A gain: one number for every axis, or ``size`` of them; each finite and >= 0."""
    if np.ndim(value) == 0:
        gains = np.full(size, as_float(name, value))
    else:
        gains = as_array(name, value, (size,), batch=False).copy()
    if (gains < 0).any():
        raise ValueError(f"{name} must be >= 0, got {gains.tolist()}")
    return gains


def _vehicle(quad):
    """``quad`` checked as a vehicle: its body, rotors, mixer, parameters and world (a Quadrotor's; by what it has,
    as control sits below tumble.vehicles, which imports it)."""
    if not all(hasattr(quad, part) for part in ("body", "rotors", "mixer", "params", "world")):
        raise TypeError(f"quad must be a tumble.vehicles.Quadrotor, got {quad!r}")
    return quad


def _attitude_gains(quad, kp_att, kd_att) -> tuple[float, float]:
    """``(k_R, k_Ω)``: those given, else the vehicle's."""
    kp = quad.params["kp_att"] if kp_att is None else as_float("kp_att", kp_att, nonnegative=True)
    kd = quad.params["kd_att"] if kd_att is None else as_float("kd_att", kd_att, nonnegative=True)
    return kp, kd


class _Integral:
    """``∫ e dt`` over a controller's calls (rectangle rule on the time between calls), each axis held so that
    ``|k_i ∫e| <= limit`` (anti-windup by clamping)."""

    def __init__(self, gain: np.ndarray, limit: float):
        self.gain, self.limit = gain, limit
        self._active = bool(gain.any())
        self.value = np.zeros(3)
        self._last_time: float | None = None

    def update(self, t: float, error: np.ndarray) -> np.ndarray:
        """``k_i ∫e`` including the interval that ends now, at ``t``."""
        if not self._active:
            return self.value
        if self._last_time is not None and t > self._last_time:
            self.value += error * (t - self._last_time)
            bound = np.divide(self.limit, self.gain, out=np.full(3, np.inf), where=self.gain > 0.0)
            np.clip(self.value, -bound, bound, out=self.value)
        self._last_time = t
        return self.gain * self.value

    def reset(self) -> None:
        self.value[:] = 0.0
        self._last_time = None


_REFERENCE_VECTORS = ("position", "velocity", "acceleration", "jerk")


def _reference_of(reference) -> tuple[np.ndarray, float, float]:
    """``(packed, yaw, yaw_rate)``: ``packed`` (4, 3) the reference's position, velocity, acceleration and jerk (those
    missing are zero; ``position`` is needed)."""
    if not hasattr(reference, "get") or "position" not in reference:
        raise TypeError(f"reference must be a mapping with at least 'position' (what a trajectory returns), got "
                        f"{reference!r}")  # fmt: skip
    packed = np.zeros((4, 3))
    for row, name in enumerate(_REFERENCE_VECTORS):
        value = reference.get(name)
        if value is not None:
            try:
                packed[row] = value
            except (TypeError, ValueError) as error:
                raise ValueError(f"reference[{name!r}] must be 3 numbers, got {value!r}") from error
    if not np.isfinite(packed).all():
        raise ValueError(f"reference must be finite, got {dict(reference)!r}")
    return packed, as_float("reference['yaw']", reference.get("yaw", 0.0)), \
        as_float("reference['yaw_rate']", reference.get("yaw_rate", 0.0))  # fmt: skip


class SE3Controller:
    """The geometric tracking controller of Lee, Leok & McClamroch (2010) for a quadrotor.

    ``update(t, reference)`` reads the vehicle's true state and returns rotor speeds (4,) [rad/s]:

        e_x = x − x_d,  e_v = v − v_d
        F   = m (−k_x e_x − k_v e_v − k_i ∫e_x dt + a_d − g)            (gains per axis, world frame)
        f   = F · R e3                                                  collective thrust [N]
        R_d = [b1d b2d b3d], b3d = F / |F|, heading ψ_d                 (:func:`desired_rotation`)
        e_R = ½ vee(R_dᵀ R − Rᵀ R_d),  e_Ω = Ω − Rᵀ R_d Ω_d
        M   = J (−k_R e_R − k_Ω e_Ω) + Ω × J Ω                          body moments [N m]

    By default ``Ω_d = (0, 0, ψ̇_d)``, as RotorPy's ``SE3Control``, the same law with the same gains. With
    ``feedforward`` the desired body rates follow the reference's jerk and yaw rate (Mellinger & Kumar, "Minimum
    snap trajectory generation and control for quadrotors", ICRA 2011, eq. 8): ``h = m (j − (b3d·j) b3d) / |F|``,
    ``Ω_d = (−h·b2d, h·b1d, ψ̇_d b3d·e3)``. On the Crazyflie at 100 Hz it flies the figure eight closer (3.4 cm
    RMS against 5.0) but the circle farther (4.5 cm against 1.2): its 72 ms motors lag the rates it asks for.

    Args:
        quad: the :class:`~tumble.vehicles.Quadrotor`.
        kp_pos: position gain ``k_x`` [1/s²] (one or three, per world axis); as RotorPy's defaults.
        kd_pos: velocity gain ``k_v`` [1/s].
        kp_att: attitude gain ``k_R`` [1/s²] (an angular acceleration per radian of error); by default the
            vehicle's ``params["kp_att"]``.
        kd_att: body-rate gain ``k_Ω`` [1/s]; by default ``params["kd_att"]``.
        ki_pos: integral gain ``k_i`` [1/s³] (0: none, as RotorPy's); removes the steady error of a constant load
            such as a steady wind.
        integral_limit: the largest acceleration the integral term may ask for on each axis [m/s²].
        feedforward: include the desired body rates from the jerk (see above); off by default.
    """

    def __init__(self, quad, kp_pos=(6.5, 6.5, 15.0), kd_pos=(4.0, 4.0, 9.0), kp_att=None, kd_att=None, ki_pos=0.0,
                 integral_limit=3.0, feedforward: bool = False):  # fmt: skip
        self.quad = _vehicle(quad)
        self.kp_pos, self.kd_pos, self.ki_pos = (
            _gains(n, g, 3) for n, g in (("kp_pos", kp_pos), ("kd_pos", kd_pos), ("ki_pos", ki_pos))
        )
        self.kp_att, self.kd_att = _attitude_gains(self.quad, kp_att, kd_att)
        self.feedforward = bool(feedforward)
        self.integral_limit = as_float("integral_limit", integral_limit, nonnegative=True)
        self._integral = _Integral(self.ki_pos, self.integral_limit)
        self._inv_inertia = portable.inverse(self.quad.params["inertia"])

    def reset(self) -> None:
        """Forget the integral of the position error."""
        self._integral.reset()

    def _integral_state(self) -> tuple[np.ndarray, float]:
        """``(∫e_x dt, the time of its last update or NaN)``, as the compiled flights carry it (``flight.native``)."""
        last = self._integral._last_time
        return self._integral.value.copy(), math.nan if last is None else last

    def _load_integral_state(self, value: np.ndarray, last_time: float) -> None:
        """Take the integral back from the compiled flights (:meth:`_integral_state`'s form)."""
        self._integral.value[:] = value
        self._integral._last_time = None if math.isnan(last_time) else float(last_time)

    def update(self, t: float, reference) -> np.ndarray:
        """Rotor speeds (4,) [rad/s] that steer the vehicle towards ``reference`` (a trajectory's ``traj(t)``)."""
        t = as_float("t", t)
        packed, yaw, yaw_rate = _reference_of(reference)
        quad, params, mixer = self.quad, self.quad.params, self.quad.mixer
        state, i = quad.world.state, quad.body.index
        integral = self._integral.update(t, state.body_pos[i] - packed[0])
        speeds = np.empty(4)
        kernels.se3_rotor_speeds(state.body_pos[i], state.body_linvel[i], state.body_quat[i], state.body_angmom[i],
                                 self._inv_inertia, params["inertia"], params["mass"], quad.world.gravity, packed, yaw,
                                 yaw_rate, self.kp_pos, self.kd_pos, integral, self.kp_att, self.kd_att,
                                 self.feedforward, mixer.inverse, params["k_thrust"], *mixer.squared_limits,
                                 speeds)  # fmt: skip
        return speeds


def bad_rotor_speeds(controller, speeds: np.ndarray, t: float) -> ValueError:
    """What a flight's controller returned that cannot be commanded."""
    return ValueError(f"{type(controller).__name__}.update returned {speeds.tolist()!r} at t = {t:.6g} s, not four "
                      "finite rotor speeds")  # fmt: skip
