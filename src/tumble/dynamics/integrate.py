"""Free motion of every dynamic body over ``n`` steps, with recording and a guard against non-finite values.

Without contacts or joints the bodies do not interact, so each body is carried through all ``n`` steps in
registers before the next one (body-major order). That is cache friendly, lets the bodies run in parallel
with each row written by one thread only, and gives bit-identical results in any order or thread count.

Large calls split the bodies into one contiguous block per core and run the same kernel on each block in a
thread (the kernel releases the GIL). Set ``TUMBLE_THREADS=1`` to stay on one thread (``auto``, unset or empty:
one per core; anything else is warned about and read as ``auto``).

If a body's state becomes non-finite, its row keeps the last good values and the kernel reports the first
failing step; :func:`advance_free_bodies` then restores every body to where it stood before the call and
replays exactly the steps that all bodies completed, so the world stops at its last good state.
"""

from __future__ import annotations

import contextlib
import math
import os
import warnings
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

import numpy as np

from .._jit import inline, kernel
from ..math3d import add_scaled, is_finite3, load3, load4, load33, quat_is_finite, store3, store4
from ..model import Model
from ..params import Integrator
from ..state import State
from .free_motion import euler_step, flies_freely, flight_step, midpoint_step, rk4_step, spin_turn, symplectic_step

__all__ = ["Recording", "advance_free_bodies", "PARALLEL_MIN_WORK", "thread_count", "threads", "using_threads"]

# Below this many body-steps per call the threads cost more than they save (measured: one body for 20 000
# steps ran 5 % slower split across threads).
PARALLEL_MIN_WORK = 200_000


def thread_count(setting: str | None, cores: int | None) -> int:
    """The threads ``TUMBLE_THREADS=setting`` asks for on ``cores`` cores: an integer >= 1 (at most one per
    core), or one per core for ``auto``, unset or empty; anything else warns and falls back to one per core."""
    cores = max(1, cores or 1)
    text = (setting or "").strip()
    if text.lower() in ("", "auto"):
        return cores
    try:
        asked = int(text)
    except ValueError:
        asked = 0
    if asked < 1:
        warnings.warn(
            f"TUMBLE_THREADS={setting!r} is not a number of threads >= 1 or 'auto'; using one per core ({cores})",
            RuntimeWarning,
            stacklevel=2,
        )
        return cores
    return min(asked, cores)


_THREADS = thread_count(os.environ.get("TUMBLE_THREADS"), os.cpu_count())
_POOL: ThreadPoolExecutor | None = None
_POOL_SIZE = 0


class Recording(NamedTuple):
    """Frames written every ``record_every`` steps: (frames, n, 3|4) arrays; COM positions."""

    pos: np.ndarray
    quat: np.ndarray
    linvel: np.ndarray
    angmom: np.ndarray


def empty_recording(body_count: int) -> Recording:
    return Recording(
        np.empty((0, body_count, 3)), np.empty((0, body_count, 4)),
        np.empty((0, body_count, 3)), np.empty((0, body_count, 3)),
    )  # fmt: skip


@inline(into_callers=True)
def _advance_body(i, bodies, gravity, force, torque, acts, pos, quat, linvel, angmom, rec, h, n_steps, method,
                  record_every):  # fmt: skip
    """Carry body ``i`` through ``n_steps``; return the index of the failing step, or -1.

    Compiled into its callers (the row loop, ``flight.native``), and its steps take the body's constants and state as
    tuples, not the arrays they come from: a compiled call reference-counts every array it receives (atomic
    operations), which cost 1 µs a body and call before the first step (4096 bodies: 4.1 ms a call, 1.6 ms since;
    one step of their physics takes 0.3 ms). A body without actuators runs the steps compiled with ``acts=None``, in
    which they cost nothing.
    """
    # Gravity and the constant loads act in every step; applied loads in the first step only.
    weight = add_scaled(load3(bodies.constant_force, i), (gravity[0], gravity[1], gravity[2]), bodies.mass[i])
    body = (bodies.inv_mass[i], load33(bodies.inertia_local, i), load33(bodies.inv_inertia_local, i),
            bodies.linear_damping[i], bodies.angular_damping[i], weight, load3(bodies.constant_torque, i),
            load3(force, i), load3(torque, i))  # fmt: skip
    start = (load3(pos, i), load4(quat, i), load3(linvel, i), load3(angmom, i))
    if acts.driven[i]:
        failed, x, q, v, l = _body_steps(i, body, start, acts, rec, h, n_steps, method, record_every)
    else:
        failed, x, q, v, l = _body_steps(i, body, start, None, rec, h, n_steps, method, record_every)
    store3(pos, i, x)
    store4(quat, i, q)
    store3(linvel, i, v)
    store3(angmom, i, l)
    return failed


