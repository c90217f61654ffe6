"""Time of impact: fast bodies stop at static geometry instead of passing through it.

Speculative contacts (``narrow_phase``) stop a body that closes on a surface along the contact normal found at
the start of the step. A body that spins fast, or meets a wall at a slant, can reach the far side of a thin
shape along a path that normal does not see. After the solver has moved the bodies, :func:`limit_to_impact`
sweeps each *fast* body (one that moved more than half its smallest half-extent) from its pose at the start of
the step to its pose now, against the static shapes the broad phase paired it with, and moves it back to the
first pose at which it comes within ``TOI_TARGET`` of one (its velocity is kept: the next step's contact stops
it). A shape that touches the static one already at the start is swept again by its *core*, a ball at the
centre of its bounds of a quarter of its smallest half-extent (Box2D v3's core fraction): a body resting
against or sliding along a surface is left to the contact solver, while one whose middle would pass into a
static shape is stopped. Planes are skipped: a plane is a
half-space, and its contact pushes out a body however deep it went.

The sweep is conservative advancement (B. Mirtich, *Impulse-based dynamic simulation of rigid body systems*,
PhD thesis, 1996, §2.3; as in Box2D's ``b2TimeOfImpact``): along ``x(t) = x0 + t Δx`` and a rotation by ``t θ``
about the step's rotation axis, no point of the shape moves faster than ``μ = |Δx| + θ r`` per unit of ``t``
(``r`` its farthest point from the centre of mass), so with the surfaces ``d`` apart the body can advance by
``(d - target) / μ`` without touching. Distances come from GJK (``gjk.convex_contact``), per triangle for meshes.
"""

from __future__ import annotations

import math

import numpy as np

from .. import elementary
from .._jit import inline, kernel
from ..math3d import add, dot, load3, load4, quat_conj, quat_mul, quat_rotate, quat_rotate_inv, scale, sub
from ..shapes import ShapeType
from .gjk import POINT, core_proxy, proxy_contact

__all__ = ["TOI_TARGET", "limit_to_impact"]

TOI_TARGET = 0.005  # [m] a swept core stops this close to the surface it would hit
CORE_FRACTION = 0.25  # the core's radius, as a fraction of the shape's smallest half-extent
_MAX_ITERATIONS = 32
_PLANE, _TRIMESH = int(ShapeType.PLANE), int(ShapeType.TRIMESH)


@inline
def limit_to_impact(geom, body_is_dynamic, pairs_a, pairs_b, pos0, quat0, pos, quat, body_may_move):
    """Move fast bodies back to their first touch with static geometry this step; returns how many moved.

    Reads: the broad phase's pairs, body poses at the start of the step (``pos0``, ``quat0``) and now, and
    ``body_may_move``, the bodies that may be moved back on their own (free to sweep: not jointed).
    Writes: ``pos``, ``quat`` of the bodies that would have passed into a static shape.
    """
    # One side static (not a plane), the other dynamic: the moving shape first.
    moving, fixed = np.empty(pairs_a.shape[0], np.int64), np.empty(pairs_a.shape[0], np.int64)
    count = 0
    for k in range(pairs_a.shape[0]):
        static_a = not body_is_dynamic[geom.shape_body[pairs_a[k]]]
        static_b = not body_is_dynamic[geom.shape_body[pairs_b[k]]]
        if static_a == static_b:
            continue
        m, f = (pairs_a[k], pairs_b[k]) if static_b else (pairs_b[k], pairs_a[k])
        if geom.shape_type[f] != _PLANE:
            moving[count], fixed[count] = m, f
            count += 1
    if count == 0:
        return 0
    fast = _fast_bodies(geom, pos0, quat0, pos, quat)
    swept = 0
    for k in range(count):
        b = geom.shape_body[moving[k]]
        if fast[b] and body_may_move[b]:
            moving[swept], fixed[swept] = moving[k], fixed[k]
            swept += 1
    if swept == 0:
        return 0
    t_hit = np.ones(pos.shape[0])
    _sweep_pairs(geom, moving[:swept], fixed[:swept], pos0, quat0, pos, quat, TOI_TARGET, t_hit)
    hit = np.flatnonzero(t_hit < 1.0)
    _move_to_impact(hit, t_hit, pos0, quat0, pos, quat)
    return hit.shape[0]


