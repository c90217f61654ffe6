"""Flights inside the compiled loop (``tumble.control.native``, a compiled stage of ``tumble.controllers``):
``world.simulate`` of free-flying vehicles flown by the SE(3) controller on a known reference takes all its steps
in one kernel call, and flies exactly as the step-by-step path does."""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble import world_stepping
from tumble.control import Circle, Hover, Lissajous, MinimumSnap, SE3Controller
from tumble.vehicles import Quadrotor

REFERENCES = [
    (Lissajous(1.0, 0.5, 1.0, 2.0, center=(0.0, 0.0, 1.0)), {}),
    (Circle((0.0, 0.0, 1.0), 1.0, 0.2), {"ki_pos": 1.0}),
    (Hover((0.2, 0.0, 1.0)), {"ki_pos": 2.0}),
    (MinimumSnap([(0, 0, 1), (1, 0, 1.5), (1, 1, 1)], average_speed=0.7), {"feedforward": True}),
]


def flight(reference, gains, rate, stepwise: bool, wind=None):
    world = tumble.World()
    world.wind = wind
    quad = Quadrotor(world, position=reference(0.0)["position"])
    quad.rotor_speeds = [quad.hover_rotor_speed] * 4
    handle = quad.fly(SE3Controller(quad, **gains), reference, rate=rate)
    if stepwise:  # a second controller that does nothing keeps simulate stepping from Python
        world.add_controller(lambda world, t: None, name="idle")
    return world, quad, handle


@pytest.mark.parametrize(("reference", "gains"), REFERENCES, ids=["lissajous", "circle", "hover", "minimum_snap"])
@pytest.mark.parametrize("rate", [None, 100.0])
def test_the_compiled_flight_is_the_stepwise_flight(reference, gains, rate):
    runs = []
    for stepwise in (False, True):
        world, quad, handle = flight(reference, gains, rate, stepwise, wind=(1.0, 0.5, 0.0))
        recording = world.simulate(3.0, 0.002, record_every=5)
        world.simulate(0.5, 0.002)  # a second call carries the ticks and the integral on
        runs.append((recording, world, quad, handle))
    (a, wa, qa, ha), (b, wb, qb, hb) = runs
    tolerance = 0.0  # the same kernels in the same order
    np.testing.assert_allclose(a.position, b.position, rtol=0, atol=tolerance)
    np.testing.assert_allclose(wa.state.body_pos, wb.state.body_pos, rtol=0, atol=tolerance)
    np.testing.assert_allclose(qa.commanded_rotor_speeds, qb.commanded_rotor_speeds, rtol=1e-12)
    assert ha.calls == hb.calls == (1750 if rate is None else 350)
    assert wa.time == wb.time and wa.step_count == wb.step_count
    np.testing.assert_allclose(qa._flight.controller._integral.value, qb._flight.controller._integral.value,
                               rtol=0, atol=tolerance)  # fmt: skip


@pytest.mark.parametrize("dt", [0.01, 1 / 240, 0.001])
def test_the_compiled_flight_is_the_stepwise_flight_at_every_step_size(dt):
    """The controller at 100 Hz in worlds at 100, 240 (ticks fall between steps) and 1000 Hz."""
    reference = MinimumSnap([(0, 0, 1), (1, 0, 1.5), (1, 1, 1), (0, 1, 1)], average_speed=0.8)
    final = []
    for stepwise in (False, True):
        world, quad, handle = flight(reference, {"ki_pos": 1.0}, 100.0, stepwise)
        world.simulate(reference.duration, dt)
        final.append((world.state.body_pos.copy(), handle.calls))
    np.testing.assert_array_equal(final[0][0], final[1][0])
    assert final[0][1] == final[1][1]


def test_the_compiled_flights_are_used_only_when_every_controller_is_one():
    world, quad, _ = flight(Hover((0.0, 0.0, 1.0)), {}, None, stepwise=False)
    assert world_stepping._compiled_stage(world) is not None
    world.add_static(tumble.Plane())  # contacts: a step per call, the flights compiled between them
    assert world_stepping._compiled_stage(world) is not None
    world, quad, _ = flight(Hover((0.0, 0.0, 1.0)), {}, None, stepwise=True)
    assert world_stepping._compiled_stage(world) is None


@pytest.mark.parametrize("dt", [0.01, 1 / 240])
def test_with_contacts_the_compiled_flights_fly_as_python_controllers(dt):
    """Two vehicles over a ground (so contacts and a step per call), one landing on it: the flights compiled
    between the steps and the Python controllers give the same run, bit for bit."""
    runs = []
    for stepwise in (False, True):
        world = tumble.World()
        world.add_static(tumble.Plane())
        landing = MinimumSnap([(3.0, 0.0, 1.0), (3.0, 0.0, 0.0)], [0.0, 3.0])
        for reference in (Circle((0.0, 0.0, 1.0), 1.0, 0.2), landing):
            quad = Quadrotor(world, position=reference(0.0)["position"])
            quad.rotor_speeds = [quad.hover_rotor_speed] * 4
            quad.fly(SE3Controller(quad, ki_pos=1.0), reference, rate=100.0)
        if stepwise:
            world.add_controller(lambda world, t: None, name="idle")
        recording = world.simulate(4.0, dt, record_every=4)
        runs.append((recording.position, [c.calls for c in world.controllers][:2], len(world.contacts().body_a)))
    np.testing.assert_array_equal(runs[0][0], runs[1][0])
    assert runs[0][1] == runs[1][1] and runs[0][2] == runs[1][2] >= 4


def test_a_body_that_fails_mid_run_stops_the_compiled_flight_as_the_stepwise_one_does():
    """A shapeless body pushed by 2e307 N overflows after a few steps of 0.5 s: both paths stop at the same step,
    every body as it was after the step before, the recording up to it."""
    outcomes = []
    for stepwise in (False, True):
        world, quad, _ = flight(Hover((0.0, 0.0, 1.0)), {}, None, stepwise=stepwise)
        rock = world.add_body(None, mass=1.0, inertia=np.eye(3), position=(5.0, 0.0, 1.0), name="rock")
        rock.constant_force = (2e307, 0.0, 0.0)
        assert (world_stepping._compiled_stage(world) is None) == stepwise
        with pytest.raises(tumble.SimulationError, match=r"body 'rock' became non-finite") as error:
            world.simulate(10.0, 0.5)
        assert error.value.step == world.step_count > 0 and np.isfinite(world.state.body_pos).all()
        assert len(error.value.trajectory) == world.step_count + 1
        outcomes.append((world.step_count, world.state.body_pos.copy()))
    assert outcomes[0][0] == outcomes[1][0]
    np.testing.assert_array_equal(outcomes[0][1], outcomes[1][1])


def test_a_flight_that_asks_for_nan_stops_both_paths_alike():
    """A gain set to NaN behind the controller's back: both paths stop before the first step with the same error,
    naming the controller and the time."""
    messages = []
    for stepwise in (False, True):
        world, quad, handle = flight(Hover((0.0, 0.0, 1.0)), {}, None, stepwise)
        world.simulate(0.1, 0.01)
        quad._flight.controller.kp_att = float("nan")
        with pytest.raises(tumble.SimulationError, match=r"controller 'SE3Controller on Hover' raised ValueError: "
                           r"SE3Controller.update returned \[nan.*at t = 0.1 s") as error:  # fmt: skip
            world.simulate(0.1, 0.01)
        assert error.value.controller == "SE3Controller on Hover" and world.step_count == 10
        messages.append(str(error.value))
    assert messages[0] == messages[1]
