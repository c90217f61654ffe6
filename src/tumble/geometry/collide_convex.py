"""Contact manifolds for the convex pairs without a closed form, and for convex shapes against triangle meshes.

:func:`collide_convex_convex` works for any two of sphere, capsule, box, cylinder and convex hull; the narrow
phase sends it the pairs that have no closed form (anything with a cylinder or a hull). It takes one of two roads:

- **Two polyhedra** (box or hull; a box is built on the fly from its half extents, a mesh triangle is a flat
  polyhedron with two faces): the separating-axis test over the face normals of both and over the cross products
  of edge pairs, keeping only the edge pairs whose arcs cross on the Gauss map, i.e. that build a face of the
  Minkowski difference (Gregorius, "The Separating Axis Test between Convex Polyhedra", GDC 2013). A face axis
  wins over an edge axis, and the face of the shape with the lower row over the other's, unless the other
  separates better by ``FACE_BIAS_RELATIVE`` of its separation plus ``FACE_BIAS`` times the size, so that resting
  contacts do not flip between axes (the rule of the closed-form box-box kernel). A face axis then gives a
  reference face; the incident face is, of the other shape's faces round its deepest corner, the one most opposed
  to it, clipped against the reference face's side planes (Sutherland and Hodgman 1974); when nothing of it lies
  over the reference face, that corner alone is the contact. The clipped points within the speculative margin are
  reduced to four (:func:`_select_four`): the deepest, the farthest from it, the one spanning the largest triangle
  with those two, and the one farthest outside that triangle. An edge axis gives the one point between the edges.
- **A round shape involved** (sphere, capsule, cylinder): GJK on the cores, EPA when they overlap
  (:mod:`tumble.geometry.gjk`), which gives the normal and one point. One point cannot hold a cylinder standing
  on a box, so each shape then names its feature along the normal: the face of a polyhedron or triangle; a
  cylinder's end disc as an inscribed regular polygon of ``CAP_POINTS`` rim points (its first corner on the
  deepest rim point, so the depth stays exact), standing or tilted; the line of a cylinder's side, or a capsule's
  segment, when the axis is within ``asin(FLAT_SIN)`` of lying flat. When one feature is a face facing the normal
  (to ``REF_COS``) it is the reference, and the other feature, clipped against it as above, gives up to four points
  (a standing cylinder gets four of its rim corners, a tipped one those within the margin, a lying one or a capsule
  two; a tipped capsule against a mesh triangle gives its whole segment too). When neither faces the normal but
  one is a face within ``acos(NEAR_FACE_COS)`` (30°) of it, as under a cylinder's rim tipped over a box's edge, the
  other feature is clipped against that face and each point measured along GJK's normal from the plane the face's
  shape lies under, a lower bound on its distance; GJK's deepest point joins them. Two parallel segments give two
  points. Everything else is one point.

:func:`collide_convex_trimesh` collides a convex shape with each triangle of a static mesh whose bounds (in the
mesh frame) overlap the shape's, by the same two roads with the triangle as shape B (two-sided), and merges the
points into one manifold (:func:`_merge_mesh_contacts`). The deepest *face* contact (one whose normal is its
triangle's) names the contact surface, or the deepest contact when there is none; the points whose normal is within
``acos(MERGE_COS)`` of it join, face contacts pushing out the edge and corner contacts of the same surface (a sphere
on a flat mesh also meets the nearby triangles' edges); the manifold normal is the joined normals' average weighted
by depth, each separation is measured again along it, and four points are kept as above. Against a triangle, its
own face normal wins over every other axis unless that one separates better by ``TRIANGLE_FACE_BIAS`` times the
size, so the inner edges of a flat mesh do not catch a box sliding over them. One manifold has one normal: a box in
a mesh corner gets the floor or the wall, not both (several manifolds per pair would lift that). The triangles are
tested in a plain loop; a bounding-volume hierarchy over them is future work.

All the scratch arrays are allocated once per call at the size of the shapes; nothing grows inside the loops.
"""

from __future__ import annotations

import math

import numpy as np

from .. import elementary
from .._jit import inline, kernel
from ..math3d import add, add_scaled, cross, dot, load4, quat_rotate, quat_rotate_inv, scale, sub
from ..shapes import ShapeType
from .gjk import core_proxy, core_radius, core_size, proxy_contact, support_world
from .manifold import MAX_POINTS

__all__ = [
    "CAP_POINTS",
    "FLAT_SIN",
    "REF_COS",
    "NEAR_FACE_COS",
    "FACE_BIAS_RELATIVE",
    "FACE_BIAS",
    "TRIANGLE_FACE_BIAS",
    "MERGE_COS",
    "MESH_MAX_CANDIDATES",
    "collide_convex_convex",
    "collide_convex_trimesh",
    "collide_sphere_trimesh",
    "collide_capsule_trimesh",
    "collide_box_trimesh",
    "collide_cylinder_trimesh",
    "collide_hull_trimesh",
]

SPHERE = int(ShapeType.SPHERE)
CAPSULE = int(ShapeType.CAPSULE)
BOX = int(ShapeType.BOX)
CYLINDER = int(ShapeType.CYLINDER)
HULL = int(ShapeType.CONVEX_HULL)

# Rim points of a cylinder's end disc used as its face: 8 keep 92 % of the radius (cos 22.5°).
CAP_POINTS = 8
# A cylinder's end disc counts as facing the contact normal, or its side (a capsule's segment) as lying along the
# contact plane, within asin(0.1) = 5.7°; a rim or segment end that rises more than the margin is dropped anyway.
FLAT_SIN = 0.1
# A face is the reference face for a round partner only if it faces the contact normal to within 4.5e-5 rad: the
# normal of a true face contact comes out of GJK/EPA exact to round-off (a curved rim's to ~1e-5 rad), while near an
# edge or a corner it leans over, and measuring along the face's normal there overstates the depth.
REF_COS = 1.0 - 1e-9
# Neither feature faces the normal to REF_COS, but a face within 30° of it (a box's face under a tipped cylinder's rim)
# is clipped against as a near face (_collide_smooth).
NEAR_FACE_COS = 0.8660254037844387
# Preference for face axes over edge axes, and for A's faces over B's (Gregorius 2013; Box2D's 0.98 x + slop): another
# axis wins only if it separates better by 5 % of the preferred axis's separation plus 1e-3 of the pair's size, so
# round-off and small rotations never flip the reference face between steps. collide_box_box uses the same 5 %.
FACE_BIAS_RELATIVE = 0.05
FACE_BIAS = 1e-3
# Preference for a mesh triangle's face normal over every other axis, as a fraction of the pair's size.
TRIANGLE_FACE_BIAS = 1e-2
# Mesh contacts whose normal is within 30° of the deepest face contact's join its manifold.
MERGE_COS = 0.8660254037844387
# Points kept from the triangles of one mesh before the merge; when full, they are squeezed to four (_squeeze).
MESH_MAX_CANDIDATES = 64

# Feature ids: bits 0-15 the clipped point (an incident vertex, or a side plane and the edge it cut), 16-27 the
# incident feature, 28-39 the reference feature, bit 40 set when the reference is B's, bits 41-62 the mesh triangle.
_EDGE_POINT = 0xFFFF
_DEEPEST_POINT = 0xFFFE
_TRIANGLE_SHIFT = 41


# --- small geometry ----------------------------------------------------------------------------------------------


@inline
def _row(array, i):
    return (array[i, 0], array[i, 1], array[i, 2])


