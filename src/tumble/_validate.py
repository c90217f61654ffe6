"""Checks at the public boundary: every message names the argument and the bad value.

Kernels never validate (they cannot raise); everything a user hands to tumble passes through one of
these functions first. Nothing is silently clipped: a value is accepted as given or refused.

This module sits below everything it checks and imports nothing of tumble: a check that needs a tumble type
lives beside that type (``rotation.as_rotation``, ``handles.as_body``).
"""

from __future__ import annotations

import math
import numbers
import os

import numpy as np

__all__ = [
    "MAX_COUNT",
    "all_finite",
    "MAX_STEPS",
    "MIN_STEP",
    "as_count",
    "as_rate",
    "MAX_RATE",
    "finite_result",
    "listed",
    "as_filter",
    "as_material",
    "as_step",
    "step_count",
    "require_memory",
    "scaled_down",
    "vector_norm",
    "as_float",
    "as_array",
    "as_vector3",
    "as_quaternion",
    "mass_or_density",
]


MAX_STEPS = 10**15  # steps in one call or run: more would not end, and their count must stay an exact integer
MAX_COUNT = 2**31 - 1  # a count the kernels hold as an index (record_every, chunk frames)
# [s] The smallest step: the solvers divide by the substep, whose reciprocal must stay finite with room to spare
# (a subnormal step overflows it); no physical time scale comes near.
MIN_STEP = 1e-300


def _show(value) -> str:
    text = repr(value.tolist() if isinstance(value, np.ndarray) else value)
    return text if len(text) <= 80 else text[:77] + "..."


def as_float(name: str, value, *, positive: bool = False, nonnegative: bool = False) -> float:
    """A finite real scalar; ``positive``/``nonnegative`` add a sign check."""
    if (
        type(value) is float
        and math.isfinite(value)
        and (value > 0.0 or not positive)
        and (value >= 0.0 or not nonnegative)
    ):
        return value  # the common case, kept cheap for World.step
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        if not (isinstance(value, np.ndarray) and value.shape == () and np.issubdtype(value.dtype, np.number)):
            raise TypeError(f"{name} must be a real number, got {_show(value)} ({type(value).__name__})")
    x = float(value)
    if not np.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x!r}")
    if positive and not x > 0.0:
        raise ValueError(f"{name} must be > 0, got {x!r}")
    if nonnegative and not x >= 0.0:
        raise ValueError(f"{name} must be >= 0, got {x!r}")
    return x


def as_count(name: str, value, maximum: int = MAX_COUNT) -> int:
    """An integer from 1 to ``maximum`` (a Python or NumPy integer; not a bool, not a float)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or not 1 <= value <= maximum:
        raise ValueError(f"{name} must be an integer from 1 to {maximum}, got {_show(value)}")
    return int(value)


def as_step(name: str, dt, time: float) -> float:
    """A step size ``dt`` [s] that advances ``time``: finite, at least :data:`MIN_STEP`, and not lost in the
    rounding of ``time + dt``."""
    dt = as_float(name, dt, positive=True)
    if dt < MIN_STEP or not time + dt > time:
        raise ValueError(
            f"{name}={dt!r} is too small to advance time from t = {time!r} s (a step must be at least {MIN_STEP:g} s "
            "and change t)"
        )
    return dt


def physical_memory() -> int | None:
    """This machine's memory [bytes], or None where the system does not say."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, OSError, ValueError):
        return None


def _bytes(count: float) -> str:
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB"):
        if count < 1024:
            return f"{count:.3g} {unit}"
        count /= 1024
    return f"{count:.3g} PiB"


def require_memory(need: float, what: str, instead: str) -> None:
    """Refuse to allocate ``need`` bytes for ``what`` beyond this machine's memory (an allocation that would
    fail, or swap for hours): the ValueError says how much it would take and what to do ``instead``."""
    have = physical_memory()
    if have is not None and need > have:
        raise ValueError(
            f"{what} would take {_bytes(need)}, more than this machine's {_bytes(have)} of memory: {instead}"
        )


