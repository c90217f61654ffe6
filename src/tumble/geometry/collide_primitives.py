"""Closed-form contact manifolds between the primitive shapes (sphere, capsule, box; cylinder and hull on planes).

Every ``collide_<a>_<b>`` kernel has the signature of :mod:`tumble.geometry.manifold` and writes up to four points
midway between the surfaces, their signed separations along one normal from ``a`` to ``b`` (points closer than
``margin`` are kept as speculative contacts) and their feature ids.

- sphere–sphere, sphere–capsule, sphere–box: the closest point of ``b`` to the centre; a centre inside the box
  leaves through the nearest face, coincident centres separate along +z.
- capsule–capsule: closest points of the two segments (Ericson, *Real-Time Collision Detection*, 2005, §5.1.9);
  nearly parallel segments (within 2.9°) give the two ends of their common stretch instead, when both are within
  the margin and the axes pass there within a tenth of the thinner radius of each other.
- capsule–box: the exact closest point of the segment to the box (the squared distance along the segment is
  convex and piecewise quadratic, so the zero of its piecewise linear slope is found between breakpoints); a
  segment that cuts the box takes the separating axis of least penetration among the 3 face normals and the 3
  segment × edge directions. Over a face the capsule's lowest surface line is clipped to the face rectangle, the
  end ball's lowest point standing in for the line's end on its side: up to two points, on both surfaces.
- box–box: separating-axis test on 15 axes (Gottschalk et al., "OBBTree", SIGGRAPH 1996; Ericson §4.4.1), face
  axes preferred unless an edge axis is clearly better (Gregorius, "The Separating Axis Test between Convex
  Polyhedra", GDC 2013), which keeps the choice steady from step to step. A face contact intersects the
  reference face with the incident face (the most anti-parallel face of the other box): the intersection's
  vertices are the incident vertices inside the reference rectangle, the incident edges' crossings of its sides
  and the reference corners inside the incident face: exactly the vertices Sutherland–Hodgman clipping gives,
  enumerated into 16 fixed slots so nothing is allocated and each vertex carries the features that made it.
  An edge contact is one point at the closest points of the two edges. Boxes apart across a gap whose faces'
  outlines miss each other (their nearest features parallel edges or a corner, the gap diagonal) get one
  speculative point at the nearest points instead, from GJK (:mod:`tumble.geometry.gjk`): without it a box
  falling past another's edge at 13.6 m/s went 6.4 cm into it within the step (issue 44).
- box, capsule, cylinder, hull on a plane: the vertices (corners, segment ends, cap-rim samples) below the margin.

Choices between equal candidates keep the first one: separating axes and nearest faces within ``_TIE_DISTANCE``
(1e-9 m), contact points within ``_PREFERENCE`` (0.1 mm), so round-off and solver noise do not change them, or the
feature ids, from one step to the next.

:func:`reduce_manifold` keeps at most four of many candidates: the deepest, the farthest from it, then the ones
that add the most area (Gregorius, "Robust Contact Creation for Physics Simulations", GDC 2015).

**Feature ids** are ``code_a << 32 | code_b``, one code per shape naming the feature the point came from:

=========  ===========================================================================================
sphere     0
capsule    0 the end at ``-half_length``, 1 the end at ``+half_length``, 2 a point between them
box        vertex ``0..7`` (bit ``k`` set: on the + side of axis ``k``); edge ``8 + 4 axis + bits`` (the
           sides of the two other axes, lower axis in bit 0); face ``20 + 2 axis + (1 on the + side)``;
           ``26`` the nearest point of a box-box pair apart across a gap (both codes)
cylinder   ``4 cap + k`` (cap 0 at ``-half_height``, 1 at ``+``; ``k`` the rim sample below)
hull       the vertex's index within the hull
plane      0
=========  ===========================================================================================

A box-box point made by the incident vertex ``v`` inside the reference face ``f`` is ``(f, v)``; by the incident
edge ``e`` crossing the side edge ``s`` of the reference face ``(s, e)``; by the reference corner ``c`` inside the
incident face ``g`` ``(c, g)`` (reference code first when the reference box is ``a``). The id names the touching
features, not where the point is, so it stays the same from step to step while they touch. One-point sphere
manifolds always use 0 (the point slides continuously over the other shape).
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import inline, kernel
from ..math3d import (
    abs3,
    add,
    add_scaled,
    cross,
    dot,
    length3,
    lerp3,
    mat_column,
    mat_vec,
    normalize3,
    perpendicular3,
    quat_conj,
    quat_mul,
    quat_rotate,
    quat_rotate_inv,
    quat_to_mat33,
    scale,
    store3,
    sub,
)
from .gjk import core_proxy, proxy_contact

__all__ = [
    "collide_sphere_sphere",
    "collide_sphere_capsule",
    "collide_sphere_box",
    "collide_capsule_capsule",
    "collide_capsule_box",
    "collide_box_box",
    "collide_sphere_plane",
    "collide_capsule_plane",
    "collide_box_plane",
    "collide_cylinder_plane",
    "collide_hull_plane",
    "reduce_manifold",
]

_UP = (0.0, 0.0, 1.0)
# Below this distance [m] two centres (or a centre and a segment) coincide: the normal falls back to a fixed
# direction instead of dividing by a length of round-off size.
_TINY_LENGTH = 1e-12
# Candidate points closer than this [m] in the contact plane are one point to the reduction and the clipping.
_MERGE_DISTANCE = 1e-6
# Choices between candidates (separating axes, nearest faces) keep the first of those that agree within this [m]:
# far above round-off for shapes up to km in size, far below anything a contact can resolve.
_TIE_DISTANCE = 1e-9
# The reduction keeps the first of candidate points whose depths, spreads or areas agree within 0.1 mm (a fiftieth
# of the solver's 5 mm slop), and incident corners that far past the reference face's rim count as on it: solver
# noise (a stack twisting by 1e-4 rad) then changes neither the chosen points nor their feature ids.
_PREFERENCE = 1e-4
# A manifold's second point is the farthest of those whose rise per distance from the first is within this of the
# least (tan 2.9°): a face tilted less than that still keeps its widest spread.
_SLOPE_PREFERENCE = 0.05
# Separating-axis bias (after Gregorius 2013 and Box2D's 0.98 × + ½ slop): another axis replaces the preferred
# one (faces of a, then faces of b, then edges) only when its separation is larger by 5 % of the preferred one's
# size plus 1 mm. Round-off and small rotations then never flip the reference face between steps.
_AXIS_BIAS_RELATIVE = 0.05
_AXIS_BIAS_ABSOLUTE = 1e-3
# The feature code of a box-box pair's nearest points across a gap (past the vertex, edge and face codes 0-25).
_NEAREST_CODE = 26
# Two segments count as parallel (two-point manifold) below sin(angle) = 0.05, about 2.9°.
_PARALLEL_SIN = 0.05
# A segment along a box edge within |cos| >= 0.9988 (about 2.8°) clips to the edge (two points).
_EDGE_PARALLEL_COS = 0.9988
# Cross products of nearly parallel edges shorter than this are not tested as axes (their direction is
# round-off); the face axes already cover parallel edges.
_MIN_AXIS_LENGTH = 1e-6


# --- small helpers -------------------------------------------------------------------------------------------


@inline
def _feature_id(code_a, code_b):
    return (code_a << 32) | code_b


@inline
def _sign(x):
    """+1 for x >= 0, else -1: ties pick the + side, so a symmetric pose gives a fixed answer."""
    return 1.0 if x >= 0.0 else -1.0


@inline
def _clamp(x, lo, hi):
    return min(max(x, lo), hi)


@kernel
def _unit(k):
    if k == 0:
        return (1.0, 0.0, 0.0)
    if k == 1:
        return (0.0, 1.0, 0.0)
    return (0.0, 0.0, 1.0)


@inline
def _from_axes(k, x, y, z):
    """The vector with ``z`` along axis ``k``, ``x`` along axis ``k+1`` and ``y`` along axis ``k+2`` (mod 3)."""
    if k == 0:
        return (z, x, y)
    if k == 1:
        return (y, z, x)
    return (x, y, z)


@inline
def _to_axes(k, p):
    """Inverse of :func:`_from_axes`: ``(p[k+1], p[k+2], p[k])``."""
    if k == 0:
        return (p[1], p[2], p[0])
    if k == 1:
        return (p[2], p[0], p[1])
    return (p[0], p[1], p[2])


@inline
def _with_component(v, k, value):
    if k == 0:
        return (value, v[1], v[2])
    if k == 1:
        return (v[0], value, v[2])
    return (v[0], v[1], value)


@inline
def _box_code(c):
    """Feature code of the box feature whose centre is ``c`` (box frame): its zero components are the axes
    along which the feature extends (none: vertex, one: edge, two: face)."""
    zero0, zero1, zero2 = c[0] == 0.0, c[1] == 0.0, c[2] == 0.0
    zeros = int(zero0) + int(zero1) + int(zero2)
    if zeros == 0:
        return int(c[0] > 0.0) + 2 * int(c[1] > 0.0) + 4 * int(c[2] > 0.0)
    if zeros == 1:
        j = 0 if zero0 else (1 if zero1 else 2)
        lo, hi = (1, 2) if j == 0 else ((0, 2) if j == 1 else (0, 1))
        return 8 + 4 * j + int(c[lo] > 0.0) + 2 * int(c[hi] > 0.0)
    k = 0 if not zero0 else (1 if not zero1 else 2)
    return 20 + 2 * k + int(c[k] > 0.0)


@inline
def _clearly_better(separation, preferred):
    """Whether an axis of ``separation`` should replace the ``preferred`` one (the separating-axis bias)."""
    return separation > preferred + _AXIS_BIAS_RELATIVE * abs(preferred) + _AXIS_BIAS_ABSOLUTE


@inline
def _set_normal(normal, n):
    normal[0] = n[0]
    normal[1] = n[1]
    normal[2] = n[2]


@inline
def _write_point(point, separation, feature, i, p, sep, fid):
    store3(point, i, p)
    separation[i] = sep
    feature[i] = fid


@inline
def _params3(geom, shape):
    return (geom.shape_params[shape, 0], geom.shape_params[shape, 1], geom.shape_params[shape, 2])


@inline
def _plane_world(geom, shape, pos, quat):
    """World unit normal ``n`` and offset ``d`` of a plane shape: its points are ``n · x = d``."""
    n = quat_rotate(quat, _params3(geom, shape))
    return n, geom.shape_params[shape, 3] + dot(n, pos)


# --- manifold reduction --------------------------------------------------------------------------------------


@kernel
def reduce_manifold(points, normal, offset, margin):
    """Choose up to four of the candidate ``points`` that lie below ``margin`` from the plane ``normal · x = offset``.

    A deepest point comes first (it carries the penetration): of those within ``_PREFERENCE`` of the deepest, the
    one farthest from their centroid, a corner of the contact polygon. Then the one that comes down next as the
    shape tips about it (the least rise per distance; of those within ``_SLOPE_PREFERENCE`` of it, the farthest in
    the plane), the one making the largest triangle with those two, and the one adding the most area outside that
    triangle (Gregorius, GDC 2015). Points within ``_MERGE_DISTANCE`` of the chosen ones add nothing and are skipped. A
    candidate must beat the best so far by ``_PREFERENCE`` to replace it, so nearly equal candidates (a face lying
    flat) resolve to the lowest index whatever the round-off or solver noise, and the chosen ids stay the same
    from step to step; the deepest point kept can be up to 0.1 mm shallower than the deepest candidate.

    Args:
        points: indexable by candidate, each item a point ``(x, y, z, ...)`` whose first three entries are its
            coordinates: a tuple of tuples (fixed candidate sets) or an ``(n, 3)`` array (hull vertices).
            Its separation is ``normal · p - offset``; items at ``+inf`` separation are empty slots.
        normal: unit 3-tuple in the frame of ``points``.
        offset: [m] plane offset; margin: [m] keep points whose separation is below it.

    Returns:
        ``(count, i0, i1, i2, i3)``: how many were chosen and their indices (the unused ones are -1).
    """
    count = len(points)
    # The anchor: the most outlying of the deepest points (within the preference), so that a face lying flat
    # starts from a corner of its contact polygon rather than from wherever round-off puts the minimum.
    deepest = margin
    for k in range(count):
        deepest = min(deepest, dot(points[k], normal) - offset)
    if not deepest < margin:
        return 0, -1, -1, -1, -1
    limit = min(deepest + _PREFERENCE, margin)
    centre, weight = (0.0, 0.0, 0.0), 0.0
    for k in range(count):
        if dot(points[k], normal) - offset < limit:
            centre, weight = add(centre, (points[k][0], points[k][1], points[k][2])), weight + 1.0
    centre = scale(centre, 1.0 / weight)
    i0, best = -1, 0.0
    for k in range(count):
        if dot(points[k], normal) - offset < limit:
            distance = _planar_distance(points[k], centre, normal)
            if i0 < 0 or distance > best + _PREFERENCE:
                best, i0 = distance, k
    if i0 < 0:
        return 0, -1, -1, -1, -1
    p0 = points[i0]
    s0 = dot(p0, normal) - offset
    # The first to come down as the shape tips about it: the least rise per distance in the plane. Of those within
    # _SLOPE_PREFERENCE of that, the farthest, so that a face lying flat keeps its widest spread. A corner 1.4 cm up
    # and 34 cm away must not lose its place to wider ones 8 cm up: it is the one that goes in next.
    least = math.inf
    for k in range(count):
        if dot(points[k], normal) - offset < margin:
            distance = _planar_distance(points[k], p0, normal)
            if distance > _MERGE_DISTANCE:
                least = min(least, (dot(points[k], normal) - offset - s0) / distance)
    i1, best = -1, _MERGE_DISTANCE
    for k in range(count):
        if dot(points[k], normal) - offset < margin:
            distance = _planar_distance(points[k], p0, normal)
            slope = (dot(points[k], normal) - offset - s0) / max(distance, _MERGE_DISTANCE)
            if slope <= least + _SLOPE_PREFERENCE and distance > best + _PREFERENCE:
                best, i1 = distance, k
    if i1 < 0:
        return 1, i0, -1, -1, -1
    e = sub(points[i1], p0)
    e_length = length3(e)
    # Largest triangle with those two: the largest distance from the line through them.
    i2, best, orientation = -1, _MERGE_DISTANCE, 1.0
    for k in range(count):
        if dot(points[k], normal) - offset < margin:
            height = dot(cross(e, sub(points[k], p0)), normal) / e_length
            if abs(height) > best + _PREFERENCE:
                best, i2, orientation = abs(height), k, _sign(height)
    if i2 < 0:
        return 2, i0, i1, -1, -1
    # Most area added outside the triangle: the largest (twice) area beyond one of its edges.
    p1, p2 = points[i1], points[i2]
    i3, best = -1, 0.0
    for k in range(count):
        if dot(points[k], normal) - offset < margin:
            gain = max(
                _outside_area(p0, p1, points[k], normal, orientation),
                _outside_area(p1, p2, points[k], normal, orientation),
                _outside_area(p2, p0, points[k], normal, orientation),
            )
            if gain > best + _PREFERENCE * e_length:
                best, i3 = gain, k
    if i3 < 0:
        return 3, i0, i1, i2, -1
    return 4, i0, i1, i2, i3


@inline
def _planar_distance(p, q, normal):
    """Distance from ``p`` to ``q`` within the plane of unit ``normal``."""
    d = (p[0] - q[0], p[1] - q[1], p[2] - q[2])
    h = dot(d, normal)
    return math.sqrt(max(dot(d, d) - h * h, 0.0))


@inline
def _outside_area(u, v, p, normal, orientation):
    """Twice the area of triangle ``(u, v, p)`` when ``p`` lies outside the edge ``u → v`` of a triangle wound
    with ``orientation`` about ``normal`` by more than the merge distance, else 0."""
    edge = sub(v, u)
    area = -orientation * dot(cross(edge, sub(p, u)), normal)
    return area if area > _MERGE_DISTANCE * length3(edge) else 0.0


# --- sphere pairs --------------------------------------------------------------------------------------------


@inline
def _ball_contact(center_a, radius_a, center_b, radius_b, fallback, margin, fid, normal, point, separation, feature):
    """One point between two balls (a sphere, or a capsule's ball at its closest segment point)."""
    d = sub(center_b, center_a)
    dist = length3(d)
    sep = dist - radius_a - radius_b
    if not sep < margin:
        return 0
    n = scale(d, 1.0 / dist) if dist > _TINY_LENGTH else fallback
    _set_normal(normal, n)
    _write_point(point, separation, feature, 0, add_scaled(center_a, n, radius_a + 0.5 * sep), sep, fid)
    return 1


@kernel
def collide_sphere_sphere(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                          feature):  # fmt: skip
    """Sphere–sphere: along the line of centres, +z when they coincide."""
    r_a, r_b = geom.shape_params[shape_a, 0], geom.shape_params[shape_b, 0]
    return _ball_contact(pos_a, r_a, pos_b, r_b, _UP, margin, 0, normal, point, separation, feature)


@kernel
def collide_sphere_capsule(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                           feature):  # fmt: skip
    """Sphere–capsule: the sphere against the capsule's ball at the segment point closest to the centre; a
    centre on the segment leaves sideways."""
    axis = quat_rotate(quat_b, _UP)
    half_length = geom.shape_params[shape_b, 1]
    s = _clamp(dot(sub(pos_a, pos_b), axis), -half_length, half_length)
    closest = add_scaled(pos_b, axis, s)
    r_a, r_b = geom.shape_params[shape_a, 0], geom.shape_params[shape_b, 0]
    return _ball_contact(pos_a, r_a, closest, r_b, perpendicular3(axis), margin, 0, normal, point, separation,
                         feature)  # fmt: skip


@inline
def _nearest_face(c, half):
    """``(axis, side, gap)`` of the box face nearest to the inside point ``c`` (box frame), ``gap >= 0``."""
    best, axis, side = math.inf, 0, 1.0
    for k in range(3):
        if half[k] - c[k] < best - _TIE_DISTANCE:
            best, axis, side = half[k] - c[k], k, 1.0
        if half[k] + c[k] < best - _TIE_DISTANCE:
            best, axis, side = half[k] + c[k], k, -1.0
    return axis, side, best


@kernel
def collide_sphere_box(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                       feature):  # fmt: skip
    """Sphere–box: the box point closest to the centre; a centre inside the box leaves through the nearest face."""
    radius = geom.shape_params[shape_a, 0]
    half = _params3(geom, shape_b)
    c = quat_rotate_inv(quat_b, sub(pos_a, pos_b))
    q = (_clamp(c[0], -half[0], half[0]), _clamp(c[1], -half[1], half[1]), _clamp(c[2], -half[2], half[2]))
    d = sub(c, q)
    dist = length3(d)
    if dist > _TINY_LENGTH:
        outward, sep = scale(d, 1.0 / dist), dist - radius
    else:
        axis, side, gap = _nearest_face(c, half)
        q = _with_component(c, axis, side * half[axis])
        outward, sep = scale(_unit(axis), side), -gap - radius
    if not sep < margin:
        return 0
    # outward leaves the box towards the centre; the normal from the sphere to the box is its opposite.
    outward_world = quat_rotate(quat_b, outward)
    _set_normal(normal, scale(outward_world, -1.0))
    surface_b = add(pos_b, quat_rotate(quat_b, q))
    _write_point(point, separation, feature, 0, add_scaled(surface_b, outward_world, 0.5 * sep), sep, 0)
    return 1


# --- capsule-capsule -----------------------------------------------------------------------------------------


@inline
def _closest_segments(p1, d1, h1, p2, d2, h2):
    """Parameters ``(s, t)`` of the closest points ``p1 + s d1`` and ``p2 + t d2`` of two segments given by their
    centres, unit directions and half-lengths (Ericson 2005, §5.1.9, with centred parameters). Parallel
    segments take the middle of their common stretch, which is the same stretch seen from either one."""
    r = sub(p1, p2)
    b, c, f = dot(d1, d2), dot(d1, r), dot(d2, r)
    denom = 1.0 - b * b
    if denom > 1e-12:
        s = _clamp((b * f - c) / denom, -h1, h1)
    else:
        reach = h2 * abs(b)
        lo, hi = max(-h1, -c - reach), min(h1, -c + reach)
        s = 0.5 * (lo + hi) if lo <= hi else _clamp(-c, -h1, h1)
    t = b * s + f
    if t < -h2:
        t = -h2
        s = _clamp(b * t - c, -h1, h1)
    elif t > h2:
        t = h2
        s = _clamp(b * t - c, -h1, h1)
    return s, t


@inline
def _end_code(s, half_length):
    """Capsule feature code of the segment point at parameter ``s``: an end (0, 1) or in between (2)."""
    if s <= -half_length:
        return 0
    if s >= half_length:
        return 1
    return 2


@inline
def _parallel_capsule_points(pos_a, u_a, h_a, r_a, pos_b, u_b, h_b, r_b, n, margin, point, separation, feature):
    """Two points at the ends of the stretch that nearly parallel segments share, with separations along ``n``;
    0 when the stretch is shorter than the merge distance, or an end is beyond the margin or off to the side."""
    along = dot(u_a, u_b)
    centre, reach = dot(sub(pos_b, pos_a), u_a), h_b * abs(along)
    lo, hi = max(-h_a, centre - reach), min(h_a, centre + reach)
    if hi - lo <= _MERGE_DISTANCE:
        return 0
    # The end of b that bounds the stretch from below along a, and the one from above.
    b_low, b_high = (0, 1) if along >= 0.0 else (1, 0)
    for i in range(2):
        s = lo if i == 0 else hi
        p = add_scaled(pos_a, u_a, s)
        t = _clamp(dot(sub(p, pos_b), u_b), -h_b, h_b)
        gap = sub(add_scaled(pos_b, u_b, t), p)
        sep = dot(gap, n) - r_a - r_b
        # The axes must also pass within a tenth of the thinner radius of each other sideways at both ends
        # (segments that cross at a small angle over a long stretch touch at one point); the points then lie
        # within 0.005 of that radius of the surfaces.
        sideways = length3(add_scaled(gap, n, -dot(gap, n)))
        if not (sep < margin and sideways <= 0.1 * min(r_a, r_b)):
            return 0
        code_a = _end_code(s, h_a)
        code_b = 2 if code_a != 2 else (b_low if i == 0 else b_high)
        _write_point(point, separation, feature, i, add_scaled(p, n, r_a + 0.5 * sep), sep, _feature_id(code_a, code_b))
    return 2


@kernel
def collide_capsule_capsule(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point,
                            separation, feature):  # fmt: skip
    """Capsule–capsule: closest points of the segments; nearly parallel ones give the two ends of their common
    stretch (a capsule lying on another)."""
    r_a, h_a = geom.shape_params[shape_a, 0], geom.shape_params[shape_a, 1]
    r_b, h_b = geom.shape_params[shape_b, 0], geom.shape_params[shape_b, 1]
    u_a, u_b = quat_rotate(quat_a, _UP), quat_rotate(quat_b, _UP)
    s, t = _closest_segments(pos_a, u_a, h_a, pos_b, u_b, h_b)
    p_a, p_b = add_scaled(pos_a, u_a, s), add_scaled(pos_b, u_b, t)
    d = sub(p_b, p_a)
    dist = length3(d)
    if not dist - r_a - r_b < margin:
        return 0
    axis_cross = cross(u_a, u_b)
    sin_angle = length3(axis_cross)
    interior = sin_angle > _MIN_AXIS_LENGTH and abs(s) < h_a and abs(t) < h_b
    if interior or (dist <= _TINY_LENGTH and sin_angle > 1e-12):
        # Closest points inside both (non-parallel) segments, or segments that cross, lie on the common
        # perpendicular. Its direction from the cross product carries ~1e-16 / sin of round-off, where d / |d|
        # would carry the closest-point parameters' ~1e-16 / sin² (nearly parallel capsules lying on each other).
        n = scale(axis_cross, 1.0 / sin_angle)
        n = scale(n, _sign(dot(n, d if dist > _TINY_LENGTH else sub(pos_b, pos_a))))
        dist = abs(dot(d, n))
    elif dist > _TINY_LENGTH:
        n = scale(d, 1.0 / dist)
    else:
        # Parallel segments that overlap on one line: out sideways, towards b's centre.
        n = perpendicular3(u_a)
        n = scale(n, _sign(dot(n, sub(pos_b, pos_a))))
    sep = dist - r_a - r_b
    _set_normal(normal, n)
    if sin_angle < _PARALLEL_SIN:
        count = _parallel_capsule_points(pos_a, u_a, h_a, r_a, pos_b, u_b, h_b, r_b, n, margin, point, separation,
                                         feature)  # fmt: skip
        if count > 0:
            return count
    fid = _feature_id(_end_code(s, h_a), _end_code(t, h_b))
    _write_point(point, separation, feature, 0, add_scaled(p_a, n, r_a + 0.5 * sep), sep, fid)
    return 1


# --- capsule-box ---------------------------------------------------------------------------------------------


@inline
def _box_excess_slope(c, u, s, half):
    """Half the derivative of the squared distance from ``c + s u`` to the box: ``(p - clamp(p)) · u``."""
    p = add_scaled(c, u, s)
    return (
        (p[0] - _clamp(p[0], -half[0], half[0])) * u[0]
        + (p[1] - _clamp(p[1], -half[1], half[1])) * u[1]
        + (p[2] - _clamp(p[2], -half[2], half[2])) * u[2]
    )


@inline
def _segment_box_closest(c, u, half_length, half):
    """Parameter of the point of segment ``c + s u``, ``|s| <= half_length``, closest to the box (box frame).

    The squared distance is convex and quadratic between the parameters where the segment crosses a face
    plane, so its slope is piecewise linear and non-decreasing: bracket the slope's zero between two adjacent
    breakpoints and interpolate linearly, which is exact.
    """
    lo, hi = -half_length, half_length
    g_lo, g_hi = _box_excess_slope(c, u, lo, half), _box_excess_slope(c, u, hi, half)
    if g_lo >= 0.0:
        return lo
    if g_hi <= 0.0:
        return hi
    for k in range(3):
        if abs(u[k]) > _TINY_LENGTH:
            for side in (-1.0, 1.0):
                s = (side * half[k] - c[k]) / u[k]
                if lo < s < hi:
                    g = _box_excess_slope(c, u, s, half)
                    if g <= 0.0:
                        lo, g_lo = s, g
                    else:
                        hi, g_hi = s, g
    return lo - g_lo * (hi - lo) / (g_hi - g_lo)


@inline
def _capsule_box_sat(c, u, half_length, half):
    """For a segment that cuts the box: the axis of least penetration among the 3 face normals and the 3
    segment × edge directions (faces preferred within the bias). Returns ``(m, centre, s)``: the unit axis from
    the box towards the segment (box frame), the centre of the box feature it touches and the segment
    parameter of the deepest point."""
    best_face, face = -math.inf, 0
    for k in range(3):
        sep = abs(c[k]) - half_length * abs(u[k]) - half[k]
        if sep > best_face + _TIE_DISTANCE:
            best_face, face = sep, k
    best_edge, edge, edge_axis = -math.inf, 0, _UP
    for k in range(3):
        axis = cross(u, _unit(k))
        length = length3(axis)
        if length > _MIN_AXIS_LENGTH:
            axis = scale(axis, 1.0 / length)
            d = dot(c, axis)
            sep = abs(d) - dot(half, abs3(axis))
            if sep > best_edge + _TIE_DISTANCE:
                best_edge, edge, edge_axis = sep, k, scale(axis, _sign(d))
    if _clearly_better(best_edge, best_face):
        m = edge_axis
        centre = _with_component((_sign(m[0]) * half[0], _sign(m[1]) * half[1], _sign(m[2]) * half[2]), edge, 0.0)
        s, _ = _closest_segments(c, u, half_length, centre, _unit(edge), half[edge])
        return m, centre, s
    side = _sign(c[face])
    m = scale(_unit(face), side)
    s = -half_length if dot(u, m) >= 0.0 else half_length
    return m, _from_axes(face, 0.0, 0.0, side * half[face]), s


@inline
def _clip_to_feature(c, u, half_length, half, centre):
    """Clip the segment to the slabs of the axes along which the box feature at ``centre`` extends.

    Returns ``(s0, a0, b0, s1, a1, b1)``: the two ends' parameters, their capsule codes and their box codes (the
    feature itself, or the side feature that clipped the end); ``s0 > s1`` when nothing is left.
    """
    code = _box_code(centre)
    s0, a0, b0, s1, a1, b1 = -half_length, 0, code, half_length, 1, code
    for j in range(3):
        if centre[j] != 0.0:
            continue
        for side in (-1.0, 1.0):
            # side (c_j + s u_j) <= half_j, as a s <= b.
            a, b = side * u[j], half[j] - side * c[j]
            if abs(a) < _TINY_LENGTH:
                if b < 0.0:
                    return 1.0, 2, code, -1.0, 2, code
                continue
            t = b / a
            side_code = _box_code(_with_component(centre, j, side * half[j]))
            if a > 0.0 and t < s1:
                s1, a1, b1 = t, 2, side_code
            elif a < 0.0 and t > s0:
                s0, a0, b0 = t, 2, side_code
    return s0, a0, b0, s1, a1, b1


@inline
def _upright(u, m):
    """Whether the capsule axis ``u`` is along ``m``: its cross-section then has no lowest line, only the end
    ball's lowest point."""
    along = dot(u, m)
    return math.sqrt(max(0.0, 1.0 - along * along)) <= _MIN_AXIS_LENGTH


@inline
def _capsule_reach(u, m, t, half_length):
    """Unit direction from the segment point at ``t`` to the capsule's surface point lowest along ``-m``.

    At the segment end that sticks out along ``-m`` it is ``m`` itself (the end ball's lowest point); elsewhere
    the ball's lowest point lies inside the capsule, so the lowest point of the cylinder's cross-section is taken
    instead: ``m`` without its component along the axis ``u``.
    """
    along = dot(u, m)
    if (t <= -half_length and along >= 0.0) or (t >= half_length and along <= 0.0):
        return m
    across = add_scaled(m, u, -along)
    length = length3(across)
    return scale(across, 1.0 / length) if length > _MIN_AXIS_LENGTH else m


@inline
def _over_feature(p, half, centre):
    """Whether ``p`` lies within the slabs of the axes along which the box feature at ``centre`` extends."""
    for j in range(3):
        if centre[j] == 0.0 and abs(p[j]) > half[j]:
            return False
    return True


@inline
def _emit_capsule_point(count, surface, m, support, margin, fid, pos_b, quat_b, point, separation, feature):
    """Write the point of the capsule surface point ``surface`` (box frame) against the box's support plane
    along ``m`` if it is within the margin; returns the new count."""
    sep = dot(surface, m) - support
    if not sep < margin:
        return count
    mid = add_scaled(surface, m, -0.5 * sep)
    _write_point(point, separation, feature, count, add(pos_b, quat_rotate(quat_b, mid)), sep, fid)
    return count + 1


@inline
def _capsule_box_points(c, u, half_length, radius, half, m, centre, s, margin, pos_b, quat_b, normal, point,
                        separation, feature):  # fmt: skip
    """Write the capsule–box points for the box feature at ``centre`` touched along ``m`` (box frame, box →
    capsule).

    Over a face (or along a parallel edge) the capsule's lowest surface line along ``-m`` is clipped to the
    feature; the end ball's lowest point replaces the line's end on its side when it lies over the feature (it is
    the capsule's deepest point). Otherwise one point at the segment parameter ``s``.
    """
    code = _box_code(centre)
    support = dot(half, abs3(m))
    free = int(centre[0] == 0.0) + int(centre[1] == 0.0) + int(centre[2] == 0.0)
    along_edge = False
    if free == 1:
        j = 0 if centre[0] == 0.0 else (1 if centre[1] == 0.0 else 2)
        along_edge = abs(u[j]) >= _EDGE_PARALLEL_COS
    # Candidates: up to two clipped points, then the closest point if neither is within the margin.
    closest = (add_scaled(add_scaled(c, u, s), _capsule_reach(u, m, s, half_length), -radius),
               _feature_id(_end_code(s, half_length), code))  # fmt: skip
    first, second, clipped = closest, closest, 0
    if free == 2 or along_edge:
        line = add_scaled(c, _capsule_reach(u, m, 0.0, half_length), -radius)
        t0, a0, b0, t1, a1, b1 = _clip_to_feature(line, u, half_length, half, centre)
        low = -half_length if dot(u, m) >= 0.0 else half_length
        ball = add_scaled(add_scaled(c, u, low), m, -radius)
        if _over_feature(ball, half, centre):
            first, clipped = (ball, _feature_id(_end_code(low, half_length), code)), 1
            # The line's end away from the ball, if the clipped line reaches away from it.
            far, a_far, b_far = (t1, a1, b1) if low < 0.0 else (t0, a0, b0)
            if t0 <= t1 and abs(far - low) > _MERGE_DISTANCE and not _upright(u, m):
                second, clipped = (add_scaled(line, u, far), _feature_id(a_far, b_far)), 2
        elif t1 - t0 > _MERGE_DISTANCE and not _upright(u, m):
            first = (add_scaled(line, u, t0), _feature_id(a0, b0))
            second, clipped = (add_scaled(line, u, t1), _feature_id(a1, b1)), 2
    count = 0
    for i in range(3):
        if i < max(clipped, 1):
            surface, fid = first if i == 0 else second
        elif i == 2 and count == 0 and clipped > 0:
            surface, fid = closest
        else:
            continue
        count = _emit_capsule_point(count, surface, m, support, margin, fid, pos_b, quat_b, point, separation,
                                    feature)  # fmt: skip
    if count > 0:
        _set_normal(normal, scale(quat_rotate(quat_b, m), -1.0))
    return count


@kernel
def collide_capsule_box(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                        feature):  # fmt: skip
    """Capsule–box: the segment's closest point to the box names the touching box feature (face, edge or vertex);
    a segment that cuts the box uses the separating axis of least penetration. Up to two points."""
    radius, half_length = geom.shape_params[shape_a, 0], geom.shape_params[shape_a, 1]
    half = _params3(geom, shape_b)
    c = quat_rotate_inv(quat_b, sub(pos_a, pos_b))
    u = quat_rotate_inv(quat_b, quat_rotate(quat_a, _UP))
    s = _segment_box_closest(c, u, half_length, half)
    p = add_scaled(c, u, s)
    # Components outside the box by more than round-off name the feature: the centre of the touched feature has
    # the box's extent there and 0 along the axes the feature spans.
    tol = 1e-9 * (1.0 + max(half[0], max(half[1], half[2])))
    centre = (
        _sign(p[0]) * half[0] if abs(p[0]) > half[0] + tol else 0.0,
        _sign(p[1]) * half[1] if abs(p[1]) > half[1] + tol else 0.0,
        _sign(p[2]) * half[2] if abs(p[2]) > half[2] + tol else 0.0,
    )
    if centre[0] == 0.0 and centre[1] == 0.0 and centre[2] == 0.0:
        m, centre, s = _capsule_box_sat(c, u, half_length, half)
    else:
        d = (
            p[0] - centre[0] if centre[0] != 0.0 else 0.0,
            p[1] - centre[1] if centre[1] != 0.0 else 0.0,
            p[2] - centre[2] if centre[2] != 0.0 else 0.0,
        )
        if not length3(d) - radius < margin:
            return 0
        m = normalize3(d)
    return _capsule_box_points(c, u, half_length, radius, half, m, centre, s, margin, pos_b, quat_b, normal, point,
                               separation, feature)  # fmt: skip


# --- box-box -------------------------------------------------------------------------------------------------


@inline
def _box_sat(t, rel, half_a, half_b):
    """Separations of box b (centre ``t``, axes the columns of ``rel``, both in a's frame) from box a.

    Returns ``(sep_a, face_a, sep_b, face_b, sep_e, edge_a, edge_b, axis_e)``: the largest separation over a's
    face normals and its axis, the same over b's, and over the edge-pair axes (``axis_e`` unit, a's frame,
    pointing from a to b; ``sep_e = -inf`` when every edge pair is parallel).
    """
    sep_a, face_a = -math.inf, 0
    for i in range(3):
        row = (rel[3 * i], rel[3 * i + 1], rel[3 * i + 2])
        sep = abs(t[i]) - half_a[i] - dot(half_b, abs3(row))
        if sep > sep_a + _TIE_DISTANCE:
            sep_a, face_a = sep, i
    sep_b, face_b = -math.inf, 0
    for j in range(3):
        column = mat_column(rel, j)
        sep = abs(dot(t, column)) - half_b[j] - dot(half_a, abs3(column))
        if sep > sep_b + _TIE_DISTANCE:
            sep_b, face_b = sep, j
    sep_e, edge_a, edge_b, axis_e = -math.inf, 0, 0, _UP
    for i in range(3):
        for j in range(3):
            axis = cross(_unit(i), mat_column(rel, j))
            length = length3(axis)
            if length < _MIN_AXIS_LENGTH:
                continue
            axis = scale(axis, 1.0 / length)
            reach_b = (
                half_b[0] * abs(dot(axis, mat_column(rel, 0)))
                + half_b[1] * abs(dot(axis, mat_column(rel, 1)))
                + half_b[2] * abs(dot(axis, mat_column(rel, 2)))
            )
            d = dot(t, axis)
            sep = abs(d) - dot(half_a, abs3(axis)) - reach_b
            if sep > sep_e + _TIE_DISTANCE:
                sep_e, edge_a, edge_b, axis_e = sep, i, j, scale(axis, _sign(d))
    return sep_a, face_a, sep_b, face_b, sep_e, edge_a, edge_b, axis_e


@inline
def _incident_face(t, rel, inc_half, k, sigma):
    """The face of the incident box (centre ``t``, axes the columns of ``rel``, in the reference box's frame)
    most opposed to the reference normal ``sigma e_k``.

    Returns its 4 corners in reference-face coordinates ``(x, y, z)`` (``x``, ``y`` along axes ``k+1``, ``k+2``,
    ``z = sigma p_k``, height above the reference box centre), in loop order, and their box codes, the codes of
    the edges from each corner to the next, and the face's code.
    """
    j = 0
    for m in range(1, 3):
        if abs(rel[3 * k + m]) > abs(rel[3 * k + j]):
            j = m
    s = -_sign(sigma * rel[3 * k + j])
    h, h1, h2 = inc_half[j], inc_half[(j + 1) % 3], inc_half[(j + 2) % 3]
    v0 = _from_axes(j, h1, h2, s * h)
    v1 = _from_axes(j, -h1, h2, s * h)
    v2 = _from_axes(j, -h1, -h2, s * h)
    v3 = _from_axes(j, h1, -h2, s * h)
    quad = (_face_coords(t, rel, v0, k, sigma), _face_coords(t, rel, v1, k, sigma),
            _face_coords(t, rel, v2, k, sigma), _face_coords(t, rel, v3, k, sigma))  # fmt: skip
    vertex_codes = (_box_code(v0), _box_code(v1), _box_code(v2), _box_code(v3))
    edge_codes = (
        _box_code(lerp3(v0, v1, 0.5)), _box_code(lerp3(v1, v2, 0.5)),
        _box_code(lerp3(v2, v3, 0.5)), _box_code(lerp3(v3, v0, 0.5)),
    )  # fmt: skip
    return quad, vertex_codes, edge_codes, _box_code(_from_axes(j, 0.0, 0.0, s * h))


@inline
def _face_coords(t, rel, v, k, sigma):
    """Incident-box point ``v`` in reference-face coordinates (see :func:`_incident_face`)."""
    f = _to_axes(k, add(t, mat_vec(rel, v)))
    return (f[0], f[1], sigma * f[2])


@inline
def _side_distance(p, side, e1, e2):
    """How far ``p`` lies outside side ``side`` of the reference rectangle (0: x = e1, 1: x = -e1, 2: y = e2,
    3: y = -e2); negative inside."""
    if side == 0:
        return p[0] - e1
    if side == 1:
        return -p[0] - e1
    if side == 2:
        return p[1] - e2
    return -p[1] - e2


@inline
def _clip_edge(p, q, e1, e2):
    """Liang–Barsky: the part ``[t0, t1]`` of edge ``p → q`` inside the rectangle ``|x| <= e1, |y| <= e2`` and the
    sides that cut it there (-1 where an end is the edge's own). Nothing left gives sides -1 and ``t0 > t1``."""
    t0, side0, t1, side1 = 0.0, -1, 1.0, -1
    for side in range(4):
        dp, dq = _side_distance(p, side, e1, e2), _side_distance(q, side, e1, e2)
        if dp > 0.0 and dq > 0.0:
            return 1.0, -1, 0.0, -1
        if dp > 0.0:
            t = dp / (dp - dq)
            if t > t0:
                t0, side0 = t, side
        elif dq > 0.0:
            t = dp / (dp - dq)
            if t < t1:
                t1, side1 = t, side
    if t0 > t1:
        return 1.0, -1, 0.0, -1
    return t0, side0, t1, side1


@inline
def _ref_code(k, sigma, h, x, y):
    """Box code of the reference-box feature centred at face coordinates ``(x, y)`` on the reference face."""
    return _box_code(_from_axes(k, x, y, sigma * h))


@inline
def _edge_candidates(p, q, edge_code, e1, e2, k, sigma, h):
    """The points where the incident edge ``p → q`` enters and leaves the reference rectangle (empty slots at
    ``z = inf``): ``(x, y, z, reference code, incident code)``."""
    t0, side0, t1, side1 = _clip_edge(p, q, e1, e2)
    entry = (0.0, 0.0, math.inf, 0, edge_code)
    leave = (0.0, 0.0, math.inf, 0, edge_code)
    if side0 >= 0:
        x = lerp3(p, q, t0)
        sx, sy = _side_offset(side0, e1, e2)
        entry = (x[0], x[1], x[2], _ref_code(k, sigma, h, sx, sy), edge_code)
    if side1 >= 0:
        x = lerp3(p, q, t1)
        sx, sy = _side_offset(side1, e1, e2)
        leave = (x[0], x[1], x[2], _ref_code(k, sigma, h, sx, sy), edge_code)
    return entry, leave


@inline
def _side_offset(side, e1, e2):
    """Face coordinates of the centre of side ``side`` of the reference rectangle."""
    if side == 0:
        return e1, 0.0
    if side == 1:
        return -e1, 0.0
    if side == 2:
        return 0.0, e2
    return 0.0, -e2


@inline
def _corner_candidate(quad, x, y, corner_code, face_code):
    """The reference corner ``(x, y)`` lifted onto the incident face if it lies inside the face's outline
    (projected along the reference normal), else an empty slot."""
    p0, p1, p3 = quad[0], quad[1], quad[3]
    m = cross(sub(p1, p0), sub(p3, p0))
    if abs(m[2]) <= _TINY_LENGTH:
        return (0.0, 0.0, math.inf, corner_code, face_code)
    for i in range(4):
        a, b = quad[i], quad[(i + 1) % 4]
        if ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) * m[2] < 0.0:
            return (0.0, 0.0, math.inf, corner_code, face_code)
    z = p0[2] - (m[0] * (x - p0[0]) + m[1] * (y - p0[1])) / m[2]
    return (x, y, z, corner_code, face_code)


