"""Flights in the kernels: when a world's only controllers are ``quad.fly(SE3Controller(...), Hover | Circle |
Lissajous | MinimumSnap)``, ``world.simulate`` evaluates them with :func:`command_flights`, one kernel call for all
of them, instead of a Python controller each. :class:`NativeFlights` is the compiled stage the world's controllers
hand the run to (``tumble.controllers.Controllers.compiled_stage``); a world without sensors and with a constant wind
takes every step and flight in one call of a compiled loop of the runner (``tumble.runner``: free bodies, or contacts
and joints), which calls :func:`command_stage` before each step.

It does what the step-by-step path does, in the same order and with the same kernels: at each step's counted start
time the flights that are due evaluate their reference (``reference_derivatives``) and the SE(3) law
(``se3_rotor_speeds``) and command their rotors; then the runner steps the bodies and the motors. The two paths fly
bit for bit alike.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._jit import inline, kernel
from ..actuators import packed_rows
from ..controllers import TICK_TOLERANCE, controller_failed
from .kernels import reference_derivatives, se3_rotor_speeds
from .se3 import SE3Controller, bad_rotor_speeds
from .trajectories import Circle, Hover, Lissajous, MinimumSnap

__all__ = ["FlightTable", "NativeFlights", "command_flights", "command_stage", "flight_table"]


class FlightTable(NamedTuple):
    """Every native flight of a world, one row each (``f`` rows); the references' parameters padded."""

    body: np.ndarray  # (f,) int64
    rows: np.ndarray  # (f, 4) int64: the rotors' rows in the actuator arrays
    speed_min: np.ndarray  # (f, 4)
    speed_max: np.ndarray  # (f, 4)
    rate: np.ndarray  # (f,) Hz; 0: every step
    next_tick: np.ndarray  # (f,) int64, the index k of the next tick k / rate (written back)
    calls: np.ndarray  # (f,) int64, calls made in this run (written back)
    mass: np.ndarray  # (f,)
    inertia: np.ndarray  # (f, 3, 3)
    inv_inertia: np.ndarray  # (f, 3, 3)
    gains: np.ndarray  # (f, 12): kp_pos (3), kd_pos (3), ki_pos (3), kp_att, kd_att, integral_limit
    feedforward: np.ndarray  # (f,) bool
    integral: np.ndarray  # (f, 3): the position error's integral (written back)
    last_time: np.ndarray  # (f,): the time of the integral's last update, NaN before the first (written back)
    mixer_inverse: np.ndarray  # (f, 4, 4)
    k_thrust: np.ndarray  # (f,)
    squared_limits: np.ndarray  # (f, 2)
    kind: np.ndarray  # (f,) int64: _HOVER, _CIRCLE, _LISSAJOUS, _MINIMUM_SNAP
    params: np.ndarray  # (f, 11): see control.kernels (HOVER and the others)
    knot_count: np.ndarray  # (f,) int64: MinimumSnap's waypoints
    knots: np.ndarray  # (f, k): MinimumSnap's times, padded
    coefficients: np.ndarray  # (f, k - 1, 8, 3): MinimumSnap's pieces, padded


def _reference_spec(trajectory):
    """The :class:`~tumble.control.trajectories.ReferenceSpec` of a trajectory the kernel evaluates; None for others."""
    return trajectory.spec if type(trajectory) in (Hover, Circle, Lissajous, MinimumSnap) else None


def flight_table(world, controllers) -> FlightTable | None:
    """The native flights behind ``controllers`` (the world's, in order); None when one of them is not a flight
    the kernel can run (an SE(3) controller on a known reference, its vehicle's rotors in the actuator arrays)."""
    rows = []
    for controller in controllers:
        flight = getattr(controller.callback, "flight", None)
        if flight is None or type(flight.controller) is not SE3Controller:
            return None
        reference = _reference_spec(flight.trajectory)
        if reference is None:
            return None
        quad, law = flight.quad, flight.controller
        rotor_rows = packed_rows(quad.rotors)
        if rotor_rows is None:
            return None
        rows.append((quad, law, controller, reference, rotor_rows, law._integral_state()))
    if not rows:
        return None
    size = max(r[3].knots.shape[0] for r in rows)
    table = FlightTable(
        body=np.array([q.body.index for q, *_ in rows], np.int64),
        rows=np.array([r[4] for r in rows], np.int64),
        speed_min=np.array([[rotor.speed_min for rotor in q.rotors] for q, *_ in rows], float),
        speed_max=np.array([[rotor.speed_max for rotor in q.rotors] for q, *_ in rows], float),
        rate=np.array([r[2].rate or 0.0 for r in rows], float),
        next_tick=np.array([r[2].next_tick for r in rows], np.int64),
        calls=np.zeros(len(rows), np.int64),
        mass=np.array([q.params["mass"] for q, *_ in rows], float),
        inertia=np.array([q.params["inertia"] for q, *_ in rows], float),
        inv_inertia=np.array([law._inv_inertia for _, law, *_ in rows], float),
        gains=np.array(
            [
                [*law.kp_pos, *law.kd_pos, *law.ki_pos, law.kp_att, law.kd_att, law.integral_limit]
                for _, law, *_ in rows
            ],
            float,
        ),  # fmt: skip
        feedforward=np.array([law.feedforward for _, law, *_ in rows], np.bool_),
        integral=np.array([r[5][0] for r in rows], float),
        last_time=np.array([r[5][1] for r in rows], float),
        mixer_inverse=np.array([q.mixer.inverse for q, *_ in rows], float),
        k_thrust=np.array([q.params["k_thrust"] for q, *_ in rows], float),
        squared_limits=np.array([q.mixer.squared_limits for q, *_ in rows], float),
        kind=np.array([r[3].kind for r in rows], np.int64),
        params=np.array([r[3].params for r in rows], float),
        knot_count=np.array([r[3].knot_count for r in rows], np.int64),
        knots=np.array([np.pad(r[3].knots, (0, size - len(r[3].knots))) for r in rows], float),
        coefficients=np.array(
            [np.pad(r[3].coefficients, ((0, size - len(r[3].coefficients)), (0, 0), (0, 0))) for r in rows], float
        ),  # fmt: skip
    )
    return table