def step_count(duration: float, dt: float) -> int:
    """``round(duration / dt)`` for a positive ``duration`` and step ``dt``: at least one step, at most
    :data:`MAX_STEPS`."""
    steps = duration / dt
    if not steps <= MAX_STEPS:
        raise ValueError(
            f"duration={duration!r} at dt={dt!r} is {steps:g} steps; one call takes at most {MAX_STEPS:.0e} "
            "(split the run, or take a larger dt)"
        )
    if round(steps) < 1:
        raise ValueError(f"duration={duration!r} is shorter than one step of dt={dt!r}")
    return round(steps)


def as_filter(name: str, bits) -> int:
    """A collision filter: an integer of 32 bits."""
    if isinstance(bits, (bool, np.bool_)) or not isinstance(bits, (int, np.integer)):
        raise TypeError(f"{name} must be an integer of 32 bits (0 to 0xFFFFFFFF), got {bits!r} ({type(bits).__name__})")
    if not 0 <= int(bits) <= 0xFFFFFFFF:
        raise ValueError(f"{name} must be an integer of 32 bits (0 to 0xFFFFFFFF), got {int(bits)}")
    return int(bits)


def as_material(friction, restitution, rolling_resistance) -> tuple[float, float, float]:
    """``(friction, restitution, rolling_resistance)``: all >= 0, restitution at most 1."""
    friction = as_float("friction", friction, nonnegative=True)
    restitution = as_float("restitution", restitution, nonnegative=True)
    if restitution > 1.0:
        raise ValueError(f"restitution must be in [0, 1], got {restitution!r}")
    return friction, restitution, as_float("rolling_resistance", rolling_resistance, nonnegative=True)


def listed(value) -> list | None:
    return None if value is None else np.asarray(value, dtype=float).tolist()


def finite_result(result: np.ndarray, name: str, given, what: str) -> np.ndarray:
    """``result``, computed from the argument ``name`` = ``given``, if finite; else a ValueError that says ``what``
    ``given`` gave (the caller writes nothing: a refused call changes nothing)."""
    with np.errstate(over="ignore", invalid="ignore"):
        if np.isfinite(result).all():
            return result
    raise ValueError(f"{name}={listed(given)} {what} {listed(result)}, which overflows (non-finite)")


def as_array(name: str, value, trailing_shape: tuple[int, ...], *, batch: bool = True) -> np.ndarray:
    """A finite float64 array whose last dimensions are ``trailing_shape`` (leading batch dims allowed)."""
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{name} must be an array of numbers with shape (..., {trailing_shape}), got {_show(value)}")
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise TypeError(f"{name} must be an array of numbers, got {_show(value)}") from error
    k = len(trailing_shape)
    shape_ok = array.shape[array.ndim - k :] == trailing_shape if array.ndim >= k else False
    if not shape_ok or (not batch and array.ndim != k):
        expected = ("(..., " if batch else "(") + ", ".join(map(str, trailing_shape)) + ")"
        raise ValueError(f"{name} must have shape {expected}, got shape {array.shape}: {_show(array)}")
    if not all_finite(array):
        raise ValueError(f"{name} must be finite, got {_show(array)}")
    return array


_SMALL = 64  # elements: up to here a Python sum of the list is cheaper than NumPy's ufunc and reduction


def all_finite(array: np.ndarray) -> bool:
    """Whether every element of a float array is finite. A small array is summed first (0.1–0.3 µs where
    ``np.isfinite(a).all()`` costs 0.9 µs, before every step of a controller that passes ``tau``): a NaN or an
    infinity makes the sum non-finite, so a finite sum proves them all finite; a sum that overflowed is checked
    element by element."""
    if array.size <= _SMALL and math.isfinite(sum(array.ravel().tolist())):
        return True
    return bool(np.isfinite(array).all())


