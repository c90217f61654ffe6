"""Rotations for users: quaternions, rotation matrices, axis-angle and rotation vectors, vectorised in NumPy.

Conventions (the same everywhere in tumble, see ``API.md``):

- A quaternion is a float64 array ``[w, x, y, z]``: scalar first, as in MuJoCo and as in the course's
  ``q = (cos θ/2, sin θ/2 ê)`` for a rotation by ``θ`` about the unit axis ``ê``.
- Products are Hamilton products (``i² = j² = k² = ijk = -1``), so ``p ⊗ q`` rotates by ``q`` first and then
  by ``p``, and ``quat_to_matrix(p ⊗ q) == quat_to_matrix(p) @ quat_to_matrix(q)``.
- Rotations are active: ``quat_rotate(q, v) = q v q⁻¹`` turns the vector ``v``; it does not re-express it in
  another frame. For a body with orientation ``q``, ``quat_rotate(q, v_body)`` is that vector in the world
  frame and ``quat_rotate(quat_conjugate(q), v_world)`` takes it back.
- ``q`` and ``-q`` are the same rotation. Functions that must pick one (``matrix_to_quat``, ``from_scipy``)
  return ``w >= 0``; ``quat_to_axis_angle`` and ``quat_to_rotvec`` return angles in ``[0, π]``.
- Angular velocity ``ω`` is a world-frame vector, so ``dq/dt = ½ (0, ω) ⊗ q`` (``quat_derivative``).

Every function takes lists, tuples or arrays, accepts leading batch dimensions (``(..., 4)``, ``(..., 3)``,
``(..., 3, 3)``) that broadcast against each other, and returns new float64 arrays. Input is checked at the
boundary: bad shapes, NaN or Inf and zero quaternions raise ``ValueError`` naming the argument, and
non-numbers raise ``TypeError``. The Numba versions used inside kernels live in :mod:`tumble.math3d`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from . import portable
from ._validate import _show, as_array, as_quaternion, scaled_down, vector_norm

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

__all__ = [
    "skew",
    "quat_identity",
    "quat_multiply",
    "quat_conjugate",
    "quat_inverse",
    "quat_normalize",
    "quat_rotate",
    "quat_from_axis_angle",
    "quat_to_axis_angle",
    "quat_from_rotvec",
    "quat_to_rotvec",
    "quat_to_matrix",
    "matrix_to_quat",
    "quat_slerp",
    "quat_derivative",
    "orthonormalize",
    "to_scipy",
    "from_scipy",
]

# A quaternion shorter than this has no meaningful direction; the same bound as ``_validate.as_quaternion``.
_MIN_QUAT_NORM = 1e-12
_LARGE = 1e150  # a vector with components below this rotates without scaling (|v| < 2e150)

# Below this angle the series forms take over from the closed forms (whose ratios become 0/0 at zero).
# The first neglected term is O(θ⁴) relative, i.e. below 1e-16 here: the series is exact in float64.
_SMALL_ANGLE = 1e-4

# Below this angle between the two quaternions slerp's sin Ω denominator is too small to trust; normalised
# lerp differs from slerp by O(Ω³), below 1e-18 here.
_SLERP_LERP_ANGLE = 1e-6

# How far from orthonormal a matrix handed to ``matrix_to_quat`` may be (max |RᵀR - I|): loose enough for
# matrices that went through float32 (~1e-7), tight enough to refuse anything that is not a rotation.
_ROTATION_ATOL = 1e-6

# Gram-Schmidt residuals smaller than this fraction of the matrix's scale are rounding noise: the columns
# are linearly dependent and no orthonormal frame follows from them.
_DEPENDENT_RTOL = 1e-12


# --- helpers -------------------------------------------------------------------------------------------


def _where(mask: np.ndarray) -> str:
    """`` at index (i, j)`` of the first true entry of a batch mask, or nothing for a single value."""
    if mask.ndim == 0:
        return ""
    index = tuple(int(i) for i in np.argwhere(mask)[0])
    return f" at index {index}"


def _nonzero(name: str, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(q', |q'|)`` with ``q'`` the same rotation as ``q`` scaled where its squares would overflow
    (``_validate.scaled_down``; ``q`` itself elsewhere), refusing a (near-)zero quaternion that has no rotation."""
    scaled, scale, norm = scaled_down(q)
    with np.errstate(over="ignore"):
        bad = norm * scale < _MIN_QUAT_NORM
    if np.any(bad):
        first = q[tuple(np.argwhere(bad)[0])] if bad.ndim else q
        raise ValueError(f"{name} must be a non-zero quaternion [w, x, y, z], got {_show(first)}{_where(bad)}")
    return scaled, norm


