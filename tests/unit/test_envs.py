"""tumble.envs: Gymnasium's API and checker, seeds, native vector envs (autoreset, copies equal single envs), the
physics of each task against its closed form, rendering and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from gymnasium.utils import seeding  # noqa: E402
from gymnasium.utils.env_checker import check_env  # noqa: E402
from gymnasium.vector import AutoresetMode  # noqa: E402

import tumble.envs  # noqa: E402
from tumble.envs import TASKS, TumbleEnv, TumbleVectorEnv, make_env, make_vector_env  # noqa: E402
from tumble.models.mjcf import MJCFError  # noqa: E402
from tumble.rotation import quat_from_rotvec  # noqa: E402
from tumble.vehicles import rotor_hubs  # noqa: E402

NAMES = tuple(TASKS)


def _actions(space, count: int, seed: int) -> list:
    space.seed(seed)
    return [space.sample() for _ in range(count)]


@pytest.mark.parametrize("name", NAMES)
def test_every_env_passes_gymnasiums_checker(name):
    env = gym.make(f"tumble/{name}", render_mode="rgb_array")
    assert isinstance(env.unwrapped, TumbleEnv)
    check_env(env.unwrapped)
    assert env.spec.max_episode_steps == TASKS[name].max_episode_steps


@pytest.mark.parametrize("name", NAMES)
def test_the_same_seed_gives_the_same_episode(name):
    episodes = []
    for _ in range(2):
        env = gym.make(f"tumble/{name}")
        observation, _ = env.reset(seed=11)
        frames = [observation]
        for action in _actions(env.action_space, 12, seed=5):
            observation, reward, terminated, truncated, _ = env.step(action)
            frames.append(np.append(observation, reward))
            if terminated:
                break
        episodes.append(frames)
    other = gym.make(f"tumble/{name}").reset(seed=12)[0]
    assert not np.array_equal(episodes[0][0], other)
    assert len(episodes[0]) == len(episodes[1])
    for a, b in zip(*episodes, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("name", NAMES)
def test_make_vec_returns_the_native_vector_env(name):
    envs = gym.make_vec(f"tumble/{name}", num_envs=3, vectorization_mode="vector_entry_point")
    assert isinstance(envs, TumbleVectorEnv)
    assert envs.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert envs.max_episode_steps == TASKS[name].max_episode_steps
    single = make_env(name)
    assert envs.single_observation_space == single.observation_space
    assert envs.single_action_space == single.action_space
    observations, infos = envs.reset(seed=0)
    assert observations.shape == (3, *single.observation_space.shape)
    assert observations.dtype == single.observation_space.dtype
    assert all(observations[c] in single.observation_space for c in range(3))
    results = envs.step(envs.action_space.sample())
    assert results[0].shape == observations.shape
    assert results[1].shape == results[2].shape == results[3].shape == (3,)
    assert results[2].dtype == results[3].dtype == np.bool_


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("seed", [3, [7, 1, 7, 40]])
def test_each_vector_copy_equals_the_single_env_with_its_seed(name, seed):
    """Gymnasium's ``SyncVectorEnv`` convention: ``reset(seed=s)`` starts copy i as a single env seeded ``s + i``,
    ``reset(seed=[...])`` as one seeded with its entry; stepped with the same actions, each copy is that env bit for
    bit (states, observations, rewards, terminations) through its episode and its autoreset's next start."""
    copies = 4
    seeds = [seed + c for c in range(copies)] if isinstance(seed, int) else seed
    envs = make_vector_env(name, copies, max_episode_steps=6)
    observations, _ = envs.reset(seed=seed)
    singles = [make_env(name) for _ in range(copies)]
    for c, env in enumerate(singles):
        np.testing.assert_array_equal(observations[c], env.reset(seed=seeds[c])[0])
    restart = np.zeros(copies, dtype=bool)
    for actions in _actions(envs.action_space, 9, seed=2):
        observations, rewards, terminated, truncated, _ = envs.step(actions)
        for c, env in enumerate(singles):
            if restart[c]:
                observation, reward, ended = env.reset()[0], 0.0, False
            else:
                observation, reward, ended, _, _ = env.step(actions[c])
            np.testing.assert_array_equal(envs.state[0][c], env.state[0])
            np.testing.assert_array_equal(envs.state[1][c], env.state[1])
            np.testing.assert_array_equal(observations[c], observation)
            assert rewards[c] == reward and terminated[c] == ended
        restart = terminated | truncated
    assert restart.any() or envs._copies.elapsed.max() < 6


