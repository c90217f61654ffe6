"""Contact manifolds of tumble.geometry.collide_convex: convex pairs without a closed form, convex shapes on meshes.

Resting contacts are checked against their closed forms (where the points are, how deep, along which normal),
the box built on the fly against an independent separating-axis reference in NumPy (and against the closed-form
``collide_box_box`` when it is there), and the mesh path against a brute-force nearest point over the triangles.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tumble.geometry import collide_convex, gjk
from tumble.geometry.collide_convex import collide_convex_convex, collide_convex_trimesh
from tumble.geometry.packing import pack_geometry
from tumble.shapes import Box, Capsule, ConvexHull, Cylinder, Sphere, TriMesh

IDENTITY = (1.0, 0.0, 0.0, 0.0)
MARGIN = 0.02
CUBE = ConvexHull(np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]))
GROUND = TriMesh(np.array([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]], float), np.array([[0, 1, 2], [0, 2, 3]]))


class Manifold(NamedTuple):
    count: int
    normal: np.ndarray
    point: np.ndarray
    separation: np.ndarray
    feature: np.ndarray


def quat(axis, degrees):
    x, y, z, w = Rotation.from_rotvec(np.radians(degrees) * np.asarray(axis, float) / np.linalg.norm(axis)).as_quat()
    return (float(w), float(x), float(y), float(z))


def collide(shape_a, pos_a, shape_b, pos_b, quat_a=IDENTITY, quat_b=IDENTITY, margin=MARGIN):
    """The manifold of A against B (a mesh B goes through collide_convex_trimesh)."""
    geom = pack_geometry([shape_a, shape_b], [0, 1], np.zeros((2, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (2, 1)))
    kernel = collide_convex_trimesh if isinstance(shape_b, TriMesh) else collide_convex_convex
    normal, point, separation, feature = np.zeros(3), np.zeros((4, 3)), np.zeros(4), np.zeros(4, np.int64)
    count = kernel(geom, 0, tuple(map(float, pos_a)), tuple(map(float, quat_a)), 1, tuple(map(float, pos_b)),
                   tuple(map(float, quat_b)), margin, normal, point, separation, feature)  # fmt: skip
    return Manifold(count, normal, point[:count], separation[:count], feature[:count])


def same_points(actual, expected, atol):
    """Every expected point has an actual one within ``atol`` and the counts match."""
    assert len(actual) == len(expected)
    for p in expected:
        assert np.min(np.linalg.norm(actual - np.asarray(p), axis=1)) < atol, (actual, p)


# --- polyhedra: SAT and face clipping ------------------------------------------------------------------------------


def test_hull_resting_on_hull_gives_the_four_corners_of_the_overlap_at_the_depth():
    m = collide(CUBE, (0, 0, 0), CUBE, (0.2, 0.1, 0.99))
    assert m.count == 4
    np.testing.assert_allclose(m.normal, [0, 0, 1], atol=1e-15)  # measured 0
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-12)  # measured 9e-18
    same_points(
        m.point, [(-0.3, -0.4, 0.495), (0.5, -0.4, 0.495), (0.5, 0.5, 0.495), (-0.3, 0.5, 0.495)], 1e-12
    )  # measured 0


def test_hull_on_a_larger_box_gives_the_hull_corners():
    m = collide(Box((2, 2, 1)), (0, 0, 0), CUBE, (0.2, 0.1, 0.99))
    assert m.count == 4
    np.testing.assert_allclose(m.normal, [0, 0, 1], atol=1e-15)  # measured 0
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-12)  # measured 9e-18
    same_points(
        m.point, [(-0.3, -0.4, 0.495), (0.7, -0.4, 0.495), (0.7, 0.6, 0.495), (-0.3, 0.6, 0.495)], 1e-12
    )  # measured 0


def test_turned_hull_on_hull_keeps_four_of_the_octagon():
    """B turned 45° about z: the overlap is an octagon; four of its corners, spanning most of its area, remain."""
    m = collide(CUBE, (0, 0, 0), CUBE, (0, 0, 0.99), IDENTITY, quat((0, 0, 1), 45))
    assert m.count == 4
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-12)  # measured 9e-18
    xy = m.point[:, :2]
    assert np.all(np.abs(xy) <= 0.5 + 1e-12)
    assert np.all(np.abs(xy @ np.array([[1, 1], [1, -1]]) / math.sqrt(2.0)) <= 0.5 + 1e-12)
    # Four octagon corners spanning most of it: the quadrilateral covers over 60 % of the octagon's 0.828 m².
    assert polygon_area(xy) > 0.5


def polygon_area(xy):
    """Area of the convex polygon through the points (sorted round their centroid; shoelace formula)."""
    order = np.argsort(np.arctan2(xy[:, 1] - xy[:, 1].mean(), xy[:, 0] - xy[:, 0].mean()))
    x, y = xy[order, 0], xy[order, 1]
    return 0.5 * abs(x @ np.roll(y, -1) - y @ np.roll(x, -1))


def test_crossed_edges_give_one_point_between_them():
    """A's top edge along x at √2/2, B's bottom edge along y at 1.4 - √2/2: the edges cross at the z axis."""
    m = collide(CUBE, (0, 0, 0), CUBE, (0, 0, 1.4), quat((1, 0, 0), 45), quat((0, 1, 0), 45))
    assert m.count == 1
    np.testing.assert_allclose(m.normal, [0, 0, 1], atol=1e-12)  # measured 0
    assert m.separation[0] == pytest.approx(1.4 - math.sqrt(2.0), abs=1e-12)  # measured 2e-16
    np.testing.assert_allclose(m.point[0], [0, 0, 0.7], atol=1e-12)  # measured 1e-17


def test_speculative_margin():
    m = collide(CUBE, (0, 0, 0), CUBE, (0, 0, 1.01))
    assert m.count == 4
    np.testing.assert_allclose(m.separation, 0.01, atol=1e-12)  # measured 9e-18
    assert collide(CUBE, (0, 0, 0), CUBE, (0, 0, 1.01), margin=0.005).count == 0
    assert collide(Sphere(0.5), (0, 0, 0), CUBE, (0, 0, 1.01), margin=0.005).count == 0
    m = collide(Sphere(0.5), (0, 0, 0), CUBE, (0, 0, 1.01))
    assert m.count == 1 and m.separation[0] == pytest.approx(0.01, abs=1e-12)  # measured 9e-18


def test_swapping_the_shapes_flips_the_normal():
    for a, b, q in [(CUBE, Box((1.2, 0.8, 0.6)), quat((1, 2, 3), 25)), (Cylinder(0.3, 1.0), CUBE, quat((1, 0, 0), 3))]:
        ab = collide(a, (0, 0, 0), b, (0.1, 0.05, 0.75), IDENTITY, q)
        ba = collide(b, (0.1, 0.05, 0.75), a, (0, 0, 0), q, IDENTITY)
        assert ab.count > 0 and ab.count == ba.count
        np.testing.assert_allclose(ab.normal, -ba.normal, atol=1e-12)  # measured 0
        np.testing.assert_allclose(np.sort(ab.separation), np.sort(ba.separation), atol=1e-9)  # measured 0


def test_feature_ids_survive_a_small_motion():
    """Warm starting matches points by id: a resting hull nudged by 0.1 mm keeps its ids."""
    a = collide(CUBE, (0, 0, 0), CUBE, (0.2, 0.1, 0.99))
    b = collide(CUBE, (0, 0, 0), CUBE, (0.2001, 0.1001, 0.9899))
    assert len(set(a.feature)) == 4
    assert set(a.feature) == set(b.feature)


def test_box_built_on_the_fly_agrees_with_the_sat_reference():
    """Box against box through the polyhedron road: depth and normal as the 15-axis SAT reference in NumPy (and the
    closed-form collide_box_box when it exists), on poses where the best axis wins clearly."""
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(200):
        ha, hb = rng.uniform(0.2, 0.8, 3), rng.uniform(0.2, 0.8, 3)
        qa = tuple(Rotation.random(random_state=rng).as_quat()[[3, 0, 1, 2]])
        qb = tuple(Rotation.random(random_state=rng).as_quat()[[3, 0, 1, 2]])
        pb = rng.uniform(-1.0, 1.0, 3)
        depth, axis, margin_to_next = sat_box_box(ha, np.zeros(3), qa, hb, pb, qb)
        # Both kernels keep a face axis unless another beats it by 5 % plus about 1 mm: compare where none is close.
        if depth <= 0.0 or margin_to_next < 0.05 * depth + 0.01:
            continue
        m = collide(Box(2 * ha), (0, 0, 0), Box(2 * hb), pb, qa, qb)
        assert m.count >= 1
        assert -m.separation.min() == pytest.approx(depth, abs=1e-9)  # measured 9e-16
        np.testing.assert_allclose(m.normal, axis, atol=1e-9)  # measured 8e-16
        closed = closed_form_box_box(Box(2 * ha), Box(2 * hb), pb, qa, qb)
        if closed is not None:
            assert closed.separation.min() == pytest.approx(m.separation.min(), abs=1e-9)  # measured 7e-16
            np.testing.assert_allclose(closed.normal, m.normal, atol=1e-9)  # measured 8e-16
        checked += 1
    assert checked > 40


def sat_box_box(ha, pa, qa, hb, pb, qb):
    """Least overlap over the 15 axes of two boxes, its axis (A to B), and how much the next axis loses by."""
    ra = Rotation.from_quat([qa[1], qa[2], qa[3], qa[0]]).as_matrix()
    rb = Rotation.from_quat([qb[1], qb[2], qb[3], qb[0]]).as_matrix()
    axes = [ra[:, i] for i in range(3)] + [rb[:, i] for i in range(3)]
    axes += [np.cross(ra[:, i], rb[:, j]) for i in range(3) for j in range(3)]
    overlaps = []
    for axis in axes:
        if np.linalg.norm(axis) < 1e-6:
            continue
        axis = axis / np.linalg.norm(axis)
        if axis @ (pb - pa) < 0:
            axis = -axis
        overlaps.append((np.abs(ra.T @ axis) @ ha + np.abs(rb.T @ axis) @ hb - axis @ (pb - pa), tuple(axis)))
    overlaps.sort()
    return overlaps[0][0], np.array(overlaps[0][1]), overlaps[1][0] - overlaps[0][0]


def closed_form_box_box(box_a, box_b, pb, qa, qb):
    """The other engineer's collide_box_box, when it is in the tree."""
    try:
        from tumble.geometry.collide_primitives import collide_box_box
    except ImportError:
        return None
    geom = pack_geometry([box_a, box_b], [0, 1], np.zeros((2, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (2, 1)))
    normal, point, separation, feature = np.zeros(3), np.zeros((4, 3)), np.zeros(4), np.zeros(4, np.int64)
    count = collide_box_box(geom, 0, (0.0, 0.0, 0.0), qa, 1, tuple(map(float, pb)), qb, MARGIN, normal, point,
                            separation, feature)  # fmt: skip
    return Manifold(count, normal, point[:count], separation[:count], feature[:count])


def test_face_contact_near_an_edge_keeps_the_deepest_corner():
    """B's face is the best axis, but the face of A most opposed to it lies beside it: the incident face is taken
    round A's deepest corner, so that corner is clipped in and the depth is the face axis's (a hypothesis find)."""
    a = ConvexHull(np.array([[0.05, 0.05, 0.05], [0.05, -0.2, 0.05], [0.3, -0.2, -0.2], [-0.075, 0.175, -0.2],
                             [-0.1375, 0.3, -0.1375]]))  # fmt: skip
    b = ConvexHull(np.array([[0.05, 0.05, 0.05], [0.05, 0.05, -0.2], [0.05, 0.3, 0.175], [0.3, 0.05, -0.2]]))
    q = (0.7427813527082074, -0.3713906763541037, -0.5570860145311556, 0.0)
    m = collide(a, (0, 0, 0), b, (0, 0, -0.375), q, q)
    geom = pack_geometry([a, b], [0, 1], np.zeros((2, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (2, 1)))
    sep, n, _, _ = gjk.shape_distance(geom, 0, (0.0, 0.0, 0.0), q, 1, (0.0, 0.0, -0.375), q)
    assert m.count >= 1
    assert m.separation.min() == pytest.approx(sep, abs=1e-12)  # measured 1e-17
    np.testing.assert_allclose(m.normal, n, atol=1e-12)  # measured 1e-16


def test_reduction_drops_copies_of_a_corner():
    """Clipping can list a corner twice; the four kept points are distinct, whichever shape comes first."""
    a = ConvexHull(np.array([[0.05, 0.05, 0.05], [0.175, -0.2, -0.2], [0.08125, 0.175, -0.2],
                             [-0.075, 0.3048457109475499, -0.028769237061605]]))  # fmt: skip
    b = ConvexHull(np.array([[0.05, 0.05, -0.2], [0.175, -0.2, -0.2], [0.08125, 0.175, -0.2], [-0.2, 0.05, 0.05]]))
    q = (0.6, 0.0, 0.0, 0.8)
    ab = collide(a, (0.25, 0, 0), b, (0.25, 0, 0), q, q)
    ba = collide(b, (0.25, 0, 0), a, (0.25, 0, 0), q, q)
    for m in (ab, ba):
        gaps = [np.linalg.norm(p - r) for i, p in enumerate(m.point) for r in m.point[i + 1 :]]
        assert min(gaps) > 1e-9
    assert ab.count == ba.count


def test_many_sided_hull_face_on_a_box():
    """A 24-sided prism standing on a box: its bottom face is clipped whole, four corners spanning it remain."""
    angles = np.linspace(0.0, 2.0 * np.pi, 24, endpoint=False)
    ring = np.c_[0.4 * np.cos(angles), 0.4 * np.sin(angles)]
    prism = ConvexHull(np.vstack([np.c_[ring, np.full(24, -0.5)], np.c_[ring, np.full(24, 0.5)]]))
    m = collide(Box((2, 2, 1)), (0, 0, 0), prism, (0.1, 0.2, 0.99))
    assert m.count == 4
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-12)  # measured 9e-18
    np.testing.assert_allclose(np.linalg.norm(m.point[:, :2] - [0.1, 0.2], axis=1), 0.4, atol=1e-12)  # measured 1e-16


# --- round shapes: GJK/EPA and features -----------------------------------------------------------------------------


def test_cylinder_standing_on_a_box_gets_four_rim_points():
    m = collide(Box((2, 2, 1)), (0, 0, 0), Cylinder(0.3, 1.0), (0.2, 0.1, 0.99))
    assert m.count == 4
    np.testing.assert_allclose(m.normal, [0, 0, 1], atol=1e-12)  # measured 0
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-9)  # measured 9e-18
    np.testing.assert_allclose(np.linalg.norm(m.point[:, :2] - [0.2, 0.1], axis=1), 0.3, atol=1e-9)  # measured 6e-17
    # They span the disc: two diameters' worth.
    assert np.ptp(m.point[:, 0]) > 0.5 and np.ptp(m.point[:, 1]) > 0.5