def _unit(name: str, q: np.ndarray) -> np.ndarray:
    scaled, norm = _nonzero(name, q)
    return scaled / norm[..., None]


def _stack(*components) -> np.ndarray:
    """Stack broadcast components along a new last axis (float64, always a fresh array)."""
    return np.stack(np.broadcast_arrays(*components), axis=-1).astype(np.float64, copy=False)


def _positive_w(q: np.ndarray) -> np.ndarray:
    """Pick the representative with ``w >= 0`` (``q`` and ``-q`` are the same rotation)."""
    q = np.where(q[..., :1] < 0.0, -q, q)
    # Adding +0.0 turns -0.0 into 0.0, so printed and compared results carry no stray signs.
    return q + 0.0


# --- basic algebra -------------------------------------------------------------------------------------


def skew(v) -> np.ndarray:
    """The hat (cross-product) operator: ``skew(a) @ b == cross(a, b)``.

    Args:
        v: (..., 3) vectors.

    Returns:
        (..., 3, 3) skew-symmetric matrices ``[[0, -z, y], [z, 0, -x], [-y, x, 0]]`` (course 001's ``ω̃``).

    Example:
        >>> skew([1.0, 2.0, 3.0])
        array([[ 0., -3.,  2.],
               [ 3.,  0., -1.],
               [-2.,  1.,  0.]])
    """
    v = as_array("v", v, (3,))
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    zero = np.zeros_like(x)
    rows = (_stack(zero, -z, y), _stack(z, zero, -x), _stack(-y, x, zero))
    # +0.0 keeps the zero diagonal free of -0.0 when an entry of v is negative.
    return np.stack(rows, axis=-2) + 0.0


def quat_identity() -> np.ndarray:
    """The identity rotation ``[1, 0, 0, 0]`` (a fresh (4,) array)."""
    return np.array([1.0, 0.0, 0.0, 0.0])


def quat_multiply(p, q) -> np.ndarray:
    """Hamilton product ``p ⊗ q``: rotate by ``q`` first, then by ``p``.

    ``p ⊗ q = (p_w q_w - p_v·q_v, p_w q_v + q_w p_v + p_v × q_v)`` (course 002, "Quaternion multiplication").

    Args:
        p: (..., 4) quaternions ``[w, x, y, z]``.
        q: (..., 4) quaternions; the batch dimensions of ``p`` and ``q`` broadcast.

    Returns:
        (..., 4) the products; unit if both factors are unit.
    """
    p = as_array("p", p, (4,))
    q = as_array("q", q, (4,))
    pw, px, py, pz = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    qw, qx, qy, qz = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return _stack(
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    )


def quat_conjugate(q) -> np.ndarray:
    """The conjugate ``(w, -x, -y, -z)``; for a unit quaternion, the inverse rotation.

    Args:
        q: (..., 4) quaternions.

    Returns:
        (..., 4) conjugates.
    """
    q = as_array("q", q, (4,))
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quat_inverse(q) -> np.ndarray:
    """The inverse ``q⁻¹ = conj(q) / |q|²`` (course 002): ``q ⊗ q⁻¹ = (1, 0, 0, 0)`` for any non-zero ``q``.

    Args:
        q: (..., 4) non-zero quaternions.

    Returns:
        (..., 4) inverses.

    Raises:
        ValueError: a quaternion in ``q`` is zero.
    """
    q = as_array("q", q, (4,))
    scaled, norm = _nonzero("q", q)
    if scaled is q:
        return quat_conjugate(q) / (norm * norm)[..., None]
    true_norm = vector_norm(q)[..., None]  # q⁻¹ = q* / |q|², divided twice so that |q|² cannot overflow
    return quat_conjugate(q) / true_norm / true_norm


