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

The noiseless values of all the sensors of a world are computed together from the state arrays
(:class:`Sensors`, one NumPy pass per step); each sensor then adds its own noise.

Pose (motion capture): the body's position plus white noise of ``position_noise`` [m] per axis, and its orientation
turned by a random rotation whose rotation vector has ``orientation_noise`` [rad] per axis.
"""

from __future__ import annotations

import numpy as np

from ._validate import as_float, as_seed, as_vector3
from .handles import as_body, as_new_part
from .rotation import quat_from_rotvec, quat_multiply, quat_to_matrix

__all__ = ["IMU", "Pose", "Sensor", "Sensors"]


class Sensor:
    """What every sensor shares: its body, its generator, its link to a world, its last reading."""

    def __init__(self, body, seed):
        self.body = as_body(body)
        self.seed = as_seed(seed)
        self._rng = np.random.default_rng(seed)
        self._world = None
        self._reading: tuple[np.ndarray, np.ndarray] | None = None  # None: no step yet

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """The last step's sample (before any step: the state as it is, without noise)."""
        if self._reading is None:
            self._world._sensors.refresh(self._world)
            return self._reading_now()
        return self._reading[0].copy(), self._reading[1].copy()

    def _reading_now(self) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError


class IMU(Sensor):
    """An accelerometer and a gyroscope on ``body`` at ``position`` (body frame); see the module docstring.
    ``read()`` gives ``(specific_force_body [m/s²], angular_velocity_body [rad/s])``."""

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

    def _reading_now(self):
        # Before any step: a body not accelerating, whose specific force is −g.
        bank = self._world._sensors
        row = bank.imus.index(self)
        return bank.imu_rotation[row].T @ -self._world.gravity, bank.imu_omega_body[row].copy()

    def _take(self, specific_force: np.ndarray, angular_velocity: np.ndarray, dt: float) -> None:
        """Add this step's bias walk and noise to the true values."""
        self.accel_bias = self.accel_bias + self.accel_bias_walk * np.sqrt(dt) * self._rng.standard_normal(3)
        self.gyro_bias = self.gyro_bias + self.gyro_bias_walk * np.sqrt(dt) * self._rng.standard_normal(3)
        self._reading = (
            specific_force + self.accel_bias + self.accel_noise * self._rng.standard_normal(3),
            angular_velocity + self.gyro_bias + self.gyro_noise * self._rng.standard_normal(3),
        )

    def __repr__(self) -> str:
        return f"<IMU on body {self.body.name or self.body.index!r}>"


class Pose(Sensor):
    """Motion capture of ``body``: ``read()`` gives ``(position [m], orientation [w, x, y, z])`` with noise; see the
    module docstring."""

    def __init__(self, body, position_noise=0.0, orientation_noise=0.0, seed=None):
        super().__init__(body, seed)
        self.position_noise = as_float("position_noise", position_noise, nonnegative=True)
        self.orientation_noise = as_float("orientation_noise", orientation_noise, nonnegative=True)

    def _reading_now(self):
        return self.body.position, self.body.orientation

    def _take(self, position: np.ndarray, orientation: np.ndarray, dt: float) -> None:
        noisy = position + self.position_noise * self._rng.standard_normal(3)
        turn = quat_from_rotvec(self.orientation_noise * self._rng.standard_normal(3))
        self._reading = (noisy, quat_multiply(turn, orientation))

    def __repr__(self) -> str:
        return f"<Pose sensor on body {self.body.name or self.body.index!r}>"


class Sensors:
    """A world's sensors: their true values from the state arrays, all IMUs (and all poses) in one NumPy pass."""

    def __init__(self):
        self.imus: list[IMU] = []
        self.poses: list[Pose] = []
        # Per IMU, now: orientation (world from body), angular velocity in the body frame, point velocity (world).
        self.imu_quat = self.imu_omega_body = self._point_velocity = np.zeros((0, 3))
        self.imu_rotation = np.zeros((0, 3, 3))
        self._imu_bodies = self._imu_positions = self._pose_bodies = None  # gathered on first use after an add

    def __len__(self) -> int:
        return len(self.imus) + len(self.poses)

    def __iter__(self):
        return iter([*self.imus, *self.poses])

    def add(self, world, sensor) -> Sensor:
        as_new_part(world, sensor, Sensor, "sensor", "a", "a tumble.sensors.IMU or Pose")
        sensor._world = world
        (self.imus if isinstance(sensor, IMU) else self.poses).append(sensor)
        self._imu_bodies = self._imu_positions = self._pose_bodies = None
        return sensor

    def refresh(self, world) -> None:
        """Each IMU's orientation, body-frame angular velocity ``ω_b = I⁻¹ Rᵀ L`` and point velocity
        ``v + R (ω_b × r)`` now. One rotation matrix per IMU serves all three (this runs twice a step: a handful of
        NumPy calls, not the validated quaternion functions of :mod:`tumble.rotation` for each quantity)."""
        model, state = world.model, world.state
        if self._imu_bodies is None:
            self._imu_bodies = np.array([imu.body.index for imu in self.imus], np.int64)
            self._imu_positions = np.array([imu.position for imu in self.imus]).reshape(-1, 3)
        bodies = self._imu_bodies
        self.imu_quat = state.body_quat[bodies]
        self.imu_rotation = quat_to_matrix(self.imu_quat)
        angmom_body = np.einsum("nji,nj->ni", self.imu_rotation, state.body_angmom[bodies])
        self.imu_omega_body = np.einsum("nij,nj->ni", model.body_inv_inertia_local[bodies], angmom_body)
        arms = self._imu_positions - model.body_com_local[bodies]
        spin = np.einsum("nij,nj->ni", self.imu_rotation, _cross(self.imu_omega_body, arms))
        self._point_velocity = state.body_linvel[bodies] + spin

    def before_step(self, world) -> None:
        if self.imus:
            self.refresh(world)

    def sample(self, world, dt: float) -> None:
        """The samples of the step just taken."""
        if self.imus:
            quat0, velocity0 = self.imu_quat, self._point_velocity
            self.refresh(world)
            # The mean acceleration over the step, in the body frame of the step's middle (second order in ω dt).
            acceleration = (self._point_velocity - velocity0) / dt - world.gravity
            aligned = np.where(np.einsum("ni,ni->n", quat0, self.imu_quat)[:, None] >= 0.0, self.imu_quat,
                               -self.imu_quat)  # fmt: skip
            specific_force = np.einsum("nji,nj->ni", quat_to_matrix(quat0 + aligned), acceleration)
            for row, imu in enumerate(self.imus):
                imu._take(specific_force[row], self.imu_omega_body[row], dt)
        if self.poses:
            state, com = world.state, world.model.body_com_local
            if self._pose_bodies is None:
                self._pose_bodies = np.array([pose.body.index for pose in self.poses], np.int64)
            bodies = self._pose_bodies
            quat = state.body_quat[bodies]
            origins = state.body_pos[bodies] - np.einsum("nij,nj->ni", quat_to_matrix(quat), com[bodies])
            for row, pose in enumerate(self.poses):
                pose._take(origins[row], quat[row], dt)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a × b`` row by row for (n, 3) arrays: ``np.cross`` spends ten times longer checking and moving axes."""
    (ax, ay, az), (bx, by, bz) = a.T, b.T
    return np.stack((ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx), axis=1)
