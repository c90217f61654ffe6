"""The runner: a world's arrays advanced ``n`` steps, backed up before each, restored on a non-finite value, a frame
recorded every ``record_every`` steps, the clock and the motors advanced. ``World.step``, ``World.simulate``
(``world_stepping.py``), ``Batch`` and the compiled stages of controllers all come here.

    simulate_steps   the one entry: free bodies take every step in one compiled loop (:func:`_free_steps`);
                     a world whose shapes can touch or whose bodies are jointed takes every step in the other
                     (:func:`_contact_loop`, one pipeline.contact_stages a step)
    _free_steps      the compiled loop: before each chunk of steps a compiled controller stage (if any) commands the
                     actuators; the bodies are backed up, carried through the chunk (dynamics/integrate.py), restored
                     and replayed to the last good step on a non-finite value; the motors advance. Without a stage the
                     chunk is the whole run (body-major, split over threads when large); with one, a step
    _contact_loop    the compiled loop of soft steps: each backed up, restored on a non-finite value (the body that
                     failed found as the Python loop did), the motors advanced, a frame recorded; it returns early
                     when the contact buffers must grow, and the caller grows them and calls it again
    step_by_step     the Python loop: one step a call, a frame recorded after it; a world's Python controllers and
                     sensors (world_stepping.py) run in it
    advance_clock    time accumulated step by step (n steps in one call = n calls of one step, bit for bit)
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np

from . import pipeline
from ._jit import inline, kernel_for
from .compiled_world import compiled_world, held, same_objects
from .dynamics import integrate
from .dynamics.actuation import ActuatorArrays, advance_motors
from .dynamics.integrate import Recording, advance_rows
from .inputs import Inputs
from .math3d import load3, load4, store3, store4
from .model import Model
from .params import Integrator, Params
from .scratch import Scratch
from .state import CONTACT_FIELDS, State

__all__ = ["ReadyStep", "Steps", "advance_clock", "record_frame", "simulate_steps", "step_by_step"]


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
    actuators before each step; the step ``s`` starts at ``clock[0] + (clock[1] + s) h``, as the world's
    ``StepClock`` counts.
    """
    if acts is None:
        acts = ActuatorArrays.empty(model.body_count)
    if recording is None:
        record_every = 0
    if model.has_constraints:
        steps = _contact_steps(model, state, inputs, params, scratch, acts, recording, h, n_steps, record_every, stage,
                               clock)  # fmt: skip
    else:
        method = int(params.resolve_integrator(False))
        world = compiled_world(model, state, inputs, params, scratch, acts, recording).record
        steps = _free_body_steps(world, state, inputs, acts, scratch, h, n_steps, method, record_every, stage, clock)
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


def _free_steps(stage, world, h, n_steps, chunk, method, record_every, first, last, origin_time, origin_count):
    """Bodies ``first..last-1`` of the ``world`` (a ``CompiledWorld``) through ``n_steps`` steps, ``chunk`` at a
    time: before each chunk ``command_stage`` (bound by :func:`kernel_for`) commands the actuators at the chunk's
    counted start time; the rows are backed up, advanced (``advance_rows``), and on a non-finite value restored and
    replayed to the last step all completed; the motors of these bodies advance by the chunk; the driven bodies are
    woken first. Returns ``(steps_done, failing_body, failing_controller)``, -1 for none. The applied loads
    (``world.loads``) act in step 0, and are zeroed when it returns. Releases the GIL (``nogil``).

    The replay goes through the same call of ``advance_rows`` as the chunk. It takes the record and the few arrays
    this loop writes itself: every array a compiled function holds costs two atomic reference counts per call."""
    gravity, backup, failed_step = world.gravity, world.free_backup, world.failed_step
    driven, rotors = world.loads[2].driven, world.loads[2].first  # the actuators' arrays taken where used
    pos, quat, linvel, angmom, sleep_time, sleeping = world.body_state[:6]
    for i in range(first, last):  # thrust that holds a body still must not let it sleep
        if driven[i]:
            sleep_time[i], sleeping[i] = 0.0, False
    done = 0
    while done < n_steps:
        end = min(done + chunk, n_steps)
        t = origin_time + (origin_count + done) * h
        failing_controller = command_stage(stage, gravity, world.loads[2], pos, quat, linvel, angmom, t, h)  # noqa: F821
        if failing_controller >= 0:
            return _loads_dropped(world, first, last, done, -1, failing_controller)
        for i in range(first, last):
            _save_row(i, pos, quat, linvel, angmom, backup)
        failing_body = -1
        while True:  # the chunk; after a failure, once more from the backup up to the failing step
            advance_rows(first, last, world, h, done, end, method, record_every)
            failing_step, body = _first_failure(failed_step, first, last, end)
            if body < 0:
                break
            failing_body, end = body, failing_step
            for i in range(first, last):
                _restore_row(i, pos, quat, linvel, angmom, backup)
            if end == done:
                return _loads_dropped(world, first, last, done, failing_body, -1)
        if rotors[last] > rotors[first]:  # a call costs its arrays' reference counts: only for rotors
            advance_motors(world.loads[2], first, last, (end - done) * h)
        done = end
        if failing_body >= 0:
            return _loads_dropped(world, first, last, done, failing_body, -1)
    return _loads_dropped(world, first, last, n_steps, -1, -1)


