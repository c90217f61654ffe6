"""``World.step``'s lean path (issue 46, part 2): a world without controllers, sensors or wind takes the step its last
one prepared (``runner.ReadyStep``): ``dt`` checked, the objects compared, one compiled call. It must step as the
full path does through every change a user makes between steps, and fail as it does."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import tumble
from stepping import steps_through
from tumble import scenes
from tumble.actuators import Thruster
from tumble.errors import SimulationError
from tumble.sensors import IMU


def _spinning_bodies() -> tumble.World:
    """Two free bodies (their shapes collide with nothing), spinning about no principal axis."""
    world = tumble.World()
    world.add_body(tumble.Box((0.4, 0.3, 0.2)), mass=1.0, position=(0.0, 0.0, 1.0), angular_velocity=(0.3, 2.0, 1.0),
                   collision_mask=0)  # fmt: skip
    world.add_body(tumble.Cylinder(0.1, 0.5), mass=2.0, position=(1.0, 0.0, 1.0), velocity=(0.5, 0.0, 3.0),
                   angular_velocity=(4.0, 0.1, -0.3), collision_mask=0)  # fmt: skip
    return world


def _changes():
    """``(name, change)``: every kind of change a world of free bodies sees between steps, as a user makes it;
    ``None`` marks a change that leaves a Python part (a controller, a sensor, a wind) until the next one."""
    parts = {}

    def apply_force(world):
        world.bodies[0].apply_force((3.0, 0.0, 1.0), point=(0.0, 0.1, 1.0))

    def add_body(world):
        world.add_body(tumble.Sphere(0.1), mass=0.5, position=(0.6, 0.0, 0.4), velocity=(-1.0, 0.0, 0.0),
                       collision_mask=0)  # fmt: skip

    def add_thruster(world):
        world.add_actuator(Thruster(world.bodies[-1], (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), max_force=10.0)).command(3.0)

    def change_integrator(world):
        world.integrator = "symplectic"

    def change_it_back(world):
        world.integrator = "auto"

    def set_gravity(world):
        world.gravity = (0.0, 1.0, -9.81)

    def assign_state(world):
        world.state.assign(world.state.copy())

    def replace_state_array(world):
        world.state.body_linvel = world.state.body_linvel + (0.0, 0.0, 1.0)

    def replace_inputs_array(world):
        world.inputs.body_force = np.full_like(world.inputs.body_force, 2.0)

    def write_state_in_place(world):
        world.state.body_angmom[1] *= 1.5

    def add_controller(world):
        parts["controller"] = world.add_controller(lambda w, t: w.bodies[1].apply_torque((0.0, 0.2, 0.0)))

    def remove_controller(world):
        parts.pop("controller").remove()

    def add_drag_and_wind(world):
        world.add_drag(world.bodies[0], (0.3, 0.3, 0.3))
        world.wind = (4.0, 0.0, 0.0)

    def calm_the_wind(world):
        world.wind = None

    def add_sensor(world):
        parts["imu"] = world.add_sensor(IMU(world.bodies[1]))

    return [apply_force, add_body, add_thruster, change_integrator, change_it_back, set_gravity, assign_state,
            replace_state_array, replace_inputs_array, write_state_in_place, add_controller, remove_controller,
            add_drag_and_wind, calm_the_wind, add_sensor], parts  # fmt: skip


def _forget(world: tumble.World) -> None:
    world._scratch.ready = None


def _run(dt: float, full_path: bool) -> list:
    """The free bodies' digests through every change, and the IMU's last reading."""
    world = _spinning_bodies()
    changes, parts = _changes()
    seen = steps_through(world, dt, changes, _forget if full_path else None)
    return seen + [np.concatenate(parts["imu"].read()).tobytes()]


@pytest.mark.parametrize("hertz", [60, 240, 1000])
def test_the_prepared_step_steps_as_the_full_path_through_every_change(hertz):
    assert _run(1.0 / hertz, False) == _run(1.0 / hertz, True)


def test_a_world_keeps_its_prepared_step_until_it_changes_and_prepares_another_after():
    world = _spinning_bodies()
    assert world._scratch.ready is None
    world.step(0.01)
    ready = world._scratch.ready
    assert ready is not None
    for _ in range(3):
        world.bodies[0].apply_force((1.0, 0.0, 0.0))  # loads and in-place writes are read through, not changes
        world.state.body_pos[1, 2] += 0.01
        world.step(0.01)
        assert world._scratch.ready is ready
    changes, _ = _changes()
    for change in changes:
        change(world)
        world.step(0.01)
        has_python_parts = bool(world.controllers or world.sensors or world.wind is not None)
        if has_python_parts:
            assert world._scratch.ready is None, change.__name__
        elif change.__name__ not in ("apply_force", "write_state_in_place"):
            assert world._scratch.ready is not ready, change.__name__
        ready = world._scratch.ready


def test_a_controller_added_after_the_step_was_prepared_runs_at_the_next_step():
    world = _spinning_bodies()
    world.step(0.01)
    calls = []
    world.add_controller(lambda w, t: calls.append(t))
    world.step(0.01)
    world.step(0.01)
    assert calls == [0.01, 0.02]


def test_the_applied_loads_act_in_one_prepared_step_only():
    world, full = _spinning_bodies(), _spinning_bodies()
    world.step(0.01)
    full.step(0.01)
    for other in (world, full):
        other.bodies[0].apply_force((0.0, 0.0, 50.0))
    world.step(0.01)
    full._scratch.ready = None
    full.step(0.01)
    assert world.state.digest() == full.state.digest()
    assert not world.inputs.body_force.any()
    v = world.bodies[0].velocity
    world.step(0.01)
    np.testing.assert_allclose(world.bodies[0].velocity - v, (0.0, 0.0, -9.81 * 0.01), atol=1e-12)


@pytest.mark.parametrize("dt", [float("nan"), float("inf"), -0.01, 0.0, 1e-300, "0.01", None])
def test_bad_steps_get_the_full_paths_errors_and_move_nothing(dt):
    world = _spinning_bodies()
    world.step(0.01)
    assert world._scratch.ready is not None
    before = world.state.digest()
    with pytest.raises((ValueError, TypeError)) as prepared:
        world.step(dt)
    full = _spinning_bodies()
    full.step(0.01)
    full._scratch.ready = None
    with pytest.raises(type(prepared.value)) as unprepared:
        full.step(dt)
    assert str(prepared.value) == str(unprepared.value) and "dt" in str(prepared.value)
    assert world.state.digest() == before


def test_a_step_that_overflows_keeps_the_world_and_drops_its_loads():
    world = _spinning_bodies()
    world.step(0.01)
    before = world.state.digest()
    world.bodies[1].apply_force((1e308, 1e308, 0.0))
    with pytest.raises(SimulationError, match="body #1 became non-finite .* in step 1") as error:
        world.step(0.01)
    assert error.value.body == 1 and error.value.step == 1
    assert world.state.digest() == before and not world.inputs.body_force.any()
    world.step(0.01)
    assert world.step_count == 2 and np.isfinite(world.state.body_pos).all()


@pytest.mark.parametrize("duplicate", [copy.deepcopy, lambda world: pickle.loads(pickle.dumps(world))],
                         ids=["deepcopy", "pickle"])  # fmt: skip
def test_a_copy_of_a_world_with_a_prepared_step_steps_its_own_arrays(duplicate):
    world = _spinning_bodies()
    world.step(0.01)
    other = duplicate(world)
    assert other._scratch.ready is None
    for _ in range(3):
        world.step(0.01)
        other.step(0.01)
    assert other.state.digest() == world.state.digest()
    assert not np.shares_memory(other.state.body_pos, world.state.body_pos)


# --- contacts and joints: the prepared soft step ----------------------------------------------------------------


def _contact_changes():
    """Changes of a world with contacts between steps; the last ones add a Python part."""

    def add_touching_body(world):
        world.add_body(tumble.Sphere(0.1), mass=0.5, position=(0.5, 0.0, 0.15), velocity=(-1.0, 0.0, 0.0))

    def set_solver(world):
        world.set_solver(substeps=12, contact_hertz=40.0)

    def assign_state(world):
        world.state.assign(world.state.copy())

    def replace_contact_impulses(world):
        world.state.contact_normal_impulse = 0.5 * world.state.contact_normal_impulse

    def push(world):
        world.bodies[1].apply_force((30.0, 0.0, 0.0), point=world.bodies[1].position + (0.0, 0.0, 0.1))

    def add_joint(world):
        world.add_joint(tumble.BallJoint(world.bodies[-1], None, anchor=world.bodies[-1].position + (0.0, 0.0, 0.3)))

    def add_sensor(world):
        world.add_sensor(IMU(world.bodies[1]))

    return [push, add_touching_body, set_solver, assign_state, replace_contact_impulses, add_joint, add_sensor]


def _ground_with_a_box() -> tumble.World:
    world = tumble.World()
    world.add_static(tumble.Plane())
    world.add_body(tumble.Box((0.4, 0.3, 0.2)), mass=1.0, position=(0.0, 0.0, 0.3), angular_velocity=(0.3, 0.2, 1.0))
    return world


def _run_contacts(make, dt: float, full_path: bool, changes) -> list:
    world = make()
    seen = steps_through(world, dt, changes, _forget if full_path else None)
    return seen + [world.state.contact_count, world._scratch.steps_found_again]


@pytest.mark.parametrize("hertz", [60, 240, 1000])
def test_the_prepared_soft_step_steps_as_the_full_path_through_every_change(hertz):
    prepared = _run_contacts(_ground_with_a_box, 1.0 / hertz, False, _contact_changes())
    assert prepared[-2] > 0 and prepared == _run_contacts(_ground_with_a_box, 1.0 / hertz, True, _contact_changes())


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("hertz", [60, 240])
def test_a_pile_steps_the_same_prepared_whatever_its_seed(seed, hertz):
    """A pile falls for 0.75 s and lands: its contacts outgrow the buffers while it has a prepared step (which then
    hands the step to the full path, which grows them): the same bits as the full path at every step, over seeds."""
    dt = 1.0 / hertz
    prepared, full = scenes.box_pile(8, seed=seed), scenes.box_pile(8, seed=seed)
    grew_while_prepared = 0
    for _ in range(round(0.75 / dt)):
        ready, capacity = prepared._scratch.ready, prepared._scratch.manifolds.shape_a.shape[0]
        prepared.step(dt)
        grew_while_prepared += ready is not None and prepared._scratch.manifolds.shape_a.shape[0] > capacity
        full._scratch.ready = None
        full.step(dt)
        assert prepared.state.digest() == full.state.digest()
    assert prepared.state.contact_count >= 8, grew_while_prepared
    assert grew_while_prepared > 0


def test_many_free_bodies_prepare_a_step_until_one_step_is_split_over_threads(monkeypatch):
    """Up to ``PARALLEL_MIN_WORK`` bodies a step is one call on this thread, prepared; past it the full path splits
    the bodies over the threads (the same bits either way: rows are independent)."""
    from tumble.dynamics import integrate

    def spinning(count):
        world = tumble.World()
        for k in range(count):
            world.add_body(tumble.Box((0.3, 0.2, 0.1)), mass=1.0, position=(k, 0.0, 0.0), collision_mask=0,
                           angular_velocity=(1.0, 2.0 + k % 7, 3.0))  # fmt: skip
        return world

    digests = []
    for limit in (10_000, 200):  # 1000 bodies: prepared; then split (threads permitting)
        monkeypatch.setattr(integrate, "PARALLEL_MIN_WORK", limit)
        world = spinning(1000)
        world.bodies[3].apply_force((0.0, 5.0, 0.0))
        for _ in range(20):
            world.step(1 / 240)
        assert (world._scratch.ready is not None) == (limit > 1000)
        digests.append(world.state.digest())
    assert digests[0] == digests[1]


def test_a_resting_box_keeps_its_prepared_soft_step():
    world = _ground_with_a_box()
    for _ in range(30):
        world.step(1 / 60)
    ready = world._scratch.ready
    assert type(ready).__name__ == "_ReadyContactStep"
    for _ in range(30):
        world.step(1 / 60)
    assert world._scratch.ready is ready and world.state.contact_count == 1


def test_a_prepared_soft_step_refuses_too_many_substeps_and_moves_nothing():
    world = _ground_with_a_box()
    world.step(1 / 60)
    world.step(1 / 60)
    before = world.state.digest()
    with pytest.raises(ValueError, match="substeps"):
        world.step(1e3)
    assert world.state.digest() == before
    world.step(1 / 60)
    assert world.step_count == 3
