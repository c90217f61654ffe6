"""Trajectory: the recorded frames of a run, as arrays, with energies; saved and loaded as ``.npz`` or HDF5
(``trajectory_io.py``, ``docs/files.md``) and exported as CSV."""

from __future__ import annotations

import csv
import os
from dataclasses import dataclass, field

import numpy as np

from . import diagnostics, trajectory_io
from ._validate import require_memory
from .dynamics.integrate import Recording
from .handles import Body
from .rotation import quat_rotate
from .trajectory_io import FRAME_ARRAYS, STATIC_ARRAYS

__all__ = ["Trajectory"]

# From this many bodies on, ω of each frame comes from the step's compiled kernel (0.03 ms a frame for 1000 bodies,
# against 0.5 ms in NumPy, measured); below it the kernel's 3 µs call overhead per frame costs more than it saves.
_KERNEL_MIN_BODIES = 16


def _angular_velocities(model, quat: np.ndarray, angmom: np.ndarray) -> np.ndarray:
    """ω = R I⁻¹ Rᵀ L for (T, N) frames: (T, N, 3) [rad/s], world frame."""
    from .dynamics.substep import to_angular_velocity

    # NumPy for few bodies, and when the kernel is plain Python (NUMBA_DISABLE_JIT=1: no dispatcher).
    if model.body_count < _KERNEL_MIN_BODIES or not hasattr(to_angular_velocity, "py_func"):
        return diagnostics.world_tensor_apply(model.body_inv_inertia_local, quat, angmom)

    omega = np.empty_like(angmom)
    inv_inertia_world = np.empty((model.body_count, 3, 3))  # also written by the kernel; not needed here
    for t in range(quat.shape[0]):
        to_angular_velocity(model.body_arrays, quat[t], angmom[t], omega[t], inv_inertia_world)
    return omega


def _to_frame_origins(com_local: np.ndarray, com: np.ndarray, quat: np.ndarray) -> np.ndarray:
    """Turn the COMs ``com`` (T, N, 3) [m] into the body frames' origins ``x_com − R c``, in place (no copy of a
    large array: fresh pages cost more than the arithmetic). Only bodies whose COM is off the frame origin are
    rotated (a box's is not), which saves most of the work in piles of primitives."""
    offset = np.flatnonzero(np.any(com_local != 0.0, axis=1))
    if offset.size:
        local = np.broadcast_to(com_local[offset], (com.shape[0], offset.size, 3))
        com[:, offset] -= quat_rotate(quat[:, offset], local)
    return com


RECORDED_FLOATS = 3 + 4 + 3 + 3  # per body and frame: position, orientation, velocity, angular momentum


CSV_COLUMNS = ("time", "body", "x", "y", "z", "qw", "qx", "qy", "qz", "vx", "vy", "vz", "wx", "wy", "wz")


