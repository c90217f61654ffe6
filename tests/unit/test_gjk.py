"""GJK distance and EPA depth (tumble.geometry.gjk) against closed forms.

Distances between separated spheres, boxes, capsules, cylinders and hulls, their closest points, EPA depths of
overlapping pairs, a hull of a cube against the box, and the degenerate inputs: touching shapes and coincident
centres. The support functions are checked against ``Shape.support``, an independent NumPy implementation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tumble.geometry import gjk
from tumble.geometry.packing import pack_geometry
from tumble.shapes import Box, Capsule, ConvexHull, Cylinder, Sphere

IDENTITY = (1.0, 0.0, 0.0, 0.0)
CUBE_POINTS = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
OCTAHEDRON_POINTS = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)


def geometry(shape_a, shape_b):
    return pack_geometry([shape_a, shape_b], [0, 1], np.zeros((2, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (2, 1)))


def quat(axis, degrees):
    """Scalar-first unit quaternion of a rotation about ``axis``."""
    x, y, z, w = Rotation.from_rotvec(np.radians(degrees) * np.asarray(axis, float) / np.linalg.norm(axis)).as_quat()
    return (float(w), float(x), float(y), float(z))


def distance(shape_a, pos_a, shape_b, pos_b, quat_a=IDENTITY, quat_b=IDENTITY):
    """``(separation, normal, point_a, point_b)`` as NumPy arrays."""
    g = geometry(shape_a, shape_b)
    sep, n, pa, pb = gjk.shape_distance(g, 0, tuple(map(float, pos_a)), quat_a, 1, tuple(map(float, pos_b)), quat_b)
    return sep, np.array(n), np.array(pa), np.array(pb)


# --- support functions -------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "shape",
    [Sphere(0.4), Capsule(0.3, 1.2), Box((1.0, 2.0, 0.6)), Cylinder(0.5, 1.4), ConvexHull(OCTAHEDRON_POINTS * 0.7)],
    ids=["sphere", "capsule", "box", "cylinder", "hull"],
)
def test_support_plus_radius_matches_shape_support(shape):
    """Core support plus radius along d reaches as far along d as Shape.support (NumPy) does."""
    g = geometry(shape, shape)
    rng = np.random.default_rng(0)
    radius = gjk.core_radius(g, 0, -1)
    for d in rng.normal(size=(50, 3)):
        core = np.array(gjk.support_local(g, 0, -1, tuple(d)))
        reach = core @ d + radius * np.linalg.norm(d)
        assert reach == pytest.approx(shape.support(d) @ d, abs=1e-12)  # measured 4e-16


def test_support_world_applies_the_pose():
    g = geometry(Box((1.0, 2.0, 3.0)), Sphere(1.0))
    q = quat((0, 0, 1), 90)
    # The box's +x half extent 0.5 now points along +y; its y extent 1.0 along -x.
    p = gjk.support_world(g, 0, -1, (1.0, 2.0, 3.0), q, (0.0, 1.0, 0.0))
    assert p[1] == pytest.approx(2.5, abs=1e-12)  # measured 0


# --- separated pairs -------------------------------------------------------------------------------------------


def test_spheres_distance_normal_and_closest_points():
    d = np.array([1.0, 2.0, 2.0]) / 3.0
    sep, n, pa, pb = distance(Sphere(0.5), (0, 0, 0), Sphere(0.3), 2.0 * d)
    assert sep == pytest.approx(1.2, abs=1e-12)  # measured 0
    np.testing.assert_allclose(n, d, atol=1e-12)  # measured 0
    np.testing.assert_allclose(pa, 0.5 * d, atol=1e-12)  # measured 0
    np.testing.assert_allclose(pb, 1.7 * d, atol=1e-12)  # measured 0


def test_boxes_face_to_face():
    sep, n, pa, pb = distance(Box((1, 1, 1)), (0, 0, 0), Box((2, 1, 0.5)), (0.1, 0.2, 1.5))
    assert sep == pytest.approx(0.75, abs=1e-12)  # measured 0
    np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)  # measured 3e-16
    assert pa[2] == pytest.approx(0.5) and pb[2] == pytest.approx(1.25)


def test_boxes_corner_to_corner():
    sep, n, pa, pb = distance(Box((1, 1, 1)), (0, 0, 0), Box((1, 1, 1)), (2, 2, 2))
    assert sep == pytest.approx(math.sqrt(3.0), abs=1e-12)  # measured 0
    np.testing.assert_allclose(pa, [0.5, 0.5, 0.5], atol=1e-12)  # measured 0
    np.testing.assert_allclose(pb, [1.5, 1.5, 1.5], atol=1e-12)  # measured 0


def test_boxes_edge_to_edge():
    """A's top edge along x at height √2/2, B's bottom edge along y at z - √2/2: they cross over the origin."""
    sep, n, pa, pb = distance(Box((1, 1, 1)), (0, 0, 0), Box((1, 1, 1)), (0, 0, 2.0), quat((1, 0, 0), 45),
                              quat((0, 1, 0), 45))  # fmt: skip
    assert sep == pytest.approx(2.0 - math.sqrt(2.0), abs=1e-12)  # measured 2e-16
    np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)  # measured 5e-17
    np.testing.assert_allclose(pa, [0, 0, math.sqrt(0.5)], atol=1e-12)  # measured 1e-16


def test_capsules_parallel_and_crossed():
    sep, n, _, _ = distance(Capsule(0.2, 1.0), (0, 0, 0), Capsule(0.2, 1.0), (1, 0, 0.3))
    assert sep == pytest.approx(0.6, abs=1e-12)  # measured 1e-16
    np.testing.assert_allclose(n, [1, 0, 0], atol=1e-12)  # measured 6e-17
    # B lies along x at y = 1, z = 0.3: the nearest points are (0, 0, 0.3) on A's axis and (0, 1, 0.3) on B's.
    sep, n, pa, pb = distance(
        Capsule(0.2, 1.0), (0, 0, 0), Capsule(0.2, 1.0), (0, 1, 0.3), IDENTITY, quat((0, 1, 0), 90)
    )
    assert sep == pytest.approx(0.6, abs=1e-12)  # measured 1e-16
    np.testing.assert_allclose(pa, [0, 0.2, 0.3], atol=1e-12)  # measured 6e-17
    np.testing.assert_allclose(pb, [0, 0.8, 0.3], atol=1e-12)  # measured 0


def test_cylinders_side_by_side_stacked_and_rim():
    cyl = Cylinder(0.5, 1.0)
    sep, n, _, _ = distance(cyl, (0, 0, 0), cyl, (1.5, 0, 0.2))
    assert sep == pytest.approx(0.5, abs=1e-12)  # measured 0 (the side faces it: exact support)
    np.testing.assert_allclose(n, [1, 0, 0], atol=1e-12)  # measured 0
    sep, n, _, _ = distance(cyl, (0, 0, 0), cyl, (0.3, 0.1, 1.2))
    assert sep == pytest.approx(0.2, abs=1e-12)  # measured 6e-17
    np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)  # measured 1e-16
    # A sphere above the rim: the nearest rim point is (0.5, 0, 0.5), 0.5√2 from its centre.
    sep, n, pa, _ = distance(cyl, (0, 0, 0), Sphere(0.2), (1, 0, 1))
    assert sep == pytest.approx(math.sqrt(0.5) - 0.2, abs=1e-12)  # measured 0
    np.testing.assert_allclose(pa, [0.5, 0, 0.5], atol=1e-12)  # measured 0


def test_tilted_cylinder_rim_to_sphere():
    """The same rim problem in a turned and moved frame: the answer follows the frame."""
    q = quat((1, 2, 0), 30)
    rot = Rotation.from_quat([q[1], q[2], q[3], q[0]])
    origin = np.array([0.3, -0.2, 1.0])
    sep, _, pa, _ = distance(Cylinder(0.5, 1.0), origin, Sphere(0.2), origin + rot.apply([1, 0, 1]), q)
    assert sep == pytest.approx(math.sqrt(0.5) - 0.2, abs=1e-12)  # measured 0
    np.testing.assert_allclose(pa, origin + rot.apply([0.5, 0, 0.5]), atol=1e-12)  # measured 0


def test_sphere_over_an_octahedron_face():
    """|x|+|y|+|z| <= 1: the face x+y+z = 1 is 5/√3 from (2, 2, 2); the foot (1/3, 1/3, 1/3) is inside it."""
    sep, n, pa, pb = distance(ConvexHull(OCTAHEDRON_POINTS), (0, 0, 0), Sphere(0.1), (2, 2, 2))
    assert sep == pytest.approx(5.0 / math.sqrt(3.0) - 0.1, abs=1e-12)  # measured 0
    np.testing.assert_allclose(n, np.ones(3) / math.sqrt(3.0), atol=1e-12)  # measured 2e-16
    np.testing.assert_allclose(pa, np.ones(3) / 3.0, atol=1e-12)  # measured 1e-16


def test_hull_against_hull_vertex_to_vertex():
    sep, _, pa, pb = distance(ConvexHull(OCTAHEDRON_POINTS), (0, 0, 0), ConvexHull(OCTAHEDRON_POINTS), (3, 0, 0))
    assert sep == pytest.approx(1.0, abs=1e-12)  # measured 0
    np.testing.assert_allclose(pa, [1, 0, 0], atol=1e-12)  # measured 0
    np.testing.assert_allclose(pb, [2, 0, 0], atol=1e-12)  # measured 0


# --- overlapping pairs: EPA --------------------------------------------------------------------------------------


def test_epa_boxes_least_overlap_axis():
    sep, n, pa, pb = distance(Box((1, 1, 1)), (0, 0, 0), Box((1, 1, 1)), (0.3, 0.2, 0.0))
    assert sep == pytest.approx(-0.7, abs=1e-12)  # measured 0
    np.testing.assert_allclose(n, [1, 0, 0], atol=1e-12)  # measured 0
    # Moving B by the depth along the normal makes the surfaces touch.
    assert (pa - pb) @ n == pytest.approx(0.7, abs=1e-12)  # measured 0


def test_epa_spheres():
    sep, n, pa, pb = distance(Sphere(0.5), (0, 0, 0), Sphere(0.5), (0, 0.5, 0))
    assert sep == pytest.approx(-0.5, abs=1e-12)  # measured 0 (the cores are apart: no EPA needed)
    np.testing.assert_allclose(n, [0, 1, 0], atol=1e-12)  # measured 0


def test_epa_box_and_sphere_centre_inside():
    """The sphere's centre is 0.2 inside the box's +x face: depth 0.2 + r along +x."""
    sep, n, _, _ = distance(Box((1, 1, 1)), (0, 0, 0), Sphere(0.2), (0.3, 0.1, -0.05))
    assert sep == pytest.approx(-0.4, abs=1e-12)  # measured 0
    np.testing.assert_allclose(n, [1, 0, 0], atol=1e-12)  # measured 0


def test_epa_rotated_boxes_against_sat_reference():
    """Depth of two overlapping turned boxes against the 15-axis separating-axis reference in NumPy."""
    qa, qb = quat((1, 1, 0), 20), quat((0, 1, 1), 35)
    pa, pb = np.array([0.1, 0, 0]), np.array([0.5, 0.6, 0.3])
    sep, n, _, _ = distance(Box((1, 1, 1)), pa, Box((1.2, 0.8, 1.0)), pb, qa, qb)
    depth, axis = sat_box_box(np.array([0.5] * 3), pa, qa, np.array([0.6, 0.4, 0.5]), pb, qb)
    assert sep == pytest.approx(-depth, abs=1e-12)  # measured 1e-16
    np.testing.assert_allclose(n, axis, atol=1e-12)  # measured 1e-16


def sat_box_box(ha, pa, qa, hb, pb, qb):
    """Least overlap of two boxes over the 15 separating axes, and its axis from A to B (NumPy reference)."""
    ra = Rotation.from_quat([qa[1], qa[2], qa[3], qa[0]]).as_matrix()
    rb = Rotation.from_quat([qb[1], qb[2], qb[3], qb[0]]).as_matrix()
    axes = [ra[:, i] for i in range(3)] + [rb[:, i] for i in range(3)]
    axes += [np.cross(ra[:, i], rb[:, j]) for i in range(3) for j in range(3)]
    best, best_axis = np.inf, None
    for axis in axes:
        if np.linalg.norm(axis) < 1e-9:
            continue
        axis = axis / np.linalg.norm(axis)
        if axis @ (pb - pa) < 0:
            axis = -axis
        overlap = np.abs(ra.T @ axis) @ ha + np.abs(rb.T @ axis) @ hb - axis @ (pb - pa)
        if overlap < best:
            best, best_axis = overlap, axis
    return best, best_axis


# --- a hull of a cube is the box ---------------------------------------------------------------------------------


def test_hull_of_a_cube_behaves_like_the_box():
    rng = np.random.default_rng(3)
    box_geom = geometry(Box((1, 1, 1)), Box((1, 1, 1)))
    hull_geom = geometry(ConvexHull(CUBE_POINTS), ConvexHull(CUBE_POINTS))
    for _ in range(40):
        qa = tuple(Rotation.random(random_state=rng).as_quat()[[3, 0, 1, 2]])
        qb = tuple(Rotation.random(random_state=rng).as_quat()[[3, 0, 1, 2]])
        pb = tuple(rng.uniform(-1.5, 1.5, 3))
        box = gjk.shape_distance(box_geom, 0, (0.0, 0.0, 0.0), qa, 1, pb, qb)
        hull = gjk.shape_distance(hull_geom, 0, (0.0, 0.0, 0.0), qa, 1, pb, qb)
        assert hull[0] == pytest.approx(box[0], abs=1e-12)  # measured 2e-16
        np.testing.assert_allclose(hull[1], box[1], atol=1e-12)  # measured 4e-16


# --- degenerate inputs ---------------------------------------------------------------------------------------------


def test_touching_boxes_have_zero_separation_and_the_face_normal():
    sep, n, _, _ = distance(Box((1, 1, 1)), (0, 0, 0), Box((1, 1, 1)), (0.2, 0.3, 1.0))
    assert abs(sep) < 1e-12  # measured 0
    np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)  # measured 0


def test_sphere_touching_a_box_corner():
    d = np.ones(3) / math.sqrt(3.0)
    sep, n, pa, _ = distance(Box((1, 1, 1)), (0, 0, 0), Sphere(0.25), np.full(3, 0.5) + 0.25 * d)
    assert abs(sep) < 1e-12  # measured 6e-17
    np.testing.assert_allclose(n, d, atol=1e-12)  # measured 1e-16
    np.testing.assert_allclose(pa, [0.5, 0.5, 0.5], atol=1e-12)  # measured 0


def test_coincident_spheres():
    sep, n, _, _ = distance(Sphere(0.5), (1, 2, 3), Sphere(0.25), (1, 2, 3))
    assert sep == pytest.approx(-0.75)
    assert np.linalg.norm(n) == pytest.approx(1.0)


def test_coincident_capsules_separate_across_their_axis():
    sep, n, _, _ = distance(Capsule(0.5, 1.0), (0, 0, 0), Capsule(0.5, 1.0), (0, 0, 0))
    assert sep == pytest.approx(-1.0)
    assert abs(n[2]) < 1e-12 and np.linalg.norm(n) == pytest.approx(1.0)


def test_sphere_centre_on_a_capsule_axis():
    sep, n, _, _ = distance(Sphere(0.1), (0, 0, 0.3), Capsule(0.5, 1.0), (0, 0, 0))
    assert sep == pytest.approx(-0.6)
    assert abs(n[2]) < 1e-12


def test_coincident_boxes():
    sep, n, _, _ = distance(Box((1, 1, 1)), (0, 0, 0), Box((1, 1, 1)), (0, 0, 0))
    assert sep == pytest.approx(-1.0, abs=1e-12)  # measured 0
    assert sorted(np.abs(n)) == pytest.approx([0, 0, 1], abs=1e-12)  # measured 0


def test_coincident_hull_and_cylinder():
    """The cylinder (r 0.3, h 1) inside the unit octahedron: the least push is sideways across an octahedron edge
    (half-width √2/2 plus the radius); whichever direction comes out, the depth is the support sweep along it."""
    g = geometry(ConvexHull(OCTAHEDRON_POINTS), Cylinder(0.3, 1.0))
    sep, n, _, _ = gjk.shape_distance(g, 0, (0.0, 0.0, 0.0), IDENTITY, 1, (0.0, 0.0, 0.0), IDENTITY)
    n = np.array(n)
    sweep = np.max(OCTAHEDRON_POINTS @ n) + Cylinder(0.3, 1.0).support(-n) @ -n
    assert -sep == pytest.approx(sweep, abs=1e-9)  # measured 0


# --- GJK on its own --------------------------------------------------------------------------------------------------


def test_gjk_stops_early_past_max_distance():
    g = geometry(Box((1, 1, 1)), Box((1, 1, 1)))
    sim_a, sim_b = np.zeros((4, 3)), np.zeros((4, 3))
    status, _, lower, _, _ = gjk.gjk(g, 0, -1, (0.0, 0.0, 0.0), IDENTITY, 1, -1, (0.0, 0.0, 5.0), IDENTITY, 1.0, sim_a,
                                     sim_b)  # fmt: skip
    assert status == gjk.GJK_FAR
    assert 1.0 < lower <= 4.0 + 1e-12
    found, *_ = gjk.convex_contact(g, 0, -1, (0.0, 0.0, 0.0), IDENTITY, 1, -1, (0.0, 0.0, 5.0), IDENTITY, 1.0)
    assert not found


def test_gjk_reports_overlap_with_a_simplex_round_the_origin():
    g = geometry(Box((1, 1, 1)), Box((1, 1, 1)))
    sim_a, sim_b = np.zeros((4, 3)), np.zeros((4, 3))
    status, count, _, _, _ = gjk.gjk(g, 0, -1, (0.0, 0.0, 0.0), IDENTITY, 1, -1, (0.2, 0.1, 0.3), IDENTITY, np.inf,
                                     sim_a, sim_b)  # fmt: skip
    assert status == gjk.GJK_OVERLAPPING
    status, depth, n, _, _ = gjk.epa(g, 0, -1, (0.0, 0.0, 0.0), IDENTITY, 1, -1, (0.2, 0.1, 0.3), IDENTITY, sim_a,
                                     sim_b, count)  # fmt: skip
    assert status == gjk.EPA_CONVERGED and depth == pytest.approx(0.7, abs=1e-12)  # measured 0
    np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)  # measured 0


def test_nearly_coincident_spheres_keep_their_tiny_offset():
    """Centres 1e-7 apart: GJK hands over to EPA, which finds no volume (two points); the offset still counts."""
    sep, n, _, _ = distance(Sphere(0.5), (0, 0, 0), Sphere(0.5), (0, 0, 1e-7))
    assert sep == pytest.approx(-1.0 + 1e-7, abs=1e-15)  # measured 1e-16
    np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)  # measured 0


def test_crossing_capsules_separate_across_their_plane():
    """Segments along z and y crossing 1e-10 apart along z: A - B is flat, and GJK's last, unconverged direction
    (in that plane) must not be taken for the normal."""
    sep, n, _, _ = distance(Capsule(0.5, 0.5), (0, 0, 0), Capsule(0.5, 0.5), (0, 0, 1e-10), IDENTITY,
                            quat((1, 0, 0), 90))  # fmt: skip
    assert sep == pytest.approx(-1.0, abs=1e-12)  # measured 0
    assert abs(n[0]) == pytest.approx(1.0, abs=1e-12)  # measured 0


def test_nearly_coaxial_cylinders_depth_is_frame_independent():
    """Coincident cylinders, one flipped and tilted 3.6°: a whole circle of nearly equal depths, EPA's hardest case
    (it needs about 100 vertices). The depth must not depend on the frame, and the normal must realise it."""
    c = Cylinder(0.25, 0.5)
    q = (0.0, 0.9995120760870788, 0.0, 0.03123475237772121)
    turn = quat((1, 2, 3), 70)
    rot = Rotation.from_quat([turn[1], turn[2], turn[3], turn[0]])
    turned = (rot * Rotation.from_quat([q[1], q[2], q[3], q[0]])).as_quat()
    sep, n, _, _ = distance(c, (0, 0, 0), c, (0, 0, 0), IDENTITY, q)
    sep2, n2, _, _ = distance(c, (0, 0, 0), c, (0, 0, 0), turn, (turned[3], turned[0], turned[1], turned[2]))
    assert sep2 == pytest.approx(sep, abs=1e-9)  # measured 2e-14
    # The overlap along the normal: the supports of both cylinders (NumPy, Shape.support) across it.
    qb = Rotation.from_quat([q[1], q[2], q[3], q[0]])
    along = c.support(n) @ n + qb.apply(c.support(qb.inv().apply(-n))) @ -n
    assert along == pytest.approx(-sep, abs=1e-9)  # measured 0


# --- degenerate polytopes: EPA is total ----------------------------------------------------------------------------


def _face_corners_simplex(g, rot, pa, qa, pb, order):
    """Support pairs of the +z face's four corners of shape 0 (a cube hull) against a point core at ``pb``."""
    corners = [(1, 1), (1, -1), (-1, -1), (-1, 1)]
    sim_a = np.array([gjk.support_world(g, 0, -1, pa, qa, tuple(rot.apply([*corners[i], 1e-3]))) for i in order])
    return sim_a, np.tile(pb, (4, 1))