def test_tilted_cylinder_keeps_the_exact_lowest_rim_depth():
    """Tilted 3° about x: the lowest rim point is r sin 3° below the tilted cap centre; the opposite rim is as high
    above it, still inside the margin here."""
    tilt = math.radians(3.0)
    m = collide(Box((2, 2, 1)), (0, 0, 0), Cylinder(0.3, 1.0), (0.2, 0.1, 0.99), IDENTITY, quat((1, 0, 0), 3))
    centre_bottom = 0.99 - 0.5 * math.cos(tilt)
    assert m.count >= 3
    assert m.separation.min() == pytest.approx(centre_bottom - 0.3 * math.sin(tilt) - 0.5, abs=1e-9)  # measured 0
    assert m.separation.max() == pytest.approx(centre_bottom + 0.3 * math.sin(tilt) - 0.5, abs=1e-9)  # measured 0
    np.testing.assert_allclose(m.normal, [0, 0, 1], atol=1e-12)  # measured 0


def test_cylinder_tipped_on_its_rim_gets_the_rim_corners_within_the_margin():
    """Tilted 30° about x, its lowest rim point 1 cm into the box: the rim's corners 45° round it are
    0.3 sin 30° (1 - cos 45°) higher, inside a 5 cm margin, the next ones outside. One rim point (before issue 44's
    fix) let a cylinder tipping over on a hull dig the rest of its rim in within the step."""
    tilt = math.radians(30.0)
    centre_z = 0.5 + 0.5 * math.cos(tilt) + 0.3 * math.sin(tilt) - 0.01
    m = collide(Box((2, 2, 1)), (0, 0, 0), Cylinder(0.3, 1.0), (0.2, 0.1, centre_z), IDENTITY, quat((1, 0, 0), 30),
                margin=0.05)  # fmt: skip
    assert m.count == 3
    np.testing.assert_allclose(m.normal, [0, 0, 1], atol=1e-12)
    next_corner = -0.01 + 0.3 * math.sin(tilt) * (1.0 - math.cos(math.pi / 4))
    np.testing.assert_allclose(np.sort(m.separation), [-0.01, next_corner, next_corner], atol=1e-9)


