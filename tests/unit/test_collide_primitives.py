"""Closed-form contact manifolds (tumble.geometry.collide_primitives) on poses whose answer is known exactly.

Each case places two shapes so that the depth, the normal and the contact points follow from elementary
geometry (a sphere resting 1 mm deep on a plane, a box on a box, crossed edges, ...). The kernels are called
exactly as the narrow phase calls them: shapes packed by ``pack_geometry``, world poses of the two shape frames
as tuples, preallocated output rows. Everything here also runs as plain Python under ``NUMBA_DISABLE_JIT=1``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pytest
import scipy.spatial

from tumble.geometry import collide_primitives as cp
from tumble.geometry.packing import pack_geometry
from tumble.rotation import quat_from_axis_angle, quat_multiply
from tumble.shapes import Box, Capsule, ConvexHull, Cylinder, Plane, Sphere

IDENTITY = (1.0, 0.0, 0.0, 0.0)
MM = 1e-3
# Closed-form poses: only round-off separates the kernels from the exact answers (measured <= 4e-16).
ATOL = 1e-12


class Contact(NamedTuple):
    count: int
    normal: np.ndarray
    points: np.ndarray
    separation: np.ndarray
    feature: np.ndarray


def quat(axis, angle) -> tuple:
    return tuple(float(x) for x in quat_from_axis_angle(np.asarray(axis, float), angle))


def compose(*quats) -> tuple:
    q = np.array(IDENTITY)
    for r in quats:
        q = quat_multiply(q, np.asarray(r))
    return tuple(float(x) for x in q)


def collide(kernel, shape_a, pos_a, quat_a, shape_b, pos_b, quat_b, margin=0.02) -> Contact:
    geom = pack_geometry([shape_a, shape_b], [0, 1], np.zeros((2, 3)), np.tile(IDENTITY, (2, 1)))
    normal, point = np.zeros(3), np.zeros((4, 3))
    separation, feature = np.zeros(4), np.zeros(4, np.int64)
    pa, qa = tuple(float(x) for x in pos_a), tuple(float(x) for x in quat_a)
    pb, qb = tuple(float(x) for x in pos_b), tuple(float(x) for x in quat_b)
    count = kernel(geom, 0, pa, qa, 1, pb, qb, float(margin), normal, point, separation, feature)
    return Contact(int(count), normal, point[:count].copy(), separation[:count].copy(), feature[:count].copy())


def sorted_rows(points) -> np.ndarray:
    points = np.round(np.asarray(points), 9)
    return points[np.lexsort(points.T[::-1])]


def assert_points(actual, expected, atol=ATOL):
    np.testing.assert_allclose(sorted_rows(actual), sorted_rows(expected), atol=atol)


def area_2d(points) -> float:
    """Area of the convex hull of the points' (x, y)."""
    return float(scipy.spatial.ConvexHull(np.asarray(points)[:, :2]).volume)


def fid(code_a, code_b) -> int:
    return (code_a << 32) | code_b


# --- sphere pairs ------------------------------------------------------------------------------------------


def test_sphere_sphere_overlap_gives_the_midpoint_along_the_centre_line():
    c = collide(cp.collide_sphere_sphere, Sphere(1.0), (0, 0, 0), IDENTITY, Sphere(0.5), (1.499, 0, 0), IDENTITY)
    assert c.count == 1
    np.testing.assert_allclose(c.normal, [1, 0, 0], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM], atol=ATOL)
    np.testing.assert_allclose(c.points, [[1.0 - 0.5 * MM, 0, 0]], atol=ATOL)
    assert c.feature.tolist() == [0]


def test_sphere_sphere_with_coincident_centres_separates_along_z():
    c = collide(cp.collide_sphere_sphere, Sphere(1.0), (1, 2, 3), IDENTITY, Sphere(0.5), (1, 2, 3), IDENTITY)
    assert c.count == 1
    np.testing.assert_allclose(c.normal, [0, 0, 1])
    np.testing.assert_allclose(c.separation, [-1.5])


@pytest.mark.parametrize(("gap", "count"), [(0.019, 1), (0.021, 0)])
def test_sphere_sphere_speculative_point_within_the_margin_only(gap, count):
    c = collide(cp.collide_sphere_sphere, Sphere(1.0), (0, 0, 0), IDENTITY, Sphere(1.0), (0, 0, 2 + gap), IDENTITY,
                margin=0.02)  # fmt: skip
    assert c.count == count
    if count:
        np.testing.assert_allclose(c.separation, [gap], atol=ATOL)


