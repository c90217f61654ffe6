"""Symbolic kinematics: rotation matrices in the generalised coordinates, velocities, angular velocities.

Positions are 3-vectors and rotations 3x3 matrices (body -> world) of SymPy expressions in the coordinates
``q(t)`` and the time ``t``. Velocities follow the course's velocity analysis (``course/004_…``, video 2.3):
``v = d r / dt`` and the skew-symmetric ``ω̂ = Ṙ Rᵀ`` (world frame) or ``Rᵀ Ṙ`` (body frame).

The angular velocity is assembled from the partial derivatives, ``ω̂ = Σ_j (∂R/∂q_j Rᵀ) q̇_j + ∂R/∂t Rᵀ``:
each ``∂R/∂q_j Rᵀ`` depends on ``q`` only and is trigonometrically simplified once, so ``ω`` of a chain
comes out as ``q̇1 + q̇2`` rather than as a sum of sine and cosine products.
"""

from __future__ import annotations

import sympy as sp
from sympy.core.function import AppliedUndef

from ._checks import TIME, as_matrix3, as_scalar, as_vector

__all__ = [
    "rotation_x",
    "rotation_y",
    "rotation_z",
    "rotation_about",
    "skew",
    "vee",
    "velocity",
    "angular_velocity",
    "jacobian",
    "angular_jacobian",
    "partial_time",
    "functions_of_time",
    "speed_squared",
]

# Gram entries larger than this are left unsimplified: trigsimp grows quickly with size, and the
# equations stay right either way (only their printed form is longer).
_TRIGSIMP_MAX_OPS = 400


def rotation_x(angle) -> sp.Matrix:
    """The 3x3 rotation by ``angle`` [rad] about the x axis (right-handed)."""
    a = as_scalar("angle", angle)
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def rotation_y(angle) -> sp.Matrix:
    """The 3x3 rotation by ``angle`` [rad] about the y axis (right-handed)."""
    a = as_scalar("angle", angle)
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rotation_z(angle) -> sp.Matrix:
    """The 3x3 rotation by ``angle`` [rad] about the z axis (right-handed)."""
    a = as_scalar("angle", angle)
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rotation_about(axis, angle) -> sp.Matrix:
    """Rodrigues' rotation ``R = cos a E + sin a [e]× + (1 - cos a) e eᵀ`` about the unit ``axis``.

    Args:
        axis: 3 numbers or expressions; a numeric axis is normalised, a symbolic one is taken as unit.
        angle: the angle [rad], an expression in the coordinates (or a number).
    """
    e = as_vector("axis", axis)
    if all(entry.is_number for entry in e):
        norm = sp.sqrt(sum(entry**2 for entry in e))
        if norm == 0:
            raise ValueError(f"axis must be non-zero, got {list(e)}")
        if norm != 1:
            e = e / norm
    a = as_scalar("angle", angle)
    c, s = sp.cos(a), sp.sin(a)
    return c * sp.eye(3) + s * skew(e) + (1 - c) * (e * e.T)


def skew(v) -> sp.Matrix:
    """The hat operator: ``skew(a) @ b == a × b``."""
    x, y, z = as_vector("v", v)
    return sp.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])


def vee(matrix) -> sp.Matrix:
    """The inverse of :func:`skew`: the 3-vector of a skew-symmetric matrix."""
    m = as_matrix3("matrix", matrix)
    return sp.Matrix([m[2, 1], m[0, 2], m[1, 0]])


def velocity(position) -> sp.Matrix:
    """``d r / dt`` of a position given in the coordinates ``q(t)`` and ``t``."""
    return as_vector("position", position).diff(TIME)


def jacobian(position, coordinates) -> sp.Matrix:
    """The 3 x n matrix ``∂r/∂q_j``: column ``j`` is the virtual displacement of the point per ``δq_j``."""
    r = as_vector("position", position)
    columns = [r.diff(q) for q in coordinates]
    return sp.Matrix.hstack(*columns) if columns else sp.zeros(3, 0)


