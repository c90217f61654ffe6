"""``tumble batch SCENE -n N``: step N copies of a scene's world as one :class:`~tumble.Batch` and report the
throughput (body-steps per second). A command of ``tumble.cli`` in its own module (the CLI splits by command; what
the commands share is in ``tumble.cli_common``).
"""

from __future__ import annotations

import math
import time

import numpy as np

from .cli_common import (
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
    _Progress,
    _Terminated,
    _text,
)

__all__ = ["add_command", "run_batch"]

CHUNKS = 100  # the progress bar moves (and Ctrl-C is answered) between chunks of about steps / CHUNKS


def add_command(commands, positive_int, positive_float) -> None:
    """Register ``tumble batch`` on the CLI's subparsers."""
    batch = commands.add_parser("batch", help="step N copies of a scene at once and report body-steps/s",
                                description="Step N copies of the scene's world as one tumble.Batch (all copies in "
                                "each compiled call, one block of copies per core) and print the throughput. "
                                "Nothing is recorded.")  # fmt: skip
    batch.add_argument("scene", metavar="SCENE", help="the scene file (.toml or .json), or a shipped scene's name")
    batch.add_argument("-n", "--copies", type=positive_int, required=True, metavar="N", help="the number of copies")
    batch.add_argument("--duration", type=positive_float, metavar="S", help="simulated seconds (default: the scene's)")
    batch.add_argument("--dt", type=positive_float, metavar="S", help="the step [s] (default: the scene's)")
    batch.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    batch.set_defaults(handler=run_batch)


def run_batch(args) -> int:
    from . import Batch
    from .errors import SimulationError

    _, loaded = _load_scene(args.scene)
    dt = args.dt if args.dt is not None else float(loaded.run.dt)
    duration = args.duration if args.duration is not None else float(loaded.run.duration)
    steps = round(duration / dt)
    if steps < 1:
        raise BadInput(f"--duration {duration:g} is shorter than one step of --dt {dt:g}")
    try:
        batch = Batch(loaded.world, args.copies)
    except ValueError as error:
        raise BadInput(f"{args.scene}: {error}") from None
    bodies = int(loaded.world.model.body_is_dynamic.sum())
    out_console, err_console = _consoles()
    progress = _Progress(err_console, steps, batch.step_count, duration, enabled=not args.quiet)
    chunk = max(1, math.ceil(steps / CHUNKS))
    began, done, failure = time.perf_counter(), 0, None
    try:
        with _InterruptLatch() as latch, progress, np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            while done < steps:
                take = min(chunk, steps - done)
                batch.step(dt, steps=take)
                done += take
                progress(batch, None)
                latch.check()
    except SimulationError as error:
        failure = error
    except KeyboardInterrupt as interrupt:
        how = "terminated (SIGTERM)" if isinstance(interrupt, _Terminated) else "interrupted"
        _note(f"{how} at t = {batch.time:.6g} s, after {done} of {steps} steps")
        return EXIT_TERMINATED if isinstance(interrupt, _Terminated) else EXIT_INTERRUPTED
    wall = time.perf_counter() - began
    if failure is not None:
        _error(f"simulation failed: {failure}")
    _print_summary(out_console, args, batch, bodies, dt, done, steps, wall, progress, failure is not None)
    return EXIT_SIMULATION if failure is not None else EXIT_OK


def _print_summary(console, args, batch, bodies, dt, done, steps, wall, progress, failed) -> None:
    from rich.table import Table

    rate, note = progress.steps_per_second(done, wall)
    table = Table(title=_text(f"{args.scene}: {args.copies} copies, {'FAILED' if failed else 'done'}"),
                  title_justify="left")  # fmt: skip
    table.add_column("quantity")
    table.add_column("value", justify="right")
    table.add_column("note")
    rows = [
        ("copies", f"{batch.n}", f"{bodies} dynamic bodies each, {len(batch._blocks)} block(s) of copies"),
        ("steps", f"{done}", f"dt = {dt:.6g} s" + ("" if done == steps else f", of {steps} planned")),
        ("wall time", f"{wall:.3g} s", ""),
        ("body-steps/s", f"{rate * batch.n * bodies:.4g}", note),
        ("copy-steps/s", f"{rate * batch.n:.4g}", "steps of one copy per wall-clock second"),
        ("real-time factor", f"{rate * dt * batch.n:.4g}", "simulated seconds of all copies per wall-clock second"),
    ]
    for quantity, value, text in rows:
        table.add_row(_text(quantity), _text(value), _text(text))
    console.print(table)
