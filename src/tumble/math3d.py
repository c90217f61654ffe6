"""Inline Numba helpers for the kernels: 3-vectors, quaternions and 3x3 matrices as tuples.

Tuples are values in Numba, so these helpers never allocate inside a kernel's loop. Vectors are
``(x, y, z)``; quaternions are ``(w, x, y, z)`` (scalar first, as everywhere in tumble); a 3x3 matrix is a
row-major 9-tuple. The vectorised NumPy versions for users live in :mod:`tumble.rotation`; the unit
tests check that both agree.
"""

from __future__ import annotations

import math

from . import elementary
from ._jit import inline

# --- vectors -----------------------------------------------------------------------------------------


@inline
def load3(array, i):
    """Row ``i`` of an ``(n, 3)`` array as a tuple."""
    return (array[i, 0], array[i, 1], array[i, 2])


@inline
def store3(array, i, v):
    """Write the tuple ``v`` into row ``i`` of an ``(n, 3)`` array."""
    array[i, 0] = v[0]
    array[i, 1] = v[1]
    array[i, 2] = v[2]


@inline
def load4(array, i):
    return (array[i, 0], array[i, 1], array[i, 2], array[i, 3])


@inline
def store4(array, i, q):
    array[i, 0] = q[0]
    array[i, 1] = q[1]
    array[i, 2] = q[2]
    array[i, 3] = q[3]


@inline
def load33(array, i):
    """The ``i``-th 3x3 matrix of an ``(n, 3, 3)`` array as a row-major 9-tuple."""
    return (
        array[i, 0, 0], array[i, 0, 1], array[i, 0, 2],
        array[i, 1, 0], array[i, 1, 1], array[i, 1, 2],
        array[i, 2, 0], array[i, 2, 1], array[i, 2, 2],
    )  # fmt: skip


@inline
def store33(array, i, m):
    """Write the row-major 9-tuple ``m`` into the ``i``-th 3x3 matrix of an ``(n, 3, 3)`` array."""
    for k in range(9):
        array[i, k // 3, k % 3] = m[k]


@inline
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@inline
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@inline
def scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


@inline
def add_scaled(a, b, s):
    """``a + s b``."""
    return (a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2])


@inline
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@inline
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@inline
def is_finite3(a):
    return math.isfinite(a[0]) and math.isfinite(a[1]) and math.isfinite(a[2])


# --- 3x3 matrices ------------------------------------------------------------------------------------


@inline
def mat_vec(m, v):
    """``M v`` for a row-major 9-tuple ``M``."""
    return (
        m[0] * v[0] + m[1] * v[1] + m[2] * v[2],
        m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
        m[6] * v[0] + m[7] * v[1] + m[8] * v[2],
    )


@inline
def _cramer33(m, b, c0, det):
    """``M⁻¹ b`` from the first column's cofactors ``c0`` and the determinant ``det``."""
    inv_det = 1.0 / det
    x0 = (b[0] * c0[0] + b[1] * (m[2] * m[7] - m[1] * m[8]) + b[2] * (m[1] * m[5] - m[2] * m[4])) * inv_det
    x1 = (b[0] * c0[1] + b[1] * (m[0] * m[8] - m[2] * m[6]) + b[2] * (m[2] * m[3] - m[0] * m[5])) * inv_det
    x2 = (b[0] * c0[2] + b[1] * (m[1] * m[6] - m[0] * m[7]) + b[2] * (m[0] * m[4] - m[1] * m[3])) * inv_det
    return (x0, x1, x2)


