"""Vehicles and wind in scene files (issue 19, part 2): built as the API builds them, validated with the place
named, and written back by ``World.to_scene`` so that the loaded world flies the same."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from tumble import scene_file, wind
from tumble.control import CascadedPID, MinimumSnap, SE3Controller
from tumble.scene_file import SceneError
from tumble.vehicles import quadrotors

SCENE = """
[world]
dt = 0.01
[[static]]
shape = { type = "plane" }
[[vehicles]]
type = "quadrotor"
name = "cf"
position = [1.0, 0.0, 1.0]
rotor_speeds = "hover"
controller = { type = "se3", rate = 100, ki_pos = 1.0 }
trajectory = { type = "circle", center = [0, 0, 1], radius = 1.0, frequency = 0.2 }
[[vehicles]]
type = "quadrotor"
name = "hb"
params = { base = "hummingbird", mass = 0.6, inertia = [0.004, 0.004, 0.007] }
layout = "+"
position = [0.0, 3.0, 1.0]
rotor_speeds = "hover"
controller = { type = "cascaded_pid", ki_vel = 1.0 }
trajectory = { type = "minimum_snap", waypoints = [[0, 3, 1], [1, 3, 1.5], [2, 3, 1]], average_speed = 0.5 }
[[vehicles]]
type = "quadrotor"
name = "open"
position = [3.0, 0.0, 1.0]
rotor_speeds = [1800, 1800, 1800, 1800]
commands = [1900, 1700, 1900, 1700]
[wind]
type = "dryden"
mean = [2.0, 0.0, 0.0]
sigma = 0.5
length_scale = 20.0
seed = 3
"""


def test_vehicles_are_built_as_the_api_builds_them():
    world = scene_file.from_dict(tomllib.loads(SCENE)).world
    cf, hb, free = quadrotors(world)
    assert cf.body.name == "cf" and cf.params["mass"] == 0.03 and cf.layout == "x"
    assert isinstance(cf._flight.controller, SE3Controller) and cf._flight.rate == 100.0
    np.testing.assert_array_equal(cf._flight.controller.ki_pos, [1.0, 1.0, 1.0])
    np.testing.assert_allclose(cf.rotor_speeds, [cf.hover_rotor_speed] * 4)
    assert hb.params["mass"] == 0.6 and hb.params["k_thrust"] == 5.57e-6 and hb.layout == "+"
    np.testing.assert_array_equal(hb.params["inertia"], np.diag([0.004, 0.004, 0.007]))
    assert isinstance(hb._flight.controller, CascadedPID) and isinstance(hb._flight.trajectory, MinimumSnap)
    np.testing.assert_array_equal(free.commanded_rotor_speeds, [1900, 1700, 1900, 1700])
    assert free._flight is None and len(world.controllers) == 2
    assert isinstance(world.wind, wind.Dryden) and world.wind.seed == 3


def test_to_scene_writes_vehicles_and_wind_back_and_the_copy_flies_the_same():
    world = scene_file.from_dict(tomllib.loads(SCENE)).world
    again = scene_file.from_dict(tomllib.loads(scene_file.dumps(world.to_scene(dt=0.01)))).world
    assert [q.body.name for q in quadrotors(again)] == ["cf", "hb", "open"]
    for w in (world, again):
        w.simulate(0.3, 0.01)
    np.testing.assert_allclose(again.state.body_pos, world.state.body_pos, atol=1e-12)
    np.testing.assert_allclose(again.state.body_quat, world.state.body_quat, atol=1e-12)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('[[vehicles]]\ntype = "quadrotor"\ncontroller = { type = "se3" }\n',
         r"s\.toml: vehicles\[0\]: .*give a controller and a trajectory together, or neither"),
        ('[[vehicles]]\ntype = "quadrotor"\nparams = { mass = -1 }\n',
         r"s\.toml: vehicles\[0\]\.params\.mass: Input should be greater than 0"),
        ('[[vehicles]]\ntype = "quadrotor"\nparams = "blimp"\n',
         r"s\.toml: vehicles\[0\]\.params: Input should be 'crazyflie' or 'hummingbird' \(got 'blimp'\)"),
        ('[[vehicles]]\ntype = "quadrotor"\ncontroller = { type = "se3", kp_pos = -1 }\n'
         'trajectory = { type = "hover", position = [0, 0, 1] }\n',
         r"s\.toml: vehicles\[0\]: controller: kp_pos must be >= 0"),
        ('[[vehicles]]\ntype = "quadrotor"\ncontroller = { type = "se3" }\n'
         'trajectory = { type = "minimum_snap", waypoints = [[0, 0, 0], [1, 0, 0]], times = [0, 1, 2] }\n',
         r"s\.toml: vehicles\[0\]: trajectory: times must give one time per waypoint"),
        ('[[vehicles]]\ntype = "quadrotor"\nrotor_speeds = [1, 2, 3, 9000]\n',
         r"s\.toml: vehicles\[0\]: rotor_speeds must be within \[speed_min, speed_max\]"),
        ('[wind]\ntype = "dryden"\nmean = [0, 0, 0]\nsigma = 1\nlength_scale = 1\n',
         r"s\.toml: wind: mean must be a non-zero wind"),
        ('[[vehicles]]\ntype = "quadrotor"\ncolour = "red"\n', r"s\.toml: vehicles\[0\]\.colour: unknown key"),
        ('[[vehicles]]\ntype = "blimp"\n', r"s\.toml: vehicles\[0\]\.type: Input should be 'quadrotor'"),
        ('[[vehicles]]\ntype = "quadrotor"\ncommands = [1, 2, 3, 4]\ncontroller = { type = "se3" }\n'
         'trajectory = { type = "hover", position = [0, 0, 1] }\n',
         r"commands are for a vehicle without a controller"),
    ],
)  # fmt: skip
def test_bad_vehicles_and_wind_name_the_place(text, message):
    with pytest.raises(SceneError, match=message):
        scene_file.from_dict(tomllib.loads(text), label="s.toml")
