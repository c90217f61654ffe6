"""The compiled parts of flight control: the SE(3) law from the state arrays, the desired attitude and its error,
and the mixer's allocation under saturation (equations in ``tumble.control`` and ``tumble.vehicles``).

One controller call is one kernel call: a controller at every step of a 500 Hz world costs microseconds, not the
hundreds a NumPy version of the same 3-vector algebra takes.
"""

from __future__ import annotations

import math

from .. import elementary
from .._jit import inline, kernel
from ..math3d import add, add_scaled, cross, dot, load3, mat_vec, quat_rotate_inv, quat_to_mat33, scale, sub

__all__ = [
    "HOVER",
    "CIRCLE",
    "LISSAJOUS",
    "MINIMUM_SNAP",
    "allocate_speeds",
    "attitude_error",
    "desired_axes",
    "reference_derivatives",
    "se3_rotor_speeds",
]

# The kinds of reference (tumble.references), and what their ``params`` (11,) hold: [0:3] the hover position, the
# centre, or the first waypoint; circle: [3] radius, [4] frequency; Lissajous: [3:8] A, B, a, b, delta; minimum
# snap: [3:6] the last waypoint; [10] the yaw.
HOVER, CIRCLE, LISSAJOUS, MINIMUM_SNAP = 0, 1, 2, 3


@inline
def desired_axes(force, yaw):
    """The axes ``(b1d, b2d, b3d)`` of the attitude whose ``z`` is along ``force`` and whose heading is ``yaw``
    (Lee, Leok & McClamroch 2010, section IV): ``b3d = F/|F|``, ``b2d = b3d × (cos ψ, sin ψ, 0) / |…|``,
    ``b1d = b2d × b3d``. No force: ``b3d = z``; a horizontal force along the heading: ``b2d`` is the heading's
    left."""
    size = math.sqrt(dot(force, force))
    b3 = scale(force, 1.0 / size) if size > 0.0 else (0.0, 0.0, 1.0)
    b2 = cross(b3, (elementary.cos(yaw), elementary.sin(yaw), 0.0))
    b2_size = math.sqrt(dot(b2, b2))
    b2 = scale(b2, 1.0 / b2_size) if b2_size > 1e-9 else (-elementary.sin(yaw), elementary.cos(yaw), 0.0)
    return cross(b2, b3), b2, b3


@inline
def attitude_error(r, b1, b2, b3):
    """``e_R = ½ vee(R_dᵀ R − Rᵀ R_d)`` (Lee et al. 2010, eq. 10) for ``R`` (row-major 9-tuple) and ``R_d =
    [b1 b2 b3]``: with ``M = R_dᵀ R``, ``e_R = ½ (M21 − M12, M02 − M20, M10 − M01)``."""
    c0, c1, c2 = (r[0], r[3], r[6]), (r[1], r[4], r[7]), (r[2], r[5], r[8])
    return (
        0.5 * (dot(b3, c1) - dot(b2, c2)),
        0.5 * (dot(b1, c2) - dot(b3, c0)),
        0.5 * (dot(b2, c0) - dot(b1, c1)),
    )


@inline
def _largest_fraction(squared, change, low, high):
    """The largest ``s`` in [0, 1] with every ``low <= squared[i] + s change[i] <= high``."""
    fraction = 1.0
    for i in range(4):
        if change[i] > 0.0 and squared[i] + change[i] > high:
            fraction = min(fraction, (high - squared[i]) / change[i])
        elif change[i] < 0.0 and squared[i] + change[i] < low:
            fraction = min(fraction, (low - squared[i]) / change[i])
    return max(fraction, 0.0)


@kernel
def allocate_speeds(inverse, k_thrust, low, high, thrust, moments, out):
    """Rotor speeds into ``out`` (4,) for the collective ``thrust`` and body ``moments`` (3-tuple or array), the
    mixer's ``inverse`` (4, 4) mapping ``(T, M)`` to ``ω²``, each ``ω²`` within ``[low, high]``: the thrust first
    (clipped), then roll and pitch together (scaled down as one), then yaw; what is kept is met exactly."""
    per_rotor = min(max(thrust / (4.0 * k_thrust), low), high)
    squared = [per_rotor, per_rotor, per_rotor, per_rotor]
    for stage in range(2):
        change = [0.0, 0.0, 0.0, 0.0]
        for i in range(4):
            if stage == 0:
                change[i] = inverse[i, 1] * moments[0] + inverse[i, 2] * moments[1]
            else:
                change[i] = inverse[i, 3] * moments[2]
        fraction = _largest_fraction(squared, change, low, high)
        for i in range(4):
            squared[i] += fraction * change[i]
    for i in range(4):
        out[i] = math.sqrt(min(max(squared[i], low), high))


@inline
def _vec(a):
    """A (3,) array as a tuple."""
    return (a[0], a[1], a[2])


@inline
def _mat(a):
    """A (3, 3) array as a row-major 9-tuple."""
    return (a[0, 0], a[0, 1], a[0, 2], a[1, 0], a[1, 1], a[1, 2], a[2, 0], a[2, 1], a[2, 2])


