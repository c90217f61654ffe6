"""Planar and universal (Hooke's) world joints against closed-form motions.

A body on a :class:`~tumble.PlanarJoint` to the world moves as a free body whose velocity along the normal and
spin across it are taken away: its centre of mass follows the in-plane part of gravity, ``x(t) = x₀ + v t + ½ g∥
t²``, and it turns about the normal at a constant rate whatever its inertia (no torque acts along a fixed axis).

Two shafts at an angle ``β`` joined by a :class:`~tumble.UniversalJoint` obey Cardan's law: with the input turned by
``φ₁`` from where its yoke lies in the plane of the shafts, the output is turned by ``φ₂`` with
``tan φ₂ = tan φ₁ / cos β`` (its speed swings between ``ω cos β`` and ``ω / cos β`` twice a turn).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import tumble
from tumble.rotation import quat_conjugate, quat_from_axis_angle, quat_multiply


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240, 1 / 1000])
def test_a_body_on_a_planar_joint_slides_down_its_plane_and_spins_about_its_normal(dt):
    world = tumble.World(gravity=(0.0, 0.0, -9.81))
    start_orientation = quat_from_axis_angle((0.3, -0.5, 0.8), 0.9)
    body = world.add_body(tumble.Box((0.3, 0.2, 0.1)), mass=2.0, position=(0.2, -0.1, 1.0),
                          orientation=start_orientation)  # fmt: skip
    normal = np.array([0.0, math.sin(0.4), math.cos(0.4)])  # a plane tilted 0.4 rad about x
    joint = world.add_joint(tumble.PlanarJoint(body, None, normal))
    assert joint.kind == "planar"
    across = np.array([0.4, -0.2, 0.1]) - (np.array([0.4, -0.2, 0.1]) @ normal) * normal
    omega = 1.7 * normal + across
    body.velocity = np.array([0.5, 0.3, 0.0]) + 0.8 * normal  # the part along the normal is taken at the first step
    body.angular_velocity = omega
    # The joint's moment is across the normal, so the momentum along it is kept: the spin left is n·Iω / n·I n
    # (with the inertia as the first step leaves it: it turns the body before the joint acts).
    inertia = body.inertia_world
    first_guess = float(normal @ inertia @ omega) / float(normal @ inertia @ normal)
    in_plane_v = np.array([0.5, 0.3, 0.0]) - (np.array([0.5, 0.3, 0.0]) @ normal) * normal
    g = np.array([0.0, 0.0, -9.81])
    g_plane = g - (g @ normal) * normal
    world.step(dt)
    after_first = body.orientation
    spin = float(body.angular_velocity @ normal)
    np.testing.assert_allclose(body.angular_velocity, spin * normal, atol=1e-9)
    assert spin == pytest.approx(first_guess, rel=0.2 * dt)
    steps = round(1.0 / dt)
    for _ in range(steps - 1):
        world.step(dt)
    t = steps * dt
    expected = np.array([0.2, -0.1, 1.0]) + in_plane_v * t + 0.5 * g_plane * t**2
    # symplectic Euler: the position runs ahead of the exact parabola by ½ g∥ dt t
    np.testing.assert_allclose(body.position, expected, atol=0.6 * np.linalg.norm(g_plane) * dt * t + 1e-6)
    np.testing.assert_allclose(body.velocity, in_plane_v + g_plane * t, atol=1e-6)
    # It turns about the normal only; its spin drifts by the implicit gyroscopic step's first-order error (about a
    # non-principal axis: 0.14 dt per second measured at 60, 240 and 1000 Hz), as it would on a hinge.
    omega = body.angular_velocity
    np.testing.assert_allclose(omega - (omega @ normal) * normal, 0.0, atol=1e-9)
    assert omega @ normal == pytest.approx(spin, rel=0.2 * dt * t)
    turn = quat_multiply(body.orientation, quat_conjugate(after_first))
    # (less the first step's turn across the normal, which the joint's position bias takes back)
    np.testing.assert_allclose(np.cross(turn[1:], normal), 0.0, atol=2e-5)
    # a soft joint: gravity along the normal holds it off the plane by a sag ~ g dt² (1.6e-5 m at 60 Hz)
    assert joint.position_error < 0.02 * 9.81 * dt**2 and joint.angular_error < 1e-5


def _cardan(beta: float, dt: float):
    """Input shaft along x driven at 2 rad/s, output shaft along (cos β, sin β, 0), a Hooke's joint at the origin
    whose input yoke starts in the plane of the shafts."""
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    shaft = np.array([math.cos(beta), math.sin(beta), 0.0])
    along_x = quat_from_axis_angle((0.0, 1.0, 0.0), math.pi / 2)  # a cylinder's axis from z to x
    driver = world.add_body(tumble.Cylinder(0.05, 0.8), mass=1.0, position=(-0.5, 0.0, 0.0),
                            orientation=along_x)  # fmt: skip
    along_shaft = quat_multiply(quat_from_axis_angle((0.0, 0.0, 1.0), beta), along_x)
    driven = world.add_body(tumble.Cylinder(0.05, 0.8), mass=1.0, position=0.5 * shaft, orientation=along_shaft)
    motor = world.add_joint(tumble.HingeJoint(driver, None, (-0.5, 0.0, 0.0), (1.0, 0.0, 0.0), motor_speed=2.0,
                                              max_motor_torque=1e4))  # fmt: skip
    output = world.add_joint(tumble.HingeJoint(driven, None, 0.5 * shaft, shaft))
    cross = world.add_joint(tumble.UniversalJoint(driver, driven, (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))
    return world, motor, output, cross


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240, pytest.param(1 / 1000, marks=pytest.mark.slow)])  # 1 kHz: 9 s each
@pytest.mark.parametrize("beta", [0.3, 0.6])
def test_two_shafts_joined_by_a_universal_joint_follow_cardans_law(beta, dt):
    world, motor, output, cross = _cardan(beta, dt)
    assert cross.kind == "universal"
    worst_angle, worst_ratio, ratios = 0.0, 0.0, []
    for _ in range(round(3.0 / dt)):  # about one turn
        world.step(dt)
        phi_1, phi_2 = motor.angle, output.angle
        expected = math.atan2(math.sin(phi_1), math.cos(phi_1) * math.cos(beta))
        worst_angle = max(worst_angle, abs(math.remainder(phi_2 - expected, 2 * math.pi)))
        # dφ₂/dφ₁ = cos β / (cos²β cos²φ₁ + sin²φ₁)
        ratio = output.angular_speed / motor.angular_speed
        exact = math.cos(beta) / ((math.cos(beta) * math.cos(phi_1)) ** 2 + math.sin(phi_1) ** 2)
        worst_ratio = max(worst_ratio, abs(ratio / exact - 1.0))
        ratios.append(ratio)
    # measured: 1.4e-4 rad and 1.6e-5 at 60 Hz, 9e-6 rad and 1.8e-5 at 1 kHz
    assert worst_angle < 5e-4
    assert worst_ratio < 1e-4
    assert min(ratios) == pytest.approx(math.cos(beta), rel=1e-4)  # twice a turn each
    assert max(ratios) == pytest.approx(1.0 / math.cos(beta), rel=1e-4)
    assert cross.position_error < 1e-8 and cross.angular_error < 5e-5


def test_bad_planar_and_universal_joints_are_refused():
    world = tumble.World()
    body = world.add_body(tumble.Sphere(0.1), mass=1.0)
    with pytest.raises(ValueError, match=r"axis_a and axis_b must be perpendicular \(a Hooke's joint\), got"):
        tumble.UniversalJoint(body, None, (0, 0, 0), (1, 0, 0), (1, 1, 0))
    with pytest.raises(ValueError, match="normal"):
        tumble.PlanarJoint(body, None, (0, 0, 0))
    with pytest.raises(ValueError, match="anchor"):
        tumble.UniversalJoint(body, None, (0, float("nan"), 0), (1, 0, 0), (0, 1, 0))
    assert world.joints == []


@pytest.mark.parametrize("to_world", [True, False])
def test_servos_on_a_universal_joints_two_angles_turn_the_body_to_their_targets(to_world):
    """No gravity, a box pinned at its centre to the world (or to a heavy body welded still): position servos hold
    its angle about the axis it carries at 0.5 and the one about the fixed side's axis at -0.3. The coordinates are
    those of ``b`` relative to ``a`` (of ``a`` relative to the world when ``b`` is None), the turn about the fixed
    side's axis first: the box ends turned ``R(fixed axis, -0.3) R(box's axis, 0.5)`` from where it started."""
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    start = quat_from_axis_angle((0.2, 0.9, -0.4), 0.7)
    box = world.add_body(tumble.Box((0.4, 0.2, 0.1)), mass=1.0, orientation=start)
    carried, fixed = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.6, 0.8])
    if to_world:  # axis_a is carried by a, the box
        joint = world.add_joint(tumble.UniversalJoint(box, None, (0.0, 0.0, 0.0), carried, fixed))
        targets = [0.5, -0.3]
    else:  # axis_a is carried by a, the still body
        base = world.add_static(tumble.Sphere(0.1), position=(0.0, 0.0, -1.0))
        holder = world.add_body(tumble.Sphere(0.1), mass=1e3, position=(0.0, 0.0, -0.5))
        world.add_joint(tumble.FixedJoint(holder, base))
        joint = world.add_joint(tumble.UniversalJoint(holder, box, (0.0, 0.0, 0.0), fixed, carried))
        targets = [-0.3, 0.5]
    for coordinate in (0, 1):
        world.add_joint_actuator(joint, gain=0.5, bias=(0.0, -0.5, -0.2), coordinate=coordinate)
    world.ctrl = targets
    world.simulate(8.0, 1 / 240)
    turned = quat_multiply(quat_from_axis_angle(fixed, -0.3), quat_from_axis_angle(carried, 0.5))
    assert abs(abs(float(quat_multiply(turned, start) @ box.orientation)) - 1.0) < 1e-8
    np.testing.assert_allclose(world.actuator_forces(), 0.0, atol=1e-5)


def test_a_motor_on_a_universal_joints_angle_turns_the_body_about_that_axis():
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    box = world.add_body(tumble.Box((0.4, 0.2, 0.1)), mass=1.0)
    joint = world.add_joint(tumble.UniversalJoint(box, None, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)))
    world.add_joint_actuator(joint, gear=2.0, coordinate=1, name="pitch")
    world.ctrl = [1.5]
    world.step(0.01)
    inertia_y = 1.0 * (0.4**2 + 0.1**2) / 12.0
    np.testing.assert_allclose(box.angular_velocity, [0.0, 2.0 * 1.5 / inertia_y * 0.01, 0.0], atol=1e-9)
    np.testing.assert_allclose(world.actuator_forces(), [1.5])
