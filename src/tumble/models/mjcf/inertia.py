"""Mass properties of MJCF geoms and bodies, as MuJoCo's compiler computes them.

A geom's mass is ``density × volume`` unless its ``mass`` is given; it is a solid of uniform density. A body's
mass properties are its ``inertial`` element's, or (``compiler inertiafromgeom``: ``"auto"`` without an
``inertial``, or ``"true"``) the sum of its geoms' in ``inertiagrouprange``; then ``boundmass`` and
``boundinertia`` bound the mass and each principal moment from below. The solids' formulas are the textbook ones
(a capsule is a cylinder and two hemispheres, each moved by the parallel-axis theorem), in tumble's ``mass``
module.
"""

from __future__ import annotations

import numpy as np

from ... import mass as _mass
from ...mass import MassProperties

__all__ = ["VOLUME_TYPES", "bounded", "geom_mass_properties", "geom_volume"]

VOLUME_TYPES = ("sphere", "capsule", "cylinder", "ellipsoid", "box")


def geom_volume(kind: str, size: np.ndarray) -> float:
    """The volume of a primitive geom of MuJoCo's ``size`` (radius, half length, half sizes)."""
    r = size[0]
    if kind == "sphere":
        return 4.0 / 3.0 * np.pi * r**3
    if kind == "capsule":
        return np.pi * r**2 * 2.0 * size[1] + 4.0 / 3.0 * np.pi * r**3
    if kind == "cylinder":
        return np.pi * r**2 * 2.0 * size[1]
    if kind == "ellipsoid":
        return 4.0 / 3.0 * np.pi * size[0] * size[1] * size[2]
    return 8.0 * size[0] * size[1] * size[2]  # box


def geom_mass_properties(kind: str, size: np.ndarray, mass: float) -> MassProperties:
    """A primitive geom of ``mass`` in its own frame (centred, its axis along z)."""
    if kind == "sphere":
        return _mass.solid_sphere(size[0], mass=mass)
    if kind == "capsule":
        return _mass.capsule(size[0], 2.0 * size[1], mass=mass)
    if kind == "cylinder":
        return _mass.solid_cylinder(size[0], 2.0 * size[1], mass=mass)
    if kind == "ellipsoid":
        return _mass.solid_ellipsoid(*size, mass=mass)
    return _mass.box(2.0 * size, mass=mass)


def bounded(properties: MassProperties | None, boundmass: float, boundinertia: float) -> MassProperties | None:
    """``compiler boundmass``/``boundinertia``: the mass and each principal moment at least these."""
    if boundmass <= 0.0 and boundinertia <= 0.0:
        return properties
    if properties is None:
        if boundmass <= 0.0:
            return None
        return MassProperties(boundmass, np.zeros(3), boundinertia * np.eye(3))
    moments, axes = properties.principal()
    moments = np.maximum(moments, boundinertia)
    return MassProperties(max(properties.mass, boundmass), properties.com, axes @ np.diag(moments) @ axes.T)
