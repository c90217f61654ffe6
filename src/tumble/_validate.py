"""Checks at the public boundary: every message names the argument and the bad value.

Kernels never validate (they cannot raise); everything a user hands to tumble passes through one of
these functions first. Nothing is silently clipped: a value is accepted as given or refused.

This module sits below everything it checks and imports nothing of tumble: a check that needs a tumble type
lives beside that type (``rotation.as_rotation``, ``handles.as_body``).
"""

from __future__ import annotations

import math
import numbers

import numpy as np

__all__ = [
    "as_float",
    "as_array",
    "as_vector3",
    "as_quaternion",
    "mass_or_density",
]


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
    if not np.isfinite(array).all():
        raise ValueError(f"{name} must be finite, got {_show(array)}")
    return array


def as_vector3(name: str, value) -> np.ndarray:
    """One finite 3-vector (a fresh float64 array of shape (3,))."""
    return as_array(name, value, (3,), batch=False).copy()


def as_unit_vector3(name: str, value, *, tiny: float = 1e-12) -> np.ndarray:
    """One finite 3-vector longer than ``tiny``, returned normalised (an axis, a normal, a direction)."""
    vector = as_vector3(name, value)
    norm = float(np.linalg.norm(vector))
    if not norm > tiny:
        raise ValueError(f"{name} must be a non-zero vector, got {vector.tolist()}")
    return vector / norm


def as_quaternion(name: str, value) -> np.ndarray:
    """One finite, non-zero quaternion ``[w, x, y, z]``, returned normalised to unit length."""
    q = as_array(name, value, (4,), batch=False)
    with np.errstate(over="ignore"):
        norm = float(np.linalg.norm(q))
    if math.isinf(norm):  # finite components whose squares overflow: scale them down first
        q = q / np.max(np.abs(q))
        norm = float(np.linalg.norm(q))
    if norm < 1e-12:
        raise ValueError(f"{name} must be a non-zero quaternion [w, x, y, z], got {_show(q)}")
    return q / norm


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
