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

__all__ = ["soft_coefficients"]


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
