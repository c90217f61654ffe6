"""What a world can be asked about its geometry: the contacts of the last step, and rays."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Contacts", "RayHit"]


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
