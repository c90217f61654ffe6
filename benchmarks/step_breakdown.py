"""Where a ``world.step()`` call's time goes (issue 46): the call, the same step inside ``simulate``, and the entry into
the runner's compiled loop (a call of it for no step at all, with the arguments the runner passes); the Python of the
call is the rest. Beside them, the arrays compiled code allocates (and frees) in a step, counted by Numba's runtime:
each costs a ``malloc``, a ``free`` and atomic reference counts. Internals are called by name: this is a measurement
of them, not an API.

Run from the repository root:

    python -m benchmarks.step_breakdown
"""

from __future__ import annotations

import time

from numba.core.runtime import _nrt_python

from tumble import runner

from .contact_steps import DT, box_on_a_plane, one_free_body


def _microseconds(call, count: int, repeat: int = 5) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(count):
            call()
        best = min(best, (time.perf_counter() - start) / count)
    return 1e6 * best


def _entry_call(world):
    """A call of the runner's compiled loop for no step, with the handle the world's last step kept."""
    record, scratch = world._scratch.compiled[1].record, world._scratch
    if world._model.has_constraints:
        substeps = world._params.solver.substeps_for(DT)
        return lambda: runner._plain_contact_loop(0, record, scratch.contact_count, 0, DT, substeps, 0, 0, 0.0, 0)
    bodies = world._state.body_count
    return lambda: runner._plain_steps(0, record, DT, 0, 0, 0, 0, 0, bodies, 0.0, 0)


def _allocations_per_step(world, steps: int = 100) -> float:
    """The arrays compiled code allocates in one ``world.step`` (Numba's runtime counts them while asked to)."""
    _nrt_python.memsys_enable_stats()
    try:
        before = _nrt_python.memsys_get_stats_alloc()
        for _ in range(steps):
            world.step(DT)
        return (_nrt_python.memsys_get_stats_alloc() - before) / steps
    finally:
        _nrt_python.memsys_disable_stats()


def breakdown() -> list[dict]:
    """One row per scene: ``step_us``, ``simulate_us``, ``entry_us``, ``python_us``, ``allocations``."""
    rows = []
    for scene, make in (("one free body", one_free_body), ("box on a plane", box_on_a_plane)):
        world = make()
        world.step(DT)
        step = _microseconds(lambda world=world: world.step(DT), 3000)
        other = make()
        other.step(DT)
        start = time.perf_counter()
        other.simulate(3000 * DT, DT, record_every=3000)
        inside = 1e6 * (time.perf_counter() - start) / 3000
        entry = _microseconds(_entry_call(world), 20000)
        rows.append({"scene": scene, "step_us": step, "simulate_us": inside, "entry_us": entry,
                     "python_us": step - inside - entry, "allocations": _allocations_per_step(world)})  # fmt: skip
    return rows


if __name__ == "__main__":
    for row in breakdown():
        print(", ".join(f"{key} {value:.2f}" if isinstance(value, float) else str(value) for key, value in row.items()))
