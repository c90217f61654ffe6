"""``tumble.ensemble.run``: submit the members that are not finished yet, gather their rows as they end, and write
the table."""

from __future__ import annotations

import csv
import json
import math
import os
import sys
import tempfile
from concurrent.futures import CancelledError, as_completed
from pathlib import Path

from .._validate import as_count, as_float
from .executors import check_executor, executor_for
from .member import MemberTask, finished_entry, member_path, run_member
from .params import as_members

__all__ = ["run", "RESULTS_FILE"]

RESULTS_FILE = "results.csv"
# The table's own columns, around the parameters' and the summaries'.
_LEADING = ("member",)
_TRAILING = ("status", "error")
_LAST = ("wall_s", "reused", "path")


def _as_build(build) -> tuple[object, str]:
    """``(build as the workers get it, its description stored with each member)``: a callable, or a scene file's
    absolute path (a shipped scene's name is found too)."""
    from .. import scene_file

    if callable(build):
        return build, f"{getattr(build, '__module__', '?')}.{getattr(build, '__qualname__', repr(build))}"
    if isinstance(build, (str, os.PathLike)):
        path = Path(build)
        if not path.is_file():
            try:
                path = scene_file.shipped_scene(os.fspath(build)) if not path.suffix else path
            except KeyError:
                pass
        if not path.is_file():
            raise ValueError(f"build: no scene file at {os.fspath(build)!r} (nor a shipped scene of that name)")
        text = str(path.resolve())
        return text, text
    raise TypeError(f"build must be a callable (build(**params) gives a World or a scene path) or a scene file's "
                    f"path, got {build!r}")  # fmt: skip


def _check_places(scene: str, members: list[dict]) -> None:
    """Each distinct set of places, with its first member's values, validated against the scene before anything
    runs: a typo fails the call at once, naming the member and the place."""
    from .. import scene_file

    seen = set()
    for k, member in enumerate(members):
        key = tuple(member)
        if key in seen:
            continue
        seen.add(key)
        try:
            scene_file.check(scene, member)
        except scene_file.SceneError as error:
            raise ValueError(f"params[{k}]: {error}") from None


def _writable(out_dir) -> Path:
    if not isinstance(out_dir, (str, os.PathLike)):
        raise TypeError(f"out_dir must be a folder's path, got {out_dir!r}")
    out = Path(out_dir).resolve()
    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=out, prefix=".write-check-"):
            pass
    except OSError as error:
        raise ValueError(f"out_dir {os.fspath(out_dir)!r}: cannot write there: {error.strerror or error}") from None
    return out


def _reused_row(entry: dict, out: Path, index: int) -> dict:
    return {"member": index, "status": "done", "error": None, "summary": entry.get("summary", {}),
            "wall_s": entry.get("wall_s", math.nan), "reused": True,
            "path": str(member_path(out, index))}  # fmt: skip


def _row_of(future, index: int) -> dict:
    """The row a finished future gives: the member's result, or a row saying that its worker was lost."""
    try:
        row = future.result()
    except KeyboardInterrupt:
        raise
    except BaseException as error:  # the worker, not the member: killed, cancelled, unpicklable
        row = _lost_row(index, error)
    row["reused"] = False
    return row


def _lost_row(index: int, error: BaseException) -> dict:
    what = "cancelled" if isinstance(error, CancelledError) else f"{type(error).__name__}: {error}"
    return {"member": index, "status": "failed", "error": f"its worker was lost ({what})", "summary": {},
            "wall_s": math.nan, "path": None}  # fmt: skip