def test_sphere_capsule_side_and_end():
    capsule = Capsule(0.5, 2.0)  # segment z in [-1, 1]
    side = collide(cp.collide_sphere_capsule, Sphere(1.0), (1.499, 0, 0.3), IDENTITY, capsule, (0, 0, 0), IDENTITY)
    np.testing.assert_allclose(side.normal, [-1, 0, 0], atol=ATOL)
    np.testing.assert_allclose(side.separation, [-MM], atol=ATOL)
    np.testing.assert_allclose(side.points, [[0.5 - 0.5 * MM, 0, 0.3]], atol=ATOL)
    # Beyond the +z end, on a capsule turned to lie along x.
    turned = quat((0, 1, 0), math.pi / 2)
    end = collide(cp.collide_sphere_capsule, Sphere(1.0), (2.499, 0, 0), IDENTITY, capsule, (0, 0, 0), turned)
    np.testing.assert_allclose(end.normal, [-1, 0, 0], atol=ATOL)
    np.testing.assert_allclose(end.separation, [-MM], atol=ATOL)


def test_sphere_centred_on_the_capsule_segment_leaves_sideways():
    c = collide(cp.collide_sphere_capsule, Sphere(1.0), (0, 0, 0.5), IDENTITY, Capsule(0.5, 2.0), (0, 0, 0), IDENTITY)
    assert c.count == 1
    assert abs(np.linalg.norm(c.normal) - 1.0) < ATOL and abs(c.normal[2]) < ATOL
    np.testing.assert_allclose(c.separation, [-1.5], atol=ATOL)


def test_sphere_on_a_turned_box_face_edge_and_corner():
    box, spin = Box((2.0, 2.0, 2.0)), quat((0, 0, 1), 0.3)
    face = collide(cp.collide_sphere_box, Sphere(0.5), (0, 0, 1.499), IDENTITY, box, (0, 0, 0), spin)
    np.testing.assert_allclose(face.normal, [0, 0, -1], atol=ATOL)
    np.testing.assert_allclose(face.separation, [-MM], atol=ATOL)
    np.testing.assert_allclose(face.points, [[0, 0, 1 - 0.5 * MM]], atol=ATOL)
    corner = collide(cp.collide_sphere_box, Sphere(0.5), np.full(3, 1 + 0.4 / math.sqrt(3)), IDENTITY, box,
                     (0, 0, 0), IDENTITY)  # fmt: skip
    np.testing.assert_allclose(corner.normal, -np.ones(3) / math.sqrt(3), atol=ATOL)
    np.testing.assert_allclose(corner.separation, [-0.1], atol=ATOL)
    edge = collide(cp.collide_sphere_box, Sphere(0.5), (1.3, 1.4, 0.2), IDENTITY, box, (0, 0, 0), IDENTITY)
    np.testing.assert_allclose(edge.normal, [-0.6, -0.8, 0], atol=ATOL)
    np.testing.assert_allclose(edge.separation, [0.0], atol=ATOL)


def test_sphere_centre_inside_the_box_leaves_through_the_nearest_face():
    box = Box((2.0, 4.0, 6.0))  # half extents 1, 2, 3
    c = collide(cp.collide_sphere_box, Sphere(0.5), (0.7, 0.2, -0.1), IDENTITY, box, (0, 0, 0), IDENTITY)
    np.testing.assert_allclose(c.normal, [-1, 0, 0])  # out through +x: 0.3 away; the box is pushed to -x
    np.testing.assert_allclose(c.separation, [-0.8], atol=ATOL)
    np.testing.assert_allclose(c.points, [[0.6, 0.2, -0.1]], atol=ATOL)  # midway from the face to the ball's far side
    centred = collide(cp.collide_sphere_box, Sphere(0.5), (0, 0, 0), IDENTITY, Box((2, 2, 2)), (0, 0, 0), IDENTITY)
    assert centred.count == 1 and abs(np.linalg.norm(centred.normal) - 1) < ATOL
    np.testing.assert_allclose(centred.separation, [-1.5], atol=ATOL)


# --- capsule pairs -----------------------------------------------------------------------------------------


def test_crossed_capsules_touch_at_one_point():
    lying_x, lying_y = quat((0, 1, 0), math.pi / 2), quat((1, 0, 0), math.pi / 2)
    c = collide(cp.collide_capsule_capsule, Capsule(0.5, 2.0), (0.3, 0, 0), lying_x, Capsule(0.25, 4.0),
                (0, -0.2, 0.749), lying_y)  # fmt: skip
    assert c.count == 1
    np.testing.assert_allclose(c.normal, [0, 0, 1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM], atol=ATOL)
    np.testing.assert_allclose(c.points, [[0, 0, 0.5 - 0.5 * MM]], atol=ATOL)
    assert c.feature.tolist() == [fid(2, 2)]


