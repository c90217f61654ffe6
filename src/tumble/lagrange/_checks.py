"""Checks at the boundary of ``tumble.lagrange``: every message names the argument and the bad value.

Symbolic inputs are SymPy objects; the time symbol is the one of ``sympy.physics.mechanics``
(``dynamicsymbols._t``), so coordinates are made with ``dynamicsymbols('theta')``.
"""

from __future__ import annotations

import numbers
from collections.abc import Iterable, Mapping

import numpy as np
import sympy as sp
from sympy.core.function import AppliedUndef
from sympy.physics.mechanics import dynamicsymbols

TIME = dynamicsymbols._t


def show(value) -> str:
    """A short repr for error messages."""
    text = repr(value.tolist() if isinstance(value, np.ndarray) else value)
    return text if len(text) <= 100 else text[:97] + "..."


def _describe(value) -> str:
    return f"{show(value)} ({type(value).__name__})"


def is_coordinate(value) -> bool:
    """A function of time alone, such as ``dynamicsymbols('theta')``."""
    return isinstance(value, AppliedUndef) and value.args == (TIME,)


def as_coordinates(value) -> tuple[sp.Expr, ...]:
    """One coordinate or a sequence of distinct ones, each a SymPy function of the time ``t``."""
    if isinstance(value, sp.Basic):
        items = [value]
    elif isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        raise TypeError(
            "coordinates must be a sequence of functions of time such as dynamicsymbols('theta'), "
            f"got {_describe(value)}"
        )
    else:
        items = list(value)
    if not items:
        raise ValueError("coordinates must name at least one generalised coordinate, got an empty sequence")
    for i, item in enumerate(items):
        if is_coordinate(item):
            continue
        if isinstance(item, AppliedUndef):
            raise ValueError(
                f"coordinates[{i}] must be a function of the time symbol t alone (use dynamicsymbols), got {item}"
            )
        hint = " (a Symbol is constant in time)" if isinstance(item, sp.Symbol) else ""
        raise TypeError(
            f"coordinates[{i}] must be a function of time such as dynamicsymbols('theta'){hint}, got {_describe(item)}"
        )
    seen: dict[sp.Expr, int] = {}
    for i, item in enumerate(items):
        if item in seen:
            raise ValueError(f"coordinates must be distinct, but coordinates[{seen[item]}] and [{i}] are both {item}")
        seen[item] = i
    return tuple(items)


def as_expression(name: str, value) -> sp.Expr:
    """A scalar SymPy expression (Python numbers are refused: a symbolic input is asked for)."""
    if isinstance(value, sp.Eq):
        raise TypeError(f"{name} must be a SymPy expression, got the equation {value} (write lhs - rhs)")
    if not isinstance(value, sp.Expr) or isinstance(value, sp.MatrixBase):
        raise TypeError(f"{name} must be a scalar SymPy expression, got {_describe(value)}")
    return value


def as_scalar(name: str, value) -> sp.Expr:
    """A scalar given as a SymPy expression or a real Python/NumPy number (converted to SymPy)."""
    if isinstance(value, sp.Expr) and not isinstance(value, sp.MatrixBase):
        return value
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.number)):
        raise TypeError(f"{name} must be a real number or a SymPy expression, got {_describe(value)}")
    if not np.isfinite(float(value)):
        raise ValueError(f"{name} must be finite, got {show(value)}")
    return exact_number(float(value))


def exact_number(x: float, scale: float = 1.0) -> sp.Expr:
    """A float as SymPy: an Integer when it is within ``1e-12 * scale`` of a whole number, else a Float.

    Rotation matrices made from quaternions carry ~1e-16 round-off; snapping their exact zeros and ones
    keeps the symbolic kinematics free of ``1.0e-17*sin(q)`` terms. ``scale`` is the size of the numbers
    the value comes with (an inertia tensor's largest entry), so a tiny body's moments are not zeroed.
    """
    nearest = round(x)
    if abs(x - nearest) <= 1e-12 * scale:
        return sp.Integer(int(nearest))
    return sp.Float(x)


