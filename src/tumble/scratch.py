"""Scratch: reusable buffers of a world. Throwing them away never changes results."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .dynamics.contact_solver import ContactRows
from .dynamics.integrate import Recording, empty_recording
from .geometry.broad_phase import PairBuffer
from .geometry.manifold import MAX_POINTS, Manifolds

__all__ = ["Scratch"]


@dataclass(eq=False)
class Scratch:
    """Buffers sized to the body count, and growable contact buffers.

    Attributes:
        backup_pos, backup_quat, backup_linvel, backup_angmom: the state before the current call, kept so that a
            failed free-motion step can be undone.
        failed_step: (body_count,) int64, the step at which each body became non-finite (-1: none).
        no_recording: zero-frame recording for calls that record nothing.
        body_angvel: (body_count, 3) ω during a contact step [rad/s], world frame.
        body_inv_inertia_world: (body_count, 3, 3) ``R I⁻¹ Rᵀ`` at the start of the contact step.
        manifolds, rows, warm_normal, warm_tangent: contact buffers, grown as needed.
        fresh: manifolds found again within a step (as many rows as ``manifolds``).
        stored: the contact state's arrays (``State.contact_*``, in that order) with as many rows as ``manifolds``:
            the step writes its impulses here, and the state keeps the rows in use.
        contact_count: manifolds in use after the last contact step (``World.contacts`` reads them).
        steps_found_again: the contact steps in which some pairs found their contacts again within the step (fast
            pairs, ``narrow_phase.contact_passes``): a count for diagnosis and tests.
        aabb_lo, aabb_hi: (shape_count, 3) world bounds of the shapes; pairs: the broad phase's output buffer.
        island_parent, island_min_time: (body_count,) union-find work arrays of the sleep pass.
        joint_force_total, joint_moment_total: (joint_count, 3) linear and angular impulses each joint gave its
            body b over the last contact step [N s, N m s]; joint_step: that step's length [s] (0: none yet).
        compiled: ``(objects, compiled_world.Compiled)``: the world's arrays as one compiled object, kept for the
            next step while the ``objects`` it was built from stay the same (``compiled_world.compiled_world``); None
            after the buffers grew.
        ready: the ``World.step`` of a world without Python parts, prepared (``runner.ReadyStep``); None until a step
            made it, and after anything it does not check changed.
        contacts_left: ``(ids, arrays)``: the ``State.contact_*`` arrays the last contact call left, views of the
            first rows of :attr:`stored` (while the state holds them, the next call need not copy them back).
    """

    backup_pos: np.ndarray
    backup_quat: np.ndarray
    backup_linvel: np.ndarray
    backup_angmom: np.ndarray
    failed_step: np.ndarray
    no_recording: Recording
    body_angvel: np.ndarray
    body_inv_inertia_world: np.ndarray
    manifolds: Manifolds = field(default_factory=lambda: Manifolds.allocate(1))
    rows: ContactRows = field(default_factory=lambda: ContactRows.allocate(1))
    warm_normal: np.ndarray = field(default_factory=lambda: np.zeros((1, MAX_POINTS)))
    warm_tangent: np.ndarray = field(default_factory=lambda: np.zeros((1, MAX_POINTS, 3)))
    fresh: Manifolds = field(default_factory=lambda: Manifolds.allocate(1))
    stored: tuple = field(default_factory=lambda: _stored_contacts(1))
    contact_count: int = 0
    steps_found_again: int = 0
    aabb_lo: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    aabb_hi: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    pairs: PairBuffer = field(default_factory=PairBuffer)
    island_parent: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    island_min_time: np.ndarray = field(default_factory=lambda: np.zeros(0))
    joint_force_total: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    joint_moment_total: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    joint_step: float = 0.0
    compiled: tuple | None = None
    ready: object | None = None
    contacts_left: tuple = ((), ())

    def __getstate__(self) -> dict:
        """A copy or a pickle without the compiled record (a Numba object that neither copies nor pickles, and would
        hold the original's arrays), the prepared step holding it, and the ids of the state's contact views: the copy
        builds its own."""
        return {**self.__dict__, "compiled": None, "ready": None, "contacts_left": ((), ())}

    @classmethod
    def for_world(cls, body_count: int, shape_count: int, joint_count: int = 0) -> Scratch:
        scratch = cls(
            np.zeros((body_count, 3)), np.zeros((body_count, 4)), np.zeros((body_count, 3)),
            np.zeros((body_count, 3)), np.full(body_count, -1, dtype=np.int64), empty_recording(body_count),
            np.zeros((body_count, 3)), np.zeros((body_count, 3, 3)),
        )  # fmt: skip
        scratch.aabb_lo, scratch.aabb_hi = np.zeros((shape_count, 3)), np.zeros((shape_count, 3))
        scratch.island_parent = np.zeros(body_count, np.int64)
        scratch.island_min_time = np.zeros(body_count)
        scratch.joint_force_total, scratch.joint_moment_total = np.zeros((joint_count, 3)), np.zeros((joint_count, 3))
        return scratch

    @property
    def backup(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        return self.backup_pos, self.backup_quat, self.backup_linvel, self.backup_angmom

    def reserve_contacts(self, pair_count: int, keep: int = 0) -> None:
        """Grow the pair and contact buffers to hold one manifold per candidate pair (doubling, never shrinking),
        keeping the first ``keep`` rows of :attr:`stored`."""
        pairs = self.pairs.a
        self.pairs.reserve(pair_count)
        if self.pairs.a is not pairs:
            self.compiled = self.ready = None  # they hold the buffers replaced
        capacity = self.manifolds.shape_a.shape[0]
        if pair_count > capacity:
            capacity = max(pair_count, 2 * capacity)
            self.manifolds = Manifolds.allocate(capacity)
            self.fresh = Manifolds.allocate(capacity)
            stored, self.stored = self.stored, _stored_contacts(capacity)
            for old, new in zip(stored, self.stored, strict=True):
                new[:keep] = old[:keep]
            self.rows = ContactRows.allocate(capacity)
            self.warm_normal = np.zeros((capacity, MAX_POINTS))
            self.warm_tangent = np.zeros((capacity, MAX_POINTS, 3))
            self.compiled = self.ready = None


def _stored_contacts(capacity: int) -> tuple[np.ndarray, ...]:
    """Room for ``capacity`` manifolds of the contact state, in the order of ``state.CONTACT_FIELDS``."""
    return (np.zeros(capacity, np.int64), np.zeros(capacity, np.int64), np.zeros(capacity, np.int64),
            np.zeros((capacity, MAX_POINTS), np.int64), np.zeros((capacity, MAX_POINTS)),
            np.zeros((capacity, MAX_POINTS, 3)))  # fmt: skip