def quat_normalize(q) -> np.ndarray:
    """``q / |q|``: the unit quaternion of the same rotation.

    Args:
        q: (..., 4) non-zero quaternions.

    Returns:
        (..., 4) unit quaternions (the sign is kept).

    Raises:
        ValueError: a quaternion in ``q`` is zero (it has no direction, so it is refused rather than guessed).
    """
    q = as_array("q", q, (4,))
    return _unit("q", q)


def quat_rotate(q, v) -> np.ndarray:
    """Rotate vectors: ``q v q⁻¹`` with ``v`` read as the pure quaternion ``(0, v)``.

    Meant for unit quaternions, but because ``q v q⁻¹`` does not change when ``q`` is scaled, any non-zero
    ``q`` rotates by ``q / |q|`` (the formula divides by ``|q|²`` once instead of normalising).

    Expanding the product with ``q = (w, u)`` gives ``v + (2/|q|²) (w (u × v) + u × (u × v))``, written
    with ``t = (2/|q|²) u × v`` as ``v + w t + u × t``: two cross products and no matrix.

    Args:
        q: (..., 4) non-zero quaternions, e.g. a body's orientation.
        v: (..., 3) vectors; batch dimensions broadcast against those of ``q``. With ``q`` a body's
            orientation, ``v`` in the body frame gives the result in the world frame.

    Returns:
        (..., 3) rotated vectors.

    Raises:
        ValueError: a quaternion in ``q`` is zero.
    """
    q = as_array("q", q, (4,))
    v = as_array("v", v, (3,))
    q, norm = _nonzero("q", q)
    scale = 1.0
    if v.size and not -_LARGE < v.min() <= v.max() < _LARGE:  # two passes, no copy: the usual vectors skip this
        v, scale, _ = scaled_down(v)  # a vector of 1e300 rotates as one of 1: t must not overflow on the way
    w = q[..., 0:1]
    u = q[..., 1:]
    t = np.cross(u, v) * (2.0 / (norm * norm))[..., None]
    rotated = v + w * t + np.cross(u, t)
    if isinstance(scale, float):  # nothing scaled: |t| <= 2 |v| / |q| <= 4e162 stays inside float range
        return rotated
    with np.errstate(over="ignore"):
        rotated *= scale[..., None]
    if not np.isfinite(rotated).all():  # |v| within one rounding of the largest float
        raise ValueError(f"v is too long to rotate within float range, got {_show(v * scale[..., None])}")
    return rotated


# --- axis-angle and rotation vectors -------------------------------------------------------------------


def _sin_half_over(angle: np.ndarray) -> np.ndarray:
    """``sin(θ/2) / θ``, with its Taylor series ``½ - θ²/48 + θ⁴/3840`` near zero (where it is 0/0)."""
    small = angle < _SMALL_ANGLE
    safe = np.where(small, 1.0, angle)
    a2 = np.where(small, angle, 0.0) ** 2  # the series' argument only where it is used (θ² of 1e200 overflows)
    return np.where(small, 0.5 - a2 / 48.0 + a2 * a2 / 3840.0, portable.sin(0.5 * safe) / safe)


