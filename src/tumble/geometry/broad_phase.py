"""Broad phase: the world bounds of every shape, then sort-and-sweep for the pairs the narrow phase tests.

:func:`update_aabbs` turns each shape's box into a world axis-aligned box, ``c = x + R c_local`` and
``e = |R| e_local`` (Ericson 2005, *Real-Time Collision Detection*, §4.2.6): the primitives exactly (the tightest
box however they are turned in their body), hulls and meshes from their packed body-frame box
(``shape_aabb_center_local`` ± ``shape_aabb_half_local``). It grows the box by the speculative margin and sweeps
it along the body's displacement over the step.

:func:`find_pairs` is sort-and-sweep (sweep and prune; Baraff 1992, Ericson 2005 §7.5.2): sort the boxes by their
lower bound on one axis, then walk the sorted list; a box can only overlap the boxes that start before it ends,
so the inner loop stops at the first box that starts after it. That costs O(n log n) for the sort plus O(n + k)
for k overlaps on the axis. The axis is the one along which the box centres vary most (Ericson's choice in
§7.5.2): in a pile spread over a floor that is a horizontal axis, never the stacking one. The sort is a full sort
each call rather than an insertion sort kept from the last step: it needs no state, so throwing the scratch away
never changes a result, and it is not where the time goes (5000 boxes after one step of motion: argsort
0.16-0.49 ms, an insertion sort from the last order 0.14-0.19 ms, the sweep 6-22 ms). Planes have no finite box and
are tested apart against every box. The pairs come out sorted by ``(shape_a, shape_b)`` whatever the input order,
so the narrow phase and the solver see them deterministically. :func:`sweep_and_prune` is all of it in one
compiled call (the contact step's); :func:`find_pairs` calls it from Python.

:func:`find_pairs_brute_force` tests every pair with NumPy: the readable reference and the tests' oracle.
"""

from __future__ import annotations

import math

import numpy as np

from .. import math3d
from .._jit import inline, kernel
from ..shapes import ShapeType
from .packing import GeometryArrays

__all__ = [
    "update_aabbs",
    "find_pairs",
    "find_pairs_brute_force",
    "pair_filters",
    "sweep_and_prune",
    "exclusion_table",
    "PairBuffer",
    "DEFAULT_GROUP",
    "DEFAULT_MASK",
]

DEFAULT_GROUP = 1
DEFAULT_MASK = 0xFFFFFFFF

_SPHERE = int(ShapeType.SPHERE)
_CAPSULE = int(ShapeType.CAPSULE)
_BOX = int(ShapeType.BOX)
_CYLINDER = int(ShapeType.CYLINDER)
_PLANE = int(ShapeType.PLANE)


# --- bounds ------------------------------------------------------------------------------------------


@inline
def _primitive_half_extents(kind, params, m):
    """World half-widths of a primitive turned by ``m`` (row-major 9-tuple, shape to world), about its origin.

    Each is the tightest box: a sphere's is ``r``; a box's ``|R| h``; a capsule's is its segment's,
    ``|u| l``, grown by ``r`` (``u = R e_z`` its axis); a cylinder's is ``|u_k| l + r sqrt(1 - u_k²)`` per axis k,
    the end discs' extent. ``(-1, -1, -1)`` for hulls and meshes, whose bounds are not centred on their origin.
    """
    u = (m[2], m[5], m[8])
    if kind == _SPHERE:
        return (params[0], params[0], params[0])
    if kind == _CAPSULE:
        return (abs(u[0]) * params[1] + params[0], abs(u[1]) * params[1] + params[0], abs(u[2]) * params[1] + params[0])
    if kind == _BOX:
        return math3d.abs_mat_vec(m, (params[0], params[1], params[2]))
    if kind == _CYLINDER:
        r, half_h = params[0], params[1]
        return (
            abs(u[0]) * half_h + r * math.sqrt(max(1.0 - u[0] * u[0], 0.0)),
            abs(u[1]) * half_h + r * math.sqrt(max(1.0 - u[1] * u[1], 0.0)),
            abs(u[2]) * half_h + r * math.sqrt(max(1.0 - u[2] * u[2], 0.0)),
        )
    return (-1.0, -1.0, -1.0)