@inline
def _vertex_candidate(p, vertex_code, e1, e2, face_code):
    # Within the preference of the rim counts as inside: equal boxes stacked with a slight twist keep their corners
    # (and ids), and faces that meet exactly along their rims keep their contact.
    if abs(p[0]) <= e1 + _PREFERENCE and abs(p[1]) <= e2 + _PREFERENCE:
        return (p[0], p[1], p[2], face_code, vertex_code)
    return (0.0, 0.0, math.inf, face_code, vertex_code)


@inline
def _face_candidates(quad, vertex_codes, edge_codes, inc_face_code, e1, e2, k, sigma, h):
    """The 16 slots of the contact polygon between the reference rectangle and the incident quad: incident
    vertices inside the rectangle (4), incident edges' entry and exit points (8), reference corners inside the
    incident face (4)."""
    ref_face = _ref_code(k, sigma, h, 0.0, 0.0)
    vertices = (
        _vertex_candidate(quad[0], vertex_codes[0], e1, e2, ref_face),
        _vertex_candidate(quad[1], vertex_codes[1], e1, e2, ref_face),
        _vertex_candidate(quad[2], vertex_codes[2], e1, e2, ref_face),
        _vertex_candidate(quad[3], vertex_codes[3], e1, e2, ref_face),
    )
    edges = (
        _edge_candidates(quad[0], quad[1], edge_codes[0], e1, e2, k, sigma, h)
        + _edge_candidates(quad[1], quad[2], edge_codes[1], e1, e2, k, sigma, h)
        + _edge_candidates(quad[2], quad[3], edge_codes[2], e1, e2, k, sigma, h)
        + _edge_candidates(quad[3], quad[0], edge_codes[3], e1, e2, k, sigma, h)
    )
    corners = (
        _corner_candidate(quad, e1, e2, _ref_code(k, sigma, h, e1, e2), inc_face_code),
        _corner_candidate(quad, -e1, e2, _ref_code(k, sigma, h, -e1, e2), inc_face_code),
        _corner_candidate(quad, -e1, -e2, _ref_code(k, sigma, h, -e1, -e2), inc_face_code),
        _corner_candidate(quad, e1, -e2, _ref_code(k, sigma, h, e1, -e2), inc_face_code),
    )
    return vertices + edges + corners