@inline
def _loads_dropped(world, first, last, done, failing_body, failing_controller):
    """``(done, failing_body, failing_controller)``, the applied loads of bodies ``first..last-1`` zeroed: they act
    in a call's first step only, and a call that failed drops them too (``simulate_steps``)."""
    force, torque = world.loads[0], world.loads[1]
    for i in range(first, last):
        for k in range(3):
            force[i, k] = 0.0
            torque[i, k] = 0.0
    return done, failing_body, failing_controller


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


def _free_body_steps(world, state, inputs, acts, scratch, h, n_steps, method, record_every, stage, clock):
    """The free bodies' loop over the ``world`` record: without a stage one chunk of all the steps, split over the
    threads when the work is large (rows are independent: any split gives the same bits); with one, a chunk a step
    on this thread."""
    n = state.body_count
    if stage is not None:
        origin_time, origin_count = clock
        return Steps(*_staged_steps(stage.compiled_command)(stage.compiled_data, world, h, n_steps, 1, method,
                                                             record_every, 0, n, float(origin_time),
                                                             int(origin_count)))  # fmt: skip
    if n < 2 or n * n_steps < integrate.PARALLEL_MIN_WORK or integrate.threads() < 2:
        return Steps(*_plain_steps(0, world, h, n_steps, n_steps, method, record_every, 0, n, 0.0, 0))
    speeds, loads = acts.speed.copy(), (inputs.body_force.copy(), inputs.body_torque.copy())
    bounds = np.linspace(0, n, min(integrate.threads(), n) + 1).astype(np.int64)
    futures = [
        integrate.thread_pool().submit(
            _plain_steps, 0, world, h, n_steps, n_steps, method, record_every, int(lo), int(hi), 0.0, 0
        )  # fmt: skip
        for lo, hi in zip(bounds[:-1], bounds[1:], strict=True)
    ]
    blocks = [Steps(*future.result()) for future in futures]
    first_failure = min(blocks, key=lambda block: block.done)  # the first block of the earliest failing step
    if first_failure.failing_body < 0:
        return Steps(n_steps)
    # Every block back to the start, then all the rows on this thread to the last step all of them completed.
    arrays = (state.body_pos, state.body_quat, state.body_linvel, state.body_angmom)
    for array, saved in zip(arrays, scratch.backup, strict=True):
        np.copyto(array, saved)
    np.copyto(acts.speed, speeds)
    np.copyto(inputs.body_force, loads[0])  # each block dropped its rows' loads: the replay's first step has them
    np.copyto(inputs.body_torque, loads[1])
    if first_failure.done > 0:
        _plain_steps(0, world, h, first_failure.done, first_failure.done, method, record_every, 0, n, 0.0, 0)
    return first_failure


