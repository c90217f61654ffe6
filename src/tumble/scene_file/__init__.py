"""Scene files: a world described in TOML (or the same structure in JSON), validated, built, written back.

>>> from tumble import scene_file
>>> loaded = scene_file.load(scene_file.shipped_scene("pendulum"))
>>> loaded.run.dt, len(loaded.world.joints)
(0.016666666666666666, 1)

``load(path)`` reads and validates a file (pydantic: a wrong type, a value out of range, an unknown key or a
missing mesh file is a :class:`SceneError` naming the file and the place, ``pile.toml: bodies[3].shape.extents:
...``) and builds the :class:`~tumble.World`; nothing in the file is executed. ``World.to_scene()`` writes a
world back as the same structure (:func:`dumps` makes it TOML or JSON text). See ``docs/scenes.md``.
"""

from __future__ import annotations

import gc
import json
import reprlib
import tomllib
import warnings
from collections.abc import Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from pydantic import ValidationError

from ..io.scene_dump import world_to_scene
from . import schema
from .build import SceneError, build_world
from .overrides import apply as apply_overrides

__all__ = [
    "LoadedScene",
    "RunSettings",
    "SceneError",
    "check",
    "dumps",
    "from_dict",
    "load",
    "read",
    "shipped",
    "shipped_scene",
]

SHIPPED_DIR = Path(__file__).resolve().parent.parent / "scene_files"


@dataclass(frozen=True)
class RunSettings:
    """How the file asks to run it: step, duration, recording."""

    dt: float
    duration: float
    record_every: int
    output: str | None


@dataclass(frozen=True)
class LoadedScene:
    """A loaded scene: the world built, the run settings, and the validated scene (``source``: as a JSON-able dict,
    every key with its default filled in)."""

    world: object
    run: RunSettings
    scene: schema.Scene

    @cached_property
    def source(self) -> dict:
        # Made when first asked for (tumble run stores it with the recording): for a scene of 100 000 bodies it
        # costs a tenth of the load.
        return self.scene.model_dump(mode="json", exclude_none=True)


def _place(location: tuple) -> str:
    """``('bodies', 3, 'shape', 'box', 'extents', 0)`` → ``bodies[3].shape.extents[0]`` (union tags dropped)."""
    text = ""
    for part in location:
        if isinstance(part, int):
            text += f"[{part}]"
        elif (
            part in _UNION_TAGS
            or part in ("QuadrotorParams", "float", "int")
            or part.startswith(("tuple[", "function-", "literal["))
        ):
            continue
        else:
            text += f".{part}" if text else part
    return text or "(top level)"


_UNION_TAGS = {"sphere", "box", "capsule", "cylinder", "plane", "hull", "mesh", "ball", "hinge", "slider", "fixed",
               "distance", "spring", "rope", "se3", "cascaded_pid", "hover", "circle", "lissajous", "minimum_snap",
               "constant", "sinusoid", "dryden"}  # fmt: skip


def _validation_message(label: str, error: ValidationError) -> str:
    lines = []
    for item in error.errors(include_url=False)[:5]:
        message = item["msg"]
        if item["type"] == "extra_forbidden":
            message = "unknown key"
        got = item.get("input")
        try:
            shown = repr(got)
        except RecursionError:  # nested thousands deep: the first levels
            shown = reprlib.repr(got)
        shown = shown if len(shown) <= 60 else shown[:57] + "..."
        lines.append(f"{label}: {_place(item['loc'])}: {message} (got {shown})")
    more = error.error_count() - len(lines)
    return "\n".join(lines) + (f"\n{label}: ... and {more} more" if more > 0 else "")


def _parse_toml(text: str) -> dict:
    """The TOML document as a dict: parsed by rtoml (compiled; the standard library's parser takes 30 us a body,
    as long as building it), and by ``tomllib`` when rtoml refuses it, so that a malformed file is reported as the
    standard parser reports it (and a value only it reads, such as an integer past 64 bits, still loads)."""
    try:
        import rtoml

        return rtoml.loads(text)
    except Exception:  # rtoml missing, or its error: tomllib says what is wrong, the same way every time
        return tomllib.loads(text)


