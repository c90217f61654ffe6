"""One step of a world: the order of the stages, and nothing else (no arithmetic here).

Free bodies (nothing can touch) take all the steps of a call at once, body by body, in the runner's compiled loop
(runner.py):

    advance_rows          model.body_*, inputs  -> state.body_*            (dynamics/integrate.py)

Bodies with contacts (the soft step of DESIGN.md):

    to_angular_velocity   state.body_angmom      -> scratch.body_angvel, body_inv_inertia_world (dynamics/substep.py)
    update_aabbs          state, geometry        -> world bounds           (geometry/broad_phase.py)
    find_pairs            bounds, filters        -> candidate pairs        (geometry/broad_phase.py)
    collide_pairs         pairs                  -> scratch.manifolds      (geometry/narrow_phase.py)
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
    store impulses        rows                   -> state.contact_*        (here)
    update_sleep          manifolds, velocities  -> state.body_sleep_*     (dynamics/islands.py)
    to_angular_momentum   scratch.body_angvel    -> state.body_angmom      (dynamics/substep.py)

Actuators and drag act inside the integrators, from each stage's or substep's state (dynamics/actuation.py).
The loop over steps (back up, restore on failure, record, advance the clock) is the runner's (runner.py).
"""

from __future__ import annotations

import numpy as np

from .dynamics.actuation import ActuatorArrays
from .dynamics.contact_solver import apply_restitution, prepare_contacts, rebase_contacts
from .dynamics.islands import update_sleep, wake_touched
from .dynamics.substep import run_substeps, to_angular_momentum, to_angular_velocity
from .geometry.broad_phase import find_pairs, update_aabbs
from .geometry.narrow_phase import allocate_manifolds, collide_each, collide_pairs, contact_passes, match_warm_start
from .geometry.toi import limit_to_impact
from .inputs import Inputs
from .model import Model
from .params import Params
from .scratch import Scratch
from .state import State

__all__ = ["contact_step"]


def contact_step(
    model: Model, state: State, inputs: Inputs, params: Params, scratch: Scratch, dt: float, acts: ActuatorArrays
) -> None:
    """One soft step of ``dt`` (see the module docstring for the stages)."""
    settings = params.solver
    substeps = settings.substeps_for(dt)
    h = dt / substeps
    bodies, geom = model.body_arrays, model.geometry
    angvel, inv_inertia_world = scratch.body_angvel, scratch.body_inv_inertia_world
    # Angular velocities and world inverse inertias at the start of the step.
    to_angular_velocity(bodies, state.body_quat, state.body_angmom, angvel, inv_inertia_world)
    # Broad phase: bounds swept over the step, candidate pairs.
    update_aabbs(
        geom,
        state.body_pos,
        state.body_quat,
        state.body_linvel,
        settings.speculative_distance,
        dt,
        scratch.aabb_lo,
        scratch.aabb_hi,
    )
    pairs_a, pairs_b = find_pairs(
        geom,
        state.body_pos,
        state.body_quat,
        scratch.aabb_lo,
        scratch.aabb_hi,
        model.body_is_dynamic,
        shape_group=model.shape_group,
        shape_mask=model.shape_mask,
        excluded_body_pairs=model.joint_exclusions,
        margin=settings.speculative_distance,
        buffer=scratch.pairs,
        segment_size=model.copy_shape_count,
    )
    # Narrow phase: manifolds, and the impulses of the same points last step.
    scratch.reserve_contacts(pairs_a.shape[0])
    manifolds = scratch.manifolds
    count = collide_pairs(
        geom,
        state.body_pos,
        state.body_quat,
        state.body_linvel,
        angvel,
        pairs_a,
        pairs_b,
        settings.speculative_distance,
        dt,
        manifolds,
    )
    match_warm_start(
        manifolds,
        count,
        state.contact_shape_a,
        state.contact_shape_b,
        state.contact_point_count,
        state.contact_feature,
        state.contact_normal_impulse,
        state.contact_tangent_impulse,
        scratch.warm_normal,
        scratch.warm_tangent,
    )
    # Sleeping islands that an awake body touches wake up; bodies that do not move count as fixed.
    if settings.sleep and state.body_sleeping.any():
        wake_touched(
            model.body_is_dynamic,
            geom.shape_body,
            manifolds,
            count,
            model.joints.body_a,
            model.joints.body_b,
            state.body_sleep_time,
            state.body_sleeping,
            state.body_island,
        )
    moving = model.body_is_dynamic & ~state.body_sleeping
    inv_mass = np.where(moving, bodies.inv_mass, 0.0)
    inv_inertia_world[~moving] = 0.0
    # Solver: prepare once, then the substeps, then restitution.
    rows = scratch.rows
    prepare_contacts(
        manifolds,
        count,
        geom.shape_body,
        model.shape_friction,
        model.shape_restitution,
        model.shape_rolling,
        model.shape_core_radius,
        inv_mass,
        inv_inertia_world,
        state.body_pos,
        state.body_linvel,
        angvel,
        scratch.warm_normal,
        scratch.warm_tangent,
        settings.contact_hertz,
        settings.contact_damping_ratio,
        h,
        rows,
    )
    pos0, quat0 = state.body_pos.copy(), state.body_quat.copy()
    scratch.joint_force_total[:] = 0.0
    scratch.joint_moment_total[:] = 0.0
    scratch.joint_step = dt

    def substeps_between(first: int, last: int) -> None:
        run_substeps(
            bodies,
            moving,
            inv_mass,
            model.body_gravity,
            inputs.body_force,
            inputs.body_torque,
            acts,
            rows,
            count,
            inv_inertia_world,
            state.body_pos,
            state.body_quat,
            pos0,
            quat0,
            state.body_linvel,
            angvel,
            h,
            first,
            last,
            settings.contact_push_max,
            settings.restitution_threshold,
            model.joints if model.joint_count > 0 else None,  # None: no joint solver compiled or run
            state.joint_impulses,
            settings.joint_hertz,
            settings.joint_damping_ratio,
            scratch.joint_force_total,
            scratch.joint_moment_total,
        )

    # Fast pairs, and the other pairs of their moving bodies, find their contacts again within the step
    # (contact_passes); by the motion of their own bodies only, so a batch's copies step as separate worlds would.
    passes = np.empty(count, dtype=np.int64)
    if substeps > 1 and contact_passes(geom.shape_body, geom.shape_aabb_center_local, geom.shape_aabb_half_local,
                                       moving, manifolds.shape_a, manifolds.shape_b, count, state.body_linvel, angvel,
                                       dt, passes) > 1:  # fmt: skip
        first = 0
        for last, listed in _pass_boundaries(passes, substeps):
            substeps_between(first, last)
            _find_again(model, state, settings, scratch, listed, (substeps - last) * h, inv_mass, pos0, quat0)
            first = last
        substeps_between(first, substeps)
    else:
        substeps_between(0, substeps)
    apply_restitution(rows, count, inv_mass, inv_inertia_world, state.body_pos, state.body_quat, pos0, quat0,
                      state.body_linvel, angvel, settings.restitution_threshold)  # fmt: skip
    # Fast bodies that would have passed into static geometry stop at their first touch (unless jointed).
    limit_to_impact(geom, model.body_is_dynamic, pairs_a, pairs_b, pos0, quat0, state.body_pos, state.body_quat,
                    model.body_free_to_sweep)  # fmt: skip
    _store_impulses(state, manifolds, rows, count)
    scratch.contact_count = count
    # Islands whose bodies have all been still long enough go to sleep.
    if settings.sleep:
        update_sleep(
            model.body_is_dynamic,
            geom.shape_body,
            manifolds,
            count,
            model.joints.body_a,
            model.joints.body_b,
            state.body_linvel,
            angvel,
            dt,
            settings.sleep_linear,
            settings.sleep_angular,
            settings.time_to_sleep,
            state.body_sleep_time,
            state.body_sleeping,
            state.body_island,
            scratch.island_parent,
            scratch.island_min_time,
        )
    to_angular_momentum(bodies, state.body_quat, angvel, state.body_angmom)


