"""World joints' damping (MJCF's joint ``damping``: a torque ``−b ω`` about a hinge, a force ``−b v`` along a
slider) against closed-form motions.

A wheel of moment ``I`` on a damped hinge spins down as ``ω(t) = ω₀ e^{−b t / I}``; a block of mass ``m`` on a
damped slider coasts to ``x₀ + v₀ (m / b)(1 − e^{−b t / m})``. The damping is implicit in the solver's substeps
(``tumble/dynamics/softness.py``), so its error is first order in the substep and it is stable at any ``b``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import tumble
import tumble.scene_file

INERTIA = 2.0 * 0.5**2 + 0.4 * 2.0 * 0.05**2  # a 2 kg ball of radius 0.05 m, 0.5 m from the axis


def wheel(damping: float):
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    bob = world.add_body(tumble.Sphere(0.05), mass=2.0, position=(0.5, 0.0, 0.0))
    joint = world.add_joint(tumble.HingeJoint(bob, None, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), damping=damping))
    bob.velocity, bob.angular_velocity = (0.0, 1.0, 0.0), (0.0, 0.0, 2.0)
    return world, joint


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240, 1 / 1000])
def test_a_damped_wheel_spins_down_exponentially(dt):
    world, joint = wheel(0.3)
    assert joint.damping == 0.3
    speeds = []
    for _ in range(round(1.0 / dt)):
        world.step(dt)
        speeds.append(joint.angular_speed)
    t = dt * np.arange(1, len(speeds) + 1)
    exact = 2.0 * np.exp(-0.3 * t / INERTIA)
    # implicit Euler in 8 substeps: each loses b h/I of the speed to the exponential's second order; measured
    # 1e-3, 1.3e-4 and 2.5e-5 of the speed after 1 s at 60, 240 and 1000 Hz
    np.testing.assert_allclose(speeds, exact, rtol=0.1 * dt + 1e-5)
    assert np.all(np.diff(speeds) < 0.0)


def test_a_damped_slider_coasts_to_a_stop_at_m_v_over_b():
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    block = world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=3.0)
    joint = world.add_joint(tumble.SliderJoint(block, None, (1.0, 0.0, 0.0), damping=1.5))
    block.velocity = (0.8, 0.0, 0.0)
    world.simulate(2.0, 1 / 1000)
    tau = 3.0 / 1.5
    assert joint.translation == pytest.approx(0.8 * tau * (1.0 - math.exp(-2.0 / tau)), rel=1e-4)
    assert joint.speed == pytest.approx(0.8 * math.exp(-2.0 / tau), rel=1e-4)


def test_damping_is_stable_however_stiff_and_settable():
    world, joint = wheel(1e6)  # b h / I = 2e4 in a substep at 60 Hz: an explicit damper would blow up
    world.step(1 / 60)
    assert 0.0 <= joint.angular_speed < 1e-3
    joint.damping = 0.0
    world.step(1 / 60)
    assert joint.damping == 0.0 and joint.angular_speed == pytest.approx(world.joints[0].angular_speed)
    with pytest.raises(ValueError, match="damping"):
        joint.damping = -1.0
    with pytest.raises(ValueError, match="damping"):
        tumble.HingeJoint(world.bodies[0], None, (0, 0, 0), (0, 0, 1), damping=float("nan"))
    ball = world.add_joint(tumble.BallJoint(world.bodies[0], None, (0.0, 0.0, 0.0)))
    with pytest.raises(AttributeError, match="a ball joint has no such coordinate"):
        _ = ball.damping


def test_damping_goes_through_a_scene_file_and_mjcf(tmp_path):
    world, joint = wheel(0.3)
    copy = tumble.scene_file.from_dict(world.to_scene()).world
    assert copy.joints[0].damping == 0.3
    with pytest.warns(UserWarning, match="keyframe"):  # load_mjcf does not read the velocities' keyframe
        rebuilt = tumble.load_mjcf(world.to_mjcf())
    assert rebuilt.joints[0].damping == 0.3
    rebuilt.bodies[0].velocity, rebuilt.bodies[0].angular_velocity = (0.0, 1.0, 0.0), (0.0, 0.0, 2.0)
    for w in (world, copy, rebuilt):
        w.simulate(0.5, 1 / 240)
    assert copy.joints[0].angular_speed == pytest.approx(joint.angular_speed, rel=1e-12)
    assert rebuilt.joints[0].angular_speed == pytest.approx(joint.angular_speed, rel=1e-9)


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240, 1 / 1000])
def test_an_articulations_implicit_damping_is_mujocos_euler_in_closed_form(dt):
    """An articulation's ``symplectic_implicit_damping`` step solves ``(I + h b) ω' = I ω``: a damped wheel keeps
    ``ω₀ (I / (I + h b))ⁿ`` after n steps to round-off, however stiff the damper (``h b / I`` = 3 here at 60 Hz,
    where the explicit step's factor ``1 - h b / I`` = -2 blows up)."""
    from tumble.articulation import Articulation, Revolute

    art = Articulation(gravity=(0.0, 0.0, 0.0))
    bob = art.add_link(Revolute((0.0, 0.0, 1.0)), shape=tumble.Sphere(0.05), mass=2.0, shape_position=(0.5, 0.0, 0.0),
                       damping=3.0 * INERTIA * 60.0)  # fmt: skip
    art.set_joint(bob, qd=2.0)
    b, steps = 3.0 * INERTIA * 60.0, round(0.05 / dt)
    for _ in range(steps):
        art.step(dt, integrator="symplectic_implicit_damping")
    assert art.qd[0] == pytest.approx(2.0 * (INERTIA / (INERTIA + dt * b)) ** steps, rel=1e-12, abs=0.0)
