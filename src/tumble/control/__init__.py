"""The user's control namespace: flight controllers, reference trajectories, and the handle of a world's
controllers.

``world.add_controller(callback, rate)`` runs Python code before the steps of a world, each at its own rate (a
zero-order hold; :mod:`tumble.controllers` says how the ticks are counted). For a quadrotor:
:class:`SE3Controller` (``se3.py``), :class:`CascadedPID` (``pid.py``) and :class:`Autopilot` (``autopilot.py``)
steer it along :class:`Hover`, :class:`Circle`, :class:`Lissajous` or :class:`MinimumSnap` (``trajectories.py``),
attached by ``quad.fly(controller, trajectory)`` (``fly.py``); ``kernels.py`` holds their compiled parts and
``native.py`` the compiled stage that flies SE(3) on a known trajectory inside the kernels.

Notation (Lee, Leok & McClamroch, "Geometric tracking control of a quadrotor UAV on SE(3)", IEEE CDC 2010): the
vehicle at ``x``, ``v`` with rotation ``R`` (body to world) and body rates ``Ω``, inertia ``J``, mass ``m``, gravity
``g`` (the world's vector); the reference's position ``x_d``, velocity, acceleration, jerk and yaw ``ψ_d``. Every
controller ends in a collective thrust ``f`` and body moments ``M``, turned into rotor speeds by the vehicle's
mixer (``Mixer.allocate``, which keeps the thrust first under saturation).
"""

from __future__ import annotations

from ..controllers import Controller, Controllers, StepClock
from .autopilot import Autopilot
from .pid import CascadedPID
from .se3 import SE3Controller
from .trajectories import Circle, Hover, Lissajous, MinimumSnap

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