@inline
def _set_row(array, i, v):
    array[i, 0], array[i, 1], array[i, 2] = v[0], v[1], v[2]


@inline
def _set_vec(array, v):
    array[0], array[1], array[2] = v[0], v[1], v[2]


@inline
def _neg(v):
    return (-v[0], -v[1], -v[2])


@inline
def _unit(v):
    """``v / |v|``, or zero for a zero vector."""
    length = math.sqrt(dot(v, v))
    if length > 0.0:
        return scale(v, 1.0 / length)
    return (0.0, 0.0, 0.0)


@inline
def _clamp01(x):
    return min(max(x, 0.0), 1.0)


@inline
def _closest_segments(p0, p1, q0, q1):
    """Closest points of segments ``p0 p1`` and ``q0 q1``: minimise ``|p(s) - q(t)|`` over the unit square, clamping
    one parameter then the other (Ericson 2005, §5.1.9)."""
    d1, d2, r = sub(p1, p0), sub(q1, q0), sub(p0, q0)
    a, e, f = dot(d1, d1), dot(d2, d2), dot(d2, r)
    s, t = 0.0, 0.0
    if a > 0.0 and e > 0.0:
        b, c = dot(d1, d2), dot(d1, r)
        den = a * e - b * b
        if den > 0.0:
            s = _clamp01((b * f - c * e) / den)
        t = (b * s + f) / e
        if t < 0.0:
            t, s = 0.0, _clamp01(-c / a)
        elif t > 1.0:
            t, s = 1.0, _clamp01((b - c) / a)
    elif a > 0.0:
        s = _clamp01(-dot(d1, r) / a)
    elif e > 0.0:
        t = _clamp01(f / e)
    return add_scaled(p0, d1, s), add_scaled(q0, d2, t)


# --- polyhedra: boxes, hulls and mesh triangles in the world frame --------------------------------------------------


@inline
def _polyhedron_counts(geom, shape, face):
    """``(vertices, faces, loop entries, edges)`` of a box, a hull, or mesh triangle ``face``."""
    if face >= 0:
        # A triangle: both sides as faces; each edge twice, once per half of its Gauss-map arc (see _build_polyhedron).
        return 3, 2, 6, 6
    if geom.shape_type[shape] == BOX:
        return 8, 6, 24, 12
    fs, fc = geom.shape_face_start[shape], geom.shape_face_count[shape]
    loops = 0
    for f in range(fs, fs + fc):
        loops += geom.face_loop_count[f]
    return geom.shape_vertex_count[shape], fc, loops, geom.shape_edge_count[shape]


@inline
def _allocate_polyhedron(geom, shape, face):
    """Arrays for :func:`_build_polyhedron`: ``(vertex, face_normal, face_offset, face_start, face_count, face_loop,
    edge, arc_a, arc_b)``."""
    nv, nf, nl, ne = _polyhedron_counts(geom, shape, face)
    return (np.empty((nv, 3)), np.empty((nf, 3)), np.empty(nf), np.empty(nf, np.int64), np.empty(nf, np.int64),
            np.empty(nl, np.int64), np.empty((ne, 2), np.int64), np.zeros((ne, 3)), np.zeros((ne, 3)))  # fmt: skip


@inline
def _box_corner(i, hx, hy, hz):
    """Corner ``i`` of a box: bit 0, 1, 2 of ``i`` set for the + side along x, y, z."""
    return (hx if i & 1 else -hx, hy if i & 2 else -hy, hz if i & 4 else -hz)


@inline
def _box_face_corner(axis, positive, c):
    """Corner index of the ``c``-th vertex (counter-clockwise seen from outside) of the box face on ``axis``."""
    u, w = (axis + 1) % 3, (axis + 2) % 3
    if not positive:
        c = 3 - c
    # Counter-clockwise about +axis in the (u, w) plane: (-,-), (+,-), (+,+), (-,+).
    su = 1 if c == 1 or c == 2 else 0
    sw = 1 if c >= 2 else 0
    return (1 << axis if positive else 0) | (su << u) | (sw << w)


@inline
def _axis(k, s):
    return (s if k == 0 else 0.0, s if k == 1 else 0.0, s if k == 2 else 0.0)


@inline
def _build_polyhedron(geom, shape, face, pos, quat, poly):
    """Fill ``poly`` (from :func:`_allocate_polyhedron`) with the shape in the world frame; return its centroid.

    Faces are convex loops, counter-clockwise seen from outside, with outward unit normals and plane offsets
    ``n · x``. Each edge carries its arc on the Gauss map as its two end normals ``arc_a``, ``arc_b``: the normals of
    the faces on either side. A triangle's faces ``n`` and ``-n`` are opposite, so each of its edges is stored twice,
    with the arcs from ``n`` to the edge's outward normal ``m`` in the triangle's plane and from ``m`` to ``-n``.
    """
    vertex, fnormal, foffset, fstart, fcount, floop, edge, arc_a, arc_b = poly
    nv, nf, nl, ne = _polyhedron_counts(geom, shape, face)
    if face >= 0:
        start = geom.face_loop_start[face]
        for k in range(3):
            i = geom.face_loop[start + k]
            _set_row(vertex, k, add(pos, quat_rotate(quat, _row(geom.vertex_local, i))))
        n = quat_rotate(quat, _row(geom.face_normal, face))
        for s in range(2):
            side = n if s == 0 else _neg(n)
            _set_row(fnormal, s, side)
            foffset[s] = dot(side, _row(vertex, 0))
            fstart[s], fcount[s] = 3 * s, 3
        floop[0], floop[1], floop[2], floop[3], floop[4], floop[5] = 0, 1, 2, 0, 2, 1
        centroid = scale(add(add(_row(vertex, 0), _row(vertex, 1)), _row(vertex, 2)), 1.0 / 3.0)
        for e in range(3):
            p, q = _row(vertex, e), _row(vertex, (e + 1) % 3)
            m = _unit(cross(sub(q, p), n))
            if dot(m, sub(centroid, p)) > 0.0:
                m = _neg(m)
            for half in range(2):
                edge[2 * e + half, 0], edge[2 * e + half, 1] = e, (e + 1) % 3
            _set_row(arc_a, 2 * e, n)
            _set_row(arc_b, 2 * e, m)
            _set_row(arc_a, 2 * e + 1, m)
            _set_row(arc_b, 2 * e + 1, _neg(n))
        return centroid
    if geom.shape_type[shape] == BOX:
        hx, hy, hz = geom.shape_params[shape, 0], geom.shape_params[shape, 1], geom.shape_params[shape, 2]
        for i in range(8):
            _set_row(vertex, i, add(pos, quat_rotate(quat, _box_corner(i, hx, hy, hz))))
        for f in range(6):
            k, positive = f // 2, f % 2 == 0
            n = quat_rotate(quat, _axis(k, 1.0 if positive else -1.0))
            _set_row(fnormal, f, n)
            foffset[f] = dot(n, pos) + geom.shape_params[shape, k]
            fstart[f], fcount[f] = 4 * f, 4
            for c in range(4):
                floop[4 * f + c] = _box_face_corner(k, positive, c)
        for k in range(3):
            u, w = (k + 1) % 3, (k + 2) % 3
            for c in range(4):
                e = 4 * k + c
                su, sw = c & 1, (c >> 1) & 1
                edge[e, 0] = (su << u) | (sw << w)
                edge[e, 1] = edge[e, 0] | (1 << k)
                _set_row(arc_a, e, _row(fnormal, 2 * u + (1 - su)))
                _set_row(arc_b, e, _row(fnormal, 2 * w + (1 - sw)))
        return pos
    vs = geom.shape_vertex_start[shape]
    centroid = (0.0, 0.0, 0.0)
    for i in range(nv):
        p = add(pos, quat_rotate(quat, _row(geom.vertex_local, vs + i)))
        _set_row(vertex, i, p)
        centroid = add(centroid, p)
    centroid = scale(centroid, 1.0 / nv)
    fs, es = geom.shape_face_start[shape], geom.shape_edge_start[shape]
    for e in range(ne):
        edge[e, 0], edge[e, 1] = geom.edge_vertex[es + e, 0] - vs, geom.edge_vertex[es + e, 1] - vs
    entry = 0
    for f in range(nf):
        n = quat_rotate(quat, _row(geom.face_normal, fs + f))
        _set_row(fnormal, f, n)
        foffset[f] = geom.face_offset[fs + f] + dot(n, pos)
        ls, lc = geom.face_loop_start[fs + f], geom.face_loop_count[fs + f]
        fstart[f], fcount[f] = entry, lc
        for k in range(lc):
            floop[entry + k] = geom.face_loop[ls + k] - vs
        # Each loop edge u -> v names this face as one side of edge {u, v}: arc_a for u < v, arc_b otherwise.
        for k in range(lc):
            u, v = floop[entry + k], floop[entry + (k + 1) % lc]
            e = _find_edge(edge, ne, min(u, v), max(u, v))
            if e >= 0:
                _set_row(arc_a if u < v else arc_b, e, n)
        entry += lc
    return centroid


