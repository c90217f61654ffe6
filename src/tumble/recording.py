"""Recording long runs to disk while they go: :class:`TrajectoryWriter` and :func:`record`.

Frames are buffered in memory and written a chunk (``chunk_frames`` frames) at a time. An HDF5 file (``.h5``)
grows by each chunk and is flushed, so a run that fails, is interrupted or is killed keeps every frame up to
its last chunk; an ``.npz`` file is rewritten whole at each chunk (through a temporary file and a rename),
which suits short runs only. The file carries the run's metadata: tumble version, dt, integrator, solver
settings, recording interval, the caller's scene description and the run's status. ``docs/files.md`` gives the
layout and the measured cost.

>>> import tumble, tumble.recording, tempfile, os
>>> world = tumble.World()
>>> ball = world.add_body(tumble.Sphere(0.1), density=1000.0, position=(0.0, 0.0, 1.0), name="ball")
>>> path = os.path.join(tempfile.mkdtemp(), "fall.h5")
>>> traj = tumble.recording.record(world, 0.1, 0.01, path, every=2)
>>> len(traj), traj.metadata["status"], traj.body_names
(6, 'complete', ['ball'])
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np

from . import trajectory_io, world_stepping
from ._validate import as_count, as_float, step_count
from .errors import SimulationError
from .trajectory import Trajectory
from .trajectory_io import FRAME_ARRAYS
from .vehicles import quadrotors

__all__ = ["TrajectoryWriter", "VehicleLog", "record", "default_chunk_frames"]

# A chunk of about 4 MiB of frames: large enough that writing it costs little next to the steps that made it,
# small enough that a failed run loses little (1000 bodies: 40 frames).
_CHUNK_BYTES = 4 << 20
_FRAME_VALUES_PER_BODY = 3 + 4 + 3 + 3


def default_chunk_frames(body_count: int) -> int:
    """Frames per chunk for ``body_count`` bodies: about 4 MiB, at least 16 and at most 1024 frames."""
    frame_bytes = 8 * (_FRAME_VALUES_PER_BODY * max(1, body_count) + 3)
    return int(min(1024, max(16, _CHUNK_BYTES // frame_bytes)))


def _scene_dict(scene) -> dict | None:
    """``scene`` as a dict: None, a dict (must be JSON-serialisable) or a JSON string of an object."""
    if scene is None:
        return None
    if isinstance(scene, str):
        try:
            scene = json.loads(scene)
        except json.JSONDecodeError as error:
            raise ValueError(f"scene must be a dict or a JSON string of one, got invalid JSON: {error}") from None
    if not isinstance(scene, dict):
        raise TypeError(f"scene must be a dict, a JSON string of one, or None, got {type(scene).__name__}")
    trajectory_io.metadata_to_json(scene)  # fail now, not at the first flush
    return scene


def run_metadata(world, *, dt: float | None, every: int, scene: dict | None) -> dict:
    """What a trajectory file says about the run that made it (``docs/files.md``)."""
    from ._version import __version__

    model = world.model
    metadata = {
        "tumble_version": __version__,
        "dt": dt,
        "integrator": world.integrator,
        "integrator_used": world._params.resolve_integrator(model.has_constraints).name.lower(),
        "solver": world.solver._asdict(),
        "record_every": every,
        "start_step": world.step_count,
        "start_time": world.time,
        "status": "running",
    }
    if scene is not None:
        metadata["scene"] = scene
    return metadata


class TrajectoryWriter:
    """Write a world's frames to ``path`` (``.h5``/``.hdf5``: HDF5; otherwise ``.npz``) chunk by chunk.

    Call :meth:`append` after each step (and once before the first): it keeps the frames whose step count,
    counted from the writer's creation, is a multiple of ``every``, and skips a step it already holds. It is a
    context manager; leaving the ``with`` block closes the file with status ``"complete"``, ``"interrupted"``
    (KeyboardInterrupt) or ``"failed"`` (any other exception) in its metadata.

    Args:
        path: the file to write (overwritten).
        world: the :class:`~tumble.World` to record; its body count must not change while recording.
        every: keep one frame every ``every`` steps.
        chunk_frames: frames buffered before each write (default :func:`default_chunk_frames`).
        scene: an optional scene description (a dict or a JSON string), stored in the metadata.
        dt: the step [s], stored in the metadata (set from the first trajectory given to :meth:`extend` if None).
        compression: HDF5 only: None (default: fastest), ``"lzf"`` or ``"gzip"``.
    """

    def __init__(self, path, world, *, every: int = 1, chunk_frames: int | None = None, scene=None,
                 dt: float | None = None, compression: str | None = None) -> None:  # fmt: skip
        self.path = Path(path)
        self.every = as_count("every", every)
        model = world.model
        self.body_count = model.body_count
        if chunk_frames is None:
            chunk_frames = default_chunk_frames(self.body_count)
        self.chunk_frames = as_count("chunk_frames", chunk_frames)
        if dt is not None:
            dt = as_float("dt", dt, positive=True)
        self.metadata = run_metadata(world, dt=dt, every=self.every, scene=_scene_dict(scene))
        self._static = {
            "body_mass": model.body_mass.copy(),
            "body_inertia": model.body_inertia_local.copy(),
            "body_com_local": model.body_com_local.copy(),
            "gravity": model.gravity.copy(),
        }
        self._names = [n or "" for n in model.body_name]
        self._start_step = world.step_count
        self._last_step: int | None = None
        self._pending: list[dict] = []  # frame blocks not yet written
        self._pending_count = 0
        self._written: list[dict] = []  # .npz only: every block written so far (the file is rewritten whole)
        self.frame_count = 0  # frames written to the file
        self.channels: dict[str, np.ndarray] = {}  # per-frame arrays written with the last frames (close)
        self._hdf5 = trajectory_io.is_hdf5_path(self.path)
        self._h5 = None
        if self._hdf5:
            self._h5 = trajectory_io.H5Frames(self.path, self._static, self._names, self.metadata,
                                              chunk_frames=self.chunk_frames, compression=compression)  # fmt: skip
        else:
            if compression is not None:
                raise ValueError(f"compression applies to HDF5 files only, got compression={compression!r} for "
                                 f"{os.fspath(path)!r}")  # fmt: skip
            self._rewrite_npz()
        self.closed = False

    # --- adding frames ------------------------------------------------------------------------------

    def append(self, world) -> bool:
        """Record the world's current state as a frame if its step is due; returns whether it was recorded."""
        self._check_open()
        steps = world.step_count - self._start_step
        if steps % self.every != 0 or world.step_count == self._last_step:
            return False
        model, state = world.model, world.state
        if model.body_count != self.body_count:
            raise ValueError(
                f"the world has {model.body_count} bodies but this recording was opened with {self.body_count}; "
                "start a new file after adding bodies"
            )
        frame = Trajectory.from_recording(model, state, Trajectory.allocate_recording(self.body_count, 0), 0,
                                          np.zeros(0), self.metadata["dt"] or math.nan)  # fmt: skip
        self._last_step = world.step_count
        self._add({k: getattr(frame, k) for k in FRAME_ARRAYS})
        return True

    def extend(self, trajectory: Trajectory) -> None:
        """Append every frame of ``trajectory`` (e.g. ``world.simulate(...)[1:]``, whose first frame repeats the
        state before the call)."""
        self._check_open()
        if trajectory.body_count != self.body_count:
            raise ValueError(
                f"the trajectory has {trajectory.body_count} bodies but this recording holds {self.body_count}"
            )
        if self.metadata["dt"] is None and "dt" in trajectory.metadata:
            self.metadata["dt"] = float(trajectory.metadata["dt"])
        if len(trajectory):
            self._add({k: getattr(trajectory, k) for k in FRAME_ARRAYS})

    def _add(self, block: dict) -> None:
        self._pending.append(block)
        self._pending_count += int(block["time"].shape[0])
        if self._pending_count >= self.chunk_frames:
            self.flush()

    # --- writing ------------------------------------------------------------------------------------

    def flush(self) -> None:
        """Write the buffered frames now (HDF5: append them and flush; ``.npz``: rewrite the file)."""
        self._check_open()
        if self._pending:
            self._write()

    def _write(self) -> None:
        """Write the buffered frames (if any) and the metadata."""
        block = None
        if self._pending:
            pending = self._pending
            block = (
                pending[0] if len(pending) == 1 else {k: np.concatenate([b[k] for b in pending]) for k in FRAME_ARRAYS}
            )
            self._pending, self._pending_count = [], 0
            self.frame_count += int(block["time"].shape[0])
        if self._hdf5:
            self._h5.set_metadata(self.metadata)
            self._h5.append(block if block is not None else {"time": np.zeros(0)})
            if self.channels:
                self._h5.write_channels(self.channels)
        else:
            if block is not None:
                self._written.append(block)
            self._rewrite_npz()

    def _rewrite_npz(self) -> None:
        if self._written:
            frames = {k: np.concatenate([b[k] for b in self._written]) for k in FRAME_ARRAYS}
            self._written = [frames]
        else:
            frames = {k: np.zeros((0, *self._frame_shape(k))) for k in FRAME_ARRAYS}
        trajectory_io.write_npz(self.path, {**frames, **self._static}, self._names, self.metadata,
                                channels=self.channels)  # fmt: skip

    def _frame_shape(self, name: str) -> tuple[int, ...]:
        return {"orientation": (self.body_count, 4), "time": (), "kinetic_energy": (), "potential_energy": ()}.get(
            name, (self.body_count, 3)
        )

    def close(self, status: str = "complete", error: str | None = None) -> None:
        """Write what is buffered, store ``status`` (and ``error``) in the metadata and close the file."""
        if self.closed:
            return
        self.metadata["status"] = status
        if error is not None:
            self.metadata["error"] = error
        try:
            self._write()
        finally:
            self.closed = True
            if self._h5 is not None:
                self._h5.close()

    def _check_open(self) -> None:
        if self.closed:
            raise ValueError(f"the trajectory writer of {os.fspath(self.path)!r} is closed")

    def __enter__(self) -> TrajectoryWriter:
        return self

    def __exit__(self, kind, value, traceback) -> None:
        if kind is None:
            self.close()
        elif issubclass(kind, KeyboardInterrupt):
            self.close("interrupted", "KeyboardInterrupt")
        else:
            self.close("failed", f"{kind.__name__}: {value}")

    def __repr__(self) -> str:
        state = "closed" if self.closed else "open"
        return f"TrajectoryWriter({os.fspath(self.path)!r}, {self.frame_count} frames written, {state})"


