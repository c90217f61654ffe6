"""Invariants of GJK/EPA and the convex contact kernels on random shapes and poses (hypothesis).

The referee is the support function written again here in NumPy, for many directions at once. For a unit ``u``
pointing from A to B, the overlap of the two shapes along ``u`` is ``o(u) = h_A(u) + h_B(-u)``, with
``h_X(u) = max_{x in X} u · x`` the support value: the shapes are apart along ``u`` by ``-o(u)`` when it is
negative, and B must move ``o(u)`` along ``u`` to clear A when it is positive. So for overlapping shapes the
penetration depth is ``min_u o(u)`` (the least translation that separates them), which no sampled direction can
undercut, and the normal a kernel returns must realise it: ``o(normal) == depth``. For separated hulls the distance
is also the minimum over vertex-face and edge-edge pairs, computed by brute force.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.spatial
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from strategies import unit_quaternions, vectors3
from tumble.geometry import gjk
from tumble.geometry.collide_convex import collide_convex_convex
from tumble.geometry.packing import pack_geometry
from tumble.shapes import Box, Capsule, ConvexHull, Cylinder, Sphere

sizes = st.floats(0.1, 0.8, allow_nan=False)
hull_points = st.lists(st.tuples(sizes, sizes, sizes), min_size=5, max_size=9).map(lambda p: np.array(p) - 0.45)


@st.composite
def convex_shapes(draw, kinds=("sphere", "capsule", "box", "cylinder", "hull")):
    kind = draw(st.sampled_from(kinds))
    if kind == "sphere":
        return Sphere(draw(sizes))
    if kind == "capsule":
        return Capsule(draw(sizes), draw(sizes))
    if kind == "box":
        return Box((draw(sizes), draw(sizes), draw(sizes)))
    if kind == "cylinder":
        return Cylinder(draw(sizes), draw(sizes))
    points = draw(hull_points)
    try:
        scipy.spatial.ConvexHull(points)
    except scipy.spatial.QhullError:
        assume(False)
    assume(np.ptp(points, axis=0).min() > 0.05)
    return ConvexHull(points)


def rotation(q):
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def support_values(shape, pos, quat, u):
    """``h(u)`` for rows ``u`` (k, 3) of world directions: the shape's support values, written again in NumPy."""
    local = u @ rotation(quat)  # R^T u for each row
    p = shape.params
    if isinstance(shape, Sphere):
        h = p[0] * np.linalg.norm(local, axis=1)
    elif isinstance(shape, Capsule):
        h = p[1] * np.abs(local[:, 2]) + p[0] * np.linalg.norm(local, axis=1)
    elif isinstance(shape, Box):
        h = np.abs(local) @ p[:3]
    elif isinstance(shape, Cylinder):
        h = p[0] * np.hypot(local[:, 0], local[:, 1]) + p[1] * np.abs(local[:, 2])
    else:
        h = (local @ shape.vertices.T).max(axis=1)
    return h + u @ np.asarray(pos)


def overlap(a, pa, qa, b, pb, qb, u):
    """``o(u) = h_A(u) + h_B(-u)`` for rows of unit directions from A to B."""
    return support_values(a, pa, qa, u) + support_values(b, pb, qb, -u)


def sphere_directions(count=4000):
    """Nearly uniform unit vectors (a Fibonacci spiral)."""
    k = np.arange(count) + 0.5
    z = 1.0 - 2.0 * k / count
    phi = math.pi * (1.0 + math.sqrt(5.0)) * k
    r = np.sqrt(1.0 - z * z)
    return np.c_[r * np.cos(phi), r * np.sin(phi), z]


DIRECTIONS = sphere_directions()


