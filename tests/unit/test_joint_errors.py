"""Bad joints get clear errors naming the argument and value, and leave the world as it was."""

from __future__ import annotations

import math

import pytest

import tumble


@pytest.fixture
def world():
    w = tumble.World()
    w.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, name="a")
    w.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, position=(1, 0, 0), name="b")
    w.add_static(tumble.Plane(), name="ground")
    return w


def test_a_joint_between_a_body_and_itself_is_refused(world):
    a = world.body("a")
    with pytest.raises(ValueError, match="two different bodies.*'a'"):
        world.add_joint(tumble.BallJoint(a, a, (0, 0, 0)))
    assert world.joints == []


def test_zero_or_non_finite_axes_are_refused(world):
    a = world.body("a")
    with pytest.raises(ValueError, match=r"axis must be a non-zero vector, got \[0.0, 0.0, 0.0\]"):
        tumble.HingeJoint(a, None, (0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="axis"):
        tumble.SliderJoint(a, None, (math.nan, 0, 0))
    with pytest.raises(ValueError, match="anchor"):
        tumble.BallJoint(a, None, (0, math.inf, 0))


def test_joints_need_bodies_of_this_world_and_something_dynamic(world):
    other = tumble.World()
    stranger = other.add_body(tumble.Sphere(0.1), mass=1.0)
    with pytest.raises(ValueError, match="b must be a body of this world"):
        world.add_joint(tumble.BallJoint(world.body("a"), stranger, (0, 0, 0)))
    with pytest.raises(TypeError, match="a must be a Body of this world, got 3"):
        world.add_joint(tumble.BallJoint(3, None, (0, 0, 0)))
    with pytest.raises(ValueError, match="needs a dynamic body: a='ground' is static and b=the world"):
        world.add_joint(tumble.FixedJoint(world.body("ground"), None))
    with pytest.raises(TypeError, match="joint must be one of BallJoint"):
        world.add_joint("hinge")
    assert world.joints == []


def test_drive_settings_are_checked(world):
    a = world.body("a")
    with pytest.raises(ValueError, match="lower must not exceed upper, got lower=1.0, upper=0.0"):
        tumble.HingeJoint(a, None, (0, 0, 0), (0, 0, 1), lower=1.0, upper=0.0)
    with pytest.raises(ValueError, match="max_motor_torque"):
        tumble.HingeJoint(a, None, (0, 0, 0), (0, 0, 1), max_motor_torque=-1.0)
    with pytest.raises(ValueError, match="spring_hertz"):
        tumble.SliderJoint(a, None, (1, 0, 0), spring_hertz=-2.0)
    with pytest.raises(ValueError, match="length must be at least 1e-6 m"):
        tumble.DistanceJoint(a, None, (0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="min_length <= length <= max_length"):
        tumble.DistanceJoint(a, None, (0, 0, 0), (1, 0, 0), min_length=2.0)
    with pytest.raises(TypeError, match="collide_connected must be True or False"):
        tumble.BallJoint(a, None, (0, 0, 0), collide_connected="yes")


def test_handles_refuse_coordinates_of_other_kinds_and_bad_settings(world):
    joint = world.add_joint(tumble.BallJoint(world.body("a"), world.body("b"), (0.5, 0, 0)))
    with pytest.raises(AttributeError, match="a ball joint has no such coordinate"):
        _ = joint.angle
    hinge = world.add_joint(tumble.HingeJoint(world.body("a"), None, (0, 0, 0), (0, 0, 1)))
    with pytest.raises(ValueError, match="max_motor_torque"):
        hinge.max_motor_torque = -3.0
    with pytest.raises(ValueError, match="motor_speed"):
        hinge.motor_speed = math.nan
    assert hinge.max_motor_torque == 0.0
    with pytest.raises(AttributeError, match="read-only"):
        tumble.BallJoint(world.body("a"), None, (0, 0, 0)).anchor = (1, 2, 3)
    assert repr(hinge) == "Joint(#1, hinge, a='a', b='world')"
    assert hinge.body_a is not None and hinge.body_b is None


def test_solver_joint_settings_are_checked():
    with pytest.raises(ValueError, match="joint_hertz"):
        tumble.World(joint_hertz=0.0)
    with pytest.raises(ValueError, match="joint_damping_ratio"):
        tumble.World(joint_damping_ratio=-1.0)


def test_ball_joint_limits_need_an_axis_and_sane_angles(world):
    a = world.body("a")
    with pytest.raises(ValueError, match="axis must be given with cone_angle"):
        tumble.BallJoint(a, None, (0, 0, 0), cone_angle=0.5)
    with pytest.raises(ValueError, match=r"cone_angle must be in \(0, π\], got 4.0"):
        tumble.BallJoint(a, None, (0, 0, 0), axis=(0, 0, 1), cone_angle=4.0)
    with pytest.raises(ValueError, match=r"twist_upper must be in \[-π, π\], got 5.0"):
        tumble.BallJoint(a, None, (0, 0, 0), axis=(0, 0, 1), twist_upper=5.0)
    joint = world.add_joint(tumble.HingeJoint(a, None, (0, 0, 0), (0, 0, 1)))
    with pytest.raises(AttributeError, match="a hinge joint has no such coordinate"):
        _ = joint.swing


def test_joints_default_to_the_stiffest_the_substeps_allow():
    assert tumble.World().solver.joint_hertz == math.inf
    world = tumble.World(joint_hertz=math.inf)
    world.set_solver(joint_hertz=240.0)
    assert world.solver.joint_hertz == 240.0
    with pytest.raises(ValueError, match="joint_hertz must be finite"):
        world.set_solver(joint_hertz=math.nan)
