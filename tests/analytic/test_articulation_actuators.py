"""Actuators on an articulation's joints against closed-form motions (the comparison with MuJoCo's actuators on real
models is in tests/peers/test_mjcf_models.py).

A motor pushes its joint with ``gear · ctrl``: a free wheel of moment ``I`` spins up at ``gear · ctrl / I``. A
position servo (``gain = kp``, ``bias = (0, -kp, -kv)``) is a spring ``kp g²`` and damper ``kv g²`` about
``q = ctrl / g``: it holds its target, and oscillates there at ``ω² = kp g² / I``. A velocity servo
(``gain = kv``, ``bias = (0, 0, -kv)``) drives ``q̇`` to ``ctrl / g`` with the time constant ``I / (kv g²)``.
Controls are clipped to ``ctrl_range``.
"""

from __future__ import annotations

import numpy as np
import pytest

from tumble.articulation import Articulation, Ball, Prismatic, Revolute

INERTIA = 0.5  # a point mass of 2 kg at 0.5 m


def wheel(**actuator) -> Articulation:
    art = Articulation(gravity=(0.0, 0.0, 0.0))
    link = art.add_link(Revolute((0, 0, 1)), mass=2.0, shape_position=(0.5, 0.0, 0.0))
    art.add_actuator(link, **actuator)
    return art


@pytest.mark.parametrize("integrator", ["euler", "symplectic", "rk4"])
def test_a_motor_spins_a_wheel_up_at_gear_times_control_over_its_inertia(integrator):
    art = wheel(gear=3.0, ctrl_range=(-1.0, 1.0))
    art.ctrl = [0.4]
    assert art.forward_dynamics()[0] == pytest.approx(3.0 * 0.4 / INERTIA, rel=1e-15)
    trajectory = art.simulate(2.0, 1 / 240, integrator=integrator)
    np.testing.assert_allclose(trajectory.qd[-1], [3.0 * 0.4 / INERTIA * 2.0], rtol=1e-12)
    art.ctrl = [7.0]  # clipped to 1
    assert art.forward_dynamics()[0] == pytest.approx(3.0 / INERTIA, rel=1e-15)
    np.testing.assert_allclose(art.actuator_forces(), [1.0])
    np.testing.assert_allclose(art.ctrl, [7.0])  # kept as given


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240, 1 / 1000])
def test_a_position_servo_holds_its_target_and_rings_at_its_stiffness(dt):
    gear, kp, kv = 2.0, 8.0, 0.0
    art = wheel(gear=gear, gain=kp, bias=(0.0, -kp, -kv))
    art.ctrl = [0.6]  # the length gear · q is pulled to 0.6: q to 0.3
    omega = np.sqrt(kp * gear**2 / INERTIA)
    trajectory = art.simulate(3.0, dt, integrator="rk4")
    exact = 0.3 - 0.3 * np.cos(omega * trajectory.time)
    np.testing.assert_allclose(trajectory.q[:, 0], exact, rtol=0, atol=20 * (omega * dt) ** 4 * 0.3 + 1e-12)
    damped = wheel(gear=gear, gain=kp, bias=(0.0, -kp, -4.0))
    damped.ctrl = [0.6]
    damped.simulate(20.0, dt, integrator="rk4")
    np.testing.assert_allclose(damped.q, [0.3], atol=1e-9)
    np.testing.assert_allclose(damped.actuator_forces(), [0.0], atol=1e-8)


@pytest.mark.parametrize("dt", [1 / 60, 1 / 1000])
def test_a_velocity_servo_drives_the_speed_to_its_control_exponentially(dt):
    gear, kv = 1.5, 0.2
    art = wheel(gear=gear, gain=kv, bias=(0.0, 0.0, -kv))
    art.ctrl = [3.0]  # l̇ = gear q̇ to 3: q̇ to 2
    tau = INERTIA / (kv * gear**2)
    trajectory = art.simulate(2.0, dt, integrator="rk4")
    exact = 2.0 * (1.0 - np.exp(-trajectory.time / tau))
    # RK4 on q̇' = -(q̇ - 2)/τ: a global error ~ (dt/τ)⁴ / 120 of the 2 rad/s (measured 3e-10 at 60 Hz)
    np.testing.assert_allclose(trajectory.qd[:, 0], exact, rtol=0, atol=0.1 * (dt / tau) ** 4 + 1e-14)


