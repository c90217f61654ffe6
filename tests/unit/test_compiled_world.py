"""A world's arrays as one compiled record (issue 46, part 1): built once, kept while nothing it holds is replaced,
built again after every change, and a step over a kept record equals one over a record built afresh."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import tumble
from compiled import compiled_only
from stepping import steps_through
from tumble import scenes
from tumble.actuators import Thruster

DT = 1.0 / 60.0


def _record(world: tumble.World):
    return world._scratch.compiled[1].record


def _ground_with_a_box() -> tumble.World:
    world = tumble.World()
    world.add_static(tumble.Plane())
    world.add_body(tumble.Box((0.4, 0.3, 0.2)), mass=1.0, position=(0.0, 0.0, 0.5), angular_velocity=(0.3, 0.2, 1.0))
    return world


def _changes():
    """``(name, change)``: every kind of change a world sees between steps, as a user makes it."""

    def add_body(world):
        world.add_body(tumble.Sphere(0.1), mass=0.5, position=(0.6, 0.0, 0.4), velocity=(-1.0, 0.0, 0.0))

    def add_joint(world):
        world.add_joint(tumble.BallJoint(world.bodies[-1], None, anchor=world.bodies[-1].position + (0.0, 0.0, 0.3)))

    def add_thruster(world):
        world.add_actuator(Thruster(world.bodies[-1], (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), max_force=10.0)).command(3.0)

    def set_solver(world):
        world.set_solver(substeps=12, contact_hertz=40.0)

    def assign_state(world):
        world.state.assign(world.state.copy())  # the same values, the sized arrays replaced

    def set_gravity(world):
        world.gravity = (0.0, 1.0, -9.81)

    def replace_state_array(world):
        world.state.body_linvel = world.state.body_linvel + (0.0, 0.0, 1.0)

    def replace_inputs_array(world):
        world.inputs.body_force = np.full_like(world.inputs.body_force, 2.0)

    return [add_body, add_joint, add_thruster, set_solver, assign_state, set_gravity, replace_state_array,
            replace_inputs_array]  # fmt: skip


def _run(make, dt: float, fresh_each_step: bool) -> tuple[list[str], int]:
    """The digests after every step through every change, and the contacts at the end; with ``fresh_each_step`` the
    kept record is dropped before every step, so that each step builds its own."""

    def fresh(world):
        world._scratch.compiled = None

    world = make()
    return steps_through(world, dt, _changes(), fresh if fresh_each_step else None), world.state.contact_count


HERTZ = [60, 240, 1000]


@pytest.mark.parametrize("hertz", HERTZ)
def test_a_kept_record_steps_as_a_record_built_afresh_for_each_step_through_every_kind_of_change(hertz):
    assert _run(_ground_with_a_box, 1.0 / hertz, False) == _run(_ground_with_a_box, 1.0 / hertz, True)


@compiled_only("a pile through 0.75 s, twice, at 1 kHz")
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("hertz", HERTZ)
def test_a_pile_steps_the_same_with_a_kept_record_whatever_its_seed_and_step(seed, hertz):
    """A falling pile grows its contact buffers (a new record each time) while it changes: over several seeds."""

    def pile():
        return scenes.box_pile(8, seed=seed)

    kept, contacts = _run(pile, 1.0 / hertz, False)
    assert contacts > 0 and kept == _run(pile, 1.0 / hertz, True)[0]


@pytest.mark.parametrize("change", _changes(), ids=lambda change: change.__name__)
def test_every_change_builds_the_record_again_and_plain_steps_keep_it(change):
    world = _ground_with_a_box()
    world.step(DT)
    kept = _record(world)
    world.step(DT)
    assert _record(world) is kept  # nothing changed: the same record
    change(world)
    world.step(DT)
    assert _record(world) is not kept


@pytest.mark.parametrize("hertz", HERTZ)
def test_a_static_body_added_later_gives_the_world_that_had_it_from_the_start(hertz):
    """Out of reach of everything, the wall changes nothing before or after it is added: the world that gets it after
    20 steps matches bit for bit, at every later step, the one built with it."""

    def wall(world):
        world.add_static(tumble.Box((0.2, 4.0, 4.0)), position=(50.0, 0.0, 2.0))

    late, early = _ground_with_a_box(), _ground_with_a_box()
    wall(early)
    for _ in range(20):
        late.step(1.0 / hertz)
        early.step(1.0 / hertz)
    wall(late)
    for _ in range(30):
        late.step(1.0 / hertz)
        early.step(1.0 / hertz)
        assert late.state.digest() == early.state.digest()


@pytest.mark.parametrize("hertz", HERTZ)
def test_the_states_contact_arrays_are_what_the_next_step_reads_written_in_place_or_replaced(hertz):
    """After a step the state's contact arrays are views of the rows the next step reads its warm start from: a write
    into them reaches it, as does an array put in their place (an equal copy steps the same, a changed one
    differently, and the same as the write)."""

    def settled():  # half a second: on the ground
        world = _ground_with_a_box()
        for _ in range(hertz // 2):
            world.step(1.0 / hertz)
        return world

    reference, same, written, replaced = settled(), settled(), settled(), settled()
    assert reference.state.contact_count > 0
    same.state.contact_normal_impulse = same.state.contact_normal_impulse.copy()
    written.state.contact_normal_impulse[...] *= 3.0
    replaced.state.contact_normal_impulse = 3.0 * replaced.state.contact_normal_impulse
    for world in (reference, same, written, replaced):
        world.step(1.0 / hertz)
    assert same.state.digest() == reference.state.digest()
    assert written.state.digest() == replaced.state.digest() != reference.state.digest()
    np.testing.assert_array_equal(same.state.contact_normal_impulse, reference.state.contact_normal_impulse)


@pytest.mark.parametrize("duplicate", [copy.deepcopy, lambda world: pickle.loads(pickle.dumps(world))],
                         ids=["deepcopy", "pickle"])  # fmt: skip
def test_a_stepped_world_copies_and_pickles_and_the_copy_steps_on_as_the_original(duplicate):
    """The record is not part of a copy (it would hold the original's arrays): the copy builds its own, and steps on
    bit for bit as the original, which its steps leave alone."""
    world = _ground_with_a_box()
    for _ in range(30):
        world.step(DT)
    twin = duplicate(world)
    before = world.state.digest()
    for _ in range(10):
        twin.step(DT)
    assert world.state.digest() == before
    for _ in range(10):
        world.step(DT)
    assert twin.state.digest() == world.state.digest()
