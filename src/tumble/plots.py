"""Plots of a :class:`~tumble.Trajectory`: energy, momentum, angular velocity, paths, and the flight of its
vehicles (matplotlib).

Each function returns the matplotlib ``Figure`` and writes it to ``path`` when given (the format follows the
suffix: ``.png``, ``.svg``, ``.pdf``). Figures are built with ``matplotlib.figure.Figure`` and its Agg canvas,
not with ``pyplot``: nothing needs a display, no window opens, and the backend of an interactive session is
left alone. Pass ``ax``/``axes`` to draw into axes of your own figure instead. ``import tumble`` does not
import matplotlib; this module imports it when a function is called.

>>> import tumble, tumble.plots
>>> world = tumble.World()
>>> ball = world.add_body(tumble.Sphere(0.1), density=1000.0, velocity=(1.0, 0.0, 3.0), name="ball")
>>> fig = tumble.plots.energy(world.simulate(0.5, 0.01))
>>> [line.get_label() for line in fig.axes[0].lines]
['translational kinetic', 'rotational kinetic', 'potential', 'total']
"""

from __future__ import annotations

import os

import numpy as np

__all__ = ["energy", "momentum", "angular_velocity", "paths", "flight"]

# Bodies drawn when ``bodies=None``: the first dynamic ones, at most this many (more would be unreadable).
MAX_DEFAULT_BODIES = 8
_COMPONENTS = ("x", "y", "z")
_VIEWS = ("xy", "xz", "yz", "3d")


def _blank_figure(size):
    """A figure with its own Agg canvas: no pyplot, no display, the session's backend untouched."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def _new_figure(rows: int = 1, columns: int = 1, *, size=(8.0, 4.5)):
    """A new figure and its ``rows x columns`` axes (a list, row by row)."""
    figure = _blank_figure(size)
    return figure, [figure.add_subplot(rows, columns, k + 1) for k in range(rows * columns)]


def _finish(figure, path) -> None:
    if path is not None:
        path = os.fspath(path)
        directory = os.path.dirname(path)
        if directory:
            os.makedirs(directory, exist_ok=True)
        figure.savefig(path, dpi=110)


def _check_trajectory(trajectory) -> None:
    from .trajectory import Trajectory

    if not isinstance(trajectory, Trajectory):
        raise TypeError(f"trajectory must be a tumble.Trajectory, got {type(trajectory).__name__}")
    if len(trajectory) == 0:
        raise ValueError("trajectory has no frames to plot")


def _axes_list(axes, count: int, name: str):
    """The caller's axes (one, or a sequence of ``count``) or None."""
    if axes is None:
        return None
    items = list(np.ravel(np.asarray(axes, dtype=object)))
    if len(items) != count:
        raise ValueError(f"{name} must hold {count} axes, got {len(items)}")
    return items


def _bodies(trajectory, bodies) -> list[int]:
    if bodies is None:
        rows = trajectory.select_bodies(None, dynamic_only=True)[:MAX_DEFAULT_BODIES]
        if not rows:
            raise ValueError("the trajectory has no dynamic body to plot; pass bodies= to choose some")
        return rows
    rows = trajectory.select_bodies(bodies)
    if not rows:
        raise ValueError("bodies is empty: choose at least one body")
    return rows


def energy(trajectory, path=None, ax=None):
    """Translational and rotational kinetic energy, potential energy and their total against time.

    Args:
        trajectory: a :class:`~tumble.Trajectory`.
        path: write the figure here if given.
        ax: draw into these axes (else a new figure).

    Returns:
        The ``Figure``: four lines (``translational kinetic``, ``rotational kinetic``, ``potential``, ``total``).
    """
    _check_trajectory(trajectory)
    figure, (ax,) = _new_figure() if ax is None else (ax.figure, (ax,))
    t = trajectory.time
    ax.plot(t, trajectory.translational_energy, label="translational kinetic")
    ax.plot(t, trajectory.rotational_energy, label="rotational kinetic")
    ax.plot(t, trajectory.potential_energy, label="potential")
    ax.plot(t, trajectory.total_energy, label="total", color="black", linewidth=1.5)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("energy [J]")
    ax.set_title("Energy")
    ax.legend(loc="best")
    ax.grid(True, alpha=0.3)
    _finish(figure, path)
    return figure


