"""Spatial vector algebra in the world frame (Featherstone, *Rigid Body Dynamics Algorithms*, 2008, ch. 2).

Every spatial quantity of the articulation kernels is expressed in world axes at the world origin, so no
coordinate transform is ever needed between links: a child's velocity is its parent's plus the joint's,
and the composite inertia of a subtree is a plain sum. A motion vector is a pair ``(ω, v_O)`` (angular
velocity, and the velocity of the body-fixed point passing through the origin), a force vector a pair
``(n_O, f)`` (moment about the origin, force). A spatial inertia is the 10-tuple ``(m, h, I_O)`` with
``h = m c`` the first moment and ``I_O = I_c + m (|c|² E - c cᵀ)`` about the origin, stored
``(xx, yy, zz, xy, xz, yz)``; it maps a velocity to the momentum ``(I_O ω + h × v_O, m v_O + ω × h)``.
"""

from __future__ import annotations

from .._jit import inline
from ..math3d import add, cross, dot, mat_vec, quat_rotate, quat_to_mat33, scale, sub

__all__ = [
    "ZERO3",
    "ZERO6",
    "add6",
    "assign",
    "fill",
    "fill_matrix",
    "cross_force",
    "cross_motion",
    "dot6",
    "get3",
    "get4",
    "get6",
    "get9",
    "get10",
    "inertia_add",
    "inertia_apply",
    "inertia_world",
    "kinetic_energy",
    "point_acceleration",
    "point_velocity",
    "put3",
    "put4",
    "put6",
    "put10",
    "scale6",
    "sub6",
    "vec3",
    "vec4",
]

ZERO3 = (0.0, 0.0, 0.0)
ZERO6 = (ZERO3, ZERO3)


# --- reading and writing rows of the wide arrays (row i, columns c, c + 1, ...) ------------------------


@inline
def vec3(array, c):
    """``array[c:c + 3]`` of a 1-D array as a tuple."""
    return (array[c], array[c + 1], array[c + 2])


@inline
def vec4(array, c):
    return (array[c], array[c + 1], array[c + 2], array[c + 3])


@inline
def get3(array, i, c):
    return (array[i, c], array[i, c + 1], array[i, c + 2])


@inline
def put3(array, i, c, v):
    array[i, c], array[i, c + 1], array[i, c + 2] = v[0], v[1], v[2]


@inline
def get4(array, i, c):
    return (array[i, c], array[i, c + 1], array[i, c + 2], array[i, c + 3])


@inline
def put4(array, i, c, v):
    array[i, c], array[i, c + 1], array[i, c + 2], array[i, c + 3] = v[0], v[1], v[2], v[3]


@inline
def get6(array, i, c):
    """A spatial vector ``((a0, a1, a2), (a3, a4, a5))`` from columns ``c`` to ``c + 5`` of row ``i``."""
    return ((array[i, c], array[i, c + 1], array[i, c + 2]), (array[i, c + 3], array[i, c + 4], array[i, c + 5]))


@inline
def put6(array, i, c, s):
    array[i, c], array[i, c + 1], array[i, c + 2] = s[0][0], s[0][1], s[0][2]
    array[i, c + 3], array[i, c + 4], array[i, c + 5] = s[1][0], s[1][1], s[1][2]


@inline
def get9(array, i, c):
    """A row-major 3x3 matrix (9-tuple) from columns ``c`` to ``c + 8`` of row ``i``."""
    return (
        array[i, c], array[i, c + 1], array[i, c + 2], array[i, c + 3], array[i, c + 4],
        array[i, c + 5], array[i, c + 6], array[i, c + 7], array[i, c + 8],
    )  # fmt: skip


@inline
def get10(array, i, c):
    """A spatial inertia (10-tuple) from columns ``c`` to ``c + 9`` of row ``i``."""
    return (
        array[i, c], array[i, c + 1], array[i, c + 2], array[i, c + 3], array[i, c + 4],
        array[i, c + 5], array[i, c + 6], array[i, c + 7], array[i, c + 8], array[i, c + 9],
    )  # fmt: skip


@inline
def put10(array, i, c, s):
    for k in range(10):
        array[i, c + k] = s[k]


# --- whole arrays (explicit loops: Numba compiles ``a[:] = b`` in seconds, a loop in milliseconds) -------


@inline
def assign(dst, src):
    """``dst[:] = src`` for 1-D arrays of the same length."""
    for k in range(dst.shape[0]):
        dst[k] = src[k]


@inline
def fill(dst, value):
    """``dst[:] = value`` for a 1-D array."""
    for k in range(dst.shape[0]):
        dst[k] = value


