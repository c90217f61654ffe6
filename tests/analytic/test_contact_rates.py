"""Contact outcomes that do not depend on the step size or on where a touch falls in it (issue 16).

A grid of step sizes and substep counts; in each cell the drop heights run from 0.90 to 1.10 m and the cradle's
striker starts at 9 distances, so that the touch falls at every phase of a substep. The diagonal of the grid runs
in ``make test``, the whole grid in ``make test-slow``.

Before the fix (a ball slowed by the speculative constraint in the substep before its touch, then bounced with
the speed it had left, and velocities half a substep ahead of positions), 76 of these 80 tests failed: balls
rebounded to 0.00-1.59 e²h depending on the cell and the phase (within 2 % only at 1000 Hz with 1 substep, and at
240 Hz with 1 substep for e = 1), and the cradle failed in every cell.
"""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble import scenes
from tumble.rotation import quat_from_axis_angle

G = 9.81
RATES = (30, 60, 120, 240, 1000)
SUBSTEPS = (1, 4, 8, 16)
DIAGONAL = {(30, 1), (60, 4), (120, 8), (240, 16), (1000, 8)}
GRID = [
    pytest.param(rate, substeps, marks=() if (rate, substeps) in DIAGONAL else pytest.mark.slow,
                 id=f"{rate}Hz-{substeps}sub")
    for rate in RATES
    for substeps in SUBSTEPS
]  # fmt: skip


def rebound_ratio(restitution: float, height: float, rate: int, substeps: int) -> float:
    """Apex of the first rebound of a ball (radius 0.1 m, 1000 kg/m³) dropped from ``height`` onto a plane, over
    ``e² height``."""
    world = tumble.World(substeps=substeps)
    world.add_static(tumble.Plane(), restitution=restitution)
    ball = world.add_body(tumble.Sphere(0.1), density=1000.0, position=(0, 0, height + 0.1), restitution=restitution)
    fall = np.sqrt(2 * height / G)
    trajectory = world.simulate(fall * (1 + 1.5 * restitution) + 0.1, 1 / rate)
    z = trajectory.position[:, ball.index, 2] - 0.1
    bottom = int(np.argmin(z[: int(1.3 * fall * rate) + 2]))
    return float(z[bottom:].max() / (restitution**2 * height))


@pytest.mark.parametrize(("rate", "substeps"), GRID)
@pytest.mark.parametrize("restitution", [0.5, 0.8, 1.0])
def test_a_ball_rebounds_to_e_squared_h_whatever_the_phase_of_its_touch(restitution, rate, substeps):
    ratios = [rebound_ratio(restitution, h, rate, substeps) for h in np.linspace(0.90, 1.10, 7)]
    # Issue bound 2 %; measured within 0.6 % (dt = 1/30, the apex sampled at 30 Hz), 0.1 % from 60 Hz on.
    np.testing.assert_allclose(ratios, 1.0, atol=0.02)


def box_rebound(restitution: float, height: float, rate: int, substeps: int) -> tuple[float, float]:
    """A 0.2 m cube dropped flat from ``height``: its first rebound's apex over ``e² height``, and its spin there."""
    world = tumble.World(substeps=substeps)
    world.add_static(tumble.Plane(), restitution=restitution)
    box = world.add_body(tumble.Box((0.2, 0.2, 0.2)), density=1000.0, position=(0, 0, height + 0.1),
                         restitution=restitution)  # fmt: skip
    fall = np.sqrt(2 * height / G)
    trajectory = world.simulate(fall * (1 + 1.5 * restitution) + 0.1, 1 / rate)
    z = trajectory.position[:, box.index, 2] - 0.1
    bottom = int(np.argmin(z[: int(1.3 * fall * rate) + 2]))
    apex = bottom + int(np.argmax(z[bottom:]))
    spin = np.linalg.norm(trajectory.angular_velocity[apex, box.index])
    return float(z[apex] / (restitution**2 * height)), float(spin)


@pytest.mark.parametrize(("rate", "substeps"), GRID)
@pytest.mark.parametrize("restitution", [0.5, 0.8])
def test_a_box_dropped_flat_rebounds_to_e_squared_h_without_spinning(restitution, rate, substeps):
    """Its four corners bounce together (one joint solve), not one after the other: before, 0.44-0.77 e²h and
    10-22 rad/s of spin."""
    for height in np.linspace(0.90, 1.10, 5):
        ratio, spin = box_rebound(restitution, height, rate, substeps)
        assert ratio == pytest.approx(1.0, abs=0.02)  # issue bound 2 %; measured within 0.2 %
        assert spin < 1e-6  # measured 4e-11 rad/s


