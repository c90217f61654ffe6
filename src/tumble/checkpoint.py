"""Checkpoints: save a world and load it back to resume the run bit for bit (``World.save`` / ``World.load``).

A checkpoint is one ``.npz`` file holding a JSON manifest and arrays, and no pickle:

- the model's building description: the builder's body rows (mass properties, shapes placed in the body frame,
  materials, damping, names) and joint specs, the gravity and the step settings (integrator, solver);
- the :class:`~tumble.state.State` (poses, momenta, sleep timers, warm-start impulses, time, step count) and the
  pending :class:`~tumble.inputs.Inputs` (forces applied for the next step).

Loading rebuilds the model from that description exactly as the world built it (the shapes from their stored
kernel data, not from their constructors, so that no value is recomputed) and puts the state back, so the next
steps give the same bits as those of the world that was saved. The scratch buffers are not saved: they never
change results (``Joint.reaction_force`` reads zero until the first step after loading).

Floats are exact: small arrays and scalars go into the JSON manifest as Python ``repr`` (which reads back to the
same float64), larger arrays into ``.npy`` members. Loading executes no code from the file (``allow_pickle`` is
off and only tumble's own classes are rebuilt); indices are checked against the sizes they index. Even so a
checkpoint is meant for your own runs: a crafted file can still ask for a great deal of memory.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import zipfile
from pathlib import Path

import numpy as np

from . import shapes as _shapes
from ._validate import as_filter, as_material, as_vector3
from .builder import JointSpec, ModelBuilder, ShapeSpec, _BodyRow
from .dynamics.joint_solver import JointKind
from .geometry.manifold import MAX_POINTS
from .inputs import Inputs
from .mass import MassProperties, require_invertible
from .params import Params, SolverSettings
from .state import State

__all__ = ["save_world", "load_world", "FORMAT_NAME", "FORMAT_VERSION"]

FORMAT_NAME = "tumble.checkpoint"
FORMAT_VERSION = 1
# Arrays up to this many values go into the JSON manifest; larger ones into their own .npy member.
_INLINE_SIZE = 16
# The classes a manifest may name: tumble's own data classes, never an arbitrary import path.
_DATACLASSES = {cls.__name__: cls for cls in (ModelBuilder, _BodyRow, ShapeSpec, JointSpec, State, Inputs, Params)}
_NAMEDTUPLES = {"SolverSettings": SolverSettings}
_SHAPES = {
    cls.__name__: cls
    for cls in vars(_shapes).values()
    if isinstance(cls, type) and issubclass(cls, _shapes.Shape) and cls is not _shapes.Shape
}
_DTYPES = ("b", "i", "u", "f")  # array kinds a checkpoint may hold: bool, signed, unsigned, float


class _Encoder:
    """Turns the world's description into JSON-ready values, moving large arrays aside."""

    def __init__(self) -> None:
        self.arrays: dict[str, np.ndarray] = {}
        self.shapes: list[dict] = []
        self._shape_ids: dict[int, int] = {}

    def __call__(self, value):
        if value is None or isinstance(value, (bool, int, float, str)):
            return value
        if isinstance(value, np.generic):
            return value.item()
        if isinstance(value, np.ndarray):
            return self._array(value)
        if isinstance(value, (list, tuple)) and not hasattr(value, "_fields"):
            return [self(v) for v in value]
        if isinstance(value, _shapes.Shape):
            return {"$shape": self._shape(value)}
        if isinstance(value, MassProperties):
            return {"$mass": {"mass": value.mass, "com": self(value.com), "inertia": self(value.inertia)}}
        name = type(value).__name__
        if name in _NAMEDTUPLES and isinstance(value, _NAMEDTUPLES[name]):
            return {"$type": name, "fields": {k: self(v) for k, v in value._asdict().items()}}
        if name in _DATACLASSES and isinstance(value, _DATACLASSES[name]):
            fields = {f.name: self(getattr(value, f.name)) for f in dataclasses.fields(value)}
            return {"$type": name, "fields": fields}
        raise TypeError(f"a checkpoint cannot hold {value!r} ({type(value).__name__})")

    def _array(self, array: np.ndarray) -> dict:
        if array.dtype.kind not in _DTYPES:
            raise TypeError(f"a checkpoint holds numeric arrays only, got dtype {array.dtype}")
        if array.size <= _INLINE_SIZE:
            return {"$small": array.tolist(), "dtype": array.dtype.str, "shape": list(array.shape)}
        key = f"a{len(self.arrays)}"
        self.arrays[key] = array
        return {"$array": key}

    def _shape(self, shape: _shapes.Shape) -> int:
        if id(shape) not in self._shape_ids:
            self._shape_ids[id(shape)] = len(self.shapes)
            self.shapes.append(
                {
                    "type": type(shape).__name__,
                    "params": self(shape.params),
                    "vertices": self(shape.vertices),
                    "faces": self(shape.faces),
                    "volume": shape._volume,
                }
            )
        return self._shape_ids[id(shape)]


