"""World.query_overlap: which bodies a shape placed at a pose overlaps, by the narrow phase's own kernels."""

from __future__ import annotations

import math

import numpy as np
import pytest

import tumble
from tumble.geometry.overlap import append_geometry
from tumble.geometry.packing import pack_geometry

CUBE = [[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]


def tetra_mesh(size=1.0):
    """A closed, outward-wound tetrahedron with corners at the origin and on the three axes."""
    vertices = size * np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    return tumble.TriMesh(vertices, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def floor_mesh(half=2.0):
    """A flat square of two triangles in z = 0, facing up."""
    v = [[-half, -half, 0.0], [half, -half, 0.0], [half, half, 0.0], [-half, half, 0.0]]
    return tumble.TriMesh(v, [[0, 1, 2], [0, 2, 3]])


@pytest.fixture
def scene():
    """A ground plane, a unit box at x = 0, a sphere of radius 0.5 at x = 3 and a mesh floor far off at x = 20."""
    world = tumble.World()
    plane = world.add_static(tumble.Plane(), name="ground")
    box = world.add_body(tumble.Box((1.0, 1.0, 1.0)), density=100.0, position=(0.0, 0.0, 2.0), name="box")
    ball = world.add_body(tumble.Sphere(0.5), density=100.0, position=(3.0, 0.0, 2.0), name="ball")
    mesh = world.add_static(floor_mesh(), position=(20.0, 0.0, 5.0), name="mesh")
    return world, plane, box, ball, mesh


QUERY_SHAPES = [
    tumble.Sphere(0.25),
    tumble.Box((0.5, 0.5, 0.5)),
    tumble.Capsule(0.25, 0.5),
    tumble.Cylinder(0.25, 0.5),
    tumble.ConvexHull(0.5 * np.array(CUBE)),
]


@pytest.mark.parametrize("query", QUERY_SHAPES, ids=lambda s: type(s).__name__)
def test_each_convex_kind_finds_the_plane_box_sphere_and_mesh_it_sinks_into(scene, query):
    world, plane, box, ball, mesh = scene
    # Every query shape reaches at most 0.5 from its origin along z (the capsule exactly 0.5).
    assert world.query_overlap(query, (10.0, 0.0, 0.2)) == [plane]
    assert world.query_overlap(query, (10.0, 0.0, 0.6)) == []
    assert world.query_overlap(query, (0.0, 0.0, 2.45)) == [box]
    assert world.query_overlap(query, (3.0, 0.0, 2.6)) == [ball]
    assert world.query_overlap(query, (20.5, 0.3, 5.1)) == [mesh]
    assert world.query_overlap(query, (20.5, 0.3, 5.6)) == []
    assert world.query_overlap(query, (0.0, 0.0, 10.0)) == []


def test_no_overlap_just_apart_from_each_kind(scene):
    world, *_ = scene
    probe = tumble.Sphere(0.25)
    gap = 1e-6
    assert world.query_overlap(probe, (10.0, 0.0, 0.25 + gap)) == []  # above the plane
    assert world.query_overlap(probe, (0.0, 0.0, 2.75 + gap)) == []  # above the box
    assert world.query_overlap(probe, (3.75 + gap, 0.0, 2.0)) == []  # beside the ball
    assert world.query_overlap(probe, (20.5, 0.3, 5.25 + gap)) == []  # above the mesh


def test_touching_exactly_counts_as_overlap(scene):
    world, plane, box, ball, mesh = scene
    probe = tumble.Sphere(0.25)
    # Dyadic numbers: every separation below comes out exactly 0.
    assert world.query_overlap(probe, (10.0, 0.0, 0.25)) == [plane]
    assert world.query_overlap(probe, (0.0, 0.0, 2.75)) == [box]
    assert world.query_overlap(probe, (3.75, 0.0, 2.0)) == [ball]
    assert world.query_overlap(tumble.Box((0.5, 0.5, 0.5)), (0.0, 0.0, 2.75)) == [box]
    assert world.query_overlap(tumble.Box((0.5, 0.5, 0.5)), (10.0, 0.0, 0.25)) == [plane]


def test_results_are_every_overlapping_body_once_sorted_by_index():
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    bodies = [
        world.add_body(tumble.Sphere(0.3), density=100.0, position=(x, 0.0, 0.0))
        for x in (2.0, -2.0, 0.0, 1.0, -1.0, 5.0)
    ]
    # A compound body: two of its shapes overlap the query, it is listed once.
    pair = world.add_body(
        [(tumble.Box((0.2, 0.2, 0.2)), (0.0, 0.5, 0.0)), (tumble.Box((0.2, 0.2, 0.2)), (0.0, -0.5, 0.0))],
        density=100.0,
    )
    long_box = tumble.Box((4.8, 1.2, 0.2))
    found = world.query_overlap(long_box)
    assert found == [bodies[0], bodies[1], bodies[2], bodies[3], bodies[4], pair]
    assert [b.index for b in found] == sorted(b.index for b in found)


def test_the_pose_places_the_query_shape():
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    target = world.add_body(tumble.Sphere(0.1), density=100.0, position=(0.0, 0.0, 0.9))
    stick = tumble.Capsule(0.05, 1.0)  # along z, reaching z = ±0.55
    assert world.query_overlap(stick, (0.0, 0.0, 0.0)) == []
    assert world.query_overlap(stick, (0.0, 0.0, 0.4)) == [target]
    # Laid along x it misses the target above it; turned back up (about y) it reaches it.
    along_x = tumble.rotation.quat_from_axis_angle((0.0, 1.0, 0.0), math.pi / 2)
    assert world.query_overlap(stick, (0.0, 0.0, 0.4), along_x) == []
    assert world.query_overlap(stick, (0.0, 0.0, 0.4), orientation=(2.0, 0.0, 0.0, 0.0)) == [target]  # normalised


def test_bodies_are_tested_where_they_are_now():
    world = tumble.World()
    world.add_static(tumble.Plane())
    ball = world.add_body(tumble.Sphere(0.1), density=100.0, position=(0.0, 0.0, 1.0))
    probe = tumble.Box((0.4, 0.4, 0.1))
    assert ball in world.query_overlap(probe, (0.0, 0.0, 1.0))
    ball.position = (5.0, 0.0, 1.0)
    assert ball not in world.query_overlap(probe, (0.0, 0.0, 1.0))
    assert ball in world.query_overlap(probe, (5.0, 0.0, 1.0))


def test_mask_filters_by_collision_group():
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    plane = world.add_static(tumble.Plane(), collision_group=0b001)
    red = world.add_body(tumble.Sphere(0.5), density=100.0, position=(0, 0, 0.5), collision_group=0b010)
    blue = world.add_body(tumble.Sphere(0.5), density=100.0, position=(0.5, 0, 0.5), collision_group=0b110)
    # collision_mask plays no part (as for rays): only the group against the query's mask.
    quiet = world.add_body(tumble.Sphere(0.5), density=100.0, position=(-0.5, 0, 0.5), collision_mask=0)
    probe, at = tumble.Sphere(0.3), (0.0, 0.0, 0.3)
    assert world.query_overlap(probe, at) == [plane, red, blue, quiet]
    assert world.query_overlap(probe, at, mask=0b001) == [plane, quiet]
    assert world.query_overlap(probe, at, mask=0b010) == [red, blue]
    assert world.query_overlap(probe, at, mask=0b100) == [blue]
    assert world.query_overlap(probe, at, mask=np.uint32(0b1000)) == []
    assert world.query_overlap(probe, at, mask=0) == []


def test_an_empty_world_and_a_world_without_shapes_overlap_nothing():
    world = tumble.World()
    assert world.query_overlap(tumble.Sphere(1.0)) == []
    world.add_body(None, mass=1.0, inertia=np.eye(3))
    assert world.query_overlap(tumble.Sphere(1.0)) == []


def test_a_mesh_is_a_surface_and_a_plane_a_half_space():
    world = tumble.World()
    mesh = world.add_static(tetra_mesh(3.0), position=(0.0, 0.0, 10.0))
    plane = world.add_static(tumble.Plane())
    small = tumble.Sphere(0.1)
    # Deep inside the closed mesh, no triangle within reach: the surface is not crossed.
    assert world.query_overlap(small, (0.5, 0.5, 10.5)) == []
    assert world.query_overlap(small, (0.5, 0.5, 10.05)) == [mesh]  # through the bottom face
    # Far below the plane is still inside its solid side.
    assert world.query_overlap(small, (0.0, 0.0, -100.0)) == [plane]


def test_a_query_leaves_the_world_as_it_was():
    world = tumble.World()
    world.add_static(tumble.Plane())
    world.add_body(tumble.Box((0.4, 0.4, 0.4)), density=500.0, position=(0.0, 0.0, 0.2))
    world.simulate(0.25, 1 / 60)
    before, contacts = world.state.digest(), len(world.contacts())
    world.query_overlap(tumble.Sphere(1.0))
    assert world.state.digest() == before and len(world.contacts()) == contacts
    # The next step is the same as in a twin world that was never queried.
    twin = tumble.World()
    twin.add_static(tumble.Plane())
    twin.add_body(tumble.Box((0.4, 0.4, 0.4)), density=500.0, position=(0.0, 0.0, 0.2))
    twin.simulate(0.25, 1 / 60)
    world.step(1 / 60)
    twin.step(1 / 60)
    assert world.state.digest() == twin.state.digest()


def test_appended_geometry_equals_packing_everything_at_once():
    shapes = [tumble.ConvexHull(CUBE), tumble.Sphere(1.0), floor_mesh(), tumble.Box((1, 2, 3)), tetra_mesh()]
    extra = [tumble.ConvexHull(0.3 * np.array(CUBE) + 0.1), tumble.Cylinder(0.5, 1.0)]
    rng = np.random.default_rng(7)
    pos = rng.normal(size=(len(shapes) + len(extra), 3))
    quat = rng.normal(size=(len(shapes) + len(extra), 4))
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    bodies = [0, 0, 1, 2, 3, 4, 4]
    n = len(shapes)
    together = pack_geometry(shapes + extra, bodies, pos, quat)
    appended = append_geometry(
        pack_geometry(shapes, bodies[:n], pos[:n], quat[:n]), pack_geometry(extra, bodies[n:], pos[n:], quat[n:])
    )
    for name in together._fields:
        a, b = getattr(together, name), getattr(appended, name)
        assert a.dtype == b.dtype and a.shape == b.shape, name
        np.testing.assert_array_equal(a, b, err_msg=name)


# --- bad input -----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("shape", "error", "message"),
    [
        (tumble.Plane(), ValueError, r"shape must be a Sphere, Box, Capsule, Cylinder or ConvexHull .*got Plane\("),
        (floor_mesh(), ValueError, r"shape must be .*got TriMesh\("),
        ("box", TypeError, r"shape must be .*got 'box' \(str\)"),
        (None, TypeError, r"shape must be .*got None"),
        ([(tumble.Sphere(1.0), (0, 0, 0))], TypeError, r"shape must be .*\(list\)"),
    ],
)
def test_query_shape_must_be_a_convex_solid(scene, shape, error, message):
    world, *_ = scene
    with pytest.raises(error, match=message):
        world.query_overlap(shape)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"position": (0.0, 0.0, math.nan)}, ValueError, r"position must be finite, got \[0.0, 0.0, nan\]"),
        ({"position": (0.0, math.inf, 0.0)}, ValueError, r"position must be finite, got \[0.0, inf, 0.0\]"),
        ({"position": (0.0, 0.0)}, ValueError, r"position must have shape \(3\)"),
        ({"position": "origin"}, TypeError, r"position must be an array of numbers"),
        ({"orientation": (math.nan, 0.0, 0.0, 0.0)}, ValueError, r"orientation must be finite, got \[nan"),
        ({"orientation": (0.0, 0.0, 0.0, 0.0)}, ValueError, r"orientation must be a non-zero quaternion"),
        ({"orientation": (1.0, 0.0, 0.0)}, ValueError, r"orientation must have shape \(4\)"),
        ({"mask": -1}, ValueError, r"mask must be an integer of 32 bits .*got -1"),
        ({"mask": 1 << 32}, ValueError, r"mask must be an integer of 32 bits .*got 4294967296"),
        ({"mask": 1.0}, TypeError, r"mask must be an integer of 32 bits .*got 1.0 \(float\)"),
        ({"mask": True}, TypeError, r"mask must be an integer of 32 bits .*got True \(bool\)"),
    ],
)
def test_bad_pose_or_mask_is_refused_naming_argument_and_value(scene, kwargs, error, message):
    world, *_ = scene
    with pytest.raises(error, match=message):
        world.query_overlap(tumble.Sphere(0.5), **kwargs)


def test_mask_is_keyword_only(scene):
    world, *_ = scene
    with pytest.raises(TypeError):
        world.query_overlap(tumble.Sphere(0.5), (0, 0, 0), (1, 0, 0, 0), 1)
