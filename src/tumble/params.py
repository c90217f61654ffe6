"""Params: how to step — the integrator and its settings."""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

__all__ = ["Integrator", "Params", "INTEGRATOR_NAMES"]


class Integrator(IntEnum):
    """Integrators for free motion (codes passed to the kernels)."""

    EULER = 0  # explicit Euler on (x, q, p, L), as in the course notes (course/003)
    SYMPLECTIC = 1  # semi-implicit Euler, gyroscopic term by one implicit Newton step
    RK4 = 2  # classical Runge-Kutta on (x, q, p, L), quaternion renormalised
    MIDPOINT = 3  # Lie-Poisson implicit midpoint with the Cayley map: E and L conserved to round-off


INTEGRATOR_NAMES = {
    "euler": Integrator.EULER,
    "symplectic": Integrator.SYMPLECTIC,
    "rk4": Integrator.RK4,
    "midpoint": Integrator.MIDPOINT,
}


@dataclass
class Params:
    """Step settings.

    Attributes:
        integrator: the name the user chose (``"auto"`` or a key of ``INTEGRATOR_NAMES``).
    """

    integrator: str = "auto"

    def resolve_integrator(self, has_constraints: bool) -> Integrator:
        """``"auto"``: RK4 in momentum form for free bodies (L exactly constant without torque, energy
        to ~1e-11 over 20 s at dt = 1e-3, see docs/integrators.md); semi-implicit Euler once contacts or
        joints couple bodies."""
        if self.integrator == "auto":
            return Integrator.SYMPLECTIC if has_constraints else Integrator.RK4
        return INTEGRATOR_NAMES[self.integrator]