def test_autoreset_follows_gymnasiums_next_step_mode():
    """A copy that terminates or truncates is reset by the next step: its first observation, reward 0, neither flag;
    its action is ignored and the other copies step on."""
    envs = make_vector_env("CartPole", 3, max_episode_steps=4)
    envs.reset(seed=0)
    push = np.array([1, 1, 1])
    for _ in range(3):
        _, rewards, terminated, truncated, _ = envs.step(push)
        assert not truncated.any() and not terminated.any()
    _, rewards, terminated, truncated, _ = envs.step(push)
    assert truncated.all() and not terminated.any()
    np.testing.assert_array_equal(rewards, 1.0)
    observations, rewards, terminated, truncated, _ = envs.step(push)
    np.testing.assert_array_equal(rewards, 0.0)
    assert not terminated.any() and not truncated.any()
    assert np.all(np.abs(observations) <= 0.05)  # fresh starts, uniform in ±0.05
    # a termination: copy 1 pushed over by a tilted start
    envs = make_vector_env("CartPole", 3)
    envs.reset(seed=0)
    q, qd = envs.state
    q[1, 1] = 0.2  # 11.5°, falling
    envs.set_state(q, qd)
    for _ in range(40):
        observations, rewards, terminated, truncated, _ = envs.step(np.array([1, 0, 1]))
        if terminated[1]:
            break
    assert terminated[1] and not truncated[1] and abs(observations[1, 2]) > 12 * math.pi / 180
    observations, rewards, terminated, _, _ = envs.step(np.array([1, 0, 1]))
    assert rewards[1] == 0.0 and not terminated[1] and np.all(np.abs(observations[1]) <= 0.05)


def test_a_reset_mask_resets_only_the_chosen_copies():
    envs = make_vector_env("Pendulum", 4)
    envs.reset(seed=1)
    for _ in range(3):
        envs.step(np.ones((4, 1), dtype=np.float32))
    before = envs.state[0].copy()
    mask = np.array([False, True, False, True])
    observations, _ = envs.reset(options={"reset_mask": mask})
    after = envs.state[0]
    np.testing.assert_array_equal(after[~mask], before[~mask])
    assert np.all(after[mask] != before[mask])
    assert envs._copies.elapsed.tolist() == [3, 0, 3, 0]


def test_cartpole_accelerations_are_gymnasiums_closed_form():
    """The articulation's accelerations equal CartPole-v1's equations (Florian 2007) at random states and forces."""
    task = TASKS["CartPole"]()
    art = task.articulation()
    g, cart, pole, half = 9.8, 1.0, 0.1, 0.5
    rng = np.random.default_rng(0)
    for _ in range(20):
        x, x_dot, theta, theta_dot = rng.uniform(-2, 2, 4)
        force = rng.choice((-10.0, 10.0))
        temp = (force + pole * half * theta_dot**2 * math.sin(theta)) / (cart + pole)
        theta_acc = (g * math.sin(theta) - math.cos(theta) * temp) / (
            half * (4.0 / 3.0 - pole * math.cos(theta) ** 2 / (cart + pole))
        )
        x_acc = temp - pole * half * theta_acc * math.cos(theta) / (cart + pole)
        acc = art.forward_dynamics(q=(x, theta), qd=(x_dot, theta_dot), tau=(force, 0.0))
        np.testing.assert_allclose(acc, (x_acc, theta_acc), rtol=1e-12, atol=1e-12)


def test_pendulum_accelerations_are_gymnasiums_closed_form():
    art = TASKS["Pendulum"]().articulation()
    for theta, torque in ((0.3, 0.0), (-2.0, 1.5), (3.0, -2.0)):
        acc = art.forward_dynamics(q=(theta,), qd=(0.7,), tau=(torque,))
        np.testing.assert_allclose(acc, [3 * 10.0 / 2 * math.sin(theta) + 3.0 * torque], rtol=1e-12)


def test_the_double_pendulums_bodies_are_the_mujoco_models():
    """Masses from the capsules of inverted_double_pendulum.xml at density 1000: the cart (radius 0.1, 0.2 m) and
    the poles (radius 0.045, 0.6 m); the upright pose puts the tip 1.2 m up and does not terminate."""
    task = TASKS["DoublePendulum"]()
    masses = [link.mass_properties.mass for link in task.articulation().links]
    capsule = [1000 * (math.pi * r * r * length + 4 / 3 * math.pi * r**3) for r, length in ((0.1, 0.2), (0.045, 0.6))]
    np.testing.assert_allclose(masses, [capsule[0], capsule[1], capsule[1]], rtol=1e-12)
    x, y = task.tip(np.array([[0.3, 0.0, 0.0], [0.0, math.pi / 2, 0.0]]))
    np.testing.assert_allclose(x, [0.3, 1.2], atol=1e-12)
    np.testing.assert_allclose(y, [1.2, 0.0], atol=1e-12)
    assert task.terminated(np.array([[0.3, 0.0, 0.0], [0.0, math.pi / 2, 0.0]]), np.zeros((2, 3))).tolist() == [
        False,
        True,
    ]