def dropped_shape(name: str) -> tumble.Shape:
    """The bodies of the energy grid: a 0.3 x 0.2 x 0.1 m box, a cylinder (r 0.1 m, 0.3 m long), an irregular hull."""
    if name == "box":
        return tumble.Box((0.3, 0.2, 0.1))
    if name == "cylinder":
        return tumble.Cylinder(0.1, 0.3)
    return tumble.ConvexHull(np.random.default_rng(3).normal(size=(12, 3)) * (0.15, 0.1, 0.07))


def energy_rise(name: str, angle: float, restitution: float, rate: int, substeps: int) -> float:
    """The most a body's total energy rises above its start, over its start, while it falls 1.2 m tilted by
    ``angle`` degrees onto a plane (both with ``restitution``, friction 0.5) and tumbles for 2 s, sampled every step.

    The energy is semi-implicit Euler's own: its velocity leads its positions by half a substep ``h``, so it is taken
    at the time of the positions, ``v + g h/2`` (free flight then keeps it exactly; the plain ``½ m v² + m g z``
    rises by ``m g u h`` at any bounce at ``u``, a perfect one included)."""
    world = tumble.World(substeps=substeps)
    world.add_static(tumble.Plane(), restitution=restitution)
    body = world.add_body(dropped_shape(name), density=1000.0, position=(0, 0, 1.2), restitution=restitution,
                          orientation=quat_from_axis_angle((1, 2, 0.5), np.radians(angle)))  # fmt: skip
    h = 1 / rate / world.solver.substeps_for(1 / rate)
    g = world.gravity

    def energy() -> float:
        return (
            world.total_energy() + body.mass * float(body.velocity @ g) * h / 2 + body.mass * float(g @ g) * h * h / 8
        )

    start, rise = energy(), -np.inf
    for _ in range(int(2 * rate)):
        world.step(1 / rate)
        rise = max(rise, energy() - start)
    return rise / start


@pytest.mark.parametrize(("rate", "substeps"), GRID)
@pytest.mark.parametrize("name", ["box", "cylinder", "hull"])
def test_a_tumbling_body_never_gains_energy_from_its_bounces(name, rate, substeps):
    """A box, a cylinder and a hull dropped at a slant (5°, 20°, 40°) land on corners and edges, their points touching
    at different times within a substep: with e = 0.5, 0.9 and 1 the energy never rises above its start by more than
    1e-6 of it (measured at most 1.5e-13, at 1000 Hz). Before issue 50 an elastic box gained up to 38 % (60 Hz):
    impulses turned ω through the inertia of the step's start, and a box at 50 rad/s turns 0.8 rad in a step; a
    bounce on a point the step's rotation brought in was stopped and then bounced from stale speeds. Then a hull at
    45 rad/s still gained 1.2 % (120 Hz, 1 substep) while bounces turned ω through the inertia of the substep's
    start rather than of the touch."""
    for restitution in (0.5, 0.9, 1.0):
        for angle in (5.0, 20.0, 40.0):
            assert energy_rise(name, angle, restitution, rate, substeps) <= 1e-6, (restitution, angle)


def elastic_pile_rise(seed: int, rate: int, substeps: int) -> float:
    """The largest rise of the total energy in one step, over its start, while six boxes and hulls (random sizes,
    tilts and spins of ~5 rad/s, from ``seed``) fall onto each other and a plane with e = 1 (friction 0.5) for 2 s;
    the energy taken at the positions' time, as in :func:`energy_rise`."""
    rng = np.random.default_rng(seed)
    world = tumble.World(substeps=substeps)
    world.add_static(tumble.Plane(), restitution=1.0)
    bodies = []
    for i in range(6):
        shape = (
            tumble.Box(tuple(rng.uniform(0.1, 0.3, 3))) if i % 2 else tumble.ConvexHull(rng.normal(size=(12, 3)) * 0.1)
        )
        position = (rng.uniform(-0.15, 0.15), rng.uniform(-0.15, 0.15), 0.5 + 0.4 * i)
        orientation = quat_from_axis_angle(rng.normal(size=3), rng.uniform(0, 3))
        bodies.append(world.add_body(shape, density=1000.0, restitution=1.0, position=position, orientation=orientation,
                                     angular_velocity=rng.normal(size=3) * 5))  # fmt: skip
    h = 1 / rate / world.solver.substeps_for(1 / rate)
    g = world.gravity

    def energy() -> float:
        lead = sum(b.mass * (float(b.velocity @ g) * h / 2 + float(g @ g) * h * h / 8) for b in bodies)
        return world.total_energy() + lead

    start = previous = energy()
    rise = -np.inf
    for _ in range(int(2 * rate)):
        world.step(1 / rate)
        now = energy()
        rise, previous = max(rise, now - previous), now
    return rise / start


