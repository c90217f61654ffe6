"""One step of a world: the order of the stages, and nothing else (no arithmetic here).

Free bodies (nothing can touch) take all the steps of a call at once, body by body, in the runner's compiled loop
(runner.py):

    advance_rows          model.body_*, inputs  -> state.body_*            (dynamics/integrate.py)

Bodies with contacts (the soft step of DESIGN.md), all of it compiled (``contact_stages``) and inlined into the
runner's compiled loop of steps, which a call of ``World.step`` or ``simulate`` enters once. The narrow phase's loop
of every pair type is compiled in (one copy for every world, cached on disk; the loops of pair types a world lacks
never run):

    to_angular_velocity   state.body_angmom      -> scratch.body_angvel, body_inv_inertia_world (dynamics/substep.py)
    update_aabbs          state, geometry        -> world bounds           (geometry/broad_phase.py)
    sweep_and_prune       bounds, filters        -> candidate pairs        (geometry/broad_phase.py); more than
                          the buffers hold: the call returns before anything but scratch changed, and runs again
    collide_each          pairs                  -> scratch.manifolds      (geometry/narrow_phase.py)
    keep_touching         manifolds              -> those with points      (geometry/narrow_phase.py)
    match_warm_start      state.contact_*        -> scratch.warm_*         (geometry/narrow_phase.py)
    wake_touched          manifolds              -> state.body_sleeping    (dynamics/islands.py)
    prepare_contacts      manifolds, bodies      -> scratch.rows           (dynamics/contact_solver.py)
    contact_passes        manifolds, velocities  -> how often each pair finds its contacts in the step (narrow_phase.py)
    run_substeps          integrate v, ball impacts, warm start, solve, integrate x, relax: joints
                          (dynamics/joint_solver.py), then contacts (dynamics/contact_solver.py); between runs of
                          them, the fast pairs' contacts found again at the poses then:
      collide_each        listed pairs           -> fresh manifolds        (geometry/narrow_phase.py)
      rebase_contacts     fresh manifolds        -> their manifolds, rows  (dynamics/contact_solver.py)
    apply_restitution     rows                   -> velocities             (dynamics/contact_solver.py)
    limit_to_impact       pairs, poses           -> poses of fast bodies   (geometry/toi.py)
    store_impulses        rows                   -> scratch.stored, then state.contact_* (dynamics/contact_solver.py)
    update_sleep          manifolds, velocities  -> state.body_sleep_*     (dynamics/islands.py)
    to_angular_momentum   scratch.body_angvel    -> state.body_angmom      (dynamics/substep.py)

Actuators and drag act inside the integrators, from each stage's or substep's state (dynamics/actuation.py).
The loop over steps (back up, restore on failure, record, advance the clock) is the runner's (runner.py).
"""

from __future__ import annotations

import numpy as np

from ._jit import inline
from .dynamics.contact_solver import apply_restitution, prepare_contacts, rebase_contacts, store_impulses
from .dynamics.islands import update_sleep, wake_touched
from .dynamics.substep import run_substeps, to_angular_momentum, to_angular_velocity
from .geometry.broad_phase import pair_filters, sweep_and_prune, update_aabbs
from .geometry.narrow_phase import (
    COLLIDER_OF,
    compiled_collide_each,
    contact_passes,
    keep_touching,
    match_warm_start,
    passes_due,
)
from .geometry.toi import limit_to_impact
from .model import Model
from .scratch import Scratch
from .state import State

__all__ = ["body_state", "buffers", "contact_stages", "model_rows"]


def model_rows(model: Model) -> tuple:
    """The model's arrays as :func:`contact_stages` reads them."""
    shape_rows = (model.shape_friction, model.shape_restitution, model.shape_rolling, model.shape_core_radius)
    filters = pair_filters(model.shape_count, model.shape_group, model.shape_mask, model.joint_exclusions)
    return (model.body_arrays, model.geometry, model.body_gravity, model.body_free_to_sweep, shape_rows, filters,
            model.copy_shape_count, model.joints, COLLIDER_OF)  # fmt: skip


def body_state(state: State) -> tuple:
    """The state's per-body arrays as :func:`contact_stages` reads and writes them (in place)."""
    return (state.body_pos, state.body_quat, state.body_linvel, state.body_angmom, state.body_sleep_time,
            state.body_sleeping, state.body_island)  # fmt: skip


def buffers(scratch: Scratch) -> tuple:
    """The scratch arrays :func:`contact_stages` works in (to take again after ``scratch.reserve_contacts``)."""
    return (scratch.pairs.a, scratch.pairs.b, scratch.manifolds, scratch.fresh, scratch.rows, scratch.warm_normal,
            scratch.warm_tangent, scratch.stored, scratch.body_angvel, scratch.body_inv_inertia_world, scratch.aabb_lo,
            scratch.aabb_hi, scratch.joint_force_total, scratch.joint_moment_total, scratch.island_parent,
            scratch.island_min_time)  # fmt: skip


