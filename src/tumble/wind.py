"""Wind: the air's velocity, which rotors and drag see (``world.wind = Constant(v)``, ``Sinusoid``, ``Dryden``).

The wind is uniform in space and held over each step at its value for that step (``velocity(t, dt)`` with ``t``
the step's start, counted as in ``tumble.control``): ``Sinusoid`` at the step's middle, ``Dryden`` advanced by one
exact step of its shaping filter.

Dryden turbulence (MIL-F-8785C; the form of MIL-HDBK-1797): gusts along the mean wind (``u``), across it in the
horizontal (``v``) and vertical (``w``), each a stationary Gaussian process of standard deviation ``σ`` and
correlation time ``T = L / V``, with ``L`` the length scale and ``V`` the mean wind's speed (the turbulence is frozen
in the air and carried past at ``V``). Their autocorrelations are ``σ² e^(−τ/T)`` (u) and ``σ² (1 − τ/(2T))
e^(−τ/T)`` (v, w), the spectra ``σ² (2T/π) / (1 + (Tω)²)`` and ``σ² (T/π) (1 + 3 (Tω)²) / (1 + (Tω)²)²``. Each is the
output of a linear filter driven by white noise (first order for u, a double pole with a zero for v and w); the
filter's state is advanced by its exact transition ``Φ = e^(A dt)`` and the exact noise covariance ``P − Φ P Φᵀ``
(``P`` the stationary covariance), so that the gusts have the requested intensity and correlation at every ``dt``.
"""

from __future__ import annotations

import math

import numpy as np

from . import elementary, portable
from ._validate import as_float, as_seed, as_vector3

__all__ = ["Constant", "Dryden", "Sinusoid", "Wind"]


class Wind:
    """A wind model: ``velocity(t, dt)`` is the air's velocity (world frame) [m/s] during the step at ``t``."""

    def velocity(self, t: float, dt: float) -> np.ndarray:
        raise NotImplementedError


class Constant(Wind):
    """A steady wind ``v`` [m/s]."""

    def __init__(self, v):
        self.v = as_vector3("v", v)

    def velocity(self, t: float, dt: float) -> np.ndarray:
        return self.v.copy()

    def __repr__(self) -> str:
        return f"Constant({self.v.tolist()})"


class Sinusoid(Wind):
    """``mean + amplitude sin(2π frequency t)`` [m/s] (vectors ``mean`` and ``amplitude``, ``frequency`` [Hz]),
    taken at each step's middle."""

    def __init__(self, mean, amplitude, frequency):
        self.mean = as_vector3("mean", mean)
        self.amplitude = as_vector3("amplitude", amplitude)
        self.frequency = as_float("frequency", frequency, nonnegative=True)

    def velocity(self, t: float, dt: float) -> np.ndarray:
        return self.mean + self.amplitude * elementary.sin(2.0 * math.pi * self.frequency * (t + 0.5 * dt))

    def __repr__(self) -> str:
        return f"Sinusoid({self.mean.tolist()}, {self.amplitude.tolist()}, {self.frequency!r})"


def _three(name: str, value) -> np.ndarray:
    """A positive scalar for all three gust components, or one each (u, v, w)."""
    values = np.broadcast_to(np.asarray(value, dtype=float), (3,)) if np.ndim(value) == 0 else np.asarray(value, float)
    if values.shape != (3,) or not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise ValueError(f"{name} must be a number > 0 or three of them (u, v, w), got {value!r}")
    return values.copy()