@inline
def _fast_bodies(geom, pos0, quat0, pos, quat):
    """Bodies whose shapes moved more than half their smallest half-extent during the step: the turn counts at the
    farthest reach of the body's shapes from its centre of mass."""
    n = pos.shape[0]
    smallest, reach = np.full(n, np.inf), np.zeros(n)
    for s in range(geom.shape_body.shape[0]):
        b = geom.shape_body[s]
        c, h = load3(geom.shape_aabb_center_local, s), load3(geom.shape_aabb_half_local, s)
        smallest[b] = min(smallest[b], h[0], h[1], h[2])
        reach[b] = max(reach[b], _norm(c) + _norm(h))
    fast = np.zeros(n, np.bool_)
    for i in range(n):
        q, q0 = load4(quat, i), load4(quat0, i)
        turn = min(max(abs(((q[0] * q0[0] + q[1] * q0[1]) + q[2] * q0[2]) + q[3] * q0[3]), 0.0), 1.0)
        lever = reach[i] if math.isfinite(reach[i]) else 0.0
        motion = _norm(sub(load3(pos, i), load3(pos0, i))) + 2.0 * elementary.acos(turn) * lever
        fast[i] = motion > 0.5 * smallest[i]
    return fast


@inline
def _norm(v):
    """``|v|``, summed in NumPy's order (``np.linalg.norm`` of a row)."""
    return math.sqrt((v[0] * v[0] + v[1] * v[1]) + v[2] * v[2])


@inline
def _pose_at(x0, q0, x1, q1, t):
    """The body pose a fraction ``t`` of the way from ``(x0, q0)`` to ``(x1, q1)`` (shortest rotation)."""
    dq = quat_mul(q1, quat_conj(q0))
    if dq[0] < 0.0:
        dq = (-dq[0], -dq[1], -dq[2], -dq[3])
    s = math.sqrt(dq[1] * dq[1] + dq[2] * dq[2] + dq[3] * dq[3])
    half_angle = elementary.atan2(s, dq[0]) * t
    if s > 0.0:
        k = elementary.sin(half_angle) / s
        turn = (elementary.cos(half_angle), dq[1] * k, dq[2] * k, dq[3] * k)
    else:
        turn = (1.0, 0.0, 0.0, 0.0)
    return add(x0, scale(sub(x1, x0), t)), quat_mul(turn, q0)


@inline
def _distance_to_static(geom, proxy, pp, qp, k, pk, qk, radius):
    """Distance from a convex proxy placed at ``(pp, qp)`` to static shape ``k``; for a mesh, to its nearest triangle
    among those that meet the ball of ``radius`` round ``pp``."""
    if geom.shape_type[k] != _TRIMESH:
        return proxy_contact(proxy, pp, qp, core_proxy(geom, k, np.int64(-1)), pk, qk, geom.vertex_local,
                             math.inf)[1]  # fmt: skip
    local = quat_rotate_inv(qk, sub(pp, pk))
    best = math.inf
    start = geom.shape_face_start[k]
    for f in range(start, start + geom.shape_face_count[k]):
        loop = geom.face_loop_start[f]
        apart = False
        for c in range(3):
            lo, hi = math.inf, -math.inf
            for v in range(3):
                x = geom.vertex_local[geom.face_loop[loop + v], c]
                lo, hi = min(lo, x), max(hi, x)
            if local[c] + radius < lo or local[c] - radius > hi:
                apart = True
        if not apart:
            triangle = core_proxy(geom, k, f)
            best = min(best, proxy_contact(proxy, pp, qp, triangle, pk, qk, geom.vertex_local, math.inf)[1])
    return best