@inline
def _find_edge(edge, ne, lo, hi):
    """Index of edge ``(lo, hi)``: binary search (packing lists a hull's edges sorted), then a plain scan."""
    left, right = 0, ne - 1
    while left <= right:
        mid = (left + right) // 2
        a, b = edge[mid, 0], edge[mid, 1]
        if a == lo and b == hi:
            return mid
        if a < lo or (a == lo and b < hi):
            left = mid + 1
        else:
            right = mid - 1
    for e in range(ne):
        if edge[e, 0] == lo and edge[e, 1] == hi:
            return e
    return -1


# --- the separating-axis test --------------------------------------------------------------------------------------


@inline
def _face_query(poly_p, poly_q, margin):
    """Best face axis of P: ``max_f min_{q in Q} (n_f · q - o_f)`` and its face (stops early past ``margin``)."""
    fnormal, foffset = poly_p[1], poly_p[2]
    vertex_q = poly_q[0]
    best, best_face = -math.inf, 0
    for f in range(fnormal.shape[0]):
        n = _row(fnormal, f)
        lowest = math.inf
        for i in range(vertex_q.shape[0]):
            lowest = min(lowest, dot(n, _row(vertex_q, i)))
        s = lowest - foffset[f]
        if s > best:
            best, best_face = s, f
            if s > margin:
                break
    return best, best_face


@inline
def _edge_query(poly_p, poly_q, margin):
    """Best edge-pair axis, over the pairs whose Gauss-map arcs cross (Gregorius 2013).

    P's arc ``(a, b)`` and the arc ``(-c, -d)`` of Q's edge cross when each arc's end points lie on opposite sides of
    the other's great circle and the two crossings are one point, not antipodal: with ``cba = c·(b×a)`` and so on,
    ``cba·dba < 0``, ``adc·bdc < 0`` and ``cba·bdc > 0``. The cross product of the two edges, turned towards P's arc,
    is then the normal of a face of the Minkowski difference, and its offset is the separation. Returns
    ``(separation, edge_p, edge_q, axis)``; parallel edges are left to the face axes.
    """
    vertex_p, edge_p, arc_a_p, arc_b_p = poly_p[0], poly_p[6], poly_p[7], poly_p[8]
    vertex_q, edge_q, arc_a_q, arc_b_q = poly_q[0], poly_q[6], poly_q[7], poly_q[8]
    best, best_i, best_j, best_axis = -math.inf, -1, -1, (0.0, 0.0, 0.0)
    for i in range(edge_p.shape[0]):
        p0, p1 = _row(vertex_p, edge_p[i, 0]), _row(vertex_p, edge_p[i, 1])
        dp = sub(p1, p0)
        a, b = _row(arc_a_p, i), _row(arc_b_p, i)
        bxa = cross(b, a)
        for j in range(edge_q.shape[0]):
            c, d = _neg(_row(arc_a_q, j)), _neg(_row(arc_b_q, j))
            cba, dba = dot(c, bxa), dot(d, bxa)
            if cba * dba >= 0.0:
                continue
            dxc = cross(d, c)
            adc, bdc = dot(a, dxc), dot(b, dxc)
            if adc * bdc >= 0.0 or cba * bdc <= 0.0:
                continue
            q0, q1 = _row(vertex_q, edge_q[j, 0]), _row(vertex_q, edge_q[j, 1])
            dq = sub(q1, q0)
            axis = cross(dp, dq)
            length2 = dot(axis, axis)
            # Edges within 1e-5 rad of parallel: their axis is a face axis already tested.
            if length2 <= 1e-10 * dot(dp, dp) * dot(dq, dq):
                continue
            axis = scale(axis, 1.0 / math.sqrt(length2))
            if dot(axis, add(a, b)) < 0.0:
                axis = _neg(axis)
            s = dot(axis, sub(q0, p0))
            if s > best:
                best, best_i, best_j, best_axis = s, i, j, axis
                if s > margin:
                    return best, best_i, best_j, best_axis
    return best, best_i, best_j, best_axis


# --- clipping and reduction ----------------------------------------------------------------------------------------


@inline
def _select_four(points, seps, m, n):
    """At most four of the ``m`` candidate points: the deepest, the farthest from it, the one spanning the largest
    triangle with those two (areas measured about ``n``) and the one farthest outside that triangle. Collinear or
    coincident candidates give fewer. Ties go to the first. Returns ``(count, k0, k1, k2, k3)``, ``-1`` if unused."""
    if m == 0:
        return 0, -1, -1, -1, -1
    # The deepest; among points as deep to 1e-6 of the spread (a face resting flat), the one farthest from the centre,
    # which is a corner of the patch rather than a point that clipping happened to list first.
    centre, deepest = (0.0, 0.0, 0.0), seps[0]
    for k in range(m):
        centre = add_scaled(centre, _row(points, k), 1.0 / m)
        deepest = min(deepest, seps[k])
    spread = 0.0
    for k in range(m):
        e = sub(_row(points, k), centre)
        spread = max(spread, dot(e, e))
    k0, best = 0, -1.0
    for k in range(m):
        e = sub(_row(points, k), centre)
        if seps[k] <= deepest + 1e-6 * math.sqrt(spread) and dot(e, e) > best:
            k0, best = k, dot(e, e)
    p0 = _row(points, k0)
    k1, far = -1, 0.0
    for k in range(m):
        e = sub(_row(points, k), p0)
        if dot(e, e) > far:
            k1, far = k, dot(e, e)
    if k1 < 0:
        return 1, k0, -1, -1, -1
    p1 = _row(points, k1)
    k2, area = -1, 0.0
    for k in range(m):
        s = dot(cross(sub(p1, p0), sub(_row(points, k), p0)), n)
        if abs(s) > abs(area):
            k2, area = k, s
    # Twice the area under 1e-12 of the squared span: the points are on a line.
    if k2 < 0 or abs(area) <= 1e-12 * far:
        return 2, k0, k1, -1, -1
    # Wind the triangle counter-clockwise about n; the fourth point is the one farthest outside one of its edges.
    a, b, c = k0, k1, k2
    if area < 0.0:
        b, c = k2, k1
    pa, pb, pc = _row(points, a), _row(points, b), _row(points, c)
    # Outside by more than round-off (twice an area, like far): a copy of a corner must not come back as the fourth.
    k3, outside = -1, 1e-12 * far
    for k in range(m):
        p = _row(points, k)
        o = max(-dot(cross(sub(pb, pa), sub(p, pa)), n), -dot(cross(sub(pc, pb), sub(p, pb)), n),
                -dot(cross(sub(pa, pc), sub(p, pc)), n))  # fmt: skip
        if o > outside:
            k3, outside = k, o
    if k3 < 0:
        return 3, k0, k1, k2, -1
    return 4, k0, k1, k2, k3


