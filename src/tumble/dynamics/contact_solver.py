"""Contact solver: soft step (soft contact constraints, substeps, relax, restitution).

The scheme of Box2D v3 / Box3D / Rapier (E. Catto, "Solver2D", 2024): each step finds contacts once, then
runs ``substeps`` small steps of ``h = dt / substeps`` (pairs that close or turn fast find theirs again between
substeps: :func:`rebase_contacts`). In every substep the velocities are integrated, the
impulses of the last substep are re-applied (warm start), the contact constraints are solved once by
sequential impulses with a *soft* position bias (a spring of ``contact_hertz`` and damping ratio, see
``softness.py``), the positions are integrated, and a relax pass solves the constraints again without bias
so that the push-out does not leave velocity behind. Impacts with restitution bounce in the substep where they
touch, at the time of touch, with the approach speed at the surface (:func:`resolve_impacts`); after the substeps,
restitution is applied once more, from each point's approach speed at the substep it first pushed, to the points
that pushed without having bounced (:func:`apply_restitution`). Contacts with positive separation are speculative:
they only stop the bodies from closing the gap faster than ``separation / h``, which keeps fast bodies
from tunnelling through each other.

Each contact point has a normal impulse ``λn ≥ 0`` and a friction impulse in the tangent plane bounded by the
Coulomb cone ``|λt| ≤ μ λn`` (two tangent directions, clamped as a vector). Friction mixes as ``√(μa μb)``,
restitution as ``max(ea, eb)``. Optional rolling resistance (Box2D v3's, about both tangents) bounds an angular
impulse against relative rolling by ``c r Σλn``, mixed as the larger ``c r`` of the two shapes.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._jit import inline
from .._validate import as_float
from ..geometry.manifold import MAX_POINTS
from ..math3d import (
    add,
    add_scaled,
    cross,
    dot,
    load3,
    load33,
    mat_vec,
    quat_conj,
    quat_exp,
    quat_mul,
    quat_normalize,
    quat_rotate,
    scale,
    store3,
    store33,
    sub,
    turned_symmetric33,
)
from .softness import soft_coefficients

# Gauss-Seidel sweeps over the normal points of a manifold per solve where it is an impact (closing faster than
# IMPACT_SPEED at the start of the step): one sweep lets the first corner of a box hitting a wall take all of it
# and spin the box (at 100 m/s it then passed through a 2 cm wall); a few converge towards the symmetric (block)
# solution. Resting contacts get one sweep, as the soft-step coefficients assume: four there made tall columns of
# the 1000-box pile sway and topple at 60 Hz, and cost 45 % more time.
IMPACT_SWEEPS = 4
IMPACT_SPEED = 1.0  # [m/s]
# Projected Gauss-Seidel sweeps at most over the points of one bounce (resolve_impacts): a flat box's four corners
# converge to the joint (symmetric) solution in a handful; one point needs one.
IMPACT_BLOCK_SWEEPS = 32
# The substep rate a contact of f hertz needs: static contacts run at 2 f, and a soft contact holds only up to a
# quarter of the substep rate (Box2D v3's bound h ω <= π/2; stiffer, contacts jitter and stacks topple). Below that
# rate the contacts would be softer than asked, and a stack sags by (load / m_eff) g / ω² at each contact: the
# ten-box tower toppled at 30 and 60 Hz with one substep and swayed 15-34 mm with four (issue 16).
SUBSTEP_RATE_PER_CONTACT_HERTZ = 8.0
# The most substeps the contact rule may add to one step (2**16, a step of 136 s at the default 60 Hz contacts, a
# fifth of a second of work for one body): a longer step is likelier a unit slip (ms for s) than a wish, and would
# hold the interpreter uninterruptibly for hours (a step of 1e6 s needed 4.8e8 substeps, half an hour for one box).
MAX_CONTACT_SUBSTEPS = 2**16

__all__ = [
    "ContactRows",
    "SolverSettings",
    "prepare_contacts",
    "rebase_contacts",
    "solve_contacts",
    "store_impulses",
    "warm_start_contacts",
]


class SolverSettings(NamedTuple):
    """Contact solver settings (see ``World``): all SI."""

    substeps: int
    contact_hertz: float
    contact_damping_ratio: float
    contact_push_max: float  # [m/s] largest push-out velocity (joint limits: m/s or rad/s)
    restitution_threshold: float  # [m/s] slower impacts do not bounce
    speculative_distance: float  # [m] contacts closer than this are created before touching
    sleep: bool  # let islands at rest sleep
    sleep_linear: float  # [m/s] a body slower than this ...
    sleep_angular: float  # [rad/s] ... and turning slower than this ...
    time_to_sleep: float  # [s] ... for this long may sleep with its island
    joint_hertz: float  # joints' position correction: a spring of this frequency ...
    joint_damping_ratio: float  # ... and damping ratio (joint_solver.py)

    def substeps_for(self, dt: float) -> int:
        """The substeps a step of ``dt`` takes: ``substeps``, or more where the substep would be too long for
        contacts of ``contact_hertz`` (at least 8 substeps per contact period: 8 at 60 Hz with the default 60 Hz
        contacts, 16 at 30 Hz, 1 from 480 Hz on)."""
        dt = as_float("dt", dt, positive=True)
        needed = dt * SUBSTEP_RATE_PER_CONTACT_HERTZ * self.contact_hertz * (1.0 - 1e-12)
        if not needed <= MAX_CONTACT_SUBSTEPS:
            raise ValueError(
                f"contact_hertz={self.contact_hertz!r} at dt={dt!r} needs {needed:.3g} substeps per step, more than "
                f"{MAX_CONTACT_SUBSTEPS}: lower contact_hertz or dt"
            )
        return max(self.substeps, math.ceil(needed))


class ContactRows(NamedTuple):
    """Per-manifold solver data (capacity ``M``; the first ``count`` rows are used)."""

    body_a: np.ndarray  # (M,) int64
    body_b: np.ndarray  # (M,) int64
    normal: np.ndarray  # (M, 3) from a to b, world
    tangent1: np.ndarray  # (M, 3)
    tangent2: np.ndarray  # (M, 3)
    friction: np.ndarray  # (M,)
    restitution: np.ndarray  # (M,)
    point_count: np.ndarray  # (M,) int64
    anchor_a: np.ndarray  # (M, 4, 3) contact point minus the COM of a at the start of the step
    anchor_b: np.ndarray  # (M, 4, 3)
    base_separation: np.ndarray  # (M, 4) separation at the start of the step
    normal_mass: np.ndarray  # (M, 4) 1 / (n·K n)
    tangent_mass: np.ndarray  # (M, 4, 2)
    normal_impulse: np.ndarray  # (M, 4) accumulated λn of the current substep [N s]
    tangent_impulse: np.ndarray  # (M, 4, 2) accumulated friction impulse along tangent1, tangent2
    max_normal_impulse: np.ndarray  # (M, 4) largest incremental λn of the step (did the point push?)
    relative_velocity: np.ndarray  # (M, 4) normal approach velocity: before the step, then at the first push [m/s]
    softness: np.ndarray  # (M, 3) bias_rate, mass_scale, impulse_scale
    total_normal_impulse: np.ndarray  # (M, 4) λn summed over the substeps and restitution: the step's impulse
    total_tangent_impulse: np.ndarray  # (M, 4, 2) friction impulse summed over the step
    rolling: np.ndarray  # (M,) [m] rolling resistance lever c r (the larger of the two shapes')
    rolling_mass: np.ndarray  # (M, 2) 1 / (t·(I_a⁻¹ + I_b⁻¹) t) about tangent1, tangent2
    rolling_impulse: np.ndarray  # (M, 2) accumulated angular impulse about tangent1, tangent2 [N m s]
    core_radius: np.ndarray  # (M, 2) radius round the core of a and b (sphere, capsule), else 0 [m]
    sweeps: np.ndarray  # (M,) int64 sweeps over the normal points per solve (IMPACT_SWEEPS for impacts, else 1)

    @classmethod
    def allocate(cls, capacity: int) -> ContactRows:
        p = MAX_POINTS
        return cls(
            np.zeros(capacity, np.int64), np.zeros(capacity, np.int64), np.zeros((capacity, 3)),
            np.zeros((capacity, 3)), np.zeros((capacity, 3)), np.zeros(capacity), np.zeros(capacity),
            np.zeros(capacity, np.int64), np.zeros((capacity, p, 3)), np.zeros((capacity, p, 3)),
            np.zeros((capacity, p)), np.zeros((capacity, p)), np.zeros((capacity, p, 2)), np.zeros((capacity, p)),
            np.zeros((capacity, p, 2)), np.zeros((capacity, p)), np.zeros((capacity, p)), np.zeros((capacity, 3)),
            np.zeros((capacity, p)), np.zeros((capacity, p, 2)), np.zeros(capacity), np.zeros((capacity, 2)),
            np.zeros((capacity, 2)), np.zeros((capacity, 2)), np.ones(capacity, np.int64),
        )  # fmt: skip


@inline
def tangent_basis(n):
    """Two unit tangents with ``(t1, t2, n)`` right-handed; continuous in ``n`` except across |n_x| = 0.577."""
    if abs(n[0]) >= 0.57735:
        t1 = (n[1], -n[0], 0.0)
    else:
        t1 = (0.0, n[2], -n[1])
    inv = 1.0 / math.sqrt(dot(t1, t1))
    t1 = scale(t1, inv)
    return t1, cross(n, t1)


@inline
def _inverse_effective_mass(inv_mass_a, inv_i_a, r_a, inv_mass_b, inv_i_b, r_b, d):
    """``1 / (m_a⁻¹ + m_b⁻¹ + (r_a×d)·I_a⁻¹(r_a×d) + (r_b×d)·I_b⁻¹(r_b×d))``, 0 if both are static."""
    rd_a = cross(r_a, d)
    rd_b = cross(r_b, d)
    k = inv_mass_a + inv_mass_b + dot(rd_a, mat_vec(inv_i_a, rd_a)) + dot(rd_b, mat_vec(inv_i_b, rd_b))
    return 1.0 / k if k > 0.0 else 0.0


@inline
def _inverse_angular_mass(inv_i_a, inv_i_b, axis):
    """``1 / (axis·(I_a⁻¹ + I_b⁻¹) axis)`` of an angular constraint about ``axis``, 0 if neither body turns."""
    k = dot(axis, mat_vec(inv_i_a, axis)) + dot(axis, mat_vec(inv_i_b, axis))
    return 1.0 / k if k > 0.0 else 0.0


@inline
def _clamp_to_disc(x, y, limit):
    """``(x, y)`` scaled back onto the disc of radius ``limit`` if it lies outside (a Coulomb-type bound)."""
    length = math.sqrt(x * x + y * y)
    if length > limit:
        ratio = limit / length
        return x * ratio, y * ratio
    return x, y


@inline
def _relative_velocity(v_a, w_a, r_a, v_b, w_b, r_b):
    """Velocity of b's contact point relative to a's: ``v_b + ω_b × r_b − v_a − ω_a × r_a``."""
    return sub(add(v_b, cross(w_b, r_b)), add(v_a, cross(w_a, r_a)))


@inline
def _write_point_masses(rows, m, j, ma, ia, ra, mb, ib, rb, n, t1, t2):
    """Point ``j`` of row ``m``: the inverse effective masses along the normal and the two tangents."""
    rows.normal_mass[m, j] = _inverse_effective_mass(ma, ia, ra, mb, ib, rb, n)
    rows.tangent_mass[m, j, 0] = _inverse_effective_mass(ma, ia, ra, mb, ib, rb, t1)
    rows.tangent_mass[m, j, 1] = _inverse_effective_mass(ma, ia, ra, mb, ib, rb, t2)


@inline
def _write_rolling_masses(rows, m, ia, ib, t1, t2):
    """Row ``m``'s rolling-resistance masses about the two tangents (only where it rolls with resistance)."""
    if rows.rolling[m] > 0.0:
        rows.rolling_mass[m, 0] = _inverse_angular_mass(ia, ib, t1)
        rows.rolling_mass[m, 1] = _inverse_angular_mass(ia, ib, t2)


