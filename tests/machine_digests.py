"""Build scenes, run them, and print digests of what was built and where it went, as JSON: the probe of the test
that every machine gives the same bits (``tests/analytic/test_machine_determinism.py``), which runs this in fresh
processes under different BLAS kernels, libm variants and CPU targets and compares.

    python tests/machine_digests.py CASE[@RATE] [CASE[@RATE] ...]

A case without ``@RATE`` is only built (its model's digest); with one it also runs 2 s at that rate (Hz). Each entry
of the output maps ``CASE`` to the model's field digests and ``CASE@RATE`` to the final ``State.digest()`` (or
``"error: <message>"``).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import sys

import numpy as np

import tumble
from tumble import scene_file, scenes
from tumble.errors import SimulationError
from tumble.shapes import ConvexHull

DURATION = 2.0


def hull_pile(count: int = 24, seed: int = 3) -> tumble.World:
    """Random convex hulls (each from 8 to 20 normal points) dropped onto a plane: hull mass properties, hull
    collision and a pile's chaos."""
    world = tumble.World()
    world.add_static(tumble.Plane())
    rng = np.random.default_rng(seed)
    for k in range(count):
        points = rng.normal(size=(int(rng.integers(8, 21)), 3)) * rng.uniform(0.04, 0.12, size=3)
        world.add_body(
            ConvexHull(points),
            density=float(rng.uniform(300.0, 3000.0)),
            position=(rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), 0.3 + 0.15 * k),
            orientation=tumble.rotation.quat_from_rotvec(rng.normal(size=3)),
        )
    return world


def ant() -> tumble.World:
    """Gymnasium's ant (MJCF) on its floor: a model file's inertias, frames and joints."""
    import warnings

    import gymnasium

    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets", "ant.xml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return tumble.load_mjcf(path)


def ant_articulation():
    """Gymnasium's ant as an articulation (generalised coordinates, MuJoCo's contacts, limits and motors), its motors
    held at fixed controls: the constraint and contact solve of issue 47."""
    import warnings

    import gymnasium

    from tumble.articulation import from_mjcf

    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets", "ant.xml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        art = from_mjcf(path)
    art.ctrl = np.sin(1.7 * np.arange(len(art.ctrl)))
    return art


def ant_env() -> str:
    """Four copies of ``tumble/Ant`` (seeded 5, 6, 7, 8) for 40 steps of fixed actions: the digest of their
    observations (the body terms of the compiled readout included), rewards and info values."""
    import warnings

    from tumble.envs import make_vector_env

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        envs = make_vector_env("Ant", 4)
    parts = list(envs.reset(seed=5)[:1])
    actions = np.sin(0.3 * np.arange(4 * 8).reshape(4, 8)).astype(np.float32)
    for step in range(40):
        observations, rewards, terminated, truncated, info = envs.step(np.roll(actions, step, axis=1))
        parts += [observations, rewards, terminated, *(info[key] for key in sorted(info))]
    return _digest(*parts)


def double_pendulum_env() -> str:
    """150 copies of ``tumble/DoublePendulum`` (seeded 3, 4, ...) for 60 steps of fixed actions, resets included:
    the short-chain path, whose loops LLVM vectorises as wide as the CPU allows. The digest of their observations,
    rewards and terminations."""
    from tumble.envs import make_vector_env

    envs = make_vector_env("DoublePendulum", 150)
    parts = list(envs.reset(seed=3)[:1])
    actions = np.sin(0.7 * np.arange(150)).astype(np.float32).reshape(150, 1)
    for step in range(60):
        observations, rewards, terminated, truncated, _ = envs.step(np.roll(actions, step, axis=0))
        parts += [observations, rewards, terminated, truncated]
    return _digest(*parts)


# cases that are not a world: their digest directly, whatever the rate
DIGEST_CASES = {"ant_env": ant_env, "double_pendulum_env": double_pendulum_env}


def _shipped(name: str):
    return lambda: scene_file.load(scene_file.shipped_scene(name)).world


CASES = {
    "mixed_pile": lambda: scenes.mixed_pile(40),
    "hull_pile": hull_pile,
    "ant": ant,
    "ant_articulation": ant_articulation,
    **{
        name: _shipped(name)
        for name in (
            "flagship",
            "ragdoll_stairs",
            "robot_arm",
            "dzhanibekov",
            "four_bar",
            "quadrotor_figure_eight_wind",
        )
    },
}


def _array_digests(prefix: str, value, out: dict) -> None:
    """A short digest of every array in ``value`` (a dataclass, tuple or array), keyed by its field path."""
    if dataclasses.is_dataclass(value):
        for f in dataclasses.fields(value):
            _array_digests(f"{prefix}.{f.name}", getattr(value, f.name), out)
    elif isinstance(value, np.ndarray) and value.dtype != object:
        out[prefix] = hashlib.sha256(np.ascontiguousarray(value).tobytes()).hexdigest()[:16]


def _digest(*arrays) -> str:
    return hashlib.sha256(b"".join(np.ascontiguousarray(a).tobytes() for a in arrays)).hexdigest()[:16]


def model_digests(world) -> dict:
    out: dict = {}
    if not isinstance(world, tumble.World):  # an articulation: what its model makes of its first state, and the state
        model = (world.mass_matrix(), world.contact_pairs, world.forward_dynamics())
        return {"model": _digest(*model), "state": _digest(world.q, world.qd)}
    _array_digests("model", world.model, out)
    _array_digests("state", world.state, out)
    return out


def run(case: str) -> object:
    name, _, rate = case.partition("@")
    if name in DIGEST_CASES:
        return DIGEST_CASES[name]()
    world = CASES[name]()
    if not rate:
        return model_digests(world)
    articulated = not isinstance(world, tumble.World)
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            if articulated:
                world.simulate(DURATION, 1.0 / float(rate), integrator="rk4", record_every=max(1, round(float(rate))))
            else:
                world.simulate(DURATION, 1.0 / float(rate), record_every=max(1, round(float(rate))))
    except SimulationError as error:
        return f"error: {error}"
    return _digest(world.q, world.qd) if articulated else world.state.digest()


def main(argv: list[str]) -> int:
    print(json.dumps({case: run(case) for case in argv}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
