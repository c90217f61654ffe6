"""tumble.envs against their counterparts: Gymnasium's CartPole-v1 and Pendulum-v1 (closed-form ODEs) and MuJoCo's
InvertedDoublePendulum-v5 (the same MJCF robot), stepped from the same states with the same actions."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

gym = pytest.importorskip("gymnasium")

from tumble.envs import make_env  # noqa: E402

pytestmark = pytest.mark.peers


def test_cartpole_runs_gymnasiums_episodes_with_its_semi_implicit_euler():
    """Same seed: the same start (Gymnasium's draw); then, with CartPole-v1 switched to semi-implicit Euler (the
    scheme tumble's symplectic step is), the same states to round-off for a whole episode, terminating together."""
    theirs = gym.make("CartPole-v1").unwrapped
    theirs.kinematics_integrator = "semi-implicit euler"
    ours = make_env("CartPole")
    for seed in (0, 1, 2):
        their_obs, _ = theirs.reset(seed=seed)
        our_obs, _ = ours.reset(seed=seed)
        np.testing.assert_array_equal(our_obs, their_obs)
        rng = np.random.default_rng(seed)
        for step in range(500):
            action = int(rng.integers(2)) if step % 7 else 1 - int(their_obs[2] > 0)
            their_obs, their_reward, their_end, _, _ = theirs.step(action)
            our_obs, our_reward, our_end, _, _ = ours.step(action)
            np.testing.assert_allclose(ours.state[0], theirs.state[[0, 2]], rtol=1e-9, atol=1e-12)
            np.testing.assert_allclose(ours.state[1], theirs.state[[1, 3]], rtol=1e-9, atol=1e-12)
            assert our_reward == their_reward and our_end == their_end
            if our_end:
                break
        assert step > 8  # a real episode


def test_pendulum_starts_and_pays_as_gymnasiums_and_steps_as_the_exact_ode():
    """Same seed, same start; the same reward for the same state and torque (the cost of the state before the
    step). Where Gymnasium takes a semi-implicit Euler step of 0.05 s, tumble's RK4 step lands on the exact solution of
    the same ODE, θ̈ = 3g/(2l) sin θ + 3u/(ml²) (SciPy's solve_ivp at 1e-12), to 5e-5."""
    theirs = gym.make("Pendulum-v1").unwrapped
    ours = make_env("Pendulum")
    for seed in range(5):
        their_obs, _ = theirs.reset(seed=seed)
        our_obs, _ = ours.reset(seed=seed)
        np.testing.assert_allclose(our_obs, their_obs, rtol=1e-6, atol=1e-7)
        for torque in (-2.0, 0.5, 3.0):
            theirs.state = np.array(ours.state[0].tolist() + ours.state[1].tolist())
            start = theirs.state.copy()
            _, their_reward, *_ = theirs.step(np.array([torque], dtype=np.float32))
            _, our_reward, *_ = ours.step(np.array([torque], dtype=np.float32))
            assert our_reward == pytest.approx(their_reward, rel=1e-8)  # theirs squares u in float32
            u = float(np.clip(np.float32(torque), -2.0, 2.0))
            exact = solve_ivp(lambda t, y, u=u: (y[1], 15.0 * np.sin(y[0]) + 3.0 * u), (0.0, 0.05), start,
                              rtol=1e-12, atol=1e-12).y[:, -1]  # fmt: skip
            np.testing.assert_allclose(np.concatenate(ours.state), exact, atol=5e-5)  # measured 1.1e-5


mujoco = pytest.importorskip("mujoco")


def test_double_pendulum_moves_as_mujocos_inverted_double_pendulum():
    """From the same states with the same actions, 30 steps (1.5 s) of InvertedDoublePendulum-v5 and of
    tumble/DoublePendulum: the same coordinates and velocities to 1e-8 (both RK4 at 0.01 s on the same bodies) and the
    same observations, while the cart stays inside MuJoCo's rail stops. MuJoCo's env reads the tip where its last
    substep started (``site_xpos`` is computed before the integration), tumble's where the step ends: with MuJoCo's
    kinematics brought to the end of the step, MuJoCo's own reward function (``_get_rew``) and termination
    (``y <= 1``) give tumble's to 1e-6."""
    theirs = gym.make("InvertedDoublePendulum-v5").unwrapped
    ours = make_env("DoublePendulum")
    ends = 0
    for seed in range(3):
        theirs.reset(seed=seed)
        ours.reset(seed=seed)
        q, qd = ours.state
        theirs.set_state(q, qd)
        rng = np.random.default_rng(seed)
        for _ in range(30):
            action = rng.uniform(-0.3, 0.3, 1).astype(np.float32)
            their_obs, _, _, _, _ = theirs.step(action)
            our_obs, our_reward, our_end, _, _ = ours.step(action)
            assert abs(theirs.data.qpos[0]) < 0.95  # the stops (at ±1, margin 0.01) never act
            np.testing.assert_allclose(ours.state[0], theirs.data.qpos, atol=1e-8)
            np.testing.assert_allclose(ours.state[1], theirs.data.qvel, atol=1e-7)
            np.testing.assert_allclose(our_obs, their_obs[:8], rtol=1e-5, atol=1e-6)
            mujoco.mj_kinematics(theirs.model, theirs.data)
            x, _, y = theirs.data.site_xpos[0]
            their_end = bool(y <= 1.0)
            their_reward, _ = theirs._get_rew(x, y, their_end)
            assert our_end == their_end
            assert our_reward == pytest.approx(their_reward, abs=1e-6)
            if our_end:
                ends += 1
                break
    assert ends >= 1  # the poles fell at least once: terminations compared