@inline
def fill_matrix(dst, value):
    """``dst[:, :] = value`` for a 2-D array."""
    for r in range(dst.shape[0]):
        for c in range(dst.shape[1]):
            dst[r, c] = value


# --- spatial algebra ---------------------------------------------------------------------------------


@inline
def add6(a, b):
    return (add(a[0], b[0]), add(a[1], b[1]))


@inline
def scale6(a, s):
    return (scale(a[0], s), scale(a[1], s))


@inline
def dot6(a, b):
    return dot(a[0], b[0]) + dot(a[1], b[1])


@inline
def cross_motion(v, m):
    """``v ×ₘ m``: the rate of change of the motion vector ``m`` carried by a body moving with ``v``."""
    return (cross(v[0], m[0]), add(cross(v[0], m[1]), cross(v[1], m[0])))


@inline
def cross_force(v, f):
    """``v ×_f f``: the same for a force vector (``= -(v ×ₘ)ᵀ f``)."""
    return (add(cross(v[0], f[0]), cross(v[1], f[1])), cross(v[0], f[1]))


@inline
def inertia_add(a, b):
    return (
        a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3], a[4] + b[4],
        a[5] + b[5], a[6] + b[6], a[7] + b[7], a[8] + b[8], a[9] + b[9],
    )  # fmt: skip


@inline
def inertia_apply(inertia, v):
    """The spatial momentum ``I v`` of a body of spatial inertia ``inertia`` moving with ``v``."""
    m, h = inertia[0], (inertia[1], inertia[2], inertia[3])
    xx, yy, zz, xy, xz, yz = inertia[4], inertia[5], inertia[6], inertia[7], inertia[8], inertia[9]
    w, vo = v[0], v[1]
    rotational = (
        xx * w[0] + xy * w[1] + xz * w[2],
        xy * w[0] + yy * w[1] + yz * w[2],
        xz * w[0] + yz * w[1] + zz * w[2],
    )
    return (add(rotational, cross(h, vo)), add(scale(vo, m), cross(w, h)))


@inline
def kinetic_energy(inertia, v):
    """``½ vᵀ I v`` [J]."""
    return 0.5 * dot6(v, inertia_apply(inertia, v))


@inline(into_callers=True)
def inertia_world(mass, com_local, inertia_local, pos, quat):
    """The spatial inertia of a link at pose ``(pos, quat)``.

    Args:
        mass: [kg]; com_local: 3-tuple [m], link frame; inertia_local: row-major 9-tuple [kg m²] about
            the centre of mass, link axes; pos: 3-tuple [m]; quat: unit 4-tuple, link to world.
    """
    r = quat_to_mat33(quat)
    c = add(pos, quat_rotate(quat, com_local))
    # R I: rows are R's rows times I; then (R I) Rᵀ, upper triangle only (the result is symmetric)
    a0 = mat_vec(inertia_local, (r[0], r[1], r[2]))
    a1 = mat_vec(inertia_local, (r[3], r[4], r[5]))
    a2 = mat_vec(inertia_local, (r[6], r[7], r[8]))
    row0, row1, row2 = (r[0], r[1], r[2]), (r[3], r[4], r[5]), (r[6], r[7], r[8])
    c2 = dot(c, c)
    xx = dot(a0, row0) + mass * (c2 - c[0] * c[0])
    yy = dot(a1, row1) + mass * (c2 - c[1] * c[1])
    zz = dot(a2, row2) + mass * (c2 - c[2] * c[2])
    xy = dot(a0, row1) - mass * c[0] * c[1]
    xz = dot(a0, row2) - mass * c[0] * c[2]
    yz = dot(a1, row2) - mass * c[1] * c[2]
    return (mass, mass * c[0], mass * c[1], mass * c[2], xx, yy, zz, xy, xz, yz)


@inline
def point_velocity(v, point):
    """The velocity of the body-fixed point ``point`` (world) of a body moving with spatial velocity ``v``."""
    return add(v[1], cross(v[0], point))


@inline
def point_acceleration(v, a, point):
    """The classical acceleration of a body-fixed point from the spatial velocity ``v`` and acceleration ``a``.

    ``ẍ = a_O + α × x + ω × ẋ`` (Featherstone 2008, §2.11: spatial, not classical, acceleration).
    """
    return add(add(a[1], cross(a[0], point)), cross(v[0], point_velocity(v, point)))


@inline
def sub6(a, b):
    return (sub(a[0], b[0]), sub(a[1], b[1]))