@inline(counted=False)
def prepare_contacts(
    manifolds, count, shape_body, shape_friction, shape_restitution, shape_rolling, shape_core_radius, inv_mass,
    inv_inertia_world, pos, linvel,
    angvel, warm_normal, warm_tangent, contact_hertz, damping_ratio, h, rows,
):  # fmt: skip
    """Anchors, effective masses, softness and warm-start impulses of every manifold.

    Reads: manifolds (normal, points, separations), body state at the start of the step, warm impulses
    ``warm_normal (M, 4)`` and world friction impulses ``warm_tangent (M, 4, 3)`` matched from the last step.
    Writes: rows[:count].
    """
    for m in range(count):
        a = shape_body[manifolds.shape_a[m]]
        b = shape_body[manifolds.shape_b[m]]
        rows.body_a[m], rows.body_b[m] = a, b
        n = load3(manifolds.normal, m)
        t1, t2 = tangent_basis(n)
        store3(rows.normal, m, n)
        store3(rows.tangent1, m, t1)
        store3(rows.tangent2, m, t2)
        rows.friction[m] = math.sqrt(shape_friction[manifolds.shape_a[m]] * shape_friction[manifolds.shape_b[m]])
        rows.restitution[m] = max(shape_restitution[manifolds.shape_a[m]], shape_restitution[manifolds.shape_b[m]])
        rows.rolling[m] = max(shape_rolling[manifolds.shape_a[m]], shape_rolling[manifolds.shape_b[m]])
        rows.core_radius[m, 0] = shape_core_radius[manifolds.shape_a[m]]
        rows.core_radius[m, 1] = shape_core_radius[manifolds.shape_b[m]]
        # A contact against a static body is stiffer (2x), as it has half the effective mass to move; the step's
        # substeps keep it within a quarter of the substep rate (SolverSettings.substeps_for).
        hertz = contact_hertz if inv_mass[a] > 0.0 and inv_mass[b] > 0.0 else 2.0 * contact_hertz
        bias_rate, mass_scale, impulse_scale = soft_coefficients(hertz, damping_ratio, h)
        rows.softness[m, 0], rows.softness[m, 1], rows.softness[m, 2] = bias_rate, mass_scale, impulse_scale
        ma, mb = inv_mass[a], inv_mass[b]
        ia, ib = load33(inv_inertia_world, a), load33(inv_inertia_world, b)
        va, wa, vb, wb = load3(linvel, a), load3(angvel, a), load3(linvel, b), load3(angvel, b)
        xa, xb = load3(pos, a), load3(pos, b)
        rows.point_count[m] = manifolds.point_count[m]
        rows.rolling_impulse[m, 0] = rows.rolling_impulse[m, 1] = 0.0
        _write_rolling_masses(rows, m, ia, ib, t1, t2)
        for j in range(manifolds.point_count[m]):
            p = load3(manifolds.point[m], j)
            ra, rb = sub(p, xa), sub(p, xb)
            store3(rows.anchor_a[m], j, ra)
            store3(rows.anchor_b[m], j, rb)
            rows.base_separation[m, j] = manifolds.separation[m, j]
            _write_point_masses(rows, m, j, ma, ia, ra, mb, ib, rb, n, t1, t2)
            rows.normal_impulse[m, j] = warm_normal[m, j]
            warm_t = load3(warm_tangent[m], j)
            rows.tangent_impulse[m, j, 0] = dot(warm_t, t1)
            rows.tangent_impulse[m, j, 1] = dot(warm_t, t2)
            rows.max_normal_impulse[m, j] = 0.0
            rows.total_normal_impulse[m, j] = 0.0
            rows.total_tangent_impulse[m, j, 0] = rows.total_tangent_impulse[m, j, 1] = 0.0
            rows.relative_velocity[m, j] = dot(_relative_velocity(va, wa, ra, vb, wb, rb), n)
        rows.sweeps[m] = 1
        for j in range(manifolds.point_count[m]):
            if rows.relative_velocity[m, j] < -IMPACT_SPEED:
                rows.sweeps[m] = IMPACT_SWEEPS


