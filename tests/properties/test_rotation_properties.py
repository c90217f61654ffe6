"""Hypothesis invariants of tumble.rotation: rotations are isometries that compose, matrices are proper
rotations, the conversions invert each other, slerp stays on the unit sphere, SciPy round trips.

Inputs come from ``tests/strategies.py``; the example count comes from the profile in ``tests/conftest.py``.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from strategies import rotvecs, unit_quaternions, vectors3
from tumble import rotation as rot

EPS = np.finfo(np.float64).eps


def sign_free_error(q, p) -> float:
    """Max-abs distance from q to the nearer of ±p (q and -q are the same rotation)."""
    return float(min(np.abs(q - p).max(), np.abs(q + p).max()))


@settings(deadline=None)
@given(unit_quaternions(), vectors3(10.0), vectors3(10.0))
def test_rotation_preserves_norms_and_dot_products(q, a, b):
    ra, rb = rot.quat_rotate(q, a), rot.quat_rotate(q, b)
    # |a| <= 17.4, so a few ulps of 17 is ~1e-14; measured 8.9e-15 over 4000 examples
    np.testing.assert_allclose(np.linalg.norm(ra), np.linalg.norm(a), rtol=0, atol=1e-13)
    # dot products up to 300 (ulp 5.7e-14); measured 2.0e-13 over 4000 examples
    np.testing.assert_allclose(ra @ rb, a @ b, rtol=0, atol=1e-12)


@settings(deadline=None)
@given(unit_quaternions(), unit_quaternions(), vectors3(10.0))
def test_rotation_composes(p, q, v):
    # rotating by p ⊗ q is rotating by q, then by p; measured 1.4e-14 for |v| <= 17.4 (4000 examples)
    np.testing.assert_allclose(
        rot.quat_rotate(rot.quat_multiply(p, q), v), rot.quat_rotate(p, rot.quat_rotate(q, v)), atol=1e-13
    )


@settings(deadline=None)
@given(unit_quaternions(), unit_quaternions(), unit_quaternions())
def test_product_is_associative(p, q, r):
    left = rot.quat_multiply(rot.quat_multiply(p, q), r)
    right = rot.quat_multiply(p, rot.quat_multiply(q, r))
    # two products of unit quaternions each; measured 3.3e-16 over 4000 examples
    np.testing.assert_allclose(left, right, rtol=0, atol=8 * EPS)


@settings(deadline=None)
@given(unit_quaternions())
def test_matrix_is_a_proper_rotation(q):
    R = rot.quat_to_matrix(q)
    # measured 1.3e-15 for both over 4000 examples
    np.testing.assert_allclose(R.T @ R, np.eye(3), rtol=0, atol=16 * EPS)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, rtol=0, atol=16 * EPS)


@settings(deadline=None)
@given(unit_quaternions())
def test_matrix_quat_round_trips(q):
    R = rot.quat_to_matrix(q)
    q_back = rot.matrix_to_quat(R)
    assert q_back[0] >= 0.0
    # Shepperd: every rotation, half-turns included, comes back to rounding; measured 4.4e-16 (4000 examples)
    assert sign_free_error(q_back, q) <= 8 * EPS
    # measured 6.7e-16 over 4000 examples
    np.testing.assert_allclose(rot.quat_to_matrix(q_back), R, rtol=0, atol=8 * EPS)


@settings(deadline=None)
@given(rotvecs())
def test_rotvec_round_trip_below_pi(r):
    q = rot.quat_from_rotvec(r)
    np.testing.assert_allclose(np.linalg.norm(q), 1.0, rtol=0, atol=2 * EPS)
    # angles < π: the logarithm inverts the exponential; measured 4.4e-16 absolute, 3.5e-16 relative
    np.testing.assert_allclose(rot.quat_to_rotvec(q), r, rtol=4 * EPS, atol=8 * EPS)


@settings(deadline=None)
@given(unit_quaternions(), unit_quaternions(), st.floats(0.0, 1.0))
def test_slerp_stays_unit_and_between(q0, q1, t):
    q = rot.quat_slerp(q0, q1, t)
    # measured 2.2e-16 over 4000 examples
    np.testing.assert_allclose(np.linalg.norm(q), 1.0, rtol=0, atol=4 * EPS)
    # shortest path: the angle from q0 is t times the whole (at most π); measured 6.7e-16 (4000 examples)
    whole = rot.quat_to_axis_angle(rot.quat_multiply(rot.quat_conjugate(q0), q1))[1]
    part = rot.quat_to_axis_angle(rot.quat_multiply(rot.quat_conjugate(q0), q))[1]
    np.testing.assert_allclose(part, t * whole, rtol=0, atol=1e-14)


@settings(deadline=None)
@given(unit_quaternions())
def test_scipy_round_trip(q):
    back = rot.from_scipy(rot.to_scipy(q))
    assert back[0] >= 0.0
    # measured 2.2e-16 over 4000 examples (SciPy renormalises)
    assert sign_free_error(back, q) <= 4 * EPS
