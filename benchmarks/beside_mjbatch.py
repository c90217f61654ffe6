"""tumble beside mjbatch (MuJoCo batched on C++ threads): native vector envs, 1024 copies of the ant and the
half-cheetah (issue 48); 4096 tumbling free bodies in a ``tumble.Batch`` (issue 49).

mjbatch 0.1.4 pins ``mujoco==3.14.0``, which the test and bench extras' MuJoCo 4 rules out, so this runs in a venv of
its own (mjbatch, Gymnasium and tumble):

    make bench-mjbatch                       # builds .venv-mjbatch, then runs this module
    .venv-mjbatch/bin/python -m benchmarks.beside_mjbatch [--quick] [--repeat N]

Rows, in env-steps (copies × control steps) per second, on 1 and 2 threads, the same MJCF file, timestep, integrator
and ``frame_skip``:

- ``tumble env``: ``gym.make_vec("tumble/<task>", 1024, vectorization_mode="vector_entry_point")``: observations (the
  ant's with its contact forces), rewards, ``info`` and autoresets;
- ``mjbatch env``: an ``mjbatch.Batch`` of 1024 simulations driven as a vector env with the least around it: ``ctrl``
  set, ``frame_skip`` ``mj_step`` calls, observations ``(qpos[skip:], qvel)`` gathered and the ant's fallen copies
  reset, no rewards or ``info`` (and no ``cfrc_ext``: ``mj_step`` does not compute it);
- ``tumble physics`` and ``mjbatch physics``: the controls set and the steps taken, nothing else (no resets).

Random actions drawn beforehand, the same for both; best of ``--repeat`` runs after an untimed one.

Tumbling: ``benchmarks/batch.py``'s anisotropic spinning body, 4096 copies for 1000 steps of 1 ms, tumble's RK4 beside
mjbatch's RK4 and tumble's symplectic Euler beside mjbatch's Euler, in body-steps per second.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from .timing import best_time, show_row, sizes_from_args

__all__ = ["FULL", "QUICK", "MjbatchSizes", "bench_mjbatch"]

TASKS = {"Ant": ("ant.xml", 5, 2), "HalfCheetah": ("half_cheetah.xml", 5, 1)}  # file, frame_skip, skipped qpos


@dataclass(frozen=True)
class MjbatchSizes:
    copies: int = 1024
    steps: int = 20
    tumbling_copies: int = 4096
    tumbling_steps: int = 1000
    repeat: int = 3


FULL = MjbatchSizes()
QUICK = MjbatchSizes(copies=8, steps=2, tumbling_copies=8, tumbling_steps=20, repeat=1)


def _tumble_env(task: str, copies: int, steps: int, actions, repeat: int) -> float:
    import gymnasium as gym

    envs = gym.make_vec(f"tumble/{task}", num_envs=copies, vectorization_mode="vector_entry_point")
    envs.reset(seed=0)

    def run():
        for k in range(steps):
            envs.step(actions[k])

    return copies * steps / best_time(run, repeat)


def _tumble_physics(task: str, copies: int, steps: int, actions, repeat: int) -> float:
    from tumble.envs import make_vector_env

    envs = make_vector_env(task, copies)
    envs.reset(seed=0)
    inner = envs._copies
    batch, substeps = inner.batch, inner.task.substeps

    def run():
        for k in range(steps):
            inner.task.prepare(actions[k], batch.q, batch.qd, batch.tau)  # the motors' forces, as mjbatch's ctrl
            batch._advance(inner._h, substeps, inner._method, readout=inner.links)

    return copies * steps / best_time(run, repeat)


def _mjbatch(task: str, copies: int, threads: int, steps: int, actions, repeat: int, env: bool) -> float:
    import gymnasium
    import mujoco
    from mjbatch import Batch

    name, frame_skip, skipped = TASKS[task]
    model = mujoco.MjModel.from_xml_path(os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco",
                                                      "assets", name))  # fmt: skip
    batch = Batch(model, copies, num_threads=threads)
    qpos, qvel, ctrl = batch.bind("qpos"), batch.bind("qvel"), batch.bind("ctrl")
    rng = np.random.default_rng(0)

    def start(ids):
        batch.reset(ids)
        qpos[ids] = model.qpos0 + rng.uniform(-0.1, 0.1, (len(ids), model.nq))
        qvel[ids] = 0.1 * rng.standard_normal((len(ids), model.nv))

    start(np.arange(copies))

    def run():
        for k in range(steps):
            ctrl[:] = actions[k]
            batch.step(nstep=frame_skip)
            if env:
                np.concatenate([qpos[:, skipped:], qvel], axis=1)
                if task == "Ant":
                    fallen = np.flatnonzero((qpos[:, 2] < 0.2) | (qpos[:, 2] > 1.0))
                    if len(fallen):
                        start(fallen)

    return copies * steps / best_time(run, repeat)


def bench_tumbling(sizes: MjbatchSizes = FULL, report=None) -> list[dict]:
    """4096 anisotropic spinning bodies: tumble's RK4 and symplectic Euler beside mjbatch's RK4 and Euler."""
    import mujoco
    from mjbatch import Batch

    import tumble
    from tumble.dynamics import integrate

    from . import peers
    from .batch import INERTIA, LIKE, OMEGA, tumbling_world

    copies, steps, rows = sizes.tumbling_copies, sizes.tumbling_steps, []
    for threads in (1, 2):
        for ours, theirs in LIKE.items():
            batch = tumble.Batch(tumbling_world(INERTIA, ours), copies)

            def run_tumble(batch=batch):
                batch.reset()
                batch.step(1e-3, steps=steps)

            with integrate.using_threads(threads):
                rate = copies * steps / best_time(run_tumble, sizes.repeat)
            model = mujoco.MjModel.from_xml_string(peers.tumbling_body_mjcf(theirs, 1e-3, 1.0, INERTIA))
            sims = Batch(model, copies, num_threads=threads)
            qvel = sims.bind("qvel")

            def run_mjbatch(sims=sims, qvel=qvel):
                sims.reset(np.arange(copies))
                qvel[:, 3:] = OMEGA  # a free joint's angular velocity is in its body frame, here the principal axes
                sims.step(nstep=steps)

            peer = copies * steps / best_time(run_mjbatch, sizes.repeat)
            for engine, config, value in (("tumble", ours, rate), ("mjbatch", theirs, peer)):
                row = {"task": "tumbling", "kind": f"{engine} {config}", "copies": copies, "threads": threads,
                       "body_steps_per_s": value}  # fmt: skip
                if engine == "tumble":
                    row["x_mjbatch"] = rate / peer
                rows.append(row)
                if report is not None:
                    report(row)
    return rows


def bench_mjbatch(sizes: MjbatchSizes = FULL, report=None) -> list[dict]:
    import gymnasium as gym

    import tumble.envs  # noqa: F401 - registers the environments
    from tumble.dynamics import integrate

    rows = []
    for task in TASKS:
        space = gym.make(f"tumble/{task}").action_space
        space.seed(0)
        actions = [np.stack([space.sample() for _ in range(sizes.copies)]) for _ in range(sizes.steps)]
        for threads in (1, 2):
            with integrate.using_threads(threads):
                measured = {
                    "tumble env": _tumble_env(task, sizes.copies, sizes.steps, actions, sizes.repeat),
                    "tumble physics": _tumble_physics(task, sizes.copies, sizes.steps, actions, sizes.repeat),
                }
            measured["mjbatch env"] = _mjbatch(task, sizes.copies, threads, sizes.steps, actions, sizes.repeat, True)
            measured["mjbatch physics"] = _mjbatch(task, sizes.copies, threads, sizes.steps, actions, sizes.repeat,
                                                   False)  # fmt: skip
            for kind, rate in measured.items():
                row = {"task": task, "kind": kind, "copies": sizes.copies, "threads": threads, "env_steps_per_s": rate}
                if kind.startswith("tumble"):
                    peer = measured["mjbatch " + kind.split()[1]]
                    row["x_mjbatch"] = rate / peer
                rows.append(row)
                if report is not None:
                    report(row)
    return rows


def main(argv: list[str] | None = None) -> int:
    sizes = sizes_from_args(argv, "python -m benchmarks.beside_mjbatch", __doc__, FULL, QUICK)
    bench_mjbatch(sizes, report=show_row)
    bench_tumbling(sizes, report=show_row)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
