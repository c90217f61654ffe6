"""World joints against closed-form mechanics: pendulum period, free fall along a slider, spring frequency,
motors, limits, welds, reaction forces, closed loops (slider–crank), chain accuracy, momentum."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import ellipk

import tumble
import tumble.scenes

G = 9.81
DT = 1 / 60


def _crossings(times, values) -> np.ndarray:
    """Times at which ``values`` crosses zero (linear interpolation)."""
    t, v = np.asarray(times), np.asarray(values)
    k = np.flatnonzero(np.sign(v[:-1]) != np.sign(v[1:]))
    return t[k] - v[k] * (t[k + 1] - t[k]) / (v[k + 1] - v[k])


def _pendulum(length=1.0, joint="hinge"):
    world = tumble.World()
    bob = world.add_body(tumble.Sphere(0.01), mass=1.0, position=(length, 0.0, 0.0))
    if joint == "hinge":
        handle = world.add_joint(tumble.HingeJoint(bob, None, (0, 0, 0), (0, 1, 0)))
    elif joint == "ball":
        handle = world.add_joint(tumble.BallJoint(bob, None, (0, 0, 0)))
    else:
        handle = world.add_joint(tumble.DistanceJoint(bob, None, bob.position, (0, 0, 0)))
    return world, bob, handle


@pytest.mark.parametrize("joint", ["hinge", "ball", "distance"])
def test_pendulum_released_at_90_degrees_has_the_elliptic_period(joint):
    length = 1.0
    world, bob, handle = _pendulum(length, joint)
    times, xs = [0.0], [bob.position[0]]
    for _ in range(500):
        world.step(DT)
        times.append(world.time)
        xs.append(bob.position[0])
    period = 4 * math.sqrt(length / G) * ellipk(math.sin(math.pi / 4) ** 2)
    crossings = _crossings(times, xs)
    measured = 2 * np.diff(crossings)
    assert len(measured) >= 5
    # Measured 1.1e-4 (hinge, ball) and 9.7e-5 (rod), anchors 0.19 mm apart at worst; the issue asks for 1 %.
    np.testing.assert_allclose(measured, period, rtol=5e-4)
    assert handle.position_error < 5e-4


def test_hanging_pendulum_reaction_is_its_weight_and_hinge_holds_a_torque():
    world = tumble.World()
    bob = world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=2.0, position=(0.0, 0.0, -1.0))
    joint = world.add_joint(tumble.HingeJoint(bob, None, (0, 0, 0), (0, 1, 0)))
    for _ in range(60):
        world.step(DT)
    np.testing.assert_allclose(joint.reaction_force, [0.0, 0.0, 2.0 * G], atol=1e-6)
    np.testing.assert_allclose(joint.reaction_torque, 0.0, atol=1e-6)
    # A horizontal box held by a fixed joint at one end: the weld carries the weight and the moment m g l.
    world = tumble.World()
    beam = world.add_body(tumble.Box((1.0, 0.1, 0.1)), mass=3.0, position=(0.5, 0.0, 0.0))
    weld = world.add_joint(tumble.FixedJoint(beam, None, anchor=(0.0, 0.0, 0.0)))
    for _ in range(120):
        world.step(DT)
    np.testing.assert_allclose(weld.reaction_force, [0.0, 0.0, 3.0 * G], atol=1e-4)
    # the weld turns the beam up (about -y): torque on the beam about the anchor = -r x W = (0, -m g l, 0)... sign:
    # r = (0.5, 0, 0), weight (0, 0, -m g): r x W = (0, m g 0.5, 0); the weld cancels it.
    np.testing.assert_allclose(weld.reaction_torque, [0.0, -3.0 * G * 0.5, 0.0], atol=1e-3)
    assert weld.position_error < 1e-3 and weld.angular_error < 1e-3


def test_slider_on_an_incline_accelerates_at_g_sin_theta():
    theta = math.radians(30)
    axis = (math.cos(theta), 0.0, -math.sin(theta))
    world = tumble.World()
    block = world.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0)
    slider = world.add_joint(tumble.SliderJoint(block, None, axis))
    for _ in range(60):
        world.step(DT)
    expected = 0.5 * G * math.sin(theta) * world.time**2
    # semi-implicit Euler over n = 480 substeps overshoots ½ a t² by the factor (n + 1) / n (measured 2.1e-3)
    assert slider.translation == pytest.approx(expected * 481 / 480, rel=1e-6)
    assert slider.speed == pytest.approx(G * math.sin(theta) * world.time, rel=1e-6)
    assert slider.position_error < 1e-4 and slider.angular_error < 1e-9  # soft: g cos θ / (2π 120 Hz)² = 1.5e-5 m


def test_slider_spring_oscillates_at_its_frequency_and_limits_hold():
    world = tumble.World(gravity=(0, 0, 0))
    block = world.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, velocity=(1.0, 0.0, 0.0))
    spring = world.add_joint(tumble.SliderJoint(block, None, (1, 0, 0), spring_hertz=2.0))
    times, xs = [], []
    for _ in range(180):
        world.step(1 / 240)
        times.append(world.time)
        xs.append(spring.translation)
    period = 2 * np.diff(_crossings(times, xs)).mean()
    assert period == pytest.approx(0.5, rel=2e-2)
    # limits: a block sliding at 1 m/s stops at upper = 0.2
    world = tumble.World(gravity=(0, 0, 0))
    block = world.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, velocity=(1.0, 0.0, 0.0))
    rail = world.add_joint(tumble.SliderJoint(block, None, (1, 0, 0), lower=-0.1, upper=0.2))
    for _ in range(60):
        world.step(DT)
        assert rail.translation < 0.2 + 1e-3
    assert rail.translation == pytest.approx(0.2, abs=2e-3)
    assert abs(rail.speed) < 1e-3


def test_hinge_motor_spins_a_door_up_to_speed_with_bounded_torque():
    world = tumble.World(gravity=(0, 0, 0))
    door = world.add_body(tumble.Box((1.0, 0.05, 2.0)), mass=10.0, position=(0.5, 0.0, 1.0))
    hinge = world.add_joint(tumble.HingeJoint(door, None, (0, 0, 1), (0, 0, 1), motor_speed=1.0, max_motor_torque=5.0))
    inertia_about_hinge = 10.0 * (1.0**2 + 0.05**2) / 12 + 10.0 * 0.5**2
    world.step(DT)
    # torque-limited: ω after one step = τ dt / I
    assert hinge.angular_speed == pytest.approx(5.0 * DT / inertia_about_hinge, rel=1e-3)
    np.testing.assert_allclose(hinge.reaction_torque, [0.0, 0.0, 5.0], atol=1e-6)
    for _ in range(120):
        world.step(DT)
    assert hinge.angular_speed == pytest.approx(1.0, abs=1e-4)
    hinge.motor_speed = -0.5
    for _ in range(120):
        world.step(DT)
    assert hinge.angular_speed == pytest.approx(-0.5, abs=1e-4)
    assert hinge.position_error < 1e-4 and hinge.angular_error < 1e-4


def test_hinge_limits_stop_a_pendulum():
    world = tumble.World()
    bob = world.add_body(tumble.Sphere(0.05), mass=1.0, position=(1.0, 0.0, 0.0))
    # The bob swings down about +y (x towards -z is a positive rotation about +y); stop it at 45 degrees.
    hinge = world.add_joint(tumble.HingeJoint(bob, None, (0, 0, 0), (0, 1, 0), lower=-0.1, upper=math.pi / 4))
    angles = []
    for _ in range(120):
        world.step(DT)
        angles.append(hinge.angle)
    assert max(angles) < math.pi / 4 + 0.02
    assert max(angles) > math.pi / 4 - 0.02


@pytest.mark.parametrize("rate", [60, 240, 1000])
@pytest.mark.parametrize("kind", ["hinge", "slider"])
def test_a_joint_loaded_outside_its_range_is_brought_to_the_near_stop_and_left_at_rest(kind, rate):
    """A 1 kg ball and a 1 kg rod, free in space, joined 30° (0.3 m) outside a 40° (0.4 m) range: the limit brings
    them to the near stop, opening at contact_push_max (3 rad/s, 3 m/s) at most, and leaves them there: the slider
    exactly, the hinge within 0.9° (the relax pass leaves 1.7 % of the push, 0.05 rad/s, until the pair sleeps),
    the pair's momentum zero. Before the push was capped the hinge opened at over 100 rad/s, the relax pass left
    1.5 rad/s of it and the rod swung on past the stop (50 rad/s in Gymnasium's ant: its ankles hit the far stops)."""
    world = tumble.World(gravity=(0, 0, 0))
    ball = world.add_body(tumble.Sphere(0.25), mass=1.0)
    rod = world.add_body(tumble.Capsule(0.08, 0.4), mass=1.0, position=(0.28, 0, 0),
                         orientation=(math.cos(math.pi / 4), 0, math.sin(math.pi / 4), 0))  # fmt: skip
    if kind == "hinge":
        joint = world.add_joint(tumble.HingeJoint(ball, rod, (0.08, 0, 0), (0, 1, 0), lower=math.radians(30),
                                                  upper=math.radians(70)))  # fmt: skip
        stop, overshoot, value_of, speed_of = math.radians(30), math.radians(1.5), "angle", "angular_speed"
    else:
        joint = world.add_joint(tumble.SliderJoint(ball, rod, (1, 0, 0), lower=0.3, upper=0.7))
        stop, overshoot, value_of, speed_of = 0.3, 1e-9, "translation", "speed"
    values, speeds = [], []
    for _ in range(rate):  # one second
        world.step(1 / rate)
        values.append(getattr(joint, value_of))
        speeds.append(getattr(joint, speed_of))
    assert values[rate // 20 - 1] <= 3.0 * 0.05  # no faster than the cap over the first 0.05 s
    assert stop - 1e-6 < max(values) < stop + overshoot  # at the near stop, not past it (30.9°, 0.3 m measured)
    assert abs(speeds[-1]) < 1e-9  # at rest (asleep)
    momentum = ball.linear_momentum + rod.linear_momentum
    np.testing.assert_allclose(momentum, 0.0, atol=1e-12)


def test_hinge_spring_holds_a_horizontal_bar_against_gravity_at_its_static_deflection():
    world = tumble.World()
    bar = world.add_body(tumble.Box((1.0, 0.05, 0.05)), mass=1.0, position=(0.5, 0.0, 0.0))
    hinge = world.add_joint(
        tumble.HingeJoint(bar, None, (0, 0, 0), (0, 1, 0), spring_hertz=3.0, spring_damping_ratio=1.0)
    )
    for _ in range(300):
        world.step(DT)
    # the spring's stiffness is m_eff ω² with m_eff the bar's moment of inertia about the hinge (the joint's
    # effective mass along its axis with the anchor held); at rest k θ = m g l cos θ
    inertia = 1.0 * (1.0 + 0.0025) / 12 + 1.0 * 0.5**2
    k = inertia * (2 * math.pi * 3.0) ** 2
    theta = hinge.angle
    assert k * theta == pytest.approx(1.0 * G * 0.5 * math.cos(theta), rel=1e-2)


def test_fixed_joint_makes_two_bodies_one_rigid_body():
    world = tumble.World(gravity=(0, 0, 0))
    a = world.add_body(tumble.Box((0.4, 0.2, 0.2)), mass=1.0, position=(0, 0, 0), angular_velocity=(0.3, 2.0, 0.1))
    b = world.add_body(tumble.Sphere(0.1), mass=0.5, position=(0.3, 0.0, 0.0))
    # give b the velocity of the point of a where it sits, so the pair starts as one rigid body
    b.velocity = np.cross(a.angular_velocity, b.position - a.center_of_mass)
    b.angular_velocity = a.angular_velocity
    weld = world.add_joint(tumble.FixedJoint(a, b))
    p0, l0, e0 = world.linear_momentum(), world.angular_momentum(), world.kinetic_energy()
    for _ in range(240):
        world.step(DT)
        assert weld.position_error < 1e-3 and weld.angular_error < 1e-3
    np.testing.assert_allclose(world.linear_momentum(), p0, atol=1e-12)
    np.testing.assert_allclose(world.angular_momentum(), l0, rtol=5e-3, atol=1e-6)
    assert world.kinetic_energy() == pytest.approx(e0, rel=1e-2)


def test_ball_joint_conical_pendulum_keeps_its_height():
    length, alpha = 1.0, math.radians(30)
    radius = length * math.sin(alpha)
    speed = math.sqrt(G * radius * math.tan(alpha))
    world = tumble.World()
    bob = world.add_body(
        tumble.Sphere(0.01), mass=1.0, position=(radius, 0.0, -length * math.cos(alpha)), velocity=(0.0, speed, 0.0)
    )
    world.add_joint(tumble.BallJoint(bob, None, (0, 0, 0)))
    heights = []
    for _ in range(240):
        world.step(DT)
        heights.append(bob.position[2])
    np.testing.assert_allclose(heights, -length * math.cos(alpha), atol=2e-3)


def test_rope_is_slack_until_taut_then_holds():
    world = tumble.World()
    ball = world.add_body(tumble.Sphere(0.05), mass=1.0, position=(0.0, 0.0, -0.5))
    rope = world.add_joint(tumble.DistanceJoint(ball, None, ball.position, (0, 0, 0), length=1.0, min_length=0.0))
    world.step(DT)
    assert ball.velocity[2] == pytest.approx(-G * DT, rel=1e-9)  # free fall while slack
    for _ in range(120):
        world.step(DT)
    assert rope.length == pytest.approx(1.0, abs=2e-3)
    assert ball.position[2] == pytest.approx(-1.0, abs=2e-3)


def test_slider_crank_piston_follows_the_closed_form():
    """Crank (r) on a motor, connecting rod (l), piston on a slider: a closed loop of four joints."""
    r, l = 0.1, 0.3
    world = tumble.World(gravity=(0, 0, 0))
    crank = world.add_body(tumble.Box((r, 0.02, 0.02)), mass=0.5, position=(r / 2, 0.0, 0.0))
    rod = world.add_body(tumble.Box((l, 0.02, 0.02)), mass=0.3, position=(r + l / 2, 0.0, 0.0))
    piston = world.add_body(tumble.Box((0.05, 0.05, 0.05)), mass=0.4, position=(r + l, 0.0, 0.0))
    drive = world.add_joint(
        tumble.HingeJoint(crank, None, (0, 0, 0), (0, 0, 1), motor_speed=2 * math.pi, max_motor_torque=100.0)
    )
    world.add_joint(tumble.HingeJoint(rod, crank, (r, 0, 0), (0, 0, 1)))
    world.add_joint(tumble.HingeJoint(piston, rod, (r + l, 0, 0), (0, 0, 1)))
    world.add_joint(tumble.SliderJoint(piston, None, (1, 0, 0)))
    worst = 0.0
    for _ in range(120):
        world.step(DT)
        theta = drive.angle
        expected = r * math.cos(theta) + math.sqrt(l**2 - (r * math.sin(theta)) ** 2)
        worst = max(worst, abs(piston.position[0] - expected))
    assert worst < 1e-3
    assert drive.angular_speed == pytest.approx(2 * math.pi, rel=1e-3)


def test_hinge_chain_stays_connected_under_gravity():
    """A 10-link chain of 0.1 m capsules released at 45 degrees: anchors < 1 mm apart, axes < 0.01 rad."""
    world = tumble.World()
    direction = np.array([math.cos(math.pi / 4), 0.0, -math.sin(math.pi / 4)])
    tilt = tumble.rotation.quat_from_axis_angle((0, 1, 0), math.pi / 2 + math.pi / 4)
    previous = None
    for i in range(10):
        link = world.add_body(
            tumble.Capsule(0.01, 0.08), mass=0.1, position=direction * (0.05 + 0.1 * i), orientation=tilt
        )
        world.add_joint(tumble.HingeJoint(link, previous, direction * 0.1 * i, (0, 1, 0)))
        previous = link
    worst_gap = worst_angle = 0.0
    for _ in range(300):
        world.step(DT)
        worst_gap = max(worst_gap, max(j.position_error for j in world.joints))
        worst_angle = max(worst_angle, max(j.angular_error for j in world.joints))
    assert worst_gap < 1e-3
    assert worst_angle < 1e-2


def test_jointed_bodies_do_not_collide_unless_asked():
    def pair(collide):
        world = tumble.World(gravity=(0, 0, 0))
        a = world.add_body(tumble.Box((0.4, 0.4, 0.4)), mass=1.0, position=(0, 0, 0))
        b = world.add_body(tumble.Box((0.4, 0.4, 0.4)), mass=1.0, position=(0.3, 0, 0))  # overlapping by 0.1
        world.add_joint(tumble.BallJoint(a, b, (0.15, 0, 0), collide_connected=collide))
        for _ in range(30):
            world.step(DT)
        return world

    assert len(pair(False).contacts()) == 0
    assert len(pair(True).contacts()) > 0


def test_joint_impulses_conserve_linear_momentum_and_runs_are_deterministic():
    def run():
        world = tumble.World(gravity=(0, 0, 0))
        a = world.add_body(tumble.Box((0.3, 0.1, 0.1)), mass=1.0, velocity=(0.1, 0, 0), angular_velocity=(0, 0, 3))
        b = world.add_body(tumble.Box((0.3, 0.1, 0.1)), mass=2.0, position=(0.3, 0, 0), angular_velocity=(1, 0, 0))
        world.add_joint(tumble.HingeJoint(a, b, (0.15, 0, 0), (0, 1, 0)))
        p0 = world.linear_momentum()
        for _ in range(120):
            world.step(DT)
        np.testing.assert_allclose(world.linear_momentum(), p0, atol=1e-12)
        return world.state.digest()

    assert run() == run()


def test_a_jointed_island_sleeps_together_and_wakes_when_pushed():
    world = tumble.World()
    a = world.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, position=(0, 0, -0.5))
    b = world.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, position=(0, 0, -1.0))
    world.add_joint(tumble.BallJoint(a, None, (0, 0, 0)))
    world.add_joint(tumble.BallJoint(b, a, (0, 0, -0.75)))
    for _ in range(120):
        world.step(DT)
    assert a.sleeping and b.sleeping
    b.apply_impulse((0.5, 0.0, 0.0))
    assert not a.sleeping and not b.sleeping
    world.step(DT)
    assert abs(a.velocity[0]) > 0.0