@inline
def _write_four(points, seps, ids, m, n, point, separation, feature):
    """Write :func:`_select_four`'s points into the manifold outputs; return their count."""
    count, k0, k1, k2, k3 = _select_four(points, seps, m, n)
    for j in range(count):
        k = k0 if j == 0 else (k1 if j == 1 else (k2 if j == 2 else k3))
        _set_row(point, j, _row(points, k))
        separation[j], feature[j] = seps[k], ids[k]
    return count


@inline
def _clip_points(ref, ref_count, ref_n, inc, inc_count, inc_radius, plane_n, plane_offset, margin, base_id, out_point,
                 out_sep, out_id):  # fmt: skip
    """Contact points of an incident feature (polygon, segment or point core: rows ``[:inc_count]`` of ``inc``) over a
    reference face (convex polygon ``ref[:ref_count]``, either winding, outward unit normal ``ref_n``).

    Clips the incident feature against the side planes of the reference face, measures each point's height above the
    plane ``plane_n · x = plane_offset`` (the face's own, or one the reference shape lies under) less
    ``inc_radius``, and writes those within ``margin``, midway between the two surfaces, into ``out_*`` (room for
    ``inc_count + ref_count`` rows). Returns how many.
    """
    # A convex incident feature gains at most one vertex per side plane. Rows are written before they are read.
    cap = inc_count + ref_count
    buf = np.empty((cap, 3))
    buf_ids = np.empty(cap, np.int64)
    tmp = np.empty((cap, 3))
    tmp_ids = np.empty(cap, np.int64)
    for k in range(inc_count):
        _set_row(buf, k, _row(inc, k))
        buf_ids[k] = k
    m = inc_count
    centre = (0.0, 0.0, 0.0)
    for k in range(ref_count):
        centre = add(centre, _row(ref, k))
    centre = scale(centre, 1.0 / ref_count)
    for side in range(ref_count):
        # The side plane through a reference edge, facing out of the face; a cut point's id names it and the edge cut.
        r0, r1 = _row(ref, side), _row(ref, (side + 1) % ref_count)
        sn = cross(sub(r1, r0), ref_n)
        if dot(sn, sub(centre, r0)) > 0.0:
            sn = _neg(sn)
        so = dot(sn, r0)
        out = 0
        if m == 1:
            if dot(sn, _row(buf, 0)) - so <= 0.0:
                _set_row(tmp, 0, _row(buf, 0))
                tmp_ids[0] = buf_ids[0]
                out = 1
        elif m == 2:
            # A segment: move the ends that are outside onto the plane.
            p, q = _row(buf, 0), _row(buf, 1)
            dp, dq = dot(sn, p) - so, dot(sn, q) - so
            if dp <= 0.0 or dq <= 0.0:
                for end in range(2):
                    x, dx, other, dother, xid = (p, dp, q, dq, buf_ids[0]) if end == 0 else (q, dq, p, dp, buf_ids[1])
                    if dx > 0.0:
                        x = add_scaled(x, sub(other, x), dx / (dx - dother))
                        xid = ((side + 1) << 8) | (xid & 0xFF)
                    _set_row(tmp, end, x)
                    tmp_ids[end] = xid
                out = 2
        else:
            # Sutherland-Hodgman: keep the inside vertices and add a point where an edge crosses the plane. A convex
            # polygon gains at most one vertex per plane, which `cap` allows for; a polygon that round-off has made a
            # little non-convex (points nearly in a line, crossing the plane in turn) can cross it more than twice,
            # and the points past `cap` are dropped rather than written past the end.
            for k in range(m):
                p, q = _row(buf, k), _row(buf, (k + 1) % m)
                dp, dq = dot(sn, p) - so, dot(sn, q) - so
                if dp <= 0.0 and out < cap:
                    _set_row(tmp, out, p)
                    tmp_ids[out] = buf_ids[k]
                    out += 1
                if (dp <= 0.0) != (dq <= 0.0) and out < cap:
                    _set_row(tmp, out, add_scaled(p, sub(q, p), dp / (dp - dq)))
                    tmp_ids[out] = ((side + 1) << 8) | (buf_ids[k] & 0xFF)
                    out += 1
        buf, tmp = tmp, buf
        buf_ids, tmp_ids = tmp_ids, buf_ids
        m = out
        if m == 0:
            return 0
    # Heights above the plane; each point goes midway between the two surfaces.
    kept = 0
    for k in range(m):
        p = _row(buf, k)
        height = dot(plane_n, p) - plane_offset
        if height - inc_radius <= margin:
            _set_row(out_point, kept, add_scaled(p, plane_n, -0.5 * (height + inc_radius)))
            out_sep[kept] = height - inc_radius
            out_id[kept] = base_id | (buf_ids[k] & 0xFFFF)
            kept += 1
    return kept


# --- two polyhedra ---------------------------------------------------------------------------------------------------


@inline
def _collide_polyhedra(geom, sa, fa, pa, qa, sb, fb, pb, qb, margin, out_point, out_sep, out_id):
    """Two boxes or hulls (or one and mesh triangle ``fb``): SAT, then face clipping or the edge-edge point.

    Writes the candidate points into ``out_*`` (unreduced) and returns ``(count, normal)``.
    """
    zero = (0.0, 0.0, 0.0)
    poly_a = _allocate_polyhedron(geom, sa, fa)
    poly_b = _allocate_polyhedron(geom, sb, fb)
    _build_polyhedron(geom, sa, fa, pa, qa, poly_a)
    _build_polyhedron(geom, sb, fb, pb, qb, poly_b)
    sep_a, face_a = _face_query(poly_a, poly_b, margin)
    if sep_a > margin:
        return 0, zero
    sep_b, face_b = _face_query(poly_b, poly_a, margin)
    if sep_b > margin:
        return 0, zero
    sep_e, edge_a, edge_b, axis = _edge_query(poly_a, poly_b, margin)
    if sep_e > margin:
        return 0, zero
    size = core_size(geom, sa, fa) + core_size(geom, sb, fb)
    bias = FACE_BIAS * size
    if fb >= 0 and max(sep_a, sep_e) <= sep_b + TRIANGLE_FACE_BIAS * size:
        # The triangle's own normal, unless another axis separates clearly better (inner edges do not catch).
        use_b, use_edge = True, False
    else:
        # Between the two shapes' faces the one of the lower shape row wins ties, so swapping A and B changes nothing;
        # then an edge pair must beat the chosen face. A chosen axis is thus at most 1/0.95 times deeper than the best.
        use_b = _beats(sep_b, sep_a, bias) if sa < sb else not _beats(sep_a, sep_b, bias)
        use_edge = edge_a >= 0 and _beats(sep_e, sep_b if use_b else sep_a, bias)
    if not use_edge:
        if use_b:
            count, n = _face_contact(poly_b, face_b, poly_a, margin, use_b, out_point, out_sep, out_id)
        else:
            count, n = _face_contact(poly_a, face_a, poly_b, margin, use_b, out_point, out_sep, out_id)
        if count > 0:
            return count, n
        # Nothing of the incident face lies over the reference face (its deepest corner does, just outside an edge of
        # it, or none does): that corner alone, at the face axis's separation.
        if use_b:
            return _corner_contact(poly_b, face_b, poly_a, use_b, out_point, out_sep, out_id)
        return _corner_contact(poly_a, face_a, poly_b, use_b, out_point, out_sep, out_id)
    vertex_a, edges_a = poly_a[0], poly_a[6]
    vertex_b, edges_b = poly_b[0], poly_b[6]
    ca, cb = _closest_segments(_row(vertex_a, edges_a[edge_a, 0]), _row(vertex_a, edges_a[edge_a, 1]),
                               _row(vertex_b, edges_b[edge_b, 0]), _row(vertex_b, edges_b[edge_b, 1]))  # fmt: skip
    _set_row(out_point, 0, scale(add(ca, cb), 0.5))
    out_sep[0] = sep_e
    out_id[0] = ((edge_a & 0xFFF) << 28) | ((edge_b & 0xFFF) << 16) | _EDGE_POINT
    return 1, axis


