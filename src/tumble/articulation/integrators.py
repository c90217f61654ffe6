"""One time step of an articulation: explicit Euler, semi-implicit (symplectic) Euler, or RK4.

Every scheme evaluates ``q̈ = FD(q, q̇, τ)`` (with loop closures, ``loops.py``) and advances the coordinates
on the configuration manifold with :func:`~.kinematics.integrate_configuration`, so quaternions stay unit.

* ``euler``: ``q ← q ⊕ h q̇₀``, ``q̇ ← q̇₀ + h q̈₀`` (first order; drifts in energy, for teaching).
* ``symplectic``: ``q̇ ← q̇₀ + h q̈₀`` then ``q ← q ⊕ h q̇`` (first order, bounded energy error).
* ``symplectic_implicit_damping``: MuJoCo's Euler integrator. ``symplectic``, with the joints' damping ``B``
  implicit in the velocity update: ``q̈ ← (H + h B)⁻¹ H q̈₀`` before the step (MuJoCo documentation, *Computation*:
  "Numerical integration"), so a stiff damper stays stable at a long step.
* ``rk4``: the classical four stages in the Runge–Kutta–Munthe-Kaas form (Munthe-Kaas, "High order
  Runge-Kutta methods on manifolds", 1999): each stage's coordinates are ``q₀ ⊕ θ`` with ``θ`` in the tangent
  space at ``q₀``, and a stage velocity ``ω`` enters as ``dexp⁻¹_θ(ω) ≈ ω + ½ θ × ω + θ × (θ × ω)/12`` for the
  rotation of a ball or free joint (identity for the other coordinates). Without that correction the
  scheme is only second order for rotations; with it, it is fourth order and agrees with MuJoCo's RK4 to
  rounding.

Each evaluation adds the actuators' and tendons' forces to the joint forces and, where the model has limits or dry
friction, solves them (``constraints.py``) at that stage's state, as MuJoCo's RK4 does. After the step, loop closures
are projected back onto their manifold, and a non-finite result is rolled back (``q``, ``q̇`` keep their values from
before the step).
"""

from __future__ import annotations

import math

from .._jit import inline
from ..math3d import add, add_scaled, cross, scale
from .aba import aba
from .constraints import applied_forces, constrained, scalar_rows
from .contacts import contact_rows, find_contacts
from .dual_solver import solve_constraints
from .dynamics import crba, ltdl_factor, ltdl_solve, rnea
from .joints import JointType
from .kinematics import forward_kinematics, integrate_configuration
from .loops import loop_jacobian, project_loop_closures, solve_loop_closures
from .model import (
    BIAS,
    CHART,
    DAMPING,
    DIAG,
    JOINT,
    Q_START,
    QD_STAGE,
    QD_START,
    QD_SUM,
    QDD,
    QDD_SUM,
    RHS,
    V_START,
)
from .spatial import assign, fill, fill_matrix, vec3

__all__ = ["DAMPED", "EULER", "NOT_FINITE", "OK", "RK4", "SINGULAR", "SYMPLECTIC", "accelerations", "rk4_stage", "step"]

EULER, SYMPLECTIC, RK4, DAMPED = 0, 1, 2, 3
OK, SINGULAR, NOT_FINITE = 0, 1, 2
_BALL = int(JointType.BALL)
_FREE = int(JointType.FREE)


@inline(counted=False)
def accelerations(m, w, q, qd, tau, external, use_external, step_size):
    """``q̈`` into ``w.dof_work[QDD]`` for the state ``(q, qd)`` under joint forces ``tau`` (nv,).

    A tree without limits or dry friction takes the articulated-body algorithm (``aba.py``, O(n)). Otherwise: bias
    forces by RNEA, ``H`` by CRBA, its LTDL factor (left in ``w.mass_matrix`` for the projection), the solve, then
    the constraints (``constraints.py``, whose time constants are kept above twice ``step_size``; 0 for a query)
    and the loop-closure correction (``loops.py``). Returns -1, or the row of a singular pivot.
    """
    link_ints, world, dof_params = m.link_ints, m.world, m.dof_params
    link_work, dof_motion, dof_work, h = w.link_work, w.dof_motion, w.dof_work, w.mass_matrix
    forward_kinematics(link_ints, m.link_reals, world, q, qd, link_work, dof_motion)
    tau = applied_forces(m, w, q, qd, tau)
    limited = constrained(m)
    if m.loop_ints.shape[0] == 0 and not limited:
        return aba(link_ints, world, dof_params, link_work, dof_motion, w.dof_u, dof_work[DIAG], q, qd, tau,
                   external, use_external, dof_work[QDD])  # fmt: skip
    at_rest = dof_work[RHS]  # the bias forces are the joint forces at q̈ = 0
    fill(at_rest, 0.0)
    rnea(link_ints, world, dof_params, link_work, dof_motion, q, qd, at_rest, external, use_external, dof_work[BIAS])
    crba(link_ints, m.dof_ints, dof_params, link_work, dof_motion, h)
    bad = ltdl_factor(m.dof_ints, h, dof_work[DIAG])
    if bad >= 0:
        return bad
    qdd, bias = dof_work[QDD], dof_work[BIAS]
    for k in range(qdd.shape[0]):
        qdd[k] = tau[k] - bias[k]
    ltdl_solve(m.dof_ints, h, qdd)
    if limited:
        count = scalar_rows(m, w, q, qd, step_size)
        if m.pair_ints.shape[0] > 0:
            count = contact_rows(m, w, find_contacts(m, w), count, qd, step_size)
        solve_constraints(m, w, count, h, qdd)
        w.efc_count[0] = count
    if m.loop_ints.shape[0] > 0:
        loop_jacobian(link_ints, m.dof_ints, m.loop_ints, m.loop_reals, link_work, dof_motion, w.loop_jac,
                      w.loop_work)  # fmt: skip
        solve_loop_closures(m.dof_ints, h, w.loop_jac, w.loop_minv_jt, w.loop_matrix, w.loop_work, qdd)
    return -1


