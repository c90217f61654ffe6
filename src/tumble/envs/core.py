"""The machinery every tumble environment shares: a :class:`Task` (what the robot is and what it is asked to do)
run by :class:`TumbleEnv` (one copy, Gymnasium's ``Env``) or :class:`TumbleVectorEnv` (``n`` copies,
Gymnasium's ``VectorEnv``).

Both step an :class:`~tumble.articulation.ArticulationBatch` (of one copy, or of ``n``) through the same code: the
task turns actions into joint forces, observations, rewards and terminations with array operations over the copy
axis, and the batch takes the physics steps of one control step in one compiled call. So a copy of a vector env is
bit for bit the single env with the same seed and actions.

Seeds follow Gymnasium's ``SyncVectorEnv``: each copy has its own generator, and ``reset(seed=s)`` seeds copy ``i``
as a single env seeded ``s + i`` (``gymnasium.utils.seeding.np_random(s + i)``), ``reset(seed=[s0, s1, ...])`` copy
``i`` with ``si``; a copy's later starts come from its generator. So every copy equals the single env with its seed,
bit for bit. Autoreset is Gymnasium 1.x's default,
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
from ..articulation.kernels import READOUT_WIDTH

__all__ = ["Task", "TumbleEnv", "TumbleVectorEnv", "uniform"]

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
    reads_links = False  # whether observe() and outcome() read the links' readout (else they get None)
    observation_space: gym.Space
    action_space: gym.Space
    # A copy's start as the standard draws it takes from its own generator, in order: ("uniform", n) takes n
    # uniforms in [0, 1), ("normal", n) n standard normals. They are drawn a copy at a time (each copy has its own
    # generator: one short call an entry), and start() maps the draws of every restarting copy at once.
    start_draws: tuple[tuple[str, int], ...] = ()

    def articulation(self) -> Articulation:
        """The robot, built fresh."""
        raise NotImplementedError

    def start(self, draws: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(q, qd)``, (copies, nq) and (copies, nv), of copies starting an episode: their :attr:`start_draws`
        (copies, total count), mapped all at once (see :func:`uniform`)."""
        raise NotImplementedError

    def prepare(self, actions: np.ndarray, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Write the joint forces of ``actions`` (copies, ...) into ``tau`` (copies, nv); return the actions as they
        act (clipped to the action space), which :meth:`reward` receives."""
        raise NotImplementedError

    def observe(self, q: np.ndarray, qd: np.ndarray, links=None, tau=None) -> np.ndarray:
        """(copies, observation size) in the observation space's dtype. ``links``: (copies, links,
        ``READOUT_WIDTH``) the links' inertia, velocity and contact wrench at ``(q, qd)`` if ``reads_links``;
        ``tau``: (copies, nv) the joint forces of the step that reached it (zero at a start)."""
        raise NotImplementedError

    def reward(self, q0, qd0, actions, q, qd, terminated) -> np.ndarray:
        """(copies,) the reward of a step from ``(q0, qd0)`` (``None`` unless ``reward_reads_start``) to ``(q, qd)``
        under ``actions`` (as they acted)."""
        raise NotImplementedError

    def outcome(self, start, actions, q, qd, links) -> tuple[np.ndarray, np.ndarray, dict]:
        """``(rewards (copies,), terminated (copies,), info)`` of a step from ``start`` (``(q0, qd0, links0)``, or
        ``None`` unless ``reward_reads_start``) to ``(q, qd, links)``; ``info`` maps each key to (copies, ...)
        values. By default :meth:`terminated`, :meth:`reward`'s rewards and no info."""
        q0, qd0 = (None, None) if start is None else start[:2]
        terminated = self.terminated(q, qd)
        return self.reward(q0, qd0, actions, q, qd, terminated), terminated, {}

    def reset_info(self, q: np.ndarray, qd: np.ndarray, links=None) -> dict:
        """``info`` of copies starting an episode at ``(q, qd)``: key to (copies, ...) values (none by default)."""
        return {}

    def terminated(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """(copies,) bool: the episode ended (fell, left the arena)."""
        return np.zeros(q.shape[0], dtype=bool)

    def draw(self, q: np.ndarray) -> np.ndarray:
        """One copy's picture at the coordinates ``q`` (nq,): an (height, width, 3) uint8 image."""
        raise NotImplementedError


def uniform(unit: np.ndarray, low, high) -> np.ndarray:
    """Uniform draws in ``[low, high)`` from standard ones ``unit`` in [0, 1): ``low + (high - low) unit``, the
    arithmetic of NumPy's ``Generator.uniform`` (``random_uniform`` in numpy/random/src/distributions), so a
    start equals ``rng.uniform(low, high)`` of the same generator bit for bit."""
    low, high = np.asarray(low, dtype=np.float64), np.asarray(high, dtype=np.float64)
    return low + (high - low) * unit


_DRAWS = {"uniform": "random", "normal": "standard_normal"}  # a start draw's kind: its Generator method


def _draw_plan(task: Task) -> tuple[list[tuple[str, int, int]], int]:
    """``([(Generator method, first column, end column)], total columns)`` of the task's ``start_draws``."""
    plan, total = [], 0
    for entry in task.start_draws:
        kind, count = entry if isinstance(entry, tuple) and len(entry) == 2 else (None, None)
        if kind not in _DRAWS or isinstance(count, bool) or not isinstance(count, numbers.Integral) or count < 1:
            raise ValueError(f"{type(task).__name__}.start_draws entries must be (kind, count) with kind in "
                             f"{sorted(_DRAWS)} and a positive count, got {entry!r}")  # fmt: skip
        plan.append((_DRAWS[kind], total, total + int(count)))
        total += int(count)
    return plan, total


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
    """The copies' physics, generators and episode clocks: what the single and the vector env share."""

    def __init__(self, task: Task, n: int) -> None:
        self.task = task
        articulation = task.articulation()
        self.batch = ArticulationBatch(articulation, n)
        self.rngs: list[np.random.Generator | None] = [None] * n
        self._unseeded = n
        self.elapsed = np.zeros(n, dtype=np.int64)
        self.links = np.zeros((n, len(articulation.links), READOUT_WIDTH)) if task.reads_links else None
        self._method = INTEGRATORS[task.integrator]
        self._h = task.dt / task.substeps
        self._draws, draw_count = _draw_plan(task)
        self._start_draws = np.zeros((n, draw_count))  # each copy's row: its latest start's draws
        self._fills: list[tuple] = [()] * n  # each copy's (generator method, its slice of the row) in draw order

    @property
    def seeded(self) -> bool:
        return self._unseeded == 0

    def seed(self, which: np.ndarray, seeds) -> None:
        """New generators for copies ``which`` (indices) from ``seeds`` (an int or None each)."""
        for i, seed in zip(which, seeds, strict=True):
            self.use_generator(i, seeding.np_random(seed)[0])

    def use_generator(self, i: int, rng: np.random.Generator) -> None:
        """Copy ``i`` draws from ``rng`` from now on."""
        self._unseeded -= self.rngs[i] is None
        self.rngs[i] = rng
        row = self._start_draws[i]
        self._fills[i] = tuple((getattr(rng, method), row[first:end]) for method, first, end in self._draws)

    def reset(self, which: np.ndarray) -> None:
        """Start new episodes in copies ``which`` (int64 indices), each drawn from its own generator; their joint
        forces are zero until the next step, and their links are read at the start if the task reads them."""
        batch, fills = self.batch, self._fills
        if len(which):
            for i in which.tolist():  # a copy at a time: each draws from its own generator
                for fill, row in fills[i]:
                    fill(out=row)
            batch.q[which], batch.qd[which] = self.task.start(self._start_draws[which])
        batch.tau[which] = 0.0
        self.elapsed[which] = 0
        if self.links is not None:
            batch._advance(self._h, 0, self._method, copies=which, readout=self.links)

    def observe(self, which=slice(None)) -> np.ndarray:
        batch = self.batch
        links = None if self.links is None else self.links[which]
        return self.task.observe(batch.q[which], batch.qd[which], links, batch.tau[which])

    def reset_info(self, which) -> dict:
        batch = self.batch
        links = None if self.links is None else self.links[which]
        return self.task.reset_info(batch.q[which], batch.qd[which], links)

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
        if self.links is not None:
            copies = np.arange(batch.n, dtype=np.int64)[which]
            batch._advance(self._h, 0, self._method, copies=np.atleast_1d(copies), readout=self.links)

    def step(self, actions: np.ndarray, moving=None):
        """One control step: ``(observations, rewards, terminated, elapsed steps, info)`` of every copy, of which only
        ``moving`` (int64 indices; all by default) take the physics steps (the others restart after it)."""
        task, batch = self.task, self.batch
        start = None
        if task.reward_reads_start:
            start = (batch.q.copy(), batch.qd.copy(), None if self.links is None else self.links.copy())
        acting = task.prepare(actions, batch.q, batch.qd, batch.tau)
        batch._advance(self._h, task.substeps, self._method, copies=moving, readout=self.links)
        self.elapsed += 1
        rewards, terminated, info = task.outcome(start, acting, batch.q, batch.qd, self.links)
        return self.observe(), rewards, terminated, self.elapsed, info


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
        self._copies.use_generator(0, self.np_random)  # Env.reset made it from seed, or kept the one it had
        self._copies.reset(np.zeros(1, dtype=np.int64))
        return self._copies.observe()[0], _first(self._copies.reset_info(slice(0, 1)))

    def step(self, action):
        actions = np.asarray(action)[None]
        observations, rewards, terminated, _, info = self._copies.step(actions)
        return observations[0], float(rewards[0]), bool(terminated[0]), False, _first(info)

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
        which = np.arange(self.num_envs, dtype=np.int64)
        if options is not None and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"])
            if mask.dtype != np.bool_ or mask.shape != (self.num_envs,):
                raise ValueError(f"options['reset_mask'] must be a bool array of shape ({self.num_envs},), "
                                 f"got {mask.dtype} {mask.shape}")  # fmt: skip
            which = np.flatnonzero(mask).astype(np.int64)
        seeds = self._seeds(seed)
        copies = self._copies
        unseeded = [i for i in which if copies.rngs[i] is None]
        if seed is not None:
            copies.seed(which, [seeds[i] for i in which])
        elif unseeded:
            copies.seed(unseeded, [None] * len(unseeded))
        copies.reset(which)
        self._autoreset[which] = False
        return copies.observe(), _merge_info({}, copies.reset_info(which), which, self.num_envs)

    def _seeds(self, seed) -> list:
        """One seed (or None) per copy from ``reset``'s ``seed``: ``s + i`` from an int, a list as given."""
        n = self.num_envs
        if seed is None:
            return [None] * n
        if isinstance(seed, numbers.Integral) and not isinstance(seed, bool):
            return [int(seed) + i for i in range(n)]
        if isinstance(seed, (list, tuple, np.ndarray)):
            seeds = list(seed)
            if len(seeds) != n:
                raise ValueError(f"seed must have one entry per copy ({n}), got {len(seeds)}")
            for entry in seeds:
                if entry is not None and (isinstance(entry, bool) or not isinstance(entry, numbers.Integral)):
                    raise TypeError(f"seed entries must be ints or None, got {entry!r}")
            return [None if entry is None else int(entry) for entry in seeds]
        raise TypeError(f"seed must be None, an int or a list of {n} ints, got {seed!r}")

    def step(self, actions):
        if not self._copies.seeded:
            raise RuntimeError("call reset() before step()")
        actions = np.asarray(actions)
        if actions.ndim == 0 or actions.shape[0] != self.num_envs:
            raise ValueError(f"actions must have {self.num_envs} rows (one per copy), got shape {actions.shape}")
        restarting = np.flatnonzero(self._autoreset).astype(np.int64)
        copies = self._copies
        moving = np.flatnonzero(~self._autoreset).astype(np.int64) if len(restarting) else None  # the others restart
        observations, rewards, terminated, elapsed, info = copies.step(actions, moving)
        truncated = elapsed >= self.max_episode_steps
        infos = _masked(info, ~self._autoreset)
        if len(restarting):
            copies.reset(restarting)
            observations[restarting] = copies.observe(restarting)
            rewards[restarting] = 0.0
            terminated[restarting] = False
            truncated[restarting] = False
            _merge_info(infos, copies.reset_info(restarting), restarting, self.num_envs)
        self._autoreset = terminated | truncated
        return observations, rewards, terminated, truncated, infos

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode: make the environment with render_mode='rgb_array'")
            return None
        return tuple(self.task.draw(q) for q in self._copies.batch.q)


def _first(info: dict) -> dict:
    """A single env's ``info`` from the copies' (one copy): scalars as NumPy scalars, arrays as arrays."""
    return {key: values[0] for key, values in info.items()}


def _masked(info: dict, mask: np.ndarray) -> dict:
    """Gymnasium's vector ``info`` from every copy's values (``info``, each (n, ...)), kept where ``mask`` is true:
    each key beside its mask ``_key``."""
    infos: dict = {}
    for key, values in info.items():
        infos[key] = np.where(mask.reshape(-1, *([1] * (np.ndim(values) - 1))), values, 0)
        infos[f"_{key}"] = mask.copy()
    return infos


def _merge_info(infos: dict, info: dict, which: np.ndarray, n: int) -> dict:
    """Put the values of copies ``which`` (``info``, each (len(which), ...)) into the vector ``infos`` of ``n``
    copies, their masks set; returns ``infos``."""
    for key, values in info.items():
        values = np.asarray(values)
        if key not in infos:
            infos[key] = np.zeros((n, *values.shape[1:]), dtype=values.dtype)
            infos[f"_{key}"] = np.zeros(n, dtype=bool)
        infos[key][which] = values
        infos[f"_{key}"][which] = True
    return infos
