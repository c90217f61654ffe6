"""``sin``, ``cos``, ``atan``, ``atan2``, ``asin``, ``acos`` and ``exp`` in IEEE arithmetic written out in a fixed
order: the same bits on every machine, in a kernel and in Python alike.

The C library's versions are not: glibc picks an FMA/AVX2 build of each by CPU (its ifuncs), and the two round
differently about once in a thousand calls (measured on glibc 2.36 with ``GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,
-FMA``: 201 of 300 000 ``sin``, 68 ``atan2``, 220 ``exp``); other versions of the library round differently again.
A pile turns one such last bit into another outcome (issue 44). These use only ``+ - * /``, ``sqrt``, ``floor``
and ``ldexp``, which round exactly on every machine, and the kernels run them with ``fastmath`` off, so LLVM fuses
and reorders nothing.

Method (Muller, *Elementary Functions: Algorithms and Implementation*, 3rd ed., 2016): additive argument reduction
by a constant split in parts whose products with the quotient are exact (Cody and Waite, *Software Manual for the
Elementary Functions*, 1980), then the Taylor series of the reduced argument, evaluated by Horner's rule to a degree
whose first dropped term is below 1e-17 of the result. Within 1 ulp of the correctly rounded value on the ranges
tested (``tests/unit/test_elementary.py``); ``sin`` and ``cos`` reduce exactly for ``|x| <= 1e6`` and lose accuracy
(not determinism) beyond, where ``x`` is first taken modulo the double nearest 2π (no angle of a simulation comes
near).
"""

from __future__ import annotations

import math

from ._jit import inline

__all__ = ["SIN_COS_RANGE", "acos", "asin", "atan", "atan2", "cos", "exp", "sin", "sin_cos"]

_HALF_PI = math.pi / 2.0
_QUARTER_PI = math.pi / 4.0
_TWO_OVER_PI = 2.0 / math.pi
# π/2 in three parts (Cody and Waite): the first two have 33 significant bits, so k · part is exact for |k| < 2**20.
_PI2_A = 1.5707963267341256e00  # 0x3FF921FB54400000
_PI2_B = 6.077100506303966e-11  # 0x3DD0B4611A600000
_PI2_C = 2.0222662487959506e-21  # π/2 - A - B, to double precision
# ln 2 in two parts: the first has 32 significant bits, so k · part is exact for |k| < 2**21.
_LN2_HI = 6.93147180369123816490e-01  # 0x3FE62E42FEE00000
_LN2_LO = 1.90821492927058770002e-10  # ln 2 - HI
_INV_LN2 = 1.0 / math.log(2.0)
# Taylor coefficients, highest degree first, for Horner's rule.
_SIN = tuple((-1.0) ** k / math.factorial(2 * k + 1) for k in range(9, 0, -1))  # x³ … x¹⁹ terms over x
_COS = tuple((-1.0) ** k / math.factorial(2 * k) for k in range(10, 1, -1))  # x⁴ … x²⁰ terms over x⁴ … x⁰
_EXP = tuple(1.0 / math.factorial(k) for k in range(14, 1, -1))  # x² … x¹⁴ over x²
_ATAN = tuple((-1.0) ** k / (2 * k + 1) for k in range(15, 0, -1))  # x³ … x³¹ over x
_SQRT3 = math.sqrt(3.0)
_TAN_PI_12 = 2.0 - _SQRT3  # tan(π/12): above it the argument is turned by π/6
_PI_6 = 0.5235987755982989  # π/6 correctly rounded (math.pi / 6 is one ulp below)


@inline
def _horner(coefficients, y):
    out = 0.0
    for c in coefficients:
        out = out * y + c
    return out


@inline
def _sin_reduced(r):
    """``sin r`` for ``|r| <= π/4``."""
    y = r * r
    return r + r * (y * _horner(_SIN, y))


@inline
def _cos_reduced(r):
    """``cos r`` for ``|r| <= π/4``."""
    y = r * r
    return 1.0 - 0.5 * y + y * y * _horner(_COS, y)


# Beyond this |x| the quotient k no longer fits the reduction: x is first taken modulo the double nearest 2π (exact:
# C's fmod, then one rounded addition), which keeps the result finite and the same everywhere, if no longer accurate.
_REDUCE_LIMIT = 1e6
_TWO_PI = 2.0 * math.pi


@inline
def _reduce(x):
    """``(r, k mod 4)`` with ``x = k π/2 + r`` and ``|r| <= π/4`` (to rounding)."""
    if abs(x) > _REDUCE_LIMIT:
        x = x % _TWO_PI
    r, quadrant = _reduce_near(x)
    return r, int(quadrant)


