"""Slider–crank statics by virtual work: the crank torque that holds a piston force.

The course's slider–crank (crank r, rod l, piston at ``x = r cos θ + √(l² − r² sin² θ)``) has one degree
of freedom. A force F on the piston and a torque τ on the crank are in equilibrium when their virtual
work vanishes, ``δW = τ δθ + F δx = 0``. tumble.lagrange maps both loads to the generalised force of θ,
solves for τ at a sweep of crank angles, and compares with the closed form
``τ = F r sin θ (1 + r cos θ / √(l² − r² sin² θ))``.

Run: ``python examples/lagrange/slider_crank.py``.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from tumble import lagrange

R, ROD, FORCE = 0.05, 0.2, 1000.0  # crank [m], rod [m], piston force [N] along +x


def build() -> tuple[lagrange.System, sp.Symbol]:
    """A massless slider–crank loaded by F on the piston and τ on the crank; returns it and τ."""
    theta = lagrange.dynamicsymbols("theta")
    r, l, F, tau = sp.symbols("r l F tau", positive=True)
    piston = r * sp.cos(theta) + sp.sqrt(l**2 - r**2 * sp.sin(theta) ** 2)
    loads = [
        lagrange.Force((piston, 0, 0), (F, 0, 0)),  # F along the slide, at the piston
        lagrange.Torque(lagrange.rotation_z(theta), (0, 0, tau)),  # τ about the crank axis
    ]
    system = lagrange.System(theta, sp.S(0), forces=loads, parameters={"r": R, "l": ROD, "F": FORCE})
    return system, tau


def closed_form(theta: np.ndarray) -> np.ndarray:
    return FORCE * R * np.sin(theta) * (1.0 + R * np.cos(theta) / np.sqrt(ROD**2 - R**2 * np.sin(theta) ** 2))


def main(steps: int = 12, render: bool = False) -> str:
    """Balance the crank at ``steps`` angles over a turn; print a table and the worst error."""
    system, tau = build()
    print("generalised force of θ:", system.generalized_forces()[0])
    angles = np.linspace(0.0, 2.0 * np.pi, steps, endpoint=False)
    worst = 0.0
    print("  θ [deg]   τ [N m]   closed form")
    for angle in angles:
        torque = system.balancing(tau, [angle])[tau]
        expected = closed_form(angle)
        worst = max(worst, abs(torque - expected))
        print(f"  {np.degrees(angle):7.1f}  {torque + 0.0:8.3f}  {expected + 0.0:8.3f}".replace("-0.000", " 0.000"))
    summary = f"final: {steps} crank angles balanced, max torque error {worst:.0e} N m"
    print(summary)
    return summary


if __name__ == "__main__":
    main()