def _pass_boundaries(passes: np.ndarray, substeps: int):
    """``(k, rows)``: before substep ``k``, the rows whose contacts are found again, ``passes[m]`` equal runs of the
    substeps for row ``m`` (as equal as whole substeps allow)."""
    k = np.arange(1, substeps)
    starts = (k * passes[:, None]) // substeps > ((k - 1) * passes[:, None]) // substeps
    for column in np.flatnonzero(starts.any(axis=0)):
        yield int(k[column]), np.flatnonzero(starts[:, column])


def _find_again(model, state, settings, scratch, listed, remaining, inv_mass, pos0, quat0) -> None:
    """The contacts of manifolds ``listed`` found again at the poses now, into their rows (``remaining``: the time
    left in the step, which the speculative margin looks ahead)."""
    manifolds, angvel = scratch.manifolds, scratch.body_angvel
    fresh = allocate_manifolds(listed.shape[0])
    collide_each(model.geometry, state.body_pos, state.body_quat, state.body_linvel, angvel,
                 manifolds.shape_a[listed], manifolds.shape_b[listed], settings.speculative_distance, remaining,
                 fresh)  # fmt: skip
    rebase_contacts(listed, fresh, manifolds, scratch.rows, inv_mass, scratch.body_inv_inertia_world, state.body_pos,
                    state.body_quat, pos0, quat0, state.body_linvel, angvel)  # fmt: skip


def _store_impulses(state: State, manifolds, rows, count: int) -> None:
    """Keep this step's impulses, keyed by shape pair and feature, to warm-start the next step."""
    state.contact_shape_a = manifolds.shape_a[:count].copy()
    state.contact_shape_b = manifolds.shape_b[:count].copy()
    state.contact_point_count = manifolds.point_count[:count].copy()
    state.contact_feature = manifolds.feature[:count].copy()
    state.contact_normal_impulse = rows.normal_impulse[:count].copy()
    state.contact_tangent_impulse = (
        rows.tangent_impulse[:count, :, 0, None] * rows.tangent1[:count, None, :]
        + rows.tangent_impulse[:count, :, 1, None] * rows.tangent2[:count, None, :]
    )
    # Slots past each manifold's point count hold leftovers of earlier steps: zero them, so that the state (and
    # its digest) holds only what the next step reads.
    unused = np.arange(state.contact_feature.shape[1])[None, :] >= state.contact_point_count[:, None]
    state.contact_feature[unused] = 0
    state.contact_normal_impulse[unused] = 0.0
    state.contact_tangent_impulse[unused] = 0.0