@inline
def _corner_contact(poly_ref, face_ref, poly_inc, flip, out_point, out_sep, out_id):
    """One point at the incident polyhedron's corner deepest below the reference face. Returns ``(1, normal)``."""
    vertex_i = poly_inc[0]
    n = _row(poly_ref[1], face_ref)
    deepest, low = 0, math.inf
    for i in range(vertex_i.shape[0]):
        h = dot(n, _row(vertex_i, i))
        if h < low:
            deepest, low = i, h
    sep = low - poly_ref[2][face_ref]
    _set_row(out_point, 0, add_scaled(_row(vertex_i, deepest), n, -0.5 * sep))
    out_sep[0] = sep
    out_id[0] = ((1 << 40) if flip else 0) | ((face_ref & 0xFFF) << 28) | (deepest & 0xFFFF) | 0x8000
    return 1, (_neg(n) if flip else n)


@inline
def _beats(separation, preferred, bias):
    """Whether an axis of ``separation`` replaces the ``preferred`` one: by ``FACE_BIAS_RELATIVE`` of its size plus
    ``bias`` (the rule of the closed-form box-box kernel, so both roads pick the same axis)."""
    return separation > preferred + FACE_BIAS_RELATIVE * abs(preferred) + bias


@inline
def _face_contact(poly_ref, face_ref, poly_inc, margin, flip, out_point, out_sep, out_id):
    """Clip the incident polyhedron's face most opposed to ``face_ref`` against it; ``flip`` when the reference is B.
    Returns ``(count, normal)``."""
    vertex_r, fnormal_r, fstart_r, fcount_r, floop_r = poly_ref[0], poly_ref[1], poly_ref[3], poly_ref[4], poly_ref[5]
    vertex_i, fnormal_i, fstart_i, fcount_i, floop_i = poly_inc[0], poly_inc[1], poly_inc[3], poly_inc[4], poly_inc[5]
    n = _row(fnormal_r, face_ref)
    # The incident face: of the faces round the incident shape's deepest corner, the one most opposed to the
    # reference (Gregorius takes the most opposed of all; requiring the corner keeps the deepest point in the clip).
    deepest, low = 0, math.inf
    for i in range(vertex_i.shape[0]):
        h = dot(n, _row(vertex_i, i))
        if h < low:
            deepest, low = i, h
    face_inc, lowest = -1, math.inf
    for f in range(fnormal_i.shape[0]):
        c = dot(_row(fnormal_i, f), n)
        if c < lowest:
            for k in range(fcount_i[f]):
                if floop_i[fstart_i[f] + k] == deepest:
                    face_inc, lowest = f, c
                    break
    if face_inc < 0:
        face_inc = 0
    ref = np.empty((fcount_r[face_ref], 3))
    for k in range(fcount_r[face_ref]):
        _set_row(ref, k, _row(vertex_r, floop_r[fstart_r[face_ref] + k]))
    inc = np.empty((fcount_i[face_inc], 3))
    for k in range(fcount_i[face_inc]):
        _set_row(inc, k, _row(vertex_i, floop_i[fstart_i[face_inc] + k]))
    base_id = ((1 << 40) if flip else 0) | ((face_ref & 0xFFF) << 28) | ((face_inc & 0xFFF) << 16)
    count = _clip_points(ref, ref.shape[0], n, inc, inc.shape[0], 0.0, n, dot(n, _row(ref, 0)), margin, base_id,
                         out_point, out_sep, out_id)  # fmt: skip
    return count, (_neg(n) if flip else n)


# --- a round shape involved: GJK/EPA, then features ------------------------------------------------------------------


@inline
def _feature_capacity(geom, shape, face):
    """Rows needed for :func:`_support_feature`'s output: the most vertices of a face, or the cap polygon's."""
    if face >= 0:
        return 3
    t = geom.shape_type[shape]
    if t == BOX:
        return 4
    if t == HULL:
        most = 1
        for f in range(geom.shape_face_start[shape], geom.shape_face_start[shape] + geom.shape_face_count[shape]):
            most = max(most, geom.face_loop_count[f])
        return most
    return CAP_POINTS


@inline
def _candidate_capacity(geom, sa, fa, sb, fb):
    """Rows for a pair's unreduced candidate points: clipping adds at most one point per side plane."""
    return _feature_capacity(geom, sa, fa) + _feature_capacity(geom, sb, fb) + 1


@inline
def _write_axis_line(out, pos, quat, x, y, half):
    """Rows 0 and 1 of ``out``: the world ends of the line ``(x, y, ±half)`` of a capsule's or cylinder's frame."""
    _set_row(out, 0, add(pos, quat_rotate(quat, (x, y, -half))))
    _set_row(out, 1, add(pos, quat_rotate(quat, (x, y, half))))


