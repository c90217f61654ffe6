"""tumble.elementary and tumble.portable: the engine's own transcendental functions and products, within 2 ulp of
the correctly rounded value (mpmath at 120 bits), C's special values, the same bits compiled and in Python, and
products that agree with NumPy's to round-off."""

from __future__ import annotations

import math
import struct

import mpmath
import numpy as np
import pytest

from tumble import elementary, portable
from tumble._jit import kernel

mpmath.mp.prec = 120
RNG = np.random.default_rng(44)


def ulps(a: float, b: float) -> int:
    """Distance in units in the last place (0 for equal values, zeros of either sign included)."""
    if a == b:
        return 0
    ia, ib = (struct.unpack("<q", struct.pack("<d", v))[0] for v in (a, b))
    ia, ib = (i if i >= 0 else -(i & 0x7FFFFFFFFFFFFFFF) for i in (ia, ib))
    return abs(ia - ib)


def _log_uniform(low_exp: float, high_exp: float, n: int, signed: bool = True) -> np.ndarray:
    x = 10.0 ** RNG.uniform(low_exp, high_exp, n)
    return x * RNG.choice([-1.0, 1.0], n) if signed else x


CASES = {
    # name: (tumble's, the reference, arguments)
    "sin": (elementary.sin, mpmath.sin, _log_uniform(-10, 5, 3000)),
    "cos": (elementary.cos, mpmath.cos, _log_uniform(-10, 5, 3000)),
    "atan": (elementary.atan, mpmath.atan, _log_uniform(-10, 10, 3000)),
    "asin": (elementary.asin, mpmath.asin, np.concatenate([_log_uniform(-9, 0, 2000), RNG.uniform(-1, 1, 1000)])),
    "acos": (elementary.acos, mpmath.acos, np.concatenate([_log_uniform(-9, 0, 2000), RNG.uniform(-1, 1, 1000)])),
    "exp": (elementary.exp, mpmath.exp, np.concatenate([_log_uniform(-12, 2.85, 3000), RNG.uniform(-745, 709, 500)])),
}


@pytest.mark.parametrize("name", list(CASES))
def test_within_two_ulp_of_the_correctly_rounded_value(name):
    function, reference, xs = CASES[name]
    worst = max((ulps(function(float(x)), float(reference(mpmath.mpf(float(x))))), float(x)) for x in xs)
    assert worst[0] <= 2, f"{name}({worst[1]!r}) is {worst[0]} ulp off"


def test_atan2_within_two_ulp_in_every_quadrant():
    y, x = _log_uniform(-6, 6, 3000), _log_uniform(-6, 6, 3000)
    worst = max(
        ulps(elementary.atan2(a, b), float(mpmath.atan2(mpmath.mpf(a), mpmath.mpf(b))))
        for a, b in zip(y, x, strict=True)
    )
    assert worst <= 2


@pytest.mark.parametrize(
    "y, x",
    [(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0), (-0.0, -0.0), (1.0, 0.0), (-1.0, -0.0), (0.0, -1.0), (-0.0, -1.0),
     (math.inf, math.inf), (-math.inf, -math.inf), (math.inf, -math.inf), (2.0, math.inf), (2.0, -math.inf),
     (-math.inf, 3.0), (1e-300, 1e300), (1e300, 1e-300)],
)  # fmt: skip
def test_atan2_gives_cs_special_values(y, x):
    ours, c = elementary.atan2(y, x), math.atan2(y, x)
    assert ours == c and math.copysign(1.0, ours) == math.copysign(1.0, c)


def test_special_values():
    assert math.isnan(elementary.sin(math.inf)) and math.isnan(elementary.cos(-math.inf))
    assert math.isnan(elementary.sin(math.nan)) and math.isnan(elementary.atan2(math.nan, 1.0))
    assert math.isnan(elementary.asin(1.0 + 1e-15)) and math.isnan(elementary.acos(-2.0))
    assert elementary.asin(1.0) == math.pi / 2 and elementary.acos(-1.0) == math.pi and elementary.acos(1.0) == 0.0
    assert math.copysign(1.0, elementary.sin(-0.0)) < 0.0 and elementary.cos(0.0) == 1.0
    assert elementary.exp(0.0) == 1.0 and elementary.exp(710.0) == math.inf and elementary.exp(-746.0) == 0.0
    assert elementary.exp(-740.0) == math.exp(-740.0)  # a subnormal, rounded once
    assert elementary.atan(math.inf) == math.pi / 2 and elementary.atan(-math.inf) == -math.pi / 2


def test_compiled_loops_give_the_bits_of_the_python_source():
    """portable's arrays run the functions in a compiled loop; one call from Python runs their source."""
    x = _log_uniform(-8, 4, 2000)
    y = _log_uniform(-8, 4, 2000)
    u = RNG.uniform(-1.0, 1.0, 2000)
    for array, scalar, args in [
        (portable.sin, elementary.sin, (x,)),
        (portable.cos, elementary.cos, (x,)),
        (portable.arctan2, elementary.atan2, (y, x)),
        (portable.arccos, elementary.acos, (u,)),
        (portable.arcsin, elementary.asin, (u,)),
        (portable.arctan, elementary.atan, (x,)),
    ]:
        assert array(*args).tobytes() == np.array([scalar(*a) for a in zip(*args, strict=True)]).tobytes(), (
            scalar.__name__
        )
    assert isinstance(portable.sin(0.5), np.floating) and portable.sin(np.zeros((2, 3))).shape == (2, 3)


