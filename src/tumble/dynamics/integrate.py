"""Free motion of a block of bodies over a range of steps (:func:`advance_rows`), and the threads it runs on.

Without contacts or joints the bodies do not interact, so each body is carried through all its steps in
registers before the next one (body-major order). That is cache friendly, lets the bodies run in parallel
with each row written by one thread only, and gives bit-identical results in any order or thread count.
The loop of steps around it, with the backup, the restore on a non-finite value, the motors and a compiled
controller stage between steps, is the runner's (``tumble.runner``).

Large calls split the bodies into one contiguous block per core and run the runner's kernel on each block in a
thread (the kernel releases the GIL). Set ``TUMBLE_THREADS=1`` to stay on one thread (``auto``, unset or empty:
one per core; anything else is warned about and read as ``auto``).
"""

from __future__ import annotations

import contextlib
import math
import os
import warnings
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

import numpy as np

from .._jit import inline
from ..math3d import add_scaled, is_finite3, load3, load4, load33, quat_is_finite, store3, store4
from .free_motion import euler_step, flies_freely, flight_step, midpoint_step, rk4_step, spin_turn, symplectic_step

__all__ = [
    "Recording",
    "advance_rows",
    "PARALLEL_MIN_WORK",
    "thread_count",
    "thread_pool",
    "threads",
    "using_threads",
]

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