@kernel
def update_aabbs(geom, body_pos, body_quat, body_linvel, margin, h, out_lo, out_hi):
    """World axis-aligned bounds of every shape, enlarged for speculative contact and swept over the step.

    A primitive (sphere, capsule, box, cylinder) at ``p`` in body ``b`` gets its tightest box, centred on
    ``x_b + R_b p`` (see :func:`_primitive_half_extents`); a hull or mesh gets the box around its packed
    body-frame bounds, ``x_b + R_b c ± |R_b| e_c`` (Ericson 2005, §4.2.6). Either is grown by ``margin`` on every
    side and then stretched along the displacement ``h v_b`` the body makes over the step, so a fast body finds
    the pairs it will reach before the narrow phase runs again (a linear sweep only: rotation over one step
    moves a point by ``|ω| h r``, which the margin covers for ordinary spins). Pass ``h = 0`` for the bounds at
    the current pose only. Planes get infinite bounds.

    Args:
        geom: the packed shapes (:class:`~tumble.geometry.packing.GeometryArrays`).
        body_pos: (body_count, 3) float64 [m], centre of mass, world frame.
        body_quat: (body_count, 4) float64, unit ``[w, x, y, z]``, body to world.
        body_linvel: (body_count, 3) float64 [m/s], world frame.
        margin: [m] >= 0, added on every side (the speculative contact distance).
        h: [s] >= 0, the step over which the bounds are swept.
        out_lo, out_hi: (shape_count, 3) float64 [m], world frame; written.
    """
    for s in range(geom.shape_type.shape[0]):
        kind = geom.shape_type[s]
        if kind == _PLANE:
            for k in range(3):
                out_lo[s, k] = -math.inf
                out_hi[s, k] = math.inf
            continue
        b = geom.shape_body[s]
        q_body = math3d.load4(body_quat, b)
        rotation = math3d.quat_to_mat33(math3d.quat_mul(q_body, math3d.load4(geom.shape_quat_local, s)))
        half = _primitive_half_extents(kind, math3d.load4(geom.shape_params, s), rotation)
        center_local = math3d.load3(geom.shape_pos_local, s)
        if half[0] < 0.0:
            center_local = math3d.load3(geom.shape_aabb_center_local, s)
            half = math3d.abs_mat_vec(math3d.quat_to_mat33(q_body), math3d.load3(geom.shape_aabb_half_local, s))
        center = math3d.add(math3d.load3(body_pos, b), math3d.quat_rotate(q_body, center_local))
        sweep = math3d.scale(math3d.load3(body_linvel, b), h)
        for k in range(3):
            out_lo[s, k] = center[k] - half[k] - margin + min(sweep[k], 0.0)
            out_hi[s, k] = center[k] + half[k] + margin + max(sweep[k], 0.0)


# --- pair rules (shared by the sweep and the plane pass) ------------------------------------------------


@inline
def _is_excluded(excluded, body_a, body_b):
    """Whether the body pair is a row of ``excluded`` ((k, 2), rows ``lo < hi``, sorted): binary search."""
    lo_body, hi_body = min(body_a, body_b), max(body_a, body_b)
    lo, hi = 0, excluded.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if excluded[mid, 0] < lo_body or (excluded[mid, 0] == lo_body and excluded[mid, 1] < hi_body):
            lo = mid + 1
        else:
            hi = mid
    return lo < excluded.shape[0] and excluded[lo, 0] == lo_body and excluded[lo, 1] == hi_body


@inline
def _may_collide(a, b, shape_body, body_is_dynamic, shape_group, shape_mask, excluded):
    """The filter rules, cheapest first: other body, one of them dynamic, group/mask both ways, no joint."""
    body_a, body_b = shape_body[a], shape_body[b]
    if body_a == body_b:
        return False
    if not (body_is_dynamic[body_a] or body_is_dynamic[body_b]):
        return False
    if (shape_group[a] & shape_mask[b]) == 0 or (shape_group[b] & shape_mask[a]) == 0:
        return False
    return not _is_excluded(excluded, body_a, body_b)


@inline
def _emit(shape_type, a, b, out_a, out_b, count):
    """Write the pair with the lower ShapeType first (then the lower index), if there is room; count it."""
    if shape_type[a] > shape_type[b] or (shape_type[a] == shape_type[b] and a > b):
        a, b = b, a
    if count < out_a.shape[0]:
        out_a[count] = a
        out_b[count] = b
    return count + 1