def quat_from_axis_angle(axis, angle) -> np.ndarray:
    """The rotation by ``angle`` about ``axis``: ``(cos θ/2, sin θ/2 ê)`` with ``ê = axis / |axis|``.

    Args:
        axis: (..., 3) rotation axes, any non-zero length (normalised here).
        angle: (...) angles [rad], right-hand rule about ``axis``; any real value, broadcast against
            the batch dimensions of ``axis``.

    Returns:
        (..., 4) unit quaternions (``w < 0`` when ``|angle| > π``; that is the same rotation as ``-q``).

    Raises:
        ValueError: an axis is zero (it names ``axis`` and the value).

    Example:
        >>> q = quat_from_axis_angle([0.0, 0.0, 2.0], np.pi / 2)
        >>> np.round(q, 6)
        array([0.707107, 0.      , 0.      , 0.707107])
        >>> np.round(quat_rotate(q, [1.0, 0.0, 0.0]), 12) + 0.0
        array([0., 1., 0.])
    """
    axis = as_array("axis", axis, (3,))
    angle = as_array("angle", angle, ())
    scaled, _, length = scaled_down(axis)
    bad = length == 0.0
    if np.any(bad):
        raise ValueError(f"axis must be a non-zero vector, got {_show(axis)}{_where(bad)}")
    unit = scaled / np.where(bad, 1.0, length)[..., None]
    half = 0.5 * angle
    return _stack(portable.cos(half), *np.moveaxis(portable.sin(half)[..., None] * unit, -1, 0))


def quat_to_axis_angle(q) -> tuple[np.ndarray, np.ndarray]:
    """The axis and angle of a rotation, with the angle in ``[0, π]``.

    ``θ = 2 atan2(|u|, |w|)`` for ``q = (w, u)``: unlike ``2 acos(w)`` it keeps full precision for tiny and
    near-π angles and needs no normalisation (the ratio does not depend on ``|q|``).

    Args:
        q: (..., 4) non-zero quaternions.

    Returns:
        ``(axis, angle)``: (..., 3) unit axes and (...) angles [rad] in ``[0, π]``. The identity gives the
        axis ``(1, 0, 0)`` and angle 0. For an angle of exactly π both ``±axis`` are right; the sign of
        ``q``'s vector part is kept.

    Raises:
        ValueError: a quaternion in ``q`` is zero.
    """
    q, _ = _nonzero("q", as_array("q", q, (4,)))
    # Use the representative with w >= 0, whose angle lies in [0, π].
    q = _positive_w(q)
    u = q[..., 1:]
    length = np.linalg.norm(u, axis=-1)
    angle = 2.0 * portable.arctan2(length, q[..., 0])
    identity = length == 0.0
    axis = np.where(identity[..., None], np.array([1.0, 0.0, 0.0]), u / np.where(identity, 1.0, length)[..., None])
    return axis, angle


def quat_from_rotvec(r) -> np.ndarray:
    """The exponential map: the rotation by ``|r|`` about ``r / |r|``, i.e. ``(cos θ/2, (sin(θ/2)/θ) r)``.

    ``sin(θ/2)/θ`` switches to its Taylor series for ``θ < 1e-4``, so a tiny rotation vector keeps full
    relative precision (``quat_from_rotvec([1e-12, 0, 0])`` has ``x == 5e-13`` exactly) and zero maps to
    the identity.

    Args:
        r: (..., 3) rotation vectors [rad], angle times unit axis (any length; ``|r| > π`` is allowed).

    Returns:
        (..., 4) unit quaternions.

    Example:
        >>> np.round(quat_from_rotvec([0.0, np.pi, 0.0]), 12) + 0.0
        array([0., 0., 1., 0.])
        >>> quat_from_rotvec([1e-12, 0.0, 0.0])
        array([1.e+00, 5.e-13, 0.e+00, 0.e+00])
    """
    r = as_array("r", r, (3,))
    angle = vector_norm(r)
    if not np.isfinite(angle).all():
        raise ValueError(
            f"r must be rotation vectors of finite length (angle), got {_show(r)}{_where(~np.isfinite(angle))}"
        )
    vector = _sin_half_over(angle)[..., None] * r
    return _stack(portable.cos(0.5 * angle), *np.moveaxis(vector, -1, 0))


