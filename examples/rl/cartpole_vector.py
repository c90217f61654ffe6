"""Balancing 256 cart-poles at once: a native Gymnasium vector env and a hand-made policy.

``gymnasium.make_vec("tumble/CartPole", num_envs=256, vectorization_mode="vector_entry_point")`` steps all the
copies in one compiled call. The policy is a linear state feedback, push right when ``θ + 0.5 θ̇ + 0.1 x + 0.2 ẋ``
is positive (a bang-bang controller that keeps the pole up and the cart near the middle), applied to every copy at
once with array operations. Every copy starts from its own random state; none falls.

Run: ``python examples/rl/cartpole_vector.py``.
"""

from __future__ import annotations

import time

import gymnasium as gym
import numpy as np

import tumble.envs  # noqa: F401 - registers the environments

GAINS = np.array([0.1, 0.2, 1.0, 0.5])  # on (x, ẋ, θ, θ̇)


def main(steps: int = 500, render: bool = False, copies: int = 256) -> str:
    envs = gym.make_vec("tumble/CartPole", num_envs=copies, vectorization_mode="vector_entry_point")
    observations, _ = envs.reset(seed=0)
    fallen = truncated_total = 0
    start = time.perf_counter()
    for _ in range(steps):
        actions = (observations @ GAINS > 0.0).astype(np.int64)
        observations, rewards, terminated, truncated, _ = envs.step(actions)
        fallen += int(terminated.sum())
        truncated_total += int(truncated.sum())
    elapsed = time.perf_counter() - start
    print(f"{copies * steps / elapsed:,.0f} env-steps/s")
    summary = (f"final: {copies} copies for {steps} steps, {fallen} fell, {truncated_total} episodes reached the "
               f"{envs.max_episode_steps}-step limit")  # fmt: skip
    print(summary)
    return summary


if __name__ == "__main__":
    main()