class VehicleLog:
    """The channels of a world's vehicles, sampled with the frames of a recording (one every ``every`` steps from
    now): for each vehicle ``vehicle/NAME/rotor_speeds`` and ``vehicle/NAME/commands`` (4,) [rad/s] and
    ``vehicle/NAME/reference`` (3,) [m], the position its trajectory asks for (NaN when none is flown). It samples
    from a world controller before each due step, and :meth:`sample` takes the state after the last one."""

    def __init__(self, world, every: int):
        self.every = every
        self._start = world.step_count
        self._vehicles = quadrotors(world)
        self._samples: list[list[np.ndarray]] = []
        self._last_step: int | None = None
        self._handle = world.add_controller(lambda world, t: self.sample(world), name="vehicle log")

    def sample(self, world) -> None:
        """Take the vehicles' values now if the step count is one of the frames' (once per step)."""
        if (world.step_count - self._start) % self.every or world.step_count == self._last_step:
            return
        self._last_step = world.step_count
        row = []
        for quad in self._vehicles:
            flight = quad._flight
            flying = flight is not None and flight.handle in world.controllers
            reference = flight.trajectory(world.time)["position"] if flying else np.full(3, np.nan)
            row.append(np.concatenate([quad.rotor_speeds, quad.commanded_rotor_speeds, reference]))
        self._samples.append(row)

    def stop(self) -> None:
        self._handle.remove()

    def channels(self, frames: int) -> dict[str, np.ndarray]:
        """The first ``frames`` samples of each channel."""
        values = np.array(self._samples[:frames], dtype=float).reshape(-1, len(self._vehicles), 11)
        out = {}
        for k, quad in enumerate(self._vehicles):
            name = quad.body.name or f"#{quad.body.index}"
            for what, columns in (("rotor_speeds", slice(0, 4)), ("commands", slice(4, 8)),
                                  ("reference", slice(8, 11))):  # fmt: skip
                out[f"vehicle/{name}/{what}"] = values[:, k, columns]
        return out


