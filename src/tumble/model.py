"""Model: what the world *is* — masses, inertias, shapes, materials. Built once by the builder.

Structure of arrays, prefix-named (``body_*``, ``shape_*``). Constant during a step; rebuilt by
:class:`~tumble.builder.ModelBuilder` when bodies are added.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np

from .dynamics.joint_solver import JointArrays
from .geometry.packing import GeometryArrays

__all__ = ["Model", "BodyArrays"]


class BodyArrays(NamedTuple):
    """The model's per-body arrays that the integrators read (a NamedTuple Numba accepts)."""

    mass: np.ndarray  # (n,) [kg]
    inv_mass: np.ndarray  # (n,) [1/kg]
    inertia_local: np.ndarray  # (n, 3, 3) [kg m²]
    inv_inertia_local: np.ndarray  # (n, 3, 3)
    is_dynamic: np.ndarray  # (n,) bool
    linear_damping: np.ndarray  # (n,) [1/s]
    angular_damping: np.ndarray  # (n,) [1/s]
    constant_force: np.ndarray  # (n, 3) [N] world frame, at the COM, every step
    constant_torque: np.ndarray  # (n, 3) [N m] world frame, every step


@dataclass(frozen=True, eq=False)
class Model:
    """Static arrays of a world.

    Attributes:
        gravity: (3,) float64 [m/s²], world frame.
        body_mass: (body_count,) float64 [kg]; 0 for static bodies.
        body_inv_mass: (body_count,) float64 [1/kg]; 0 for static bodies.
        body_inertia_local: (body_count, 3, 3) float64 [kg m²], about the COM, body frame.
        body_inv_inertia_local: (body_count, 3, 3) float64; zeros for static bodies.
        body_com_local: (body_count, 3) float64 [m], the COM in the body frame (from the frame origin).
        body_is_dynamic: (body_count,) bool.
        body_linear_damping, body_angular_damping: (body_count,) float64 [1/s].
        body_name: body names (``None`` where unnamed), in row order.
        geometry: every shape packed for the collision kernels (:class:`~tumble.geometry.packing.GeometryArrays`);
            ``model.shape_body``, ``shape_type``, ``shape_params``, ``shape_pos_local`` and ``shape_quat_local``
            read from it.
        shape_friction, shape_restitution: (shape_count,) float64.
        shape_rolling: (shape_count,) float64 [m], rolling resistance times the shape's rolling radius.
        shape_core_radius: (shape_count,) float64 [m], a sphere's or capsule's radius round its core, else 0.
        shape_group, shape_mask: (shape_count,) uint32 collision filter bits.
        has_contacts: whether two shapes of different bodies can touch (then the contact solver steps).
        shapes: the shape objects, in row order (for geometry that does not fit the arrays).
        body_constant_force, body_constant_torque: (body_count, 3) [N], [N m] loads that act in every step (world
            frame; the force at the centre of mass), set with ``Body.constant_force`` and ``constant_torque``.
        joints: the world joints (:class:`~tumble.dynamics.joint_solver.JointArrays`; body -1 is the world).
        joint_exclusions: (k, 2) int64 sorted body pairs that a joint keeps from colliding.
        body_gravity: (body_count, 3) [m/s²] the gravity each body falls under with contacts or joints: ``gravity`` in
            every row (the default), or each copy's for the rows of a batch (``tumble.batch``).
        copy_shape_count: shapes per copy when the rows are a batch's copies one after the other (shapes of different
            copies never pair); 0 for a world.
    """

    gravity: np.ndarray
    body_mass: np.ndarray
    body_inv_mass: np.ndarray
    body_inertia_local: np.ndarray
    body_inv_inertia_local: np.ndarray
    body_com_local: np.ndarray
    body_is_dynamic: np.ndarray
    body_linear_damping: np.ndarray
    body_angular_damping: np.ndarray
    body_name: tuple
    geometry: GeometryArrays
    shape_friction: np.ndarray
    shape_restitution: np.ndarray
    shape_rolling: np.ndarray
    shape_core_radius: np.ndarray
    shape_group: np.ndarray
    shape_mask: np.ndarray
    has_contacts: bool
    shapes: tuple
    body_constant_force: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    body_constant_torque: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    joints: JointArrays = field(default_factory=JointArrays.empty)
    joint_exclusions: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    body_gravity: np.ndarray | None = None
    copy_shape_count: int = 0

    def __post_init__(self) -> None:
        if self.body_gravity is None:  # a world: one gravity for every body
            rows = np.tile(np.asarray(self.gravity, np.float64), (self.body_count, 1))
            object.__setattr__(self, "body_gravity", rows)

    @property
    def body_count(self) -> int:
        return int(self.body_mass.shape[0])

    @property
    def joint_count(self) -> int:
        return int(self.joints.kind.shape[0])

    @property
    def shape_count(self) -> int:
        return int(self.geometry.shape_body.shape[0])

    @property
    def shape_body(self) -> np.ndarray:
        return self.geometry.shape_body

    @property
    def shape_type(self) -> np.ndarray:
        return self.geometry.shape_type

    @property
    def shape_params(self) -> np.ndarray:
        return self.geometry.shape_params

    @property
    def shape_pos_local(self) -> np.ndarray:
        return self.geometry.shape_pos_local

    @property
    def shape_quat_local(self) -> np.ndarray:
        return self.geometry.shape_quat_local

    @cached_property
    def body_arrays(self) -> BodyArrays:
        """The per-body arrays the integrators read, as one NamedTuple for the kernels."""
        return BodyArrays(
            self.body_mass,
            self.body_inv_mass,
            self.body_inertia_local,
            self.body_inv_inertia_local,
            self.body_is_dynamic,
            self.body_linear_damping,
            self.body_angular_damping,
            self.body_constant_force,
            self.body_constant_torque,
        )

    @cached_property
    def body_free_to_sweep(self) -> np.ndarray:
        """(body_count,) bool: dynamic bodies that no joint holds, which time of impact may move back on its own
        (moving one jointed body back would tear its joints open)."""
        free = self.body_is_dynamic.copy()
        for column in (self.joints.body_a, self.joints.body_b):
            free[column[column >= 0]] = False
        return free

    @cached_property
    def has_constraints(self) -> bool:
        """Whether anything couples bodies (contacts or joints); free-motion integrators apply if not."""
        return self.has_contacts or self.joint_count > 0