def test_cylinder_rim_over_a_box_edge_gets_the_rim_corners_over_the_face_beside_the_deepest_point():
    """Tipped 10° about x and hanging 10 cm over the box's edge, the rim digs in by the edge: GJK's normal faces
    neither the box's face nor the disc to REF_COS, and the pair kept that one point, about which a cylinder tipped
    on a box rocked from one side of its rim to the other and dug each in (issue 44: 6.0 cm in the bowl). Within
    NEAR_FACE_COS of the face, the rim corners over it join the deepest point, each measured along the normal from
    the plane the box lies under: never farther apart than the rim corner really is from the box."""
    box, cylinder = Box((2, 2, 1)), Cylinder(0.3, 1.0)
    pos_b, quat_b = (1.1, 0.0, 1.0), quat((1, 0, 0), 10)
    m = collide(box, (0, 0, 0), cylinder, pos_b, IDENTITY, quat_b, margin=0.05)
    geom = pack_geometry([box, cylinder], [0, 1], np.zeros((2, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (2, 1)))
    box_core, cylinder_core = gjk.core_proxy(geom, 0, -1), gjk.core_proxy(geom, 1, -1)
    found, depth, normal, _, _ = gjk.proxy_contact(box_core, (0.0, 0.0, 0.0), IDENTITY, cylinder_core, pos_b, quat_b,
                                                   geom.vertex_local, 0.05)  # fmt: skip
    assert found and depth == pytest.approx(-0.0414, abs=1e-4)
    assert m.count == 4
    np.testing.assert_allclose(m.normal, normal, atol=1e-15)
    assert m.separation.min() == depth
    for point, separation in zip(m.point, m.separation, strict=True):
        rim_corner = point + 0.5 * separation * np.asarray(normal)
        assert rim_corner[0] <= 1.0 + 1e-9  # over the box's top face
        outside = np.maximum(np.abs(rim_corner) - (1.0, 1.0, 0.5), 0.0)
        assert separation <= np.linalg.norm(outside) + 1e-12


def test_cylinder_lying_on_its_side_gets_the_two_ends_of_its_line():
    m = collide(Box((2, 2, 1)), (0, 0, 0), Cylinder(0.3, 1.0), (0.2, 0.1, 0.79), IDENTITY, quat((1, 0, 0), 90))
    assert m.count == 2
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-9)  # measured 2e-16
    same_points(m.point, [(0.2, 0.6, 0.495), (0.2, -0.4, 0.495)], 1e-9)  # measured 3e-12


