"""A world's arrays as one compiled object (:class:`CompiledWorld`, a Numba StructRef): what the runner's loops
(``runner.py``) read and write, given to them as one argument.

A call of a compiled function from Python unboxes and reference-counts each array it receives, about 0.3 µs each.
The contact loop reads some hundred arrays (the model's rows, the state, the scratch buffers): 25 µs before a step
of a box on a plane began, the step itself taking 28 µs. A record is one pointer to unbox (under a microsecond). It
holds the world's own arrays, not copies, so ``world.state.*``, ``world.ctrl`` and the handles stay views of what the
loops write. It is built again only when an array it holds has been replaced: a body, joint or actuator added, a
setting changed, a state assigned, the contact buffers grown (:func:`compiled_world` checks, at each call).
"""

from __future__ import annotations

import operator
from typing import NamedTuple

import numpy as np

from . import pipeline
from ._jit import Record, RecordType, define_record, kernel
from .dynamics.actuation import ActuatorArrays
from .dynamics.integrate import Recording
from .inputs import Inputs
from .model import Model
from .params import Params
from .scratch import Scratch
from .state import BODY_FIELDS, JOINT_FIELDS, State

__all__ = ["Compiled", "CompiledWorld", "compiled_world", "held", "same_objects"]

_FIELDS = (
    "gravity",  # (3,) the model's gravity
    "model_rows",  # pipeline.model_rows: bodies, shapes, pair filters, joints
    "body_state",  # pipeline.body_state: pos, quat, linvel, angmom, sleep time, sleeping, island
    "joint_impulses",  # State.joint_impulses
    "loads",  # (force, torque, actuators) of a call's first step
    "idle",  # (zeros, zeros, actuators): the loads of its other steps
    "buffers",  # pipeline.buffers: the contact step's scratch
    "backup",  # room for the state before a contact step: bodies, contact rows, joints' impulses
    "free_backup",  # room for the free bodies before a chunk of steps (Scratch.backup)
    "failed_step",  # (n,) the step each free body became non-finite in (Scratch.failed_step)
    "progress",  # (3,) int64: the contact step running, its contact count, the steps found again
    "rec",  # the frames of the call (Scratch.no_recording when it records none)
    "settings",  # the solver's settings (Params.solver)
)


class CompiledWorldType(RecordType):
    """The compiled type of :class:`CompiledWorld`: one for every world (its arrays' types do not vary)."""


class CompiledWorld(Record):
    """A world's arrays for the runner's loops, as one compiled object (the fields of ``_FIELDS``)."""


define_record(CompiledWorld, CompiledWorldType, _FIELDS)


@kernel
def _build(gravity, model_rows, body_state, joint_impulses, loads, idle, buffers, backup, free_backup, failed_step,
           progress, rec, settings):  # fmt: skip
    return CompiledWorld(gravity, model_rows, body_state, joint_impulses, loads, idle, buffers, backup, free_backup,
                         failed_step, progress, rec, settings)  # fmt: skip


class Compiled(NamedTuple):
    """A world's record, the values it holds, and those of them that the runner's Python also reads: the contact
    loop's ``progress`` and ``backup`` (to restore the state when a kernel raises mid-step)."""

    record: CompiledWorld
    values: tuple
    progress: np.ndarray
    backup: tuple


# The state's arrays a record holds, read in one call (a step checks them: any may have been assigned anew).
_STATE_ARRAYS = operator.attrgetter(*BODY_FIELDS, *JOINT_FIELDS)


def held(model: Model, state: State, inputs: Inputs, params: Params, acts: ActuatorArrays) -> tuple:
    """The objects a record is built from: while each is the same object (not just equal), the record holds the
    world's arrays."""
    return (model, state, inputs, inputs.body_force, inputs.body_torque, acts, params.solver, *_STATE_ARRAYS(state))


def same_objects(these: tuple, those: tuple) -> bool:
    """Whether the tuples hold the same objects, one by one (identities: arrays are never compared by value)."""
    return all(map(operator.is_, these, those))


def compiled_world(
    model: Model,
    state: State,
    inputs: Inputs,
    params: Params,
    scratch: Scratch,
    acts: ActuatorArrays,
    recording: Recording | None = None,
) -> Compiled:
    """The record of these arrays: the one kept in ``scratch`` while the objects it was built from are the same
    (:func:`held`), else a new one, then kept. With a ``recording`` (a ``simulate`` call's frames) a record for the
    call, sharing all but its frames with the kept one."""
    objects = held(model, state, inputs, params, acts)
    kept = scratch.compiled
    if kept is None or not same_objects(objects, kept[0]):
        kept = objects, _built(model, state, inputs, params, scratch, acts)
        scratch.compiled = kept
    compiled = kept[1]
    if recording is None:
        return compiled
    values = (*compiled.values[:_RECORDING], recording, *compiled.values[_RECORDING + 1 :])
    return compiled._replace(record=_build(*values), values=values)


_RECORDING = _FIELDS.index("rec")


def _built(model, state, inputs, params, scratch, acts) -> Compiled:
    body_state = pipeline.body_state(state)
    progress = np.zeros(3, np.int64)
    backup = (tuple(np.empty_like(a) for a in body_state), tuple(np.empty_like(a) for a in scratch.stored),
              tuple(np.empty_like(a) for a in state.joint_impulses))  # fmt: skip
    values = (
        model.gravity,
        pipeline.model_rows(model),
        body_state,
        state.joint_impulses,
        (inputs.body_force, inputs.body_torque, acts),
        (np.zeros_like(inputs.body_force), np.zeros_like(inputs.body_torque), acts),
        pipeline.buffers(scratch),
        backup,
        scratch.backup,
        scratch.failed_step,
        progress,
        scratch.no_recording,
        params.solver,
    )
    return Compiled(_build(*values), values, progress, backup)
