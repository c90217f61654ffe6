"""``tumble sweep SCENE --param PLACE=VALUES ... --out DIR``: run a scene once per combination of values (or per
random draw) on a process pool or a Dask cluster, through :func:`tumble.ensemble.run`. A command of ``tumble.cli``
in its own module (what the commands share is in ``tumble.cli_common``).
"""

from __future__ import annotations

import math
import re

from .cli_common import (
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_SIMULATION,
    EXIT_TERMINATED,
    BadInput,
    _consoles,
    _note,
    _scene_path,
    _Terminated,
    _text,
)

__all__ = ["add_command", "run_sweep", "parse_param"]

SHOWN_ROWS = 20  # the table printed; results.csv holds every row
_INTEGER = re.compile(r"[+-]?\d+")
_SHOWN_SUMMARY = ("energy_change", "max_displacement", "max_speed")


def add_command(commands, positive_int, positive_float) -> None:
    """Register ``tumble sweep`` on the CLI's subparsers."""
    sweep = commands.add_parser("sweep", help="run a scene for every combination of parameter values",
                                description="Run the scene once per member: every combination of the --param "
                                "values (a grid), or --samples random draws. Each member's trajectory goes to "
                                "DIR/member_NNNNN.h5 and the table of results to DIR/results.csv; running the same "
                                "command again runs only the members not finished yet.",
                                epilog="VALUES: LOW:HIGH:N (N values from LOW to HIGH), A,B,C (these), or A. With "
                                "--samples: LOW:HIGH (uniform) or A,B,C (one of them).")  # fmt: skip
    sweep.add_argument("scene", metavar="SCENE", help="the scene file (.toml or .json), or a shipped scene's name")
    sweep.add_argument("--param", "-p", action="append", required=True, metavar="PLACE=VALUES",
                       help="a place in the scene and its values: bodies[0].friction=0.1:0.9:9, "
                       "world.gravity[2]=-9.81,-1.62 (repeatable)")  # fmt: skip
    sweep.add_argument("--out", required=True, metavar="DIR", help="the folder of the trajectories and results.csv")
    sweep.add_argument("--samples", type=positive_int, metavar="K", help="K random members instead of the grid")
    sweep.add_argument("--seed", type=int, default=0, metavar="S", help="the random draws' seed (default 0)")
    where = sweep.add_mutually_exclusive_group()
    where.add_argument("--workers", "-j", type=positive_int, metavar="N", help="local worker processes (default: "
                       "one per core)")  # fmt: skip
    where.add_argument("--scheduler", metavar="ADDRESS", help="run on this Dask scheduler (tcp://host:8786) instead")
    sweep.add_argument("--duration", type=positive_float, metavar="S", help="simulated seconds (default: the scene's)")
    sweep.add_argument("--dt", type=positive_float, metavar="S", help="the step [s] (default: the scene's)")
    sweep.add_argument("--every", type=positive_int, metavar="N", help="record one frame every N steps (default: the "
                       "scene's recording.every)")  # fmt: skip
    sweep.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    sweep.set_defaults(handler=run_sweep)


def _value(text: str):
    """A value as a scene holds it: an integer, a number, true/false, else the text."""
    text = text.strip()
    if _INTEGER.fullmatch(text):
        return int(text)
    try:
        value = float(text)
    except ValueError:
        return {"true": True, "false": False}.get(text.lower(), text)
    if not math.isfinite(value):
        raise BadInput(f"--param: {text!r} is not a finite number")
    return value


