"""The user's control namespace: flight controllers, reference trajectories, and the handle of a world's
controllers.

``world.add_controller(callback, rate)`` runs Python code before the steps of a world, each at its own rate (a
zero-order hold; :mod:`tumble.controllers` says how the ticks are counted). For a quadrotor:
:class:`SE3Controller`, :class:`CascadedPID` and :class:`Autopilot` steer it along :class:`Hover`,
:class:`Circle`, :class:`Lissajous` or :class:`MinimumSnap` (``quad.fly(controller, trajectory)``).
"""

from __future__ import annotations

from .controllers import Controller, Controllers, StepClock

# The flight controllers and reference trajectories have their own modules; they belong to this namespace.
from .flight import Autopilot, CascadedPID, SE3Controller
from .references import Circle, Hover, Lissajous, MinimumSnap

__all__ = [
    "Autopilot",
    "CascadedPID",
    "Circle",
    "Controller",
    "Controllers",
    "Hover",
    "Lissajous",
    "MinimumSnap",
    "SE3Controller",
    "StepClock",
]
