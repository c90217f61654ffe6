"""Run shipped scenes at given rates and print each run's final ``State.digest()`` as JSON (for the slow test of
``tests/analytic/test_shipped_scenes.py``, which runs this twice in separate processes and compares).

    python tests/scene_runs.py SCENE DURATION RATE [RATE ...]

Each rate starts from a fresh load of the scene. A run that fails gives ``"error: <message>"`` instead of a digest.
"""

from __future__ import annotations

import json
import sys

import numpy as np

from tumble import scene_file
from tumble.errors import SimulationError


def run(name: str, duration: float, rate: float) -> str:
    world = scene_file.load(scene_file.shipped_scene(name)).world
    try:
        # Recording every step would only cost memory: one frame a second is enough to prove the run went through.
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            world.simulate(duration, 1.0 / rate, record_every=max(1, round(rate)))
    except SimulationError as error:
        return f"error: {error}"
    return world.state.digest()


def main(argv: list[str]) -> int:
    name, duration, rates = argv[0], float(argv[1]), [float(r) for r in argv[2:]]
    print(json.dumps({f"{rate:g}": run(name, duration, rate) for rate in rates}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