@pytest.mark.parametrize(("rate", "substeps"), [(60, 8), (240, 4), (1000, 1)])
def test_a_pile_of_spinning_bodies_bouncing_elastically_never_gains_energy_in_a_step(rate, substeps):
    """Bodies that strike each other, not only the ground, spinning: both bodies of a pair are turned to the touch.
    Over four seeds no step adds more than 1e-6 of the energy (measured: none adds any, every step loses 2e-8 to
    4e-6). Before the bounce turned ω through the inertia of the touch (950304f), steps added 1e-4 to 4.7e-3."""
    for seed in range(4):
        assert elastic_pile_rise(seed, rate, substeps) <= 1e-6, seed


def cradle(offset: float, rate: int, substeps: int) -> tuple[float, float, float]:
    """Newton's cradle (``scenes.newtons_cradle``, striker at 2 m/s) with the striker ``offset`` further back, after
    1 s: the last ball's speed over the striker's, the kinetic energy over its start, and the striker's speed."""
    world = scenes.newtons_cradle(substeps=substeps)
    striker = world.body("striker")
    striker.position = striker.position - np.array([offset, 0.0, 0.0])
    energy = world.kinetic_energy()
    world.simulate(1.0, 1 / rate)
    return world.body("last").velocity[0] / 2.0, world.kinetic_energy() / energy, float(striker.velocity[0])


CRADLE_OFFSETS = np.linspace(0.0, 0.0333, 9)  # [m] a 2 m/s striker's path over a 60 Hz step: every phase


@pytest.mark.parametrize(("rate", "substeps"), GRID)
def test_newtons_cradle_passes_the_striker_speed_whatever_the_phase_of_its_touch(rate, substeps):
    for offset in CRADLE_OFFSETS:
        speed, energy, striker = cradle(offset, rate, substeps)
        # Issue bounds 1 %; measured to round-off (5e-16) in every cell, so held to 1e-9: equal balls with e = 1
        # swap velocities exactly, and anything short of that is a bug.
        assert speed == pytest.approx(1.0, rel=1e-9)
        assert energy == pytest.approx(1.0, rel=1e-9)
        assert abs(striker) < 1e-9


# --- friction, rolling and resting contact across the grid (tolerances as in test_contact.py) -----------------------


def ramp_world(theta: float, mu: float, substeps: int):
    """A plane through the origin tilted by ``theta`` about y (downhill is +x), friction ``mu``."""
    world = tumble.World(substeps=substeps)
    normal = np.array([-np.sin(theta), 0.0, np.cos(theta)])
    world.add_static(tumble.Plane(normal=tuple(normal)), friction=mu)
    return world, normal, np.array([np.cos(theta), 0.0, np.sin(theta)])  # uphill direction


def box_on_ramp(theta_deg: float, mu: float, substeps: int):
    theta = np.radians(theta_deg)
    world, normal, uphill = ramp_world(theta, mu, substeps)
    box = world.add_body(tumble.Box((0.2, 0.2, 0.2)), density=500.0, position=0.1 * normal, friction=mu,
                         orientation=quat_from_axis_angle((0, 1, 0), -theta))  # fmt: skip
    return world, box, uphill


def downhill_acceleration(world, body, uphill, rate: int) -> float:
    trajectory = world.simulate(1.0, 1 / rate)
    s = -(trajectory.position[:, body.index] @ uphill)
    return float(2 * np.polyfit(trajectory.time - trajectory.time[0], s, 2)[0])


def stick_drift(rate: int, substeps: int) -> float:
    """How far a box on a 30° ramp with μ = 0.7 (tan 30° = 0.58) moves in 2 s after settling [m]."""
    world, box, _ = box_on_ramp(30.0, 0.7, substeps)
    world.simulate(0.5, 1 / rate)
    start = box.position
    world.simulate(2.0, 1 / rate)
    return float(np.linalg.norm(box.position - start))


