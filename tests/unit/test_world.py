"""World and Body: building bodies, reading and writing state, diagnostics, errors at the boundary."""

from __future__ import annotations

import os
import re

import numpy as np
import pytest

import tumble
from compiled import COMPILED, compiled_only
from tumble import mass as tm
from tumble import scenes
from tumble.dynamics import integrate
from tumble.rotation import quat_from_axis_angle, quat_to_matrix


def test_add_body_from_a_shape_uses_its_mass_properties():
    world = tumble.World()
    body = world.add_body(tumble.Box((1.0, 2.0, 3.0)), density=10.0, position=(1, 2, 3))
    expected = tm.box((1.0, 2.0, 3.0), density=10.0)
    assert body.mass == pytest.approx(60.0)
    np.testing.assert_allclose(body.inertia_body, expected.inertia, rtol=1e-14)
    np.testing.assert_allclose(body.position, [1, 2, 3])
    np.testing.assert_allclose(body.center_of_mass, [1, 2, 3])
    assert not body.is_static


def test_compound_body_spreads_mass_by_volume_and_puts_the_com_between_parts():
    world = tumble.World()
    parts = [(tumble.Sphere(0.5), (-1.0, 0.0, 0.0)), (tumble.Sphere(0.5), (1.0, 0.0, 0.0))]
    q = quat_from_axis_angle((0, 0, 1), np.pi / 2)
    body = world.add_body(parts, mass=2.0, position=(0, 0, 5), orientation=q)
    np.testing.assert_allclose(body.center_of_mass, [0, 0, 5], atol=1e-15)
    sphere = tm.solid_sphere(0.5, mass=1.0)
    expected = sphere.transformed(translation=(-1, 0, 0)) + sphere.transformed(translation=(1, 0, 0))
    np.testing.assert_allclose(body.inertia_body, expected.inertia, rtol=1e-13)
    r = quat_to_matrix(q)
    np.testing.assert_allclose(body.inertia_world, r @ expected.inertia @ r.T, atol=1e-13)


def test_offset_compound_keeps_the_frame_origin_as_position():
    world = tumble.World()
    body = world.add_body([(tumble.Box((1, 1, 1)), (0.0, 0.0, 1.0))], density=1.0, position=(2, 0, 0))
    np.testing.assert_allclose(body.position, [2, 0, 0])
    np.testing.assert_allclose(body.center_of_mass, [2, 0, 1])
    body.position = (0, 0, 0)
    np.testing.assert_allclose(body.center_of_mass, [0, 0, 1])
    # Turning the body about its origin swings the COM around it.
    body.orientation = quat_from_axis_angle((1, 0, 0), np.pi / 2)
    np.testing.assert_allclose(body.center_of_mass, [0, -1, 0], atol=1e-15)
    np.testing.assert_allclose(body.position, [0, 0, 0], atol=1e-15)


def test_explicit_inertia_overrides_the_shape():
    world = tumble.World()
    inertia = np.diag([1.0, 2.0, 2.5])
    body = world.add_body(tumble.Sphere(1.0), mass=3.0, inertia=inertia)
    np.testing.assert_array_equal(body.inertia_body, inertia)
    assert body.mass == 3.0


def test_angular_velocity_round_trips_through_the_momentum_state():
    world = tumble.World()
    q = quat_from_axis_angle((1, 1, 0), 0.7)
    body = world.add_body(None, mass=1.0, inertia=np.diag([1.0, 2.0, 3.0]), orientation=q)
    body.angular_velocity = (0.3, -0.2, 0.5)
    np.testing.assert_allclose(body.angular_velocity, [0.3, -0.2, 0.5], rtol=1e-14)
    np.testing.assert_allclose(body.angular_momentum, body.inertia_world @ [0.3, -0.2, 0.5], rtol=1e-14)
    np.testing.assert_allclose(body.angular_velocity_body, body.rotation.T @ [0.3, -0.2, 0.5], atol=1e-15)
    np.testing.assert_allclose(world.angular_velocities()[0], [0.3, -0.2, 0.5], rtol=1e-14)


def test_point_velocity_is_v_plus_omega_cross_r():
    world = tumble.World()
    body = world.add_body(tumble.Sphere(1.0), mass=1.0, velocity=(1, 0, 0), angular_velocity=(0, 0, 2))
    np.testing.assert_allclose(body.point_velocity((0, 1, 0)), [1 - 2, 0, 0])