def test_parallel_capsules_side_by_side_touch_at_both_ends_of_the_shared_stretch():
    c = collide(cp.collide_capsule_capsule, Capsule(0.5, 2.0), (0, 0, 0), IDENTITY, Capsule(0.5, 2.0),
                (0.999, 0, 0.5), IDENTITY)  # fmt: skip
    assert c.count == 2
    np.testing.assert_allclose(c.normal, [1, 0, 0], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM, -MM], atol=ATOL)
    assert_points(c.points, [[0.4995, 0, -0.5], [0.4995, 0, 1.0]])
    # The lower end is b's own end (code 0), the upper one a's +end (code 1).
    assert sorted(c.feature.tolist()) == sorted([fid(2, 0), fid(1, 2)])


def test_capsules_end_to_end_touch_along_their_axis():
    c = collide(cp.collide_capsule_capsule, Capsule(0.5, 2.0), (0, 0, 0), IDENTITY, Capsule(0.5, 2.0),
                (0, 0, 2.999), quat((1, 0, 0), math.pi))  # fmt: skip
    assert c.count == 1
    np.testing.assert_allclose(c.normal, [0, 0, 1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM], atol=ATOL)
    assert c.feature.tolist() == [fid(1, 1)]


def test_capsules_whose_segments_cross_separate_along_their_common_normal():
    c = collide(cp.collide_capsule_capsule, Capsule(0.5, 2.0), (0, 0, 0), quat((0, 1, 0), math.pi / 2),
                Capsule(0.5, 2.0), (0, 0, 0), quat((1, 0, 0), math.pi / 2))  # fmt: skip
    assert c.count == 1
    np.testing.assert_allclose(np.abs(c.normal), [0, 0, 1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-1.0], atol=ATOL)


def test_nearly_parallel_capsules_use_their_common_perpendicular():
    # b turned 1e-5 rad about z in the plane of a's axis, 1 mm deep on top: the normal is +z from the cross product
    # of the axes, to ~1e-16 / sin = 1e-11 (measured 1.1e-11), where the closest points' difference would carry
    # round-off of ~1e-16 / sin² = 1e-6.
    lying_x = quat((0, 1, 0), math.pi / 2)
    c = collide(cp.collide_capsule_capsule, Capsule(0.5, 2.0), (0, 0, 0), lying_x, Capsule(0.5, 2.0),
                (0.2, 0, 0.999), compose(quat((0, 0, 1), 1e-5), lying_x))  # fmt: skip
    assert c.count == 2
    np.testing.assert_allclose(c.normal, [0, 0, 1], atol=1e-10)
    np.testing.assert_allclose(c.separation, [-MM, -MM], atol=1e-9)


def test_capsules_crossing_at_a_small_angle_touch_once():
    # 2 degrees apart over a 4 m stretch: the axes are 7 cm apart sideways at its ends, far more than a tenth of
    # the 0.1 m radius, so it is one crossing point, not a line.
    lying_x = quat((0, 1, 0), math.pi / 2)
    c = collide(cp.collide_capsule_capsule, Capsule(0.1, 4.0), (0, 0, 0), lying_x, Capsule(0.1, 4.0),
                (0, 0, 0.199), compose(quat((0, 0, 1), math.radians(2)), lying_x))  # fmt: skip
    assert c.count == 1
    np.testing.assert_allclose(c.normal, [0, 0, 1], atol=1e-13)  # ~1e-16 / sin 2° (measured 3e-15)
    np.testing.assert_allclose(c.separation, [-MM], atol=1e-12)


def test_capsule_lying_on_a_box_gives_two_points():
    lying = quat((0, 1, 0), math.pi / 2)  # segment along x, from -1 to 1
    c = collide(cp.collide_capsule_box, Capsule(0.5, 2.0), (0.2, 0.3, 1.499), lying, Box((4, 4, 2)), (0, 0, 0),
                IDENTITY)  # fmt: skip
    assert c.count == 2
    np.testing.assert_allclose(c.normal, [0, 0, -1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM, -MM], atol=ATOL)
    assert_points(c.points, [[-0.8, 0.3, 1 - 0.5 * MM], [1.2, 0.3, 1 - 0.5 * MM]])
    top = 20 + 2 * 2 + 1  # box face +z
    assert sorted(c.feature.tolist()) == sorted([fid(0, top), fid(1, top)])


def test_capsule_overhanging_a_box_edge_is_clipped_at_the_edge():
    lying = quat((0, 1, 0), math.pi / 2)
    c = collide(cp.collide_capsule_box, Capsule(0.5, 2.0), (1.5, 0, 1.499), lying, Box((4, 4, 2)), (0, 0, 0),
                IDENTITY)  # fmt: skip
    assert c.count == 2
    assert_points(c.points, [[0.5, 0, 1 - 0.5 * MM], [2.0, 0, 1 - 0.5 * MM]])
    edge = 8 + 4 * 1 + 1 + 2  # edge along y at x = +2, z = +1
    assert fid(2, edge) in c.feature.tolist()


