"""Contact against closed-form mechanics: bounce, friction on a ramp, stopping distance, rolling, momentum."""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble.rotation import quat_from_axis_angle, quat_to_matrix

G = 9.81
DT = 1 / 60


def ramp_world(theta: float, mu: float):
    """A plane through the origin tilted by ``theta`` about y (downhill is +x), friction ``mu``."""
    world = tumble.World()
    normal = (-np.sin(theta), 0.0, np.cos(theta))
    world.add_static(tumble.Plane(normal=normal), friction=mu)
    return world, np.array(normal), np.array([np.cos(theta), 0.0, np.sin(theta)])  # uphill direction


def drop_height(restitution: float, h0: float = 1.0) -> float:
    world = tumble.World()
    world.add_static(tumble.Plane(), restitution=restitution)
    ball = world.add_body(tumble.Sphere(0.1), density=1000.0, position=(0, 0, h0 + 0.1), restitution=restitution)
    traj = world.simulate(1.5 * np.sqrt(2 * h0 / G) * (1 + restitution) + 0.5, DT)
    z = traj.position[:, ball.index, 2] - 0.1
    first_impact = int(np.argmax(z < 0.02))  # the first frame at the ground
    assert first_impact > 0
    return float(z[first_impact:].max())


@pytest.mark.parametrize("restitution", [0.5, 0.8])
def test_ball_rebounds_to_e_squared_h(restitution):
    height = drop_height(restitution)
    # Issue bound 5 %; measured 0.8 % and 1.0 % low at 60 Hz (the apex is sampled at 60 Hz).
    assert height == pytest.approx(restitution**2 * 1.0, rel=0.05)


def test_ball_without_restitution_does_not_bounce():
    assert drop_height(0.0) < 0.005


@pytest.mark.parametrize(("theta_deg", "mu"), [(20.0, 0.5), (30.0, 0.7)])
def test_box_on_a_ramp_holds_when_tan_theta_below_mu(theta_deg, mu):
    theta = np.radians(theta_deg)
    assert np.tan(theta) < mu
    world, normal, _ = ramp_world(theta, mu)
    q = quat_from_axis_angle((0, 1, 0), -theta)  # tilt the box onto the ramp
    box = world.add_body(tumble.Box((0.2, 0.2, 0.2)), density=500.0, orientation=q, position=0.1 * normal,
                         friction=mu)  # fmt: skip
    world.simulate(0.5, DT)  # settle
    start = box.position
    world.simulate(2.0, DT)
    assert np.linalg.norm(box.position - start) < 1e-3  # issue: drift < 1 mm over 2 s


@pytest.mark.parametrize(("theta_deg", "mu"), [(30.0, 0.3), (40.0, 0.2)])
def test_box_slides_down_a_ramp_at_g_sin_minus_mu_cos(theta_deg, mu):
    theta = np.radians(theta_deg)
    world, normal, uphill = ramp_world(theta, mu)
    q = quat_from_axis_angle((0, 1, 0), -theta)
    box = world.add_body(tumble.Box((0.2, 0.2, 0.2)), density=500.0, orientation=q, position=0.1 * normal,
                         friction=mu)  # fmt: skip
    world.simulate(0.25, DT)
    traj = world.simulate(1.0, DT)
    s = -(traj.position[:, box.index] @ uphill)  # distance travelled downhill
    t = traj.time - traj.time[0]
    accel = np.polyfit(t, s, 2)[0] * 2
    expected = G * (np.sin(theta) - mu * np.cos(theta))
    assert accel == pytest.approx(expected, rel=0.03)  # issue bound 3 %


def test_box_sliding_on_the_floor_stops_after_v0_squared_over_2_mu_g():
    mu, v0 = 0.4, 3.0
    world = tumble.World()
    world.add_static(tumble.Plane(), friction=mu)
    box = world.add_body(tumble.Box((0.2, 0.2, 0.2)), density=500.0, position=(0, 0, 0.1), friction=mu)
    world.simulate(0.2, DT)  # settle the resting contact first
    x0 = box.position[0]
    box.velocity = (v0, 0.0, 0.0)
    world.simulate(2.0, DT)
    assert abs(box.velocity[0]) < 1e-3
    assert box.position[0] - x0 == pytest.approx(v0**2 / (2 * mu * G), rel=0.03)


@pytest.mark.parametrize("c", [0.02, 0.05])
def test_a_ball_with_rolling_resistance_stops_after_v0_squared_over_two_five_sevenths_c_g(c):
    # A resisting moment c N r on a ball rolling without slipping: (I + m r²) ω' = -c m g r, so a = -(5/7) c g.
    v0, r = 2.0, 0.1
    world = tumble.World()
    world.add_static(tumble.Plane(), friction=0.8)
    ball = world.add_body(tumble.Sphere(r), density=1000.0, position=(0, 0, r), friction=0.8, rolling_resistance=c)
    world.simulate(0.1, DT)  # settle
    x0 = ball.position[0]
    ball.velocity, ball.angular_velocity = (v0, 0.0, 0.0), (0.0, v0 / r, 0.0)
    world.simulate(v0 / (5 / 7 * c * G) + 1.0, DT)
    assert np.linalg.norm(ball.velocity) < 1e-3
    assert ball.position[0] - x0 == pytest.approx(v0**2 / (2 * 5 / 7 * c * G), rel=0.03)