@inline(into_callers=True)
def _body_steps(i, body, start, acts, rec, h, n_steps, method, record_every):
    """The steps of :func:`_advance_body` from the state ``start``, with its actuators ``acts`` or ``None``: the
    failing step (or -1) and the last good state."""
    inv_m, inertia, inv_inertia, c_lin, c_ang, weight, steady_torque, applied_force, applied_torque = body
    x, q, v, l = start
    failed = -1
    turn, turn_for = (1.0, 0.0, 0.0, 0.0), (math.nan, math.nan, math.nan)  # exp(½ h ω) of the flight, and its L
    for s in range(n_steps):
        f = (weight[0] + applied_force[0], weight[1] + applied_force[1], weight[2] + applied_force[2])
        t = (steady_torque[0] + applied_torque[0], steady_torque[1] + applied_torque[1],
             steady_torque[2] + applied_torque[2])  # fmt: skip
        if s > 0:
            f = weight
            t = steady_torque
        # method: an Integrator code; 4 (auto) flies a body exactly where its motion has a closed form, else RK4.
        if method == 4 and acts is None and flies_freely(t, c_lin, c_ang, inv_inertia, l):
            if l[0] != turn_for[0] or l[1] != turn_for[1] or l[2] != turn_for[2]:  # L is constant in flight
                turn, turn_for = spin_turn(inv_inertia, l, h), l
            xn, qn, vn, ln = flight_step(x, q, v, l, inv_m, f, turn, h)
        elif method == 0:
            xn, qn, vn, ln = euler_step(x, q, v, l, inv_m, inertia, inv_inertia, f, t, c_lin, c_ang, h, acts, i, s * h)
        elif method == 1:
            xn, qn, vn, ln = symplectic_step(
                x, q, v, l, inv_m, inertia, inv_inertia, f, t, c_lin, c_ang, h, acts, i, s * h
            )
        elif method == 2 or method == 4:
            xn, qn, vn, ln = rk4_step(x, q, v, l, inv_m, inertia, inv_inertia, f, t, c_lin, c_ang, h, acts, i, s * h)
        else:
            xn, qn, vn, ln = midpoint_step(
                x, q, v, l, inv_m, inertia, inv_inertia, f, t, c_lin, c_ang, h, acts, i, s * h
            )
        if not (is_finite3(xn) and quat_is_finite(qn) and is_finite3(vn) and is_finite3(ln)):
            failed = s
            break
        x, q, v, l = xn, qn, vn, ln
        if record_every > 0 and (s + 1) % record_every == 0:
            frame = (s + 1) // record_every - 1
            store3(rec.pos[frame], i, x)
            store4(rec.quat[frame], i, q)
            store3(rec.linvel[frame], i, v)
            store3(rec.angmom[frame], i, l)
    return failed, x, q, v, l


