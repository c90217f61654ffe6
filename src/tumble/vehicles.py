"""Vehicles built from ordinary bodies and actuators: the quadrotor of the course (``course/004_…``, "Quadrotor").

A :class:`Quadrotor` is one rigid body with four :class:`~tumble.actuators.Rotor`\\ s on it; nothing about it is
special to the engine. Its rotors push along the body's ``z`` axis, the thrust ``k_thrust ω²`` and the reaction
``spin k_moment ω²`` of each, with rotor drag, inflow and the motors' first-order lag as in
``dynamics/actuation.py``. The :class:`Mixer` maps the four ``ω²`` to the collective thrust and the three body
moments, and back.

Layouts (rotor ``i`` at ``p_i``, spins ``s_i``; the arm length ``L`` from the centre of mass to each hub):

- ``"x"``: ``p = L/√2 (+,+), (+,−), (−,−), (−,+)``, spins ``(+1, −1, +1, −1)`` (RotorPy's layout);
- ``"+"``: ``p = L (+x), (+y), (−x), (−y)``, spins ``(+1, −1, +1, −1)``: the course's numbering, whose moments are
  ``(L (F2 − F4), L (F3 − F1), M1 − M2 + M3 − M4)``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType

import numpy as np

from . import portable
from ._validate import as_array, as_float, as_vector3
from .actuators import Rotor, command_all
from .flight.kernels import allocate_speeds
from .mass import MassProperties
from .shapes import Box, Sphere

__all__ = ["CRAZYFLIE", "HUMMINGBIRD", "Mixer", "Quadrotor", "quadrotor_params", "quadrotors", "rotor_hubs"]

_PARAMETER_NAMES = ("mass", "inertia", "arm_length", "k_thrust", "k_moment", "k_drag", "k_inflow", "speed_min",
                    "speed_max", "time_constant", "rotor_directions", "drag_coefficients", "kp_att",
                    "kd_att")  # fmt: skip


def quadrotor_params(**values) -> Mapping:
    """A read-only parameter set for :class:`Quadrotor`, validated: ``mass`` [kg], ``inertia`` (3, 3) [kg m²] about
    the centre of mass in the body frame, ``arm_length`` [m] (centre of mass to hub), ``k_thrust`` [N s²/rad²],
    ``k_moment`` [N m s²/rad²], ``k_drag`` and ``k_inflow`` [N s²/(m rad)] (rotor drag across and along the axis),
    ``speed_min``/``speed_max`` [rad/s], ``time_constant`` [s] (the motors' lag), ``rotor_directions`` (4,) of ±1
    ``drag_coefficients`` (3,) [kg/m] (parasitic drag of the frame, ``world.add_drag``), and the attitude gains
    the vehicle flies well with, ``kp_att`` [1/s²] and ``kd_att`` [1/s] (the motors' lag bounds them; the
    controllers of ``tumble.control`` take them by default, as RotorPy's do). Every name is needed;
    start from a shipped set to change a few: ``quadrotor_params(**{**CRAZYFLIE, "mass": 0.035})``."""
    unknown = sorted(set(values) - set(_PARAMETER_NAMES))
    missing = [name for name in _PARAMETER_NAMES if name not in values]
    if unknown or missing:
        raise ValueError(f"quadrotor parameters: unknown {unknown}, missing {missing}; the names are "
                         f"{list(_PARAMETER_NAMES)}")  # fmt: skip
    p = {name: as_float(name, values[name], positive=True) for name in ("mass", "arm_length", "k_thrust")}
    for name in ("k_moment", "k_drag", "k_inflow", "speed_min", "time_constant", "kp_att", "kd_att"):
        p[name] = as_float(name, values[name], nonnegative=True)
    p["speed_max"] = as_float("speed_max", values["speed_max"], positive=True)
    if p["speed_min"] >= p["speed_max"]:
        raise ValueError(f"speed_min must be < speed_max, got {p['speed_min']!r} >= {p['speed_max']!r}")
    inertia = as_array("inertia", values["inertia"], (3, 3), batch=False)
    if not np.allclose(inertia, inertia.T, rtol=1e-12, atol=0.0) or portable.eigh(inertia)[0][0] <= 0.0:
        raise ValueError(f"inertia must be symmetric and positive definite, got {inertia.tolist()}")
    directions = as_array("rotor_directions", values["rotor_directions"], (4,), batch=False)
    if not np.all(np.abs(directions) == 1.0):
        raise ValueError(f"rotor_directions must be four of +1 or -1, got {directions.tolist()}")
    drag = as_vector3("drag_coefficients", values["drag_coefficients"])
    if (drag < 0).any():
        raise ValueError(f"drag_coefficients must be >= 0, got {drag.tolist()}")
    for array in (inertia, directions, drag):
        array.flags.writeable = False
    p.update(inertia=inertia, rotor_directions=directions, drag_coefficients=drag)
    return MappingProxyType({name: p[name] for name in _PARAMETER_NAMES})


# The Crazyflie 2.0 (Bitcraze), with RotorPy's figures: inertia and rotor coefficients from J. Förster, "System
# identification of the Crazyflie 2.0 nano quadrocopter", ETH Zürich, 2015; thrust from 14.5 g at 2500 rad/s;
# attitude gains RotorPy 3.0's (its 72 ms motors leave the attitude loop with little phase to spare).
CRAZYFLIE = quadrotor_params(
    mass=0.03, inertia=np.diag([1.43e-5, 1.43e-5, 2.89e-5]), arm_length=0.043, k_thrust=2.3e-8, k_moment=7.8e-10,
    k_drag=1.02506e-6, k_inflow=7.553e-7, speed_min=0.0, speed_max=2500.0, time_constant=0.072,
    rotor_directions=(1, -1, 1, -1), drag_coefficients=(0.0, 0.0, 0.0), kp_att=310.0, kd_att=57.0,
)  # fmt: skip

# The AscTec Hummingbird, with RotorPy's figures: mass and inertia from D. Mellinger, "Trajectory generation and
# control for quadrotors", PhD thesis, University of Pennsylvania, 2012, and M. Achtelik et al.; rotor coefficients
# from E. Kaufman et al. (IEEE 7991501, 2017) and the identification of A. Mehrotra (University of New Mexico
# thesis, ece_etds 1189); the rotor drag and inflow coefficients are RotorPy's, a tenth of those papers'.
HUMMINGBIRD = quadrotor_params(
    mass=0.5, inertia=np.diag([3.65e-3, 3.68e-3, 7.03e-3]), arm_length=0.17, k_thrust=5.57e-6, k_moment=1.36e-7,
    k_drag=1.19e-4, k_inflow=2.32e-4, speed_min=0.0, speed_max=1500.0, time_constant=0.005,
    rotor_directions=(1, -1, 1, -1), drag_coefficients=(0.5e-2, 0.5e-2, 1e-2), kp_att=544.0, kd_att=46.64,
)  # fmt: skip

_LAYOUTS = {
    "x": np.array([[1.0, 1.0, 0.0], [1.0, -1.0, 0.0], [-1.0, -1.0, 0.0], [-1.0, 1.0, 0.0]]) / math.sqrt(2.0),
    "+": np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]),
}


def rotor_hubs(layout: str, arm_length: float) -> np.ndarray:
    """(4, 3) [m] the rotors' hubs in the body frame for ``layout`` ``"x"`` or ``"+"`` (module docstring)."""
    if layout not in _LAYOUTS:
        raise ValueError(f"layout must be 'x' or '+', got {layout!r}")
    return _LAYOUTS[layout] * arm_length


class Mixer:
    """The map between the rotors' squared speeds ``ω²`` (4,) and the wrench ``(T, Mx, My, Mz)`` they make: the
    collective thrust along the body's ``z`` [N] and the moments about the centre of mass, body frame [N m].

    ``matrix`` has columns ``k_thrust (1, p_y, −p_x, 0) + spin k_moment (0, 0, 0, 1)`` (the moment of a force
    ``F ẑ`` at ``p`` is ``p × F ẑ = F (p_y, −p_x, 0)``); ``inverse`` is its inverse."""

    def __init__(self, positions: np.ndarray, spins: np.ndarray, k_thrust: float, k_moment: float,
                 speed_min: float, speed_max: float):  # fmt: skip
        matrix = np.vstack([np.ones(4), positions[:, 1], -positions[:, 0], spins * (k_moment / k_thrust)])
        self.matrix = k_thrust * matrix
        self.inverse = portable.inverse(self.matrix)
        for array in (self.matrix, self.inverse):
            array.flags.writeable = False
        self.k_thrust = k_thrust
        self.squared_limits = (speed_min**2, speed_max**2)  # the bounds of each ω²

    def wrench(self, rotor_speeds) -> np.ndarray:
        """``(T, Mx, My, Mz)`` of the rotors at ``rotor_speeds`` (4,) [rad/s]."""
        speeds = as_array("rotor_speeds", rotor_speeds, (4,), batch=False)
        return portable.matvec(self.matrix, speeds**2)

    def allocate(self, thrust, moments) -> np.ndarray:
        """Rotor speeds (4,) [rad/s] that make the collective ``thrust`` [N] and body ``moments`` (3,) [N m].

        Within the motors' limits this is ``√(inverse @ (T, M))``. Beyond them the demand is cut in order of
        priority: the thrust first (clipped to what four rotors between their limits can give), then roll and pitch
        together (scaled down, keeping the direction of the tilting moment), then yaw; what is kept is met
        exactly."""
        speeds = np.empty(4)
        allocate_speeds(self.inverse, self.k_thrust, *self.squared_limits, as_float("thrust", thrust),
                        as_vector3("moments", moments), speeds)  # fmt: skip
        return speeds


class Quadrotor:
    """A quadrotor: one body with four rotors, in ``world`` (see the module docstring for the layouts).

    The body's origin is its centre of mass; its collision shape is a flat hub of one arm's length square and
    ``0.2 L`` thick with four feet (spheres of ``0.1 L`` under the hubs, ``0.3 L`` below the centre), so it can land
    and stand. Its mass and inertia are the parameters', not the shapes'.

    Args:
        world: the :class:`~tumble.World` to add it to.
        params: a parameter set (:data:`CRAZYFLIE`, :data:`HUMMINGBIRD` or from :func:`quadrotor_params`).
        position, orientation, velocity, angular_velocity: the initial state (world frame; ``angular_velocity``
            too).
        layout: ``"x"`` or ``"+"``.
        name: the body's name.

    The motors start at ``speed_min`` (for a flight from hover, set ``quad.rotor_speeds = [quad.hover_rotor_speed]
    * 4`` and command the same).
    """

    def __init__(self, world, params: Mapping = CRAZYFLIE, position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0),
                 velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0), layout: str = "x",
                 name: str | None = None):  # fmt: skip
        if not isinstance(params, Mapping):
            raise TypeError(f"params must be a mapping such as tumble.vehicles.CRAZYFLIE, got {params!r}")
        self.params = quadrotor_params(**params)
        hubs = rotor_hubs(layout, self.params["arm_length"])
        self.layout = layout
        p = self.params
        arm = p["arm_length"]
        shapes = [(Box((arm, arm, 0.2 * arm)), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))]
        shapes += [(Sphere(0.1 * arm), (x, y, -0.3 * arm), (1.0, 0.0, 0.0, 0.0)) for x, y, _ in hubs]
        self.body = world.add_body(
            shapes, mass_properties=MassProperties(p["mass"], np.zeros(3), p["inertia"]), position=position,
            orientation=orientation, velocity=velocity,
            angular_velocity=angular_velocity, name=name,
        )  # fmt: skip
        self.world = world
        self.rotors = tuple(
            world.add_actuator(Rotor(self.body, hub, (0.0, 0.0, 1.0), int(spin), p["k_thrust"], p["k_moment"],
                                     p["speed_min"], p["speed_max"], p["time_constant"], p["k_drag"], p["k_inflow"]))
            for hub, spin in zip(hubs, p["rotor_directions"], strict=True)
        )  # fmt: skip
        if np.any(p["drag_coefficients"] > 0.0):
            world.add_drag(self.body, p["drag_coefficients"])
        self.mixer = Mixer(hubs, p["rotor_directions"], p["k_thrust"], p["k_moment"], p["speed_min"], p["speed_max"])
        self._autopilot = None
        self._flight = None  # what fly() attached (tumble.flight.Flight)
        world.attach(self)

    @property
    def rotor_speeds(self) -> np.ndarray:
        """The motors' present speeds (4,) [rad/s]; setting them (within the limits) skips the lag."""
        return np.array([rotor.speed for rotor in self.rotors])

    @rotor_speeds.setter
    def rotor_speeds(self, value) -> None:
        speeds = as_array("rotor_speeds", value, (4,), batch=False)
        low, high = self.params["speed_min"], self.params["speed_max"]
        if not np.all((speeds >= low) & (speeds <= high)):
            raise ValueError(f"rotor_speeds must be within [speed_min, speed_max] = [{low!r}, {high!r}], got "
                             f"{speeds.tolist()}")  # fmt: skip
        for rotor, speed in zip(self.rotors, speeds, strict=True):
            rotor.speed = float(speed)

    @property
    def commanded_rotor_speeds(self) -> np.ndarray:
        """The speeds the motors are following (4,) [rad/s]."""
        return np.array([rotor.commanded_speed for rotor in self.rotors])

    def command_rotor_speeds(self, speeds) -> None:
        """Command the four motors (4,) [rad/s], each clipped to ``[speed_min, speed_max]``; held until the next
        command. Ends any command of a higher level (``tumble.control.Autopilot``)."""
        speeds = as_array("speeds", speeds, (4,), batch=False)
        self._stop_autopilot()
        self._command(speeds)

    def _command(self, speeds: np.ndarray) -> None:
        command_all(self.rotors, speeds)

    def _stop_autopilot(self) -> None:
        if self._autopilot is not None:
            self._autopilot.stop()

    @property
    def hover_rotor_speed(self) -> float:
        """The speed at which the four rotors carry the weight: ``√(m g / (4 k_thrust))`` [rad/s]."""
        g = float(portable.norm(self.world.gravity))
        return math.sqrt(self.params["mass"] * g / (4.0 * self.params["k_thrust"]))

    def state(self) -> dict[str, np.ndarray]:
        """``position``, ``velocity`` (world frame), ``orientation`` (quaternion w, x, y, z), ``angular_velocity_body``
        (the body rates p, q, r) and ``rotor_speeds`` (4,), copies of the present values."""
        body = self.body
        return {
            "position": body.position,
            "velocity": body.velocity,
            "orientation": body.orientation,
            "angular_velocity_body": body.angular_velocity_body,
            "rotor_speeds": self.rotor_speeds,
        }

    @property
    def autopilot(self):
        """The vehicle's :class:`~tumble.control.Autopilot`: thrust and moments, body rates, attitude or velocity
        commands held by inner loops that run before every step."""
        if self._autopilot is None:
            from .flight import Autopilot

            self._autopilot = Autopilot(self)
        return self._autopilot

    def fly(self, controller, trajectory, rate: float | None = None):
        """Fly ``trajectory`` with ``controller``: a world controller that, before each step (or at ``rate`` Hz),
        commands ``controller.update(t, trajectory(t))``. Returns the world controller's handle (``.remove()``).
        A controller that returns rotor speeds that are not four finite numbers stops the run with a
        :class:`~tumble.SimulationError` naming it and the time."""
        from .flight.attach import fly

        handle = fly(self, controller, trajectory, rate)
        self._flight = handle.callback.flight
        return handle

    def __repr__(self) -> str:
        return f"<Quadrotor {self.body.name or self.body.index!r} ({self.layout} layout, {self.params['mass']:g} kg)>"


def quadrotors(world) -> list[Quadrotor]:
    """The quadrotors attached to ``world``, in the order they were made (none for ``None``)."""
    return [] if world is None else [item for item in world.attachments if isinstance(item, Quadrotor)]