def test_portable_sin_and_cos_give_the_same_bits_on_their_vectorised_and_their_branching_loops():
    """An array wholly in SIN_COS_RANGE takes the branch-free loop (``elementary.sin_cos``); one entry beyond it
    (1e7, inf, NaN) sends the whole array down the branching one. Either way every entry is the scalar's bits."""
    edges = np.arange(-40, 41) * (math.pi / 4)
    x = np.concatenate([_log_uniform(-12, 6, 4000), edges, np.nextafter(edges, 0.0), np.nextafter(edges, 10.0),
                        [0.0, -0.0, 1e-8, -1e-8, elementary.SIN_COS_RANGE, -elementary.SIN_COS_RANGE]])  # fmt: skip
    x = x[np.abs(x) <= elementary.SIN_COS_RANGE]
    for array, scalar in ((portable.sin, elementary.sin), (portable.cos, elementary.cos)):
        near = array(x)
        assert near.tobytes() == np.array([scalar(float(v)) for v in x]).tobytes(), scalar.__name__
        for far in (1e7, math.inf, math.nan):
            mixed = array(np.append(x, far))
            assert mixed[:-1].tobytes() == near.tobytes()
            assert np.array(mixed[-1]).tobytes() == np.array(scalar(far)).tobytes(), (scalar.__name__, far)


@kernel
def _sin_cos_loop(x, out):
    """elementary.sin_cos over an array, in a loop LLVM vectorises, beside the branching sin and cos."""
    for i in range(x.shape[0]):
        out[0, i], out[1, i] = elementary.sin_cos(x[i])
    for i in range(x.shape[0]):
        out[2, i], out[3, i] = elementary.sin(x[i]), elementary.cos(x[i])


def test_sin_cos_gives_the_bits_of_sin_and_cos_over_its_range():
    """The branch-free pair (one reduction, the quadrant by selects) is sin and cos to the bit, in Python and
    compiled, from the sub-1e-8 shortcut of sin to SIN_COS_RANGE, at the quadrants' edges and at zeros of either
    sign."""
    edges = np.arange(-40, 41) * (math.pi / 4)
    x = np.concatenate([_log_uniform(-12, 6, 4000), edges, np.nextafter(edges, 0.0), np.nextafter(edges, 10.0),
                        [0.0, -0.0, 1e-8, -1e-8, elementary.SIN_COS_RANGE, -elementary.SIN_COS_RANGE]])  # fmt: skip
    x = x[np.abs(x) <= elementary.SIN_COS_RANGE]
    out = np.zeros((4, x.size))
    _sin_cos_loop(x, out)
    assert out[0].tobytes() == out[2].tobytes() and out[1].tobytes() == out[3].tobytes()
    python = np.array([elementary.sin_cos(float(v)) for v in x]).T
    assert python.tobytes() == out[:2].tobytes()


def test_products_inverses_and_principal_axes_agree_with_numpy():
    a, b = RNG.normal(size=(50, 3, 3)), RNG.normal(size=(50, 3, 3))
    v = RNG.normal(size=(50, 3))
    np.testing.assert_allclose(portable.matmul(a, b), a @ b, rtol=0, atol=1e-14)
    np.testing.assert_allclose(portable.matvec(a, v), np.einsum("nij,nj->ni", a, v), rtol=0, atol=1e-14)
    np.testing.assert_allclose(portable.dot(v, v), np.einsum("ni,ni->n", v, v), rtol=1e-15)
    np.testing.assert_allclose(portable.det(a), np.linalg.det(a), rtol=0, atol=1e-13)
    np.testing.assert_allclose(portable.inverse(a) @ a, np.broadcast_to(np.eye(3), a.shape), atol=1e-9)
    m = RNG.normal(size=(6, 6))
    np.testing.assert_allclose(portable.inverse(m) @ m, np.eye(6), atol=1e-12)
    np.testing.assert_allclose(portable.solve(m, v[:6, 0]), np.linalg.solve(m, v[:6, 0]), rtol=1e-10)
    with pytest.raises(ValueError, match="singular"):
        portable.inverse(np.ones((3, 3)))
    with pytest.raises(ValueError, match="singular"):
        portable.solve(np.zeros((4, 4)), np.ones(4))
    for n in (3, 5):
        q = np.linalg.qr(RNG.normal(size=(n, n)))[0]
        for moments in (np.logspace(-6, 6, n), np.array([1.0, 1.0, 2.0, 3.0, 3.0][:n])):
            tensor = (q * moments) @ q.T
            values, axes = portable.eigh(tensor)
            np.testing.assert_allclose(values, np.sort(moments), rtol=1e-12, atol=1e-12 * moments.max())
            np.testing.assert_allclose((axes * values) @ axes.T, tensor, atol=1e-12 * moments.max())
            np.testing.assert_allclose(axes.T @ axes, np.eye(n), atol=1e-13)
