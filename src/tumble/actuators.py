"""Actuators: rotors and thrusters fixed to bodies, turning commands into forces inside the step.

``world.add_actuator(Rotor(body, ...))`` adds one and returns it as its handle. The loads are evaluated inside the
step from the state of each integrator stage or substep (``dynamics/actuation.py`` has the formulas and their
source); a command holds until the next one (a zero-order hold, as from a controller at its own rate).

Rotor: thrust ``k_thrust ω²`` along ``axis`` at ``position`` (both in the body frame), reaction torque
``spin k_moment ω²`` about ``axis`` (``spin`` = ±1: +1 for a rotor whose reaction turns the body positively about
the axis, the sense of RotorPy's ``rotor_directions``), rotor drag and inflow from the hub's air-relative velocity.
The motor follows its command ``ω_c`` with a first-order lag, discretised exactly: ``ω ← ω_c + (ω − ω_c)
e^(−dt/τ)``; commands are clipped to ``[speed_min, speed_max]``.

Thruster: a force along a body-fixed ``direction`` at ``position``, commanded in newtons and clipped to
``[0, max_force]`` (a thruster pushes; turn it round to pull).
"""

from __future__ import annotations

import math

import numpy as np

from ._validate import as_float, as_unit_vector3, as_vector3
from .dynamics.actuation import ROTOR, THRUSTER, ActuatorArrays
from .handles import as_body, as_dynamic_body_of, as_new_part

__all__ = ["Actuator", "Rotor", "Thruster", "command_all", "packed_rows"]


class Actuator:
    """What rotors and thrusters share: the body, the point, the axis, and the link to the world's arrays."""

    _kind = -1

    def __init__(self, body, position, axis, axis_name: str):
        self.body = as_body(body)
        self.position = as_vector3("position", position)
        self.axis = as_unit_vector3(axis_name, axis)
        self._world = None
        self._owner: Actuation | None = None  # set when the arrays hold its row
        self._row = -1
        self._speed = 0.0
        self._command = 0.0

    def _parameters(self) -> tuple[float, float, float, float, float, float]:
        """``(spin, k_thrust, k_moment, k_drag, k_inflow, time_constant)`` for the arrays."""
        raise NotImplementedError

    def _present(self) -> float:
        return float(self._owner.arrays.speed[self._row]) if self._owner is not None else self._speed

    def _commanded(self) -> float:
        return float(self._owner.arrays.command[self._row]) if self._owner is not None else self._command

    def _set(self, column: str, value: float) -> None:
        if self._owner is None:
            setattr(self, f"_{column}", value)
        else:
            getattr(self._owner.arrays, column)[self._row] = value
            self.body._require_dynamic("command an actuator")  # wakes the body's island


