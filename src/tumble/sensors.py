"""Sensors: what real hardware reads of a body, sampled at the end of every step, seeded and reproducible.

``world.add_sensor(IMU(body, ...))`` adds one and returns it; ``.read()`` gives its latest sample. Each sensor draws
its noise from its own generator (``numpy.random.default_rng(seed)``) once per step, so the readings depend only on
the seed and the steps, not on how often they are read.

IMU (an accelerometer and a gyroscope at ``position`` in the body frame): the specific force ``f = a − g`` of that
point, ``a`` its mean acceleration over the step (the change of its velocity ``v + ω × r`` over the step, divided
by ``dt``, in the body frame of the step's middle), and the angular velocity at the step's end in the body frame;
at rest on the ground it reads ``(0, 0, +g)`` and zero, in free fall zero. White noise of standard deviation
``accel_noise`` [m/s²] and ``gyro_noise`` [rad/s] per sample is added to a bias that walks by ``bias_walk √dt``
per step from zero (``accel_bias_walk`` [m/s²/√s], ``gyro_bias_walk`` [rad/s/√s]; Woodman, "An introduction to
inertial navigation", Cambridge TR-696, 2007).

Pose (motion capture): the body's position plus white noise of ``position_noise`` [m] per axis, and its orientation
turned by a random rotation whose rotation vector has ``orientation_noise`` [rad] per axis.
"""

from __future__ import annotations

import numpy as np

from ._validate import as_body, as_dynamic_body_of, as_float, as_seed, as_vector3
from .rotation import quat_from_rotvec, quat_multiply, quat_to_matrix

__all__ = ["IMU", "Pose", "Sensor"]


class Sensor:
    """What every sensor shares: its body, its generator, its link to a world."""

    def __init__(self, body, seed):
        self.body = as_body(body)
        self.seed = as_seed(seed)
        self._rng = np.random.default_rng(seed)
        self._world = None

    def _attach(self, world) -> None:
        if self._world is not None:
            raise ValueError(f"{self!r} is in a world already")
        as_dynamic_body_of(world, self.body, "a sensor")
        self._world = world
        self._reset()

    def _reset(self) -> None:
        """The reading before any step."""

    def _before_step(self) -> None:
        """Note what the sample after the step needs."""

    def _sample(self, dt: float) -> None:
        """Take the sample of the step just taken."""


class IMU(Sensor):
    """An accelerometer and a gyroscope on ``body`` at ``position`` (body frame); see the module docstring."""

    def __init__(self, body, position=(0.0, 0.0, 0.0), accel_noise=0.0, gyro_noise=0.0, accel_bias_walk=0.0,
                 gyro_bias_walk=0.0, seed=None):  # fmt: skip
        super().__init__(body, seed)
        self.position = as_vector3("position", position)
        self.accel_noise = as_float("accel_noise", accel_noise, nonnegative=True)
        self.gyro_noise = as_float("gyro_noise", gyro_noise, nonnegative=True)
        self.accel_bias_walk = as_float("accel_bias_walk", accel_bias_walk, nonnegative=True)
        self.gyro_bias_walk = as_float("gyro_bias_walk", gyro_bias_walk, nonnegative=True)
        self.accel_bias = np.zeros(3)
        self.gyro_bias = np.zeros(3)
        self._reading = (np.zeros(3), np.zeros(3))
        self._point_velocity = np.zeros(3)
        self._orientation = np.array([1.0, 0.0, 0.0, 0.0])

    def _arm(self) -> np.ndarray:
        """From the COM to the sensor, world frame."""
        return quat_to_matrix(self.body.orientation) @ (self.position - self.body._com_local())

    def _point(self) -> np.ndarray:
        return self.body.velocity + np.cross(self.body.angular_velocity, self._arm())

    def _reset(self) -> None:
        # Before any step: the reading of a body not accelerating (specific force −g), no noise.
        rotation = quat_to_matrix(self.body.orientation)
        self._reading = (rotation.T @ -self._world.gravity, rotation.T @ self.body.angular_velocity)

    def _before_step(self) -> None:
        self._point_velocity = self._point()
        self._orientation = self.body.orientation

    def _sample(self, dt: float) -> None:
        rotation = quat_to_matrix(self.body.orientation)
        # The mean acceleration over the step, in the body frame of the step's middle (second order in ω dt).
        acceleration = (self._point() - self._point_velocity) / dt
        q0, q1 = self._orientation, self.body.orientation
        middle = quat_to_matrix(q0 + q1 if np.dot(q0, q1) >= 0.0 else q0 - q1)
        self.accel_bias = self.accel_bias + self.accel_bias_walk * np.sqrt(dt) * self._rng.standard_normal(3)
        self.gyro_bias = self.gyro_bias + self.gyro_bias_walk * np.sqrt(dt) * self._rng.standard_normal(3)
        specific_force = middle.T @ (acceleration - self._world.gravity)
        angular_velocity = rotation.T @ self.body.angular_velocity
        self._reading = (
            specific_force + self.accel_bias + self.accel_noise * self._rng.standard_normal(3),
            angular_velocity + self.gyro_bias + self.gyro_noise * self._rng.standard_normal(3),
        )

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """``(specific_force_body [m/s²], angular_velocity_body [rad/s])`` of the last step."""
        return self._reading[0].copy(), self._reading[1].copy()

    def __repr__(self) -> str:
        return f"<IMU on body {self.body.name or self.body.index!r}>"


class Pose(Sensor):
    """Motion capture of ``body``: position and orientation with noise; see the module docstring."""

    def __init__(self, body, position_noise=0.0, orientation_noise=0.0, seed=None):
        super().__init__(body, seed)
        self.position_noise = as_float("position_noise", position_noise, nonnegative=True)
        self.orientation_noise = as_float("orientation_noise", orientation_noise, nonnegative=True)
        self._reading = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))

    def _reset(self) -> None:
        self._reading = (self.body.position.copy(), self.body.orientation.copy())

    def _sample(self, dt: float) -> None:
        position = self.body.position + self.position_noise * self._rng.standard_normal(3)
        turn = quat_from_rotvec(self.orientation_noise * self._rng.standard_normal(3))
        self._reading = (position, quat_multiply(turn, self.body.orientation))

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """``(position [m], orientation quaternion [w, x, y, z])`` of the last step."""
        return self._reading[0].copy(), self._reading[1].copy()

    def __repr__(self) -> str:
        return f"<Pose sensor on body {self.body.name or self.body.index!r}>"
