"""Building a world: the checks and conversions behind ``World.add_body`` and ``World.add_static`` (shapes and
their frames, materials, mass properties from shapes or given), a room of :class:`~tumble.World`."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from . import diagnostics
from ._validate import as_float, as_quaternion, as_vector3, mass_or_density
from .builder import ShapeSpec
from .mass import MassProperties
from .params import INTEGRATOR_NAMES
from .shapes import Plane, Shape, TriMesh

__all__ = [
    "NO_ROTATION",
    "ORIGIN",
    "body_mass_properties",
    "check_dynamic_shapes",
    "check_integrator",
    "checked_name",
    "explicit_mass_properties",
    "shape_items",
    "vector_or_origin",
    "world_apply",
]

_IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
# add_body's defaults: an argument left at one of them skips its validation (bodies are added by the 100 000).
ORIGIN, NO_ROTATION = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)


def vector_or_origin(name: str, value) -> np.ndarray:
    return np.zeros(3) if value is ORIGIN else as_vector3(name, value)


def world_apply(tensor: np.ndarray, quat: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """``R T Rᵀ v`` for one body, inf where it overflows (the caller refuses it by the argument's name)."""
    with np.errstate(over="ignore", invalid="ignore"):
        try:
            return diagnostics.world_tensor_apply(tensor[None], quat[None], vector[None])[0]
        except ValueError:  # quat_rotate refused the overflowed T Rᵀv
            return np.full(3, np.inf)


def check_integrator(integrator) -> str:
    names = ("auto", *INTEGRATOR_NAMES)
    if not isinstance(integrator, str) or integrator not in names:
        raise ValueError(f"integrator must be one of {names}, got {integrator!r}")
    return integrator


def check_dynamic_shapes(shape) -> None:
    """Refuse planes and meshes in a dynamic body: a plane has no mass, and the contact kernels collide meshes as
    fixed geometry only (convex shapes against a mesh, never a mesh against a mesh or a plane)."""
    if shape is None:
        return
    items = (
        [("shape", shape)] if isinstance(shape, Shape) else [(f"shape[{k}]", item[0]) for k, item in enumerate(shape)]
    )
    for label, item in items:
        if isinstance(item, (Plane, TriMesh)):
            kind = type(item).__name__
            raise ValueError(
                f"{label} cannot be a {kind} in a dynamic body: a {kind} can only be static (use world.add_static, "
                f"or a ConvexHull for a dynamic body), got {item!r}"
            )


def shape_items(shape, material: tuple[float, float, float], group: int = 1, mask: int = 0xFFFFFFFF
                 ) -> list[ShapeSpec]:  # fmt: skip
    """``None``, one shape, or a list of ``(shape, position[, orientation])`` in the body frame; ``material`` is
    ``(friction, restitution, rolling_resistance)``."""
    if shape is None:
        return []
    if isinstance(shape, Shape):
        return [ShapeSpec(shape, np.zeros(3), _IDENTITY.copy(), *material, group=group, mask=mask)]
    if not isinstance(shape, Sequence) or isinstance(shape, str) or len(shape) == 0:
        raise TypeError(
            f"shape must be a Shape, a non-empty list of (shape, position[, orientation]) or None, got {shape!r}"
        )
    items = []
    for k, item in enumerate(shape):
        if not isinstance(item, Sequence) or len(item) not in (2, 3) or not isinstance(item[0], Shape):
            raise TypeError(f"shape[{k}] must be (shape, position[, orientation]), got {item!r}")
        position = as_vector3(f"shape[{k}] position", item[1])
        quat = as_quaternion(f"shape[{k}] orientation", item[2]) if len(item) == 3 else _IDENTITY.copy()
        items.append(ShapeSpec(item[0], position, quat, *material, group=group, mask=mask))
    return items


def body_mass_properties(items: list[ShapeSpec], mass, density, inertia) -> MassProperties:
    """Mass properties in the body frame: from the shapes (``mass=`` spread by volume) or explicit."""
    if not items:
        if density is not None:
            raise ValueError(f"density={density!r} needs a shape; a body without geometry takes mass= and inertia=")
        if mass is None or inertia is None:
            raise ValueError(
                "a body without geometry (shape=None) needs both mass= and inertia=, "
                f"got mass={mass!r}, inertia={inertia!r}"
            )
        return MassProperties(as_float("mass", mass, positive=True), np.zeros(3), inertia)
    kind, value = mass_or_density(mass, density)
    per_volume = value if kind == "density" else 1.0
    mp = _placed_mass_properties(items[0], per_volume)
    for item in items[1:]:
        mp = mp + _placed_mass_properties(item, per_volume)
    if kind == "mass":
        mp = mp.scaled_to(value)
    if inertia is not None:
        mp = MassProperties(mp.mass, mp.com, inertia)
    return mp


def _placed_mass_properties(item: ShapeSpec, density: float) -> MassProperties:
    """One shape's mass properties in the body frame (as given when the shape frame is the body frame: most
    bodies, and moving them would only cost time)."""
    shape = item.shape
    mp = shape._unit_mass_properties() if density == 1.0 else shape.mass_properties(density=density)
    if (item.quat == _IDENTITY).all() and not item.position.any():
        return mp
    return mp.transformed(rotation=item.quat, translation=item.position)


def explicit_mass_properties(mass_properties, mass, density, inertia) -> MassProperties | None:
    if mass_properties is None:
        return None
    if not isinstance(mass_properties, MassProperties):
        raise TypeError(
            f"mass_properties must be a tumble.MassProperties, got {mass_properties!r} "
            f"({type(mass_properties).__name__})"
        )
    if mass is not None or density is not None or inertia is not None:
        raise ValueError(
            f"mass_properties= replaces mass=, density= and inertia=; got mass={mass!r}, density={density!r}, "
            f"inertia={'given' if inertia is not None else None}"
        )
    if not mass_properties.mass > 0.0:
        raise ValueError(f"mass_properties must have a positive mass for a dynamic body, got {mass_properties.mass!r}")
    return mass_properties


def checked_name(builder, name) -> str | None:
    """``name`` checked as a new body's: None, or a non-empty string without NUL that no body of ``builder`` has."""
    if name is None:
        return None
    if not isinstance(name, str) or not name:
        raise TypeError(f"name must be a non-empty string or None, got {name!r}")
    if "\x00" in name:
        raise ValueError(f"name must not hold a NUL character (HDF5 strings end there), got {name!r}")
    if builder.index_of(name) is not None:
        raise ValueError(f"name must be unique in the world, {name!r} is already taken")
    return name
