"""The only module that imports Numba.

Kernels are compiled once and cached on disk (``cache=True``) so that the second process starts warm.
``fastmath`` stays off: results must be bit-for-bit reproducible and IEEE-exact enough for the
conservation tests. Setting ``NUMBA_DISABLE_JIT=1`` turns every kernel back into plain Python, which
is how CI runs the unit tests once (pdb and coverage reach the kernels that way).
"""

from __future__ import annotations

import functools
import hashlib
import inspect
from pathlib import Path
from types import FunctionType

import numba
from numba.core import caching, config, types
from numba.core.datamodel import default_manager
from numba.core.registry import CPUDispatcher
from numba.experimental import structref

__all__ = ["Record", "RecordType", "define_record", "kernel", "kernel_for", "inline", "prange"]

prange = numba.prange
_PACKAGE_DIR = Path(__file__).resolve().parent


# Subpackages whose kernels nothing outside them calls: an edit there invalidates their own kernels only.
# Everything else (top-level modules, geometry/, dynamics/) is the core that every kernel may embed.
_LEAF_PACKAGES = ("articulation", "control", "lagrange")


def _leaf_of(path: Path) -> str | None:
    parts = path.relative_to(_PACKAGE_DIR).parts
    return parts[0] if len(parts) > 1 and parts[0] in _LEAF_PACKAGES else None


# Modules without compiled code whose constants kernels freeze at compile time (shape and integrator codes), and
# this one, whose options (wrappers, literal typing) shape every compiled function.
_CONSTANT_MODULES = ("_jit.py", "shapes.py", "params.py", "geometry/manifold.py", "geometry/packing.py")


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
        return _package_stamp(self._leaf)

    @classmethod
    def from_function(cls, py_func, py_file):
        if not _resolved(py_file).is_relative_to(_PACKAGE_DIR):
            return None
        locator = super().from_function(py_func, py_file)
        if locator is not None:
            # A copy made by kernel_for embeds the functions bound into it: their leaf package stamps it too.
            locator._leaf = getattr(py_func, "_bound_leaf", None) or _leaf_of(_resolved(py_file))
        return locator


@functools.cache
def _resolved(py_file: str) -> Path:
    """The real path of a source file, resolved once per file (not once per compiled function: 20 ms of import)."""
    return Path(py_file).resolve()


class _PackageCacheLocator(_PackageStamp, caching.InTreeCacheLocator):
    """The cache beside the sources (``__pycache__``)."""


class _PackageUserDirLocator(_PackageStamp, caching.UserProvidedCacheLocator):
    """The cache in ``NUMBA_CACHE_DIR`` when one is set (``make test-slow`` gives its bounds-checked kernels their own,
    as Numba's cache index does not tell a bounds-checked build from a plain one)."""


caching.CacheImpl._locator_classes[:0] = [_PackageUserDirLocator, _PackageCacheLocator]


class _Kernel(CPUDispatcher):
    """A compiled function that kernels call with plain types: a constant argument (``True``, an index ``0``, a
    shape code) does not compile a copy of the callee for its value, as Numba's literal typing would. Those copies
    were 14–15 s of a cold flagship run (``solve_contacts(…, True)`` and ``(…, False)``, the GJK stack once for
    ``POINT``); LLVM still folds the constant where it inlines the callee."""

    def get_call_template(self, args, kws):
        plain = {name: types.unliteral(value) for name, value in kws.items()}
        return super().get_call_template(tuple(types.unliteral(value) for value in args), plain)


class _Helper(_Kernel):
    """A helper compiled without the Python-callable wrapper that every ``njit`` function gets (8–13 s of a cold
    flagship run went to building those wrappers). Kernels call the compiled code; a call from Python runs the
    Python source, which does the same IEEE arithmetic (``fastmath`` is off), since there is no wrapper to enter."""

    def __call__(self, *args, **kwargs):
        return self.py_func(*args, **kwargs)


class _UncountedHelper(_Helper):
    """A helper compiled without reference counts (Numba's ``_nrt=False``): it neither increments nor decrements the
    count of an array it is given, views or takes out of a record, which is safe while nothing it makes outlives
    the call. So it may not allocate (Numba refuses to compile that) nor return an array, or anything holding one
    (refused here: its caller would release a reference it was never given)."""

    def add_overload(self, cres):
        returned = cres.signature.return_type
        if default_manager.lookup(returned).contains_nrt_meminfo():
            raise TypeError(f"{self.py_func.__qualname__} is compiled without reference counts (inline(counted=False))"
                            f" and may not return arrays, but returns {returned}")  # fmt: skip
        super().add_overload(cres)


def _compiled(function, dispatcher: type, **options):
    if config.DISABLE_JIT:
        return function
    compiled = dispatcher(py_func=function, locals={}, targetoptions={"nopython": True, "fastmath": False, **options})
    compiled.enable_caching()
    return compiled


