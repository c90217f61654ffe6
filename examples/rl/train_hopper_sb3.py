"""Training PPO (stable-baselines3) on tumble/Hopper and on Gymnasium's Hopper-v5 (MuJoCo) with the same budget.

Not run in CI: it needs stable-baselines3 and PyTorch (``pip install stable-baselines3``), and minutes of training.
For each engine and seed, PPO with its default hyperparameters learns from one env (SB3's ``make_vec_env``, its
``Monitor`` logging each episode) for the same number of timesteps; the learning curves (the mean return of the last
20 episodes against the timesteps) go to ``out/hopper_sb3.csv`` and ``out/hopper_sb3.png``, and each trained policy
is scored on 10 fresh episodes of the engine it learnt on. docs/envs.md records a run.

Run: ``python examples/rl/train_hopper_sb3.py [timesteps] [seeds]`` (default 100 000 timesteps, seed 0; docs/envs.md's
run: ``200000 0,1``).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import tumble.envs  # noqa: F401 - registers the environments

OUT = Path("out")
ENGINES = {"tumble": "tumble/Hopper", "MuJoCo": "Hopper-v5"}


def train(env_id: str, steps: int, seed: int):
    """PPO on ``env_id``: ``(timesteps at each episode's end, episode returns, score of the trained policy)``."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.evaluation import evaluate_policy

    envs = make_vec_env(env_id, n_envs=1, seed=seed)
    model = PPO("MlpPolicy", envs, seed=seed, verbose=0)
    model.learn(total_timesteps=steps)
    monitor = envs.envs[0]
    returns = np.array(monitor.get_episode_rewards())
    ends = np.cumsum(monitor.get_episode_lengths())
    score, _ = evaluate_policy(model, make_vec_env(env_id, n_envs=1, seed=1000 + seed), n_eval_episodes=10)
    return ends, returns, score


def _window(returns: np.ndarray) -> np.ndarray:
    return np.array([returns[max(0, k - 19) : k + 1].mean() for k in range(len(returns))])


def main(steps: int = 100_000, render: bool = True, seeds=(0,)) -> str:
    OUT.mkdir(exist_ok=True)
    rows, curves, runs = [], {}, {}
    for engine, env_id in ENGINES.items():
        for seed in seeds:
            start = time.perf_counter()
            ends, returns, score = train(env_id, steps, seed)
            seconds = time.perf_counter() - start
            window = _window(returns)
            curves[engine, seed], runs[engine, seed] = (ends, window), (returns, window[-1], score)
            rows += [(engine, seed, end, value, mean) for end, value, mean in zip(ends, returns, window, strict=True)]
            print(f"{env_id} seed {seed}: {len(returns)} episodes, mean return of the last 20 {window[-1]:.0f}, "
                  f"trained policy {score:.0f} over 10 episodes, {seconds:.0f} s")  # fmt: skip
    with open(OUT / "hopper_sb3.csv", "w") as file:
        file.write("engine,seed,timesteps,return,mean_return_last_20\n")
        file.writelines(f"{e},{s},{t},{r:.6g},{m:.6g}\n" for e, s, t, r, m in rows)
    if render:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        figure, axes = plt.subplots(figsize=(7, 4))
        for (engine, seed), (ends, window) in curves.items():
            axes.plot(ends, window, color="C0" if engine == "tumble" else "C1", alpha=1.0 if seed == seeds[0] else 0.6,
                      label=f"{ENGINES[engine]} (seed {seed})")  # fmt: skip
        axes.set(xlabel="timesteps", ylabel="mean return of the last 20 episodes", title="PPO on Hopper, same budget")
        axes.legend()
        figure.savefig(OUT / "hopper_sb3.png", dpi=120, bbox_inches="tight")
    ours, theirs = runs["tumble", seeds[0]], runs["MuJoCo", seeds[0]]
    if len(ours[0]) == len(theirs[0]) and np.allclose(ours[0], theirs[0], rtol=1e-3):
        summary = (f"final: the same {len(ours[0])} episodes on both engines, mean return of the last 20 "
                   f"{ours[1]:.0f}, trained policy {ours[2]:.0f} over 10 episodes")  # fmt: skip
    else:
        summary = (f"final: the engines part within {min(len(ours[0]), len(theirs[0]))} episodes; mean return of the "
                   f"last 20 {ours[1]:.0f} (tumble) and {theirs[1]:.0f} (MuJoCo)")  # fmt: skip
    print(summary)
    return summary


if __name__ == "__main__":
    arguments = sys.argv[1:]
    main(int(arguments[0]) if arguments else 100_000,
         seeds=tuple(int(s) for s in arguments[1].split(",")) if len(arguments) > 1 else (0,))  # fmt: skip