def momentum(trajectory, path=None, axes=None, *, point=(0.0, 0.0, 0.0)):
    """Components of the total linear momentum and of the angular momentum about ``point`` against time.

    Args:
        trajectory: a :class:`~tumble.Trajectory`.
        path: write the figure here if given.
        axes: two axes to draw into (linear, angular), else a new figure.
        point: (3,) [m] the point the angular momentum is taken about.

    Returns:
        The ``Figure``: two axes with three lines each (x, y, z).
    """
    _check_trajectory(trajectory)
    given = _axes_list(axes, 2, "axes")
    figure, (ax_p, ax_l) = _new_figure(2, 1, size=(8.0, 6.0)) if given is None else (given[0].figure, given)
    t = trajectory.time
    for values, ax, symbol, unit in (
        (trajectory.linear_momentum(), ax_p, "p", "kg m/s"),
        (trajectory.angular_momentum(point), ax_l, "L", "kg m²/s"),
    ):
        for k, c in enumerate(_COMPONENTS):
            ax.plot(t, values[:, k], label=f"{symbol}{c}")
        ax.set_ylabel(f"{symbol} [{unit}]")
        ax.legend(loc="best")
        ax.grid(True, alpha=0.3)
    ax_p.set_title("Linear momentum")
    ax_l.set_title(f"Angular momentum about {tuple(float(v) for v in point)}")
    ax_l.set_xlabel("time [s]")
    _finish(figure, path)
    return figure


def angular_velocity(trajectory, bodies=None, frame: str = "body", path=None, axes=None):
    """The angular velocity of chosen bodies against time: one axes per component, one line per body.

    Args:
        trajectory: a :class:`~tumble.Trajectory`.
        bodies: names, indices or Body handles (default: the first 8 dynamic bodies).
        frame: ``"body"`` (components in each body's frame, as the Euler equations use them) or ``"world"``.
        path: write the figure here if given.
        axes: three axes to draw into (x, y, z), else a new figure.

    Returns:
        The ``Figure``: three axes (ωx, ωy, ωz) with one line per body.
    """
    _check_trajectory(trajectory)
    if frame not in ("body", "world"):
        raise ValueError(f"frame must be 'body' or 'world', got {frame!r}")
    rows = _bodies(trajectory, bodies)
    omega = trajectory.angular_velocity_body() if frame == "body" else trajectory.angular_velocity
    given = _axes_list(axes, 3, "axes")
    figure, axs = _new_figure(3, 1, size=(8.0, 7.0)) if given is None else (given[0].figure, given)
    for k, (ax, c) in enumerate(zip(axs, _COMPONENTS, strict=True)):
        for i in rows:
            ax.plot(trajectory.time, omega[:, i, k], label=trajectory.body_label(i))
        ax.set_ylabel(f"ω{c} [rad/s]")
        ax.grid(True, alpha=0.3)
    axs[0].set_title(f"Angular velocity, {frame} frame")
    axs[0].legend(loc="best")
    axs[-1].set_xlabel("time [s]")
    _finish(figure, path)
    return figure


def paths(trajectory, bodies=None, views=("xy", "xz"), path=None, axes=None):
    """The paths of chosen bodies' frame origins, in plane views or in 3-D.

    Args:
        trajectory: a :class:`~tumble.Trajectory`.
        bodies: names, indices or Body handles (default: the first 8 dynamic bodies).
        views: one or more of ``"xy"`` (seen from above), ``"xz"``, ``"yz"`` (from the side) and ``"3d"``.
        path: write the figure here if given.
        axes: one axes per view to draw into (3-D axes for ``"3d"``), else a new figure.

    Returns:
        The ``Figure``: one axes per view, one line per body; a dot marks each start. Plane views keep equal
        scales on both axes.
    """
    _check_trajectory(trajectory)
    views = (views,) if isinstance(views, str) else tuple(views)
    bad = [v for v in views if v not in _VIEWS]
    if not views or bad:
        raise ValueError(f"views must be one or more of {_VIEWS}, got {views!r}")
    rows = _bodies(trajectory, bodies)
    given = _axes_list(axes, len(views), "axes")
    if given is None:
        figure = _blank_figure((5.0 * len(views), 5.0))
        given = [
            figure.add_subplot(1, len(views), k + 1, projection="3d" if v == "3d" else None)
            for k, v in enumerate(views)
        ]
    figure = given[0].figure
    xyz = trajectory.position
    for ax, view in zip(given, views, strict=True):
        for i in rows:
            label = trajectory.body_label(i)
            if view == "3d":
                (line,) = ax.plot(xyz[:, i, 0], xyz[:, i, 1], xyz[:, i, 2], label=label)
                ax.scatter(*xyz[0, i], color=line.get_color(), s=12)
            else:
                a, b = (_COMPONENTS.index(c) for c in view)
                (line,) = ax.plot(xyz[:, i, a], xyz[:, i, b], label=label)
                ax.scatter(xyz[0, i, a], xyz[0, i, b], color=line.get_color(), s=12)
        if view == "3d":
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]")
            ax.set_zlabel("z [m]")
        else:
            ax.set_xlabel(f"{view[0]} [m]")
            ax.set_ylabel(f"{view[1]} [m]")
            ax.set_aspect("equal", adjustable="datalim")
            ax.grid(True, alpha=0.3)
        ax.set_title(f"Paths, {view} view" if view != "3d" else "Paths")
    given[0].legend(loc="best")
    _finish(figure, path)
    return figure