@inline
def advance_rows(first, last, world, h, first_step, end_step, method, record_every):
    """Carry bodies ``first..last-1`` of ``world`` (the runner's record, ``compiled_world.CompiledWorld``: its model
    rows, gravity, loads, body state, frames and ``failed_step``) through steps ``first_step..end_step-1`` of a run
    (the runner's loop, ``tumble.runner``, owns the run): ``failed_step[i]`` is the index of the step in which body
    ``i`` failed, or -1; a failed body's row keeps its last good state. The applied loads (``world.loads``) act in
    the run's step 0; the actuators' motors are at their speeds of step ``first_step``.

    It takes the record, not its arrays, and is not compiled into the runner's loop: every array a compiled function
    holds in a variable costs two atomic reference counts per call, so the arrays are taken out of the record here,
    where they are used, once (a one-body step 0.3 µs faster than with the arrays passed in and this function
    inlined).

    The loop over the bodies is in here, and its body hands the per-body steps no array: a function compiled into a
    loop (Numba's ``inline="always"``) takes a reference to every array it is given at each pass, two atomic
    operations per array, which LLVM does not remove across the steps' loop. Given the model's, the actuators' and the
    recording's arrays (about 50), that cost 440 ns a body and call whatever the number of steps (1.8 ms a
    ``step()`` of 4096 bodies, whose physics takes 0.1–0.6 ms). Recording stays here too, between runs of
    ``record_every`` steps. Each body's steps take its constants and state as tuples; a body without actuators runs
    the steps compiled with ``acts=None``, in which they cost nothing.
    """
    bodies, gravity, rec, failed_step = world.model_rows[0], world.gravity, world.rec, world.failed_step
    force, torque, driven = world.loads[0], world.loads[1], world.loads[2].driven  # the actuators where driven
    pos, quat, linvel, angmom = world.body_state[:4]
    g = (gravity[0], gravity[1], gravity[2])
    for i in range(first, last):
        failed_step[i] = -1
        if not bodies.is_dynamic[i]:
            _copy_static_rows(i, pos, quat, linvel, angmom, rec, first_step, end_step, record_every)
            continue
        # Gravity and the constant loads act in every step; applied loads in the first step only.
        weight = add_scaled(load3(bodies.constant_force, i), g, bodies.mass[i])
        body = (bodies.inv_mass[i], load33(bodies.inertia_local, i), load33(bodies.inv_inertia_local, i),
                bodies.linear_damping[i], bodies.angular_damping[i], weight, load3(bodies.constant_torque, i),
                load3(force, i), load3(torque, i))  # fmt: skip
        state = (load3(pos, i), load4(quat, i), load3(linvel, i), load3(angmom, i))
        turn = ((1.0, 0.0, 0.0, 0.0), (math.nan, math.nan, math.nan))  # auto's flight: exp(½ h ω), and the L of ω
        done, failed = first_step, -1
        while done < end_step and failed < 0:
            end = min((done // record_every + 1) * record_every, end_step) if record_every > 0 else end_step
            if driven[i]:
                failed, state, turn = _body_steps(i, body, state, turn, world.loads[2], h, first_step, done, end,
                                                  method)  # fmt: skip
            else:
                failed, state, turn = _body_steps(i, body, state, turn, None, h, first_step, done, end, method)
            if failed < 0 and record_every > 0 and end % record_every == 0:
                frame = end // record_every - 1
                store3(rec.pos[frame], i, state[0])
                store4(rec.quat[frame], i, state[1])
                store3(rec.linvel[frame], i, state[2])
                store3(rec.angmom[frame], i, state[3])
            done = end
        store3(pos, i, state[0])
        store4(quat, i, state[1])
        store3(linvel, i, state[2])
        store3(angmom, i, state[3])
        failed_step[i] = failed


@inline(into_callers=True)
def _body_steps(i, body, state, turn, acts, h, motors_step, first_step, end_step, method):
    """Steps ``first_step..end_step-1`` of body ``i`` from ``state``, with its actuators ``acts`` (their motors at
    their speeds of step ``motors_step``) or ``None``: ``(failing step or -1, last good state, turn)``. ``turn``
    carries auto's flight rotation ``exp(½ h ω)`` with the ``L`` it was computed for, so that a flight computes it
    once, not at every step or recorded frame."""
    inv_m, inertia, inv_inertia, c_lin, c_ang, weight, steady_torque, applied_force, applied_torque = body
    x, q, v, l = state
    spin, spin_for = turn
    failed = -1
    for s in range(first_step, end_step):
        tau = (s - motors_step) * h  # the time since the motors' speeds
        f = (weight[0] + applied_force[0], weight[1] + applied_force[1], weight[2] + applied_force[2])
        t = (steady_torque[0] + applied_torque[0], steady_torque[1] + applied_torque[1],
             steady_torque[2] + applied_torque[2])  # fmt: skip
        if s > 0:
            f = weight
            t = steady_torque
        # method: an Integrator code; 4 (auto) flies a body exactly where its motion has a closed form, else RK4.
        if method == 4 and acts is None and flies_freely(t, c_lin, c_ang, inv_inertia, l):
            if l[0] != spin_for[0] or l[1] != spin_for[1] or l[2] != spin_for[2]:  # L is constant in flight
                spin, spin_for = spin_turn(inv_inertia, l, h), l
            xn, qn, vn, ln = flight_step(x, q, v, l, inv_m, f, spin, h)
        elif method == 0:
            xn, qn, vn, ln = euler_step(x, q, v, l, inv_m, inertia, inv_inertia, f, t, c_lin, c_ang, h, acts, i, tau)
        elif method == 1:
            xn, qn, vn, ln = symplectic_step(
                x, q, v, l, inv_m, inertia, inv_inertia, f, t, c_lin, c_ang, h, acts, i, tau
            )
        elif method == 2 or method == 4:
            xn, qn, vn, ln = rk4_step(x, q, v, l, inv_m, inertia, inv_inertia, f, t, c_lin, c_ang, h, acts, i, tau)
        else:
            xn, qn, vn, ln = midpoint_step(x, q, v, l, inv_m, inertia, inv_inertia, f, t, c_lin, c_ang, h, acts, i, tau)
        if not (is_finite3(xn) and quat_is_finite(qn) and is_finite3(vn) and is_finite3(ln)):
            failed = s
            break
        x, q, v, l = xn, qn, vn, ln
    return failed, (x, q, v, l), (spin, spin_for)


@inline
def _copy_static_rows(i, pos, quat, linvel, angmom, rec, first_step, end_step, record_every):
    """Static bodies do not move; their rows in every frame recorded in steps ``first_step..end_step-1`` are their
    current state."""
    if record_every > 0:
        for frame in range(first_step // record_every, end_step // record_every):
            store3(rec.pos[frame], i, load3(pos, i))
            store4(rec.quat[frame], i, load4(quat, i))
            store3(rec.linvel[frame], i, load3(linvel, i))
            store3(rec.angmom[frame], i, load3(angmom, i))


def threads() -> int:
    """The threads free bodies run on (``TUMBLE_THREADS``, or :func:`using_threads` inside its block)."""
    return _THREADS


def one_thread_for_this_process() -> None:
    """Free bodies on one thread from now on in this process: a worker of a process pool, whose siblings share the
    cores (``tumble.ensemble``'s pool starts each worker with it)."""
    global _THREADS
    _THREADS = 1


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


def thread_pool() -> ThreadPoolExecutor:
    """The pool, grown to ``_THREADS`` workers if :func:`using_threads` asked for more than it has."""
    global _POOL, _POOL_SIZE
    if _POOL_SIZE < _THREADS:
        if _POOL is not None:
            _POOL.shutdown(wait=False)
        _POOL, _POOL_SIZE = ThreadPoolExecutor(max_workers=_THREADS, thread_name_prefix="tumble"), _THREADS
    return _POOL
