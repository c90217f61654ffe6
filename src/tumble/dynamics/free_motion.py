"""One step of a free rigid body under a constant force and torque, for each integrator.

Newton–Euler in momentum form (course 001, "state vector (x, A, p, L)"; Baraff 2001, SIGGRAPH course
notes "Rigid Body Simulation I", section 2.9):

    ẋ = v,   q̇ = ½ (0, ω) ⊗ q,   m v̇ = F − c_lin m v,   L̇ = τ − c_ang L,   ω = R I⁻¹ Rᵀ L.

Each function takes one body's state ``(x, q, v, L)`` as tuples and returns it after one step ``h``. The
state carries the angular momentum ``L`` (world frame, about the COM) rather than ``ω``: with no torque the
momentum integrators (euler, rk4, midpoint) then keep it exactly constant, which converting ``ω → L → ω``
every step would not do (measured: 1e-11 relative drift over 20 000 steps from the round-off of ``I I⁻¹``).

- ``euler_step``: explicit Euler exactly as the course (course 003, "Euler Time Integration Algorithm for
  rigid bodies"): ``x += h v``, orientation from the *old* ω, then ``p += h F``, ``L += h τ``. First order;
  gains energy on a tumbling body. For teaching.
- ``symplectic_step``: semi-implicit Euler. Velocities first, then positions from the new velocities. The
  gyroscopic term ``ω × Iω`` is taken implicitly in body coordinates with one Newton step (E. Catto,
  "Numerical Methods", GDC 2015), which keeps a fast-spinning body from gaining energy. First order; it
  dissipates the energy of a tumbling body and turns its ``L`` slightly (1 % over 20 s at dt = 1e-3 for
  the Dzhanibekov body), the price of never blowing up.
- ``rk4_step``: classical Runge–Kutta on ``(x, q, v, L)``; ``L`` is integrated directly, so a body with no
  torque keeps ``L`` exactly; the quaternion is renormalised once at the end. Fourth order.
- ``flight_step``: the exact motion of a body whose loads give a closed form: a constant force, no torque, no
  damping, and a spin that stays constant (``ω = I⁻¹ L`` with an isotropic ``I``, or no spin). The parabola
  ``x + h (v + ½ h F/m)`` and the turn ``exp(½ h ω) ⊗ q``, both exact; ``"auto"`` takes it for such bodies and
  RK4 for the others.
- ``midpoint_step``: the implicit midpoint rule on the body-frame momentum ``Π = Rᵀ L`` (a Lie–Poisson
  integrator) with the Cayley map for the orientation, inside a Strang splitting of the force and torque
  kicks. ``Π' = Π + h Π_m × I⁻¹Π_m`` is exactly ``Π' = cay(−h Ω̂_m) Π``, so with ``R' = R cay(h Ω̂_m)`` the
  world ``L = R Π`` is unchanged and the energy ``½ Π·I⁻¹Π`` too: both quadratic invariants are conserved
  to round-off, for ever, at second order in the trajectory (Austin, Krishnaprasad & Wang 1993, "Almost
  Poisson integration of rigid body systems", J. Comput. Phys. 107; Hairer, Lubich & Wanner, "Geometric
  Numerical Integration", 2nd ed., sections IV.1 and VII.5).

Each step also takes the loads of the body's actuators and drag (``actuation.py``) from the state at each of its
stages and the time ``tau`` of the step's start within the call: at the start (Euler, semi-implicit Euler), at
each stage (RK4), before and after the free flight (midpoint). They are zero for a body without any.

Damping ``c`` is linear drag: implicit ``v / (1 + h c)`` (from ``exp(−c h)`` to first order) in the Euler
schemes, exact-to-fourth-order inside RK4.
"""

from __future__ import annotations

import math

from .._jit import inline
from ..math3d import (
    add,
    add_scaled,
    cross,
    dot,
    mat_vec,
    quat_add_scaled,
    quat_derivative,
    quat_exp,
    quat_integrate,
    quat_mul,
    quat_normalize,
    quat_rotate,
    quat_rotate_inv,
    scale,
    solve33,
    sub,
    world_inertia_apply,
)
from .actuation import actuator_wrench


@inline
def euler_step(x, q, v, angmom, inv_m, inertia, inv_inertia, force, torque, c_lin, c_ang, h, acts, i, tau):
    """Explicit Euler (course 003): positions from the old velocities, then momenta."""
    w = world_inertia_apply(q, inv_inertia, angmom)
    force, torque = _with_actuators(force, torque, acts, i, tau, q, v, w)
    x_new = add_scaled(x, v, h)
    q_new = quat_integrate(q, w, h)
    v_new = scale(add_scaled(v, force, h * inv_m), 1.0 / (1.0 + h * c_lin))
    l_new = scale(add_scaled(angmom, torque, h), 1.0 / (1.0 + h * c_ang))
    return x_new, q_new, v_new, l_new