@inline
def _box_face_contact(ref_pos, ref_quat, ref_half, k, inc_pos, inc_quat, inc_half, margin, ref_is_a, normal, point,
                      separation, feature):  # fmt: skip
    """Face contact: clip the incident face against reference face ``k`` (on the incident box's side), reduce to
    four points and write them, the normal from a to b and the ids."""
    t = quat_rotate_inv(ref_quat, sub(inc_pos, ref_pos))
    rel = quat_to_mat33(quat_mul(quat_conj(ref_quat), inc_quat))
    sigma = _sign(t[k])
    h, e1, e2 = ref_half[k], ref_half[(k + 1) % 3], ref_half[(k + 2) % 3]
    quad, vertex_codes, edge_codes, face_code = _incident_face(t, rel, inc_half, k, sigma)
    candidates = _face_candidates(quad, vertex_codes, edge_codes, face_code, e1, e2, k, sigma, h)
    count, i0, i1, i2, i3 = reduce_manifold(candidates, _UP, h, margin)
    chosen = (i0, i1, i2, i3)
    for i in range(count):
        x, y, z, code_ref, code_inc = candidates[chosen[i]]
        local = _from_axes(k, x, y, sigma * 0.5 * (z + h))
        fid = _feature_id(code_ref, code_inc) if ref_is_a else _feature_id(code_inc, code_ref)
        _write_point(point, separation, feature, i, add(ref_pos, quat_rotate(ref_quat, local)), z - h, fid)
    if count > 0:
        n = quat_rotate(ref_quat, _from_axes(k, 0.0, 0.0, sigma))
        _set_normal(normal, n if ref_is_a else scale(n, -1.0))
    return count


