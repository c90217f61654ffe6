"""MuJoCo's constraint problem, solved in its dual: the forces of the active rows that ``constraints.py`` and
``contacts.py`` wrote (their Jacobians, reference accelerations, regularisers and bounds in ``w.efc_*``).

The forces minimise ``½ fᵀ (A + R) f + fᵀ (J q̈₀ - aref)`` within their bounds, ``A = J H⁻¹ Jᵀ`` (MuJoCo
documentation, *Computation*: "Solver"); ``q̈ = q̈₀ + H⁻¹ Jᵀ f``. ``A + R`` is positive definite, so the solution is
unique, the one MuJoCo's Newton, CG and PGS solvers converge to. The work stays in the joints' space: with
``H = Lᵀ D L`` (``dynamics.ltdl_factor``) and ``Y = L⁻ᵀ Jᵀ`` (one sparse half-solve a row, Featherstone 2008, §6.5),
``A = Yᵀ D⁻¹ Y``, so a row's residual is ``offset + R f + yᵀ D⁻¹ z`` with ``z = Σ fⱼ yⱼ`` kept as the forces change,
and no ``rows × rows`` matrix is ever made (a fallen humanoid has 40 rows over 27 joints, a walker 56 over 9).

Projected Gauss–Seidel sweeps find which rows rest on their bounds. Every other sweep, block principal pivoting
(Júdice and Pires, 1994) starts from that active set: the free rows are solved exactly with the others at their
bounds, by the Sherman–Morrison–Woodbury identity ``(R + Yᵀ D⁻¹ Y)⁻¹ = R⁻¹ - R⁻¹ Yᵀ K⁻¹ Y R⁻¹`` with the
``nv × nv`` matrix ``K = D + Y R⁻¹ Yᵀ`` (Cholesky), then free rows that left their box are bound and bound rows that
would rather leave their bound are freed, until nothing changes: the KKT conditions hold and the solve ends, at the
solution to rounding. Otherwise (a few rounds, or a cycle) the sweeps go on.
"""

from __future__ import annotations

from .._jit import inline
from ..dense import cholesky, cholesky_solve
from .dynamics import dl_solve, lt_solve
from .model import (
    EFC_AREF,
    EFC_DIAG,
    EFC_FORCE,
    EFC_HIGH,
    EFC_LOW,
    EFC_OFFSET,
    EFC_R,
    EFC_STATE,
    EFC_TRIAL,
    RHS,
)

__all__ = ["solve_constraints"]

# the sweeps stop when no force moves by more than this fraction of the largest (or after the cap)
_TOLERANCE = 1e-13
_MAX_SWEEPS = 10000
# every this many sweeps, pivoting from the sweeps' active set; it stops when the KKT conditions hold to this fraction
# of the largest offset, or after this many rounds
_PIVOT_EVERY = 2
_KKT_TOLERANCE = 1e-12
_PIVOT_ROUNDS = 8


@inline
def _weighted_dot(y, i, inverse_pivots, z):
    """``yᵢᵀ D⁻¹ z``."""
    total = 0.0
    for k in range(z.shape[0]):
        total += y[i, k] * inverse_pivots[k] * z[k]
    return total


@inline
def _gather(y, e, row, count, z):
    """``z = Σ fⱼ yⱼ`` with ``fⱼ = e[row, j]``."""
    for k in range(z.shape[0]):
        z[k] = 0.0
    for j in range(count):
        force = e[row, j]
        if force != 0.0:
            for k in range(z.shape[0]):
                z[k] += force * y[j, k]


