"""Params: how to step — the integrator and its settings."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

from .dynamics.contact_solver import SolverSettings

__all__ = ["Integrator", "Params", "INTEGRATOR_NAMES", "DEFAULT_SOLVER", "SolverSettings"]


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


# Box2D v3's published defaults for a 60 Hz step (DESIGN.md): 4 substeps, contacts at 30 Hz with damping
# ratio 10 (static contacts at 2x), push-out at most 3 m/s, no bounce below 1 m/s, 2 cm speculative margin.
DEFAULT_SOLVER = SolverSettings(
    substeps=4,
    contact_hertz=30.0,
    contact_damping_ratio=10.0,
    contact_push_max=3.0,
    restitution_threshold=1.0,
    speculative_distance=0.02,
)


@dataclass
class Params:
    """Step settings.

    Attributes:
        integrator: the name the user chose (``"auto"`` or a key of ``INTEGRATOR_NAMES``).
        solver: the contact solver's settings.
    """

    integrator: str = "auto"
    solver: SolverSettings = field(default_factory=lambda: DEFAULT_SOLVER)

    def resolve_integrator(self, has_constraints: bool) -> Integrator:
        """``"auto"``: RK4 in momentum form for free bodies (L exactly constant without torque, energy
        to ~1e-11 over 20 s at dt = 1e-3, see docs/integrators.md); semi-implicit Euler once contacts or
        joints couple bodies."""
        if self.integrator == "auto":
            return Integrator.SYMPLECTIC if has_constraints else Integrator.RK4
        return INTEGRATOR_NAMES[self.integrator]
