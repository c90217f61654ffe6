"""Bad input for contact scenes: degenerate hulls, zero-extent shapes, non-finite poses, a dynamic plane or mesh,
bad solver settings and collision filters. Each raises a clear error naming the argument and the bad value, and a
refused call leaves the world as it was."""

from __future__ import annotations

import math

import numpy as np
import pytest

import tumble

NAN, INF = math.nan, math.inf
SQUARE = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]


def tetra_mesh():
    vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    return tumble.TriMesh(vertices, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


# --- degenerate hulls ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("points", "message"),
    [
        (SQUARE + [[0.5, 0.5, 0.0]], r"points must span a volume, but the 5 points are coplanar: \[\[0.0, 0.0, 0.0\]"),
        (SQUARE, r"points must span a volume, but the 4 points are coplanar: \[\["),
        ([[k, 2.0 * k, -k] for k in range(6)], r"points must span a volume, but the 6 points are collinear: \[\["),
        ([[1.0, 2.0, 3.0]] * 5, r"points must span a volume, got 5 copies of one point \[1.0, 2.0, 3.0\]"),
        # Duplicates do not add a dimension: three distinct corners of a triangle, one of them twice.
        ([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], r"the 4 points are coplanar"),
        # 1e-12 m thin over 1 m: Qhull builds it, but it encloses no usable volume.
        (SQUARE + [[0.5, 0.5, 1e-12]], r"points span no usable volume .*encloses zero volume"),
    ],
    ids=["coplanar", "square", "collinear", "one-point", "duplicates", "sliver"],
)
def test_a_hull_without_volume_is_refused(points, message):
    with pytest.raises(ValueError, match=message):
        tumble.ConvexHull(points)


@pytest.mark.parametrize(
    ("points", "error", "message"),
    [
        ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], ValueError, r"n >= 4 .*got shape \(3, 3\): \[\[0.0"),
        ([[0.0, 0.0, 0.0]], ValueError, r"n >= 4 .*got shape \(1, 3\)"),
        ([1.0, 2.0, 3.0], ValueError, r"points must have shape \(n, 3\) .*got shape \(3,\)"),
        (np.zeros((4, 2)), ValueError, r"points must have shape"),
        # (The value is shown to 80 characters, so the bad entry is put first.)
        ([[0.0, 0.0, NAN]] + SQUARE, ValueError, r"points must be finite, got \[\[0.0, 0.0, nan\]"),
        ([[0.0, INF, 1.0]] + SQUARE, ValueError, r"points must be finite, got \[\[0.0, inf, 1.0\]"),
        (None, TypeError, r"points must be an array of numbers"),
        ([["a", "b", "c"]] * 4, TypeError, r"points must be an array of numbers"),
    ],
)
def test_hull_points_of_the_wrong_shape_or_not_finite_are_refused(points, error, message):
    with pytest.raises(error, match=message):
        tumble.ConvexHull(points)


# --- zero-extent primitives ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("make", "error", "message"),
    [
        (lambda: tumble.Box((0.0, 1.0, 1.0)), ValueError, r"extents must be > 0 .*got \[0.0, 1.0, 1.0\]"),
        (lambda: tumble.Box((1.0, -1.0, 1.0)), ValueError, r"extents must be > 0 .*got \[1.0, -1.0, 1.0\]"),
        (lambda: tumble.Box((1.0, 1.0, NAN)), ValueError, r"extents must be finite, got \[1.0, 1.0, nan\]"),
        (lambda: tumble.Box(1.0), ValueError, r"extents must have shape \(3\)"),
        (lambda: tumble.Box("big"), TypeError, r"extents must be an array of numbers"),
        (lambda: tumble.Sphere(0), ValueError, r"radius must be > 0, got 0.0"),
        (lambda: tumble.Sphere(-0.5), ValueError, r"radius must be > 0, got -0.5"),
        (lambda: tumble.Sphere(INF), ValueError, r"radius must be finite, got inf"),
        (lambda: tumble.Sphere("1"), TypeError, r"radius must be a real number, got '1' \(str\)"),
        (lambda: tumble.Sphere(True), TypeError, r"radius must be a real number, got True \(bool\)"),
        (lambda: tumble.Capsule(0.0, 1.0), ValueError, r"radius must be > 0, got 0.0"),
        (lambda: tumble.Capsule(0.5, -1.0), ValueError, r"length must be >= 0, got -1.0"),
        (lambda: tumble.Capsule(0.5, NAN), ValueError, r"length must be finite, got nan"),
        (lambda: tumble.Cylinder(0.0, 1.0), ValueError, r"radius must be > 0, got 0.0"),
        (lambda: tumble.Cylinder(0.5, -1.0), ValueError, r"height must be > 0, got -1.0"),
        (lambda: tumble.Cylinder(0.5, 0.0), ValueError, r"height must be > 0, got 0.0"),
        (lambda: tumble.Plane((0.0, 0.0, 0.0)), ValueError, r"normal must be a non-zero vector, got \[0.0, 0.0, 0.0\]"),
        (lambda: tumble.Plane(offset=NAN), ValueError, r"offset must be finite, got nan"),
    ],
)
def test_zero_negative_or_non_finite_sizes_are_refused(make, error, message):
    with pytest.raises(error, match=message):
        make()


