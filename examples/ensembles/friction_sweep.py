"""A friction sweep on every core: how far a sliding box gets, against Coulomb's law.

The shipped scene ``sliding_block`` slides a box along the ground at 2 m/s; box and ground share one material, so
the pair's friction is the material's. ``tumble.ensemble.run`` runs the scene once per member of a grid (five
frictions on the Earth, Mars and the Moon) on a local process pool, writes each member's trajectory to
``out/friction_sweep/`` and returns the table. Coulomb friction stops the box after ``v² / (2 μ g)``, or it is still
sliding at the end of the run: ``v t − μ g t² / 2`` (below μ = 1: there the cube's friction at its base
tips it, its width over its height being 1). Run it twice: the second call finds every member finished and
only reads the table back.

Run: ``python examples/ensembles/friction_sweep.py`` (the same from the command line:
``tumble sweep sliding_block -p materials.surface.friction=0.1:0.9:5 -p world.gravity[2]=-9.81,-3.71,-1.62
--duration 1 --out out/friction_sweep``).
"""

from __future__ import annotations

from pathlib import Path

from tumble import ensemble

OUT = Path("out") / "friction_sweep"
SPEED = 2.0  # [m/s] the box's start speed in the scene
DT = 1.0 / 240.0


def coulomb(mu: float, g: float, t: float) -> float:
    """Distance slid after ``t`` s from SPEED under Coulomb friction (stopped at SPEED / (mu g))."""
    t = min(t, SPEED / (mu * g))
    return SPEED * t - 0.5 * mu * g * t * t


def main(steps: int = 240, render: bool = False, out: Path = OUT) -> str:
    members = ensemble.grid({"materials.surface.friction": [0.1, 0.3, 0.5, 0.7, 0.9],
                             "world.gravity[2]": [-9.81, -3.71, -1.62]})  # fmt: skip
    duration = steps * DT
    table = ensemble.run("sliding_block", members, duration, DT, out, workers=2, progress=render)
    rows = table.to_dict("records") if hasattr(table, "to_dict") else table
    worst = 0.0
    for row in rows:
        mu, g = row["materials.surface.friction"], -row["world.gravity[2]"]
        expected = coulomb(mu, g, duration)
        worst = max(worst, abs(row["max_displacement"] - expected))
        print(f"mu = {mu:.1f}, g = {g:5.2f} m/s²: slid {row['max_displacement']:.4f} m (Coulomb {expected:.4f} m), "
              f"{row['status']}")  # fmt: skip
    done = sum(row["status"] == "done" for row in rows)
    summary = (f"final: {done} of {len(rows)} members done in {duration:.2f} s each, largest difference from "
               f"Coulomb's law {worst * 1000:.2f} mm")  # fmt: skip
    print(summary)
    return summary


if __name__ == "__main__":  # the pool's workers are fresh processes that import this file
    main(render=True)
