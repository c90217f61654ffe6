"""GJK distance and EPA penetration depth between convex shapes, from their support functions.

Every convex shape is a *core* swept by a *radius* (van den Bergen 2003, *Collision Detection in Interactive 3D
Environments*, §4.3; the same split as Box2D's shape proxies): a sphere is a point swept by its radius, a
capsule a segment swept by its radius, and a box, cylinder, hull or single mesh triangle is its own core with
radius 0. GJK (Gilbert, Johnson & Keerthi 1988) runs on the cores only, so round shapes cost a few iterations
instead of an approximation of a curved surface, and the radii are taken off at the end.

GJK looks for the point ``v`` of the Minkowski difference ``D = A - B`` nearest the origin. Each iteration adds
the support point ``w = s_A(-v) - s_B(v)`` to a simplex of at most four points and replaces ``v`` with the point
of that simplex nearest the origin, found by Johnson's sub-algorithm in its Voronoi-region form (Ericson 2005,
*Real-Time Collision Detection*, §5.1.5 and §9.5.2): find the vertex, edge or face region of the simplex that
holds the origin and keep only that feature. ``|v|`` bounds the distance from above and ``v·w/|v|`` from below;
the loop stops when the two agree to ``GJK_TOLERANCE`` times the size of the pair, when the lower bound passes
the caller's ``max_distance`` (nothing to report), when the simplex encloses the origin, or after
``GJK_MAX_ITERATIONS``.

When the cores touch or overlap (``|v|`` under ``GJK_OVERLAP`` times the size), the Expanding Polytope
Algorithm (van den Bergen 2001, "Proximity queries and penetration depth computation on 3D game objects",
GDC) grows GJK's last simplex into a polytope inside ``D`` around the origin, then repeatedly pushes out the
face nearest the origin with the support point along its normal, until that face is part of ``D``'s boundary
to ``EPA_TOLERANCE`` times the size. That face's normal is the direction from ``A`` to ``B``, and the overlap of
the cores along it, ``h_A(n) + h_B(-n)``, the penetration depth (see :func:`_polish_depth`, which also tries the
axes of round cores, where EPA is slow). The polytope lives in arrays of fixed size (``EPA_MAX_VERTICES``), so the
cost of a call is bounded and nothing grows; a step that would break its convexity through round-off ends the
search with the last sound answer. Ties go to the lowest index everywhere, so results are deterministic.

Only support points are needed, so the same code serves every convex pair and one triangle of a mesh
(``face >= 0`` names a face of ``geom``; its support is the farthest of its corners). The ``proxy_*`` functions
take cores as :func:`core_proxy` tuples; :func:`gjk`, :func:`epa` and :func:`convex_contact` take shape rows.
"""

from __future__ import annotations

import math

import numpy as np

from .. import elementary
from .._jit import inline, kernel
from ..math3d import add, add_scaled, cross, dot, quat_rotate, quat_rotate_inv, scale, sub
from ..shapes import ShapeType

__all__ = [
    "GJK_MAX_ITERATIONS",
    "GJK_TOLERANCE",
    "GJK_OVERLAP",
    "EPA_MAX_VERTICES",
    "EPA_MAX_FACES",
    "EPA_TOLERANCE",
    "GJK_SEPARATED",
    "GJK_OVERLAPPING",
    "GJK_FAR",
    "EPA_FLAT",
    "EPA_CONVERGED",
    "EPA_STOPPED",
    "core_proxy",
    "core_radius",
    "core_size",
    "proxy_support",
    "proxy_support_world",
    "support_local",
    "support_world",
    "proxy_gjk",
    "proxy_epa",
    "proxy_contact",
    "gjk",
    "epa",
    "convex_contact",
    "shape_distance",
]

SPHERE = int(ShapeType.SPHERE)
CAPSULE = int(ShapeType.CAPSULE)
BOX = int(ShapeType.BOX)
CYLINDER = int(ShapeType.CYLINDER)

# An iteration adds one support point; polytopes converge in a handful, a cylinder's rim in about 20.
GJK_MAX_ITERATIONS = 64
# Stop when the upper and lower bounds on the distance agree to this fraction of the pair's size.
GJK_TOLERANCE = 1e-10
# Cores closer than this fraction of the size count as touching: the normal then comes from EPA, because the
# direction of a vector this short is mostly round-off.
GJK_OVERLAP = 1e-7
# A closed triangulated polytope with V vertices has 2V - 4 faces, so the face arrays never fill up. Polytopes need
# a handful of vertices; a curved core with a circle of equal depths (coaxial cylinders) needs about 100 to reach the
# depth to 1e-9 (measured: 64 leave 5e-4 m on radius-0.25 m cylinders).
EPA_MAX_VERTICES = 128
EPA_MAX_FACES = 2 * EPA_MAX_VERTICES
# Stop when the support point along the nearest face's normal is this fraction of the size beyond it.
EPA_TOLERANCE = 1e-9

GJK_SEPARATED = 0  # the cores are apart: distance and closest points are valid
GJK_OVERLAPPING = 1  # the cores touch or overlap: run EPA on the simplex
GJK_FAR = 2  # farther apart than max_distance: the distance is only a lower bound

EPA_FLAT = 0  # A - B has no volume round the origin: no depth from EPA (see _flat_depth)
EPA_CONVERGED = 1  # the nearest face is on the boundary of A - B to EPA_TOLERANCE
EPA_STOPPED = 2  # out of vertices (or round-off ended it): the best face so far


# --- shapes as a core and a radius -------------------------------------------------------------------------
#
# The GJK and EPA loops call the support functions hundreds of times. Each call of a compiled function that takes
# the geometry arrays pays the reference counts of its twenty arrays (measured: 0.25 us a call, against 0.01 us
# for the support point itself), so the loops work on a *proxy* instead: a tuple, passed by value, with what the
# support function of one core needs, and only the vertex array beside it.

POINT = 0  # a sphere's centre
SEGMENT = 1  # a capsule's segment, half length a, along z
BLOCK = 2  # a box, half extents (a, b, c)
DISC_PRISM = 3  # a cylinder, radius a and half height b, axis z
VERTICES = 4  # a hull or a whole mesh: vertex rows start .. start + count
TRIANGLE = 5  # one mesh face: corners v0, v1, v2


