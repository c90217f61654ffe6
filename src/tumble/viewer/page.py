"""Assemble the replay page: the trajectory packed into typed arrays, inlined with the template, CSS and JS.

The page is one self-contained HTML file: no URL is fetched when it is viewed. Its data sit in a
``<script type="application/json" id="tumble-data">`` block; every array there is a *blob*
``{"dtype", "shape", "gzip", "data"}``, the little-endian bytes in base64, gzip-compressed when that makes them
smaller (the page inflates them with the browser's ``DecompressionStream``). To keep files small:

- positions are float32 and orientations int16 (``round(32767 q)``: at most 1.5e-5 per component, well under
  a pixel), speeds float16;
- bodies that never move in the recorded frames (static bodies, sleepers) are stored once, not per frame;
- moving bodies are stored body-major ``(M, T, …)``, so a body at rest repeats the same bytes and gzip removes
  them.
"""

from __future__ import annotations

import base64
import gzip
import html
import json
import re
from importlib import resources

import numpy as np

from .geometry import body_radius, check_geometry, plane_quads

__all__ = ["build_data", "render_page", "encode_array", "decode_array", "read_page_data", "select_frames"]

_DTYPES = {"f2": "<f2", "f4": "<f4", "f8": "<f8", "i2": "<i2", "i4": "<i4", "u4": "<u4"}
_GZIP_MIN_BYTES = 2048  # smaller blobs are not worth a DecompressionStream round trip
_QUAT_SCALE = 32767.0
_SPEED_FLOAT16_MAX = 6.0e4  # float16 tops out at 65504; faster bodies keep float32 speeds


def encode_array(values, dtype: str, *, compress: bool = True) -> dict:
    """A blob for the page: ``values`` as little-endian ``dtype`` (``"f4"``, ``"i2"``, ...), base64, maybe gzip."""
    array = np.ascontiguousarray(np.asarray(values).astype(_DTYPES[dtype]))
    raw = array.tobytes()
    packed, zipped = raw, False
    if compress and len(raw) >= _GZIP_MIN_BYTES:
        candidate = gzip.compress(raw, compresslevel=6, mtime=0)
        if len(candidate) < len(raw):
            packed, zipped = candidate, True
    return {
        "dtype": dtype,
        "shape": list(array.shape),
        "gzip": zipped,
        "data": base64.b64encode(packed).decode("ascii"),
    }


def decode_array(blob: dict) -> np.ndarray:
    """The array a blob holds (the inverse of :func:`encode_array`)."""
    raw = base64.b64decode(blob["data"])
    if blob["gzip"]:
        raw = gzip.decompress(raw)
    return np.frombuffer(raw, dtype=_DTYPES[blob["dtype"]]).reshape(blob["shape"])


def select_frames(frame_count: int, max_frames: int | None) -> np.ndarray:
    """Indices of at most ``max_frames`` frames spread evenly over ``frame_count``, first and last kept."""
    if max_frames is None or frame_count <= max_frames:
        return np.arange(frame_count)
    return np.unique(np.round(np.linspace(0, frame_count - 1, max_frames)).astype(np.int64))


def _moving_bodies(position: np.ndarray, orientation: np.ndarray, body_mass: np.ndarray) -> np.ndarray:
    """Bodies with mass whose pose changes in some frame; the others are drawn at their first pose."""
    moved = np.any(position != position[:1], axis=(0, 2)) | np.any(orientation != orientation[:1], axis=(0, 2))
    return np.flatnonzero(moved & (body_mass > 0.0))