def distance(a, pa, qa, b, pb, qb):
    geom = pack_geometry([a, b], [0, 1], np.zeros((2, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (2, 1)))
    sep, n, point_a, point_b = gjk.shape_distance(geom, 0, tuple(pa), tuple(qa), 1, tuple(pb), tuple(qb))
    return sep, np.array(n), np.array(point_a), np.array(point_b)


def manifold(a, pa, qa, b, pb, qb, margin=0.05, swap=False):
    """The manifold of A against B; ``swap`` asks for B against A with the same packing (A stays shape row 0)."""
    geom = pack_geometry([a, b], [0, 1], np.zeros((2, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (2, 1)))
    normal, point, separation, feature = np.zeros(3), np.zeros((4, 3)), np.zeros(4), np.zeros(4, np.int64)
    first, second = ((0, pa, qa), (1, pb, qb)) if not swap else ((1, pb, qb), (0, pa, qa))
    count = collide_convex_convex(geom, first[0], tuple(first[1]), tuple(first[2]), second[0], tuple(second[1]),
                                  tuple(second[2]), margin, normal, point, separation, feature)  # fmt: skip
    return count, normal, point[:count], separation[:count]


poses = st.tuples(vectors3(0.8), unit_quaternions())


# --- hulls: GJK against a vertex-based reference --------------------------------------------------------------------


def hull_distance_reference(a, pa, qa, b, pb, qb):
    """Distance between two separated hulls: the least over vertex-triangle pairs (both ways) and edge-edge pairs."""
    va = a.vertices @ rotation(qa).T + pa
    vb = b.vertices @ rotation(qb).T + pb
    best = math.inf
    for points, other, faces in ((va, vb, b.faces), (vb, va, a.faces)):
        for face in faces:
            best = min(best, _points_to_triangle(points, *other[face]).min())
    edges_a = {tuple(sorted((f[i], f[(i + 1) % 3]))) for f in a.faces for i in range(3)}
    edges_b = {tuple(sorted((f[i], f[(i + 1) % 3]))) for f in b.faces for i in range(3)}
    for i, j in edges_a:
        for k, m in edges_b:
            best = min(best, _segment_distance(va[i], va[j], vb[k], vb[m]))
    return best


def _points_to_triangle(p, a, b, c):
    """Distances from rows of p to triangle abc: to the plane if the foot is inside, else to the nearest edge."""
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    height = (p - a) @ n
    foot = p - np.outer(height, n)
    inside = np.ones(len(p), bool)
    for v0, v1 in ((a, b), (b, c), (c, a)):
        inside &= np.cross(v1 - v0, foot - v0) @ n >= 0.0
    d = np.where(inside, np.abs(height), np.inf)
    for v0, v1 in ((a, b), (b, c), (c, a)):
        t = np.clip((p - v0) @ (v1 - v0) / ((v1 - v0) @ (v1 - v0)), 0.0, 1.0)
        d = np.minimum(d, np.linalg.norm(p - (v0 + np.outer(t, v1 - v0)), axis=1))
    return d


def _segment_distance(p0, p1, q0, q1):
    """Distance between two segments by a fine scan of one and the closed-form nearest point on the other."""
    s = np.linspace(0.0, 1.0, 201)[:, None]
    p = p0 + s * (p1 - p0)
    t = np.clip((p - q0) @ (q1 - q0) / ((q1 - q0) @ (q1 - q0)), 0.0, 1.0)
    return float(np.min(np.linalg.norm(p - (q0 + np.outer(t, q1 - q0)), axis=1)))


@settings(deadline=None)
@given(convex_shapes(("hull",)), convex_shapes(("hull",)), poses, poses)
def test_gjk_distance_between_hulls_is_symmetric_and_matches_the_vertex_reference(a, b, pose_a, pose_b):
    (pa, qa), (pb, qb) = pose_a, pose_b
    pb = pb + np.array([1.6, 0.0, 0.0])
    sep_ab, n_ab, point_a, point_b = distance(a, pa, qa, b, pb, qb)
    sep_ba, n_ba, _, _ = distance(b, pb, qb, a, pa, qa)
    assert sep_ab == np.float64(sep_ab) and abs(sep_ab - sep_ba) < 1e-9  # measured 0 (600 examples)
    assume(sep_ab > 1e-3)
    # Separated: the distance, its normal (unique) and its closest points.
    np.testing.assert_allclose(n_ab, -n_ba, atol=1e-6)  # measured 0
    reference = hull_distance_reference(a, pa, qa, b, pb, qb)
    # The edge-edge reference scans one edge in 200 steps: it overshoots by at most (step)^2 / (2 distance).
    assert reference - 1e-4 <= sep_ab <= reference + 1e-9  # measured 1.4e-6 below (the scan), 4e-16 above
    assert np.linalg.norm(point_b - point_a) == np.float64(np.linalg.norm(point_b - point_a))
    assert abs(np.linalg.norm(point_b - point_a) - sep_ab) < 1e-9  # measured 4e-16


# --- any pair: depth against the support sweep ------------------------------------------------------------------------


@settings(deadline=None)
@given(convex_shapes(), convex_shapes(), poses, poses)
def test_depth_never_exceeds_the_support_sweep_and_the_normal_realises_it(a, b, pose_a, pose_b):
    (pa, qa), (pb, qb) = pose_a, pose_b
    pb = 0.5 * pb  # mostly overlapping
    sep, n, _, _ = distance(a, pa, qa, b, pb, qb)
    assume(sep < -1e-3)
    depth = -sep
    sweep = overlap(a, pa, qa, b, pb, qb, DIRECTIONS).min()
    # No direction separates with less than the depth (the kernel's depth is an overlap along its normal, so it can
    # only overstate: by up to 5e-6 on deep, nearly coaxial round cores)...
    assert depth <= sweep + 1e-5  # measured: never above (1.2e-6 to spare, 600 examples)
    # ... and the returned normal does, up to how finely EPA resolves curved shapes.
    along_normal = overlap(a, pa, qa, b, pb, qb, n[None, :])[0]
    assert along_normal == np.float64(along_normal) and abs(along_normal - depth) < 1e-6  # measured 7e-11
    # The contact kernel's points are no deeper along its normal than the shapes overlap along it, and that overlap
    # is within the separating-axis bias of the least one: a kept axis loses by under 5 % of its own overlap plus
    # 1e-3 of the size (here under 1.6 m), so it overlaps by at most (depth + 1.6e-3) / 0.95.
    count, normal, _, separations = manifold(a, pa, qa, b, pb, qb)
    assert count >= 1
    along = overlap(a, pa, qa, b, pb, qb, normal[None, :])[0]
    assert -separations.min() <= along + 1e-9  # measured: never above by more than 8e-16
    assert along <= (depth + 1.6e-3) / 0.95 + 1e-9  # measured: never above (1.8e-3 to spare)


# --- invariance under a common rigid transform, and under swapping --------------------------------------------------


@settings(deadline=None)
@given(convex_shapes(), convex_shapes(), poses, poses, vectors3(3.0), unit_quaternions())
def test_a_common_rigid_transform_leaves_the_result_invariant(a, b, pose_a, pose_b, shift, turn):
    (pa, qa), (pb, qb) = pose_a, pose_b
    rot = rotation(turn)

    def moved(p, q):
        w1, v1 = turn[0], turn[1:]
        w2, v2 = q[0], q[1:]
        quat = np.r_[w1 * w2 - v1 @ v2, w1 * v2 + w2 * v1 + np.cross(v1, v2)]
        return rot @ p + shift, quat / np.linalg.norm(quat)

    sep, n, point_a, _ = distance(a, pa, qa, b, pb, qb)
    pa2, qa2 = moved(pa, qa)
    pb2, qb2 = moved(pb, qb)
    sep2, n2, point_a2, _ = distance(a, pa2, qa2, b, pb2, qb2)
    # Deep, nearly coaxial round cores: a near-tie of directions, resolved to about 5e-6 (see gjk._polish_depth).
    assert abs(sep2 - sep) < 1e-5  # measured 4e-10 (600 examples)
    if sep > 1e-3:
        # Apart: the normal is unique and moves with the frame. GJK stops when its bounds on the distance agree to
        # 1e-10 of the size; on a curved rim that leaves the normal good to about sqrt(2e-10 size / distance).
        np.testing.assert_allclose(n2, rot @ n, atol=3e-5)  # measured 1e-5
    else:
        # Touching or overlapping: ties can pick another direction of least depth; whichever it is, it must be one.
        along = overlap(a, pa2, qa2, b, pb2, qb2, n2[None, :])[0]
        assert abs(along + sep2) < 1e-6  # measured 1.2e-10


@settings(deadline=None)
@given(convex_shapes(), convex_shapes(), poses, poses)
def test_swapping_a_and_b_flips_the_normal(a, b, pose_a, pose_b):
    (pa, qa), (pb, qb) = pose_a, pose_b
    sep_ab, n_ab, _, _ = distance(a, pa, qa, b, pb, qb)
    sep_ba, n_ba, _, _ = distance(b, pb, qb, a, pa, qa)
    assert abs(sep_ab - sep_ba) < 1e-5  # measured 4e-10 (near-ties of round cores, as above)
    if sep_ab > 1e-3:
        np.testing.assert_allclose(n_ba, -n_ab, atol=3e-5)  # measured 0 (curved rims, as above)
    else:
        # B's normal towards A, turned round, must separate A from B by the same least depth.
        along = overlap(a, pa, qa, b, pb, qb, -n_ba[None, :])[0]
        assert abs(along + sep_ab) < 1e-6  # measured 4e-10


@settings(deadline=None)
@given(convex_shapes(("box", "hull")), convex_shapes(("box", "hull")), poses, poses)
def test_swapping_polyhedra_flips_the_manifold(a, b, pose_a, pose_b):
    """Two polyhedra: the same axis wins either way (between faces, ties go to the lower shape row), so the same
    points come back."""
    (pa, qa), (pb, qb) = pose_a, pose_b
    count_ab, n_ab, points_ab, sep_ab = manifold(a, pa, qa, b, pb, qb)
    count_ba, n_ba, points_ba, sep_ba = manifold(a, pa, qa, b, pb, qb, swap=True)
    assert count_ab == count_ba
    if count_ab == 0:
        return
    if np.allclose(n_ab, -n_ba, rtol=0.0, atol=1e-12):  # measured 0
        np.testing.assert_allclose(np.sort(sep_ab), np.sort(sep_ba), atol=1e-12)  # measured 1e-16
    else:
        # An exact tie (A - B symmetric, as for a shape meeting a copy of itself): both axes overlap alike.
        along_ab = overlap(a, pa, qa, b, pb, qb, n_ab[None, :])[0]
        along_ba = overlap(a, pa, qa, b, pb, qb, -n_ba[None, :])[0]
        assert abs(along_ab - along_ba) < 1e-12  # measured 0