class ReadyStep:
    """One step as :func:`simulate_steps` takes it (no recording, no stage), prepared once for the steps that
    follow: a call of the compiled loop over the kept record, the clock advanced and the loads cleared, and little
    else. ``World.step`` takes it while it :meth:`fits`; anything else the step reads (controllers, sensors, the
    wind) is the caller's to check. This class steps free bodies; :class:`_ReadyContactStep` contacts and joints."""

    __slots__ = ("_objects", "_integrator", "_compiled", "_record", "_method", "_bodies", "_state", "_inputs")

    def __init__(self, model: Model, state: State, inputs: Inputs, params: Params, scratch: Scratch,
                 acts: ActuatorArrays):  # fmt: skip
        self._objects = held(model, state, inputs, params, acts)
        self._integrator = params.integrator
        self._compiled = compiled_world(model, state, inputs, params, scratch, acts)
        self._record = self._compiled.record
        self._method = int(params.resolve_integrator(False))
        self._bodies = state.body_count
        self._state, self._inputs = state, inputs

    @classmethod
    def of(cls, model: Model, state: State, inputs: Inputs, params: Params, scratch: Scratch,
           acts: ActuatorArrays) -> ReadyStep | None:  # fmt: skip
        """The prepared step of these arrays, or None where one step of free bodies is split over threads."""
        if model.has_constraints:
            return _ReadyContactStep(model, state, inputs, params, scratch, acts)
        if state.body_count >= integrate.PARALLEL_MIN_WORK:
            return None
        return cls(model, state, inputs, params, scratch, acts)

    def fits(self, model: Model, state: State, inputs: Inputs, params: Params, acts: ActuatorArrays) -> bool:
        """Whether these are the objects it was prepared from (the integrator's name too): then its record holds
        them."""
        return params.integrator is self._integrator and same_objects(held(model, state, inputs, params, acts),
                                                                      self._objects)  # fmt: skip

    def __call__(self, h: float) -> int:
        """One step of ``h``: the row of the body that became non-finite (the arrays as they were), or -1."""
        done, failing, _ = _plain_steps(0, self._record, h, 1, 1, self._method, 0, 0, self._bodies, 0.0, 0)
        if done:  # advance_clock's sum for one step
            state = self._state
            state.time += h
            state.step_count += 1
        return failing  # the loop dropped the loads (they act in this step, or are dropped with it)


class _ReadyContactStep(ReadyStep):
    """One soft step (:func:`_contact_loop`) prepared: the substeps found again only for a new ``h``; the contact
    rows stay where the last step left them, while the state holds their views (:meth:`fits`). A step that must grow
    the contact buffers takes the full path."""

    __slots__ = ("_model", "_params", "_acts", "_scratch", "_h", "_substeps")

    def __init__(self, model: Model, state: State, inputs: Inputs, params: Params, scratch: Scratch,
                 acts: ActuatorArrays):  # fmt: skip
        super().__init__(model, state, inputs, params, scratch, acts)
        self._model, self._params, self._acts, self._scratch = model, params, acts, scratch
        self._h, self._substeps = math.nan, 0

    def fits(self, model: Model, state: State, inputs: Inputs, params: Params, acts: ActuatorArrays) -> bool:
        return super().fits(model, state, inputs, params, acts) and _views_held(state, self._scratch)

    def __call__(self, h: float) -> int:
        if h != self._h:  # a ValueError before anything moved, as the full path's
            self._substeps, self._h = self._params.solver.substeps_for(h), h
        scratch, state = self._scratch, self._state
        count = scratch.contact_count
        try:
            done, failing, _, count, needed = _plain_contact_loop(0, self._record, count, 0, h, self._substeps, 0, 1,
                                                                  0.0, 0)  # fmt: skip
        except (ZeroDivisionError, FloatingPointError):  # a kernel divided by an overflowed value
            done, count, failing = _restored(self._compiled.progress, self._compiled.backup, state, scratch,
                                             self._model)  # fmt: skip
        else:
            if needed > 0:  # nothing of the step ran: the full path grows the buffers and takes it
                return simulate_steps(self._model, state, self._inputs, self._params, scratch, h,
                                      acts=self._acts).failing_body  # fmt: skip
        if done > 0:
            scratch.joint_step = h
        _leave_contacts(state, scratch, count, self._compiled.progress, True)
        advance_clock(state, h, done)
        self._inputs.clear()
        return failing


