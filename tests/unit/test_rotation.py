"""Unit tests for tumble.rotation: conventions, round trips at the edge angles, Shepperd's branches,
slerp, the world-frame derivative, Gram-Schmidt, batching, SciPy agreement and input checking.

Tolerances are in units of float64 rounding (eps = 2.2e-16); each one says what was measured.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tumble import rotation as rot

EPS = np.finfo(np.float64).eps
ANGLES = [0.0, 1e-12, 1e-6, np.pi / 2, np.pi - 1e-9, np.pi]
AXES = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 2.0, -3.0), (-0.3, 0.1, 0.9)]


def unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_quats(n, seed=0) -> np.ndarray:
    """Uniformly distributed unit quaternions (normalised Gaussians), both signs of w."""
    return unit(np.random.default_rng(seed).normal(size=(n, 4)))


def sign_free_error(q, p) -> np.ndarray:
    """Max-abs distance between q and the nearer of ±p (q and -q are the same rotation)."""
    q, p = np.asarray(q), np.asarray(p)
    return np.minimum(np.abs(q - p).max(axis=-1), np.abs(q + p).max(axis=-1))


# --- skew, product, conjugate, inverse, normalize ------------------------------------------------------


def test_skew_is_the_cross_product_matrix():
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=(2, 50, 3))
    S = rot.skew(a)
    assert S.shape == (50, 3, 3)
    # measured 4.4e-16 (entries of a and b up to ~3, one product and one difference per entry)
    np.testing.assert_allclose(S @ b[..., None], np.cross(a, b)[..., None], rtol=0, atol=8 * EPS)
    np.testing.assert_array_equal(S, -np.swapaxes(S, -1, -2))
    # Course 001's layout of ω̃, entry by entry.
    np.testing.assert_array_equal(rot.skew([1, 2, 3]), [[0, -3, 2], [3, 0, -1], [-2, 1, 0]])


def test_hamilton_product_basis_units():
    one, i, j, k = np.eye(4)
    # Hamilton's i j = k and j i = -k (the JPL convention would give the opposite signs).
    np.testing.assert_array_equal(rot.quat_multiply(i, j), k)
    np.testing.assert_array_equal(rot.quat_multiply(j, i), -k)
    np.testing.assert_array_equal(rot.quat_multiply(j, k), i)
    np.testing.assert_array_equal(rot.quat_multiply(k, i), j)
    np.testing.assert_array_equal(rot.quat_multiply(i, i), -one)
    np.testing.assert_array_equal(rot.quat_multiply(rot.quat_identity(), j), j)


def test_product_composes_like_matrices():
    p, q = random_quats(200, seed=2), random_quats(200, seed=3)
    lhs = rot.quat_to_matrix(rot.quat_multiply(p, q))
    rhs = rot.quat_to_matrix(p) @ rot.quat_to_matrix(q)
    # measured 7.8e-16
    np.testing.assert_allclose(lhs, rhs, rtol=0, atol=8 * EPS)


def test_product_rotates_by_q_then_by_p():
    p, q = random_quats(100, seed=4), random_quats(100, seed=5)
    v = np.random.default_rng(6).normal(size=(100, 3))
    # measured 1.6e-15 for |v| components up to 3.1
    np.testing.assert_allclose(
        rot.quat_rotate(rot.quat_multiply(p, q), v), rot.quat_rotate(p, rot.quat_rotate(q, v)), atol=40 * EPS
    )


def test_rotation_is_active_and_right_handed():
    quarter_z = rot.quat_from_axis_angle([0, 0, 1], np.pi / 2)
    # +90° about z carries x onto y (the vector moves; the frame does not).
    np.testing.assert_allclose(rot.quat_rotate(quarter_z, [1, 0, 0]), [0, 1, 0], atol=2 * EPS)
    np.testing.assert_allclose(rot.quat_to_matrix(quarter_z) @ [1, 0, 0], [0, 1, 0], atol=2 * EPS)


def test_conjugate_and_inverse():
    q = np.array([1.0, -2.0, 0.5, 3.0])  # deliberately not unit
    np.testing.assert_array_equal(rot.quat_conjugate(q), [1.0, 2.0, -0.5, -3.0])
    # measured 0 (exact) on both products
    np.testing.assert_allclose(rot.quat_multiply(q, rot.quat_inverse(q)), [1, 0, 0, 0], atol=4 * EPS)
    np.testing.assert_allclose(rot.quat_multiply(rot.quat_inverse(q), q), [1, 0, 0, 0], atol=4 * EPS)
    u = random_quats(20, seed=7)
    # measured 2.2e-16: for unit q the inverse is the conjugate
    np.testing.assert_allclose(rot.quat_inverse(u), rot.quat_conjugate(u), atol=2 * EPS)
    assert np.all(q == [1.0, -2.0, 0.5, 3.0]), "inputs must not be modified"


def test_normalize_keeps_direction_and_sign():
    q = np.array([[-3.0, 0.0, 4.0, 0.0], [0.0, 0.0, 0.0, 1e-3]])
    np.testing.assert_allclose(rot.quat_normalize(q), [[-0.6, 0.0, 0.8, 0.0], [0.0, 0.0, 0.0, 1.0]], atol=EPS)


def test_rotate_and_matrix_accept_non_unit_quaternions():
    q = random_quats(30, seed=8)
    v = np.random.default_rng(9).normal(size=(30, 3))
    scaled = 7.5 * q
    # q v q⁻¹ does not change when q is scaled; measured 1.3e-15 (vectors) and 5.6e-16 (matrices)
    np.testing.assert_allclose(rot.quat_rotate(scaled, v), rot.quat_rotate(q, v), atol=16 * EPS)
    np.testing.assert_allclose(rot.quat_to_matrix(scaled), rot.quat_to_matrix(q), atol=8 * EPS)


def test_rotate_agrees_with_matrix():
    q = random_quats(100, seed=10)
    v = np.random.default_rng(11).normal(size=(100, 3))
    expected = np.einsum("nij,nj->ni", rot.quat_to_matrix(q), v)
    # measured 6.7e-16 for |v| components up to ~3
    np.testing.assert_allclose(rot.quat_rotate(q, v), expected, atol=16 * EPS)


# --- round trips at the edge angles --------------------------------------------------------------------


@pytest.mark.parametrize("axis", AXES)
@pytest.mark.parametrize("angle", ANGLES)
def test_round_trips(angle, axis):
    e = unit(axis)
    q = rot.quat_from_axis_angle(axis, angle)
    np.testing.assert_allclose(np.linalg.norm(q), 1.0, atol=2 * EPS)
    np.testing.assert_allclose(q, [np.cos(angle / 2), *(np.sin(angle / 2) * e)], atol=2 * EPS)

    # rotvec -> quat agrees with axis-angle -> quat; measured 2.2e-16
    np.testing.assert_allclose(rot.quat_from_rotvec(angle * e), q, rtol=0, atol=2 * EPS)

    # quat -> rotvec keeps full RELATIVE precision even for tiny angles; measured 2.4e-16 relative
    rotvec = rot.quat_to_rotvec(q)
    if angle == np.pi:
        # w = cos(π/2) = 6e-17 > 0 in float64, so the sign of the axis survives
        np.testing.assert_allclose(rotvec, np.pi * e, rtol=4 * EPS)
    else:
        assert np.linalg.norm(rotvec - angle * e) <= 4 * EPS * angle

    # quat -> axis-angle; measured: the angle within 2e-22, the axis within 1.1e-16
    axis_back, angle_back = rot.quat_to_axis_angle(q)
    assert abs(angle_back - angle) <= 2 * EPS * max(angle, 1.0)
    assert 0.0 <= angle_back <= np.pi
    np.testing.assert_allclose(axis_back, [1.0, 0.0, 0.0] if angle == 0.0 else e, atol=2 * EPS)

    # quat -> matrix is orthonormal (measured 6.7e-16); -> quat (Shepperd) has w >= 0 (measured 1.1e-16)
    R = rot.quat_to_matrix(q)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=8 * EPS)
    q_back = rot.matrix_to_quat(R)
    assert q_back[0] >= 0.0
    assert sign_free_error(q_back, q) <= 2 * EPS


def test_axis_angle_of_identity_and_negative_w():
    axis, angle = rot.quat_to_axis_angle([-1.0, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(axis, [1.0, 0.0, 0.0])
    assert angle == 0.0
    # -q is the same rotation, so w < 0 still gives angle 2.5 about +e (not 2π - 2.5).
    q = -rot.quat_from_axis_angle([0.0, 3.0, 4.0], 2.5)
    axis, angle = rot.quat_to_axis_angle(q)
    np.testing.assert_allclose(angle, 2.5, atol=4 * EPS)  # measured 0
    np.testing.assert_allclose(axis, [0.0, 0.6, 0.8], atol=2 * EPS)  # measured 0
    # An angle above π comes back as its complement about the opposite axis.
    axis, angle = rot.quat_to_axis_angle(rot.quat_from_axis_angle([0, 0, 1], 1.5 * np.pi))
    np.testing.assert_allclose(angle, 0.5 * np.pi, atol=4 * EPS)  # measured 2.2e-16
    np.testing.assert_allclose(axis, [0, 0, -1], atol=2 * EPS)  # measured 0


def test_rotvec_log_is_inverse_of_exp_for_large_and_negative_w():
    rotvec = np.array([0.4, -2.0, 1.1])  # |r| = 2.32 < π
    q = rot.quat_from_rotvec(rotvec)
    np.testing.assert_allclose(rot.quat_to_rotvec(-q), rotvec, atol=8 * EPS)  # measured 2.2e-16
    # Beyond π the logarithm wraps to the shorter rotation about the opposite axis.
    e = unit([1.0, 1.0, 0.0])
    np.testing.assert_allclose(rot.quat_to_rotvec(rot.quat_from_rotvec(4.0 * e)), (4.0 - 2 * np.pi) * e, atol=8 * EPS)


def test_tiny_rotvec_keeps_relative_precision():
    # A naive 2 acos(w) loses everything here (w rounds to 1); the sinc-style forms must not.
    r = np.array([3e-13, -1e-12, 2e-12])
    q = rot.quat_from_rotvec(r)
    np.testing.assert_allclose(q[1:], 0.5 * r, rtol=EPS)  # measured exact
    np.testing.assert_allclose(rot.quat_to_rotvec(q), r, rtol=2 * EPS)  # measured exact
    np.testing.assert_array_equal(rot.quat_to_rotvec([1.0, 0.0, 0.0, 0.0]), [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(rot.quat_from_rotvec([0.0, 0.0, 0.0]), [1.0, 0.0, 0.0, 0.0])


def test_rotvec_series_and_closed_form_meet_smoothly():
    # Either side of the 1e-4 switch the two formulas must agree to rounding; measured 2.2e-16 relative.
    e = unit([1.0, -2.0, 0.5])
    for angle in (1e-4 * (1 - 1e-9), 1e-4 * (1 + 1e-9), 2e-4 * (1 - 1e-9), 2e-4 * (1 + 1e-9)):
        q = rot.quat_from_rotvec(angle * e)
        np.testing.assert_allclose(q[1:], np.sin(angle / 2) * e, rtol=4 * EPS)
        np.testing.assert_allclose(rot.quat_to_rotvec(q), angle * e, rtol=4 * EPS)


# --- Shepperd's four branches --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("q", "branch"),
    [
        # Generic quaternions whose largest component is w, x, y, z in turn, every component non-zero,
        # so all off-diagonal formulas of that branch are exercised.
        ([0.9, 0.3, -0.2, 0.25], 0),
        ([0.2, -0.85, 0.35, 0.3], 1),
        ([-0.3, 0.25, 0.9, -0.15], 2),
        ([0.15, -0.3, 0.2, -0.9], 3),
    ],
)
def test_matrix_to_quat_each_shepperd_branch(q, branch):
    q = unit(q)
    R = rot.quat_to_matrix(q)
    trace = np.trace(R)
    assert np.argmax([trace, R[0, 0], R[1, 1], R[2, 2]]) == branch, "test input does not reach the branch"
    q_back = rot.matrix_to_quat(R)
    assert q_back[0] >= 0.0
    np.testing.assert_allclose(q_back, q * np.sign(q[0]), atol=2 * EPS)  # measured 1.1e-16


@pytest.mark.parametrize(
    ("R", "expected"),
    [
        (np.diag([1.0, -1.0, -1.0]), [0.0, 1.0, 0.0, 0.0]),  # π about x: the R00 branch
        (np.diag([-1.0, 1.0, -1.0]), [0.0, 0.0, 1.0, 0.0]),  # π about y: the R11 branch
        (np.diag([-1.0, -1.0, 1.0]), [0.0, 0.0, 0.0, 1.0]),  # π about z: the R22 branch
        (np.eye(3), [1.0, 0.0, 0.0, 0.0]),  # identity: the trace branch
    ],
)
def test_matrix_to_quat_half_turns_are_exact(R, expected):
    # At w = 0 the trace-only formula divides 0 by 0; Shepperd's branches give the exact answer.
    np.testing.assert_array_equal(rot.matrix_to_quat(R), expected)


def test_matrix_to_quat_near_half_turn_keeps_precision():
    # π - 1e-9 about a generic axis: 1 + tr R ≈ 1e-18, so a trace-only formula would be pure noise.
    axes = unit(np.random.default_rng(12).normal(size=(50, 3)))
    q = rot.quat_from_axis_angle(axes, np.pi - 1e-9)
    q_back = rot.matrix_to_quat(rot.quat_to_matrix(q))
    assert np.all(q_back[:, 0] >= 0.0)
    assert np.max(sign_free_error(q_back, q)) <= 4 * EPS  # measured 1.1e-16
    # Near identity (the trace branch) the vector part is only as good as the matrix entries: absolute 1e-16.
    q = rot.quat_from_axis_angle(axes, 1e-6)
    assert np.max(sign_free_error(rot.matrix_to_quat(rot.quat_to_matrix(q)), q)) <= 2 * EPS  # measured 1.1e-16


def test_matrix_to_quat_returns_nonnegative_w():
    q = random_quats(500, seed=13)
    assert np.any(q[:, 0] < 0), "the input should include w < 0"
    q_back = rot.matrix_to_quat(rot.quat_to_matrix(q))
    assert np.all(q_back[:, 0] >= 0.0)
    # measured 3.3e-16
    np.testing.assert_allclose(q_back, q * np.where(q[:, :1] < 0, -1.0, 1.0), atol=4 * EPS)
    np.testing.assert_allclose(np.linalg.norm(q_back, axis=-1), 1.0, atol=2 * EPS)


@pytest.mark.parametrize(
    "R",
    [
        np.diag([1.0, 1.0, -1.0]),  # a reflection: orthonormal but det -1
        2.0 * np.eye(3),  # not orthonormal
        np.eye(3) + 1e-4,  # drifted far past float32 rounding
    ],
)
def test_matrix_to_quat_refuses_non_rotations(R):
    with pytest.raises(ValueError, match=r"R must be a rotation matrix"):
        rot.matrix_to_quat(R)


def test_matrix_to_quat_accepts_float32_rounding():
    q = random_quats(10, seed=14)
    R32 = rot.quat_to_matrix(q).astype(np.float32)
    # float32 rounding leaves |RᵀR - I| ~ 1e-7, the result is float32-accurate (measured 1.6e-8)
    np.testing.assert_array_less(sign_free_error(rot.matrix_to_quat(R32), q), 1e-6)


# --- slerp ---------------------------------------------------------------------------------------------


def angle_between(p, q) -> np.ndarray:
    """Rotation angle of p⁻¹ q, in [0, π]."""
    return rot.quat_to_axis_angle(rot.quat_multiply(rot.quat_conjugate(p), q))[1]


def test_slerp_endpoints():
    q0, q1 = random_quats(40, seed=15), random_quats(40, seed=16)
    # measured 1.1e-16 at both ends (q1 may come back as -q1 when q0·q1 < 0)
    np.testing.assert_allclose(rot.quat_slerp(q0, q1, 0.0), q0, atol=4 * EPS)
    assert np.max(sign_free_error(rot.quat_slerp(q0, q1, 1.0), q1)) <= 4 * EPS


def test_slerp_midpoint_is_half_the_angle():
    q0, q1 = random_quats(40, seed=17), random_quats(40, seed=18)
    mid = rot.quat_slerp(q0, q1, 0.5)
    # measured 4.4e-16 (angles from atan2 of products of unit quaternions)
    np.testing.assert_allclose(angle_between(q0, mid), 0.5 * angle_between(q0, q1), atol=1e-14)
    np.testing.assert_allclose(angle_between(mid, q1), 0.5 * angle_between(q0, q1), atol=1e-14)


def test_slerp_takes_the_short_way():
    q0 = rot.quat_identity()
    q1 = -rot.quat_from_axis_angle([0, 0, 1], 0.2)  # the same rotation, but q0·q1 < 0
    assert np.dot(q0, q1) < 0
    mid = rot.quat_slerp(q0, q1, 0.5)
    # the short way turns 0.1 about +z; the long way would turn π - 0.1 about -z. Measured 0.
    assert sign_free_error(mid, rot.quat_from_axis_angle([0, 0, 1], 0.1)) <= 2 * EPS
    for t in np.linspace(0.0, 1.0, 11):
        assert angle_between(q0, rot.quat_slerp(q0, q1, t)) <= 0.2 + 1e-15


def test_slerp_constant_angular_speed():
    q0 = rot.quat_from_rotvec([0.3, -1.0, 0.5])
    q1 = rot.quat_from_rotvec([-1.2, 0.4, 2.0])
    t = np.linspace(0.0, 1.0, 21)
    path = rot.quat_slerp(q0, q1, t)
    assert path.shape == (21, 4)
    steps = angle_between(path[:-1], path[1:])
    total = angle_between(q0, q1)
    # every step covers 1/20 of the total angle; measured 3.6e-16 (a normalised lerp is off by 2.4e-2 here)
    np.testing.assert_allclose(steps, total / 20, atol=1e-14)


def test_slerp_tiny_angle_falls_back_cleanly():
    q0 = rot.quat_from_rotvec([0.1, 0.2, 0.3])
    delta = rot.quat_from_rotvec([1e-9, 0.0, 0.0])
    q1 = rot.quat_multiply(delta, q0)
    mid = rot.quat_slerp(q0, q1, 0.5)
    expected = rot.quat_multiply(rot.quat_from_rotvec([5e-10, 0.0, 0.0]), q0)
    assert np.all(np.isfinite(mid))
    assert sign_free_error(mid, expected) <= 2 * EPS  # measured 1.4e-17
    # Between a quaternion and itself: itself, renormalised (q0 is unit to round-off, not exactly).
    np.testing.assert_allclose(rot.quat_slerp(q0, q0, 0.3), q0, rtol=0, atol=EPS)


def test_slerp_normalises_inputs_and_broadcasts():
    q0, q1 = random_quats(6, seed=19), random_quats(6, seed=20)
    t = np.linspace(0.0, 1.0, 5)[:, None]  # (5, 1) against (6,) batches -> (5, 6)
    out = rot.quat_slerp(3.0 * q0, 0.5 * q1, t)
    assert out.shape == (5, 6, 4)
    np.testing.assert_allclose(np.linalg.norm(out, axis=-1), 1.0, atol=2 * EPS)
    np.testing.assert_allclose(out[2], rot.quat_slerp(q0, q1, 0.5), atol=2 * EPS)  # measured 1.1e-16


# --- derivative (world-frame ω) -------------------------------------------------------------------------


def test_derivative_matches_finite_difference_in_world_frame():
    rng = np.random.default_rng(21)
    q0 = random_quats(20, seed=22)
    omega = rng.normal(size=(20, 3))
    t, h = 0.7, 1e-5

    def q_of(time):
        # constant world-frame ω: q(t) = exp(t ω/2) ⊗ q0
        return rot.quat_multiply(rot.quat_from_rotvec(omega * time), q0)

    central = (q_of(t + h) - q_of(t - h)) / (2 * h)
    # truncation h²|ω|³/24 ~ 1e-10 and rounding eps/h ~ 2e-11: measured 4.8e-11
    np.testing.assert_allclose(rot.quat_derivative(q_of(t), omega), central, atol=1e-9)
    # The body-frame formula ½ q ⊗ (0, ω) must NOT match: this test can tell the frames apart.
    pure = np.concatenate([np.zeros((20, 1)), omega], axis=-1)
    body = 0.5 * rot.quat_multiply(q_of(t), pure)
    assert np.max(np.abs(body - central)) > 0.1


def test_derivative_is_tangent_to_the_unit_sphere():
    q = random_quats(30, seed=23)
    omega = np.random.default_rng(24).normal(size=(30, 3))
    # d|q|²/dt = 2 q·q̇ = 0; measured 1.1e-16
    np.testing.assert_allclose(np.sum(q * rot.quat_derivative(q, omega), axis=-1), 0.0, atol=4 * EPS)


# --- orthonormalize ------------------------------------------------------------------------------------


def test_orthonormalize_random_matrices_are_orthonormal():
    A = np.random.default_rng(25).normal(size=(100, 3, 3))
    B = rot.orthonormalize(A)
    error = np.max(np.abs(np.swapaxes(B, -1, -2) @ B - np.eye(3)), axis=(-2, -1))
    # Classical Gram-Schmidt loses orthogonality in proportion to cond(A)²: measured max error / cond² =
    # 2.5e-16 over 1e5 Gaussian matrices (max error 4e-12 at cond 1.7e5; a drifted rotation has cond ≈ 1).
    np.testing.assert_array_less(error, 4 * EPS * np.linalg.cond(A) ** 2)
    # det keeps the sign of det A (Gram-Schmidt never flips a column)
    np.testing.assert_array_equal(np.sign(np.linalg.det(B)), np.sign(np.linalg.det(A)))


def test_orthonormalize_leaves_rotations_unchanged():
    R = rot.quat_to_matrix(random_quats(50, seed=26))
    np.testing.assert_allclose(rot.orthonormalize(R), R, atol=4 * EPS)  # measured 4.4e-16


def test_orthonormalize_repairs_a_drifted_rotation():
    R = rot.quat_to_matrix(random_quats(50, seed=27))
    drifted = R + 1e-4 * np.random.default_rng(28).normal(size=R.shape)
    fixed = rot.orthonormalize(drifted)
    np.testing.assert_allclose(np.swapaxes(fixed, -1, -2) @ fixed, np.broadcast_to(np.eye(3), R.shape), atol=8 * EPS)
    np.testing.assert_allclose(np.linalg.det(fixed), 1.0, atol=8 * EPS)
    # The repair moves each entry by about the drift (1e-4 noise, measured 2.8e-4 max): close to R again.
    np.testing.assert_allclose(fixed, R, atol=2e-3)
    # and matrix_to_quat accepts the result (it refused the drifted matrix)
    with pytest.raises(ValueError):
        rot.matrix_to_quat(drifted[0])
    rot.matrix_to_quat(fixed)


def test_orthonormalize_follows_gram_schmidt_column_order():
    # columns a1 = (1, 1, 0), a2 = (1, 0, 0), a3 = (0, 1, 1): b1 = a1/√2, b2 = (a2 - b1/√2) normalised, and
    # b3 = a3 - (1/√2) b1 + (1/√2) b2 = (0, 0, 1)
    A = np.array([[1.0, 1.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    s = 1 / np.sqrt(2)
    expected = np.array([[s, s, 0.0], [s, -s, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(rot.orthonormalize(A), expected, atol=4 * EPS)  # measured 3.3e-16
    # Rows instead of columns would give a different answer here.
    assert not np.allclose(rot.orthonormalize(A.T).T, expected)
    # The first column is only normalised, whatever the others are.
    B = np.random.default_rng(29).normal(size=(20, 3, 3))
    # measured 0
    np.testing.assert_allclose(rot.orthonormalize(B)[..., 0], unit(B[..., 0]), atol=2 * EPS)


def test_orthonormalize_refuses_dependent_columns():
    with pytest.raises(ValueError, match="A must have linearly independent columns"):
        rot.orthonormalize([[1.0, 2.0, 0.0], [0.0, 0.0, 0.0], [1.0, 2.0, 1.0]])
    with pytest.raises(ValueError, match=r"A .* at index \(1,\)"):
        rot.orthonormalize(np.stack([np.eye(3), np.zeros((3, 3))]))


# --- batches and dtypes --------------------------------------------------------------------------------


def test_batch_shapes():
    rng = np.random.default_rng(30)
    q = unit(rng.normal(size=(5, 7, 4)))
    p = unit(rng.normal(size=(5, 7, 4)))
    v = rng.normal(size=(5, 7, 3))
    A = rng.normal(size=(5, 7, 3, 3))
    assert rot.skew(v).shape == (5, 7, 3, 3)
    assert rot.quat_multiply(p, q).shape == (5, 7, 4)
    assert rot.quat_conjugate(q).shape == (5, 7, 4)
    assert rot.quat_inverse(q).shape == (5, 7, 4)
    assert rot.quat_normalize(q).shape == (5, 7, 4)
    assert rot.quat_rotate(q, v).shape == (5, 7, 3)
    assert rot.quat_from_axis_angle(v, rng.normal(size=(5, 7))).shape == (5, 7, 4)
    axis, angle = rot.quat_to_axis_angle(q)
    assert axis.shape == (5, 7, 3) and angle.shape == (5, 7)
    assert rot.quat_from_rotvec(v).shape == (5, 7, 4)
    assert rot.quat_to_rotvec(q).shape == (5, 7, 3)
    R = rot.quat_to_matrix(q)
    assert R.shape == (5, 7, 3, 3)
    assert rot.matrix_to_quat(R).shape == (5, 7, 4)
    assert rot.quat_slerp(p, q, 0.3).shape == (5, 7, 4)
    assert rot.quat_derivative(q, v).shape == (5, 7, 4)
    assert rot.orthonormalize(A).shape == (5, 7, 3, 3)
    assert rot.from_scipy(rot.to_scipy(q)).shape == (5, 7, 4)
    # Broadcasting: one quaternion against many vectors and many quaternions against one vector.
    assert rot.quat_rotate(q[0, 0], v).shape == (5, 7, 3)
    assert rot.quat_rotate(q[:, :1], v[:1]).shape == (5, 7, 3)
    assert rot.quat_from_axis_angle([0, 0, 1], np.zeros((2, 3))).shape == (2, 3, 4)
    # Empty batches are fine too.
    assert rot.quat_to_matrix(np.zeros((0, 4))).shape == (0, 3, 3)


def test_batch_equals_elementwise():
    rng = np.random.default_rng(31)
    q = unit(rng.normal(size=(3, 4, 4)))
    v = rng.normal(size=(3, 4, 3))
    batched = (rot.quat_rotate(q, v), rot.quat_to_rotvec(q), rot.matrix_to_quat(rot.quat_to_matrix(q)))
    for i in range(3):
        for j in range(4):
            single = (
                rot.quat_rotate(q[i, j], v[i, j]),
                rot.quat_to_rotvec(q[i, j]),
                rot.matrix_to_quat(rot.quat_to_matrix(q[i, j])),
            )
            for b, s in zip(batched, single, strict=True):
                np.testing.assert_array_equal(b[i, j], s)


def test_lists_of_ints_give_float64():
    outputs = [
        rot.quat_multiply([1, 0, 0, 0], [0, 1, 0, 0]),
        rot.quat_rotate([1, 0, 0, 0], [1, 2, 3]),
        rot.quat_to_matrix((1, 0, 0, 0)),
        rot.matrix_to_quat([[1, 0, 0], [0, 1, 0], [0, 0, 1]]),
        rot.quat_from_axis_angle((0, 0, 1), 1),
        rot.quat_from_rotvec([0, 0, 0]),
        rot.quat_to_rotvec([1, 0, 0, 0]),
        rot.skew([1, 2, 3]),
        rot.quat_slerp([1, 0, 0, 0], [0, 1, 0, 0], 0),
        rot.quat_derivative([1, 0, 0, 0], [0, 0, 1]),
        rot.orthonormalize([[1, 0, 0], [0, 1, 0], [0, 0, 1]]),
        rot.quat_identity(),
    ]
    for out in outputs:
        assert out.dtype == np.float64


# --- SciPy agreement -----------------------------------------------------------------------------------


def test_agrees_with_scipy():
    q = random_quats(300, seed=32)
    v = np.random.default_rng(33).normal(size=(300, 3))
    # SciPy is scalar-LAST; build its Rotation independently of to_scipy
    ref = Rotation.from_quat(q[:, [1, 2, 3, 0]])
    np.testing.assert_allclose(rot.quat_to_matrix(q), ref.as_matrix(), atol=8 * EPS)  # measured 8.9e-16
    np.testing.assert_allclose(rot.quat_to_rotvec(q), ref.as_rotvec(), atol=8 * EPS)  # measured 8.9e-16
    np.testing.assert_allclose(rot.quat_rotate(q, v), ref.apply(v), atol=16 * EPS)  # measured 8.9e-16
    r = np.random.default_rng(34).normal(size=(300, 3))
    scipy_q = Rotation.from_rotvec(r).as_quat()[:, [3, 0, 1, 2]]
    assert np.max(sign_free_error(rot.quat_from_rotvec(r), scipy_q)) <= 4 * EPS  # measured 0
    # composition: SciPy's a * b also applies b first; measured 7.8e-16
    p = random_quats(300, seed=35)
    composed = (Rotation.from_quat(p[:, [1, 2, 3, 0]]) * ref).as_matrix()
    np.testing.assert_allclose(rot.quat_to_matrix(rot.quat_multiply(p, q)), composed, atol=8 * EPS)
    # matrix_to_quat against SciPy's own matrix reader; measured 2.2e-16
    R = ref.as_matrix()
    scipy_q = Rotation.from_matrix(R).as_quat()[:, [3, 0, 1, 2]]
    assert np.max(sign_free_error(rot.matrix_to_quat(R), scipy_q)) <= 4 * EPS


def test_scipy_interop_round_trip():
    q = random_quats(100, seed=36)
    S = rot.to_scipy(q)
    # to_scipy must reorder to scalar-last: compare with quat_to_matrix; measured 6.7e-16
    np.testing.assert_allclose(S.as_matrix(), rot.quat_to_matrix(q), atol=8 * EPS)
    back = rot.from_scipy(S)
    assert np.all(back[:, 0] >= 0.0)
    np.testing.assert_allclose(back, q * np.where(q[:, :1] < 0, -1.0, 1.0), atol=2 * EPS)  # measured 1.1e-16
    single = rot.to_scipy([0.0, 0.0, 0.0, 1.0])
    assert single.single
    np.testing.assert_allclose(single.as_rotvec(), [0.0, 0.0, np.pi], atol=2 * EPS)
    np.testing.assert_allclose(rot.from_scipy(Rotation.from_rotvec([0.0, 0.0, 0.2])), [np.cos(0.1), 0, 0, np.sin(0.1)])


# --- input checking ------------------------------------------------------------------------------------

ZERO = [0.0, 0.0, 0.0, 0.0]


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: rot.quat_normalize(ZERO), "q"),
        (lambda: rot.quat_inverse(ZERO), "q"),
        (lambda: rot.quat_to_matrix(ZERO), "q"),
        (lambda: rot.quat_to_axis_angle(ZERO), "q"),
        (lambda: rot.quat_to_rotvec(ZERO), "q"),
        (lambda: rot.quat_rotate(ZERO, [1.0, 0.0, 0.0]), "q"),
        (lambda: rot.quat_slerp(ZERO, [1.0, 0.0, 0.0, 0.0], 0.5), "q0"),
        (lambda: rot.quat_slerp([1.0, 0.0, 0.0, 0.0], ZERO, 0.5), "q1"),
        (lambda: rot.to_scipy(ZERO), "q"),
    ],
)
def test_zero_quaternion_is_refused(call, name):
    with pytest.raises(ValueError, match=rf"^{name} must be a non-zero quaternion .*\[0\.0, 0\.0, 0\.0, 0\.0\]"):
        call()


def test_zero_quaternion_in_a_batch_names_its_index():
    q = np.tile([1.0, 0.0, 0.0, 0.0], (2, 3, 1))
    q[1, 2] = 0.0
    with pytest.raises(ValueError, match=r"q must be a non-zero quaternion .* at index \(1, 2\)"):
        rot.quat_to_matrix(q)


def test_zero_axis_is_refused():
    with pytest.raises(ValueError, match=r"^axis must be a non-zero vector, got \[0\.0, 0\.0, 0\.0\]"):
        rot.quat_from_axis_angle([0.0, 0.0, 0.0], 1.0)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: rot.quat_multiply([1, 0, 0], [1, 0, 0, 0]), "p"),
        (lambda: rot.quat_multiply([1, 0, 0, 0], [[1, 0], [0, 0]]), "q"),
        (lambda: rot.quat_rotate([1, 0, 0, 0], [1, 0, 0, 0]), "v"),
        (lambda: rot.quat_to_matrix(np.eye(3)), "q"),
        (lambda: rot.matrix_to_quat([1, 0, 0, 0]), "R"),
        (lambda: rot.matrix_to_quat(np.eye(4)), "R"),
        (lambda: rot.skew([1, 2]), "v"),
        (lambda: rot.quat_from_axis_angle([1, 0], 1.0), "axis"),
        (lambda: rot.quat_from_rotvec(5.0), "r"),
        (lambda: rot.quat_derivative([1, 0, 0, 0], [1, 0]), "omega"),
        (lambda: rot.orthonormalize(np.eye(2)), "A"),
    ],
)
def test_wrong_shape_names_the_argument(call, name):
    with pytest.raises(ValueError, match=rf"^{name} must have shape"):
        call()


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: rot.quat_multiply([np.nan, 0, 0, 1], [1, 0, 0, 0]), "p"),
        (lambda: rot.quat_rotate([1, 0, 0, 0], [np.inf, 0, 0]), "v"),
        (lambda: rot.quat_to_rotvec([1, np.nan, 0, 0]), "q"),
        (lambda: rot.quat_from_axis_angle([0, 0, 1], np.nan), "angle"),
        (lambda: rot.quat_slerp([1, 0, 0, 0], [1, 0, 0, 0], np.nan), "t"),
        (lambda: rot.matrix_to_quat(np.full((3, 3), np.nan)), "R"),
        (lambda: rot.skew([0, np.nan, 0]), "v"),
    ],
)
def test_nan_and_inf_name_the_argument(call, name):
    with pytest.raises(ValueError, match=rf"^{name} must be finite"):
        call()


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: rot.quat_normalize("1, 0, 0, 0"), "q"),
        (lambda: rot.quat_rotate([1, 0, 0, 0], ["a", "b", "c"]), "v"),
        (lambda: rot.quat_from_axis_angle([0, 0, 1], "90deg"), "angle"),
        (lambda: rot.matrix_to_quat(None), "R"),
        (lambda: rot.from_scipy([1.0, 0.0, 0.0, 0.0]), "rotation"),
    ],
)
def test_wrong_types_name_the_argument(call, name):
    with pytest.raises(TypeError, match=rf"^{name} must be"):
        call()
