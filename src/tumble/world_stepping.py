"""How a world steps: ``World.step`` and ``World.simulate`` around the runner (``runner.py``). A room of
:class:`~tumble.World`: these functions read and write the world's parts as its own methods would.

Before each step the controllers that are due run (``controllers.py``), or the compiled stage that stands in for
them; the actuators' arrays and the wind are taken for the step; the runner advances the arrays; the sensors sample.
A world with none of these Python parts takes all the steps of ``simulate`` in one call of the runner.
"""

from __future__ import annotations

import numpy as np

from ._validate import as_count, as_float, as_step, step_count
from .errors import SimulationError
from .params import substeps_to_run
from .runner import ReadyStep, simulate_steps, step_by_step
from .trajectory import Trajectory
from .wind import Constant

__all__ = ["checked_step", "note_substeps", "simulate", "step", "substeps_run"]


def step(world, dt: float) -> None:
    """``World.step``: the controllers due, one step of ``dt`` by the runner, the sensors' samples (or a
    :class:`SimulationError` for the failing body, the world as it was).

    A world without controllers, sensors or wind takes the step the runner prepared at its last one
    (``runner.ReadyStep``) while nothing it holds has changed: ``dt`` checked, the objects compared, one call. The
    world's methods that add a Python part forget it (``scratch.ready``)."""
    ready = world._scratch.ready
    if ready is not None and ready.fits(world._model, world._state, world._inputs, world._params,
                                        world._actuation._arrays):  # fmt: skip
        dt = as_step("dt", dt, world._state.time)
        if dt != world._last_dt:
            note_substeps(world, dt)
        failing = ready(dt)
    else:
        dt = checked_step(world, dt)
        failing = _controlled_step(world, dt)
        if not (world._controllers or world._sensors or world._wind is not None):
            world._scratch.ready = ReadyStep.of(world._model, world._state, world._inputs, world._params,
                                                world._scratch, world._actuation._arrays)  # fmt: skip
    if failing >= 0:
        raise _simulation_error(world, failing)


def checked_step(world, dt) -> float:
    """``dt`` checked as a step of ``world``: one that advances its time and, where the contact solver runs,
    needs no more substeps than it allows (before any controller runs or state changes)."""
    dt = as_step("dt", dt, world._state.time)
    world._sync()
    note_substeps(world, dt)
    return dt


def substeps_run(world) -> int:
    """``World.substeps``: what the last step's ``dt`` runs with the solver's settings now; before the first step, and
    in a world whose bodies neither touch nor are jointed (they take no substeps), the number asked."""
    solver = world._params.solver
    if world._last_dt is None or world._model is None or not world._model.has_constraints:
        return solver.substeps
    return solver.substeps_for(world._last_dt)


def note_substeps(world, dt: float) -> None:
    """Keep ``dt`` as the world's last step (``World.substeps``); where the contact solver runs, check its substeps
    and warn, once, if it must raise them."""
    if world._model.has_constraints:
        substeps_to_run(world._params.solver, dt, world._substeps_told)
    world._last_dt = dt


def _controlled_step(world, dt: float, stage=None) -> int:
    """The controllers that are due (or the compiled ``stage`` in their place), one step, the sensors' samples:
    the failing body's row, or -1. A part the world lacks costs a check, not a call.

    Raises:
        SimulationError: a controller raised (before the step: the world is as it was).
    """
    if stage is not None:
        stage.command(world._model, world._state, world._actuation.arrays, _next_step_time(world, dt), dt)
        world._sync()
    elif world._controllers:
        world._controllers.run(world, _next_step_time(world, dt), dt)
        world._sync()  # a controller may have added bodies
    sensors = world._sensors
    if sensors:
        sensors.before_step(world)
    failing = simulate_steps(world._model, world._state, world._inputs, world._params, world._scratch, dt,
                             acts=_actuators_for_step(world, dt)).failing_body  # fmt: skip
    if failing < 0 and sensors:
        sensors.sample(world, dt)
    return failing


def _next_step_time(world, dt: float) -> float:
    """The next step's start time as controllers and wind see it: counted, not accumulated."""
    return world._clock.start_of_next_step(world._state.time, world._state.step_count, dt)


_CALM = np.zeros(3)
_CALM.flags.writeable = False


def _actuators_for_step(world, dt: float):
    """The actuators' arrays with the wind for the next steps (the runner's loops keep their bodies awake: thrust that
    holds a body still must not let it sleep, or a change of wind or command would not reach it)."""
    actuation = world._actuation
    actuation.wind = _CALM if world._wind is None else world._wind.velocity(_next_step_time(world, dt), dt)
    return actuation.for_bodies(world._model.body_com_local)