@dataclass(eq=False)
class Trajectory:
    """Frames ``T`` of ``N`` bodies (static ones included), world frame.

    Attributes:
        time: (T,) [s].
        position: (T, N, 3) [m], the body frame's origin (as ``Body.position``).
        orientation: (T, N, 4), ``[w, x, y, z]``.
        velocity: (T, N, 3) [m/s], of the centre of mass.
        angular_velocity: (T, N, 3) [rad/s], world frame.
        kinetic_energy, potential_energy: (T,) [J], summed over bodies.
        body_mass: (N,) [kg]; body_inertia: (N, 3, 3) about the COM, body frame; body_com_local: (N, 3).
        gravity: (3,) [m/s²]; body_names: N names (``""`` where unnamed); metadata: dt, integrator, version.
        channels: other per-frame arrays by name, each (T, ...): a recording of a world with vehicles holds
            ``vehicle/NAME/rotor_speeds``, ``vehicle/NAME/commands`` (4,) [rad/s] and ``vehicle/NAME/reference``
            (3,) [m] (NaN while no trajectory is flown); see ``tumble.recording``.
    """

    time: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    kinetic_energy: np.ndarray
    potential_energy: np.ndarray
    body_mass: np.ndarray
    body_inertia: np.ndarray
    body_com_local: np.ndarray
    gravity: np.ndarray
    body_names: list[str] = field(default_factory=list)
    metadata: dict = field(default_factory=dict)
    channels: dict = field(default_factory=dict)

    # --- building (used by World.simulate) ----------------------------------------------------------

    @staticmethod
    def allocate_recording(body_count: int, frames: int) -> Recording:
        """Room for ``frames`` frames of ``body_count`` bodies.

        Raises:
            ValueError: the recording and the trajectory made from it (about twice the recording) would not fit
                in this machine's memory; the message says how much they would take.
        """
        need = 2 * frames * body_count * RECORDED_FLOATS * 8  # [bytes] the recording, then the trajectory
        require_memory(need, f"recording {frames} frames of {body_count} bodies (and the trajectory made from them)",
                       "record fewer frames (a larger record_every, a shorter duration) or stream them to a file "
                       "(tumble.recording.record)")  # fmt: skip
        return Recording(
            np.empty((frames, body_count, 3)), np.empty((frames, body_count, 4)),
            np.empty((frames, body_count, 3)), np.empty((frames, body_count, 3)),
        )  # fmt: skip

    @classmethod
    def from_recording(cls, model, initial, recording: Recording, frames: int, times, dt: float) -> Trajectory:
        """The initial state followed by the first ``frames`` recorded frames."""

        def stack(first, recorded):
            return np.concatenate([first[None], recorded[:frames]])

        com = stack(initial.body_pos, recording.pos)
        quat = stack(initial.body_quat, recording.quat)
        vel = stack(initial.body_linvel, recording.linvel)
        angmom = stack(initial.body_angmom, recording.angmom)
        omega = _angular_velocities(model, quat, angmom)
        mass, inertia = model.body_mass, model.body_inertia_local
        potential = diagnostics.potential_energy(mass, com, model.gravity).sum(axis=-1)  # before com becomes origins
        from ._version import __version__

        return cls(
            time=np.concatenate([[initial.time], times]),
            position=_to_frame_origins(model.body_com_local, com, quat),
            orientation=quat,
            velocity=vel,
            angular_velocity=omega,
            kinetic_energy=diagnostics.kinetic_energy(mass, vel, omega, angmom).sum(axis=-1),
            potential_energy=potential,
            body_mass=mass.copy(),
            body_inertia=inertia.copy(),
            body_com_local=model.body_com_local.copy(),
            gravity=model.gravity.copy(),
            body_names=[n or "" for n in model.body_name],
            metadata={"dt": float(dt), "tumble_version": __version__},
        )

    # --- derived ------------------------------------------------------------------------------------

    def __len__(self) -> int:
        return int(self.time.shape[0])

    @property
    def body_count(self) -> int:
        return int(self.position.shape[1])

    @property
    def total_energy(self) -> np.ndarray:
        """(T,) [J]."""
        return self.kinetic_energy + self.potential_energy

    @property
    def translational_energy(self) -> np.ndarray:
        """(T,) [J]: Σ ½ m |v|² over the bodies."""
        return 0.5 * np.einsum("n,tni,tni->t", self.body_mass, self.velocity, self.velocity)

    @property
    def rotational_energy(self) -> np.ndarray:
        """(T,) [J]: Σ ½ ω·L over the bodies, ``L = R I Rᵀ ω`` (so translational + rotational = kinetic)."""
        angmom = diagnostics.world_tensor_apply(self.body_inertia, self.orientation, self.angular_velocity)
        return 0.5 * np.einsum("tni,tni->t", self.angular_velocity, angmom)

    @property
    def center_of_mass(self) -> np.ndarray:
        """(T, N, 3) [m]: each body's COM."""
        return self.position + quat_rotate(self.orientation, np.broadcast_to(self.body_com_local, self.position.shape))

    def linear_momentum(self) -> np.ndarray:
        """(T, 3) [kg m/s]."""
        return diagnostics.linear_momentum(self.body_mass, self.velocity)

    def angular_momentum(self, point=(0.0, 0.0, 0.0)) -> np.ndarray:
        """(T, 3) [kg m²/s] about ``point``."""
        angmom = diagnostics.world_tensor_apply(self.body_inertia, self.orientation, self.angular_velocity)
        return diagnostics.angular_momentum(self.body_mass, self.center_of_mass, self.velocity, angmom, point)

    def angular_velocity_body(self) -> np.ndarray:
        """(T, N, 3) [rad/s]: ω in each body's frame."""
        from .rotation import quat_conjugate

        return quat_rotate(quat_conjugate(self.orientation), self.angular_velocity)

    def body_index(self, name: str) -> int:
        try:
            return self.body_names.index(name)
        except ValueError:
            raise KeyError(f"no body named {name!r} in this trajectory; names: {self.body_names}") from None

    # --- selecting ----------------------------------------------------------------------------------

    def __getitem__(self, frames: slice) -> Trajectory:
        """The frames ``frames`` (a slice) as a new trajectory sharing the per-body arrays."""
        if not isinstance(frames, slice):
            raise TypeError(f"a trajectory is indexed by a slice of frames (traj[10:20]), got {frames!r}")
        picked = {k: getattr(self, k)[frames] for k in FRAME_ARRAYS}
        return Trajectory(**picked, **{k: getattr(self, k) for k in STATIC_ARRAYS},
                          body_names=list(self.body_names), metadata=dict(self.metadata),
                          channels={k: v[frames] for k, v in self.channels.items()})  # fmt: skip

    def select_bodies(self, bodies=None, *, dynamic_only: bool = False) -> list[int]:
        """Body indices from ``bodies``: None (all bodies, or all dynamic ones with ``dynamic_only``), or a name,
        an index, a :class:`~tumble.Body`, or a list of those."""
        if bodies is None:
            rows = range(self.body_count)
            return [i for i in rows if self.body_mass[i] > 0.0] if dynamic_only else list(rows)
        items = [bodies] if isinstance(bodies, (str, int, np.integer, Body)) else bodies
        rows = []
        for item in items:
            if isinstance(item, str):
                rows.append(self.body_index(item))
            elif isinstance(item, (int, np.integer)) and not isinstance(item, bool):
                if not -self.body_count <= int(item) < self.body_count:
                    raise IndexError(f"bodies: index {int(item)} is out of range for {self.body_count} bodies")
                rows.append(int(item) % self.body_count)
            elif isinstance(item, Body):
                rows.append(item.index)
            else:
                raise TypeError(f"bodies must hold names, indices or Body handles, got {item!r}")
        return rows

    def body_label(self, index: int) -> str:
        """The body's name, or ``"#index"`` when it has none."""
        name = self.body_names[index] if index < len(self.body_names) else ""
        return name or f"#{index}"

    # --- files --------------------------------------------------------------------------------------

    def save(self, path: str | os.PathLike, *, compression: str | None = "gzip") -> None:
        """Write the trajectory: HDF5 when ``path`` ends in ``.h5``/``.hdf5`` (``compression`` None, ``"gzip"``
        or ``"lzf"``), else a compressed ``.npz`` (readable with ``numpy.load`` alone; ``.npz`` is appended to a
        name without it, as numpy does). ``docs/files.md`` lists the arrays and the metadata."""
        arrays = {k: getattr(self, k) for k in FRAME_ARRAYS + STATIC_ARRAYS}
        if trajectory_io.is_hdf5_path(path):
            trajectory_io.write_h5(path, arrays, self.body_names, self.metadata, compression=compression,
                                   channels=self.channels)  # fmt: skip
            return
        path = os.fspath(path)
        if not path.endswith(".npz"):
            path += ".npz"
        trajectory_io.write_npz(path, arrays, self.body_names, self.metadata, channels=self.channels)

    @classmethod
    def load(cls, path: str | os.PathLike) -> Trajectory:
        """Read a trajectory from an ``.npz`` or HDF5 file (written by :meth:`save` or by
        :func:`tumble.recording.record`); no World is needed."""
        arrays, names, metadata = trajectory_io.read(path)
        return cls(**arrays, body_names=names, metadata=metadata)

    def to_csv(self, path: str | os.PathLike, bodies=None) -> None:
        """Write one row per frame and body: ``time, body, x, y, z, qw, qx, qy, qz, vx, vy, vz, wx, wy, wz``.

        ``bodies``: as :meth:`select_bodies` (default: every body). ``body`` is the name (``#index`` when unnamed);
        positions are the body frame's origin, ``v`` the COM velocity, ``w`` the world-frame angular velocity.
        Numbers are written in full precision (they read back to the same float64).
        """
        rows = self.select_bodies(bodies)
        labels = [self.body_label(i) for i in rows]
        block = np.concatenate(
            [self.position[:, rows], self.orientation[:, rows], self.velocity[:, rows],
             self.angular_velocity[:, rows]], axis=-1,
        ).tolist()  # fmt: skip
        with open(path, "w", newline="", encoding="utf-8") as f:
            writer = csv.writer(f)
            writer.writerow(CSV_COLUMNS)
            for t, frame in zip(self.time.tolist(), block, strict=True):
                writer.writerows([t, label, *values] for label, values in zip(labels, frame, strict=True))
