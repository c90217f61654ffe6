"""The runner: a world's arrays advanced ``n`` steps, backed up before each, restored on a non-finite value, a frame
recorded every ``record_every`` steps, the clock and the motors advanced. ``World.step``, ``World.simulate``
(``world_stepping.py``), ``Batch`` and the compiled stages of controllers all come here.

    simulate_steps        free bodies: every step in one compiled call (dynamics/integrate.py), which keeps its own
                          backup and replays to the last good step; else one pipeline.contact_step a step
    advance_clock         time accumulated step by step (n steps in one call = n calls of one step, bit for bit)
"""

from __future__ import annotations

import numpy as np

from .dynamics.actuation import ActuatorArrays, advance_motors
from .dynamics.integrate import Recording, advance_free_bodies
from .inputs import Inputs
from .model import Model
from .params import Integrator, Params
from .pipeline import contact_step
from .scratch import Scratch
from .state import State

__all__ = ["advance_clock", "record_frame", "simulate_steps"]


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
) -> tuple[int, int]:
    """Advance ``n_steps`` steps of ``h``; returns ``(steps_done, failing_body)`` (-1 when all went well).

    ``acts`` are the actuators, drag and wind (none if ``None``); their motors' speeds advance with the steps.
    """
    if acts is None:
        acts = ActuatorArrays.empty(model.body_count)
    if model.has_constraints:
        steps_done, failing_body = _contact_steps(
            model, state, inputs, params, scratch, h, n_steps, recording, record_every, acts
        )
    else:
        method = params.resolve_integrator(False)
        steps_done, failing_body = advance_free_bodies(
            model, state, inputs.body_force, inputs.body_torque, acts, scratch, h, n_steps, method, recording,
            record_every,
        )  # fmt: skip
        advance_clock(state, h, steps_done)
        _advance_motors(acts, steps_done * h)
    # The applied loads act in the first step; one that failed drops them too (the world keeps its state from
    # before it), or a load that makes every step overflow (RK4 sums four stages of it) would leave it stuck.
    inputs.clear()
    return steps_done, failing_body


def _advance_motors(acts: ActuatorArrays, elapsed: float) -> None:
    """The rotors' speeds ``elapsed`` on; nothing to enter the kernel for without any (5 µs a step)."""
    if acts.speed.shape[0]:
        advance_motors(acts, elapsed)


def advance_clock(state: State, h: float, steps: int) -> None:
    # Accumulate time step by step so that simulate(n steps) and n calls of step() agree bit for bit.
    time = state.time
    for _ in range(steps):
        time += h
    state.time = time
    state.step_count += steps


def _contact_steps(model, state, inputs, params, scratch, h, n_steps, recording, record_every, acts):
    """Soft steps one after the other; on a non-finite value, restore the state before that step."""
    if params.resolve_integrator(True) != Integrator.SYMPLECTIC:
        raise ValueError(
            f"integrator={params.integrator!r} integrates free bodies only; a world whose shapes can touch or whose "
            "bodies are jointed steps with the contact and joint solver: use integrator='auto' or 'symplectic'"
        )
    zero = Inputs.zeros(model.body_count)
    for step in range(n_steps):
        before = state.copy()
        loads = inputs if step == 0 else zero  # applied loads act during the first step only
        try:
            contact_step(model, state, loads, params, scratch, h, acts)
            bad = _first_non_finite_body(state, model.body_is_dynamic, before)
        except (ZeroDivisionError, FloatingPointError):  # a kernel divided by an overflowed value
            bad = _fastest_body(before, model.body_is_dynamic)
        if bad >= 0:
            state.assign(before)
            return step, bad
        advance_clock(state, h, 1)
        _advance_motors(acts, h)
        record_frame(recording, record_every, step, state)
    return n_steps, -1


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