def test_crossed_lying_cylinders_touch_at_one_point():
    c = Cylinder(0.3, 1.0)
    m = collide(c, (0, 0, 0), c, (0, 0, 0.59), quat((1, 0, 0), 90), quat((0, 1, 0), 90))
    assert m.count == 1
    assert m.separation[0] == pytest.approx(-0.01, abs=1e-9)  # measured 6e-17 (the cores are apart: GJK)


def test_cylinder_stacked_on_a_cylinder():
    m = collide(Cylinder(0.5, 1.0), (0, 0, 0), Cylinder(0.3, 1.0), (0.1, 0.0, 0.99))
    assert m.count == 4
    np.testing.assert_allclose(m.normal, [0, 0, 1], atol=1e-12)  # measured 0
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-9)  # measured 9e-18
    np.testing.assert_allclose(np.linalg.norm(m.point[:, :2] - [0.1, 0.0], axis=1), 0.3, atol=1e-9)  # measured 6e-17


def test_cylinders_side_by_side_get_two_points():
    c = Cylinder(0.3, 1.0)
    m = collide(c, (0, 0, 0), c, (0.59, 0.2, 0), quat((1, 0, 0), 90), quat((1, 0, 0), 90))
    assert m.count == 2
    # EPA alone resolves two curved sides to about 5e-5 rad; the direction square to both axes is tried after it
    # (gjk._polish_depth) and is exact here.
    np.testing.assert_allclose(m.normal, [1, 0, 0], atol=1e-12)  # measured 7e-17
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-12)  # measured 9e-18