@inline(into_callers=True)
def contact_stages(model_rows, body_state, contact_state, joint_impulses, loads, buffers, settings, dt, substeps):
    """One soft step of ``dt`` in ``substeps``: the stages of the module docstring in order, over the groups of
    arrays that :func:`model_rows`, :func:`body_state` and :func:`buffers` give (``loads``: applied force, torque
    and the actuators). ``contact_state`` is the last step's ``State.contact_*`` arrays, read before this step's
    impulses go to ``scratch.stored`` (they may be its rows). Returns ``(manifolds, most passes)``, or
    ``(-candidate pairs, 0)`` when the pair and contact buffers hold fewer (then nothing but scratch has changed:
    grow them and step again). Inlined into the runner's compiled loop, its one caller (a kernel of its own would be
    optimised twice, once alone and once in the loop: a minute of a cold start)."""
    bodies, geom, gravity, free_to_sweep, shape_rows, filters, segment_size, joints, collider_of = model_rows
    pos, quat, linvel, angmom, sleep_time, sleeping, island = body_state
    force, torque, acts = loads
    (pairs_a, pairs_b, manifolds, fresh, rows, warm_normal, warm_tangent, stored, angvel, inv_inertia_world, aabb_lo,
     aabb_hi, joint_force_total, joint_moment_total, island_parent, island_min_time) = buffers  # fmt: skip
    h = dt / substeps
    margin = settings.speculative_distance
    # Angular velocities and world inverse inertias at the start of the step.
    to_angular_velocity(bodies, quat, angmom, angvel, inv_inertia_world)
    # Broad phase: bounds swept over the step, candidate pairs.
    update_aabbs(geom, pos, quat, linvel, margin, dt, aabb_lo, aabb_hi)
    group, mask, excluded = filters
    pair_count = sweep_and_prune(geom, pos, quat, aabb_lo, aabb_hi, bodies.is_dynamic, group, mask, excluded, margin,
                                 segment_size, pairs_a, pairs_b)  # fmt: skip
    if pair_count > pairs_a.shape[0] or pair_count > manifolds.shape_a.shape[0]:
        return -pair_count, 0
    pairs_a, pairs_b = pairs_a[:pair_count], pairs_b[:pair_count]
    # Narrow phase: manifolds, and the impulses of the same points last step.
    compiled_collide_each(geom, pos, quat, linvel, angvel, pairs_a, pairs_b, margin, dt, manifolds, collider_of)
    count = keep_touching(manifolds, pair_count)
    match_warm_start(manifolds, count, *contact_state, warm_normal, warm_tangent)
    # Sleeping islands that an awake body touches wake up; bodies that do not move count as fixed.
    if settings.sleep and sleeping.any():
        wake_touched(bodies.is_dynamic, geom.shape_body, manifolds, count, joints.body_a, joints.body_b, sleep_time,
                     sleeping, island)  # fmt: skip
    moving = bodies.is_dynamic & ~sleeping
    inv_mass = np.where(moving, bodies.inv_mass, 0.0)
    for i in range(moving.shape[0]):
        if not moving[i]:
            inv_inertia_world[i] = 0.0
    # Solver: prepare once, then the substeps, then restitution.
    friction, restitution, rolling, core_radius = shape_rows
    prepare_contacts(manifolds, count, geom.shape_body, friction, restitution, rolling, core_radius, inv_mass,
                     inv_inertia_world, pos, linvel, angvel, warm_normal, warm_tangent, settings.contact_hertz,
                     settings.contact_damping_ratio, h, rows)  # fmt: skip
    pos0, quat0 = pos.copy(), quat.copy()
    joint_force_total[:] = 0.0
    joint_moment_total[:] = 0.0
    substeps_args = (bodies, moving, inv_mass, gravity, force, torque, acts, rows, count, inv_inertia_world, pos,
                     quat, pos0, quat0, linvel, angvel, h)  # fmt: skip
    solver_args = (settings.contact_push_max, settings.restitution_threshold, joints, joint_impulses,
                   settings.joint_hertz, settings.joint_damping_ratio, joint_force_total,
                   joint_moment_total)  # fmt: skip
    # Fast pairs, and the other pairs of their moving bodies, find their contacts again within the step
    # (contact_passes); by the motion of their own bodies only, so a batch's copies step as separate worlds would.
    passes = np.empty(count, np.int64)
    first, most = 0, 1
    if substeps > 1:
        most = contact_passes(geom.shape_body, geom.shape_aabb_center_local, geom.shape_aabb_half_local, moving,
                              manifolds.shape_a, manifolds.shape_b, count, linvel, angvel, dt, passes)  # fmt: skip
    if most > 1:
        listed = np.empty(count, np.int64)
        for k in range(1, substeps):
            due = passes_due(passes, count, k, substeps, listed)
            if due == 0:
                continue
            run_substeps(*substeps_args, first, k, *solver_args)
            # The listed manifolds' contacts found again at the poses now; the margin looks ahead to the step's end.
            again = listed[:due]
            compiled_collide_each(geom, pos, quat, linvel, angvel, manifolds.shape_a[again], manifolds.shape_b[again],
                                  margin, (substeps - k) * h, fresh, collider_of)  # fmt: skip
            rebase_contacts(again, fresh, manifolds, rows, inv_mass, inv_inertia_world, pos, quat, pos0, quat0,
                            linvel, angvel)  # fmt: skip
            first = k
    run_substeps(*substeps_args, first, substeps, *solver_args)
    apply_restitution(rows, count, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel,
                      settings.restitution_threshold)  # fmt: skip
    # Fast bodies that would have passed into static geometry stop at their first touch (unless jointed).
    limit_to_impact(geom, bodies.is_dynamic, pairs_a, pairs_b, pos0, quat0, pos, quat, free_to_sweep)
    store_impulses(manifolds, rows, count, *stored)
    # Islands whose bodies have all been still long enough go to sleep.
    if settings.sleep:
        update_sleep(bodies.is_dynamic, geom.shape_body, manifolds, count, joints.body_a, joints.body_b, linvel, angvel,
                     dt, settings.sleep_linear, settings.sleep_angular, settings.time_to_sleep, sleep_time, sleeping,
                     island, island_parent, island_min_time)  # fmt: skip
    to_angular_momentum(bodies, quat, angvel, angmom)
    return count, most