@kernel
def command_flights(table, gravity, acts, pos, quat, linvel, angmom, t, h, ref, speeds, integral):
    """Before the step of ``h`` that starts at ``t``: each flight that is due evaluates its reference and the SE(3)
    law and commands its rotors (``tumble.control.fly`` and ``_Integral``, in the order of the table). Returns the
    first flight whose rotor speeds are not finite (then in ``speeds``), or -1. ``ref`` (5, 3), ``speeds`` (4,) and
    ``integral`` (3,) are scratch."""
    for f in range(table.body.shape[0]):
        rate = table.rate[f]
        if rate > 0.0 and t < table.next_tick[f] / rate - TICK_TOLERANCE * h:
            continue
        reference_derivatives(table.kind[f], table.params[f], table.knot_count[f], table.knots[f],
                              table.coefficients[f], t, ref)  # fmt: skip
        b = table.body[f]
        gains = table.gains[f]
        integral[:] = 0.0
        if gains[6] > 0.0 or gains[7] > 0.0 or gains[8] > 0.0:
            last = table.last_time[f]
            if not math.isnan(last) and t > last:
                for k in range(3):
                    value = table.integral[f, k] + (pos[b, k] - ref[0, k]) * (t - last)
                    if gains[6 + k] > 0.0:
                        bound = gains[11] / gains[6 + k]
                        value = min(max(value, -bound), bound)
                    table.integral[f, k] = value
            table.last_time[f] = t
            for k in range(3):
                integral[k] = gains[6 + k] * table.integral[f, k]
        se3_rotor_speeds(pos[b], linvel[b], quat[b], angmom[b], table.inv_inertia[f], table.inertia[f], table.mass[f],
                         gravity, ref, table.params[f, 10], 0.0, gains[0:3], gains[3:6], integral, gains[9],
                         gains[10], table.feedforward[f], table.mixer_inverse[f], table.k_thrust[f],
                         table.squared_limits[f, 0], table.squared_limits[f, 1], speeds)  # fmt: skip
        for k in range(4):
            if not math.isfinite(speeds[k]):
                return f
        for k in range(4):
            acts.command[table.rows[f, k]] = min(max(speeds[k], table.speed_min[f, k]), table.speed_max[f, k])
        table.calls[f] += 1
        if rate > 0.0:
            table.next_tick[f] = max(table.next_tick[f] + 1, math.floor((t + TICK_TOLERANCE * h) * rate) + 1)
    return -1


@inline
def command_stage(data, gravity, acts, pos, quat, linvel, angmom, t, h):
    """:func:`command_flights` as the runner's compiled loop calls a stage (``tumble.runner``): ``data`` is
    :attr:`NativeFlights.compiled_data`, the table and its scratch."""
    table, ref, speeds, integral = data
    return command_flights(table, gravity, acts, pos, quat, linvel, angmom, t, h, ref, speeds, integral)


class NativeFlights:
    """The compiled stage of a world whose controllers are all native flights (see
    ``tumble.controllers.Controllers.compiled_stage`` for what a stage does): :func:`command_flights` before each
    step, from a Python loop (:meth:`command`) or from the runner's compiled loop (:func:`command_stage`)."""

    compiled_command = staticmethod(command_stage)

    def __init__(self, controllers: list, table: FlightTable):
        self._controllers, self._table = controllers, table
        # command_flights' scratch: the reference's derivatives, the rotor speeds asked for (read by failure()),
        # the integral term
        self._ref, self._speeds, self._integral = np.zeros((5, 3)), np.zeros(4), np.zeros(3)
        self.compiled_data = (table, self._ref, self._speeds, self._integral)

    @classmethod
    def for_world(cls, world, controllers) -> NativeFlights | None:
        """The stage of ``controllers`` (the world's, in order), or None when one is not a flight it runs."""
        table = flight_table(world, controllers)
        if table is None:
            return None
        return cls(controllers, table)

    def command(self, model, state, acts, t: float, dt: float) -> None:
        failing = command_flights(self._table, model.gravity, acts, state.body_pos, state.body_quat, state.body_linvel,
                                  state.body_angmom, t, dt, self._ref, self._speeds, self._integral)  # fmt: skip
        if failing >= 0:
            raise self.failure(failing, t, state.step_count)

    def finish(self) -> None:
        table = self._table
        for k, controller in enumerate(self._controllers):
            controller.count_calls(table.calls[k], table.next_tick[k])
            law = controller.callback.flight.controller
            law._load_integral_state(table.integral[k], table.last_time[k])

    def failure(self, flight: int, t: float, step: int):
        """The error of flight ``flight`` (its index in the table), whose rotor speeds were not finite before the
        step ``step`` from ``t``."""
        controller = self._controllers[flight]
        return controller_failed(controller.name, bad_rotor_speeds(controller.callback.flight.controller,
                                                                   self._speeds, t), t, step)  # fmt: skip
