"""The runner: a world's arrays advanced ``n`` steps, backed up before each, restored on a non-finite value, a frame
recorded every ``record_every`` steps, the clock and the motors advanced. ``World.step``, ``World.simulate``
(``world_stepping.py``), ``Batch`` and the compiled stages of controllers all come here.

    simulate_steps   the one entry: free bodies take every step in one compiled loop (:func:`_free_steps`);
                     a world whose shapes can touch or whose bodies are jointed takes one pipeline.contact_step a
                     step in the Python loop (:func:`_contact_steps`)
    _free_steps      the compiled loop: before each chunk of steps a compiled controller stage (if any) commands the
                     actuators; the bodies are backed up, carried through the chunk (dynamics/integrate.py), restored
                     and replayed to the last good step on a non-finite value; the motors advance. Without a stage the
                     chunk is the whole run (body-major, split over threads when large); with one, a step
    step_by_step     the Python loop: one step a call, a frame recorded after it; the contact steps, and a world's
                     Python controllers and sensors (world_stepping.py), run in it
    advance_clock    time accumulated step by step (n steps in one call = n calls of one step, bit for bit)
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

from ._jit import inline, kernel_for
from .dynamics import integrate
from .dynamics.actuation import ActuatorArrays, advance_motors
from .dynamics.integrate import Recording, advance_rows
from .inputs import Inputs
from .math3d import load3, load4, store3, store4
from .model import Model
from .params import Integrator, Params
from .pipeline import contact_step
from .scratch import Scratch
from .state import State

__all__ = ["Steps", "advance_clock", "record_frame", "simulate_steps", "step_by_step"]


class Steps(NamedTuple):
    """What a call of the runner did: the steps done, and the row of the body that became non-finite in the next
    one (the world is as it was before that step) or the index of the compiled stage's controller that failed
    before it; -1 for none."""

    done: int
    failing_body: int = -1
    failing_controller: int = -1


def simulate_steps(
    model: Model,
    state: State,
    inputs: Inputs,
    params: Params,
    scratch: Scratch,
    h: float,
    n_steps: int = 1,
    recording: Recording | None = None,
    record_every: int = 0,
    acts: ActuatorArrays | None = None,
    stage=None,
    clock: tuple[float, int] = (0.0, 0),
) -> Steps:
    """Advance ``n_steps`` steps of ``h``.

    ``acts`` are the actuators, drag and wind (none if ``None``); their motors' speeds advance with the steps.
    ``stage`` is a compiled controller stage (``tumble.controllers.Controllers.compiled_stage``) that commands the
    actuators before each step of a world of free bodies; the step ``s`` starts at ``clock[0] + (clock[1] + s) h``,
    as the world's ``StepClock`` counts.
    """
    if acts is None:
        acts = ActuatorArrays.empty(model.body_count)
    if model.has_constraints:
        if stage is not None:
            raise ValueError("a compiled stage runs in the free bodies' loop; a world with contacts or joints "
                             "calls stage.command before each step")  # fmt: skip
        steps = _contact_steps(model, state, inputs, params, scratch, h, n_steps, recording, record_every, acts)
    else:
        if recording is None:
            recording, record_every = scratch.no_recording, 0
        method = int(params.resolve_integrator(False))
        steps = _free_body_steps(model, state, inputs, acts, scratch, h, n_steps, method, recording, record_every,
                                 stage, clock)  # fmt: skip
        advance_clock(state, h, steps.done)
    # The applied loads act in the first step; one that failed drops them too (the world keeps its state from
    # before it), or a load that makes every step overflow (RK4 sums four stages of it) would leave it stuck.
    inputs.clear()
    return steps


def advance_clock(state: State, h: float, steps: int) -> None:
    # Accumulate time step by step so that simulate(n steps) and n calls of step() agree bit for bit.
    time = state.time
    for _ in range(steps):
        time += h
    state.time = time
    state.step_count += steps


def _free_steps(stage, bodies, gravity, force, torque, acts, pos, quat, linvel, angmom, backup, rec, failed_step, h,
                n_steps, chunk, method, record_every, first, last, origin_time, origin_count):  # fmt: skip
    """Bodies ``first..last-1`` through ``n_steps`` steps, ``chunk`` at a time: before each chunk ``command_stage``
    (bound by :func:`kernel_for`) commands the actuators at the chunk's counted start time; the rows are backed up,
    advanced (``advance_rows``), and on a non-finite value restored and replayed to the last step all completed; the
    motors of these bodies advance by the chunk. Returns ``(steps_done, failing_body, failing_controller)``, -1 for
    none. The applied loads ``force``, ``torque`` act in step 0. Releases the GIL (``nogil``).

    The replay goes through the same call of ``advance_rows`` as the chunk: it is compiled into this loop, and a
    second call would compile the integrators twice (5 s more of a cold start)."""
    done = 0
    while done < n_steps:
        end = min(done + chunk, n_steps)
        t = origin_time + (origin_count + done) * h
        failing_controller = command_stage(stage, gravity, acts, pos, quat, linvel, angmom, t, h)  # noqa: F821
        if failing_controller >= 0:
            return done, -1, failing_controller
        for i in range(first, last):
            _save_row(i, pos, quat, linvel, angmom, backup)
        failing_body = -1
        while True:  # the chunk; after a failure, once more from the backup up to the failing step
            advance_rows(first, last, bodies, gravity, force, torque, acts, pos, quat, linvel, angmom, rec,
                         failed_step, h, done, end, method, record_every)  # fmt: skip
            failing_step, body = _first_failure(failed_step, first, last, end)
            if body < 0:
                break
            failing_body, end = body, failing_step
            for i in range(first, last):
                _restore_row(i, pos, quat, linvel, angmom, backup)
            if end == done:
                return done, failing_body, -1
        advance_motors(acts, first, last, (end - done) * h)
        done = end
        if failing_body >= 0:
            return done, failing_body, -1
    return n_steps, -1, -1


@inline
def _first_failure(failed_step, first, last, end):
    """``(step, row)``: the earliest step in which a row of ``first..last-1`` failed and the first such row, or
    ``(end, -1)``."""
    step, row = end, -1
    for i in range(first, last):
        if 0 <= failed_step[i] < step:
            step, row = failed_step[i], i
    return step, row


@inline
def _no_stage(stage, gravity, acts, pos, quat, linvel, angmom, t, h):
    """The stage of a world without compiled controllers: nothing to command."""
    return -1


@inline(into_callers=True)
def _save_row(i, pos, quat, linvel, angmom, backup):
    store3(backup[0], i, load3(pos, i))
    store4(backup[1], i, load4(quat, i))
    store3(backup[2], i, load3(linvel, i))
    store3(backup[3], i, load3(angmom, i))


@inline(into_callers=True)
def _restore_row(i, pos, quat, linvel, angmom, backup):
    store3(pos, i, load3(backup[0], i))
    store4(quat, i, load4(backup[1], i))
    store3(linvel, i, load3(backup[2], i))
    store3(angmom, i, load3(backup[3], i))


_plain_steps = kernel_for(_free_steps, "free_steps", command_stage=_no_stage)


@functools.cache
def _staged_steps(command):
    """The compiled loop with a stage's ``command`` bound in: one copy per kind of stage, cached on disk under its
    name (``kernel_for``)."""
    name = getattr(command, "py_func", command).__name__.strip("_")
    return kernel_for(_free_steps, f"free_steps_{name}", command_stage=command)


def _free_body_steps(model, state, inputs, acts, scratch, h, n_steps, method, recording, record_every, stage, clock):
    """The free bodies' loop: without a stage one chunk of all the steps, split over the threads when the work is
    large (rows are independent: any split gives the same bits); with one, a chunk a step on this thread."""
    arrays = (state.body_pos, state.body_quat, state.body_linvel, state.body_angmom)
    head = (model.body_arrays, model.gravity, inputs.body_force, inputs.body_torque, acts, *arrays, scratch.backup,
            recording, scratch.failed_step, h)  # fmt: skip
    tail = (method, record_every)
    n = model.body_count
    if stage is not None:
        origin_time, origin_count = clock
        return Steps(*_staged_steps(stage.compiled_command)(stage.compiled_data, *head, n_steps, 1, *tail, 0, n,
                                                             float(origin_time), int(origin_count)))  # fmt: skip
    if n * n_steps < integrate.PARALLEL_MIN_WORK or integrate.threads() < 2 or n < 2:
        return Steps(*_plain_steps(0, *head, n_steps, n_steps, *tail, 0, n, 0.0, 0))
    speeds = acts.speed.copy()
    bounds = np.linspace(0, n, min(integrate.threads(), n) + 1).astype(np.int64)
    futures = [
        integrate.thread_pool().submit(_plain_steps, 0, *head, n_steps, n_steps, *tail, int(lo), int(hi), 0.0, 0)
        for lo, hi in zip(bounds[:-1], bounds[1:], strict=True)
    ]
    blocks = [Steps(*future.result()) for future in futures]
    first_failure = min(blocks, key=lambda block: block.done)  # the first block of the earliest failing step
    if first_failure.failing_body < 0:
        return Steps(n_steps)
    # Every block back to the start, then all the rows on this thread to the last step all of them completed.
    for array, saved in zip(arrays, scratch.backup, strict=True):
        np.copyto(array, saved)
    np.copyto(acts.speed, speeds)
    if first_failure.done > 0:
        _plain_steps(0, *head, first_failure.done, first_failure.done, *tail, 0, n, 0.0, 0)
    return first_failure


def step_by_step(n_steps: int, one_step, recording: Recording, record_every: int, state: State) -> Steps:
    """The Python loop of steps: ``one_step(step)`` (the failing body's row, or -1; it backs up and restores its own
    arrays), then the frame of ``state`` when one is due; stops at the first failure. The contact steps run in it,
    and ``world_stepping`` runs a world's Python controllers and sensors in it."""
    for step in range(n_steps):
        failing = one_step(step)
        if failing >= 0:
            return Steps(step, failing)
        record_frame(recording, record_every, step, state)
    return Steps(n_steps)


