"""The quadrotor's parts (issue 18): parameter sets, the mixer, the vehicle's handle, reference trajectories and the
errors at the boundary."""

from __future__ import annotations

import math

import numpy as np
import pytest

import tumble
from tumble.control import CascadedPID, Circle, Hover, Lissajous, MinimumSnap, SE3Controller
from tumble.vehicles import CRAZYFLIE, HUMMINGBIRD, Quadrotor, quadrotor_params, quadrotors


def quad(layout="x", params=CRAZYFLIE, **kw) -> Quadrotor:
    return Quadrotor(tumble.World(), params, position=(0.0, 0.0, 1.0), layout=layout, **kw)


def test_parameter_sets_are_read_only_and_hold_the_published_figures():
    assert CRAZYFLIE["mass"] == 0.03 and CRAZYFLIE["arm_length"] == 0.043
    np.testing.assert_array_equal(CRAZYFLIE["inertia"], np.diag([1.43e-5, 1.43e-5, 2.89e-5]))
    assert (CRAZYFLIE["k_thrust"], CRAZYFLIE["k_moment"]) == (2.3e-8, 7.8e-10)
    assert (CRAZYFLIE["k_drag"], CRAZYFLIE["k_inflow"], CRAZYFLIE["time_constant"]) == (1.02506e-6, 7.553e-7, 0.072)
    assert (CRAZYFLIE["speed_min"], CRAZYFLIE["speed_max"]) == (0.0, 2500.0)
    np.testing.assert_array_equal(CRAZYFLIE["rotor_directions"], [1, -1, 1, -1])
    assert HUMMINGBIRD["mass"] == 0.5 and HUMMINGBIRD["speed_max"] == 1500.0
    with pytest.raises(TypeError):
        CRAZYFLIE["mass"] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        CRAZYFLIE["inertia"][0, 0] = 1.0


def test_parameters_are_validated_by_name():
    with pytest.raises(ValueError, match=r"missing \['kd_att'\]"):
        quadrotor_params(**{k: v for k, v in CRAZYFLIE.items() if k != "kd_att"})
    with pytest.raises(ValueError, match=r"unknown \['colour'\]"):
        quadrotor_params(**CRAZYFLIE, colour="red")
    with pytest.raises(ValueError, match="mass must be > 0, got -1.0"):
        quadrotor_params(**{**CRAZYFLIE, "mass": -1.0})
    with pytest.raises(ValueError, match="rotor_directions must be four of"):
        quadrotor_params(**{**CRAZYFLIE, "rotor_directions": (1, 1, 0, -1)})
    with pytest.raises(ValueError, match="speed_min must be < speed_max"):
        quadrotor_params(**{**CRAZYFLIE, "speed_min": 3000.0})
    with pytest.raises(ValueError, match="inertia must be symmetric and positive definite"):
        quadrotor_params(**{**CRAZYFLIE, "inertia": -np.eye(3)})
    heavier = Quadrotor(tumble.World(), {**CRAZYFLIE, "mass": 0.035})  # a plain dict is validated and frozen
    assert heavier.body.mass == 0.035 and heavier.params["mass"] == 0.035


@pytest.mark.parametrize("layout", ["x", "+"])
def test_the_mixer_and_its_inverse_compose_to_the_identity(layout):
    mixer = quad(layout).mixer
    np.testing.assert_allclose(mixer.matrix @ mixer.inverse, np.eye(4), atol=1e-12)
    np.testing.assert_allclose(mixer.inverse @ mixer.matrix, np.eye(4), atol=1e-12)
    speeds = np.array([1500.0, 1700.0, 1900.0, 1600.0])
    np.testing.assert_allclose(mixer.allocate(*np.split(mixer.wrench(speeds), [1])[0], mixer.wrench(speeds)[1:]),
                               speeds, rtol=1e-12)  # fmt: skip


def test_the_plus_layout_gives_the_course_moments():
    """course/004 "Newton-Euler Equations": (L (F2 − F4), L (F3 − F1), M1 − M2 + M3 − M4)."""
    q = quad("+")
    speeds = np.array([1500.0, 1700.0, 1900.0, 1600.0])
    forces, torques = CRAZYFLIE["k_thrust"] * speeds**2, CRAZYFLIE["k_moment"] * speeds**2
    L = CRAZYFLIE["arm_length"]
    expected = [forces.sum(), L * (forces[1] - forces[3]), L * (forces[2] - forces[0]),
                torques[0] - torques[1] + torques[2] - torques[3]]  # fmt: skip
    np.testing.assert_allclose(q.mixer.wrench(speeds), expected, rtol=1e-12)


