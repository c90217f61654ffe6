"""Joint solver: ball, hinge, slider, fixed, distance, planar and universal joints as soft constraints in the
substeps.

Joints are solved with the contacts in the soft step (E. Catto, "Solver2D", 2024; Box2D v3's joints): every
substep re-applies the joints' accumulated impulses (warm start), solves each joint once with a soft position
bias (a spring of ``joint_hertz`` and damping ratio, ``softness.py``), and the relax pass solves them again
without bias. Unlike contacts, the arms and axes are recomputed from the bodies' current poses at every
solve, so that joint chains stay tight while they swing.

Each joint is a *rigid block* of up to six rows, solved as one linear system (Cholesky of its effective mass,
so that a hinge's anchor and axis rows do not fight each other as separate Gauss–Seidel blocks would), plus an
optional *drive* along its free axis (hinge angle, slider translation, distance), solved first, row by row: a
spring (always soft, its own frequency) with the joint's damping (an absolute coefficient, MJCF's, implicit in the
same row), a velocity motor with a bounded impulse, and one-sided limits
(speculative when apart, as contacts are).

Rows (world frame; ``r_a``, ``r_b`` the arms from each COM to its anchor, ``d = x_b + r_b − x_a − r_a``); each
is ``Ċ = l·(v_b − v_a) − α·ω_a + β·ω_b`` with effective mass ``K_rs = (m_a⁻¹ + m_b⁻¹) l_r·l_s + α_r·I_a⁻¹ α_s
+ β_r·I_b⁻¹ β_s``:

- anchors together (ball, hinge, fixed): ``l`` the world axes, ``α = r_a × l``, ``β = r_b × l``, error ``d``;
- angular lock (fixed, slider): ``l = 0``, ``α = β`` the world axes, error the rotation vector of
  ``q_b f_b (q_a f_a)⁻¹``; hinge alignment: the two of those across the axis, error ``n_a × n_b``;
- slider: the anchor rows across the axis and the drive along it use ``a``'s arm ``r_a + d`` (the axis turns
  with ``a``: ``d/dt (d·n) = (v_b + ω_b × r_b − v_a − ω_a × (r_a + d))·n``);
- planar (``n`` the plane's normal, the frame's x axis): one linear row along ``n`` with the slider's arm, and the
  hinge's two alignment rows (``b`` turns only about ``n``);
- universal (Hooke's joint: ``n_a`` the frame's x axis carried by ``a``, ``m_b`` its y axis carried by ``b``,
  perpendicular at creation): the anchor rows and one angular row keeping them perpendicular, ``C = n_a·m_b``,
  ``Ċ = (m_b × n_a)·(ω_b − ω_a)``.

Impulses live in ``state.joint_*`` (for warm starting and bit-identical resume): the point or cross-axis linear
impulse and the angular impulse as world vectors, and four drive impulses (spring, motor, lower, upper).
What each joint applied to body ``b`` over the step is summed into ``force_total`` (linear impulses) and
``moment_total`` (pure angular impulses, i.e. the moment about the anchor); ``Joint.reaction_force`` and
``reaction_torque`` are their opposites on ``a`` divided by the step.
"""

from __future__ import annotations

import math
from enum import IntEnum
from typing import NamedTuple

import numpy as np

from .. import elementary
from .._jit import inline, kernel
from ..dense import cholesky, cholesky_solve
from ..math3d import (
    add,
    add_scaled,
    cross,
    dot,
    load3,
    load4,
    load33,
    mat_vec,
    quat_conj,
    quat_mul,
    quat_rotate,
    scale,
    store3,
    sub,
)
from .contact_solver import _apply_impulse
from .softness import soft_coefficients, spring_damper_coefficients

__all__ = ["JointArrays", "JointKind", "joint_coordinates", "solve_joints", "warm_start_joints"]

BALL, HINGE, SLIDER, FIXED, DISTANCE, PLANAR, UNIVERSAL = 0, 1, 2, 3, 4, 5, 6  # joint kinds, plain ints for kernels