# --- sweep ---------------------------------------------------------------------------------------------


@inline
def _sweep_kernel(
    order, segment_size, sorted_lo, sorted_hi, shape_type, shape_body, body_is_dynamic, shape_group, shape_mask,
    excluded, out_a, out_b, count,
):  # fmt: skip
    """Sort-and-sweep; returns the new pair count.

    ``order`` lists the finite boxes by segment (shape row // ``segment_size``, when > 0: boxes of different segments
    never pair), then by increasing lower bound on the sweep axis; ``sorted_lo``, ``sorted_hi`` ((n, 3) float64) are
    their bounds in that order, with the sweep axis moved to column 0 so the inner loop reads memory in sequence.
    Writes at most ``len(out_a)`` pairs but counts all of them, so the caller can grow the buffers and rerun.
    """
    n = order.shape[0]
    for i in range(n):
        end = sorted_hi[i, 0]
        lo_1, hi_1, lo_2, hi_2 = sorted_lo[i, 1], sorted_hi[i, 1], sorted_lo[i, 2], sorted_hi[i, 2]
        for j in range(i + 1, n):
            # Sorted by lower bound: every later box starts after this one ends. Before that, the boxes overlap
            # on the sweep axis (lo_i <= lo_j <= hi_j); test the other two, closed intervals as the brute force.
            if sorted_lo[j, 0] > end or (segment_size > 0 and order[j] // segment_size != order[i] // segment_size):
                break
            if sorted_lo[j, 1] > hi_1 or lo_1 > sorted_hi[j, 1] or sorted_lo[j, 2] > hi_2 or lo_2 > sorted_hi[j, 2]:
                continue
            a, b = order[i], order[j]
            if _may_collide(a, b, shape_body, body_is_dynamic, shape_group, shape_mask, excluded):
                count = _emit(shape_type, a, b, out_a, out_b, count)
    return count


@inline
def _plane_kernel(
    planes, boxes, segment_size, geom, body_pos, body_quat, aabb_lo, aabb_hi, body_is_dynamic, shape_group, shape_mask,
    excluded, margin, out_a, out_b, count,
):  # fmt: skip
    """Pair each plane with every box of its segment (``boxes``, ascending, whose row // ``segment_size`` is the
    plane's; every box when ``segment_size`` is 0) whose lowest corner along the plane normal is within ``margin``
    of it.

    The plane ``n · x = d`` of shape frame ``(p, q)`` is ``(R n) · x = d + (R n) · p`` in the world. The box
    ``[lo, hi]`` reaches ``min n · x = Σ_k n_k (lo_k if n_k >= 0 else hi_k)``: its support point along ``-n``.
    """
    for i in range(planes.shape[0]):
        p = planes[i]
        b = geom.shape_body[p]
        q_body = math3d.load4(body_quat, b)
        origin = math3d.add(
            math3d.load3(body_pos, b), math3d.quat_rotate(q_body, math3d.load3(geom.shape_pos_local, p))
        )
        q_plane = math3d.quat_mul(q_body, math3d.load4(geom.shape_quat_local, p))
        params = math3d.load4(geom.shape_params, p)
        normal = math3d.quat_rotate(q_plane, (params[0], params[1], params[2]))
        offset = params[3] + math3d.dot(normal, origin)
        first, last = 0, boxes.shape[0]
        if segment_size > 0:
            start = p // segment_size * segment_size
            first, last = np.searchsorted(boxes, start), np.searchsorted(boxes, start + segment_size)
        for j in range(first, last):
            s = boxes[j]
            lowest = 0.0
            for k in range(3):
                lowest += normal[k] * (aabb_lo[s, k] if normal[k] >= 0.0 else aabb_hi[s, k])
            if lowest <= offset + margin and _may_collide(
                p, s, geom.shape_body, body_is_dynamic, shape_group, shape_mask, excluded
            ):
                count = _emit(geom.shape_type, p, s, out_a, out_b, count)
    return count


# --- Python entry points -------------------------------------------------------------------------------


class PairBuffer:
    """Reusable output arrays for :func:`find_pairs`; they grow (by half again) when a scene needs more.

    Attributes:
        a, b: (capacity,) int64 shape rows; only the first ``count`` of the last call are meaningful.
    """

    __slots__ = ("a", "b")

    def __init__(self, capacity: int = 256) -> None:
        self.a = np.zeros(capacity, np.int64)
        self.b = np.zeros(capacity, np.int64)

    @property
    def capacity(self) -> int:
        return int(self.a.shape[0])

    def reserve(self, count: int) -> None:
        """Make room for at least ``count`` pairs (contents are not kept)."""
        if count > self.capacity:
            capacity = max(count, self.capacity + self.capacity // 2)
            self.a = np.zeros(capacity, np.int64)
            self.b = np.zeros(capacity, np.int64)


def exclusion_table(body_pairs) -> np.ndarray:
    """Body pairs that never collide (jointed bodies) as the (k, 2) int64 table :func:`find_pairs` searches.

    Each row is ordered ``(lo, hi)``, rows are sorted and duplicates dropped; a pair of a body with itself is
    meaningless (shapes of one body never pair) and dropped too.
    """
    pairs = np.asarray(body_pairs, dtype=np.int64).reshape(-1, 2)
    pairs = np.sort(pairs, axis=1)
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    return np.unique(pairs, axis=0).reshape(-1, 2)


def _is_exclusion_table(table: np.ndarray) -> bool:
    if table.shape[0] == 0:
        return True
    if not np.all(table[:, 0] < table[:, 1]):
        return False
    first, second = table[1:], table[:-1]
    return bool(np.all((first[:, 0] > second[:, 0]) | ((first[:, 0] == second[:, 0]) & (first[:, 1] > second[:, 1]))))


def pair_filters(shape_count, shape_group=None, shape_mask=None, excluded_body_pairs=None):
    """``(group, mask, excluded)`` as the kernels take them: uint32 filter bits (the defaults where None) and the
    excluded body pairs as an :func:`exclusion_table`."""
    group = np.full(shape_count, DEFAULT_GROUP, np.uint32) if shape_group is None else np.asarray(shape_group)
    mask = np.full(shape_count, DEFAULT_MASK, np.uint32) if shape_mask is None else np.asarray(shape_mask)
    group, mask = group.astype(np.uint32, copy=False), mask.astype(np.uint32, copy=False)
    if excluded_body_pairs is None:
        excluded = np.zeros((0, 2), np.int64)
    else:
        excluded = np.asarray(excluded_body_pairs, dtype=np.int64).reshape(-1, 2)
        if not _is_exclusion_table(excluded):
            excluded = exclusion_table(excluded)
    return group, mask, excluded


def find_pairs(
    geom: GeometryArrays,
    body_pos: np.ndarray,
    body_quat: np.ndarray,
    aabb_lo: np.ndarray,
    aabb_hi: np.ndarray,
    body_is_dynamic: np.ndarray,
    *,
    shape_group: np.ndarray | None = None,
    shape_mask: np.ndarray | None = None,
    excluded_body_pairs: np.ndarray | None = None,
    margin: float = 0.0,
    buffer: PairBuffer | None = None,
    segment_size: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """Candidate shape pairs whose bounds overlap, by sort-and-sweep (see the module docstring).

    A pair is kept when the two boxes overlap (closed intervals: touching counts), or, for a plane, when the
    box comes within ``margin`` of the plane; and the shapes are on different bodies, at least one body is
    dynamic, ``(group[a] & mask[b]) != 0 and (group[b] & mask[a]) != 0``, and the body pair is not excluded.
    Two planes are never paired.

    Args:
        geom: the packed shapes.
        body_pos: (body_count, 3) float64 [m], centre of mass, world frame (places planes).
        body_quat: (body_count, 4) float64, unit ``[w, x, y, z]`` (orients planes).
        aabb_lo, aabb_hi: (shape_count, 3) float64 [m], world bounds from :func:`update_aabbs`.
        body_is_dynamic: (body_count,) bool.
        shape_group, shape_mask: (shape_count,) uint32 collision filter bits; default group 1, mask all ones.
        excluded_body_pairs: (k, 2) int64 body pairs that never collide (e.g. jointed); any order (an
            :func:`exclusion_table` is searched as given, anything else is normalised into one first).
        margin: [m] >= 0, how close a box must come to a plane. Use the margin given to :func:`update_aabbs`:
            the plane has no box of its own to enlarge, so this keeps the reach of plane pairs like that of
            two enlarged boxes.
        buffer: reusable output arrays (grown as needed); a fresh one when None.
        segment_size: > 0 splits the shapes into segments of this many rows (a batch's copies, one after the other)
            whose shapes never pair with another segment's; 0: one segment.

    Returns:
        ``(shape_a, shape_b)``: (pair_count,) int64 each, with ``type(a) < type(b)`` or equal types and
        ``a < b``; sorted by ``(shape_a, shape_b)``.
    """
    shape_count = int(geom.shape_type.shape[0])
    body_is_dynamic = np.asarray(body_is_dynamic, dtype=bool)
    group, mask, excluded = pair_filters(shape_count, shape_group, shape_mask, excluded_body_pairs)
    if buffer is None:
        buffer = PairBuffer(max(64, 2 * shape_count))
    while True:
        count = sweep_and_prune(geom, body_pos, body_quat, aabb_lo, aabb_hi, body_is_dynamic, group, mask, excluded,
                                float(margin), int(segment_size), buffer.a, buffer.b)  # fmt: skip
        if count <= buffer.capacity:
            return buffer.a[:count].copy(), buffer.b[:count].copy()
        # The kernels counted every pair but wrote only what fitted: grow to the count and run again.
        buffer.reserve(count)


@kernel
def sweep_and_prune(geom, body_pos, body_quat, aabb_lo, aabb_hi, body_is_dynamic, shape_group, shape_mask, excluded,
                    margin, segment_size, out_a, out_b):  # fmt: skip
    """:func:`find_pairs` in one compiled call, into ``out_a``, ``out_b`` sorted by ``(a, b)``: returns the pair
    count, which is more than ``out_a`` holds when it must grow (then only what fitted was written, unsorted).
    ``shape_group``, ``shape_mask``, ``excluded`` as :func:`pair_filters` gives them."""
    n = geom.shape_type.shape[0]
    box_count = 0
    for s in range(n):
        box_count += geom.shape_type[s] != _PLANE
    boxes, planes = np.empty(box_count, np.int64), np.empty(n - box_count, np.int64)
    i = j = 0
    for s in range(n):
        if geom.shape_type[s] != _PLANE:
            boxes[i] = s
            i += 1
        else:
            planes[j] = s
            j += 1
    axis = _sweep_axis(boxes, aabb_lo, aabb_hi)
    order = boxes[_sweep_order(boxes, aabb_lo, axis, segment_size)]
    sorted_lo, sorted_hi = np.empty((box_count, 3)), np.empty((box_count, 3))
    for k in range(box_count):
        for c in range(3):  # the sweep axis first, so that the sweep reads memory in sequence
            sorted_lo[k, c] = aabb_lo[order[k], (axis + c) % 3]
            sorted_hi[k, c] = aabb_hi[order[k], (axis + c) % 3]
    count = _sweep_kernel(order, segment_size, sorted_lo, sorted_hi, geom.shape_type, geom.shape_body,
                          body_is_dynamic, shape_group, shape_mask, excluded, out_a, out_b, 0)  # fmt: skip
    count = _plane_kernel(planes, boxes, segment_size, geom, body_pos, body_quat, aabb_lo, aabb_hi, body_is_dynamic,
                          shape_group, shape_mask, excluded, margin, out_a, out_b, count)  # fmt: skip
    if count <= out_a.shape[0]:
        # By the key a n + b (exact in int64 up to 3·10⁹ shapes): unique, so any sort gives the same order.
        key = np.sort(out_a[:count] * n + out_b[:count])
        for k in range(count):
            out_a[k], out_b[k] = key[k] // n, key[k] % n
    return count


@inline
def _sweep_axis(boxes, aabb_lo, aabb_hi):
    """The axis along which the box centres spread most (Ericson 2005, §7.5.2): any axis finds the same pairs, this
    one fewest candidates on the way."""
    if boxes.shape[0] < 2:
        return 0
    best, axis = -1.0, 0
    for c in range(3):
        mean = 0.0
        for s in boxes:
            mean += aabb_lo[s, c] + aabb_hi[s, c]
        mean /= boxes.shape[0]
        spread = 0.0
        for s in boxes:
            spread += (aabb_lo[s, c] + aabb_hi[s, c] - mean) ** 2
        if spread > best:
            best, axis = spread, c
    return axis


@inline
def _sweep_order(boxes, aabb_lo, axis, segment_size):
    """The boxes' order for the sweep: by segment (row // ``segment_size``, when > 0), then by lower bound on
    ``axis`` (two stable sorts)."""
    lower = np.empty(boxes.shape[0])
    for k in range(boxes.shape[0]):
        lower[k] = aabb_lo[boxes[k], axis]
    order = np.argsort(lower, kind="mergesort")
    if segment_size > 0:
        order = order[np.argsort(boxes[order] // segment_size, kind="mergesort")]
    return order


def find_pairs_brute_force(
    geom: GeometryArrays,
    body_pos: np.ndarray,
    body_quat: np.ndarray,
    aabb_lo: np.ndarray,
    aabb_hi: np.ndarray,
    body_is_dynamic: np.ndarray,
    *,
    shape_group: np.ndarray | None = None,
    shape_mask: np.ndarray | None = None,
    excluded_body_pairs: np.ndarray | None = None,
    margin: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """The same pairs as :func:`find_pairs`, by testing every pair: O(n²), NumPy, one shape per row.

    Written apart from the kernels (NumPy rotations, a Python set for exclusions) to serve as their oracle.
    """
    from ..rotation import quat_to_matrix

    n = int(geom.shape_type.shape[0])
    shape_type, shape_body = geom.shape_type, geom.shape_body
    group, mask, _ = pair_filters(n, shape_group, shape_mask, None)
    rows = [] if excluded_body_pairs is None else np.asarray(excluded_body_pairs, np.int64).reshape(-1, 2)
    excluded = {(min(int(i), int(j)), max(int(i), int(j))) for i, j in rows}
    is_plane = shape_type == _PLANE
    # Every plane in the world frame: normal n and offset d of n · x = d.
    plane_normal, plane_offset = np.zeros((n, 3)), np.zeros(n)
    for p in np.flatnonzero(is_plane):
        body_rotation = quat_to_matrix(body_quat[shape_body[p]])
        origin = body_pos[shape_body[p]] + body_rotation @ geom.shape_pos_local[p]
        plane_normal[p] = body_rotation @ quat_to_matrix(geom.shape_quat_local[p]) @ geom.shape_params[p, :3]
        plane_offset[p] = geom.shape_params[p, 3] + plane_normal[p] @ origin
    pairs = []
    for a in range(n):
        b = np.arange(a + 1, n)
        keep = shape_body[b] != shape_body[a]
        keep &= body_is_dynamic[shape_body[a]] | body_is_dynamic[shape_body[b]]
        keep &= ((group[a] & mask[b]) != 0) & ((group[b] & mask[a]) != 0)
        if is_plane[a]:
            # The lowest corner of each box along the plane normal, against the plane.
            corner = np.where(plane_normal[a] >= 0.0, aabb_lo[b], aabb_hi[b])
            corner[is_plane[b]] = 0.0  # planes never pair; their infinite bounds would only make NaNs here
            lowest = corner @ plane_normal[a]
            keep &= ~is_plane[b] & (lowest <= plane_offset[a] + margin)
        else:
            boxes_overlap = np.all((aabb_lo[a] <= aabb_hi[b]) & (aabb_lo[b] <= aabb_hi[a]), axis=1)
            lowest = np.einsum("ij,ij->i", np.where(plane_normal[b] >= 0.0, aabb_lo[a], aabb_hi[a]), plane_normal[b])
            keep &= np.where(is_plane[b], lowest <= plane_offset[b] + margin, boxes_overlap)
        for other in b[keep]:
            if (min(shape_body[a], shape_body[other]), max(shape_body[a], shape_body[other])) in excluded:
                continue
            first, second = (a, other) if shape_type[a] <= shape_type[other] else (other, a)
            pairs.append((first, second))
    pairs.sort()
    table = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    return table[:, 0].copy(), table[:, 1].copy()