@inline
def solve33(m, b):
    """``M⁻¹ b`` by Cramer's rule (``M`` well conditioned: an inertia-like matrix).

    Where the determinant, a product of three entries, leaves the safe range (the inertia of a body of 1e-100 or
    1e300 kg), ``M`` and ``b`` are first scaled by the power of two nearest ``1 / max |M_ij|``: exact, so the answer
    is the one the unscaled formula gives wherever that one is finite."""
    c0 = (m[4] * m[8] - m[5] * m[7], m[5] * m[6] - m[3] * m[8], m[3] * m[7] - m[4] * m[6])
    det = m[0] * c0[0] + m[1] * c0[1] + m[2] * c0[2]
    if 1e-290 < abs(det) < 1e290:
        return _cramer33(m, b, c0, det)
    largest = max(abs(m[0]), abs(m[1]), abs(m[2]), abs(m[3]), abs(m[4]), abs(m[5]), abs(m[6]), abs(m[7]), abs(m[8]))
    scale = math.ldexp(1.0, -math.frexp(largest)[1]) if 0.0 < largest < math.inf else 1.0
    m = (m[0] * scale, m[1] * scale, m[2] * scale, m[3] * scale, m[4] * scale, m[5] * scale, m[6] * scale,
         m[7] * scale, m[8] * scale)  # fmt: skip
    b = (b[0] * scale, b[1] * scale, b[2] * scale)
    c0 = (m[4] * m[8] - m[5] * m[7], m[5] * m[6] - m[3] * m[8], m[3] * m[7] - m[4] * m[6])
    return _cramer33(m, b, c0, m[0] * c0[0] + m[1] * c0[1] + m[2] * c0[2])


# --- quaternions -------------------------------------------------------------------------------------


@inline
def quat_mul(p, q):
    """Hamilton product ``p ⊗ q``."""
    return (
        p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3],
        p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2],
        p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1],
        p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0],
    )


@inline
def quat_conj(q):
    return (q[0], -q[1], -q[2], -q[3])


@inline
def quat_normalize(q):
    inv = 1.0 / math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return (q[0] * inv, q[1] * inv, q[2] * inv, q[3] * inv)


@inline
def quat_rotate(q, v):
    """``q v q*`` for a unit quaternion, as ``v + 2 w (u × v) + 2 u × (u × v)`` with ``u`` the vector part."""
    u = (q[1], q[2], q[3])
    t = scale(cross(u, v), 2.0)
    return add(add_scaled(v, t, q[0]), cross(u, t))


@inline
def quat_rotate_inv(q, v):
    """``q* v q``: a world vector expressed in the body frame."""
    return quat_rotate(quat_conj(q), v)


@inline
def quat_derivative(q, w):
    """``dq/dt = ½ (0, ω) ⊗ q`` with ``ω`` in the world frame."""
    dq = quat_mul((0.0, w[0], w[1], w[2]), q)
    return (0.5 * dq[0], 0.5 * dq[1], 0.5 * dq[2], 0.5 * dq[3])


@inline
def quat_add_scaled(q, dq, s):
    """``q + s dq`` for 4-tuples."""
    return (q[0] + s * dq[0], q[1] + s * dq[1], q[2] + s * dq[2], q[3] + s * dq[3])


@inline
def quat_integrate(q, w, h):
    """First-order update ``q + h ½ (0, ω) ⊗ q``, renormalised."""
    return quat_normalize(quat_add_scaled(q, quat_derivative(q, w), h))


@inline
def quat_exp(w, h):
    """``exp(½ ω h)``: the rotation by the angle ``|ω| h`` about ``ω``, as a unit quaternion."""
    speed = math.sqrt(dot(w, w))
    half = 0.5 * speed * h
    if not math.isfinite(half):  # an overflowed state: NaN, which the step rejects (plain Python would raise)
        return (math.nan, math.nan, math.nan, math.nan)
    # sin(half) / speed → h / 2 as speed → 0; the series keeps full precision below 1e-4 rad
    if abs(half) < 1e-4:
        s = 0.5 * h * (1.0 - half * half / 6.0)
    else:
        s = elementary.sin(half) / speed
    return (elementary.cos(half), w[0] * s, w[1] * s, w[2] * s)


@inline
def quat_is_finite(q):
    return math.isfinite(q[0]) and math.isfinite(q[1]) and math.isfinite(q[2]) and math.isfinite(q[3])


# --- inertia -----------------------------------------------------------------------------------------