def test_ball_joint_cone_and_twist_limits_hold():
    # A rod held at one end, starting horizontal along the cone's axis: it swings down until the 30° cone stops it.
    world = tumble.World()
    rod = world.add_body(
        tumble.Box((0.05, 0.05, 1.0)), mass=1.0, position=(0.5, 0, 0),
        orientation=tumble.rotation.quat_from_axis_angle((0, 1, 0), math.pi / 2),
    )  # fmt: skip
    shoulder = world.add_joint(tumble.BallJoint(rod, None, (0, 0, 0), axis=(1, 0, 0), cone_angle=math.radians(30)))
    swings = []
    for _ in range(120):
        world.step(DT)
        swings.append(shoulder.swing)
    assert max(swings) < math.radians(30) + 1e-3
    assert swings[-1] == pytest.approx(math.radians(30), abs=2e-3)  # resting against the cone
    assert shoulder.position_error < 1e-3
    # Spun about its own axis, a rod turns until the twist limit (about -z here: the spin is negative).
    world = tumble.World(gravity=(0, 0, 0))
    rod = world.add_body(tumble.Box((0.05, 0.05, 1.0)), mass=1.0, position=(0, 0, -0.5), angular_velocity=(0, 0, 3))
    wrist = world.add_joint(
        tumble.BallJoint(rod, None, (0, 0, 0), axis=(0, 0, -1), twist_lower=-0.5, twist_upper=0.5, cone_angle=0.3)
    )
    twists = []
    for _ in range(120):
        world.step(DT)
        twists.append(wrist.twist)
    assert min(twists) > -0.5 - 1e-3
    assert twists[-1] == pytest.approx(-0.5, abs=2e-3)
    assert wrist.swing < 1e-6


def test_stiff_joints_keep_a_whipping_chain_s_energy():
    """A 2-link chain released horizontal snaps taut as it swings: at 600 Hz the default joints (as stiff as the
    substeps allow, 1200 Hz) keep its energy within 1 %; 120 Hz joints soak up 5.8 % in 3 s (measured)."""
    drop = 0.1 * 9.81 * (0.05 + 0.15)  # potential released from horizontal to hanging
    losses = {}
    for hertz in (math.inf, 120.0):
        world = tumble.scenes.pendulum_chain(2, joint_hertz=hertz)
        energy = world.total_energy()
        world.simulate(3.0, 1 / 600)
        losses[hertz] = (energy - world.total_energy()) / drop
    assert abs(losses[math.inf]) < 0.01
    assert losses[120.0] > 0.03
