"""The shared scenes of ``tumble.scenes`` against the outcomes issue 3 asks for: stacks stand and sleep, piles
settle without sinking, rows topple, ramps sort by friction, bullets stop at their walls."""

from __future__ import annotations

import numpy as np
import pytest

from tumble import scenes
from tumble.rotation import quat_to_matrix

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


@pytest.mark.slow
def test_the_1000_box_pile_settles_without_sinking_into_the_ground():
    world = scenes.box_pile(1000)
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
@pytest.mark.parametrize("rate", [60.0, 240.0])
@pytest.mark.parametrize("seed", range(4, 14))
def test_mixed_piles_of_40_to_60_bodies_stay_in_the_mesh_bowl_at_60_and_240_hz(seed, rate):
    below, kept = mixed_pile_depths(seed, rate, count=40 + 2 * (seed - 4))
    assert below < 0.01
    assert kept > 0.9


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