class Dryden(Wind):
    """Dryden turbulence about a mean wind (see the module docstring).

    Args:
        mean: (3,) the mean wind [m/s], world frame; its speed carries the turbulence (must be > 0).
        sigma: gust standard deviation [m/s], one for all or (σu, σv, σw).
        length_scale: [m], one for all or (Lu, Lv, Lw).
        seed: for the white noise (``numpy.random.default_rng``).

    Attributes:
        gust: (3,) the last gust (u, v, w) [m/s], about the mean.
    """

    def __init__(self, mean, sigma, length_scale, seed=None):
        self.mean = as_vector3("mean", mean)
        speed = float(portable.norm(self.mean))
        if not speed > 0.0:
            raise ValueError(
                f"mean must be a non-zero wind (its speed carries the turbulence), got {self.mean.tolist()}"
            )
        self.sigma = _three("sigma", sigma)
        self.length_scale = _three("length_scale", length_scale)
        self.seed = as_seed(seed)
        self.correlation_time = self.length_scale / speed
        # The wind frame: u along the mean wind, w as near world up as can be, v = w × u.
        u = self.mean / speed
        up = np.array([0.0, 0.0, 1.0]) if abs(u[2]) < 0.999 else np.array([1.0, 0.0, 0.0])
        w = up - portable.dot(up, u) * u
        w /= portable.norm(w)
        self.axes = np.stack([u, np.cross(w, u), w], axis=1)  # columns u, v, w in the world frame
        # The three filters side by side: one state x (1 + 2 + 2), gust = C x.
        filters = [_shaping_filter(k == 0, self.sigma[k], self.correlation_time[k]) for k in range(3)]
        self._c, self._p = np.zeros((3, _SIZE)), np.zeros((_SIZE, _SIZE))
        for k, (c, p) in enumerate(filters):
            self._c[k, _BLOCKS[k]], self._p[_BLOCKS[k], _BLOCKS[k]] = c, p
        self._rng = np.random.default_rng(seed)
        self._state = self._sample(self._p)  # stationary from the start
        self._transitions: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self.gust = portable.matvec(self._c, self._state)

    def _sample(self, covariance: np.ndarray) -> np.ndarray:
        return portable.matvec(_root(covariance), self._rng.standard_normal(covariance.shape[0]))

    def _transition(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """``Φ = e^(A dt)`` and a square root of the exact noise covariance ``P − Φ P Φᵀ`` over ``dt``."""
        if dt not in self._transitions:
            phi = np.zeros((_SIZE, _SIZE))
            for k in range(3):
                phi[_BLOCKS[k], _BLOCKS[k]] = _filter_transition(k == 0, self.correlation_time[k], dt)
            noise = self._p - portable.matmul(portable.matmul(phi, self._p), phi.T)
            self._transitions[dt] = phi, _root(noise)
        return self._transitions[dt]

    def velocity(self, t: float, dt: float) -> np.ndarray:
        """Advance the gusts by one step of ``dt`` and return the mean wind plus them."""
        phi, root = self._transition(as_float("dt", dt, positive=True))
        self._state = portable.matvec(phi, self._state) + portable.matvec(
            root, self._rng.standard_normal(root.shape[1])
        )
        self.gust = portable.matvec(self._c, self._state)
        return self.mean + portable.matvec(self.axes, self.gust)

    def __repr__(self) -> str:
        return f"Dryden({self.mean.tolist()}, {self.sigma.tolist()}, {self.length_scale.tolist()}, seed={self.seed})"


# The three filters side by side in one state x (1 + 2 + 2), gust = C x: the rows of each.
_BLOCKS = (slice(0, 1), slice(1, 3), slice(3, 5))
_SIZE = 5


def _shaping_filter(longitudinal: bool, sigma: float, t: float) -> tuple[np.ndarray, np.ndarray]:
    """``(c, P)``: output row and stationary state covariance of a filter whose output has the Dryden autocorrelation
    of standard deviation ``sigma`` and time ``t`` (unit white noise into the last state).

    ``P`` solves the Lyapunov equation ``A P + P Aᵀ + b bᵀ = 0`` in closed form: ``T/2`` for ``ẋ = −x/T + ξ``; for
    ``ẍ + 2ω ẋ + ω² x = ξ`` (``ω = 1/T``) the diagonal ``(1/(4ω³), 1/(4ω))``, the variances of a critically damped
    oscillator driven by unit white noise (e.g. Gardiner, Stochastic Methods, §3.8.4)."""
    if longitudinal:  # ẋ = −x/T + ξ, u = c x
        c, p = np.array([1.0]), np.array([[0.5 * t]])
    else:  # (1 + √3 T s) / (1 + T s)²: a double pole at −1/T and a zero at −1/(√3 T)
        c, p = np.array([1.0, math.sqrt(3.0) * t]), np.diag([0.25 * t**3, 0.25 * t])
    c = c * sigma / math.sqrt(float(np.sum(c * portable.matvec(p, c))))  # cᵀ P c
    return c, p


def _filter_transition(longitudinal: bool, t: float, dt: float) -> np.ndarray:
    """``Φ = e^(A dt)`` of a shaping filter in closed form: ``e^(−dt/T)``, and for the double pole ``A = −ω I + N``
    with ``N² = 0``, ``e^(−ω dt) (I + N dt)``."""
    decay = elementary.exp(-dt / t)
    if longitudinal:
        return np.array([[decay]])
    w = 1.0 / t
    return decay * np.array([[1.0 + w * dt, dt], [-w * w * dt, 1.0 - w * dt]])


def _root(covariance: np.ndarray) -> np.ndarray:
    """``S`` with ``S Sᵀ = covariance`` for a symmetric positive semi-definite matrix (round-off clipped)."""
    values, vectors = portable.eigh(0.5 * (covariance + covariance.T))
    return vectors * np.sqrt(np.clip(values, 0.0, None))


def as_wind(value) -> Wind | None:
    """``None`` (no wind), a :class:`Wind`, or a 3-vector for a :class:`Constant` wind."""
    if value is None or isinstance(value, Wind):
        return value
    try:
        return Constant(value)
    except (TypeError, ValueError):
        raise TypeError(
            f"wind must be None, a 3-vector or a tumble.wind model (Constant, Sinusoid, Dryden), got {value!r}"
        ) from None