def _scene_bounds(position: np.ndarray, radius: np.ndarray, has_extent: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World-frame box holding every body with extent over all frames (planes left out)."""
    if not np.any(has_extent):
        return np.full(3, -1.0), np.full(3, 1.0)
    pos = position[:, has_extent]
    r = radius[has_extent][:, None]
    lo = np.min(np.nanmin(pos, axis=0) - r, axis=0)
    hi = np.max(np.nanmax(pos, axis=0) + r, axis=0)
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        return np.full(3, -1.0), np.full(3, 1.0)
    return lo, hi


def _view_bounds(
    position: np.ndarray, radius: np.ndarray, has_extent: np.ndarray, moving: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The box the camera frames first: the median over frames of the box around the moving bodies (so that
    bodies dropped from high up, or flung away late, do not shrink the rest), joined with the bodies that do
    not move."""
    still = has_extent.copy()
    still[moving] = False
    boxes = []
    if len(moving):
        reach = radius[moving][None, :, None]
        with np.errstate(invalid="ignore"):
            lo = np.nanmedian(np.nanmin(position[:, moving] - reach, axis=1), axis=0)
            hi = np.nanmedian(np.nanmax(position[:, moving] + reach, axis=1), axis=0)
        if np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)):
            boxes.append((lo, hi))
    if np.any(still):
        boxes.append(_scene_bounds(position[:1], radius, still))
    if not boxes:
        return _scene_bounds(position, radius, has_extent)
    return np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)


def build_data(trajectory, geometry: dict, *, title: str, max_frames: int | None = None, compress: bool = True,
               channels: dict | None = None):  # fmt: skip
    """The JSON-ready dict the page's script reads (arrays as blobs, see :func:`encode_array`); ``channels`` (the
    recording's, or made up from the world) give the quadrotors' reference paths and rotor speeds."""
    n = trajectory.body_count
    check_geometry(geometry, n)
    frames = select_frames(len(trajectory), max_frames)
    position = np.asarray(trajectory.position)[frames]
    orientation = np.asarray(trajectory.orientation)[frames]
    speed = np.linalg.norm(np.asarray(trajectory.velocity)[frames], axis=-1)
    body_mass = np.asarray(trajectory.body_mass, dtype=float)

    moving = _moving_bodies(position, orientation, body_mass)
    unit = orientation / np.linalg.norm(orientation, axis=-1, keepdims=True)
    quantised = np.round(unit[:, moving].transpose(1, 0, 2) * _QUAT_SCALE)
    moving_speed = speed[:, moving].T
    speed_dtype = "f2" if moving_speed.size == 0 or np.nanmax(moving_speed) < _SPEED_FLOAT16_MAX else "f4"

    radius = body_radius(geometry, n)
    has_extent = np.zeros(n, dtype=bool)
    for shape in geometry["shapes"]:
        has_extent[shape["body"]] |= shape["kind"] != "plane"
    lo, hi = _scene_bounds(position, radius, has_extent)
    view_lo, view_hi = _view_bounds(position, radius, has_extent, moving)
    diagonal = float(np.linalg.norm(hi - lo))
    planes = plane_quads(geometry, position[0], unit[0], 0.5 * (lo + hi), max(1.5 * diagonal, 2.0))

    def blob(values, dtype):
        return encode_array(values, dtype, compress=compress)

    overlays, path_points = _vehicle_overlays(trajectory, geometry, channels or {}, frames, blob)
    if len(path_points):  # the camera also frames the paths the vehicles are to fly
        view_lo, view_hi = np.minimum(view_lo, path_points.min(axis=0)), np.maximum(view_hi, path_points.max(axis=0))

    meshes = [{"vertices": blob(m["vertices"], "f4"), "faces": blob(m["faces"], "u4")} for m in geometry["meshes"]]
    shapes = [{k: v for k, v in s.items()} for s in geometry["shapes"] if s["kind"] != "plane"]
    return {
        "format": 1,
        "title": title,
        "bodyCount": n,
        "frameCount": len(frames),
        "names": [name or f"body {i}" for i, name in enumerate(_names(trajectory, n))],
        "mass": body_mass.tolist(),
        "time": blob(np.asarray(trajectory.time)[frames], "f8"),
        "kinetic": blob(np.asarray(trajectory.kinetic_energy)[frames], "f4"),
        "potential": blob(np.asarray(trajectory.potential_energy)[frames], "f4"),
        "restPos": blob(position[0], "f4"),
        "restQuat": blob(unit[0], "f4"),
        "moving": blob(moving, "i4"),
        "pos": blob(position[:, moving].transpose(1, 0, 2), "f4"),
        "quat": blob(quantised, "i2"),
        "speed": blob(moving_speed, speed_dtype),
        "shapes": shapes,
        "meshes": meshes,
        "planes": planes,
        **overlays,
        "bounds": {"min": lo.tolist(), "max": hi.tolist()},
        "view": {"min": view_lo.tolist(), "max": view_hi.tolist()},
    }


