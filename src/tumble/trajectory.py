"""Trajectory: the recorded frames of a run, as arrays, with energies; saved and loaded as ``.npz``."""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from . import diagnostics
from .dynamics.integrate import Recording
from .rotation import quat_rotate

__all__ = ["Trajectory"]

_ARRAYS = (
    "time", "position", "orientation", "velocity", "angular_velocity", "kinetic_energy", "potential_energy",
    "body_mass", "body_inertia", "body_com_local", "gravity",
)  # fmt: skip


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

    # --- building (used by World.simulate) ----------------------------------------------------------

    @staticmethod
    def allocate_recording(body_count: int, frames: int) -> Recording:
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
        omega = diagnostics.world_tensor_apply(model.body_inv_inertia_local, quat, angmom)
        mass, inertia = model.body_mass, model.body_inertia_local
        from . import __version__

        return cls(
            time=np.concatenate([[initial.time], times]),
            position=com - quat_rotate(quat, np.broadcast_to(model.body_com_local, com.shape)),
            orientation=quat,
            velocity=vel,
            angular_velocity=omega,
            kinetic_energy=diagnostics.kinetic_energy(mass, vel, omega, angmom).sum(axis=-1),
            potential_energy=diagnostics.potential_energy(mass, com, model.gravity).sum(axis=-1),
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

    # --- files --------------------------------------------------------------------------------------

    def save(self, path: str | os.PathLike) -> None:
        """Write a compressed ``.npz`` (readable with ``numpy.load`` alone)."""
        arrays = {k: getattr(self, k) for k in _ARRAYS}
        np.savez_compressed(
            path,
            **arrays,
            body_names=np.array(self.body_names, dtype=str),
            metadata_keys=np.array(list(self.metadata), dtype=str),
            metadata_values=np.array([str(v) for v in self.metadata.values()], dtype=str),
        )

    @classmethod
    def load(cls, path: str | os.PathLike) -> Trajectory:
        """Read a file written by :meth:`save`."""
        with np.load(path, allow_pickle=False) as data:
            missing = [k for k in _ARRAYS if k not in data]
            if missing:
                raise ValueError(f"{os.fspath(path)!r} is not a tumble trajectory: missing arrays {missing}")
            arrays = {k: data[k] for k in _ARRAYS}
            names = [str(n) for n in data["body_names"]]
            metadata = dict(zip(map(str, data["metadata_keys"]), map(str, data["metadata_values"]), strict=True))
        if "dt" in metadata:
            metadata["dt"] = float(metadata["dt"])
        return cls(**arrays, body_names=names, metadata=metadata)
