"""Soft-constraint coefficients: a constraint as a damped spring of given stiffness (hertz) and damping ratio.

From the implicit integration of a spring–damper over a substep ``h`` (E. Catto, "Solver2D" and "Soft Step",
2024; the same coefficients as Box2D v3's ``b2MakeSoft``, derived from Erin Catto's GDC 2011 "Soft
Constraints"). With ``ω = 2π f`` and damping ratio ``ζ``::

    a1 = 2ζ + h ω,   a2 = h ω a1,   a3 = 1 / (1 + a2)
    bias_rate = ω / a1            (velocity bias per metre of error)
    mass_scale = a2 a3            (fraction of the rigid impulse)
    impulse_scale = a3            (how much of the accumulated impulse leaks back)

A stiffness of 0 hertz means a rigid constraint: bias 0, mass scale 1, impulse scale 0.
"""

from __future__ import annotations

import math

from .._jit import inline

__all__ = ["soft_coefficients", "spring_damper_coefficients"]


@inline
def soft_coefficients(hertz, damping_ratio, h):
    """``(bias_rate, mass_scale, impulse_scale)`` of a soft constraint over a substep ``h``."""
    if hertz <= 0.0:
        return 0.0, 1.0, 0.0
    omega = 2.0 * math.pi * hertz
    a1 = 2.0 * damping_ratio + h * omega
    a2 = h * omega * a1
    a3 = 1.0 / (1.0 + a2)
    return omega / a1, a2 * a3, a3


@inline
def spring_damper_coefficients(hertz, damping_ratio, damping, mass, h):
    """The same for a joint's drive: a spring of ``hertz`` and ``damping_ratio`` relative to the effective mass
    ``mass`` (``k = m ω²``, ``c = 2 m ζ ω``) plus an absolute damping ``damping`` [N s/m or N m s/rad] (MJCF's
    joint ``damping``): with ``k/m = ω²`` and ``c/m = 2ζω + damping/m``, ``a2 = h (c/m + h k/m)``, ``a3 = 1/(1 +
    a2)``, bias ``(k/m) / (c/m + h k/m)``. Without damping these are :func:`soft_coefficients`; without a spring,
    an implicit damper, stable at any ``damping``."""
    omega = 2.0 * math.pi * hertz if hertz > 0.0 else 0.0
    stiffness_rate = omega * omega
    damping_rate = 2.0 * damping_ratio * omega + (damping / mass if mass > 0.0 else 0.0)
    a2 = h * (damping_rate + h * stiffness_rate)
    a3 = 1.0 / (1.0 + a2)
    bias = stiffness_rate / (damping_rate + h * stiffness_rate) if stiffness_rate > 0.0 else 0.0
    return bias, a2 * a3, a3