def _contact_steps(model, state, inputs, params, scratch, h, n_steps, recording, record_every, acts):
    """Soft steps one after the other; on a non-finite value, restore the state before that step."""
    if params.resolve_integrator(True) != Integrator.SYMPLECTIC:
        raise ValueError(
            f"integrator={params.integrator!r} integrates free bodies only; a world whose shapes can touch or whose "
            "bodies are jointed steps with the contact and joint solver: use integrator='auto' or 'symplectic'"
        )
    zero = Inputs.zeros(model.body_count)

    def one_step(step: int) -> int:
        before = state.copy()
        loads = inputs if step == 0 else zero  # applied loads act during the first step only
        try:
            contact_step(model, state, loads, params, scratch, h, acts)
            bad = _first_non_finite_body(state, model.body_is_dynamic, before)
        except (ZeroDivisionError, FloatingPointError):  # a kernel divided by an overflowed value
            bad = _fastest_body(before, model.body_is_dynamic)
        if bad >= 0:
            state.assign(before)
            return bad
        advance_clock(state, h, 1)
        if acts.speed.shape[0]:  # nothing to enter the kernel for without rotors (5 µs a step)
            advance_motors(acts, 0, model.body_count, h)
        return -1

    return step_by_step(n_steps, one_step, recording, record_every, state)


