"""The ``tumble`` command: run scene files, inspect them, replay and plot recorded trajectories.

::

    tumble run SCENE [--duration S] [--dt S] [--every N] [--out FILE.h5|FILE.npz] [--html FILE] [--plot FILE]
                     [--max-frames N] [--quiet]
    tumble info SCENE
    tumble batch SCENE -n N [--duration S] [--dt S] [--quiet]
    tumble view TRAJ -o replay.html [--scene SCENE] [--title TEXT] [--max-frames N]
    tumble plot TRAJ [--what energy,momentum,omega,paths] [-o DIR|FILE] [--bodies NAMES]
    tumble examples [--copy DIR] [--force]
    tumble warmup [--jobs N] [--quiet]
    tumble bench [--quick] [--only NAME]... [--csv [DIR]] [--repeat N] [--machine NAME]
    tumble --version

Exit status: 0 done; 1 the simulation failed (a :class:`~tumble.SimulationError`: the message names the body and
the step, and what was recorded up to the last good step is kept); 2 bad input (a scene file that does not
validate, a missing file, a bad option value: one line on stderr, no traceback); 130 interrupted (Ctrl-C); 143
terminated (SIGTERM, which stops a run as Ctrl-C does).
``python -m tumble`` is the same command. See ``docs/cli.md``.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import shutil
import sys
import tempfile
import time
import warnings
from pathlib import Path

from ._validate import MAX_STEPS
from .cli_common import (
    EXIT_BAD_INPUT,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_SIMULATION,
    EXIT_TERMINATED,
    BadInput,
    _consoles,
    _error,
    _InterruptLatch,
    _load_scene,
    _note,
    _PipeClosed,
    _positive_float,
    _positive_int,
    _Progress,
    _shipped_scenes,
    _Terminated,
    _text,
)

__all__ = ["main", "EXIT_OK", "EXIT_SIMULATION", "EXIT_BAD_INPUT", "EXIT_INTERRUPTED", "EXIT_TERMINATED"]

TRAJECTORY_SUFFIXES = (".h5", ".hdf5", ".he5", ".npz")
PLOT_KINDS = ("energy", "momentum", "omega", "paths", "flight")
# The run is cut into about this many chunks (fewer for .npz, which is rewritten whole at each chunk), so that
# the progress bar moves and Ctrl-C is answered within a chunk: the compiled loop only sees it between chunks.
_TARGET_CHUNKS = {"h5": 50, "npz": 10}
_MIN_CHUNK_FRAMES = 16  # a chunk costs a compiled call and a write: fewer frames would cost small scenes speed
_TINY = sys.float_info.min  # the smallest normal float64: the floor of |E_0| in the energy drift


# --- small helpers ----------------------------------------------------------------------------------------------


def _fmt(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}"


def _vec(values, digits: int = 4) -> str:
    return "(" + ", ".join(_fmt(float(v), digits) for v in values) + ")"


def _frames_limit(text: str) -> int:
    value = _positive_int(text)
    if value < 2:
        raise argparse.ArgumentTypeError(f"must be an integer >= 2, got {text!r}")
    return value


def _existing_file(path: str, what: str) -> Path:
    p = Path(path)
    if not p.exists():
        raise BadInput(f"{path}: no such {what}")
    if not p.is_file():
        raise BadInput(f"{path}: not a file")
    return p


def _load_trajectory(path: str):
    from .trajectory import Trajectory

    _existing_file(path, "trajectory file")
    try:
        return Trajectory.load(path)
    except Exception as error:  # noqa: BLE001 - h5py, numpy and zipfile raise many kinds for a file that is not one
        raise BadInput(f"{path}: cannot read it as a tumble trajectory (.h5 or .npz): {error}") from None


def _check_trajectory_path(path: str, option: str) -> Path:
    p = Path(path)
    if p.suffix.lower() not in TRAJECTORY_SUFFIXES:
        raise BadInput(f"{option} {path}: a trajectory file must end in .h5 (HDF5) or .npz, got {p.suffix!r}")
    return p


def _check_plot_path(path: str, option: str) -> Path:
    p = Path(path)
    supported = _plot_formats()
    if p.suffix.lower().lstrip(".") not in supported:
        raise BadInput(f"{option} {path}: the suffix picks the image format; use one of "
                       f"{', '.join('.' + s for s in sorted(supported))}")  # fmt: skip
    return p


def _plot_formats() -> set[str]:
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError:
        raise BadInput("plots need matplotlib: pip install 'tumble[plot]'") from None
    return set(FigureCanvasAgg(Figure()).get_supported_filetypes())


def _prepare_output(path: Path) -> Path:
    """Create the parent directory of an output file and make sure the file can be written, before anything runs
    (a run of ten minutes must not fail at its end); a directory in its place is bad input. An existing file is
    left as it is, a new one removed again."""
    if path.is_dir():
        raise BadInput(f"{path}: is a directory, not a file")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise BadInput(f"{path}: cannot create its directory: {error.strerror or error}") from None
    existed = path.exists()
    try:
        with open(path, "ab"):
            pass
    except OSError as error:
        raise BadInput(f"{path}: cannot write it: {error.strerror or error}") from None
    if not existed:
        path.unlink(missing_ok=True)
    return path


# --- tumble run -------------------------------------------------------------------------------------------------


def _chunk_frames(body_count: int, frames: int, hdf5: bool) -> int:
    from .recording import default_chunk_frames

    target = _TARGET_CHUNKS["h5" if hdf5 else "npz"]
    largest = default_chunk_frames(body_count)
    return int(max(1, min(largest, max(_MIN_CHUNK_FRAMES, math.ceil(frames / target)))))


def _scene_metadata(path: Path, loaded) -> dict:
    """What ``tumble run`` stores as the trajectory's ``scene`` metadata (``tumble view`` rebuilds from it)."""
    return {"file": path.name, "path": str(path.resolve()), "source": loaded.source}