@inline
def _support_feature(geom, shape, face, pos, quat, d, out):
    """The feature of a shape's core farthest along the unit world direction ``d``, as world points in ``out``.

    Returns ``(count, plane_normal, alignment, id, polyhedral)``: 1 point (a sphere's centre, a capsule's end);
    2 (a capsule's segment or a cylinder's side line lying within ``FLAT_SIN`` of the plane across ``d``); or a
    face with its outward normal and ``alignment = normal · d``: a polyhedron's or triangle's face (``polyhedral``
    True) or the end disc of a cylinder not lying flat, as a regular polygon.
    """
    zero = (0.0, 0.0, 0.0)
    if face >= 0:
        n = quat_rotate(quat, _row(geom.face_normal, face))
        side = 0
        if dot(n, d) < 0.0:
            n, side = _neg(n), 1
        start = geom.face_loop_start[face]
        for k in range(3):
            _set_row(out, k, add(pos, quat_rotate(quat, _row(geom.vertex_local, geom.face_loop[start + k]))))
        return 3, n, dot(n, d), side, True
    t = geom.shape_type[shape]
    dl = quat_rotate_inv(quat, d)
    if t == SPHERE:
        _set_row(out, 0, pos)
        return 1, zero, 0.0, 0, False
    if t == BOX:
        k = 0
        for j in range(1, 3):
            if abs(dl[j]) > abs(dl[k]):
                k = j
        positive = dl[k] >= 0.0
        h = (geom.shape_params[shape, 0], geom.shape_params[shape, 1], geom.shape_params[shape, 2])
        for c in range(4):
            corner = _box_corner(_box_face_corner(k, positive, c), h[0], h[1], h[2])
            _set_row(out, c, add(pos, quat_rotate(quat, corner)))
        n = quat_rotate(quat, _axis(k, 1.0 if positive else -1.0))
        return 4, n, dot(n, d), 2 * k + (0 if positive else 1), True
    if t == HULL:
        fs = geom.shape_face_start[shape]
        best, best_c = fs, -math.inf
        for f in range(fs, fs + geom.shape_face_count[shape]):
            c = dot(_row(geom.face_normal, f), dl)
            if c > best_c:
                best, best_c = f, c
        ls, lc = geom.face_loop_start[best], geom.face_loop_count[best]
        for k in range(lc):
            _set_row(out, k, add(pos, quat_rotate(quat, _row(geom.vertex_local, geom.face_loop[ls + k]))))
        return lc, quat_rotate(quat, _row(geom.face_normal, best)), best_c, best - fs, True
    # Capsule or cylinder: the axis is z; `radial` is the unit direction of d across it (x when d is along it).
    half = geom.shape_params[shape, 1]
    axial = dl[2]
    rho = math.sqrt(dl[0] * dl[0] + dl[1] * dl[1])
    rx, ry = (dl[0] / rho, dl[1] / rho) if rho > 1e-12 else (1.0, 0.0)
    if abs(axial) <= FLAT_SIN:
        r = geom.shape_params[shape, 0] if t == CYLINDER else 0.0
        _write_axis_line(out, pos, quat, r * rx, r * ry, half)
        return 2, zero, 0.0, 0, False
    if t == CAPSULE:
        _set_row(out, 0, add(pos, quat_rotate(quat, (0.0, 0.0, half if axial >= 0.0 else -half))))
        return 1, zero, 0.0, 0, False
    # A cylinder's end disc: CAP_POINTS rim corners counter-clockwise about its outward normal, the first deepest.
    # Tilted, it is still the feature: clipped against a face, the rim corners within the margin hold the cylinder
    # as they do on a plane, where one rim point let a tipping cylinder dig its opposite rim into a hull's face
    # (issue 44: 2.8-3.2 cm at 240 Hz). It is a reference face only when it faces d (REF_COS).
    r = geom.shape_params[shape, 0]
    s = 1.0 if axial >= 0.0 else -1.0
    for k in range(CAP_POINTS):
        ang = 2.0 * math.pi * k / CAP_POINTS
        ca, sn = elementary.cos(ang), s * elementary.sin(ang)
        corner = (r * (ca * rx - sn * ry), r * (sn * rx + ca * ry), s * half)
        _set_row(out, k, add(pos, quat_rotate(quat, corner)))
    n = quat_rotate(quat, (0.0, 0.0, s))
    return CAP_POINTS, n, abs(axial), 0 if s > 0.0 else 1, False


@inline
def _segment_pair(a0, a1, ra, b0, b1, rb, n, margin, out_point, out_sep, out_id):
    """Two parallel segment cores (capsules, cylinder sides): B's segment clipped to A's extent, two points."""
    u = sub(a1, a0)
    length = math.sqrt(dot(u, u))
    v = sub(b1, b0)
    if length == 0.0 or dot(v, v) == 0.0:
        return 0
    u = scale(u, 1.0 / length)
    if dot(cross(u, v), cross(u, v)) > FLAT_SIN * FLAT_SIN * dot(v, v):
        return 0
    t0, t1 = dot(u, sub(b0, a0)), dot(u, sub(b1, a0))
    if max(t0, t1) < 0.0 or min(t0, t1) > length or t0 == t1:
        return 0
    count = 0
    for end in range(2):
        # Where B's segment crosses A's end planes, or B's own end.
        t = max(0.0, min(length, t0 if end == 0 else t1))
        q = add_scaled(b0, v, (t - t0) / (t1 - t0))
        on_a = add_scaled(a0, u, max(0.0, min(length, dot(u, sub(q, a0)))))
        sep = dot(n, sub(q, on_a)) - ra - rb
        if sep <= margin:
            _set_row(out_point, count, scale(add(add_scaled(on_a, n, ra), add_scaled(q, n, -rb)), 0.5))
            out_sep[count] = sep
            out_id[count] = end
            count += 1
    return count


@inline
def _collide_smooth(geom, sa, fa, pa, qa, sb, fb, pb, qb, margin, out_point, out_sep, out_id):
    """A pair with a sphere, capsule or cylinder: GJK/EPA for the normal, then the features along it.

    Writes the candidate points into ``out_*`` (unreduced) and returns ``(count, normal)``.
    """
    xa, xb = core_proxy(geom, sa, fa), core_proxy(geom, sb, fb)
    ra, rb = xa[1], xb[1]
    found, sep, n, wa, wb = proxy_contact(xa, pa, qa, xb, pb, qb, geom.vertex_local, margin)
    if not found:
        return 0, (0.0, 0.0, 0.0)
    feat_a = np.empty((_feature_capacity(geom, sa, fa), 3))
    feat_b = np.empty((_feature_capacity(geom, sb, fb), 3))
    ka, na, align_a, id_a, poly_a = _support_feature(geom, sa, fa, pa, qa, n, feat_a)
    kb, nb, align_b, id_b, poly_b = _support_feature(geom, sb, fb, pb, qb, _neg(n), feat_b)
    ref_a = ka >= 3 and align_a >= REF_COS
    ref_b = kb >= 3 and align_b >= REF_COS
    if ref_a and ref_b:
        # A true face beats a cylinder's polygon; then the better aligned, then A.
        if poly_a != poly_b:
            ref_a = poly_a
        else:
            ref_a = align_a >= align_b
        ref_b = not ref_a
    # A capsule on a mesh's triangle (always B) is held by its whole segment: by its nearer end only, a capsule hit
    # from above turned about that end and drove the other 6-8 cm into the bowl within the step (issue 44).
    if ref_b and fb >= 0 and ka == 1 and geom.shape_type[sa] == CAPSULE:
        _write_axis_line(feat_a, pa, qa, 0.0, 0.0, geom.shape_params[sa, 1])
        ka = 2
    # Neither faces the normal, but one is a face within NEAR_FACE_COS of it: the other's feature clipped to it, each
    # point's separation measured along the normal from the plane the face's shape lies under (a lower bound on its
    # distance), and the deepest point besides. One point let a cylinder tipped on a box's edge rock from one side of
    # its rim to the other and dig each in (issue 44: 6 cm).
    near = not (ref_a or ref_b) and fa < 0 and fb < 0
    near_a = near and ka >= 3 and kb >= 2 and align_a >= NEAR_FACE_COS
    near_b = near and kb >= 3 and ka >= 2 and align_b >= NEAR_FACE_COS
    if near_a and near_b:
        near_a = align_a >= align_b
        near_b = not near_a
    count = 0
    normal = n
    id_a_ref = ((id_a & 0xFFF) << 28) | ((id_b & 0xFFF) << 16)
    id_b_ref = (1 << 40) | ((id_b & 0xFFF) << 28) | ((id_a & 0xFFF) << 16)
    if ref_a and kb >= 2:
        base_id = id_a_ref
        count = _clip_points(feat_a, ka, na, feat_b, kb, rb, na, dot(na, _row(feat_a, 0)), margin, base_id, out_point,
                             out_sep, out_id)  # fmt: skip
        normal = na
    elif ref_b and ka >= 2:
        base_id = id_b_ref
        count = _clip_points(feat_b, kb, nb, feat_a, ka, ra, nb, dot(nb, _row(feat_b, 0)), margin, base_id, out_point,
                             out_sep, out_id)  # fmt: skip
        normal = _neg(nb)
    elif near_a or near_b:
        if near_a:
            base_id = id_a_ref
            count = _clip_points(feat_a, ka, na, feat_b, kb, rb, n, dot(n, wa), margin, base_id, out_point, out_sep,
                                 out_id)  # fmt: skip
        else:
            base_id = id_b_ref
            count = _clip_points(feat_b, kb, nb, feat_a, ka, ra, _neg(n), -dot(n, wb), margin, base_id, out_point,
                                 out_sep, out_id)  # fmt: skip
        # The deepest point: clipping may have cut it off (it lies past the face's outline, on a rim or an edge).
        _set_row(out_point, count, scale(add(wa, wb), 0.5))
        out_sep[count] = sep
        out_id[count] = base_id | _DEEPEST_POINT
        count += 1
    elif ka == 2 and kb == 2:
        count = _segment_pair(_row(feat_a, 0), _row(feat_a, 1), ra, _row(feat_b, 0), _row(feat_b, 1), rb, n, margin,
                              out_point, out_sep, out_id)  # fmt: skip
    if count > 0:
        return count, normal
    # One point, midway between the surfaces.
    _set_row(out_point, 0, scale(add(wa, wb), 0.5))
    out_sep[0] = sep
    out_id[0] = 0
    return 1, n


