"""Mass properties: mass, centre of mass and inertia tensor of rigid bodies.

A :class:`MassProperties` is an immutable value: ``mass`` [kg], ``com`` (3,) [m] and ``inertia`` (3, 3)
[kg m²] about the centre of mass, all expressed in the frame the geometry was described in. Composite
bodies are sums (``a + b``, or ``sum([...])``), moved with :meth:`MassProperties.transformed`.

The constructors give the closed forms of the primitives of ``course/002_ea6177634d64fff8.txt`` ("Inertia
of Primitive Shapes"; the box is ``m/12``, not the ``m/10`` typo of deck 000), plus the capsule and the cone
derived below, point masses, and closed triangle meshes integrated exactly by the divergence theorem
(signed tetrahedra, Tonon 2004; the same sums as Eberly's "Polyhedral Mass Properties (Revisited)", 2002,
after Mirtich 1996). Each takes exactly one of ``mass=`` [kg] or ``density=``: a volume density
[kg/m³] for solids, an areal density [kg/m²] for the thin shells (``hollow_sphere``, ``hollow_cylinder``).

The inertia tensor is the course's ``I = ∫ (|r|² E - r rᵀ) dm`` with ``r`` measured from the centre of
mass, so its products of inertia carry the minus sign (``I_xy = -∫ x y dm``).
"""

from __future__ import annotations

import functools
import inspect
import math
import numbers
import sys

import numpy as np

from . import portable
from ._validate import as_array, as_float, as_vector3, mass_or_density
from .rotation import as_rotation

__all__ = [
    "MassProperties",
    "solid_sphere",
    "hollow_sphere",
    "solid_ellipsoid",
    "box",
    "solid_cylinder",
    "hollow_cylinder",
    "capsule",
    "cone",
    "particles",
    "mesh",
]

# Symmetry is judged relative to the largest entry: float64 sums of products leave ~1e-16 relative
# asymmetry, so 1e-9 refuses only tensors that are really asymmetric.
_SYMMETRY_RTOL = 1e-9
# An eigenvalue of a PSD tensor computed in float64 can come out as -eps * trace; a rod (particles on a
# line) has one exactly-zero principal moment, so the bound is -1e-12 trace (about 1e4 eps).
_PSD_RTOL = 1e-12
# A lamina has I1 + I2 = I3 exactly, and measured tensors miss it by their measurement error: the Crazyflie's
# diag(1.43, 1.43, 2.89) e-5 kg m² (J. Förster, ETH Zürich 2015, the figures RotorPy flies) by 0.5 % of the trace.
# A tensor is refused when I1 + I2 falls short of I3 by more than 1 % of the trace.
_TRIANGLE_RTOL = 1e-2


def _show(value) -> str:
    text = repr(np.asarray(value).tolist())
    return text if len(text) <= 120 else text[:117] + "..."


def _readonly(array: np.ndarray) -> np.ndarray:
    out = np.array(array, dtype=np.float64, copy=True)
    out.flags.writeable = False
    return out


def _check_inertia(inertia) -> np.ndarray:
    """A finite, symmetric, positive semi-definite (3, 3) tensor meeting the triangle inequality."""
    tensor = as_array("inertia", inertia, (3, 3), batch=False)
    scale = float(np.max(np.abs(tensor)))
    asymmetry = float(np.max(np.abs(tensor - tensor.T)))
    if asymmetry > _SYMMETRY_RTOL * scale:
        raise ValueError(f"inertia must be symmetric, got {_show(tensor)} (largest |I - Iᵀ| entry {asymmetry:.3g})")
    tensor = 0.5 * (tensor + tensor.T)
    moments = portable.eigh(tensor)[0]
    trace = float(np.trace(tensor))
    if moments[0] < -_PSD_RTOL * abs(trace) or trace < 0.0:
        raise ValueError(f"inertia must be positive semi-definite, got eigenvalues {_show(moments)} of {_show(tensor)}")
    if moments[0] + moments[1] < moments[2] - _TRIANGLE_RTOL * trace:
        raise ValueError(
            "inertia violates the triangle inequality I1 + I2 >= I3 of its principal moments "
            f"(no mass distribution has it), got eigenvalues {_show(moments)} of {_show(tensor)}"
        )
    return tensor