def test_actuators_on_one_joint_add_and_inverse_dynamics_counts_them():
    art = Articulation(gravity=(0.0, 0.0, -9.81))
    arm = art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0.4, 0.0, 0.0), damping=0.1)
    slide = art.add_link(Prismatic((1, 0, 0)), parent=arm, mass=0.5, stiffness=3.0)
    art.add_actuator(arm, gear=2.0, name="motor")
    art.add_actuator(arm, gear=-1.5, gain=4.0, bias=(0.3, -4.0, -0.5), name="servo")
    art.add_actuator(slide, gain=2.0, bias=(0.0, 0.0, -2.0), ctrl_range=(-0.5, 0.5))
    art.ctrl = [0.7, -0.2, 2.0]
    q, qd = np.array([0.3, 0.05]), np.array([-0.4, 0.2])
    servo_length, servo_speed = -1.5 * q[0], -1.5 * qd[0]
    forces = [0.7, 4.0 * -0.2 + 0.3 - 4.0 * servo_length - 0.5 * servo_speed, 2.0 * 0.5 - 2.0 * qd[1]]  # 2.0 → 0.5
    np.testing.assert_allclose(art.actuator_forces(q, qd), forces, rtol=1e-14)
    drive = np.array([2.0 * forces[0] - 1.5 * forces[1], forces[2]])
    free = Articulation(gravity=(0.0, 0.0, -9.81))
    free.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0.4, 0.0, 0.0), damping=0.1)
    free.add_link(Prismatic((1, 0, 0)), parent=0, mass=0.5, stiffness=3.0)
    np.testing.assert_allclose(art.bias_forces(q, qd), free.bias_forces(q, qd) - drive, atol=1e-12)
    np.testing.assert_allclose(art.forward_dynamics(q, qd), free.forward_dynamics(q, qd, tau=drive), rtol=1e-12)
    # what the joints need beside their actuators for that motion is nothing
    np.testing.assert_allclose(art.inverse_dynamics(q, qd, art.forward_dynamics(q, qd)), [0.0, 0.0], atol=1e-12)


def test_setting_ctrl_after_a_step_takes_effect_and_adding_a_link_keeps_it():
    art = wheel(gear=1.0)
    art.step(0.01)
    art.ctrl = [2.0]
    assert art.forward_dynamics()[0] == pytest.approx(2.0 / INERTIA)
    art.add_link(Revolute((0, 0, 1)), parent=0, position=(0.5, 0, 0), mass=1.0, shape_position=(0.2, 0, 0))
    assert art.ctrl.tolist() == [2.0]
    np.testing.assert_allclose(art.inverse_dynamics(art.q, np.zeros(2), art.forward_dynamics(qd=np.zeros(2))),
                               [0.0, 0.0], atol=1e-12)  # fmt: skip


def test_bad_actuators_and_controls_are_refused_and_change_nothing():
    art = Articulation()
    hinge = art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -1))
    ball = art.add_link(Ball(), parent=hinge, mass=1.0, shape_position=(0, 0, -1))
    with pytest.raises(ValueError, match=r"link 1 has a Ball\(\) joint: an actuator drives a Revolute or Prismatic"):
        art.add_actuator(ball)
    with pytest.raises(ValueError, match=r"link must be a link index in 0 to 1, got 5"):
        art.add_actuator(5)
    with pytest.raises(ValueError, match=r"ctrl_range must be \(low, high\) with low <= high, got \(1, -1\)"):
        art.add_actuator(hinge, ctrl_range=(1, -1))
    with pytest.raises(ValueError, match=r"gear"):
        art.add_actuator(hinge, gear=float("nan"))
    with pytest.raises(ValueError, match=r"bias"):
        art.add_actuator(hinge, bias=(0, 1))
    assert art.actuators == () and art.ctrl.shape == (0,)
    art.add_actuator(hinge, name="elbow")
    with pytest.raises(ValueError, match=r"name must be unique among the actuators, got 'elbow'"):
        art.add_actuator(hinge, name="elbow")
    with pytest.raises(ValueError, match=r"ctrl"):
        art.ctrl = [1.0, 2.0]
    with pytest.raises(ValueError, match=r"ctrl"):
        art.ctrl = [float("inf")]
    assert art.ctrl.tolist() == [0.0]


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240, 1e-3])
def test_force_range_clips_a_servo_so_the_wheel_spins_up_at_the_clipped_torque(dt):
    """A position servo far from its target pulls with ``kp · error``, clipped to ``force_range``: the wheel spins up
    at ``gear · f_max / I`` until it comes near."""
    art = wheel(gear=2.0, gain=100.0, bias=(0.0, -100.0, 0.0), force_range=(-0.5, 0.25))
    art.ctrl = [40.0]  # a target 20 rad away
    assert art.forward_dynamics()[0] == pytest.approx(2.0 * 0.25 / INERTIA, rel=1e-15)
    np.testing.assert_allclose(art.actuator_forces(), [0.25])
    art.simulate(1.0, dt, integrator="rk4")
    assert art.qd[0] == pytest.approx(2.0 * 0.25 / INERTIA, rel=1e-12)


