"""ModelBuilder: the world's bodies and shapes as Python lists, packed into a :class:`Model` on demand.

The builder moves shape offsets once: the user places shapes relative to the body frame's origin, the
model stores them relative to the body's centre of mass (``body_pos`` in the state is the COM).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .geometry.packing import pack_geometry
from .mass import MassProperties
from .model import Model

__all__ = ["ModelBuilder", "ShapeSpec"]


@dataclass(frozen=True)
class ShapeSpec:
    """One shape of a body, placed in the body frame (relative to the frame origin)."""

    shape: object
    position: np.ndarray  # (3,) [m]
    quat: np.ndarray  # (4,) [w, x, y, z]
    friction: float
    restitution: float


@dataclass
class _BodyRow:
    mass_properties: MassProperties | None  # None: static
    shapes: list[ShapeSpec]
    linear_damping: float
    angular_damping: float
    name: str | None


@dataclass
class ModelBuilder:
    """Accumulates bodies; :meth:`finalize` packs them into structure-of-arrays."""

    rows: list[_BodyRow] = field(default_factory=list)

    @property
    def body_count(self) -> int:
        return len(self.rows)

    def add_body(
        self,
        mass_properties: MassProperties | None,
        shapes: list[ShapeSpec],
        *,
        linear_damping: float = 0.0,
        angular_damping: float = 0.0,
        name: str | None = None,
    ) -> int:
        """Append a body (``mass_properties=None`` for a static one); returns its row."""
        self.rows.append(_BodyRow(mass_properties, list(shapes), linear_damping, angular_damping, name))
        return len(self.rows) - 1

    def finalize(self, gravity: np.ndarray) -> Model:
        n = len(self.rows)
        mass = np.zeros(n)
        inertia = np.zeros((n, 3, 3))
        inv_inertia = np.zeros((n, 3, 3))
        com = np.zeros((n, 3))
        for i, row in enumerate(self.rows):
            mp = row.mass_properties
            if mp is not None:
                mass[i], com[i], inertia[i] = mp.mass, mp.com, mp.inertia
                inv_inertia[i] = np.linalg.inv(mp.inertia)
        is_dynamic = mass > 0.0
        inv_mass = np.divide(1.0, mass, out=np.zeros(n), where=is_dynamic)
        specs = [(i, s) for i, row in enumerate(self.rows) for s in row.shapes]
        return Model(
            gravity=np.array(gravity, dtype=np.float64),
            body_mass=mass,
            body_inv_mass=inv_mass,
            body_inertia_local=inertia,
            body_inv_inertia_local=inv_inertia,
            body_com_local=com,
            body_is_dynamic=is_dynamic,
            body_linear_damping=np.array([r.linear_damping for r in self.rows], dtype=np.float64),
            body_angular_damping=np.array([r.angular_damping for r in self.rows], dtype=np.float64),
            body_name=tuple(r.name for r in self.rows),
            geometry=pack_geometry(
                [s.shape for _, s in specs],
                [i for i, _ in specs],
                np.array([s.position - com[i] for i, s in specs], dtype=np.float64).reshape(-1, 3),
                np.array([s.quat for _, s in specs], dtype=np.float64).reshape(-1, 4),
            ),
            shape_friction=np.array([s.friction for _, s in specs], dtype=np.float64),
            shape_restitution=np.array([s.restitution for _, s in specs], dtype=np.float64),
            shapes=tuple(s.shape for _, s in specs),
        )