def _first_non_finite_body(state: State, is_dynamic: np.ndarray, before: State | None = None) -> int:
    """The body with a non-finite value, dynamic bodies first (a static one only turns NaN through them); when
    several turned non-finite in the same step (one hit the other), the one that was fastest before it."""
    finite = np.isfinite(state.body_pos).all(axis=1) & np.isfinite(state.body_quat).all(axis=1)
    finite &= np.isfinite(state.body_linvel).all(axis=1) & np.isfinite(state.body_angmom).all(axis=1)
    bad = np.flatnonzero(~finite & is_dynamic)
    if bad.size == 0:
        bad = np.flatnonzero(~finite)
    if bad.size > 1 and before is not None:
        return int(bad[np.argmax(_motion(before)[bad])])
    return int(bad[0]) if bad.size else -1


def _motion(state: State) -> np.ndarray:
    """|v| + |L| per body (non-finite counts as infinite): a rough measure of which body runs away."""
    with np.errstate(over="ignore", invalid="ignore"):
        size = np.linalg.norm(state.body_linvel, axis=1) + np.linalg.norm(state.body_angmom, axis=1)
    return np.where(np.isfinite(size), size, np.inf)


def _fastest_body(state: State, is_dynamic: np.ndarray) -> int:
    motion = np.where(is_dynamic, _motion(state), -1.0)
    return int(np.argmax(motion)) if motion.size else -1


def record_frame(recording: Recording, record_every: int, step: int, state: State) -> None:
    """Frame ``(step + 1) / record_every - 1`` of ``recording`` from ``state`` after ``step``, when it is one."""
    if record_every > 0 and (step + 1) % record_every == 0:
        frame = (step + 1) // record_every - 1
        np.copyto(recording.pos[frame], state.body_pos)
        np.copyto(recording.quat[frame], state.body_quat)
        np.copyto(recording.linvel[frame], state.body_linvel)
        np.copyto(recording.angmom[frame], state.body_angmom)