def _cmd_run(args) -> int:
    import numpy as np

    from . import recording
    from .errors import SimulationError

    scene_path, loaded = _load_scene(args.scene)
    settings = loaded.run
    dt = args.dt if args.dt is not None else float(settings.dt)
    duration = args.duration if args.duration is not None else float(settings.duration)
    every = args.every if args.every is not None else int(settings.record_every)
    if not duration / dt <= MAX_STEPS:
        given = (f"--duration {duration:g}" if args.duration is not None else f"the scene's duration {duration:g} s",
                 f"--dt {dt:g}" if args.dt is not None else f"the scene's dt {dt:g} s")  # fmt: skip
        raise BadInput(f"{given[0]} at {given[1]} is {duration / dt:g} steps; a run takes at most {MAX_STEPS:.0e}")
    steps = round(duration / dt)
    if steps < 1:
        raise BadInput(f"--duration {duration:g} is shorter than one step of --dt {dt:g}")
    out = args.out if args.out is not None else settings.output
    out_path = _check_trajectory_path(out, "--out" if args.out else "recording.path") if out else None
    html_path = Path(args.html) if args.html else None
    plot_path = _check_plot_path(args.plot, "--plot") if args.plot else None
    for path in (out_path, html_path, plot_path):  # every check first: bad input writes nothing
        if path is not None:
            _prepare_output(path)

    world = loaded.world
    out_console, err_console = _consoles()
    start_step, start_time = world.step_count, world.time
    energy_0 = world.total_energy()
    with tempfile.TemporaryDirectory(prefix="tumble-run-") as scratch:
        path = out_path if out_path is not None else Path(scratch) / "run.h5"
        hdf5 = path.suffix.lower() != ".npz"
        chunk = _chunk_frames(world.model.body_count, steps // every + 1, hdf5)
        progress = _Progress(err_console, steps, start_step, duration, enabled=not args.quiet)
        failure = None
        need_frames = html_path is not None or plot_path is not None
        began = time.perf_counter()
        latch = _InterruptLatch()

        def each_chunk(world, writer) -> None:
            progress(world, writer)
            latch.check()

        try:
            with latch, progress, np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                trajectory = recording.record(world, duration, dt, path, every=every, chunk_frames=chunk,
                                              scene=_scene_metadata(scene_path, loaded), callback=each_chunk,
                                              load=need_frames)  # fmt: skip
        except SimulationError as error:
            failure = error
            trajectory = getattr(error, "trajectory", None)
        except KeyboardInterrupt as interrupt:
            done = world.step_count - start_step
            how = "terminated (SIGTERM)" if isinstance(interrupt, _Terminated) else "interrupted"
            _note(f"{how} at t = {world.time:.6g} s, after {done} of {steps} steps")
            if out_path is not None:
                _note(f"{out_path}: {_frames_kept(out_path)} (status 'interrupted')")
            return EXIT_TERMINATED if isinstance(interrupt, _Terminated) else EXIT_INTERRUPTED
        wall = time.perf_counter() - began

        if failure is not None:
            message = str(failure)
            if str(failure.body) not in message or str(failure.step) not in message:
                message = f"body {failure.body!r}, step {failure.step}: {message}"
            _error(f"simulation failed: {message}")
            if out_path is not None:
                _note(f"{out_path}: {_frames_kept(out_path)}, the last good step (status 'failed')")
        # After a failure the last frames may hold huge values: no overflow warnings while drawing them.
        with np.errstate(all="ignore") if failure is not None else contextlib.nullcontext():
            _write_outputs(trajectory, world, html_path, plot_path, f"{scene_path.stem} (tumble run)", args.max_frames)
        if out_path is not None and failure is None:
            _note(f"wrote {out_path}")

    done = world.step_count - start_step
    summary = {"dt": dt, "steps": done, "planned": steps, "sim_time": world.time - start_time, "wall": wall}
    _print_run_summary(out_console, world, scene_path, progress=progress, energy_0=energy_0,
                       failed=failure is not None, **summary)  # fmt: skip
    return EXIT_SIMULATION if failure is not None else EXIT_OK


def _frames_kept(path: Path) -> str:
    """What an interrupted recording holds, in words."""
    from .trajectory import Trajectory

    try:
        trajectory = Trajectory.load(path)
    except Exception as error:  # noqa: BLE001 - a report, not a check: say what went wrong and go on
        return f"could not be read back ({error})"
    if len(trajectory) == 0:
        return "holds no frames"
    return f"kept {len(trajectory)} frames, up to t = {trajectory.time[-1]:.6g} s"


def _write_outputs(trajectory, world, html_path, plot_path, title: str, max_frames) -> None:
    """The HTML replay and the energy plot of what was recorded, when asked for."""
    if trajectory is None or len(trajectory) == 0:
        return
    if html_path is not None:
        from . import viewer

        viewer.write_html(trajectory, html_path, world=world, title=title, max_frames=max_frames)
        _note(f"wrote {html_path}")
    if plot_path is not None:
        from . import plots

        plots.energy(trajectory, plot_path)
        _note(f"wrote {plot_path}")
        if any(name.startswith("vehicle/") for name in trajectory.channels):
            flight_path = plot_path.with_name(f"{plot_path.stem}_flight{plot_path.suffix}")
            plots.flight(trajectory, path=flight_path)
            _note(f"wrote {flight_path}")


def _print_run_summary(console, world, scene_path: Path, *, dt, steps, planned, sim_time, wall, progress, energy_0,
                       failed) -> None:  # fmt: skip
    from rich.table import Table

    rate, rate_note = progress.steps_per_second(steps, wall)
    energy_end = world.total_energy()
    drift = (energy_end - energy_0) / max(abs(energy_0), _TINY)
    bodies = world.bodies
    dynamic = [b for b in bodies if not b.is_static]
    sleeping = sum(1 for b in dynamic if b.sleeping)

    table = Table(
        title=_text(f"{scene_path.name}: {'FAILED' if failed else 'done'}"),
        title_justify="left",
        caption="energy drift: the relative change of the total (kinetic + potential) energy over the run; "
        "contacts, friction and damping remove energy, so a pile shows a negative drift",
        caption_justify="left",
    )
    table.add_column("quantity")
    table.add_column("value", justify="right")
    table.add_column("note")
    rows = [
        ("simulated time", f"{sim_time:.6g} s", "" if steps == planned else f"of {planned * dt:.6g} s planned"),
        ("steps", f"{steps}", f"dt = {dt:.6g} s"),
        ("wall time", f"{wall:.3g} s", "recording and writing included"),
        ("steps/s", f"{rate:.4g}", rate_note),
        ("real-time factor", f"{rate * dt:.4g}", "simulated seconds per wall-clock second"),
        ("energy drift", f"{drift:+.3e}", f"(E_end - E_0) / |E_0|: {energy_0:.6g} J -> {energy_end:.6g} J"),
        ("contacts", f"{len(world.contacts())}", "contact points in the last step"),
        ("sleeping bodies", f"{sleeping} / {len(dynamic)}", "dynamic bodies at rest"),
        ("joints", f"{len(world.joints)}", ""),
        ("state digest", world.state.digest()[:16], "world.state.digest(): equal on every machine for equal inputs"),
    ]
    for quantity, value, note in rows:
        table.add_row(_text(quantity), _text(value), _text(note))
    console.print(table)


# --- tumble info ------------------------------------------------------------------------------------------------


def _axis_label(column) -> str:
    """``+x``, ``-z``, … for a principal axis along a body axis, else its components."""
    import numpy as np

    k = int(np.argmax(np.abs(column)))
    if abs(abs(column[k]) - 1.0) < 1e-9:
        return ("+" if column[k] > 0 else "-") + "xyz"[k]
    return _vec(column, 3)


INFO_ROWS = 100  # rows of a table ``tumble info`` prints unless --all; a scene of 100 000 bodies lists the first


def _more(console, left_out: int, what: str) -> None:
    if left_out > 0:
        console.print(_text(f"... and {left_out} more {what} (tumble info --all lists every one)"))


def _cmd_info(args) -> int:
    from rich.table import Table

    from .mass import MassProperties

    scene_path, loaded = _load_scene(args.scene)
    world = loaded.world
    model = world.model
    console, _ = _consoles()

    description = loaded.source.get("description", "") if isinstance(loaded.source, dict) else ""
    console.print(_text(f"{scene_path.name}: {description.strip().splitlines()[0] if description.strip() else ''}"))

    shape_kinds: dict[int, list[str]] = {}
    for k, shape in enumerate(model.shapes):
        shape_kinds.setdefault(int(model.shape_body[k]), []).append(type(shape).__name__)

    bodies = Table(title=_text(f"bodies ({model.body_count})"), title_justify="left")
    for name, justify in (("#", "right"), ("name", "left"), ("kind", "left"), ("shape", "left"),
                          ("mass [kg]", "right"), ("COM [m] (world)", "left"),
                          ("principal moments [kg m²]", "left"), ("principal axes (body frame)", "left")):  # fmt: skip
        bodies.add_column(_text(name), justify=justify, no_wrap=name in ("name", "#"))
    listed = world.bodies if args.all else world.bodies[:INFO_ROWS]
    for i, body in enumerate(listed):
        kinds = shape_kinds.get(i, [])
        shape = "+".join(kinds) if len(kinds) <= 3 else f"{len(kinds)} shapes"
        if body.is_static:
            row = [str(i), body.name or "", "static", shape or "-", "-", _vec(body.position), "-", "-"]
        else:
            mp = MassProperties(model.body_mass[i], model.body_com_local[i], model.body_inertia_local[i])
            moments, axes = mp.principal()
            row = [str(i), body.name or "", "dynamic", shape or "(none)", _fmt(body.mass), _vec(body.center_of_mass),
                   _vec(moments), ", ".join(_axis_label(axes[:, j]) for j in range(3))]  # fmt: skip
        bodies.add_row(*map(_text, row))
    console.print(bodies)
    _more(console, model.body_count - len(listed), "bodies")

    joints = world.joints
    if joints:
        table = Table(title=_text(f"joints ({len(joints)})"), title_justify="left")
        for name in ("#", "kind", "body a", "body b", "anchor [m] (world)"):
            table.add_column(_text(name))
        for j, joint in enumerate(joints if args.all else joints[:INFO_ROWS]):
            b = joint.body_b
            label_a = joint.body_a.name or f"#{joint.body_a.index}"
            label_b = "world" if b is None else (b.name or f"#{b.index}")
            table.add_row(*map(_text, (j, joint.kind, label_a, label_b, _vec(joint.anchor_a))))
        console.print(table)
        _more(console, len(joints) - table.row_count, "joints")
    else:
        console.print(_text("joints: none"))
    drives = [] if world._joint_drives is None else world._joint_drives.drives
    if drives:  # a model file's actuators, driven by world.ctrl
        table = Table(title=_text(f"actuators ({len(drives)}, world.ctrl)"), title_justify="left")
        for name in ("#", "name", "joint", "gear", "gain", "bias", "ctrl range"):
            table.add_column(_text(name))
        for drive in drives if args.all else drives[:INFO_ROWS]:
            span = "-" if drive.ctrl_range is None else f"[{_fmt(drive.ctrl_range[0])}, {_fmt(drive.ctrl_range[1])}]"
            table.add_row(*map(_text, (drive.index, drive.name or "", f"#{drive.joint.index} {drive.joint.kind}",
                                       _fmt(drive.gear), _fmt(drive.gain), _vec(drive.bias), span)))  # fmt: skip
        console.print(table)
        _more(console, len(drives) - table.row_count, "actuators")

    run = loaded.run
    settings = Table(title="settings", title_justify="left")
    settings.add_column("setting")
    settings.add_column("value")
    integrator_used = world._params.resolve_integrator(model.has_constraints).name.lower()
    rows = [
        ("gravity [m/s²]", _vec(world.gravity)),
        ("integrator", f"{world.integrator} (uses {integrator_used})"),
        ("dt [s]", _fmt(run.dt, 6)),
        ("duration [s]", _fmt(run.duration, 6)),
        ("record every", str(run.record_every)),
        ("output", run.output or "-"),
    ]
    rows += [(f"solver.{key}", str(value)) for key, value in world.solver._asdict().items()]
    for key, value in rows:
        settings.add_row(_text(key), _text(value))
    console.print(settings)
    return EXIT_OK


# --- tumble view ------------------------------------------------------------------------------------------------


def _world_from_metadata(trajectory, source_name: str):
    """The world ``tumble run`` recorded, rebuilt from the scene stored in the file, or (None, why not)."""
    scene = trajectory.metadata.get("scene")
    if not isinstance(scene, dict) or not isinstance(scene.get("source"), dict):
        return None, f"{source_name} holds no scene description"
    from . import scene_file

    from_dict = getattr(scene_file, "from_dict", None)
    if from_dict is None:
        return None, "this tumble cannot rebuild a scene from a dict"
    base = Path(scene["path"]).parent if isinstance(scene.get("path"), str) else Path(".")
    try:
        from .models.mjcf import MJCFWarning

        with warnings.catch_warnings():  # a model file's notes were given when it was run
            warnings.simplefilter("ignore", MJCFWarning)
            loaded = from_dict(scene["source"], base=base, label=str(scene.get("file", "<stored scene>")))
    except (ValueError, TypeError) as error:  # SceneError is a ValueError
        return None, f"the scene stored in {source_name} does not build here: {str(error).splitlines()[0]}"
    return loaded.world, None


def _check_same_bodies(world, trajectory, what: str) -> None:
    if world.model.body_count != trajectory.body_count:
        raise BadInput(f"{what} has {world.model.body_count} bodies but the trajectory has {trajectory.body_count}; "
                       "pass the scene that recorded it")  # fmt: skip


def _cmd_view(args) -> int:
    from . import viewer

    trajectory = _load_trajectory(args.trajectory)
    if len(trajectory) == 0:
        raise BadInput(f"{args.trajectory}: holds no frames")
    out = _prepare_output(Path(args.output))
    world = None
    if args.scene is not None:
        world = _load_scene(args.scene)[1].world
        _check_same_bodies(world, trajectory, args.scene)
    else:
        world, why = _world_from_metadata(trajectory, Path(args.trajectory).name)
        if world is not None and world.model.body_count != trajectory.body_count:
            world, why = None, "the scene stored in the file does not match its frames"
        if world is None:
            _note(f"{why}: bodies are drawn as balls of their mass and inertia (pass --scene SCENE for the shapes)")
    title = args.title or f"{Path(args.trajectory).stem} (tumble view)"
    viewer.write_html(trajectory, out, world=world, title=title, max_frames=args.max_frames)
    _note(f"wrote {out} ({len(trajectory)} frames, {trajectory.body_count} bodies)")
    return EXIT_OK


# --- tumble plot ------------------------------------------------------------------------------------------------


def _plot_targets(what: list[str], output: str | None, trajectory_path: Path) -> dict[str, Path]:
    """The file each plot goes to: ``-o FILE.png`` for one plot (``FILE_<what>.png`` for several), ``-o DIR``
    (default: the trajectory's directory) for ``DIR/<trajectory>_<what>.png``."""
    if output is not None and Path(output).suffix and not Path(output).is_dir():
        target = _check_plot_path(output, "-o")
        if len(what) == 1:
            return {what[0]: target}
        return {w: target.with_name(f"{target.stem}_{w}{target.suffix}") for w in what}
    _plot_formats()  # matplotlib present?
    folder = Path(output) if output is not None else trajectory_path.parent
    return {w: folder / f"{trajectory_path.stem}_{w}.png" for w in what}


def _cmd_plot(args) -> int:
    from . import plots

    what = [w.strip() for w in args.what.split(",") if w.strip()]
    bad = [w for w in what if w not in PLOT_KINDS]
    if not what or bad:
        raise BadInput(f"--what {args.what}: choose from {', '.join(PLOT_KINDS)} (comma-separated)")
    trajectory = _load_trajectory(args.trajectory)
    if len(trajectory) == 0:
        raise BadInput(f"{args.trajectory}: holds no frames")
    targets = _plot_targets(what, args.output, Path(args.trajectory))
    bodies = None
    if args.bodies:
        bodies = [b.strip() for b in args.bodies.split(",") if b.strip()]
        bodies = [int(b) if b.isdigit() else b for b in bodies]
    for kind, target in targets.items():
        _prepare_output(target)
        try:
            if kind == "energy":
                plots.energy(trajectory, target)
            elif kind == "momentum":
                plots.momentum(trajectory, target)
            elif kind == "omega":
                plots.angular_velocity(trajectory, bodies=bodies, path=target)
            elif kind == "flight":
                plots.flight(trajectory, vehicle=bodies[0] if bodies else None, path=target)
            else:
                plots.paths(trajectory, bodies=bodies, path=target)
        except (KeyError, IndexError, ValueError) as error:
            raise BadInput(f"{kind}: {str(error).strip(chr(34) + chr(39))}") from None
        _note(f"wrote {target}")
    return EXIT_OK


# --- tumble examples --------------------------------------------------------------------------------------------


def _read_raw(path: Path) -> dict:
    import tomllib

    text = path.read_text(encoding="utf-8")
    data = json.loads(text) if path.suffix == ".json" else tomllib.loads(text)
    return data if isinstance(data, dict) else {}


def _mesh_files(data) -> list[str]:
    """Relative mesh paths a scene refers to (``shape = {type = "mesh", path = ...}``), to copy beside it."""
    found: list[str] = []
    if isinstance(data, dict):
        if data.get("type") == "mesh" and isinstance(data.get("path"), str):
            found.append(data["path"])
        for value in data.values():
            found += _mesh_files(value)
    elif isinstance(data, list):
        for value in data:
            found += _mesh_files(value)
    return found


def _cmd_warmup(args) -> int:
    from .warmup import default_jobs, warmup

    jobs = args.jobs or default_jobs()
    began = time.perf_counter()

    def done(result, count, total) -> None:
        if result.error is not None:
            _error(f"warmup of {result.name} failed: {result.error}")
        elif not args.quiet:
            _note(f"warmed {result.name} ({count}/{total}, {result.seconds:.1f} s)")

    results = warmup(jobs, on_done=done)
    failed = [r for r in results if r.error is not None]
    if not args.quiet or failed:
        _note(f"{len(results) - len(failed)} of {len(results)} warmed (the scenes and the articulation kernels) in "
              f"{time.perf_counter() - began:.1f} s "
              f"with {jobs} process{'es' if jobs > 1 else ''} at a time")  # fmt: skip
    return EXIT_SIMULATION if failed else EXIT_OK


def _cmd_examples(args) -> int:
    from rich.table import Table

    console, _ = _consoles()
    files = _shipped_scenes()
    table = Table(title=_text(f"scene files shipped with tumble ({len(files)})"), title_justify="left")
    table.add_column("name", no_wrap=True)
    table.add_column("description")
    raw = {}
    for path in files:
        try:
            raw[path] = _read_raw(path)
            description = str(raw[path].get("description", "")).strip()
        except (OSError, ValueError) as error:
            raw[path], description = {}, f"(unreadable: {error})"
        table.add_row(_text(path.name), _text(description.splitlines()[0] if description else ""))
    console.print(table)
    if not args.copy:
        if files:
            console.print(
                _text(f"run one by name: tumble run {files[0].stem}   (copy them: tumble examples --copy DIR)")
            )
        return EXIT_OK

    target = Path(args.copy)
    if target.exists() and not target.is_dir():
        raise BadInput(f"--copy {target}: exists and is not a directory")
    target.mkdir(parents=True, exist_ok=True)
    copied, skipped = 0, []
    for path in files:
        items = [(path, target / path.name)]
        for relative in _mesh_files(raw[path]):
            source = (path.parent / relative).resolve()
            if source.is_file() and not Path(relative).is_absolute() and ".." not in Path(relative).parts:
                items.append((source, target / relative))
        for source, destination in items:
            if destination.exists() and not args.force:
                skipped.append(destination.name)
                continue
            destination.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, destination)
            copied += 1
    _note(f"copied {copied} files to {target}" + (f" (kept existing: {', '.join(skipped)}; --force overwrites)"
                                                  if skipped else ""))  # fmt: skip
    return EXIT_OK


