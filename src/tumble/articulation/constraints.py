"""Joint and tendon physics beyond the tree: actuators, tendon springs, and MuJoCo's soft limits and dry friction.

A *scalar* is a linear function of the coordinates: a hinge's or slide's coordinate, or a fixed tendon's length
``L = Σ cᵢ qᵢ`` (MuJoCo's ``<fixed>`` tendon), with the velocity ``L̇ = J q̇`` (``model.scalar_q``, ``scalar_v``).
Actuators pull along scalars, tendons carry springs and dampers, and limits and dry friction hold them.

Actuators and springs are forces (:func:`applied_forces`). Limits and friction are constraints, solved as MuJoCo
solves them (MuJoCo documentation, *Computation*: "Soft constraints" and "Solver parameters"). Each active row
``i`` (a limit whose distance ``r`` is below its margin, or a scalar with frictionloss) has the Jacobian ``Jᵢ``, the
impedance ``d(r)`` of its ``solimp``, the stiffness and damping ``k = 1/(d_max² τ² ζ²)``, ``b = 2/(d_max τ)`` of its
``solref = (τ, ζ)`` (or ``k = -solref₀/d_max²``, ``b = -solref₁/d_max`` when negative), the reference acceleration
``aref = -b J q̇ - k d (r - margin)`` (``k = 0`` for friction) and the regulariser ``R = (1 - d)/d · invweight0``.
The constraint forces solve MuJoCo's dual problem with them (``dual_solver.py``): limits push only (``f ≥ 0``), dry
friction is boxed (``|f| ≤ frictionloss``). ``τ`` is at least twice the step, as MuJoCo keeps it
(``mjDSBL_REFSAFE`` off).
"""

from __future__ import annotations

import math

from .._jit import inline
from .model import (
    APPLIED,
    BIAS_LENGTH,
    BIAS_SPEED,
    EFC_AREF,
    EFC_FORCE,
    EFC_HIGH,
    EFC_LOW,
    EFC_R,
    EFC_SCALAR,
    FORCE0,
    FORCE_HIGH,
    FORCE_LOW,
    FRICTION_SOLIMP,
    FRICTION_SOLREF,
    FRICTIONLOSS,
    GEAR,
    INVWEIGHT,
    JOINT_Q,
    JOINT_V,
    LIMIT_SOLIMP,
    LIMIT_SOLREF,
    LIMITED,
    LOWER,
    MARGIN,
    TENDON_DAMPING,
    TENDON_SPRINGLENGTH,
    TENDON_STIFFNESS,
    UPPER,
)

__all__ = ["applied_forces", "constrained", "impedance", "scalar_rows", "scalar_value", "soft_row"]

# MuJoCo's mjMINVAL: the smallest regulariser
_MIN_VALUE = 1e-15


@inline
def scalar_value(coefficients, s, x):
    """``Σ_j coefficients[s, j] x[j]``: a scalar's length (``scalar_q`` and ``q``) or rate (``scalar_v``, ``q̇``)."""
    total = 0.0
    for j in range(x.shape[0]):
        total += coefficients[s, j] * x[j]
    return total


@inline
def scalar_length(m, s, q):
    """Scalar ``s``'s length: its joint's coordinate, or the tendon's ``Σ cᵢ qᵢ``."""
    row = int(m.scalar_reals[s, JOINT_Q])
    return q[row] if row >= 0 else scalar_value(m.scalar_q, s, q)


@inline
def scalar_rate(m, s, qd):
    """Scalar ``s``'s rate ``J q̇``."""
    row = int(m.scalar_reals[s, JOINT_V])
    return qd[row] if row >= 0 else scalar_value(m.scalar_v, s, qd)


@inline(into_callers=True)
def constrained(m):
    """Whether any scalar has a limit or dry friction, or geoms may touch (the model then solves constraints at
    every evaluation)."""
    if m.pair_ints.shape[0] > 0:
        return True
    for s in range(m.scalar_reals.shape[0]):
        if m.scalar_reals[s, LIMITED] != 0.0 or m.scalar_reals[s, FRICTIONLOSS] > 0.0:
            return True
    return False


@inline(into_callers=True)
def applied_forces(m, w, q, qd, tau):
    """The joint forces with the actuators' and the tendons' springs and dampers added: ``tau`` itself when the
    model has neither, else ``w.dof_work[APPLIED]``."""
    if m.act_ints.shape[0] == 0 and m.scalar_reals.shape[0] == 0:
        return tau
    out = w.dof_work[APPLIED]
    _add_drives(m, q, qd, tau, out)
    return out


@inline(counted=False)
def _add_drives(m, q, qd, tau, out):
    """``out = tau`` plus the actuators' and tendons' forces."""
    scalar_reals, act_reals = m.scalar_reals, m.act_reals
    for k in range(tau.shape[0]):
        out[k] = tau[k]
    for s in range(scalar_reals.shape[0]):
        stiffness, damping = scalar_reals[s, TENDON_STIFFNESS], scalar_reals[s, TENDON_DAMPING]
        if stiffness == 0.0 and damping == 0.0:
            continue
        force = -damping * scalar_rate(m, s, qd)
        if stiffness != 0.0:
            force -= stiffness * (scalar_length(m, s, q) - scalar_reals[s, TENDON_SPRINGLENGTH])
        for k in range(out.shape[0]):
            out[k] += force * m.scalar_v[s, k]
    for a in range(act_reals.shape[0]):
        s, gear = m.act_ints[a, 0], act_reals[a, GEAR]
        length, speed = gear * scalar_length(m, s, q), gear * scalar_rate(m, s, qd)
        force = act_reals[a, FORCE0] + act_reals[a, BIAS_LENGTH] * length + act_reals[a, BIAS_SPEED] * speed
        force = min(max(force, act_reals[a, FORCE_LOW]), act_reals[a, FORCE_HIGH])
        joint = int(scalar_reals[s, JOINT_V])
        if joint >= 0:
            out[joint] += gear * force
            continue
        for k in range(out.shape[0]):
            out[k] += gear * force * m.scalar_v[s, k]