@inline
def _box_edge_contact(pos_a, quat_a, half_a, t, rel, half_b, i, j, axis, margin, normal, point, separation,
                      feature):  # fmt: skip
    """Edge contact: one point between edge ``i`` of a and edge ``j`` of b, those farthest along ``axis`` (a's
    frame, from a to b) and against it, at the closest points of the two edges."""
    centre_a = _with_component((_sign(axis[0]) * half_a[0], _sign(axis[1]) * half_a[1], _sign(axis[2]) * half_a[2]),
                               i, 0.0)  # fmt: skip
    axis_b = (dot(axis, mat_column(rel, 0)), dot(axis, mat_column(rel, 1)), dot(axis, mat_column(rel, 2)))
    centre_b = _with_component((-_sign(axis_b[0]) * half_b[0], -_sign(axis_b[1]) * half_b[1],
                                -_sign(axis_b[2]) * half_b[2]), j, 0.0)  # fmt: skip
    start_b, dir_b = add(t, mat_vec(rel, centre_b)), mat_column(rel, j)
    s, u = _closest_segments(centre_a, _unit(i), half_a[i], start_b, dir_b, half_b[j])
    on_a, on_b = add_scaled(centre_a, _unit(i), s), add_scaled(start_b, dir_b, u)
    sep = dot(sub(on_b, on_a), axis)
    if not sep < margin:
        return 0
    _set_normal(normal, quat_rotate(quat_a, axis))
    mid = add(pos_a, quat_rotate(quat_a, lerp3(on_a, on_b, 0.5)))
    _write_point(point, separation, feature, 0, mid, sep, _feature_id(_box_code(centre_a), _box_code(centre_b)))
    return 1


