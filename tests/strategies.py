"""Hypothesis strategies shared by the property tests: unit quaternions, 3-vectors, rotation vectors.

Each strategy yields fresh float64 NumPy arrays. Import them as ``from strategies import unit_quaternions``
(``tests/`` is on ``sys.path`` because ``tests/conftest.py`` lives there).
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st

__all__ = ["unit_quaternions", "vectors3", "unit_vectors3", "rotvecs"]


def _floats(low: float, high: float, **kwargs) -> st.SearchStrategy[float]:
    return st.floats(low, high, allow_nan=False, allow_infinity=False, **kwargs)


def vectors3(max_abs: float = 10.0) -> st.SearchStrategy[np.ndarray]:
    """(3,) float64 vectors with every component in ``[-max_abs, max_abs]`` (zero included)."""
    component = _floats(-max_abs, max_abs)
    return st.tuples(component, component, component).map(lambda v: np.array(v, dtype=np.float64))


def unit_vectors3() -> st.SearchStrategy[np.ndarray]:
    """(3,) unit vectors: normalised non-degenerate draws of :func:`vectors3` (axes, normals)."""
    return vectors3(1.0).filter(lambda v: np.linalg.norm(v) > 1e-3).map(lambda v: v / np.linalg.norm(v))


def unit_quaternions() -> st.SearchStrategy[np.ndarray]:
    """(4,) unit quaternions ``[w, x, y, z]``, either sign of ``w``.

    Components are drawn in ``[-1, 1]`` and normalised; draws shorter than 0.1 are rejected so the
    direction is well defined. Hypothesis likes 0 and ±1, so the identity, ``-identity`` and the
    half-turns ``(0, 1, 0, 0)``... come up often, which is what the edge cases need.
    """
    component = _floats(-1.0, 1.0)
    return (
        st.tuples(component, component, component, component)
        .map(lambda q: np.array(q, dtype=np.float64))
        .filter(lambda q: np.linalg.norm(q) > 0.1)
        .map(lambda q: q / np.linalg.norm(q))
    )


def rotvecs(max_angle: float = math.pi) -> st.SearchStrategy[np.ndarray]:
    """(3,) rotation vectors ``θ ê`` with ``0 <= θ < max_angle`` (strictly below, so ``θ < π`` by default)."""
    angle = _floats(0.0, max_angle, exclude_max=True)
    return st.tuples(unit_vectors3(), angle).map(lambda pair: pair[0] * pair[1])
