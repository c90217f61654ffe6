"""Narrow phase: contact manifolds for the candidate pairs, and warm-start matching with the last step.

``collide_pairs`` computes each shape's world pose, picks the ``collide_<a>_<b>`` kernel of the pair's types
(lower type first, as the broad phase orders them) and writes the manifolds of the pairs that touch or are
closer than their speculative margin. The margin of a pair grows with how far the two bodies can close in one
step, so fast bodies get speculative contacts before they could pass through each other.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import inline, kernel, kernel_for
from ..math3d import add, load3, load4, quat_mul, quat_rotate
from .collide_convex import collide_convex_convex, collide_convex_trimesh
from .collide_primitives import (
    collide_box_box,
    collide_box_plane,
    collide_capsule_box,
    collide_capsule_capsule,
    collide_capsule_plane,
    collide_cylinder_plane,
    collide_hull_plane,
    collide_sphere_box,
    collide_sphere_capsule,
    collide_sphere_plane,
    collide_sphere_sphere,
)
from .manifold import Manifolds

__all__ = [
    "COLLIDER_OF",
    "collide_each",
    "collide_pairs",
    "compiled_collide_each",
    "keep_touching",
    "contact_passes",
    "match_warm_start",
    "passes_due",
    "shape_world_pose",
]

SPHERE, CAPSULE, BOX, CYLINDER, HULL, PLANE, TRIMESH = 0, 1, 2, 3, 4, 5, 6
# A pair whose bodies can close or turn by more than this fraction of the smaller moving shape's bounding radius in
# one step finds its contacts again within the step, up to MAX_CONTACT_PASSES times (contact_passes). Half left a
# box spinning at 105 rad/s on a hull's face with one point for half a 240 Hz step, and it dug in 2.9 cm.
PASS_TRAVEL = 0.25
MAX_CONTACT_PASSES = 4


@inline
def shape_world_pose(geom, s, body_pos, body_quat):
    """World pose of shape ``s``: its body's COM frame composed with the shape's local pose."""
    b = geom.shape_body[s]
    qb = load4(body_quat, b)
    pos = add(load3(body_pos, b), quat_rotate(qb, load3(geom.shape_pos_local, s)))
    return pos, quat_mul(qb, load4(geom.shape_quat_local, s))


@inline
def _bounding_radius(aabb_center_local, aabb_half_local, s):
    """A radius about shape ``s``'s body's centre of mass that holds the shape (inf for a plane)."""
    c, hw = load3(aabb_center_local, s), load3(aabb_half_local, s)
    return math.sqrt(c[0] ** 2 + c[1] ** 2 + c[2] ** 2) + math.sqrt(hw[0] ** 2 + hw[1] ** 2 + hw[2] ** 2)


@inline
def _reach(geom, s, body_linvel, body_angvel):
    """How far any point of shape ``s`` can move per second: ``|v| + |ω| r`` with ``r`` its bounding radius."""
    return _shape_reach(geom.shape_body, geom.shape_aabb_center_local, geom.shape_aabb_half_local, s, body_linvel,
                        body_angvel)[0]  # fmt: skip


@inline
def _shape_reach(shape_body, aabb_center_local, aabb_half_local, s, body_linvel, body_angvel):
    """``(|v| + |ω| r, r)``: how far any point of shape ``s`` can move per second, and ``r`` its bounding radius."""
    b = shape_body[s]
    radius = _bounding_radius(aabb_center_local, aabb_half_local, s)
    v, w = load3(body_linvel, b), load3(body_angvel, b)
    speed = math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    spin = math.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2)
    return speed + (spin * radius if math.isfinite(radius) else 0.0), radius


@kernel
def _pair_setup(geom, body_pos, body_quat, body_linvel, body_angvel, pairs_a, pairs_b, k, margin, dt, manifolds):
    """Shapes and world poses of pair ``k`` (written to manifold row ``k``), and the pair's speculative margin:
    the default plus how far the two can close during this step."""
    sa, sb = pairs_a[k], pairs_b[k]
    manifolds.shape_a[k], manifolds.shape_b[k] = sa, sb
    pa, qa = shape_world_pose(geom, sa, body_pos, body_quat)
    pb, qb = shape_world_pose(geom, sb, body_pos, body_quat)
    reach = _reach(geom, sa, body_linvel, body_angvel) + _reach(geom, sb, body_linvel, body_angvel)
    return sa, sb, pa, qa, pb, qb, margin + dt * reach


def _pairs_template(geom, pos, quat, linvel, angvel, pairs_a, pairs_b, listed, margin, dt, manifolds):
    """The manifold of each listed pair ``k`` into row ``k`` (point count 0 if apart), by ``collide``, a name that
    :func:`kernel_for` binds to one pair type's function."""
    for k in listed:
        sa, sb, pa, qa, pb, qb, mg = _pair_setup(geom, pos, quat, linvel, angvel, pairs_a, pairs_b, k, margin, dt,
                                                 manifolds)  # fmt: skip
        rows = manifolds.normal[k], manifolds.point[k], manifolds.separation[k], manifolds.feature[k]
        manifolds.point_count[k] = collide(geom, sa, pa, qa, sb, pb, qb, mg, *rows)  # noqa: F821 (kernel_for binds it)


