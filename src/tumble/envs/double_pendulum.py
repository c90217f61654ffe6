"""``tumble/DoublePendulum``: balance two poles stacked on a cart (Gymnasium's ``InvertedDoublePendulum-v5``).

The robot is the one of Gymnasium's ``inverted_double_pendulum.xml``, built from the same geometry:

=====================  ===========================================  ===========================================
                       tumble/DoublePendulum                        InvertedDoublePendulum-v5 (MuJoCo)
=====================  ===========================================  ===========================================
model                  an articulation: a capsule cart (radius      the same bodies, masses and inertias from
                       0.1 m, 0.2 m long, along x) on a slider      the same geoms (density 1000 kg/m³)
                       along x; two capsule poles (radius 0.045 m,
                       0.6 m) on hinges about y; density 1000
                       kg/m³ (cart 10.5 kg, poles 4.2 kg); damping
                       0.05 on every joint
rail                   unbounded                                    stops at x = ±1 m
gravity                (1e-5, 0, -9.81) m/s² (the tilt breaks the   the same
                       symmetry of the upright pose)
action                 a in [-1, 1] (clipped), force 500 a N on     the same (a motor of gear 500)
                       the cart
step                   0.05 s: five RK4 steps of 0.01 s             the same
observation (8)        x, sin θ₁, sin θ₂, cos θ₁, cos θ₂, and the   the same, and a 9th: the rail stops'
                       three velocities clipped to ±10              force
start                  coordinates uniform in ±0.1, velocities      the same
                       0.1 × standard normal
reward                 10 (while alive) - (0.01 x_t² + (y_t - 2)²)  the same
                       - (1e-3 θ̇₁² + 5e-3 θ̇₂²), (x_t, y_t) the
                       tip of the upper pole
termination            y_t <= 1 m                                   the same
truncation             1000 steps                                   1000 steps
=====================  ===========================================  ===========================================

The rail's stops are the one difference: an articulation has no joint limits, so the cart runs on past ±1 m
(a balancing policy keeps it near the middle) and there is no stop force to observe.
"""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces

from .. import elementary, portable
from ..articulation import Articulation, Prismatic, Revolute
from ..shapes import Capsule
from .canvas import Canvas
from .core import Task, uniform

__all__ = ["DoublePendulumTask"]

POLE, DENSITY, DAMPING, GEAR = 0.6, 1000.0, 0.05, 500.0
ALONG_X = (elementary.cos(math.pi / 4), 0.0, elementary.sin(math.pi / 4), 0.0)  # the capsule's z axis turned onto x


class DoublePendulumTask(Task):
    dt, substeps, integrator = 0.05, 5, "rk4"
    max_episode_steps = 1000
    render_fps = 20

    def __init__(self) -> None:
        inf = np.finfo(np.float32).max
        self.observation_space = spaces.Box(-inf, inf, shape=(8,), dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)

    def articulation(self) -> Articulation:
        art = Articulation(gravity=(1e-5, 0.0, -9.81), name="double pendulum on a cart")
        cart = art.add_link(Prismatic((1.0, 0.0, 0.0)), shape=Capsule(0.1, 0.2), density=DENSITY,
                            shape_orientation=ALONG_X, damping=DAMPING, name="cart")  # fmt: skip
        pole = Capsule(0.045, POLE)
        lower = art.add_link(Revolute((0.0, 1.0, 0.0)), parent=cart, shape=pole, density=DENSITY,
                             shape_position=(0.0, 0.0, POLE / 2), damping=DAMPING, name="pole")  # fmt: skip
        art.add_link(Revolute((0.0, 1.0, 0.0)), parent=lower, position=(0.0, 0.0, POLE), shape=pole, density=DENSITY,
                     shape_position=(0.0, 0.0, POLE / 2), damping=DAMPING, name="pole2")  # fmt: skip
        return art

    start_draws = (("uniform", 3), ("normal", 3))

    def start(self, draws):
        return uniform(draws[:, :3], -0.1, 0.1), 0.1 * draws[:, 3:]

    def prepare(self, actions, q, qd, tau):
        pushes = np.clip(np.asarray(actions, dtype=np.float64).reshape(q.shape[0], 1)[:, 0], -1.0, 1.0)
        tau[:, 0] = GEAR * pushes
        return pushes

    def observe(self, q, qd, links=None, tau=None):
        angles = q[:, 1:]
        return np.concatenate([q[:, :1], portable.sin(angles), portable.cos(angles), np.clip(qd, -10.0, 10.0)],
                              axis=1).astype(np.float32)  # fmt: skip

    @staticmethod
    def tip(q):
        """(x, y) of the upper pole's tip (copies,) each [m]."""
        first, second = q[:, 1], q[:, 1] + q[:, 2]
        return (
            q[:, 0] + POLE * (portable.sin(first) + portable.sin(second)),
            POLE * (portable.cos(first) + portable.cos(second)),
        )

    def outcome(self, start, actions, q, qd, links):
        x, y = self.tip(q)  # once for both
        terminated = y <= 1.0
        return _reward(x, y, qd, terminated), terminated, {}

    def reward(self, q0, qd0, actions, q, qd, terminated):
        return _reward(*self.tip(q), qd, terminated)

    def terminated(self, q, qd):
        return self.tip(q)[1] <= 1.0

    def draw(self, q):
        canvas = Canvas(600, 400, scale=400 / 1.6, centre=(q[0], 0.55))
        canvas.segment((q[0] - 3.0, 0.0), (q[0] + 3.0, 0.0), 0.02, (77, 77, 179))
        for mark in np.arange(math.floor(q[0] - 3.0), q[0] + 3.0):  # ticks every metre show the cart's motion
            canvas.segment((mark, -0.05), (mark, 0.05), 0.01, (77, 77, 179))
        canvas.segment((q[0] - 0.1, 0.0), (q[0] + 0.1, 0.0), 0.2, (179, 179, 0))
        elbow = (q[0] + POLE * elementary.sin(q[1]), POLE * elementary.cos(q[1]))
        tip = (elbow[0] + POLE * elementary.sin(q[1] + q[2]), elbow[1] + POLE * elementary.cos(q[1] + q[2]))
        canvas.segment((q[0], 0.0), elbow, 0.09, (0, 179, 179))
        canvas.segment(elbow, tip, 0.09, (0, 179, 179))
        return canvas.image


def _reward(x, y, qd, terminated):
    """10 while alive, less the tip's distance from (0, 2) and the poles' speeds (InvertedDoublePendulum-v5's)."""
    alive = np.where(terminated, 0.0, 10.0)
    return alive - (0.01 * x**2 + (y - 2.0) ** 2) - (1e-3 * qd[:, 1] ** 2 + 5e-3 * qd[:, 2] ** 2)
