"""The runner's compiled loops (``tumble.runner``): free bodies with or without a compiled controller stage, on one
thread or split over two, and worlds with contacts, back up, restore on a non-finite value and advance the motors
alike; the contact loop grows its buffers within a call without changing a bit."""

from __future__ import annotations

import os

import numpy as np
import pytest

import tumble
from compiled import compiled_only
from tumble import _jit, pipeline, runner
from tumble.actuators import Rotor, Thruster
from tumble.control import native
from tumble.dynamics import integrate

K_THRUST, K_MOMENT = 8.5e-6, 1.4e-7


def _rotors_and_a_runaway(bodies: int = 6) -> tuple[tumble.World, list]:
    """Free bodies, the first ones each lifted by a rotor that spins up (a motor lag), the last one so fast that its
    position overflows after about 17 steps of 1 s."""
    world = tumble.World(gravity=(0, 0, -9.81))
    rotors = []
    for k in range(bodies - 1):
        body = world.add_body(None, mass=0.1, inertia=np.eye(3) * 1e-3, position=(k, 0, 0), velocity=(0, 0, k))
        rotor = world.add_actuator(Rotor(body, (0, 0, 0), (0, 0, 1), 1, K_THRUST, K_MOMENT, time_constant=0.05))
        rotor.command(400.0 + 10 * k)
        rotors.append(rotor)
    world.add_body(None, mass=1.0, inertia=np.eye(3), velocity=(1e307, 0, 0), name="runaway")
    return world, rotors


def _run_until_failure(world: tumble.World, rotors: list):
    with pytest.raises(tumble.SimulationError, match="runaway") as info:
        world.simulate(100.0, 1.0, record_every=2)
    trajectory = info.value.trajectory
    return (info.value.step, world.state.digest(), [r.speed for r in rotors], trajectory.position.tobytes(),
            trajectory.orientation.tobytes())  # fmt: skip


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="needs two cores")
@compiled_only("plain Python runs the blocks one after the other")
def test_a_failure_in_one_block_of_threads_leaves_what_one_thread_leaves(monkeypatch):
    """The runaway body is in the second block: the first block ran all the steps, so the runner rolls every block
    back, motors included, and replays the steps that all the bodies completed."""
    monkeypatch.setattr(integrate, "PARALLEL_MIN_WORK", 1)
    results = {}
    for count, push in ((1, True), (2, True), (1, False)):
        with integrate.using_threads(count):
            world, rotors = _rotors_and_a_runaway()
            if push:  # applied loads act in the first step: in the replay's too, though each block dropped its own
                world.bodies[0].apply_force((0.0, 0.3, 0.0))
                world.bodies[1].apply_torque((0.0, 0.0, 0.01))
            results[count, push] = _run_until_failure(world, rotors)
    assert results[1, True] == results[2, True]
    assert results[1, True][1] != results[1, False][1]  # the loads count
    step, *_ = results[1, True]
    assert 10 < step < 30


def test_the_motors_of_a_failed_run_stop_at_the_last_good_step():
    """A rotor's speed after the failure is the speed after the steps done: the same as a run of just those steps."""
    world, rotors = _rotors_and_a_runaway()
    step, digest, speeds, *_ = _run_until_failure(world, rotors)
    again, again_rotors = _rotors_and_a_runaway()
    again.simulate(float(step), 1.0)
    assert again.state.digest() == digest
    assert [r.speed for r in again_rotors] == speeds


def test_a_step_that_fails_at_once_changes_nothing_not_even_the_motors():
    """The world keeps its state from before the failed step: a thruster's force stays the last step's, not the new
    command (a motor advanced by no time would take it)."""
    world = tumble.World(gravity=(0, 0, 0))
    body = world.add_body(None, mass=0.1, inertia=np.eye(3) * 1e-3)
    rotor = world.add_actuator(Rotor(body, (0, 0, 0), (0, 0, 1), 1, K_THRUST, K_MOMENT, time_constant=0.05))
    thruster = world.add_actuator(Thruster(body, (0, 0, 0), (1, 0, 0), max_force=10.0))
    rotor.command(500.0)
    thruster.command(2.0)
    world.add_body(None, mass=1.0, inertia=np.eye(3), velocity=(1e308, 0, 0), name="runaway")
    before = world.state.copy()
    with pytest.raises(tumble.SimulationError, match="runaway"):
        world.step(1e10)
    assert world.state.digest() == before.digest()
    assert rotor.speed == 0.0 and thruster.force == 0.0
    assert rotor.commanded_speed == 500.0 and thruster.commanded_force == 2.0  # the commands wait for the next step


@compiled_only("the cache stamps compiled code")
def test_the_loop_with_a_compiled_stage_is_stamped_with_the_stage_package():
    """The copy of the runner's loop that the flights' stage is bound into embeds control's kernels: an edit there
    must invalidate it on disk, as it does control's own kernels."""
    staged = runner._staged_steps(native.command_stage)
    stamp = staged._cache._impl._locator.get_source_stamp()
    assert stamp == _jit._package_stamp("control") != _jit._package_stamp(None)
    assert runner._plain_steps._cache._impl._locator.get_source_stamp() == _jit._package_stamp(None)


