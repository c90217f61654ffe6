"""``quad.fly(controller, trajectory)``: a flight attached to its vehicle's world as a controller, whose compiled
stage (:class:`~tumble.control.native.NativeFlights`) runs it in the kernels where it can."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .native import NativeFlights
from .se3 import bad_rotor_speeds

__all__ = ["Flight", "fly"]


class Flight(NamedTuple):
    """What :func:`fly` attached to a vehicle: the controller, the trajectory, the rate and the world controller."""

    controller: object
    trajectory: object
    rate: float | None
    handle: object
    quad: object


def fly(quad, controller, trajectory, rate: float | None = None):
    """Attach ``controller`` following ``trajectory`` to ``quad``'s world (``Quadrotor.fly``); returns the world
    controller's handle."""
    if not callable(getattr(controller, "update", None)):
        raise TypeError(f"controller must have update(t, reference) -> rotor speeds, got {controller!r}")
    if not callable(trajectory):
        raise TypeError(f"trajectory must be callable as trajectory(t) -> reference, got {trajectory!r}")
    name = f"{type(controller).__name__} on {type(trajectory).__name__}"

    def follow(world, t):
        speeds = np.asarray(controller.update(t, trajectory(t)), dtype=float)
        if speeds.shape != (4,) or not np.all(np.isfinite(speeds)):
            raise bad_rotor_speeds(controller, speeds, t)
        quad.command_rotor_speeds(speeds)

    # The compiled flights (control.native) can stand in for this callback; they read what it flies from it.
    follow.compiled_stage = NativeFlights.for_world
    handle = quad.world.add_controller(follow, rate=rate, name=name)
    follow.flight = Flight(controller, trajectory, rate, handle, quad)
    return handle