# One compiled loop per collision function, so that a world compiles only the pair types it has (the eleven
# primitive pairs compiled together cost 15 s of a first run for pairs mostly absent). Pairs with a cylinder or a
# hull that no closed form covers go to the general convex path, and any convex shape against a mesh to the mesh's.
_COLLIDERS = (
    collide_sphere_sphere, collide_sphere_capsule, collide_sphere_box, collide_capsule_capsule, collide_capsule_box,
    collide_box_box, collide_sphere_plane, collide_capsule_plane, collide_box_plane, collide_cylinder_plane,
    collide_hull_plane, collide_convex_convex, collide_convex_trimesh,
)  # fmt: skip
_PAIR_KERNELS = tuple(
    kernel_for(_pairs_template, f"pairs_{collide.__name__.removeprefix('collide_')}", collide=collide)
    for collide in _COLLIDERS
)


def _collider_table() -> np.ndarray:
    """``table[ta, tb]``: the index in ``_COLLIDERS`` of the function for a pair of types ``ta <= tb``."""
    index = {collide.__name__: i for i, collide in enumerate(_COLLIDERS)}
    names = ("sphere", "capsule", "box")
    table = np.full((7, 7), index["collide_convex_convex"], dtype=np.int64)
    for a, name_a in enumerate(names):
        for b in range(a, len(names)):
            table[a, b] = index[f"collide_{name_a}_{names[b]}"]
    for a, name_a in enumerate((*names, "cylinder", "hull")):
        table[a, PLANE] = index[f"collide_{name_a}_plane"]
    table[:, TRIMESH] = index["collide_convex_trimesh"]
    return table


COLLIDER_OF = _collider_table()
_COLLIDER_COUNT = len(_COLLIDERS)


@kernel
def _group_by_collider(shape_type, pairs_a, pairs_b, table, order, starts):
    """A counting sort of the pairs by collision function: the pairs of function ``i`` are
    ``order[starts[i]:starts[i + 1]]``, in pair order. One compiled call instead of a dozen NumPy ones per step.
    Writes: order (n,), starts (functions + 1,) (zeros on entry)."""
    n = pairs_a.shape[0]
    which = np.empty(n, dtype=np.int64)
    for k in range(n):
        which[k] = table[shape_type[pairs_a[k]], shape_type[pairs_b[k]]]
        starts[which[k] + 1] += 1
    for i in range(1, starts.shape[0]):
        starts[i] += starts[i - 1]
    filled = starts[:-1].copy()
    for k in range(n):
        order[filled[which[k]]] = k
        filled[which[k]] += 1


@kernel
def keep_touching(manifolds, n):
    """Move the manifolds of the first ``n`` pairs that have points to the front, in order; returns how many.
    Element by element: row copies of the 2-D and 3-D fields compiled six times slower (5.7 s against 1.0 s)."""
    count = 0
    for k in range(n):
        points = manifolds.point_count[k]
        if points == 0:
            continue
        if count < k:
            manifolds.shape_a[count] = manifolds.shape_a[k]
            manifolds.shape_b[count] = manifolds.shape_b[k]
            manifolds.point_count[count] = points
            for i in range(3):
                manifolds.normal[count, i] = manifolds.normal[k, i]
            for j in range(manifolds.point.shape[1]):
                manifolds.separation[count, j] = manifolds.separation[k, j]
                manifolds.feature[count, j] = manifolds.feature[k, j]
                for i in range(3):
                    manifolds.point[count, j, i] = manifolds.point[k, j, i]
        count += 1
    return count