def test_a_capsule_of_zero_length_is_a_sphere_and_allowed():
    capsule = tumble.Capsule(0.5, 0.0)
    assert capsule.volume == pytest.approx(tumble.Sphere(0.5).volume)


# --- non-finite poses and velocities ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"position": (0.0, 0.0, NAN)}, r"position must be finite, got \[0.0, 0.0, nan\]"),
        ({"position": (INF, 0.0, 0.0)}, r"position must be finite, got \[inf, 0.0, 0.0\]"),
        ({"orientation": (NAN, 0.0, 0.0, 0.0)}, r"orientation must be finite, got \[nan, 0.0, 0.0, 0.0\]"),
        ({"orientation": (1.0, 0.0, -INF, 0.0)}, r"orientation must be finite, got \[1.0, 0.0, -inf, 0.0\]"),
        (
            {"orientation": (0.0, 0.0, 0.0, 0.0)},
            r"orientation must be a non-zero quaternion .*got \[0.0, 0.0, 0.0, 0.0\]",
        ),
        ({"velocity": (0.0, NAN, 0.0)}, r"velocity must be finite, got \[0.0, nan, 0.0\]"),
        ({"velocity": (1e400, 0.0, 0.0)}, r"velocity must be finite, got \[inf, 0.0, 0.0\]"),
        ({"angular_velocity": (0.0, 0.0, INF)}, r"angular_velocity must be finite, got \[0.0, 0.0, inf\]"),
    ],
)
def test_add_body_refuses_non_finite_poses_and_velocities(kwargs, message):
    world = tumble.World()
    with pytest.raises(ValueError, match=message):
        world.add_body(tumble.Box((1.0, 1.0, 1.0)), mass=1.0, **kwargs)
    assert world.bodies == []


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"position": (NAN, 0.0, 0.0)}, r"position must be finite, got \[nan, 0.0, 0.0\]"),
        ({"position": (0.0, 0.0, -INF)}, r"position must be finite, got \[0.0, 0.0, -inf\]"),
        ({"orientation": (1.0, NAN, 0.0, 0.0)}, r"orientation must be finite, got \[1.0, nan, 0.0, 0.0\]"),
        ({"orientation": (0.0, 0.0, 0.0, 0.0)}, r"orientation must be a non-zero quaternion"),
    ],
)
@pytest.mark.parametrize("shape", [tumble.Plane(), tetra_mesh(), tumble.Box((1.0, 1.0, 1.0))], ids=repr)
def test_add_static_refuses_non_finite_poses(shape, kwargs, message):
    world = tumble.World()
    with pytest.raises(ValueError, match=message):
        world.add_static(shape, **kwargs)
    assert world.bodies == []


def test_a_compound_part_with_a_non_finite_pose_is_named_by_its_place():
    world = tumble.World()
    parts = [(tumble.Sphere(0.5), (0.0, 0.0, 0.0)), (tumble.Sphere(0.5), (0.0, NAN, 0.0))]
    with pytest.raises(ValueError, match=r"shape\[1\] position must be finite, got \[0.0, nan, 0.0\]"):
        world.add_body(parts, mass=1.0)
    parts = [(tumble.Sphere(0.5), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0))]
    with pytest.raises(ValueError, match=r"shape\[0\] orientation must be a non-zero quaternion"):
        world.add_static(parts)


# --- a dynamic plane or mesh ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("shape", "message"),
    [
        (
            tumble.Plane(),
            r"shape cannot be a Plane in a dynamic body: .*add_static.*got Plane\(normal=\[0.0, 0.0, 1.0\]",
        ),
        (
            tetra_mesh(),
            r"shape cannot be a TriMesh in a dynamic body: .*add_static.*got TriMesh\(<4 vertices, 4 faces>\)",
        ),
    ],
    ids=["plane", "mesh"],
)
@pytest.mark.parametrize(
    "amount", [{"mass": 1.0}, {"density": 1000.0}, {}, {"mass": 1.0, "inertia": np.eye(3)}], ids=repr
)
def test_a_plane_or_mesh_cannot_be_dynamic(shape, message, amount):
    world = tumble.World()
    with pytest.raises(ValueError, match=message):
        world.add_body(shape, **amount)
    assert world.bodies == []