@kernel
def _advance(geom, proxy, offset, offset_quat, reach, x0, q0, x1, q1, k, pk, qk, target):
    """Conservative advancement of a proxy carried by the body (at ``offset``, ``offset_quat`` in the body frame;
    no point of it farther than ``reach`` from the centre of mass) against static shape ``k``: the first ``t`` at
    which it comes within ``target``, 1 if it never does, -1 if it is that close already at the start."""
    dq = quat_mul(q1, quat_conj(q0))
    angle = 2.0 * elementary.atan2(math.sqrt(dq[1] ** 2 + dq[2] ** 2 + dq[3] ** 2), abs(dq[0]))
    travel = math.sqrt(dot(sub(x1, x0), sub(x1, x0)))
    speed = travel + angle * reach  # no point of the proxy moves faster, per unit of t
    t = 0.0
    for iteration in range(_MAX_ITERATIONS):
        xb, qb = _pose_at(x0, q0, x1, q1, t)
        pp, qp = add(xb, quat_rotate(qb, offset)), quat_mul(qb, offset_quat)
        d = _distance_to_static(geom, proxy, pp, qp, k, pk, qk, reach + travel + angle * reach)
        if d <= target:
            return t if iteration > 0 else -1.0
        if speed <= 0.0:
            return 1.0
        t += (d - 0.5 * target) / speed
        if t >= 1.0:
            return 1.0
    return t


@inline
def _sweep_pairs(geom, moving, fixed, pos0, quat0, pos, quat, target, t_hit):
    """The earliest touch of each fast body with static geometry this step (``t_hit``, left at 1 when none).

    Each shape is swept whole; one that touches its partner already at the start is swept again by its core (to
    a fifth of the target), so that a body pressed into a wall cannot slip through it either."""
    zero = (0.0, 0.0, 0.0)
    identity = (1.0, 0.0, 0.0, 0.0)
    for p in range(moving.shape[0]):
        s, k = moving[p], fixed[p]
        b, kb = geom.shape_body[s], geom.shape_body[k]
        x0, q0, x1, q1 = load3(pos0, b), load4(quat0, b), load3(pos, b), load4(quat, b)
        qkb = load4(quat, kb)
        pk = add(load3(pos, kb), quat_rotate(qkb, load3(geom.shape_pos_local, k)))
        qk = quat_mul(qkb, load4(geom.shape_quat_local, k))
        c, h = load3(geom.shape_aabb_center_local, s), load3(geom.shape_aabb_half_local, s)
        whole = core_proxy(geom, s, np.int64(-1))
        t = _advance(geom, whole, load3(geom.shape_pos_local, s), load4(geom.shape_quat_local, s),
                     math.sqrt(dot(c, c)) + math.sqrt(dot(h, h)), x0, q0, x1, q1, k, pk, qk, target)  # fmt: skip
        if t < 0.0:
            r = CORE_FRACTION * min(h[0], h[1], h[2])
            core = (POINT, r, r, 0.0, 0.0, 0.0, np.int64(0), np.int64(0), zero, zero, zero, zero)
            t = _advance(geom, core, c, identity, math.sqrt(dot(c, c)), x0, q0, x1, q1, k, pk, qk, 0.2 * target)
        if 0.0 <= t < t_hit[b]:
            t_hit[b] = t


@inline
def _move_to_impact(bodies, t_hit, pos0, quat0, pos, quat):
    for i in bodies:
        x, q = _pose_at(load3(pos0, i), load4(quat0, i), load3(pos, i), load4(quat, i), t_hit[i])
        pos[i, 0], pos[i, 1], pos[i, 2] = x
        quat[i, 0], quat[i, 1], quat[i, 2], quat[i, 3] = q
