"""Vehicle channels in recordings (issue 19, part 2): rotor speeds, commands and the reference recorded with the
frames, kept by both file formats, sliced with the frames, and drawn by ``plots.flight``."""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble import plots, recording
from tumble.control import Circle, SE3Controller
from tumble.vehicles import Quadrotor


def flying_world() -> tuple[tumble.World, Quadrotor, Circle]:
    world = tumble.World()
    quad = Quadrotor(world, position=(1.0, 0.0, 1.0), name="cf")
    quad.rotor_speeds = [quad.hover_rotor_speed] * 4
    circle = Circle((0.0, 0.0, 1.0), 1.0, 0.2)
    quad.fly(SE3Controller(quad), circle, rate=100)
    Quadrotor(world, position=(3.0, 0.0, 1.0))  # unnamed, not flying: its commands hold
    return world, quad, circle


@pytest.mark.parametrize("suffix", [".h5", ".npz"])
def test_record_keeps_the_vehicles_channels_frame_by_frame(tmp_path, suffix):
    world, quad, circle = flying_world()
    controllers = world.controllers
    trajectory = recording.record(world, 0.3, 0.01, tmp_path / f"run{suffix}", every=3, chunk_frames=4)
    assert world.controllers == controllers  # the log is gone
    channels = trajectory.channels
    assert sorted(channels) == sorted(f"vehicle/{name}/{what}" for name in ("cf", "#1")
                                      for what in ("commands", "reference", "rotor_speeds"))  # fmt: skip
    assert all(value.shape[0] == len(trajectory) == 11 for value in channels.values())
    reference = np.array([circle(t)["position"] for t in trajectory.time])
    np.testing.assert_allclose(channels["vehicle/cf/reference"], reference, atol=1e-12)
    np.testing.assert_allclose(channels["vehicle/cf/rotor_speeds"][-1], quad.rotor_speeds, rtol=1e-12)
    np.testing.assert_allclose(channels["vehicle/cf/commands"][-1], quad.commanded_rotor_speeds, rtol=1e-12)
    assert np.isnan(channels["vehicle/#1/reference"]).all()
    assert channels["vehicle/cf/rotor_speeds"][0] == pytest.approx([quad.hover_rotor_speed] * 4)
    # The frames are those of the same flight without the log.
    again, _, _ = flying_world()
    plain = again.simulate(0.3, 0.01, record_every=3)
    np.testing.assert_array_equal(plain.position, trajectory.position)


def test_channels_survive_save_load_and_slicing(tmp_path):
    world, _, _ = flying_world()
    trajectory = recording.record(world, 0.2, 0.01, tmp_path / "run.h5")
    for name in ("copy.npz", "copy.h5"):
        trajectory.save(tmp_path / name)
        loaded = tumble.Trajectory.load(tmp_path / name)
        assert sorted(loaded.channels) == sorted(trajectory.channels)
        for key, value in trajectory.channels.items():
            np.testing.assert_array_equal(loaded.channels[key], value)
    part = trajectory[5:9]
    np.testing.assert_array_equal(part.channels["vehicle/cf/commands"], trajectory.channels["vehicle/cf/commands"][5:9])


def test_the_flight_plot_draws_position_error_attitude_and_rotors(tmp_path):
    pytest.importorskip("matplotlib")
    world, _, _ = flying_world()
    trajectory = recording.record(world, 0.2, 0.01, tmp_path / "run.h5")
    figure = plots.flight(trajectory, path=tmp_path / "flight.png")
    assert len(figure.axes) == 4 and (tmp_path / "flight.png").stat().st_size > 20_000
    assert [line.get_label() for line in figure.axes[3].lines][::2] == [f"rotor {k}" for k in range(1, 5)]
    plots.flight(trajectory, vehicle="#1")
    with pytest.raises(KeyError, match=r"no vehicle named 'nope' in this trajectory; vehicles: \['cf', '#1'\]"):
        plots.flight(trajectory, vehicle="nope")
    with pytest.raises(ValueError, match="this trajectory holds no vehicle channels"):
        plots.flight(tumble.World().simulate(0.01, 0.01))