def run(build, params, duration: float | None = None, dt: float | None = None, out_dir=None, *, executor=None,
        workers: int | None = None, record_every: int | None = None, summary=None,
        progress: bool | None = None):  # fmt: skip
    """Run every member of an ensemble, each on its own world, on a process pool or a Dask cluster.

    Args:
        build: ``build(**p)`` for the member's parameters ``p``, giving a :class:`~tumble.World`, a scene file's
            path, or ``(path, overrides)``; or a scene file's path itself, whose places each member's parameters
            set (``{"bodies[0].friction": 0.3}``: :mod:`tumble.scene_file.overrides`).
        params: one dict per member (:func:`grid`, :func:`sample`).
        duration, dt: [s]; None takes the scene's (a ``build`` giving a World needs both).
        out_dir: the folder of the trajectories (``member_NNNNN.h5``) and of ``results.csv``; a worker elsewhere
            must see it (a shared file system).
        executor: None (a local pool of processes), any ``concurrent.futures.Executor``, a ``distributed.Client``
            or a Dask scheduler's address (``"tcp://host:8786"``).
        workers: the local pool's processes (default one per core).
        record_every: record one frame every N steps (default: the scene's, else 1).
        summary: ``summary(world) -> dict`` of more columns, called on each member's world at the end.
        progress: show a progress bar (members done and failed, ETA) on stderr; None: when stderr is a terminal.

    Returns:
        The table, one row per member in the order of ``params``: ``member``, the parameters, ``status``
        (``"done"`` or ``"failed"``), ``error``, the summary (``time``, ``kinetic_energy``, ``potential_energy``,
        ``energy_change``, ``max_displacement``, ``max_speed`` and ``summary``'s), ``wall_s``, ``reused`` (finished
        by an earlier call: read back from its file) and ``path``. A pandas DataFrame when pandas is installed, a
        list of dicts otherwise; also written to ``out_dir/results.csv``.

    A member that fails (its build, its simulation, its summary, or its worker dying) is reported in its row and
    costs no other member. Calling again with the same arguments runs only the members without a finished file.
    """
    build, described = _as_build(build)
    reserved = _LEADING + _TRAILING + _LAST
    members = as_members(params, reserved)
    duration = None if duration is None else as_float("duration", duration, positive=True)
    dt = None if dt is None else as_float("dt", dt, positive=True)
    record_every = None if record_every is None else as_count("record_every", record_every)
    if not isinstance(build, str) and (duration is None or dt is None):
        raise ValueError("duration and dt: give both when build is a function (only a scene file has its own)")
    if summary is not None and not callable(summary):
        raise TypeError(f"summary must be a function of the world giving a dict, or None, got {summary!r}")
    if workers is not None:
        workers = as_count("workers", workers)
        if executor is not None:
            raise ValueError(f"workers={workers} sizes the local process pool; the executor given sizes itself")
    check_executor(executor, build, summary)
    if out_dir is None:
        raise ValueError("out_dir: give the folder the members' trajectories go to")
    out = _writable(out_dir)
    if isinstance(build, str):
        _check_places(build, members)
    settings = {"build": described, "duration": duration, "dt": dt, "record_every": record_every}
    tasks = [MemberTask(k, p, build, duration, dt, record_every, str(out), summary, {**settings, "params": p})
             for k, p in enumerate(members)]  # fmt: skip
    rows: list[dict | None] = [None] * len(tasks)
    for task in tasks:
        entry = finished_entry(out, task.index)
        if entry is not None:
            if entry.get("request") != _as_json(task.request):
                raise ValueError(f"out_dir {os.fspath(out_dir)!r} holds {member_path(out, task.index).name} of "
                                 f"another run ({entry.get('request')}), not of {task.request}: give a new "
                                 "out_dir, or delete the files")  # fmt: skip
            rows[task.index] = _reused_row(entry, out, task.index)
    todo = [task for task in tasks if rows[task.index] is None]
    if todo:
        with (
            executor_for(executor, workers, len(todo)) as pool,
            _ProgressBar(len(tasks), len(tasks) - len(todo), progress) as bar,
        ):
            futures = {pool.submit(run_member, task): task.index for task in todo}
            try:
                for future in as_completed(futures):
                    rows[futures[future]] = row = _row_of(future, futures[future])
                    bar.advance(row["status"] == "done")
            except BaseException:  # Ctrl-C, SIGTERM: members not started are dropped (running ones end themselves)
                for future in futures:
                    future.cancel()
                raise
    table = _table(members, rows)
    _write_csv(out / RESULTS_FILE, table)
    return _as_frame(table)


def _as_json(value):
    """``value`` as a file's metadata gives it back (tuples as lists)."""
    return json.loads(json.dumps(value))


def _table(members: list[dict], rows: list[dict]) -> list[dict]:
    names = list(dict.fromkeys(name for member in members for name in member))
    summaries = list(dict.fromkeys(name for row in rows for name in row["summary"]))
    table = []
    for member, row in zip(members, rows, strict=True):
        line = {"member": row["member"], **{name: member.get(name) for name in names}}
        line.update(status=row["status"], error=row["error"])
        line.update({name: row["summary"].get(name) for name in summaries})
        line.update(wall_s=row["wall_s"], reused=row["reused"], path=row["path"])
        table.append(line)
    return table


def _write_csv(path: Path, table: list[dict]) -> None:
    partial = path.with_suffix(".partial.csv")
    with open(partial, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(table[0]))
        writer.writeheader()
        writer.writerows(table)
    os.replace(partial, path)


def _as_frame(table: list[dict]):
    try:
        import pandas
    except ImportError:
        return table
    return pandas.DataFrame(table)


class _ProgressBar:
    """Members done and failed of all, and the time left (rich, on stderr)."""

    def __init__(self, total: int, reused: int, enabled: bool | None, console=None) -> None:
        self._bar = None
        self.done, self.failed = reused, 0
        if enabled is None:
            enabled = sys.stderr.isatty()
        if enabled:
            from rich.console import Console
            from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

            self._bar = Progress(
                TextColumn("members"),
                BarColumn(),
                TextColumn("{task.fields[done]} done, {task.fields[failed]} failed of {task.total}"
                           + (f" ({reused} from an earlier run)" if reused else "")),
                TimeRemainingColumn(),
                console=console or Console(stderr=True),
                transient=True,
            )  # fmt: skip
            self._task = self._bar.add_task("members", total=total, completed=reused, done=reused, failed=0)

    def __enter__(self):
        if self._bar is not None:
            self._bar.start()
        return self

    def __exit__(self, *exc) -> None:
        if self._bar is not None:
            self._bar.stop()

    def advance(self, done: bool) -> None:
        if done:
            self.done += 1
        else:
            self.failed += 1
        if self._bar is not None:
            self._bar.update(self._task, advance=1, done=self.done, failed=self.failed)