@inline
def _dexp_inverse(theta, w):
    """``dexp⁻¹_θ(ω) ≈ ω + ½ θ × ω + θ × (θ × ω) / 12``: the rate of the chart coordinate ``θ`` of
    ``q₀ ⊗ exp(θ)`` for the body angular velocity ``ω`` (right trivialisation, Iserles et al. 2000, §2.3)."""
    half = cross(theta, w)
    return add(add_scaled(w, half, 0.5), scale(cross(theta, half), 1.0 / 12.0))


@inline(counted=False)
def _chart_rates(link_ints, v, weight, reach, chart, rate_sum):
    """One RK4 stage in the chart at ``q₀``: its rate ``k = dexp⁻¹_θ(v)`` (``θ = chart``) is added with
    ``weight`` to ``rate_sum``, and the chart point of the next stage, ``reach k``, replaces ``θ``."""
    nv = v.shape[0]
    n = link_ints.shape[0]
    for i in range(n):
        kind, first = link_ints[i, JOINT], link_ints[i, V_START]
        stop = link_ints[i + 1, V_START] if i + 1 < n else nv
        rotation = first + 3 if kind == _FREE else (first if kind == _BALL else stop)
        for k in range(first, rotation):
            rate_sum[k] += weight * v[k]
            chart[k] = reach * v[k]
        if rotation < stop:
            rate = _dexp_inverse(vec3(chart, rotation), vec3(v, rotation))
            for k in range(3):
                rate_sum[rotation + k] += weight * rate[k]
                chart[rotation + k] = reach * rate[k]


@inline(into_callers=True)
def rk4_stage(stage, h):
    """``(weight, reach)`` of RK4 stage ``stage`` (0 to 3): the stage weights 1, 2, 2, 1; the next stage is reached
    from the start, ``h/2``, ``h/2`` then ``h`` along."""
    return (1.0 if stage == 0 or stage == 3 else 2.0), (0.5 * h if stage < 2 else h)


@inline
def _implicit_damping(m, w, qdd, h):
    """``q̈ ← (H + h B)⁻¹ H q̈`` with ``B`` the joints' damping (MuJoCo's ``mj_Euler``; nothing without damping).
    ``H`` is made again by the CRBA (the kinematics are those of the evaluation) into ``w.mass_matrix``, where the
    factor of ``H + h B`` is left. Returns -1 or the row of a singular pivot."""
    dof_params, damped = m.dof_params, False
    for k in range(qdd.shape[0]):
        damped = damped or dof_params[k, DAMPING] > 0.0
    if not damped:
        return -1
    matrix, product = w.mass_matrix, w.dof_work[RHS]
    fill_matrix(matrix, 0.0)
    crba(m.link_ints, m.dof_ints, dof_params, w.link_work, w.dof_motion, matrix)
    nv = qdd.shape[0]
    for j in range(nv):
        total = 0.0
        for k in range(nv):
            total += matrix[j, k] * qdd[k]
        product[j] = total
    for k in range(nv):
        matrix[k, k] += h * dof_params[k, DAMPING]
    bad = ltdl_factor(m.dof_ints, matrix, w.dof_work[DIAG])
    if bad >= 0:
        return bad
    assign(qdd, product)
    ltdl_solve(m.dof_ints, matrix, qdd)
    return -1


