"""The only module that imports Numba.

Kernels are compiled once and cached on disk (``cache=True``) so that the second process starts warm.
``fastmath`` stays off: results must be bit-for-bit reproducible and IEEE-exact enough for the
conservation tests. Setting ``NUMBA_DISABLE_JIT=1`` turns every kernel back into plain Python, which
is how CI runs the unit tests once (pdb and coverage reach the kernels that way).
"""

from __future__ import annotations

import functools
import hashlib
from pathlib import Path

import numba
from numba.core import caching

__all__ = ["kernel", "inline", "prange"]

prange = numba.prange
_PACKAGE_DIR = Path(__file__).resolve().parent


# Subpackages whose kernels nothing outside them calls: an edit there invalidates their own kernels only.
# Everything else (top-level modules, geometry/, dynamics/) is the core that every kernel may embed.
_LEAF_PACKAGES = ("articulation", "flight", "lagrange")


def _leaf_of(path: Path) -> str | None:
    parts = path.relative_to(_PACKAGE_DIR).parts
    return parts[0] if len(parts) > 1 and parts[0] in _LEAF_PACKAGES else None


# Modules without compiled code whose constants kernels freeze at compile time (shape and integrator codes).
_CONSTANT_MODULES = ("shapes.py", "params.py", "geometry/manifold.py", "geometry/packing.py")


def _compiles(path: Path) -> bool:
    """Whether a module's code or constants can end up inside a kernel: it defines compiled code, or it is one of
    :data:`_CONSTANT_MODULES`. The facade, scenes and handles never do, so editing them keeps the cache."""
    relative = path.relative_to(_PACKAGE_DIR).as_posix()
    return relative in _CONSTANT_MODULES or "_jit import" in path.read_text(encoding="utf-8")


@functools.cache
def _package_stamp(leaf: str | None = None) -> str:
    """One stamp for the core's compiled sources (paths, sizes, modification times), plus those of ``leaf``."""
    digest = hashlib.sha256()
    for path in sorted(_PACKAGE_DIR.rglob("*.py")):
        if _leaf_of(path) not in (None, leaf) or not _compiles(path):
            continue
        stat = path.stat()
        digest.update(f"{path.relative_to(_PACKAGE_DIR)}:{stat.st_size}:{stat.st_mtime_ns};".encode())
    return digest.hexdigest()


class _PackageStamp:
    """Numba's on-disk cache, invalidated when any core tumble source changes (a mixin for Numba's locators).

    Numba stamps a cached kernel with its own file only, but a kernel embeds the code of the helpers it calls
    from other files: after an edit of ``contact_solver.py`` (or an upgrade of the package over an old cache)
    ``substep.run_substeps`` would load with the old solver inside. One stamp for the whole core is safe; a
    leaf subpackage (``_LEAF_PACKAGES``) adds its own files to the stamp of its kernels.
    """

    def get_source_stamp(self):
        return _package_stamp(_leaf_of(Path(self._py_file).resolve()))

    @classmethod
    def from_function(cls, py_func, py_file):
        if not Path(py_file).resolve().is_relative_to(_PACKAGE_DIR):
            return None
        return super().from_function(py_func, py_file)


class _PackageCacheLocator(_PackageStamp, caching.InTreeCacheLocator):
    """The cache beside the sources (``__pycache__``)."""


class _PackageUserDirLocator(_PackageStamp, caching.UserProvidedCacheLocator):
    """The cache in ``NUMBA_CACHE_DIR`` when one is set (``make test-slow`` gives its bounds-checked kernels their own,
    as Numba's cache index does not tell a bounds-checked build from a plain one)."""


caching.CacheImpl._locator_classes[:0] = [_PackageUserDirLocator, _PackageCacheLocator]


def kernel(function=None, *, parallel: bool = False):
    """Compile a hot loop: ``njit(cache=True, fastmath=False, nogil=True)``."""

    def wrap(f):
        return numba.njit(cache=True, fastmath=False, nogil=True, parallel=parallel)(f)

    return wrap(function) if function is not None else wrap


def inline(function):
    """A small helper called from kernels (``math3d``).

    Compiled as its own function and left to LLVM to inline: Numba's IR-level ``inline="always"`` made the
    contact kernels compile 30 % slower for no measurable gain at run time.
    """
    return numba.njit(cache=True, fastmath=False)(function)
