"""Arithmetic whose bits do not depend on the machine: what builds a model or feeds a step goes through these.

NumPy gives ``@``, ``dot``, ``einsum`` (with BLAS) and the ``linalg`` functions to the BLAS/LAPACK library it ships,
which picks a kernel by CPU (OpenBLAS's Haswell, SkylakeX, Sandybridge, … sum in different orders and fuse
multiply-adds differently), and it picks SIMD variants of ``sin``, ``tanh``, ``arctan2``, … by CPU too
(``numpy.lib.introspect.opt_func_info``: AVX-512 machines run Intel's SVML for ``arccos``, ``arctan2``,
``power``). Each changes the last bit of a result from one machine to the next, and a pile turns one last bit into
another outcome (issue 44).

Here every product and sum is written out in a fixed order with the IEEE operations ``+ - * /`` and ``sqrt``,
which round exactly on every machine; NumPy's elementwise ufuncs and its reductions (``np.sum``) are used only for
those. Transcendental functions are :mod:`tumble.elementary`'s, which the kernels call too (the C library's differ
between its FMA and plain builds). Matrices and vectors lie on the last axes of arrays of any batch shape; most
are 3x3 and 3-vectors.
"""

from __future__ import annotations

import math

import numpy as np

from . import elementary
from ._jit import kernel

__all__ = [
    "arccos", "arcsin", "arctan", "arctan2", "cos", "det", "dot", "eigh", "inverse", "matmul", "matvec", "norm",
    "outer_sum", "sandwich", "sin", "solve", "weighted_sum",
]  # fmt: skip


# --- products and sums -------------------------------------------------------------------------------------------


def dot(a, b) -> np.ndarray:
    """``a · b`` over the last axis (length 3), summed left to right."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def norm(v) -> np.ndarray:
    """``|v|`` over the last axis (any length)."""
    v = np.asarray(v, np.float64)
    return np.sqrt(np.sum(v * v, axis=-1))


def matvec(m, v) -> np.ndarray:
    """``M v`` for (..., k, n) ``m`` and (..., n) ``v``."""
    m, v = np.asarray(m, np.float64), np.asarray(v, np.float64)
    return np.sum(m * v[..., None, :], axis=-1)


def matmul(a, b) -> np.ndarray:
    """``A B`` for (..., k, n) ``a`` and (..., n, m) ``b``."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return np.sum(a[..., :, :, None] * b[..., None, :, :], axis=-2)


def sandwich(r, m) -> np.ndarray:
    """``R M Rᵀ``, symmetrised (a tensor turned into another frame, course deck 002)."""
    r = np.asarray(r, np.float64)
    out = matmul(matmul(r, m), np.swapaxes(r, -1, -2))
    return 0.5 * (out + np.swapaxes(out, -1, -2))


def weighted_sum(w, rows) -> np.ndarray:
    """``Σ_i w_i rows_i`` over the first axis: (n,) weights and (n, ...) rows."""
    w, rows = np.asarray(w, np.float64), np.asarray(rows, np.float64)
    return np.sum(w.reshape(w.shape + (1,) * (rows.ndim - 1)) * rows, axis=0)


def outer_sum(w, a, b) -> np.ndarray:
    """``Σ_i w_i a_i b_iᵀ``: (n,) weights and (n, 3) ``a``, ``b``; a (3, 3) matrix."""
    w, a, b = (np.asarray(x, np.float64) for x in (w, a, b))
    return np.sum((w[:, None] * a)[:, :, None] * b[:, None, :], axis=0)


def det(m) -> np.ndarray:
    """``det M`` of (..., 3, 3) ``m`` by the rule of Sarrus, expanded along the first row."""
    m = np.asarray(m, np.float64)
    return (
        m[..., 0, 0] * (m[..., 1, 1] * m[..., 2, 2] - m[..., 1, 2] * m[..., 2, 1])
        - m[..., 0, 1] * (m[..., 1, 0] * m[..., 2, 2] - m[..., 1, 2] * m[..., 2, 0])
        + m[..., 0, 2] * (m[..., 1, 0] * m[..., 2, 1] - m[..., 1, 1] * m[..., 2, 0])
    )


