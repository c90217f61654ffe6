"""Reinforcement-learning environments: tumble's Gymnasium envs beside Gymnasium's MuJoCo ones (issues 29 and 48).

Run from the repository root:

    python -m benchmarks.envs [--quick] [--repeat N]
    python -m benchmarks.run --only envs

Pairs: ``tumble/CartPole`` beside ``InvertedPendulum-v5`` (a cart-pole in MuJoCo, 2 RK4 steps of 0.02 s per env
step) and ``tumble/DoublePendulum`` beside ``InvertedDoublePendulum-v5`` (the same robot, 5 RK4 steps of 0.01 s);
``tumble/Pendulum`` and ``tumble/QuadrotorHover`` alone; the five locomotion tasks ``tumble/Hopper``,
``tumble/Walker2d``, ``tumble/HalfCheetah``, ``tumble/Ant`` and ``tumble/Humanoid`` beside their ``-v5`` MuJoCo envs
(the same MJCF files, timesteps and integrators; a tenth of the vector env-steps, as a step costs 10-100 times more).
Each env takes random actions drawn beforehand (the same for both engines' copies), resetting when an episode ends:

- one env from ``gymnasium.make`` (with its registration's wrappers), steps per second;
- vector envs of 1, 64 and 1024 copies: tumble's native one (``vectorization_mode="vector_entry_point"``, on 1 and
  2 threads) and Gymnasium's ``SyncVectorEnv`` of the MuJoCo env (``vectorization_mode="sync"``; one thread), in
  env-steps (copies × steps) per second.

Ratios: ``x_mujoco_single`` divides a single tumble env's rate by the single MuJoCo env's; ``x_mujoco_vec64`` a
tumble vector env's by the 64-copy MuJoCo vector env's (issue 29's targets: >= 1 and >= 50 at 1024 copies; issue
48's: one Hopper >= 1, HalfCheetah and Ant at 1024 copies >= 5). Every timing is the best of ``--repeat`` runs after a
first, untimed one (compile, cache load).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from tumble.dynamics import integrate

from .timing import best_time, show_row, sizes_from_args

__all__ = ["EnvSizes", "FULL", "QUICK", "bench_envs"]

PAIRS = (("tumble/CartPole", "InvertedPendulum-v5"), ("tumble/DoublePendulum", "InvertedDoublePendulum-v5"),
         ("tumble/Pendulum", None), ("tumble/QuadrotorHover", None))  # fmt: skip
LOCOMOTION = tuple(
    (f"tumble/{name}", f"{name}-v5") for name in ("Hopper", "Walker2d", "HalfCheetah", "Ant", "Humanoid")
)


@dataclass(frozen=True)
class EnvSizes:
    single_steps: int = 5000
    vector_copies: tuple = (1, 64, 1024)
    vector_env_steps: int = 200_000  # copies × steps per timed run (20 to 5000 steps)
    locomotion_env_steps: int = 20_000  # the same for the locomotion tasks
    mujoco_vector_copies: tuple = (1, 64)
    repeat: int = 3


FULL = EnvSizes()
QUICK = EnvSizes(single_steps=20, vector_copies=(1, 4), vector_env_steps=40, locomotion_env_steps=40,
                 mujoco_vector_copies=(1, 4), repeat=1)  # fmt: skip


def _mujoco_available() -> bool:
    try:
        import gymnasium as gym

        gym.make("InvertedPendulum-v5").close()
    except Exception:  # noqa: BLE001 - MuJoCo or its Gymnasium extras missing: tumble's rows alone
        return False
    return True


def _single_rate(env_id: str, steps: int, repeat: int) -> float:
    import gymnasium as gym

    env = gym.make(env_id)
    env.reset(seed=0)
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(steps)]

    def run():
        for action in actions:
            _, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                env.reset()

    return steps / best_time(run, repeat)


def _vector_rate(env_id: str, copies: int, mode: str, env_steps: int, repeat: int) -> float:
    import gymnasium as gym

    envs = gym.make_vec(env_id, num_envs=copies, vectorization_mode=mode)
    envs.reset(seed=0)
    envs.action_space.seed(0)
    steps = max(20, min(env_steps // copies, 5000))
    actions = [envs.action_space.sample() for _ in range(min(steps, 50))]

    def run():
        for k in range(steps):
            envs.step(actions[k % len(actions)])

    return copies * steps / best_time(run, repeat)


def _row(env_id, engine, kind, copies, threads, rate) -> dict:
    return {"env": env_id, "engine": engine, "kind": kind, "copies": copies, "threads": threads,
            "env_steps_per_s": rate}  # fmt: skip


def bench_envs(sizes: EnvSizes = FULL, report=None) -> list[dict]:
    """Every row (``report(row)`` as each is measured, when given), with the ratios of :func:`with_ratios`."""
    import tumble.envs  # noqa: F401 - registers the environments

    mujoco = _mujoco_available()
    cores = max(1, min(2, os.cpu_count() or 1))
    rows = _Rows(report)
    for ours, theirs in PAIRS + LOCOMOTION:
        env_steps = sizes.locomotion_env_steps if (ours, theirs) in LOCOMOTION else sizes.vector_env_steps
        rows.append(_row(ours, "tumble", "single", 1, 1, _single_rate(ours, sizes.single_steps, sizes.repeat)))
        for copies in sizes.vector_copies:
            for threads in sorted({1, cores}):
                with integrate.using_threads(threads):
                    rate = _vector_rate(ours, copies, "vector_entry_point", env_steps, sizes.repeat)
                rows.append(_row(ours, "tumble", "vector", copies, threads, rate))
        if theirs is None or not mujoco:
            continue
        rows.append(_row(theirs, "MuJoCo", "single", 1, 1, _single_rate(theirs, sizes.single_steps, sizes.repeat)))
        for copies in sizes.mujoco_vector_copies:
            rate = _vector_rate(theirs, copies, "sync", env_steps, sizes.repeat)
            rows.append(_row(theirs, "MuJoCo", "vector", copies, 1, rate))
    return with_ratios(list(rows))


class _Rows(list):
    """A list that reports each row appended."""

    def __init__(self, report) -> None:
        super().__init__()
        self._report = report

    def append(self, row) -> None:
        super().append(row)
        if self._report is not None:
            self._report(row)


def with_ratios(rows: list[dict]) -> list[dict]:
    """Each tumble row of a pair gets its ratio to the MuJoCo single env (single rows) or to the largest MuJoCo
    vector env (vector rows)."""
    for ours, theirs in PAIRS + LOCOMOTION:
        peer = [r for r in rows if r["env"] == theirs]
        if not peer:
            continue
        single = next(r["env_steps_per_s"] for r in peer if r["kind"] == "single")
        vector = max((r for r in peer if r["kind"] == "vector"), key=lambda r: r["copies"])
        for row in rows:
            if row["env"] != ours:
                continue
            if row["kind"] == "single":
                row["x_mujoco_single"] = row["env_steps_per_s"] / single
            else:
                row[f"x_mujoco_vec{vector['copies']}"] = row["env_steps_per_s"] / vector["env_steps_per_s"]
    return rows


def main(argv: list[str] | None = None) -> int:
    rows = bench_envs(sizes_from_args(argv, "python -m benchmarks.envs", __doc__, FULL, QUICK), report=show_row)
    print("ratios:")
    for row in rows:
        if any(key.startswith("x_") for key in row):
            show_row(row)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