def quat_to_rotvec(q) -> np.ndarray:
    """The logarithm map: the rotation vector ``θ ê`` of ``q``, with ``θ`` in ``[0, π]``.

    For ``q = (w, u)`` taken with ``w >= 0``: ``θ = 2 atan2(|u|, w)`` and ``θ ê = (θ / |u|) u``. Unlike
    ``2 acos(w)``, ``atan2`` keeps full relative precision for tiny rotations; near the identity the ratio
    ``θ / |u|`` (0/0 at the identity itself) is taken from its series ``(2/w)(1 - s²/3 + s⁴/5)`` with
    ``s = |u|/w``, so the identity maps to exactly zero. ``q`` need not be unit.

    Args:
        q: (..., 4) non-zero quaternions.

    Returns:
        (..., 3) rotation vectors [rad] with norm in ``[0, π]``.

    Raises:
        ValueError: a quaternion in ``q`` is zero.
    """
    q, _ = _nonzero("q", as_array("q", q, (4,)))
    q = _positive_w(q)
    w = q[..., 0]
    u = q[..., 1:]
    length = np.linalg.norm(u, axis=-1)
    # s = tan(θ/2) is small exactly when the rotation is (|u| << w, so w > 0 on that branch).
    small = length < _SMALL_ANGLE * w
    safe_w = np.where(small, w, 1.0)
    s2 = (length / safe_w) ** 2
    series = (2.0 / safe_w) * (1.0 - s2 / 3.0 + s2 * s2 / 5.0)
    safe_length = np.where(small, 1.0, length)
    closed = 2.0 * portable.arctan2(length, w) / safe_length
    return np.where(small, series, closed)[..., None] * u


# --- rotation matrices ---------------------------------------------------------------------------------


def quat_to_matrix(q) -> np.ndarray:
    """The rotation matrix ``R`` with ``R v == quat_rotate(q, v)``.

    Uses ``s = 2 / |q|²`` in the usual expansion, so any non-zero ``q`` gives the (orthonormal) matrix of
    ``q / |q|``; for a unit quaternion it is the textbook formula with ``s = 2``.

    Args:
        q: (..., 4) non-zero quaternions.

    Returns:
        (..., 3, 3) rotation matrices (orthonormal, det +1). The columns are the body axes in the world
        frame when ``q`` is a body's orientation.

    Raises:
        ValueError: a quaternion in ``q`` is zero.
    """
    q, norm = _nonzero("q", as_array("q", q, (4,)))
    s = 2.0 / (norm * norm)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    xx, yy, zz = s * x * x, s * y * y, s * z * z
    xy, xz, yz = s * x * y, s * x * z, s * y * z
    wx, wy, wz = s * w * x, s * w * y, s * w * z
    # Filled entry by entry: stacking rows of broadcast components took 1.5 times as long (161 µs for one matrix).
    matrix = np.empty(q.shape[:-1] + (3, 3))
    matrix[..., 0, 0], matrix[..., 0, 1], matrix[..., 0, 2] = 1.0 - yy - zz, xy - wz, xz + wy
    matrix[..., 1, 0], matrix[..., 1, 1], matrix[..., 1, 2] = xy + wz, 1.0 - xx - zz, yz - wx
    matrix[..., 2, 0], matrix[..., 2, 1], matrix[..., 2, 2] = xz - wy, yz + wx, 1.0 - xx - yy
    return matrix