def _shift_term(mass: float, d: np.ndarray) -> np.ndarray:
    """``m (|d|² E - d dᵀ)``: the parallel-axis term for an offset ``d`` (course deck 002)."""
    return mass * (float(portable.dot(d, d)) * np.eye(3) - np.outer(d, d))


class MassProperties:
    """Mass, centre of mass and inertia about the centre of mass of one rigid body. Immutable.

    Args:
        mass: total mass [kg], finite and > 0.
        com: (3,) float64 [m], the centre of mass in the frame the geometry was described in.
        inertia: (3, 3) float64 [kg m²], about ``com``, axes of that same frame. Symmetric, positive
            semi-definite (a rod of point masses has one zero moment; the World asks for definite
            inertia for dynamic bodies) and meeting the triangle inequality of the principal moments.

    >>> body = box((2.0, 2.0, 2.0), mass=3.0) + solid_sphere(1.0, mass=1.0).transformed(translation=(0, 0, 2))
    >>> round(body.mass, 12), body.com.tolist()
    (4.0, [0.0, 0.0, 0.5])
    """

    __slots__ = ("_mass", "_com", "_inertia", "_moments")

    def __init__(self, mass, com, inertia) -> None:
        object.__setattr__(self, "_mass", as_float("mass", mass, positive=True))
        object.__setattr__(self, "_com", _readonly(as_vector3("com", com)))
        object.__setattr__(self, "_inertia", _readonly(_check_inertia(inertia)))
        object.__setattr__(self, "_moments", None)

    @classmethod
    def _trusted(cls, mass: float, com: np.ndarray, inertia: np.ndarray, moments=None) -> MassProperties:
        """One made from a valid one by a change that keeps it valid (a positive scale), without checking again;
        ``moments``: its principal moments when known."""
        out = object.__new__(cls)
        object.__setattr__(out, "_mass", float(mass))
        object.__setattr__(out, "_com", _readonly(com))
        object.__setattr__(out, "_inertia", _readonly(inertia))
        object.__setattr__(out, "_moments", moments)
        return out

    def _principal_moments(self) -> np.ndarray:
        """The principal moments, ascending, worked out once (a body checks them, and bodies of one shape and
        scale share them)."""
        if self._moments is None:
            object.__setattr__(self, "_moments", _readonly(portable.eigh(self._inertia)[0]))
        return self._moments

    def __setattr__(self, name, value):
        raise AttributeError(f"MassProperties is immutable; cannot set {name!r} (build a new one instead)")

    def __delattr__(self, name):
        raise AttributeError(f"MassProperties is immutable; cannot delete {name!r}")

    def __reduce__(self):
        return (MassProperties, (self._mass, self._com, self._inertia))

    # --- the three numbers ---------------------------------------------------------------------------

    @property
    def mass(self) -> float:
        """Total mass [kg]."""
        return self._mass

    @property
    def com(self) -> np.ndarray:
        """(3,) float64 [m]: the centre of mass (read-only array)."""
        return self._com

    @property
    def inertia(self) -> np.ndarray:
        """(3, 3) float64 [kg m²]: the inertia tensor about the centre of mass (read-only array)."""
        return self._inertia

    # --- other points and axes -----------------------------------------------------------------------

    def inertia_about(self, point) -> np.ndarray:
        """The inertia tensor about ``point`` by the full-tensor parallel-axis theorem.

        ``I_p = I_c + m (|d|² E - d dᵀ)`` with ``d = com - point`` (course deck 002, "Parallel-Axis
        Theorem", in tensor form).

        Args:
            point: (3,) float64 [m], same frame as ``com``.

        Returns:
            (3, 3) float64 [kg m²], a new array.
        """
        d = self._com - as_vector3("point", point)
        return self._inertia + _shift_term(self._mass, d)

    def moment_about(self, axis, point=None) -> float:
        """The scalar moment ``eᵀ I e`` [kg m²] about the line along ``axis`` through ``point``.

        Args:
            axis: (3,) direction, any non-zero length (it is normalised).
            point: (3,) [m], a point of the line; default the centre of mass.
        """
        e = as_vector3("axis", axis)
        norm = float(portable.norm(e))
        if not norm > 0.0:
            raise ValueError(f"axis must be a non-zero vector, got {_show(e)}")
        e = e / norm
        tensor = self._inertia if point is None else self.inertia_about(point)
        return float(portable.dot(e, portable.matvec(tensor, e)))

    def transformed(self, rotation=None, translation=None) -> MassProperties:
        """The same body rotated by ``rotation`` and then moved by ``translation``.

        ``com' = R com + t`` and ``I' = R I Rᵀ`` (course deck 002, "Change of coordinates").

        Args:
            rotation: a unit quaternion ``[w, x, y, z]`` or a (3, 3) rotation matrix; default none.
            translation: (3,) [m]; default zero.
        """
        rot = np.eye(3) if rotation is None else as_rotation("rotation", rotation)
        shift = np.zeros(3) if translation is None else as_vector3("translation", translation)
        com = portable.matvec(rot, self._com) + shift
        return MassProperties(self._mass, com, portable.sandwich(rot, self._inertia))

    def principal(self) -> tuple[np.ndarray, np.ndarray]:
        """Principal moments and axes (course deck 000, "Rotational Inertia Diagonalization").

        Returns:
            ``(moments, axes)``: moments (3,) [kg m²] ascending; axes a (3, 3) right-handed rotation
            matrix (det +1) whose columns are the principal axes:
            ``inertia = axes @ diag(moments) @ axes.T``.
            Axes of equal moments are any orthonormal basis of their eigenspace.
        """
        moments, axes = portable.eigh(self._inertia)  # Jacobi's method, the course's
        if portable.det(axes) < 0.0:
            axes[:, 2] = -axes[:, 2]
        return moments, axes

    def scaled_to(self, mass) -> MassProperties:
        """The same shape with total mass ``mass`` [kg]: the inertia scales with the mass."""
        new_mass = as_float("mass", mass, positive=True)
        scale = new_mass / self._mass
        moments = self._principal_moments()
        # No entry of a positive semi-definite tensor exceeds its largest moment: this bounds them all.
        if not (math.isfinite(scale) and scale * float(moments[-1]) < math.inf):
            raise ValueError(f"mass={new_mass!r} for a body of {self._mass!r} kg at unit density scales its inertia "
                             f"out of float range (by {scale!r})")  # fmt: skip
        return MassProperties._trusted(new_mass, self._com, self._inertia * scale, moments * scale)

    # --- composites ----------------------------------------------------------------------------------

    def __add__(self, other):
        """The composite body: masses add, the centre of mass is mass-weighted, and each inertia is moved
        to the new centre of mass by the parallel-axis theorem before adding (course deck 002, "Complex
        Objects")."""
        if not isinstance(other, MassProperties):
            return NotImplemented
        mass = self._mass + other._mass
        com = (self._mass * self._com + other._mass * other._com) / mass
        inertia = self.inertia_about(com) + other.inertia_about(com)
        return MassProperties(mass, com, inertia)

    def __radd__(self, other):
        # sum([...]) starts from the integer 0.
        if isinstance(other, numbers.Number) and not isinstance(other, bool) and other == 0:
            return self
        return NotImplemented

    def isclose(self, other: MassProperties, rtol: float = 1e-9, atol: float = 1e-12) -> bool:
        """Whether two mass properties agree: mass, com and inertia each within ``atol + rtol * scale``.

        The scale of com and inertia is the largest entry of either operand, so small products of
        inertia are compared relative to the tensor's size rather than to themselves.
        """
        if not isinstance(other, MassProperties):
            raise TypeError(f"other must be a MassProperties, got {type(other).__name__}")
        rtol = as_float("rtol", rtol, nonnegative=True)
        atol = as_float("atol", atol, nonnegative=True)

        def close(a, b) -> bool:
            a, b = np.asarray(a), np.asarray(b)
            scale = max(float(np.max(np.abs(a))), float(np.max(np.abs(b))))
            return bool(np.max(np.abs(a - b)) <= atol + rtol * scale)

        return close(self._mass, other._mass) and close(self._com, other._com) and close(self._inertia, other._inertia)

    def __repr__(self) -> str:
        return f"MassProperties(mass={self._mass!r}, com={self._com.tolist()!r}, inertia={self._inertia.tolist()!r})"