# --- tumble bench -----------------------------------------------------------------------------------------------


def _find_benchmarks():
    """``benchmarks.run`` from the repository: the current directory or a parent, or the checkout tumble is
    installed from (editable install). None when there is no repository at hand."""
    import importlib

    candidates = [Path.cwd(), *Path.cwd().parents, Path(__file__).resolve().parents[2]]
    for folder in candidates:
        if (folder / "benchmarks" / "run.py").is_file():
            if str(folder) not in sys.path:
                sys.path.insert(0, str(folder))
            break
    try:
        return importlib.import_module("benchmarks.run")
    except ModuleNotFoundError as error:
        if error.name in ("benchmarks", "benchmarks.run"):
            return None
        raise BadInput(f"the benchmarks need {error.name!r}: pip install -e '.[bench]' ({error})") from None


def _cmd_bench(args) -> int:
    module = _find_benchmarks()
    if module is None:
        raise BadInput("the benchmarks live in the repository (benchmarks/run.py), not in the installed package; "
                       "run tumble bench inside a checkout of tumble")  # fmt: skip
    argv = []
    if args.quick:
        argv.append("--quick")
    for name in args.only or []:
        argv += ["--only", name]
    if args.csv is not None:
        argv += ["--csv", args.csv]
    if args.repeat is not None:
        argv += ["--repeat", str(args.repeat)]
    if args.machine is not None:
        argv += ["--machine", args.machine]
    return int(module.main(argv) or 0)