def matrix_to_quat(R) -> np.ndarray:
    """The unit quaternion (with ``w >= 0``) of a rotation matrix, robust for every rotation.

    Shepperd's method (S. W. Shepperd, "Quaternion from rotation matrix", J. Guidance and Control 1(3),
    1978, pp. 223-224): each of ``4w² = 1 + tr R``, ``4x² = 1 + 2R₀₀ - tr R`` (and the same for ``y``, ``z``)
    gives one component, and the off-diagonal sums and differences give the products of that component with
    the other three. Branching on the largest of ``tr R, R₀₀, R₁₁, R₂₂`` picks the largest component, whose
    square is at least ¼, so nothing is divided by a small number, even at angles of exactly π. Here the
    chosen row ``4 q_i q`` is normalised instead of divided by ``4 q_i``, which is the same thing.

    Args:
        R: (..., 3, 3) rotation matrices (orthonormal, det +1; up to 1e-6 off, e.g. after float32).

    Returns:
        (..., 4) unit quaternions ``[w, x, y, z]`` with ``w >= 0``.

    Raises:
        ValueError: ``R`` is not a rotation matrix (use :func:`orthonormalize` first for a drifted one).

    Example:
        >>> matrix_to_quat([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])
        array([0., 1., 0., 0.])
    """
    R = as_array("R", R, (3, 3))
    gram = np.swapaxes(R, -1, -2) @ R
    error = np.max(np.abs(gram - np.eye(3)), axis=(-2, -1))
    bad = (error > _ROTATION_ATOL) | (np.linalg.det(R) <= 0.0)
    if np.any(bad):
        first = R[tuple(np.argwhere(bad)[0])] if bad.ndim else R
        raise ValueError(
            "R must be a rotation matrix (orthonormal within 1e-6, det +1; see orthonormalize), "
            f"got {_show(first)}{_where(bad)}"
        )
    r00, r01, r02 = R[..., 0, 0], R[..., 0, 1], R[..., 0, 2]
    r10, r11, r12 = R[..., 1, 0], R[..., 1, 1], R[..., 1, 2]
    r20, r21, r22 = R[..., 2, 0], R[..., 2, 1], R[..., 2, 2]
    trace = r00 + r11 + r22
    # Row i is 4 q_i (w, x, y, z) computed from the entries of R (Shepperd's four cases).
    candidates = np.stack(
        [
            _stack(1.0 + trace, r21 - r12, r02 - r20, r10 - r01),
            _stack(r21 - r12, 1.0 + 2.0 * r00 - trace, r01 + r10, r02 + r20),
            _stack(r02 - r20, r01 + r10, 1.0 + 2.0 * r11 - trace, r12 + r21),
            _stack(r10 - r01, r02 + r20, r12 + r21, 1.0 + 2.0 * r22 - trace),
        ],
        axis=-2,
    )
    # The largest of (tr, R00, R11, R22) marks the largest |q_i| (4w² - 4x² = 2(tr - R00), and so on).
    case = np.argmax(np.stack([trace, r00, r11, r22], axis=-1), axis=-1)
    row = np.take_along_axis(candidates, case[..., None, None], axis=-2)[..., 0, :]
    # |row| = 4 |q_i| >= 2 for a rotation, so this division is always safe.
    q = row / np.linalg.norm(row, axis=-1, keepdims=True)
    return _positive_w(q)