def test_epa_origin_on_a_hull_face_with_its_corners_as_the_simplex():
    """A sphere's centre exactly on a turned cube's face (touching, zero depth), and GJK's simplex the face's four
    corners: coplanar to round-off, so the tetrahedron is flat and its faces wind at random. EPA must still answer
    depth 0 along the face's normal. (Before the seed measured flatness as a height, 4 % of these poses left no
    face alive, and EPA then read a face row it had never written: a crash, an IndexError with
    NUMBA_BOUNDSCHECK=1, or garbage.)"""
    g = geometry(ConvexHull(CUBE_POINTS), Sphere(0.1))
    xa, xb = gjk.core_proxy(g, 0, -1), gjk.core_proxy(g, 1, -1)
    rng = np.random.default_rng(7)
    for _ in range(100):
        rot = Rotation.random(random_state=rng)
        x, y, z, w = rot.as_quat()
        qa = (float(w), float(x), float(y), float(z))
        pa = tuple(float(c) for c in rng.uniform(-1, 1, 3))
        pb = tuple(float(c) for c in np.add(pa, rot.apply([*rng.uniform(-0.5, 0.5, 2), 0.5])))
        sim_a, sim_b = _face_corners_simplex(g, rot, pa, qa, pb, rng.permutation(4))
        status, depth, n, _, point_b = gjk.proxy_epa(xa, pa, qa, xb, pb, IDENTITY, g.vertex_local, sim_a, sim_b,
                                                     np.int64(4))  # fmt: skip
        assert status == gjk.EPA_CONVERGED
        assert abs(depth) <= 1e-12  # measured 4e-16
        np.testing.assert_allclose(n, rot.apply([0, 0, 1]), atol=1e-12)  # measured 8e-16
        np.testing.assert_allclose(point_b, pb, atol=1e-12)