def record(world, duration: float, dt: float, path, *, every: int = 1, chunk_frames: int | None = None, scene=None,
           callback=None, compression: str | None = None, load: bool = True) -> Trajectory | None:  # fmt: skip
    """Simulate ``round(duration / dt)`` steps, writing every ``every``-th frame to ``path`` as the run goes.

    The world is stepped by ``world.simulate`` one chunk (``chunk_frames * every`` steps) at a time, so the
    stepping stays compiled; each chunk is written before the next begins. The results are bit for bit those
    of one ``world.simulate(duration, dt)`` call.

    Args:
        world: the :class:`~tumble.World` to advance.
        duration, dt: [s].
        path: ``.h5``/``.hdf5`` (HDF5, for long runs) or ``.npz``.
        every: record one frame every ``every`` steps (the first frame is the state before the first step).
        chunk_frames: frames per chunk (default :func:`default_chunk_frames`).
        scene: an optional scene description (dict or JSON string) stored in the file's metadata.
        callback: called as ``callback(world, writer)`` after each chunk is written (progress, checkpoints,
            stopping early by raising).
        compression: HDF5 only: None (default), ``"lzf"`` or ``"gzip"``.
        load: read the file back and return it; False returns None (a run larger than memory, or to save the
            time of reading it).

    Returns:
        The recorded :class:`~tumble.Trajectory`, read back from the file (None with ``load=False``).

    Raises:
        SimulationError: a step went non-finite. Every frame up to the last good step is written first, the file
            is closed with status ``"failed"``, and the error's ``trajectory`` holds what the file holds.
        KeyboardInterrupt: re-raised after the file is closed with status ``"interrupted"``; it holds every
            chunk written before the interruption.
    """
    duration = as_float("duration", duration, positive=True)
    dt = world_stepping.checked_step(world, dt)
    n_steps = step_count(duration, dt)
    writer = TrajectoryWriter(path, world, every=every, chunk_frames=chunk_frames, scene=scene, dt=dt,
                              compression=compression)  # fmt: skip
    log = VehicleLog(world, writer.every) if quadrotors(world) else None
    try:
        return _record_chunks(world, n_steps, dt, writer, log, callback, load)
    finally:
        if log is not None:
            log.stop()


def _record_chunks(world, n_steps: int, dt: float, writer: TrajectoryWriter, log: VehicleLog | None, callback,
                   load: bool) -> Trajectory | None:  # fmt: skip
    """:func:`record`'s loop: the chunks, each written before the next, and the vehicles' channels at the end."""
    with writer:
        writer.append(world)
        chunk_steps = writer.chunk_frames * writer.every
        done = 0
        while done < n_steps:
            steps = min(chunk_steps, n_steps - done)
            try:
                chunk = world.simulate(steps * dt, dt, record_every=writer.every)
            except SimulationError as error:
                writer.extend(error.trajectory[1:])
                if log is not None:
                    writer.channels = log.channels(writer.frame_count + writer._pending_count)
                writer.close("failed", str(error))
                error.trajectory = Trajectory.load(writer.path)
                error.path = writer.path
                raise
            writer.extend(chunk[1:])
            writer._last_step = world.step_count - (world.step_count - writer._start_step) % writer.every
            writer.flush()
            done += steps
            if callback is not None:
                callback(world, writer)
        if log is not None:
            log.sample(world)
            writer.channels = log.channels(writer.frame_count)
    return Trajectory.load(writer.path) if load else None
