"""Body: a ``(world, row)`` view over the world's arrays, with no data of its own.

Getters return copies; setters validate and write the row. ``position`` is the body frame's origin (as
the user placed it); internally the state holds the centre of mass.
"""

from __future__ import annotations

import numpy as np

from ._validate import as_quaternion, as_vector3
from .rotation import quat_rotate, quat_to_matrix

__all__ = ["Body"]


class Body:
    """A rigid body of a :class:`~tumble.World` (dynamic or static)."""

    __slots__ = ("_world", "_index")

    def __init__(self, world, index: int):
        self._world = world
        self._index = index

    # --- identity -----------------------------------------------------------------------------------

    @property
    def index(self) -> int:
        """The body's row in the world's arrays."""
        return self._index

    @property
    def name(self) -> str | None:
        return self._world._builder.rows[self._index].name

    @property
    def is_static(self) -> bool:
        return self._world._builder.rows[self._index].mass_properties is None

    def _state(self):
        return self._world.state

    def _model(self):
        return self._world.model

    def _com_local(self) -> np.ndarray:
        return self._model().body_com_local[self._index]

    def _require_dynamic(self, what: str) -> None:
        """Refuse to move a static body; wake a sleeping one (with its island), since it is about to move."""
        if self.is_static:
            raise ValueError(f"{what}: body {self.name or self._index!r} is static and cannot move")
        s = self._state()
        if s.body_sleeping[self._index]:
            island = s.body_island == s.body_island[self._index]
            s.body_sleeping[island] = False
            s.body_sleep_time[island] = 0.0

    @property
    def sleeping(self) -> bool:
        """Whether the body sleeps (is at rest and not simulated until touched or pushed)."""
        return bool(self._state().body_sleeping[self._index])

    # --- pose and velocity --------------------------------------------------------------------------

    @property
    def position(self) -> np.ndarray:
        """The body frame's origin [m], world frame."""
        s = self._state()
        return s.body_pos[self._index] - quat_rotate(s.body_quat[self._index], self._com_local())

    @position.setter
    def position(self, value) -> None:
        value = as_vector3("position", value)
        self._require_dynamic("position")
        s = self._state()
        s.body_pos[self._index] = value + quat_rotate(s.body_quat[self._index], self._com_local())

    @property
    def orientation(self) -> np.ndarray:
        """Unit quaternion ``[w, x, y, z]``, body to world."""
        return self._state().body_quat[self._index].copy()

    @orientation.setter
    def orientation(self, value) -> None:
        """Rotate the body about its frame origin (which stays where it is)."""
        quat = as_quaternion("orientation", value)
        self._require_dynamic("orientation")
        origin = self.position
        s = self._state()
        s.body_quat[self._index] = quat
        s.body_pos[self._index] = origin + quat_rotate(quat, self._com_local())

    @property
    def rotation(self) -> np.ndarray:
        """The 3x3 rotation matrix, body to world."""
        return quat_to_matrix(self._state().body_quat[self._index])

    @property
    def center_of_mass(self) -> np.ndarray:
        """[m], world frame."""
        return self._state().body_pos[self._index].copy()

    @property
    def velocity(self) -> np.ndarray:
        """Velocity of the centre of mass [m/s], world frame."""
        return self._state().body_linvel[self._index].copy()

    @velocity.setter
    def velocity(self, value) -> None:
        value = as_vector3("velocity", value)
        self._require_dynamic("velocity")
        self._state().body_linvel[self._index] = value

    @property
    def angular_velocity(self) -> np.ndarray:
        """ω = R I⁻¹ Rᵀ L [rad/s], world frame (the state holds the angular momentum ``L``)."""
        r = self.rotation
        inv_inertia = self._model().body_inv_inertia_local[self._index]
        return r @ (inv_inertia @ (r.T @ self._state().body_angmom[self._index]))

    @angular_velocity.setter
    def angular_velocity(self, value) -> None:
        value = as_vector3("angular_velocity", value)
        self._require_dynamic("angular_velocity")
        self._state().body_angmom[self._index] = self.inertia_world @ value

    @property
    def angular_velocity_body(self) -> np.ndarray:
        """ω [rad/s] in the body frame, ``Rᵀ ω``."""
        return self.rotation.T @ self.angular_velocity

    def point_velocity(self, point) -> np.ndarray:
        """Velocity of the body-fixed point now at world ``point``: ``v + ω × (p − x_com)`` [m/s]."""
        point = as_vector3("point", point)
        s = self._state()
        return s.body_linvel[self._index] + np.cross(self.angular_velocity, point - s.body_pos[self._index])

    # --- mass ---------------------------------------------------------------------------------------

    @property
    def mass(self) -> float:
        """[kg]; 0 for a static body."""
        return float(self._model().body_mass[self._index])

    @property
    def inertia_body(self) -> np.ndarray:
        """Inertia tensor about the COM in the body frame [kg m²]."""
        return self._model().body_inertia_local[self._index].copy()

    @property
    def inertia_world(self) -> np.ndarray:
        """``R I Rᵀ`` [kg m²], about the COM."""
        r = self.rotation
        return r @ self._model().body_inertia_local[self._index] @ r.T

    @property
    def linear_momentum(self) -> np.ndarray:
        return self.mass * self.velocity

    @property
    def angular_momentum(self) -> np.ndarray:
        """``L = R I Rᵀ ω`` about the COM [kg m²/s], world frame."""
        return self._state().body_angmom[self._index].copy()

    @property
    def kinetic_energy(self) -> float:
        """½ m |v|² + ½ ω·L [J]."""
        v = self.velocity
        return float(0.5 * self.mass * v @ v + 0.5 * self.angular_velocity @ self.angular_momentum)

    # --- loads --------------------------------------------------------------------------------------

    def _lever(self, point) -> np.ndarray:
        if point is None:
            return np.zeros(3)
        return as_vector3("point", point) - self._state().body_pos[self._index]

    def apply_force(self, force, point=None) -> None:
        """Apply ``force`` [N] at world ``point`` (default the COM) during the next step only."""
        force = as_vector3("force", force)
        lever = self._lever(point)
        self._require_dynamic("apply_force")
        inputs = self._world.inputs
        inputs.body_force[self._index] += force
        inputs.body_torque[self._index] += np.cross(lever, force)

    def apply_torque(self, torque) -> None:
        """Apply ``torque`` [N m] (world frame) during the next step only."""
        torque = as_vector3("torque", torque)
        self._require_dynamic("apply_torque")
        self._world.inputs.body_torque[self._index] += torque

    def apply_impulse(self, impulse, point=None) -> None:
        """Change the momenta at once: ``Δp = J``, ``ΔL = r × J`` (so ``Δv = J / m``, ``Δω = I_w⁻¹ (r × J)``)."""
        impulse = as_vector3("impulse", impulse)
        lever = self._lever(point)
        self._require_dynamic("apply_impulse")
        s = self._state()
        s.body_linvel[self._index] += impulse * self._model().body_inv_mass[self._index]
        s.body_angmom[self._index] += np.cross(lever, impulse)

    def __eq__(self, other) -> bool:
        return isinstance(other, Body) and other._world is self._world and other._index == self._index

    def __hash__(self) -> int:
        return hash((id(self._world), self._index))

    def __repr__(self) -> str:
        kind = "static" if self.is_static else f"mass={self.mass:.6g}"
        label = f"{self.name!r}, " if self.name else ""
        return f"Body({label}#{self._index}, {kind}, position={np.round(self.position, 6).tolist()})"