@inline
def rebase_contacts(listed, fresh, manifolds, rows, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel,
                    angvel):  # fmt: skip
    """Put the contacts found again within the step into their rows: ``fresh[i]``, found at the bodies' poses now,
    replaces manifold and row ``listed[i]``.

    The solver measures every point from the step's start (:func:`_arms_now`), so the new points are written as
    the anchors and separation that give, at the poses now, the arms to the new point and its new separation; from
    here on they follow the bodies as the others do. A point with the same feature as one of the old keeps that
    point's impulses (the warm start of the next substep, the step's totals, whether it pushed, its approach speed
    for restitution); friction impulses turn onto the new tangents. A new point starts from nothing, with the
    approach speed it has now. Writes: manifolds and rows ``listed``.
    """
    old_feature = np.zeros(MAX_POINTS, np.int64)
    old_normal = np.zeros(MAX_POINTS)
    old_tangent = np.zeros((MAX_POINTS, 3))
    old_max = np.zeros(MAX_POINTS)
    old_total = np.zeros(MAX_POINTS)
    old_total_tangent = np.zeros((MAX_POINTS, 3))
    old_velocity = np.zeros(MAX_POINTS)
    for i in range(listed.shape[0]):
        m = listed[i]
        a, b, ma, ia, mb, ib, va, wa, vb, wb, dx_a, dq_a, dx_b, dq_b, weight_b = _load_pair(
            rows, m, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel
        )
        t1_old, t2_old = load3(rows.tangent1, m), load3(rows.tangent2, m)
        old_count = rows.point_count[m]
        for j in range(old_count):
            old_feature[j] = manifolds.feature[m, j]
            old_normal[j] = rows.normal_impulse[m, j]
            old_max[j] = rows.max_normal_impulse[m, j]
            old_total[j] = rows.total_normal_impulse[m, j]
            old_velocity[j] = rows.relative_velocity[m, j]
            tangent = add(scale(t1_old, rows.tangent_impulse[m, j, 0]), scale(t2_old, rows.tangent_impulse[m, j, 1]))
            total = add(scale(t1_old, rows.total_tangent_impulse[m, j, 0]),
                        scale(t2_old, rows.total_tangent_impulse[m, j, 1]))  # fmt: skip
            for c in range(3):
                old_tangent[j, c], old_total_tangent[j, c] = tangent[c], total[c]
        rolling = add(scale(t1_old, rows.rolling_impulse[m, 0]), scale(t2_old, rows.rolling_impulse[m, 1]))
        count = fresh.point_count[i]
        if count == 0:  # now apart by more than the margin: nothing to hold for the rest of the step
            manifolds.point_count[m] = rows.point_count[m] = 0
            rows.rolling_impulse[m, 0] = rows.rolling_impulse[m, 1] = 0.0
            continue
        n = load3(fresh.normal, i)
        t1, t2 = tangent_basis(n)
        for c in range(3):
            manifolds.normal[m, c] = rows.normal[m, c] = n[c]
            rows.tangent1[m, c], rows.tangent2[m, c] = t1[c], t2[c]
        manifolds.point_count[m] = rows.point_count[m] = count
        _write_rolling_masses(rows, m, ia, ib, t1, t2)
        rows.rolling_impulse[m, 0], rows.rolling_impulse[m, 1] = dot(rolling, t1), dot(rolling, t2)
        xa, xb = load3(pos, a), load3(pos, b)
        relative = sub(dx_b, dx_a)
        rows.sweeps[m] = 1
        for j in range(count):
            p = load3(fresh.point[i], j)
            manifolds.feature[m, j] = fresh.feature[i, j]
            manifolds.separation[m, j] = fresh.separation[i, j]
            store3(manifolds.point[m], j, p)
            # Anchors that _arms_now carries to p - x now; the base separation that it carries to the new one.
            ra, rb = sub(p, xa), sub(p, xb)
            store3(rows.anchor_a[m], j, add_scaled(ra, relative, -weight_b))
            store3(rows.anchor_b[m], j, add_scaled(rb, relative, 1.0 - weight_b))
            rows.base_separation[m, j] = 0.0
            _, _, moved = _arms_now(rows, m, j, n, dx_a, dq_a, dx_b, dq_b, weight_b)
            rows.base_separation[m, j] = fresh.separation[i, j] - moved
            _write_point_masses(rows, m, j, ma, ia, ra, mb, ib, rb, n, t1, t2)
            same = -1
            for jj in range(old_count):
                if old_feature[jj] == fresh.feature[i, j]:
                    same = jj
                    break
            if same >= 0:
                tangent, total = load3(old_tangent, same), load3(old_total_tangent, same)
                rows.normal_impulse[m, j] = old_normal[same]
                rows.max_normal_impulse[m, j] = old_max[same]
                rows.total_normal_impulse[m, j] = old_total[same]
                rows.relative_velocity[m, j] = old_velocity[same]
            else:
                tangent = total = (0.0, 0.0, 0.0)
                rows.normal_impulse[m, j] = rows.max_normal_impulse[m, j] = rows.total_normal_impulse[m, j] = 0.0
                rows.relative_velocity[m, j] = dot(_relative_velocity(va, wa, ra, vb, wb, rb), n)
            rows.tangent_impulse[m, j, 0], rows.tangent_impulse[m, j, 1] = dot(tangent, t1), dot(tangent, t2)
            rows.total_tangent_impulse[m, j, 0] = dot(total, t1)
            rows.total_tangent_impulse[m, j, 1] = dot(total, t2)
            if rows.relative_velocity[m, j] < -IMPACT_SPEED:
                rows.sweeps[m] = IMPACT_SWEEPS


