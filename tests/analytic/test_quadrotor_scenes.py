"""The shipped quadrotor scenes (issue 19, part 2): each flies as its description says, from its file, and runs
from the command line with its plots and replay."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from tumble import scene_file
from tumble.vehicles import CRAZYFLIE, quadrotors

FEET = 0.4 * CRAZYFLIE["arm_length"]  # the feet's depth below the centre of mass
QUADROTOR_SCENES = sorted(p.stem for p in scene_file.shipped() if p.stem.startswith("quadrotor_"))


def fly(name: str, every: int = 1):
    """The scene's world after its duration, its recording, and for each vehicle its position error over time."""
    loaded = scene_file.load(scene_file.shipped_scene(name))
    world = loaded.world
    recording = world.simulate(loaded.run.duration, loaded.run.dt, record_every=every)
    errors = []
    for quad in quadrotors(world):
        reference = np.array([quad._flight.trajectory(t)["position"] for t in recording.time])
        errors.append(np.linalg.norm(recording.position[:, quad.body.index] - reference, axis=1))
    return world, recording, errors


def test_the_six_quadrotor_scenes_are_shipped():
    assert QUADROTOR_SCENES == ["quadrotor_altitude_step", "quadrotor_figure_eight_wind", "quadrotor_landing",
                                "quadrotor_passing", "quadrotor_tilt_recovery", "quadrotor_waypoints"]  # fmt: skip


def test_tilt_recovery_rights_itself_above_the_ground():
    world, recording, (error,) = fly("quadrotor_tilt_recovery")
    i = quadrotors(world)[0].body.index
    assert recording.position[:, i, 2].min() > 0.8 and error[-1] < 1e-3


def test_altitude_step_settles_in_the_documented_time():
    world, recording, (error,) = fly("quadrotor_altitude_step")
    outside = np.flatnonzero(error > 0.02)
    assert recording.time[outside[-1] + 1] <= 2.1 + 1e-9
    assert recording.position[:, quadrotors(world)[0].body.index, 2].max() < 2.0 + 1e-4


def test_waypoint_square_is_flown_within_a_few_centimetres():
    _, _, (error,) = fly("quadrotor_waypoints")
    assert np.sqrt(np.mean(error**2)) < 0.025 and error.max() < 0.05 and error[-1] < 0.005


def test_figure_eight_in_dryden_wind_stays_close():
    """Gusts of 0.3 m/s about a 2 m/s wind: 5.7 cm RMS after 4 s (5.0 in still air), the mean push taken out by
    the integral term."""
    _, recording, (error,) = fly("quadrotor_figure_eight_wind", every=5)
    late = recording.time >= 4.0
    assert np.sqrt(np.mean(error[late] ** 2)) < 0.08 and error[late].max() < 0.12


def test_landing_comes_to_rest_on_its_feet_without_bouncing():
    world, recording, _ = fly("quadrotor_landing")
    quad = quadrotors(world)[0]
    z = recording.position[:, quad.body.index, 2]
    touch = np.argmax(z < FEET + 1e-4)
    assert 0 < touch and recording.time[touch] < 4.0  # touched down as the path reached the ground
    assert z[touch:].max() < FEET + 1e-3  # no bounce: never a millimetre off again
    assert abs(z[-1] - FEET) < 5e-4 and np.linalg.norm(quad.body.velocity) < 1e-3
    np.testing.assert_allclose(quad.body.rotation[:, 2], (0, 0, 1), atol=1e-3)  # level on its four feet
    assert len(world.contacts().body_a) >= 4


def test_two_vehicles_pass_without_touching():
    world, recording, errors = fly("quadrotor_passing")
    a, b = (quad.body.index for quad in quadrotors(world))
    gap = np.linalg.norm(recording.position[:, a] - recording.position[:, b], axis=1)
    assert gap.min() > 0.25  # their collision shapes reach 4.7 cm from their centres
    assert max(error.max() for error in errors) < 0.1
    speeds = np.linalg.norm(recording.velocity[:, a], axis=1)
    assert speeds.max() > 2.0  # at full speed as they pass


# 10 s each: make test runs the two vehicles with their sensors through the command; make test-slow every scene
# (the tests above fly each of them).
@pytest.mark.parametrize("name", [n if n == "quadrotor_passing" else pytest.param(n, marks=pytest.mark.slow)
                                  for n in QUADROTOR_SCENES])  # fmt: skip
def test_every_quadrotor_scene_runs_from_the_command_line_with_plots_and_replay(name, tmp_path):
    out = tmp_path / name
    command = [sys.executable, "-m", "tumble", "run", str(scene_file.shipped_scene(name)), "--quiet", "--duration",
               "1.0", "--out", f"{out}.h5", "--plot", f"{out}.png", "--html", f"{out}.html"]  # fmt: skip
    result = subprocess.run(command, capture_output=True, text=True, timeout=280)
    assert result.returncode == 0, result.stderr
    for suffix, size in ((".h5", 10_000), (".png", 10_000), ("_flight.png", 30_000), (".html", 50_000)):
        assert (tmp_path / f"{name}{suffix}").stat().st_size > size
    plot = [sys.executable, "-m", "tumble", "plot", f"{out}.h5", "--what", "flight,paths", "-o", str(tmp_path)]
    result = subprocess.run(plot, capture_output=True, text=True, timeout=280)
    assert result.returncode == 0, result.stderr
    assert (tmp_path / f"{name}_flight.png").stat().st_size > 30_000
