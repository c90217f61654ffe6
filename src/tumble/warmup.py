"""Compile the kernels before the first run: ``tumble warmup [--jobs N]`` (issue 23).

Numba compiles a kernel on its first call and keeps it in its on-disk cache (``cache=True``), so the first run on a
fresh machine waits for the compiler: about 100 s of CPU for the flagship scene. Warming up steps each shipped scene
a few times, every scene in a process of its own, ``jobs`` processes at a time; they share the cache, so what one
has compiled the next loads (0.1 s for ten kernels) instead of compiling it again. The largest scenes go first, one
per process, so that two cores compile two different sets of kernels at once.

``make install`` runs it once; after that, ``tumble run`` of any scene starts at once.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
import typing
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

__all__ = ["WarmedScene", "warm_scene", "warmup", "default_jobs"]

# Scenes that need the most kernels, first: the flagship (contacts of every primitive pair, meshes, hulls, joints)
# and the quadrotor (rotors, flights, wind); the rest follow in name order and mostly load what these compiled.
FIRST = ("flagship", "quadrotor_figure_eight_wind", "robot_arm", "ragdoll_stairs")
# [s] of each scene's simulated time: kernels are compiled as stages are first reached (the flagship's bodies reach
# the bowl after about 0.3 s: 3 steps compiled 311 functions, 1 s 349, the whole 8 s 351).
WARM_SECONDS = 1.0


@dataclass(frozen=True)
class WarmedScene:
    """One scene's warm-up: its name, the wall time of its process [s], and the error it ended with (or None)."""

    name: str
    seconds: float
    error: str | None = None


def default_jobs() -> int:
    """One process per core."""
    return max(1, os.cpu_count() or 1)


def warm_scene(path: str | os.PathLike) -> None:
    """Load the scene at ``path`` and run :data:`WARM_SECONDS` of it (or its whole duration if shorter) as ``tumble
    run`` does, with ``simulate``, then one ``step``: the kernels it needs are then in the cache."""
    from . import scene_file

    loaded = scene_file.load(path)
    world, dt = loaded.world, float(loaded.run.dt)
    world.simulate(max(dt, min(WARM_SECONDS, float(loaded.run.duration))), dt)
    world.step(dt)


def _ordered(scenes: list[Path]) -> list[Path]:
    rank = {name: k for k, name in enumerate(FIRST)}
    return sorted(scenes, key=lambda p: (rank.get(p.stem, len(FIRST)), p.stem))


def warmup(jobs: int | None = None, *, scenes: list[Path] | None = None,
           on_done: Callable[[WarmedScene, int, int], None] | None = None) -> list[WarmedScene]:  # fmt: skip
    """Warm the kernels of ``scenes`` (default: every shipped scene) in ``jobs`` processes at a time (default: one
    per core); ``on_done(result, done, total)`` is called as each process ends. Returns one result per scene."""
    from . import scene_file

    jobs = default_jobs() if jobs is None else jobs
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs must be an integer >= 1, got {jobs!r}")
    queue = _ordered(list(scene_file.shipped()) if scenes is None else [Path(p) for p in scenes])
    running: list[tuple[Path, subprocess.Popen, float, typing.IO]] = []
    results: list[WarmedScene] = []
    total = len(queue)
    while queue or running:
        while queue and len(running) < jobs:
            path = queue.pop(0)
            command = [sys.executable, "-m", "tumble.warmup", str(path)]
            errors = tempfile.TemporaryFile("w+")  # a file, not a pipe: a child with much to say never blocks
            process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=errors, text=True)
            running.append((path, process, time.perf_counter(), errors))
        time.sleep(0.05)
        for entry in list(running):
            path, process, started, errors = entry
            if process.poll() is None:
                continue
            running.remove(entry)
            errors.seek(0)
            stderr = errors.read()
            errors.close()
            error = None if process.returncode == 0 else (stderr.strip().splitlines() or ["failed"])[-1]
            results.append(WarmedScene(path.stem, time.perf_counter() - started, error))
            if on_done is not None:
                on_done(results[-1], len(results), total)
    return results


if __name__ == "__main__":  # one scene, in a process of its own (see warmup)
    warm_scene(sys.argv[1])