class Rotor(Actuator):
    """A propeller on a motor (see the module docstring). Handle attributes: ``speed`` (read/write, the motor's
    present speed [rad/s]), ``command(speed)``, ``commanded_speed``, ``thrust`` [N], ``torque`` [N m] (the reaction
    about the axis, signed by ``spin``)."""

    _kind = ROTOR

    def __init__(self, body, position, axis, spin, k_thrust, k_moment, speed_min=0.0, speed_max=math.inf,
                 time_constant=0.0, k_drag=0.0, k_inflow=0.0):  # fmt: skip
        super().__init__(body, position, axis, "axis")
        if isinstance(spin, bool) or spin not in (1, -1):
            raise ValueError(f"spin must be +1 or -1, got {spin!r}")
        self.spin = float(spin)
        self.k_thrust = as_float("k_thrust", k_thrust, nonnegative=True)
        self.k_moment = as_float("k_moment", k_moment, nonnegative=True)
        self.k_drag = as_float("k_drag", k_drag, nonnegative=True)
        self.k_inflow = as_float("k_inflow", k_inflow, nonnegative=True)
        self.time_constant = as_float("time_constant", time_constant, nonnegative=True)
        self.speed_min = as_float("speed_min", speed_min, nonnegative=True)
        if speed_max != math.inf:
            speed_max = as_float("speed_max", speed_max, nonnegative=True)
        self.speed_max = float(speed_max)
        if self.speed_min > self.speed_max:
            raise ValueError(f"speed_min must be <= speed_max, got speed_min={self.speed_min!r} > "
                             f"speed_max={self.speed_max!r}")  # fmt: skip
        self._speed = self._command = self.speed_min

    def _parameters(self):
        return self.spin, self.k_thrust, self.k_moment, self.k_drag, self.k_inflow, self.time_constant

    @property
    def speed(self) -> float:
        """The motor's present speed [rad/s]; setting it (within the limits) skips the lag."""
        return self._present()

    @speed.setter
    def speed(self, value) -> None:
        value = as_float("speed", value, nonnegative=True)
        if not self.speed_min <= value <= self.speed_max:
            raise ValueError(f"speed must be within [speed_min, speed_max] = [{self.speed_min!r}, "
                             f"{self.speed_max!r}], got {value!r}")  # fmt: skip
        self._set("speed", value)

    def command(self, speed) -> None:
        """Command the motor's speed [rad/s]: clipped to ``[speed_min, speed_max]``, held until the next command."""
        self._set("command", min(max(as_float("speed", speed), self.speed_min), self.speed_max))

    @property
    def commanded_speed(self) -> float:
        return self._commanded()

    @property
    def thrust(self) -> float:
        """``k_thrust ω²`` at the present speed [N]."""
        return self.k_thrust * self.speed**2

    @property
    def torque(self) -> float:
        """The reaction about the axis, ``spin k_moment ω²`` at the present speed [N m]."""
        return self.spin * self.k_moment * self.speed**2

    def __repr__(self) -> str:
        return f"<Rotor on body {self.body.name or self.body.index!r}: {self.speed:.6g} rad/s>"


class Thruster(Actuator):
    """A force along a body-fixed ``direction`` at ``position``: ``command(force)`` [N], clipped to
    ``[0, max_force]``; ``force`` is the one acting now."""

    _kind = THRUSTER

    def __init__(self, body, position, direction, max_force):
        super().__init__(body, position, direction, "direction")
        self.max_force = as_float("max_force", max_force, nonnegative=True)

    def _parameters(self):
        return 1.0, 0.0, 0.0, 0.0, 0.0, 0.0

    def command(self, force) -> None:
        """Command the force [N]: clipped to ``[0, max_force]``, acting from the next step until the next command."""
        self._set("command", min(max(as_float("force", force), 0.0), self.max_force))

    @property
    def commanded_force(self) -> float:
        return self._commanded()

    @property
    def force(self) -> float:
        """The force of the last step [N] (the command from the next one on)."""
        return self._present()

    def __repr__(self) -> str:
        return f"<Thruster on body {self.body.name or self.body.index!r}: {self.commanded_force:.6g} N>"


def packed_rows(actuators) -> list[int] | None:
    """The rows of ``actuators`` in their world's packed arrays (``ActuatorArrays``), or None unless all of them sit
    in the same packed arrays now (the arrays are rebuilt, and the rows dropped, when actuators are added)."""
    owner = actuators[0]._owner
    if owner is None or any(actuator._owner is not owner for actuator in actuators):
        return None
    return [actuator._row for actuator in actuators]


def command_all(rotors, speeds: np.ndarray) -> None:
    """``rotor.command(speed)`` for each pair, in one write when the rotors share their world's arrays (a vehicle
    commanded at every step of a fast world)."""
    rows = packed_rows(rotors)
    if rows is None:
        for rotor, speed in zip(rotors, speeds, strict=True):
            rotor.command(float(speed))
        return
    low = [rotor.speed_min for rotor in rotors]
    high = [rotor.speed_max for rotor in rotors]
    rotors[0]._owner.arrays.command[rows] = np.minimum(np.maximum(speeds, low), high)
    rotors[0].body._require_dynamic("command an actuator")
    for rotor in rotors[1:]:
        if rotor.body is not rotors[0].body:
            rotor.body._require_dynamic("command an actuator")


