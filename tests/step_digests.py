"""Digests of where every step path takes a world: the proof that a structural change of the step (issue 45: one
runner, attachments instead of a hub) changes no result. ``tests/data/step_digests.json`` holds them as recorded
before that change; ``tests/analytic/test_step_digests.py`` asserts them.

    python tests/step_digests.py [--write] [CASE ...]

Cases (each a final ``State.digest()``, or a sha256 of the arrays it produced):
- ``scene/NAME@RATE``: a shipped scene 2 s at 60 or 240 Hz in one ``World.simulate`` (free bodies, contacts,
  joints, compiled and Python flights, sensors, wind: every branch of ``simulate``);
- ``step/NAME``: 0.5 s of it at 60 Hz, one ``World.step`` at a time (the path of a Python loop);
- ``batch``: a ``Batch`` of 4 copies of a pile, one copy pushed, 60 steps;
- ``env``: 40 steps of the quadrotor hover env on fixed actions;
- ``ensemble``: one member of an ensemble over a shipped scene (``ensemble.run_member``, the recording path).
"""

from __future__ import annotations

import hashlib
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

import tumble
from tumble import scene_file, scenes
from tumble.errors import SimulationError

DATA = Path(__file__).resolve().parent / "data" / "step_digests.json"
SCENES = tuple(path.stem for path in scene_file.shipped())
RATES = (60, 240)
DURATION = 2.0


def _shipped(name: str) -> tumble.World:
    return scene_file.load(scene_file.shipped_scene(name)).world


def _arrays_digest(*arrays) -> str:
    h = hashlib.sha256()
    for array in arrays:
        array = np.ascontiguousarray(array)
        h.update(str(array.shape).encode() + str(array.dtype).encode())
        h.update(array.tobytes())
    return h.hexdigest()


def _scene(name: str, rate: int) -> str:
    world = _shipped(name)
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            trajectory = world.simulate(DURATION, 1.0 / rate, record_every=max(1, rate // 10))
    except SimulationError as error:
        return f"error: {error}"
    frames = _arrays_digest(trajectory.time, trajectory.position, trajectory.orientation, trajectory.velocity)
    return f"{frames}:{world.state.digest()}"


def _stepped(name: str) -> str:
    world = _shipped(name)
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            for _ in range(30):
                world.step(1.0 / 60.0)
    except SimulationError as error:
        return f"error: {error}"
    return world.state.digest()


def _batch() -> str:
    world = scenes.mixed_pile(12)
    batch = tumble.Batch(world, 4)
    dynamic = int(np.flatnonzero(world.model.body_is_dynamic)[0])
    for step in range(60):
        if step % 10 == 0:
            batch.apply_force(dynamic, (3.0, 0.0, 2.0 * step))  # copy 0's first body
        batch.step(1.0 / 60.0)
    state = batch.state
    return _arrays_digest(state.body_pos, state.body_quat, state.body_linvel, state.body_angmom)


def _env() -> str:
    from tumble.envs import make_env

    env = make_env("QuadrotorHover")
    observation, _ = env.reset(seed=7)
    rewards, observations = [], [observation]
    actions = np.random.default_rng(3).uniform(-1.0, 1.0, size=(40, *env.action_space.shape))
    for action in actions:
        observation, reward, terminated, truncated, _ = env.step(action.astype(env.action_space.dtype))
        observations.append(observation)
        rewards.append(reward)
        if terminated or truncated:
            observation, _ = env.reset()
    return _arrays_digest(np.array(observations), np.array(rewards))


def _ensemble() -> str:
    from tumble.ensemble.member import MemberTask, run_member
    from tumble.trajectory_io import read

    with tempfile.TemporaryDirectory() as out:
        task = MemberTask(index=0, params={}, build=str(scene_file.shipped_scene("quadrotor_waypoints")),
                          duration=1.0, dt=1.0 / 240.0, record_every=12, out_dir=out, summary=None,
                          request={})  # fmt: skip
        result = run_member(task)
        if result["status"] != "done":
            return f"error: {result['error']}"
        arrays, _, _ = read(result["path"])
    return _arrays_digest(*(arrays[key] for key in sorted(arrays) if isinstance(arrays[key], np.ndarray)))


CASES = {
    **{f"scene/{name}@{rate}": (lambda name=name, rate=rate: _scene(name, rate)) for name in SCENES for rate in RATES},
    **{f"step/{name}": (lambda name=name: _stepped(name)) for name in SCENES},
    "batch": _batch,
    "env": _env,
    "ensemble": _ensemble,
}


def digest(case: str) -> str:
    return CASES[case]()


def main(argv: list[str]) -> int:
    write = "--write" in argv
    cases = [a for a in argv if a != "--write"] or list(CASES)
    found = {}
    for case in cases:
        found[case] = digest(case)
        print(f"{case}: {found[case][:32]}", flush=True)
    if write:
        recorded = json.loads(DATA.read_text()) if DATA.exists() else {}
        recorded.update(found)
        DATA.write_text(json.dumps(dict(sorted(recorded.items())), indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
