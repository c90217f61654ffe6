"""A Crazyflie racing through three gates on a minimum-snap path, flown by the SE(3) controller at 100 Hz.

Each gate is a square frame of static boxes (a 40 cm opening, its centre 1 to 1.2 m up); the path starts hovering
at 1 m, passes through the centre of each gate at its time, and ends hovering past the last one. The controller
is RotorPy's SE(3) law and gains (``tumble.control.SE3Controller``); the vehicle feels its motors' 72 ms lag
and the drag of its rotors. A world controller logs the rotor speeds at every step. See ``docs/quadrotor.md``.

Run: ``python examples/vehicles/gates.py`` (``render=True`` writes ``out/gates.html``, a 3-D replay, and
``out/gates.png``: the path from above and from the side with the gates, the tracking error, the rotor speeds).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import tumble
from tumble.control import MinimumSnap, SE3Controller
from tumble.vehicles import Quadrotor

OUT = Path(__file__).resolve().parents[2] / "out"
DT = 1 / 500
OPENING, BAR = 0.4, 0.04  # the gate's opening and its bars' thickness [m]
GATES = [((1.5, 0.0, 1.0), 0.0), ((3.0, 1.5, 1.2), np.pi / 2), ((1.5, 3.0, 1.0), np.pi)]  # centre, heading


def add_gate(world: tumble.World, centre, heading: float) -> None:
    """Four static bars around a square opening, facing along ``heading`` (the direction it is flown through)."""
    turn = (np.cos(heading / 2), 0.0, 0.0, np.sin(heading / 2))
    across = np.array([-np.sin(heading), np.cos(heading), 0.0])
    reach = (OPENING + BAR) / 2
    for offset, extents in (
        (reach * across, (BAR, BAR, OPENING + 2 * BAR)),
        (-reach * across, (BAR, BAR, OPENING + 2 * BAR)),
        (np.array([0.0, 0.0, reach]), (BAR, OPENING, BAR)),
        (np.array([0.0, 0.0, -reach]), (BAR, OPENING, BAR)),
    ):
        world.add_static(tumble.Box(extents), position=np.asarray(centre) + offset, orientation=turn)


def build() -> tuple[tumble.World, Quadrotor, MinimumSnap]:
    world = tumble.World()
    world.add_static(tumble.Plane())
    for centre, heading in GATES:
        add_gate(world, centre, heading)
    start = (0.0, 0.0, 1.0)
    waypoints = [start, *(centre for centre, _ in GATES), (0.0, 3.0, 1.0)]
    path = MinimumSnap(waypoints, average_speed=1.0)
    quad = Quadrotor(world, position=start, name="crazyflie")
    quad.rotor_speeds = [quad.hover_rotor_speed] * 4  # hovering at the start
    quad.fly(SE3Controller(quad), path, rate=100)
    return world, quad, path


def plot(recording, quad: Quadrotor, path: MinimumSnap, speeds: np.ndarray, target: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    i = quad.body.index
    flown = recording.position[:, i]
    reference = np.array([path(t)["position"] for t in recording.time])
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    for ax, (a, b), name in ((axes[0, 0], (0, 1), "from above"), (axes[0, 1], (0, 2), "from the side")):
        ax.plot(reference[:, a], reference[:, b], "--", color="0.5", label="minimum-snap path")
        ax.plot(flown[:, a], flown[:, b], label="flown")
        for centre, _ in GATES:
            ax.plot(centre[a], centre[b], "s", color="tab:red", markersize=8, fillstyle="none")
        ax.set_aspect("equal" if b == 1 else "auto")
        ax.set_title(name)
        ax.set_xlabel("xyz"[a] + " [m]")
        ax.set_ylabel("xyz"[b] + " [m]")
    axes[0, 0].legend()
    axes[1, 0].plot(recording.time, 100 * np.linalg.norm(flown - reference, axis=1))
    axes[1, 0].set_xlabel("time [s]")
    axes[1, 0].set_ylabel("position error [cm]")
    axes[1, 1].plot(recording.time, speeds, lw=0.8)
    axes[1, 1].set_xlabel("time [s]")
    axes[1, 1].set_ylabel("rotor speeds [rad/s]")
    fig.tight_layout()
    target.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(target, dpi=110)
    plt.close(fig)


def main(steps: int | None = None, render: bool = False) -> str:
    """Fly ``steps`` steps of 1/500 s (default: the whole path and 1 s more); report the gates passed."""
    world, quad, path = build()
    speeds = [quad.rotor_speeds]
    world.add_controller(lambda world, t: speeds.append(quad.rotor_speeds), name="rotor log")
    steps = steps if steps is not None else round((path.duration + 1.0) / DT)
    recording = world.simulate(steps * DT, DT)
    speeds.append(quad.rotor_speeds)
    flown = recording.position[:, quad.body.index]
    error = np.linalg.norm(flown - np.array([path(t)["position"] for t in recording.time]), axis=1)
    passed = 0
    for centre, heading in GATES:
        # Where the vehicle crossed the gate's plane: within the opening, with its arms (5 cm) clear of the bars.
        normal = np.array([np.cos(heading), np.sin(heading), 0.0])
        side = (flown - centre) @ normal
        crossings = np.flatnonzero((side[:-1] < 0) & (side[1:] >= 0))
        if crossings.size:
            offset = flown[crossings[0]] - centre
            passed += int(np.max(np.abs(offset - (offset @ normal) * normal)) + 0.05 < OPENING / 2)
    if render:
        from tumble import viewer

        viewer.write_html(recording, OUT / "gates.html", world=world, title="Crazyflie through three gates")
        plot(recording, quad, path, np.array(speeds[1:]), OUT / "gates.png")
    rms, worst = 100 * np.sqrt(np.mean(error**2)), 100 * error.max()
    return (f"final: {passed} of {len(GATES)} gates passed in {recording.time[-1]:.1f} s, {rms:.1f} cm RMS off the "
            f"path, {worst:.1f} cm at most")  # fmt: skip


if __name__ == "__main__":
    print(main(render=True))
