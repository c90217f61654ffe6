"""A motor door: a hinge motor swings a 20 kg door open and sweeps a box out of its way.

The door (1 × 0.05 × 2 m) hangs on a world hinge along its edge; a motor drives it at 1 rad/s with at most
50 N m up to a stop at 110° (a hinge limit). Unobstructed it turns at the motor's speed; from 32° on it meets a
5 kg box on the floor and pushes it along, the motor torque rising to carry the box's friction; the hinge holds
to a fraction of a millimetre. The scene is ``tumble.scenes.hinged_door``.

Run: ``python examples/joints/door.py`` (``render=True`` writes ``out/door.png``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import tumble
from tumble import scenes

OUT = Path(__file__).resolve().parents[2] / "out"
DT = 1 / 60


def build(**world_settings) -> tumble.World:
    """The door scene: a ``"door"`` on a motor hinge (the world's first joint) and a ``"box"`` in its way."""
    return scenes.hinged_door(speed=1.0, max_torque=50.0, **world_settings)


def plot(time, angle, torque, box_xy, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ax1.plot(time, np.degrees(angle), label="door angle [°]")
    ax1.plot(time, torque, label="hinge torque about z [N m] (motor, then the stop)")
    ax1.set_xlabel("time [s]")
    ax1.legend()
    ax2.plot(box_xy[:, 0], box_xy[:, 1], label="box centre")
    for a in angle[:: max(1, len(angle) // 12)]:
        ax2.plot([0.0, math.cos(a)], [0.0, math.sin(a)], color="0.7", lw=1)
    ax2.set_aspect("equal")
    ax2.set_xlabel("x [m]")
    ax2.set_ylabel("y [m]")
    ax2.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(steps: int = 150, render: bool = False) -> str:
    """Run ``steps`` steps of 1/60 s; report where the door stopped and how far it pushed the box."""
    world = build()
    hinge, box = world.joints[0], world.body("box")
    start = box.position
    time, angle, torque, box_xy = [], [], [], []
    free_speed, gap = math.nan, 0.0
    for _ in range(steps):
        world.step(DT)
        if np.linalg.norm(box.position - start) < 1e-3:  # the box not reached yet: the unobstructed speed
            free_speed = hinge.angular_speed
        gap = max(gap, hinge.position_error)
        time.append(world.time)
        angle.append(hinge.angle)
        torque.append(hinge.reaction_torque[2])
        box_xy.append(box.position[:2])
    if render:
        plot(np.array(time), np.array(angle), np.array(torque), np.array(box_xy), OUT / "door.png")
        print(f"wrote {OUT / 'door.png'}")
    pushed = np.linalg.norm(box.position - start)
    summary = (
        f"final: door at {math.degrees(hinge.angle):.1f}° (stop 110°), {free_speed:.3f} rad/s before the box, "
        f"box pushed {pushed:.2f} m, hinge gap {gap * 1e3:.2f} mm"
    )
    print(summary)
    return summary


if __name__ == "__main__":
    main()
