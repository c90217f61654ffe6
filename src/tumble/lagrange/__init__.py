"""Lagrangian mechanics in generalised coordinates, with SymPy: equations, statics and simulation.

The course (``course/004_…``) builds Lagrange's equations from virtual work and D'Alembert's principle;
this package does the same with ``sympy.physics.mechanics``:

- :class:`System`: Lagrange's equations ``d/dt ∂L/∂q̇ - ∂L/∂q = Q - Φ_qᵀ λ`` from a Lagrangian, with
  non-conservative forces and holonomic constraints; :meth:`System.from_bodies` builds ``L = K - P``
  from :class:`Particle` and :class:`RigidBody` (tumble mass properties) placed by the coordinates.
- Numerics: :meth:`System.lambdify` and :meth:`System.simulate` (``solve_ivp``, Baumgarte-stabilised
  constraints), :meth:`System.energy`.
- Statics by virtual work: :func:`virtual_work`, :meth:`System.generalized_forces`,
  :meth:`System.equilibrium`, :meth:`System.balancing`.
- :func:`from_articulation`: the same equations for a ``tumble.Articulation`` of revolute and
  prismatic joints.

``import tumble`` does not import SymPy; ``import tumble.lagrange`` does. See ``docs/lagrange.md``.

>>> import sympy as sp
>>> from tumble import lagrange
>>> theta = lagrange.dynamicsymbols("theta")
>>> m, g, l = sp.symbols("m g l", positive=True)
>>> bob = lagrange.Particle(m, (l * sp.sin(theta), 0, -l * sp.cos(theta)))
>>> pendulum = lagrange.System.from_bodies(theta, [bob], gravity=(0, 0, -g))
>>> pendulum.accelerations()
Matrix([[-g*sin(theta(t))/l]])
"""

from __future__ import annotations

from sympy.physics.mechanics import dynamicsymbols

from .articulation import from_articulation
from .bodies import Particle, RigidBody, kinetic_energy, potential_energy
from .kinematics import (
    angular_velocity,
    jacobian,
    rotation_about,
    rotation_x,
    rotation_y,
    rotation_z,
    skew,
    vee,
    velocity,
)
from .loads import Force, Torque, virtual_work
from .numeric import Motion, NumericSystem
from .system import System

__all__ = [
    "Force",
    "Motion",
    "NumericSystem",
    "Particle",
    "RigidBody",
    "System",
    "Torque",
    "angular_velocity",
    "dynamicsymbols",
    "from_articulation",
    "jacobian",
    "kinetic_energy",
    "potential_energy",
    "rotation_about",
    "rotation_x",
    "rotation_y",
    "rotation_z",
    "skew",
    "vee",
    "velocity",
    "virtual_work",
]