@inline
def _skew_mul(a, m):
    """``skew(a) @ M`` for a row-major 9-tuple ``M`` (``skew(a) b = a × b``)."""
    return (
        a[1] * m[6] - a[2] * m[3], a[1] * m[7] - a[2] * m[4], a[1] * m[8] - a[2] * m[5],
        a[2] * m[0] - a[0] * m[6], a[2] * m[1] - a[0] * m[7], a[2] * m[2] - a[0] * m[8],
        a[0] * m[3] - a[1] * m[0], a[0] * m[4] - a[1] * m[1], a[0] * m[5] - a[1] * m[2],
    )  # fmt: skip


@inline
def _gyroscopic_jacobian(inertia, w, iw, h):
    """``J = I + h (skew(ω) I − skew(I ω))``, the derivative of ``I(ω'−ω) + h ω'×Iω'`` at ``ω`` (``iw = I ω``)."""
    a = _skew_mul(w, inertia)
    s = (0.0, -iw[2], iw[1], iw[2], 0.0, -iw[0], -iw[1], iw[0], 0.0)
    return (
        inertia[0] + h * (a[0] - s[0]), inertia[1] + h * (a[1] - s[1]), inertia[2] + h * (a[2] - s[2]),
        inertia[3] + h * (a[3] - s[3]), inertia[4] + h * (a[4] - s[4]), inertia[5] + h * (a[5] - s[5]),
        inertia[6] + h * (a[6] - s[6]), inertia[7] + h * (a[7] - s[7]), inertia[8] + h * (a[8] - s[8]),
    )  # fmt: skip


@inline
def implicit_spin(q, w_body, inertia, torque, c_ang, h):
    """Body-frame ω after one step of ``I(ω'−ω)/h + ω'×Iω' = Rᵀτ`` (one Newton step from ω), damped.

    Shared by the free-motion ``symplectic_step`` and the contact solver's velocity integration.
    """
    tau_body = quat_rotate_inv(q, torque)
    iw = mat_vec(inertia, w_body)
    residual = scale(sub(cross(w_body, iw), tau_body), h)
    w_new = sub(w_body, solve33(_gyroscopic_jacobian(inertia, w_body, iw, h), residual))
    # Dotted with ω', the exact solution's equation says ω'·Iω' = ω'·(Iω + h τ): the gyroscopic term does no work,
    # and without torque the energy cannot rise (Cauchy–Schwarz in the I inner product). The one Newton step misses
    # it by its residual and gained 7e-9 of the energy in a step of a thin box; scaling ω' by the s that restores
    # the identity keeps the energy balance of the exact step (s = 1 + O(residual)).
    norm = dot(w_new, mat_vec(inertia, w_new))
    s = dot(w_new, add_scaled(iw, tau_body, h)) / norm if norm > 0.0 else 1.0
    if not math.isfinite(s):
        s = 1.0
    return scale(w_new, s / (1.0 + h * c_ang))


@inline
def symplectic_step(x, q, v, angmom, inv_m, inertia, inv_inertia, force, torque, c_lin, c_ang, h, acts, i, tau):
    """Semi-implicit Euler; body-frame ``I(ω'−ω)/h + ω'×Iω' = τ`` solved by one Newton step from ``ω``."""
    force, torque = _with_actuators(force, torque, acts, i, tau, q, v, world_inertia_apply(q, inv_inertia, angmom))
    v_new = scale(add_scaled(v, force, h * inv_m), 1.0 / (1.0 + h * c_lin))
    w_body = implicit_spin(q, mat_vec(inv_inertia, quat_rotate_inv(q, angmom)), inertia, torque, c_ang, h)
    x_new = add_scaled(x, v_new, h)
    q_new = quat_integrate(q, quat_rotate(q, w_body), h)
    # The new spin in the body frame is carried by the new orientation: L' = R' I ω'_body.
    l_new = quat_rotate(q_new, mat_vec(inertia, w_body))
    return x_new, q_new, v_new, l_new


@inline
def _angvel_from_momentum(q, inv_inertia, angmom):
    """``ω = R I⁻¹ Rᵀ L`` with ``R`` from the normalised ``q`` (RK4 stages leave the unit sphere)."""
    return world_inertia_apply(quat_normalize(q), inv_inertia, angmom)


