"""Small dense SPD systems inside kernels: the Cholesky factor in place and its solve (Golub & Van Loan, *Matrix
Computations*, 4th ed., Alg. 4.2.2). The world's joint solver factors the blocks of its joints' rows with them, the
articulation's dual solver the ``nv × nv`` matrix of its pivoting (``articulation/dual_solver.py``). No BLAS, so the
same bits on every machine."""

from __future__ import annotations

import math

from ._jit import inline

__all__ = ["cholesky", "cholesky_solve"]


@inline
def cholesky(k, n):
    """Factorise the SPD ``K`` (n × n, its lower triangle read) in place into its lower Cholesky factor; False if a
    pivot is not above 1e-12 of its diagonal entry (singular to rounding)."""
    for c in range(n):
        s = k[c, c]
        for t in range(c):
            s -= k[c, t] * k[c, t]
        if s <= 1e-12 * max(k[c, c], 1e-300):
            return False
        k[c, c] = math.sqrt(s)
        for r in range(c + 1, n):
            s = k[r, c]
            for t in range(c):
                s -= k[r, t] * k[c, t]
            k[r, c] = s / k[c, c]
    return True


@inline
def cholesky_solve(k, x, n):
    """Solve ``L Lᵀ y = x`` in place (``x`` becomes ``y``) with the factor from :func:`cholesky`."""
    for r in range(n):
        s = x[r]
        for t in range(r):
            s -= k[r, t] * x[t]
        x[r] = s / k[r, r]
    for r in range(n - 1, -1, -1):
        s = x[r]
        for t in range(r + 1, n):
            s -= k[t, r] * x[t]
        x[r] = s / k[r, r]
