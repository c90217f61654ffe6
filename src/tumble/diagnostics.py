"""Energy and momentum of many bodies at once, vectorised over leading (frame, body) dimensions.

Shared by :class:`~tumble.World` (one instant) and :class:`~tumble.Trajectory` (every recorded frame).
``pos`` is the centre of mass; ``omega``, ``angmom`` (spin angular momentum about the COM) and the momenta
are world-frame vectors.
"""

from __future__ import annotations

import numpy as np

from .rotation import quat_conjugate, quat_rotate, quat_to_matrix

__all__ = ["kinetic_energy", "potential_energy", "linear_momentum", "angular_momentum", "world_tensor_apply"]


def world_tensor_apply(tensor_local: np.ndarray, quat: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """``R T Rᵀ v`` per body for body-frame tensors ``T`` (n, 3, 3): ``L`` from ``ω`` with the inertia,
    ``ω`` from ``L`` with its inverse. (..., n, 3).

    With every component of ``v`` under 1e150 the rotations go through one batch of matrices (0.1 ms for the
    humanoid's 20 bodies, a quarter of two validated quaternion rotations, which a joint actuator pays every step);
    larger vectors take ``quat_rotate``, which scales them so that no rotation overflows on the way."""
    vector = np.asarray(vector, dtype=np.float64)
    if vector.size and np.abs(vector).max() < 1e150:
        rotation = quat_to_matrix(quat)
        vector_body = np.einsum("...ji,...j->...i", rotation, vector)
        return np.einsum("...ij,...j->...i", rotation, np.einsum("nij,...nj->...ni", tensor_local, vector_body))
    vector_body = quat_rotate(quat_conjugate(quat), vector)
    return quat_rotate(quat, np.einsum("nij,...nj->...ni", tensor_local, vector_body))


def kinetic_energy(mass, velocity, omega, angmom) -> np.ndarray:
    """``½ m |v|² + ½ ω·L`` per body: (..., n) [J]."""
    translational = 0.5 * mass * np.einsum("...i,...i->...", velocity, velocity)
    return translational + 0.5 * np.einsum("...i,...i->...", omega, angmom)


def potential_energy(mass, pos, gravity) -> np.ndarray:
    """Uniform gravity: ``−m g·x`` per body (zero at the origin): (..., n) [J]."""
    return -mass * (pos @ np.asarray(gravity, dtype=np.float64))


def linear_momentum(mass, velocity) -> np.ndarray:
    """``Σ m v``: (..., 3) [kg m/s]."""
    return np.einsum("n,...ni->...i", mass, velocity)


def angular_momentum(mass, pos, velocity, angmom, point) -> np.ndarray:
    """``Σ (x − p) × m v + L`` about ``point``, with ``L`` each body's spin about its COM: (..., 3) [kg m²/s]."""
    orbital = np.cross(pos - np.asarray(point, dtype=np.float64), mass[:, None] * velocity)
    return (orbital + angmom).sum(axis=-2)
