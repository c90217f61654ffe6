"""The quadrotor of the course: one rigid body, four rotors, its mixer (the package's docstring), attached to its
world (``world.attach``); ``quad.fly`` and ``quad.autopilot`` hand it to :mod:`tumble.control`."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from .. import portable
from .._validate import as_array
from ..actuators import Rotor, command_all
from ..mass import MassProperties
from ..shapes import Box, Sphere
from .mixer import Mixer
from .params import CRAZYFLIE, quadrotor_params, rotor_hubs

__all__ = ["Quadrotor", "quadrotors"]


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
        self._flight = None  # what fly() attached (tumble.control.fly.Flight)
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
            from ..control.autopilot import Autopilot

            self._autopilot = Autopilot(self)
        return self._autopilot

    def fly(self, controller, trajectory, rate: float | None = None):
        """Fly ``trajectory`` with ``controller``: a world controller that, before each step (or at ``rate`` Hz),
        commands ``controller.update(t, trajectory(t))``. Returns the world controller's handle (``.remove()``).
        A controller that returns rotor speeds that are not four finite numbers stops the run with a
        :class:`~tumble.SimulationError` naming it and the time."""
        from ..control.fly import fly

        handle = fly(self, controller, trajectory, rate)
        self._flight = handle.callback.flight
        return handle

    def __repr__(self) -> str:
        return f"<Quadrotor {self.body.name or self.body.index!r} ({self.layout} layout, {self.params['mass']:g} kg)>"


def quadrotors(world) -> list[Quadrotor]:
    """The quadrotors attached to ``world``, in the order they were made (none for ``None``)."""
    return [] if world is None else [item for item in world.attachments if isinstance(item, Quadrotor)]
