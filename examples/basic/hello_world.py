"""Hello, world: a box thrown upward, tumbling under gravity.

The smallest complete tumble program: build a world, add a body from a shape, simulate, read the result.
The box's centre of mass follows the parabola ``z = z0 + v0 t − g t²/2`` exactly (RK4 integrates a
constant force without error), and its energy stays constant.

Run: ``python examples/basic/hello_world.py``.
"""

from __future__ import annotations

import tumble


def build(world: tumble.World) -> tumble.Body:
    return world.add_body(tumble.Box((0.4, 0.2, 0.1)), density=700.0, position=(0.0, 0.0, 1.0),
                          velocity=(1.0, 0.0, 5.0), angular_velocity=(0.0, 3.0, 9.0))  # fmt: skip


def main(steps: int = 100, render: bool = False) -> str:
    world = tumble.World()
    box = build(world)
    trajectory = world.simulate(duration=steps * 0.01, dt=0.01)
    drift = abs(trajectory.total_energy[-1] / trajectory.total_energy[0] - 1.0)
    summary = f"final: t={world.time:.2f} s, z={box.position[2]:.4f} m, energy drift {drift:.0e}"
    print(summary)
    return summary


if __name__ == "__main__":
    main()
