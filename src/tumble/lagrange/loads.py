"""Applied loads and their generalised forces by the principle of virtual work.

The course (``course/004_…``, video 2.1) defines the virtual work of the applied forces through a
virtual displacement, a small displacement consistent with the constraints. With generalised
coordinates ``q`` the displacement of a point ``r_i(q, t)`` is ``δr_i = Σ_j ∂r_i/∂q_j δq_j`` (time held
fixed), so

    δW = Σ_i F_i · δr_i + Σ_k τ_k · δθ_k = Σ_j Q_j δq_j,
    Q_j = Σ_i F_i · ∂r_i/∂q_j + Σ_k τ_k · vee(∂R_k/∂q_j R_kᵀ),

``Q = Σ J_iᵀ F_i`` with ``J_i`` the Jacobian of the point. A torque ``τ`` on a frame ``R(q, t)`` works
through the frame's virtual rotation ``δθ`` (world components, ``δθ̂ = δR Rᵀ``).
"""

from __future__ import annotations

from collections.abc import Iterable

import sympy as sp

from ._checks import as_coordinates, as_matrix3, as_scalar, as_vector, check_no_accelerations, show
from .kinematics import angular_jacobian, jacobian

__all__ = ["Force", "Torque", "virtual_work", "generalized_forces_of"]


class Force:
    """A force ``vector`` (world components [N]) applied at the point ``point`` (world position [m]).

    Both are 3 SymPy expressions (or numbers) in the coordinates, the time and any symbols.
    """

    __slots__ = ("point", "vector")

    def __init__(self, point, vector) -> None:
        self.point = as_vector("point", point)
        self.vector = as_vector("vector", vector)

    def __repr__(self) -> str:
        return f"Force(point={list(self.point)}, vector={list(self.vector)})"


class Torque:
    """A torque ``vector`` (world components [N m]) acting on the frame of rotation ``rotation`` (3x3).

    ``rotation`` is the body -> world rotation of the frame the torque acts on, in the coordinates.
    """

    __slots__ = ("rotation", "vector")

    def __init__(self, rotation, vector) -> None:
        self.rotation = as_matrix3("rotation", rotation)
        self.vector = as_vector("vector", vector)

    def __repr__(self) -> str:
        return f"Torque(rotation={self.rotation.tolist()}, vector={list(self.vector)})"


def virtual_work(coordinates, loads) -> sp.Matrix:
    """The generalised forces ``Q`` (n x 1) of a list of :class:`Force` and :class:`Torque` loads.

    ``Q_j = Σ F_i · ∂r_i/∂q_j + Σ τ_k · vee(∂R_k/∂q_j R_kᵀ)``: the coefficient of ``δq_j`` in the virtual
    work (course deck 004, "Virtual Work").

    >>> import sympy as sp
    >>> from sympy.physics.mechanics import dynamicsymbols
    >>> theta = dynamicsymbols("theta")
    >>> l, P = sp.symbols("l P")
    >>> virtual_work([theta], [Force((l * sp.sin(theta), 0, -l * sp.cos(theta)), (P, 0, 0))])
    Matrix([[P*l*cos(theta(t))]])
    """
    coords = as_coordinates(coordinates)
    total = sp.zeros(len(coords), 1)
    for load in _as_load_list("loads", loads):
        if isinstance(load, Force):
            total += jacobian(load.point, coords).T * load.vector
        else:
            J_omega, _ = angular_jacobian(load.rotation, coords, frame="world")
            total += J_omega.T * load.vector
    return total


def generalized_forces_of(name: str, forces, coordinates) -> sp.Matrix:
    """``forces`` given either as n generalised forces aligned with the coordinates, or as loads.

    Returns the n x 1 generalised-force column (zeros when ``forces`` is None).
    """
    n = len(coordinates)
    if forces is None:
        return sp.zeros(n, 1)
    items = _as_list(name, forces)
    if items and all(isinstance(item, (Force, Torque)) for item in items):
        Q = virtual_work(coordinates, items)
    elif any(isinstance(item, (Force, Torque)) for item in items):
        raise TypeError(
            f"{name} must be either n generalised forces or a list of Force/Torque loads, not a mix: {show(items)}"
        )
    else:
        if len(items) != n:
            raise ValueError(
                f"{name} must hold one generalised force per coordinate ({n}), got {len(items)}: {show(items)}"
            )
        Q = sp.Matrix([as_scalar(f"{name}[{j}]", item) for j, item in enumerate(items)])
    for j, entry in enumerate(Q):
        check_no_accelerations(f"{name} (generalised force {j})", entry, coordinates)
    return Q


def _as_list(name: str, value) -> list:
    if isinstance(value, sp.MatrixBase):
        return list(value)
    if isinstance(value, (Force, Torque)):
        return [value]
    if isinstance(value, (str, bytes, sp.Basic)) or not isinstance(value, Iterable):
        raise TypeError(f"{name} must be a list of generalised forces or of Force/Torque loads, got {show(value)}")
    return list(value)


def _as_load_list(name: str, loads) -> list:
    items = _as_list(name, loads)
    for i, item in enumerate(items):
        if not isinstance(item, (Force, Torque)):
            raise TypeError(f"{name}[{i}] must be a Force or a Torque, got {show(item)} ({type(item).__name__})")
    return items
