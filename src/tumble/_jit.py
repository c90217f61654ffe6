"""The only module that imports Numba.

Kernels are compiled once and cached on disk (``cache=True``) so that the second process starts warm.
``fastmath`` stays off: results must be bit-for-bit reproducible and IEEE-exact enough for the
conservation tests. Setting ``NUMBA_DISABLE_JIT=1`` turns every kernel back into plain Python, which
is how CI runs the unit tests once (pdb and coverage reach the kernels that way).
"""

from __future__ import annotations

import numba

__all__ = ["kernel", "inline", "prange"]

prange = numba.prange


def kernel(function=None, *, parallel: bool = False):
    """Compile a hot loop: ``njit(cache=True, fastmath=False, nogil=True)``."""

    def wrap(f):
        return numba.njit(cache=True, fastmath=False, nogil=True, parallel=parallel)(f)

    return wrap(function) if function is not None else wrap


def inline(function):
    """A small helper that Numba inlines into the kernels that call it (``math3d``)."""
    return numba.njit(cache=True, fastmath=False, inline="always")(function)