class _Invalid(ValueError):
    """A checkpoint found damaged; its message names the file (raised as is, never wrapped again)."""


class _Decoder:
    """The inverse of :class:`_Encoder`, rebuilding only whitelisted classes."""

    def __init__(self, arrays, shapes: list[dict], source: str) -> None:
        self._arrays = arrays
        self._source = source
        self._shapes = [self._shape(spec) for spec in shapes]

    def _fail(self, what: str) -> ValueError:
        return _Invalid(f"{self._source!r} is not a valid tumble checkpoint: {what}")

    def __call__(self, value):
        if isinstance(value, list):
            return [self(v) for v in value]
        if not isinstance(value, dict):
            return value
        if "$small" in value:
            dtype = np.dtype(value["dtype"])
            if dtype.kind not in _DTYPES:
                raise self._fail(f"array of dtype {dtype}")
            return np.array(value["$small"], dtype=dtype).reshape(value["shape"])
        if "$array" in value:
            key = value["$array"]
            if key not in self._arrays:
                raise self._fail(f"missing array {key!r}")
            array = self._arrays[key]
            if array.dtype.kind not in _DTYPES:
                raise self._fail(f"array {key!r} of dtype {array.dtype}")
            return array
        if "$shape" in value:
            index = value["$shape"]
            if not isinstance(index, int) or not 0 <= index < len(self._shapes):
                raise self._fail(f"shape reference {index!r}")
            return self._shapes[index]
        if "$mass" in value:
            m = value["$mass"]
            return MassProperties(m["mass"], self(m["com"]), self(m["inertia"]))
        if "$type" in value:
            name, fields = value["$type"], {k: self(v) for k, v in value["fields"].items()}
            cls = _DATACLASSES.get(name) or _NAMEDTUPLES.get(name)
            if cls is None:
                raise self._fail(f"unknown type {name!r}")
            try:
                return cls(**fields)
            except TypeError as error:
                raise self._fail(f"{name}: {error} (written by another tumble version?)") from None
        raise self._fail(f"unexpected object with keys {sorted(value)}")

    def _shape(self, spec: dict) -> _shapes.Shape:
        cls = _SHAPES.get(spec.get("type"))
        if cls is None:
            raise self._fail(f"unknown shape type {spec.get('type')!r}")
        params, vertices, faces = self(spec["params"]), self(spec["vertices"]), self(spec["faces"])
        params = np.asarray(params, dtype=np.float64)
        if params.shape != (4,) or not np.isfinite(params).all():
            raise self._fail(f"{cls.__name__} params {params.tolist()}")
        volume = spec["volume"]  # >= 0; a plane's is inf, a surface mesh's NaN
        if isinstance(volume, bool) or not isinstance(volume, (int, float)) or volume < 0.0:
            raise self._fail(f"{cls.__name__} volume {volume!r}")
        has_mesh = cls in (_shapes.ConvexHull, _shapes.TriMesh)
        if (vertices is not None) != has_mesh or (faces is not None) != has_mesh:
            raise self._fail(f"{cls.__name__} with vertices {vertices is not None} and faces {faces is not None}")
        if vertices is not None:
            vertices, faces = np.asarray(vertices, np.float64), np.asarray(faces, np.int64)
            if vertices.ndim != 2 or vertices.shape[1] != 3 or faces.ndim != 2 or faces.shape[1] != 3:
                raise self._fail(f"{cls.__name__} vertices {vertices.shape} and faces {faces.shape}")
            if not np.isfinite(vertices).all():
                raise self._fail(f"{cls.__name__} vertices that are not finite")
            if faces.size and (faces.min() < 0 or faces.max() >= len(vertices)):
                raise self._fail(f"{cls.__name__} face indices outside 0..{len(vertices) - 1}")
        return _shapes._rebuild(cls, params, vertices, faces, float(spec["volume"]))