def test_sphere_on_a_hull_face():
    m = collide(Sphere(0.25), (0.1, 0.2, 0.74), CUBE, (0, 0, 0))
    assert m.count == 1
    np.testing.assert_allclose(m.normal, [0, 0, -1], atol=1e-12)  # measured 1e-16
    assert m.separation[0] == pytest.approx(-0.01, abs=1e-12)  # measured 9e-18
    np.testing.assert_allclose(m.point[0], [0.1, 0.2, 0.495], atol=1e-12)  # measured 6e-17


def test_capsule_lying_on_a_hull_gets_two_points():
    m = collide(Capsule(0.1, 0.6), (0.1, 0.0, 0.59), CUBE, (0, 0, 0), quat((0, 1, 0), 90))
    assert m.count == 2
    np.testing.assert_allclose(m.normal, [0, 0, -1], atol=1e-12)  # measured 0
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-12)  # measured 1e-16
    same_points(m.point, [(-0.2, 0, 0.495), (0.4, 0, 0.495)], 1e-12)  # measured 6e-17


def test_capsule_standing_on_a_hull_gets_one_point():
    m = collide(Capsule(0.1, 0.6), (0.1, 0.0, 0.89), CUBE, (0, 0, 0))
    assert m.count == 1 and m.separation[0] == pytest.approx(-0.01, abs=1e-12)  # measured 7e-17


