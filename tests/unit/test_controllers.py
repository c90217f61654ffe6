"""Controllers (issue 17, part 1): callbacks before the steps, at their own rate, with a counted clock."""

from __future__ import annotations

import math

import numpy as np
import pytest

import tumble


def falling_ball(plane: bool = False) -> tuple[tumble.World, tumble.Body]:
    world = tumble.World()
    if plane:
        world.add_static(tumble.Plane())
    ball = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0, 0, 1.0), name="ball")
    return world, ball


@pytest.mark.parametrize("plane", [False, True], ids=["free", "contacts"])
def test_a_50_hz_controller_in_a_1_khz_world_runs_every_20th_step(plane):
    world, _ = falling_ball(plane)
    calls = []
    world.add_controller(lambda w, t: calls.append((w.step_count, t)), rate=50)
    world.simulate(1.0, 1e-3)
    assert [step for step, _ in calls] == list(range(0, 1000, 20))
    np.testing.assert_allclose([t for _, t in calls], np.arange(50) / 50, rtol=0, atol=1e-15)


def test_time_is_counted_not_accumulated():
    """A 10 s run at 100 Hz is exactly 1000 steps, and the last step starts at 9.99 s (accumulating 0.01 would
    drift by round-off); a 100 Hz controller then runs at every one of them."""
    world, _ = falling_ball()
    times = []
    world.add_controller(lambda w, t: times.append(t), rate=100)
    world.simulate(10.0, 0.01)
    assert world.step_count == len(times) == 1000
    assert times[-1] == 999 * 0.01
    assert times[700] == 7.0


def test_without_a_rate_it_runs_before_every_step_and_step_runs_it_too():
    world, _ = falling_ball()
    calls = []
    world.add_controller(lambda w, t: calls.append(w.step_count))
    world.simulate(0.1, 0.01)
    world.step(0.01)
    assert calls == list(range(11))


def test_a_controller_faster_than_the_world_runs_once_per_step():
    world, _ = falling_ball()
    handle = world.add_controller(lambda w, t: None, rate=1000, name="fast")
    world.simulate(0.5, 0.01)
    assert handle.calls == 50


def test_a_controller_slower_than_a_step_that_does_not_divide_its_period():
    """Ticks every 1/30 s with steps of 1/100 s: each runs at the first step at or past it (t = 0, 0.04, 0.07, ...)."""
    world, _ = falling_ball()
    times = []
    world.add_controller(lambda w, t: times.append(round(t, 12)), rate=30)
    world.simulate(1.0, 0.01)
    expected = [math.ceil(k / 30 * 100 - 1e-9) / 100 for k in range(30)]
    assert times == expected