def collide_pairs(geom, body_pos, body_quat, body_linvel, body_angvel, pairs_a, pairs_b, margin, dt, manifolds):
    """Manifolds of the candidate pairs that touch or are within their margin, in pair order; returns how many.

    Reads: geom, body poses and velocities (ω world), pairs (lower shape type first). Writes: manifolds[:count].
    """
    n = pairs_a.shape[0]
    if n == 0:
        return 0
    collide_each(geom, body_pos, body_quat, body_linvel, body_angvel, pairs_a, pairs_b, margin, dt, manifolds)
    return keep_touching(manifolds, n)


def collide_each(geom, body_pos, body_quat, body_linvel, body_angvel, pairs_a, pairs_b, margin, dt, manifolds):
    """The manifold of pair ``k`` into row ``k`` of ``manifolds``, point count 0 where the two are apart; ``dt`` is
    the time the speculative margin looks ahead. The pairs of each collision function go to that function's own
    kernel (:data:`_PAIR_KERNELS`)."""
    n = pairs_a.shape[0]
    order, starts = np.empty(n, dtype=np.int64), np.zeros(len(_COLLIDERS) + 1, dtype=np.int64)
    _group_by_collider(geom.shape_type, pairs_a, pairs_b, COLLIDER_OF, order, starts)
    args = (geom, body_pos, body_quat, body_linvel, body_angvel, pairs_a, pairs_b)
    bounds = starts.tolist()
    for i, run in enumerate(_PAIR_KERNELS):
        if bounds[i + 1] > bounds[i]:
            run(*args, order[bounds[i] : bounds[i + 1]], margin, dt, manifolds)


def _each_template(geom, body_pos, body_quat, body_linvel, body_angvel, pairs_a, pairs_b, margin, dt, manifolds,
                   table):  # fmt: skip
    """:func:`collide_each` as compiled code calls it (:data:`compiled_collide_each`): each collision function's pairs
    to its loop ``loop_i`` (bound by :func:`kernel_for`).
    ``table`` is :data:`COLLIDER_OF` (an argument: a global array would keep the kernel out of the cache)."""
    n = pairs_a.shape[0]
    order, starts = np.empty(n, np.int64), np.zeros(_COLLIDER_COUNT + 1, np.int64)
    _group_by_collider(geom.shape_type, pairs_a, pairs_b, table, order, starts)
    args = (geom, body_pos, body_quat, body_linvel, body_angvel, pairs_a, pairs_b)
    # One block per collision function (a dispatcher passed as an argument would keep the kernel out of the cache).
    if starts[1] > starts[0]:
        loop_0(*args, order[starts[0] : starts[1]], margin, dt, manifolds)  # noqa: F821
    if starts[2] > starts[1]:
        loop_1(*args, order[starts[1] : starts[2]], margin, dt, manifolds)  # noqa: F821
    if starts[3] > starts[2]:
        loop_2(*args, order[starts[2] : starts[3]], margin, dt, manifolds)  # noqa: F821
    if starts[4] > starts[3]:
        loop_3(*args, order[starts[3] : starts[4]], margin, dt, manifolds)  # noqa: F821
    if starts[5] > starts[4]:
        loop_4(*args, order[starts[4] : starts[5]], margin, dt, manifolds)  # noqa: F821
    if starts[6] > starts[5]:
        loop_5(*args, order[starts[5] : starts[6]], margin, dt, manifolds)  # noqa: F821
    if starts[7] > starts[6]:
        loop_6(*args, order[starts[6] : starts[7]], margin, dt, manifolds)  # noqa: F821
    if starts[8] > starts[7]:
        loop_7(*args, order[starts[7] : starts[8]], margin, dt, manifolds)  # noqa: F821
    if starts[9] > starts[8]:
        loop_8(*args, order[starts[8] : starts[9]], margin, dt, manifolds)  # noqa: F821
    if starts[10] > starts[9]:
        loop_9(*args, order[starts[9] : starts[10]], margin, dt, manifolds)  # noqa: F821
    if starts[11] > starts[10]:
        loop_10(*args, order[starts[10] : starts[11]], margin, dt, manifolds)  # noqa: F821
    if starts[12] > starts[11]:
        loop_11(*args, order[starts[11] : starts[12]], margin, dt, manifolds)  # noqa: F821
    if starts[13] > starts[12]:
        loop_12(*args, order[starts[12] : starts[13]], margin, dt, manifolds)  # noqa: F821


# collide_each for compiled code: every collision function's loop bound in (one copy for every world; the loops of
# pair types a world lacks are compiled but never run).
compiled_collide_each = kernel_for(
    _each_template, "compiled_collide_each", **{f"loop_{i}": loop for i, loop in enumerate(_PAIR_KERNELS)}
)


