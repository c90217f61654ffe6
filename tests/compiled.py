"""Whether this run compiles tumble's kernels. ``make test`` runs tests/unit a second time with ``NUMBA_DISABLE_JIT=1``,
the kernels as plain Python (how coverage reaches their lines), tens to hundreds of times slower: a test whose kernels
the shorter tests also run there is marked :func:`compiled_only`."""

from __future__ import annotations

import os

import pytest

COMPILED = os.environ.get("NUMBA_DISABLE_JIT", "0") != "1"


def compiled_only(why: str) -> pytest.MarkDecorator:
    """Skip the test under ``NUMBA_DISABLE_JIT=1``; ``why``: what it would take there, or why it means nothing."""
    return pytest.mark.skipif(not COMPILED, reason=f"compiled only: {why}")