def test_the_mixer_matches_the_rotors_wrench_in_the_step():
    """The mixer's (T, M) is what the rotors do to the body: Euler's first step from rest gives it back."""
    world = tumble.World(gravity=(0, 0, 0), integrator="euler")
    q = Quadrotor(world, {**CRAZYFLIE, "time_constant": 0.0})
    speeds = np.array([1500.0, 1700.0, 1900.0, 1600.0])
    q.rotor_speeds = speeds
    q.command_rotor_speeds(speeds)
    h = 1e-4
    world.step(h)
    thrust, moments = q.mixer.wrench(speeds)[0], q.mixer.wrench(speeds)[1:]
    np.testing.assert_allclose(q.body.velocity, [0, 0, thrust / CRAZYFLIE["mass"] * h], rtol=1e-12)
    np.testing.assert_allclose(q.body.angular_velocity, np.linalg.solve(CRAZYFLIE["inertia"], moments) * h,
                               rtol=1e-9)  # fmt: skip


def test_allocate_under_saturation_keeps_the_thrust_then_roll_and_pitch_then_yaw():
    mixer = quad().mixer
    hover_thrust = CRAZYFLIE["mass"] * 9.81
    # A yaw moment far beyond what the rotors can give: the thrust and the roll moment are kept exactly.
    speeds = mixer.allocate(hover_thrust, (1e-5, 0.0, 1.0))
    wrench = mixer.wrench(speeds)
    assert np.all((speeds >= 0.0) & (speeds <= 2500.0))
    np.testing.assert_allclose(wrench[:3], [hover_thrust, 1e-5, 0.0], atol=1e-15, rtol=1e-10)
    assert 0.0 < wrench[3] < 1.0
    # Roll and pitch beyond the limits: the thrust kept, the tilting moment's direction kept, no yaw.
    speeds = mixer.allocate(hover_thrust, (3e-3, 4e-3, 0.0))
    T, Mx, My, Mz = mixer.wrench(speeds)
    assert T == pytest.approx(hover_thrust, rel=1e-10) and Mz == pytest.approx(0.0, abs=1e-15)
    assert My / Mx == pytest.approx(4.0 / 3.0, rel=1e-9) and 0.0 < Mx < 3e-3
    # More thrust than four rotors give: each rotor at its maximum.
    np.testing.assert_allclose(mixer.allocate(10.0, (0.0, 0.0, 0.0)), [2500.0] * 4)
    np.testing.assert_allclose(mixer.allocate(-1.0, (0.0, 0.0, 0.0)), [0.0] * 4)


def test_rotor_speeds_read_write_and_commands():
    q = quad()
    np.testing.assert_array_equal(q.rotor_speeds, [0.0] * 4)  # motors start at speed_min
    q.rotor_speeds = [100.0, 200.0, 300.0, 400.0]
    np.testing.assert_array_equal(q.rotor_speeds, [100.0, 200.0, 300.0, 400.0])
    q.command_rotor_speeds([1000.0, 3000.0, -5.0, 1.0])
    np.testing.assert_array_equal(q.commanded_rotor_speeds, [1000.0, 2500.0, 0.0, 1.0])  # clipped to the limits
    assert q.hover_rotor_speed == pytest.approx(math.sqrt(0.03 * 9.81 / (4 * 2.3e-8)), rel=1e-15)
    state = q.state()
    assert set(state) == {"position", "velocity", "orientation", "angular_velocity_body", "rotor_speeds"}
    np.testing.assert_array_equal(state["position"], [0, 0, 1])
    assert len(q.rotors) == 4 and all(r.body is q.body for r in q.rotors)


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        (lambda q: q.command_rotor_speeds([1.0, 2.0, 3.0]), ValueError, r"speeds must have shape \(4\), got shape"),
        (lambda q: q.command_rotor_speeds([1.0, 2.0, 3.0, float("nan")]), ValueError, "speeds must be finite"),
        (lambda q: setattr(q, "rotor_speeds", [0.0, 0.0, 0.0, 2600.0]), ValueError, "within"),
        (lambda q: q.mixer.allocate(1.0, (0.0, 0.0)), ValueError, "moments must have shape"),
        (lambda q: Quadrotor(q.world, layout="h"), ValueError, "layout must be 'x' or '\\+', got 'h'"),
        (lambda q: Quadrotor(q.world, params=3), TypeError, "params must be a mapping"),
        (lambda q: SE3Controller(q, kp_pos=-1.0), ValueError, r"kp_pos must be >= 0, got \[-1.0, -1.0, -1.0\]"),
        (lambda q: SE3Controller(q, kd_pos=(1.0, 2.0)), ValueError, r"kd_pos must have shape \(3\)"),
        (lambda q: SE3Controller(q, kp_att=-5.0), ValueError, "kp_att must be >= 0"),
        (lambda q: CascadedPID(q, ki_vel=(0.0, 0.0, -1.0)), ValueError, "ki_vel must be >= 0"),
        (lambda q: SE3Controller(tumble.World()), TypeError, "quad must be a tumble.vehicles.Quadrotor"),
        (lambda q: SE3Controller(q).update(0.0, {"velocity": (0, 0, 0)}), TypeError, "reference must be a mapping"),
        (lambda q: q.fly(object(), Hover((0, 0, 1))), TypeError, "controller must have update"),
        (lambda q: q.fly(SE3Controller(q), 5), TypeError, "trajectory must be callable"),
        (lambda q: q.autopilot.thrust_attitude(0.3, (0, 0, 0, 0)), ValueError, "orientation"),
    ],
)
def test_bad_input_is_refused_by_name(call, error, match):
    with pytest.raises(error, match=match):
        call(quad())