def save_world(world, path: str | os.PathLike) -> Path:
    """Write ``world`` (model description, step settings, state, pending inputs) to ``path``; returns the path.

    The file is written next to ``path`` and renamed over it, so an interrupted save never leaves half a file.
    """
    from ._version import __version__

    drives = world.ctrl.shape[0]
    if drives:
        raise ValueError(
            f"save: the world has {drives} joint actuators (world.ctrl), which checkpoints do not hold (yet)"
        )
    path = Path(path)
    if path.suffix.lower() in (".h5", ".hdf5", ".he5"):
        raise ValueError(f"checkpoints are .npz files, got {os.fspath(path)!r}")
    world._sync()
    encode = _Encoder()
    manifest = {
        "format": FORMAT_NAME,
        "format_version": FORMAT_VERSION,
        "tumble_version": __version__,
        "gravity": encode(world._gravity),
        "params": encode(world._params),
        "builder": encode(world._builder),
        "state": encode(world._state),
        "inputs": encode(world._inputs),
    }
    manifest["shapes"] = encode.shapes  # filled while encoding the builder
    temporary = path.with_name(f".{path.name}.partial")
    with open(temporary, "wb") as f:
        np.savez_compressed(f, manifest=np.array(json.dumps(manifest)), **encode.arrays)
        f.flush()
        os.fsync(f.fileno())
    os.replace(temporary, path)
    return path