@contextmanager
def _without_cyclic_gc():
    """Loading makes a few objects per body and no cyclic garbage to speak of, but the cyclic collector walks them
    all again each time enough are made: 1.6 s of the 8.9 s a scene of 100 000 bodies took. It runs again after."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _validated(data: dict, label: str, overrides: Mapping[str, object] | None = None) -> schema.Scene:
    """The scene ``data`` validated, with ``overrides`` (place: value) applied to it first. A place inside something
    the file leaves to its default (``world.gravity[2]`` in a file without gravity) is set on the scene with every
    default filled in, which costs one more validation (a sixth of a load at 10 000 bodies), so only then."""
    if not isinstance(data, dict):
        raise SceneError(f"{label}: a scene must be a table (a dict), got {type(data).__name__}")
    try:
        if overrides:
            try:
                data = apply_overrides(data, overrides, label)
            except SceneError:  # not in the file as written: with the defaults (or the error, said the same way)
                whole = schema.Scene.model_validate(data).model_dump(mode="json", exclude_none=True)
                data = apply_overrides(whole, overrides, label)
        scene = schema.Scene.model_validate(data)
    except ValidationError as error:
        raise SceneError(_validation_message(label, error)) from None
    except RecursionError:  # a dict nested thousands deep
        raise SceneError(f"{label}: nested too deeply to be a scene") from None
    return scene


def from_dict(data: dict, *, base: Path | str = ".", label: str = "<scene>",
              overrides: Mapping[str, object] | None = None) -> LoadedScene:  # fmt: skip
    """Validate and build a scene given as a dict (``label`` names it in errors; meshes relative to ``base``).
    ``overrides`` changes values by their place first (``{"bodies[0].friction": 0.3}``: see
    :mod:`tumble.scene_file.overrides`)."""
    with _without_cyclic_gc():
        scene = _validated(data, label, overrides)
        world = build_world(scene, Path(base), label)
    run = RunSettings(scene.world.dt, scene.world.duration, scene.recording.every, scene.recording.path)
    return LoadedScene(world, run, scene)


def _model_scene_data(path: Path) -> dict:
    """A model file (MJCF or URDF) as a scene of that one model, with its gravity and its timestep as the step (a
    URDF has neither: MuJoCo's defaults, 9.81 m/s² down and 2 ms)."""
    from ..models.mjcf import MJCFError, read_mjcf
    from ..models.urdf import read_urdf

    try:
        with warnings.catch_warnings():  # read for its options only; building it reads it again, and warns
            warnings.simplefilter("ignore")
            model = read_urdf(path) if path.suffix.lower() == ".urdf" else read_mjcf(path)
    except (MJCFError, OSError) as error:
        raise SceneError(str(error)) from None
    return {"world": {"gravity": model.gravity.tolist(), "dt": float(model.timestep)}, "models": [{"path": path.name}]}


def read(path) -> tuple[dict, Path, str]:
    """``(data, base, label)``: the file at ``path`` parsed (not yet validated), the folder its meshes and models
    are relative to, and its name for errors. A model file (MJCF ``.xml``, URDF ``.urdf``) reads as a scene of that
    one model."""
    path = Path(path)
    label = path.name
    if path.suffix.lower() in (".xml", ".urdf"):
        return _model_scene_data(path), path.parent, label
    if path.suffix not in (".toml", ".json"):
        raise SceneError(f"{label}: a scene file must end in .toml or .json (or be a model file: MJCF .xml, URDF "
                         ".urdf)")  # fmt: skip
    try:
        text = path.read_bytes().decode("utf-8-sig")  # a byte-order mark, as some editors write, is skipped
    except OSError as error:
        raise SceneError(f"{label}: cannot read the file: {error.strerror or error}") from None
    except UnicodeDecodeError as error:
        byte = error.object[error.start]
        raise SceneError(f"{label}: not UTF-8 text (byte 0x{byte:02x} at offset {error.start}: {error.reason}); "
                         "scene files are UTF-8") from None  # fmt: skip
    with _without_cyclic_gc():
        try:
            data = _parse_toml(text) if path.suffix == ".toml" else json.loads(text)
        except (tomllib.TOMLDecodeError, json.JSONDecodeError) as error:
            raise SceneError(f"{label}: not valid {path.suffix[1:].upper()}: {error}") from None
        except RecursionError:
            raise SceneError(f"{label}: not valid {path.suffix[1:].upper()}: nested too deeply") from None
    return data, path.parent, label


def load(path, overrides: Mapping[str, object] | None = None) -> LoadedScene:
    """Read, validate and build the scene file at ``path`` (``.toml`` or ``.json``, or a model file: MJCF ``.xml``,
    URDF ``.urdf``), with ``overrides`` (place: value, ``{"bodies[0].friction": 0.3}``) changed in it first."""
    data, base, label = read(path)
    return from_dict(data, base=base, label=label, overrides=overrides)


def check(path, overrides: Mapping[str, object] | None = None) -> schema.Scene:
    """Read and validate the scene file at ``path`` with ``overrides`` applied, without building it (cheap: the
    check of a sweep's places before its members run). Raises :class:`SceneError` as :func:`load` does."""
    data, _, label = read(path)
    with _without_cyclic_gc():
        return _validated(data, label, overrides)


def dumps(scene: dict, format: str = "toml") -> str:
    """A scene dict (``World.to_scene()``) as TOML or JSON text."""
    if format == "json":
        return json.dumps(scene, indent=2)
    if format != "toml":
        raise ValueError(f"format must be 'toml' or 'json', got {format!r}")
    return _toml(scene)


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(float(value)) if isinstance(value, float) else str(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items() if v is not None) + " }"
    return "[" + ", ".join(_toml_value(v) for v in value) + "]"


def _toml(scene: dict) -> str:
    lines = []
    # Plain values first: in TOML they must come before the first table.
    ordered = sorted(scene.items(), key=lambda item: isinstance(item[1], (dict, list)))
    for key, value in ordered:
        if isinstance(value, dict) and key != "materials":
            lines.append(f"[{key}]")
            lines += [f"{k} = {_toml_value(v)}" for k, v in value.items() if v is not None]
        elif key == "materials":
            for name, material in value.items():
                lines.append(f"[materials.{name}]")
                lines += [f"{k} = {_toml_value(v)}" for k, v in material.items()]
        elif isinstance(value, list):
            for item in value:
                lines.append(f"[[{key}]]")
                lines += [f"{k} = {_toml_value(v)}" for k, v in item.items() if v is not None]
        else:
            lines.append(f"{key} = {_toml_value(value)}")
        lines.append("")
    return "\n".join(lines)


def shipped() -> list[Path]:
    """The scene files shipped with tumble, sorted by name."""
    return sorted(SHIPPED_DIR.glob("*.toml"))


def shipped_scene(name: str) -> Path:
    """The shipped scene file called ``name`` (without ``.toml``)."""
    path = SHIPPED_DIR / f"{name}.toml"
    if not path.is_file():
        raise KeyError(f"no shipped scene {name!r}; scenes: {[p.stem for p in shipped()]}")
    return path


# Re-exported for World.to_scene.
to_scene = world_to_scene