def test_capsule_standing_on_a_box_touches_with_its_lower_end():
    c = collide(cp.collide_capsule_box, Capsule(0.5, 2.0), (0.1, 0.2, 2.499), IDENTITY, Box((4, 4, 2)), (0, 0, 0),
                IDENTITY)  # fmt: skip
    assert c.count == 1
    np.testing.assert_allclose(c.normal, [0, 0, -1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM], atol=ATOL)
    np.testing.assert_allclose(c.points, [[0.1, 0.2, 1 - 0.5 * MM]], atol=ATOL)
    assert c.feature.tolist() == [fid(0, 25)]


def test_capsule_across_a_box_edge_touches_the_edge_once():
    # The box edge along y at x = 1, z = 1; the capsule lies across it at 45 degrees, touching it with its side.
    tilt = quat((0, 1, 0), -math.pi / 4)  # axis along (-1, 0, 1), across the offset (1, 0, 1)
    centre = np.array([1.0, 0.0, 1.0]) + (0.5 - MM) * np.array([1, 0, 1]) / math.sqrt(2)
    c = collide(cp.collide_capsule_box, Capsule(0.5, 2.0), centre, tilt, Box((2, 2, 2)), (0, 0, 0), IDENTITY)
    assert c.count == 1
    np.testing.assert_allclose(c.normal, -np.array([1, 0, 1]) / math.sqrt(2), atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM], atol=ATOL)
    # The capsule surface is 1 mm past the edge along the normal: the point is half of that inside the corner.
    np.testing.assert_allclose(c.points, [[1 - 0.5 * MM / math.sqrt(2), 0, 1 - 0.5 * MM / math.sqrt(2)]], atol=ATOL)


def test_capsule_segment_through_a_box_leaves_along_the_least_penetration():
    # A vertical capsule whose segment pierces the box near its +x face: out through +x.
    c = collide(cp.collide_capsule_box, Capsule(0.25, 4.0), (0.9, 0, 0), IDENTITY, Box((2, 2, 2)), (0, 0, 0),
                IDENTITY)  # fmt: skip
    assert c.count == 2
    np.testing.assert_allclose(c.normal, [-1, 0, 0], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-0.35, -0.35], atol=ATOL)  # 0.1 to the face plus the radius
    assert_points(c.points, [[0.825, 0, -1], [0.825, 0, 1]])


def test_upright_capsule_sunk_into_a_box_touches_with_its_lower_end_only():
    c = collide(cp.collide_capsule_box, Capsule(0.5, 1.0), (0.2, 0, 1.2), IDENTITY, Box((4, 4, 2)), (0, 0, 0),
                IDENTITY, margin=2.0)  # fmt: skip
    assert c.count == 1
    np.testing.assert_allclose(c.separation, [-0.8], atol=ATOL)  # lowest point at z = 0.2, face at z = 1
    assert c.feature.tolist() == [fid(0, 25)]


@pytest.mark.parametrize(("gap", "count"), [(0.015, 2), (0.025, 0)])
def test_capsule_box_speculative_points(gap, count):
    lying = quat((0, 1, 0), math.pi / 2)
    c = collide(cp.collide_capsule_box, Capsule(0.5, 2.0), (0, 0, 1.5 + gap), lying, Box((4, 4, 2)), (0, 0, 0),
                IDENTITY, margin=0.02)  # fmt: skip
    assert c.count == count
    np.testing.assert_allclose(c.separation, [gap] * count, atol=ATOL)


# --- box-box -----------------------------------------------------------------------------------------------


def test_box_on_box_face_to_face_gives_the_four_corners_of_the_overlap():
    c = collide(cp.collide_box_box, Box((2, 2, 2)), (0, 0, 0), IDENTITY, Box((1, 1, 1)), (0.8, 0.7, 1.499), IDENTITY)
    assert c.count == 4
    np.testing.assert_allclose(c.normal, [0, 0, 1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM] * 4, atol=ATOL)
    z = 1 - 0.5 * MM
    assert_points(c.points, [[0.3, 0.2, z], [1, 0.2, z], [0.3, 1, z], [1, 1, z]])
    # ids: two incident corners in the top face (20 + 5 = 25) and two side edges crossing, one top corner of a.
    assert len(set(c.feature.tolist())) == 4


def test_box_on_box_turned_45_degrees_keeps_four_of_the_octagon():
    turn = quat((0, 0, 1), math.pi / 4)
    c = collide(cp.collide_box_box, Box((2, 2, 2)), (0, 0, 0), IDENTITY, Box((2, 2, 2)), (0, 0, 1.999), turn)
    assert c.count == 4
    np.testing.assert_allclose(c.normal, [0, 0, 1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM] * 4, atol=ATOL)
    # The overlap is a regular octagon with vertices at R = 1/cos(22.5°) from the axis; the four kept are every
    # other one, the largest square in it (area 2 R²).
    radial = np.hypot(c.points[:, 0], c.points[:, 1])
    radius = 1 / math.cos(math.pi / 8)
    np.testing.assert_allclose(radial, radius, atol=1e-12)
    assert area_2d(c.points) == pytest.approx(2 * radius**2, abs=1e-12)