def test_a_controller_that_returns_nan_stops_the_run_naming_it_and_the_time():
    class Broken:
        def update(self, t, reference):
            return np.full(4, np.nan) if t >= 0.5 else np.zeros(4)

    q = quad()
    q.fly(Broken(), Hover((0, 0, 1)), rate=100)
    with pytest.raises(tumble.SimulationError, match=r"Broken on Hover.*Broken.update returned \[nan.*t = 0.5 s") as e:
        q.world.simulate(1.0, 0.01)
    assert e.value.controller == "Broken on Hover"
    assert q.world.time == pytest.approx(0.5)


def _finite_difference_check(traj, times, order_names=("position", "velocity", "acceleration", "jerk", "snap")):
    h = 1e-5
    for t in times:
        before, after = traj(t - h), traj(t + h)
        for lower, higher in zip(order_names, order_names[1:], strict=False):
            derivative = (after[lower] - before[lower]) / (2 * h)
            np.testing.assert_allclose(derivative, traj(t)[higher], atol=2e-5 * (1 + np.abs(traj(t)[higher]).max()))


@pytest.mark.parametrize(
    "traj",
    [
        Circle((1, 2, 3), 1.5, 0.3),
        Lissajous(1, 0.5, 1, 2, delta=0.3, center=(0, 0, 1)),
        Hover((1, 2, 3), yaw=0.5),
        MinimumSnap([(0, 0, 1), (1, 0, 1.5), (1, 2, 1), (0, 1, 2)], average_speed=1.0),
    ],  # fmt: skip
)
def test_each_reference_is_consistent_with_its_own_derivatives(traj):
    _finite_difference_check(traj, np.linspace(0.1, 3.7, 13))
    reference = traj(0.7)
    assert set(reference) == {"position", "velocity", "acceleration", "jerk", "snap", "yaw", "yaw_rate"}