@inline
def world_inertia_apply(q, inertia_local, v):
    """``R I Rᵀ v``: apply a body-frame inertia-like 9-tuple to a world vector."""
    return quat_rotate(q, mat_vec(inertia_local, quat_rotate_inv(q, v)))


# --- rotation matrices and bounds --------------------------------------------------------------------


@inline
def quat_to_mat33(q):
    """The rotation matrix of a unit quaternion as a row-major 9-tuple (``R v == quat_rotate(q, v)``)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    return (
        1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y),
        2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x),
        2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y),
    )  # fmt: skip


@inline
def turned_symmetric33(q, a):
    """``R A Rᵀ`` for the rotation ``R`` of the unit quaternion ``q`` and a symmetric ``A`` (a row-major 9-tuple): an
    inertia, or its inverse, carried from one frame to another. The upper triangle, mirrored (about 90 flops)."""
    r = quat_to_mat33(q)
    # The rows of R A, then their products with the rows of R (the columns of Rᵀ) from the diagonal on.
    x0 = r[0] * a[0] + r[1] * a[3] + r[2] * a[6]
    y0 = r[0] * a[1] + r[1] * a[4] + r[2] * a[7]
    z0 = r[0] * a[2] + r[1] * a[5] + r[2] * a[8]
    x1 = r[3] * a[0] + r[4] * a[3] + r[5] * a[6]
    y1 = r[3] * a[1] + r[4] * a[4] + r[5] * a[7]
    z1 = r[3] * a[2] + r[4] * a[5] + r[5] * a[8]
    x2 = r[6] * a[0] + r[7] * a[3] + r[8] * a[6]
    y2 = r[6] * a[1] + r[7] * a[4] + r[8] * a[7]
    z2 = r[6] * a[2] + r[7] * a[5] + r[8] * a[8]
    m01 = x0 * r[3] + y0 * r[4] + z0 * r[5]
    m02 = x0 * r[6] + y0 * r[7] + z0 * r[8]
    m12 = x1 * r[6] + y1 * r[7] + z1 * r[8]
    return (x0 * r[0] + y0 * r[1] + z0 * r[2], m01, m02,
            m01, x1 * r[3] + y1 * r[4] + z1 * r[5], m12,
            m02, m12, x2 * r[6] + y2 * r[7] + z2 * r[8])  # fmt: skip


@inline
def abs_mat_vec(m, v):
    """``|M| v`` with ``|M|`` the element-wise absolute value: the half-widths of a box of half-widths ``v``
    turned by ``M`` (Ericson 2005, §4.2.6)."""
    return (
        abs(m[0]) * v[0] + abs(m[1]) * v[1] + abs(m[2]) * v[2],
        abs(m[3]) * v[0] + abs(m[4]) * v[1] + abs(m[5]) * v[2],
        abs(m[6]) * v[0] + abs(m[7]) * v[1] + abs(m[8]) * v[2],
    )


@inline
def abs3(a):
    return (abs(a[0]), abs(a[1]), abs(a[2]))


# --- lengths, directions and columns (contact generation) --------------------------------------------


@inline
def length3(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@inline
def normalize3(a):
    """``a / |a|``; ``a`` must be non-zero (callers pick their own fallback for the degenerate case)."""
    inv = 1.0 / math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    return (a[0] * inv, a[1] * inv, a[2] * inv)


@inline
def lerp3(a, b, t):
    """``a + t (b - a)``."""
    return (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]))


@inline
def perpendicular3(a):
    """A unit vector perpendicular to the unit vector ``a``: ``a`` crossed with an axis it is far from (some
    component of a unit vector is at least 1/√3 ≈ 0.57735 in size, so the cross product is never short)."""
    if abs(a[0]) >= 0.57735:
        return normalize3((a[1], -a[0], 0.0))
    return normalize3((0.0, a[2], -a[1]))


@inline
def mat_column(m, j):
    """Column ``j`` of a row-major 9-tuple (for a rotation matrix: the image of axis ``j``)."""
    return (m[j], m[3 + j], m[6 + j])
