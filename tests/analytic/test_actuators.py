"""Actuators and drag (issue 17, parts 2 and 4): rotors, thrusters and parasitic drag against closed forms."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import tumble
from tumble.actuators import Rotor, Thruster
from tumble.rotation import quat_from_axis_angle, quat_to_matrix

G = 9.81
K_THRUST, K_MOMENT = 2.3e-8, 7.8e-11  # a Crazyflie's rotor (RotorPy's parameters) [N s², N m s²]


def plate(integrator: str = "auto", ground: bool = False, **body) -> tuple[tumble.World, tumble.Body]:
    world = tumble.World(integrator=integrator)
    if ground:
        world.add_static(tumble.Plane())
    body.setdefault("position", (0.0, 0.0, 1.0))
    return world, world.add_body(tumble.Box((0.3, 0.2, 0.04)), mass=1.5, **body)


@pytest.mark.parametrize("spin", [1, -1])
def test_a_rotor_at_constant_speed_gives_newton_euler_accelerations(spin):
    """Explicit Euler's first step is the derivative itself: Δv/h = R Σf / m + g and ΔL/h = R M, to round-off; the
    body-frame angular acceleration is then I⁻¹(M − ω × Iω), checked by a central difference of RK4 steps."""
    q0 = quat_from_axis_angle((1.0, 2.0, 0.5), 0.7)
    world, body = plate("euler", orientation=q0, angular_velocity=(0.3, -0.2, 0.5))
    position, axis = np.array([0.1, -0.05, 0.02]), np.array([0.1, 0.2, 1.0]) / np.linalg.norm([0.1, 0.2, 1.0])
    rotor = world.add_actuator(Rotor(body, position, axis, spin, K_THRUST, K_MOMENT))
    rotor.speed = 20000.0
    rotor.command(20000.0)
    f = K_THRUST * 20000.0**2 * axis
    moment = np.cross(position, f) + spin * K_MOMENT * 20000.0**2 * axis
    rotation = quat_to_matrix(body.orientation)
    v0, l0, h = body.velocity.copy(), world.state.body_angmom[0].copy(), 1e-4
    world.step(h)
    np.testing.assert_allclose((body.velocity - v0) / h, rotation @ f / 1.5 + (0, 0, -G), rtol=0, atol=1e-9)
    np.testing.assert_allclose((world.state.body_angmom[0] - l0) / h, rotation @ moment, rtol=0, atol=1e-12)
    # The reaction torque's sign follows spin: the moment about the axis is spin k_moment ω² (p × f ⊥ f ∥ axis).
    assert np.dot(moment, axis) == pytest.approx(spin * K_MOMENT * 20000.0**2, rel=1e-12)
    assert rotor.thrust == pytest.approx(K_THRUST * 4e8) and rotor.torque == pytest.approx(spin * K_MOMENT * 4e8)

    # Angular acceleration in the body frame: I ω̇ = M − ω × I ω.
    def body_rate(dt):
        w, b = plate("rk4", orientation=q0, angular_velocity=(0.3, -0.2, 0.5))
        r = w.add_actuator(Rotor(b, position, axis, spin, K_THRUST, K_MOMENT))
        r.speed = 20000.0
        r.command(20000.0)
        if dt > 0:
            w.step(dt)
        return b.angular_velocity_body, b.inertia_body

    dt = 1e-5
    (w_plus, inertia), (w_zero, _) = body_rate(dt), body_rate(0.0)
    expected = np.linalg.solve(inertia, moment - np.cross(w_zero, inertia @ w_zero))
    np.testing.assert_allclose((w_plus - w_zero) / dt, expected, rtol=1e-4, atol=1e-6)


@pytest.mark.parametrize("dt", [1e-4, 1e-3, 1e-2])
def test_a_motor_reaches_one_minus_one_over_e_of_a_step_after_one_time_constant(dt):
    world, body = plate()
    rotor = world.add_actuator(Rotor(body, (0, 0, 0), (0, 0, 1), 1, K_THRUST, K_MOMENT, speed_min=1000.0,
                                     speed_max=25000.0, time_constant=0.05))  # fmt: skip
    assert rotor.speed == rotor.commanded_speed == 1000.0  # a motor starts at its lowest speed
    rotor.command(21000.0)
    world.simulate(0.05, dt)
    assert rotor.speed == pytest.approx(1000.0 + 20000.0 * (1 - math.exp(-1)), rel=1e-12)
    rotor.command(1e9)  # clipped to the limits
    assert rotor.commanded_speed == 25000.0
    rotor.command(-5.0)
    assert rotor.commanded_speed == 1000.0


def lift_off_height(t: float, omega: float, tau: float, mass: float, rotors: int = 1) -> float:
    """Height gained by a body from rest under ``rotors`` k ω(t)² − m g with ω(t) = omega (1 − e^(−t/τ)) (the
    double integral of ω² = omega² (1 − 2 e^(−t/τ) + e^(−2t/τ)))."""
    e1, e2 = 1 - math.exp(-t / tau), 1 - math.exp(-2 * t / tau)
    double = t * t / 2 - 2 * tau * (t - tau * e1) + tau / 2 * (t - tau / 2 * e2)
    return rotors * K_THRUST * omega**2 * double / mass - G * t * t / 2


def test_rk4_sees_the_thrust_at_each_stage_of_the_motor_lag():
    """Four rotors spin up from rest with a 30 ms lag: RK4 follows the exact height to 1e-8 m over 1 s at dt 1e-3
    (measured 1.6e-9 m, and 1.3e-13 m at dt 1e-4: fourth order; holding the speed over each step would miss by
    about 2e-3 m)."""
    world, body = plate("rk4")
    omega = math.sqrt(2.0 * 1.5 * G / (4 * K_THRUST))  # twice the hover thrust
    for x, y, spin in ((0.1, 0.1, 1), (-0.1, 0.1, -1), (-0.1, -0.1, 1), (0.1, -0.1, -1)):
        world.add_actuator(Rotor(body, (x, y, 0), (0, 0, 1), spin, K_THRUST, K_MOMENT, time_constant=0.03)).command(
            omega
        )
    world.simulate(1.0, 1e-3)
    assert body.position[2] - 1.0 == pytest.approx(lift_off_height(1.0, omega, 0.03, 1.5, 4), abs=1e-8)
    np.testing.assert_allclose(body.angular_velocity, 0.0, atol=1e-12)  # the four reactions cancel


# Measured at dt 1e-3 (and 1e-4): Euler 1.4e-2 m (1.4e-3), semi-implicit 4.9e-3 (4.9e-4), midpoint 1.6e-6 (1.6e-8).
@pytest.mark.parametrize(
    ("integrator", "tolerance"), [("euler", 2e-2), ("symplectic", 7e-3), ("rk4", 1e-8), ("midpoint", 3e-6)]
)
def test_every_integrator_lifts_off_as_the_closed_form(integrator, tolerance):
    world, body = plate(integrator)
    omega = math.sqrt(2.0 * 1.5 * G / K_THRUST)
    world.add_actuator(Rotor(body, (0, 0, 0), (0, 0, 1), 1, K_THRUST, 0.0, time_constant=0.03)).command(omega)
    world.simulate(1.0, 1e-3)
    assert body.position[2] - 1.0 == pytest.approx(lift_off_height(1.0, omega, 0.03, 1.5), abs=tolerance)


@pytest.mark.parametrize("rate", [60, 240, 1000])
def test_a_rotor_lifts_a_body_off_the_ground_with_contacts(rate):
    world, body = plate(ground=True, position=(0, 0, 0.02))
    omega = math.sqrt(2.0 * 1.5 * G / K_THRUST)
    rotor = world.add_actuator(Rotor(body, (0, 0, 0), (0, 0, 1), 1, K_THRUST, 0.0))
    world.simulate(1.0, 1 / rate)  # at rest on the ground
    assert body.position[2] == pytest.approx(0.02, abs=1e-3)
    rotor.command(omega)
    world.simulate(1.0, 1 / rate)
    assert body.position[2] - 0.02 == pytest.approx(G / 2, rel=0.02)  # (2 g − g) t² / 2


@pytest.mark.parametrize("rate", [60, 240, 1000])
def test_a_thruster_holds_a_hinged_arm_level(rate):
    """A 1 m rod hinged at one end, a thruster at its tip pushing up with half its weight: static equilibrium."""
    world = tumble.World()
    rod = world.add_body(tumble.Box((1.0, 0.05, 0.05)), mass=2.0, position=(0.5, 0, 1.0))
    world.add_joint(tumble.HingeJoint(rod, None, anchor=(0, 0, 1.0), axis=(0, 1, 0)))
    thruster = world.add_actuator(Thruster(rod, (0.5, 0, 0), (0, 0, 1), max_force=50.0))
    thruster.command(2.0 * G / 2)
    world.simulate(2.0, 1 / rate)
    assert abs(rod.position[2] - 1.0) < 1e-4
    thruster.command(-3.0)  # a thruster only pushes
    assert thruster.commanded_force == 0.0
    thruster.command(500.0)
    assert thruster.commanded_force == 50.0


def test_a_thruster_force_turns_with_its_body():
    world, body = plate("rk4", orientation=quat_from_axis_angle((0, 1, 0), math.pi / 2))
    world.gravity = (0, 0, 0)
    world.add_actuator(Thruster(body, (0, 0, 0), (0, 0, 1), max_force=10.0)).command(3.0)
    world.simulate(1.0, 1e-2)
    np.testing.assert_allclose(body.velocity, (2.0, 0, 0), atol=1e-12)  # body z is world x: 3 N / 1.5 kg


def test_drag_brings_a_falling_body_to_its_terminal_speed():
    world, body = plate("rk4", position=(0, 0, 100.0))
    world.add_drag(body, (0.0, 0.0, 0.2))
    world.simulate(10.0, 1e-2)
    assert -body.velocity[2] == pytest.approx(math.sqrt(1.5 * G / 0.2), rel=1e-6)


def test_commands_from_a_controller_hold_between_its_calls():
    world, body = plate()
    rotor = world.add_actuator(Rotor(body, (0, 0, 0), (0, 0, 1), 1, K_THRUST, K_MOMENT))
    seen = []
    world.add_controller(lambda w, t: rotor.command(1000.0 * (1 + round(50 * t))), rate=50)
    world.add_controller(lambda w, t: seen.append(rotor.speed), name="probe")
    world.simulate(0.2, 1e-3)
    assert seen[1:] == [1000.0 * (1 + k // 20) for k in range(199)]


@pytest.mark.parametrize(
    ("make", "error", "message"),
    [
        (lambda b: Rotor(b, (0, 0, 0), (0, 0, 1), 1, -1.0, 0.0), ValueError, r"k_thrust must be >= 0, got -1.0"),
        (lambda b: Rotor(b, (0, 0, 0), (0, 0, 1), 1, 1.0, -2.0), ValueError, r"k_moment must be >= 0"),
        (lambda b: Rotor(b, (0, 0, 0), (0, 0, 1), 1, 1.0, 0.0, k_drag=-1), ValueError, r"k_drag must be >= 0"),
        (lambda b: Rotor(b, (0, 0, 0), (0, 0, 1), 1, 1.0, 0.0, k_inflow=-1), ValueError, r"k_inflow must be >= 0"),
        (lambda b: Rotor(b, (0, 0, 0), (0, 0, 1), 1, 1, 0, time_constant=-1), ValueError, r"time_constant must be"),
        (lambda b: Rotor(b, (0, 0, 0), (0, 0, 1), 1, 1, 0, speed_min=5, speed_max=4), ValueError,
         r"speed_min must be <= speed_max, got speed_min=5.0 > speed_max=4.0"),
        (lambda b: Rotor(b, (0, 0, 0), (0, 0, 1), 0, 1.0, 0.0), ValueError, r"spin must be \+1 or -1, got 0"),
        (lambda b: Rotor(b, (0, 0, 0), (0, 0, 0), 1, 1.0, 0.0), ValueError, r"axis must be a non-zero vector"),
        (lambda b: Rotor(b, (0, 0, math.nan), (0, 0, 1), 1, 1.0, 0.0), ValueError, r"position"),
        (lambda b: Rotor("body", (0, 0, 0), (0, 0, 1), 1, 1.0, 0.0), TypeError, r"body must be a tumble.Body"),
        (lambda b: Thruster(b, (0, 0, 0), (1, 0, 0), max_force=-1), ValueError, r"max_force must be >= 0"),
        (lambda b: Thruster(b, (0, 0, 0), (0, 0, 0), max_force=1), ValueError, r"direction must be a non-zero"),
    ],
)  # fmt: skip
def test_bad_actuators_are_refused(make, error, message):
    _, body = plate()
    with pytest.raises(error, match=message):
        make(body)


def test_actuators_and_drag_need_a_dynamic_body_of_this_world():
    world, body = plate()
    ground = world.add_static(tumble.Plane(), name="ground")
    other_world, other = plate()
    with pytest.raises(ValueError, match="body 'ground' is static: an actuator needs a dynamic body"):
        world.add_actuator(Rotor(ground, (0, 0, 0), (0, 0, 1), 1, 1.0, 0.0))
    with pytest.raises(ValueError, match="belongs to another world"):
        world.add_actuator(Rotor(other, (0, 0, 0), (0, 0, 1), 1, 1.0, 0.0))
    with pytest.raises(TypeError, match="actuator must be a tumble.actuators.Rotor or Thruster"):
        world.add_actuator("rotor")
    rotor = world.add_actuator(Rotor(body, (0, 0, 0), (0, 0, 1), 1, 1.0, 0.0))
    with pytest.raises(ValueError, match="in a world already"):
        other_world.add_actuator(rotor)
    with pytest.raises(ValueError, match=r"coefficients must be >= 0, got \[0.0, -1.0, 0.0\]"):
        world.add_drag(body, (0, -1, 0))
    with pytest.raises(ValueError, match="static"):
        world.add_drag(ground, (1, 1, 1))
    with pytest.raises(ValueError, match=r"speed must be >= 0, got -1.0"):
        rotor.speed = -1.0
    bounded = world.add_actuator(Rotor(body, (0, 0, 0), (0, 0, 1), 1, 1.0, 0.0, speed_min=10, speed_max=20))
    with pytest.raises(ValueError, match=r"speed must be within \[speed_min, speed_max\] = \[10.0, 20.0\], got 30.0"):
        bounded.speed = 30.0
    assert bounded.speed == 10.0
    assert world.actuators == [rotor, bounded]


def test_the_worked_example_of_docs_actuators_md_hovers_at_one_metre():
    text = (Path(__file__).resolve().parents[2] / "docs" / "actuators.md").read_text()
    namespace: dict = {}
    exec(re.search(r"```python\n(.*?)```", text, re.S).group(1), namespace)
    plate, rotors = namespace["plate"], namespace["rotors"]
    assert plate.position[2] == pytest.approx(1.0, abs=2e-3)
    hover = math.sqrt(1.5 * G / (4 * 2.3e-8))
    assert [rotor.speed for rotor in rotors] == pytest.approx([hover] * 4, rel=1e-3)
    # The closed form of level flight in quadratic drag; measured 0.503 m/s, the climb adding to |v_air| at first.
    assert plate.velocity[0] == pytest.approx(2.0 - 2.0 / (1 + 0.05 * 2.0 * 5.0 / 1.5), abs=5e-3)
