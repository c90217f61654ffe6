"""Loop closures: closed chains (four-bars, slider–cranks) as constraints on the tree.

A loop closure keeps a point of link a on a point of link b (or of the world): ``φ(q) = x_a - x_b = 0``, three
rows. Differentiated twice, ``J q̈ = γ`` with ``J`` the difference of the two point Jacobians and
``γ = -J̇ q̇`` the velocity-product part of the points' accelerations. Forward dynamics solves the KKT system

    H q̈ = τ - C + Jᵀ λ,     J q̈ = γ

by the range-space method (Featherstone 2008, §8.3): ``q̈ = q̈₀ + H⁻¹ Jᵀ λ`` with ``(J H⁻¹ Jᵀ) λ = γ - J q̈₀``,
reusing the LTDL factor of ``H``. Planar mechanisms make some rows redundant (the out-of-plane row of a
point closure is identically zero), so ``J H⁻¹ Jᵀ`` is factored as ``L D Lᵀ`` with rows whose pivot vanishes
dropped (their λ is zero), which is exact for consistent redundant rows.

Drift: after every step the state is projected back onto the constraint manifold (no Baumgarte terms):
Gauss–Newton steps ``q ← q ⊕ (-H⁻¹ Jᵀ (J H⁻¹ Jᵀ)⁻¹ φ)`` until ``|φ| ≤`` :data:`POSITION_TOLERANCE`, then the
mass-weighted velocity projection ``q̇ ← q̇ - H⁻¹ Jᵀ (J H⁻¹ Jᵀ)⁻¹ J q̇``, which removes only the kinetic
energy of constraint-violating motion (Cline and Pai, "Post-stabilization for rigid body simulation with
contact and constraints", ICRA 2003).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._jit import inline
from ..math3d import add, add_scaled, cross, quat_rotate
from .dynamics import ltdl_solve
from .kinematics import forward_kinematics, integrate_configuration
from .model import (
    ACC,
    DOF_PARENT,
    DOF_TIP,
    LINK_A,
    LOOP_ACTIVE,
    LOOP_ERROR,
    LOOP_LAMBDA,
    LOOP_RHS,
    PARENT,
    POINT_A,
    POS,
    QUAT,
    RHS,
    VEL,
    VEL_PRODUCT,
)
from .spatial import ZERO3, ZERO6, add6, assign, fill, fill_matrix, get3, get4, get6, point_acceleration, put6

__all__ = [
    "LoopClosure",
    "POSITION_TOLERANCE",
    "loop_jacobian",
    "project_loop_closures",
    "solve_loop_closures",
]

# [m]: the projection stops once every closure is this close; a few ulps of a metre-sized mechanism.
POSITION_TOLERANCE = 1e-12
PROJECTION_ITERATIONS = 4  # Gauss–Newton converges quadratically: 2 iterations reach 1e-12 after one step
# Rows of J H⁻¹ Jᵀ whose pivot is below this fraction of the largest diagonal entry are redundant.
REDUNDANT_RTOL = 1e-10


@dataclass(frozen=True)
class LoopClosure:
    """A point of ``link_a`` held on a point of ``link_b`` (``None``: the world). Points in those frames [m]."""

    index: int
    link_a: int
    point_a: np.ndarray
    link_b: int | None
    point_b: np.ndarray
    kind: str = "point"


@inline
def loop_jacobian(link_ints, dof_ints, loop_ints, loop_reals, link_work, dof_motion, loop_jac, loop_work):
    """The closure errors, Jacobian and acceleration bias at the state of the last kinematics pass.

    Reads ``link_work`` (``POS``, ``QUAT``, ``VEL``, ``VEL_PRODUCT``) and ``dof_motion``. Writes
    ``link_work[:, ACC]`` (velocity-product accelerations, without gravity), ``loop_jac`` (J) and the
    ``loop_work`` rows ``LOOP_ERROR`` (φ) and ``LOOP_RHS`` (γ = -J̇ q̇).
    """
    for i in range(link_ints.shape[0]):
        parent = link_ints[i, PARENT]
        inherited = ZERO6 if parent < 0 else get6(link_work, parent, ACC)
        put6(link_work, i, ACC, add6(inherited, get6(link_work, i, VEL_PRODUCT)))
    fill_matrix(loop_jac, 0.0)
    for c in range(loop_ints.shape[0]):
        error, bias = ZERO3, ZERO3
        for side in range(2):
            link = loop_ints[c, LINK_A + side]
            local = get3(loop_reals, c, POINT_A + 3 * side)
            sign = 1.0 - 2.0 * side
            if link < 0:  # a world point: fixed
                error = add_scaled(error, local, sign)
                continue
            point = add(get3(link_work, link, POS), quat_rotate(get4(link_work, link, QUAT), local))
            acc = point_acceleration(get6(link_work, link, VEL), get6(link_work, link, ACC), point)
            error = add_scaled(error, point, sign)
            bias = add_scaled(bias, acc, sign)
            k = link_ints[link, DOF_TIP]
            while k >= 0:
                s = get6(dof_motion, k, 0)
                column = add(s[1], cross(s[0], point))
                for r in range(3):
                    loop_jac[3 * c + r, k] += sign * column[r]
                k = dof_ints[k, DOF_PARENT]
        for r in range(3):
            loop_work[LOOP_ERROR, 3 * c + r] = error[r]
            loop_work[LOOP_RHS, 3 * c + r] = -bias[r]


@inline
def _dot(a, b):
    total = 0.0
    for k in range(a.shape[0]):
        total += a[k] * b[k]
    return total


@inline
def _factor_loop_matrix(dof_ints, mass_matrix, loop_jac, loop_minv_jt, loop_matrix, active):
    """``J H⁻¹ Jᵀ`` into ``loop_matrix`` as ``L D Lᵀ``, redundant rows marked 0 in ``active``; keeps ``H⁻¹ Jᵀ``."""
    nc = loop_jac.shape[0]
    for r in range(nc):
        row = loop_minv_jt[r]
        assign(row, loop_jac[r])
        ltdl_solve(dof_ints, mass_matrix, row)
    a = loop_matrix
    largest = 0.0
    for r in range(nc):
        for s in range(r + 1):
            a[r, s] = _dot(loop_jac[r], loop_minv_jt[s])
        largest = max(largest, a[r, r])
    for k in range(nc):
        d = a[k, k]
        for j in range(k):
            d -= a[k, j] * a[k, j] * a[j, j]
        if not d > REDUNDANT_RTOL * largest:
            active[k] = 0.0
            a[k, k] = 1.0
            for i in range(k + 1, nc):
                a[i, k] = 0.0
            continue
        active[k] = 1.0
        a[k, k] = d
        for i in range(k + 1, nc):
            s = a[i, k]
            for j in range(k):
                s -= a[i, j] * a[k, j] * a[j, j]
            a[i, k] = s / d


@inline
def _solve_loop_matrix(loop_matrix, active, x):
    """Solve ``L D Lᵀ x = b`` in place with the factor of :func:`_factor_loop_matrix`; inactive rows get 0."""
    a = loop_matrix
    nc = a.shape[0]
    for i in range(nc):
        for j in range(i):
            x[i] -= a[i, j] * x[j]
    for i in range(nc):
        x[i] = x[i] / a[i, i] if active[i] > 0.0 else 0.0
    for i in range(nc - 1, -1, -1):
        for j in range(i + 1, nc):
            x[i] -= a[j, i] * x[j]


@inline
def _add_constraint_motion(loop_minv_jt, lam, sign, x):
    """``x += sign H⁻¹ Jᵀ λ``."""
    for r in range(loop_minv_jt.shape[0]):
        scaled = sign * lam[r]
        for k in range(x.shape[0]):
            x[k] += scaled * loop_minv_jt[r, k]


@inline
def solve_loop_closures(dof_ints, mass_matrix, loop_jac, loop_minv_jt, loop_matrix, loop_work, qdd):
    """Correct the tree accelerations ``qdd`` (nv,) so that ``J q̈ = γ`` (the range-space KKT solve).

    Needs ``J`` and ``γ`` from :func:`loop_jacobian` and the LTDL factor of ``H`` in ``mass_matrix``.
    """
    _factor_loop_matrix(dof_ints, mass_matrix, loop_jac, loop_minv_jt, loop_matrix, loop_work[LOOP_ACTIVE])
    lam = loop_work[LOOP_LAMBDA]
    for r in range(lam.shape[0]):
        lam[r] = loop_work[LOOP_RHS, r] - _dot(loop_jac[r], qdd)
    _solve_loop_matrix(loop_matrix, loop_work[LOOP_ACTIVE], lam)
    _add_constraint_motion(loop_minv_jt, lam, 1.0, qdd)


@inline
def project_loop_closures(m, w, q, qd):
    """Move ``q`` and ``qd`` (in place) onto the closure manifold; ``w.mass_matrix`` must hold a factor of ``H``."""
    link_ints, link_reals, world, dof_ints = m.link_ints, m.link_reals, m.world, m.dof_ints
    link_work, dof_motion, h = w.link_work, w.dof_motion, w.mass_matrix
    loop_jac, loop_minv_jt, loop_matrix, loop_work = w.loop_jac, w.loop_minv_jt, w.loop_matrix, w.loop_work
    step, lam, error, active = w.dof_work[RHS], loop_work[LOOP_LAMBDA], loop_work[LOOP_ERROR], loop_work[LOOP_ACTIVE]
    for _ in range(PROJECTION_ITERATIONS + 1):
        forward_kinematics(link_ints, link_reals, world, q, qd, link_work, dof_motion)
        loop_jacobian(link_ints, dof_ints, m.loop_ints, m.loop_reals, link_work, dof_motion, loop_jac, loop_work)
        _factor_loop_matrix(dof_ints, h, loop_jac, loop_minv_jt, loop_matrix, active)
        worst = 0.0
        for r in range(error.shape[0]):
            worst = max(worst, abs(error[r]))
        if worst <= POSITION_TOLERANCE:
            break
        # a Gauss–Newton step, mass-weighted: the smallest motion (in kinetic metric) that closes φ to first order
        assign(lam, error)
        _solve_loop_matrix(loop_matrix, active, lam)
        fill(step, 0.0)
        _add_constraint_motion(loop_minv_jt, lam, -1.0, step)
        integrate_configuration(link_ints, q, step, 1.0, q)
    # velocities: remove the part that violates J q̇ = 0, in the kinetic-energy metric
    for r in range(lam.shape[0]):
        lam[r] = _dot(loop_jac[r], qd)
    _solve_loop_matrix(loop_matrix, active, lam)
    _add_constraint_motion(loop_minv_jt, lam, -1.0, qd)