def test_crossed_edges_give_one_point_at_the_closest_points():
    # a: its top is the edge along x at z = sqrt(2)/2; b: its bottom is the edge along y; they cross with 1 mm overlap.
    ridge_x, ridge_y = quat((1, 0, 0), math.pi / 4), quat((0, 1, 0), math.pi / 4)
    top = 1 / math.sqrt(2)
    c = collide(cp.collide_box_box, Box((1, 1, 1)), (0, 0, 0), ridge_x, Box((1, 1, 1)), (0.1, -0.2, 2 * top - MM),
                ridge_y)  # fmt: skip
    assert c.count == 1
    np.testing.assert_allclose(c.normal, [0, 0, 1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM], atol=ATOL)
    np.testing.assert_allclose(c.points, [[0.1, 0, top - 0.5 * MM]], atol=ATOL)
    code_a, code_b = int(c.feature[0]) >> 32, int(c.feature[0]) & 0xFFFFFFFF
    assert 8 <= code_a < 12 and 12 <= code_b < 16  # a's edge along its x axis, b's along its y axis


def test_box_box_swapped_flips_the_normal():
    turn = compose(quat((0, 0, 1), 0.3), quat((1, 0, 0), 0.1))
    ab = collide(cp.collide_box_box, Box((2, 2, 2)), (0, 0, 0), IDENTITY, Box((1, 1.5, 1)), (0.2, 0.1, 1.45), turn)
    ba = collide(cp.collide_box_box, Box((1, 1.5, 1)), (0.2, 0.1, 1.45), turn, Box((2, 2, 2)), (0, 0, 0), IDENTITY)
    np.testing.assert_allclose(ab.normal, -ba.normal, atol=ATOL)
    assert abs(ab.separation.min() - ba.separation.min()) < ATOL
    assert_points(ab.points, ba.points, atol=1e-12)


@pytest.mark.parametrize(("gap", "count"), [(0.015, 4), (0.025, 0)])
def test_box_box_speculative_points(gap, count):
    c = collide(cp.collide_box_box, Box((2, 2, 2)), (0, 0, 0), IDENTITY, Box((1, 1, 1)), (0, 0, 1.5 + gap), IDENTITY,
                margin=0.02)  # fmt: skip
    assert c.count == count
    np.testing.assert_allclose(c.separation, [gap] * count, atol=ATOL)


@pytest.mark.parametrize(("gap", "count"), [(0.01, 1), (0.015, 0)])
def test_box_box_apart_across_a_diagonal_gap_get_their_nearest_points(gap, count):
    """Unit cubes side by side, offset by ``gap`` along x and y: their nearest features are parallel edges
    ``gap √2`` apart, and no face outline overlaps the other's. Within the 2 cm margin they get one point there
    (issue 44: without it a box falling past another's edge at 13.6 m/s went 6.4 cm into it); beyond, none."""
    c = collide(cp.collide_box_box, Box((1, 1, 1)), (0, 0, 0), IDENTITY, Box((1, 1, 1)), (1 + gap, 1 + gap, 0.3),
                IDENTITY, margin=0.02)  # fmt: skip
    assert c.count == count
    if count:
        assert c.separation[0] == pytest.approx(gap * math.sqrt(2.0), abs=ATOL)
        np.testing.assert_allclose(c.normal, [math.sqrt(0.5), math.sqrt(0.5), 0.0], atol=ATOL)
        np.testing.assert_allclose(c.points[0, :2], [0.5 + gap / 2, 0.5 + gap / 2], atol=ATOL)
        assert 0.3 - 0.5 - ATOL <= c.points[0, 2] <= 0.5 + ATOL  # on the common stretch of the two edges
        assert c.feature[0] == (26 << 32) | 26


def test_box_box_feature_ids_stay_while_the_same_features_touch():
    spin = quat((0, 0, 1), 0.2)
    first = collide(cp.collide_box_box, Box((2, 2, 2)), (0, 0, 0), IDENTITY, Box((1, 1, 1)), (0.8, 0.7, 1.499), spin)
    moved = collide(cp.collide_box_box, Box((2, 2, 2)), (0, 0, 0), IDENTITY, Box((1, 1, 1)), (0.81, 0.69, 1.498),
                    spin)  # fmt: skip
    assert sorted(first.feature.tolist()) == sorted(moved.feature.tolist())


def test_boxes_meeting_exactly_along_their_rims_keep_their_contact():
    # a's top face spans y in [0.3125, 0.5625], b's bottom face y in [-0.3125, 0.3125]: they share one line; the
    # turns by 90 degrees leave round-off that may put it either side of the rim.
    a_turn, b_turn = quat((1, 0, 0), math.pi / 2), quat((0, 1, 1), math.pi)
    c = collide(cp.collide_box_box, Box((2.0, 2.0, 0.25)), (0, 0.4375, -0.5625), a_turn, Box((2.0, 1.125, 0.625)),
                (0, 0, 1), b_turn)  # fmt: skip
    assert c.count >= 1
    np.testing.assert_allclose(c.separation, 0.0, atol=1e-15)