@inline
def _with_actuators(force, torque, acts, i, tau, q, v, w):
    """The constant loads plus the actuators' and drag's at this state and time (``q`` need not be normalised).
    ``acts`` is ``None`` for a body without any: Numba then compiles this to nothing (a branch on ``None`` is
    pruned at compile time), so free bodies run as fast as before actuators existed."""
    if acts is None:
        return force, torque
    f, t = actuator_wrench(acts, i, tau, quat_normalize(q), v, w)
    return add(force, f), add(torque, t)


@inline
def _rk4_rates(q, v, angmom, inv_m, inv_inertia, force, torque, c_lin, c_ang, acts, i, tau):
    """``(q̇, v̇, L̇)`` of one RK4 stage."""
    w = _angvel_from_momentum(q, inv_inertia, angmom)
    force, torque = _with_actuators(force, torque, acts, i, tau, q, v, w)
    return quat_derivative(q, w), add_scaled(scale(force, inv_m), v, -c_lin), add_scaled(torque, angmom, -c_ang)


@inline
def rk4_step(x, q, v, angmom, inv_m, inertia, inv_inertia, force, torque, c_lin, c_ang, h, acts, i, tau):
    """Classical RK4 on ``(x, q, v, L)`` with constant ``F`` and ``τ`` plus the actuators' at each stage."""
    half = 0.5 * h
    # Stage 1 at (x, q, v, L); ẋ = v, q̇ = ½ ω ⊗ q, v̇ = F/m − c v, L̇ = τ − c L.
    q1, v1, l1 = q, v, angmom
    dq1, dv1, dl1 = _rk4_rates(q1, v1, l1, inv_m, inv_inertia, force, torque, c_lin, c_ang, acts, i, tau)
    # Stage 2 at y + h/2 k1.
    q2, v2, l2 = quat_add_scaled(q, dq1, half), add_scaled(v, dv1, half), add_scaled(angmom, dl1, half)
    dq2, dv2, dl2 = _rk4_rates(q2, v2, l2, inv_m, inv_inertia, force, torque, c_lin, c_ang, acts, i, tau + half)
    # Stage 3 at y + h/2 k2.
    q3, v3, l3 = quat_add_scaled(q, dq2, half), add_scaled(v, dv2, half), add_scaled(angmom, dl2, half)
    dq3, dv3, dl3 = _rk4_rates(q3, v3, l3, inv_m, inv_inertia, force, torque, c_lin, c_ang, acts, i, tau + half)
    # Stage 4 at y + h k3.
    q4, v4, l4 = quat_add_scaled(q, dq3, h), add_scaled(v, dv3, h), add_scaled(angmom, dl3, h)
    dq4, dv4, dl4 = _rk4_rates(q4, v4, l4, inv_m, inv_inertia, force, torque, c_lin, c_ang, acts, i, tau + h)
    # Combine: y + h/6 (k1 + 2 k2 + 2 k3 + k4); ẋ's stages are the v's.
    sixth = h / 6.0
    x_new = add_scaled(x, add(add(v1, v4), scale(add(v2, v3), 2.0)), sixth)
    v_new = add_scaled(v, add(add(dv1, dv4), scale(add(dv2, dv3), 2.0)), sixth)
    l_new = add_scaled(angmom, add(add(dl1, dl4), scale(add(dl2, dl3), 2.0)), sixth)
    dq = (
        dq1[0] + 2.0 * dq2[0] + 2.0 * dq3[0] + dq4[0],
        dq1[1] + 2.0 * dq2[1] + 2.0 * dq3[1] + dq4[1],
        dq1[2] + 2.0 * dq2[2] + 2.0 * dq3[2] + dq4[2],
        dq1[3] + 2.0 * dq2[3] + 2.0 * dq3[3] + dq4[3],
    )
    q_new = quat_normalize(quat_add_scaled(q, dq, sixth))
    return x_new, q_new, v_new, l_new


@inline
def flies_freely(torque, c_lin, c_ang, inv_inertia, angmom):
    """Whether :func:`flight_step` is exact for this body: no torque, no damping, and ``ω = I⁻¹ L`` constant,
    which holds when ``I`` is isotropic (sphere, cube) or the body does not spin (``L = 0`` stays 0)."""
    if torque[0] != 0.0 or torque[1] != 0.0 or torque[2] != 0.0 or c_lin != 0.0 or c_ang != 0.0:
        return False
    if angmom[0] == 0.0 and angmom[1] == 0.0 and angmom[2] == 0.0:
        return True
    m = inv_inertia
    off_diagonal = abs(m[1]) + abs(m[2]) + abs(m[3]) + abs(m[5]) + abs(m[6]) + abs(m[7])
    return off_diagonal == 0.0 and m[0] == m[4] and m[4] == m[8]