def _euler_zyx(q: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (Z-Y-X Tait-Bryan angles: yaw about z, then pitch about y, then roll about x) of
    quaternions (..., 4) [rad], as flight logs show attitude."""
    w, x, y, z = np.moveaxis(q, -1, 0)
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.stack([roll, pitch, yaw], axis=-1)


def flight(trajectory, vehicle=None, path=None):
    """The flight of one vehicle of a recording made with vehicles (``tumble run`` of a quadrotor scene, or
    ``tumble.recording.record``): its position against its reference, the tracking error, its attitude (roll,
    pitch, yaw) and its rotor speeds with their commands.

    Args:
        trajectory: a :class:`~tumble.Trajectory` with vehicle channels (``trajectory.channels``).
        vehicle: the vehicle's (body's) name; default the first.
        path: write the figure here if given.

    Returns:
        The ``Figure``: four axes, row by row.
    """
    _check_trajectory(trajectory)
    names = {k[len("vehicle/") :].rsplit("/", 1)[0] for k in trajectory.channels if k.startswith("vehicle/")}
    index = {name: int(name[1:]) if name.startswith("#") else trajectory.body_index(name) for name in names}
    names = sorted(names, key=index.get)  # in the order of the bodies
    if not names:
        raise ValueError("this trajectory holds no vehicle channels: record a world with vehicles (tumble run of a "
                         "quadrotor scene, or tumble.recording.record)")  # fmt: skip
    name = names[0] if vehicle is None else str(vehicle)
    if name not in names:
        raise KeyError(f"no vehicle named {name!r} in this trajectory; vehicles: {names}")
    i = index[name]
    channel = {what: trajectory.channels[f"vehicle/{name}/{what}"] for what in ("rotor_speeds", "commands",
                                                                                "reference")}  # fmt: skip
    time, position = trajectory.time, trajectory.position[:, i]
    figure, (ax_p, ax_e, ax_a, ax_r) = _new_figure(2, 2, size=(11.0, 7.5))
    for k, c in enumerate(_COMPONENTS):
        (line,) = ax_p.plot(time, position[:, k], label=c)
        ax_p.plot(time, channel["reference"][:, k], "--", color=line.get_color(), lw=1)
    ax_p.set_title(f"{name}: position (dashed: reference)")
    ax_p.set_ylabel("[m]")
    ax_e.plot(time, 100 * np.linalg.norm(position - channel["reference"], axis=1))
    ax_e.set_title("Tracking error |x - x_ref|")
    ax_e.set_ylabel("[cm]")
    for k, label in enumerate(("roll", "pitch", "yaw")):
        ax_a.plot(time, np.degrees(_euler_zyx(trajectory.orientation[:, i])[:, k]), label=label)
    ax_a.set_title("Attitude (Z-Y-X angles)")
    ax_a.set_ylabel("[deg]")
    for k in range(4):
        (line,) = ax_r.plot(time, channel["rotor_speeds"][:, k], label=f"rotor {k + 1}")
        ax_r.plot(time, channel["commands"][:, k], ":", color=line.get_color(), lw=1)
    ax_r.set_title("Rotor speeds (dotted: commands)")
    ax_r.set_ylabel("[rad/s]")
    for ax in (ax_p, ax_e, ax_a, ax_r):
        ax.set_xlabel("time [s]")
        ax.grid(True, alpha=0.3)
    for ax in (ax_p, ax_a, ax_r):
        ax.legend(loc="best", fontsize="small")
    _finish(figure, path)
    return figure