def test_twisted_stack_of_equal_boxes_keeps_its_four_corners_and_ids():
    # Solver noise twists a stack by ~1e-4 rad either way: the corners stay the points, with the same ids.
    ids = set()
    for twist in (0.0, 1e-4, -1e-4):
        c = collide(cp.collide_box_box, Box((0.5, 0.5, 0.5)), (0, 0, 0), IDENTITY, Box((0.5, 0.5, 0.5)),
                    (0, 0, 0.499), quat((0, 0, 1), twist))  # fmt: skip
        assert c.count == 4
        np.testing.assert_allclose(np.abs(c.points[:, :2]), 0.25, atol=3e-5)  # 0.25 m x 1e-4 rad
        ids.add(tuple(sorted(c.feature.tolist())))
    assert ids == {tuple(fid(25, v) for v in range(4))}


def test_box_box_ids_do_not_depend_on_round_off_among_equally_deep_points():
    # Turned 45 degrees, the overlap is an octagon of 8 equally deep candidates: a turn by 1e-13 rad must keep
    # the same four.
    turn = quat((0, 0, 1), math.pi / 4)
    first = collide(cp.collide_box_box, Box((2, 2, 2)), (0, 0, 0), IDENTITY, Box((2, 2, 2)), (0, 0, 1.999), turn)
    nudged = collide(cp.collide_box_box, Box((2, 2, 2)), (0, 0, 0), IDENTITY, Box((2, 2, 2)), (0, 0, 1.999),
                     compose(quat((1, 1, 0), 1e-13), turn))  # fmt: skip
    assert sorted(first.feature.tolist()) == sorted(nudged.feature.tolist())


def test_box_deep_inside_a_box_still_gives_a_face_manifold():
    c = collide(cp.collide_box_box, Box((4, 4, 4)), (0, 0, 0), IDENTITY, Box((1, 1, 1)), (0.2, 0.1, 1.2), IDENTITY)
    assert c.count == 4
    np.testing.assert_allclose(c.normal, [0, 0, 1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-1.3] * 4, atol=ATOL)  # bottom at 0.7, a's top at 2


# --- planes ------------------------------------------------------------------------------------------------


def test_sphere_resting_one_millimetre_deep_on_a_plane():
    c = collide(cp.collide_sphere_plane, Sphere(0.5), (0.3, -0.2, 0.499), IDENTITY, Plane(), (0, 0, 0), IDENTITY)
    assert c.count == 1
    np.testing.assert_allclose(c.normal, [0, 0, -1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM], atol=ATOL)
    np.testing.assert_allclose(c.points, [[0.3, -0.2, -0.5 * MM]], atol=ATOL)


def test_sphere_on_a_turned_and_offset_plane():
    # Plane n = x, offset 1 in its frame; the frame is turned a quarter about z (n becomes +y) and moved by (0, 2, 0).
    plane, turn = Plane((1, 0, 0), 1.0), quat((0, 0, 1), math.pi / 2)
    c = collide(cp.collide_sphere_plane, Sphere(0.5), (5, 3.49, 7), IDENTITY, plane, (0, 2, 0), turn)
    np.testing.assert_allclose(c.normal, [0, -1, 0], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-0.01], atol=ATOL)
    np.testing.assert_allclose(c.points, [[5, 2.995, 7]], atol=ATOL)


def test_capsule_on_a_plane_lying_and_standing():
    lying = quat((0, 1, 0), math.pi / 2)
    flat = collide(cp.collide_capsule_plane, Capsule(0.5, 2.0), (0, 0, 0.499), lying, Plane(), (0, 0, 0), IDENTITY)
    assert flat.count == 2
    assert_points(flat.points, [[-1, 0, -0.5 * MM], [1, 0, -0.5 * MM]])
    assert sorted(flat.feature.tolist()) == [fid(0, 0), fid(1, 0)]
    up = collide(cp.collide_capsule_plane, Capsule(0.5, 2.0), (0, 0, 1.499), IDENTITY, Plane(), (0, 0, 0), IDENTITY)
    assert up.count == 1 and up.feature.tolist() == [fid(0, 0)]
    np.testing.assert_allclose(up.separation, [-MM], atol=ATOL)


def test_upright_capsule_sunk_into_a_plane_touches_with_its_lower_end_only():
    c = collide(cp.collide_capsule_plane, Capsule(0.5, 1.0), (0, 0, 0.3), IDENTITY, Plane(), (0, 0, 0), IDENTITY,
                margin=2.0)  # fmt: skip
    assert c.count == 1 and c.feature.tolist() == [fid(0, 0)]
    np.testing.assert_allclose(c.separation, [-0.7], atol=ATOL)