def step_by_step(n_steps: int, one_step, recording: Recording, record_every: int, state: State) -> Steps:
    """The Python loop of steps: ``one_step(step)`` (the failing body's row, or -1; it backs up and restores its own
    arrays), then the frame of ``state`` when one is due; stops at the first failure. ``world_stepping`` runs a
    world's Python controllers and sensors in it."""
    for step in range(n_steps):
        failing = one_step(step)
        if failing >= 0:
            return Steps(step, failing)
        record_frame(recording, record_every, step, state)
    return Steps(n_steps)


def _contact_steps(model, state, inputs, params, scratch, acts, recording, h, n_steps, record_every, stage, clock):
    """Soft steps in the compiled loop (:func:`_contact_loop`, with the ``stage``'s command bound in when there is
    one); on a non-finite value the state before that step."""
    if params.resolve_integrator(True) != Integrator.SYMPLECTIC:
        raise ValueError(
            f"integrator={params.integrator!r} integrates free bodies only; a world whose shapes can touch or whose "
            "bodies are jointed steps with the contact and joint solver: use integrator='auto' or 'symplectic'"
        )
    substeps = params.solver.substeps_for(h)
    # The last step's contacts into the rows the loop reads and writes, unless the state holds the views of those
    # rows that the last call left (any other arrays were put there since).
    count = state.contact_count
    scratch.reserve_contacts(count)
    compiled = compiled_world(model, state, inputs, params, scratch, acts, recording)
    stored = scratch.stored
    held = _views_held(state, scratch)
    if not held:
        for rows, array in zip(stored, state.contact_arrays, strict=True):
            rows[:count] = array
    loop, data = (_plain_contact_loop, 0) if stage is None else (_staged_contact_loop(stage.compiled_command),
                                                                 stage.compiled_data)  # fmt: skip
    origin_time, origin_count = float(clock[0]), int(clock[1])
    done, failing, failing_controller = 0, -1, -1
    while done < n_steps and failing < 0 and failing_controller < 0:
        try:
            done, failing, failing_controller, count, needed = loop(
                data, compiled.record, count, record_every, h, substeps, done, n_steps, origin_time, origin_count
            )
        except (ZeroDivisionError, FloatingPointError):  # a kernel divided by an overflowed value
            done, count, failing = _restored(compiled.progress, compiled.backup, state, scratch, model)
        else:
            if needed > 0:  # more candidate pairs than the buffers hold: grow them, keeping the contact rows
                scratch.reserve_contacts(needed, keep=count)
                compiled = compiled_world(model, state, inputs, params, scratch, acts, recording)
        if done > 0:
            scratch.joint_step = h
    _leave_contacts(state, scratch, count, compiled.progress, held and scratch.stored is stored)
    advance_clock(state, h, done)
    return Steps(done, failing, failing_controller)


def _views_held(state: State, scratch: Scratch) -> bool:
    """Whether the state's contact arrays are the views of the stored rows that the last contact call left."""
    return tuple(map(id, state.contact_arrays)) == scratch.contacts_left[0]


def _restored(progress, backup, state: State, scratch: Scratch, model: Model) -> tuple[int, int, int]:
    """After a kernel raised mid-step: the state as it was before that step (the compiled record's ``backup``), and
    ``(steps_done, contact_count, failing_body)``."""
    done, count = int(progress[0]), int(progress[1])
    _copy_state(backup[0], backup[1], count, backup[2], pipeline.body_state(state), scratch.stored,
                state.joint_impulses)  # fmt: skip
    return done, count, _fastest_body(backup, model.body_is_dynamic)


def _leave_contacts(state: State, scratch: Scratch, count: int, progress: np.ndarray, views_held: bool) -> None:
    """After a contact call: its contact count and the steps it found contacts again in, into ``scratch``; the
    state's contact arrays the views of the ``count`` rows stored, made again unless it holds them already."""
    scratch.contact_count = count
    if progress[2]:
        scratch.steps_found_again += int(progress[2])
        progress[2] = 0
    if not views_held or count != state.contact_count:
        views = tuple(rows[:count] for rows in scratch.stored)
        for name, view in zip(CONTACT_FIELDS, views, strict=True):
            setattr(state, name, view)
        scratch.contacts_left = tuple(map(id, views)), views  # the views held: their ids are not reused meanwhile


