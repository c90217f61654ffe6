"""Mass properties of MJCF geoms and bodies, as MuJoCo's compiler computes them.

A geom's mass is ``density × volume`` unless its ``mass`` is given; it is a solid of uniform density, or with
``shellinertia`` a shell whose surface carries the mass (``density × area``; a box's six faces, a cylinder's side
and two discs, a capsule's side and two hemispheres). A body's
mass properties are its ``inertial`` element's, or (``compiler inertiafromgeom``: ``"auto"`` without an
``inertial``, or ``"true"``) the sum of its geoms' in ``inertiagrouprange``; then ``boundmass`` and
``boundinertia`` bound the mass and each principal moment from below. The solids' formulas are the textbook ones
(a capsule is a cylinder and two hemispheres, each moved by the parallel-axis theorem), in tumble's ``mass``
module.
"""

from __future__ import annotations

import numpy as np

from ... import mass as _mass
from ... import portable
from ...mass import MassProperties

__all__ = ["VOLUME_TYPES", "bounded", "geom_area", "geom_mass_properties", "geom_volume",
           "shell_mass_properties"]  # fmt: skip

VOLUME_TYPES = ("sphere", "capsule", "cylinder", "ellipsoid", "box")
# An ellipsoid's area has no closed form: MuJoCo takes Knud Thomsen's approximation (within 1.061 %) and spreads the
# mass as a layer of thickness 1 µm would (measured against MuJoCo 4's compiled masses and inertias).
_THOMSEN_P = 1.6075
_ELLIPSOID_LAYER = 1e-6  # [m]


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


def geom_area(kind: str, size: np.ndarray) -> float:
    """The surface area of a primitive geom (an ellipsoid's by Thomsen's approximation)."""
    r, h = size[0], size[1]
    if kind == "sphere":
        return 4.0 * np.pi * r**2
    if kind == "capsule":
        return 4.0 * np.pi * r * h + 4.0 * np.pi * r**2
    if kind == "cylinder":
        return 4.0 * np.pi * r * h + 2.0 * np.pi * r**2
    a, b, c = size
    if kind == "ellipsoid":
        p = _THOMSEN_P
        return 4.0 * np.pi * (((a * b) ** p + (a * c) ** p + (b * c) ** p) / 3.0) ** (1.0 / p)
    return 8.0 * (a * b + b * c + c * a)  # box


def shell_mass_properties(kind: str, size: np.ndarray, mass: float) -> MassProperties:
    """A primitive shell of ``mass`` in its own frame: each part's moments (thin plates, a thin tube, spherical
    shells, ``I = ⅔ m r²`` about a diameter) moved to the centre by the parallel-axis theorem."""
    rho = mass / geom_area(kind, size)
    r, h = size[0], size[1]
    if kind == "sphere":
        return MassProperties(mass, np.zeros(3), 2.0 / 3.0 * mass * r**2 * np.eye(3))
    if kind == "ellipsoid":  # the moments per unit mass of a thin layer: a difference of two solids
        inner, outer = (
            geom_mass_properties(kind, size + t, geom_volume(kind, size + t)) for t in (0, _ELLIPSOID_LAYER)
        )
        layer = outer.mass - inner.mass
        return MassProperties(mass, np.zeros(3), (outer.inertia - inner.inertia) * (mass / layer))
    if kind == "box":
        a, b, c = size
        side = np.array([a, b, c])
        pairs = 2.0 * rho * 4.0 * np.array([b * c, a * c, a * b])  # the mass of the two faces normal to x, y, z
        # row k: the mean of x², y², z² over the faces normal to axis k (at ±side there, uniform across)
        mean_square = np.tile(side**2 / 3.0, (3, 1))
        np.fill_diagonal(mean_square, side**2)
        second = portable.matvec(mean_square.T, pairs)  # ∫ x², ∫ y², ∫ z²
        moments = second.sum() - second
        return MassProperties(mass, np.zeros(3), np.diag(moments))
    side = rho * 4.0 * np.pi * r * h  # the tube of length 2h
    axial, transverse = side * r**2, side * (r**2 / 2.0 + h**2 / 3.0)
    if kind == "cylinder":
        discs = rho * 2.0 * np.pi * r**2
        axial, transverse = axial + discs * r**2 / 2.0, transverse + discs * (r**2 / 4.0 + h**2)
    else:  # capsule: two hemispherical shells, each centred r/2 from its rim at the tube's end
        caps = rho * 4.0 * np.pi * r**2
        axial, transverse = axial + caps * 2.0 / 3.0 * r**2, transverse + caps * (2.0 / 3.0 * r**2 + h**2 + h * r)
    return MassProperties(mass, np.zeros(3), np.diag([transverse, transverse, axial]))


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
    return MassProperties(max(properties.mass, boundmass), properties.com, portable.matmul(axes * moments, axes.T))