# --- convex against a triangle mesh ------------------------------------------------------------------------------


def test_box_on_a_two_triangle_ground_gets_its_four_corners():
    """The box straddles the diagonal shared by the two triangles; it still gets its corners, not clip points."""
    q = quat((0, 0, 1), 20)
    m = collide(Box((1, 1, 1)), (0.3, -0.2, 0.49), GROUND, (0, 0, 0), q)
    assert m.count == 4
    np.testing.assert_allclose(m.normal, [0, 0, -1], atol=1e-12)  # measured 1e-16
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-12)  # measured 1e-17
    corners = Rotation.from_quat([q[1], q[2], q[3], q[0]]).apply(
        [[x, y, 0] for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    )
    same_points(m.point, 0.5 * corners + [0.3, -0.2, -0.005], 1e-12)  # measured 2e-16
    # Two triangles contributed: their indices sit in the feature ids.
    assert len({int(f) >> 41 for f in m.feature}) == 2


def test_box_sliding_over_the_inner_edge_is_not_caught():
    """The box's corner has just crossed into the second triangle: the shallow sideways axis of that triangle must
    not win over the ground's normal."""
    m = collide(Box((1, 1, 1)), (0.5, -0.499, 0.495), GROUND, (0, 0, 0))
    assert m.count == 4
    np.testing.assert_allclose(m.normal, [0, 0, -1], atol=1e-12)  # measured 0
    np.testing.assert_allclose(m.separation, -0.005, atol=1e-12)  # measured 4e-18


def test_round_shapes_on_the_ground():
    sphere = collide(Sphere(0.5), (0.3, -0.2, 0.49), GROUND, (0, 0, 0))
    assert sphere.count == 1 and sphere.separation[0] == pytest.approx(-0.01, abs=1e-12)  # measured 9e-18
    np.testing.assert_allclose(sphere.point[0], [0.3, -0.2, -0.005], atol=1e-12)  # measured 7e-16
    # Lying across the diagonal: both triangles see the capsule; the merge keeps its two ends.
    capsule = collide(Capsule(0.2, 1.0), (0.3, -0.2, 0.19), GROUND, (0, 0, 0), quat((1, 0, 0), 90))
    assert capsule.count == 2
    same_points(capsule.point, [(0.3, 0.3, -0.005), (0.3, -0.7, -0.005)], 1e-12)  # measured 6e-17
    cylinder = collide(Cylinder(0.2, 1.0), (0.3, -0.2, 0.49), GROUND, (0, 0, 0))
    assert cylinder.count == 4
    np.testing.assert_allclose(cylinder.separation, -0.01, atol=1e-9)  # measured 1e-17
    hull = collide(CUBE, (0.3, -0.2, 0.49), GROUND, (0, 0, 0))
    assert hull.count == 4


def test_a_tipped_capsule_on_a_mesh_triangle_gets_both_ends_within_the_margin():
    """Tipped 8° off lying flat (past FLAT_SIN), its lower end 1 cm into a triangle and its upper end 0.6 sin 8° higher:
    both ends within the margin. By its lower end only, a capsule hit from above turned about it and drove the other
    6-8 cm into the bowl within the step (issue 44)."""
    tilt = math.radians(8.0)
    centre_z = 0.2 + 0.3 * math.sin(tilt) - 0.01
    m = collide(Capsule(0.2, 0.6), (2.0, -1.0, centre_z), GROUND, (0, 0, 0), quat((0, 1, 0), 90 - 8), margin=0.1)
    assert m.count == 2
    np.testing.assert_allclose(m.normal, [0, 0, -1], atol=1e-12)
    np.testing.assert_allclose(np.sort(m.separation), [-0.01, -0.01 + 0.6 * math.sin(tilt)], atol=1e-12)
    ends = [
        (2.0 + s * 0.3 * math.cos(tilt), -1.0, 0.5 * h) for s, h in ((-1, -0.01), (1, -0.01 + 0.6 * math.sin(tilt)))
    ]
    same_points(m.point, ends, 1e-12)


def test_nothing_far_from_the_mesh():
    assert collide(Box((1, 1, 1)), (0.0, 0.0, 3.0), GROUND, (0, 0, 0)).count == 0
    assert collide(Sphere(0.5), (20.0, 0.0, 0.0), GROUND, (0, 0, 0)).count == 0


def bowl(radius=2.0, rings=8, segments=16, top_degrees=80.0):
    """The inside of a sphere's lower cap, centred at (0, 0, radius): a pole fan and quad rings, normals inward."""
    vertices = [(0.0, 0.0, 0.0)]
    for i in range(1, rings + 1):
        theta = math.radians(top_degrees) * i / rings
        for j in range(segments):
            phi = 2.0 * math.pi * j / segments
            vertices.append((radius * math.sin(theta) * math.cos(phi), radius * math.sin(theta) * math.sin(phi),
                             radius * (1.0 - math.cos(theta))))  # fmt: skip
    faces = [(0, 1 + j, 1 + (j + 1) % segments) for j in range(segments)]
    for i in range(rings - 1):
        for j in range(segments):
            a, b = 1 + i * segments + j, 1 + i * segments + (j + 1) % segments
            faces += [(a, a + segments, b + segments), (a, b + segments, b)]
    return TriMesh(np.array(vertices), np.array(faces))


def nearest_on_triangles(mesh, p):
    """The nearest point to p over every triangle (NumPy brute force, by projection and edge clamping)."""
    best, best_q = math.inf, None
    for face in mesh.faces:
        a, b, c = mesh.vertices[face]
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n)
        q = p - ((p - a) @ n) * n
        inside = all(np.cross(v1 - v0, q - v0) @ n >= 0 for v0, v1 in ((a, b), (b, c), (c, a)))
        candidates = [q] if inside else []
        for v0, v1 in ((a, b), (b, c), (c, a)):
            t = np.clip((p - v0) @ (v1 - v0) / ((v1 - v0) @ (v1 - v0)), 0.0, 1.0)
            candidates.append(v0 + t * (v1 - v0))
        for q in candidates:
            if np.linalg.norm(p - q) < best:
                best, best_q = np.linalg.norm(p - q), q
    return best, best_q


