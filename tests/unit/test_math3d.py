"""Parity of the Numba inline helpers in tumble.math3d with the NumPy reference in tumble.rotation.

The helpers only run inside compiled code (they are ``inline="always"``), so one small kernel below calls
each of them on rows of random inputs and writes the results out. With ``NUMBA_DISABLE_JIT=1`` the same
kernel runs as plain Python, which is how CI reaches these lines with coverage.
"""

from __future__ import annotations

import numpy as np
import pytest

from tumble import math3d, rotation
from tumble._jit import kernel

EPS = np.finfo(np.float64).eps
N = 200


@kernel
def _apply_helpers(quat, quat_b, vec, vec_b, mat, h, out4, out3):
    """Row i of each output holds one helper's result for row i of the inputs.

    out4[k]: 0 quat_mul(q, q_b), 1 quat_derivative(q, v), 2 quat_integrate(q, v, h).
    out3[k]: 0 quat_rotate(q, v), 1 quat_rotate_inv(q, v), 2 mat_vec(M, v), 3 solve33(M, v), 4 cross(v, v_b).
    """
    for i in range(quat.shape[0]):
        q = math3d.load4(quat, i)
        v = math3d.load3(vec, i)
        m = math3d.load33(mat, i)
        math3d.store4(out4[0], i, math3d.quat_mul(q, math3d.load4(quat_b, i)))
        math3d.store4(out4[1], i, math3d.quat_derivative(q, v))
        math3d.store4(out4[2], i, math3d.quat_integrate(q, v, h))
        math3d.store3(out3[0], i, math3d.quat_rotate(q, v))
        math3d.store3(out3[1], i, math3d.quat_rotate_inv(q, v))
        math3d.store3(out3[2], i, math3d.mat_vec(m, v))
        math3d.store3(out3[3], i, math3d.solve33(m, v))
        math3d.store3(out3[4], i, math3d.cross(v, math3d.load3(vec_b, i)))


@pytest.fixture(scope="module")
def results():
    rng = np.random.default_rng(2024)
    quat = rotation.quat_normalize(rng.normal(size=(N, 4)))
    quat_b = rotation.quat_normalize(rng.normal(size=(N, 4)))
    vec = rng.normal(size=(N, 3))
    vec_b = rng.normal(size=(N, 3))
    # Inertia-like matrices (symmetric positive definite, condition number <= 10), as solve33 expects.
    axes = rotation.quat_to_matrix(rotation.quat_normalize(rng.normal(size=(N, 4))))
    moments = rng.uniform(0.1, 1.0, size=(N, 3))
    mat = np.einsum("nij,nj,nkj->nik", axes, moments, axes)
    h = 1e-3
    out4 = np.zeros((3, N, 4))
    out3 = np.zeros((5, N, 3))
    _apply_helpers(quat, quat_b, vec, vec_b, mat, h, out4, out3)
    inputs = {"quat": quat, "quat_b": quat_b, "vec": vec, "vec_b": vec_b, "mat": mat, "h": h}
    return inputs, out4, out3


def test_quat_mul(results):
    x, out4, _ = results
    # the same expression; measured 0 (4 eps allows a different summation order)
    np.testing.assert_allclose(out4[0], rotation.quat_multiply(x["quat"], x["quat_b"]), rtol=0, atol=4 * EPS)


def test_quat_rotate_and_inverse(results):
    x, _, out3 = results
    # different but equivalent formulas; measured 1.3e-15 for |v| components up to 3.8
    np.testing.assert_allclose(out3[0], rotation.quat_rotate(x["quat"], x["vec"]), rtol=0, atol=16 * EPS)
    inverse = rotation.quat_rotate(rotation.quat_conjugate(x["quat"]), x["vec"])
    np.testing.assert_allclose(out3[1], inverse, rtol=0, atol=16 * EPS)
    # and the inverse really undoes the rotation: R Rᵀ v = v; measured 2.2e-15 (two rotations)
    np.testing.assert_allclose(rotation.quat_rotate(x["quat"], out3[1]), x["vec"], rtol=0, atol=32 * EPS)


def test_quat_derivative_is_world_frame(results):
    x, out4, _ = results
    # measured 0
    np.testing.assert_allclose(out4[1], rotation.quat_derivative(x["quat"], x["vec"]), rtol=0, atol=4 * EPS)


def test_quat_integrate(results):
    x, out4, _ = results
    q, omega, h = x["quat"], x["vec"], x["h"]
    # The first-order update q + h q̇, renormalised; measured 1.1e-16
    expected = rotation.quat_normalize(q + h * rotation.quat_derivative(q, omega))
    np.testing.assert_allclose(out4[2], expected, rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(np.linalg.norm(out4[2], axis=-1), 1.0, rtol=0, atol=2 * EPS)
    # and it follows the exact rotation exp(h ω / 2) ⊗ q: the renormalised step turns by 2 atan(h|ω|/2)
    # instead of h|ω|, an error of (h|ω|)³/12 <= 5e-9 here; measured 1.8e-9
    exact = rotation.quat_multiply(rotation.quat_from_rotvec(h * omega), q)
    np.testing.assert_allclose(out4[2], exact, rtol=0, atol=1e-8)


def test_mat_vec_and_solve33(results):
    x, _, out3 = results
    m, v = x["mat"], x["vec"]
    # measured 2.2e-16
    np.testing.assert_allclose(out3[2], np.einsum("nij,nj->ni", m, v), rtol=0, atol=4 * EPS)
    # Cramer's rule versus LU; condition number <= 10 and |M⁻¹ v| up to 19: measured 7.1e-15
    np.testing.assert_allclose(out3[3], np.linalg.solve(m, v[..., None])[..., 0], rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("exponent", [-400, -100, 100, 400])
def test_solve33_gives_the_same_bits_for_matrices_scaled_by_powers_of_two(results, exponent):
    # At 2^±400 the determinant (a product of three entries) leaves float range; solve33 then rescales by a power
    # of two, which is exact: M s x = b s has the bits of M x = b. (At 2^±100 no rescaling happens at all.)
    x, _, out3 = results
    scale = 2.0**exponent
    out4, scaled = np.zeros((3, N, 4)), np.zeros((5, N, 3))
    _apply_helpers(x["quat"], x["quat_b"], x["vec"] * scale, x["vec_b"], x["mat"] * scale, x["h"], out4, scaled)
    np.testing.assert_array_equal(scaled[3], out3[3])


def test_cross(results):
    x, _, out3 = results
    np.testing.assert_array_equal(out3[4], np.cross(x["vec"], x["vec_b"]))
