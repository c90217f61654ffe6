"""Scratch: reusable buffers of a world. Throwing them away never changes results."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .dynamics.integrate import Recording, empty_recording

__all__ = ["Scratch"]


@dataclass(eq=False)
class Scratch:
    """Buffers sized to the body count.

    Attributes:
        backup_pos, backup_quat, backup_linvel, backup_angmom: the state before the current call, kept so
            that a failed step can be undone.
        failed_step: (body_count,) int64, the step at which each body became non-finite (-1: none).
        no_recording: zero-frame recording for calls that record nothing.
    """

    backup_pos: np.ndarray
    backup_quat: np.ndarray
    backup_linvel: np.ndarray
    backup_angmom: np.ndarray
    failed_step: np.ndarray
    no_recording: Recording

    @classmethod
    def for_bodies(cls, body_count: int) -> Scratch:
        return cls(
            np.zeros((body_count, 3)), np.zeros((body_count, 4)), np.zeros((body_count, 3)),
            np.zeros((body_count, 3)), np.full(body_count, -1, dtype=np.int64), empty_recording(body_count),
        )  # fmt: skip

    @property
    def backup(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        return self.backup_pos, self.backup_quat, self.backup_linvel, self.backup_angmom