@kernel
def se3_rotor_speeds(pos, vel, quat, angmom, inv_inertia, inertia, mass, gravity, reference, yaw, yaw_rate, kp, kd,
                     integral, kp_att, kd_att, feedforward, inverse, k_thrust, low, high, out):  # fmt: skip
    """The SE(3) controller (``tumble.control.SE3Controller``) for the body at ``pos``, ``vel`` (its COM, world),
    ``quat`` and spin ``angmom`` (world), ``inv_inertia``/``inertia`` (3, 3) in its frame; ``reference`` (4, 3): the
    desired position, velocity, acceleration and jerk; ``integral``: the integral term's acceleration (3,). Rotor
    speeds into ``out`` (4,)."""
    e_x = sub(_vec(pos), load3(reference, 0))
    e_v = sub(_vec(vel), load3(reference, 1))
    a = sub(load3(reference, 2), _vec(gravity))
    force = scale((a[0] - kp[0] * e_x[0] - kd[0] * e_v[0] - integral[0],
                   a[1] - kp[1] * e_x[1] - kd[1] * e_v[1] - integral[1],
                   a[2] - kp[2] * e_x[2] - kd[2] * e_v[2] - integral[2]), mass)  # fmt: skip
    q = _vec4(quat)
    r = quat_to_mat33(q)
    thrust = dot(force, (r[2], r[5], r[8]))
    b1, b2, b3 = desired_axes(force, yaw)
    if feedforward:  # Mellinger & Kumar 2011, eq. 8: the body rates that turn b3d as the jerk asks
        jerk = load3(reference, 3)
        h = scale(add_scaled(jerk, b3, -dot(b3, jerk)), mass / max(math.sqrt(dot(force, force)), 1e-12))
        rates_desired = (-dot(h, b2), dot(h, b1), yaw_rate * b3[2])
    else:
        rates_desired = (0.0, 0.0, yaw_rate)
    desired_world = add_scaled(add_scaled(scale(b1, rates_desired[0]), b2, rates_desired[1]), b3, rates_desired[2])
    rates = mat_vec(_mat(inv_inertia), quat_rotate_inv(q, _vec(angmom)))
    e_w = sub(rates, quat_rotate_inv(q, desired_world))
    e_r = attitude_error(r, b1, b2, b3)
    i_body = _mat(inertia)
    wanted = sub(scale(e_r, -kp_att), scale(e_w, kd_att))  # the angular acceleration asked for
    moments = add(mat_vec(i_body, wanted), cross(rates, mat_vec(i_body, rates)))
    allocate_speeds(inverse, k_thrust, low, high, thrust, moments, out)


@inline
def _vec4(a):
    return (a[0], a[1], a[2], a[3])


@kernel
def reference_derivatives(kind, params, knot_count, knots, coefficients, t, out):
    """A reference's position, velocity, acceleration, jerk and snap at ``t`` into ``out`` (5, 3): the formulas of
    ``tumble.references`` (one evaluation for the Python references and the compiled flights alike). MinimumSnap:
    ``knots`` its times (the first ``knot_count``), ``coefficients`` its 7th-order pieces in the normalised time
    ``s = (t - t_i) / T_i``; outside its times it waits at its first or last waypoint."""
    out[:, :] = 0.0
    if kind == HOVER:
        out[0, :] = params[:3]
    elif kind == CIRCLE:
        r, w = params[3], 2.0 * math.pi * params[4]
        c, s = elementary.cos(w * t), elementary.sin(w * t)
        for k in range(5):  # d^k/dt^k of r (cos wt, sin wt) is r w^k (cos, sin)(wt + k π/2)
            out[k, 0] = r * w**k * (c if k % 4 == 0 else -s if k % 4 == 1 else -c if k % 4 == 2 else s)
            out[k, 1] = r * w**k * (s if k % 4 == 0 else c if k % 4 == 1 else -s if k % 4 == 2 else -c)
        out[0, :] += params[:3]
    elif kind == LISSAJOUS:
        A, B, a, b, delta = params[3], params[4], params[5], params[6], params[7]
        for k in range(5):  # the k-th derivative of A sin(a t + δ) is A a^k sin(a t + δ + k π/2)
            out[k, 0] = A * a**k * elementary.sin(a * t + delta + k * (math.pi / 2))
            out[k, 1] = B * b**k * elementary.sin(b * t + k * (math.pi / 2))
        out[0, :] += params[:3]
    else:
        last = knot_count - 1
        if t < knots[0]:
            out[0, :] = params[:3]
        elif t > knots[last]:
            out[0, :] = params[3:6]
        else:
            piece = 0
            while piece < last - 1 and knots[piece + 1] <= t:
                piece += 1
            duration = knots[piece + 1] - knots[piece]
            s = (t - knots[piece]) / duration
            for derivative in range(5):
                for axis in range(3):
                    value = 0.0
                    for k in range(derivative, 8):
                        factor = 1.0  # k! / (k - derivative)!
                        for m in range(k - derivative + 1, k + 1):
                            factor *= m
                        value += factor * s ** (k - derivative) * coefficients[piece, k, axis]
                    out[derivative, axis] = value / duration**derivative