# --- the parser -------------------------------------------------------------------------------------------------


class _Parser(argparse.ArgumentParser):
    """argparse that reports a bad argument in one line (exit status 2), pointing at ``--help``."""

    def error(self, message: str):  # noqa: D401
        _error(f"{self.prog}: {message} (see {self.prog} --help)")
        raise SystemExit(EXIT_BAD_INPUT)


def _version() -> str:
    import platform

    from ._version import __version__

    return f"tumble {__version__} (Python {platform.python_version()})"


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="tumble", description="tumble: rigid-body physics. Run scene files, inspect them, "
                     "replay and plot trajectories.", epilog="Exit status: 0 done, 1 simulation error, 2 bad input, "
                     "130 interrupted, 143 terminated. See docs/cli.md.")  # fmt: skip
    parser.add_argument("--version", action="version", version=_version())
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    run = commands.add_parser("run", help="run a scene file, record it, write the replay and the energy plot",
                              description="Run a scene file (TOML or JSON) with the recorder: frames are written "
                              "in chunks as the run goes. Prints a summary table at the end.")  # fmt: skip
    run.add_argument("scene", metavar="SCENE", help="the scene file (.toml or .json)")
    run.add_argument("--duration", type=_positive_float, metavar="S", help="simulated seconds (default: the scene's)")
    run.add_argument("--dt", type=_positive_float, metavar="S", help="the step [s] (default: the scene's)")
    run.add_argument("--every", type=_positive_int, metavar="N", help="record one frame every N steps "
                     "(default: the scene's recording.every)")  # fmt: skip
    run.add_argument("--out", metavar="FILE", help="the trajectory file, .h5 (HDF5) or .npz (default: the scene's "
                     "recording.path; else a temporary file, deleted at the end)")  # fmt: skip
    run.add_argument("--html", metavar="FILE", help="write the HTML replay here")
    run.add_argument("--plot", metavar="FILE", help="write the energy plot here (.png, .svg, .pdf, ...)")
    run.add_argument("--max-frames", type=_frames_limit, metavar="N", help="keep at most N frames in the replay")
    run.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    run.set_defaults(handler=_cmd_run)

    from .cli_batch import add_command as add_batch_command

    add_batch_command(commands, _positive_int, _positive_float)

    from .cli_sweep import add_command as add_sweep_command

    add_sweep_command(commands, _positive_int, _positive_float)

    info = commands.add_parser("info", help="the bodies, joints and settings of a scene file",
                               description="Load a scene file and print its bodies (mass, centre of mass, principal "
                               "moments and axes), joints and settings.")  # fmt: skip
    info.add_argument("scene", metavar="SCENE")
    info.add_argument("--all", action="store_true", help=f"list every body and joint (default: the first {INFO_ROWS})")
    info.set_defaults(handler=_cmd_info)

    view = commands.add_parser("view", help="write the HTML replay of a trajectory file",
                               description="Write the self-contained HTML replay of a recorded trajectory. The "
                               "shapes come from --scene, else from the scene tumble run stored in the file, else "
                               "each body is drawn as a ball of its mass and inertia.")  # fmt: skip
    view.add_argument("trajectory", metavar="TRAJ", help="a trajectory file (.h5 or .npz)")
    view.add_argument("-o", "--output", metavar="FILE", required=True, help="the .html file to write")
    view.add_argument("--scene", metavar="SCENE", help="rebuild the shapes from this scene file")
    view.add_argument("--title", help="the page title")
    view.add_argument("--max-frames", type=_frames_limit, metavar="N", help="keep at most N frames")
    view.set_defaults(handler=_cmd_view)

    plot = commands.add_parser("plot", help="plot a trajectory file", description="Plot a recorded trajectory.")
    plot.add_argument("trajectory", metavar="TRAJ", help="a trajectory file (.h5 or .npz)")
    plot.add_argument("--what", default="energy", help=f"comma-separated, from {','.join(PLOT_KINDS)} "
                      "(default: energy)")  # fmt: skip
    plot.add_argument("-o", "--output", metavar="DIR|FILE", help="an image file (FILE_<what>.png for several plots) "
                      "or a directory (default: beside the trajectory, <traj>_<what>.png)")  # fmt: skip
    plot.add_argument("--bodies", metavar="NAMES", help="comma-separated names or indices for omega and paths "
                      "(default: the first 8 dynamic bodies)")  # fmt: skip
    plot.set_defaults(handler=_cmd_plot)

    examples = commands.add_parser("examples", help="list the shipped scene files, or copy them",
                                   description="List the scene files shipped with tumble; --copy DIR copies them "
                                   "(and the mesh files they use) to DIR.")  # fmt: skip
    examples.add_argument("--copy", metavar="DIR", help="copy the scene files here")
    examples.add_argument("--force", action="store_true", help="overwrite files already in DIR")
    examples.set_defaults(handler=_cmd_examples)

    warm = commands.add_parser("warmup", help="compile the kernels before the first run (make install does)",
                               description="Step every shipped scene a few times in parallel processes that share "
                               "Numba's cache, so that later runs start at once.")  # fmt: skip
    warm.add_argument("--jobs", "-j", type=_positive_int, metavar="N", help="processes at a time (default: one "
                      "per core)")  # fmt: skip
    warm.add_argument("--quiet", "-q", action="store_true", help="print only failures")
    warm.set_defaults(handler=_cmd_warmup)

    bench = commands.add_parser(
        "bench",
        help="run the benchmarks (from a checkout of the repository)",
        description="Run benchmarks/run.py of the repository (python -m benchmarks.run).",
    )
    bench.add_argument("--quick", action="store_true", help="tiny sizes, a smoke test")
    bench.add_argument("--only", action="append", metavar="NAME", help="run only this benchmark (repeatable)")
    bench.add_argument("--csv", nargs="?", const="benchmarks/results", metavar="DIR", help="write CSV results")
    bench.add_argument("--repeat", type=_positive_int, metavar="N", help="timed repeats (the best is kept)")
    bench.add_argument("--machine", help="the results folder's name")
    bench.set_defaults(handler=_cmd_bench)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (the ``tumble`` entry point passes it to ``sys.exit``)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if getattr(args, "handler", None) is None:
            parser.print_help()
            return EXIT_BAD_INPUT
        with _InterruptLatch():  # SIGTERM as Ctrl-C in every command (a run takes its own latch within)
            return args.handler(args)
    except BadInput as error:
        _error(str(error))
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as interrupt:
        if isinstance(interrupt, _Terminated):
            _note("terminated (SIGTERM)")
            return EXIT_TERMINATED
        _note("interrupted")
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # `tumble info big.toml | head`: stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except _PipeClosed:
        return EXIT_OK
    except OSError as error:  # a file that could not be written after all (a full disk, a file system gone)
        where = f"{error.filename}: " if error.filename else ""
        _error(f"{where}cannot write it: {error.strerror or error}")
        return EXIT_BAD_INPUT


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
