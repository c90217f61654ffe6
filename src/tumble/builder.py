"""ModelBuilder: the world's bodies and shapes as Python lists, packed into a :class:`Model` on demand.

The builder moves shape offsets once: the user places shapes relative to the body frame's origin, the
model stores them relative to the body's centre of mass (``body_pos`` in the state is the COM).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import portable
from .dynamics.joint_solver import JointArrays
from .geometry.broad_phase import exclusion_table
from .geometry.packing import pack_geometry
from .mass import MassProperties
from .model import Model
from .shapes import ShapeType

__all__ = ["JointSpec", "ModelBuilder", "ShapeSpec"]


_ZERO3, _ZERO33 = np.zeros(3), np.zeros((3, 3))  # a static body's COM and inertia in the model's arrays


@dataclass(frozen=True, slots=True)  # slots: a world holds one per shape, and fewer objects for the GC to walk
class ShapeSpec:
    """One shape of a body, placed in the body frame (relative to the frame origin)."""

    shape: object
    position: np.ndarray  # (3,) [m]
    quat: np.ndarray  # (4,) [w, x, y, z]
    friction: float
    restitution: float
    rolling_resistance: float = 0.0  # coefficient c: torque c N r opposes rolling (r: the shape's radius)
    group: int = 1  # collision filter bits: a and b collide iff (group_a & mask_b) and (group_b & mask_a)
    mask: int = 0xFFFFFFFF


@dataclass(slots=True)
class JointSpec:
    """One joint in body-frame terms (body -1: the world); ``drive`` is mutable (motor speed and the like)."""

    kind: int
    body_a: int
    body_b: int
    local_anchor_a: np.ndarray  # (3,) anchor minus a's COM, a's frame
    local_anchor_b: np.ndarray  # (3,)
    local_frame_a: np.ndarray  # (4,) joint frame (x: axis) in a's frame
    local_frame_b: np.ndarray  # (4,)
    drive: np.ndarray  # (9,) see joint_solver.JointArrays
    collide_connected: bool
    to_world: bool = False  # the user's ``b`` was None: the world is body_a (-1) and the user's ``a`` is body_b


@dataclass(slots=True)
class _BodyRow:
    mass_properties: MassProperties | None  # None: static
    shapes: list[ShapeSpec]
    linear_damping: float
    angular_damping: float
    name: str | None
    constant_force: np.ndarray = field(default_factory=lambda: np.zeros(3))  # [N] world frame, at the COM
    constant_torque: np.ndarray = field(default_factory=lambda: np.zeros(3))  # [N m] world frame


@dataclass
class ModelBuilder:
    """Accumulates bodies; :meth:`finalize` packs them into structure-of-arrays."""

    rows: list[_BodyRow] = field(default_factory=list)
    joints: list[JointSpec] = field(default_factory=list)

    def __post_init__(self) -> None:
        # Name -> row, so that checking a new name and finding a body stay O(1) (not a field: derived from rows).
        self._names = {row.name: i for i, row in enumerate(self.rows) if row.name is not None}

    @property
    def body_count(self) -> int:
        return len(self.rows)

    def index_of(self, name: str) -> int | None:
        """The row of the body called ``name``, or None."""
        return self._names.get(name)

    @property
    def names(self) -> list[str]:
        return list(self._names)

    def mass_row(self, index: int) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
        """``(mass, com, inertia, inv_inertia)`` of one body, body frame, as :meth:`finalize` packs them (zeros for a
        static body): what a handle reads before the model is built."""
        mp = self.rows[index].mass_properties
        if mp is None:
            return 0.0, np.zeros(3), np.zeros((3, 3)), np.zeros((3, 3))
        return float(mp.mass), np.asarray(mp.com, np.float64), mp.inertia, portable.inverse(mp.inertia)

    def add_body(
        self,
        mass_properties: MassProperties | None,
        shapes: list[ShapeSpec],
        *,
        linear_damping: float = 0.0,
        angular_damping: float = 0.0,
        name: str | None = None,
    ) -> int:
        """Append a body (``mass_properties=None`` for a static one); returns its row. ``shapes`` is kept, not
        copied: the caller hands over a list of its own."""
        self.rows.append(_BodyRow(mass_properties, shapes, linear_damping, angular_damping, name))
        if name is not None:
            self._names[name] = len(self.rows) - 1
        return len(self.rows) - 1

    def add_joint(self, spec: JointSpec) -> int:
        self.joints.append(spec)
        return len(self.joints) - 1

    def _joint_arrays(self) -> tuple[JointArrays, np.ndarray]:
        if not self.joints:
            return JointArrays.empty(), np.zeros((0, 2), np.int64)
        specs = self.joints
        arrays = JointArrays(
            np.array([s.kind for s in specs], np.int64),
            np.array([s.body_a for s in specs], np.int64),
            np.array([s.body_b for s in specs], np.int64),
            np.array([s.local_anchor_a for s in specs], np.float64),
            np.array([s.local_anchor_b for s in specs], np.float64),
            np.array([s.local_frame_a for s in specs], np.float64),
            np.array([s.local_frame_b for s in specs], np.float64),
            np.array([s.drive for s in specs], np.float64),
        )
        pairs = [(s.body_a, s.body_b) for s in specs if not s.collide_connected and min(s.body_a, s.body_b) >= 0]
        return arrays, exclusion_table(np.array(pairs, np.int64).reshape(-1, 2))

    def finalize(self, gravity: np.ndarray) -> Model:
        n = len(self.rows)
        mps = [row.mass_properties for row in self.rows]
        mass = np.array([0.0 if mp is None else mp.mass for mp in mps], np.float64)
        com = np.array([_ZERO3 if mp is None else mp.com for mp in mps], np.float64).reshape(n, 3)
        inertia = np.array([_ZERO33 if mp is None else mp.inertia for mp in mps], np.float64).reshape(n, 3, 3)
        inv_inertia = np.zeros((n, 3, 3))
        is_dynamic = mass > 0.0
        inv_inertia[is_dynamic] = portable.inverse(inertia[is_dynamic])  # as mass_row inverts one
        inv_mass = np.divide(1.0, mass, out=np.zeros(n), where=is_dynamic)
        specs = [(i, s) for i, row in enumerate(self.rows) for s in row.shapes]
        shape_body = np.array([i for i, _ in specs], np.int64)
        geometry = pack_geometry(
            [s.shape for _, s in specs],
            shape_body,
            np.array([s.position for _, s in specs], np.float64).reshape(-1, 3) - com[shape_body],
            np.array([s.quat for _, s in specs], np.float64).reshape(-1, 4),
        )
        # The radius a shape rolls on (sphere, capsule, cylinder) and the one swept round a sphere's centre or a
        # capsule's segment: the first of their params; 0 for the other shapes.
        radius, kind = geometry.shape_params[:, 0], geometry.shape_type
        rolls = np.isin(kind, (ShapeType.SPHERE, ShapeType.CAPSULE, ShapeType.CYLINDER))
        swept = np.isin(kind, (ShapeType.SPHERE, ShapeType.CAPSULE))
        joints, joint_exclusions = self._joint_arrays()
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
            geometry=geometry,
            shape_friction=np.array([s.friction for _, s in specs], dtype=np.float64),
            shape_restitution=np.array([s.restitution for _, s in specs], dtype=np.float64),
            shape_rolling=np.array([s.rolling_resistance for _, s in specs], np.float64) * np.where(rolls, radius, 0.0),
            shape_core_radius=np.where(swept, radius, 0.0),
            shape_group=np.array([s.group for _, s in specs], dtype=np.uint32),
            shape_mask=np.array([s.mask for _, s in specs], dtype=np.uint32),
            has_contacts=_contacts_possible(specs, is_dynamic),
            shapes=tuple(s.shape for _, s in specs),
            body_constant_force=np.array([r.constant_force for r in self.rows], np.float64).reshape(n, 3),
            body_constant_torque=np.array([r.constant_torque for r in self.rows], np.float64).reshape(n, 3),
            joints=joints,
            joint_exclusions=joint_exclusions,
        )


def _contacts_possible(specs: list[tuple[int, ShapeSpec]], is_dynamic: np.ndarray) -> bool:
    """Whether two shapes of different bodies, one of them dynamic, may pass each other's filter.

    Works on the few distinct (group, mask) classes rather than on shape pairs, so it stays linear; it may
    over-approximate when the only such pairs are between two static bodies (the broad phase skips those).
    """
    classes: dict[tuple[int, int], tuple[set[int], bool]] = {}
    for i, s in specs:
        bodies, dynamic = classes.get((s.group, s.mask), (set(), False))
        bodies.add(i)
        classes[(s.group, s.mask)] = (bodies, dynamic or bool(is_dynamic[i]))
    keys = list(classes)
    for k, (group_a, mask_a) in enumerate(keys):
        for group_b, mask_b in keys[k:]:
            bodies_a, dynamic_a = classes[(group_a, mask_a)]
            bodies_b, dynamic_b = classes[(group_b, mask_b)]
            if (group_a & mask_b) and (group_b & mask_a) and (dynamic_a or dynamic_b) and len(bodies_a | bodies_b) > 1:
                return True
    return False