def test_energy_and_momentum_diagnostics_match_hand_values():
    world = tumble.World(gravity=(0, 0, -10))
    a = world.add_body(tumble.Sphere(0.5), mass=2.0, position=(0, 0, 3), velocity=(1, 0, 0))
    b = world.add_body(None, mass=1.0, inertia=np.diag([1, 2, 3]), position=(1, 0, 0), angular_velocity=(0, 0, 2))
    world.add_static(tumble.Plane())
    assert world.kinetic_energy() == pytest.approx(0.5 * 2 * 1 + 0.5 * 3 * 4)
    assert world.potential_energy() == pytest.approx(2 * 10 * 3)
    assert world.total_energy() == pytest.approx(1 + 6 + 60)
    np.testing.assert_allclose(world.linear_momentum(), [2, 0, 0])
    # L about the origin: a's orbital r × m v = (0,0,3) × (2,0,0) = (0,6,0); b's spin (0,0,6).
    np.testing.assert_allclose(world.angular_momentum(), [0, 6, 6])
    np.testing.assert_allclose(world.angular_momentum(point=(0, 0, 3)), [0, 0, 6])
    assert a.kinetic_energy == pytest.approx(1.0) and b.kinetic_energy == pytest.approx(6.0)


def test_static_bodies_do_not_move_and_refuse_forces():
    world = tumble.World()
    ground = world.add_static(tumble.Plane(), name="ground")
    box = world.add_static(tumble.Box((1, 1, 1)), position=(0, 0, 2))
    world.step(0.01)
    np.testing.assert_array_equal(box.position, [0, 0, 2])
    assert ground.is_static and ground.mass == 0.0
    with pytest.raises(ValueError, match="static"):
        box.apply_force((1, 0, 0))
    with pytest.raises(ValueError, match="static"):
        box.velocity = (1, 0, 0)
    assert world.body("ground") == ground


def test_trajectory_records_frames_and_round_trips_through_npz(tmp_path):
    world = tumble.World()
    world.add_body(tumble.Box((0.1, 0.2, 0.3)), density=100.0, velocity=(1, 0, 5), angular_velocity=(1, 2, 3),
                   collision_mask=0, name="box")  # fmt: skip
    world.add_static(tumble.Plane())
    traj = world.simulate(1.0, 0.01, record_every=10)
    assert len(traj) == 11 and traj.position.shape == (11, 2, 3) and traj.orientation.shape == (11, 2, 4)
    np.testing.assert_allclose(traj.time, np.linspace(0, 1, 11), atol=1e-12)
    np.testing.assert_allclose(traj.position[-1, 0], world.body("box").position)
    np.testing.assert_allclose(traj.angular_velocity[-1, 0], world.body("box").angular_velocity)
    assert traj.body_names == ["box", ""]
    path = tmp_path / "run.npz"
    traj.save(path)
    loaded = tumble.Trajectory.load(path)
    for name in ("time", "position", "orientation", "velocity", "angular_velocity", "kinetic_energy",
                 "potential_energy"):  # fmt: skip
        np.testing.assert_array_equal(getattr(loaded, name), getattr(traj, name))
    assert loaded.body_names == traj.body_names and loaded.metadata["dt"] == 0.01


def test_trajectory_load_refuses_a_foreign_file(tmp_path):
    path = tmp_path / "other.npz"
    np.savez(path, x=np.zeros(3))
    with pytest.raises(ValueError, match="not a tumble trajectory"):
        tumble.Trajectory.load(path)


def _scene(integrator="auto"):
    world = tumble.World(integrator=integrator)
    rng = np.random.default_rng(7)
    for k in range(50):
        world.add_body(
            tumble.Box(rng.uniform(0.1, 1.0, 3)),
            density=1.0,
            position=rng.normal(size=3),
            velocity=rng.normal(size=3),
            angular_velocity=rng.normal(size=3) * 5,
            collision_mask=0,
            name=f"b{k}",
        )  # fmt: skip  (collision_mask=0: free flight, these tests are about the integrators)
    return world


@pytest.mark.parametrize("integrator", ["euler", "symplectic", "rk4", "midpoint"])
def test_runs_are_bit_identical_and_simulate_equals_repeated_steps(integrator):
    steps = 1000 if COMPILED else 50  # a minute as plain Python, where 50 steps reach the same lines
    a, b, c = _scene(integrator), _scene(integrator), _scene(integrator)
    a.simulate(steps * 1e-3, 1e-3)
    b.simulate(steps * 1e-3, 1e-3)
    for _ in range(steps):
        c.step(1e-3)
    assert a.state.digest() == b.state.digest() == c.state.digest()


two_cores = pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="needs two cores")