@kernel
def core_proxy(geom, shape, face):
    """The core of shape ``shape`` (or of its face ``face`` if ``face >= 0``) as a tuple, passed by value.

    Returns ``(kind, radius, size, a, b, c, start, count, v0, v1, v2, centre)``: one of the kinds above, the radius
    swept round the core [m], a length for relative tolerances [m] (about the radius of a ball holding the shape),
    the sizes ``a, b, c`` [m], a vertex range, a triangle's corners and a point well inside, all in the shape frame.
    The inside point is the origin, or for a mesh triangle a point one triangle size behind its centroid (as if the
    mesh were solid behind its front faces): GJK's first direction, and the side a flat contact's normal takes.
    """
    zero = (0.0, 0.0, 0.0)
    kind, radius, size, a, b, c = VERTICES, 0.0, 0.0, 0.0, 0.0, 0.0
    start, count = geom.shape_vertex_start[shape], geom.shape_vertex_count[shape]
    v0, v1, v2, centre = zero, zero, zero, zero
    if face >= 0:
        kind = TRIANGLE
        loop = geom.face_loop_start[face]
        v0 = _vertex(geom, geom.face_loop[loop])
        v1 = _vertex(geom, geom.face_loop[loop + 1])
        v2 = _vertex(geom, geom.face_loop[loop + 2])
        size = math.sqrt(
            max(dot(sub(v1, v0), sub(v1, v0)), dot(sub(v2, v0), sub(v2, v0)), dot(sub(v2, v1), sub(v2, v1)))
        )
        n = _vertex_row(geom.face_normal, face)
        centre = add_scaled(scale(add(add(v0, v1), v2), 1.0 / 3.0), n, -size)
    else:
        t = geom.shape_type[shape]
        p0, p1, p2 = geom.shape_params[shape, 0], geom.shape_params[shape, 1], geom.shape_params[shape, 2]
        if t == SPHERE:
            kind, radius, size = POINT, p0, p0
        elif t == CAPSULE:
            kind, radius, size, a = SEGMENT, p0, p0 + p1, p1
        elif t == BOX:
            kind, size, a, b, c = BLOCK, math.sqrt(p0 * p0 + p1 * p1 + p2 * p2), p0, p1, p2
        elif t == CYLINDER:
            kind, size, a, b = DISC_PRISM, math.sqrt(p0 * p0 + p1 * p1), p0, p1
        else:
            # Hulls and meshes: the half-diagonal of their bounds (turned into the body frame, which only grows it).
            h = _vertex_row(geom.shape_aabb_half_local, shape)
            size = math.sqrt(dot(h, h))
    return (kind, radius, size, a, b, c, start, count, v0, v1, v2, centre)


@inline
def _vertex_row(array, i):
    return (array[i, 0], array[i, 1], array[i, 2])


@inline
def _vertex(geom, i):
    return (geom.vertex_local[i, 0], geom.vertex_local[i, 1], geom.vertex_local[i, 2])


@inline
def proxy_support(px, vertices, d):
    """A point of the core farthest along ``d`` (shape frame, need not be unit) [m], shape frame.

    Point: itself. Segment: its end on ``d``'s side. Box: the corner picked by the signs of ``d``. Cylinder: the rim
    point ``(r d_xy / |d_xy|, ±h)`` (exact; the centre of the end disc when ``d`` is along the axis). Vertices and
    triangles: the farthest vertex (the first of equals). A zero component picks the + side.
    """
    kind = px[0]
    if kind == POINT:
        return (0.0, 0.0, 0.0)
    if kind == SEGMENT:
        return (0.0, 0.0, px[3] if d[2] >= 0.0 else -px[3])
    if kind == BLOCK:
        return (px[3] if d[0] >= 0.0 else -px[3], px[4] if d[1] >= 0.0 else -px[4], px[5] if d[2] >= 0.0 else -px[5])
    if kind == DISC_PRISM:
        z = px[4] if d[2] >= 0.0 else -px[4]
        radial = math.sqrt(d[0] * d[0] + d[1] * d[1])
        if radial > 0.0:
            return (px[3] * d[0] / radial, px[3] * d[1] / radial, z)
        return (0.0, 0.0, z)
    if kind == TRIANGLE:
        best, s1, s2 = px[8], dot(px[9], d), dot(px[10], d)
        s0 = dot(best, d)
        if s1 > s0:
            best, s0 = px[9], s1
        if s2 > s0:
            best = px[10]
        return best
    start = px[6]
    best_i = start
    best_s = dot(_vertex_row(vertices, start), d)
    for i in range(start + 1, start + px[7]):
        s = dot(_vertex_row(vertices, i), d)
        if s > best_s:
            best_s, best_i = s, i
    return _vertex_row(vertices, best_i)


@inline
def proxy_support_world(px, vertices, pos, quat, d):
    """:func:`proxy_support` for a core placed at ``(pos, quat)``: world direction in, world point out."""
    return add(pos, quat_rotate(quat, proxy_support(px, vertices, quat_rotate_inv(quat, d))))


@kernel
def core_radius(geom, shape, face):
    """The radius swept around the core [m]: a sphere's or capsule's radius, else 0."""
    return core_proxy(geom, shape, face)[1]


@inline
def core_size(geom, shape, face):
    """A length for relative tolerances [m]: about the radius of a ball holding the shape (core and radius)."""
    return core_proxy(geom, shape, face)[2]


@kernel
def support_local(geom, shape, face, d):
    """A point of the core of shape ``shape`` (or its face ``face``) farthest along ``d``, shape frame [m]."""
    return proxy_support(core_proxy(geom, shape, face), geom.vertex_local, d)


@kernel
def support_world(geom, shape, face, pos, quat, d):
    """:func:`support_local` for a shape placed at ``(pos, quat)``: world direction in, world point out."""
    return proxy_support_world(core_proxy(geom, shape, face), geom.vertex_local, pos, quat, d)


@inline
def _support_pair(xa, pa, qa, xb, pb, qb, vertices, d):
    """The support points ``s_A(d)`` and ``s_B(-d)``, whose difference is the support of ``A - B`` along ``d``."""
    a = proxy_support_world(xa, vertices, pa, qa, d)
    b = proxy_support_world(xb, vertices, pb, qb, (-d[0], -d[1], -d[2]))
    return a, b


@inline
def _centre(px, pos, quat):
    """The proxy's inside point, world frame."""
    return add(pos, quat_rotate(quat, px[11]))


# --- Johnson's sub-algorithm: the point of a simplex nearest the origin ----------------------------------


@inline
def _closest_on_segment(w0, w1):
    """Nearest point to the origin on the segment, with its barycentric weights ``(l0, l1)``."""
    e = sub(w1, w0)
    ee = dot(e, e)
    t = -dot(w0, e) / ee if ee > 0.0 else 0.0
    if t <= 0.0:
        return w0, 1.0, 0.0
    if t >= 1.0:
        return w1, 0.0, 1.0
    return add_scaled(w0, e, t), 1.0 - t, t