# --- constructors --------------------------------------------------------------------------------------


class _OutOfRange(ValueError):
    """Sizes, mass or density whose volume, mass or moments leave float range; :func:`_named_arguments` adds the
    call's arguments to the message."""


def _named_arguments(function):
    """``function`` (a primitive's mass properties), whose out-of-range errors name the call and its arguments."""

    @functools.wraps(function)
    def named(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except _OutOfRange as error:
            bound = inspect.signature(function).bind(*args, **kwargs)
            given = ", ".join(f"{k}={v!r}" for k, v in bound.arguments.items() if v is not None)
            raise ValueError(f"{function.__name__}({given}): {error}") from None

    return named


def _total_mass(mass, density, measure: float) -> float:
    """The mass from ``mass=`` or ``density=`` times ``measure`` (a volume, or an area for shells).

    Raises:
        _OutOfRange: sizes so small or so large that ``measure`` is not a normal, finite float (the mass would be
            spread over nothing, 1/V overflows, or the moments do), or a density times it that overflows.
    """
    kind, value = mass_or_density(mass, density)
    if not sys.float_info.min <= measure < math.inf:  # a subnormal volume has lost its digits: 1/V overflows
        raise _OutOfRange(f"the sizes give a volume of {measure!r}: too {'small' if measure < 1.0 else 'large'} for "
                          "a float; give sizes between about 1e-100 and 1e100 m")  # fmt: skip
    total = value if kind == "mass" else value * measure
    if not sys.float_info.min <= total < math.inf:
        raise _OutOfRange(f"density times volume gives a mass of {total!r}, out of float range")
    return total


def _diagonal(mass: float, moments, com=(0.0, 0.0, 0.0)) -> MassProperties:
    """The primitives' formulas give a valid tensor for valid sizes, so only an overflow or underflow of the
    moments is looked for; bodies are built by the hundred thousand, and this is on their way."""
    with np.errstate(over="ignore", under="ignore"):
        inertia = np.diag(np.asarray(moments, dtype=np.float64))
    if not np.isfinite(inertia).all():
        raise _OutOfRange(f"the moments of inertia {np.diag(inertia).tolist()} overflow: give a smaller mass or size")
    return MassProperties._trusted(
        mass, np.asarray(com, dtype=np.float64), inertia, _readonly(np.sort(np.diag(inertia)))
    )


@_named_arguments
def solid_sphere(radius, *, mass=None, density=None) -> MassProperties:
    """A solid ball centred at the origin: ``I = 2/5 m r² E`` (course deck 002, "Inertia of Primitive
    Shapes").

    Args:
        radius: [m], > 0.
        mass: [kg], or density: [kg/m³] over the volume ``4/3 π r³``.
    """
    r = as_float("radius", radius, positive=True)
    m = _total_mass(mass, density, 4.0 / 3.0 * math.pi * r * r * r)
    return _diagonal(m, [0.4 * m * r * r] * 3)


@_named_arguments
def hollow_sphere(radius, *, mass=None, density=None) -> MassProperties:
    """A thin spherical shell centred at the origin: ``I = 2/3 m r² E`` (course deck 002).

    Args:
        radius: [m], > 0.
        mass: [kg], or density: an AREAL density [kg/m²] over the surface ``4 π r²``.
    """
    r = as_float("radius", radius, positive=True)
    m = _total_mass(mass, density, 4.0 * math.pi * r * r)
    return _diagonal(m, [2.0 / 3.0 * m * r * r] * 3)


@_named_arguments
def solid_ellipsoid(a, b, c, *, mass=None, density=None) -> MassProperties:
    """A solid ellipsoid with semi-axes ``a, b, c`` along x, y, z, centred at the origin.

    ``I = m/5 diag(b² + c², a² + c², a² + b²)`` (course deck 002); volume ``4/3 π a b c``.
    """
    a = as_float("a", a, positive=True)
    b = as_float("b", b, positive=True)
    c = as_float("c", c, positive=True)
    m = _total_mass(mass, density, 4.0 / 3.0 * math.pi * a * b * c)
    return _diagonal(m, [m / 5.0 * (b * b + c * c), m / 5.0 * (a * a + c * c), m / 5.0 * (a * a + b * b)])


def _positive_extents(extents) -> np.ndarray:
    sizes = as_vector3("extents", extents)
    if not (sizes > 0.0).all():
        raise ValueError(f"extents must be > 0 (full edge lengths along x, y, z), got {_show(sizes)}")
    return sizes


@_named_arguments
def box(extents, *, mass=None, density=None) -> MassProperties:
    """A solid box with FULL edge lengths ``extents = (x, y, z)`` [m], centred at the origin.

    ``I = m/12 diag(y² + z², x² + z², x² + y²)`` (course deck 002; deck 000's ``m/10`` is a typo).
    """
    x, y, z = map(float, _positive_extents(extents))  # Python floats: an overflow is inf, with no warning
    m = _total_mass(mass, density, x * y * z)
    return _diagonal(m, [m / 12.0 * (y * y + z * z), m / 12.0 * (x * x + z * z), m / 12.0 * (x * x + y * y)])


@_named_arguments
def solid_cylinder(radius, height, *, mass=None, density=None) -> MassProperties:
    """A solid cylinder with axis z, centred at the origin (course deck 002).

    ``I_xx = I_yy = m (3 r² + h²) / 12``, ``I_zz = m r² / 2``; volume ``π r² h``.
    """
    r = as_float("radius", radius, positive=True)
    h = as_float("height", height, positive=True)
    m = _total_mass(mass, density, math.pi * r * r * h)
    side = m * (3.0 * r * r + h * h) / 12.0
    return _diagonal(m, [side, side, 0.5 * m * r * r])


@_named_arguments
def hollow_cylinder(radius, height, *, mass=None, density=None) -> MassProperties:
    """A thin open tube (no end caps) with axis z, centred at the origin (course deck 002).

    ``I_xx = I_yy = m (6 r² + h²) / 12``, ``I_zz = m r²``. ``density`` is AREAL [kg/m²] over the lateral
    surface ``2 π r h``.
    """
    r = as_float("radius", radius, positive=True)
    h = as_float("height", height, positive=True)
    m = _total_mass(mass, density, 2.0 * math.pi * r * h)
    side = m * (6.0 * r * r + h * h) / 12.0
    return _diagonal(m, [side, side, m * r * r])


@_named_arguments
def capsule(radius, length, *, mass=None, density=None) -> MassProperties:
    """A solid capsule: a cylinder of ``length`` along z capped by two hemispheres, centred at the origin.

    ``length`` is the cylindrical part only (>= 0; 0 gives a sphere); the total extent along z is
    ``length + 2 radius``. The mass splits by volume: cylinder ``m_c`` (``π r² L``) and each hemisphere
    ``m_h`` (``2/3 π r³``). Derivation, from the primitives of course deck 002:

    - axial: ``I_zz = m_c r²/2 + 2 · (2/5 m_h r²)`` (each hemisphere is half a ball about its own axis);
    - transverse: a hemisphere about a diameter of its flat face has ``2/5 m_h r²`` (half a ball). Its
      centre of mass lies ``3r/8`` from that face (standard centroid of a solid hemisphere), so about its
      own centre ``2/5 m_h r² - m_h (3r/8)²``; moved to the capsule centre at ``L/2 + 3r/8`` this gives
      ``m_h (2/5 r² + L²/4 + 3 L r/8)``. With the cylinder's ``m_c (3 r² + L²)/12``:
      ``I_xx = m_c (3r² + L²)/12 + 2 m_h (2r²/5 + L²/4 + 3Lr/8)``.
    """
    r = as_float("radius", radius, positive=True)
    length_ = as_float("length", length, nonnegative=True)
    cylinder_volume = math.pi * r * r * length_
    hemisphere_volume = 2.0 / 3.0 * math.pi * r * r * r
    volume = cylinder_volume + 2.0 * hemisphere_volume
    m = _total_mass(mass, density, volume)
    m_c = m * cylinder_volume / volume
    m_h = m * hemisphere_volume / volume
    axial = 0.5 * m_c * r * r + 0.8 * m_h * r * r
    side = m_c * (3.0 * r * r + length_ * length_) / 12.0 + 2.0 * m_h * (
        0.4 * r * r + 0.25 * length_ * length_ + 0.375 * length_ * r
    )
    return _diagonal(m, [side, side, axial])


@_named_arguments
def cone(radius, height, *, mass=None, density=None) -> MassProperties:
    """A solid right circular cone, base disc of ``radius`` at z = 0, apex at z = ``height``.

    Centre of mass at ``z = h/4``; about it ``I_zz = 3/10 m r²`` and ``I_xx = I_yy = 3/20 m r² + 3/80 m h²``
    (standard table, e.g. Meriam & Kraige, Engineering Mechanics: Dynamics, appendix B; from the disc
    slicing of course deck 002). Volume ``π r² h / 3``.
    """
    r = as_float("radius", radius, positive=True)
    h = as_float("height", height, positive=True)
    m = _total_mass(mass, density, math.pi * r * r * h / 3.0)
    side = 3.0 / 20.0 * m * r * r + 3.0 / 80.0 * m * h * h
    return _diagonal(m, [side, side, 0.3 * m * r * r], com=(0.0, 0.0, 0.25 * h))


def particles(masses, points) -> MassProperties:
    """Point masses: ``I = Σ m_i (|r_i|² E - r_i r_iᵀ) = Σ -m_i r̃_i r̃_i``, ``r_i`` from the centre of mass.

    Course deck 000, "Rotational Inertia of a Particle". The inertia may be singular (points on a line).

    Args:
        masses: (n,) [kg], each finite and > 0.
        points: (n, 3) [m].
    """
    m = as_array("masses", masses, (), batch=True)
    if m.ndim != 1 or m.size == 0:
        raise ValueError(f"masses must be a non-empty 1-D array, got shape {m.shape}: {_show(m)}")
    if not np.all(m > 0.0):
        raise ValueError(f"masses must all be > 0, got {_show(m)}")
    p = as_array("points", points, (3,), batch=True)
    if p.ndim != 2 or p.shape[0] != m.size:
        raise ValueError(f"points must have shape ({m.size}, 3) to match masses, got shape {p.shape}")
    total = float(m.sum())
    com = portable.weighted_sum(m, p) / total
    r = p - com
    inertia = np.sum(m * portable.dot(r, r)) * np.eye(3) - portable.outer_sum(m, r, r)
    return MassProperties(total, com, inertia)


# --- triangle meshes -------------------------------------------------------------------------------------


def _mesh_arrays(vertices, faces) -> tuple[np.ndarray, np.ndarray]:
    """Validated ``(vertices (n, 3) float64, faces (f, 3) int64)``: indices in range, no repeated corner."""
    verts = as_array("vertices", vertices, (3,), batch=True)
    if verts.ndim != 2 or verts.shape[0] < 3:
        raise ValueError(f"vertices must have shape (n, 3) with n >= 3, got shape {verts.shape}")
    if isinstance(faces, (str, bytes)) or faces is None:
        raise TypeError(f"faces must be an (f, 3) array of integer vertex indices, got {_show(faces)}")
    tris = np.asarray(faces)
    if tris.size and not np.issubdtype(tris.dtype, np.integer):
        raise TypeError(f"faces must hold integer vertex indices, got dtype {tris.dtype}: {_show(tris)}")
    if tris.ndim != 2 or tris.shape[1] != 3 or tris.shape[0] == 0:
        raise ValueError(f"faces must have shape (f, 3) with f >= 1, got shape {tris.shape}")
    tris = tris.astype(np.int64)
    bad = np.flatnonzero(np.any((tris < 0) | (tris >= verts.shape[0]), axis=1))
    if bad.size:
        raise ValueError(
            f"faces index vertices out of range 0..{verts.shape[0] - 1}: {bad.size} faces, "
            f"e.g. face {bad[0]} = {tris[bad[0]].tolist()}"
        )
    repeated = np.flatnonzero((tris[:, 0] == tris[:, 1]) | (tris[:, 1] == tris[:, 2]) | (tris[:, 2] == tris[:, 0]))
    if repeated.size:
        raise ValueError(
            f"faces must be triangles of three distinct vertices (degenerate): {repeated.size} faces repeat "
            f"a vertex, e.g. face {repeated[0]} = {tris[repeated[0]].tolist()}"
        )
    return verts, tris


def _edge_problem(faces: np.ndarray) -> str | None:
    """Why a triangle list is not a closed, consistently wound surface; None when it is.

    Each face ``(a, b, c)`` walks the directed edges ``a→b, b→c, c→a``. Closed and consistent means each
    undirected edge belongs to exactly two faces that walk it in opposite directions.
    """
    directed = np.stack([faces, np.roll(faces, -1, axis=1)], axis=2).reshape(-1, 2)
    undirected = np.sort(directed, axis=1)
    keys, inverse, counts = np.unique(undirected, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    boundary = keys[counts == 1]
    if boundary.size:
        return (
            f"is not closed: {len(boundary)} boundary edges are used by only one face, e.g. edge {boundary[0].tolist()}"
        )
    shared = keys[counts > 2]
    if shared.size:
        worst = int(np.max(counts))
        return (
            f"is not a closed manifold: {len(shared)} edges are used by more than two faces "
            f"(up to {worst}), e.g. edge {shared[0].tolist()}"
        )
    # Exactly two uses per edge: opposite directions means the two directed copies differ.
    pairs = np.argsort(inverse, kind="stable").reshape(-1, 2)
    same = np.flatnonzero(np.all(directed[pairs[:, 0]] == directed[pairs[:, 1]], axis=1))
    if same.size:
        first = pairs[same[0]]
        return (
            f"is inconsistently wound: {same.size} edges are traversed twice in the same direction, "
            f"e.g. edge {directed[first[0]].tolist()} by faces {first[0] // 3} and {first[1] // 3}"
        )
    return None


def _polyhedron_integrals(vertices: np.ndarray, faces: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, centroid and second moment ``∫ (x - c)(x - c)ᵀ dV`` of a closed outward-wound mesh.

    Divergence theorem on signed tetrahedra (origin, a, b, c), Tonon (2004), "Explicit exact formulas for
    the 3-D tetrahedron inertia tensor in terms of its vertex coordinates", J. Math. Stat. 1(1): for a
    tetrahedron with one corner at the origin and ``D = a · (b × c)`` (six times its signed volume),
    ``∫ x xᵀ dV = D/120 (a aᵀ + b bᵀ + c cᵀ + s sᵀ)`` with ``s = a + b + c``, and ``∫ x dV = D/24 s``.
    The signed sums over all faces give the polyhedron's integrals exactly. The vertices are first
    shifted to their mean so that far-from-origin meshes lose no digits to cancellation.
    """
    origin = vertices[np.unique(faces)].mean(axis=0)
    a, b, c = (vertices[faces[:, k]] - origin for k in range(3))
    d = portable.dot(a, np.cross(b, c))
    s = a + b + c
    volume = float(d.sum()) / 6.0
    first = portable.weighted_sum(d, s) / 24.0
    second = sum(portable.outer_sum(d, e, e) for e in (a, b, c, s)) / 120.0
    if volume == 0.0:
        return volume, origin, second
    centroid = first / volume
    second_about_centroid = second - volume * np.outer(centroid, centroid)
    return volume, centroid + origin, second_about_centroid


def _closed_mesh_integrals(vertices, faces) -> tuple[float, np.ndarray, np.ndarray]:
    """Validate a closed, outward-wound mesh (ValueError saying what is wrong) and integrate it."""
    verts, tris = _mesh_arrays(vertices, faces)
    problem = _edge_problem(tris)
    if problem is not None:
        raise ValueError(f"the mesh (faces) {problem}; mass properties need a closed, outward-wound surface")
    volume, centroid, second = _polyhedron_integrals(verts, tris)
    used = verts[np.unique(tris)]
    size = float(np.max(used.max(axis=0) - used.min(axis=0)))
    # Rounding in the signed sum is ~1e-16 size³ per face; 1e-12 size³ is zero volume for any mesh.
    if abs(volume) <= 1e-12 * size**3:
        raise ValueError(
            f"the mesh (vertices, faces) encloses zero volume ({volume:.3g} m³ for a size of {size:.3g} m); "
            "it is flat or degenerate"
        )
    if volume < 0.0:
        raise ValueError(
            f"the mesh (faces) is inward-wound (faces point inside); reverse the face winding "
            f"(signed volume {volume:.6g} m³)"
        )
    return volume, centroid, second


@_named_arguments
def mesh(vertices, faces, *, mass=None, density=None) -> MassProperties:
    """A solid bounded by a closed, outward-wound triangle mesh, by exact polyhedral integration.

    Signed tetrahedra and the divergence theorem (Tonon 2004; equivalent to Eberly, "Polyhedral Mass
    Properties (Revisited)", 2002, after Mirtich 1996): exact up to rounding for any closed polyhedron,
    convex or not. The inertia is ``ρ (tr(C) E - C)`` with ``C = ∫ (x - c)(x - c)ᵀ dV`` about the centroid.

    Args:
        vertices: (n, 3) [m].
        faces: (f, 3) integer indices into ``vertices``, counter-clockwise seen from outside.
        mass: [kg], or density: [kg/m³].

    Raises:
        ValueError: saying which: out-of-range or repeated indices, an open surface (boundary edges),
            a non-manifold edge, inconsistent winding, inward winding, or zero volume.
        TypeError: faces that are not integers.
    """
    volume, centroid, second = _closed_mesh_integrals(vertices, faces)
    m = _total_mass(mass, density, volume)
    rho = m / volume
    inertia = rho * (np.trace(second) * np.eye(3) - second)
    return MassProperties(m, centroid, 0.5 * (inertia + inertia.T))


def require_invertible(mp: MassProperties) -> None:
    """A dynamic body's mass and inertia must be invertible: the solver works with 1/m and I⁻¹."""
    with np.errstate(over="ignore", divide="ignore"):
        inverse = 1.0 / mp.mass
    if not math.isfinite(inverse):
        raise ValueError(f"mass={mp.mass!r} is too small for a dynamic body: 1/mass overflows")
    moments = mp._principal_moments()
    with np.errstate(over="ignore", divide="ignore"):
        smallest_inverse = 1.0 / moments[0]
    if moments[0] > 0.0 and not math.isfinite(smallest_inverse):
        raise ValueError(f"inertia must be invertible for a dynamic body, got principal moments {moments.tolist()}")
    if moments[0] <= 1e-12 * moments[-1]:
        raise ValueError(
            f"inertia must be positive definite for a dynamic body, got principal moments {moments.tolist()}"
        )