@kernel
def collide_box_box(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                    feature):  # fmt: skip
    """Box–box: separating axes, then face clipping (up to four points) or one edge–edge point."""
    half_a, half_b = _params3(geom, shape_a), _params3(geom, shape_b)
    t = quat_rotate_inv(quat_a, sub(pos_b, pos_a))
    rel = quat_to_mat33(quat_mul(quat_conj(quat_a), quat_b))
    sep_a, face_a, sep_b, face_b, sep_e, edge_a, edge_b, axis_e = _box_sat(t, rel, half_a, half_b)
    # No point can be closer than the largest separation along any axis.
    if not max(sep_a, max(sep_b, sep_e)) < margin:
        return 0
    # Preferred order for a steady choice: a face of a, a face of b, then an edge pair.
    use_b = _clearly_better(sep_b, sep_a)
    edge_first = _clearly_better(sep_e, sep_b if use_b else sep_a)
    ref_pos, ref_quat, ref_half, inc_pos, inc_quat, inc_half = pos_a, quat_a, half_a, pos_b, quat_b, half_b
    if use_b:
        ref_pos, ref_quat, ref_half, inc_pos, inc_quat, inc_half = pos_b, quat_b, half_b, pos_a, quat_a, half_a
    if edge_first:
        # The edges' support separation along the axis is below the margin, so this always writes its point.
        return _box_edge_contact(pos_a, quat_a, half_a, t, rel, half_b, edge_a, edge_b, axis_e, margin, normal, point,
                                 separation, feature)  # fmt: skip
    count = _box_face_contact(ref_pos, ref_quat, ref_half, face_b if use_b else face_a, inc_pos, inc_quat, inc_half,
                              margin, not use_b, normal, point, separation, feature)  # fmt: skip
    if count == 0:
        # Faces whose outlines miss each other across a gap: the nearest points, if within the margin.
        count = _nearest_points_contact(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point,
                                        separation, feature)  # fmt: skip
    return count