@inline
def _apply_impulse(ra, rb, impulse, ma, ia, mb, ib, va, wa, vb, wb):
    """Apply ``impulse`` (world): ``−P`` to body a at arm ``ra``, ``+P`` to body b at arm ``rb``."""
    va = add_scaled(va, impulse, -ma)
    wa = sub(wa, mat_vec(ia, cross(ra, impulse)))
    vb = add_scaled(vb, impulse, mb)
    wb = add(wb, mat_vec(ib, cross(rb, impulse)))
    return va, wa, vb, wb


@inline
def _motion_since_start(pos, quat, pos0, quat0, i):
    """How far body ``i``'s COM has moved since the start of the step, and its rotation since then."""
    q = (quat[i, 0], quat[i, 1], quat[i, 2], quat[i, 3])
    q0 = (quat0[i, 0], quat0[i, 1], quat0[i, 2], quat0[i, 3])
    return sub(load3(pos, i), load3(pos0, i)), quat_mul(q, quat_conj(q0))


@inline
def _arms_now(rows, m, j, n, dx_a, dq_a, dx_b, dq_b, weight_b):
    """Lever arms of point ``j`` now, and its separation now.

    The arms keep their start-of-step directions (Box2D v3: rotating them with the bodies changes the leverage
    that the effective masses were computed for, and the solver overshoots), but both reach the same world
    point, so that an impulse exerts no net moment and contacts conserve angular momentum to round-off. That
    point is the contact point carried along by the bodies' displacements weighted by inverse mass
    (``weight_b = m_b⁻¹ / (m_a⁻¹ + m_b⁻¹)``): against a static or much heavier body it stays under the light
    one, as a rolling ball needs. The separation follows the anchors as material points, rotations included,
    except for the part of an anchor that crosses a sphere's or capsule's radius: the surface of a rolling ball
    stays under its centre, so a turning ball does not seem to lift off the ground.
    """
    ra0, rb0 = load3(rows.anchor_a[m], j), load3(rows.anchor_b[m], j)
    relative = sub(dx_b, dx_a)
    core_a, core_b = add_scaled(ra0, n, -rows.core_radius[m, 0]), add_scaled(rb0, n, rows.core_radius[m, 1])
    moved_b = add(dx_b, sub(quat_rotate(dq_b, core_b), core_b))
    moved_a = add(dx_a, sub(quat_rotate(dq_a, core_a), core_a))
    separation = rows.base_separation[m, j] + dot(n, sub(moved_b, moved_a))
    return add_scaled(ra0, relative, weight_b), add_scaled(rb0, relative, weight_b - 1.0), separation