def test_a_plane_or_mesh_in_a_compound_dynamic_body_is_named_by_its_place():
    world = tumble.World()
    parts = [(tumble.Sphere(0.5), (0.0, 0.0, 0.0)), (tetra_mesh(), (1.0, 0.0, 0.0))]
    with pytest.raises(ValueError, match=r"shape\[1\] cannot be a TriMesh in a dynamic body"):
        world.add_body(parts, mass=1.0)
    # Static, the same parts are fine.
    assert world.add_static(parts).is_static


@pytest.mark.parametrize("shape", [tumble.Plane(), tetra_mesh()], ids=repr)
def test_a_plane_or_mesh_has_no_mass_properties_of_its_own(shape):
    if isinstance(shape, tumble.Plane):
        with pytest.raises(ValueError, match=r"a Plane is static only"):
            shape.mass_properties(mass=1.0)
    else:  # a closed mesh has mass properties; only a dynamic *body* of one is refused
        assert shape.mass_properties(mass=1.0).mass == pytest.approx(1.0)


# --- solver settings -----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("settings", "error", "message"),
    [
        ({"substeps": 0}, ValueError, r"substeps must be an integer >= 1 \(at most \d+\), got 0"),
        ({"substeps": -3}, ValueError, r"substeps must be an integer >= 1 \(at most \d+\), got -3"),
        ({"substeps": 2.5}, TypeError, r"substeps must be an integer >= 1 \(at most \d+\), got 2.5 \(float\)"),
        ({"substeps": True}, TypeError, r"substeps must be an integer >= 1 \(at most \d+\), got True \(bool\)"),
        ({"contact_hertz": -1}, ValueError, r"contact_hertz must be > 0, got -1.0"),
        ({"contact_hertz": 0.0}, ValueError, r"contact_hertz must be > 0, got 0.0"),
        ({"contact_hertz": NAN}, ValueError, r"contact_hertz must be finite, got nan"),
        ({"contact_damping_ratio": -0.1}, ValueError, r"contact_damping_ratio must be >= 0, got -0.1"),
        ({"contact_push_max": 0.0}, ValueError, r"contact_push_max must be > 0, got 0.0"),
        ({"restitution_threshold": INF}, ValueError, r"restitution_threshold must be finite, got inf"),
        ({"speculative_distance": -0.01}, ValueError, r"speculative_distance must be >= 0, got -0.01"),
        ({"speculative_distance": "2cm"}, TypeError, r"speculative_distance must be a real number, got '2cm'"),
        ({"sleep": 1}, TypeError, r"sleep must be True or False, got 1"),
        ({"integrator": "verlet"}, ValueError, r"integrator must be one of .*got 'verlet'"),
    ],
)
def test_bad_solver_settings_are_refused_at_construction(settings, error, message):
    with pytest.raises(error, match=message):
        tumble.World(**settings)


def test_set_solver_refuses_unknown_and_bad_settings_and_keeps_the_old_ones():
    world = tumble.World(substeps=4)
    with pytest.raises(TypeError, match=r"unknown solver setting 'unknown'; settings: \[.*'substeps'"):
        world.set_solver(unknown=1)
    with pytest.raises(ValueError, match=r"contact_hertz must be > 0, got -1.0"):
        world.set_solver(contact_hertz=-1)
    # Nothing of a refused call is applied, not even the good settings given beside the bad one.
    with pytest.raises(ValueError, match=r"substeps must be an integer >= 1 \(at most \d+\), got 0"):
        world.set_solver(contact_hertz=30.0, substeps=0)
    assert world.solver.substeps == 4
    assert world.solver.contact_hertz == tumble.World().solver.contact_hertz


# --- collision filters ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("argument", ["collision_group", "collision_mask"])
@pytest.mark.parametrize(
    ("bits", "error", "shown"),
    [
        (-1, ValueError, "-1"),
        (1 << 32, ValueError, "4294967296"),
        (np.int64(-2), ValueError, "-2"),
        (1.0, TypeError, r"1.0 \(float\)"),
        ("1", TypeError, r"'1' \(str\)"),
        (None, TypeError, r"None \(NoneType\)"),
        (True, TypeError, r"True \(bool\)"),
    ],
)
@pytest.mark.parametrize("static", [False, True], ids=["add_body", "add_static"])
def test_bad_collision_filter_bits_are_refused(argument, bits, error, shown, static):
    world = tumble.World()
    message = rf"{argument} must be an integer of 32 bits \(0 to 0xFFFFFFFF\), got {shown}"
    with pytest.raises(error, match=message):
        if static:
            world.add_static(tumble.Plane(), **{argument: bits})
        else:
            world.add_body(tumble.Sphere(0.5), mass=1.0, **{argument: bits})
    assert world.bodies == []


