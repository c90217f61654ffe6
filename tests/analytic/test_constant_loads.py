"""Constant loads act in every step, in both step paths, and survive checkpoints and scene files."""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble import scene_file


@pytest.mark.parametrize("touching", [False, True], ids=["free motion", "contact solver"])
def test_a_constant_force_and_torque_give_uniform_accelerations(touching):
    world = tumble.World()
    if touching:  # a plane far below: the world steps with the contact solver
        world.add_static(tumble.Plane(offset=-100.0))
    ball = world.add_body(tumble.Sphere(0.1), mass=2.0, position=(0.0, 0.0, 10.0))
    ball.constant_force = (1.0, 0.0, 2.0 * 9.81 + 4.0)  # net (1, 0, 4) N: a = (0.5, 0, 2) m/s²
    ball.constant_torque = (0.0, 0.0, 0.5)
    world.simulate(1.0, 1 / 60)
    np.testing.assert_allclose(ball.velocity, (0.5, 0.0, 2.0), rtol=1e-9)
    np.testing.assert_allclose(ball.angular_velocity, (0.0, 0.0, 0.5 / (0.4 * 2.0 * 0.01)), rtol=1e-9)
    np.testing.assert_allclose(ball.constant_force, (1.0, 0.0, 2.0 * 9.81 + 4.0))
    with pytest.raises(ValueError, match="constant_force must be finite"):
        ball.constant_force = (np.nan, 0.0, 0.0)
    ground = world.add_static(tumble.Plane(offset=-200.0))
    with pytest.raises(ValueError, match="is static and cannot move"):
        ground.constant_torque = (1.0, 0.0, 0.0)


def test_constant_loads_resume_from_a_checkpoint_and_round_trip_through_a_scene(tmp_path):
    world = tumble.World()
    world.add_static(tumble.Plane())
    box = world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=1.0, position=(0.0, 0.0, 0.1), name="box")
    box.constant_force = (3.0, 0.0, 0.0)  # pushes the box along the floor against friction 0.5 (4.9 N): it stays
    box.constant_torque = (0.0, 0.0, 0.2)
    world.simulate(0.5, 1 / 60)
    world.save(tmp_path / "c.npz")
    resumed = tumble.World.load(tmp_path / "c.npz")
    world.simulate(0.5, 1 / 60)
    resumed.simulate(0.5, 1 / 60)
    assert resumed.state.digest() == world.state.digest()
    again = scene_file.from_dict(world.to_scene()).world
    np.testing.assert_allclose(again.body("box").constant_force, (3.0, 0.0, 0.0))
    np.testing.assert_allclose(again.body("box").constant_torque, (0.0, 0.0, 0.2))