def load_world(path: str | os.PathLike, cls):
    """A new ``cls`` (:class:`~tumble.World`, which calls this) in the state :func:`save_world` wrote to ``path``."""
    source = os.fspath(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            manifest = json.loads(str(data["manifest"])) if "manifest" in data.files else {}
            arrays = {k: data[k] for k in data.files if k != "manifest"}
    except FileNotFoundError:
        raise FileNotFoundError(f"no checkpoint file at {source!r}") from None
    except (OSError, EOFError, ValueError, zipfile.BadZipFile) as error:
        raise ValueError(f"{source!r} is not a readable tumble checkpoint: {error}") from None
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT_NAME:
        raise ValueError(f"{source!r} is not a tumble checkpoint (no tumble.checkpoint manifest)")
    if manifest.get("format_version") != FORMAT_VERSION:
        raise ValueError(
            f"{source!r} is a checkpoint of format version {manifest.get('format_version')!r}; this tumble reads "
            f"version {FORMAT_VERSION}"
        )
    try:
        decode = _Decoder(arrays, manifest["shapes"], source)
        parts = {key: decode(manifest[key]) for key in ("params", "builder", "state", "inputs", "gravity")}
        for key, kind in (("params", Params), ("builder", ModelBuilder), ("state", State), ("inputs", Inputs)):
            if not isinstance(parts[key], kind):
                raise decode._fail(f"{key} is {type(parts[key]).__name__}, expected {kind.__name__}")
        builder, state, inputs = parts["builder"], parts["state"], parts["inputs"]
        _check_consistent(builder, state, inputs, source)
        _check_values(builder, state, inputs, source)
        # Through the public checks again: the integrator, gravity and every solver setting.
        return cls._from_builder(builder, state, inputs, gravity=parts["gravity"], params=parts["params"])
    except _Invalid:
        raise
    except KeyError as error:
        raise _Invalid(f"{source!r} is not a valid tumble checkpoint: no entry {error}") from None
    except (TypeError, ValueError, AttributeError, IndexError, OverflowError) as error:
        raise _Invalid(f"{source!r} is not a valid tumble checkpoint: {error}") from None


def _check_consistent(builder: ModelBuilder, state: State, inputs: Inputs, source: str) -> None:
    """Sizes and indices agree, so that no kernel reads outside an array."""
    n, j = builder.body_count, len(builder.joints)
    shape_count = sum(len(row.shapes) for row in builder.rows)
    # The shapes a fresh state of this size has; contact arrays have one row per manifold instead.
    template = State.empty(n)
    template.with_joints(j)
    k = state.contact_shape_a.shape[0]
    problems = []
    for f in dataclasses.fields(State):
        value, like = getattr(state, f.name), getattr(template, f.name)
        if not isinstance(like, np.ndarray):
            continue
        expected = (k, *like.shape[1:]) if f.name.startswith("contact_") else like.shape
        if not isinstance(value, np.ndarray) or value.shape != expected or value.dtype != like.dtype:
            problems.append(f"{f.name} is {_describe(value)}, expected {expected} {like.dtype}")
    problems += [f"inputs.{name} is {_describe(getattr(inputs, name))}, expected {(n, 3)}"
                 for name in ("body_force", "body_torque") if np.shape(getattr(inputs, name)) != (n, 3)]  # fmt: skip
    if not problems:
        checks = {
            "body_island": (state.body_island, -1, n),
            "contact_shape_a": (state.contact_shape_a, 0, shape_count),
            "contact_shape_b": (state.contact_shape_b, 0, shape_count),
            "contact_point_count": (state.contact_point_count, 0, MAX_POINTS + 1),
            "joint bodies": (np.array([[s.body_a, s.body_b] for s in builder.joints], np.int64), -1, n),
        }
        for name, (values, lo, hi) in checks.items():
            if values.size and (values.min() < lo or values.max() >= hi):
                problems.append(f"{name} outside {lo}..{hi - 1}")
    if problems:
        raise _Invalid(f"{source!r} is not a consistent tumble checkpoint: " + "; ".join(problems))


def _check_values(builder: ModelBuilder, state: State, inputs: Inputs, source: str) -> None:
    """Every value as the public API would have accepted it, so that a damaged file is refused here and not by a
    step that fails later: finite numbers (joint limits may be infinite, never NaN), unit quaternions, materials,
    filters, names and mass properties the API checks."""
    problems = []

    def check(where: str, test, *args) -> None:
        try:
            test(*args)
        except (TypeError, ValueError, AttributeError, OverflowError) as error:
            problems.append(f"{where}: {error}")

    for i, row in enumerate(builder.rows):
        where = f"body {i}"
        if row.mass_properties is not None:
            check(where, _require_mass, row.mass_properties)
        check(where, _require_numbers, "linear_damping", row.linear_damping, True)
        check(where, _require_numbers, "angular_damping", row.angular_damping, True)
        check(where, as_vector3, "constant_force", row.constant_force)
        check(where, as_vector3, "constant_torque", row.constant_torque)
        if not (row.name is None or (isinstance(row.name, str) and row.name and "\0" not in row.name)):
            problems.append(f"{where}: name {row.name!r}")
        for k, spec in enumerate(row.shapes):
            check(f"{where}, shape {k}", _require_shape, spec)
    if len(builder.names) != sum(row.name is not None for row in builder.rows):
        problems.append("two bodies share a name")
    for j, spec in enumerate(builder.joints):
        check(f"joint {j}", _require_joint, spec)
    for f in dataclasses.fields(State):
        value = getattr(state, f.name)
        if f.name != "body_quat" and isinstance(value, (np.ndarray, float)) and np.asarray(value).dtype.kind == "f":
            check("state", _require_numbers, f.name, value, f.name == "time" or f.name == "body_sleep_time")
    check("state", _require_unit_quaternions, "body_quat", state.body_quat)
    if not isinstance(state.step_count, int) or isinstance(state.step_count, bool) or state.step_count < 0:
        problems.append(f"state: step_count {state.step_count!r}")
    if not isinstance(state.time, float) or not math.isfinite(state.time):
        problems.append(f"state: time {state.time!r}")
    for name in ("body_force", "body_torque"):
        check("inputs", _require_numbers, name, getattr(inputs, name))
    if problems:
        shown = "; ".join(problems[:5]) + (f"; and {len(problems) - 5} more" if len(problems) > 5 else "")
        raise _Invalid(f"{source!r} is not a valid tumble checkpoint: {shown}")


def _require_numbers(name: str, value, nonnegative: bool = False, allow_inf: bool = False) -> None:
    array = np.asarray(value)
    if array.dtype.kind not in "fiu":
        raise TypeError(f"{name} is {type(value).__name__}, not numbers")
    bad = np.isnan(array) if allow_inf else ~np.isfinite(array)
    if nonnegative:
        bad |= array < 0
    if bad.any():
        raise ValueError(f"{name} holds {array[bad].ravel()[0].item()!r}")


def _require_unit_quaternions(name: str, value) -> None:
    _require_numbers(name, value)
    norms = np.linalg.norm(np.asarray(value, dtype=np.float64).reshape(-1, 4), axis=1)
    if norms.size and not np.all(np.abs(norms - 1.0) < 1e-6):
        raise ValueError(f"{name} holds a quaternion of norm {norms[np.argmax(np.abs(norms - 1.0))]!r}, not 1")


def _require_quaternion(name: str, value) -> None:
    """One unit quaternion: shape (4,) (an empty list passed the unit check, and a kernel read past it)."""
    if np.shape(value) != (4,):
        raise ValueError(f"{name} of shape {np.shape(value)}, expected (4,)")
    _require_unit_quaternions(name, value)


def _require_mass(mp) -> None:
    if not isinstance(mp, MassProperties):
        raise TypeError(f"mass properties are {type(mp).__name__}")
    require_invertible(mp)


def _require_shape(spec) -> None:
    if not isinstance(spec, ShapeSpec) or not isinstance(spec.shape, _shapes.Shape):
        raise TypeError(f"{type(spec).__name__} holding {type(getattr(spec, 'shape', None)).__name__}, not a shape")
    as_vector3("position", spec.position)
    _require_quaternion("quat", spec.quat)
    as_material(spec.friction, spec.restitution, spec.rolling_resistance)
    as_filter("group", spec.group)
    as_filter("mask", spec.mask)


def _require_joint(spec) -> None:
    if not isinstance(spec, JointSpec):
        raise TypeError(f"{type(spec).__name__}, not a joint")
    JointKind(spec.kind)
    for name in ("local_anchor_a", "local_anchor_b"):
        as_vector3(name, getattr(spec, name))
    for name in ("local_frame_a", "local_frame_b"):
        _require_quaternion(name, getattr(spec, name))
    drive = np.asarray(spec.drive)
    if drive.shape == (8,):  # written before joints had damping (issue 26): none
        spec.drive = drive = np.append(drive, 0.0)
    if drive.shape != (9,):
        raise ValueError(f"drive of shape {drive.shape}, expected (9,)")
    _require_numbers("drive", drive, allow_inf=True)


def _describe(value) -> str:
    return f"{value.shape} {value.dtype}" if isinstance(value, np.ndarray) else type(value).__name__