def test_without_rolling_resistance_a_rolling_ball_keeps_rolling():
    world = tumble.World()
    world.add_static(tumble.Plane())
    ball = world.add_body(tumble.Sphere(0.1), density=1000.0, position=(0, 0, 0.1))
    ball.velocity, ball.angular_velocity = (2.0, 0.0, 0.0), (0.0, 20.0, 0.0)
    world.simulate(2.0, DT)
    assert ball.velocity[0] == pytest.approx(2.0, rel=1e-3)


def test_sphere_rolls_down_a_ramp_at_five_sevenths_g_sin_theta():
    theta, mu = np.radians(20.0), 0.6
    world, normal, uphill = ramp_world(theta, mu)
    ball = world.add_body(tumble.Sphere(0.1), density=1000.0, position=0.1 * normal, friction=mu)
    world.simulate(0.1, DT)
    traj = world.simulate(1.0, DT)
    s = -(traj.position[:, ball.index] @ uphill)
    t = traj.time - traj.time[0]
    accel = np.polyfit(t, s, 2)[0] * 2
    assert accel == pytest.approx(5 / 7 * G * np.sin(theta), rel=0.03)  # issue bound 3 %
    # Rolling without slipping: v = ω r.
    v = np.linalg.norm(ball.velocity)
    assert np.linalg.norm(ball.angular_velocity) * 0.1 == pytest.approx(v, rel=0.02)


def test_head_on_collision_without_gravity_conserves_momentum():
    world = tumble.World(gravity=(0, 0, 0))
    a = world.add_body(tumble.Box((0.2, 0.2, 0.2)), density=1000.0, position=(-0.5, 0.0, 0.0), velocity=(3, 0, 0),
                       angular_velocity=(0, 1, 0.5), restitution=0.5)  # fmt: skip
    world.add_body(tumble.Sphere(0.15), density=500.0, position=(0.5, 0.03, 0.0), velocity=(-1, 0, 0), restitution=0.5)
    p0, L0 = world.linear_momentum(), world.angular_momentum()
    world.simulate(1.0, DT)
    assert a.velocity[0] < 3.0  # they did collide
    np.testing.assert_allclose(world.linear_momentum(), p0, atol=1e-12)  # round-off (measured 4e-15)
    np.testing.assert_allclose(world.angular_momentum(), L0, atol=1e-11)


def test_newtons_cradle_passes_the_momentum_along():
    world = tumble.World(gravity=(0, 0, 0))
    r = 0.1
    balls = [world.add_body(tumble.Sphere(r), density=1000.0, position=(2 * r * k, 0, 0), restitution=1.0)
             for k in range(5)]  # fmt: skip
    striker = world.add_body(tumble.Sphere(r), density=1000.0, position=(-0.5, 0, 0), velocity=(2.0, 0, 0),
                             restitution=1.0)  # fmt: skip
    p0, e0 = world.linear_momentum(), world.kinetic_energy()
    world.simulate(1.0, DT)
    speeds = [b.velocity[0] for b in balls]
    # Sequential impacts with e = 1 between equal balls swap velocities: all the motion ends in the last ball
    # (measured exactly: 0 and 2 m/s to round-off), with momentum and energy kept.
    assert striker.velocity[0] == pytest.approx(0.0, abs=1e-9)
    assert speeds[-1] == pytest.approx(2.0, rel=1e-9)
    assert all(abs(v) < 1e-9 for v in speeds[:-1])
    np.testing.assert_allclose(world.linear_momentum(), p0, atol=1e-12)
    assert world.kinetic_energy() == pytest.approx(e0, rel=1e-9)


def test_ten_box_tower_stands():
    world = tumble.World()
    world.add_static(tumble.Plane())
    boxes = [world.add_body(tumble.Box((0.5, 0.5, 0.5)), density=500.0, position=(0, 0, 0.25 + 0.5 * k))
             for k in range(10)]  # fmt: skip
    top0 = boxes[-1].position
    world.simulate(10.0, DT)
    assert np.linalg.norm(boxes[-1].position - top0) < 0.01  # issue: top moves < 1 cm
    assert all(np.linalg.norm(b.velocity) < 1e-2 for b in boxes)