def _two_wheels(**tendon):
    art = Articulation(gravity=(0.0, 0.0, 0.0))
    first = art.add_link(Revolute((0, 0, 1)), mass=2.0, shape_position=(0.5, 0.0, 0.0))  # I = 0.5
    second = art.add_link(Revolute((0, 0, 1)), position=(3.0, 0, 0), mass=1.0, shape_position=(1.0, 0.0, 0.0))  # 1
    return art, art.add_tendon([first, second], [1.0, -2.0], **tendon)


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240, 1e-3])
def test_a_tendon_spring_couples_two_wheels_at_its_normal_frequency(dt):
    """A fixed tendon ``L = q₀ - 2 q₁`` with stiffness ``k`` on two free wheels (inertias I₀, I₁): ``L`` oscillates
    about its spring length at ``ω² = k (1/I₀ + 4/I₁)``, and ``I₀ q̇₀ + I₁ q̇₁ / 2`` (the momentum the tendon's
    force leaves alone: it pushes ``+f`` on the first and ``-2f`` on the second) is conserved."""
    k = 3.0
    art, tendon = _two_wheels(stiffness=k, springlength=0.0)
    art.q = [0.2, 0.0]
    omega = np.sqrt(k * (1 / 0.5 + 4 / 1.0))
    trajectory = art.simulate(2.0, dt, integrator="rk4")
    length = trajectory.q[:, 0] - 2.0 * trajectory.q[:, 1]
    np.testing.assert_allclose(length, 0.2 * np.cos(omega * trajectory.time), atol=2e-3 * (dt * 240) ** 4 + 1e-9)
    momentum = 0.5 * trajectory.qd[:, 0] + 0.5 * trajectory.qd[:, 1]
    np.testing.assert_allclose(momentum, 0.0, atol=1e-12)
    assert art.tendon_lengths()[0] == pytest.approx(length[-1], abs=1e-15)
    assert art.tendons[tendon].springlength == 0.0


def test_a_tendon_damper_and_an_actuator_on_a_tendon_pull_both_wheels():
    """A motor on the tendon ``L = q₀ - 2 q₁`` pushes ``gear · c`` on the first wheel and ``-2 gear · c`` on the
    second; a damper ``b`` adds ``-b L̇`` along ``L``. The spring length defaults to the length at the start."""
    art, tendon = _two_wheels(damping=0.4)
    art.q = [0.3, 0.1]
    assert art.tendons[tendon].springlength == 0.0  # the length when the tendon was added
    motor = art.add_actuator(tendon=tendon, gear=1.5)
    art.ctrl = [0.8]
    art.qd = [1.0, -0.5]  # L̇ = 2
    force = 1.5 * 0.8 - 0.4 * 2.0
    np.testing.assert_allclose(art.forward_dynamics(), [force / 0.5, -2.0 * force / 1.0], rtol=1e-14)
    np.testing.assert_allclose(art.actuator_forces(), [0.8])
    assert art.actuators[motor].tendon == tendon and art.actuators[motor].link is None