# --- public kernels ------------------------------------------------------------------------------------------------


@inline
def _is_polyhedron(t):
    return t == BOX or t == HULL


@kernel
def collide_convex_convex(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                          feature):  # fmt: skip
    """Contact manifold of any two convex shapes (sphere, capsule, box, cylinder, hull), as in :mod:`.manifold`.

    Args:
        geom: :class:`~tumble.geometry.packing.GeometryArrays`.
        shape_a, shape_b: shape rows (any order of types; the normal points from A to B).
        pos_a, quat_a, pos_b, quat_b: world poses of the shape frames, tuples ([m], unit quaternion w-first).
        margin: [m] speculative distance: points up to this far apart are reported.
        normal: (3,) float64 output, unit, world frame, from A to B.
        point: (4, 3) float64 output [m], world frame, midway between the surfaces.
        separation: (4,) float64 output [m], negative when overlapping.
        feature: (4,) int64 output, feature ids for warm starting.

    Returns:
        The number of points written, 0 when the shapes are farther apart than ``margin``.
    """
    # A typed -1 (the whole shape, not a face), not a literal: a literal argument compiles its own copy of a callee.
    whole = np.int64(-1)
    cap = _candidate_capacity(geom, shape_a, whole, shape_b, whole)
    cand_point = np.empty((cap, 3))
    cand_sep = np.empty(cap)
    cand_id = np.empty(cap, np.int64)
    if _is_polyhedron(geom.shape_type[shape_a]) and _is_polyhedron(geom.shape_type[shape_b]):
        m, n = _collide_polyhedra(geom, shape_a, whole, pos_a, quat_a, shape_b, whole, pos_b, quat_b, margin,
                                  cand_point, cand_sep, cand_id)  # fmt: skip
    else:
        m, n = _collide_smooth(geom, shape_a, whole, pos_a, quat_a, shape_b, whole, pos_b, quat_b, margin, cand_point,
                               cand_sep, cand_id)  # fmt: skip
    if m == 0:
        return 0
    _set_vec(normal, n)
    return _write_four(cand_point, cand_sep, cand_id, m, n, point, separation, feature)


@inline
def _convex_bounds_in(geom, shape, pos, quat, frame_pos, frame_quat, grow):
    """Bounds of a convex shape along the axes of another frame, grown by ``grow`` [m]: ``(lo, hi)`` in that frame."""
    whole = np.int64(-1)
    r = core_radius(geom, shape, whole) + grow
    lo0 = lo1 = lo2 = hi0 = hi1 = hi2 = 0.0
    for k in range(3):
        axis = quat_rotate(frame_quat, _axis(k, 1.0))
        top = dot(axis, sub(support_world(geom, shape, whole, pos, quat, axis), frame_pos)) + r
        bottom = dot(axis, sub(support_world(geom, shape, whole, pos, quat, _neg(axis)), frame_pos)) - r
        if k == 0:
            lo0, hi0 = bottom, top
        elif k == 1:
            lo1, hi1 = bottom, top
        else:
            lo2, hi2 = bottom, top
    return (lo0, lo1, lo2), (hi0, hi1, hi2)


@kernel
def collide_convex_trimesh(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin, normal, point, separation,
                           feature):  # fmt: skip
    """Contact manifold of a convex shape A against a static triangle mesh B (see the module docstring).

    Same arguments and outputs as :func:`collide_convex_convex`; ``shape_b`` is a TriMesh. Feature ids carry the
    triangle's index within the mesh in bits 41-62.
    """
    whole = np.int64(-1)
    polyhedral = _is_polyhedron(geom.shape_type[shape_a])
    lo, hi = _convex_bounds_in(geom, shape_a, pos_a, quat_a, pos_b, quat_b, margin)
    fs = geom.shape_face_start[shape_b]
    # One triangle's candidates, and the mesh's; the latter is squeezed to four points whenever it would overflow.
    tri_cap = _candidate_capacity(geom, shape_a, whole, shape_b, fs)
    tri_point = np.empty((tri_cap, 3))
    tri_sep = np.empty(tri_cap)
    tri_id = np.empty(tri_cap, np.int64)
    cap = max(MESH_MAX_CANDIDATES, MAX_POINTS + tri_cap)
    cand_point = np.empty((cap, 3))
    cand_normal = np.empty((cap, 3))
    cand_sep = np.empty(cap)
    cand_id = np.empty(cap, np.int64)
    cand_face = np.empty(cap, np.bool_)
    m = np.int64(0)  # typed, not a literal 0: a literal argument compiles its own copy of the callee
    vertex_local, face_loop, face_loop_start, face_normal = (
        geom.vertex_local,
        geom.face_loop,
        geom.face_loop_start,
        geom.face_normal,
    )
    for f in range(fs, fs + geom.shape_face_count[shape_b]):
        # Skip faces without area, and faces whose bounds (mesh frame) miss the shape's. The loop reads the arrays
        # directly: a helper call that binds them again costs their reference counts on every pass.
        if face_normal[f, 0] == 0.0 and face_normal[f, 1] == 0.0 and face_normal[f, 2] == 0.0:
            continue
        start = face_loop_start[f]
        i0, i1, i2 = face_loop[start], face_loop[start + 1], face_loop[start + 2]
        apart = False
        for c in range(3):
            x0, x1, x2 = vertex_local[i0, c], vertex_local[i1, c], vertex_local[i2, c]
            if max(x0, x1, x2) < lo[c] or min(x0, x1, x2) > hi[c]:
                apart = True
        if apart:
            continue
        if polyhedral:
            k, n = _collide_polyhedra(geom, shape_a, whole, pos_a, quat_a, shape_b, f, pos_b, quat_b, margin,
                                      tri_point, tri_sep, tri_id)  # fmt: skip
        else:
            k, n = _collide_smooth(geom, shape_a, whole, pos_a, quat_a, shape_b, f, pos_b, quat_b, margin, tri_point,
                                   tri_sep, tri_id)  # fmt: skip
        if k == 0:
            continue
        # A face contact: the manifold's normal is the triangle's own (not an edge or corner of it).
        n_face = quat_rotate(quat_b, _row(face_normal, f))
        if dot(n, n_face) > 0.0:
            # Meshes are one-sided: a shape sunk deep (or straddling the triangle) is never pushed out through the
            # back, as the least-depth axis of a thin triangle may say; it goes back out along the face normal. Only
            # a shape over the triangle, though: one beside it (beyond an open mesh's rim, or past an inner edge,
            # where the neighbour holds it) would be dragged through the mesh sideways (issue 44: at a bowl's rim, a
            # hull outside and below it was pulled in through the wall, 6 cm under the surface).
            if not _over_triangle(geom, shape_a, pos_a, quat_a, pos_b, quat_b, vertex_local, i0, i1, i2, n_face):
                continue
            v0 = add(pos_b, quat_rotate(quat_b, _row(vertex_local, i0)))
            k = _front_face_contact(geom, shape_a, pos_a, quat_a, v0, n_face, margin, tri_point, tri_sep, tri_id)
            if k == 0:
                continue
            n = scale(n_face, -1.0)
        on_face = abs(dot(n, n_face)) >= REF_COS
        if m + k > cap:
            m = _squeeze(cand_point, cand_normal, cand_sep, cand_id, cand_face, m)
        for j in range(k):
            _set_row(cand_point, m, _row(tri_point, j))
            _set_row(cand_normal, m, n)
            cand_sep[m] = tri_sep[j]
            cand_id[m] = ((f - fs) << _TRIANGLE_SHIFT) | (tri_id[j] & ((1 << _TRIANGLE_SHIFT) - 1))
            cand_face[m] = on_face
            m += 1
    if m == 0:
        return 0
    return _merge_mesh_contacts(cand_point, cand_normal, cand_sep, cand_id, cand_face, m, margin, normal, point,
                                separation, feature)  # fmt: skip