def _hovering_quadrotor():
    """The quadrotor's task and the action (every rotor alike) whose speed carries its weight: kt ω² = m g / 4."""
    task = TASKS["QuadrotorHover"]()
    p = task.params
    hover = math.sqrt(p["mass"] * 9.81 / (4 * p["k_thrust"]))
    return task, 2 * (hover - p["speed_min"]) / (p["speed_max"] - p["speed_min"]) - 1


def test_the_quadrotor_hovers_at_the_speeds_that_carry_its_weight_and_falls_without_them():
    task, action = _hovering_quadrotor()
    env = make_env("QuadrotorHover")
    env.reset(seed=0)
    start = np.array([0.1, -0.2, 0.3, 1.0, 0.0, 0.0, 0.0])
    env.set_state(start, np.zeros(6))
    for _ in range(50):
        observation, reward, terminated, _, _ = env.step(np.full(4, action))  # float64: the exact hover speed
    q, qd = env.state
    np.testing.assert_allclose(q, start, atol=1e-9)  # held still for 0.5 s
    np.testing.assert_allclose(qd, 0.0, atol=1e-9)
    assert reward == pytest.approx(1.0 - np.linalg.norm(start[:3]) - 1e-5 * 2 * abs(action), abs=1e-8)
    env.set_state(start, np.zeros(6))
    for _ in range(30):  # rotors at their slowest (zero speed): free fall for 0.3 s
        _, reward, *_ = env.step(np.full(4, -1.0, dtype=np.float32))
    q, qd = env.state
    np.testing.assert_allclose(q[2], 0.3 - 0.5 * 9.81 * 0.3**2, atol=1e-12)
    np.testing.assert_allclose(qd[2], -9.81 * 0.3, atol=1e-12)
    # the cost: distance, half the speed, half the body rate (none) and 1e-5 |a| (|a| = 2)
    assert reward == pytest.approx(1.0 - np.linalg.norm(q[:3]) - 0.5 * 9.81 * 0.3 - 2e-5, abs=1e-12)


@pytest.mark.parametrize(
    ("axis", "action"),
    [(0, (0.3, -0.3, -0.3, 0.3)), (1, (-0.3, -0.3, 0.3, 0.3)), (2, (0.3, -0.3, 0.3, -0.3))],
    ids=["roll", "pitch", "yaw"],
)
def test_the_quadrotor_turns_about_the_body_axis_its_rotors_push(axis, action):
    """Rotor speeds that differ across an axis (layout "x": hubs at (+,+), (+,-), (-,-), (-,+)) or between the two
    spin directions: the body rate about that axis grows at M/I from rest, M from the rotors' geometry
    (Mx = kt Σ ω² y, My = -kt Σ ω² x, Mz = km Σ spin ω²), and the other two rates stay zero."""
    task = TASKS["QuadrotorHover"]()
    p = task.params
    env = make_env("QuadrotorHover")
    env.reset(seed=0)
    env.set_state(np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]), np.zeros(6))
    action = np.array(action)
    _, reward, *_ = env.step(action)
    squared = task.rotor_speeds(action[None])[0] ** 2
    hubs = rotor_hubs("x", p["arm_length"])
    moments = (p["k_thrust"] * squared @ hubs[:, 1], -p["k_thrust"] * squared @ hubs[:, 0],
               p["k_moment"] * squared @ np.asarray(p["rotor_directions"], dtype=float))  # fmt: skip
    (q, qd), rates = env.state, env.state[1][3:]
    assert abs(moments[axis]) > 1e-6
    np.testing.assert_allclose(rates[axis], moments[axis] / p["inertia"][axis, axis] * 0.01, rtol=1e-6)
    np.testing.assert_allclose(np.delete(rates, axis), 0.0, atol=1e-9)
    cost = np.linalg.norm(q[:3]) + 0.5 * np.linalg.norm(qd[:3]) + 0.5 * np.linalg.norm(rates)
    assert reward == pytest.approx(1.0 - cost - 1e-5 * np.linalg.norm(action), abs=1e-12)


