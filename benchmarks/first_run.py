"""First-run benchmark (issue 23): what a fresh machine waits for before its first results.

Run through ``python -m benchmarks.run --only first_run`` (about five minutes on two cores: it compiles everything
three times). Each case runs in fresh processes whose ``NUMBA_CACHE_DIR`` is a new, empty directory, so nothing
compiled before counts, and reports wall seconds:

- ``flagship, one process``: ``tumble run flagship --quiet`` (8 s of the scene at 60 Hz, recorded to HDF5);
- ``flagship after warmup``: ``tumble warmup --jobs 2`` (every shipped scene, two processes at a time), then the
  same ``tumble run``: ``warmup_s``, ``run_s`` and their sum ``total_s``;
- ``sphere on a plane``: one sphere dropped on a plane, one ``world.step``, in a fresh interpreter (``import
  tumble`` included).

The warm ``import tumble`` and first step in-process are the ``cold_start`` benchmark's ``warm`` row. No peer:
MuJoCo's wheel ships compiled code and pays nothing of this.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

__all__ = ["bench_first_run", "SPHERE_ON_PLANE"]

SPHERE_ON_PLANE = (
    "import tumble; w = tumble.World(); w.add_static(tumble.Plane()); "
    "w.add_body(tumble.Sphere(0.1), mass=1.0, position=(0, 0, 0.2)); w.step(1 / 60)"
)


def _timed(command: list[str], cache_dir: str | None, cwd: str) -> float:
    """Wall seconds of ``command`` with Numba's cache in ``cache_dir`` (None: the usual one); raises if it fails."""
    env = dict(os.environ) if cache_dir is None else {**os.environ, "NUMBA_CACHE_DIR": cache_dir}
    start = time.perf_counter()
    result = subprocess.run(command, env=env, cwd=cwd, capture_output=True, text=True, timeout=900)
    seconds = time.perf_counter() - start
    if result.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed ({result.returncode}):\n{result.stderr[-2000:]}")
    return seconds


def bench_first_run(sizes) -> list[dict]:
    """One row per case (see the module docstring); with ``sizes.cold_start`` False (the smoke test) only the sphere
    runs, with the usual (warm) cache, so that the plumbing is exercised in seconds."""
    tumble_cli = [sys.executable, "-m", "tumble"]
    rows = []
    with tempfile.TemporaryDirectory(prefix="tumble-first-run-") as scratch:
        out = str(Path(scratch) / "run.h5")
        run = [*tumble_cli, "run", "flagship", "--quiet", "--out", out]
        sphere = [sys.executable, "-c", SPHERE_ON_PLANE]

        def empty_cache(name: str) -> str | None:
            if not sizes.cold_start:
                return None
            path = Path(scratch) / name
            path.mkdir()
            return str(path)

        if sizes.cold_start:
            one_s = _timed(run, empty_cache("one"), scratch)
            rows.append({"benchmark": "first_run", "case": "flagship, one process", "run_s": one_s})
            warm_dir = empty_cache("warmup")
            warmup_s = _timed([*tumble_cli, "warmup", "--jobs", "2", "--quiet"], warm_dir, scratch)
            run_s = _timed(run, warm_dir, scratch)
            rows.append({"benchmark": "first_run", "case": "flagship after warmup", "warmup_s": warmup_s,
                         "run_s": run_s, "total_s": warmup_s + run_s})  # fmt: skip
        sphere_s = _timed(sphere, empty_cache("sphere"), scratch)
        rows.append({"benchmark": "first_run", "case": "sphere on a plane", "run_s": sphere_s})
    return rows