def _contact_loop(stage, world, count, record_every, h, substeps, first, n_steps, origin_time, origin_count):
    """Steps ``first..n_steps-1`` of a call over the ``world`` (a ``CompiledWorld``), each one
    ``pipeline.contact_stages``: before it ``command_stage`` (bound by :func:`kernel_for`) commands the actuators at
    the step's counted start time and the driven bodies are woken (thrust that holds a body still must not let it
    sleep); the state is backed up, and restored on a non-finite value; the motors advance and a frame is recorded
    when one is due. The applied loads (``world.loads``) act in step 0 of the call, ``world.idle`` (none) in the
    others. The contact state is the first ``count`` rows of the stored arrays (``world.buffers[7]``); each step
    reads them and stores its own there.

    Returns ``(steps_done, failing_body, failing_controller, count, pairs_needed)``: ``pairs_needed`` > 0 when the
    pair and contact buffers must grow before step ``steps_done`` (nothing of it has run). ``progress`` holds the
    step running and its contact count, for the caller to restore from ``backup`` when a kernel raises, and counts
    the steps in which some contacts were found again (``Scratch.steps_found_again``)."""
    model_rows, body_state, joint_impulses, buffers = (
        world.model_rows,
        world.body_state,
        world.joint_impulses,
        world.buffers,
    )
    settings = world.settings
    loads, idle, backup, progress, rec, gravity = (
        world.loads,
        world.idle,
        world.backup,
        world.progress,
        world.rec,
        world.gravity,
    )
    bodies, acts, stored = model_rows[0], loads[2], buffers[7]
    pos, quat, linvel, angmom, sleep_time, sleeping = body_state[:6]
    for step in range(first, n_steps):
        t = origin_time + (origin_count + step) * h
        failing_controller = command_stage(stage, gravity, acts, pos, quat, linvel, angmom, t, h)  # noqa: F821
        if failing_controller >= 0:
            return step, -1, failing_controller, count, 0
        for i in range(sleeping.shape[0]):
            if acts.driven[i]:
                sleep_time[i], sleeping[i] = 0.0, False
        progress[0], progress[1] = step, count
        _copy_state(body_state, stored, count, joint_impulses, backup[0], backup[1], backup[2])
        contact_state = (stored[0][:count], stored[1][:count], stored[2][:count], stored[3][:count],
                         stored[4][:count], stored[5][:count])  # fmt: skip
        step_loads = loads if step == 0 else idle
        new_count, most = pipeline.contact_stages(model_rows, body_state, contact_state, joint_impulses, step_loads,
                                                  buffers, settings, h, substeps)  # fmt: skip
        if new_count < 0:
            return step, -1, -1, count, -new_count
        failing = _first_non_finite_body(body_state, bodies.is_dynamic, backup[0])
        if failing >= 0:
            _copy_state(backup[0], backup[1], count, backup[2], body_state, stored, joint_impulses)
            return step, failing, -1, count, 0
        count = new_count
        progress[2] += most > 1
        advance_motors(acts, 0, bodies.mass.shape[0], h)
        if record_every > 0 and (step + 1) % record_every == 0:
            frame = (step + 1) // record_every - 1
            rec.pos[frame][:] = body_state[0]
            rec.quat[frame][:] = body_state[1]
            rec.linvel[frame][:] = body_state[2]
            rec.angmom[frame][:] = body_state[3]
    return n_steps, -1, -1, count, 0