def solve(a, b) -> np.ndarray:
    """``x`` of ``A x = b`` for one (n, n) ``a`` and an (n,) or (n, k) ``b``: Gaussian elimination with partial
    pivoting (Golub & Van Loan, Matrix Computations, 4th ed., Alg. 3.4.1), rows combined in a fixed order.
    ValueError for a singular matrix."""
    a = np.array(a, np.float64)
    x = np.array(b, np.float64)
    n = a.shape[0]
    if a.shape != (n, n) or x.shape[0] != n:
        raise ValueError(f"solve needs a square matrix and a right side of as many rows, got {a.shape} and {x.shape}")
    for k in range(n):
        pivot = k + int(np.argmax(np.abs(a[k:, k])))
        if not a[pivot, k] != 0.0:
            raise ValueError(f"cannot solve with a singular {n}x{n} matrix (no pivot in column {k})")
        a[[k, pivot]], x[[k, pivot]] = a[[pivot, k]], x[[pivot, k]]
        for i in range(k + 1, n):
            factor = a[i, k] / a[k, k]
            a[i, k:] -= factor * a[k, k:]
            x[i] -= factor * x[k]
    for k in range(n - 1, -1, -1):
        # Back substitution, the known unknowns subtracted one at a time.
        for j in range(k + 1, n):
            x[k] -= a[k, j] * x[j]
        x[k] /= a[k, k]
    return x


def inverse(m) -> np.ndarray:
    """``M⁻¹``: for (..., 3, 3) ``m`` the adjugate (transposed cofactors) over the determinant (Cramer's rule); for
    one (n, n) matrix of another size by :func:`solve`. ValueError for a singular matrix."""
    m = np.asarray(m, np.float64)
    if m.shape[-2:] != (3, 3):
        return solve(m, np.eye(m.shape[0]))
    # Scaled by a power of two (exact) to entries near 1, so that the cofactors of a tensor of 1e-300 or 1e300 kg m²
    # neither underflow nor overflow: (s M)⁻¹ = M⁻¹ / s.
    with np.errstate(divide="ignore"):
        _, exponent = np.frexp(np.max(np.abs(m), axis=(-2, -1)))
    m = np.ldexp(m, -exponent[..., None, None])
    cof = np.empty(m.shape)
    for i in range(3):
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            # The cyclic minor carries the cofactor's sign (-1)^(i+j) for a 3x3 matrix.
            cof[..., j, i] = m[..., i1, j1] * m[..., i2, j2] - m[..., i1, j2] * m[..., i2, j1]
    d = m[..., 0, 0] * cof[..., 0, 0] + m[..., 0, 1] * cof[..., 1, 0] + m[..., 0, 2] * cof[..., 2, 0]
    if np.any(d == 0.0) or not np.all(np.isfinite(d)):
        raise ValueError(f"cannot invert a singular 3x3 matrix (determinant {np.min(np.abs(d))!r})")
    return np.ldexp(cof / d[..., None, None], -exponent[..., None, None])


# --- principal axes ----------------------------------------------------------------------------------------------

# Sweeps of the cyclic Jacobi method before giving up: it converges quadratically, in 4 to 6 sweeps for a 3x3.
_JACOBI_SWEEPS = 50


