"""The same bits on every machine (issue 44): a scene built and run in fresh processes under each BLAS kernel OpenBLAS
can pick, a C library without its AVX2/FMA/AVX-512 variants, NumPy without its SIMD dispatch and Numba compiling for a
generic x86-64 gives one digest of the model and one of the final state.

Each process runs ``tests/machine_digests.py``. A kernel this CPU cannot execute (SkylakeX needs AVX-512) is left out
here and named in the skip reason; CI's machines run it.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from compiled import compiled_only

PROBE = Path(__file__).resolve().parents[1] / "machine_digests.py"

# Every SIMD target NumPy dispatches to on x86-64 (numpy._core._multiarray_umath.__cpu_dispatch__): all off leaves
# its baseline loops, the other end from the AVX2 and AVX-512 loops a machine picks by itself.
NUMPY_BASELINE = {"NPY_DISABLE_CPU_FEATURES": "X86_V3 X86_V4 AVX512_ICL AVX512_SPR"}
# glibc's libm picks FMA/AVX2 variants of exp, log, sin, … by CPU (its ifuncs); this mask takes them away.
LIBM_MASK = {"GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA,-AVX,-AVX512F"}
OPENBLAS_KERNELS = ("Haswell", "SkylakeX", "Zen", "Sandybridge", "Nehalem")
VARIANTS = {
    **{f"OpenBLAS {kernel}": {"OPENBLAS_CORETYPE": kernel} for kernel in OPENBLAS_KERNELS},
    "libm without AVX2/FMA/AVX-512": LIBM_MASK,
    "NumPy baseline loops": NUMPY_BASELINE,
    "Numba for a generic x86-64": {"NUMBA_CPU_NAME": "generic"},
}
# The model of each case (a case without a rate) and 2 s of it at 60 and 240 Hz.
CASES = ("mixed_pile", "hull_pile", "ant", "ant_articulation", "flagship", "ragdoll_stairs", "robot_arm", "dzhanibekov",
         "four_bar", "quadrotor_figure_eight_wind")  # fmt: skip
RUNS = (*CASES, *(f"{case}@{rate}" for case in CASES for rate in (60, 240)), "ant_env", "double_pendulum_env")
# Numba compiles every kernel again for a generic CPU (minutes for them all): there, the cases whose kernels are
# fewest, and each step path still once (hull contacts, joints and capsules, free flight, rotors and wind).
GENERIC_RUNS = (
    "hull_pile",
    "hull_pile@60",
    "hull_pile@240",
    "ant@60",
    "ant_articulation@60",
    "ant_env",
    "double_pendulum_env",
    "dzhanibekov@60",
    "quadrotor_figure_eight_wind@60",
)


def _cpu_flags() -> set[str]:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    return {flag for line in text.splitlines() if line.startswith("flags") for flag in line.split(":", 1)[1].split()}


def _unsupported(env: dict) -> str | None:
    """Why this machine cannot run the variant (OpenBLAS stops on an illegal instruction), or None."""
    if env.get("OPENBLAS_CORETYPE") == "SkylakeX" and "avx512f" not in _cpu_flags():
        return "this CPU has no AVX-512, which OpenBLAS's SkylakeX kernel executes"
    return None


def digests(runs, env: dict | None = None) -> dict:
    """The probe's digests of ``runs`` in a fresh process with ``env`` added to this one's environment."""
    result = subprocess.run(
        [sys.executable, str(PROBE), *runs],
        env={**os.environ, **(env or {})},
        capture_output=True,
        text=True,
        timeout=1200,
    )
    assert result.returncode == 0, f"{env}: exit {result.returncode}\n{result.stderr[-3000:]}"
    return json.loads(result.stdout)


def _differences(reference: dict, other: dict) -> list[str]:
    """Which runs (and, for a model, which arrays) differ."""
    out = []
    for run, value in reference.items():
        if isinstance(value, dict):
            out += [f"{run}: {field}" for field in value if other[run].get(field) != value[field]]
        elif other[run] != value:
            out.append(run)
    return out


@compiled_only("thousands of steps of piles and robots in fresh processes")
def test_a_hull_pile_gives_the_same_bits_under_another_blas_kernel_and_numpys_baseline_loops():
    """The quick version for make test: the pile of random hulls (whose inertia tensors, inverses and hull faces
    differed in their last bits under Sandybridge's and Nehalem's kernels before issue 44) and the mixed pile's
    model, under OpenBLAS's Sandybridge kernel with NumPy's baseline loops, against this machine's own choice."""
    runs = ("mixed_pile", "hull_pile", "hull_pile@60")
    here = digests(runs)
    other = digests(runs, {"OPENBLAS_CORETYPE": "Sandybridge", **NUMPY_BASELINE})
    assert _differences(here, other) == []


@pytest.mark.slow
@pytest.mark.timeout(1500)  # about 7 minutes: ten processes, and Numba compiling the generic one's kernels
@compiled_only("thousands of steps of piles and robots in fresh processes")
def test_every_case_gives_the_same_bits_under_every_kernel():
    """One test, not one per variant: the reference digests are worked out once (two test processes would each
    work them out), and a failure lists every variant that differs."""
    reference = digests(RUNS)
    differing, skipped = {}, []
    for variant, env in VARIANTS.items():
        reason = _unsupported(env)
        if reason is not None:
            skipped.append(f"{variant} ({reason})")
            continue
        runs = GENERIC_RUNS if "NUMBA_CPU_NAME" in env else RUNS
        differences = _differences({run: reference[run] for run in runs}, digests(runs, env))
        if differences:
            differing[variant] = differences
    assert differing == {}, f"differ: {differing}; not run here: {skipped}"


def test_the_libm_mask_takes():
    """The mask turns glibc's x86-64-v3 library variants off (``ld.so --list-diagnostics``), so the variant above
    runs what it says it runs."""
    loader = Path("/lib64/ld-linux-x86-64.so.2")
    if not loader.exists():
        pytest.skip("not a glibc x86-64 system")

    def active(env: dict) -> set[str]:
        text = subprocess.run([str(loader), "--list-diagnostics"], env={**os.environ, **env}, capture_output=True,
                              text=True, check=True).stdout  # fmt: skip
        subdirs = next(line for line in text.splitlines() if line.startswith("dl_hwcaps_subdirs="))
        mask = next(line for line in text.splitlines() if line.startswith("dl_hwcaps_subdirs_active="))
        names = subdirs.split("=", 1)[1].strip('"').split(":")
        bits = int(mask.split("=", 1)[1], 16)
        return {name for k, name in enumerate(names) if bits >> k & 1}

    assert "x86-64-v3" not in active(LIBM_MASK)
    assert "x86-64-v2" in active(LIBM_MASK)