@inline
def _nearest_points_contact(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                            feature):  # fmt: skip
    """One speculative point midway between the nearest points of two convex shapes (GJK), with the normal from a
    to b along them and feature code ``_NEAREST_CODE`` on both sides; none if they are ``margin`` or more apart."""
    whole = np.int64(-1)  # typed, not a literal: a literal argument compiles its own copy of the callee
    found, sep, n, on_a, on_b = proxy_contact(core_proxy(geom, shape_a, whole), pos_a, quat_a,
                                              core_proxy(geom, shape_b, whole), pos_b, quat_b, geom.vertex_local,
                                              margin)  # fmt: skip
    if not (found and sep < margin):
        return 0
    _set_normal(normal, n)
    _write_point(point, separation, feature, 0, scale(add(on_a, on_b), 0.5), sep,
                 _feature_id(_NEAREST_CODE, _NEAREST_CODE))  # fmt: skip
    return 1


# --- planes --------------------------------------------------------------------------------------------------
# Every plane pair has the plane as b: the normal from a to b is minus the plane's normal.


@kernel
def collide_sphere_plane(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                         feature):  # fmt: skip
    """Sphere–plane: the centre's height above the plane minus the radius."""
    n, offset = _plane_world(geom, shape_b, pos_b, quat_b)
    radius = geom.shape_params[shape_a, 0]
    sep = dot(n, pos_a) - offset - radius
    if not sep < margin:
        return 0
    _set_normal(normal, scale(n, -1.0))
    _write_point(point, separation, feature, 0, add_scaled(pos_a, n, -(radius + 0.5 * sep)), sep, 0)
    return 1


