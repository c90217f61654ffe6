"""Kinetic and potential energy of particles and rigid bodies placed by the generalised coordinates.

A rigid body is its mass properties (mass ``m``, centre of mass ``c`` and inertia ``I_c`` about it, all in
the body frame) plus the pose of its frame in the world: origin ``p(q, t)`` and rotation ``R(q, t)``
(body -> world). Then the centre of mass is at ``x_c = p + R c`` and

    K = ½ m v_c·v_c + ½ ω_bᵀ I_c ω_b,   P = -m g·x_c,

with ``v_c = d x_c / dt`` and the body-frame angular velocity ``ω̂_b = Rᵀ Ṙ`` (König's theorem: the
energy splits into the motion of the centre of mass and the rotation about it; course deck 004,
video 2.3 for ``ω̂``, video 2.4 for ``H_C = I_C ω``).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import sympy as sp

from ..mass import MassProperties
from ._checks import as_matrix3, as_scalar, as_vector, exact_number, show
from .kinematics import angular_velocity, functions_of_time, speed_squared

__all__ = ["Particle", "RigidBody", "kinetic_energy", "potential_energy", "DEFAULT_GRAVITY"]

DEFAULT_GRAVITY = (0.0, 0.0, -9.81)


class Particle:
    """A point mass ``mass`` [kg] at the world position ``position`` (3 expressions in ``q`` and ``t``)."""

    __slots__ = ("mass", "position", "name")

    def __init__(self, mass, position, *, name: str | None = None) -> None:
        self.mass = _as_mass(mass)
        self.position = as_vector("position", position)
        self.name = name

    @property
    def center_of_mass(self) -> sp.Matrix:
        """The world position of the mass (3 x 1)."""
        return self.position

    def kinetic_energy(self) -> sp.Expr:
        """``½ m v·v``."""
        return sp.Rational(1, 2) * self.mass * speed_squared(self.position)

    def potential_energy(self, gravity=DEFAULT_GRAVITY) -> sp.Expr:
        """``-m g·x`` (zero at the world origin)."""
        g = as_vector("gravity", gravity)
        return -self.mass * (g.T * self.position)[0, 0]

    def __repr__(self) -> str:
        return f"Particle(mass={self.mass}, position={list(self.position)})"


class RigidBody:
    """A rigid body whose frame is at ``position`` and turned by ``rotation`` in the world.

    Args:
        mass_properties: a :class:`tumble.MassProperties` in the body frame, or a tumble shape together
            with exactly one of ``mass=`` or ``density=`` (its mass properties about the shape frame).
        position: the world position of the body frame's origin: 3 SymPy expressions in the coordinates
            (and the time).
        rotation: the body -> world rotation, a 3x3 SymPy matrix in the coordinates; default identity
            (a body that only translates).
        mass, density: only with a shape.
        name: optional label.

    For symbolic mass and inertia (a textbook derivation), use :meth:`RigidBody.symbolic`.
    """

    __slots__ = ("mass", "com", "inertia", "position", "rotation", "name")

    def __init__(self, mass_properties, position, rotation=None, *, mass=None, density=None, name=None) -> None:
        properties = _as_mass_properties(mass_properties, mass, density)
        self.mass = exact_number(properties.mass, properties.mass)
        self.com = sp.Matrix(_numbers(properties.com))
        self.inertia = sp.Matrix(3, 3, _numbers(properties.inertia.ravel()))
        self.position = as_vector("position", position)
        self.rotation = sp.eye(3) if rotation is None else as_matrix3("rotation", rotation)
        self.name = name

    @classmethod
    def symbolic(cls, mass, inertia, position, rotation=None, *, com=(0, 0, 0), name=None) -> RigidBody:
        """A body with SymPy (or numeric) mass, inertia about the centre of mass and centre of mass.

        Args:
            mass: scalar.
            inertia: 3x3 about the centre of mass, body-frame axes (a 3-sequence is the diagonal).
            position, rotation, name: as for the constructor.
            com: the centre of mass in the body frame (3 entries); default the frame's origin.
        """
        body = object.__new__(cls)
        body.mass = _as_mass(mass)
        if not isinstance(inertia, sp.MatrixBase) and np.ndim(np.asarray(inertia, dtype=object)) == 1:
            inertia = sp.diag(*as_vector("inertia", inertia))
        body.inertia = as_matrix3("inertia", inertia)
        if body.inertia != body.inertia.T:
            raise ValueError(f"inertia must be symmetric, got {body.inertia.tolist()}")
        body.com = as_vector("com", com)
        body.position = as_vector("position", position)
        body.rotation = sp.eye(3) if rotation is None else as_matrix3("rotation", rotation)
        body.name = name
        return body

    @property
    def center_of_mass(self) -> sp.Matrix:
        """``x_c = p + R c``: the world position of the centre of mass (3 x 1)."""
        return self.position + self.rotation * self.com

    def kinetic_energy(self) -> sp.Expr:
        """``½ m v_c·v_c + ½ ω_bᵀ I_c ω_b``."""
        translation = sp.Rational(1, 2) * self.mass * speed_squared(self.center_of_mass)
        if self.rotation == sp.eye(3) or self.inertia.is_zero_matrix:
            return translation
        # every function of time in R moves it: the coordinates and any prescribed motion
        omega = angular_velocity(self.rotation, functions_of_time(self.rotation), frame="body")
        rotation = sp.Rational(1, 2) * (omega.T * self.inertia * omega)[0, 0]
        return translation + rotation

    def potential_energy(self, gravity=DEFAULT_GRAVITY) -> sp.Expr:
        """``-m g·x_c`` (zero with the centre of mass at the world origin)."""
        g = as_vector("gravity", gravity)
        return -self.mass * (g.T * self.center_of_mass)[0, 0]

    def __repr__(self) -> str:
        label = f"{self.name!r}, " if self.name else ""
        return f"RigidBody({label}mass={self.mass}, position={list(self.position)})"


def kinetic_energy(bodies) -> sp.Expr:
    """The total kinetic energy of a sequence of :class:`Particle` and :class:`RigidBody`."""
    items = _as_bodies(bodies)
    return sp.Add(*[body.kinetic_energy() for body in items])


def potential_energy(bodies, gravity=DEFAULT_GRAVITY) -> sp.Expr:
    """The total gravitational potential energy ``-Σ m g·x_c`` of a sequence of bodies."""
    items = _as_bodies(bodies)
    return sp.Add(*[body.potential_energy(gravity) for body in items])


def _as_bodies(bodies) -> list:
    if isinstance(bodies, (Particle, RigidBody)):
        return [bodies]
    if isinstance(bodies, (str, bytes)) or not isinstance(bodies, Iterable):
        raise TypeError(f"bodies must be a sequence of Particle or RigidBody, got {show(bodies)}")
    items = list(bodies)
    if not items:
        raise ValueError("bodies must hold at least one Particle or RigidBody, got an empty sequence")
    for i, item in enumerate(items):
        if not isinstance(item, (Particle, RigidBody)):
            hint = " (wrap it: lagrange.RigidBody(mass_properties, position, rotation))"
            if not isinstance(item, MassProperties):
                hint = ""
            raise TypeError(
                f"bodies[{i}] must be a lagrange.Particle or lagrange.RigidBody, got {show(item)} "
                f"({type(item).__name__}){hint}"
            )
    return items


def _as_mass(mass) -> sp.Expr:
    value = as_scalar("mass", mass)
    if value.is_number and not value > 0:
        raise ValueError(f"mass must be > 0, got {value}")
    if value.is_nonpositive:
        raise ValueError(f"mass must be > 0, got {value} (a symbol declared non-positive)")
    return value


def _as_mass_properties(value, mass, density) -> MassProperties:
    if isinstance(value, MassProperties):
        if mass is not None or density is not None:
            raise TypeError("mass= and density= go with a shape, not with a MassProperties (it has its mass)")
        return value
    if hasattr(value, "mass_properties") and callable(value.mass_properties):
        return value.mass_properties(mass=mass, density=density)
    raise TypeError(
        "mass_properties must be a tumble MassProperties, or a shape with mass= or density=, "
        f"got {show(value)} ({type(value).__name__}); for symbolic mass use RigidBody.symbolic"
    )


def _numbers(values) -> list:
    """Floats as SymPy numbers, round-off (relative to the largest of them) snapped to exact integers."""
    scale = max((abs(float(x)) for x in values), default=0.0) or 1.0
    return [exact_number(float(x), scale) for x in values]