@inline(into_callers=True)
def _reduce_near(x):
    """:func:`_reduce` for ``|x| <= SIN_COS_RANGE``, the quadrant as a float."""
    k = math.floor(x * _TWO_OVER_PI + 0.5)
    r = ((x - k * _PI2_A) - k * _PI2_B) - k * _PI2_C
    return r, k - 4.0 * math.floor(0.25 * k)


SIN_COS_RANGE = _REDUCE_LIMIT


@inline(into_callers=True)
def sin_cos(x):
    """``(sin(x), cos(x))``, the bits of :func:`sin` and :func:`cos`, for a finite ``|x| <= SIN_COS_RANGE`` (the
    caller checks; beyond, the result means nothing). One reduction for both, and the quadrant picks by selects, not
    branches, so that a loop of them over many ``x`` vectorises (``articulation/chain.py``)."""
    r, quadrant = _reduce_near(x)
    s, c = _sin_reduced(r), _cos_reduced(r)
    sine = s if quadrant == 0.0 else (c if quadrant == 1.0 else (-s if quadrant == 2.0 else -c))
    cosine = c if quadrant == 0.0 else (-s if quadrant == 1.0 else (-c if quadrant == 2.0 else s))
    return (x if abs(x) < 1e-8 else sine), cosine


@inline
def sin(x):
    if not math.isfinite(x):
        return math.nan
    if abs(x) < 1e-8:  # x - x³/6 rounds to x
        return x
    r, quadrant = _reduce(x)
    if quadrant == 0:
        return _sin_reduced(r)
    if quadrant == 1:
        return _cos_reduced(r)
    if quadrant == 2:
        return -_sin_reduced(r)
    return -_cos_reduced(r)


@inline
def cos(x):
    if not math.isfinite(x):
        return math.nan
    r, quadrant = _reduce(x)
    if quadrant == 0:
        return _cos_reduced(r)
    if quadrant == 1:
        return -_sin_reduced(r)
    if quadrant == 2:
        return -_cos_reduced(r)
    return _sin_reduced(r)


@inline
def _atan_unit(t):
    """``atan t`` for ``0 <= t <= 1``: turned by π/6 above tan(π/12), ``atan t = π/6 + atan((√3 t − 1)/(√3 + t))``,
    so the series runs on at most tan(π/12) ≈ 0.27."""
    if t > _TAN_PI_12:
        u = (_SQRT3 * t - 1.0) / (_SQRT3 + t)
        return _PI_6 + (u + u * (u * u * _horner(_ATAN, u * u)))
    return t + t * (t * t * _horner(_ATAN, t * t))


@inline
def _atan_positive(a, b):
    """``atan(a / b)`` for ``a, b >= 0``, not both zero or both infinite, in [0, π/2]."""
    if a > b:
        return _HALF_PI - _atan_unit(b / a)
    return _atan_unit(a / b)


@inline
def atan(x):
    if math.isnan(x):
        return math.nan
    return math.copysign(_atan_positive(abs(x), 1.0), x)


@inline
def atan2(y, x):
    """The angle of ``(x, y)`` in [-π, π], with C's signs for zeros and infinities."""
    if math.isnan(x) or math.isnan(y):
        return math.nan
    ax, ay = abs(x), abs(y)
    if ay == 0.0 and ax == 0.0:
        angle = 0.0
    elif math.isinf(ax) and math.isinf(ay):
        angle = _QUARTER_PI
    else:
        angle = _atan_positive(ay, ax)
    if math.copysign(1.0, x) < 0.0:
        angle = math.pi - angle
    return math.copysign(angle, y)


@inline
def asin(x):
    """NaN outside [-1, 1]."""
    if not abs(x) <= 1.0:
        return math.nan
    return atan2(x, math.sqrt((1.0 - x) * (1.0 + x)))


@inline
def acos(x):
    """NaN outside [-1, 1]."""
    if not abs(x) <= 1.0:
        return math.nan
    return atan2(math.sqrt((1.0 - x) * (1.0 + x)), x)


@inline
def exp(x):
    if math.isnan(x):
        return math.nan
    if x > 709.782712893384:
        return math.inf
    if x < -745.2:
        return 0.0
    k = math.floor(x * _INV_LN2 + 0.5)
    r = (x - k * _LN2_HI) - k * _LN2_LO
    p = 1.0 + r + r * r * _horner(_EXP, r)
    return math.ldexp(p, int(k))