@inline
def _load_pair(rows, m, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel):
    """What the solver needs of manifold ``m``'s two bodies: indices, inverse masses and world inverse inertias,
    velocities, motion since the start of the step, and b's share of the inverse mass."""
    a, b = rows.body_a[m], rows.body_b[m]
    ma, mb = inv_mass[a], inv_mass[b]
    dx_a, dq_a = _motion_since_start(pos, quat, pos0, quat0, a)
    dx_b, dq_b = _motion_since_start(pos, quat, pos0, quat0, b)
    return (a, b, ma, load33(inv_inertia_world, a), mb, load33(inv_inertia_world, b), load3(linvel, a),
            load3(angvel, a), load3(linvel, b), load3(angvel, b), dx_a, dq_a, dx_b, dq_b, mb / (ma + mb))  # fmt: skip


@inline
def _store_pair(linvel, angvel, a, b, va, wa, vb, wb):
    store3(linvel, a, va)
    store3(angvel, a, wa)
    store3(linvel, b, vb)
    store3(angvel, b, wb)


@inline(counted=False)
def warm_start_contacts(rows, count, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel):
    """Re-apply the accumulated impulses of every point (normal and friction).

    Reads: rows.normal_impulse, rows.tangent_impulse, body poses now and at the start of the step.
    Writes: linvel, angvel.
    """
    for m in range(count):
        if rows.normal_mass[m, 0] == 0.0:
            continue
        a, b, ma, ia, mb, ib, va, wa, vb, wb, dx_a, dq_a, dx_b, dq_b, weight_b = _load_pair(
            rows, m, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel
        )
        n, t1, t2 = load3(rows.normal, m), load3(rows.tangent1, m), load3(rows.tangent2, m)
        for j in range(rows.point_count[m]):
            ra, rb, _ = _arms_now(rows, m, j, n, dx_a, dq_a, dx_b, dq_b, weight_b)
            impulse = add(
                scale(n, rows.normal_impulse[m, j]),
                add(scale(t1, rows.tangent_impulse[m, j, 0]), scale(t2, rows.tangent_impulse[m, j, 1])),
            )
            va, wa, vb, wb = _apply_impulse(ra, rb, impulse, ma, ia, mb, ib, va, wa, vb, wb)
        moment = add(scale(t1, rows.rolling_impulse[m, 0]), scale(t2, rows.rolling_impulse[m, 1]))
        wa, wb = sub(wa, mat_vec(ia, moment)), add(wb, mat_vec(ib, moment))
        _store_pair(linvel, angvel, a, b, va, wa, vb, wb)


@inline(counted=False)
def solve_contacts(
    rows, count, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel, inv_h, push_max, use_bias,
    threshold,
):  # fmt: skip
    """One Gauss–Seidel pass over all contacts: normal impulses (soft when ``use_bias``), then friction.

    A point that will bounce (restitution, closing faster than ``threshold``) is left alone by the relax pass:
    :func:`resolve_impacts` bounces it in the substep of the touch (or the next, if the substep's rotation brought
    it in) with the speed it has there. Slowed to close the gap in one more substep, it kept only
    ``((s/h + g h) / v)²`` of its rebound energy, anywhere from 0 to 1 with where the touch fell in the substep;
    stopped once in, it bounced at the step's end from a stale speed and could gain energy (issue 50).

    Reads: rows, body poses now (``pos``, ``quat``) and at the start of the step (``pos0``, ``quat0``).
    Writes: rows.normal_impulse, rows.tangent_impulse, rows.max_normal_impulse, linvel, angvel.
    """
    for m in range(count):
        if rows.normal_mass[m, 0] == 0.0:
            continue  # neither body moves (static or asleep): keep the impulses it had, for the report and waking
        a, b, ma, ia, mb, ib, va, wa, vb, wb, dx_a, dq_a, dx_b, dq_b, weight_b = _load_pair(
            rows, m, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel
        )
        n, t1, t2 = load3(rows.normal, m), load3(rows.tangent1, m), load3(rows.tangent2, m)
        bias_rate, mass_scale, impulse_scale = rows.softness[m, 0], rows.softness[m, 1], rows.softness[m, 2]
        will_bounce = not use_bias and rows.restitution[m] > 0.0
        # Non-penetration: λn ≥ 0, soft towards zero separation; speculative while apart.
        for jj in range(rows.sweeps[m] * rows.point_count[m]):
            j = jj % rows.point_count[m]
            ra, rb, s = _arms_now(rows, m, j, n, dx_a, dq_a, dx_b, dq_b, weight_b)
            vn = dot(_relative_velocity(va, wa, ra, vb, wb, rb), n)
            if will_bounce and vn < -threshold:
                continue
            bias, m_scale, i_scale = 0.0, 1.0, 0.0
            if s > 0.0:
                bias = s * inv_h
            elif use_bias:
                bias, m_scale, i_scale = max(bias_rate * s, -push_max), mass_scale, impulse_scale
            if use_bias and rows.max_normal_impulse[m, j] == 0.0:
                # Not pushed yet this step: the approach speed at the substep of impact is what bounces, not the
                # speed at the step's start (another point's bounce may have slowed it since: an elastic box then
                # gained 3.4 % of its energy, issue 50).
                rows.relative_velocity[m, j] = vn
            old = rows.normal_impulse[m, j]
            new = max(old - rows.normal_mass[m, j] * m_scale * (vn + bias) - i_scale * old, 0.0)
            rows.normal_impulse[m, j] = new
            rows.max_normal_impulse[m, j] = max(rows.max_normal_impulse[m, j], new - old)
            va, wa, vb, wb = _apply_impulse(ra, rb, scale(n, new - old), ma, ia, mb, ib, va, wa, vb, wb)
        # Friction: both tangents at once, the accumulated impulse clamped to the Coulomb cone μ λn.
        mu = rows.friction[m]
        for j in range(rows.point_count[m]):
            ra, rb, _ = _arms_now(rows, m, j, n, dx_a, dq_a, dx_b, dq_b, weight_b)
            dv = _relative_velocity(va, wa, ra, vb, wb, rb)
            old1, old2 = rows.tangent_impulse[m, j, 0], rows.tangent_impulse[m, j, 1]
            new1 = old1 - rows.tangent_mass[m, j, 0] * dot(dv, t1)
            new2 = old2 - rows.tangent_mass[m, j, 1] * dot(dv, t2)
            new1, new2 = _clamp_to_disc(new1, new2, mu * rows.normal_impulse[m, j])
            rows.tangent_impulse[m, j, 0], rows.tangent_impulse[m, j, 1] = new1, new2
            impulse = add(scale(t1, new1 - old1), scale(t2, new2 - old2))
            va, wa, vb, wb = _apply_impulse(ra, rb, impulse, ma, ia, mb, ib, va, wa, vb, wb)
        # Rolling resistance (Box2D v3's, about both tangents): an angular impulse against the relative rolling,
        # bounded by c r Σλn, the moment of a resisting force c N at the rolling radius r.
        if rows.rolling[m] > 0.0:
            total = 0.0
            for j in range(rows.point_count[m]):
                total += rows.normal_impulse[m, j]
            dw = sub(wb, wa)
            old1, old2 = rows.rolling_impulse[m, 0], rows.rolling_impulse[m, 1]
            limit = rows.rolling[m] * total
            new1, new2 = _clamp_to_disc(old1 - rows.rolling_mass[m, 0] * dot(dw, t1),
                                        old2 - rows.rolling_mass[m, 1] * dot(dw, t2), limit)  # fmt: skip
            rows.rolling_impulse[m, 0], rows.rolling_impulse[m, 1] = new1, new2
            moment = add(scale(t1, new1 - old1), scale(t2, new2 - old2))
            wa, wb = sub(wa, mat_vec(ia, moment)), add(wb, mat_vec(ib, moment))
        _store_pair(linvel, angvel, a, b, va, wa, vb, wb)


