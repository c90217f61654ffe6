"""Reference trajectories for flying vehicles, as flat outputs (reached as ``tumble.control.*``).

A quadrotor is differentially flat in its position and yaw (Mellinger & Kumar, "Minimum snap trajectory generation
and control for quadrotors", ICRA 2011): the position's derivatives up to the snap and the yaw's rate fix the
thrust, the attitude, the body rates and their derivatives. Each reference here is callable, ``traj(t)``
returning a dict with ``position``, ``velocity``, ``acceleration``, ``jerk``, ``snap`` ((3,) arrays, world
frame, SI) and ``yaw`` [rad], ``yaw_rate`` [rad/s].
"""

from __future__ import annotations

import math
import warnings
from typing import NamedTuple

import numpy as np

from .. import portable
from .._validate import as_array, as_float, as_vector3
from .kernels import CIRCLE, HOVER, LISSAJOUS, MINIMUM_SNAP, reference_derivatives

__all__ = ["Circle", "Hover", "Lissajous", "MinimumSnap"]

_DERIVATIVES = ("position", "velocity", "acceleration", "jerk", "snap")


class ReferenceSpec(NamedTuple):
    """A reference as the compiled evaluator takes it (``flight.kernels.reference_derivatives``)."""

    kind: int
    params: np.ndarray  # (11,)
    knot_count: int
    knots: np.ndarray
    coefficients: np.ndarray  # (pieces, 8, 3)


_NO_KNOTS, _NO_PIECES = np.zeros(1), np.zeros((1, 8, 3))


def _spec(kind: int, values: tuple, knots=_NO_KNOTS, coefficients=_NO_PIECES) -> ReferenceSpec:
    """``values``: pairs of a place in ``params`` (an index or a slice) and what goes there."""
    params = np.zeros(11)
    for where, value in values:
        params[where] = value
    return ReferenceSpec(kind, params, len(knots), np.asarray(knots, float), np.asarray(coefficients, float))


class _Reference:
    """A reference evaluated by ``flight.kernels.reference_derivatives`` from its :class:`ReferenceSpec`. Immutable
    once built (the spec is derived from the attributes): build a new one to change it."""

    spec: ReferenceSpec
    yaw: float

    def _freeze(self) -> None:
        for value in (*vars(self).values(), *self.spec):
            if isinstance(value, np.ndarray):
                value.flags.writeable = False
        object.__setattr__(self, "_frozen", True)

    def __setattr__(self, name, value) -> None:
        if getattr(self, "_frozen", False):
            raise AttributeError(f"{type(self).__name__} is immutable; cannot set {name!r} (build a new one instead)")
        object.__setattr__(self, name, value)

    def __call__(self, t) -> dict:
        derivatives = np.empty((5, 3))
        reference_derivatives(*self.spec, _time(t), derivatives)
        return _flat_output(derivatives, self.yaw)


def _flat_output(derivatives, yaw: float = 0.0, yaw_rate: float = 0.0) -> dict:
    """The reference as a dict: the rows of ``derivatives`` (5, 3), position to snap, and the yaw and its rate."""
    rows = np.asarray(derivatives, dtype=float)
    out = dict(zip(_DERIVATIVES, rows, strict=True))
    out.update(yaw=float(yaw), yaw_rate=float(yaw_rate))
    return out


def _time(t) -> float:
    return as_float("t", t)


class Hover(_Reference):
    """Stay at ``position`` (3,) [m] facing ``yaw`` [rad]."""

    def __init__(self, position, yaw=0.0):
        self.position = as_vector3("position", position)
        self.yaw = as_float("yaw", yaw)
        self.spec = _spec(HOVER, ((slice(0, 3), self.position), (10, self.yaw)))
        self._freeze()

    def __repr__(self) -> str:
        return f"Hover({self.position.tolist()}, yaw={self.yaw!r})"


class Circle(_Reference):
    """A horizontal circle about ``center`` (3,) [m] of ``radius`` [m], flown anticlockwise seen from above at
    ``frequency`` [Hz] (laps per second), from ``center + (radius, 0, 0)`` at ``t = 0``, facing ``yaw`` [rad]:
    ``x = c + r (cos 2πft, sin 2πft, 0)``."""

    def __init__(self, center, radius, frequency, yaw=0.0):
        self.center = as_vector3("center", center)
        self.radius = as_float("radius", radius, positive=True)
        self.frequency = as_float("frequency", frequency, nonnegative=True)
        self.yaw = as_float("yaw", yaw)
        self.spec = _spec(CIRCLE, ((slice(0, 3), self.center), (3, self.radius), (4, self.frequency), (10, self.yaw)))
        self._freeze()

    def __repr__(self) -> str:
        return f"Circle({self.center.tolist()}, radius={self.radius!r}, frequency={self.frequency!r})"


class Lissajous(_Reference):
    """A horizontal Lissajous figure about ``center``: ``x = c + (A sin(a t + δ), B sin(b t), 0)`` with ``A``, ``B``
    [m] and the angular frequencies ``a``, ``b`` [rad/s] (``A = 1, B = 0.5, a = 1, b = 2``: a figure eight, as
    RotorPy's), facing ``yaw`` [rad]."""

    def __init__(self, A, B, a, b, delta=0.0, center=(0.0, 0.0, 0.0), yaw=0.0):
        self.A = as_float("A", A, nonnegative=True)
        self.B = as_float("B", B, nonnegative=True)
        self.a = as_float("a", a)
        self.b = as_float("b", b)
        self.delta = as_float("delta", delta)
        self.center = as_vector3("center", center)
        self.yaw = as_float("yaw", yaw)
        shape = (self.A, self.B, self.a, self.b, self.delta)
        self.spec = _spec(LISSAJOUS, ((slice(0, 3), self.center), (slice(3, 8), shape), (10, self.yaw)))
        self._freeze()

    def __repr__(self) -> str:
        return f"Lissajous(A={self.A!r}, B={self.B!r}, a={self.a!r}, b={self.b!r}, delta={self.delta!r})"


