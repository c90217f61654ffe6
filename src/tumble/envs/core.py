"""The machinery every tumble environment shares: a :class:`Task` (what the robot is and what it is asked to do)
run by :class:`TumbleEnv` (one copy, Gymnasium's ``Env``) or :class:`TumbleVectorEnv` (``n`` copies,
Gymnasium's ``VectorEnv``).

Both step an :class:`~tumble.articulation.ArticulationBatch` (of one copy, or of ``n``) through the same code: the
task turns actions into joint forces, observations, rewards and terminations with array operations over the copy
axis, and the batch takes the physics steps of one control step in one compiled call. So a copy of a vector env is
bit for bit the single env with the same seed and actions.

Seeds: ``reset(seed=s)`` seeds the environment's one generator (``gymnasium.utils.seeding.np_random(s)``), from which
a vector env draws the starts of all the copies it resets at once (as Gymnasium's own vector ``CartPole`` does):
the same seed gives the same episodes. Autoreset is Gymnasium 1.x's default,
``AutoresetMode.NEXT_STEP``: the step after a copy's episode ends resets that copy and returns its first
observation with reward 0, ignoring its action.
"""

from __future__ import annotations

import numbers

import gymnasium as gym
import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .._validate import as_array
from ..articulation import Articulation, ArticulationBatch
from ..articulation.articulation import INTEGRATORS

__all__ = ["Task", "TumbleEnv", "TumbleVectorEnv"]

RENDER_MODES = ("rgb_array",)


