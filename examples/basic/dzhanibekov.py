"""The Dzhanibekov effect: a T-handle spun about its intermediate axis flips over and over.

A rigid body spinning about the principal axis of intermediate moment is unstable (the tennis-racket
theorem): a tiny wobble grows until the handle turns half over, returns, and flips again, while its energy
and angular momentum stay constant. This example builds a wing-nut-like T-handle from two cylinders, spins
it in space, prints the flip times and plots the body-frame angular velocity, the energy and |L|.

Run: ``python examples/basic/dzhanibekov.py`` (writes ``out/dzhanibekov.png``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import tumble
from tumble.rotation import quat_from_axis_angle

OUT = Path(__file__).resolve().parents[2] / "out"


def build(world: tumble.World, spin: float = 12.0, wobble: float = 0.01) -> tumble.Body:
    """A T-handle (steel, about 0.4 kg) spinning at ``spin`` rad/s about its intermediate principal axis."""
    crossbar = tumble.Cylinder(radius=0.01, height=0.12)  # along y after the rotation below
    stem = tumble.Cylinder(radius=0.008, height=0.08)  # along x
    along_y = quat_from_axis_angle((1, 0, 0), np.pi / 2)
    along_x = quat_from_axis_angle((0, 1, 0), np.pi / 2)
    parts = [(crossbar, (0.0, 0.0, 0.0), along_y), (stem, (0.05, 0.0, 0.0), along_x)]
    handle = world.add_body(parts, density=7800.0, name="t-handle")
    moments, axes = tumble.mass.MassProperties(handle.mass, np.zeros(3), handle.inertia_body).principal()
    minor, intermediate, major = axes.T
    handle.angular_velocity = spin * intermediate + wobble * (minor + major)
    return handle


def flip_times(time: np.ndarray, omega_intermediate: np.ndarray) -> np.ndarray:
    """Times at which the spin about the intermediate axis reverses (sign changes, interpolated)."""
    s = np.sign(omega_intermediate)
    k = np.flatnonzero(s[1:] != s[:-1])
    w0, w1 = omega_intermediate[k], omega_intermediate[k + 1]
    return time[k] + (time[k + 1] - time[k]) * w0 / (w0 - w1)


def plot(traj: tumble.Trajectory, axes: np.ndarray, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    omega = traj.angular_velocity_body()[:, 0] @ axes  # components along the principal axes
    energy = traj.total_energy
    angmom = np.linalg.norm(traj.angular_momentum(), axis=-1)
    fig, (ax1, ax2, ax3) = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    for k, label in enumerate(["minor axis", "intermediate axis", "major axis"]):
        ax1.plot(traj.time, omega[:, k], label=label)
    ax1.set_ylabel("ω, body frame [rad/s]")
    ax1.legend(loc="upper right")
    ax1.set_title("Dzhanibekov effect: a T-handle spun about its intermediate axis")
    ax2.plot(traj.time, (energy - energy[0]) / energy[0])
    ax2.set_ylabel("relative energy change")
    ax3.plot(traj.time, (angmom - angmom[0]) / angmom[0])
    ax3.set_ylabel("relative |L| change")
    ax3.set_xlabel("time [s]")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(steps: int = 20_000, render: bool = True, dt: float = 1e-3) -> str:
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    handle = build(world)
    _, axes = tumble.mass.MassProperties(handle.mass, np.zeros(3), handle.inertia_body).principal()
    traj = world.simulate(steps * dt, dt, record_every=10)
    omega_intermediate = traj.angular_velocity_body()[:, 0] @ axes[:, 1]
    flips = flip_times(traj.time, omega_intermediate)
    energy_drift = np.max(np.abs(traj.total_energy / traj.total_energy[0] - 1.0))
    angmom = np.linalg.norm(traj.angular_momentum(), axis=-1)
    angmom_drift = np.max(np.abs(angmom / angmom[0] - 1.0))
    if render:
        print(f"T-handle: mass {handle.mass * 1000:.1f} g, spin 12 rad/s about the intermediate axis")
        print("flip times [s]: " + ", ".join(f"{t:.3f}" for t in flips))
        plot(traj, axes, OUT / "dzhanibekov.png")
        print(f"wrote {OUT / 'dzhanibekov.png'}")
    summary = (
        f"final: {len(flips)} flips in {traj.time[-1]:.1f} s, energy drift {energy_drift:.1e}, "
        f"|L| drift {angmom_drift:.1e}"
    )
    print(summary)
    return summary


if __name__ == "__main__":
    main()
