"""State: what the world *is doing*. Enough to resume a run bit for bit.

``body_pos`` is the centre of mass in the world frame (the public ``Body.position`` is the body frame's
origin, computed from it); ``body_quat`` the orientation ``[w, x, y, z]``; ``body_linvel`` the COM velocity;
``body_angmom`` the angular momentum ``L = R I Rᵀ ω`` about the COM, world frame. Angular momentum, not
velocity, is the state (as in the course's state vector ``(x, A, p, L)``): with no torque it stays exactly
constant. ``Body.angular_velocity`` computes ``ω = R I⁻¹ Rᵀ L``.

The ``contact_*`` arrays are the impulses of the last step's contact points, kept to warm-start the next
step; they are sorted by shape pair and change size every step. After a step they are views of the rows the next
step reads and overwrites, as the body arrays are (``copy()`` keeps a snapshot). The ``joint_*`` arrays are the joints'
accumulated impulses, one row per joint, kept for the same reason.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np

from .geometry.manifold import MAX_POINTS

__all__ = ["BODY_FIELDS", "CONTACT_FIELDS", "JOINT_FIELDS", "State"]

BODY_FIELDS = (
    "body_pos",
    "body_quat",
    "body_linvel",
    "body_angmom",
    "body_sleep_time",
    "body_sleeping",
    "body_island",
)
CONTACT_FIELDS = (
    "contact_shape_a",
    "contact_shape_b",
    "contact_point_count",
    "contact_feature",
    "contact_normal_impulse",
    "contact_tangent_impulse",
)

JOINT_FIELDS = ("joint_linear_impulse", "joint_angular_impulse", "joint_drive_impulse")
_JOINT_WIDTHS = (3, 3, 5)
# Fields replaced (not written in place) when they change size: contacts every step, joints when added.
_SIZED_FIELDS = CONTACT_FIELDS + JOINT_FIELDS


def _no_contacts() -> dict[str, np.ndarray]:
    return {
        "contact_shape_a": np.zeros(0, np.int64),
        "contact_shape_b": np.zeros(0, np.int64),
        "contact_point_count": np.zeros(0, np.int64),
        "contact_feature": np.zeros((0, MAX_POINTS), np.int64),
        "contact_normal_impulse": np.zeros((0, MAX_POINTS)),
        "contact_tangent_impulse": np.zeros((0, MAX_POINTS, 3)),
    }


@dataclass(eq=False)
class State:
    """Dynamic arrays of a world.

    Attributes:
        body_pos: (body_count, 3) float64 [m], centre of mass, world frame.
        body_quat: (body_count, 4) float64, unit quaternion ``[w, x, y, z]``, body to world.
        body_linvel: (body_count, 3) float64 [m/s], COM velocity, world frame.
        body_angmom: (body_count, 3) float64 [kg m²/s], about the COM, world frame.
        body_sleep_time: (body_count,) float64 [s] the body has been slower than the sleep thresholds.
        body_sleeping: (body_count,) bool; a sleeping body is not moved until it is woken.
        body_island: (body_count,) int64, the root body of the island it last slept in (-1: none).
        time: simulated time [s].
        step_count: number of steps taken.
        contact_shape_a, contact_shape_b: (K,) int64 shape rows of the last step's manifolds.
        contact_point_count: (K,) int64.
        contact_feature: (K, 4) int64 feature ids of the points.
        contact_normal_impulse: (K, 4) float64 [N s] of the last substep.
        contact_tangent_impulse: (K, 4, 3) float64 [N s], friction impulses as world vectors.
    """

    body_pos: np.ndarray
    body_quat: np.ndarray
    body_linvel: np.ndarray
    body_angmom: np.ndarray
    body_sleep_time: np.ndarray = field(default_factory=lambda: np.zeros(0))
    body_sleeping: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))
    body_island: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    time: float = 0.0
    step_count: int = 0
    contact_shape_a: np.ndarray = field(default_factory=lambda: _no_contacts()["contact_shape_a"])
    contact_shape_b: np.ndarray = field(default_factory=lambda: _no_contacts()["contact_shape_b"])
    contact_point_count: np.ndarray = field(default_factory=lambda: _no_contacts()["contact_point_count"])
    contact_feature: np.ndarray = field(default_factory=lambda: _no_contacts()["contact_feature"])
    contact_normal_impulse: np.ndarray = field(default_factory=lambda: _no_contacts()["contact_normal_impulse"])
    contact_tangent_impulse: np.ndarray = field(default_factory=lambda: _no_contacts()["contact_tangent_impulse"])
    joint_linear_impulse: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    joint_angular_impulse: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    joint_drive_impulse: np.ndarray = field(default_factory=lambda: np.zeros((0, 5)))

    @classmethod
    def empty(cls, body_count: int = 0) -> State:
        quat = np.zeros((body_count, 4))
        quat[:, 0] = 1.0
        zeros3 = np.zeros((body_count, 3))
        return cls(
            zeros3.copy(), quat, zeros3.copy(), zeros3.copy(), np.zeros(body_count), np.zeros(body_count, bool),
            np.full(body_count, -1, np.int64),
        )  # fmt: skip

    def grown(self, pos, quat, linvel, angmom) -> State:
        """A new state with rows appended for new bodies (awake, at the given poses and momenta)."""
        new = State.empty(len(pos))
        new.body_pos[:], new.body_quat[:], new.body_linvel[:], new.body_angmom[:] = pos, quat, linvel, angmom
        arrays = {f: np.concatenate([getattr(self, f), getattr(new, f)]) for f in BODY_FIELDS}
        kept = {f: getattr(self, f) for f in _SIZED_FIELDS}  # shapes and joints are only appended: rows stay valid
        return State(**arrays, **kept, time=self.time, step_count=self.step_count)

    def with_joints(self, joint_count: int) -> None:
        """Append zero impulses for joints added since (rows of existing joints are kept)."""
        if self.joint_drive_impulse.shape[0] == joint_count:  # before every step: the usual case costs one check
            return
        for name, width in zip(JOINT_FIELDS, _JOINT_WIDTHS, strict=True):
            old = getattr(self, name)
            if old.shape[0] < joint_count:
                setattr(self, name, np.concatenate([old, np.zeros((joint_count - old.shape[0], width))]))

    @property
    def joint_impulses(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(linear (J, 3), angular (J, 3), drive (J, 5))`` as the joint kernels take them."""
        return self.joint_linear_impulse, self.joint_angular_impulse, self.joint_drive_impulse

    @property
    def contact_arrays(self) -> tuple[np.ndarray, ...]:
        """The ``contact_*`` arrays in the order of :data:`CONTACT_FIELDS`."""
        return (self.contact_shape_a, self.contact_shape_b, self.contact_point_count, self.contact_feature,
                self.contact_normal_impulse, self.contact_tangent_impulse)  # fmt: skip

    @property
    def body_count(self) -> int:
        return int(self.body_pos.shape[0])

    @property
    def contact_count(self) -> int:
        return int(self.contact_shape_a.shape[0])

    def copy(self) -> State:
        arrays = {f: getattr(self, f).copy() for f in BODY_FIELDS + _SIZED_FIELDS}
        return State(**arrays, time=self.time, step_count=self.step_count)

    def assign(self, other: State) -> None:
        """Overwrite this state with ``other``: body arrays in place (views held by users stay valid)."""
        for f in BODY_FIELDS:
            np.copyto(getattr(self, f), getattr(other, f))
        for f in _SIZED_FIELDS:
            setattr(self, f, getattr(other, f).copy())
        self.time = other.time
        self.step_count = other.step_count

    def forget_contacts(self) -> None:
        """Drop the warm-start impulses (after the shapes changed)."""
        for name, value in _no_contacts().items():
            setattr(self, name, value)

    def digest(self) -> str:
        """sha256 over the arrays (fixed field order), the time and the step count."""
        h = hashlib.sha256()
        for f in BODY_FIELDS + _SIZED_FIELDS:
            array = getattr(self, f)
            h.update(str(array.shape).encode())
            h.update(np.ascontiguousarray(array).tobytes())
        h.update(np.float64(self.time).tobytes())
        h.update(np.int64(self.step_count).tobytes())
        return h.hexdigest()

    def body_arrays(self) -> dict[str, np.ndarray]:
        return {f: getattr(self, f) for f in BODY_FIELDS}
