"""Collision shapes: immutable value objects in their own (shape) frame.

Every shape carries the data the kernels will need in structure-of-arrays form, so that a world's
shapes pack into ``shape_type (n,)``, ``shape_params (n, 4)`` and one concatenated vertex array (plus a
face array) addressed by a start and a count per shape:

=======================  =======================  =======================================================
shape                    ``params`` (4,)          geometry in the shape frame
=======================  =======================  =======================================================
``Sphere(radius)``       ``(r, 0, 0, 0)``         centred at the origin
``Capsule(r, length)``   ``(r, length/2, 0, 0)``  segment ``z ∈ [-length/2, length/2]`` swept by ``r``
``Box(extents)``         ``(hx, hy, hz, 0)``      HALF extents; ``extents`` are full edge lengths
``Cylinder(r, height)``  ``(r, height/2, 0, 0)``  axis z, centred
``ConvexHull(points)``   zeros                    ``vertices (v, 3)``, outward ``faces (f, 3)``
``Plane(normal, off)``   ``(nx, ny, nz, off)``    the points ``n · x = off``; solid side ``n · x <= off``
``TriMesh(v, f)``        zeros                    ``vertices (v, 3)``, ``faces (f, 3)`` as given
=======================  =======================  =======================================================

:class:`ShapeType` numbers the kinds; a collision kernel for a pair is ``collide_<a>_<b>`` with the lower
type first, and new kinds are appended at the end. Mass properties come from :mod:`tumble.mass` and are
expressed in the shape frame.
"""

from __future__ import annotations

import math
from enum import IntEnum

import numpy as np

from . import mass as _mass
from . import portable
from ._validate import _show, as_array, as_float, as_unit_vector3, as_vector3

__all__ = [
    "ShapeType",
    "Shape",
    "Sphere",
    "Capsule",
    "Box",
    "Cylinder",
    "ConvexHull",
    "Plane",
    "TriMesh",
]


class ShapeType(IntEnum):
    """The kinds of shape, as stored in ``shape_type``. Append new kinds at the end only."""

    SPHERE = 0
    CAPSULE = 1
    BOX = 2
    CYLINDER = 3
    CONVEX_HULL = 4
    PLANE = 5
    TRIMESH = 6


def _frozen(values) -> np.ndarray:
    out = np.array(values, copy=True)
    out.flags.writeable = False
    return out


def _centred_bounds(shape) -> tuple[np.ndarray, np.ndarray]:
    """``(-h, h)`` for a primitive centred on its frame, ``h`` from its class's vectorised ``_half_widths`` (which
    ``geometry.packing`` calls once for all the shapes of a class)."""
    half = shape._half_widths(shape._params[None])[0]
    return -half, half


def _unit_direction(direction) -> np.ndarray:
    return as_unit_vector3("direction", direction, tiny=0.0)


# Unit-density mass properties of primitives by (type, params): see Shape._unit_mass_properties.
_UNIT_MASS: dict[tuple[int, bytes], _mass.MassProperties] = {}
_UNIT_MASS_SIZE = 4096