@inline
def _closest_on_triangle(w0, w1, w2):
    """Nearest point to the origin on the triangle and its weights, by Voronoi regions (Ericson 2005, §5.1.5).

    Each test below rules a region in or out with dot products of edges and the vectors to the origin; the weights
    of the vertices the region does not use are exactly 0, which tells the caller which vertices to drop.
    """
    e1, e2 = sub(w1, w0), sub(w2, w0)
    # Region of vertex 0.
    d1, d2 = -dot(e1, w0), -dot(e2, w0)
    if d1 <= 0.0 and d2 <= 0.0:
        return w0, 1.0, 0.0, 0.0
    # Region of vertex 1.
    d3, d4 = -dot(e1, w1), -dot(e2, w1)
    if d3 >= 0.0 and d4 <= d3:
        return w1, 0.0, 1.0, 0.0
    # Region of edge 0-1.
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0 and d1 - d3 > 0.0:
        t = d1 / (d1 - d3)
        return add_scaled(w0, e1, t), 1.0 - t, t, 0.0
    # Region of vertex 2.
    d5, d6 = -dot(e1, w2), -dot(e2, w2)
    if d6 >= 0.0 and d5 <= d6:
        return w2, 0.0, 0.0, 1.0
    # Region of edge 0-2.
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0 and d2 - d6 > 0.0:
        t = d2 / (d2 - d6)
        return add_scaled(w0, e2, t), 1.0 - t, 0.0, t
    # Region of edge 1-2.
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0 and (d4 - d3) + (d5 - d6) > 0.0:
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return add_scaled(w1, sub(w2, w1), t), 0.0, 1.0 - t, t
    # Inside the face; a triangle with no area (all weights 0) falls back to its best edge.
    den = va + vb + vc
    if den > 0.0:
        l1, l2 = vb / den, vc / den
        return add(w0, add(scale(e1, l1), scale(e2, l2))), 1.0 - l1 - l2, l1, l2
    p01, a0, a1 = _closest_on_segment(w0, w1)
    p02, b0, b2 = _closest_on_segment(w0, w2)
    p12, c1, c2 = _closest_on_segment(w1, w2)
    if dot(p01, p01) <= dot(p02, p02) and dot(p01, p01) <= dot(p12, p12):
        return p01, a0, a1, 0.0
    if dot(p02, p02) <= dot(p12, p12):
        return p02, b0, 0.0, b2
    return p12, 0.0, c1, c2


@inline
def _closest_on_simplex(sim_a, sim_b, count):
    """Replace the simplex (rows ``[:count]`` of the support points of A and B) by its sub-simplex nearest the origin.

    Returns ``(count, v, l0, l1, l2, l3)``: the new count (4 only when the tetrahedron encloses the origin), the
    nearest point ``v`` and the weights of the kept rows, which are compacted to the front in their old order.
    """
    w0 = sub((sim_a[0, 0], sim_a[0, 1], sim_a[0, 2]), (sim_b[0, 0], sim_b[0, 1], sim_b[0, 2]))
    w1 = sub((sim_a[1, 0], sim_a[1, 1], sim_a[1, 2]), (sim_b[1, 0], sim_b[1, 1], sim_b[1, 2]))
    w2 = sub((sim_a[2, 0], sim_a[2, 1], sim_a[2, 2]), (sim_b[2, 0], sim_b[2, 1], sim_b[2, 2]))
    w3 = sub((sim_a[3, 0], sim_a[3, 1], sim_a[3, 2]), (sim_b[3, 0], sim_b[3, 1], sim_b[3, 2]))
    lam = (1.0, 0.0, 0.0, 0.0)
    v = w0
    if count == 2:
        v, l0, l1 = _closest_on_segment(w0, w1)
        lam = (l0, l1, 0.0, 0.0)
    elif count == 3:
        v, l0, l1, l2 = _closest_on_triangle(w0, w1, w2)
        lam = (l0, l1, l2, 0.0)
    elif count == 4:
        # The origin is outside the tetrahedron through a face exactly when that face's plane separates it from the
        # opposite vertex (or the tetrahedron is flat there); the nearest of those faces' nearest points wins.
        best = math.inf
        inside = True
        for f in range(4):
            if f == 0:
                p, q, r, o = w1, w2, w3, w0
            elif f == 1:
                p, q, r, o = w0, w2, w3, w1
            elif f == 2:
                p, q, r, o = w0, w1, w3, w2
            else:
                p, q, r, o = w0, w1, w2, w3
            n = cross(sub(q, p), sub(r, p))
            if -dot(n, p) * dot(n, sub(o, p)) > 0.0:
                continue
            inside = False
            x, lp, lq, lr = _closest_on_triangle(p, q, r)
            xx = dot(x, x)
            if xx < best:
                best, v = xx, x
                if f == 0:
                    lam = (0.0, lp, lq, lr)
                elif f == 1:
                    lam = (lp, 0.0, lq, lr)
                elif f == 2:
                    lam = (lp, lq, 0.0, lr)
                else:
                    lam = (lp, lq, lr, 0.0)
        if inside:
            return 4, (0.0, 0.0, 0.0), 0.25, 0.25, 0.25, 0.25
    # Keep the rows with a positive weight, in order.
    kept = 0
    o0, o1, o2, o3 = 0.0, 0.0, 0.0, 0.0
    for i in range(count):
        if lam[i] > 0.0:
            for c in range(3):
                sim_a[kept, c] = sim_a[i, c]
                sim_b[kept, c] = sim_b[i, c]
            if kept == 0:
                o0 = lam[i]
            elif kept == 1:
                o1 = lam[i]
            elif kept == 2:
                o2 = lam[i]
            else:
                o3 = lam[i]
            kept += 1
    return kept, v, o0, o1, o2, o3


# --- GJK -------------------------------------------------------------------------------------------------------


@inline
def _row(array, i):
    return (array[i, 0], array[i, 1], array[i, 2])