def _on_the_ground_with_a_runaway() -> tuple[tumble.World, list]:
    """A contact world: a box resting on a plane, a body lifted by a rotor that spins up, and a body without shape so
    fast that its position overflows after about 17 steps of 1 s."""
    world = tumble.World(gravity=(0, 0, -9.81))
    world.add_static(tumble.Plane())
    world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=1.0, position=(0, 0, 0.1))
    lifted = world.add_body(None, mass=0.1, inertia=np.eye(3) * 1e-3, position=(3, 0, 1))
    rotor = world.add_actuator(Rotor(lifted, (0, 0, 0), (0, 0, 1), 1, K_THRUST, K_MOMENT, time_constant=0.05))
    rotor.command(400.0)
    world.add_body(None, mass=1.0, inertia=np.eye(3), velocity=(1e307, 0, 0), name="runaway")
    return world, [rotor]


def test_a_contact_world_that_fails_mid_call_keeps_the_steps_before_as_a_step_loop_does():
    """The compiled loop of contact steps restores the state before the failing step, motors included, and the
    trajectory holds the frames before it: the same bits as stepping one step a call."""
    world, rotors = _on_the_ground_with_a_runaway()
    step, digest, speeds, *_ = _run_until_failure(world, rotors)
    assert 10 < step < 30
    stepped, stepped_rotors = _on_the_ground_with_a_runaway()
    with pytest.raises(tumble.SimulationError, match="runaway") as info:
        for _ in range(100):
            stepped.step(1.0)
    assert info.value.step == step
    assert stepped.state.digest() == digest
    assert [r.speed for r in stepped_rotors] == speeds


@compiled_only("2 s of a 30-box pile, twice, and as many steps one by one")
@pytest.mark.parametrize("hz", [60, 240])
def test_contact_buffers_that_grow_within_a_call_give_the_bits_of_steps_one_by_one(hz):
    """Boxes dropped from rising heights meet the ground and each other one after the other, so the candidate pairs
    outgrow the buffers several times within one ``simulate``: the loop returns, the buffers grow (keeping the last
    step's contacts) and it goes on, with the bits of a step a call and of buffers grown beforehand."""

    def pile() -> tumble.World:
        world = tumble.World()
        world.add_static(tumble.Plane())
        for k in range(30):
            world.add_body(
                tumble.Box((0.2, 0.2, 0.2)), mass=1.0, position=(0.05 * (k % 3), 0.05 * (k % 2), 0.3 + 0.25 * k)
            )
        return world

    dt, steps = 1.0 / hz, 2 * hz
    called = pile()
    called.simulate(steps * dt, dt)
    assert called._scratch.manifolds.shape_a.shape[0] >= 8  # grown within the call from room for one pair
    stepped = pile()
    for _ in range(steps):
        stepped.step(dt)
    roomy = pile()
    roomy.step(dt)
    roomy._scratch.reserve_contacts(4096)
    roomy.simulate((steps - 1) * dt, dt)
    assert called.state.digest() == stepped.state.digest() == roomy.state.digest()


@compiled_only("the cache stamps compiled code")
def test_the_contact_loop_with_a_compiled_stage_is_stamped_with_the_stage_package():
    staged = runner._staged_contact_loop(native.command_stage)
    assert staged._cache._impl._locator.get_source_stamp() == _jit._package_stamp("control")
    assert runner._plain_contact_loop._cache._impl._locator.get_source_stamp() == _jit._package_stamp(None)


def test_a_kernel_that_raises_within_the_contact_loop_leaves_the_state_before_that_step(monkeypatch):
    """A kernel that divides by an overflowed value raises out of the compiled loop mid-step: the runner restores the
    backup the loop took before that step (bodies, contact rows, joints) and names the body that was fastest then."""
    world, _ = _on_the_ground_with_a_runaway()
    world.step(1.0)
    before = world.state.copy()
    loop = runner._plain_contact_loop

    def raise_mid_step(stage, record, count, *rest):
        """The loop's own bookkeeping for its first step (the backup and the progress, in the arrays the world's
        compiled record shares with the runner), then a ruined state and the error, as a kernel that raised there
        would leave them."""
        compiled, stored = world._scratch.compiled[1], world._scratch.stored
        body_state, joint_impulses = pipeline.body_state(world._state), world._state.joint_impulses
        runner._copy_state(body_state, stored, count, joint_impulses, *compiled.backup)
        compiled.progress[0], compiled.progress[1] = rest[-4], count
        for array in (*body_state[:4], *(rows[:count] for rows in stored[4:])):
            array[...] = np.nan
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(runner, "_plain_contact_loop", raise_mid_step)
    with pytest.raises(tumble.SimulationError, match="runaway") as info:
        world.simulate(3.0, 1.0)
    assert info.value.step == 1
    assert world.state.digest() == before.digest()
    monkeypatch.setattr(runner, "_plain_contact_loop", loop)
    world.step(1.0)  # and the world steps on from there
