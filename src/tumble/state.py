"""State: what the world *is doing*. Enough to resume a run bit for bit.

``body_pos`` is the centre of mass in the world frame (the public ``Body.position`` is the body frame's
origin, computed from it); ``body_quat`` the orientation ``[w, x, y, z]``; ``body_linvel`` the COM
velocity; ``body_angmom`` the world-frame angular velocity.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

__all__ = ["State"]

_FIELDS = ("body_pos", "body_quat", "body_linvel", "body_angmom")


@dataclass(eq=False)
class State:
    """Dynamic arrays of a world.

    Attributes:
        body_pos: (body_count, 3) float64 [m], centre of mass, world frame.
        body_quat: (body_count, 4) float64, unit quaternion ``[w, x, y, z]``, body to world.
        body_linvel: (body_count, 3) float64 [m/s], COM velocity, world frame.
        body_angmom: (body_count, 3) float64 [rad/s], world frame.
        time: simulated time [s].
        step_count: number of steps taken.
    """

    body_pos: np.ndarray
    body_quat: np.ndarray
    body_linvel: np.ndarray
    body_angmom: np.ndarray
    time: float = 0.0
    step_count: int = 0

    @classmethod
    def empty(cls, body_count: int = 0) -> State:
        quat = np.zeros((body_count, 4))
        quat[:, 0] = 1.0
        zeros3 = np.zeros((body_count, 3))
        return cls(zeros3.copy(), quat, zeros3.copy(), zeros3.copy())

    @property
    def body_count(self) -> int:
        return int(self.body_pos.shape[0])

    def copy(self) -> State:
        return State(*(getattr(self, f).copy() for f in _FIELDS), time=self.time, step_count=self.step_count)

    def assign(self, other: State) -> None:
        """Overwrite this state with ``other`` in place (views held by users stay valid)."""
        for f in _FIELDS:
            np.copyto(getattr(self, f), getattr(other, f))
        self.time = other.time
        self.step_count = other.step_count

    def digest(self) -> str:
        """sha256 over the arrays (fixed field order), the time and the step count."""
        h = hashlib.sha256()
        for f in _FIELDS:
            h.update(np.ascontiguousarray(getattr(self, f), dtype=np.float64).tobytes())
        h.update(np.float64(self.time).tobytes())
        h.update(np.int64(self.step_count).tobytes())
        return h.hexdigest()

    def arrays(self) -> dict[str, np.ndarray]:
        return {f: getattr(self, f) for f in _FIELDS}