@kernel
def collide_capsule_plane(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                          feature):  # fmt: skip
    """Capsule–plane: a point at each segment end (the lower one only when the capsule stands upright or is a
    ball): the end ball's lowest point at the lower end, the cylinder's lowest line at the upper one."""
    n, offset = _plane_world(geom, shape_b, pos_b, quat_b)
    radius, half_length = geom.shape_params[shape_a, 0], geom.shape_params[shape_a, 1]
    axis = quat_rotate(quat_a, _UP)
    # An upright capsule (its axis along the normal) or a point-like one touches with its lower end only.
    low = -half_length if dot(axis, n) >= 0.0 else half_length
    ends = 1 if _upright(axis, n) or half_length <= _MERGE_DISTANCE else 2
    count = 0
    for end in range(ends):
        s = (2.0 * end - 1.0) * half_length if ends == 2 else low
        surface = add_scaled(add_scaled(pos_a, axis, s), _capsule_reach(axis, n, s, half_length), -radius)
        sep = dot(n, surface) - offset
        if sep < margin:
            fid = _feature_id(_end_code(s, half_length), 0)
            _write_point(point, separation, feature, count, add_scaled(surface, n, -0.5 * sep), sep, fid)
            count += 1
    if count > 0:
        _set_normal(normal, scale(n, -1.0))
    return count