@inline
def _pivot(w, count, inverse_pivots, factor):
    """Block principal pivoting from the active set of ``EFC_FORCE``; True (the solution in ``EFC_FORCE`` and
    ``w.efc_z``) when it ends at the KKT conditions."""
    e, y, k_matrix, z = w.efc_work, w.efc_jac, w.efc_factor, w.efc_z
    nv = z.shape[0]
    scale = 0.0
    for i in range(count):
        force = e[EFC_FORCE, i]
        e[EFC_STATE, i] = -1.0 if force <= e[EFC_LOW, i] else (1.0 if force >= e[EFC_HIGH, i] else 0.0)
        scale = max(scale, abs(e[EFC_OFFSET, i]))
    for _ in range(_PIVOT_ROUNDS):
        # the bound rows' push on the free ones, then K = D + Σ_F yᵢ yᵢᵀ / Rᵢ and t = Σ_F yᵢ bᵢ / Rᵢ
        for i in range(count):
            state = e[EFC_STATE, i]
            e[EFC_TRIAL, i] = e[EFC_LOW, i] if state < 0.0 else (e[EFC_HIGH, i] if state > 0.0 else 0.0)
        _gather(y, e, EFC_TRIAL, count, z)
        t = w.dof_work[RHS]
        for a in range(nv):
            t[a] = 0.0
            for b in range(a + 1):
                k_matrix[a, b] = 0.0
            k_matrix[a, a] = factor[a, a]
        for i in range(count):
            if e[EFC_STATE, i] != 0.0:
                continue
            weight = 1.0 / e[EFC_R, i]
            rhs = -(e[EFC_OFFSET, i] + _weighted_dot(y, i, inverse_pivots, z))
            e[EFC_TRIAL, i] = rhs  # the free row's right-hand side, for now
            for a in range(nv):
                ya = y[i, a]
                if ya != 0.0:
                    t[a] += ya * rhs * weight
                    for b in range(a + 1):
                        k_matrix[a, b] += ya * y[i, b] * weight
        if not cholesky(k_matrix, nv):
            return False
        cholesky_solve(k_matrix, t, nv)
        for i in range(count):  # xᵢ = (bᵢ - yᵢ · u) / Rᵢ, u = K⁻¹ t
            if e[EFC_STATE, i] == 0.0:
                projected = 0.0
                for a in range(nv):
                    projected += y[i, a] * t[a]
                e[EFC_TRIAL, i] = (e[EFC_TRIAL, i] - projected) / e[EFC_R, i]
        _gather(y, e, EFC_TRIAL, count, z)
        changed = False
        for i in range(count):
            state, trial = e[EFC_STATE, i], e[EFC_TRIAL, i]
            if state == 0.0:
                if trial < e[EFC_LOW, i]:
                    e[EFC_STATE, i], changed = -1.0, True
                elif trial > e[EFC_HIGH, i]:
                    e[EFC_STATE, i], changed = 1.0, True
                continue
            gradient = e[EFC_OFFSET, i] + e[EFC_R, i] * trial + _weighted_dot(y, i, inverse_pivots, z)
            wrong_way = gradient < -_KKT_TOLERANCE * scale if state < 0.0 else gradient > _KKT_TOLERANCE * scale
            if wrong_way:
                e[EFC_STATE, i], changed = 0.0, True
        if not changed:
            for i in range(count):
                e[EFC_FORCE, i] = e[EFC_TRIAL, i]
            return True
    return False


@inline(counted=False)
def solve_constraints(m, w, count, factor, qdd):
    """Add the accelerations of the ``count`` active constraint rows in ``w.efc_*`` to ``qdd`` (which holds ``q̈₀``);
    ``factor``: ``H``'s LTDL factor (``dynamics.ltdl_factor``). The rows' forces stay in ``w.efc_work``."""
    if count == 0:
        return
    e, y, z, nv = w.efc_work, w.efc_jac, w.efc_z, qdd.shape[0]
    inverse_pivots = w.efc_inverse_pivots
    for k in range(nv):
        inverse_pivots[k] = 1.0 / factor[k, k]
    for i in range(count):  # the offsets J q̈₀ - aref, then yᵢ = L⁻ᵀ Jᵢᵀ in place of Jᵢ, and the diagonal of A
        offset = 0.0
        for k in range(nv):
            offset += y[i, k] * qdd[k]
        lt_solve(m.dof_ints, factor, y[i])
        e[EFC_OFFSET, i] = offset - e[EFC_AREF, i]
        e[EFC_DIAG, i] = _weighted_dot(y, i, inverse_pivots, y[i])
        e[EFC_FORCE, i] = 0.0
    for k in range(nv):
        z[k] = 0.0
    for sweep in range(_MAX_SWEEPS):
        largest, change = 0.0, 0.0
        for i in range(count):
            old = e[EFC_FORCE, i]
            residual = e[EFC_OFFSET, i] + e[EFC_R, i] * old + _weighted_dot(y, i, inverse_pivots, z)
            new = min(max(old - residual / (e[EFC_DIAG, i] + e[EFC_R, i]), e[EFC_LOW, i]), e[EFC_HIGH, i])
            if new != old:
                e[EFC_FORCE, i] = new
                for k in range(nv):
                    z[k] += (new - old) * y[i, k]
            change = max(change, abs(new - old))
            largest = max(largest, abs(new))
        if change <= _TOLERANCE * largest:
            break
        if sweep % _PIVOT_EVERY == _PIVOT_EVERY - 1:
            if _pivot(w, count, inverse_pivots, factor):
                break
            _gather(y, e, EFC_FORCE, count, z)  # the pivoting used z: the sweeps' own, again
    dl_solve(m.dof_ints, factor, z)  # H⁻¹ Jᵀ f = L⁻¹ D⁻¹ z
    for k in range(nv):
        qdd[k] += z[k]