class Shape:
    """Base of all shapes: an immutable value with kernel-ready data.

    Attributes:
        type: the :class:`ShapeType`.
        params: (4,) float64, the per-type sizes of the table in the module docstring (read-only).
        vertices: (v, 3) float64 [m] for ``ConvexHull`` and ``TriMesh``, else None (read-only).
        faces: (f, 3) int64 vertex indices for ``ConvexHull`` and ``TriMesh``, else None (read-only).
    """

    __slots__ = ("_params", "_vertices", "_faces", "_volume", "_unit_mass")
    type: ShapeType

    def _init(self, params, vertices=None, faces=None, volume=math.nan) -> None:
        object.__setattr__(self, "_params", _frozen(np.asarray(params, dtype=np.float64).reshape(4)))
        object.__setattr__(self, "_vertices", None if vertices is None else _frozen(vertices))
        object.__setattr__(self, "_faces", None if faces is None else _frozen(faces))
        object.__setattr__(self, "_volume", float(volume))
        object.__setattr__(self, "_unit_mass", None)
        if math.isinf(volume) and self.type != ShapeType.PLANE:
            raise ValueError(f"{self!r} is too large: its volume overflows a float (inf)")

    def _unit_mass_properties(self) -> _mass.MassProperties:
        """``mass_properties(density=1.0)``, worked out once per shape, and once per size for the primitives (a
        shape is immutable; a scene of many bodies holds a few sizes, often as a new shape object per body)."""
        if self._unit_mass is None:
            key = (int(self.type), self._params.tobytes()) if self._vertices is None else None
            mp = _UNIT_MASS.get(key) if key is not None else None
            if mp is None:
                mp = self.mass_properties(density=1.0)
                if key is not None:
                    if len(_UNIT_MASS) >= _UNIT_MASS_SIZE:
                        _UNIT_MASS.clear()
                    _UNIT_MASS[key] = mp
            object.__setattr__(self, "_unit_mass", mp)
        return self._unit_mass

    def __setattr__(self, name, value):
        raise AttributeError(f"{type(self).__name__} is immutable; cannot set {name!r} (make a new shape)")

    def __delattr__(self, name):
        raise AttributeError(f"{type(self).__name__} is immutable; cannot delete {name!r}")

    @property
    def params(self) -> np.ndarray:
        """(4,) float64: the per-type sizes for the kernels (see the module docstring)."""
        return self._params

    @property
    def vertices(self) -> np.ndarray | None:
        """(v, 3) float64 [m] in the shape frame for hulls and meshes; None for the primitives."""
        return self._vertices

    @property
    def faces(self) -> np.ndarray | None:
        """(f, 3) int64 indices into ``vertices`` for hulls and meshes; None for the primitives."""
        return self._faces

    @property
    def volume(self) -> float:
        """Enclosed volume [m³]."""
        return self._volume

    def mass_properties(self, *, mass=None, density=None) -> _mass.MassProperties:
        """Mass, centre of mass and inertia in the shape frame; exactly one of ``mass=`` [kg] or
        ``density=`` [kg/m³]."""
        raise NotImplementedError

    def local_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lo, hi)``: (3,) float64 [m] corners of the tightest axis-aligned box in the shape frame."""
        raise NotImplementedError

    def support(self, direction) -> np.ndarray:
        """(3,) float64 [m]: a point of the shape farthest along ``direction`` (shape frame, non-zero)."""
        raise NotImplementedError

    def _key(self) -> tuple:
        parts = [int(self.type), self._params.tobytes()]
        if self._vertices is not None:
            parts += [
                self._vertices.shape,
                self._vertices.tobytes(),
                self._faces.shape,
                self._faces.tobytes(),
            ]
        return tuple(parts)

    def __eq__(self, other) -> bool:
        if not isinstance(other, Shape):
            return NotImplemented
        return type(self) is type(other) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __reduce__(self):
        return (_rebuild, (type(self), self._params, self._vertices, self._faces, self._volume))


def _rebuild(cls, params, vertices, faces, volume):
    shape = object.__new__(cls)
    shape._init(params, vertices, faces, volume)
    return shape


class Sphere(Shape):
    """A ball of ``radius`` [m] centred at the shape origin."""

    __slots__ = ()
    type = ShapeType.SPHERE

    def __init__(self, radius) -> None:
        r = as_float("radius", radius, positive=True)
        self._init((r, 0.0, 0.0, 0.0), volume=4.0 / 3.0 * math.pi * r * r * r)

    @property
    def radius(self) -> float:
        return float(self._params[0])

    def mass_properties(self, *, mass=None, density=None) -> _mass.MassProperties:
        return _mass.solid_sphere(self.radius, mass=mass, density=density)

    @staticmethod
    def _half_widths(params: np.ndarray) -> np.ndarray:
        return np.repeat(params[:, :1], 3, axis=1)

    def local_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return _centred_bounds(self)

    def support(self, direction) -> np.ndarray:
        return self.radius * _unit_direction(direction)

    def __repr__(self) -> str:
        return f"Sphere(radius={self.radius!r})"


class Box(Shape):
    """A box with FULL edge lengths ``extents = (x, y, z)`` [m], centred; ``params`` holds half extents."""

    __slots__ = ()
    type = ShapeType.BOX

    def __init__(self, extents) -> None:
        sizes = as_vector3("extents", extents)
        if not (sizes > 0.0).all():
            raise ValueError(f"extents must be > 0 (full edge lengths along x, y, z), got {sizes.tolist()}")
        self._init((*(0.5 * sizes), 0.0), volume=math.prod(sizes.tolist()))

    @property
    def extents(self) -> np.ndarray:
        """(3,) float64 [m]: full edge lengths."""
        return 2.0 * self._params[:3]

    @property
    def half_extents(self) -> np.ndarray:
        """(3,) float64 [m]: half edge lengths (as in ``params``)."""
        return self._params[:3].copy()

    def mass_properties(self, *, mass=None, density=None) -> _mass.MassProperties:
        return _mass.box(self.extents, mass=mass, density=density)

    @staticmethod
    def _half_widths(params: np.ndarray) -> np.ndarray:
        return params[:, :3].copy()

    def local_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return _centred_bounds(self)

    def support(self, direction) -> np.ndarray:
        d = _unit_direction(direction)
        # A zero component picks the + face: any point of that face is a support point.
        return np.where(d >= 0.0, self._params[:3], -self._params[:3])

    def __repr__(self) -> str:
        return f"Box(extents={self.extents.tolist()!r})"


class Capsule(Shape):
    """A segment of ``length`` [m] along z (centred) swept by a ball of ``radius`` [m].

    ``length`` is the cylindrical part only (>= 0; 0 is a sphere); the full extent along z is
    ``length + 2 radius``.
    """

    __slots__ = ()
    type = ShapeType.CAPSULE

    def __init__(self, radius, length) -> None:
        r = as_float("radius", radius, positive=True)
        length_ = as_float("length", length, nonnegative=True)
        volume = math.pi * r * r * length_ + 4.0 / 3.0 * math.pi * r * r * r
        self._init((r, 0.5 * length_, 0.0, 0.0), volume=volume)

    @property
    def radius(self) -> float:
        return float(self._params[0])

    @property
    def length(self) -> float:
        """Length of the cylindrical part [m]."""
        return 2.0 * float(self._params[1])

    def mass_properties(self, *, mass=None, density=None) -> _mass.MassProperties:
        return _mass.capsule(self.radius, self.length, mass=mass, density=density)

    @staticmethod
    def _half_widths(params: np.ndarray) -> np.ndarray:
        r, half = params[:, 0], params[:, 1]
        return np.stack([r, r, half + r], axis=1)

    def local_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return _centred_bounds(self)

    def support(self, direction) -> np.ndarray:
        d = _unit_direction(direction)
        end = self._params[1] if d[2] >= 0.0 else -self._params[1]
        return np.array([0.0, 0.0, end]) + self._params[0] * d

    def __repr__(self) -> str:
        return f"Capsule(radius={self.radius!r}, length={self.length!r})"


class Cylinder(Shape):
    """A solid cylinder of ``radius`` [m] and ``height`` [m], axis z, centred at the shape origin."""

    __slots__ = ()
    type = ShapeType.CYLINDER

    def __init__(self, radius, height) -> None:
        r = as_float("radius", radius, positive=True)
        h = as_float("height", height, positive=True)
        self._init((r, 0.5 * h, 0.0, 0.0), volume=math.pi * r * r * h)

    @property
    def radius(self) -> float:
        return float(self._params[0])

    @property
    def height(self) -> float:
        return 2.0 * float(self._params[1])

    def mass_properties(self, *, mass=None, density=None) -> _mass.MassProperties:
        return _mass.solid_cylinder(self.radius, self.height, mass=mass, density=density)

    @staticmethod
    def _half_widths(params: np.ndarray) -> np.ndarray:
        r, half = params[:, 0], params[:, 1]
        return np.stack([r, r, half], axis=1)

    def local_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return _centred_bounds(self)

    def support(self, direction) -> np.ndarray:
        d = _unit_direction(direction)
        r, half = self._params[0], self._params[1]
        radial = math.hypot(d[0], d[1])
        # Along the axis (radial = 0) any point of the end disc is a support point: take its centre.
        scale = r / radial if radial > 0.0 else 0.0
        return np.array([d[0] * scale, d[1] * scale, half if d[2] >= 0.0 else -half])

    def __repr__(self) -> str:
        return f"Cylinder(radius={self.radius!r}, height={self.height!r})"


class Plane(Shape):
    """The infinite plane ``n · x = offset`` with unit normal ``n``; the solid side is ``n · x <= offset``.

    Static only: it has no mass properties, infinite volume and infinite bounds (the broad phase must
    treat planes apart: an AABB with infinite corners would poison sort-and-sweep arithmetic if it were
    made tighter for axis-aligned normals, so it is not).
    """

    __slots__ = ()
    type = ShapeType.PLANE

    def __init__(self, normal=(0.0, 0.0, 1.0), offset=0.0) -> None:
        n = as_unit_vector3("normal", normal, tiny=0.0)
        c = as_float("offset", offset)
        self._init((*n, c), volume=math.inf)

    @property
    def normal(self) -> np.ndarray:
        """(3,) float64: the unit normal, pointing out of the solid side."""
        return self._params[:3].copy()

    @property
    def offset(self) -> float:
        """[m]: the plane is ``normal · x = offset``."""
        return float(self._params[3])

    def mass_properties(self, *, mass=None, density=None) -> _mass.MassProperties:
        raise ValueError("a Plane is static only and has no mass properties; add it with world.add_static")

    def local_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return np.full(3, -math.inf), np.full(3, math.inf)

    def support(self, direction) -> np.ndarray:
        raise ValueError("a Plane is unbounded and has no support point; collide it with its closed form")

    def __repr__(self) -> str:
        return f"Plane(normal={self.normal.tolist()!r}, offset={self.offset!r})"


def _hull_extent_check(points: np.ndarray) -> float:
    size = float(np.max(points.max(axis=0) - points.min(axis=0)))
    if not size > 0.0:
        raise ValueError(f"points must span a volume, got {len(points)} copies of one point {points[0].tolist()}")
    return size


def _flatness(points: np.ndarray) -> str:
    """How degenerate points are that Qhull refused: "collinear", "coplanar" or "nearly flat".

    The singular values of the centred points measure their spread along three orthogonal directions; 1e-10 of
    the largest is far below any real thickness and far above the round-off of the SVD (~1e-16).
    """
    spread = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    if spread[1] <= 1e-10 * spread[0]:
        return "collinear"
    if spread[2] <= 1e-10 * spread[0]:
        return "coplanar"
    return "nearly flat"


class ConvexHull(Shape):
    """The convex hull of ``points`` (n, 3) [m], computed with Qhull (``scipy.spatial.ConvexHull``).

    Only the hull's corners are kept, as ``vertices``; ``faces`` are triangles wound counter-clockwise
    seen from outside (Qhull's triangles are not consistently oriented, so each is flipped where its
    normal disagrees with Qhull's outward facet normal). Points inside or on the hull are dropped.
    """

    __slots__ = ()
    type = ShapeType.CONVEX_HULL

    def __init__(self, points) -> None:
        pts = as_array("points", points, (3,), batch=True)
        if pts.ndim != 2 or pts.shape[0] < 4:
            raise ValueError(
                f"points must have shape (n, 3) with n >= 4 to span a volume, got shape {pts.shape}: {_show(pts)}"
            )
        size = _hull_extent_check(pts)
        import scipy.spatial  # on first use: import tumble stays light

        try:
            hull = scipy.spatial.ConvexHull(pts)
        except scipy.spatial.QhullError as error:
            reason = str(error).strip().splitlines()[0] if str(error).strip() else "no volume"
            raise ValueError(
                f"points must span a volume, but the {len(pts)} points are {_flatness(pts)}: {_show(pts)} "
                f"(Qhull: {reason})"
            ) from error
        corners = np.sort(hull.vertices)
        remap = np.full(len(pts), -1, dtype=np.int64)
        remap[corners] = np.arange(len(corners))
        faces = remap[hull.simplices].astype(np.int64)
        vertices = pts[corners]
        # Orient every triangle along its facet's outward normal (the first three entries of `equations`).
        a, b, c = (vertices[faces[:, k]] for k in range(3))
        normals = np.cross(b - a, c - a)
        inward = portable.dot(normals, hull.equations[:, :3]) < 0.0
        faces[inward] = faces[inward][:, [0, 2, 1]]
        try:
            volume = _mass._closed_mesh_integrals(vertices, faces)[0]
        except ValueError as error:
            raise ValueError(f"points span no usable volume (size {size:.3g} m): {error}") from error
        self._init(np.zeros(4), vertices, faces, volume)

    def mass_properties(self, *, mass=None, density=None) -> _mass.MassProperties:
        return _mass.mesh(self._vertices, self._faces, mass=mass, density=density)

    def local_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return self._vertices.min(axis=0), self._vertices.max(axis=0)

    def support(self, direction) -> np.ndarray:
        d = _unit_direction(direction)
        return self._vertices[int(np.argmax(portable.dot(self._vertices, d)))].copy()

    def __repr__(self) -> str:
        return f"ConvexHull(<{len(self._vertices)} vertices, {len(self._faces)} faces>)"


class TriMesh(Shape):
    """Any triangle mesh: ``vertices`` (n, 3) [m] and ``faces`` (f, 3) integer indices, kept as given.

    An open or badly wound mesh is fine as static collision geometry. Mass properties and ``volume``
    need a closed, outward-wound mesh and raise the :func:`tumble.mass.mesh` ValueError otherwise.
    """

    __slots__ = ()
    type = ShapeType.TRIMESH

    def __init__(self, vertices, faces) -> None:
        verts, tris = _mass._mesh_arrays(vertices, faces)
        self._init(np.zeros(4), verts, tris)

    @property
    def is_closed(self) -> bool:
        """Whether every edge is shared by exactly two faces that walk it in opposite directions
        (a closed, consistently wound surface; it may still be wound inward)."""
        return _mass._edge_problem(self._faces) is None

    @property
    def volume(self) -> float:
        """Enclosed volume [m³]; ValueError when the mesh is not closed and outward-wound."""
        return _mass._closed_mesh_integrals(self._vertices, self._faces)[0]

    def mass_properties(self, *, mass=None, density=None) -> _mass.MassProperties:
        return _mass.mesh(self._vertices, self._faces, mass=mass, density=density)

    def local_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        used = self._vertices[np.unique(self._faces)]
        return used.min(axis=0), used.max(axis=0)

    def support(self, direction) -> np.ndarray:
        """The farthest vertex along ``direction``: the support point of the mesh's convex hull."""
        d = _unit_direction(direction)
        used = self._vertices[np.unique(self._faces)]
        return used[int(np.argmax(portable.dot(used, d)))].copy()

    def __repr__(self) -> str:
        return f"TriMesh(<{len(self._vertices)} vertices, {len(self._faces)} faces>)"
