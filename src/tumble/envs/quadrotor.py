"""``tumble/QuadrotorHover``: hold a Crazyflie quadrotor at the origin by commanding its four rotor speeds
(RotorPy's ``Quadrotor-v0`` with its hover reward).

=====================  ===========================================  ===========================================
                       tumble/QuadrotorHover                        RotorPy Quadrotor-v0, hover reward
=====================  ===========================================  ===========================================
model                  a rigid body on a free joint with the        the Crazyflie 2.0 with the same figures,
                       Crazyflie 2.0's mass, inertia, arm and       plus rotor drag, inflow and the motors'
                       rotor constants (``tumble.vehicles.          first-order lag
                       CRAZYFLIE``, "x" layout); each rotor
                       pushes k_thrust ω² along the body z axis
                       and twists spin k_moment ω² about it
action                 a in [-1, 1]⁴ (clipped): rotor speeds ω =    the same (``cmd_motor_speeds``)
                       ω_min + (a + 1)/2 (ω_max - ω_min), reached
                       at once
step                   0.01 s, one RK4 step                         0.01 s
observation (13)       position [m], velocity [m/s] (world),        the same, the quaternion as [x, y, z, w]
                       quaternion [w, x, y, z], body rates [rad/s]
start                  position and velocity uniform in ±0.5,       random position and velocity in the arena
                       a rotation vector uniform in ±0.2 rad, body
                       rates uniform in ±0.2 rad/s
reward                 1 while flying - (|p| + 0.5 |v| + 0.5 |ω|    -(|p| + 0.5 |v| + 0.5 |ω| + 1e-5 |a|)
                       + 1e-5 |a|)
termination            leaving the box |x|, |y|, |z| <= 2 m, or     leaving the arena
                       turning upside down (body z pointing down)
truncation             1000 steps (10 s)                            10 s
=====================  ===========================================  ===========================================

The alive bonus of 1 keeps an agent from ending episodes early to stop paying the cost; the rotors' lag and drag
are left out, so a policy sees the body's dynamics alone.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from ..articulation import Articulation, Free
from ..mass import MassProperties
from ..rotation import quat_from_rotvec, quat_rotate
from ..vehicles import CRAZYFLIE, Mixer, quadrotor_params, rotor_hubs
from .canvas import Canvas
from .core import Task, uniform

__all__ = ["QuadrotorHoverTask"]

BOX = 2.0


def _norm(rows: np.ndarray) -> np.ndarray:
    """The length of each row, summed column by column: the same bits whatever the number of rows (NumPy's
    ``norm(axis=1)`` may sum a row in another order when there are many)."""
    total = rows[:, 0] * rows[:, 0]
    for k in range(1, rows.shape[1]):
        total = total + rows[:, k] * rows[:, k]
    return np.sqrt(total)


def _body_z(quat: np.ndarray) -> np.ndarray:
    """(copies, 3) the body z axis in the world of unit quaternions ``[w, x, y, z]`` (copies, 4): the third column
    of the rotation matrix."""
    w, x, y, z = quat[:, 0], quat[:, 1], quat[:, 2], quat[:, 3]
    return np.stack([2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y)], axis=1)


class QuadrotorHoverTask(Task):
    dt, substeps, integrator = 0.01, 1, "rk4"
    max_episode_steps = 1000
    render_fps = 100

    def __init__(self) -> None:
        self.params = quadrotor_params(**CRAZYFLIE)
        p = self.params
        self.hubs = rotor_hubs("x", p["arm_length"])
        self.mixer = Mixer(self.hubs, p["rotor_directions"], p["k_thrust"], p["k_moment"], p["speed_min"],
                           p["speed_max"])  # fmt: skip
        inf = np.finfo(np.float32).max
        self.observation_space = spaces.Box(-inf, inf, shape=(13,), dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(4,), dtype=np.float32)

    def articulation(self) -> Articulation:
        art = Articulation(gravity=(0.0, 0.0, -9.81), name="crazyflie")
        body = MassProperties(self.params["mass"], np.zeros(3), self.params["inertia"])
        art.add_link(Free(), mass_properties=body, name="body")
        return art

    start_draws = (("uniform", 12),)  # position, rotation vector, velocity and body rates, in that order

    def start(self, draws):
        start = uniform(draws, np.repeat((-0.5, -0.2, -0.5, -0.2), 3), np.repeat((0.5, 0.2, 0.5, 0.2), 3))
        return np.concatenate([start[:, :3], quat_from_rotvec(start[:, 3:6])], axis=1), start[:, 6:]

    def rotor_speeds(self, actions) -> np.ndarray:
        """(copies, 4) [rad/s] of actions in [-1, 1] (clipped)."""
        low, high = self.params["speed_min"], self.params["speed_max"]
        return low + 0.5 * (np.clip(actions, -1.0, 1.0) + 1.0) * (high - low)

    def prepare(self, actions, q, qd, tau):
        actions = np.clip(np.asarray(actions, dtype=np.float64).reshape(q.shape[0], 4), -1.0, 1.0)
        squared = self.rotor_speeds(actions) ** 2
        # (T, Mx, My, Mz) of each copy, summed rotor by rotor: a matrix product's summation order (BLAS) may
        # differ with the number of copies, and a copy must move as the single env does, bit for bit
        matrix = self.mixer.matrix
        wrench = squared[:, :1] * matrix[:, 0]
        for rotor in range(1, 4):
            wrench = wrench + squared[:, rotor : rotor + 1] * matrix[:, rotor]
        tau[:, :3] = wrench[:, :1] * _body_z(q[:, 3:7])  # the thrust, along the body's z axis
        tau[:, 3:] = wrench[:, 1:]
        return actions

    def observe(self, q, qd, links=None, tau=None):
        return np.concatenate([q[:, :3], qd[:, :3], q[:, 3:7], qd[:, 3:]], axis=1).astype(np.float32)

    def reward(self, q0, qd0, actions, q, qd, terminated):
        cost = _norm(q[:, :3]) + 0.5 * _norm(qd[:, :3]) + 0.5 * _norm(qd[:, 3:]) + 1e-5 * _norm(actions)
        return np.where(terminated, 0.0, 1.0) - cost

    def terminated(self, q, qd):
        upright = _body_z(q[:, 3:7])[:, 2]
        return (np.abs(q[:, :3]) > BOX).any(axis=1) | (upright < 0.0)

    def draw(self, q):
        """The side view (x right, z up): the arms, the hubs and the target."""
        canvas = Canvas(500, 500, scale=500 / (2 * BOX))
        canvas.segment((-0.1, 0.0), (0.1, 0.0), 0.01, (0, 160, 0))
        canvas.segment((0.0, -0.1), (0.0, 0.1), 0.01, (0, 160, 0))
        hubs = q[None, :3] + quat_rotate(np.repeat(q[None, 3:7], 4, axis=0), self.hubs) * 4.0  # drawn 4x larger
        centre = (q[0], q[2])
        for hub in hubs:
            canvas.segment(centre, (hub[0], hub[2]), 0.03, (60, 60, 60))
            canvas.disc((hub[0], hub[2]), 0.04, (204, 77, 77))
        return canvas.image