def as_vector(name: str, value, size: int = 3) -> sp.Matrix:
    """A column of ``size`` scalars (SymPy expressions or numbers) as a SymPy Matrix."""
    if isinstance(value, sp.MatrixBase):
        entries = list(value)
        if value.shape not in ((size, 1), (1, size)):
            raise ValueError(f"{name} must have {size} entries, got a matrix of shape {value.shape}")
    elif isinstance(value, (str, bytes, sp.Basic)) or not isinstance(value, Iterable):
        raise TypeError(f"{name} must be a sequence of {size} expressions or numbers, got {_describe(value)}")
    else:
        entries = list(np.asarray(value, dtype=object).ravel()) if isinstance(value, np.ndarray) else list(value)
        if len(entries) != size:
            raise ValueError(f"{name} must have {size} entries, got {len(entries)}: {show(value)}")
    return sp.Matrix([as_scalar(f"{name}[{i}]", entry) for i, entry in enumerate(entries)])


def as_matrix3(name: str, value) -> sp.Matrix:
    """A 3x3 matrix of SymPy expressions or numbers."""
    if isinstance(value, (str, bytes)) or not isinstance(value, (Iterable, sp.MatrixBase)):
        raise TypeError(f"{name} must be a 3x3 matrix of expressions, got {_describe(value)}")
    matrix = sp.Matrix(value) if not isinstance(value, np.ndarray) else sp.Matrix(value.tolist())
    if matrix.shape != (3, 3):
        raise ValueError(f"{name} must be a 3x3 matrix, got shape {matrix.shape}: {show(value)}")
    return matrix.applyfunc(lambda entry: as_scalar(name, entry))


def check_no_accelerations(name: str, expression, coordinates) -> None:
    """Refuse q̈ in a force or constraint: only the Lagrangian's derivatives may bring accelerations."""
    accelerations = [q.diff(TIME, 2) for q in coordinates]
    found = [a for a in accelerations if expression.has(a)]
    if found:
        raise ValueError(f"{name} must not depend on accelerations, got {expression} (contains {found[0]})")


def check_holonomic(name: str, expression, coordinates) -> None:
    """A holonomic constraint ``f(q, t) = 0``: no velocities or accelerations, and at least one coordinate."""
    derivatives = [d for d in expression.atoms(sp.Derivative)]
    if derivatives:
        raise ValueError(
            f"{name} must be holonomic, f(q, t) = 0, without velocities; got {expression} "
            f"(contains {derivatives[0]}); nonholonomic constraints are not supported"
        )
    if not any(expression.has(q) for q in coordinates):
        raise ValueError(f"{name} must involve at least one coordinate, got {expression}")


def as_parameter_values(name: str, value) -> dict:
    """A mapping ``{Symbol or name: real number}``; returns ``{key: float}`` with keys kept as given."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise TypeError(f"{name} must be a mapping {{symbol or name: number}}, got {_describe(value)}")
    out = {}
    for key, number in value.items():
        if not isinstance(key, (sp.Symbol, str)):
            raise TypeError(f"{name} keys must be SymPy Symbols or their names, got {_describe(key)}")
        out[key] = as_real(f"{name}[{key}]", number)
    return out


def as_real(name: str, value) -> float:
    """A finite real number, Python, NumPy or a SymPy number."""
    if isinstance(value, sp.Basic):
        if not value.is_number or not value.is_real:
            raise TypeError(f"{name} must be a real number, got {_describe(value)}")
        value = float(value)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.number)):
        raise TypeError(f"{name} must be a real number, got {_describe(value)}")
    x = float(value)
    if not np.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x!r}")
    return x


def as_state(name: str, value, size: int) -> np.ndarray:
    """A finite float64 vector of ``size`` entries (a scalar is accepted when size is 1)."""
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{name} must be {size} numbers, got {_describe(value)}")
    try:
        array = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError) as error:
        raise TypeError(f"{name} must be {size} numbers, got {_describe(value)}") from error
    if array.shape != (size,):
        raise ValueError(f"{name} must have {size} entries (one per coordinate), got {array.size}: {show(value)}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, got {show(array)}")
    return array
