"""The shared scenes of ``tumble.scenes`` against the outcomes issue 3 asks for: stacks stand and sleep, piles
settle without sinking, rows topple, ramps sort by friction, bullets stop at their walls."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from overlap_depths import overlap_depths
from tumble import World, scenes
from tumble.rotation import quat_from_rotvec, quat_to_matrix
from tumble.shapes import Box, ConvexHull, Cylinder, Plane, Sphere

DT = 1 / 60


def lowest_corner_heights(world, edge: float) -> np.ndarray:
    """The lowest corner of each cube (edge ``edge``) above z = 0."""
    half = np.full(3, edge / 2)
    return np.array([b.position[2] - np.abs(quat_to_matrix(b.orientation)[2]) @ half
                     for b in world.bodies if not b.is_static])  # fmt: skip


@pytest.mark.slow
def test_the_210_box_pyramid_stands_for_ten_seconds_and_falls_asleep():
    world = scenes.pyramid(20)
    top = world.body("top")
    start = top.position
    world.simulate(10.0, DT)
    assert np.linalg.norm(top.position - start) < 0.01  # issue: top moves < 1 cm (measured 7.9 mm, most of it sag)
    assert all(body.sleeping for body in world.bodies if not body.is_static)


def test_the_ten_box_tower_falls_asleep_standing():
    world = scenes.tower(10)
    top = world.body("top")
    start = top.position
    world.simulate(3.0, DT)
    assert np.linalg.norm(top.position[:2] - start[:2]) < 2e-3  # hardly any sway (measured 1.1 mm)
    assert top.sleeping


# Every pile over several seeds, never one lucky trajectory (issue 44): seeds 0-2 in make test, 3-12 in make
# test-slow. Measured over seeds 0-12: the lowest corner 0.48-0.77 mm into the ground, the deepest contact 1.8-2.9 mm,
# the fastest awake box 11-27 mm/s.
@pytest.mark.parametrize("seed", [*range(3), *(pytest.param(seed, marks=pytest.mark.slow) for seed in range(3, 13))])
def test_the_1000_box_pile_settles_without_sinking_into_the_ground(seed):
    world = scenes.box_pile(1000, seed=seed)
    world.simulate(5.0, DT)
    assert lowest_corner_heights(world, 0.2).min() > -0.01  # issue: no box more than 1 cm into the ground
    assert -world.contacts().separation.min() < 5e-3  # benchmark target: penetration < 5 mm
    moving = [b for b in world.bodies if not b.is_static and not b.sleeping]
    assert max((np.linalg.norm(b.velocity) for b in moving), default=0.0) < 0.1


def mesh_height(mesh, points) -> np.ndarray:
    """The height of an upward-facing mesh (one sheet over the xy plane) under each of ``points`` (..., 3): the
    plane of the triangle whose projection holds the point; NaN outside the mesh."""
    v, f = mesh.vertices, mesh.faces
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    xy = points[..., None, :2]  # (..., 1, 2) against (faces, 2)
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    u = ((xy[..., 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (xy[..., 1] - a[:, 1])) / det
    w = ((b[:, 0] - a[:, 0]) * (xy[..., 1] - a[:, 1]) - (xy[..., 0] - a[:, 0]) * (b[:, 1] - a[:, 1])) / det
    inside = (u >= -1e-12) & (w >= -1e-12) & (u + w <= 1.0 + 1e-12)
    z = a[:, 2] + u * (b[:, 2] - a[:, 2]) + w * (c[:, 2] - a[:, 2])
    return np.where(inside.any(axis=-1), np.nanmax(np.where(inside, z, -np.inf), axis=-1), np.nan)


def mixed_pile_depths(seed: int, rate: float, count: int = 40, duration: float = 4.0):
    """``scenes.mixed_pile(count, seed)`` run at ``rate`` Hz: how far below the bowl's surface any body's centre of
    mass went at any step [m] (negative: none did), and the share of the bodies over the bowl at the end."""
    world = scenes.mixed_pile(count, seed=seed)
    bowl = scenes.bowl_mesh()  # the one mixed_pile puts into the world
    dynamic = [b.index for b in world.bodies if not b.is_static]
    centres = world.simulate(duration, 1.0 / rate).center_of_mass[:, dynamic]
    below = mesh_height(bowl, centres) - centres[..., 2]  # NaN where a centre is off the bowl (over its rim)
    over_the_bowl = np.hypot(centres[-1, :, 0], centres[-1, :, 1]) < 1.4
    return float(np.nanmax(below)), float(over_the_bowl.mean())


# Nothing falls through the one-sided mesh: no centre of mass goes 1 cm below its surface (issue 44; measured at
# 60 Hz over seeds 1-10: at most 0.52 cm above it, i.e. none below). The centre, not the frame origin: a hull's
# origin lies where its points were drawn around, centimetres from its centre of mass. And the pile stays in the
# bowl (a ball may roll over the rim).
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_mixed_pile_stays_in_the_mesh_bowl(seed):
    below, kept = mixed_pile_depths(seed, 60.0)
    assert below < 0.01
    assert kept > 0.9


@pytest.mark.slow
@pytest.mark.parametrize(
    ("seed", "rate"),
    [*((seed, rate) for seed in range(4, 14) for rate in (60.0, 240.0)), *((seed, 60.0) for seed in range(14, 21))],
)
def test_mixed_piles_of_40_to_60_bodies_stay_in_the_mesh_bowl_at_60_and_240_hz(seed, rate):
    """Seeds 1-20 at 60 Hz (1-3 above), 4-13 at 240 Hz."""
    below, kept = mixed_pile_depths(seed, rate, count=40 + 2 * ((seed - 4) % 10))
    assert below < 0.01
    assert kept > 0.9


@functools.cache
def poured_pile_depths(seed: int, rate: float) -> tuple[float, float, float]:
    """``scenes.mixed_pile(50, seed)`` stepped at ``rate`` Hz for 4 s, as ``mixed_drop_depths``."""
    return overlap_depths(scenes.mixed_pile(50, seed), rate, 4.0)


# 50 shapes poured into the bowl: no contact goes deeper than issue 44's targets, 5 cm at 60 Hz and 2.5 cm at
# 240 Hz, into the bowl or between bodies. Measured over seeds 1-20: 0.5-3.4 cm into the bowl and 1.4-4.5 cm between
# bodies at 60 Hz, 0.3-1.3 and 0.4-1.7 cm at 240 Hz. (The overlaps mixed_pile builds with are left out:
# overlap_depths.)
POUR_BOUNDS = {60.0: 0.05, 240.0: 0.025}
POUR_MISSES: dict[tuple[int, float], str] = {
    (18, 240.0): "for one step (460) the manifold of cylinders 23 and 38, moving at 0.3 m/s, reports -12 cm: a "
    "cylinder-cylinder narrow-phase miss that issue 50's substep inertia brought this seed to (issue 50, noticed)",
}


def _pile_case(seed, rate, misses):
    """A seed and rate of a pile test: seeds 1-3 at 60 Hz in ``make test``, the rest slow; a measured miss of issue
    44's target a strict xfail, so that a fix shows."""
    marks = [] if rate == 60.0 and seed <= 3 else [pytest.mark.slow]
    if (seed, rate) in misses:
        marks.append(pytest.mark.xfail(strict=True, reason=f"issue 44, part 3: {misses[seed, rate]} (docs/contact.md)"))
    return pytest.param(seed, rate, marks=marks)


