"""Training PPO (stable-baselines3) on tumble/CartPole, with its learning curve.

Not run in CI: it needs stable-baselines3 and PyTorch (``pip install stable-baselines3``), and minutes of training.
Eight copies of ``tumble/CartPole`` feed PPO with its default hyperparameters; each episode's return is logged by
SB3's ``Monitor`` and the learning curve (the mean return of the last 20 episodes against the timesteps) is written
to ``out/cartpole_sb3.csv`` and ``out/cartpole_sb3.png``. The run recorded in docs/envs.md (seed 0) climbs from a
mean return of 20 to 386 (of 500 at most) in 114 688 timesteps, seven PPO updates.

Run: ``python examples/rl/train_cartpole_sb3.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import tumble.envs  # noqa: F401 - registers the environments

OUT = Path("out")


def main(steps: int = 100_000, render: bool = True, seed: int = 0) -> str:
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env

    OUT.mkdir(exist_ok=True)
    envs = make_vec_env("tumble/CartPole", n_envs=8, seed=seed)
    model = PPO("MlpPolicy", envs, seed=seed, verbose=0)
    model.learn(total_timesteps=steps)
    episodes = [(info["episode"]["r"], info["episode"]["l"]) for info in _episodes(envs)]
    returns = np.array([r for r, _ in episodes])
    lengths = np.cumsum([length for _, length in episodes])
    window = np.array([returns[max(0, k - 19) : k + 1].mean() for k in range(len(returns))])
    np.savetxt(OUT / "cartpole_sb3.csv", np.column_stack([lengths, returns, window]), delimiter=",",
               header="timesteps,return,mean_return_last_20", comments="")  # fmt: skip
    if render:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        figure, axes = plt.subplots(figsize=(7, 4))
        axes.plot(lengths, returns, ".", alpha=0.3, label="episode return")
        axes.plot(lengths, window, label="mean of the last 20")
        axes.set(xlabel="timesteps (all copies)", ylabel="return", title="PPO on tumble/CartPole")
        axes.legend()
        figure.savefig(OUT / "cartpole_sb3.png", dpi=120, bbox_inches="tight")
    summary = f"final: {len(returns)} episodes, mean return of the last 20: {window[-1]:.1f}"
    print(summary)
    return summary


def _episodes(envs):
    """Every finished episode's Monitor record, in the order they ended (all copies merged)."""
    records = []
    for monitor in envs.envs:
        times = monitor.get_episode_times()
        records += [(t, {"episode": {"r": r, "l": n}}) for t, r, n in
                    zip(times, monitor.get_episode_rewards(), monitor.get_episode_lengths(), strict=True)]  # fmt: skip
    return [info for _, info in sorted(records, key=lambda pair: pair[0])]


if __name__ == "__main__":
    main()
