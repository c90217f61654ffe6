"""Ray casts: closed-form hits on every shape type, misses, rays from inside, poses, limits and filters."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tumble import shapes as S
from tumble.geometry.packing import pack_geometry
from tumble.geometry.raycast import RayHit, cast_ray
from tumble.rotation import quat_from_axis_angle, quat_normalize, quat_rotate

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
X, Y, Z = np.eye(3)


def world(shapes, body_pos=None, body_quat=None, pos_local=None, quat_local=None):
    """Each shape on its own body; returns ``(geom, body_pos, body_quat)``."""
    n = len(shapes)
    geom = pack_geometry(
        shapes,
        np.arange(n),
        np.zeros((n, 3)) if pos_local is None else np.asarray(pos_local, float).reshape(n, 3),
        np.tile(IDENTITY, (n, 1)) if quat_local is None else np.asarray(quat_local, float).reshape(n, 4),
    )
    body_pos = np.zeros((n, 3)) if body_pos is None else np.asarray(body_pos, float).reshape(n, 3)
    body_quat = np.tile(IDENTITY, (n, 1)) if body_quat is None else np.asarray(body_quat, float).reshape(n, 4)
    return geom, body_pos, body_quat


def cast(shape, origin, direction, max_distance=math.inf, **kwargs) -> RayHit | None:
    return cast_ray(*world([shape]), origin, direction, max_distance, **kwargs)


def assert_hit(hit, distance, point, normal, tol=1e-12):
    """Closed forms on metre-sized shapes: round-off only (measured worst 3.3e-16 over this file)."""
    assert hit is not None, "expected a hit"
    assert hit.distance == pytest.approx(distance, abs=tol)
    np.testing.assert_allclose(hit.point, point, atol=tol)
    np.testing.assert_allclose(hit.normal, normal, atol=tol)


# --- closed forms, shape by shape ------------------------------------------------------------------------


def test_sphere():
    # |(-5 + t, 0.3, 0)| = 1 at t = 5 - sqrt(1 - 0.09).
    t = 5.0 - math.sqrt(1.0 - 0.09)
    assert_hit(cast(S.Sphere(1.0), (-5, 0.3, 0), X), t, (t - 5, 0.3, 0), (t - 5, 0.3, 0))
    assert cast(S.Sphere(1.0), (-5, 1.01, 0), X) is None  # passes by
    assert cast(S.Sphere(1.0), (5, 0.3, 0), X) is None  # behind the origin


@pytest.mark.parametrize("axis", range(3))
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_box_every_face(axis, sign):
    half = np.array([0.5, 1.0, 1.5])
    e = np.eye(3)[axis]
    offset = np.array([0.1, -0.2, 0.3]) * (1 - e)  # off centre on the face
    hit = cast(S.Box(2 * half), 5.0 * sign * e + offset, -sign * e)
    assert_hit(hit, 5.0 - half[axis], sign * half[axis] * e + offset, sign * e)


def test_box_oblique_and_miss():
    d = np.array([1.0, 0.1, 0.0]) / math.hypot(1.0, 0.1)
    # Enters through x = -0.5 where y = 0.2 + 0.1 * 1.5 = 0.35 (< 0.5: on the face).
    assert_hit(cast(S.Box((1, 1, 1)), (-2, 0.2, 0.1), d), 1.5 / d[0], (-0.5, 0.35, 0.1), -X)
    assert cast(S.Box((1, 1, 1)), (-2, 0.2, 0.6), X) is None  # above the top face, parallel to it
    assert cast(S.Box((1, 1, 1)), (-2, 0.2, 0.5), X) is not None  # grazing the top face counts


def test_capsule_side_cap_and_end_sphere():
    capsule = S.Capsule(0.5, 2.0)  # segment z in [-1, 1]
    assert_hit(cast(capsule, (5, 0, 0.3), -X), 4.5, (0.5, 0, 0.3), X)
    assert_hit(cast(capsule, (0, 0, 5), -Z), 3.5, (0, 0, 1.5), Z)
    assert_hit(cast(capsule, (0, 0, -5), Z), 3.5, (0, 0, -1.5), -Z)
    # Down at x = 0.3: the top sphere at z = 1 + sqrt(0.25 - 0.09) = 1.4.
    assert_hit(cast(capsule, (0.3, 0, 5), -Z), 3.6, (0.3, 0, 1.4), (0.6, 0, 0.8))
    # Sideways above the segment's end, through the sphere: at z = 1.3 the sphere's radius is 0.4.
    assert_hit(cast(capsule, (5, 0, 1.3), -X), 4.6, (0.4, 0, 1.3), (0.8, 0, 0.6))
    assert cast(capsule, (0.51, 0, 5), -Z) is None  # parallel to the axis, outside the radius
    assert cast(capsule, (5, 0, 1.51), -X) is None  # over the top


def test_cylinder_side_caps_and_rim():
    cylinder = S.Cylinder(1.0, 1.0)  # |z| <= 0.5
    assert_hit(cast(cylinder, (0, -4, 0.2), Y), 3.0, (0, -1, 0.2), -Y)
    assert_hit(cast(cylinder, (0.3, 0.4, 5), -Z), 4.5, (0.3, 0.4, 0.5), Z)
    assert_hit(cast(cylinder, (0.3, 0.4, -5), Z), 4.5, (0.3, 0.4, -0.5), -Z)
    # Slanted onto the top cap: at z = 0.5, x = 0.1 * 4.5 = 0.45 < r.
    d = np.array([0.1, 0.0, -1.0]) / math.hypot(0.1, 1.0)
    assert_hit(cast(cylinder, (0, 0, 5), d), 4.5 / -d[2], (0.45, 0, 0.5), Z)
    # Diagonal through the rim region from the side, below the cap: the side.
    d = np.array([-1.0, 0.0, -0.1]) / math.hypot(1.0, 0.1)
    assert_hit(cast(cylinder, (3, 0, 0.45), d), 2.0 / -d[0], (1.0, 0, 0.25), X)
    assert cast(cylinder, (1.01, 0, 5), -Z) is None  # just outside the rim
    assert cast(cylinder, (5, 0, 0.51), -X) is None  # just above the top


def test_convex_hull_matches_the_box_it_spans():
    corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-1, 1) for z in (-1.5, 1.5)])
    hull, box = S.ConvexHull(corners), S.Box((1, 2, 3))
    rng = np.random.default_rng(3)
    hits = 0
    for _ in range(60):
        origin = rng.normal(size=3) * 4.0
        direction = -origin / np.linalg.norm(origin) + rng.normal(size=3) * 0.15
        a, b = cast(hull, origin, direction), cast(box, origin, direction)
        assert (a is None) == (b is None)
        if a is not None:
            hits += 1
            # The same slab arithmetic through face planes: measured identical (0 difference).
            assert a.distance == pytest.approx(b.distance, abs=1e-12)
            np.testing.assert_allclose(a.normal, b.normal, atol=1e-12)
    assert hits > 30


def test_convex_hull_tetrahedron():
    tetra = S.ConvexHull([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    # The slanted face x + y + z = 1, from the far side of it along -(1, 1, 1).
    d = -np.ones(3) / math.sqrt(3)
    assert_hit(cast(tetra, (1, 1, 1), d), 2 / math.sqrt(3), np.full(3, 1 / 3), -d)
    assert_hit(cast(tetra, (0.2, 0.2, -3), Z), 3.0, (0.2, 0.2, 0), -Z)
    assert cast(tetra, (0.6, 0.6, -3), Z) is None  # x + y = 1.2 > 1: beside the hull


def test_plane():
    plane = S.Plane((0, 0, 1), 0.5)
    assert_hit(cast(plane, (1, 2, 3), -Z), 2.5, (1, 2, 0.5), Z)
    assert cast(plane, (1, 2, 3), Z) is None  # away from it
    assert cast(plane, (1, 2, 3), X) is None  # parallel
    tilted = S.Plane((1, 0, 1), 0.0)  # n = (1, 0, 1)/√2
    d = -X
    assert_hit(cast(tilted, (2, 0, 0), d), 2.0, (0, 0, 0), np.array([1, 0, 1]) / math.sqrt(2))


def test_triangle_mesh_is_two_sided():
    mesh = S.TriMesh([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[0, 1, 2]])  # normal +z
    assert_hit(cast(mesh, (0.5, 0.5, 3), -Z), 3.0, (0.5, 0.5, 0), Z)
    assert_hit(cast(mesh, (0.5, 0.5, -3), Z), 3.0, (0.5, 0.5, 0), -Z)  # from below: the normal faces the ray
    assert cast(mesh, (1.5, 1.5, 3), -Z) is None  # outside the triangle (u + v > 1)
    assert cast(mesh, (0.5, 0.5, 3), X) is None  # parallel


def test_closed_mesh_reports_the_nearest_face_from_outside_and_inside():
    vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    mesh = S.TriMesh(vertices, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    assert_hit(cast(mesh, (0.2, 0.2, -3), Z), 3.0, (0.2, 0.2, 0), -Z)
    # A mesh is a surface: from inside the ray reports the wall it crosses, not distance 0.
    assert_hit(cast(mesh, (0.2, 0.2, 0.2), -Z), 0.2, (0.2, 0.2, 0), Z)


# --- rays starting inside --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "shape",
    [
        S.Sphere(1.0),
        S.Box((1, 1, 1)),
        S.Capsule(0.3, 1.0),
        S.Cylinder(0.5, 1.0),
        S.ConvexHull([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]),
        S.Plane((0, 0, 1), 0.3),
    ],
)
def test_ray_starting_inside_hits_at_distance_zero_facing_back(shape):
    direction = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    origin = np.array([0.05, 0.1, 0.2])
    assert_hit(cast(shape, origin, direction), 0.0, origin, -direction, tol=1e-15)
    assert_hit(cast(shape, origin, direction, 0.0), 0.0, origin, -direction, tol=1e-15)


# --- poses -----------------------------------------------------------------------------------------------


def carry(pose, v, translate=True):
    """A shape-frame point (or, with ``translate=False``, vector) in the world."""
    body_pos, body_quat, pos_local, quat_local = pose
    v = quat_rotate(body_quat, quat_rotate(quat_local, v) + (pos_local if translate else 0.0))
    return v + body_pos if translate else v


@pytest.mark.parametrize(
    "shape",
    [
        S.Sphere(0.7),
        S.Box((0.6, 1.0, 1.4)),
        S.Capsule(0.3, 1.2),
        S.Cylinder(0.5, 1.2),
        S.ConvexHull(np.random.default_rng(0).normal(size=(12, 3))),
        S.TriMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
        S.Plane((0.2, 0.3, 1.0), 0.1),
    ],
)
def test_rigid_motion_moves_the_hit_with_the_shape(shape):
    """A ray in the shape frame, and the same ray carried by the shape's local and body poses: the same distance,
    with the point and normal carried along."""
    rng = np.random.default_rng(11)
    target = np.zeros(3) if shape.vertices is None else shape.vertices.mean(axis=0)  # inside the shape
    hits = 0
    for _ in range(12):
        body_pos, body_quat = rng.normal(size=3), quat_normalize(rng.normal(size=4))
        pos_local, quat_local = rng.normal(size=3) * 0.5, quat_normalize(rng.normal(size=4))
        origin = target + rng.normal(size=3) * 3.0
        direction = target + rng.normal(size=3) * 0.1 - origin
        direction /= np.linalg.norm(direction)
        local = cast(shape, origin, direction)
        pose = (body_pos, body_quat, pos_local, quat_local)
        moved = cast_ray(
            *world([shape], [body_pos], [body_quat], [pos_local], [quat_local]),
            carry(pose, origin),
            carry(pose, direction, translate=False),
        )
        assert (local is None) == (moved is None)
        if local is not None:
            hits += 1
            # Rotations round at 1e-16 relative; distances of a few metres: measured worst 1e-14.
            assert moved.distance == pytest.approx(local.distance, abs=1e-12)
            np.testing.assert_allclose(moved.point, carry(pose, local.point), atol=1e-12)
            np.testing.assert_allclose(moved.normal, carry(pose, local.normal, translate=False), atol=1e-12)
    assert hits >= 6


# --- limits, several shapes, filters, inputs --------------------------------------------------------------


def test_max_distance_is_inclusive():
    assert cast(S.Box((1, 1, 1)), (0, 0, 3), -Z, 2.5) is not None
    assert cast(S.Box((1, 1, 1)), (0, 0, 3), -Z, 2.5 - 1e-9) is None
    assert cast(S.Plane(), (0, 0, 3), -Z, 2.999) is None
    assert cast(S.Sphere(1.0), (0, 0, 3), -Z, 0.0) is None


def test_closest_of_several_shapes_wins_and_ties_go_to_the_lower_index():
    shapes = [S.Box((1, 1, 1)), S.Sphere(0.5), S.Sphere(0.5), S.Plane()]
    geom, body_pos, body_quat = world(shapes, [[0, 0, 0.5], [3, 0, 2.0], [3, 0, 2.0], [0, 0, 0]])
    hit = cast_ray(geom, body_pos, body_quat, (0, 0, 10), -Z)
    assert (hit.shape, hit.distance) == (0, pytest.approx(9.0))
    hit = cast_ray(geom, body_pos, body_quat, (3, 0, 10), -Z)
    assert (hit.shape, hit.distance) == (1, pytest.approx(7.5))
    hit = cast_ray(geom, body_pos, body_quat, (-3, 0, 10), -Z)
    assert (hit.shape, hit.distance) == (3, pytest.approx(10.0))
    assert cast_ray(geom, body_pos, body_quat, (-3, 0, 10), Z) is None


def test_ray_mask_skips_shapes_outside_its_groups():
    shapes = [S.Box((1, 1, 1)), S.Plane()]
    geom, body_pos, body_quat = world(shapes, [[0, 0, 0.5], [0, 0, 0]])
    group = np.array([2, 1], np.uint32)
    assert cast_ray(geom, body_pos, body_quat, (0, 0, 10), -Z, shape_group=group).shape == 0
    assert cast_ray(geom, body_pos, body_quat, (0, 0, 10), -Z, shape_group=group, ray_mask=1).shape == 1
    assert cast_ray(geom, body_pos, body_quat, (0, 0, 10), -Z, shape_group=group, ray_mask=4) is None


def test_direction_is_normalised():
    a = cast(S.Sphere(1.0), (0, 0, 5), (0, 0, -7.0))
    assert_hit(a, 4.0, (0, 0, 1), Z)


def test_far_shapes_are_culled_but_long_rays_reach_them():
    hit = cast_ray(*world([S.Sphere(1.0)], [[1e4, 0, 0]]), (0, 0, 0), X)
    assert hit.distance == pytest.approx(1e4 - 1.0)
    turned = quat_from_axis_angle(Y, 0.5 * math.pi)  # the capsule lies along x
    hit = cast_ray(*world([S.Capsule(0.5, 4.0)], [[0, 0, 0]], [turned]), (10, 0, 0), -X)
    assert_hit(hit, 7.5, (2.5, 0, 0), X)


@pytest.mark.parametrize(
    ("origin", "direction", "max_distance"),
    [((0, 0, math.nan), (1, 0, 0), 1.0), ((0, 0, 0), (0, 0, 0), 1.0), ((0, 0, 0), (1, 0, 0), -1.0), ((0, 0), Z, 1.0)],
)
def test_bad_input_raises(origin, direction, max_distance):
    with pytest.raises(ValueError):
        cast(S.Sphere(1.0), origin, direction, max_distance)