class JointKind(IntEnum):
    """Joint type codes in the model arrays (``model.joints.kind``; public as ``tumble.joints.JointKind``)."""

    BALL = BALL
    HINGE = HINGE
    SLIDER = SLIDER
    FIXED = FIXED
    DISTANCE = DISTANCE
    PLANAR = PLANAR
    UNIVERSAL = UNIVERSAL


# Columns of JointArrays.drive
LOWER, UPPER, MOTOR_SPEED, MAX_MOTOR, SPRING_HERTZ, SPRING_RATIO, TARGET, CONE, DAMPING = 0, 1, 2, 3, 4, 5, 6, 7, 8
# Columns of the drive impulses (state.joint_drive_impulse)
SPRING, MOTOR, LOWER_LIMIT, UPPER_LIMIT, CONE_LIMIT = 0, 1, 2, 3, 4

_EX, _EY, _EZ = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)


class JointArrays(NamedTuple):
    """The model's joints (``J`` rows). Body ``-1`` is the world (anchor and frame then in world coordinates)."""

    kind: np.ndarray  # (J,) int64, a JointKind
    body_a: np.ndarray  # (J,) int64
    body_b: np.ndarray  # (J,) int64
    local_anchor_a: np.ndarray  # (J, 3) anchor minus a's COM, a's frame
    local_anchor_b: np.ndarray  # (J, 3)
    local_frame_a: np.ndarray  # (J, 4) joint frame (x: the axis) relative to a's frame
    local_frame_b: np.ndarray  # (J, 4)
    drive: np.ndarray  # (J, 9) lower, upper, motor speed, max motor torque/force, spring hertz, ratio, target, cone,
    # damping

    @classmethod
    def empty(cls) -> JointArrays:
        z = np.zeros
        return cls(z(0, np.int64), z(0, np.int64), z(0, np.int64), z((0, 3)), z((0, 3)), z((0, 4)), z((0, 4)),
                   z((0, 9)))  # fmt: skip