# Vectors whose norm lies in this range have squares well inside float range (so do their components).
_SQUARES_SAFE = (1e-150, 1e150)


def scaled_down(array: np.ndarray) -> tuple[np.ndarray, np.ndarray | float, np.ndarray]:
    """``(array / s, s, |array / s|)`` with one scale ``s`` per vector of the last axis: 1 where the squares of the
    vector's components stay in float range, its largest magnitude where they would overflow or underflow, so that
    a norm or a direction computed from ``array / s`` stays exact to round-off (the scaling of LAPACK's ``dnrm2``,
    applied only where it is needed). When no vector needs it, ``array`` itself comes back with the float
    ``s = 1.0``."""
    with np.errstate(over="ignore", under="ignore"):
        norm = np.linalg.norm(array, axis=-1)
    risky = ~((norm > _SQUARES_SAFE[0]) & (norm < _SQUARES_SAFE[1]))
    if not np.any(risky):
        return array, 1.0, norm
    largest = np.max(np.abs(array), axis=-1)
    scale = np.where(risky & (largest > 0.0), largest, 1.0)
    scaled = array / scale[..., None]
    return scaled, scale, np.linalg.norm(scaled, axis=-1)


def vector_norm(array: np.ndarray) -> np.ndarray:
    """``|v|`` over the last axis without overflow or underflow in the squares (inf only where ``|v|`` itself
    exceeds the largest float)."""
    _, scale, norm = scaled_down(array)
    with np.errstate(over="ignore"):
        return norm * scale


def as_vector3(name: str, value) -> np.ndarray:
    """One finite 3-vector (a fresh float64 array of shape (3,))."""
    return as_array(name, value, (3,), batch=False).copy()


MAX_RATE = 1e300  # [rad/s] ω is stored as L = I ω and read back as I⁻¹ L: near the largest float it rounds past


def as_rate(name: str, value) -> np.ndarray:
    """An angular velocity [rad/s]: a finite 3-vector with components of at most :data:`MAX_RATE`."""
    vector = as_vector3(name, value)
    if not np.abs(vector).max() <= MAX_RATE:
        raise ValueError(f"{name} must have components of at most {MAX_RATE:g} rad/s, got {vector.tolist()}")
    return vector


def as_unit_vector3(name: str, value, *, tiny: float = 1e-12) -> np.ndarray:
    """One finite 3-vector longer than ``tiny``, returned normalised (an axis, a normal, a direction)."""
    vector = as_vector3(name, value)
    scaled, scale, norm = scaled_down(vector)
    if not norm * scale > tiny:
        raise ValueError(f"{name} must be a non-zero vector, got {vector.tolist()}")
    return scaled / norm


def as_quaternion(name: str, value) -> np.ndarray:
    """One finite, non-zero quaternion ``[w, x, y, z]``, returned normalised to unit length."""
    q = as_array(name, value, (4,), batch=False)
    scaled, scale, norm = scaled_down(q)
    if norm * scale < 1e-12:
        raise ValueError(f"{name} must be a non-zero quaternion [w, x, y, z], got {_show(q)}")
    return scaled / norm


def mass_or_density(mass, density) -> tuple[str, float]:
    """Exactly one of ``mass=`` or ``density=``, positive and finite: returns ``("mass"|"density", value)``."""
    if (mass is None) == (density is None):
        raise TypeError(f"give exactly one of mass= or density=, got mass={_show(mass)} and density={_show(density)}")
    if mass is not None:
        return "mass", as_float("mass", mass, positive=True)
    return "density", as_float("density", density, positive=True)


def as_seed(value) -> int | None:
    """A seed for ``numpy.random.default_rng``: an integer >= 0, or ``None`` for a fresh one."""
    if value is not None and (isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0):
        raise ValueError(f"seed must be an integer >= 0 or None, got {value!r}")
    return None if value is None else int(value)
