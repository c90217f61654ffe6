"""``tumble/Pendulum``: swing a pendulum up and hold it upright with a weak motor (Gymnasium's ``Pendulum-v1``).

=====================  ===========================================  ===========================================
                       tumble/Pendulum                              Pendulum-v1
=====================  ===========================================  ===========================================
model                  an articulation: a uniform 1 kg rod 1 m      θ̈ = 3g/(2l) sin θ + 3u/(ml²): the same rod
                       long on a hinge at one end                   as a closed-form ODE
gravity                10 m/s²                                      10 m/s²
action                 torque u in [-2, 2] N m (clipped)            the same
step                   0.05 s, one RK4 step                         0.05 s, one semi-implicit Euler step, then
                                                                    θ̇ clipped to ±8 rad/s
observation            (cos θ, sin θ, θ̇), θ from upright           the same (θ̇ within ±8)
start                  θ uniform in ±π, θ̇ uniform in ±1           the same
reward                 -(θ² + 0.1 θ̇² + 0.001 u²), θ wrapped to     the same
                       [-π, π), at the state before the step
termination            none                                         none
truncation             200 steps                                    200 steps
=====================  ===========================================  ===========================================

tumble does not clip the speed (a motor does not stop a pendulum): θ̇ is unbounded in the observation space.
"""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces

from .. import portable
from ..articulation import Articulation, Revolute
from ..mass import MassProperties
from .canvas import Canvas
from .core import Task, uniform

__all__ = ["PendulumTask"]

MASS, LENGTH, GRAVITY, MAX_TORQUE = 1.0, 1.0, 10.0, 2.0


class PendulumTask(Task):
    dt, substeps, integrator = 0.05, 1, "rk4"
    max_episode_steps = 200
    reward_reads_start = True  # Gymnasium's cost is that of the state before the step
    render_fps = 20

    def __init__(self) -> None:
        inf = np.finfo(np.float32).max
        self.observation_space = spaces.Box(np.array([-1.0, -1.0, -inf], dtype=np.float32),
                                            np.array([1.0, 1.0, inf], dtype=np.float32), dtype=np.float32)  # fmt: skip
        self.action_space = spaces.Box(-MAX_TORQUE, MAX_TORQUE, shape=(1,), dtype=np.float32)

    def articulation(self) -> Articulation:
        art = Articulation(gravity=(0.0, 0.0, -GRAVITY), name="pendulum")
        rod = MASS * LENGTH**2 / 12.0
        mass = MassProperties(MASS, (0.0, 0.0, LENGTH / 2), np.diag([rod, rod, 0.0]))
        art.add_link(Revolute((0.0, 1.0, 0.0)), mass_properties=mass, name="rod")
        return art

    start_draws = (("uniform", 2),)  # (θ, θ̇)

    def start(self, draws):
        start = uniform(draws, (-math.pi, -1.0), (math.pi, 1.0))
        return start[:, :1], start[:, 1:]

    def prepare(self, actions, q, qd, tau):
        torques = np.clip(np.asarray(actions, dtype=np.float64).reshape(q.shape[0], 1), -MAX_TORQUE, MAX_TORQUE)
        tau[:, 0] = torques[:, 0]
        return torques[:, 0]

    def observe(self, q, qd, links=None, tau=None):
        return np.stack([portable.cos(q[:, 0]), portable.sin(q[:, 0]), qd[:, 0]], axis=1).astype(np.float32)

    def reward(self, q0, qd0, actions, q, qd, terminated):
        angle = (q0[:, 0] + math.pi) % (2 * math.pi) - math.pi
        return -(angle**2 + 0.1 * qd0[:, 0] ** 2 + 0.001 * actions**2)

    def draw(self, q):
        canvas = Canvas(500, 500, scale=500 / 2.4)
        tip = (LENGTH * math.sin(q[0]), LENGTH * math.cos(q[0]))
        canvas.segment((0.0, 0.0), tip, 0.2, (204, 77, 77))
        canvas.disc((0.0, 0.0), 0.05, (0, 0, 0))
        return canvas.image