@inline
def _over_triangle(geom, shape_a, pos_a, quat_a, pos_b, quat_b, vertex_local, i0, i1, i2, n_face):
    """Whether shape A's centre (its bounds' centre) lies over the triangle ``(i0, i1, i2)``: inside the prism its
    edges sweep along its normal ``n_face`` (counter-clockwise about it)."""
    # The bounds' centre is stored in the body frame: from the shape's origin there, turned into the shape's frame.
    offset = sub(_row(geom.shape_aabb_center_local, shape_a), _row(geom.shape_pos_local, shape_a))
    local = quat_rotate_inv(load4(geom.shape_quat_local, shape_a), offset)
    c = add(pos_a, quat_rotate(quat_a, local))
    v0 = add(pos_b, quat_rotate(quat_b, _row(vertex_local, i0)))
    v1 = add(pos_b, quat_rotate(quat_b, _row(vertex_local, i1)))
    v2 = add(pos_b, quat_rotate(quat_b, _row(vertex_local, i2)))
    return (
        dot(cross(sub(v1, v0), sub(c, v0)), n_face) >= 0.0
        and dot(cross(sub(v2, v1), sub(c, v1)), n_face) >= 0.0
        and dot(cross(sub(v0, v2), sub(c, v2)), n_face) >= 0.0
    )


@inline
def _front_face_contact(geom, shape_a, pos_a, quat_a, v0, n_face, margin, tri_point, tri_sep, tri_id):
    """One point: shape A's lowest point along the face normal ``n_face`` of a triangle through ``v0``, midway
    between it and the triangle's plane, and its signed height above the plane; 0 points past ``margin``."""
    down = scale(n_face, -1.0)
    lowest = add_scaled(support_world(geom, shape_a, -1, pos_a, quat_a, down), n_face, -core_radius(geom, shape_a, -1))
    height = dot(sub(lowest, v0), n_face)
    if height > margin:
        return 0
    _set_row(tri_point, 0, add_scaled(lowest, n_face, -0.5 * height))
    tri_sep[0] = height
    tri_id[0] = 0
    return 1


@inline
def _squeeze(cand_point, cand_normal, cand_sep, cand_id, cand_face, m):
    """Keep four of the mesh's candidates (:func:`_select_four` about the deepest one's normal); return how many."""
    deepest = 0
    for c in range(1, m):
        if cand_sep[c] < cand_sep[deepest]:
            deepest = c
    count, k0, k1, k2, k3 = _select_four(cand_point, cand_sep, m, _row(cand_normal, deepest))
    keep = np.array([k0, k1, k2, k3])
    # Gather first, then write back: a kept row may sit where another is written.
    point, normal = np.empty((MAX_POINTS, 3)), np.empty((MAX_POINTS, 3))
    sep, ids, face = np.empty(MAX_POINTS), np.empty(MAX_POINTS, np.int64), np.empty(MAX_POINTS, np.bool_)
    for j in range(count):
        k = keep[j]
        _set_row(point, j, _row(cand_point, k))
        _set_row(normal, j, _row(cand_normal, k))
        sep[j], ids[j], face[j] = cand_sep[k], cand_id[k], cand_face[k]
    for j in range(count):
        _set_row(cand_point, j, _row(point, j))
        _set_row(cand_normal, j, _row(normal, j))
        cand_sep[j], cand_id[j], cand_face[j] = sep[j], ids[j], face[j]
    return count


@inline
def _merge_mesh_contacts(cand_point, cand_normal, cand_sep, cand_id, cand_face, m, margin, normal, point, separation,
                         feature):  # fmt: skip
    """One manifold from the triangles' points (see the module docstring): the contact surface is the deepest face
    contact's (the deepest point's if none), its normal the depth-weighted average over the points within
    ``acos(MERGE_COS)`` of it; face contacts there push out the edge and corner contacts of the same surface (a
    sphere on a flat mesh also sees the nearby triangles' edges); separations are measured again along the normal."""
    anchor, anchor_face = 0, cand_face[0]
    for c in range(1, m):
        better = cand_sep[c] < cand_sep[anchor]
        if (cand_face[c] and not anchor_face) or (cand_face[c] == anchor_face and better):
            anchor, anchor_face = c, cand_face[c]
    n0 = _row(cand_normal, anchor)
    total = (0.0, 0.0, 0.0)
    for c in range(m):
        nc = _row(cand_normal, c)
        if dot(nc, n0) >= MERGE_COS and (cand_face[c] or not anchor_face):
            total = add_scaled(total, nc, max(margin - cand_sep[c], 0.0) + 1e-12)
    n = _unit(total)
    if dot(n, n) == 0.0:
        n = n0
    kept = np.int64(0)
    for c in range(m):
        nc = _row(cand_normal, c)
        if dot(nc, n0) >= MERGE_COS and (cand_face[c] or not anchor_face):
            # Moving along n by s / cos(angle) closes a gap s measured along the triangle's own normal.
            sep = cand_sep[c] / dot(nc, n)
            if sep <= margin or c == anchor:
                _set_row(cand_point, kept, _row(cand_point, c))
                cand_sep[kept] = sep
                cand_id[kept] = cand_id[c]
                kept += 1
    _set_vec(normal, n)
    return _write_four(cand_point, cand_sep, cand_id, kept, n, point, separation, feature)


# One kernel serves every convex type against a mesh; the per-pair names are for the dispatcher's table.
collide_sphere_trimesh = collide_convex_trimesh
collide_capsule_trimesh = collide_convex_trimesh
collide_box_trimesh = collide_convex_trimesh
collide_cylinder_trimesh = collide_convex_trimesh
collide_hull_trimesh = collide_convex_trimesh
