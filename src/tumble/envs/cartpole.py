"""``tumble/CartPole``: keep a pole upright on a cart by pushing it left or right (Gymnasium's ``CartPole-v1``).

Physics, side by side with Gymnasium's closed-form equations (Barto, Sutton & Anderson 1983; Florian 2007):

=====================  ===========================================  ===========================================
                       tumble/CartPole                              CartPole-v1
=====================  ===========================================  ===========================================
model                  an articulation: a 1 kg cart on a prismatic  the same bodies as two coupled ODEs
                       joint along x, a uniform 0.1 kg rod 1 m long
                       on a hinge about y (inertia m L²/12 about
                       its centre)
gravity                9.8 m/s²                                     9.8 m/s²
action                 Discrete(2): 0 pushes the cart with -10 N,   the same
                       1 with +10 N
step                   0.02 s, one semi-implicit Euler step         0.02 s, one explicit Euler step
                       (bounded energy error)                       (energy grows)
observation            (x, ẋ, θ, θ̇), θ from upright, positive      the same
                       towards +x
start                  each of the four uniform in ±0.05            the same
reward                 +1 every step, the last included             the same
termination            |x| > 2.4 m or |θ| > 12°                     the same
truncation             500 steps                                    500 steps
=====================  ===========================================  ===========================================
"""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces

from ..articulation import Articulation, Prismatic, Revolute
from ..mass import MassProperties
from .canvas import Canvas
from .core import Task, uniform

__all__ = ["CartPoleTask"]

CART_MASS, POLE_MASS, POLE_LENGTH, FORCE = 1.0, 0.1, 1.0, 10.0
X_LIMIT, ANGLE_LIMIT = 2.4, 12.0 * 2.0 * math.pi / 360.0
PUSHES = np.array([-FORCE, FORCE])  # the force on the cart [N] of actions 0 and 1
LIMITS = np.array([X_LIMIT, ANGLE_LIMIT])  # of (x, θ): beyond either the episode ends


class CartPoleTask(Task):
    dt, substeps, integrator = 0.02, 1, "symplectic"
    max_episode_steps = 500
    render_fps = 50

    def __init__(self) -> None:
        high = np.array([2 * X_LIMIT, np.finfo(np.float32).max, 2 * ANGLE_LIMIT, np.finfo(np.float32).max],
                        dtype=np.float32)  # fmt: skip
        self.observation_space = spaces.Box(-high, high, dtype=np.float32)
        self.action_space = spaces.Discrete(2)

    def articulation(self) -> Articulation:
        art = Articulation(gravity=(0.0, 0.0, -9.8), name="cart-pole")
        cart = art.add_link(Prismatic((1.0, 0.0, 0.0)), mass=CART_MASS, name="cart")
        rod = POLE_MASS * POLE_LENGTH**2 / 12.0  # a thin uniform rod about its centre
        pole = MassProperties(POLE_MASS, (0.0, 0.0, POLE_LENGTH / 2), np.diag([rod, rod, 0.0]))
        art.add_link(Revolute((0.0, 1.0, 0.0)), parent=cart, mass_properties=pole, name="pole")
        return art

    start_draws = (("uniform", 4),)  # (x, ẋ, θ, θ̇)

    def start(self, draws):
        start = uniform(draws, -0.05, 0.05)
        return start[:, 0::2], start[:, 1::2]

    def prepare(self, actions, q, qd, tau):
        pushes = np.asarray(actions).reshape(-1)
        try:  # as unsigned integers, anything but 0 and 1 is out of PUSHES' range (-1 too)
            if pushes.dtype.kind not in "iub":
                raise IndexError
            tau[:, 0] = PUSHES[pushes.astype(np.uintp)]
        except IndexError:
            raise ValueError(f"actions must be 0 (push left) or 1 (push right), got {actions!r}") from None
        return pushes

    def observe(self, q, qd, links=None, tau=None):
        observations = np.empty((q.shape[0], 4), dtype=np.float32)
        observations[:, 0::2], observations[:, 1::2] = q, qd
        return observations

    def reward(self, q0, qd0, actions, q, qd, terminated):
        return np.ones(q.shape[0])

    def terminated(self, q, qd):
        return (np.abs(q) > LIMITS).any(axis=1)

    def draw(self, q):
        canvas = Canvas(600, 400, scale=600 / (2 * X_LIMIT), centre=(0.0, 0.6))
        canvas.segment((-X_LIMIT - 0.5, 0.0), (X_LIMIT + 0.5, 0.0), 0.01, (0, 0, 0))
        x, angle = q[0], q[1]
        canvas.segment((x - 0.2, 0.0), (x + 0.2, 0.0), 0.24, (40, 40, 40))
        tip = (x + POLE_LENGTH * math.sin(angle), POLE_LENGTH * math.cos(angle))
        canvas.segment((x, 0.0), tip, 0.08, (202, 152, 101))
        canvas.disc((x, 0.0), 0.03, (129, 132, 203))
        return canvas.image