def orthonormalize(A) -> np.ndarray:
    """Gram-Schmidt on the columns of ``A``: the re-orthonormalisation of a drifted orientation matrix.

    Exactly as course 001 ("Reorthonormalization of the Orientation"): ``b₁ = a₁/|a₁|``,
    ``b₂ = a₂ - (b₁·a₂) b₁`` normalised, ``b₃ = a₃ - (b₁·a₃) b₁ - (b₂·a₃) b₂`` normalised. The first column
    keeps its direction, the second stays in the plane of the first two; the result is not the nearest
    orthonormal matrix (that would be the polar decomposition), but it is cheap and leaves an orthonormal
    ``A`` unchanged. ``det`` keeps the sign of ``det A``: a rotation stays a rotation. Being classical
    Gram-Schmidt, orthogonality degrades like ``eps cond(A)²`` for ill-conditioned ``A``; a drifted rotation
    has ``cond(A) ≈ 1`` and comes back orthonormal to rounding.

    Args:
        A: (..., 3, 3) matrices with linearly independent columns.

    Returns:
        (..., 3, 3) matrices with orthonormal columns.

    Raises:
        ValueError: the columns of ``A`` are (numerically) linearly dependent.
    """
    A = as_array("A", A, (3, 3))
    a1, a2, a3 = A[..., :, 0], A[..., :, 1], A[..., :, 2]
    # The scale that rounding noise in the residuals is measured against.
    scale = np.max(np.linalg.norm(A, axis=-2), axis=-1)

    def unit(b: np.ndarray) -> np.ndarray:
        length = np.linalg.norm(b, axis=-1)
        bad = ~(length > _DEPENDENT_RTOL * scale)
        if np.any(bad):
            first = A[tuple(np.argwhere(bad)[0])] if bad.ndim else A
            raise ValueError(
                f"A must have linearly independent columns to orthonormalize, got {_show(first)}{_where(bad)}"
            )
        return b / length[..., None]

    def along(b: np.ndarray, a: np.ndarray) -> np.ndarray:
        """The component of ``a`` along the unit vector ``b``."""
        return np.sum(b * a, axis=-1, keepdims=True) * b

    b1 = unit(a1)
    b2 = unit(a2 - along(b1, a2))
    b3 = unit(a3 - along(b1, a3) - along(b2, a3))
    return np.stack([b1, b2, b3], axis=-1)


# --- interpolation and kinematics ----------------------------------------------------------------------


def quat_slerp(q0, q1, t) -> np.ndarray:
    """Shortest-path spherical linear interpolation from ``q0`` (``t = 0``) to ``q1`` (``t = 1``).

    ``slerp = (sin((1-t)Ω) q0 + sin(tΩ) q1) / sin Ω`` with ``Ω`` the angle between the two unit quaternions
    (Shoemake, "Animating rotation with quaternion curves", SIGGRAPH 1985). ``q1`` is first replaced by
    ``-q1`` when ``q0·q1 < 0``, so the path is the shorter of the two (the rotation angle covered is at most
    π). The angle turns at a constant rate in ``t``. ``Ω = 2 atan2(|q1 - q0|, |q1 + q0|)`` stays accurate
    for tiny angles, and below 1e-6 rad the normalised linear interpolation is used instead (it differs from
    slerp by O(Ω³)).

    Args:
        q0: (..., 4) non-zero quaternions at ``t = 0`` (normalised here).
        q1: (..., 4) non-zero quaternions at ``t = 1`` (normalised here).
        t: (...) interpolation parameters, a scalar or an array; batch dimensions of ``q0``, ``q1`` and
            ``t`` broadcast. Values outside ``[0, 1]`` extrapolate along the same great circle.

    Returns:
        (..., 4) unit quaternions; ``t = 0`` gives ``q0`` and ``t = 1`` gives ``±q1``.

    Raises:
        ValueError: a quaternion in ``q0`` or ``q1`` is zero.
    """
    q0 = as_array("q0", q0, (4,))
    q1 = as_array("q1", q1, (4,))
    t = as_array("t", t, ())
    q0 = _unit("q0", q0)
    q1 = _unit("q1", q1)
    # Shortest path: q1 and -q1 are the same rotation; take the one in q0's hemisphere.
    q1 = np.where(np.sum(q0 * q1, axis=-1, keepdims=True) < 0.0, -q1, q1)
    omega = 2.0 * portable.arctan2(np.linalg.norm(q1 - q0, axis=-1), np.linalg.norm(q1 + q0, axis=-1))
    omega, t = np.broadcast_arrays(omega, t)
    small = omega < _SLERP_LERP_ANGLE
    safe_omega = np.where(small, 1.0, omega)
    sin_omega = portable.sin(safe_omega)
    c0 = np.where(small, 1.0 - t, portable.sin((1.0 - t) * safe_omega) / sin_omega)
    c1 = np.where(small, t, portable.sin(t * safe_omega) / sin_omega)
    q = c0[..., None] * q0 + c1[..., None] * q1
    # Exact slerp is already unit; this removes rounding and is the "normalised" of normalised lerp.
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def quat_derivative(q, omega) -> np.ndarray:
    """The time derivative of an orientation: ``dq/dt = ½ (0, ω) ⊗ q`` with ``ω`` in the WORLD frame.

    With ``q(t+h) ≈ exp(h ω / 2) ⊗ q(t)`` (a small world-frame rotation applied after ``q``), the derivative
    is ``½ (0, ω) ⊗ q`` (course 002, "Instantaneous Rotation"). For a body-frame ``ω_body`` it would be
    ``½ q ⊗ (0, ω_body)``.

    Args:
        q: (..., 4) orientations (unit quaternions for a physical derivative; not normalised here).
        omega: (..., 3) angular velocities [rad/s], world frame; batch dimensions broadcast against ``q``.

    Returns:
        (..., 4) ``dq/dt`` [1/s].
    """
    q = as_array("q", q, (4,))
    omega = as_array("omega", omega, (3,))
    pure = np.concatenate([np.zeros(omega.shape[:-1] + (1,)), omega], axis=-1)
    return 0.5 * quat_multiply(pure, q)