@inline
def _load_acceleration(i, inv_mass, gravity, force, constant_force):
    """Body ``i``'s acceleration from its gravity (row ``i`` of ``gravity``) and its applied and constant forces (zero
    if it does not move)."""
    if inv_mass[i] == 0.0:
        return (0.0, 0.0, 0.0)
    applied = add(load3(force, i), load3(constant_force, i))
    return add_scaled(load3(gravity, i), applied, inv_mass[i])


@inline
def _time_of_touch(s, u_half, g_n, h):
    """When a gap ``s`` closes within a substep ``h``, and how fast: ``(τ, u_s)``, or ``τ = -1`` if it does not.

    ``u_half`` is the approach speed the substep moves with: semi-implicit Euler's velocity leads the positions
    by half a substep, so it is the speed at ``h/2``, and ``u0 = u_half − g_n h/2`` the speed at the start, with
    ``g_n`` the rate at which the loads speed the approach up. Then ``s = u0 τ + ½ g_n τ²`` and ``u_s² = u0² +
    2 g_n s``; exact for constant loads, as semi-implicit Euler is. A gap already closed touches at 0."""
    u0 = u_half - 0.5 * g_n * h
    if s <= 0.0:
        return 0.0, u0
    squared = u0 * u0 + 2.0 * g_n * s
    if squared < 0.0:
        return -1.0, 0.0
    u_s = math.sqrt(squared)
    if u0 + u_s <= 0.0:
        return -1.0, 0.0
    return min(2.0 * s / (u0 + u_s), h), u_s


@inline
def _move_back(i, dv, tau, turn, inv_inertia, inv_mass, pos, quat, inv_inertia_world):
    """Undo ``τ`` of body ``i``'s motion with a velocity change ``dv`` it got at ``τ`` into the substep, and turn it by
    ``turn``; ``inv_inertia`` is its world inverse inertia before the turn."""
    if inv_mass[i] == 0.0:
        return
    store3(pos, i, add_scaled(load3(pos, i), dv, -tau))
    q = quat_normalize(quat_mul(turn, (quat[i, 0], quat[i, 1], quat[i, 2], quat[i, 3])))
    quat[i, 0], quat[i, 1], quat[i, 2], quat[i, 3] = q[0], q[1], q[2], q[3]
    store33(inv_inertia_world, i, turned_symmetric33(turn, inv_inertia))


@inline
def impact_work():
    """The work arrays of :func:`resolve_impacts`, one row per point of a manifold: each point's approach speed at
    its touch (-1: it does not bounce now), when it touches within the substep [s], the normal velocity its bounce
    leaves it with, its impulse, and its arms at the time of touch (a and b)."""
    return (np.zeros(MAX_POINTS), np.zeros(MAX_POINTS), np.zeros(MAX_POINTS), np.zeros(MAX_POINTS),
            np.zeros((MAX_POINTS, 3)), np.zeros((MAX_POINTS, 3)))  # fmt: skip