def eigh(m) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (ascending) and orthonormal eigenvectors (columns) of a symmetric (n, n) matrix, 3x3 above all.

    The cyclic Jacobi method of course deck 000 ("Rotational Inertia Diagonalization"): plane rotations, each
    zeroing one off-diagonal entry, until none is left above round-off; the rotation of each step as in Press et
    al., Numerical Recipes (3rd ed.), §11.1, eqs. 11.1.8-11.1.18, which keeps its angle at most π/4.
    """
    m = np.asarray(m, np.float64)
    n = m.shape[0]
    if np.count_nonzero(m - np.diag(np.diag(m))) == 0:  # diagonal already (a primitive's inertia): sort it
        order = np.argsort(np.diag(m), kind="stable")
        return np.diag(m)[order], np.eye(n)[:, order]
    a = m.tolist()
    v = [[1.0 if i == j else 0.0 for j in range(n)] for i in range(n)]
    pairs = [(p, q) for p in range(n) for q in range(p + 1, n)]
    for _ in range(_JACOBI_SWEEPS):
        if all(a[p][q] == 0.0 for p, q in pairs):
            break
        for p, q in pairs:
            apq = a[p][q]
            if apq == 0.0:
                continue
            # Below round-off against both diagonal entries: the rotation would change nothing; drop it.
            if abs(apq) <= 1e-18 * abs(a[p][p]) and abs(apq) <= 1e-18 * abs(a[q][q]):
                a[p][q] = a[q][p] = 0.0
                continue
            theta = (a[q][q] - a[p][p]) / (2.0 * apq)
            if abs(theta) > 1e150:  # θ² would overflow: t ≈ 1 / (2θ)
                t = 0.5 / theta
            else:
                t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                t = -t if theta < 0.0 else t
            c = 1.0 / math.sqrt(t * t + 1.0)
            s = t * c
            tau = s / (1.0 + c)
            a[p][p] -= t * apq
            a[q][q] += t * apq
            a[p][q] = a[q][p] = 0.0
            for r in range(n):
                if r != p and r != q:
                    arp, arq = a[r][p], a[r][q]
                    a[r][p] = a[p][r] = arp - s * (arq + tau * arp)
                    a[r][q] = a[q][r] = arq + s * (arp - tau * arq)
            for k in range(n):
                vkp, vkq = v[k][p], v[k][q]
                v[k][p] = vkp - s * (vkq + tau * vkp)
                v[k][q] = vkq + s * (vkp - tau * vkq)
    order = sorted(range(n), key=lambda k: a[k][k])
    values = np.array([a[k][k] for k in order])
    vectors = np.array([[v[i][k] for k in order] for i in range(n)]).reshape(n, n)
    return values, vectors


# --- transcendental functions ------------------------------------------------------------------------------------

_SIN, _COS, _ARCTAN2, _ARCCOS, _ARCSIN, _ARCTAN = range(6)


@kernel
def _elementwise(function, y, x, out):
    """``out[i] = f(y[i])`` (``atan2(y[i], x[i])``) for :mod:`tumble.elementary`'s ``f``: one loop for all six.

    ``sin`` and ``cos`` of arguments all in ``elementary.SIN_COS_RANGE`` take ``elementary.sin_cos``, the same bits
    without branches, in a loop that vectorises (3-4 times faster: the observations of the environments)."""
    if function == _SIN or function == _COS:
        near = True
        for i in range(out.shape[0]):
            near = near and abs(y[i]) <= elementary.SIN_COS_RANGE  # false for inf and NaN
        if near:
            for i in range(out.shape[0]):
                sine, cosine = elementary.sin_cos(y[i])
                out[i] = sine if function == _SIN else cosine
            return
    for i in range(out.shape[0]):
        if function == _SIN:
            out[i] = elementary.sin(y[i])
        elif function == _COS:
            out[i] = elementary.cos(y[i])
        elif function == _ARCTAN2:
            out[i] = elementary.atan2(y[i], x[i])
        elif function == _ARCCOS:
            out[i] = elementary.acos(y[i])
        elif function == _ARCSIN:
            out[i] = elementary.asin(y[i])
        else:
            out[i] = elementary.atan(y[i])


def _apply(function: int, y, x=None):
    y = np.asarray(y, dtype=np.float64, order="C")  # 0-d stays 0-d (ascontiguousarray makes it 1-d)
    if x is None:
        x = y  # not read
    else:
        y, x = (np.asarray(a, order="C") for a in np.broadcast_arrays(y, np.asarray(x, np.float64)))
    out = np.empty(y.shape)
    _elementwise(function, y.reshape(-1), x.reshape(-1), out.reshape(-1))
    return out if out.ndim else out[()]


def sin(x):
    """``sin x`` elementwise (a float64 array, or a NumPy float for a scalar)."""
    return _apply(_SIN, x)


def cos(x):
    return _apply(_COS, x)


def arctan2(y, x):
    return _apply(_ARCTAN2, y, x)


def arccos(x):
    """``acos x`` elementwise; NaN outside [-1, 1]."""
    return _apply(_ARCCOS, x)


def arcsin(x):
    return _apply(_ARCSIN, x)


def arctan(x):
    return _apply(_ARCTAN, x)