_ZERO33 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@inline
def _load_pose(i, pos, quat, linvel, angvel):
    """COM, orientation and velocities of body ``i`` (the world, at rest at the origin, for -1)."""
    if i < 0:
        return (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    return load3(pos, i), load4(quat, i), load3(linvel, i), load3(angvel, i)


@inline
def _load_body(i, inv_mass, inv_inertia_world, pos, quat, linvel, angvel):
    """Inverse mass, world inverse inertia, COM, orientation, velocities of body ``i`` (the world for -1)."""
    x, q, v, w = _load_pose(i, pos, quat, linvel, angvel)
    if i < 0:
        return 0.0, _ZERO33, x, q, v, w
    return inv_mass[i], load33(inv_inertia_world, i), x, q, v, w


@inline
def _store_body(i, linvel, angvel, v, w):
    if i >= 0:
        store3(linvel, i, v)
        store3(angvel, i, w)


@inline
def _frames(joints, j, xa, qa, xb, qb):
    """Arms, anchor gap ``d`` and world joint frames of joint ``j`` at the bodies' current poses."""
    ra = quat_rotate(qa, load3(joints.local_anchor_a, j))
    rb = quat_rotate(qb, load3(joints.local_anchor_b, j))
    d = sub(add(xb, rb), add(xa, ra))
    fa = quat_mul(qa, load4(joints.local_frame_a, j))
    fb = quat_mul(qb, load4(joints.local_frame_b, j))
    return ra, rb, d, fa, fb


@inline
def _arm_a(kind, ra, d):
    """``a``'s lever arm for linear rows: a slider's axis (a plane's normal) turns with ``a`` about the point
    ``x_a + r_a + d``."""
    return add(ra, d) if kind == SLIDER or kind == PLANAR else ra


@inline
def _wrap_angle(angle):
    if angle > math.pi:
        return angle - 2.0 * math.pi
    if angle <= -math.pi:
        return angle + 2.0 * math.pi
    return angle


@inline
def _hinge_angle(fa, fb):
    """The twist of ``b``'s joint frame relative to ``a``'s about the x axis, in (−π, π]."""
    rel = quat_mul(quat_conj(fa), fb)
    return _wrap_angle(2.0 * elementary.atan2(rel[1], rel[0]))


@inline
def _drive_axis(kind, fa, d):
    """The drive's direction (world) and coordinate: hinge angle, slider translation, or distance."""
    if kind == DISTANCE:
        length = math.sqrt(dot(d, d))
        u = scale(d, 1.0 / length) if length > 1e-12 else _EX
        return u, length
    n = quat_rotate(fa, _EX)
    return n, dot(d, n)


@inline
def _point_rate(va, wa, arm_a, vb, wb, rb):
    return sub(add(vb, cross(wb, rb)), add(va, cross(wa, arm_a)))


@inline
def _axial_rate(angular, n, arm_a, rb, va, wa, vb, wb):
    if angular:
        return dot(sub(wb, wa), n)
    return dot(_point_rate(va, wa, arm_a, vb, wb, rb), n)


@inline
def _axial_inverse_mass(angular, n, arm_a, rb, ma, ia, mb, ib):
    if angular:
        k = dot(n, mat_vec(ia, n)) + dot(n, mat_vec(ib, n))
    else:
        an, bn = cross(arm_a, n), cross(rb, n)
        k = ma + mb + dot(an, mat_vec(ia, an)) + dot(bn, mat_vec(ib, bn))
    return 1.0 / k if k > 0.0 else 0.0


@inline
def _axial_apply(angular, n, arm_a, rb, impulse, ma, ia, mb, ib, va, wa, vb, wb):
    """Apply a drive impulse; returns the velocities and what b received (linear impulse, pure moment)."""
    if angular:
        m = scale(n, impulse)
        return va, sub(wa, mat_vec(ia, m)), vb, add(wb, mat_vec(ib, m)), (0.0, 0.0, 0.0), m
    p = scale(n, impulse)
    va, wa, vb, wb = _apply_impulse(arm_a, rb, p, ma, ia, mb, ib, va, wa, vb, wb)
    return va, wa, vb, wb, p, (0.0, 0.0, 0.0)


@inline
def _limit_impulse(old, mass, rate, c, inv_h, soft, push_max, use_bias):
    """New accumulated impulse (>= 0) of a one-sided limit with position error ``c`` (>= 0 when satisfied).

    A deep violation is pushed out at ``push_max`` at most (m/s or rad/s), as contacts are: at the joint's
    stiffness a 30° violation opened at over 100 rad/s, and between two free bodies the relax pass, which can only
    take back what the limit pushed, left up to 50 rad/s of it (the ant's ankles, loaded outside their range,
    flew to their far stops)."""
    bias, m_scale, i_scale = 0.0, 1.0, 0.0
    if c > 0.0:
        bias = c * inv_h  # speculative: may close the gap within the substep, no faster
    elif use_bias:
        bias, m_scale, i_scale = max(soft[0] * c, -push_max), soft[1], soft[2]
    return max(old - mass * m_scale * (rate + bias) - i_scale * old, 0.0)


@inline
def _block_work():
    """Work arrays of the rigid block (at most 6 rows): directions, errors, right-hand side, effective mass."""
    return np.zeros((6, 3)), np.zeros((6, 3)), np.zeros((6, 3)), np.zeros(6), np.zeros(6), np.zeros((6, 6))


@inline
def _set_row(r, lin, ang_a, ang_b, err, dir_l, dir_a, dir_b, error):
    store3(dir_l, r, lin)
    store3(dir_a, r, ang_a)
    store3(dir_b, r, ang_b)
    error[r] = err


@inline
def _block_rows(kind, fa, fb, arm, rb, d, dir_l, dir_a, dir_b, error):
    """The rigid rows of a joint: each row r is ``Ċ_r = l·(v_b − v_a) − α·ω_a + β·ω_b`` with position error
    ``C_r``; linear rows first (``l`` a direction, ``α = arm_a × l``, ``β = r_b × l``), then angular rows
    (``l = 0``, ``α = β`` the axis). Returns ``(rows, linear rows)``."""
    zero = (0.0, 0.0, 0.0)
    rows = 0
    if kind == BALL or kind == HINGE or kind == FIXED or kind == UNIVERSAL:
        _set_row(0, _EX, cross(arm, _EX), cross(rb, _EX), d[0], dir_l, dir_a, dir_b, error)
        _set_row(1, _EY, cross(arm, _EY), cross(rb, _EY), d[1], dir_l, dir_a, dir_b, error)
        _set_row(2, _EZ, cross(arm, _EZ), cross(rb, _EZ), d[2], dir_l, dir_a, dir_b, error)
        rows = 3
    elif kind == SLIDER:
        y, z = quat_rotate(fa, _EY), quat_rotate(fa, _EZ)
        _set_row(0, y, cross(arm, y), cross(rb, y), dot(d, y), dir_l, dir_a, dir_b, error)
        _set_row(1, z, cross(arm, z), cross(rb, z), dot(d, z), dir_l, dir_a, dir_b, error)
        rows = 2
    elif kind == PLANAR:
        n = quat_rotate(fa, _EX)
        _set_row(0, n, cross(arm, n), cross(rb, n), dot(d, n), dir_l, dir_a, dir_b, error)
        rows = 1
    linear_rows = rows
    if kind == HINGE or kind == PLANAR:
        y, z = quat_rotate(fa, _EY), quat_rotate(fa, _EZ)
        err = cross(quat_rotate(fa, _EX), quat_rotate(fb, _EX))
        _set_row(rows, zero, y, y, dot(err, y), dir_l, dir_a, dir_b, error)
        _set_row(rows + 1, zero, z, z, dot(err, z), dir_l, dir_a, dir_b, error)
        rows += 2
    elif kind == FIXED or kind == SLIDER:
        q_err = quat_mul(fb, quat_conj(fa))
        sign = 2.0 if q_err[0] >= 0.0 else -2.0  # the rotation vector of the error, for small errors
        _set_row(rows, zero, _EX, _EX, sign * q_err[1], dir_l, dir_a, dir_b, error)
        _set_row(rows + 1, zero, _EY, _EY, sign * q_err[2], dir_l, dir_a, dir_b, error)
        _set_row(rows + 2, zero, _EZ, _EZ, sign * q_err[3], dir_l, dir_a, dir_b, error)
        rows += 3
    elif kind == UNIVERSAL:
        n_a, m_b = quat_rotate(fa, _EX), quat_rotate(fb, _EY)
        t = cross(m_b, n_a)
        _set_row(rows, zero, t, t, dot(n_a, m_b), dir_l, dir_a, dir_b, error)
        rows += 1
    return rows, linear_rows


@inline
def _block_mass(rows, ma, ia, mb, ib, dir_l, dir_a, dir_b, k):
    """``K_rs = (m_a⁻¹ + m_b⁻¹) l_r·l_s + α_r·I_a⁻¹ α_s + β_r·I_b⁻¹ β_s``."""
    for r in range(rows):
        lr, ar, br = load3(dir_l, r), load3(dir_a, r), load3(dir_b, r)
        ia_ar, ib_br = mat_vec(ia, ar), mat_vec(ib, br)
        for c in range(r + 1):
            value = (ma + mb) * dot(lr, load3(dir_l, c)) + dot(ia_ar, load3(dir_a, c)) + dot(ib_br, load3(dir_b, c))
            k[r, c] = value
            k[c, r] = value


@inline
def _block_impulse(rows, linear_rows, lam, dir_l, dir_a, dir_b):
    """The block's impulses ``λ`` as world vectors: linear ``Σ λ l``, angular ``Σ λ n`` (angular rows), and the
    moments they exert on a and b (``Σ λ α``, ``Σ λ β``)."""
    p, m, turn_a, turn_b = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    for r in range(rows):
        if r < linear_rows:
            p = add_scaled(p, load3(dir_l, r), lam[r])
        else:
            m = add_scaled(m, load3(dir_a, r), lam[r])
        turn_a = add_scaled(turn_a, load3(dir_a, r), lam[r])
        turn_b = add_scaled(turn_b, load3(dir_b, r), lam[r])
    return p, m, turn_a, turn_b


@inline
def _held_direction(dl, da, db, rows, linear_rows, ma, ia, mb, ib, dir_l, dir_a, dir_b, k_block, solvable, k_bd, y):
    """A drive row ``(l, α, β)`` with the joint's rigid block held: minus the block's response ``y = K⁻¹ K_B,d``
    (a Schur complement). Returns the held row, the block's share of a unit impulse (linear, angular) and the
    row's effective mass ``1 / (K_dd − K_dB y)``."""
    for r in range(rows):
        k_bd[r] = (
            (ma + mb) * dot(load3(dir_l, r), dl)
            + dot(mat_vec(ia, load3(dir_a, r)), da)
            + dot(mat_vec(ib, load3(dir_b, r)), db)
        )
        y[r] = k_bd[r]
    if solvable:
        cholesky_solve(k_block, y, rows)
    k_dd = (ma + mb) * dot(dl, dl) + dot(da, mat_vec(ia, da)) + dot(db, mat_vec(ib, db))
    block_p, block_m = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    for r in range(rows if solvable else 0):
        k_dd -= y[r] * k_bd[r]
        dl = add_scaled(dl, load3(dir_l, r), -y[r])
        da = add_scaled(da, load3(dir_a, r), -y[r])
        db = add_scaled(db, load3(dir_b, r), -y[r])
        if r < linear_rows:
            block_p = add_scaled(block_p, load3(dir_l, r), -y[r])
        else:
            block_m = add_scaled(block_m, load3(dir_a, r), -y[r])
    return dl, da, db, block_p, block_m, (1.0 / k_dd if k_dd > 1e-12 else 0.0)


@inline
def _has_drive(joints, j, kind):
    """Whether joint ``j`` has a drive row to solve: a spring, a motor, a limit, or a rigid distance (a plain
    hinge or ball joint has none, and skips the drive's setup)."""
    if kind == FIXED:
        return False
    lower, upper = joints.drive[j, LOWER], joints.drive[j, UPPER]
    limited = lower < upper and (lower > -math.inf or upper < math.inf)
    rod = kind == DISTANCE and lower == upper
    return (
        limited
        or rod
        or joints.drive[j, SPRING_HERTZ] > 0.0
        or joints.drive[j, DAMPING] > 0.0
        or joints.drive[j, MAX_MOTOR] > 0.0
        or (kind == BALL and joints.drive[j, CONE] < math.pi)
    )


@inline
def _swing(fa, fb):
    """The swing of ``b``'s joint x axis away from ``a``'s: its angle and the unit axis it turns about."""
    na, nb = quat_rotate(fa, _EX), quat_rotate(fb, _EX)
    turn = cross(na, nb)
    sine = math.sqrt(dot(turn, turn))
    axis = scale(turn, 1.0 / sine) if sine > 1e-9 else _EY
    return elementary.atan2(sine, dot(na, nb)), axis


@inline(counted=False)
def warm_start_joints(joints, impulses, inv_mass, inv_inertia_world, pos, quat, linvel, angvel, force_total,
                      moment_total):  # fmt: skip
    """Re-apply every joint's accumulated impulses at the current poses. Writes: velocities, the totals."""
    linear, angular_impulse, drive_impulse = impulses
    for j in range(joints.kind.shape[0]):
        a, b, kind = joints.body_a[j], joints.body_b[j], joints.kind[j]
        ma, ia, xa, qa, va, wa = _load_body(a, inv_mass, inv_inertia_world, pos, quat, linvel, angvel)
        mb, ib, xb, qb, vb, wb = _load_body(b, inv_mass, inv_inertia_world, pos, quat, linvel, angvel)
        p = load3(linear, j)
        if ma + mb == 0.0:
            # Asleep (or both fixed): the joint still holds with the impulses it had; report them.
            store3(force_total, j, add(load3(force_total, j), p))
            store3(moment_total, j, add(load3(moment_total, j), load3(angular_impulse, j)))
            continue
        ra, rb, d, fa, fb = _frames(joints, j, xa, qa, xb, qb)
        arm = _arm_a(kind, ra, d)
        m = load3(angular_impulse, j)
        va, wa, vb, wb = _apply_impulse(arm, rb, p, ma, ia, mb, ib, va, wa, vb, wb)
        wa, wb = sub(wa, mat_vec(ia, m)), add(wb, mat_vec(ib, m))
        got_p, got_m = p, m
        total = (drive_impulse[j, SPRING] + drive_impulse[j, MOTOR] + drive_impulse[j, LOWER_LIMIT]
                 - drive_impulse[j, UPPER_LIMIT])  # fmt: skip
        if total != 0.0:
            n, _ = _drive_axis(kind, fa, d)
            angular = kind == HINGE or kind == BALL
            va, wa, vb, wb, dp, dm = _axial_apply(angular, n, arm, rb, total, ma, ia, mb, ib, va, wa, vb, wb)
            got_p, got_m = add(got_p, dp), add(got_m, dm)
        if drive_impulse[j, CONE_LIMIT] != 0.0:
            _, k = _swing(fa, fb)
            m = scale(k, -drive_impulse[j, CONE_LIMIT])
            wa, wb = sub(wa, mat_vec(ia, m)), add(wb, mat_vec(ib, m))
            got_m = add(got_m, m)
        _store_body(a, linvel, angvel, va, wa)
        _store_body(b, linvel, angvel, vb, wb)
        store3(force_total, j, add(load3(force_total, j), got_p))
        store3(moment_total, j, add(load3(moment_total, j), got_m))


@inline
def solve_joints(joints, impulses, inv_mass, inv_inertia_world, pos, quat, linvel, angvel, h, joint_hertz,
                 joint_damping_ratio, push_max, use_bias, force_total, moment_total):  # fmt: skip
    """One Gauss–Seidel pass over the joints: drive, angular rows, point rows (soft when ``use_bias``); limits
    push out at ``push_max`` at most.

    Writes: the accumulated impulses, velocities, and what each joint gave body ``b`` (the totals).
    """
    linear, angular_impulse, drive_impulse = impulses
    inv_h = 1.0 / h
    dir_l, dir_a, dir_b, error, rhs, k_block = _block_work()
    coupling = np.zeros(6)
    accumulated = np.zeros(6)
    soft = soft_coefficients(min(joint_hertz, 0.25 * inv_h), joint_damping_ratio, h)
    for j in range(joints.kind.shape[0]):
        a, b, kind = joints.body_a[j], joints.body_b[j], joints.kind[j]
        ma, ia, xa, qa, va, wa = _load_body(a, inv_mass, inv_inertia_world, pos, quat, linvel, angvel)
        mb, ib, xb, qb, vb, wb = _load_body(b, inv_mass, inv_inertia_world, pos, quat, linvel, angvel)
        if ma + mb == 0.0:
            continue
        ra, rb, d, fa, fb = _frames(joints, j, xa, qa, xb, qb)
        arm = _arm_a(kind, ra, d)
        got_p, got_m = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        # The rigid block (anchors together or across the slider's axis, axes aligned): rows and factorised mass.
        rows, linear_rows = _block_rows(kind, fa, fb, arm, rb, d, dir_l, dir_a, dir_b, error)
        _block_mass(rows, ma, ia, mb, ib, dir_l, dir_a, dir_b, k_block)
        solvable = cholesky(k_block, rows)
        # Drive along the free axis: spring, motor, limits (rod: a rigid distance), each row acting on the joint
        # *with its block held*: the row's direction minus its block response y = K⁻¹ K_B,d (a Schur complement),
        # so that a hinge limit stops a pendulum bob swinging round the pivot, not just its spin about its COM.
        if _has_drive(joints, j, kind):
            angular = kind == HINGE or kind == BALL  # a ball joint's drive is its twist (limits only)
            n, value = _drive_axis(kind, fa, d)
            if angular:
                value = _hinge_angle(fa, fb)
                dl, da, db = (0.0, 0.0, 0.0), n, n
            else:
                dl, da, db = n, cross(arm, n), cross(rb, n)
            dl, da, db, block_p, block_m, mass = _held_direction(
                dl, da, db, rows, linear_rows, ma, ia, mb, ib, dir_l, dir_a, dir_b, k_block, solvable, rhs, coupling
            )
            pure_m = add(n, block_m) if angular else block_m
            lower, upper = joints.drive[j, LOWER], joints.drive[j, UPPER]
            spring_hertz, damping = joints.drive[j, SPRING_HERTZ], joints.drive[j, DAMPING]
            rigid_rod = kind == DISTANCE and spring_hertz == 0.0 and lower == upper
            for row in range(4):
                if row == SPRING:
                    if not (spring_hertz > 0.0 or rigid_rod or (damping > 0.0 and mass > 0.0)):
                        continue
                    if rigid_rod:
                        sc = soft if use_bias else (0.0, 1.0, 0.0)
                    else:  # the spring and the joint's damping, implicit together
                        sc = spring_damper_coefficients(spring_hertz, joints.drive[j, SPRING_RATIO], damping, mass, h)
                    old = drive_impulse[j, SPRING]
                    rate = dot(dl, sub(vb, va)) - dot(da, wa) + dot(db, wb)
                    new = old - mass * sc[1] * (rate + sc[0] * (value - joints.drive[j, TARGET])) - sc[2] * old
                    step = new - old
                elif row == MOTOR:
                    max_motor = joints.drive[j, MAX_MOTOR]
                    if max_motor <= 0.0:
                        continue
                    old = drive_impulse[j, MOTOR]
                    rate = dot(dl, sub(vb, va)) - dot(da, wa) + dot(db, wb)
                    bound = max_motor * h
                    new = min(max(old - mass * (rate - joints.drive[j, MOTOR_SPEED]), -bound), bound)
                    step = new - old
                elif row == LOWER_LIMIT:
                    if not (lower < upper and lower > -math.inf):
                        continue
                    old = drive_impulse[j, LOWER_LIMIT]
                    rate = dot(dl, sub(vb, va)) - dot(da, wa) + dot(db, wb)
                    new = _limit_impulse(old, mass, rate, value - lower, inv_h, soft, push_max, use_bias)
                    step = new - old
                else:
                    if not (lower < upper and upper < math.inf):
                        continue
                    old = drive_impulse[j, UPPER_LIMIT]
                    rate = dot(dl, sub(vb, va)) - dot(da, wa) + dot(db, wb)
                    new = _limit_impulse(old, mass, -rate, upper - value, inv_h, soft, push_max, use_bias)
                    step = old - new  # the upper limit pushes against the axis
                drive_impulse[j, row] = new
                va, vb = add_scaled(va, dl, -ma * step), add_scaled(vb, dl, mb * step)
                wa, wb = sub(wa, mat_vec(ia, scale(da, step))), add(wb, mat_vec(ib, scale(db, step)))
                store3(linear, j, add_scaled(load3(linear, j), block_p, step))
                store3(angular_impulse, j, add_scaled(load3(angular_impulse, j), block_m, step))
                got_p, got_m = add_scaled(got_p, dl, step), add_scaled(got_m, pure_m, step)
            if kind == BALL and joints.drive[j, CONE] < math.pi:
                # Swing cone: b's x axis within ``cone`` of a's, a one-sided limit about the axis it swings on.
                swing, k = _swing(fa, fb)
                dl, da, db, block_p, block_m, mass = _held_direction(
                    (0.0, 0.0, 0.0), k, k, rows, linear_rows, ma, ia, mb, ib, dir_l, dir_a, dir_b, k_block, solvable,
                    rhs, coupling,
                )  # fmt: skip
                old = drive_impulse[j, CONE_LIMIT]
                rate = dot(dl, sub(vb, va)) - dot(da, wa) + dot(db, wb)
                new = _limit_impulse(old, mass, -rate, joints.drive[j, CONE] - swing, inv_h, soft, push_max, use_bias)
                step = old - new
                drive_impulse[j, CONE_LIMIT] = new
                va, vb = add_scaled(va, dl, -ma * step), add_scaled(vb, dl, mb * step)
                wa, wb = sub(wa, mat_vec(ia, scale(da, step))), add(wb, mat_vec(ib, scale(db, step)))
                store3(linear, j, add_scaled(load3(linear, j), block_p, step))
                store3(angular_impulse, j, add_scaled(load3(angular_impulse, j), block_m, step))
                got_p, got_m = add_scaled(got_p, dl, step), add_scaled(got_m, add(k, block_m), step)
        if rows > 0 and solvable:
            bias_rate, m_scale, i_scale = (soft[0], soft[1], soft[2]) if use_bias else (0.0, 1.0, 0.0)
            old_p, old_m = load3(linear, j), load3(angular_impulse, j)
            for r in range(rows):
                lr, ar, br = load3(dir_l, r), load3(dir_a, r), load3(dir_b, r)
                rate = dot(lr, sub(vb, va)) - dot(ar, wa) + dot(br, wb)
                rhs[r] = -m_scale * (rate + bias_rate * error[r])
            cholesky_solve(k_block, rhs, rows)
            for r in range(rows):
                old_r = dot(old_p, load3(dir_l, r)) if r < linear_rows else dot(old_m, load3(dir_a, r))
                rhs[r] -= i_scale * old_r
                accumulated[r] = old_r + rhs[r]
            p, m, turn_a, turn_b = _block_impulse(rows, linear_rows, rhs, dir_l, dir_a, dir_b)
            # The accumulated impulse is kept on the rows as they are now: the part of the old one that the joint's
            # turning has carried off them (onto a hinge's free axis, a slider's) is no reaction of this block, and
            # warm starting it again would drive the free axis (a wrist spun up until the arm blew up).
            kept_p, kept_m, _, _ = _block_impulse(rows, linear_rows, accumulated, dir_l, dir_a, dir_b)
            store3(linear, j, kept_p if linear_rows > 0 else old_p)
            store3(angular_impulse, j, kept_m if rows > linear_rows else old_m)
            va, vb = add_scaled(va, p, -ma), add_scaled(vb, p, mb)
            wa, wb = sub(wa, mat_vec(ia, turn_a)), add(wb, mat_vec(ib, turn_b))
            got_p, got_m = add(got_p, p), add(got_m, m)
        _store_body(a, linvel, angvel, va, wa)
        _store_body(b, linvel, angvel, vb, wb)
        store3(force_total, j, add(load3(force_total, j), got_p))
        store3(moment_total, j, add(load3(moment_total, j), got_m))


@kernel
def joint_coordinates(joints, pos, quat, linvel, angvel, first, stop, out):
    """Per joint ``first <= j < stop``: the drive coordinate (hinge angle or ball twist, slider translation,
    distance), its rate, the anchor gap ``|d|``, the axis misalignment angle [rad] and a ball joint's swing
    [rad]. Writes: out (stop - first, 5)."""
    for j in range(first, stop):
        a, b, kind = joints.body_a[j], joints.body_b[j], joints.kind[j]
        xa, qa, va, wa = _load_pose(a, pos, quat, linvel, angvel)
        xb, qb, vb, wb = _load_pose(b, pos, quat, linvel, angvel)
        ra, rb, d, fa, fb = _frames(joints, j, xa, qa, xb, qb)
        n, value = _drive_axis(kind, fa, d)
        arm = _arm_a(kind, ra, d)
        if kind == HINGE or kind == BALL:
            value = _hinge_angle(fa, fb)
        out[j - first, 0] = value
        out[j - first, 1] = _axial_rate(kind == HINGE or kind == BALL, n, arm, rb, va, wa, vb, wb)
        out[j - first, 4] = _swing(fa, fb)[0] if kind == BALL else 0.0
        out[j - first, 2] = math.sqrt(dot(d, d))
        if kind == HINGE or kind == PLANAR:
            na, nb = quat_rotate(fa, _EX), quat_rotate(fb, _EX)
            out[j - first, 3] = elementary.atan2(math.sqrt(dot(cross(na, nb), cross(na, nb))), dot(na, nb))
        elif kind == UNIVERSAL:
            out[j - first, 3] = abs(
                elementary.asin(min(max(dot(quat_rotate(fa, _EX), quat_rotate(fb, _EY)), -1.0), 1.0))
            )
        elif kind == FIXED or kind == SLIDER:
            q_err = quat_mul(fb, quat_conj(fa))
            sine = math.sqrt(q_err[1] ** 2 + q_err[2] ** 2 + q_err[3] ** 2)
            out[j - first, 3] = 2.0 * elementary.atan2(sine, abs(q_err[0]))
        else:
            out[j - first, 3] = 0.0