@inline
def _energy_safe_share(rows, m, n, impulse, u_surface, arm_a, arm_b, va, wa, vb, wb, va2, wa2, vb2, wb2, g_n, lead):
    """The share of a manifold's bounce impulses (applied jointly, velocities ``v → v2``) that keeps it energy-safe:
    1, or less where the bounce would leave the pair more energy than it had.

    The energy is that of the end of the substep, with semi-implicit Euler's velocity taken at the time of the
    positions (``v + a h/2``, which free flight under constant loads conserves exactly). Impulses ``λ`` at the points
    change the kinetic energy by ``½ Σ λ (vn⁻ + vn⁺)`` exactly (``v⁺ = v⁻ + W λ``); the bounce at ``τ`` (the body
    moved back by ``τ Δv``) adds ``−g_n (τ − h/2) Σ λ`` through the loads. For e = 1 the two cancel exactly at every
    point the solve drives to its target, so the cap binds only where projected Gauss–Seidel stops short of
    convergence (``IMPACT_BLOCK_SWEEPS``); it never did in the energy grid of
    ``tests/analytic/test_contact_rates.py``, but it is what bounds such a bounce. Scaling all the impulses by
    ``s`` makes the change ``A s + B s²`` (``B = ½ λᵀ W λ > 0``): the largest ``s ≤ 1`` with no gain is ``−A / B``,
    Stronge's energetic bound on the impulse (W. J. Stronge, *Impact Mechanics*, 2000, ch. 4) taken as a cap."""
    linear, quadratic, total = 0.0, 0.0, 0.0
    for j in range(rows.point_count[m]):
        if u_surface[j] < 0.0:
            continue
        ra, rb = load3(arm_a, j), load3(arm_b, j)
        before = dot(_relative_velocity(va, wa, ra, vb, wb, rb), n)
        after = dot(_relative_velocity(va2, wa2, ra, vb2, wb2, rb), n)
        linear += impulse[j] * before
        quadratic += 0.5 * impulse[j] * (after - before)
        total += impulse[j]
    linear -= g_n * lead * total
    if linear + quadratic <= 1e-12 * quadratic:
        return 1.0
    return max(-linear / quadratic, 0.0) if quadratic > 0.0 else 0.0


@inline(counted=False)
def resolve_impacts(rows, count, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel, h, threshold,
                    gravity, force, constant_force, work):  # fmt: skip
    """Bounce impacts as they happen, at the time of touch within the substep, one after the other, so momentum
    passes along a row.

    Called at the start of a substep, after the velocities. In a manifold with restitution ``e``, the points that
    close faster than ``threshold`` and touch within the substep first, at ``τ`` (:func:`_time_of_touch`; a flat face
    touches with all its points at once), bounce together: their approach speeds *at the surface* ``u_s`` become
    ``e u_s``, by impulses at the arms of time ``τ`` solved jointly (projected Gauss–Seidel to convergence,
    ``λ ≥ 0``), through each body's inertia as it lies at ``τ`` (turned on by its spin until then), so that a box
    landing flat leaves without a spin. Semi-implicit Euler then moves the bodies with their new velocities over the
    whole substep, so each body is moved back by its velocity change times ``τ`` and turned back by its new spin
    times ``τ``: the positions at the end of the substep are those of the exact motion (constant loads), and the
    bounce does not depend on where the touch falls in the substep (issue 16). The moves keep the centre of mass,
    and a turn about ``ω`` keeps the kinetic energy, so that the bounce's energy is that of the touch (issue 50); a
    struck ball that strikes the next at the same
    instant keeps its place (its two velocity changes cancel). Sweeps repeat while any contact bounced: a struck
    ball then strikes the next (Newton's cradle), and a corner that touches later in the substep bounces then.
    Resolving the impacts inside the substeps' inelastic solve instead would merge a touching row into one body.
    Writes: linvel, angvel, pos, quat, and ``rows.relative_velocity`` (0: bounced, so that
    :func:`apply_restitution` leaves the point alone). ``work``: :func:`impact_work`'s arrays (compiled without
    reference counts, this function may not allocate them).
    """
    u_surface, touch, target, impulse, arm_a, arm_b = work  # impact_work(): written before they are read
    for _ in range(count + 1):
        bounced = False
        for m in range(count):
            e = rows.restitution[m]
            if e == 0.0 or rows.normal_mass[m, 0] == 0.0:
                continue
            a, b, ma, ia, mb, ib, va, wa, vb, wb, dx_a, dq_a, dx_b, dq_b, weight_b = _load_pair(
                rows, m, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel
            )
            n = load3(rows.normal, m)
            # Each point's touch in this substep, and the first of them (the loads only where one closes in time).
            tau, g_n, loaded = math.inf, 0.0, False
            for j in range(rows.point_count[m]):
                ra, rb, s = _arms_now(rows, m, j, n, dx_a, dq_a, dx_b, dq_b, weight_b)
                vn = dot(_relative_velocity(va, wa, ra, vb, wb, rb), n)
                u_surface[j] = -1.0
                if vn >= -threshold or s > -vn * h + 1e-9:  # (1 nm: a gap that closes exactly at the substep's end)
                    continue
                if not loaded:
                    acc_a = _load_acceleration(a, inv_mass, gravity, force, constant_force)
                    acc_b = _load_acceleration(b, inv_mass, gravity, force, constant_force)
                    g_n, loaded = -dot(n, sub(acc_b, acc_a)), True
                t_j, u_j = _time_of_touch(s, -vn, g_n, h)
                if t_j >= 0.0:
                    u_surface[j], touch[j] = u_j, t_j
                    tau = min(tau, t_j)
            if tau == math.inf:
                continue
            # The impulses turn ω through the inertia at the touch: each body turned on by its spin until then (a
            # turn about ω keeps ½ ωᵀ I ω). Through the inertia of the substep's start, an elastic hull at 45 rad/s
            # gained 1.6 % of its energy at a bounce (issue 50).
            turn_a, turn_b = quat_exp(wa, tau), quat_exp(wb, tau)
            ia_start, ib_start = ia, ib
            ia = turned_symmetric33(turn_a, ia_start)
            ib = turned_symmetric33(turn_b, ib_start)
            # The points that touch at τ (to round-off) bounce together, at their arms of time τ (reaching one point,
            # as in _arms_now): λ ≥ 0 with vn → −u_half + (1 + e) u_s, by projected Gauss-Seidel.
            relative = scale(sub(vb, va), tau)
            for j in range(rows.point_count[m]):
                impulse[j] = 0.0
                if u_surface[j] < 0.0 or touch[j] > tau + 1e-9 * h:
                    u_surface[j] = -1.0
                    continue
                ra, rb, _ = _arms_now(rows, m, j, n, dx_a, dq_a, dx_b, dq_b, weight_b)
                ra, rb = add_scaled(ra, relative, weight_b), add_scaled(rb, relative, weight_b - 1.0)
                store3(arm_a, j, ra)
                store3(arm_b, j, rb)
                target[j] = dot(_relative_velocity(va, wa, ra, vb, wb, rb), n) + (1.0 + e) * u_surface[j]
            va2, wa2, vb2, wb2 = va, wa, vb, wb
            for _sweep in range(IMPACT_BLOCK_SWEEPS):
                largest, total = 0.0, 0.0
                for j in range(rows.point_count[m]):
                    if u_surface[j] < 0.0:
                        continue
                    ra, rb = load3(arm_a, j), load3(arm_b, j)
                    vn = dot(_relative_velocity(va2, wa2, ra, vb2, wb2, rb), n)
                    new = max(impulse[j] + rows.normal_mass[m, j] * (target[j] - vn), 0.0)
                    va2, wa2, vb2, wb2 = _apply_impulse(ra, rb, scale(n, new - impulse[j]), ma, ia, mb, ib, va2, wa2,
                                                        vb2, wb2)  # fmt: skip
                    largest = max(largest, abs(new - impulse[j]))
                    impulse[j] = new
                    total += new
                if largest <= 1e-12 * total:
                    break
            keep = _energy_safe_share(rows, m, n, impulse, u_surface, arm_a, arm_b, va, wa, vb, wb, va2, wa2, vb2, wb2,
                                      g_n, tau - 0.5 * h)  # fmt: skip
            if keep < 1.0:
                va2, wa2 = add_scaled(va, sub(va2, va), keep), add_scaled(wa, sub(wa2, wa), keep)
                vb2, wb2 = add_scaled(vb, sub(vb2, vb), keep), add_scaled(wb, sub(wb2, wb), keep)
            _store_pair(linvel, angvel, a, b, va2, wa2, vb2, wb2)
            if tau > 0.0:  # turned on by ω⁻ τ and back by ω⁺ τ: the substep then turns it by ω⁻ τ + ω⁺ (h − τ)
                _move_back(a, sub(va2, va), tau, quat_mul(quat_exp(wa2, -tau), turn_a), ia_start, inv_mass, pos, quat,
                           inv_inertia_world)  # fmt: skip
                _move_back(b, sub(vb2, vb), tau, quat_mul(quat_exp(wb2, -tau), turn_b), ib_start, inv_mass, pos, quat,
                           inv_inertia_world)  # fmt: skip
            for j in range(rows.point_count[m]):
                if u_surface[j] >= 0.0:
                    rows.relative_velocity[m, j] = 0.0
            bounced = True
        if not bounced:
            break