def slide_ratio(rate: int, substeps: int) -> float:
    """A box sliding down a 30° ramp with μ = 0.3: its acceleration over ``g (sin θ − μ cos θ)``."""
    theta, mu = np.radians(30.0), 0.3
    world, box, uphill = box_on_ramp(30.0, mu, substeps)
    world.simulate(0.25, 1 / rate)
    return downhill_acceleration(world, box, uphill, rate) / (G * (np.sin(theta) - mu * np.cos(theta)))


def roll_ratio(rate: int, substeps: int) -> float:
    """A ball rolling down a 20° ramp (μ = 0.6): its acceleration over ``5/7 g sin θ``."""
    theta, mu = np.radians(20.0), 0.6
    world, normal, uphill = ramp_world(theta, mu, substeps)
    ball = world.add_body(tumble.Sphere(0.1), density=1000.0, position=0.1 * normal, friction=mu)
    world.simulate(0.1, 1 / rate)
    return downhill_acceleration(world, ball, uphill, rate) / (5 / 7 * G * np.sin(theta))


STOP_MU, STOP_V0 = 0.4, 3.0


def stop_ratio(rate: int, substeps: int) -> tuple[float, float]:
    """A box sent sliding at 3 m/s on a floor with μ = 0.4: the distance to its stop over ``v0² / (2 μ g)``, and
    its speed after 2 s."""
    world = tumble.World(substeps=substeps)
    world.add_static(tumble.Plane(), friction=STOP_MU)
    box = world.add_body(tumble.Box((0.2, 0.2, 0.2)), density=500.0, position=(0, 0, 0.1), friction=STOP_MU)
    world.simulate(0.2, 1 / rate)
    x0 = box.position[0]
    box.velocity = (STOP_V0, 0.0, 0.0)
    world.simulate(2.0, 1 / rate)
    return (box.position[0] - x0) / (STOP_V0**2 / (2 * STOP_MU * G)), abs(float(box.velocity[0]))


def tower_motion(rate: int, substeps: int) -> tuple[float, float]:
    """Ten 0.5 m boxes stacked on a plane, after 10 s: how far the top one moved [m] and the fastest speed [m/s]."""
    world = tumble.World(substeps=substeps)
    world.add_static(tumble.Plane())
    boxes = [world.add_body(tumble.Box((0.5, 0.5, 0.5)), density=500.0, position=(0, 0, 0.25 + 0.5 * k))
             for k in range(10)]  # fmt: skip
    top = boxes[-1].position
    world.simulate(10.0, 1 / rate)
    return float(np.linalg.norm(boxes[-1].position - top)), max(float(np.linalg.norm(b.velocity)) for b in boxes)


@pytest.mark.parametrize(("rate", "substeps"), GRID)
def test_a_box_sticks_on_a_ramp_below_the_friction_angle(rate, substeps):
    assert stick_drift(rate, substeps) < 1e-3  # measured at most 6e-8 mm (0.2 mm at 30 Hz before substeps_for)


@pytest.mark.parametrize(("rate", "substeps"), GRID)
def test_a_box_slides_down_a_ramp_at_g_sin_minus_mu_cos(rate, substeps):
    assert slide_ratio(rate, substeps) == pytest.approx(1.0, rel=0.03)  # measured within 1.3e-4


@pytest.mark.parametrize(("rate", "substeps"), GRID)
def test_a_ball_rolls_down_a_ramp_at_five_sevenths_g_sin_theta(rate, substeps):
    assert roll_ratio(rate, substeps) == pytest.approx(1.0, rel=0.03)  # measured within 5e-5 (1.1 % before
    # substeps_for, at 30 Hz with one substep)


@pytest.mark.parametrize(("rate", "substeps"), GRID)
def test_a_sliding_box_stops_after_v0_squared_over_2_mu_g(rate, substeps):
    distance, speed = stop_ratio(rate, substeps)
    assert speed < 1e-3
    # Semi-implicit Euler stops short by v0 h / 2 (its velocities lead its positions by half a substep): a relative
    # μ g h / v0 with h the substep the step takes (measured 0.27 % at 30, 60 and 120 Hz, whose steps take 480 Hz
    # substeps whatever they ask); the test allows it on top of the 3 %.
    h = 1 / (rate * taken(rate, substeps))
    assert distance == pytest.approx(1.0, rel=0.03 + STOP_MU * G * h / STOP_V0)