@inline(counted=False)
def _first_bad_link(link_ints, q, qd):
    """The first link with a non-finite coordinate or velocity, or -1."""
    finite = True
    for k in range(q.shape[0]):
        finite = finite and math.isfinite(q[k])
    for k in range(qd.shape[0]):
        finite = finite and math.isfinite(qd[k])
    if finite:
        return -1
    n = link_ints.shape[0]
    for i in range(n):
        q_stop = link_ints[i + 1, Q_START] if i + 1 < n else q.shape[0]
        v_stop = link_ints[i + 1, V_START] if i + 1 < n else qd.shape[0]
        for k in range(link_ints[i, Q_START], q_stop):
            if not math.isfinite(q[k]):
                return i
        for k in range(link_ints[i, V_START], v_stop):
            if not math.isfinite(qd[k]):
                return i
    return -1


@inline(counted=False)
def step(m, w, q, qd, tau, external, use_external, h, method):
    """Advance ``q``, ``qd`` in place by ``h`` seconds. Returns ``(status, where)``.

    ``status``: ``OK``; ``SINGULAR`` (``where`` the degree of freedom of a zero pivot of ``H``); ``NOT_FINITE``
    (``where`` the first link with a non-finite value). On failure ``q`` and ``qd`` are unchanged.
    """
    dof_work, link_ints = w.dof_work, m.link_ints
    q_start, q_stage = w.q_start, w.q_stage
    qd_start, qd_stage, qdd = dof_work[QD_START], dof_work[QD_STAGE], dof_work[QDD]
    assign(q_start, q)
    assign(qd_start, qd)
    nv = qd.shape[0]
    # a tree's evaluation is called here directly, with the arrays it needs: passing the model and work
    # tuples through one more call per stage costs 10 % of a step of a 20-link chain
    tree = m.loop_ints.shape[0] == 0 and not constrained(m)
    link_reals, world, dof_params = m.link_reals, m.world, m.dof_params
    link_work, dof_motion, dof_u, pivots = w.link_work, w.dof_motion, w.dof_u, dof_work[DIAG]
    if method == RK4:
        qdd_sum, qd_sum, chart = dof_work[QDD_SUM], dof_work[QD_SUM], dof_work[CHART]
        assign(q_stage, q)
        assign(qd_stage, qd)
        fill(qdd_sum, 0.0)
        fill(qd_sum, 0.0)
        fill(chart, 0.0)
        for stage in range(4):
            if tree:
                forward_kinematics(link_ints, link_reals, world, q_stage, qd_stage, link_work, dof_motion)
                forces = applied_forces(m, w, q_stage, qd_stage, tau)
                bad = aba(link_ints, world, dof_params, link_work, dof_motion, dof_u, pivots, q_stage, qd_stage,
                          forces, external, use_external, qdd)  # fmt: skip
            else:
                bad = accelerations(m, w, q_stage, qd_stage, tau, external, use_external, h)
            if bad >= 0:
                assign(q, q_start)
                assign(qd, qd_start)
                # a stage that overflowed makes NaN pivots: report the link, not a singular matrix
                overflowed = _first_bad_link(link_ints, q_stage, qd_stage)
                return (NOT_FINITE, overflowed) if overflowed >= 0 else (SINGULAR, bad)
            weight, reach = rk4_stage(stage, h)
            _chart_rates(link_ints, qd_stage, weight, reach, chart, qd_sum)
            for k in range(nv):
                qdd_sum[k] += weight * qdd[k]
            if stage < 3:
                integrate_configuration(link_ints, q_start, chart, 1.0, q_stage)
                for k in range(nv):
                    qd_stage[k] = qd_start[k] + reach * qdd[k]
        for k in range(nv):
            qd_sum[k] /= 6.0
            qd[k] = qd_start[k] + (h / 6.0) * qdd_sum[k]
        integrate_configuration(link_ints, q_start, qd_sum, h, q)
    else:
        if tree:
            forward_kinematics(link_ints, link_reals, world, q, qd, link_work, dof_motion)
            forces = applied_forces(m, w, q, qd, tau)
            bad = aba(link_ints, world, dof_params, link_work, dof_motion, dof_u, pivots, q, qd, forces, external,
                      use_external, qdd)  # fmt: skip
        else:
            bad = accelerations(m, w, q, qd, tau, external, use_external, h)
        if bad < 0 and method == DAMPED:
            bad = _implicit_damping(m, w, qdd, h)
        if bad >= 0:
            return SINGULAR, bad
        for k in range(nv):
            qd[k] += h * qdd[k]
        integrate_configuration(link_ints, q_start, qd_start if method == EULER else qd, h, q)
    if m.loop_ints.shape[0] > 0:
        project_loop_closures(m, w, q, qd)
    bad = _first_bad_link(link_ints, q, qd)
    if bad >= 0:
        assign(q, q_start)
        assign(qd, qd_start)
        return NOT_FINITE, bad
    return OK, -1