class Task:
    """One environment's physics, spaces and rules; array methods take a leading copy axis.

    Subclasses set ``dt`` (the control step [s]), ``substeps`` and ``integrator`` (the physics steps of one control
    step), ``max_episode_steps``, ``render_fps``, ``observation_space`` and ``action_space`` (one copy's), and
    implement the methods below.
    """

    dt: float
    substeps: int
    integrator: str
    max_episode_steps: int
    reward_reads_start = False  # whether reward() reads the state before the step (else it gets None)
    observation_space: gym.Space
    action_space: gym.Space

    def articulation(self) -> Articulation:
        """The robot, built fresh."""
        raise NotImplementedError

    def initial_state(self, rng: np.random.Generator, count: int) -> tuple[np.ndarray, np.ndarray]:
        """``(q, qd)``, (count, nq) and (count, nv), of ``count`` copies starting an episode, drawn from ``rng`` copy
        after copy (row 0's numbers first)."""
        raise NotImplementedError

    def prepare(self, actions: np.ndarray, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Write the joint forces of ``actions`` (copies, ...) into ``tau`` (copies, nv); return the actions as they
        act (clipped to the action space), which :meth:`reward` receives."""
        raise NotImplementedError

    def observe(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """(copies, observation size) float32."""
        raise NotImplementedError

    def reward(self, q0, qd0, actions, q, qd, terminated) -> np.ndarray:
        """(copies,) the reward of a step from ``(q0, qd0)`` (``None`` unless ``reward_reads_start``) to ``(q, qd)``
        under ``actions`` (as they acted)."""
        raise NotImplementedError

    def terminated(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """(copies,) bool: the episode ended (fell, left the arena)."""
        return np.zeros(q.shape[0], dtype=bool)

    def draw(self, q: np.ndarray) -> np.ndarray:
        """One copy's picture at the coordinates ``q`` (nq,): an (height, width, 3) uint8 image."""
        raise NotImplementedError


def _check_render_mode(render_mode) -> str | None:
    if render_mode is not None and render_mode not in RENDER_MODES:
        raise ValueError(f"render_mode must be None or one of {RENDER_MODES}, got {render_mode!r}")
    return render_mode


def _check_episode_steps(max_episode_steps, default: int) -> int:
    if max_episode_steps is None:
        return default
    if isinstance(max_episode_steps, bool) or not isinstance(max_episode_steps, numbers.Integral):
        raise TypeError(f"max_episode_steps must be a positive integer, got {max_episode_steps!r}")
    if max_episode_steps < 1:
        raise ValueError(f"max_episode_steps must be a positive integer, got {max_episode_steps!r}")
    return int(max_episode_steps)


class _Copies:
    """The copies' physics and episode clocks: what the single and the vector env share."""

    def __init__(self, task: Task, n: int) -> None:
        self.task = task
        self.batch = ArticulationBatch(task.articulation(), n)
        self.rng: np.random.Generator | None = None
        self.elapsed = np.zeros(n, dtype=np.int64)
        self._method = INTEGRATORS[task.integrator]
        self._h = task.dt / task.substeps

    def reset(self, which: np.ndarray) -> None:
        """Start new episodes in copies ``which`` (indices), drawn from the generator."""
        q, qd = self.task.initial_state(self.rng, len(which))
        self.batch.q[which], self.batch.qd[which] = q, qd
        self.elapsed[which] = 0

    def set_state(self, which, q, qd) -> None:
        """Put copies ``which`` (an index, or a slice of all) at ``(q, qd)``: validated, quaternions renormalised,
        nothing changed if refused."""
        batch = self.batch
        shape = () if isinstance(which, int) else (batch.n,)
        q = as_array("q", q, (*shape, batch.nq), batch=False)
        qd = as_array("qd", qd, (*shape, batch.nv), batch=False)
        new_q, new_qd = batch.q.copy(), batch.qd.copy()
        new_q[which], new_qd[which] = q, qd
        batch.q = new_q
        batch.qd = new_qd

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """One control step of every copy: ``(observations, rewards, terminated, elapsed steps)``."""
        task, batch = self.task, self.batch
        q0, qd0 = (batch.q.copy(), batch.qd.copy()) if task.reward_reads_start else (None, None)
        acting = task.prepare(actions, batch.q, batch.qd, batch.tau)
        batch._advance(self._h, task.substeps, self._method)
        self.elapsed += 1
        terminated = task.terminated(batch.q, batch.qd)
        rewards = task.reward(q0, qd0, acting, batch.q, batch.qd, terminated)
        return task.observe(batch.q, batch.qd), rewards, terminated, self.elapsed


class TumbleEnv(gym.Env):
    """One copy of a :class:`Task` as a Gymnasium environment (``gymnasium.make("tumble/...")`` wraps it in the
    time limit of the registration)."""

    def __init__(self, task: Task, render_mode=None) -> None:
        self.task = task
        self.render_mode = _check_render_mode(render_mode)
        self.metadata = {"render_modes": list(RENDER_MODES), "render_fps": task.render_fps}
        self.observation_space = task.observation_space
        self.action_space = task.action_space
        self._copies = _Copies(task, 1)

    @property
    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """``(q, qd)`` of the robot (copies): the articulation's coordinates, ``task.articulation()``'s layout."""
        return self._copies.batch.q[0].copy(), self._copies.batch.qd[0].copy()

    def set_state(self, q, qd) -> None:
        """Put the robot at ``(q, qd)`` (nq,), (nv,) mid-episode (as MuJoCo environments' ``set_state``)."""
        self._copies.set_state(0, q, qd)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self._copies.rng = self.np_random
        self._copies.reset(np.zeros(1, dtype=np.int64))
        batch = self._copies.batch
        return self.task.observe(batch.q, batch.qd)[0], {}

    def step(self, action):
        actions = np.asarray(action)[None]
        observations, rewards, terminated, _ = self._copies.step(actions)
        return observations[0], float(rewards[0]), bool(terminated[0]), False, {}

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode: make the environment with render_mode='rgb_array'")
            return None
        return self.task.draw(self._copies.batch.q[0])


class TumbleVectorEnv(VectorEnv):
    """``num_envs`` copies of a :class:`Task` stepped together: a native Gymnasium ``VectorEnv``.

    ``gymnasium.make_vec("tumble/...", num_envs=N, vectorization_mode="vector_entry_point")`` returns one. It
    truncates episodes at ``max_episode_steps`` itself (the registration's by default) and autoresets as
    Gymnasium 1.x does by default (``AutoresetMode.NEXT_STEP``). ``reset(options={"reset_mask": mask})`` resets only
    the copies where ``mask`` is true.
    """

    def __init__(self, task: Task, num_envs: int, max_episode_steps=None, render_mode=None) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, numbers.Integral) or num_envs < 1:
            raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")
        self.task = task
        self.num_envs = int(num_envs)
        self.max_episode_steps = _check_episode_steps(max_episode_steps, task.max_episode_steps)
        self.render_mode = _check_render_mode(render_mode)
        self.metadata = {"render_modes": list(RENDER_MODES), "render_fps": task.render_fps,
                         "autoreset_mode": AutoresetMode.NEXT_STEP}  # fmt: skip
        self.single_observation_space = task.observation_space
        self.single_action_space = task.action_space
        self.observation_space = batch_space(task.observation_space, self.num_envs)
        self.action_space = batch_space(task.action_space, self.num_envs)
        self._copies = _Copies(task, self.num_envs)
        self._autoreset = np.zeros(self.num_envs, dtype=bool)

    @property
    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """``(q, qd)`` of every copy, ``(num_envs, nq)`` and ``(num_envs, nv)`` (copies)."""
        return self._copies.batch.q.copy(), self._copies.batch.qd.copy()

    def set_state(self, q, qd) -> None:
        """Put every copy at its row of ``q`` (num_envs, nq) and ``qd`` (num_envs, nv) mid-episode."""
        self._copies.set_state(slice(None), q, qd)

    def reset(self, *, seed=None, options=None):
        which = np.arange(self.num_envs)
        if options is not None and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"])
            if mask.dtype != np.bool_ or mask.shape != (self.num_envs,):
                raise ValueError(f"options['reset_mask'] must be a bool array of shape ({self.num_envs},), "
                                 f"got {mask.dtype} {mask.shape}")  # fmt: skip
            which = np.flatnonzero(mask)
        if seed is not None or self._copies.rng is None:
            if isinstance(seed, bool) or not (seed is None or isinstance(seed, numbers.Integral)):
                raise TypeError(f"seed must be None or an int, got {seed!r}")
            self._copies.rng, _ = seeding.np_random(None if seed is None else int(seed))
        self._copies.reset(which)
        self._autoreset[which] = False
        batch = self._copies.batch
        return self.task.observe(batch.q, batch.qd), {}

    def step(self, actions):
        if self._copies.rng is None:
            raise RuntimeError("call reset() before step()")
        actions = np.asarray(actions)
        if actions.ndim == 0 or actions.shape[0] != self.num_envs:
            raise ValueError(f"actions must have {self.num_envs} rows (one per copy), got shape {actions.shape}")
        restarting = np.flatnonzero(self._autoreset)
        observations, rewards, terminated, elapsed = self._copies.step(actions)
        truncated = elapsed >= self.max_episode_steps
        if len(restarting):
            self._copies.reset(restarting)
            batch = self._copies.batch
            observations[restarting] = self.task.observe(batch.q[restarting], batch.qd[restarting])
            rewards[restarting] = 0.0
            terminated[restarting] = False
            truncated[restarting] = False
        self._autoreset = terminated | truncated
        return observations, rewards, terminated, truncated, {}

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode: make the environment with render_mode='rgb_array'")
            return None
        return tuple(self.task.draw(q) for q in self._copies.batch.q)