@inline
def proxy_gjk(xa, pa, qa, xb, pb, qb, vertices, max_distance, sim_a, sim_b):
    """Distance between the cores of two convex shapes (radii not included).

    Args:
        xa, xb: the cores, from :func:`core_proxy`.
        pa, qa, pb, qb: world poses of the shape frames (tuples).
        vertices: ``geom.vertex_local`` (V, 3) float64 [m], for hulls.
        max_distance: [m] stop early once the cores are provably farther apart than this (``inf`` for never).
        sim_a, sim_b: (4, 3) float64 outputs: the support points of A and B of the last simplex, world frame.

    Returns:
        ``(status, count, distance, point_a, point_b)``: ``GJK_SEPARATED`` with the distance and closest points of
        the cores; ``GJK_OVERLAPPING`` when they touch or overlap (``count`` rows of ``sim_a``/``sim_b`` then seed
        :func:`epa`); ``GJK_FAR`` when farther than ``max_distance`` (``distance`` is then a lower bound).
    """
    size = xa[2] + xb[2]
    tol = GJK_TOLERANCE * size
    touching = GJK_OVERLAP * size
    # First point: the supports facing each other along the line between the centres.
    d = sub(_centre(xb, pb, qb), _centre(xa, pa, qa))
    if dot(d, d) == 0.0:
        d = (1.0, 0.0, 0.0)
    a, b = _support_pair(xa, pa, qa, xb, pb, qb, vertices, d)
    for c in range(3):
        sim_a[0, c], sim_b[0, c] = a[c], b[c]
    for i in range(1, 4):
        for c in range(3):
            sim_a[i, c], sim_b[i, c] = 0.0, 0.0
    count = 1
    lam = (1.0, 0.0, 0.0, 0.0)
    v = sub(a, b)
    status = GJK_SEPARATED
    for _ in range(GJK_MAX_ITERATIONS):
        vv = dot(v, v)
        if vv <= touching * touching:
            status = GJK_OVERLAPPING
            break
        a, b = _support_pair(xa, pa, qa, xb, pb, qb, vertices, (-v[0], -v[1], -v[2]))
        w = sub(a, b)
        vw = dot(v, w)
        # v·w / |v| is a lower bound on the distance: past max_distance there is nothing to report.
        if vw > 0.0 and vw * vw > max_distance * max_distance * vv:
            status = GJK_FAR
            break
        # |v| - v·w/|v| is the gap between the bounds: converged.
        if vv - vw <= tol * math.sqrt(vv):
            break
        repeated = False
        for i in range(count):
            if sim_a[i, 0] == a[0] and sim_a[i, 1] == a[1] and sim_a[i, 2] == a[2]:
                if sim_b[i, 0] == b[0] and sim_b[i, 1] == b[1] and sim_b[i, 2] == b[2]:
                    repeated = True
        if repeated:
            break
        for c in range(3):
            sim_a[count, c], sim_b[count, c] = a[c], b[c]
        count, v_new, l0, l1, l2, l3 = _closest_on_simplex(sim_a, sim_b, count + 1)
        lam = (l0, l1, l2, l3)
        if count == 4:
            status = GJK_OVERLAPPING
            v = v_new
            break
        # Round-off can stall the descent; stop when |v| no longer shrinks.
        stalled = dot(v_new, v_new) >= vv
        v = v_new
        if stalled:
            break
    point_a = (0.0, 0.0, 0.0)
    point_b = (0.0, 0.0, 0.0)
    for i in range(count):
        point_a = add_scaled(point_a, _row(sim_a, i), lam[i])
        point_b = add_scaled(point_b, _row(sim_b, i), lam[i])
    distance = math.sqrt(dot(v, v))
    if status == GJK_SEPARATED and distance <= touching:
        # Out of iterations on a last step that reached the origin: touching (and never a normal divided by 0).
        status = GJK_OVERLAPPING
    if status == GJK_FAR:
        distance = dot(v, sub(a, b)) / distance
    return status, count, distance, point_a, point_b


# --- EPA -------------------------------------------------------------------------------------------------------
#
# The Expanding Polytope Algorithm of van den Bergen (2001; 2003, §4.3.8), with the hole found by a walk over
# neighbour links. :func:`proxy_epa` has four ways out, each its own function below:
#
# 1. the seed has no volume round the origin (``A - B`` is flat there): :func:`_epa_flat_answer`, ``EPA_FLAT``;
# 2. the nearest face lies on the boundary of ``A - B``: ``EPA_CONVERGED`` (:func:`_epa_expand`);
# 3. out of vertices, out of face slots, or a step that cannot be taken soundly (the new point sees every face, the
#    hole's rim is not one loop, a new face comes out nearer than the old): ``EPA_STOPPED`` with the nearest face of
#    the last sound polytope (:func:`_epa_grow` refuses the step, :func:`_epa_expand` keeps the answer);
# 4. no face of the seed tetrahedron has a finite distance (only on non-finite input): the flat answer again.
#
# Every buffer is written before it is read. Vertex rows ``[:count]`` are written as they are made; a face slot's
# vertices, normal and distance when its face is made, and only alive faces are read (``alive`` starts all False); a
# neighbour link is followed only where ``adj`` is not -1 (it starts so), and ``adj_edge`` is written with it; the
# walk's stack, the horizon and the fan are read only below their fill level.


@inline
def _epa_push(xa, pa, qa, xb, pb, qb, vertices, d, va, vb, n):
    """Append the support pair along ``d`` as vertex ``n``; return its point of ``A - B``."""
    a, b = _support_pair(xa, pa, qa, xb, pb, qb, vertices, d)
    for c in range(3):
        va[n, c], vb[n, c] = a[c], b[c]
    return sub(a, b)


@inline
def _epa_w(va, vb, i):
    return sub(_row(va, i), _row(vb, i))


@inline
def _copy_vertex(va, vb, to, source):
    for c in range(3):
        va[to, c], vb[to, c] = va[source, c], vb[source, c]


