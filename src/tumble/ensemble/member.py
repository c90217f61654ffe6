"""One member of an ensemble, as a worker process runs it: build the world, record the run to a temporary file,
summarise it, and rename the file once it is whole.

A member's files in ``out_dir`` (``NNNNN`` its index):

- ``member_NNNNN.partial.h5`` while it runs (a worker killed mid-run leaves it: never taken as finished);
- ``member_NNNNN.h5`` once it is complete: the trajectory, with the member's parameters, the run's settings and its
  summary in the metadata's ``ensemble`` entry (what a rerun reads back instead of running it again);
- ``member_NNNNN.failed.h5`` when the simulation failed: the frames up to the last good step, and the error;
- ``member_NNNNN.failed.txt`` when the member failed: its parameters and the traceback.

A member that runs again removes its earlier failure's files first.
"""

from __future__ import annotations

import os
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["MemberTask", "run_member", "member_path", "finished_entry", "default_summary"]


@dataclass(frozen=True)
class MemberTask:
    """What a worker needs to run member ``index`` (sent to it by pickling).

    ``build`` is a callable (``build(**params)`` gives a world, a scene path, or ``(scene path, overrides)``) or the
    path of a scene file whose places ``params`` sets. ``request`` is what identifies the run (build, parameters,
    settings as asked), stored in the file and compared by a rerun."""

    index: int
    params: dict
    build: Callable | str
    duration: float | None
    dt: float | None
    record_every: int | None
    out_dir: str
    summary: Callable | None
    request: dict


def member_path(out_dir, index: int, kind: str = "") -> Path:
    """``out_dir/member_NNNNN.h5`` (``kind``: ``""``, ``"partial"`` or ``"failed"``)."""
    return Path(out_dir) / f"member_{index:05d}{'.' + kind if kind else ''}.h5"


def _traceback_path(out_dir, index: int) -> Path:
    return Path(out_dir) / f"member_{index:05d}.failed.txt"


def default_summary(world, start_energy: float, start_positions: np.ndarray) -> dict:
    """What every row holds: the time reached, the energies at the end and the change of the total, the farthest
    any dynamic body moved from its start and the fastest one's speed at the end."""
    dynamic = world.model.body_is_dynamic
    positions = world.state.body_pos[dynamic]
    speeds = np.linalg.norm(world.state.body_linvel[dynamic], axis=1)
    kinetic, potential = world.kinetic_energy(), world.potential_energy()
    moved = np.linalg.norm(positions - start_positions, axis=1)
    return {
        "time": float(world.time),
        "kinetic_energy": kinetic,
        "potential_energy": potential,
        "energy_change": kinetic + potential - start_energy,
        "max_displacement": float(moved.max()) if moved.size else 0.0,
        "max_speed": float(speeds.max()) if speeds.size else 0.0,
    }


def _user_summary(summary, world) -> dict:
    values = summary(world)
    if not isinstance(values, dict) or not all(isinstance(key, str) for key in values):
        raise TypeError(f"summary must return a dict of names to numbers, got {values!r}")
    return {key: value.item() if isinstance(value, np.generic) else value for key, value in values.items()}


def _built(task: MemberTask):
    """``(world, scene dict or None, duration, dt, record_every)`` of the member."""
    from .. import scene_file
    from ..world import World

    made = task.build if isinstance(task.build, str) else task.build(**task.params)
    overrides = task.params if isinstance(task.build, str) else {}
    if isinstance(made, tuple) and len(made) == 2 and isinstance(made[1], dict):
        made, overrides = made
    if isinstance(made, World):
        if task.duration is None or task.dt is None:
            raise ValueError("build gave a World: give the ensemble a duration and a dt (only a scene has its own)")
        return made, None, task.duration, task.dt, task.record_every or 1
    if isinstance(made, (str, os.PathLike)):
        loaded = scene_file.load(made, overrides)
        run = loaded.run
        duration = task.duration if task.duration is not None else run.duration
        dt = task.dt if task.dt is not None else run.dt
        return loaded.world, loaded.source, duration, dt, task.record_every or run.record_every
    raise TypeError(f"build must give a tumble.World, a scene file's path, or (path, overrides), got {made!r}")


def run_member(task: MemberTask) -> dict:
    """Run one member (in a worker): ``{"member", "status": "done" | "failed", "error", "summary", "path",
    "wall_s"}``. An error of the member's own (its build, its simulation, its summary) is reported in the result,
    never raised, so that it costs no other member; its traceback goes to ``member_NNNNN.failed.txt``."""
    from ..recording import record
    from ..trajectory_io import update_h5_metadata

    began = time.perf_counter()
    partial = member_path(task.out_dir, task.index, "partial")
    result = {"member": task.index, "status": "failed", "error": None, "summary": {}, "path": None}
    for stale in (member_path(task.out_dir, task.index, "failed"), _traceback_path(task.out_dir, task.index)):
        stale.unlink(missing_ok=True)  # an earlier call's failure of this member
    try:
        world, scene, duration, dt, every = _built(task)
        dynamic = world.model.body_is_dynamic
        start_energy, start_positions = world.total_energy(), world.state.body_pos[dynamic].copy()
        record(world, duration, dt, partial, every=every, scene=scene, load=False)
        summary = default_summary(world, start_energy, start_positions)
        if task.summary is not None:
            summary.update(_user_summary(task.summary, world))
        result.update(status="done", summary=summary)
    except Exception as error:  # the member's own failure: reported in its row
        result["error"] = f"{type(error).__name__}: {error}"
        _traceback_path(task.out_dir, task.index).write_text(
            f"member {task.index}, parameters {task.params}\n\n{traceback.format_exc()}"
        )
    result["wall_s"] = time.perf_counter() - began
    final = member_path(task.out_dir, task.index, "" if result["status"] == "done" else "failed")
    if partial.exists():
        entry = {"member": task.index, "request": task.request, "summary": result["summary"],
                 "status": result["status"], "error": result["error"], "wall_s": result["wall_s"]}  # fmt: skip
        update_h5_metadata(partial, {"ensemble": entry})
        os.replace(partial, final)  # atomic: a file under the final name is whole
        result["path"] = str(final)
    return result


def finished_entry(out_dir, index: int) -> dict | None:
    """The ``ensemble`` entry of member ``index``'s finished file, or None when there is none (or it is not a
    complete tumble trajectory)."""
    from ..trajectory_io import read_h5_metadata

    path = member_path(out_dir, index)
    if not path.is_file():
        return None
    try:
        metadata = read_h5_metadata(path)
    except (OSError, ValueError):
        return None
    entry = metadata.get("ensemble")
    if metadata.get("status") != "complete" or not isinstance(entry, dict) or entry.get("status") != "done":
        return None
    return entry