def test_a_tilted_quadrotors_thrust_pushes_along_its_body_z_axis():
    """Tilted 30° about x with every rotor at the hover speed: the thrust 4 kt ω² along the body z axis,
    (0, -sin 30°, cos 30°) in the world, plus gravity, accelerates it from rest; RK4 integrates the constant
    acceleration exactly."""
    task, action = _hovering_quadrotor()
    env = make_env("QuadrotorHover")
    env.reset(seed=0)
    tilt = math.radians(30.0)
    env.set_state(np.array([0.0, 0.0, 0.0, math.cos(tilt / 2), math.sin(tilt / 2), 0.0, 0.0]), np.zeros(6))
    env.step(np.full(4, action))
    p = task.params
    thrust = 4 * p["k_thrust"] * task.rotor_speeds(np.full((1, 4), action))[0, 0] ** 2
    expected = thrust / p["mass"] * np.array([0.0, -math.sin(tilt), math.cos(tilt)]) + (0.0, 0.0, -9.81)
    np.testing.assert_allclose(env.state[1][:3], expected * 0.01, atol=1e-12)
    np.testing.assert_allclose(env.state[1][3:], 0.0, atol=1e-12)
    assert expected[1] < -4.0  # it slides towards -y


@pytest.mark.parametrize("name", NAMES)
def test_rendering_draws_the_state(name):
    env = make_env(name, render_mode="rgb_array")
    env.reset(seed=0)
    first = env.render()
    assert first.dtype == np.uint8 and first.ndim == 3 and first.shape[2] == 3
    assert len(np.unique(first.reshape(-1, 3), axis=0)) >= 3  # background and at least two colours
    q, qd = env.state
    q = q.copy()
    q[0] += 0.4
    env.set_state(q, qd)
    assert not np.array_equal(env.render(), first)
    vector = make_vector_env(name, 2, render_mode="rgb_array")
    vector.reset(seed=0)
    frames = vector.render()
    assert len(frames) == 2 and frames[0].shape == first.shape
    with pytest.warns(UserWarning, match="render_mode"):
        assert make_env(name).render() is None


def test_bad_input_is_refused_with_the_argument_named():
    with pytest.raises(ValueError, match="render_mode must be None or one of"):
        make_env("CartPole", render_mode="human")
    with pytest.raises(ValueError, match="task must be one of"):
        make_env("Acrobot")
    with pytest.raises(ValueError, match="num_envs must be a positive integer"):
        make_vector_env("CartPole", 0)
    with pytest.raises(ValueError, match="max_episode_steps must be a positive integer"):
        make_vector_env("CartPole", 2, max_episode_steps=0)
    envs = make_vector_env("CartPole", 2)
    with pytest.raises(RuntimeError, match="reset"):
        envs.step(np.array([0, 1]))
    envs.reset(seed=0)
    with pytest.raises(ValueError, match="actions must have 2 rows"):
        envs.step(np.array([0, 1, 1]))
    with pytest.raises(ValueError, match=r"actions must be 0 \(push left\) or 1"):
        envs.step(np.array([0, 2]))
    with pytest.raises(TypeError, match="seed must be None, an int or a list of 2 ints"):
        envs.reset(seed=1.5)
    with pytest.raises(ValueError, match="one entry per copy"):
        envs.reset(seed=[1, 2, 3])
    with pytest.raises(TypeError, match="seed entries must be ints or None"):
        envs.reset(seed=[1, "2"])
    with pytest.raises(ValueError, match="reset_mask"):
        envs.reset(options={"reset_mask": np.array([1, 0])})
    env = make_env("DoublePendulum")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="qd"):
        env.set_state(np.zeros(3), np.zeros(2))
    before = env.state
    with pytest.raises(ValueError, match="q"):
        env.set_state(np.zeros(4), np.zeros(3))
    np.testing.assert_array_equal(env.state[0], before[0])


def test_actions_are_clipped_to_the_action_space():
    envs = make_vector_env("DoublePendulum", 2)
    envs.reset(seed=4)
    state = envs.state
    first = envs.step(np.array([[1.0], [1.0]], dtype=np.float32))
    envs.set_state(*state)
    envs._copies.elapsed[:] = 0
    second = envs.step(np.array([[7.0], [1.0]], dtype=np.float32))
    np.testing.assert_array_equal(first[0], second[0])


def test_the_module_registers_each_env_once():
    import importlib

    importlib.reload(tumble.envs)
    assert {f"tumble/{name}" for name in NAMES} <= set(gym.registry)


