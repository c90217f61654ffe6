"""Plots of a trajectory: energy, momentum, angular velocity, paths (issue 5.4)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import tumble
from tumble import plots

pytest.importorskip("matplotlib")

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def trajectory() -> tumble.Trajectory:
    """Two tumbling bodies in free flight (no contacts) and a static ground."""
    world = tumble.World()
    world.add_static(tumble.Plane(), name="ground")
    world.add_body(tumble.Box((0.1, 0.2, 0.3)), density=500.0, position=(0, 0, 5), velocity=(1, 0, 3),
                   angular_velocity=(0.1, 4.0, 0.1), collision_mask=0, name="box")  # fmt: skip
    world.add_body(tumble.Capsule(0.05, 0.2), density=500.0, position=(1, 0, 5), velocity=(0, 1, 2),
                   angular_velocity=(2.0, 0.0, 1.0), collision_mask=0, name="capsule")  # fmt: skip
    return world.simulate(0.5, 0.005, record_every=2)


def _is_png(path) -> bool:
    return path.read_bytes()[:8] == PNG_SIGNATURE and path.stat().st_size > 1000


def test_energy_plots_four_curves_and_writes_a_png(trajectory, tmp_path):
    path = tmp_path / "out" / "energy.png"
    figure = plots.energy(trajectory, path=path)
    assert _is_png(path)
    (ax,) = figure.axes
    assert [line.get_label() for line in ax.lines] == ["translational kinetic", "rotational kinetic", "potential",
                                                       "total"]  # fmt: skip
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), trajectory.translational_energy)
    np.testing.assert_array_equal(ax.lines[3].get_ydata(), trajectory.total_energy)
    assert ax.get_xlabel() == "time [s]" and ax.get_ylabel() == "energy [J]"


def test_momentum_plots_three_components_of_p_and_l(trajectory, tmp_path):
    path = tmp_path / "momentum.png"
    figure = plots.momentum(trajectory, path=path, point=(1.0, 0.0, 0.0))
    assert _is_png(path)
    assert len(figure.axes) == 2 and [len(ax.lines) for ax in figure.axes] == [3, 3]
    p, angular = trajectory.linear_momentum(), trajectory.angular_momentum((1.0, 0.0, 0.0))
    np.testing.assert_array_equal(figure.axes[0].lines[2].get_ydata(), p[:, 2])
    np.testing.assert_array_equal(figure.axes[1].lines[1].get_ydata(), angular[:, 1])
    assert [line.get_label() for line in figure.axes[1].lines] == ["Lx", "Ly", "Lz"]


def test_angular_velocity_in_body_and_world_frames(trajectory, tmp_path):
    figure = plots.angular_velocity(trajectory, bodies=["box", "capsule"], frame="body", path=tmp_path / "w.png")
    assert _is_png(tmp_path / "w.png")
    assert len(figure.axes) == 3 and [len(ax.lines) for ax in figure.axes] == [2, 2, 2]
    body = trajectory.angular_velocity_body()
    np.testing.assert_array_equal(figure.axes[1].lines[0].get_ydata(), body[:, 1, 1])  # box, ω_y
    world = plots.angular_velocity(trajectory, bodies="capsule", frame="world")
    assert [len(ax.lines) for ax in world.axes] == [1, 1, 1]
    np.testing.assert_array_equal(world.axes[2].lines[0].get_ydata(), trajectory.angular_velocity[:, 2, 2])
    # Default: the dynamic bodies only (not the ground).
    default = plots.angular_velocity(trajectory)
    assert [line.get_label() for line in default.axes[0].lines] == ["box", "capsule"]
    with pytest.raises(ValueError, match="frame must be 'body' or 'world'"):
        plots.angular_velocity(trajectory, frame="inertial")


def test_paths_in_plane_views_and_in_3d(trajectory, tmp_path):
    figure = plots.paths(trajectory, path=tmp_path / "paths.png")
    assert _is_png(tmp_path / "paths.png")
    assert [ax.get_title() for ax in figure.axes] == ["Paths, xy view", "Paths, xz view"]
    assert [len(ax.lines) for ax in figure.axes] == [2, 2]
    np.testing.assert_array_equal(figure.axes[1].lines[0].get_xdata(), trajectory.position[:, 1, 0])
    np.testing.assert_array_equal(figure.axes[1].lines[0].get_ydata(), trajectory.position[:, 1, 2])
    solid = plots.paths(trajectory, bodies=[2], views="3d", path=tmp_path / "paths3d.png")
    assert _is_png(tmp_path / "paths3d.png")
    assert solid.axes[0].name == "3d" and len(solid.axes[0].lines) == 1
    with pytest.raises(ValueError, match="views must be one or more of"):
        plots.paths(trajectory, views="xw")


def test_plots_draw_into_given_axes(trajectory):
    from matplotlib.figure import Figure

    figure = Figure()
    axes = figure.subplots(2, 3)
    assert plots.energy(trajectory, ax=axes[0, 0]) is figure
    assert plots.momentum(trajectory, axes=axes[0, 1:]) is figure
    assert plots.angular_velocity(trajectory, axes=[axes[1, 0], axes[1, 1], axes[1, 2]]) is figure
    assert [len(ax.lines) for ax in axes.ravel()] == [4, 3, 3, 2, 2, 2]
    with pytest.raises(ValueError, match="axes must hold 2 axes, got 1"):
        plots.momentum(trajectory, axes=[axes[0, 0]])


def test_plots_refuse_bad_input(trajectory):
    with pytest.raises(TypeError, match="tumble.Trajectory"):
        plots.energy(np.zeros(3))
    with pytest.raises(ValueError, match="no frames"):
        plots.energy(trajectory[0:0])
    with pytest.raises(KeyError, match="no body named 'nope'"):
        plots.paths(trajectory, bodies="nope")


def test_neither_import_tumble_nor_plotting_loads_pyplot():
    """``import tumble`` loads no matplotlib, and the plots never go through pyplot (no backend switch)."""
    script = textwrap.dedent("""
        import sys
        import tumble
        assert "matplotlib" not in sys.modules, "import tumble loaded matplotlib"
        import tumble.plots
        assert "matplotlib" not in sys.modules, "import tumble.plots loaded matplotlib"
        world = tumble.World(gravity=(0, 0, 0))
        world.add_body(tumble.Sphere(0.1), density=10.0, velocity=(1, 0, 0))
        traj = world.simulate(0.1, 0.01)
        for plot in (tumble.plots.energy, tumble.plots.momentum, tumble.plots.angular_velocity, tumble.plots.paths):
            plot(traj)
        assert "matplotlib.pyplot" not in sys.modules, "a plot imported pyplot"
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