def simulate(world, duration: float, dt: float, record_every: int = 1) -> Trajectory:
    """``World.simulate``: one call of the runner for all the steps, or a Python loop of :func:`step`'s parts where
    controllers, sensors or a changing wind need one; the trajectory, or the error carrying it."""
    duration = as_float("duration", duration, positive=True)
    dt = checked_step(world, dt)
    record_every = as_count("record_every", record_every)
    n_steps = step_count(duration, dt)
    world._sync()
    t0, initial = world._state.time, world._state.copy()
    recording = Trajectory.allocate_recording(world._state.body_count, n_steps // record_every)
    controller_error = None
    stage = _compiled_stage(world)
    if stage is not None:
        steps_done, failing, controller_error = _simulate_stage(world, stage, dt, n_steps, recording,
                                                                     int(record_every))  # fmt: skip
    elif world._controllers or world._sensors or not isinstance(world._wind, (Constant, type(None))):
        steps_done, failing, controller_error = _simulate_stepwise(world, dt, n_steps, recording, int(record_every))
    else:
        steps_done, failing, _ = simulate_steps(
            world._model,
            world._state,
            world._inputs,
            world._params,
            world._scratch,
            dt,
            n_steps,
            recording,
            int(record_every),
            _actuators_for_step(world, dt),
        )
    frames = steps_done // record_every
    trajectory = Trajectory.from_recording(
        world._model, initial, recording, frames, t0 + dt * record_every * np.arange(1, frames + 1), dt
    )
    if controller_error is not None or failing >= 0:
        error = controller_error if controller_error is not None else _simulation_error(world, failing)
        error.trajectory = trajectory
        raise error
    return trajectory


def _compiled_stage(world):
    """The compiled stage that runs every controller of ``world`` in their place (``Controllers.compiled_stage``),
    or None."""
    if not world._controllers:
        return None
    world._sync()
    world._actuation.for_bodies(world._model.body_com_local)  # the actuators' rows in the arrays
    return world._controllers.compiled_stage(world)


def _simulate_stage(world, stage, dt: float, n_steps: int, recording, record_every: int):
    """The steps with the compiled ``stage`` between them: ``(steps_done, failing_body, error)`` as
    :func:`_simulate_stepwise`. Without sensors and with a constant wind, all the steps take one call of the runner,
    the stage compiled into its loop; else each step is a call, and the stage one more (instead of a Python
    controller each)."""
    if world._sensors or not isinstance(world._wind, (Constant, type(None))):
        result = _simulate_stepwise(world, dt, n_steps, recording, record_every, stage=stage)
    else:
        state = world._state
        clock = world._clock.count(state.time, state.step_count, dt)
        steps = simulate_steps(world._model, state, world._inputs, world._params, world._scratch, dt, n_steps,
                               recording, record_every, _actuators_for_step(world, dt), stage, clock)  # fmt: skip
        error = None
        if steps.failing_controller >= 0:  # before the step ``steps.done``, at its counted start time
            error = stage.failure(steps.failing_controller, _next_step_time(world, dt), state.step_count)
        result = steps.done, steps.failing_body, error
    stage.finish()
    return result


def _simulate_stepwise(world, dt: float, n_steps: int, recording, record_every: int, stage=None):
    """Step by step in the runner's Python loop, the controllers (or the compiled ``stage``) before each step and
    the sensors after it: ``(steps_done, failing_body, error)``."""
    start = world._state.step_count

    def one_step(step: int) -> int:
        failing = _controlled_step(world, dt, stage)
        if world._state.body_count != recording.pos.shape[1]:
            raise ValueError("a controller added bodies during simulate; add them before it, or between calls")
        return failing

    try:
        steps = step_by_step(n_steps, one_step, recording, record_every, world._state)
    except SimulationError as error:  # a controller raised before a step: the steps before it are done
        return world._state.step_count - start, -1, error
    return steps.done, steps.failing_body, None


def _simulation_error(world, row: int) -> SimulationError:
    name = world._model.body_name[row]
    label = repr(name) if name is not None else f"#{row}"
    step = world._state.step_count
    return SimulationError(
        f"body {label} became non-finite (NaN or Inf) in step {step} (t = {world._state.time:.6g} s); "
        "the world keeps its state from before that step (the loads applied for it are dropped)",
        body=name if name is not None else row,
        step=step,
    )