@two_cores
@compiled_only("plain Python runs a parallel loop on one thread")
def test_threaded_and_single_threaded_runs_agree_bit_for_bit(monkeypatch):
    threaded, single = _scene(), _scene()
    monkeypatch.setattr(integrate, "PARALLEL_MIN_WORK", 1)
    with integrate.using_threads(2):
        threaded.simulate(0.5, 1e-3)  # split into two blocks of rows, one per thread
        for _ in range(500):
            single.step(1e-3)  # threaded too, one step at a time
    with integrate.using_threads(1):
        again = _scene()
        again.simulate(0.5, 1e-3)
    assert threaded.state.digest() == single.state.digest() == again.state.digest()


@pytest.fixture(scope="module")
def free_spheres():
    """4096 spinning spheres that cannot touch, and their state at the start (built once: 3 s)."""
    world = tumble.World()
    spins = np.random.default_rng(0).normal(0.0, 5.0, (4096, 3))
    for k in range(4096):
        position = (0.2 * (k % 64), 0.2 * (k // 64), 1.0)
        world.add_body(tumble.Sphere(0.05), mass=1.0, position=position, angular_velocity=spins[k], collision_mask=0)
    return world, world.state.copy()


@two_cores
@compiled_only("minutes as plain Python")
@pytest.mark.parametrize("integrator", ["auto", "symplectic"])
def test_4096_free_bodies_and_a_pile_give_the_same_bits_on_one_thread_and_two(integrator, free_spheres):
    """4096 bodies for 60 steps is above the size at which the free bodies split across threads; the pile (contacts)
    runs its one thread either way."""
    bodies, start = free_spheres
    bodies.integrator = integrator
    assert 4096 * 60 >= integrate.PARALLEL_MIN_WORK
    digests = {}
    for count in (1, 2):
        with integrate.using_threads(count):
            bodies.state.assign(start)
            bodies.simulate(0.06, 1e-3)
            pile = scenes.box_pile(27)
            pile.simulate(0.25, 1 / 240)
        digests[count] = (bodies.state.digest(), pile.state.digest())
    assert integrate._POOL_SIZE >= 2  # the two-thread run went through the pool
    assert digests[1] == digests[2]
    assert digests[1][0] != start.digest()  # the bodies moved


@pytest.mark.parametrize("count", [0, -1, 1.5, True, "2", 10**6])
def test_using_threads_refuses_what_is_not_a_thread_count(count):
    before = integrate.threads()
    message = rf"count must be a number of threads from 1 to \d+ \(one per core\), got {re.escape(repr(count))}"
    with pytest.raises(ValueError, match=message):
        with integrate.using_threads(count):
            pass
    assert integrate.threads() == before


def test_non_finite_step_raises_and_keeps_the_last_good_state():
    world = tumble.World(gravity=(0, 0, 0))
    calm = world.add_body(None, mass=1.0, inertia=np.eye(3), velocity=(1, 0, 0), name="calm")
    wild = world.add_body(None, mass=1.0, inertia=np.eye(3), name="wild")
    world.step(0.1)
    before = world.state.copy()
    wild.apply_force((1e308, 1e308, 0))
    with pytest.raises(tumble.SimulationError, match=r"'wild'.*step 1") as info:
        world.step(1e300)
    assert info.value.body == "wild" and info.value.step == 1
    assert world.state.digest() == before.digest()
    # The loads of the failed step are dropped: they could fail every later step (issue 22).
    np.testing.assert_array_equal(world.inputs.body_force[wild.index], [0, 0, 0])
    np.testing.assert_array_equal(calm.velocity, [1, 0, 0])
    world.step(0.1)
    np.testing.assert_array_equal(wild.velocity, [0, 0, 0])


def test_simulate_stops_at_the_last_good_step_and_returns_what_it_recorded():
    world = tumble.World(gravity=(0, 0, 0))
    world.add_body(None, mass=1.0, inertia=np.eye(3), velocity=(1, 0, 0), name="calm")
    world.add_body(None, mass=1.0, inertia=np.eye(3), velocity=(1e307, 0, 0), name="runaway")
    with pytest.raises(tumble.SimulationError, match="runaway") as info:
        world.simulate(100.0, 1.0)  # x grows by 1e307 each step and overflows after ~17 steps
    steps_done = world.step_count
    assert 0 < steps_done < 100 and info.value.step == steps_done
    assert np.all(np.isfinite(world.state.body_pos))
    assert world.body("calm").position[0] == pytest.approx(steps_done)
    traj = info.value.trajectory
    assert len(traj) == steps_done + 1 and traj.time[-1] == pytest.approx(steps_done)


def test_names_are_unique_and_lookup_fails_clearly():
    world = tumble.World()
    world.add_body(tumble.Sphere(1.0), mass=1.0, name="a")
    with pytest.raises(ValueError, match="unique"):
        world.add_body(tumble.Sphere(1.0), mass=1.0, name="a")
    with pytest.raises(KeyError, match="no body named 'b'"):
        world.body("b")


def test_state_arrays_are_live_views_for_batch_work():
    world = _scene()
    world.state.body_linvel[:] = 0.0
    world.gravity = (0, 0, 0)
    assert all(np.all(b.velocity == 0.0) for b in world.bodies)


# --- bad input -------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"mass": -1.0}, ValueError, "mass"),
        ({"mass": 0.0}, ValueError, "mass"),
        ({"mass": float("nan")}, ValueError, "mass"),
        ({"mass": float("inf")}, ValueError, "mass"),
        ({"mass": "heavy"}, TypeError, "mass"),
        ({"mass": 1.0, "density": 1.0}, TypeError, "exactly one"),
        ({}, TypeError, "exactly one"),
        ({"mass": 1.0, "position": (0, np.nan, 0)}, ValueError, "position"),
        ({"mass": 1.0, "position": (0, 0)}, ValueError, "position"),
        ({"mass": 1.0, "orientation": (0, 0, 0, 0)}, ValueError, "orientation"),
        ({"mass": 1.0, "velocity": (np.inf, 0, 0)}, ValueError, "velocity"),
        ({"mass": 1.0, "angular_velocity": "fast"}, TypeError, "angular_velocity"),
        ({"mass": 1.0, "friction": -0.1}, ValueError, "friction"),
        ({"mass": 1.0, "restitution": 1.5}, ValueError, "restitution"),
        ({"mass": 1.0, "linear_damping": -1.0}, ValueError, "linear_damping"),
        ({"mass": 1.0, "inertia": np.diag([1.0, 1.0, 3.0])}, ValueError, "triangle"),
        ({"mass": 1.0, "inertia": np.diag([1.0, -1.0, 1.0])}, ValueError, "inertia"),
        ({"mass": 1.0, "inertia": [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]}, ValueError, "symmetric"),
        ({"mass": 1.0, "name": 3}, TypeError, "name"),
    ],
)
def test_add_body_refuses_bad_input_and_names_the_argument(kwargs, error, match):
    world = tumble.World()
    with pytest.raises(error, match=match):
        world.add_body(tumble.Sphere(0.5), **kwargs)
    assert world.bodies == []  # nothing half-added