def test_every_32_bit_filter_value_is_accepted():
    world = tumble.World()
    for bits in (0, 1, 0xFFFFFFFF, np.uint32(0xFFFFFFFF), np.int64(7)):
        world.add_body(tumble.Sphere(0.5), mass=1.0, collision_group=bits, collision_mask=bits)
    assert len(world.bodies) == 5


# --- a refused call loses nothing ---------------------------------------------------------------------------


def _settled_world():
    world = tumble.World()
    world.add_static(tumble.Plane(), name="ground")
    world.add_body(tumble.Box((0.4, 0.4, 0.4)), density=500.0, position=(0.0, 0.0, 0.3), name="box")
    world.simulate(0.25, 1 / 60)
    return world


REFUSED_CALLS = {
    "dynamic plane": lambda w: w.add_body(tumble.Plane(), mass=1.0),
    "dynamic mesh in compound": lambda w: w.add_body(
        [(tumble.Sphere(0.1), (0, 0, 0)), (tetra_mesh(), (0, 0, 1))], mass=1.0
    ),
    "nan position": lambda w: w.add_body(tumble.Sphere(0.1), mass=1.0, position=(0.0, NAN, 1.0)),
    "inf velocity": lambda w: w.add_body(tumble.Sphere(0.1), mass=1.0, velocity=(INF, 0.0, 0.0)),
    "bad group": lambda w: w.add_body(tumble.Sphere(0.1), mass=1.0, collision_group=-1),
    "taken name": lambda w: w.add_body(tumble.Sphere(0.1), mass=1.0, name="box"),
    "no mass": lambda w: w.add_body(tumble.Sphere(0.1)),
    "static nan orientation": lambda w: w.add_static(tumble.Box((1, 1, 1)), orientation=(NAN, 0, 0, 0)),
    "static bad mask": lambda w: w.add_static(tumble.Plane(), collision_mask=1 << 40),
    "static None": lambda w: w.add_static(None),
    "bad solver": lambda w: w.set_solver(substeps=0),
}


@pytest.mark.parametrize("call", list(REFUSED_CALLS.values()), ids=list(REFUSED_CALLS))
def test_a_refused_call_leaves_the_world_unchanged_and_steppable(call):
    world, twin = _settled_world(), _settled_world()
    bodies, digest, solver = world.bodies, world.state.digest(), world.solver
    with pytest.raises((ValueError, TypeError)):
        call(world)
    assert world.bodies == bodies and len(world.bodies) == 2
    assert world.model.body_count == 2 and world.model.shape_count == 2
    assert world.state.digest() == digest and world.solver == solver
    # It steps on exactly as a world that never saw the refused call.
    world.step(1 / 60)
    twin.step(1 / 60)
    assert world.state.digest() == twin.state.digest()
    # And it still takes good bodies.
    world.add_body(tumble.Sphere(0.1), mass=1.0, position=(2.0, 0.0, 1.0))
    world.step(1 / 60)
    assert len(world.bodies) == 3 and np.all(np.isfinite(world.state.body_pos))


def test_a_force_whose_moment_overflows_is_refused():
    world = tumble.World()
    body = world.add_body(tumble.Sphere(0.1), mass=1.0)
    with pytest.raises(ValueError, match="has the moment .* which overflows"):
        body.apply_force((1e300, 0.0, 0.0), point=(0.0, 1e300, 0.0))
    assert not world.inputs.body_torque.any()


@pytest.mark.parametrize(("spin", "step"), [(1e160, 0), (1e120, 25)])
def test_a_runaway_body_is_named_even_when_it_takes_another_with_it(spin, step):
    """1e160 rad/s overflows inside a kernel (a division by an infinite value); 1e120 rad/s lands on the ground
    beside a calm box in the same step, and both turn NaN: the error names the spinner either way. (1e100 rad/s
    did too until the implicit spin kept the energy balance of its exact step; it now leaves at 1e96 m/s, finite.)"""
    world = tumble.World()
    world.add_static(tumble.Plane(), name="ground")
    world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=1.0, position=(0, 0, 1), name="calm")
    world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=1.0, position=(1, 0, 1), angular_velocity=(spin, 0, 0),
                   name="spinner")  # fmt: skip
    with np.errstate(all="ignore"), pytest.raises(tumble.SimulationError, match=f"body 'spinner' .* in step {step} "):
        world.simulate(2.0, 1 / 60)
    assert np.isfinite(world.state.body_pos).all()
