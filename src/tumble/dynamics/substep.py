"""The substep loop of the soft step, and the velocity/position integration it uses.

Velocities are semi-implicit Euler with the gyroscopic term implicit (``free_motion.implicit_spin``), so that
contact worlds are stable at 60 Hz; positions move with the new velocities. During the substeps the angular
state is ω (world frame), which the contact impulses change directly; the step converts ``L → ω`` before and
``ω → L`` after (``to_angular_velocity`` and ``to_angular_momentum``).
"""

from __future__ import annotations

from .._jit import inline, kernel
from ..math3d import (
    add,
    add_scaled,
    load3,
    load4,
    load33,
    quat_integrate,
    quat_rotate,
    quat_rotate_inv,
    scale,
    store3,
    store4,
    store33,
    turned_symmetric33,
    world_inertia_apply,
)
from .actuation import actuator_wrench
from .contact_solver import accumulate_impulses, impact_work, resolve_impacts, solve_contacts, warm_start_contacts
from .free_motion import implicit_spin
from .joint_solver import solve_joints, warm_start_joints

__all__ = ["run_substeps", "to_angular_velocity", "to_angular_momentum"]


@kernel
def to_angular_velocity(bodies, quat, angmom, angvel, inv_inertia_world):
    """``ω = R I⁻¹ Rᵀ L`` and ``R I⁻¹ Rᵀ`` of every body (zeros for static bodies).

    Writes: angvel (n, 3), inv_inertia_world (n, 3, 3).
    """
    for i in range(quat.shape[0]):
        store3(angvel, i, world_inertia_apply(load4(quat, i), load33(bodies.inv_inertia_local, i), load3(angmom, i)))
        _store_world_inverse_inertia(bodies, quat, i, inv_inertia_world)


@inline
def _store_world_inverse_inertia(bodies, quat, i, inv_inertia_world):
    """Body ``i``'s ``R I⁻¹ Rᵀ`` at its orientation now."""
    turned = turned_symmetric33(load4(quat, i), load33(bodies.inv_inertia_local, i))
    store33(inv_inertia_world, i, turned)


@inline(counted=False)
def to_angular_momentum(bodies, quat, angvel, angmom):
    """``L = R I Rᵀ ω`` of every dynamic body. Writes: angmom."""
    for i in range(quat.shape[0]):
        if bodies.is_dynamic[i]:
            store3(angmom, i, world_inertia_apply(load4(quat, i), load33(bodies.inertia_local, i), load3(angvel, i)))


@inline(counted=False)
def integrate_velocities(bodies, moving, gravity, force, torque, acts, tau, quat, linvel, angvel, h):
    """``v += h (g + F/m)`` (``gravity``: (bodies, 3), each body's ``g``), implicit gyroscopic spin update, implicit
    damping; moving (awake dynamic) bodies. The actuators' and drag's loads are those of the substep's start state,
    ``tau`` into the step."""
    for i in range(quat.shape[0]):
        if not moving[i]:
            continue
        q = load4(quat, i)
        applied = add(load3(force, i), load3(bodies.constant_force, i))
        spin = add(load3(torque, i), load3(bodies.constant_torque, i))
        if acts.driven[i]:
            driven_force, driven_torque = actuator_wrench(acts, i, tau, q, load3(linvel, i), load3(angvel, i))
            applied, spin = add(applied, driven_force), add(spin, driven_torque)
        accel = add_scaled(load3(gravity, i), applied, bodies.inv_mass[i])
        v = scale(add_scaled(load3(linvel, i), accel, h), 1.0 / (1.0 + h * bodies.linear_damping[i]))
        store3(linvel, i, v)
        w_body = quat_rotate_inv(q, load3(angvel, i))
        inertia = load33(bodies.inertia_local, i)
        w_body = implicit_spin(q, w_body, inertia, spin, bodies.angular_damping[i], h)
        store3(angvel, i, quat_rotate(q, w_body))


@inline(counted=False)
def integrate_positions(bodies, moving, linvel, angvel, pos, quat, inv_inertia_world, h):
    """``x += h v``, ``q ← q + h ½ (0, ω) ⊗ q`` renormalised, and ``R I⁻¹ Rᵀ`` at the new orientation; moving (awake
    dynamic) bodies. The impulses of the rest of the step turn ω through the inertia of the body as it lies now: a
    box spinning at 50 rad/s turns 0.8 rad in a 60 Hz step, and an impulse through the inertia of its start gave a
    bounce with e = 1 up to 26 % more energy than it had (issue 50)."""
    for i in range(pos.shape[0]):
        if moving[i]:
            store3(pos, i, add_scaled(load3(pos, i), load3(linvel, i), h))
            store4(quat, i, quat_integrate(load4(quat, i), load3(angvel, i), h))
            _store_world_inverse_inertia(bodies, quat, i, inv_inertia_world)


@inline
def run_substeps(
    bodies, moving, inv_mass, gravity, force, torque, acts, rows, count, inv_inertia_world, pos, quat, pos0, quat0,
    linvel, angvel, h, first, last, push_max, threshold, joints, joint_impulses, joint_hertz, joint_damping_ratio,
    joint_force_total, joint_moment_total,
):  # fmt: skip
    """Substeps ``first`` to ``last - 1`` of the soft step's inner loop (Catto 2024): per substep integrate
    velocities, bounce the ball impacts of the substep, warm start (joints, then contacts), solve with a soft bias,
    integrate positions, relax without bias. The step runs them in one call, or in several where contacts are found
    again between them (``pipeline.contact_stages``); the state between calls is all in the arrays.
    ``inv_mass`` and ``inv_inertia_world`` are zero for bodies that do not move (static or sleeping), which the
    solver then treats as fixed."""
    inv_h = 1.0 / h
    jointed = joints.kind.shape[0] > 0  # without joints, not even the joint solver's work arrays
    impacts = impact_work()
    for k in range(first, last):
        integrate_velocities(bodies, moving, gravity, force, torque, acts, k * h, quat, linvel, angvel, h)
        resolve_impacts(rows, count, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel, h, threshold,
                        gravity, force, bodies.constant_force, impacts)  # fmt: skip
        if jointed:
            warm_start_joints(joints, joint_impulses, inv_mass, inv_inertia_world, pos, quat, linvel, angvel,
                              joint_force_total, joint_moment_total)  # fmt: skip
        warm_start_contacts(rows, count, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel)
        if jointed:
            solve_joints(joints, joint_impulses, inv_mass, inv_inertia_world, pos, quat, linvel, angvel, h,
                         joint_hertz, joint_damping_ratio, push_max, True, joint_force_total,
                         joint_moment_total)  # fmt: skip
        solve_contacts(rows, count, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel, inv_h,
                       push_max, True, threshold)  # fmt: skip
        integrate_positions(bodies, moving, linvel, angvel, pos, quat, inv_inertia_world, h)
        if jointed:
            solve_joints(joints, joint_impulses, inv_mass, inv_inertia_world, pos, quat, linvel, angvel, h,
                         joint_hertz, joint_damping_ratio, push_max, False, joint_force_total,
                         joint_moment_total)  # fmt: skip
        solve_contacts(rows, count, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel, inv_h,
                       push_max, False, threshold)  # fmt: skip
        accumulate_impulses(rows, count)