def angular_jacobian(rotation, coordinates, *, frame: str = "world") -> tuple[sp.Matrix, sp.Matrix]:
    """``(J_ω, ω_t)`` with ``ω = J_ω q̇ + ω_t``: columns ``vee(∂R/∂q_j Rᵀ)`` (or ``vee(Rᵀ ∂R/∂q_j)``).

    Column ``j`` is the virtual rotation of the frame per ``δq_j`` (world or body components); ``ω_t`` the
    part from an explicit dependence on time. Each entry is trigonometrically simplified.
    """
    R = as_matrix3("rotation", rotation)
    if frame not in ("world", "body"):
        raise ValueError(f"frame must be 'world' or 'body', got {frame!r}")

    def rate(partial: sp.Matrix) -> sp.Matrix:
        product = partial * R.T if frame == "world" else R.T * partial
        return sp.Matrix([_tidy(entry) for entry in vee(product)])

    columns = [rate(R.diff(q)) for q in coordinates]
    explicit = rate(partial_time(R, coordinates))
    return sp.Matrix.hstack(*columns) if columns else sp.zeros(3, 0), explicit


def angular_velocity(rotation, coordinates, *, frame: str = "world") -> sp.Matrix:
    """The angular velocity ``ω`` of a frame whose rotation (body -> world) is ``rotation(q, t)``.

    Args:
        rotation: 3x3 expressions.
        coordinates: the generalised coordinates the rotation depends on.
        frame: ``"world"`` (``ω̂ = Ṙ Rᵀ``, the API's default) or ``"body"`` (``ω̂ = Rᵀ Ṙ``).
    """
    coords = list(coordinates)
    J, explicit = angular_jacobian(rotation, coords, frame=frame)
    if not coords:
        return explicit
    rates = sp.Matrix([q.diff(TIME) for q in coords])
    return J * rates + explicit


def partial_time(expression, coordinates):
    """``∂/∂t`` at fixed coordinates: the explicit (rheonomic) dependence on time only."""
    stand_ins = {q: sp.Dummy(str(q.func)) for q in coordinates}
    frozen = expression.xreplace(stand_ins)
    if not frozen.has(TIME):
        return expression * 0 if isinstance(expression, sp.MatrixBase) else sp.S.Zero
    return frozen.diff(TIME).xreplace({dummy: q for q, dummy in stand_ins.items()})


def functions_of_time(expression) -> list:
    """The functions of time ``q(t)`` in an expression or matrix, sorted (coordinates, prescribed inputs)."""
    found = [f for f in expression.atoms(AppliedUndef) if f.args == (TIME,)]
    return sorted(found, key=sp.default_sort_key)


def speed_squared(position) -> sp.Expr:
    """``v·v`` of a point ``r(q, t)``, as ``q̇ᵀ (JᵀJ) q̇ + 2 r_tᵀ J q̇ + r_t·r_t``.

    The Gram matrix ``JᵀJ`` (``J = ∂r/∂q``) depends on ``q`` only; simplifying its entries turns a
    pendulum's ``l² (sin² + cos²) θ̇²`` into ``l² θ̇²`` and a double pendulum's cross term into
    ``l1 l2 cos(θ1 - θ2)``.
    """
    r = as_vector("position", position)
    moving = functions_of_time(r)
    r_t = partial_time(r, moving)
    if not moving:
        return _tidy((r_t.T * r_t)[0, 0])
    J = jacobian(r, moving)
    rates = sp.Matrix([q.diff(TIME) for q in moving])
    gram = (J.T * J).applyfunc(_tidy)
    cross = (J.T * r_t).applyfunc(_tidy)
    return (rates.T * gram * rates)[0, 0] + 2 * (cross.T * rates)[0, 0] + _tidy((r_t.T * r_t)[0, 0])


def _tidy(entry: sp.Expr) -> sp.Expr:
    if entry == 0 or sp.count_ops(entry) > _TRIGSIMP_MAX_OPS:
        return entry
    return sp.trigsimp(sp.expand(entry))