@inline
def _epa_seed(xa, pa, qa, xb, pb, qb, vertices, va, vb, count, tol):
    """Grow GJK's simplex (1 to 4 points, the origin on or in it) into a tetrahedron: any point away from a single
    point, the point farthest from a segment's line, the higher apex over a triangle. The origin is then inside or on
    the boundary (a face through it is fine for EPA).

    Flatness is measured as a height against ``tol``: a tetrahedron whose apex is within ``tol`` of the plane of its
    largest face keeps its face round the origin (the one nearest it; of those, the largest), and a triangle whose
    height over its longest edge is within ``tol`` keeps that edge. (A test of the volume in absolute units lets
    through a tetrahedron flat to round-off, whose four faces then wind at random: the origin on a hull's face,
    GJK's simplex four corners of that face.)

    Returns ``(count, hint)``: ``count >= 4`` on success. Otherwise ``A - B`` has no volume around the origin (two
    points, a point and a segment, two crossing segments, a point in a triangle's plane...) and ``hint`` is a
    unit normal of the flat set when it is a plane (zero otherwise).
    """
    hint = (0.0, 0.0, 0.0)
    if count == 4:
        w0 = _epa_w(va, vb, 0)
        volume = dot(cross(sub(_epa_w(va, vb, 1), w0), sub(_epa_w(va, vb, 2), w0)), sub(_epa_w(va, vb, 3), w0))
        # Face f leaves out vertex f; |volume| / |2 area| is the height over face f.
        most = 0.0
        for f in range(4):
            p, q, r = _epa_w(va, vb, (f + 1) % 4), _epa_w(va, vb, (f + 2) % 4), _epa_w(va, vb, (f + 3) % 4)
            area = cross(sub(q, p), sub(r, p))
            most = max(most, dot(area, area))
        if volume * volume > tol * tol * most:
            return 4, hint
        nearest = math.inf
        for f in range(4):
            p, q, r = _epa_w(va, vb, (f + 1) % 4), _epa_w(va, vb, (f + 2) % 4), _epa_w(va, vb, (f + 3) % 4)
            x = _closest_on_triangle(p, q, r)[0]
            nearest = min(nearest, dot(x, x))
        keep, kept_area = 3, -1.0
        for f in range(4):
            p, q, r = _epa_w(va, vb, (f + 1) % 4), _epa_w(va, vb, (f + 2) % 4), _epa_w(va, vb, (f + 3) % 4)
            x = _closest_on_triangle(p, q, r)[0]
            area = cross(sub(q, p), sub(r, p))
            if dot(x, x) <= nearest + tol * tol and dot(area, area) > kept_area:
                keep, kept_area = f, dot(area, area)
        _copy_vertex(va, vb, keep, 3)
        count = 3
    if count == 3:
        w0, w1, w2 = _epa_w(va, vb, 0), _epa_w(va, vb, 1), _epa_w(va, vb, 2)
        n = cross(sub(w1, w0), sub(w2, w0))
        l01, l02, l12 = dot(sub(w1, w0), sub(w1, w0)), dot(sub(w2, w0), sub(w2, w0)), dot(sub(w2, w1), sub(w2, w1))
        if dot(n, n) <= tol * tol * max(l01, l02, l12):
            # A sliver: keep its longest edge in rows 0 and 1, and grow again from there.
            if l12 >= l01 and l12 >= l02:
                _copy_vertex(va, vb, 0, 2)
            elif l02 > l01:
                _copy_vertex(va, vb, 1, 2)
            count = 2
    if count == 2:
        w0 = _epa_w(va, vb, 0)
        u = sub(_epa_w(va, vb, 1), w0)
        if dot(u, u) <= tol * tol:
            count = 1
    if count == 1:
        # Any support point away from the first.
        w0 = _epa_w(va, vb, 0)
        for k in range(6):
            s = 1.0 if k % 2 == 0 else -1.0
            d = (s if k // 2 == 0 else 0.0, s if k // 2 == 1 else 0.0, s if k // 2 == 2 else 0.0)
            w = _epa_push(xa, pa, qa, xb, pb, qb, vertices, d, va, vb, count)
            if dot(sub(w, w0), sub(w, w0)) > tol * tol:
                count += 1
                break
        if count == 1:
            return 1, hint
    if count == 2:
        # The support point farthest from the segment's line, over six directions around it.
        w0 = _epa_w(va, vb, 0)
        u = sub(_epa_w(va, vb, 1), w0)
        u = scale(u, 1.0 / math.sqrt(dot(u, u)))
        e1 = _perpendicular(u)
        e2 = cross(u, e1)
        best, best_k = -1.0, 0
        for k in range(6):
            ang = k * math.pi / 3.0
            d = add(scale(e1, elementary.cos(ang)), scale(e2, elementary.sin(ang)))
            w = _epa_push(xa, pa, qa, xb, pb, qb, vertices, d, va, vb, count)
            off = cross(sub(w, w0), u)
            dist = dot(off, off)
            if dist > best:
                best, best_k = dist, k
        if best <= tol * tol:
            return 2, hint
        ang = best_k * math.pi / 3.0
        _epa_push(xa, pa, qa, xb, pb, qb, vertices, add(scale(e1, elementary.cos(ang)), scale(e2, elementary.sin(ang))),
                  va, vb, count)  # fmt: skip
        count += 1
    # A triangle round the origin: the higher of the apexes on either side of its plane (row 4 is scratch).
    w0 = _epa_w(va, vb, 0)
    n = cross(sub(_epa_w(va, vb, 1), w0), sub(_epa_w(va, vb, 2), w0))
    n = scale(n, 1.0 / math.sqrt(dot(n, n)))
    up = dot(n, sub(_epa_push(xa, pa, qa, xb, pb, qb, vertices, n, va, vb, count), w0))
    down = -dot(n, sub(_epa_push(xa, pa, qa, xb, pb, qb, vertices, (-n[0], -n[1], -n[2]), va, vb, count + 1), w0))
    if max(up, down) <= tol:
        return 3, n
    if down > up:
        _copy_vertex(va, vb, count, count + 1)
    return 4, hint


@inline
def _perpendicular(u):
    """A unit vector perpendicular to the unit vector ``u``."""
    if abs(u[0]) >= 0.57735:
        p = (u[1], -u[0], 0.0)
    else:
        p = (0.0, u[2], -u[1])
    return scale(p, 1.0 / math.sqrt(dot(p, p)))


@inline
def _epa_flat_answer(xa, pa, qa, xb, pb, qb, vertices, va, vb, count, hint):
    """Exit 1 (and 4): ``A - B`` has no volume round the origin. Depth 0, the normal of the flat set (see
    :func:`_flat_normal`), and the mean of the ``count`` support pairs as the points."""
    point_a, point_b = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    for i in range(count):
        point_a = add_scaled(point_a, _row(va, i), 1.0 / count)
        point_b = add_scaled(point_b, _row(vb, i), 1.0 / count)
    n = _flat_normal(xa, pa, qa, xb, pb, qb, vertices, va, vb, count, hint)
    return EPA_FLAT, 0.0, n, point_a, point_b


@kernel
def _epa_polytope():
    """The polytope's face arrays: ``(faces, adj, adj_edge, normal, dist, alive, stack, horizon, fan)``.

    ``faces[f]`` are the vertex rows of face ``f``, wound outwards; ``adj[f, e]`` is the face across its edge ``e``
    (from vertex ``e`` to ``e + 1``) and ``adj_edge[f, e]`` that face's number for the edge; ``normal`` and ``dist``
    the unit outward normal and the distance of the face's plane from the origin. The walk pushes at most 3 + 2 per
    removed face onto ``stack``, so ``2 * EPA_MAX_FACES + 3`` rows bound it, the horizon and the fan.
    """
    walk = 2 * EPA_MAX_FACES + 3
    return (np.empty((EPA_MAX_FACES, 3), np.int64), np.full((EPA_MAX_FACES, 3), -1, np.int64),
            np.empty((EPA_MAX_FACES, 3), np.int64), np.empty((EPA_MAX_FACES, 3)), np.empty(EPA_MAX_FACES),
            np.zeros(EPA_MAX_FACES, np.bool_), np.empty((walk, 2), np.int64), np.empty((walk, 2), np.int64),
            np.empty(walk, np.int64))  # fmt: skip


@inline
def _epa_update_face(va, vb, faces, normal, dist, f):
    """Unit normal and origin distance of face ``f`` as wound (a face with no area: zero normal, infinite distance,
    so it is never the nearest)."""
    wi = _epa_w(va, vb, faces[f, 0])
    n = cross(sub(_epa_w(va, vb, faces[f, 1]), wi), sub(_epa_w(va, vb, faces[f, 2]), wi))
    length = math.sqrt(dot(n, n))
    if length > 0.0:
        n = scale(n, 1.0 / length)
        dist[f] = dot(n, wi)
    else:
        dist[f] = math.inf
    normal[f, 0], normal[f, 1], normal[f, 2] = n[0], n[1], n[2]


@inline
def _epa_link(faces, adj, adj_edge, f, g):
    """Link ``f`` and ``g`` as neighbours across the edge they share (walked in opposite directions); False if none."""
    for e in range(3):
        for k in range(3):
            if faces[f, e] == faces[g, (k + 1) % 3] and faces[f, (e + 1) % 3] == faces[g, k]:
                adj[f, e], adj_edge[f, e] = g, k
                adj[g, k], adj_edge[g, k] = f, e
                return True
    return False


@kernel
def _epa_tetrahedron(va, vb, poly):
    """The seed tetrahedron in rows 0 to 3 as four faces (face f leaves out vertex f), each wound to face away from
    the centroid, linked to its neighbours."""
    faces, adj, adj_edge, normal, dist, alive = poly[0], poly[1], poly[2], poly[3], poly[4], poly[5]
    interior = (0.0, 0.0, 0.0)
    for i in range(4):
        interior = add_scaled(interior, _epa_w(va, vb, i), 0.25)
    for f in range(4):
        i, j, k = (f + 1) % 4, (f + 2) % 4, (f + 3) % 4
        wi = _epa_w(va, vb, i)
        if dot(cross(sub(_epa_w(va, vb, j), wi), sub(_epa_w(va, vb, k), wi)), sub(interior, wi)) > 0.0:
            j, k = k, j
        faces[f, 0], faces[f, 1], faces[f, 2] = i, j, k
        _epa_update_face(va, vb, faces, normal, dist, f)
        alive[f] = True
    for f in range(4):
        for g in range(f + 1, 4):
            _epa_link(faces, adj, adj_edge, f, g)


@kernel
def _epa_nearest(dist, alive, face_count):
    """The alive face nearest the origin (first of equals), or -1 when no alive face has a finite distance."""
    best = -1
    for f in range(face_count):
        if alive[f] and math.isfinite(dist[f]) and (best < 0 or dist[f] < dist[best]):
            best = f
    return best


@kernel
def _epa_grow(va, vb, poly, best, count, face_count, depth, tol, flat):
    """Add vertex ``count`` (the support point beyond face ``best``) to the polytope: remove the faces it sees, found
    by a walk over neighbours from ``best`` (so the hole is one connected patch), and fill the hole with a fan of faces
    to the new point, reusing dead slots.

    Faces within ``flat`` of containing the point in their plane count as seen, so that no sliver of a fan face comes
    out wound the wrong way. Returns the new face count, or -1 when the step cannot be taken soundly (exit 3): the
    point sees every face (a polytope flat to round-off), the hole's rim is not one loop, the slots run out, or a
    new face is nearer the origin than ``depth`` (a grown convex polytope never is; round-off broke convexity). The
    polytope is then left broken, and the caller stops with the answer it had.
    """
    faces, adj, adj_edge, normal, dist, alive, stack, horizon, fan = poly
    w = _epa_w(va, vb, count)
    alive[best] = False
    top = 0
    for e in range(3):
        if adj[best, e] >= 0:
            stack[top, 0], stack[top, 1] = adj[best, e], adj_edge[best, e]
            top += 1
    edge_count = 0
    while top > 0:
        top -= 1
        g, k = stack[top, 0], stack[top, 1]
        if not alive[g]:
            continue
        if dot(_row(normal, g), sub(w, _epa_w(va, vb, faces[g, 0]))) > -flat:
            alive[g] = False
            for e in (1, 2):
                if adj[g, (k + e) % 3] >= 0:
                    stack[top, 0], stack[top, 1] = adj[g, (k + e) % 3], adj_edge[g, (k + e) % 3]
                    top += 1
        else:
            horizon[edge_count, 0], horizon[edge_count, 1] = g, k
            edge_count += 1
    # A rim has at least three edges; none means the point saw every face.
    if edge_count < 3:
        return -1
    # Across the horizon edge (a -> b of the kept face) the new face is (b, a, w), which keeps the winding.
    slot = 0
    for h in range(edge_count):
        while slot < face_count and alive[slot]:
            slot += 1
        if slot >= EPA_MAX_FACES:
            return -1
        g, k = horizon[h, 0], horizon[h, 1]
        faces[slot, 0], faces[slot, 1], faces[slot, 2] = faces[g, (k + 1) % 3], faces[g, k], count
        adj[slot, 0], adj_edge[slot, 0] = g, k
        adj[g, k], adj_edge[g, k] = slot, 0
        _epa_update_face(va, vb, faces, normal, dist, slot)
        alive[slot] = True
        fan[h] = slot
        if slot == face_count:
            face_count += 1
    # Link the fan's faces to each other: (b, a, w) meets the face whose edge starts at a ... ends at w.
    for h in range(edge_count):
        found = False
        for h2 in range(edge_count):
            if h2 != h and faces[fan[h2], 0] == faces[fan[h], 1]:
                adj[fan[h], 1], adj_edge[fan[h], 1] = fan[h2], 2
                adj[fan[h2], 2], adj_edge[fan[h2], 2] = fan[h], 1
                found = True
                break
        if not found:
            return -1
    for h in range(edge_count):
        if dist[fan[h]] < depth - tol:
            return -1
    return face_count


@inline
def _epa_expand(xa, pa, qa, xb, pb, qb, vertices, va, vb, poly, tol, flat):
    """Push out the nearest face until it lies on the boundary of ``A - B`` (exit 2) or no sound step is left
    (exit 3). Returns ``(status, depth, face, normal)``: the nearest face's distance, vertex rows and unit normal;
    ``EPA_FLAT`` when the seed has no face with a finite distance (exit 4)."""
    faces, normal, dist, alive = poly[0], poly[3], poly[4], poly[5]
    face_count = 4
    best = _epa_nearest(dist, alive, face_count)
    if best < 0:
        return EPA_FLAT, 0.0, (0, 1, 2), (0.0, 0.0, 1.0)
    for count in range(4, EPA_MAX_VERTICES):
        # (Copied: the slot may be reused by the step below.)
        depth, face, n = dist[best], (faces[best, 0], faces[best, 1], faces[best, 2]), _row(normal, best)
        w = _epa_push(xa, pa, qa, xb, pb, qb, vertices, n, va, vb, count)
        if dot(n, w) - depth <= tol:
            return EPA_CONVERGED, depth, face, n
        face_count = _epa_grow(va, vb, poly, best, count, face_count, depth, tol, flat)
        if face_count < 0:
            return EPA_STOPPED, depth, face, n
        best = _epa_nearest(dist, alive, face_count)
        if best < 0:
            return EPA_STOPPED, depth, face, n
    # Out of vertices: the nearest face of the full polytope.
    return EPA_STOPPED, dist[best], (faces[best, 0], faces[best, 1], faces[best, 2]), _row(normal, best)


@inline
def _epa_witnesses(va, vb, depth, face, n):
    """The origin's projection on the answer's face, ``depth · n``, in barycentric weights of the face's support
    pairs: the deepest points of A and B."""
    i, j, k = face
    w0 = _epa_w(va, vb, i)
    e1, e2 = sub(_epa_w(va, vb, j), w0), sub(_epa_w(va, vb, k), w0)
    x = sub(scale(n, depth), w0)
    d00, d01, d11 = dot(e1, e1), dot(e1, e2), dot(e2, e2)
    d20, d21 = dot(x, e1), dot(x, e2)
    den = d00 * d11 - d01 * d01
    l1, l2 = 1.0 / 3.0, 1.0 / 3.0
    if den > 0.0:
        l1 = (d11 * d20 - d01 * d21) / den
        l2 = (d00 * d21 - d01 * d20) / den
    l0 = 1.0 - l1 - l2
    point_a = add(add(scale(_row(va, i), l0), scale(_row(va, j), l1)), scale(_row(va, k), l2))
    point_b = add(add(scale(_row(vb, i), l0), scale(_row(vb, j), l1)), scale(_row(vb, k), l2))
    return point_a, point_b


@kernel
def proxy_epa(xa, pa, qa, xb, pb, qb, vertices, sim_a, sim_b, count):
    """Penetration depth of overlapping cores, seeded with GJK's last simplex (``count`` rows of ``sim_a``/``sim_b``).

    The polytope is a closed triangle mesh with neighbour links (see :func:`_epa_polytope`); each step removes the
    faces the new support point sees and fills the hole with a fan to the point (:func:`_epa_grow`). Every way out
    returns a defined answer (see the list above :func:`_epa_push`).

    Returns:
        ``(status, depth, normal, point_a, point_b)``: the depth [m] (``>= 0`` up to round-off; slightly negative when
        the cores only touch), the unit normal from A to B (moving B by ``depth · normal`` makes the cores touch) and
        the deepest points of each core, world frame. ``status`` is ``EPA_FLAT`` when ``A - B`` has no volume around
        the origin (``normal`` is then a normal of that flat set, see :func:`_flat_normal`, and depth is 0),
        ``EPA_CONVERGED`` or ``EPA_STOPPED`` (the best face of the last sound polytope).
    """
    size = xa[2] + xb[2]
    tol = EPA_TOLERANCE * size
    # Rows [:count] are written before they are read (the seed's copy, then one push per vertex).
    va = np.empty((EPA_MAX_VERTICES, 3))
    vb = np.empty((EPA_MAX_VERTICES, 3))
    for i in range(count):
        for c in range(3):
            va[i, c], vb[i, c] = sim_a[i, c], sim_b[i, c]
    count, hint = _epa_seed(xa, pa, qa, xb, pb, qb, vertices, va, vb, count, tol)
    if count < 4:
        return _epa_flat_answer(xa, pa, qa, xb, pb, qb, vertices, va, vb, count, hint)
    poly = _epa_polytope()
    _epa_tetrahedron(va, vb, poly)
    status, depth, face, n = _epa_expand(xa, pa, qa, xb, pb, qb, vertices, va, vb, poly, tol, 1e-12 * size)
    if status == EPA_FLAT:
        return _epa_flat_answer(xa, pa, qa, xb, pb, qb, vertices, va, vb, np.int64(1), hint)
    point_a, point_b = _epa_witnesses(va, vb, depth, face, n)
    return status, depth, n, point_a, point_b


# --- the whole query ---------------------------------------------------------------------------------------------


@inline
def _core_overlap(xa, pa, qa, xb, pb, qb, vertices, u):
    """How far core B must move along the unit ``u`` to clear core A: ``h_A(u) + h_B(-u)``, and the two supports."""
    a, b = _support_pair(xa, pa, qa, xb, pb, qb, vertices, u)
    return dot(u, sub(a, b)), a, b


@inline
def _polish_depth(xa, pa, qa, xb, pb, qb, vertices, n, ca, cb):
    """EPA's answer measured again along its normal, and the axes of round cores tried as well.

    EPA's polytope sits inside ``A - B``, so its nearest face is a lower bound on the depth; the overlap of the cores
    along the face's normal, ``h_A(n) + h_B(-n)``, is an upper bound, and the one that matters (how far B must move
    along the normal it is given). On curved shapes EPA stops at its vertex budget, and where a cylinder's cap and
    side are equally deep (coaxial round cores) it is slowest, as it must resolve a whole circle of equal depths.
    The exact answers there are the axis, or a direction square to it (EPA's normal turned square to the axis, the
    line between the centres, exact for a point core near the axis, or for two round cores the direction square to
    both axes), so these are tried for every capsule and cylinder and the least overlap wins: on deep, nearly coaxial
    cylinders and capsules the depth is then within 5e-6 m of the true one (measured against a Nelder-Mead search
    over the sphere; 1e-3 m with EPA alone). Returns ``(depth, normal, point_a, point_b)``.
    """
    depth, a, b = _core_overlap(xa, pa, qa, xb, pb, qb, vertices, n)
    best = n
    offset = sub(_centre(xb, pb, qb), _centre(xa, pa, qa))
    for k in range(8):
        x, q = (xa, qa) if k < 4 else (xb, qb)
        if x[0] != SEGMENT and x[0] != DISC_PRISM:
            continue
        axis = quat_rotate(q, (0.0, 0.0, 1.0))
        if k % 4 >= 2:
            # Across the axis: towards EPA's normal, or along the line between the centres (a core near a cylinder's
            # axis leaves through the side it is nearest, which EPA's polygon of the rim is too coarse to find).
            u = n if k % 4 == 2 else offset
            u = add_scaled(u, axis, -dot(u, axis))
            length = math.sqrt(dot(u, u))
            if length <= 1e-12 * (xa[2] + xb[2]):
                continue
            u = scale(u, 1.0 / length)
        else:
            u = axis if k % 4 == 0 else (-axis[0], -axis[1], -axis[2])
        o, a_u, b_u = _core_overlap(xa, pa, qa, xb, pb, qb, vertices, u)
        if o < depth - 1e-12 * (xa[2] + xb[2]):
            depth, best, ca, cb = o, u, a_u, b_u
    # Two round cores: square to both axes neither cap nor end counts (nearly coaxial cylinders leave sideways there).
    round_a = xa[0] == SEGMENT or xa[0] == DISC_PRISM
    round_b = xb[0] == SEGMENT or xb[0] == DISC_PRISM
    if round_a and round_b:
        across = cross(quat_rotate(qa, (0.0, 0.0, 1.0)), quat_rotate(qb, (0.0, 0.0, 1.0)))
        length = math.sqrt(dot(across, across))
        if length > 1e-12:
            across = scale(across, 1.0 / length)
            for k in range(2):
                u = across if k == 0 else (-across[0], -across[1], -across[2])
                o, a_u, b_u = _core_overlap(xa, pa, qa, xb, pb, qb, vertices, u)
                if o < depth - 1e-12 * (xa[2] + xb[2]):
                    depth, best, ca, cb = o, u, a_u, b_u
    return depth, best, ca, cb


@inline
def _flat_depth(xa, pa, qa, xb, pb, qb, vertices, n, ca, cb):
    """Depth and normal when ``A - B`` has no volume near the origin (points, segments, a point in a triangle's
    plane): the least core overlap over the flat set's normal ``n`` (either way) and the direction of GJK's last
    ``cb - ca`` (which is the true one for two nearly coincident points, and noise when the origin is inside the
    flat set). GJK's witness points stay: they sit where the cores cross."""
    depth, _, _ = _core_overlap(xa, pa, qa, xb, pb, qb, vertices, n)
    best = n
    gap = sub(cb, ca)
    length = math.sqrt(dot(gap, gap))
    tiny = 1e-12 * (xa[2] + xb[2])
    for k in range(2):
        if k == 0:
            u = (-n[0], -n[1], -n[2])
        elif length > tiny:
            u = scale(gap, 1.0 / length)
        else:
            continue
        o, _, _ = _core_overlap(xa, pa, qa, xb, pb, qb, vertices, u)
        if o < depth - tiny:
            depth, best = o, u
    return depth, best


@inline
def proxy_contact(xa, pa, qa, xb, pb, qb, vertices, max_separation):
    """Signed separation of two convex cores (:func:`core_proxy`) with their radii: GJK, then EPA on overlap.

    Args:
        max_separation: [m] report nothing when the surfaces are provably farther apart than this.

    Returns:
        ``(found, separation, normal, point_a, point_b)``: the signed distance between the surfaces [m] (negative
        when they overlap: minus the penetration depth), the unit normal from A to B and the nearest (or deepest)
        point of each surface, world frame. ``found`` is False, and the rest meaningless, past ``max_separation``.
    """
    ra, rb = xa[1], xb[1]
    sim_a = np.empty((4, 3))
    sim_b = np.empty((4, 3))
    status, count, distance, ca, cb = proxy_gjk(xa, pa, qa, xb, pb, qb, vertices, max_separation + ra + rb, sim_a,
                                          sim_b)  # fmt: skip
    zero = (0.0, 0.0, 0.0)
    if status == GJK_FAR:
        return False, distance - ra - rb, zero, ca, cb
    if status == GJK_SEPARATED:
        n = scale(sub(cb, ca), 1.0 / distance)
        separation = distance - ra - rb
    else:
        epa_status, depth, n, ea, eb = proxy_epa(xa, pa, qa, xb, pb, qb, vertices, sim_a, sim_b, count)
        if epa_status != EPA_FLAT:
            ca, cb = ea, eb
            depth, n, ca, cb = _polish_depth(xa, pa, qa, xb, pb, qb, vertices, n, ca, cb)
        else:
            depth, n = _flat_depth(xa, pa, qa, xb, pb, qb, vertices, n, ca, cb)
        separation = -depth - ra - rb
    if separation > max_separation:
        return False, separation, n, ca, cb
    return True, separation, n, add_scaled(ca, n, ra), add_scaled(cb, n, -rb)


@inline
def _flat_normal(xa, pa, qa, xb, pb, qb, vertices, va, vb, count, hint):
    """A unit normal from A to B when ``A - B`` has no volume round the origin (two points, a point on a segment, a
    sphere's centre in a triangle's plane...). The cores are then tangent along the flat set's normal, or along any
    direction across a line or a point; of those, take the one nearest the line from A's centre to B's."""
    d = sub(_centre(xb, pb, qb), _centre(xa, pa, qa))
    if dot(hint, hint) > 0.0:
        return hint if dot(hint, d) >= 0.0 else (-hint[0], -hint[1], -hint[2])
    if count >= 2:
        # A - B along a line: the part of d across it.
        u = sub(_epa_w(va, vb, 1), _epa_w(va, vb, 0))
        uu = dot(u, u)
        if uu > 0.0:
            u = scale(u, 1.0 / math.sqrt(uu))
            across = add_scaled(d, u, -dot(d, u))
            # Along the line (or no offset at all): any direction across it.
            d = across if dot(across, across) > 1e-24 * dot(d, d) and dot(across, across) > 0.0 else _perpendicular(u)
    # Scaled before it is squared: the centres may differ by a number whose square is below the smallest normal double.
    biggest = max(abs(d[0]), abs(d[1]), abs(d[2]))
    if biggest > 0.0:
        d = (d[0] / biggest, d[1] / biggest, d[2] / biggest)  # (1 / biggest may overflow)
        return scale(d, 1.0 / math.sqrt(dot(d, d)))
    return (0.0, 0.0, 1.0)


@kernel
def gjk(geom, sa, fa, pa, qa, sb, fb, pb, qb, max_distance, sim_a, sim_b):
    """:func:`proxy_gjk` for shape rows (``fa``/``fb`` a mesh face, or -1 for the whole shape)."""
    return proxy_gjk(core_proxy(geom, sa, fa), pa, qa, core_proxy(geom, sb, fb), pb, qb, geom.vertex_local,
                     max_distance, sim_a, sim_b)  # fmt: skip


@kernel
def epa(geom, sa, fa, pa, qa, sb, fb, pb, qb, sim_a, sim_b, count):
    """:func:`proxy_epa` for shape rows (``fa``/``fb`` a mesh face, or -1 for the whole shape)."""
    return proxy_epa(core_proxy(geom, sa, fa), pa, qa, core_proxy(geom, sb, fb), pb, qb, geom.vertex_local, sim_a,
                     sim_b, count)  # fmt: skip


@kernel
def convex_contact(geom, sa, fa, pa, qa, sb, fb, pb, qb, max_separation):
    """:func:`proxy_contact` for shape rows (``fa``/``fb`` a mesh face, or -1 for the whole shape)."""
    return proxy_contact(core_proxy(geom, sa, fa), pa, qa, core_proxy(geom, sb, fb), pb, qb, geom.vertex_local,
                         max_separation)  # fmt: skip


@kernel
def shape_distance(geom, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b):
    """Signed distance between two convex shapes [m] (negative: minus the penetration depth), the unit normal from
    A to B and the nearest or deepest surface points ``(distance, normal, point_a, point_b)``. The referee of the
    closed-form kernels in tests; the collide kernels use :func:`convex_contact` with their margin."""
    # A typed -1, not a literal: a literal argument would compile a second copy of everything below.
    whole = np.int64(-1)
    _, separation, n, point_a, point_b = convex_contact(geom, shape_a, whole, pos_a, quat_a, shape_b, whole, pos_b,
                                                        quat_b, math.inf)  # fmt: skip
    return separation, n, point_a, point_b
