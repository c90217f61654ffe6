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
(:class:`Sensors`, one compiled call per step); each sensor then adds its own noise.

Pose (motion capture): the body's position plus white noise of ``position_noise`` [m] per axis, and its orientation
turned by a random rotation whose rotation vector has ``orientation_noise`` [rad] per axis.
"""

from __future__ import annotations

import numpy as np

from . import portable
from ._jit import kernel
from ._validate import as_float, as_seed, as_vector3
from .handles import as_body, as_new_part
from .math3d import (
    add,
    cross,
    load3,
    load4,
    load33,
    mat_vec,
    quat_exp,
    quat_mul,
    quat_normalize,
    quat_rotate,
    quat_rotate_inv,
    store3,
    store4,
    sub,
)
from .rotation import quat_to_matrix

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
        quat, angular_velocity = self._world._sensors.imu_now(self._world, self)
        return portable.matvec(quat_to_matrix(quat).T, -self._world.gravity), angular_velocity

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
        # The turn exp(½ θ) of θ = orientation_noise n, through math3d's helpers on tuples: rotation's checked
        # functions took 0.45 ms a step.
        turn = quat_exp(tuple(self._rng.standard_normal(3).tolist()), self.orientation_noise)
        self._reading = (noisy, np.array(quat_mul(turn, tuple(orientation.tolist()))))

    def __repr__(self) -> str:
        return f"<Pose sensor on body {self.body.name or self.body.index!r}>"


class Sensors:
    """A world's sensors: the true values of all IMUs (and of all poses) from the state arrays in one compiled call
    per step (:func:`_point_motion`); each sensor then adds its own noise."""

    def __init__(self):
        self.imus: list[IMU] = []
        self.poses: list[Pose] = []
        self._imu = self._pose = None  # each a _Points, gathered on first use after an add

    def __len__(self) -> int:
        return len(self.imus) + len(self.poses)

    def __iter__(self):
        return iter([*self.imus, *self.poses])

    def add(self, world, sensor) -> Sensor:
        as_new_part(world, sensor, Sensor, "sensor", "a", "a tumble.sensors.IMU or Pose")
        sensor._world = world
        (self.imus if isinstance(sensor, IMU) else self.poses).append(sensor)
        self._imu = self._pose = None
        return sensor

    def imu_now(self, world, imu: IMU) -> tuple[np.ndarray, np.ndarray]:
        """``imu``'s orientation [w, x, y, z] and body-frame angular velocity now, without noise."""
        self.refresh(world)
        row = self.imus.index(imu)
        return self._imu.quat[row].copy(), self._imu.omega_body[row].copy()

    def refresh(self, world, dt: float = 0.0) -> None:
        """Each IMU's orientation, body-frame angular velocity and point velocity now; with ``dt``, first the
        specific force over the step of ``dt`` that ends now, from the values kept at its start."""
        if self._imu is None:
            self._imu = _Points(self.imus, [imu.position for imu in self.imus])
        self._imu.update(world, dt)

    def before_step(self, world) -> None:
        if self.imus:
            self.refresh(world)

    def sample(self, world, dt: float) -> None:
        """The samples of the step just taken."""
        if self.imus:
            self.refresh(world, dt)
            imu = self._imu
            for row, sensor in enumerate(self.imus):
                sensor._take(imu.specific_force[row], imu.omega_body[row], dt)
        if self.poses:
            if self._pose is None:
                self._pose = _Points(self.poses, [(0.0, 0.0, 0.0)] * len(self.poses))  # the body frames' origins
            pose = self._pose
            pose.update(world, 0.0)
            for row, sensor in enumerate(self.poses):
                sensor._take(pose.position[row].copy(), pose.quat[row].copy(), dt)


class _Points:
    """Points fixed in bodies (``points[k]`` in the body frame of ``sensors[k].body``) and their motion now."""

    def __init__(self, sensors: list[Sensor], points):
        count = len(sensors)
        self.bodies = np.array([sensor.body.index for sensor in sensors], np.int64)
        self.points = np.array(points, np.float64).reshape(count, 3)
        self.quat = np.zeros((count, 4))
        self.position, self.velocity, self.omega_body, self.specific_force = np.zeros((4, count, 3))

    def update(self, world, dt: float) -> None:
        model, state = world.model, world.state
        _point_motion(self.bodies, self.points, state.body_pos, state.body_quat, state.body_linvel,
                      state.body_angmom, model.body_inv_inertia_local, model.body_com_local, world.gravity, dt,
                      self.quat, self.position, self.velocity, self.omega_body, self.specific_force)  # fmt: skip


@kernel
def _point_motion(bodies, points, body_pos, body_quat, body_linvel, body_angmom, inv_inertia_local, com_local,
                  gravity, dt, quat, position, velocity, omega_body, specific_force):  # fmt: skip
    """For each point ``r`` (body frame) of body ``b``: the orientation ``q``, the angular velocity in the body frame
    ``ω_b = I⁻¹ Rᵀ L``, the position ``x + R (r − c)`` and the velocity ``v + R (ω_b × (r − c))`` now (``x``, ``v``
    the centre of mass's). With ``dt > 0``, first the specific force ``f = a − g`` over the step that ends now, ``a``
    the change of the point's velocity (the ``velocity`` row, from the step's start) over ``dt``, in the body frame of
    the step's middle: turned by the normalised sum of the two orientations (second order in ``ω dt``)."""
    for k in range(bodies.shape[0]):
        b = bodies[k]
        q = load4(body_quat, b)
        omega = mat_vec(load33(inv_inertia_local, b), quat_rotate_inv(q, load3(body_angmom, b)))
        arm = sub(load3(points, k), load3(com_local, b))
        point_velocity = add(load3(body_linvel, b), quat_rotate(q, cross(omega, arm)))
        if dt > 0.0:
            q0 = load4(quat, k)
            side = 1.0 if q0[0] * q[0] + q0[1] * q[1] + q0[2] * q[2] + q0[3] * q[3] >= 0.0 else -1.0
            middle = quat_normalize((q0[0] + side * q[0], q0[1] + side * q[1], q0[2] + side * q[2],
                                     q0[3] + side * q[3]))  # fmt: skip
            change = sub(point_velocity, load3(velocity, k))
            acceleration = (change[0] / dt - gravity[0], change[1] / dt - gravity[1], change[2] / dt - gravity[2])
            store3(specific_force, k, quat_rotate_inv(middle, acceleration))
        store4(quat, k, q)
        store3(omega_body, k, omega)
        store3(position, k, add(load3(body_pos, b), quat_rotate(q, arm)))
        store3(velocity, k, point_velocity)