@pytest.mark.parametrize(
    ("seed", "rate"), [_pile_case(seed, rate, POUR_MISSES) for rate in (60.0, 240.0) for seed in range(1, 21)]
)
def test_shapes_poured_into_the_bowl_overlap_at_most_5_cm_at_60_hz_and_2_5_cm_at_240_hz(seed, rate):
    into_bowl, between_bodies, _ = poured_pile_depths(seed, rate)
    assert into_bowl < POUR_BOUNDS[rate]
    assert between_bodies < POUR_BOUNDS[rate]


def test_a_row_of_dominoes_topples_to_the_last():
    world = scenes.dominoes(20)
    world.simulate(3.0, DT)
    up = quat_to_matrix(world.body("last").orientation)[:, 2]
    assert abs(up[2]) < 0.2  # the last one lies on its face


def test_the_friction_ramp_holds_the_boxes_with_mu_above_tan_theta():
    world = scenes.friction_ramp(30.0, frictions=(0.2, 0.4, 0.7, 0.9))
    starts = {b.name: b.position for b in world.bodies if not b.is_static}
    world.simulate(1.0, DT)
    moved = {name: np.linalg.norm(world.body(name).position - p) for name, p in starts.items()}
    assert moved["mu=0.2"] > 0.5 and moved["mu=0.4"] > 0.2  # tan 30° = 0.577
    assert moved["mu=0.7"] < 1e-3 and moved["mu=0.9"] < 1e-3


