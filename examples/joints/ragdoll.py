"""A ragdoll down the stairs: eleven bodies, ball joints and limited hinges, tumbling down eight steps.

A 70 kg ragdoll (box pelvis and torso, sphere head, capsule limbs) stands at the top of a staircase of static
boxes and gets a push. Ball joints hold the neck, waist, shoulders and hips; elbows and knees are hinges limited
to 0–150°. It falls down the steps without any limb passing through one. The scene is
``tumble.scenes.ragdoll_stairs``.

Run: ``python examples/joints/ragdoll.py`` (``render=True`` writes ``out/ragdoll.png``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import tumble
from tumble import scenes

OUT = Path(__file__).resolve().parents[2] / "out"
STEPS, RISE, RUN, DT = 8, 0.2, 0.3, 1 / 60


def build(**world_settings) -> tumble.World:
    """The staircase (8 steps of 0.2 × 0.3 m, landing at x < 0) and the ragdoll, pushed towards +x."""
    return scenes.ragdoll_stairs(steps=STEPS, rise=RISE, run=RUN, **world_settings)


def stair_height(x: float) -> float:
    """The top of the stairs (or the ground) under ``x``."""
    if -1.0 <= x < 0.0:
        return STEPS * RISE
    k = int(x // RUN) + 1 if x >= 0.0 else STEPS
    return (STEPS - k) * RISE if k < STEPS else 0.0


def plot(frames, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 5))
    xs = np.linspace(-0.5, 3.5, 801)
    ax.fill_between(xs, [stair_height(x) for x in xs], color="0.85", step="post")
    for k, centres in enumerate(frames):
        ax.plot(centres[:, 0], centres[:, 2], "o", ms=3, color=plt.cm.viridis(k / max(1, len(frames) - 1)))
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title("body centres every 0.25 s")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(steps: int = 180, render: bool = False) -> str:
    """Run ``steps`` steps of 1/60 s; report the fall, whether a body centre went under a tread, the joint gaps."""
    world = build()
    dynamic = [body for body in world.bodies if not body.is_static]
    pelvis = world.body("pelvis")
    start = pelvis.position[2]
    clearance, frames = np.inf, []
    for k in range(steps):
        world.step(DT)
        centres = np.array([body.center_of_mass for body in dynamic])
        clearance = min(clearance, min(c[2] - stair_height(c[0]) for c in centres))
        if k % 15 == 0:
            frames.append(centres)
    gap = max(joint.position_error for joint in world.joints)
    if render:
        plot(frames, OUT / "ragdoll.png")
        print(f"wrote {OUT / 'ragdoll.png'}")
    through = "no body centre under a tread" if clearance > 0.0 else f"a body centre {-clearance:.2f} m under a tread"
    summary = (
        f"final: pelvis from {start:.2f} m to {pelvis.position[2]:.2f} m in {world.time:.1f} s, {through}, "
        f"joint gaps {gap * 1e3:.1f} mm now"
    )
    print(summary)
    return summary


if __name__ == "__main__":
    main()
