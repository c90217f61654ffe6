"""What a world can be asked about its geometry: the contacts of the last step, rays and overlaps (the work of
``World.contacts``, ``World.query_ray`` and ``World.query_overlap``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._validate import as_filter, as_float, as_quaternion, as_unit_vector3, as_vector3
from .shapes import Plane, Shape, TriMesh

__all__ = ["Contacts", "RayHit", "first_ray_hit", "overlapping_bodies"]


@dataclass(frozen=True, eq=False)
class Contacts:
    """The contact points of the last step, one row per point (speculative points included).

    Attributes:
        body_a, body_b: (K,) int64 body indices; the normal points from a to b.
        shape_a, shape_b: (K,) int64 shape rows.
        point: (K, 3) [m], midway between the two surfaces, world frame.
        normal: (K, 3) unit, world frame, from a to b.
        separation: (K,) [m], negative where the shapes overlap, positive for speculative points.
        normal_impulse: (K,) [N s] pushed along the normal during the step (on b; a gets the opposite).
        friction_impulse: (K, 3) [N s] friction impulse on b during the step, world frame.
    """

    body_a: np.ndarray
    body_b: np.ndarray
    shape_a: np.ndarray
    shape_b: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    separation: np.ndarray
    normal_impulse: np.ndarray
    friction_impulse: np.ndarray

    def __len__(self) -> int:
        return int(self.point.shape[0])

    @classmethod
    def from_solver(cls, shape_body: np.ndarray, manifolds, rows, count: int) -> Contacts:
        """Flatten the first ``count`` manifolds (points beyond each manifold's count are dropped)."""
        used = np.arange(manifolds.point.shape[1])[None, :] < manifolds.point_count[:count, None]
        m_index, _ = np.nonzero(used)
        shape_a, shape_b = manifolds.shape_a[:count][m_index], manifolds.shape_b[:count][m_index]
        tangent = (
            rows.total_tangent_impulse[:count, :, 0, None] * rows.tangent1[:count, None, :]
            + rows.total_tangent_impulse[:count, :, 1, None] * rows.tangent2[:count, None, :]
        )
        return cls(
            body_a=shape_body[shape_a],
            body_b=shape_body[shape_b],
            shape_a=shape_a,
            shape_b=shape_b,
            point=manifolds.point[:count][used],
            normal=manifolds.normal[:count][m_index],
            separation=manifolds.separation[:count][used],
            normal_impulse=rows.total_normal_impulse[:count][used],
            friction_impulse=tangent[used],
        )


@dataclass(frozen=True)
class RayHit:
    """The first surface a ray meets.

    Attributes:
        body: the :class:`~tumble.Body` hit; shape: its shape row in the world.
        distance: [m] along the ray; point: (3,) [m] world; normal: (3,) unit outward surface normal.
    """

    body: object
    shape: int
    distance: float
    point: np.ndarray
    normal: np.ndarray


def _check_query_shape(shape) -> Shape:
    if not isinstance(shape, Shape):
        raise TypeError(
            f"shape must be a Sphere, Box, Capsule, Cylinder or ConvexHull, got {shape!r} ({type(shape).__name__})"
        )
    if isinstance(shape, (Plane, TriMesh)):
        raise ValueError(
            f"shape must be a Sphere, Box, Capsule, Cylinder or ConvexHull (a convex solid) to query overlaps, "
            f"got {shape!r}"
        )
    return shape


def first_ray_hit(model, state, bodies: list, origin, direction, max_distance, mask) -> RayHit | None:
    """``World.query_ray``: the arguments checked, the ray cast by the step's geometry; ``bodies`` the handles."""
    from .geometry.raycast import raycast_shapes  # its kernels load on the first query, not with tumble

    origin = as_vector3("origin", origin)
    direction = as_unit_vector3("direction", direction, tiny=0.0)
    if not (isinstance(max_distance, float) and max_distance == math.inf):
        max_distance = as_float("max_distance", max_distance, nonnegative=True)
    mask = as_filter("mask", mask)
    shape, distance, point, normal = raycast_shapes(
        model.geometry, state.body_pos, state.body_quat, origin, direction, max_distance,
        model.shape_group, np.uint32(mask),
    )  # fmt: skip
    if shape < 0:
        return None
    if not (math.isfinite(distance) and np.isfinite(point).all()):
        raise ValueError(
            f"the ray from origin={origin.tolist()} along direction={direction.tolist()} meets a shape outside "
            "float range"
        )
    body = bodies[int(model.shape_body[shape])]
    return RayHit(body, int(shape), float(distance), np.array(point), np.array(normal))


def overlapping_bodies(model, state, bodies: list, shape, position, orientation, mask) -> list:
    """``World.query_overlap``: the arguments checked, the overlaps found by the step's contact kernels."""
    from .geometry.overlap import overlapping_shapes

    shape = _check_query_shape(shape)
    position = as_vector3("position", position)
    quat = as_quaternion("orientation", orientation)
    mask = as_filter("mask", mask)
    rows = overlapping_shapes(
        model.geometry, state.body_pos, state.body_quat, model.shape_group, mask, shape, position, quat
    )
    indices = np.unique(model.shape_body[rows])
    return [bodies[int(i)] for i in indices]
