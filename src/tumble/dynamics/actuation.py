"""The loads of actuators (rotors, thrusters) and parasitic drag, evaluated inside the step from its state.

Actuators are rows of :class:`ActuatorArrays`, sorted by body (``first[i]:first[i+1]`` are body ``i``'s), with their
position and axis in the body frame. The integrators call :func:`actuator_wrench` at each of their stages with the
stage's orientation and velocities and its time ``tau`` since the start of the call, so that a rotor's thrust
follows its motor's exact first-order lag through the step and turns with the body.

Rotor (Mahony, Kumar & Corke, "Multirotor aerial vehicles", IEEE RAM 2012; the model of RotorPy): with the motor's
speed ``ω`` and the hub's air-relative velocity ``v_air = v + Ω × p − wind`` (body frame),

    force  = k_thrust ω² a − ω (k_drag v_air⊥ + k_inflow (v_air·a) a)        at the hub p
    torque = p × force + spin k_moment ω² a                                  (spin = ±1: the reaction's sense)

and the motor lags its command ``ω_c`` with time constant ``T``: ``ω(τ) = ω_c + (ω0 − ω_c) e^(−τ/T)``, exact for a
command held over the call. A thruster pushes with its commanded force along its direction at its position.
Parasitic drag on a body: ``−c ⊙ |v_air| v_air`` at the COM (body frame, ``c = (cx, cy, cz)``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .. import elementary
from .._jit import inline, kernel
from ..math3d import add, add_scaled, cross, dot, load3, quat_rotate, quat_rotate_inv, scale, sub

__all__ = ["ROTOR", "THRUSTER", "ActuatorArrays", "actuator_wrench", "advance_motors", "motor_speed"]

ROTOR = 0
THRUSTER = 1


class ActuatorArrays(NamedTuple):
    """Every actuator of a world (``a`` rows, sorted by body) and each body's drag; all SI, body frames."""

    first: np.ndarray  # (n + 1,) int64: body i's actuators are rows first[i]:first[i+1]
    kind: np.ndarray  # (a,) int64: ROTOR or THRUSTER
    position: np.ndarray  # (a, 3) hub or point of application [m]
    axis: np.ndarray  # (a, 3) unit thrust axis or direction
    spin: np.ndarray  # (a,) +1 or -1
    k_thrust: np.ndarray  # (a,) [N s²/rad²]
    k_moment: np.ndarray  # (a,) [N m s²/rad²]
    k_drag: np.ndarray  # (a,) [N s²/(m rad)]
    k_inflow: np.ndarray  # (a,) [N s²/(m rad)]
    time_constant: np.ndarray  # (a,) [s]; 0: the speed follows the command at once
    speed: np.ndarray  # (a,) the motor's speed [rad/s] (a thruster's force [N]) at the start of the call
    command: np.ndarray  # (a,) the commanded speed (force), already within limits
    drag: np.ndarray  # (n, 3) parasitic drag coefficients [kg/m]
    driven: np.ndarray  # (n,) bool: the body has actuators or drag (read in the kernels' loops, not through calls)
    wind: np.ndarray  # (3,) the air's velocity during the call, world frame [m/s]

    @classmethod
    def empty(cls, body_count: int) -> ActuatorArrays:
        none = np.zeros(0)
        return cls(np.zeros(body_count + 1, np.int64), np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3)),
                   none, none, none, none, none, none, np.zeros(0), np.zeros(0), np.zeros((body_count, 3)),
                   np.zeros(body_count, np.bool_), np.zeros(3))  # fmt: skip


@inline
def motor_speed(speed, command, time_constant, tau):
    """The motor's speed ``tau`` after the start of the call: first-order lag towards the command, exact."""
    if time_constant <= 0.0:
        return command
    return command + (speed - command) * elementary.exp(-tau / time_constant)


@inline
def actuator_wrench(acts, i, tau, q, v, w):
    """Force and torque (world frame, about the COM) of body ``i``'s actuators and drag, at time ``tau`` into the
    call, for orientation ``q``, COM velocity ``v`` and angular velocity ``w`` (world frame)."""
    zero = (0.0, 0.0, 0.0)
    has_drag = acts.drag[i, 0] != 0.0 or acts.drag[i, 1] != 0.0 or acts.drag[i, 2] != 0.0
    v_body = quat_rotate_inv(q, v)
    w_body = quat_rotate_inv(q, w)
    air = sub(v_body, quat_rotate_inv(q, (acts.wind[0], acts.wind[1], acts.wind[2])))
    force, torque = zero, zero
    for r in range(acts.first[i], acts.first[i + 1]):
        p, a = load3(acts.position, r), load3(acts.axis, r)
        if acts.kind[r] == THRUSTER:
            f = scale(a, acts.command[r])
            moment = cross(p, f)
        else:
            omega = motor_speed(acts.speed[r], acts.command[r], acts.time_constant[r], tau)
            hub_air = add(air, cross(w_body, p))
            along = dot(hub_air, a)
            across = add_scaled(hub_air, a, -along)
            f = scale(a, acts.k_thrust[r] * omega * omega)
            f = add_scaled(f, across, -omega * acts.k_drag[r])
            f = add_scaled(f, a, -omega * acts.k_inflow[r] * along)
            moment = add_scaled(cross(p, f), a, acts.spin[r] * acts.k_moment[r] * omega * omega)
        force, torque = add(force, f), add(torque, moment)
    if has_drag:
        speed = math.sqrt(dot(air, air))
        c = load3(acts.drag, i)
        force = sub(force, (c[0] * speed * air[0], c[1] * speed * air[1], c[2] * speed * air[2]))
    return quat_rotate(q, force), quat_rotate(q, torque)


@kernel
def advance_motors(acts, first_body, last_body, elapsed):
    """The speed of every rotor of bodies ``first_body..last_body-1`` ``elapsed`` seconds on; a thruster's force
    becomes its command. Writes: acts.speed."""
    for r in range(acts.first[first_body], acts.first[last_body]):
        if acts.kind[r] == THRUSTER:
            acts.speed[r] = acts.command[r]
        else:
            acts.speed[r] = motor_speed(acts.speed[r], acts.command[r], acts.time_constant[r], elapsed)
