"""Bad input to an articulation: a clear error naming the argument and the value, and nothing changed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tumble.articulation import Articulation, Ball, Fixed, Free, Prismatic, Revolute, SoftConstraint
from tumble.errors import SimulationError
from tumble.mass import MassProperties
from tumble.shapes import Box, Sphere


def pendulum() -> Articulation:
    art = Articulation()
    arm = art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -1), name="arm")
    art.add_link(Ball(), parent=arm, position=(0, 0, -1), shape=Sphere(0.1), mass=0.5)
    art.q = [0.5, 1.0, 0.0, 0.0, 0.0]
    art.qd = [0.1, 0.2, 0.3, 0.4]
    return art


def _state(art):
    return art.q, art.qd, art.time


def _unchanged(art, before):
    np.testing.assert_array_equal(art.q, before[0])
    np.testing.assert_array_equal(art.qd, before[1])
    assert art.time == before[2]


# --- joints ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("axis", "error", "message"),
    [
        ((0, 0, 0), ValueError, r"axis must be a non-zero vector, got \[0.0, 0.0, 0.0\]"),
        ((1, math.nan, 0), ValueError, r"axis must be finite"),
        ((1, 0), ValueError, r"axis must have shape \(3\), got shape \(2,\)"),
        ("x", TypeError, r"axis must be an array"),
    ],
)
@pytest.mark.parametrize("joint", [Revolute, Prismatic])
def test_bad_joint_axis(joint, axis, error, message):
    with pytest.raises(error, match=message):
        joint(axis)


def test_joint_axis_is_normalised_and_read_only():
    joint = Revolute((0, 3, 4))
    np.testing.assert_allclose(joint.axis, (0, 0.6, 0.8))
    with pytest.raises(ValueError):
        joint.axis[0] = 1.0
    with pytest.raises(AttributeError):
        joint.axis = (1, 0, 0)


def test_joint_must_be_a_joint():
    with pytest.raises(TypeError, match=r"joint must be a Revolute, Prismatic, Ball, Free or Fixed, got 'hinge'"):
        Articulation().add_link("hinge")


# --- building -------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("parent", "error", "message"),
    [
        (5, ValueError, r"parent must be None or the index of an earlier link \(0 to 1\), got 5"),
        (-1, ValueError, r"parent must be None or the index of an earlier link \(0 to 1\), got -1"),
        (2, ValueError, r"parent must be None or the index of an earlier link \(0 to 1\), got 2"),  # itself
        ("arm", TypeError, r"parent must be None or the index \(int\) of an earlier link, got 'arm'"),
        (True, TypeError, r"parent must be None or the index \(int\) of an earlier link, got True"),
        (1.0, TypeError, r"parent must be None or the index \(int\) of an earlier link, got 1.0"),
    ],
)
def test_bad_parent(parent, error, message):
    art = pendulum()
    with pytest.raises(error, match=message):
        art.add_link(Revolute((1, 0, 0)), parent=parent, mass=1.0)
    assert art.link_count == 2


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"mass": -1.0}, ValueError, r"mass must be > 0, got -1.0"),
        ({"mass": 0.0}, ValueError, r"mass must be > 0, got 0.0"),
        ({"mass": math.inf}, ValueError, r"mass must be finite, got inf"),
        ({"shape": Box((1, 1, 1)), "mass": -2.0}, ValueError, r"mass must be > 0, got -2.0"),
        ({"shape": Box((1, 1, 1)), "density": -2.0}, ValueError, r"density must be > 0, got -2.0"),
        ({"shape": Box((1, 1, 1))}, TypeError, r"give exactly one of mass= or density="),
        ({"shape": Box((1, 1, 1)), "mass": 1.0, "density": 1.0}, TypeError, r"give exactly one of mass= or density="),
        ({"density": 1000.0}, TypeError, r"density= needs a shape, got density=1000.0"),
        ({"shape": "box", "mass": 1.0}, TypeError, r"shape must be a tumble shape .*, got 'box'"),
        ({"mass_properties": 3.0}, TypeError, r"mass_properties must be a MassProperties, got 3.0"),
        ({"mass_properties": MassProperties(1.0, (0, 0, 0), np.eye(3)), "mass": 1.0}, TypeError, r"not both"),
        ({"position": (0, 0)}, ValueError, r"position must have shape \(3\)"),
        ({"orientation": (0, 0, 0, 0)}, ValueError, r"orientation must be a non-zero quaternion"),
        ({"shape_position": (0, math.nan, 0), "mass": 1.0}, ValueError, r"shape_position must be finite"),
        ({"damping": -0.1}, ValueError, r"damping must be >= 0, got -0.1"),
        ({"name": 3}, TypeError, r"name must be a string or None, got 3"),
        ({"name": "arm"}, ValueError, r"name must be unique, got 'arm' \(link 0 has it\)"),
        ({"limits": (1.0, -1.0)}, ValueError, r"limits must be \(lower, upper\) with lower <= upper, got \(1.0, -1"),
        ({"limits": (0.0, math.inf)}, ValueError, r"limits must be finite"),
        ({"margin": -0.1}, ValueError, r"margin must be >= 0, got -0.1"),
        ({"frictionloss": -1.0}, ValueError, r"frictionloss must be >= 0, got -1.0"),
        ({"limit_softness": (0.02, 1.0)}, TypeError, r"limit_softness must be a SoftConstraint or None"),
    ],
)
def test_bad_link_arguments(kwargs, error, message):
    art = pendulum()
    before = _state(art)
    with pytest.raises(error, match=message):
        art.add_link(Revolute((1, 0, 0)), parent=0, **kwargs)
    assert art.link_count == 2
    _unchanged(art, before)


def test_bad_articulation_arguments():
    with pytest.raises(ValueError, match=r"gravity must have shape \(3\)"):
        Articulation(gravity=(0, -9.81))
    with pytest.raises(ValueError, match=r"base_orientation must be a non-zero quaternion"):
        Articulation(base_orientation=(0, 0, 0, 0))
    with pytest.raises(ValueError, match=r"base_position must be finite"):
        Articulation(base_position=(0, 0, math.nan))


@pytest.mark.parametrize(
    ("args", "error", "message"),
    [
        ((7, (0, 0, 0)), ValueError, r"link_a must be a link index in 0 to 1, got 7"),
        ((0, (0, 0, 0), 0), ValueError, r"link_b must differ from link_a, got both 0"),
        ((0, (0, 0, 0), "arm"), TypeError, r"link_b must be a link index \(int\), got 'arm'"),
        ((0, (0, 0)), ValueError, r"point_a must have shape \(3\)"),
        ((0, (0, 0, 0), 1, (0, 0, math.inf)), ValueError, r"point_b must be finite"),
        ((0, (0, 0, 0), None, (0, 0, 0), "hinge"), ValueError, r"kind must be one of \('point',\), got 'hinge'"),
    ],
)
def test_bad_loop_closure(args, error, message):
    art = pendulum()
    with pytest.raises(error, match=message):
        art.add_loop_closure(*args)
    assert art.loop_closures == ()


# --- state ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "value", "error", "message"),
    [
        ("q", [0.0, 1.0, 0.0, 0.0], ValueError, r"q must have shape \(5\), got shape \(4,\)"),
        ("q", [0.0, 1.0, 0.0, math.nan, 0.0], ValueError, r"q must be finite"),
        ("q", [0.0, 0.0, 0.0, 0.0, 0.0], ValueError, r"q\[1:5\] \(link 1\) must be a non-zero quaternion"),
        ("q", None, TypeError, r"q must be an array of numbers"),
        ("qd", [0.0, 0.0, 0.0], ValueError, r"qd must have shape \(4\), got shape \(3,\)"),
        ("qd", [0.0, math.inf, 0.0, 0.0], ValueError, r"qd must be finite"),
    ],
)
def test_bad_state(name, value, error, message):
    art = pendulum()
    before = _state(art)
    with pytest.raises(error, match=message):
        setattr(art, name, value)
    _unchanged(art, before)


def test_quaternions_are_renormalised():
    art = pendulum()
    art.q = [0.0, 2.0, 0.0, 0.0, 0.0]
    np.testing.assert_array_equal(art.q, [0.0, 1.0, 0.0, 0.0, 0.0])


def test_set_joint():
    art = pendulum()
    art.set_joint(0, q=0.25, qd=-1.0)
    art.set_joint(1, q=(0.0, 0.0, 0.0, 3.0))
    np.testing.assert_array_equal(art.q, [0.25, 0.0, 0.0, 0.0, 1.0])
    np.testing.assert_array_equal(art.qd, [-1.0, 0.2, 0.3, 0.4])
    before = _state(art)
    with pytest.raises(ValueError, match=r"q must have shape \(4\), got shape \(3,\)"):
        art.set_joint(1, q=(1.0, 0.0, 0.0), qd=(0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"qd must have shape \(3\)"):
        art.set_joint(1, qd=1.0)
    with pytest.raises(ValueError, match=r"link must be a link index in 0 to 1, got 2"):
        art.set_joint(2, q=0.0)
    _unchanged(art, before)


# --- queries and dynamics ----------------------------------------------------------------------------------


def test_bad_query_arguments():
    art = pendulum()
    before = _state(art)
    with pytest.raises(ValueError, match=r"tau must have shape \(4\), got shape \(2,\)"):
        art.forward_dynamics(tau=[1.0, 2.0])
    with pytest.raises(ValueError, match=r"qdd must have shape \(4\)"):
        art.inverse_dynamics(art.q, art.qd, [0.0])
    with pytest.raises(TypeError, match=r"q and qd are required"):
        art.inverse_dynamics(None, art.qd, np.zeros(4))
    with pytest.raises(ValueError, match=r"external must have shape \(2, 6\)"):
        art.inverse_dynamics(art.q, art.qd, np.zeros(4), external=np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"link must be a link index in 0 to 1, got 3"):
        art.jacobian(3)
    with pytest.raises(ValueError, match=r"point must have shape \(3\)"):
        art.jacobian(0, point=(1, 2))
    with pytest.raises(ValueError, match=r"name must be the name of a link, got 'leg'"):
        art.link_index("leg")
    with pytest.raises(ValueError, match=r"the articulation has no links"):
        Articulation().mass_matrix()
    _unchanged(art, before)


def test_massless_link_is_allowed_until_it_makes_the_mass_matrix_singular():
    art = Articulation()
    gimbal = art.add_link(Revolute((1, 0, 0)))  # massless, but it carries a massive child
    art.add_link(Revolute((0, 1, 0)), parent=gimbal, shape=Box((0.2, 0.2, 0.2)), mass=1.0)
    assert np.linalg.eigvalsh(art.mass_matrix())[0] > 0.0
    leaf = art.add_link(Prismatic((0, 0, 1)), parent=1, name="slider")  # moves no mass at all
    assert art.links[leaf].mass_properties is None
    before = _state(art)
    with pytest.raises(
        SimulationError, match=r"mass matrix is singular at degree of freedom 2 \(joint of link 'slider'\)"
    ):
        art.forward_dynamics()
    with pytest.raises(SimulationError, match=r"singular") as caught:
        art.step(1e-3)
    assert caught.value.body == "slider"
    assert caught.value.step == 0
    _unchanged(art, before)


def test_loop_closures_with_a_massless_link_report_the_singular_joint():
    art = Articulation()
    art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(1, 0, 0))
    art.add_link(Fixed(), parent=0, position=(1, 0, 0))
    art.add_link(Prismatic((1, 0, 0)))
    art.add_loop_closure(0, (1, 0, 0), 2, (0, 0, 0))
    with pytest.raises(SimulationError, match=r"degree of freedom 1"):
        art.forward_dynamics()


# --- time stepping ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"dt": 0.0}, ValueError, r"dt must be > 0, got 0.0"),
        ({"dt": -1e-3}, ValueError, r"dt must be > 0, got -0.001"),
        ({"dt": math.nan}, ValueError, r"dt must be finite, got nan"),
        ({"dt": "1ms"}, TypeError, r"dt must be a real number, got '1ms'"),
        ({"dt": 1e-3, "integrator": "verlet"}, ValueError, r"integrator must be one of .*'rk4'.*, got 'verlet'"),
        ({"dt": 1e-3, "integrator": None}, ValueError, r"integrator must be one of"),
        ({"dt": 1e-3, "tau": [1.0]}, ValueError, r"tau must have shape \(4\), got shape \(1,\)"),
        ({"dt": 1e-3, "tau": [1.0, 0.0, math.nan, 0.0]}, ValueError, r"tau must be finite"),
    ],
)
def test_bad_step_arguments(kwargs, error, message):
    art = pendulum()
    before = _state(art)
    with pytest.raises(error, match=message):
        art.step(**kwargs)
    _unchanged(art, before)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"duration": 1.0, "dt": 0.0}, ValueError, r"dt must be > 0"),
        ({"duration": 0.0, "dt": 1e-3}, ValueError, r"duration must be > 0"),
        ({"duration": 1e-4, "dt": 1e-3}, ValueError, r"duration=0.0001 is shorter than one step of dt=0.001"),
        (
            {"duration": 1.0, "dt": 1e-3, "record_every": 0},
            ValueError,
            r"record_every must be an integer from 1 to \d+, got 0",
        ),
        ({"duration": 1.0, "dt": 1e-3, "integrator": "RK4"}, ValueError, r"integrator must be one of"),
    ],
)
def test_bad_simulate_arguments(kwargs, error, message):
    art = pendulum()
    before = _state(art)
    with pytest.raises(error, match=message):
        art.simulate(**kwargs)
    _unchanged(art, before)


def test_a_non_finite_step_keeps_the_last_good_state():
    art = pendulum()
    art.simulate(0.01, 1e-3)
    before = _state(art)
    with pytest.raises(SimulationError, match=r"step 10: link 'arm' got a non-finite") as caught:
        art.step(1e-3, tau=[1e308, 0.0, 0.0, 0.0], integrator="rk4")
    assert (caught.value.body, caught.value.step) == ("arm", 10)
    _unchanged(art, before)
    with pytest.raises(SimulationError, match=r"non-finite") as caught:
        art.simulate(0.01, 1e-3, tau=[1e308, 0.0, 0.0, 0.0])
    assert caught.value.trajectory.q.shape == (1, 5)  # the initial frame only
    _unchanged(art, before)


def test_free_link_starts_at_its_given_pose():
    art = Articulation()
    art.add_link(Free(), position=(1, 2, 3), orientation=(0, 0, 0, 2), shape=Box((1, 1, 1)), mass=1.0)
    np.testing.assert_array_equal(art.q, [1, 2, 3, 0, 0, 0, 1])
    assert art.nq == 7 and art.nv == 6


def test_import_tumble_loads_the_articulation_only_when_used():
    import subprocess
    import sys

    code = (
        "import sys, tumble; assert 'tumble.articulation' not in sys.modules; "
        "from tumble import Revolute; assert tumble.Articulation.__module__.startswith('tumble.articulation')"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"solref": (0.02, -1.0)}, ValueError, r"solref must be two positive numbers or two numbers <= 0"),
        ({"solref": (0.02,)}, ValueError, r"solref must have shape \(2\)"),
        ({"solimp": (0.9, 0.95, -0.001, 0.5, 2.0)}, ValueError, r"solimp's width .* must be >= 0"),
        ({"solimp": (0.9, math.nan, 0.001, 0.5, 2.0)}, ValueError, r"solimp must be finite"),
    ],
)
def test_bad_soft_constraints(kwargs, error, message):
    with pytest.raises(error, match=message):
        SoftConstraint(**kwargs)


def test_soft_constraints_clamp_as_mujoco_does():
    soft = SoftConstraint(solimp=(0.0, 1.5, 0.01, 2.0, 0.5))
    assert soft.solimp == (1e-4, 0.9999, 0.01, 0.9999, 1.0)


def test_limits_on_a_ball_and_loop_closures_with_limits_are_refused():
    art = pendulum()
    before = _state(art)
    with pytest.raises(ValueError, match=r"limits=\(0.0, 1.0\) need a Revolute or Prismatic joint, got Ball"):
        art.add_link(Ball(), parent=1, limits=(0.0, 1.0), mass=1.0)
    with pytest.raises(ValueError, match="loop closures are not simulated with limits"):
        limited = Articulation()
        limited.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -1), limits=(-1.0, 1.0))
        limited.add_loop_closure(0, (0, 0, -1), None, (0, 0, -1))
    looped = Articulation()
    looped.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -1))
    looped.add_link(Revolute((0, 1, 0)), parent=0, position=(0, 0, -1), mass=1.0, shape_position=(0, 0, -1))
    looped.add_loop_closure(1, (0, 0, -1), None, (0, 0, -2))
    with pytest.raises(ValueError, match="limits and frictionloss are not simulated with loop closures"):
        looped.add_link(Revolute((0, 1, 0)), parent=1, frictionloss=1.0, mass=1.0)
    with pytest.raises(ValueError, match="tendons are not simulated with loop closures"):
        looped.add_tendon([0, 1], [1.0, -1.0])
    assert art.link_count == 2 and looped.link_count == 2 and looped.tendons == ()
    _unchanged(art, before)


@pytest.mark.parametrize(
    ("args", "kwargs", "error", "message"),
    [
        (([], []), {}, ValueError, r"links must be a non-empty sequence of link indices, got \[\]"),
        (([0, 1], [1.0, 1.0]), {}, ValueError, r"links: link 1 has a Ball\(\) joint; a tendon runs over"),
        (([0, 5], [1.0, 1.0]), {}, ValueError, r"links must be"),
        (([0], [1.0, 2.0]), {}, ValueError, r"coefficients must have shape \(1\)"),
        (([0], [1.0]), {"limits": (2.0, 1.0)}, ValueError, r"limits must be \(lower, upper\)"),
        (([0], [1.0]), {"stiffness": -1.0}, ValueError, r"stiffness must be >= 0, got -1.0"),
        (([0], [1.0]), {"damping": -1.0}, ValueError, r"damping must be >= 0, got -1.0"),
        (([0], [1.0]), {"springlength": math.nan}, ValueError, r"springlength must be finite"),
        (([0], [1.0]), {"name": 3}, TypeError, r"name must be a string or None, got 3"),
    ],
)
def test_bad_tendons(args, kwargs, error, message):
    art = pendulum()
    with pytest.raises(error, match=message):
        art.add_tendon(*args, **kwargs)
    assert art.tendons == ()


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({}, ValueError, r"give one of link and tendon, got link=None and tendon=None"),
        ({"link": 0, "tendon": 0}, ValueError, r"give one of link and tendon"),
        ({"tendon": 1}, ValueError, r"tendon must be the index of a tendon \(0..0\), got 1"),
        ({"link": 0, "force_range": (1.0, -1.0)}, ValueError, r"force_range must be \(low, high\) with low <= high"),
        ({"link": 0, "ctrl_range": (1.0, -1.0)}, ValueError, r"ctrl_range must be \(low, high\) with low <= high"),
    ],
)
def test_bad_actuators(kwargs, error, message):
    art = pendulum()
    art.add_tendon([0], [2.0])
    with pytest.raises(error, match=message):
        art.add_actuator(**kwargs)
    assert art.actuators == () and art.ctrl.shape == (0,)


@pytest.mark.parametrize(
    ("args", "kwargs", "error", "message"),
    [
        ((0, "box", (1.0,)), {}, ValueError, r"kind must be one of \('plane', 'sphere', 'capsule'\), got 'box'"),
        ((0, "plane"), {}, ValueError, r"a plane belongs to the world \(link=None\), got link=0"),
        ((0, "sphere", (0.1, 0.2)), {}, ValueError, r"size must have shape \(1\)"),
        ((0, "capsule", (0.1, -0.2)), {}, ValueError, r"size must be positive for a capsule, got \(0.1, -0.2\)"),
        ((5, "sphere", (0.1,)), {}, ValueError, r"link must be"),
        ((0, "sphere", (0.1,)), {"contype": -1}, ValueError, r"contype must be a non-negative integer, got -1"),
        ((0, "sphere", (0.1,)), {"conaffinity": 1.5}, ValueError, r"conaffinity must be a non-negative integer"),
        ((0, "sphere", (0.1,)), {"condim": 6}, ValueError, r"condim must be 1 or 3, got 6"),
        ((0, "sphere", (0.1,)), {"friction": -1.0}, ValueError, r"friction must be >= 0, got -1.0"),
        ((0, "sphere", (0.1,)), {"margin": -1.0}, ValueError, r"margin must be >= 0, got -1.0"),
        ((0, "sphere", (0.1,)), {"softness": (0.02, 1.0)}, TypeError, r"softness must be a SoftConstraint or None"),
        ((0, "sphere", (0.1,)), {"orientation": (0, 0, 0, 0)}, ValueError, r"orientation must be a non-zero"),
    ],
)
def test_bad_geoms(args, kwargs, error, message):
    art = pendulum()
    before = _state(art)
    with pytest.raises(error, match=message):
        art.add_geom(*args, **kwargs)
    assert art.geoms == ()
    _unchanged(art, before)


def test_geoms_and_loop_closures_are_not_simulated_together():
    art = pendulum()
    art.add_geom(0, "sphere", (0.1,))
    with pytest.raises(ValueError, match="loop closures are not simulated with limits, frictionloss, tendons or geoms"):
        art.add_loop_closure(1, (0, 0, 0), None, (0, 0, -2))
    looped = Articulation()
    looped.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -1))
    looped.add_loop_closure(0, (0, 0, -1), None, (0, 0, -1))
    with pytest.raises(ValueError, match="contacts are not simulated with loop closures"):
        looped.add_geom(0, "sphere", (0.1,))
    assert looped.geoms == ()


def test_joints_by_name_read_and_set_their_coordinates():
    art = Articulation()
    hinge = art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -1), joint_name="hip")
    art.add_link(Prismatic((0, 0, 1)), parent=hinge, mass=1.0, joint_name="slide")
    art.add_link(Ball(), parent=hinge, mass=1.0, shape_position=(0, 0, -1), joint_name="wrist")
    hip, slide, wrist = art.joint("hip"), art.joint("slide"), art.joint("wrist")
    hip.angle, hip.angular_speed, slide.translation, slide.speed = 0.4, -1.0, 0.2, 3.0
    np.testing.assert_array_equal(art.q[:2], [0.4, 0.2])
    np.testing.assert_array_equal(art.qd[:2], [-1.0, 3.0])
    assert (hip.angle, hip.angular_speed, slide.translation, slide.speed) == (0.4, -1.0, 0.2, 3.0)
    np.testing.assert_array_equal(wrist.q, [1.0, 0.0, 0.0, 0.0])
    with pytest.raises(AttributeError, match=r"joint 'hip' is a Revolute.*translation belongs to a Prismatic joint"):
        hip.translation  # noqa: B018
    with pytest.raises(AttributeError, match=r"joint 'wrist' is a Ball\(\): angle belongs to a Revolute joint"):
        wrist.angle = 0.1
    with pytest.raises(KeyError, match=r"no joint named 'knee'; names: \['hip', 'slide', 'wrist'\]"):
        art.joint("knee")
    with pytest.raises(ValueError, match=r"joint_name must be unique, got 'hip'"):
        art.add_link(Revolute((1, 0, 0)), parent=hinge, mass=1.0, joint_name="hip")
    with pytest.raises(TypeError, match=r"joint_name must be a string or None, got 3"):
        art.add_link(Revolute((1, 0, 0)), parent=hinge, mass=1.0, joint_name=3)