def test_what_a_controller_commands_holds_until_its_next_call():
    """A 10 Hz controller sets a force that an every-step controller applies: the force changes every 10th step."""
    world, ball = falling_ball()
    command = {"force": 0.0}
    seen = []
    world.add_controller(lambda w, t: command.update(force=round(10 * t)), rate=10, name="planner")
    world.add_controller(lambda w, t: (ball.apply_force((command["force"], 0, 0)), seen.append(command["force"])))
    world.simulate(1.0, 0.01)
    assert seen == [k // 10 for k in range(100)]
    # The force acted in every step: v_x = Σ F dt / m.
    assert ball.velocity[0] == pytest.approx(sum(seen) * 0.01)


def test_removed_controllers_stop():
    world, _ = falling_ball()
    handle = world.add_controller(lambda w, t: None, name="once")
    world.simulate(0.05, 0.01)
    handle.remove()
    world.simulate(0.05, 0.01)
    assert handle.calls == 5 and world.controllers == []
    with pytest.raises(ValueError, match="controller 'once' is not in this world"):
        handle.remove()


@pytest.mark.parametrize("plane", [False, True], ids=["free", "contacts"])
def test_an_exception_names_the_controller_and_the_time_and_keeps_the_recording(plane):
    world, ball = falling_ball(plane)

    def autopilot(w, t):
        if t >= 0.25:
            raise RuntimeError("sensor timeout")

    world.add_controller(autopilot, rate=100)
    with pytest.raises(tumble.SimulationError, match=r"controller 'autopilot' raised RuntimeError: sensor timeout "
                                                     r"at t = 0\.25 s") as caught:  # fmt: skip
        world.simulate(1.0, 0.01)
    error = caught.value
    assert error.controller == "autopilot" and error.step == 25 and error.body is None
    assert isinstance(error.__cause__, RuntimeError)
    assert world.step_count == 25
    assert len(error.trajectory.time) == 26  # the initial state and the 25 steps before the failure
    np.testing.assert_array_equal(error.trajectory.position[-1, ball.index], ball.position)


def test_an_exception_in_step_leaves_the_world_as_it_was():
    world, ball = falling_ball()
    world.add_controller(lambda w, t: 1 / 0, name="divider")
    before = ball.position.copy()
    with pytest.raises(tumble.SimulationError, match=r"controller 'divider' raised ZeroDivisionError.*t = 0 s"):
        world.step(0.01)
    assert world.step_count == 0
    np.testing.assert_array_equal(ball.position, before)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"callback": 3}, TypeError, r"callback must be callable as callback\(world, t\), got 3"),
        ({"callback": None}, TypeError, r"callback must be callable"),
        ({"rate": 0}, ValueError, r"rate must be a finite number of Hz > 0 or None, got 0"),
        ({"rate": -5.0}, ValueError, r"rate must be .* got -5.0"),
        ({"rate": float("nan")}, ValueError, r"rate must be .* got nan"),
        ({"rate": "fast"}, ValueError, r"rate must be .* got 'fast'"),
        ({"rate": True}, ValueError, r"rate must be .* got True"),
        ({"name": 7}, TypeError, r"name must be a string or None, got 7"),
    ],
)
def test_bad_controllers_are_refused(kwargs, error, message):
    world, _ = falling_ball()
    arguments = {"callback": lambda w, t: None, **kwargs}
    with pytest.raises(error, match=message):
        world.add_controller(**arguments)
    assert world.controllers == []


def test_the_handle_names_itself():
    world, _ = falling_ball()

    def hover(w, t):
        pass

    assert repr(world.add_controller(hover, rate=100)) == "<Controller 'hover' at 100 Hz, 0 calls>"
    assert world.add_controller(hover, name="other").name == "other"


@pytest.mark.parametrize("plane", [False, True], ids=["free", "contacts"])
def test_a_controller_that_does_nothing_changes_nothing(plane):
    """Step by step from Python (with a controller) or in one compiled call: the same recording, bit for bit."""

    def recorded(with_controller):
        world, ball = falling_ball(plane)
        ball.angular_velocity = (1.0, 2.0, 3.0)
        if with_controller:
            world.add_controller(lambda w, t: None, rate=7)
        return world.simulate(1.5, 0.01, record_every=3)

    a, b = recorded(True), recorded(False)
    np.testing.assert_array_equal(a.time, b.time)
    np.testing.assert_array_equal(a.position, b.position)
    np.testing.assert_array_equal(a.orientation, b.orientation)


def test_the_clock_counts_steps_and_starts_again_where_time_is_set_apart():
    from tumble.control import StepClock

    clock = StepClock()
    assert clock.start_of_next_step(0.0, 0, 0.01) == 0.0
    assert clock.start_of_next_step(0.9999999999999999, 100, 0.01) == 1.0  # counted, not the accumulated sum
    assert clock.start_of_next_step(5.0, 100, 0.01) == 5.0  # a state restored from elsewhere
    assert clock.start_of_next_step(5.02, 102, 0.01) == 5.0 + 2 * 0.01
    assert clock.start_of_next_step(5.04, 103, 0.02) == 5.04  # a new dt counts from here