def test_box_on_a_plane_gives_its_four_bottom_corners():
    c = collide(cp.collide_box_plane, Box((1, 2, 3)), (0, 0, 1.499), IDENTITY, Plane(), (0, 0, 0), IDENTITY)
    assert c.count == 4
    np.testing.assert_allclose(c.normal, [0, 0, -1], atol=ATOL)
    np.testing.assert_allclose(c.separation, [-MM] * 4, atol=ATOL)
    z = -0.5 * MM
    assert_points(c.points, [[-0.5, -1, z], [0.5, -1, z], [-0.5, 1, z], [0.5, 1, z]])
    assert sorted(c.feature.tolist()) == [fid(k, 0) for k in range(4)]


def test_box_resting_on_an_edge_and_a_corner():
    edge = collide(cp.collide_box_plane, Box((1, 1, 1)), (0, 0, math.sqrt(0.5) - MM), quat((1, 0, 0), math.pi / 4),
                   Plane(), (0, 0, 0), IDENTITY)  # fmt: skip
    assert edge.count == 2
    np.testing.assert_allclose(edge.separation, [-MM, -MM], atol=1e-12)
    # A quarter turn about z brings the diagonal (1, 1, 1) to (0, √2, 1), then atan(√2) about x stands it upright.
    tip = compose(quat((1, 0, 0), math.atan(math.sqrt(2))), quat((0, 0, 1), math.pi / 4))
    corner = collide(cp.collide_box_plane, Box((1, 1, 1)), (0, 0, math.sqrt(0.75) - MM), tip, Plane(), (0, 0, 0),
                     IDENTITY)  # fmt: skip
    assert corner.count == 1
    np.testing.assert_allclose(corner.separation, [-MM], atol=1e-12)


def test_box_on_a_plane_keeps_only_corners_within_the_margin():
    angle = 0.01  # one side of the bottom (1 m wide) 1 cm higher than the other
    height = 0.5 * (math.cos(angle) + math.sin(angle)) - MM  # low corners 1 mm deep, high ones 9 mm up
    c = collide(cp.collide_box_plane, Box((1, 1, 1)), (0, 0, height), quat((0, 1, 0), angle), Plane(), (0, 0, 0),
                IDENTITY, margin=0.002)  # fmt: skip
    assert c.count == 2
    np.testing.assert_allclose(c.separation, [-MM, -MM], atol=1e-12)


def test_cylinder_flat_on_a_plane_rests_on_four_rim_points():
    c = collide(cp.collide_cylinder_plane, Cylinder(1.0, 2.0), (0, 0, 0.999), IDENTITY, Plane(), (0, 0, 0), IDENTITY)
    assert c.count == 4
    np.testing.assert_allclose(c.separation, [-MM] * 4, atol=ATOL)
    z = -0.5 * MM
    assert_points(c.points, [[1, 0, z], [0, 1, z], [-1, 0, z], [0, -1, z]])
    assert sorted(c.feature.tolist()) == [fid(k, 0) for k in range(4)]


def test_tilted_cylinder_touches_at_its_deepest_rim_point():
    angle = 0.3
    tilt = quat((0, 1, 0), angle)  # the bottom rim's lowest point is towards -x
    height = math.cos(angle) * 1.0 + math.sin(angle) * 1.0 - MM  # axis half-height 1, radius 1
    c = collide(cp.collide_cylinder_plane, Cylinder(1.0, 2.0), (0, 0, height), tilt, Plane(), (0, 0, 0), IDENTITY)
    assert c.count == 1
    np.testing.assert_allclose(c.separation, [-MM], atol=ATOL)
    # Its local x turns to (cos, 0, -sin) and its axis to (sin, 0, cos): the rim point at local (1, 0, -1) is lowest.
    lowest = np.array([0, 0, height]) + np.array([math.cos(angle), 0, -math.sin(angle)]) - np.array(
        [math.sin(angle), 0, math.cos(angle)])  # fmt: skip
    np.testing.assert_allclose(c.points, [lowest + [0, 0, 0.5 * MM]], atol=ATOL)
    assert c.feature.tolist() == [fid(0, 0)]


def test_cylinder_on_its_side_touches_along_a_line():
    side = quat((1, 0, 0), math.pi / 2)
    c = collide(cp.collide_cylinder_plane, Cylinder(0.5, 2.0), (0, 0, 0.499), side, Plane(), (0, 0, 0), IDENTITY)
    assert c.count == 2
    assert_points(c.points, [[0, -1, -0.5 * MM], [0, 1, -0.5 * MM]])