# --- SciPy interop -------------------------------------------------------------------------------------


def to_scipy(q) -> Rotation:
    """A :class:`scipy.spatial.transform.Rotation` from tumble quaternions.

    SciPy stores quaternions scalar LAST (``[x, y, z, w]``); this reorders them, so the result rotates
    exactly as :func:`quat_rotate` does (SciPy normalises the quaternion).

    Args:
        q: (4,) or (..., 4) non-zero quaternions ``[w, x, y, z]``. More than one batch dimension needs a
            SciPy whose ``Rotation`` accepts N-D arrays (1.17 does).

    Returns:
        One Rotation (for (4,)) or a stack of them.

    Raises:
        ValueError: a quaternion in ``q`` is zero.
    """
    from scipy.spatial.transform import Rotation  # on first use: import tumble stays light

    q, _ = _nonzero("q", as_array("q", q, (4,)))
    return Rotation.from_quat(q[..., [1, 2, 3, 0]])


def from_scipy(rotation: Rotation) -> np.ndarray:
    """Tumble quaternions ``[w, x, y, z]`` with ``w >= 0`` from a :class:`scipy.spatial.transform.Rotation`.

    Args:
        rotation: one Rotation or a stack of them.

    Returns:
        (4,) or (..., 4) unit quaternions, scalar first, ``w >= 0``.

    Raises:
        TypeError: ``rotation`` is not a SciPy Rotation.

    Example:
        >>> from scipy.spatial.transform import Rotation
        >>> np.round(from_scipy(Rotation.from_rotvec([0.0, 0.0, np.pi / 2])), 6)
        array([0.707107, 0.      , 0.      , 0.707107])
    """
    from scipy.spatial.transform import Rotation

    if not isinstance(rotation, Rotation):
        raise TypeError(
            f"rotation must be a scipy.spatial.transform.Rotation, got {_show(rotation)} ({type(rotation).__name__})"
        )
    xyzw = np.asarray(rotation.as_quat(), dtype=np.float64)
    return _positive_w(xyzw[..., [3, 0, 1, 2]])


def as_rotation(name: str, value) -> np.ndarray:
    """A rotation given as a unit quaternion (4,) or a proper rotation matrix (3, 3); returns the matrix."""
    array = np.asarray(value, dtype=np.float64) if not isinstance(value, (str, bytes)) else None
    if array is not None and array.shape == (4,):
        return quat_to_matrix(as_quaternion(name, array))
    matrix = as_array(name, value, (3, 3), batch=False)
    if not np.allclose(matrix.T @ matrix, np.eye(3), atol=1e-6) or np.linalg.det(matrix) < 0.0:
        raise ValueError(f"{name} must be a proper rotation matrix (orthonormal, det +1), got {_show(matrix)}")
    return matrix.copy()