@inline
def _plane_local(geom, shape_b, pos_b, quat_b, pos_a, quat_a):
    """World normal of plane b, and its normal and offset in shape a's frame."""
    n, offset = _plane_world(geom, shape_b, pos_b, quat_b)
    return n, quat_rotate_inv(quat_a, n), offset - dot(n, pos_a)


@inline
def _write_plane_points(points, n_world, n_local, offset_local, margin, pos_a, quat_a, normal, point, separation,
                        feature):  # fmt: skip
    """Reduce the candidate ``points`` (a's frame; a tuple of 3-tuples or an (n, 3) array) of a shape on a plane
    and write the chosen ones. A candidate's index is its feature code."""
    count, i0, i1, i2, i3 = reduce_manifold(points, n_local, offset_local, margin)
    chosen = (i0, i1, i2, i3)
    for i in range(count):
        k = chosen[i]
        p = (points[k][0], points[k][1], points[k][2])
        sep = dot(p, n_local) - offset_local
        world = add(pos_a, quat_rotate(quat_a, p))
        _write_point(point, separation, feature, i, add_scaled(world, n_world, -0.5 * sep), sep, _feature_id(k, 0))
    if count > 0:
        _set_normal(normal, scale(n_world, -1.0))
    return count


@kernel
def collide_box_plane(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                      feature):  # fmt: skip
    """Box–plane: the corners below the margin, reduced to four (a face resting flat gives its four corners)."""
    hx, hy, hz = _params3(geom, shape_a)
    n, n_local, offset_local = _plane_local(geom, shape_b, pos_b, quat_b, pos_a, quat_a)
    corners = (
        (-hx, -hy, -hz), (hx, -hy, -hz), (-hx, hy, -hz), (hx, hy, -hz),
        (-hx, -hy, hz), (hx, -hy, hz), (-hx, hy, hz), (hx, hy, hz),
    )  # fmt: skip
    # Corner k is on the + side of axis i where bit i of k is set: its index is its box code.
    return _write_plane_points(corners, n, n_local, offset_local, margin, pos_a, quat_a, normal, point,
                               separation, feature)  # fmt: skip


@kernel
def collide_cylinder_plane(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                           feature):  # fmt: skip
    """Cylinder–plane: four samples on each cap rim, reduced to four points.

    The samples form a square inscribed in the rim whose first corner is the rim point deepest below the plane
    (the plane normal's direction across the axis), so a tilted cylinder gets its exact deepest point and a
    cylinder on its side its exact contact line; a cap lying flat (the normal along the axis, within 1e-9) turns
    the square to the cylinder's own x axis and rests on its four corners (a support square of area 2 r²
    instead of the disc's π r²). Sample ``k`` of a cap has code ``4 cap + k``: 0 deepest, 1 a quarter turn on,
    2 opposite, 3 three quarters.
    """
    radius, half_height = geom.shape_params[shape_a, 0], geom.shape_params[shape_a, 1]
    n, n_local, offset_local = _plane_local(geom, shape_b, pos_b, quat_b, pos_a, quat_a)
    across = math.sqrt(n_local[0] * n_local[0] + n_local[1] * n_local[1])
    if across > 1e-9:
        dx, dy = -n_local[0] * radius / across, -n_local[1] * radius / across
    else:
        dx, dy = radius, 0.0
    rim = (
        (dx, dy, -half_height), (-dy, dx, -half_height), (-dx, -dy, -half_height), (dy, -dx, -half_height),
        (dx, dy, half_height), (-dy, dx, half_height), (-dx, -dy, half_height), (dy, -dx, half_height),
    )  # fmt: skip
    return _write_plane_points(rim, n, n_local, offset_local, margin, pos_a, quat_a, normal, point,
                               separation, feature)  # fmt: skip


@kernel
def collide_hull_plane(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                       feature):  # fmt: skip
    """Hull–plane: the hull vertices below the margin, reduced to four. Codes are the vertices' hull indices."""
    n, n_local, offset_local = _plane_local(geom, shape_b, pos_b, quat_b, pos_a, quat_a)
    start = geom.shape_vertex_start[shape_a]
    vertices = geom.vertex_local[start : start + geom.shape_vertex_count[shape_a]]
    return _write_plane_points(vertices, n, n_local, offset_local, margin, pos_a, quat_a, normal, point, separation,
                               feature)  # fmt: skip