@inline(counted=False)
def passes_due(passes, count, k, substeps, listed):
    """The manifolds whose contacts are found again before substep ``k``, into ``listed``; returns how many:
    ``passes[m]`` equal runs of the substeps for manifold ``m`` (as equal as whole substeps allow)."""
    due = 0
    for m in range(count):
        if (k * passes[m]) // substeps > ((k - 1) * passes[m]) // substeps:
            listed[due] = m
            due += 1
    return due


@kernel
def contact_passes(shape_body, aabb_center_local, aabb_half_local, moving, shape_a, shape_b, count, linvel, angvel, dt,
                   passes):  # fmt: skip
    """How many times within a step of ``dt`` each manifold's contacts are to be found (issue 44): once, or up to
    :data:`MAX_CONTACT_PASSES` times where the pair's bodies can close or turn by more than
    :data:`PASS_TRAVEL` of the smaller moving shape's bounding radius in the step. A manifold holds its normal and
    points for its pass; a body landing at 10 m/s moves 17 cm in a 60 Hz step and turns by tens of degrees after
    its first touch, and a corner or neighbour that came into play mid-step went 6-11 cm deep unseen. A moving
    body's manifolds all take at least the passes of its fastest pair: struck, it turns within the step.
    Reads: the manifolds' shapes, velocities at the start of the step (ω world). Writes: passes[:count]; returns
    the largest."""
    most = 1
    for m in range(count):
        radius, travel = math.inf, 0.0
        for s in (shape_a[m], shape_b[m]):
            if moving[shape_body[s]]:
                reach, r = _shape_reach(shape_body, aabb_center_local, aabb_half_local, s, linvel, angvel)
                travel += dt * reach
                radius = min(radius, r)
        passes[m] = 1
        if travel > PASS_TRAVEL * radius:
            passes[m] = min(MAX_CONTACT_PASSES, math.ceil(travel / (PASS_TRAVEL * radius)))
        most = max(most, passes[m])
    if most == 1:
        return most  # no fast pair: nothing to pass on (and no per-body array to fill in a large world)
    # A body in a fast pair finds all its contacts as often: struck at the start of the step, a slow hull on the
    # ground turned at up to 50 rad/s and put a corner its manifold had left out 2.7 cm into the ground within a 240 Hz
    # step (mixed_drop seed 11).
    body_passes = np.ones(moving.shape[0], dtype=np.int64)
    for m in range(count):
        for s in (shape_a[m], shape_b[m]):
            body_passes[shape_body[s]] = max(body_passes[shape_body[s]], passes[m])
    for m in range(count):
        for s in (shape_a[m], shape_b[m]):
            if moving[shape_body[s]]:
                passes[m] = max(passes[m], body_passes[shape_body[s]])
    return most


@inline(counted=False)
def match_warm_start(
    manifolds, count, prev_a, prev_b, prev_point_count, prev_feature, prev_normal, prev_tangent, warm_normal,
    warm_tangent,
):  # fmt: skip
    """Carry the last step's impulses to the points with the same shape pair and feature id.

    Both lists are sorted by (shape_a, shape_b), so one merge walk finds every match.
    Writes: warm_normal (count, 4), warm_tangent (count, 4, 3) (zeros for new points).
    """
    k = 0
    for m in range(count):
        a, b = manifolds.shape_a[m], manifolds.shape_b[m]
        while k < prev_a.shape[0] and (prev_a[k] < a or (prev_a[k] == a and prev_b[k] < b)):
            k += 1
        found = k < prev_a.shape[0] and prev_a[k] == a and prev_b[k] == b
        for j in range(manifolds.point_count[m]):
            warm_normal[m, j] = 0.0
            warm_tangent[m, j, 0] = warm_tangent[m, j, 1] = warm_tangent[m, j, 2] = 0.0
            if not found:
                continue
            for jj in range(prev_point_count[k]):
                if prev_feature[k, jj] == manifolds.feature[m, j]:
                    warm_normal[m, j] = prev_normal[k, jj]
                    warm_tangent[m, j, 0] = prev_tangent[k, jj, 0]
                    warm_tangent[m, j, 1] = prev_tangent[k, jj, 1]
                    warm_tangent[m, j, 2] = prev_tangent[k, jj, 2]
                    break


def allocate_manifolds(capacity: int) -> Manifolds:
    return Manifolds.allocate(max(capacity, 1))


def warm_arrays(capacity: int) -> tuple[np.ndarray, np.ndarray]:
    return np.zeros((max(capacity, 1), 4)), np.zeros((max(capacity, 1), 4, 3))