def test_bullets_stop_at_their_walls():
    world = scenes.bullets(100.0)
    world.simulate(0.5, DT)
    for name, wall in (("ball", "wall_ball"), ("box", "wall_box")):
        assert world.body(name).position[0] < world.body(wall).position[0] - 0.01


def test_a_two_level_card_house_stands_and_sleeps():
    world = scenes.card_house(2)
    start = world.state.body_pos.copy()
    world.simulate(3.0, DT)
    assert np.abs(world.state.body_pos - start).max() < 2e-3  # measured 0.8 mm (settling onto the ground)
    assert all(body.sleeping for body in world.bodies if not body.is_static)


def test_the_newtons_cradle_scene_passes_the_momentum_to_the_last_ball():
    world = scenes.newtons_cradle(5, speed=2.0)
    world.simulate(1.0, DT)
    assert world.body("striker").velocity[0] == pytest.approx(0.0, abs=1e-9)
    assert world.body("last").velocity[0] == pytest.approx(2.0, rel=1e-9)


@functools.cache
def mixed_drop_depths(seed: int, rate: float) -> tuple[float, float, float]:
    """``scenes.mixed_drop(60, seed)`` stepped at ``rate`` Hz for 3 s: the deepest overlap into the ground and between
    bodies [m], and the lowest height a centre of mass reached [m] (``overlap_depths``)."""
    return overlap_depths(scenes.mixed_drop(60, seed), rate, 3.0)


# 60 shapes dropped from 5-6.2 m onto the ground, landing on each other at 10-11 m/s: none passes through the ground
# or sinks its centre into it, and no contact goes deeper than issue 44's targets, 5 cm at 60 Hz and 2.5 cm at
# 240 Hz. Measured over seeds 1-20: into the ground 1.1-3.8 cm and between bodies 1.2-3.5 cm at 60 Hz (contacts found
# once a step: 4.2-8.4 and 5.9-10.8 cm), 0.2-0.8 and 0.4-1.7 cm at 240 Hz.
DROP_BOUNDS = {60.0: (0.05, 0.05), 240.0: (0.025, 0.025)}  # (into the ground, between bodies) [m]
DROP_MISSES: dict[tuple[int, float], str] = {}


@pytest.mark.parametrize(
    ("seed", "rate"), [_pile_case(seed, rate, DROP_MISSES) for rate in (60.0, 240.0) for seed in range(1, 21)]
)
def test_shapes_dropped_on_the_ground_at_10_m_per_s_stay_out_of_it(seed, rate):
    into_ground, between_bodies, lowest = mixed_drop_depths(seed, rate)
    assert lowest > -0.01  # as for the bowl: no centre 1 cm under the surface (measured: 2 cm above it at least)
    assert into_ground < DROP_BOUNDS[rate][0]
    assert between_bodies < DROP_BOUNDS[rate][1]


# One body dropped at 11 m/s onto the ground, at ten orientations: it turns by tens of degrees within the step of
# its first touch, and the corners and rims that come down mid-step are found then (issue 44). Measured over 1 s:
# at most 0.12 cm deep (box), 0.13 cm (cylinder), 1.7 cm (hull) at 60 Hz; 0.01, 0.39 and 0.92 cm at 240 Hz; 0.01,
# 0.11 and 0.04 cm at 1 kHz. At 60 Hz with contacts found once a step: 2.9, 4.5 and 2.1 cm; found again within the
# step but with a plane manifold's second point the farthest, not the next to come down: 1.4, 1.8 and 1.7 cm.
LANDING_BOUNDS = {"box": 0.005, "cylinder": 0.005, "hull": 0.02}  # [m]
LANDING_SHAPES = {
    "box": lambda rng: Box((0.14, 0.1, 0.08)),
    "cylinder": lambda rng: Cylinder(0.06, 0.1),
    "hull": lambda rng: ConvexHull(rng.normal(size=(12, 3)) * 0.08),
}


