"""One step of a world: the order of the stages, and nothing else (no arithmetic here).

Free bodies (no contacts, no joints yet):

    advance_free_bodies   model.body_*, inputs  -> state.body_pos/quat/linvel/angmom   (dynamics/integrate.py)
    clear inputs          applied forces act during one step only                     (inputs.py)

The contact and joint stages of DESIGN.md (broad phase, narrow phase, soft-step substeps) slot in
before the integration when the model has constraints.
"""

from __future__ import annotations

from .dynamics.integrate import Recording, advance_free_bodies
from .inputs import Inputs
from .model import Model
from .params import Params
from .scratch import Scratch
from .state import State

__all__ = ["simulate_steps"]


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
) -> tuple[int, int]:
    """Advance ``n_steps`` steps of ``h``; returns ``(steps_done, failing_body)`` (-1 when all went well)."""
    method = params.resolve_integrator(model.has_constraints)
    steps_done, failing_body = advance_free_bodies(
        model,
        state,
        inputs.body_force,
        inputs.body_torque,
        scratch,
        h,
        n_steps,
        method,
        recording,
        record_every,
    )
    state.step_count += steps_done
    # Accumulate time step by step so that simulate(n steps) and n calls of step() agree bit for bit.
    time = state.time
    for _ in range(steps_done):
        time += h
    state.time = time
    if steps_done > 0:
        inputs.clear()
    return steps_done, failing_body