@inline
def flight_step(x, q, v, angmom, inv_m, force, turn, h):
    """The exact step of a body for which :func:`flies_freely` holds, ``turn`` being ``exp(½ h ω)``: the parabola
    under the constant force, and ``q̇ = ½ ω ⊗ q`` solved in closed form, ``q(t + h) = exp(½ h ω) ⊗ q(t)``.
    ``L`` does not change; a body that does not spin keeps its ``q`` bit for bit."""
    a = scale(force, inv_m)
    x_new = add_scaled(x, add_scaled(v, a, 0.5 * h), h)  # not h² a / 2: h² alone may overflow
    v_new = add_scaled(v, a, h)
    q_new = q
    if angmom[0] != 0.0 or angmom[1] != 0.0 or angmom[2] != 0.0:
        q_new = quat_normalize(quat_mul(turn, q))
    return x_new, q_new, v_new, angmom


@inline
def spin_turn(inv_inertia, angmom, h):
    """``exp(½ h ω)`` for the constant spin ``ω = I⁻¹ L`` of an isotropic body (one step's turn)."""
    return quat_exp(scale(angmom, inv_inertia[0]), h)


@inline
def _midpoint_momentum(pi, inertia_inv, h):
    """Solve ``Π_m = Π + (h/2) Π_m × I⁻¹Π_m`` by Newton's method (quadratic; 3 to 4 iterations at h|ω| ~ 1e-2).

    Jacobian of the residual ``g(Π_m) = Π_m − Π − (h/2) Π_m × I⁻¹Π_m``:
    ``E − (h/2) (skew(Π_m) I⁻¹ − skew(I⁻¹Π_m))``.
    """
    pm = pi
    for _ in range(30):
        w = mat_vec(inertia_inv, pm)
        g = sub(sub(pm, pi), scale(cross(pm, w), 0.5 * h))
        a = _skew_mul(pm, inertia_inv)
        k = -0.5 * h
        jac = (
            1.0 + k * a[0], k * (a[1] + w[2]), k * (a[2] - w[1]),
            k * (a[3] - w[2]), 1.0 + k * a[4], k * (a[5] + w[0]),
            k * (a[6] + w[1]), k * (a[7] - w[0]), 1.0 + k * a[8],
        )  # fmt: skip
        step = solve33(jac, g)
        pm = sub(pm, step)
        if abs(step[0]) + abs(step[1]) + abs(step[2]) <= 1e-16 * (abs(pm[0]) + abs(pm[1]) + abs(pm[2])):
            break
    return pm


@inline
def midpoint_step(x, q, v, angmom, inv_m, inertia, inv_inertia, force, torque, c_lin, c_ang, h, acts, i, tau):
    """Strang splitting: half kick, free flight (exact translation, Lie–Poisson midpoint rotation), half kick."""
    half = 0.5 * h
    # Half kick: v += h/2 (a − c v), L += h/2 (τ − c L), the damping implicit.
    f0, t0 = _with_actuators(force, torque, acts, i, tau, q, v, world_inertia_apply(q, inv_inertia, angmom))
    v_half = scale(add_scaled(v, f0, half * inv_m), 1.0 / (1.0 + half * c_lin))
    l_half = scale(add_scaled(angmom, t0, half), 1.0 / (1.0 + half * c_ang))
    # Free flight: straight line; rotation by the Cayley map of h Ω_m in the body frame, L unchanged.
    x_new = add_scaled(x, v_half, h)
    pm = _midpoint_momentum(quat_rotate_inv(q, l_half), inv_inertia, h)
    w = mat_vec(inv_inertia, pm)
    # cay(h Ω̂) is the rotation of the quaternion (1, h Ω / 2), normalised (tan(θ/2) = h|Ω|/2).
    q_new = quat_normalize(quat_mul(q, (1.0, half * w[0], half * w[1], half * w[2])))
    # Second half kick, with the actuators' loads after the flight.
    f1, t1 = _with_actuators(force, torque, acts, i, tau + h, q_new, v_half,
                             world_inertia_apply(q_new, inv_inertia, l_half))  # fmt: skip
    v_new = scale(add_scaled(v_half, f1, half * inv_m), 1.0 / (1.0 + half * c_lin))
    l_new = scale(add_scaled(l_half, t1, half), 1.0 / (1.0 + half * c_ang))
    return x_new, q_new, v_new, l_new