@inline
def _copy_state(body_state, stored, count, joint_impulses, to_bodies, to_stored, to_joints):
    """The body arrays, the first ``count`` contact rows and the joints' impulses into the ``to_*`` arrays: element by
    element of the tuples, whose arrays differ in type (no loop can index them)."""
    to_bodies[0][:] = body_state[0]
    to_bodies[1][:] = body_state[1]
    to_bodies[2][:] = body_state[2]
    to_bodies[3][:] = body_state[3]
    to_bodies[4][:] = body_state[4]
    to_bodies[5][:] = body_state[5]
    to_bodies[6][:] = body_state[6]
    to_stored[0][:count] = stored[0][:count]
    to_stored[1][:count] = stored[1][:count]
    to_stored[2][:count] = stored[2][:count]
    to_stored[3][:count] = stored[3][:count]
    to_stored[4][:count] = stored[4][:count]
    to_stored[5][:count] = stored[5][:count]
    to_joints[0][:] = joint_impulses[0]
    to_joints[1][:] = joint_impulses[1]
    to_joints[2][:] = joint_impulses[2]


@inline
def _first_non_finite_body(body_state, is_dynamic, before):
    """The body with a non-finite value, dynamic bodies first (a static one only turns NaN through them); when
    several turned non-finite in the same step (one hit the other), the one that was fastest before it (first of
    equals); -1 for none."""
    pos, quat, linvel, angmom = body_state[0], body_state[1], body_state[2], body_state[3]
    found, found_dynamic, best, best_motion = -1, False, -1, -1.0
    for i in range(pos.shape[0]):
        if _finite_row(pos, i) and _finite_row(quat, i) and _finite_row(linvel, i) and _finite_row(angmom, i):
            continue
        if found_dynamic and not is_dynamic[i]:
            continue
        if is_dynamic[i] and not found_dynamic:  # the first dynamic one outranks the static ones found before
            found, found_dynamic, best, best_motion = -1, True, -1, -1.0
        motion = _motion(before[2], before[3], i)
        if found < 0:
            found = i
        if motion > best_motion:
            best, best_motion = i, motion
    return best if found >= 0 else -1


@inline
def _finite_row(array, i):
    """Whether row ``i`` of a 2-D array is all finite, element by element: ``np.isfinite(array[i]).all()`` allocated
    a temporary array for each row, four a body and step (8 of the 41 allocations of a box on a plane's step)."""
    for k in range(array.shape[1]):
        if not math.isfinite(array[i, k]):
            return False
    return True


@inline
def _motion(linvel, angmom, i):
    """|v| + |L| of body ``i`` (non-finite counts as infinite): a rough measure of which body runs away."""
    v, l = load3(linvel, i), load3(angmom, i)
    size = math.sqrt((v[0] * v[0] + v[1] * v[1]) + v[2] * v[2]) + math.sqrt((l[0] * l[0] + l[1] * l[1]) + l[2] * l[2])
    return size if math.isfinite(size) else math.inf


# After the helpers it calls: kernel_for copies the module's names as they are when it runs.
_plain_contact_loop = kernel_for(_contact_loop, "contact_loop", command_stage=_no_stage)


@functools.cache
def _staged_contact_loop(command):
    """The contact loop with a stage's ``command`` bound in (as :func:`_staged_steps`)."""
    name = getattr(command, "py_func", command).__name__.strip("_")
    return kernel_for(_contact_loop, f"contact_loop_{name}", command_stage=command)


def _fastest_body(backup, is_dynamic: np.ndarray) -> int:
    """The dynamic body that moved fastest before the step (:func:`_motion` of the backup), or -1 without one."""
    with np.errstate(over="ignore", invalid="ignore"):
        motion = [_motion(backup[0][2], backup[0][3], i) if is_dynamic[i] else -1.0 for i in range(is_dynamic.shape[0])]
    return int(np.argmax(motion)) if motion else -1


def record_frame(recording: Recording, record_every: int, step: int, state: State) -> None:
    """Frame ``(step + 1) / record_every - 1`` of ``recording`` from ``state`` after ``step``, when it is one."""
    if record_every > 0 and (step + 1) % record_every == 0:
        frame = (step + 1) // record_every - 1
        np.copyto(recording.pos[frame], state.body_pos)
        np.copyto(recording.quat[frame], state.body_quat)
        np.copyto(recording.linvel[frame], state.body_linvel)
        np.copyto(recording.angmom[frame], state.body_angmom)
