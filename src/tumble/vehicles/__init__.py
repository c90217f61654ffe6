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

``params.py`` holds the parameter sets and the rotor layouts, ``mixer.py`` the :class:`Mixer`, ``quadrotor.py`` the
vehicle. Flight controllers and trajectories are in :mod:`tumble.control`.
"""

from __future__ import annotations

from .mixer import Mixer
from .params import CRAZYFLIE, HUMMINGBIRD, quadrotor_params, rotor_hubs
from .quadrotor import Quadrotor, quadrotors

__all__ = ["CRAZYFLIE", "HUMMINGBIRD", "Mixer", "Quadrotor", "quadrotor_params", "quadrotors", "rotor_hubs"]