def test_hull_on_a_plane_keeps_its_deepest_and_spread_vertices():
    octagon = [(math.cos(a), math.sin(a), z) for a in np.arange(8) * math.pi / 4 for z in (0.0, 1.0)]
    hull = ConvexHull(np.array(octagon))
    c = collide(cp.collide_hull_plane, hull, (0, 0, -MM), IDENTITY, Plane(), (0, 0, 0), IDENTITY)
    assert c.count == 4
    np.testing.assert_allclose(c.separation, [-MM] * 4, atol=ATOL)
    np.testing.assert_allclose(np.hypot(c.points[:, 0], c.points[:, 1]), 1.0, atol=ATOL)
    # Four of the eight bottom vertices, spread out: they form a square of area 2.
    angles = np.sort(np.arctan2(c.points[:, 1], c.points[:, 0]))
    np.testing.assert_allclose(np.diff(angles), math.pi / 2, atol=1e-9)
    bottom = hull.vertices[:, 2] == 0.0
    assert set((c.feature >> 32).tolist()) <= set(np.flatnonzero(bottom).tolist())
    tetra = ConvexHull(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]))
    tip = collide(cp.collide_hull_plane, tetra, (0, 0, 0.5), quat((1, 0, 0), math.pi), Plane(), (0, 0, 0),
                  IDENTITY)  # fmt: skip
    assert tip.count == 1
    np.testing.assert_allclose(tip.separation, [-0.5], atol=ATOL)


def test_hull_on_a_plane_keeps_its_ids_when_round_off_tilts_it():
    octagon = [(math.cos(a), math.sin(a), z) for a in np.arange(8) * math.pi / 4 for z in (0.0, 1.0)]
    hull = ConvexHull(np.array(octagon))
    flat = collide(cp.collide_hull_plane, hull, (0, 0, -MM), IDENTITY, Plane(), (0, 0, 0), IDENTITY)
    for axis in [(1, 0, 0), (0, 1, 0), (1, 1, 0)]:
        tilted = collide(cp.collide_hull_plane, hull, (0, 0, -MM), quat(axis, 1e-13), Plane(), (0, 0, 0), IDENTITY)
        assert sorted(tilted.feature.tolist()) == sorted(flat.feature.tolist())


# --- manifold reduction ------------------------------------------------------------------------------------


def test_reduce_manifold_keeps_the_deepest_then_the_widest_spread():
    # 12 points on a circle in the plane z = 0, the one at angle index 5 deepest; below the plane z = 0.1.
    angles = np.arange(12) * 2 * math.pi / 12
    z = np.full(12, 0.05)
    z[5] = 0.0
    points = np.column_stack([np.cos(angles), np.sin(angles), z])
    count, *chosen = cp.reduce_manifold(points, (0.0, 0.0, 1.0), 0.1, 0.0)
    assert count == 4 and chosen[0] == 5
    assert chosen[1] == 11  # opposite the deepest
    # The largest quadrilateral on a 12-gon through two opposite points is the square of area 2.
    assert area_2d(points[chosen]) == pytest.approx(2.0, abs=1e-12)


def test_reduce_manifold_keeps_the_corner_that_comes_down_next_over_wider_ones_higher_up():
    # A hull tipped onto one corner (index 0): a corner 1.4 cm up and 34 cm away (index 1) is the next to come down
    # as it tips on, and must not lose its place to three wider ones 8.3-8.5 cm up (issue 44: it went 3.5 cm into
    # the ground within a 240 Hz step). Chosen by spread alone, it was the one left out.
    points = np.array([
        (0.0, 0.0, 0.0), (0.34, 0.0, 0.014), (0.45, 0.1, 0.083), (0.2, 0.45, 0.084), (0.2, -0.45, 0.085),
    ])  # fmt: skip
    count, *chosen = cp.reduce_manifold(points, (0.0, 0.0, 1.0), 0.0, 0.1)
    assert count == 4 and chosen[:2] == [0, 1]
    # Tilted less than the slope preference (tan 2.9°), a face keeps its widest spread: the far corner second.
    flat = points.copy()
    flat[:, 2] = 0.01 * np.hypot(flat[:, 0], flat[:, 1]) * np.array([0.0, 1.0, 4.0, 4.0, 4.0])
    count, *chosen = cp.reduce_manifold(flat, (0.0, 0.0, 1.0), 0.0, 0.1)
    assert count == 4 and chosen[:2] == [0, 3]


def test_reduce_manifold_drops_duplicates_and_points_beyond_the_margin():
    # Three equally deep points: the anchor is the one farthest from their centroid (index 2), then the first of
    # the two duplicates; the fourth is beyond the margin.
    points = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 0.0, 5.0))
    assert cp.reduce_manifold(points, (0.0, 0.0, 1.0), 0.0, 0.5) == (2, 2, 0, -1, -1)
    assert cp.reduce_manifold(points, (0.0, 0.0, 1.0), 0.0, -0.5)[0] == 0