@inline
def impedance(row, c, distance):
    """MuJoCo's impedance ``d`` of the solimp ``row[c:c + 5] = (d_min, d_max, width, midpoint, power)`` at
    ``distance`` (the violation less the margin): ``d_min`` at 0 rising to ``d_max`` at ``width`` along two
    power curves that meet at ``midpoint`` (MuJoCo documentation, *Modeling*: "Solver parameters")."""
    low, high, width, middle, power = row[c], row[c + 1], row[c + 2], row[c + 3], row[c + 4]
    if low == high or width <= _MIN_VALUE:
        return 0.5 * (low + high)
    x = abs(distance) / width
    if x >= 1.0:
        return high
    if x <= 0.0:
        return low
    if power == 1.0:
        y = x
    elif power == 2.0:  # MuJoCo's default, without pow (the same roundings)
        y = x * x / middle if x <= middle else 1.0 - (1.0 - x) * (1.0 - x) / (1.0 - middle)
    elif x <= middle:
        y = x**power / middle ** (power - 1.0)
    else:
        y = 1.0 - (1.0 - x) ** power / (1.0 - middle) ** (power - 1.0)
    return low + y * (high - low)


@inline
def soft_row(w, count, tag, distance, margin, refs, imps, weight, low, high, h, qd):
    """Fill constraint row ``count`` (its Jacobian already in ``w.efc_jac[count]``): MuJoCo's reference acceleration and
    regulariser for the violation ``distance`` less ``margin`` (zero for dry friction, which has no position term),
    the solref ``refs[0:2]`` and solimp ``imps[0:5]``, ``weight`` its ``diagApprox``, and the force's bounds. ``tag``:
    the scalar, or -1 - the contact. Returns ``count + 1``."""
    imp = impedance(imps, 0, distance - margin)
    time_constant, damping_ratio, d_max = refs[0], refs[1], imps[1]
    if time_constant > 0.0:
        time_constant = max(time_constant, 2.0 * h)
        stiffness = 1.0 / (d_max * d_max * time_constant * time_constant * damping_ratio * damping_ratio)
        damping = 2.0 / (d_max * time_constant)
    else:
        stiffness, damping = -time_constant / (d_max * d_max), -damping_ratio / d_max
    if low < 0.0:  # dry friction: no position term
        stiffness = 0.0
    e, jac = w.efc_work, w.efc_jac
    velocity = 0.0
    for k in range(qd.shape[0]):
        velocity += jac[count, k] * qd[k]
    e[EFC_SCALAR, count] = tag
    e[EFC_AREF, count] = -damping * velocity - stiffness * imp * (distance - margin)
    e[EFC_R, count] = max(_MIN_VALUE, (1.0 - imp) / imp * weight)
    e[EFC_LOW, count], e[EFC_HIGH, count] = low, high
    e[EFC_FORCE, count] = 0.0
    return count + 1


@inline
def _scalar_row(m, w, count, s, sign, distance, kind, low, high, h, qd):
    """A row of scalar ``s``: its Jacobian ``sign · scalar_v[s]``, the limit's (``kind`` LIMIT_SOLREF) or the dry
    friction's settings."""
    row = m.scalar_reals[s]
    for k in range(qd.shape[0]):
        w.efc_jac[count, k] = sign * m.scalar_v[s, k]
    imps = row[LIMIT_SOLIMP : LIMIT_SOLIMP + 5] if kind == LIMIT_SOLREF else row[FRICTION_SOLIMP : FRICTION_SOLIMP + 5]
    margin = row[MARGIN] if kind == LIMIT_SOLREF else 0.0
    return soft_row(w, count, s, distance, margin, row[kind : kind + 2], imps, row[INVWEIGHT], low, high, h, qd)


@inline(counted=False)
def scalar_rows(m, w, q, qd, h):
    """The active rows of the scalars' limits and dry friction into ``w.efc_*``; returns their count."""
    scalar_reals = m.scalar_reals
    count = 0
    for s in range(scalar_reals.shape[0]):
        row = scalar_reals[s]
        loss = row[FRICTIONLOSS]
        if loss > 0.0:
            count = _scalar_row(m, w, count, s, 1.0, 0.0, FRICTION_SOLREF, -loss, loss, h, qd)
        if row[LIMITED] != 0.0:
            length, margin = scalar_length(m, s, q), row[MARGIN]
            if length - row[LOWER] < margin:
                count = _scalar_row(m, w, count, s, 1.0, length - row[LOWER], LIMIT_SOLREF, 0.0, math.inf, h, qd)
            if row[UPPER] - length < margin:
                count = _scalar_row(m, w, count, s, -1.0, row[UPPER] - length, LIMIT_SOLREF, 0.0, math.inf, h, qd)
    return count