class Actuation:
    """A world's actuators and drag coefficients, packed into :class:`ActuatorArrays` for the kernels."""

    def __init__(self):
        self.actuators: list[Actuator] = []
        self.drag: dict[int, np.ndarray] = {}
        self.wind = np.zeros(3)
        self._arrays: ActuatorArrays | None = None
        self._body_count = -1
        self._driven = np.zeros(0, np.int64)
        self._body_com = np.zeros((0, 3))

    def add(self, world, actuator) -> Actuator:
        as_new_part(world, actuator, Actuator, "actuator", "an", "a tumble.actuators.Rotor or Thruster")
        self._pack_current()
        actuator._world = world
        self.actuators.append(actuator)
        self._arrays = None
        return actuator

    def add_drag(self, world, body, coefficients) -> None:
        as_dynamic_body_of(world, body, "drag")
        c = as_vector3("coefficients", coefficients)
        if (c < 0).any():
            raise ValueError(f"coefficients must be >= 0, got {c.tolist()}")
        self._pack_current()
        self.drag[body.index] = c
        self._arrays = None

    def driven_bodies(self) -> np.ndarray:
        """Indices of the bodies with actuators or drag (as of the last :meth:`for_bodies`)."""
        return self._driven

    def _pack_current(self) -> None:
        """Keep the present speeds and commands in the actuators before the arrays are rebuilt."""
        if self._arrays is not None:
            for actuator in self.actuators:
                actuator._speed, actuator._command = actuator._present(), actuator._commanded()
                actuator._owner = None

    @property
    def arrays(self) -> ActuatorArrays:
        if self._arrays is None:
            self._arrays = self._pack(self._body_count)
        return self._arrays

    def _com(self, index: int) -> np.ndarray:
        return self._body_com[index] if index < self._body_com.shape[0] else np.zeros(3)

    def for_bodies(self, body_com_local: np.ndarray) -> ActuatorArrays:
        """The arrays for a world whose bodies have their centres of mass at ``body_com_local`` (n, 3) in their
        frames (the actuators' positions are taken from there), with this step's wind."""
        if self._arrays is None or body_com_local.shape[0] != self._body_count:
            self._pack_current()
            self._body_com = body_com_local
            self._arrays = self._pack(body_com_local.shape[0])
        np.copyto(self._arrays.wind, self.wind)
        return self._arrays

    def _pack(self, body_count: int) -> ActuatorArrays:
        body_count = max(body_count, 1 + max((a.body.index for a in self.actuators), default=-1),
                         1 + max(self.drag, default=-1))  # fmt: skip
        order = sorted(range(len(self.actuators)), key=lambda k: self.actuators[k].body.index)
        ordered = [self.actuators[k] for k in order]
        first = np.searchsorted([a.body.index for a in ordered], np.arange(body_count + 1)).astype(np.int64)
        parameters = np.array([a._parameters() for a in ordered], dtype=float).reshape(-1, 6)
        drag = np.zeros((body_count, 3))
        for index, c in self.drag.items():
            drag[index] = c
        kind = np.array([a._kind for a in ordered], np.int64)
        position = np.array([a.position - self._com(a.body.index) for a in ordered], float).reshape(-1, 3)
        axis = np.array([a.axis for a in ordered], float).reshape(-1, 3)
        speed = np.array([a._speed for a in ordered], float)
        command = np.array([a._command for a in ordered], float)
        self._driven = np.array(sorted({a.body.index for a in ordered} | set(self.drag)), np.int64)
        driven = np.zeros(body_count, np.bool_)
        driven[self._driven] = True
        arrays = ActuatorArrays(first, kind, position, axis, *(parameters[:, k].copy() for k in range(6)), speed,
                                command, drag, driven, self.wind.copy())  # fmt: skip
        for row, actuator in enumerate(ordered):
            actuator._owner, actuator._row = self, row
        self._body_count = body_count
        return arrays
