"""Params: how to step — the integrator and its settings."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import IntEnum

import numpy as np

from ._validate import MAX_COUNT, as_float
from .dynamics.contact_solver import SUBSTEP_RATE_PER_CONTACT_HERTZ, SolverSettings
from .errors import SubstepsRaisedWarning, warn_user

__all__ = [
    "Integrator",
    "Params",
    "INTEGRATOR_NAMES",
    "DEFAULT_SOLVER",
    "SolverSettings",
    "solver_with",
    "substeps_to_run",
]


class Integrator(IntEnum):
    """Integrators for free motion (codes passed to the kernels)."""

    EULER = 0  # explicit Euler on (x, q, p, L), as in the course notes (course/003)
    SYMPLECTIC = 1  # semi-implicit Euler, gyroscopic term by one implicit Newton step
    RK4 = 2  # classical Runge-Kutta on (x, q, p, L), quaternion renormalised
    MIDPOINT = 3  # Lie-Poisson implicit midpoint with the Cayley map: E and L conserved to round-off
    EXACT_OR_RK4 = 4  # "auto" on free bodies: the exact flight where it has a closed form, RK4 elsewhere


INTEGRATOR_NAMES = {
    "euler": Integrator.EULER,
    "symplectic": Integrator.SYMPLECTIC,
    "rk4": Integrator.RK4,
    "midpoint": Integrator.MIDPOINT,
}


# Box2D v3's scheme (DESIGN.md) with stiffer contacts: 8 substeps at 60 Hz and contacts at 60 Hz (static
# contacts at 2x, which keeps h ω at Box2D's bound 2π/4), damping ratio 10. A soft contact is a spring of
# stiffness m_eff ω², so a stack sinks by about (load / m_eff) g / ω²: at Box2D's 4 substeps and 30 Hz the
# 10-box tower sags 26 mm and sways 9 mm; at 8 and 60 Hz it sags 7 mm, the 210-box pyramid stands (top moves
# 8 mm in 10 s) and the 1000-cube pile penetrates 1.8 mm. 120 Hz (static contacts then capped at 120 Hz by the 8
# substeps) sagged 3x less but let thin cards slide apart (docs/contact.md). A step takes more substeps than asked
# where 60 Hz contacts need them (SolverSettings.substeps_for: 8 per contact period, 16 at 30 Hz), so that a stack
# holds at every step size.
# Push-out at most 3 m/s, no bounce below 1 m/s, 2 cm speculative margin; islands sleep after 0.5 s below
# 5 cm/s and 0.05 rad/s. Joints are as stiff as the substeps allow (a quarter of the substep rate: 120 Hz at
# 60 Hz): a soft joint is a spring that soaks up a chain's energy when it snaps taut (a 5-link chain released
# horizontal kept 99 % of it at 1200 Hz, 50 % at 120 Hz, stepping at 600 Hz), damping ratio 2.
DEFAULT_SOLVER = SolverSettings(
    substeps=8,
    contact_hertz=60.0,
    contact_damping_ratio=10.0,
    contact_push_max=3.0,
    restitution_threshold=1.0,
    speculative_distance=0.02,
    sleep=True,
    sleep_linear=0.05,
    sleep_angular=0.05,
    time_to_sleep=0.5,
    joint_hertz=math.inf,
    joint_damping_ratio=2.0,
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
        """``"auto"``: for free bodies, the exact flight of those whose motion has a closed form (constant force, no
        torque, no damping, isotropic inertia or no spin) and RK4 in momentum form for the others (L exactly
        constant without torque, energy to ~1e-11 over 20 s at dt = 1e-3, see docs/integrators.md); semi-implicit
        Euler once contacts or joints couple bodies."""
        if self.integrator == "auto":
            return Integrator.SYMPLECTIC if has_constraints else Integrator.EXACT_OR_RK4
        return INTEGRATOR_NAMES[self.integrator]


def solver_with(solver: SolverSettings, settings: dict) -> SolverSettings:
    """``solver`` with ``settings`` (names and values, as ``World.set_solver`` takes them) checked and changed."""
    current = solver._asdict()
    for key, value in settings.items():
        if key not in current:
            raise TypeError(f"unknown solver setting {key!r}; settings: {sorted(current)}")
        if key == "substeps":
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
                kind = type(value).__name__
                raise TypeError(f"substeps must be an integer >= 1 (at most {MAX_COUNT}), got {value!r} ({kind})")
            if not 1 <= value <= MAX_COUNT:
                raise ValueError(f"substeps must be an integer >= 1 (at most {MAX_COUNT}), got {value!r}")
            current[key] = int(value)
        elif key == "sleep":
            if not isinstance(value, (bool, np.bool_)):
                raise TypeError(f"sleep must be True or False, got {value!r}")
            current[key] = bool(value)
        elif key == "joint_hertz" and value == math.inf:
            current[key] = math.inf  # as stiff as the substeps allow (the default)
        else:
            positive = key in ("contact_hertz", "contact_push_max", "joint_hertz")
            current[key] = as_float(key, value, positive=positive, nonnegative=not positive)
    return SolverSettings(**current)


def substeps_to_run(solver: SolverSettings, dt: float, warned: set, owner: str = "World") -> int:
    """The substeps a step of ``dt`` runs (``solver.substeps_for(dt)``). Where that is more than ``solver.substeps``,
    a :class:`~tumble.errors.SubstepsRaisedWarning` says so and why, once for each asked and raised number (``warned``
    keeps the pairs already told)."""
    used = solver.substeps_for(dt)
    if used > solver.substeps and (solver.substeps, used) not in warned:
        warned.add((solver.substeps, used))
        longest = 1.0 / (SUBSTEP_RATE_PER_CONTACT_HERTZ * solver.contact_hertz)
        warn_user(
            f"{owner}(substeps={solver.substeps}) runs {used} substeps at dt={dt:g}: contacts of "
            f"contact_hertz={solver.contact_hertz:g} need {SUBSTEP_RATE_PER_CONTACT_HERTZ:g} substeps per contact "
            f"period, or stacks sag and topple (a substep of at most {longest:.3g} s). "
            "A smaller dt or contact_hertz runs fewer.",
            SubstepsRaisedWarning,
        )
    return used
