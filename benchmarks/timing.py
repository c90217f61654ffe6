"""What the many-copies benchmarks share (``batch.py``, ``envs.py``): the best of repeated timings, and a command
line of ``--quick`` and ``--repeat`` that prints one row per line."""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

__all__ = ["best_time", "sizes_from_args", "show_row"]


def best_time(run, repeat: int, budget: float = 10.0) -> float:
    """The best of ``repeat`` timed runs after an untimed one; fewer once the timed runs pass ``budget`` seconds."""
    run()  # compile, or load from the cache
    best, spent = math.inf, 0.0
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        elapsed = time.perf_counter() - start
        best, spent = min(best, elapsed), spent + elapsed
        if spent > budget:
            break
    return best


def show_row(row: dict) -> None:
    """Print a result row, floats to 4 significant digits."""
    print({k: (f"{v:.4g}" if isinstance(v, float) else v) for k, v in row.items()}, flush=True)


def sizes_from_args(argv, prog: str, doc: str, full, quick):
    """The sizes that ``--quick`` and ``--repeat N`` ask of ``python -m <prog>`` (dataclasses with ``repeat``)."""
    parser = argparse.ArgumentParser(prog=prog, description=doc.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="tiny sizes (a smoke test)")
    parser.add_argument("--repeat", type=int, help="timed repeats (best is kept)")
    args = parser.parse_args(argv)
    sizes = quick if args.quick else full
    return sizes if args.repeat is None else dataclasses.replace(sizes, repeat=max(1, args.repeat))
