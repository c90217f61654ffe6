"""Contact manifolds: what the narrow phase hands the solver, as arrays.

A manifold holds up to :data:`MAX_POINTS` contact points between two shapes ``a`` and ``b`` (``a`` of the
lower :class:`~tumble.shapes.ShapeType`), sharing one world-frame ``normal`` that points from ``a`` to ``b``
(moving ``b`` along ``+normal`` separates them). Each point is midway between the two surfaces; its
``separation`` is the signed distance along the normal, negative where the shapes overlap, and positive up to
the speculative margin for points about to touch. ``feature`` ids name the touching features (face, edge,
vertex of each shape) so the solver can match points from one step to the next for warm starting.

Every ``collide_<a>_<b>`` kernel has the same signature::

    collide_<a>_<b>(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin,
                    normal, point, separation, feature) -> int

where ``geom`` is the :class:`~tumble.geometry.packing.GeometryArrays`, ``shape_a``/``shape_b`` are shape rows,
``pos_*``/``quat_*`` the world poses of the two *shape* frames as tuples, ``margin`` the speculative distance,
and ``normal (3,)``, ``point (4, 3)``, ``separation (4,)``, ``feature (4,)`` the output rows. It returns how
many points it wrote (0 when the shapes are farther apart than ``margin``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["MAX_POINTS", "Manifolds"]

MAX_POINTS = 4


class Manifolds(NamedTuple):
    """Up to ``capacity`` manifolds; the first ``count`` rows are in use.

    Attributes:
        shape_a, shape_b: (capacity,) int64 shape rows, ``type(a) <= type(b)``.
        normal: (capacity, 3) float64, world frame, from a to b.
        point_count: (capacity,) int64 in [0, MAX_POINTS].
        point: (capacity, MAX_POINTS, 3) float64 [m], world frame.
        separation: (capacity, MAX_POINTS) float64 [m], negative when overlapping.
        feature: (capacity, MAX_POINTS) int64 feature ids.
    """

    shape_a: np.ndarray
    shape_b: np.ndarray
    normal: np.ndarray
    point_count: np.ndarray
    point: np.ndarray
    separation: np.ndarray
    feature: np.ndarray

    @classmethod
    def allocate(cls, capacity: int) -> Manifolds:
        return cls(
            np.zeros(capacity, np.int64),
            np.zeros(capacity, np.int64),
            np.zeros((capacity, 3)),
            np.zeros(capacity, np.int64),
            np.zeros((capacity, MAX_POINTS, 3)),
            np.zeros((capacity, MAX_POINTS)),
            np.zeros((capacity, MAX_POINTS), np.int64),
        )