def test_sphere_resting_in_a_mesh_bowl():
    """At the bottom the sphere touches the whole pole fan: by symmetry the merged normal is straight down, and each
    fan triangle's gap, measured along its own normal, becomes gap / cos(tilt) along it."""
    mesh = bowl()
    centre = np.array([0.0, 0.0, 0.49])
    m = collide(Sphere(0.5), centre, mesh, (0, 0, 0))
    assert m.count >= 3
    np.testing.assert_allclose(m.normal, [0, 0, -1], atol=1e-12)  # measured 5e-17
    distance, _ = nearest_on_triangles(mesh, centre)
    a, b, c = mesh.vertices[mesh.faces[0]]
    n = np.cross(b - a, c - a)
    cos_tilt = abs(n[2]) / np.linalg.norm(n)
    np.testing.assert_allclose(m.separation, (distance - 0.5) / cos_tilt, atol=1e-12)  # measured 2e-18


def test_sphere_on_one_facet_up_the_side_of_a_mesh_bowl():
    """A small sphere over the middle of one side facet: one face contact, with that facet's normal and depth."""
    mesh = bowl()
    face = mesh.faces[16 + 2 * 16 * 3 + 2 * 5]
    a, b, c = mesh.vertices[face]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    if n[2] < 0:
        n = -n  # the side facing the bowl's inside, which is up here
    centre = (a + b + c) / 3.0 + 0.09 * n
    m = collide(Sphere(0.1), centre, mesh, (0, 0, 0))
    distance, nearest = nearest_on_triangles(mesh, centre)
    assert m.count == 1
    assert distance == pytest.approx(0.09, abs=1e-12)  # measured 1e-17
    assert m.separation[0] == pytest.approx(-0.01, abs=1e-12)  # measured 2e-17
    np.testing.assert_allclose(m.normal, -n, atol=1e-12)  # measured 2e-15
    np.testing.assert_allclose(m.point[0], nearest - 0.005 * n, atol=1e-12)  # measured 2e-16