def test_locomotion_arguments_and_actions_are_checked():
    """Gymnasium's v5 arguments are validated by name, bad actions refused with nothing stepped."""
    with pytest.raises(ValueError, match="ctrl_cost_weight must be a finite number"):
        make_env("Hopper", ctrl_cost_weight="x")
    with pytest.raises(ValueError, match="healthy_z_range must be a .low, high. pair with low <= high"):
        make_env("Walker2d", healthy_z_range=(2.0, 1.0))
    with pytest.raises(TypeError, match="terminate_when_unhealthy must be True or False"):
        make_env("Ant", terminate_when_unhealthy=1)
    with pytest.raises(ValueError, match="frame_skip must be a positive integer"):
        make_env("HalfCheetah", frame_skip=0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'gear'"):
        make_env("Humanoid", gear=2.0)
    with pytest.raises(ValueError, match="main_body must be the root body"):
        make_env("Ant", main_body="aux_1")
    with pytest.raises(MJCFError, match="no such model file"):
        make_env("Hopper", xml_file="/nonexistent/hopper.xml")
    env = make_env("Hopper", frame_skip=2, ctrl_cost_weight=0.5)
    assert env.task.dt == pytest.approx(0.004) and env.metadata["render_fps"] == 250
    env.reset(seed=0)
    before = env.state
    with pytest.raises(ValueError, match=r"action must have shape \(3,\), got \(2,\)"):
        env.step(np.zeros(2, dtype=np.float32))
    with pytest.raises(ValueError, match="action must be finite"):
        env.step(np.array([0.0, np.nan, 0.0], dtype=np.float32))
    np.testing.assert_array_equal(env.state[0], before[0])
    _, reward, _, _, info = env.step(np.full(3, 2.0, dtype=np.float32))  # clipped to ±1 for the motors, not the cost
    assert info["reward_ctrl"] == pytest.approx(-0.5 * 3 * 4.0)


def _gymnasium_style_start(task, rng):
    """``(q, qd)`` drawn as Gymnasium's own envs draw a start: ``rng.uniform`` and ``rng.standard_normal`` calls."""
    name = type(task).__name__
    if name == "CartPoleTask":
        start = rng.uniform(-0.05, 0.05, size=4)
        return start[0::2], start[1::2]
    if name == "PendulumTask":
        start = rng.uniform((-math.pi, -1.0), (math.pi, 1.0), size=2)
        return start[:1], start[1:]
    if name == "DoublePendulumTask":
        return rng.uniform(-0.1, 0.1, size=3), 0.1 * rng.standard_normal(3)
    if name == "QuadrotorHoverTask":
        start = rng.uniform(np.repeat((-0.5, -0.2, -0.5, -0.2), 3), np.repeat((0.5, 0.2, 0.5, 0.2), 3), size=12)
        return np.concatenate([start[:3], quat_from_rotvec(start[3:6])]), start[6:]
    noise, nv = task.reset_noise_scale, task.init_qd.shape[0]
    q = task.init_q + rng.uniform(-noise, noise, size=task.init_q.shape[0])
    if task.uniform_velocity_noise:
        return q, task.init_qd + rng.uniform(-noise, noise, size=nv)
    return q, task.init_qd + noise * rng.standard_normal(nv)


@pytest.mark.parametrize("name", NAMES)
def test_a_start_is_the_generators_own_uniform_and_normal_draws_bit_for_bit(name):
    """Starts are drawn a copy at a time as standard draws and mapped for all copies at once: the same bits as
    ``rng.uniform(low, high)`` and ``scale * rng.standard_normal()`` of the copy's generator, seeded or continued."""
    env = make_env(name)
    for seed in (0, 1, 2024):
        rng = seeding.np_random(seed)[0]
        env.reset(seed=seed)
        for _ in range(3):  # the seeded start, then starts that continue the copy's generator
            q, qd = _gymnasium_style_start(env.task, rng)
            np.testing.assert_array_equal(env.state[0], q)
            np.testing.assert_array_equal(env.state[1], qd)
            env.reset()


def test_start_draws_of_an_unknown_kind_are_refused_with_the_task_named():
    class Lopsided(TASKS["Pendulum"]):
        start_draws = (("gaussian", 2),)

    with pytest.raises(ValueError, match=r"Lopsided.start_draws entries must be \(kind, count\).*'gaussian', 2"):
        TumbleVectorEnv(Lopsided(), 2)
    Lopsided.start_draws = (("uniform", 0),)
    with pytest.raises(ValueError, match="a positive count, got \\('uniform', 0\\)"):
        TumbleEnv(Lopsided())