# A blade drawn at the rotor's true speed (300 turns a second) would strobe: it turns at this fraction of it.
BLADE_SLOWDOWN = 1.0 / 40.0
_PATH_POINTS = 400  # the reference path is drawn with at most this many points


def _vehicle_overlays(
    trajectory, geometry: dict, channels: dict, frames: np.ndarray, encode
) -> tuple[dict, np.ndarray]:
    """The quadrotors' reference paths (``paths``: body and points) and spinning blades (``rotors``: body, hub in
    the body frame, radius and the blade's angle at each frame), from the vehicle channels of the recording; and
    every path point drawn, (P, 3)."""
    paths, rotors, drawn = [], [], [np.zeros((0, 3))]
    time = np.asarray(trajectory.time, dtype=float)
    for vehicle in geometry.get("vehicles", []):
        prefix = f"vehicle/{vehicle['name']}/"
        reference = channels.get(prefix + "reference")
        if reference is not None:
            points = reference[np.isfinite(reference).all(axis=1)]
            if len(points) >= 2:
                points = points[np.unique(np.linspace(0, len(points) - 1, _PATH_POINTS).astype(int))]
                paths.append({"body": vehicle["body"], "points": encode(points, "f4")})
                drawn.append(points)
        speeds = channels.get(prefix + "rotor_speeds")
        for k, (hub, spin) in enumerate(zip(vehicle["hubs"], vehicle["spins"], strict=True)):
            angle = np.zeros(len(time))
            if speeds is not None:  # the trapezoid rule over the frames, the blade turning the way its rotor does
                angle[1:] = np.cumsum(0.5 * (speeds[1:, k] + speeds[:-1, k]) * np.diff(time))
            rotors.append({"body": vehicle["body"], "hub": hub, "radius": vehicle["radius"],
                           "angles": encode(-spin * BLADE_SLOWDOWN * angle[frames], "f4")})  # fmt: skip
    return {"paths": paths, "rotors": rotors}, np.concatenate(drawn)


def _names(trajectory, n: int) -> list[str]:
    names = list(trajectory.body_names or [])
    return [str(x) for x in names] + [""] * (n - len(names))


def _template(name: str) -> str:
    return resources.files(__package__).joinpath(name).read_text(encoding="utf-8")


def render_page(data: dict) -> str:
    """The HTML text: the template with the CSS, the script and ``data`` (as JSON) inlined."""
    # "<" never appears raw inside the JSON, so no "</script>" in a body name can close the block early.
    payload = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c")
    parts = {
        "title": html.escape(data["title"]),
        "css": _template("replay.css"),
        "js": _template("replay.js"),
        "data": payload,
    }
    # One pass over the template only: text put in is never scanned for placeholders again.
    return re.sub(r"\{\{(\w+)\}\}", lambda m: parts[m.group(1)], _template("replay.html"))


def read_page_data(page: str) -> dict:
    """The data block of a replay page with every blob decoded to a NumPy array (for tests and tools)."""
    match = re.search(r'<script type="application/json" id="tumble-data">(.*?)</script>', page, re.S)
    if match is None:
        raise ValueError("not a tumble replay page: no tumble-data block")
    data = json.loads(match.group(1))

    def decode(value):
        if isinstance(value, dict) and {"dtype", "shape", "gzip", "data"} <= set(value):
            return decode_array(value)
        if isinstance(value, dict):
            return {k: decode(v) for k, v in value.items()}
        if isinstance(value, list):
            return [decode(v) for v in value]
        return value

    return decode(data)
