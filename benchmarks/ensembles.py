"""Ensembles: 64 members of the shipped box pile (27 boxes on the ground, 4 s at 60 Hz, each member a friction and a
gravity of an 8 × 8 grid) run by ``tumble.ensemble.run`` on a local process pool and on a Dask ``LocalCluster``,
with 1 and 2 worker processes, beside a serial loop in this process (issue 30).

Run from the repository root:

    python -m benchmarks.ensembles [--quick] [--repeat N]
    python -m benchmarks.run --only ensemble

Each timing is a whole ``ensemble.run`` call into an empty folder, every trajectory written: the local pool starts
its worker processes in each call (spawned: importing tumble and loading the kernels from Numba's cache is part of
the cost a user pays); the Dask cluster is started once, outside the timings, as a user's cluster is (its workers
load the kernels in the first, untimed call). ``efficiency`` is the 1-worker time over twice the 2-worker time (the
issue's target: >= 80 %); ``x_serial`` the serial loop's time over the run's. The best of ``--repeat`` runs.
"""

from __future__ import annotations

import logging
import math
import os
import tempfile
import time
from dataclasses import dataclass

from tumble import ensemble, scene_file

from .timing import show_row, sizes_from_args

__all__ = ["EnsembleSizes", "FULL", "QUICK", "bench_ensemble"]


@dataclass(frozen=True)
class EnsembleSizes:
    frictions: int = 8
    gravities: int = 8
    duration: float = 4.0
    workers: tuple = (1, 2)
    scaling_members: tuple = (16, 64, 256)  # the local pool on every core: the cost per member should be flat
    repeat: int = 2


FULL = EnsembleSizes()
QUICK = EnsembleSizes(frictions=2, gravities=2, duration=0.1, scaling_members=(2, 4), repeat=1)
SCENE = "box_pile"


def _members(sizes: EnsembleSizes) -> list[dict]:
    frictions = [round(0.1 + 0.8 * k / max(1, sizes.frictions - 1), 6) for k in range(sizes.frictions)]
    gravities = [round(-9.81 + 8.19 * k / max(1, sizes.gravities - 1), 6) for k in range(sizes.gravities)]
    return ensemble.grid({"bodies[0].friction": frictions, "world.gravity[2]": gravities})


def _timed(run, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        with tempfile.TemporaryDirectory(prefix="tumble-ensemble-") as out:
            start = time.perf_counter()
            run(out)
            best = min(best, time.perf_counter() - start)
    return best


def _serial(members: list[dict], duration: float, out: str) -> None:
    """The loop a user writes without tumble.ensemble: load, record, next (same files, same bits)."""
    from tumble.recording import record

    path = scene_file.shipped_scene(SCENE)
    for k, member in enumerate(members):
        loaded = scene_file.load(path, member)
        record(loaded.world, duration, loaded.run.dt, f"{out}/member_{k:05d}.h5", scene=loaded.source, load=False)


def _dask_available() -> bool:
    try:
        import distributed  # noqa: F401
    except ImportError:
        return False
    return True


def bench_ensemble(sizes: EnsembleSizes = FULL) -> list[dict]:
    members = _members(sizes)
    path = scene_file.shipped_scene(SCENE)
    rows = []

    def row(executor: str, workers: int, seconds: float, serial: float | None) -> dict:
        result = {"scene": SCENE, "members": len(members), "executor": executor, "workers": workers,
                  "seconds": seconds, "members_per_s": len(members) / seconds}  # fmt: skip
        if serial is not None:
            result["x_serial"] = serial / seconds
        rows.append(result)
        show_row(result)
        return result

    _serial(members[:1], sizes.duration, tempfile.mkdtemp(prefix="tumble-ensemble-warm-"))  # kernels loaded
    serial = _timed(lambda out: _serial(members, sizes.duration, out), sizes.repeat)
    row("serial loop", 1, serial, None)

    def pool(n):
        return lambda out: ensemble.run(path, members, sizes.duration, out_dir=out, workers=n, progress=False)

    by_pool = {n: row("local pool", n, _timed(pool(n), sizes.repeat), serial) for n in sizes.workers}
    by_dask = {}
    for n in sizes.workers if _dask_available() else ():
        import distributed

        with (
            distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                                     silence_logs=logging.ERROR) as cluster,
            distributed.Client(cluster) as client,
        ):  # fmt: skip

            def on_dask(out, client=client):
                ensemble.run(path, members, sizes.duration, out_dir=out, executor=client, progress=False)

            on_dask(tempfile.mkdtemp(prefix="tumble-ensemble-warm-"))  # the workers load the kernels
            by_dask[n] = row("Dask LocalCluster", n, _timed(on_dask, sizes.repeat), serial)
    for timings in (by_pool, by_dask):
        if 1 in timings and 2 in timings:
            timings[2]["efficiency"] = timings[1]["seconds"] / (2 * timings[2]["seconds"])
            show_row({"executor": timings[2]["executor"], "efficiency": timings[2]["efficiency"]})
    return rows + _scaling(sizes, path)


def _scaling(sizes: EnsembleSizes, path) -> list[dict]:
    """Random members (one seed) of growing count on the local pool with a worker per core: seconds per member."""
    rows = []
    for count in sizes.scaling_members:
        members = ensemble.sample(count, seed=0, uniform={"bodies[0].friction": (0.1, 0.9),
                                                          "world.gravity[2]": (-9.81, -1.62)})  # fmt: skip
        seconds = _timed(lambda out, m=members: ensemble.run(path, m, sizes.duration, out_dir=out, progress=False),
                         sizes.repeat)  # fmt: skip
        row = {"scene": SCENE, "members": count, "executor": "local pool, scaling", "workers": os.cpu_count() or 1,
               "seconds": seconds, "members_per_s": count / seconds, "s_per_member": seconds / count}  # fmt: skip
        rows.append(row)
        show_row(row)
    return rows


if __name__ == "__main__":
    bench_ensemble(sizes_from_args(None, "benchmarks.ensembles", __doc__, FULL, QUICK))