def parse_param(text: str, sampled: bool) -> tuple[str, str, object]:
    """``"PLACE=VALUES"`` → ``(place, "values" | "uniform", values or (low, high))``."""
    place, equals, spec = text.partition("=")
    place = place.strip()
    if not equals or not place or not spec.strip():
        raise BadInput(f"--param {text!r}: write PLACE=VALUES, like bodies[0].friction=0.1:0.9:9")
    if ":" in spec:
        parts = [_value(part) for part in spec.split(":")]
        numbers = all(isinstance(p, (int, float)) and not isinstance(p, bool) for p in parts)
        if sampled:
            if len(parts) != 2 or not numbers or not parts[0] < parts[1]:
                raise BadInput(f"--param {text!r}: with --samples a range is LOW:HIGH (numbers, LOW < HIGH)")
            return place, "uniform", (float(parts[0]), float(parts[1]))
        count = parts[2] if len(parts) == 3 else None
        if not numbers or isinstance(count, float) or count is None or count < 1:
            raise BadInput(f"--param {text!r}: a range is LOW:HIGH:N, N values from LOW to HIGH (N a whole number "
                           ">= 1)")  # fmt: skip
        low, high = parts[0], parts[1]
        step = (high - low) / (count - 1) if count > 1 else 0.0
        values = [low + k * step for k in range(count - 1)] + [high] if count > 1 else [low]
        whole = isinstance(low, int) and isinstance(high, int) and float(step).is_integer()
        return place, "values", [int(round(v)) if whole else float(v) for v in values]
    return place, "values", [_value(part) for part in spec.split(",")]


def _members(args) -> list[dict]:
    from . import ensemble

    axes, uniform = {}, {}
    for text in args.param:
        place, kind, values = parse_param(text, args.samples is not None)
        if place in axes or place in uniform:
            raise BadInput(f"--param: {place} is given twice")
        (uniform if kind == "uniform" else axes)[place] = values
    if args.samples is None:
        return ensemble.grid(axes)
    return ensemble.sample(args.samples, seed=args.seed, uniform=uniform, choice=axes)


def run_sweep(args) -> int:
    from . import ensemble
    from .ensemble.executors import dask_client

    path = _scene_path(args.scene)
    members = _members(args)
    client = None
    try:
        client = dask_client(args.scheduler, "--scheduler") if args.scheduler else None
        table = ensemble.run(path, members, args.duration, args.dt, args.out, executor=client, workers=args.workers,
                             record_every=args.every, progress=not args.quiet)  # fmt: skip
    except (ValueError, TypeError) as error:
        raise BadInput(_as_options(str(error))) from None
    except KeyboardInterrupt as interrupt:
        how = "terminated (SIGTERM)" if isinstance(interrupt, _Terminated) else "interrupted"
        _note(f"{how}: the members finished so far are kept in {args.out}; the same command runs the rest")
        return EXIT_TERMINATED if isinstance(interrupt, _Terminated) else EXIT_INTERRUPTED
    finally:
        if client is not None:
            client.close()
    rows = table.to_dict("records") if hasattr(table, "to_dict") else table
    out_console, _ = _consoles()
    _print_table(out_console, args, rows, list(members[0]))
    failed = sum(row["status"] != "done" for row in rows)
    return EXIT_SIMULATION if failed else EXIT_OK


def _as_options(message: str) -> str:
    """ensemble.run's message in the command's words: ``out_dir`` is ``--out``, a member's ``params[k]`` is
    ``--param`` (the message names the place)."""
    message = re.sub(r"^out_dir\b", "--out", message)
    return re.sub(r"^params\[\d+\]:", "--param:", message)


def _cell(value) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def _print_table(console, args, rows: list[dict], places: list[str]) -> None:
    from rich.table import Table

    from .ensemble import RESULTS_FILE

    failed = sum(row["status"] != "done" for row in rows)
    reused = sum(bool(row["reused"]) for row in rows)
    title = (f"{args.scene}: {len(rows)} members, {len(rows) - failed} done, {failed} failed"
             + (f" ({reused} from an earlier run)" if reused else ""))  # fmt: skip
    console.print(_text(title), soft_wrap=True)  # one line, not a title wrapped to the table's width
    table = Table()
    columns = ["member", *places, "status", *_SHOWN_SUMMARY, "wall_s"]
    for name in columns:
        table.add_column(_text(name), justify="left" if name == "status" else "right")
    if failed:
        table.add_column("error")
    for row in rows[:SHOWN_ROWS]:
        cells = [_cell(row.get(name)) for name in columns]
        if failed:
            cells.append(_cell(row.get("error")))
        table.add_row(*(_text(cell) for cell in cells))
    console.print(table)
    more = f"{len(rows) - SHOWN_ROWS} more rows: " if len(rows) > SHOWN_ROWS else ""
    console.print(_text(f"{more}every row in {args.out}/{RESULTS_FILE}"), soft_wrap=True)
