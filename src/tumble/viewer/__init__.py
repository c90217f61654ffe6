"""HTML replay of a :class:`~tumble.Trajectory`: one self-contained page drawn with WebGL.

>>> import tumble, tumble.viewer
>>> world = tumble.World()
>>> ground = world.add_static(tumble.Plane(), name="ground")
>>> ball = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0.0, 0.0, 1.0), name="ball")
>>> trajectory = world.simulate(0.1, 0.01)
>>> page = tumble.viewer.replay_html(trajectory, world=world, title="falling ball")
>>> page.startswith("<!DOCTYPE html>") and "<script src=" not in page
True

The page needs no network when it is viewed (no CDN, no third-party script): the data, the styles and the
script are inlined. It shows the bodies (boxes, spheres, capsules, cylinders, hulls, meshes and planes) with an
orbit camera, play/pause, a time slider, a speed control, body picking (name, mass, speed) and the energy plot.
See ``docs/viewer.md``.
"""

from __future__ import annotations

import html as _html
import os
from pathlib import Path

import numpy as np

from ..vehicles import quadrotors
from .geometry import fallback_geometry, scene_geometry
from .page import build_data, render_page

__all__ = ["replay_html", "write_html", "show", "scene_geometry", "Replay"]


def _geometry_for(trajectory, world, geometry) -> dict:
    if world is not None and geometry is not None:
        raise ValueError("pass world= or geometry=, not both (geometry is what scene_geometry(world) returns)")
    if world is not None:
        return scene_geometry(world)
    if geometry is not None:
        return geometry
    return fallback_geometry(
        np.asarray(trajectory.body_mass), np.asarray(trajectory.body_inertia), np.asarray(trajectory.body_com_local)
    )


def _channels_for(trajectory, world) -> dict:
    """The recording's channels; where a vehicle of ``world`` has no reference there, its flight's trajectory at
    the recorded times (a ``world.simulate`` recording has no channels)."""
    channels = dict(trajectory.channels)
    for quad in quadrotors(world):
        key = f"vehicle/{quad.body.name or f'#{quad.body.index}'}/reference"
        if key not in channels and quad._flight is not None:
            reference = quad._flight.trajectory
            channels[key] = np.array([reference(t)["position"] for t in trajectory.time])
    return channels


def replay_html(trajectory, *, world=None, geometry=None, title=None, max_frames=None, compress=True) -> str:
    """The replay page of ``trajectory`` as HTML text.

    Args:
        trajectory: a :class:`~tumble.Trajectory` (``World.simulate`` or ``Trajectory.load``).
        world: the :class:`~tumble.World` that recorded it, for the shapes. Without ``world`` or ``geometry``
            each body with mass is drawn as the solid ball of the same mass and mean moment of inertia.
        geometry: what :func:`scene_geometry` returned for that world (instead of ``world``).
        title: the page title (default ``"tumble replay"``).
        max_frames: keep at most this many frames (>= 2), spread evenly, first and last kept.
        compress: gzip the large arrays (inflated by the browser); ``False`` gives plain base64.
    """
    from ..trajectory import Trajectory

    if not isinstance(trajectory, Trajectory):
        raise TypeError(f"trajectory must be a tumble.Trajectory, got {type(trajectory).__name__}")
    if len(trajectory) < 1:
        raise ValueError("trajectory has no frames to replay")
    if max_frames is not None and (
        isinstance(max_frames, bool) or not isinstance(max_frames, (int, np.integer)) or max_frames < 2
    ):
        raise ValueError(f"max_frames must be an integer >= 2 or None, got {max_frames!r}")
    if title is None:
        title = "tumble replay"
    if not isinstance(title, str):
        raise TypeError(f"title must be a string, got {type(title).__name__}")
    data = build_data(
        trajectory,
        _geometry_for(trajectory, world, geometry),
        title=title,
        max_frames=None if max_frames is None else int(max_frames),
        compress=bool(compress),
        channels=_channels_for(trajectory, world),
    )
    return render_page(data)


def write_html(
    trajectory, path: str | os.PathLike, *, world=None, geometry=None, title=None, max_frames=None, compress=True
) -> Path:
    """Write the replay page (see :func:`replay_html`) to ``path``; returns the path."""
    page = replay_html(
        trajectory, world=world, geometry=geometry, title=title, max_frames=max_frames, compress=compress
    )
    path = Path(path)
    path.write_text(page, encoding="utf-8")
    return path


class Replay:
    """A replay page for notebooks: ``_repr_html_`` embeds it in an ``<iframe srcdoc>``."""

    def __init__(self, page: str, height: int = 640) -> None:
        self.page = page
        self.height = int(height)

    def _repr_html_(self) -> str:
        return (
            f'<iframe srcdoc="{_html.escape(self.page, quote=True)}" style="width:100%;height:{self.height}px;'
            'border:1px solid #ccc" sandbox="allow-scripts" loading="eager"></iframe>'
        )

    def save(self, path: str | os.PathLike) -> Path:
        path = Path(path)
        path.write_text(self.page, encoding="utf-8")
        return path


def show(trajectory, world=None, *, geometry=None, title=None, max_frames=None, compress=True, height=640):
    """The replay inline in Jupyter: an ``IPython.display.HTML`` of the page in an iframe when IPython is
    importable, else a :class:`Replay` (whose ``_repr_html_`` notebooks call). Other arguments as in
    :func:`replay_html`; ``height`` [px] of the frame."""
    page = replay_html(
        trajectory, world=world, geometry=geometry, title=title, max_frames=max_frames, compress=compress
    )
    replay = Replay(page, height)
    try:
        from IPython.display import HTML
    except ImportError:
        return replay
    return HTML(replay._repr_html_())