def test_closed_form_references():
    np.testing.assert_allclose(Circle((0, 0, 1), 2.0, 0.25)(1.0)["position"], [0.0, 2.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(Lissajous(1, 0.5, 1, 2)(math.pi / 2)["position"], [1.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_array_equal(Hover((1, 2, 3))(7.0)["velocity"], [0, 0, 0])


def test_minimum_snap_passes_every_waypoint_at_its_time_continuous_to_snap():
    waypoints = np.array([(0, 0, 1), (1, 0, 1.5), (1, 2, 1), (0, 1, 2), (-1, -1, 1)], float)
    times = [0.0, 1.5, 3.0, 5.5, 7.0]
    traj = MinimumSnap(waypoints, times)
    for point, t in zip(waypoints, times, strict=True):
        np.testing.assert_allclose(traj(t)["position"], point, atol=1e-9)
    for t in times[1:-1]:
        before, after = traj(t - 1e-12), traj(t)  # the end of one piece, the start of the next
        for name in ("position", "velocity", "acceleration", "jerk", "snap"):
            np.testing.assert_allclose(before[name], after[name], atol=1e-9 * (1 + np.abs(after[name]).max()))
        pieces = traj._coefficients  # and exactly at the knot, from each polynomial
        k = times.index(t)
        for n in range(5):
            from tumble.control.trajectories import _basis

            left = _basis(n, 1.0) @ pieces[k - 1] / (times[k] - times[k - 1]) ** n
            right = _basis(n, 0.0) @ pieces[k] / (times[k + 1] - times[k]) ** n
            np.testing.assert_allclose(left, right, atol=1e-9 * (1 + np.abs(right).max()))
    for end in (times[0], times[-1]):  # from rest, to rest
        for name in ("velocity", "acceleration", "jerk"):
            np.testing.assert_allclose(traj(end)[name], 0.0, atol=1e-9)
    np.testing.assert_array_equal(traj(-1.0)["position"], waypoints[0])
    np.testing.assert_array_equal(traj(99.0)["position"], waypoints[-1])


def test_minimum_snap_default_times_follow_the_average_speed():
    traj = MinimumSnap([(0, 0, 0), (3, 0, 0), (3, 4, 0)], average_speed=2.0)
    np.testing.assert_allclose(traj.times, [0.0, 1.5, 3.5])
    assert traj.duration == 3.5


def test_minimum_snap_is_stationary_for_every_admissible_change():
    """A bump added to the path that keeps every constraint (zero at each waypoint's time, at rest at the ends)
    changes ∫ |snap|² by 2 a ∫ snap · bump⁽⁴⁾ + a² ∫ bump⁽⁴⁾²: at the optimum the first-order term vanishes. The
    same check fails on a path that stops at each waypoint (piecewise minimum snap, not continuous to snap)."""
    t = np.linspace(0.0, 2.0, 4001)
    h = 1e-3

    def bump_snap(s):  # the 4th derivative of sin(π s) sin(π s / 2)⁸: zero with 7 derivatives at s = 0 and 2, and
        # zero at s = 1 with its velocity free (a change the stop-and-go path below may not make)
        values = [np.sin(np.pi * x) * np.sin(np.pi * x / 2) ** 8 for x in s + h * np.arange(-2, 3)]
        return (values[0] - 4 * values[1] + 6 * values[2] - 4 * values[3] + values[4]) / h**4

    bump = np.array([bump_snap(s) for s in t])

    def first_order(snap_x):
        return abs(np.trapezoid(snap_x * bump, t)) / math.sqrt(np.trapezoid(snap_x**2, t) * np.trapezoid(bump**2, t))

    optimal = MinimumSnap([(0, 0, 0), (1, 1, 0), (2, 0, 0)], [0.0, 1.0, 2.0])
    stop_and_go = [MinimumSnap([(0, 0, 0), (1, 1, 0)], [0.0, 1.0]), MinimumSnap([(1, 1, 0), (2, 0, 0)], [1.0, 2.0])]
    assert first_order(np.array([optimal(s)["snap"][0] for s in t])) < 1e-6
    piecewise = np.array([stop_and_go[0 if s < 1.0 else 1](s)["snap"][0] for s in t])
    assert first_order(piecewise) > 1e-2


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"waypoints": [(0, 0, 0)]}, r"waypoints must have shape \(n, 3\) with n >= 2"),
        ({"waypoints": [(0, 0, 0), (1, 0, 0)], "times": [0.0, 1.0, 2.0]}, "one time per waypoint: 2 waypoints"),
        ({"waypoints": [(0, 0, 0), (1, 0, 0)], "times": [1.0, 1.0]}, "times must increase strictly"),
        ({"waypoints": [(0, 0, 0), (0, 0, 0)]}, "waypoints 0 and 1 are the same point"),
        ({"waypoints": [(0, 0, 0), (1, 0, 0)], "average_speed": 0.0}, "average_speed must be > 0"),
        ({"waypoints": [(0, 0, 0), (1, 0, float("inf"))]}, "waypoints must be finite"),
        ({"waypoints": [(0, 0, 0), (1, 0, 0), (2, 0, 0)], "times": [0.0, 1e-6, 1e3]}, "too unequal to solve for"),
    ],
)
def test_minimum_snap_refuses_bad_input(kwargs, match):
    with pytest.raises(ValueError, match=match):
        MinimumSnap(**kwargs)


def test_reference_constructors_refuse_bad_input():
    with pytest.raises(ValueError, match="radius must be > 0"):
        Circle((0, 0, 0), -1.0, 0.2)
    with pytest.raises(ValueError, match=r"center must have shape \(3\)"):
        Circle((0, 0), 1.0, 0.2)
    with pytest.raises(TypeError, match="t must be a real number"):
        Hover((0, 0, 0))("now")


def test_a_quadrotor_attaches_itself_once_and_the_world_lists_it():
    world = tumble.World()
    a = Quadrotor(world, name="a")
    b = Quadrotor(world, position=(1.0, 0.0, 0.0), name="b")
    assert world.attachments == (a, b)
    assert quadrotors(world) == [a, b] and quadrotors(None) == []
    with pytest.raises(ValueError, match="attached to this world already"):
        world.attach(a)
    assert world.attachments == (a, b)