def test_epa_with_non_finite_seed_gives_a_defined_answer():
    """A simplex of NaN support points (a body that has blown up): no face has a finite distance, and EPA falls back
    to the flat answer (depth 0, the line between the centres) instead of growing a polytope of NaNs."""
    g = geometry(Box((1, 1, 1)), Cylinder(0.3, 0.5))
    xa, xb = gjk.core_proxy(g, 0, -1), gjk.core_proxy(g, 1, -1)
    sim_a, sim_b = np.full((4, 3), np.nan), np.zeros((4, 3))
    status, depth, n, _, _ = gjk.proxy_epa(xa, (0.0, 0.0, 0.0), IDENTITY, xb, (0.0, 0.0, 0.5), IDENTITY,
                                           g.vertex_local, sim_a, sim_b, np.int64(4))  # fmt: skip
    assert status == gjk.EPA_FLAT and depth == 0.0
    np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)


def test_epa_step_that_sees_every_face_is_refused():
    """A polytope whose faces all see the new point (here: faces with no area, which every point sees) leaves no
    rim to fan: the step is refused (-1) instead of leaving no face alive."""
    va = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.3, 0.3, 0.3]]) - 0.2
    vb = np.zeros_like(va)
    poly = gjk._epa_polytope()
    gjk._epa_tetrahedron(va, vb, poly)
    assert gjk._epa_nearest(poly[4], poly[5], 4) >= 0
    poly[3][:4] = 0.0  # every face's normal gone: each one sees any point
    assert gjk._epa_grow(va, vb, poly, 0, 4, 4, 0.0, 1e-9, 1e-12) == -1