def test_fast_sphere_does_not_tunnel_through_a_thin_wall():
    world = tumble.World(gravity=(0, 0, 0))
    world.add_static(tumble.Box((0.02, 2.0, 2.0)), position=(1.0, 0, 0))
    ball = world.add_body(tumble.Sphere(0.05), density=1000.0, velocity=(100.0, 0, 0))
    world.simulate(0.5, DT)
    assert ball.position[0] < 1.0 - 0.01


def test_fast_box_does_not_tunnel_through_a_thin_wall():
    world = tumble.World(gravity=(0, 0, 0))
    world.add_static(tumble.Box((0.02, 2.0, 2.0)), position=(1.0, 0, 0))
    box = world.add_body(tumble.Box((0.1, 0.1, 0.1)), density=1000.0, velocity=(100.0, 0, 0))
    world.simulate(0.5, DT)
    assert box.position[0] < 1.0 - 0.01


def test_contact_runs_are_bit_identical():
    def pile():
        world = tumble.World()
        world.add_static(tumble.Plane())
        rng = np.random.default_rng(3)
        for k in range(20):
            world.add_body(tumble.Box((0.3, 0.3, 0.3)), density=300.0, position=(rng.uniform(-0.5, 0.5),
                           rng.uniform(-0.5, 0.5), 0.3 + 0.35 * k))  # fmt: skip
        return world

    a, b = pile(), pile()
    a.simulate(2.0, DT)
    for _ in range(120):
        b.step(DT)
    assert a.state.digest() == b.state.digest()


def _crosses_wall(shape, speed, wall_angle_deg, spin, rate: int = 60) -> bool:
    """Whether a spinning body fired at a slanted 2 cm static wall ever passes from its near side to its far side
    between two frames of ``1 / rate`` s (within the wall's extent)."""
    world = tumble.World(gravity=(0, 0, 0))
    turn = quat_from_axis_angle((0, 0, 1), np.radians(wall_angle_deg))
    world.add_static(tumble.Box((0.02, 2.0, 2.0)), position=(1.0, 0, 0), orientation=turn)
    body = world.add_body(shape, density=1000.0, velocity=(speed, 0, 0), angular_velocity=spin)
    traj = world.simulate(0.3, 1 / rate)
    rotation = quat_to_matrix(turn)
    relative = traj.position[:, body.index] - (1.0, 0.0, 0.0)
    depth, across = relative @ rotation[:, 0], relative @ rotation[:, 1]
    inside = (np.abs(across[1:]) < 1.0) & (np.abs(relative[1:, 2]) < 1.0)
    return bool(np.any((depth[:-1] < 0.0) & (depth[1:] > 0.0) & inside))


SPINNING = {
    "box": (tumble.Box((0.1, 0.1, 0.1)), (0.0, 0.0, 30.0)),
    "capsule": (tumble.Capsule(0.03, 0.2), (0.0, 50.0, 0.0)),
    "hull": (tumble.ConvexHull(np.random.default_rng(0).normal(size=(10, 3)) * 0.05), (20.0, 0.0, 40.0)),
    "cylinder": (tumble.Cylinder(0.04, 0.1), (20.0, 0.0, 40.0)),
}


@pytest.mark.parametrize("name", sorted(SPINNING))
@pytest.mark.parametrize("wall_angle_deg", [0.0, 30.0, 60.0])
def test_spinning_bodies_at_30_m_per_s_do_not_tunnel_through_a_slanted_wall(name, wall_angle_deg):
    # Speculative contacts alone let the cylinder through at every angle, and the others at 100 m/s: the time of
    # impact sweep (geometry/toi.py) stops them.
    shape, spin = SPINNING[name]
    assert not _crosses_wall(shape, 30.0, wall_angle_deg, spin)


@pytest.mark.parametrize("rate", [60, 240, 1000])
def test_a_cylinder_its_impact_spins_to_300_rad_per_s_is_held_by_the_wall_at_every_rate(rate):
    """The cylinder above, spun to 110-320 rad/s by its first impact (3-5 rad in a 60 Hz step), stays on the wall's
    near side at 60, 240 and 1000 Hz (issue 50, part 3). Its 30° case was an imperative xfail (issue 3: it worked its
    way through over several steps) that never ran its check: it already held before issue 50's changes, and
    still does after them (measured at both)."""
    shape, spin = SPINNING["cylinder"]
    for wall_angle_deg in (0.0, 30.0, 60.0):
        assert not _crosses_wall(shape, 30.0, wall_angle_deg, spin, rate), wall_angle_deg


@pytest.mark.parametrize("name", ["box", "capsule", "hull"])
@pytest.mark.parametrize("wall_angle_deg", [30.0, 45.0, 60.0])
def test_spinning_bodies_at_100_m_per_s_do_not_tunnel_through_a_slanted_wall(name, wall_angle_deg):
    shape, spin = SPINNING[name]
    assert not _crosses_wall(shape, 100.0, wall_angle_deg, spin)