@pytest.mark.parametrize(("rate", "substeps"), GRID)
def test_a_ten_box_tower_stands(rate, substeps):
    moved, fastest = tower_motion(rate, substeps)
    # Measured 5.8-7.3 mm, most of it sag. Before issue 16's part 3 the tower collapsed with one substep at 30 and
    # 60 Hz, swayed 30 cm at 120 Hz, and moved 34 and 15 mm with four substeps at 30 and 60 Hz: the substeps did
    # not reach the rate its 60 Hz contacts need, which a step now takes (SolverSettings.substeps_for).
    assert moved < 0.01
    assert fastest < 1e-2


def test_a_step_with_too_few_substeps_is_the_step_with_enough():
    """Below the substep rate the contacts need, a step takes that rate's substeps: the same motion, bit for bit."""

    def pile(substeps):
        world = scenes.box_pile(12, substeps=substeps)
        world.simulate(1.0, 1 / 30)
        return world.state.body_pos.copy()

    np.testing.assert_array_equal(pile(1), pile(16))
    assert not np.array_equal(pile(1), pile(32))


@pytest.mark.parametrize("hertz", [30.0, 60.0, 120.0])
@pytest.mark.parametrize(("rate", "substeps"), [(60, 1), (240, 1), (1000, 1), (60, 16)])
def test_a_stack_sags_by_the_rule_of_its_contact_stiffness(hertz, rate, substeps):
    """A soft contact is a spring of stiffness m_eff ω² (ω = 2π contact_hertz, static contacts at 2ω), so each of
    the four points under k boxes of mass M sinks (k M g / 4) / (m_eff ω²): m_eff = M / 8 between two boxes, M / 4
    against the ground. Ten boxes: (2 (1 + ... + 9) + 10 / 4) g / ω² = 92.5 g / ω² (6.4 mm at 60 Hz), whatever the
    step size and substeps."""
    world = tumble.World(substeps=substeps, contact_hertz=hertz)
    world.add_static(tumble.Plane())
    top = [world.add_body(tumble.Box((0.5, 0.5, 0.5)), density=500.0, position=(0, 0, 0.25 + 0.5 * k))
           for k in range(10)][-1]  # fmt: skip
    world.simulate(3.0, 1 / rate)
    sag = 4.75 - top.position[2]
    # Measured 0.94-1.09 of the rule with 30 Hz contacts (it moves with the substep), within 5 % at 60 Hz, 0.1 % at 120.
    assert sag == pytest.approx(92.5 * G / (2 * np.pi * hertz) ** 2, rel=0.12)


def taken(rate: int, substeps: int) -> int:
    """The substeps a step of ``1 / rate`` takes with ``substeps`` asked for (at least 8 per contact period)."""
    return tumble.World(substeps=substeps).solver.substeps_for(1 / rate)


def outcome_table() -> str:
    """The grid's outcomes as the Markdown table of ``docs/contact.md``."""
    lines = [
        "| Hz | substeps (taken) | ball rebound / e²h | flat box rebound / e²h (spin) | cradle: last / striker"
        " | ramp: stick drift, slide, roll | stop distance | tower: top moved |",
        "| ---: | ---: | --- | --- | --- | --- | --- | --- |",
    ]
    for rate in RATES:
        for substeps in SUBSTEPS:
            balls = [rebound_ratio(e, h, rate, substeps) for e in (0.5, 0.8, 1.0) for h in np.linspace(0.9, 1.1, 7)]
            boxes = [box_rebound(e, h, rate, substeps) for e in (0.5, 0.8) for h in np.linspace(0.9, 1.1, 5)]
            speeds = [cradle(offset, rate, substeps)[0] for offset in CRADLE_OFFSETS]
            moved, _ = tower_motion(rate, substeps)
            lines.append(
                f"| {rate} | {substeps} ({taken(rate, substeps)}) | {min(balls):.3f}–{max(balls):.3f} |"
                f" {min(b[0] for b in boxes):.3f}–{max(b[0] for b in boxes):.3f}"
                f" ({max(b[1] for b in boxes):.0e} rad/s) | {min(speeds):.4f}–"
                f"{max(speeds):.4f} | {1e3 * stick_drift(rate, substeps):.2f} mm, {slide_ratio(rate, substeps):.4f},"
                f" {roll_ratio(rate, substeps):.4f} | {stop_ratio(rate, substeps)[0]:.4f} | {1e3 * moved:.1f} mm |"
            )
    return "\n".join(lines)


if __name__ == "__main__":
    print(outcome_table())