@pytest.mark.parametrize("shape", list(LANDING_SHAPES))
@pytest.mark.parametrize("rate", [60.0, 240.0, pytest.param(1000.0, marks=pytest.mark.slow)])
def test_a_body_landing_at_11_m_per_s_stays_out_of_the_ground(shape, rate):
    deepest = 0.0
    for seed in range(10):
        rng = np.random.default_rng(seed)
        world = World()
        world.add_static(Plane())
        world.add_body(LANDING_SHAPES[shape](rng), density=800.0, position=(0, 0, 0.3 + rng.uniform(0, 0.2)),
                       orientation=quat_from_rotvec(rng.normal(size=3)), velocity=(0, 0, -11.0))  # fmt: skip
        for _ in range(round(rate)):
            world.step(1.0 / rate)
            deepest = max(deepest, -world.contacts().separation.min(initial=0.0))
    assert deepest < LANDING_BOUNDS[shape]


def slide_over_the_rim(shape, azimuth: float, speed: float, rate: float) -> tuple[float, int, int, float]:
    """``shape`` let go 0.15 m over the bowl's floor (0.3 m out, at ``azimuth``) moving out at ``speed`` [m/s]: it
    lands, slides up the wall, over the open rim (1.5 m out) and falls off outside. Returns, for the steps it
    touched the bowl with its centre past 1.35 m out (by the rim): the deepest overlap [m], how many there were and
    how many of them turned the contact normal by more than 120° from the last step's; and how far out it ends [m]."""
    world = World()
    world.add_static(scenes.bowl_mesh(), name="bowl")  # z = 0.6 (r / 1.5)², open at r = 1.5
    out = np.array([np.cos(azimuth), np.sin(azimuth), 0.0])
    position = 0.3 * out + (0.0, 0.0, 0.6 * (0.3 / 1.5) ** 2 + 0.15)
    body = world.add_body(shape, density=800.0, position=position, velocity=speed * out)
    deepest, touching, turns, last = 0.0, 0, 0, None
    for _ in range(round(1.5 * rate)):
        world.step(1.0 / rate)
        contacts = world.contacts()
        touched = contacts.separation <= 0.0
        if not touched.any() or np.hypot(*body.position[:2]) < 1.35:
            last = None
            continue
        from_bowl = (contacts.normal * np.where(contacts.body_a == body.index, -1.0, 1.0)[:, None])[touched]
        deepest = max(deepest, -contacts.separation.min())
        touching += 1
        if last is not None and (last @ from_bowl.T).min() < -0.5:
            turns += 1
        last = from_bowl
    return deepest, touching, turns, float(np.hypot(*body.position[:2]))


# The bowl's open rim (issue 44): sliding over it, a body keeps a contact normal that points out of the bowl's front,
# step after step, and stays out of the wall; in piles before issue 44 a body at the rim had its normal flip and its
# separation jump between +3 and -9 cm. Measured at 8 m/s: no turn, at most 0.73 cm deep by the rim (a capsule
# leaves out: it tumbles off the floor and flies over the rim). The sphere at 60 Hz touches by the rim in two steps
# (three, 2.7 mm deep, before fast pairs found their contacts again within the step; now 0.2-0.4 mm).
@pytest.mark.parametrize("rate", [60.0, 240.0])
@pytest.mark.parametrize(
    "shape",
    [
        Box((0.14, 0.1, 0.08)),
        Sphere(0.08),
        Cylinder(0.06, 0.1),
        ConvexHull(np.random.default_rng(1).normal(size=(12, 3)) * 0.08),
    ],
    ids=["box", "sphere", "cylinder", "hull"],
)
def test_a_body_sliding_over_the_bowls_open_rim_keeps_its_contact_normal(shape, rate):
    for azimuth in (0.0, 0.13):  # along a radial edge of the mesh, and across the middle of its triangles
        deepest, touching, turns, end = slide_over_the_rim(shape, azimuth, 8.0, rate)
        assert touching >= 2 and end > 1.6  # it slid over the rim (two steps to compare normals), and off
        assert turns == 0
        assert deepest < 0.01
