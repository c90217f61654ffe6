"""Compile the kernels before the first run: ``tumble warmup [--jobs N]`` (issue 23).

Numba compiles a kernel on its first call and keeps it in its on-disk cache (``cache=True``), so the first run on a
fresh machine waits for the compiler: about 100 s of CPU for the flagship scene. Warming up steps each shipped scene
a few times, ``jobs`` processes at a time; they share the cache, so what one has compiled the next loads (0.1 s for
ten kernels) instead of compiling it again. The scenes that need kernels no other scene does go first, one per
process, so that two cores compile two different sets of kernels at once; the rest, which mostly load what those
compiled, follow in ``jobs`` processes that each step several scenes (a process of its own cost each about 1 s of
start-up and loading).

Two kernels no scene reaches, those of :class:`~tumble.articulation.Articulation` and
:class:`~tumble.articulation.ArticulationBatch` (what the Gymnasium environments of ``tumble.envs`` step), are warmed
first in a process of their own by running a small articulation (:func:`warm_articulations`; about 25 s of compiling
each, otherwise paid by the first ``simulate`` or environment step).

``make install`` runs it once; after that, ``tumble run`` of any scene starts at once.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

__all__ = ["WarmedScene", "warm_articulations", "warm_scene", "warmup", "default_jobs"]

# Scenes that need kernels of their own, first, each in its own process: the flagship (contacts of every primitive
# pair, meshes, hulls, joints), the quadrotor (rotors, flights, wind), the arm (articulation), the free-body
# integrators; the rest follow in name order and mostly load what these compiled.
FIRST = ("flagship", "quadrotor_figure_eight_wind", "robot_arm", "dzhanibekov", "ragdoll_stairs")
# [s] of each scene's simulated time: kernels are compiled as stages are first reached (the flagship's bodies reach
# the bowl after about 0.3 s: 3 steps compiled 311 functions, 1 s 349, the whole 8 s 351).
WARM_SECONDS = 1.0
# The item of the warm-up list that stands for the articulation kernels (warm_articulations), not a scene file.
ARTICULATIONS = Path(":articulations")


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


def warm_articulations() -> None:
    """Compile the articulation kernels, which no scene reaches: ``Articulation.simulate`` (whose kernel also answers
    ``step`` and the queries) and ``ArticulationBatch.step``, on a slider, a hinge and a ball joint."""
    from .articulation import Articulation, ArticulationBatch, Ball, Prismatic, Revolute
    from .shapes import Box

    art = Articulation()
    cart = art.add_link(Prismatic((1.0, 0.0, 0.0)), mass=1.0)
    pole = art.add_link(Revolute((0.0, 1.0, 0.0)), parent=cart, mass=0.5, shape_position=(0.0, 0.0, 0.5))
    art.add_link(Ball(), parent=pole, position=(0.0, 0.0, 1.0), shape=Box((0.1, 0.1, 0.4)), mass=0.2,
                 shape_position=(0.0, 0.0, 0.2))  # fmt: skip
    art.simulate(0.01, 1e-3)
    ArticulationBatch(art, 2).step(1e-3)


def _name(path) -> str:
    """What the reports call a warm-up item."""
    return "articulation kernels" if Path(path) == ARTICULATIONS else Path(path).stem


def _batches(scenes: list[Path], jobs: int) -> list[list[Path]]:
    """The processes to run, in order: each of :data:`FIRST` alone (in that order), then the other scenes in name
    order, dealt out to ``jobs`` processes."""
    rank = {name: k for k, name in enumerate(FIRST)}
    first = sorted((p for p in scenes if p.stem in rank), key=lambda p: rank[p.stem])
    rest = sorted((p for p in scenes if p.stem not in rank), key=lambda p: p.stem)
    return [[p] for p in first] + [batch for batch in (rest[k::jobs] for k in range(jobs)) if batch]


def warmup(jobs: int | None = None, *, scenes: list[Path] | None = None,
           on_done: Callable[[WarmedScene, int, int], None] | None = None) -> list[WarmedScene]:  # fmt: skip
    """Warm the kernels of ``scenes`` (default: every shipped scene) in ``jobs`` processes at a time (default: one
    per core); ``on_done(result, done, total)`` is called for each scene as its process ends. Returns one result
    per scene. Warming every shipped scene (``scenes`` not given) warms the articulation kernels too, first, as an
    item of its own (:data:`ARTICULATIONS`)."""
    from . import scene_file

    jobs = default_jobs() if jobs is None else jobs
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs must be an integer >= 1, got {jobs!r}")
    queue = _batches(list(scene_file.shipped()) if scenes is None else [Path(p) for p in scenes], jobs)
    if scenes is None:
        queue.insert(0, [ARTICULATIONS])
    total = sum(len(batch) for batch in queue)
    running: list[_Process] = []
    results: list[WarmedScene] = []
    while queue or running:
        while queue and len(running) < jobs:
            running.append(_Process(queue.pop(0)))
        time.sleep(0.05)
        for process in [p for p in running if p.done()]:
            running.remove(process)
            for result in process.results():
                results.append(result)
                if on_done is not None:
                    on_done(result, len(results), total)
    return results


class _Process:
    """A child warming ``paths`` one after the other; it writes one JSON line per scene to stdout. Both streams go
    to files, not pipes: a child with much to say never blocks."""

    def __init__(self, paths: list[Path]) -> None:
        self.paths = paths
        self._out, self._err = tempfile.TemporaryFile("w+"), tempfile.TemporaryFile("w+")
        command = [sys.executable, "-m", "tumble.warmup", *(str(p) for p in paths)]
        self._child = subprocess.Popen(command, stdout=self._out, stderr=self._err, text=True)

    def done(self) -> bool:
        return self._child.poll() is not None

    def results(self) -> list[WarmedScene]:
        """One result per path: the child's report, or for a scene it did not report (it crashed) its exit."""
        self._out.seek(0)
        self._err.seek(0)
        reported = [WarmedScene(**json.loads(line)) for line in self._out.read().splitlines() if line.startswith("{")]
        stderr = self._err.read().strip().splitlines()
        self._out.close()
        self._err.close()
        crash = stderr[-1] if stderr else f"exit status {self._child.returncode}"
        return reported + [WarmedScene(_name(p), 0.0, crash) for p in self.paths[len(reported) :]]


def _warm_each(paths: list[str]) -> None:
    """Warm each scene in turn, reporting each (and the error it ended with) on a line of stdout."""
    for path in paths:
        began, error = time.perf_counter(), None
        try:
            warm_articulations() if Path(path) == ARTICULATIONS else warm_scene(path)
        except Exception as exc:  # reported to the parent, which names the scene
            error = f"{type(exc).__name__}: {exc}"
        seconds = time.perf_counter() - began
        print(json.dumps({"name": _name(path), "seconds": seconds, "error": error}), flush=True)


if __name__ == "__main__":  # scenes in a process of their own (see warmup)
    _warm_each(sys.argv[1:])
