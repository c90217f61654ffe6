"""A pendulum by Lagrange's equations: derive, then check the period of a large swing.

The course's pendulum: ``L = ½ m l² θ̇² + m g l cos θ`` gives ``θ̈ + (g/l) sin θ = 0``. tumble.lagrange
derives it with SymPy, integrates it from 90° with ``solve_ivp`` (DOP853), times the swings by event
detection, and compares the period with the exact ``4 √(l/g) K(sin²(θ0/2))`` (not the small-angle 2π√(l/g)).

Run: ``python examples/lagrange/pendulum.py``.
"""

from __future__ import annotations

import numpy as np
import sympy as sp
from scipy.special import ellipk

from tumble import lagrange


def build() -> lagrange.System:
    """The pendulum of the course as particle + rod: bob at (l sin θ, 0, -l cos θ)."""
    theta = lagrange.dynamicsymbols("theta")
    m, g, l = sp.symbols("m g l", positive=True)
    bob = lagrange.Particle(m, (l * sp.sin(theta), 0, -l * sp.cos(theta)))
    return lagrange.System.from_bodies(theta, [bob], gravity=(0, 0, -g), parameters={"m": 1.0, "g": 9.81, "l": 1.0})


def main(steps: int = 400, render: bool = False) -> str:
    """Simulate ``steps`` output samples over two periods; print the equation and the period error."""
    pendulum = build()
    (theta,) = pendulum.coordinates
    print("Lagrangian:", pendulum.lagrangian)
    print("equation:  ", sp.Eq(pendulum.equations[0], 0))
    print("θ̈ =", pendulum.accelerations()[0])

    def through_bottom(t, q, qd):
        return q[0]

    theta0 = np.pi / 2
    exact = 4.0 * np.sqrt(1.0 / 9.81) * ellipk(np.sin(theta0 / 2) ** 2)
    times = np.linspace(0.0, 2.0 * exact, steps)
    motion = pendulum.simulate([theta0], [0.0], (0.0, times[-1]), t_eval=times, events=[through_bottom])
    first, second = motion.t_events[0][:2]
    period = 2.0 * (second - first)
    drift = np.max(np.abs(motion.energy - motion.energy[0])) / (1.0 * 9.81 * 1.0)  # relative to m g l
    small_angle = 2.0 * np.pi * np.sqrt(1.0 / 9.81)
    print(f"period from 90°: {period:.9f} s; exact {exact:.9f} s; small-angle formula {small_angle:.6f} s")
    error = abs(period / exact - 1.0)
    summary = f"final: period {period:.6f} s (exact {exact:.6f} s, error {error:.0e}), energy drift {drift:.0e}"
    print(summary)
    return summary


if __name__ == "__main__":
    main()