def test_a_body_without_geometry_needs_mass_and_inertia():
    world = tumble.World()
    with pytest.raises(ValueError, match="inertia="):
        world.add_body(None, mass=1.0)
    with pytest.raises(ValueError, match="needs a shape"):
        world.add_body(None, density=1.0, inertia=np.eye(3))
    with pytest.raises(ValueError, match="positive definite"):
        world.add_body(None, mass=1.0, inertia=np.diag([0.0, 1.0, 1.0]))


def test_planes_and_meshes_are_static_only():
    world = tumble.World()
    with pytest.raises(ValueError, match="static"):
        world.add_body(tumble.Plane(), mass=1.0)
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    with pytest.raises(ValueError, match="static"):
        world.add_body(tumble.TriMesh(v, f), mass=1.0)
    world.add_static(tumble.TriMesh(v, f))


def test_bad_compound_lists_are_refused():
    world = tumble.World()
    with pytest.raises(TypeError, match=r"shape\[0\]"):
        world.add_body([(1.0, (0, 0, 0))], mass=1.0)
    with pytest.raises(ValueError, match=r"shape\[1\] position"):
        world.add_body([(tumble.Sphere(1), (0, 0, 0)), (tumble.Sphere(1), (0, 0))], mass=1.0)
    with pytest.raises(TypeError, match="shape must be"):
        world.add_body("box", mass=1.0)


@pytest.mark.parametrize("dt", [0.0, -1e-3, float("nan"), float("inf")])
def test_step_refuses_a_non_positive_or_non_finite_dt(dt):
    world = tumble.World()
    world.add_body(tumble.Sphere(1.0), mass=1.0)
    with pytest.raises(ValueError, match="dt"):
        world.step(dt)
    assert world.step_count == 0


def test_simulate_and_world_arguments_are_checked():
    world = tumble.World()
    with pytest.raises(ValueError, match="record_every"):
        world.simulate(1.0, 0.1, record_every=0)
    with pytest.raises(ValueError, match="duration"):
        world.simulate(0.01, 0.1)
    with pytest.raises(ValueError, match="integrator"):
        tumble.World(integrator="verlet")
    with pytest.raises(ValueError, match="gravity"):
        tumble.World(gravity=(0, 0, np.nan))
    with pytest.raises(ValueError, match="force"):
        world.add_body(tumble.Sphere(1.0), mass=1.0).apply_force((np.nan, 0, 0))