def kernel(function=None, *, parallel: bool = False):
    """Compile a function that Python calls (a stage of the step, a query): ``njit(cache=True, fastmath=False,
    nogil=True)``, typed as :class:`_Kernel`, without the C wrapper that only a first-class function value needs.
    A function that only compiled code calls is an :func:`inline`."""

    def wrap(f):
        return _compiled(f, _Kernel, nogil=True, parallel=parallel, no_cfunc_wrapper=True)

    return wrap(function) if function is not None else wrap


def inline(function=None, *, into_callers: bool = False, counted: bool = True, ieee_division: bool = False):
    """Compile a function that only compiled code calls: the helpers of ``math3d``, the solvers' passes, the
    collision routines. Without Python or C wrappers (:class:`_Helper`).

    Compiled as its own function and left to LLVM to inline: Numba's IR-level ``inline="always"`` made the
    contact kernels compile 30 % slower for no measurable gain at run time. ``into_callers=True`` asks for it where
    a call costs more than the work: a compiled call reference-counts every array it receives (atomic operations,
    0.5 µs for a few dozen), which the free-body integrator paid once per body and step (``integrate.py``).

    ``counted=False`` compiles it without reference counts at all (:class:`_UncountedHelper`): for a function over
    many arrays that allocates none and returns none, called often. Each array it holds costs two atomic operations
    a call otherwise, about 10 ns (a call over twelve arrays: 128 ns counted, 9 ns not).

    ``ieee_division=True`` compiles it with NumPy's error model: a float division by zero gives an infinity or a NaN,
    as IEEE 754 says, instead of raising. Python's model tests every divisor, a branch that keeps LLVM from
    vectorising a loop over many copies (``articulation/chain.py``); the caller must then check the results.
    """

    def wrap(f):
        options = {"inline": "always"} if into_callers else {}
        if ieee_division:
            options["error_model"] = "numpy"
        if not counted:
            return _compiled(f, _UncountedHelper, no_cpython_wrapper=True, no_cfunc_wrapper=True, _nrt=False, **options)
        return _compiled(f, _Helper, no_cpython_wrapper=True, no_cfunc_wrapper=True, **options)

    return wrap(function) if function is not None else wrap


def kernel_for(template, name: str, **names):
    """A kernel compiled from ``template``'s code with some of its global names bound to other objects: one
    compiled copy per binding, so that a caller compiles only the copies it runs (``narrow_phase`` makes one loop
    per pair type this way). A closure would do the same, but Numba keys its cache on the pickled closure, which
    holds a per-process id for a compiled function: the copies would never load from the cache. Each copy is
    named ``name``, which also names its cache files. A copy that binds a leaf package's function (a compiled
    controller stage into the core's step loop) is stamped with that package's sources as well as its own."""
    functions = [getattr(value, "py_func", value) for value in names.values()]
    files = [_resolved(inspect.getfile(f)) for f in functions if isinstance(f, FunctionType)]
    leaves = {_leaf_of(path) for path in files if path.is_relative_to(_PACKAGE_DIR)} - {None}
    if len(leaves) > 1:
        raise ValueError(f"kernel_for binds functions of several leaf packages ({sorted(leaves)}) into {name!r}")
    copy = FunctionType(template.__code__, {**template.__globals__, **names}, name)
    copy._bound_leaf = leaves.pop() if leaves else None
    copy.__qualname__ = name
    copy.__module__ = template.__module__
    copy.__doc__ = template.__doc__
    return kernel(copy)


class RecordType(types.StructRef):
    """The compiled type of a :func:`define_record` class: its fields typed as the values it was built from (a
    constant's literal type widened, so that every record of the same arrays has one type and one compiled copy of
    the kernels that take it)."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(value)) for name, value in fields)


class _PlainRecord:
    """A record without Numba (``NUMBA_DISABLE_JIT=1``): its fields as attributes, in the order defined."""

    _fields: tuple[str, ...] = ()

    def __init__(self, *values):
        for name, value in zip(self._fields, values, strict=True):
            setattr(self, name, value)


Record = _PlainRecord if config.DISABLE_JIT else structref.StructRefProxy


def define_record(record_class: type, type_class: type, fields: tuple[str, ...]) -> None:
    """Make ``record_class`` (a :class:`Record`) hold ``fields`` as one compiled object, a Numba StructRef of type
    ``type_class`` (a :class:`RecordType`, defined at a module's top level so that the kernels taking it can be
    cached): a kernel receives the whole record as one argument, a pointer, where a tuple of arrays is unboxed and
    reference-counted array by array at every call (0.3 µs each). Kernels build records (``record_class(*values)``
    inside compiled code, where its construction compiles once and is cached) and read their fields as attributes;
    the arrays are the caller's, shared, not copied."""
    record_class._fields = tuple(fields)
    if config.DISABLE_JIT:
        return
    structref.register(type_class)
    structref.define_constructor(record_class, type_class, fields)
    structref.define_boxing(type_class, record_class)
