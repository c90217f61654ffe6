"""Overlap queries: which shapes of a world a query shape, placed at a pose, overlaps.

The query shape is packed as the world packs its shapes (:func:`~tumble.geometry.packing.pack_geometry`) and
appended to the world's geometry as the only shape of one extra body (:func:`append_geometry`), so the narrow
phase's own ``collide_<a>_<b>`` kernels test it, through :func:`~tumble.geometry.narrow_phase.collide_pairs`, and
the query has no collision code of its own. Candidates are the shapes whose ``collision_group`` shares a bit with
the query mask and whose world box (:func:`~tumble.geometry.broad_phase.update_aabbs`, no margin) meets the
query's; a plane's box is infinite, so every plane is a candidate.

Overlap means a manifold point with separation <= 0. The kernels keep the points with ``separation < margin``;
the margin passed is the smallest positive double, so that test is exactly ``separation <= 0``: shapes that touch
count, shapes apart by any distance do not.
"""

from __future__ import annotations

import numpy as np

from ..shapes import Shape
from .broad_phase import update_aabbs
from .manifold import Manifolds
from .narrow_phase import collide_pairs
from .packing import GeometryArrays, pack_geometry

__all__ = ["append_geometry", "overlapping_shapes"]

# The smallest positive double: ``separation < TOUCH_MARGIN`` holds exactly when ``separation <= 0``.
TOUCH_MARGIN = float(np.nextafter(0.0, 1.0))

# Fields holding indices into another array of the packing, and the array they index.
_INDEX_FIELDS = {
    "shape_vertex_start": "vertex_local",
    "face_loop": "vertex_local",
    "edge_vertex": "vertex_local",
    "face_loop_start": "face_loop",
    "shape_face_start": "face_normal",
    "shape_edge_start": "edge_vertex",
}


def append_geometry(geom: GeometryArrays, extra: GeometryArrays) -> GeometryArrays:
    """The shapes of ``geom`` followed by those of ``extra``, as if all had been packed together.

    ``extra``'s indices into the shared vertex, face-loop, face and edge arrays are shifted past ``geom``'s;
    its ``shape_body`` rows are kept as given.
    """
    fields = {}
    for name in GeometryArrays._fields:
        head, tail = getattr(geom, name), getattr(extra, name)
        if name in _INDEX_FIELDS:
            tail = tail + getattr(geom, _INDEX_FIELDS[name]).shape[0]
        fields[name] = np.concatenate([head, tail])
    return GeometryArrays(**fields)


def overlapping_shapes(
    geom: GeometryArrays,
    body_pos: np.ndarray,
    body_quat: np.ndarray,
    shape_group: np.ndarray,
    mask: int,
    shape: Shape,
    position: np.ndarray,
    quat: np.ndarray,
) -> np.ndarray:
    """The rows of the world's shapes that ``shape``, placed at ``(position, quat)``, overlaps.

    Args:
        geom: the world's packed shapes (``shape_count`` rows).
        body_pos: (body_count, 3) float64 [m], centre of mass, world frame.
        body_quat: (body_count, 4) float64, unit ``[w, x, y, z]``, body to world.
        shape_group: (shape_count,) uint32 collision groups.
        mask: a shape is tested when ``shape_group & mask != 0``.
        shape: the query shape (convex: not a plane or a mesh; the caller checks).
        position: (3,) float64 [m], the query shape frame's origin, world frame.
        quat: (4,) float64, unit ``[w, x, y, z]``, the query shape frame's orientation.

    Returns:
        (k,) int64 shape rows, ascending.
    """
    shape_count, body_count = int(geom.shape_type.shape[0]), int(body_pos.shape[0])
    if shape_count == 0:
        return np.zeros(0, np.int64)
    # The query is shape row `q` of one more body, placed at the given pose.
    q = shape_count
    query = pack_geometry([shape], [body_count], np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0, 0.0]]))
    full = append_geometry(geom, query)
    pos = np.concatenate([body_pos, position.reshape(1, 3)])
    orientation = np.concatenate([body_quat, quat.reshape(1, 4)])
    still = np.zeros_like(pos)
    # Cull by world boxes at the current poses (no margin, no sweep).
    lo, hi = np.empty((q + 1, 3)), np.empty((q + 1, 3))
    update_aabbs(full, pos, orientation, still, 0.0, 0.0, lo, hi)
    # The boxes and the kernels round differently (by ~1e-16 relative); a 1e-9 relative slack only lets a few
    # more pairs reach the narrow phase, which decides.
    slack = 1e-9 * max(1.0, float(np.abs(np.concatenate([lo[q], hi[q]])).max()))
    meets = np.all((lo[:q] <= hi[q] + slack) & (lo[q] - slack <= hi[:q]), axis=1)
    seen = (np.asarray(shape_group, dtype=np.uint32) & np.uint32(mask)) != 0
    candidates = np.flatnonzero(meets & seen)
    if candidates.size == 0:
        return np.zeros(0, np.int64)
    # Lower shape type first, as the broad phase emits pairs (`q` has the higher row, so it goes second on a tie).
    query_first = full.shape_type[candidates] > full.shape_type[q]
    pairs_a = np.where(query_first, q, candidates).astype(np.int64)
    pairs_b = np.where(query_first, candidates, q).astype(np.int64)
    manifolds = Manifolds.allocate(candidates.size)
    count = collide_pairs(full, pos, orientation, still, still, pairs_a, pairs_b, TOUCH_MARGIN, 0.0, manifolds)
    # Touching pairs are at the front; a manifold may carry points above zero beside those at or below it.
    points = np.arange(manifolds.separation.shape[1])[None, :] < manifolds.point_count[:count, None]
    touching = np.any(points & (manifolds.separation[:count] <= 0.0), axis=1)
    other = np.where(manifolds.shape_a[:count] == q, manifolds.shape_b[:count], manifolds.shape_a[:count])
    return np.unique(other[touching]).astype(np.int64)
