"""Gymnasium environments on tumble's articulations (extra ``rl``: ``pip install 'tumble[rl]'``): ``tumble/CartPole``,
``tumble/Pendulum``, ``tumble/DoublePendulum``, ``tumble/QuadrotorHover``, and Gymnasium's MuJoCo locomotion tasks
(v5) from the same MJCF files: ``tumble/Hopper``, ``tumble/Walker2d``, ``tumble/HalfCheetah``, ``tumble/Ant`` and
``tumble/Humanoid``.

>>> import gymnasium as gym
>>> import tumble.envs  # registers the environments
>>> env = gym.make("tumble/CartPole")
>>> observation, info = env.reset(seed=0)
>>> envs = gym.make_vec("tumble/CartPole", num_envs=64, vectorization_mode="vector_entry_point")
>>> observations, infos = envs.reset(seed=0)
>>> observations.shape
(64, 4)

Each environment's physics and reward are documented beside its Gymnasium (or RotorPy) counterpart in its module
and in ``docs/envs.md``. The vector versions step every copy in one compiled call (:class:`TumbleVectorEnv`); copy
``i`` of ``reset(seed=s)`` is the single env seeded ``s + i``, bit for bit. ``gym.make("tumble/Hopper",
ctrl_cost_weight=...)`` passes Gymnasium's v5 arguments to the task.
"""

from __future__ import annotations

try:
    import gymnasium as gym
except ImportError as error:  # pragma: no cover - the extra is missing
    raise ImportError("tumble.envs needs Gymnasium 1.0 or later: pip install 'tumble[rl]'") from error

from .cartpole import CartPoleTask
from .core import Task, TumbleEnv, TumbleVectorEnv
from .double_pendulum import DoublePendulumTask
from .locomotion import AntTask, HalfCheetahTask, HopperTask, HumanoidTask, Walker2dTask
from .pendulum import PendulumTask
from .quadrotor import QuadrotorHoverTask

__all__ = ["TASKS", "Task", "TumbleEnv", "TumbleVectorEnv", "make_env", "make_vector_env"]

TASKS = {
    "CartPole": CartPoleTask,
    "Pendulum": PendulumTask,
    "DoublePendulum": DoublePendulumTask,
    "QuadrotorHover": QuadrotorHoverTask,
    "Hopper": HopperTask,
    "Walker2d": Walker2dTask,
    "HalfCheetah": HalfCheetahTask,
    "Ant": AntTask,
    "Humanoid": HumanoidTask,
}


def make_env(task: str, render_mode=None, **task_arguments) -> TumbleEnv:
    """The single environment of ``task`` (a key of :data:`TASKS`), without Gymnasium's wrappers;
    ``task_arguments`` go to the task (the locomotion tasks take Gymnasium's v5 constructor arguments)."""
    return TumbleEnv(_task(task, task_arguments), render_mode=render_mode)


def make_vector_env(task: str, num_envs: int, max_episode_steps=None, render_mode=None,
                    **task_arguments) -> TumbleVectorEnv:  # fmt: skip
    """``num_envs`` copies of ``task`` as one vector environment."""
    return TumbleVectorEnv(_task(task, task_arguments), num_envs, max_episode_steps=max_episode_steps,
                           render_mode=render_mode)  # fmt: skip


def _task(task: str, arguments: dict):
    if task not in TASKS:
        raise ValueError(f"task must be one of {tuple(TASKS)}, got {task!r}")
    return TASKS[task](**arguments)


def _register() -> None:
    for name, task in TASKS.items():
        env_id = f"tumble/{name}"
        if env_id in gym.registry:
            continue
        gym.register(id=env_id, entry_point=f"tumble.envs:_{name}_env", vector_entry_point=f"tumble.envs:_{name}_vec",
                     max_episode_steps=task.max_episode_steps)  # fmt: skip


def _entry_points(name: str):
    def single(render_mode=None, **task_arguments):
        return make_env(name, render_mode=render_mode, **task_arguments)

    def vector(num_envs=1, max_episode_steps=None, render_mode=None, **task_arguments):
        return make_vector_env(name, num_envs, max_episode_steps=max_episode_steps, render_mode=render_mode,
                               **task_arguments)  # fmt: skip

    return single, vector


for _name in TASKS:
    globals()[f"_{_name}_env"], globals()[f"_{_name}_vec"] = _entry_points(_name)
_register()