@inline(counted=False)
def apply_restitution(rows, count, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel, threshold):
    """Bounce: drive the normal velocity to ``−e`` times its approach velocity, where there was an impact that
    :func:`resolve_impacts` did not bounce (one that sped up past ``threshold`` only in the substep it touched).

    Only points that approached faster than ``threshold`` and pushed during the step bounce (Box2D v3).
    Reads: rows.relative_velocity, rows.max_normal_impulse. Writes: rows.normal_impulse, linvel, angvel.
    """
    for m in range(count):
        e = rows.restitution[m]
        if e == 0.0 or rows.normal_mass[m, 0] == 0.0:
            continue
        a, b, ma, ia, mb, ib, va, wa, vb, wb, dx_a, dq_a, dx_b, dq_b, weight_b = _load_pair(
            rows, m, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel, angvel
        )
        n = load3(rows.normal, m)
        for j in range(rows.point_count[m]):
            if rows.relative_velocity[m, j] > -threshold or rows.max_normal_impulse[m, j] == 0.0:
                continue
            ra, rb, _ = _arms_now(rows, m, j, n, dx_a, dq_a, dx_b, dq_b, weight_b)
            vn = dot(_relative_velocity(va, wa, ra, vb, wb, rb), n)
            old = rows.normal_impulse[m, j]
            new = max(old - rows.normal_mass[m, j] * (vn + e * rows.relative_velocity[m, j]), 0.0)
            rows.normal_impulse[m, j] = new
            rows.total_normal_impulse[m, j] += new - old
            va, wa, vb, wb = _apply_impulse(ra, rb, scale(n, new - old), ma, ia, mb, ib, va, wa, vb, wb)
        _store_pair(linvel, angvel, a, b, va, wa, vb, wb)


@inline(counted=False)
def accumulate_impulses(rows, count):
    """Add the impulses each point applied during a substep to the step's totals (for ``World.contacts``)."""
    for m in range(count):
        for j in range(rows.point_count[m]):
            rows.total_normal_impulse[m, j] += rows.normal_impulse[m, j]
            rows.total_tangent_impulse[m, j, 0] += rows.tangent_impulse[m, j, 0]
            rows.total_tangent_impulse[m, j, 1] += rows.tangent_impulse[m, j, 1]


@inline(counted=False)
def store_impulses(manifolds, rows, count, shape_a, shape_b, point_count, feature, normal_impulse, tangent_impulse):
    """Keep this step's impulses, keyed by shape pair and feature, to warm-start the next step: the first ``count``
    rows of the contact state's arrays (``State.contact_*``), friction as world vectors. Slots past each manifold's
    point count hold leftovers of earlier steps: they are zeroed, so that the state (and its digest) holds only
    what the next step reads."""
    for m in range(count):
        shape_a[m], shape_b[m] = manifolds.shape_a[m], manifolds.shape_b[m]
        point_count[m] = manifolds.point_count[m]
        for j in range(MAX_POINTS):
            used = j < point_count[m]
            feature[m, j] = manifolds.feature[m, j] if used else 0
            normal_impulse[m, j] = rows.normal_impulse[m, j] if used else 0.0
            for i in range(3):
                along = (
                    rows.tangent_impulse[m, j, 0] * rows.tangent1[m, i]
                    + rows.tangent_impulse[m, j, 1] * rows.tangent2[m, i]
                )
                tangent_impulse[m, j, i] = along if used else 0.0