def test_a_shape_behind_an_open_meshs_rim_is_not_dragged_in_through_it():
    """Issue 44: a box outside the bowl's rim, below it (behind the outermost ring's triangles), touches their back.
    A one-sided mesh never pushes out through its back, but only a shape over a triangle is pushed out along the
    face normal: this one lies beside the triangles, and pushing it along their normal pulled it in through the wall
    (6 cm under the surface, in a pile). A shape over the triangles, sunk as deep, still comes out the front."""
    mesh = bowl(rings=4, segments=12, top_degrees=60.0)
    rim = mesh.vertices[-12]  # a vertex of the rim, at x > 0, y = 0
    outside = rim + np.array([0.03, 0.0, -0.1])  # beyond the rim and below it, through the wall's back
    assert collide(Box((0.2, 0.2, 0.2)), outside, mesh, (0, 0, 0)).count == 0  # was 25 cm deep, pulled inwards
    # The same box moved over the last ring's triangles, as far behind their plane: pushed out the front.
    a, b, c = mesh.vertices[mesh.faces[-2]]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    over = (a + b + c) / 3.0 - 0.05 * n
    m = collide(Box((0.2, 0.2, 0.2)), over, mesh, (0, 0, 0))
    assert m.count >= 1 and m.normal @ n < -0.9 and m.separation.min() < -0.05


def test_mesh_candidate_buffer_squeezes_without_losing_the_corners():
    """A large box over a fine grid produces more candidates than the buffer holds; the box corners survive."""
    n = 21
    xs = np.linspace(-2.0, 2.0, n)
    vertices = np.array([[x, y, 0.0] for x in xs for y in xs])
    faces = []
    for i in range(n - 1):
        for j in range(n - 1):
            a = i * n + j
            faces += [[a, a + n, a + n + 1], [a, a + n + 1, a + 1]]
    grid = TriMesh(vertices, np.array(faces))
    m = collide(Box((3.0, 3.0, 1.0)), (0.05, 0.05, 0.49), grid, (0, 0, 0))
    assert m.count == 4
    np.testing.assert_allclose(m.separation, -0.01, atol=1e-12)  # measured 1e-17
    same_points(
        m.point, [(0.05 + sx * 1.5, 0.05 + sy * 1.5, -0.005) for sx in (-1, 1) for sy in (-1, 1)], 1e-12
    )  # measured 4e-18
    assert collide_convex.MESH_MAX_CANDIDATES < 6 * 4 * 8  # the grid under the box gives far more than the buffer