_DEGREE = 7  # 7th-order pieces: the Euler-Lagrange equation of ∫ snap² dt is p⁽⁸⁾ = 0
_COEFFICIENTS = _DEGREE + 1


def _basis(derivative: int, s: float) -> np.ndarray:
    """``dⁿ/dsⁿ`` of ``(1, s, s², ..., s⁷)`` at ``s``."""
    row = np.zeros(_COEFFICIENTS)
    for k in range(derivative, _COEFFICIENTS):
        row[k] = math.factorial(k) / math.factorial(k - derivative) * s ** (k - derivative)
    return row


class MinimumSnap(_Reference):
    """The path through ``waypoints`` (n, 3) [m] that minimises the integral of the squared snap, from rest to rest:
    one 7th-order polynomial per segment, passing each waypoint at its time, continuous up to the 6th derivative at
    each interior waypoint (the optimum's conditions; Mellinger & Kumar, ICRA 2011; Richter, Bry & Roy, ISRR 2013),
    velocity, acceleration and jerk zero at both ends. The coefficients come from one linear solve (SciPy).

    Args:
        waypoints: (n, 3), n >= 2 points.
        times: the time [s] at each waypoint (n,), increasing; by default from 0, each segment taking its length
            over ``average_speed``.
        average_speed: [m/s], used when ``times`` is not given.
        yaw: the heading [rad] held throughout.

    Before the first time the reference waits at the first waypoint, after the last at the last.
    """

    def __init__(self, waypoints, times=None, average_speed=1.0, yaw=0.0):
        points = as_array("waypoints", waypoints, (3,), batch=True)
        if points.ndim != 2 or points.shape[0] < 2:
            raise ValueError(f"waypoints must have shape (n, 3) with n >= 2, got shape {points.shape}")
        if times is None:
            speed = as_float("average_speed", average_speed, positive=True)
            lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
            if not (lengths > 0.0).all():
                k = int(np.argmin(lengths))
                raise ValueError(f"waypoints {k} and {k + 1} are the same point {points[k].tolist()}: give times= "
                                 f"to stay there a while")  # fmt: skip
            times = np.concatenate([[0.0], np.cumsum(lengths / speed)])
        else:
            count = len(times) if isinstance(times, (list, tuple, np.ndarray)) else None
            if count != points.shape[0]:
                raise ValueError(f"times must give one time per waypoint: {points.shape[0]} waypoints, got "
                                 f"times={times!r}")  # fmt: skip
            times = as_array("times", times, (count,), batch=False)
            if not (np.diff(times) > 0.0).all():
                raise ValueError(f"times must increase strictly, got {times.tolist()}")
        self.waypoints, self.times = points, times
        self.yaw = as_float("yaw", yaw)
        self._coefficients = self._solve()  # (segments, 8, 3) in the normalised time s = (t - t_i) / T_i
        ends = ((slice(0, 3), points[0]), (slice(3, 6), points[-1]), (10, self.yaw))
        self.spec = _spec(MINIMUM_SNAP, ends, times, self._coefficients)
        self._freeze()

    def _solve(self) -> np.ndarray:
        from scipy.linalg import LinAlgError, LinAlgWarning, solve

        segments = self.waypoints.shape[0] - 1
        durations = np.diff(self.times)
        size = _COEFFICIENTS * segments
        matrix, rhs = np.zeros((size, size)), np.zeros((size, 3))
        row = 0

        def constrain(segment: int, derivative: int, s: float, scale: float = 1.0, value=0.0):
            nonlocal row
            columns = slice(_COEFFICIENTS * segment, _COEFFICIENTS * (segment + 1))
            matrix[row, columns] += scale * _basis(derivative, s) / durations[segment] ** derivative
            rhs[row] = value

        for i in range(segments):  # each piece from its waypoint to the next
            constrain(i, 0, 0.0, value=self.waypoints[i])
            row += 1
            constrain(i, 0, 1.0, value=self.waypoints[i + 1])
            row += 1
        for derivative in (1, 2, 3):  # at rest at both ends
            constrain(0, derivative, 0.0)
            row += 1
            constrain(segments - 1, derivative, 1.0)
            row += 1
        for i in range(segments - 1):  # continuous up to the 6th derivative at the interior waypoints
            for derivative in range(1, 7):
                constrain(i, derivative, 1.0)
                constrain(i + 1, derivative, 0.0, scale=-1.0)
                row += 1
        with warnings.catch_warnings():
            warnings.simplefilter("error", LinAlgWarning)
            try:
                solve(matrix, rhs)  # only for LAPACK's condition check: its values depend on the BLAS kernel
            except (LinAlgWarning, LinAlgError) as error:
                raise ValueError(
                    f"times give segments of {durations.min():.3g} to {durations.max():.3g} s, too unequal to solve "
                    "for (the continuity of the 6th derivative scales with the duration to the 6th power): space "
                    "the times more evenly"
                ) from error
        # The coefficients feed the flight: the same bits on every machine (portable.solve's fixed order).
        return portable.solve(matrix, rhs).reshape(segments, _COEFFICIENTS, 3)

    @property
    def duration(self) -> float:
        """The time of the last waypoint [s]."""
        return float(self.times[-1])

    def __repr__(self) -> str:
        return f"MinimumSnap({len(self.waypoints)} waypoints over {self.duration:g} s)"