@inline
def _copy_static_rows(i, pos, quat, linvel, angmom, rec, n_steps, record_every):
    """Static bodies do not move; their rows in every recorded frame are their current state."""
    if record_every > 0:
        for frame in range(n_steps // record_every):
            store3(rec.pos[frame], i, load3(pos, i))
            store4(rec.quat[frame], i, load4(quat, i))
            store3(rec.linvel[frame], i, load3(linvel, i))
            store3(rec.angmom[frame], i, load3(angmom, i))


@kernel
def _advance_rows_kernel(bodies, gravity, force, torque, acts, pos, quat, linvel, angmom, backup, rec, failed_step,
                         h, n_steps, method, record_every, first, last):  # fmt: skip
    """Bodies ``first..last-1``; returns their first failing step, or -1. Releases the GIL (``nogil``).

    ``backup`` receives each row before it moves; ``failed_step[i]`` the failing step of body ``i`` or -1.
    """
    for i in range(first, last):
        _save_row(i, pos, quat, linvel, angmom, backup)
        failed_step[i] = -1
        if bodies.is_dynamic[i]:
            failed_step[i] = _advance_body(i, bodies, gravity, force, torque, acts, pos, quat, linvel, angmom, rec,
                                           h, n_steps, method, record_every)  # fmt: skip
        else:
            _copy_static_rows(i, pos, quat, linvel, angmom, rec, n_steps, record_every)
    first_failure = -1
    for i in range(first, last):
        if failed_step[i] >= 0 and (first_failure < 0 or failed_step[i] < first_failure):
            first_failure = failed_step[i]
    return first_failure


def threads() -> int:
    """The threads free bodies run on (``TUMBLE_THREADS``, or :func:`using_threads` inside its block)."""
    return _THREADS


@contextlib.contextmanager
def using_threads(count: int):
    """Run free bodies on ``count`` threads (1 to one per core) inside the block, then as before: the benchmarks
    time one and two threads in one process (``numba.set_num_threads`` does not reach these threads)."""
    global _THREADS
    cores = max(1, os.cpu_count() or 1)
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= cores:
        raise ValueError(f"count must be a number of threads from 1 to {cores} (one per core), got {count!r}")
    before, _THREADS = _THREADS, count
    try:
        yield
    finally:
        _THREADS = before


def _thread_pool() -> ThreadPoolExecutor:
    """The pool, grown to ``_THREADS`` workers if :func:`using_threads` asked for more than it has."""
    global _POOL, _POOL_SIZE
    if _POOL_SIZE < _THREADS:
        if _POOL is not None:
            _POOL.shutdown(wait=False)
        _POOL, _POOL_SIZE = ThreadPoolExecutor(max_workers=_THREADS, thread_name_prefix="tumble"), _THREADS
    return _POOL


def _run_rows(args: tuple, body_count: int, work: int) -> int:
    """Advance all rows, split across threads when the work is large (rows are independent: any split gives
    the same bits). Threads rather than ``prange`` keep one compiled kernel, which halves the cold start."""
    if work < PARALLEL_MIN_WORK or _THREADS < 2 or body_count < 2:
        return _advance_rows_kernel(*args, 0, body_count)
    bounds = np.linspace(0, body_count, min(_THREADS, body_count) + 1).astype(np.int64)
    futures = [
        _thread_pool().submit(_advance_rows_kernel, *args, int(lo), int(hi))
        for lo, hi in zip(bounds[:-1], bounds[1:], strict=True)
    ]
    failures = [f.result() for f in futures]
    failed = [f for f in failures if f >= 0]
    return min(failed) if failed else -1


@inline(into_callers=True)
def _save_row(i, pos, quat, linvel, angmom, backup):
    store3(backup[0], i, load3(pos, i))
    store4(backup[1], i, load4(quat, i))
    store3(backup[2], i, load3(linvel, i))
    store3(backup[3], i, load3(angmom, i))


def advance_free_bodies(
    model: Model,
    state: State,
    body_force: np.ndarray,
    body_torque: np.ndarray,
    acts,
    scratch,
    h: float,
    n_steps: int,
    method: Integrator,
    recording: Recording | None = None,
    record_every: int = 0,
) -> tuple[int, int]:
    """Integrate every dynamic body for ``n_steps`` steps of ``h``.

    Reads: model.body_*, model.gravity, body_force, body_torque (applied during the first step only), the
    actuators ``acts`` (:class:`~tumble.dynamics.actuation.ActuatorArrays`: their loads at every stage, the motors'
    speeds at the start of the call; the caller advances the motors after it).
    Writes: state.body_pos/quat/linvel/angmom, ``recording`` (one frame every ``record_every`` steps),
    scratch.backup_* and scratch.failed_step.

    Returns:
        ``(steps_done, failing_body)``: ``steps_done == n_steps`` and ``failing_body == -1`` on success;
        otherwise the state is that after ``steps_done`` steps (the last good one) and ``failing_body`` is
        the row of the first body whose state became non-finite in the next step.
    """
    bodies = model.body_arrays
    if recording is None:
        recording, record_every = scratch.no_recording, 0
    arrays = (state.body_pos, state.body_quat, state.body_linvel, state.body_angmom)
    args = (bodies, model.gravity, body_force, body_torque, acts, *arrays, scratch.backup, recording,
            scratch.failed_step, h, n_steps, int(method), record_every)  # fmt: skip
    first_failure = _run_rows(args, model.body_count, model.body_count * n_steps)
    if first_failure < 0:
        return n_steps, -1
    # Roll every body back and replay only the steps that all of them completed.
    steps_done = int(first_failure)
    failing_body = int(np.flatnonzero(scratch.failed_step == first_failure)[0])
    for a, b in zip(arrays, scratch.backup, strict=True):
        np.copyto(a, b)
    if steps_done > 0:
        replay = args[:-3] + (steps_done, int(method), record_every)
        _advance_rows_kernel(*replay, 0, model.body_count)
    return steps_done, failing_body
