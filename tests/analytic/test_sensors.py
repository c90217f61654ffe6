"""Sensors (issue 17, part 3): an IMU and motion capture, against what the state says and the noise asked for."""

from __future__ import annotations

import math

import numpy as np
import pytest

import tumble
from tumble.rotation import quat_conjugate, quat_from_axis_angle, quat_multiply, quat_to_matrix, quat_to_rotvec
from tumble.sensors import IMU, Pose

G = 9.81


def box_world(gravity=(0, 0, -G), ground=False, **body):
    world = tumble.World(gravity=gravity)
    if ground:
        world.add_static(tumble.Plane())
    return world, world.add_body(tumble.Box((0.4, 0.3, 0.2)), mass=2.0, **body)


@pytest.mark.parametrize("rate", [60, 240, 1000])
@pytest.mark.parametrize("angle", [0.0, math.pi / 2])
def test_an_imu_at_rest_on_the_ground_reads_plus_g_up_and_no_spin(angle, rate):
    turn = quat_from_axis_angle((1, 0, 0), angle)
    height = 0.1 if angle == 0.0 else 0.15
    world, body = box_world(ground=True, position=(0, 0, height), orientation=turn)
    imu = world.add_sensor(IMU(body, position=(0.1, -0.05, 0.1)))
    world.simulate(2.0, 1 / rate)
    specific_force, angular_velocity = imu.read()
    np.testing.assert_allclose(specific_force, quat_to_matrix(turn).T @ (0, 0, G), atol=1e-6)
    np.testing.assert_allclose(angular_velocity, 0.0, atol=1e-9)


@pytest.mark.parametrize("integrator", ["rk4", "symplectic"])
def test_an_imu_in_free_fall_reads_no_force_and_the_body_rate(integrator):
    world, body = box_world(orientation=quat_from_axis_angle((1, 1, 0), 0.4), angular_velocity=(0.0, 0.0, 0.0))
    world.integrator = integrator
    imu = world.add_sensor(IMU(body))
    world.simulate(1.0, 1e-3)
    specific_force, angular_velocity = imu.read()
    np.testing.assert_allclose(specific_force, 0.0, atol=1e-9)
    np.testing.assert_allclose(angular_velocity, 0.0, atol=1e-12)


@pytest.mark.parametrize("dt", [1e-3, 1 / 240, 1e-2])
def test_an_imu_off_the_axis_of_a_spinning_body_feels_the_centripetal_acceleration(dt):
    """Spinning at 3 rad/s about its z axis without gravity, an IMU 0.1 m out reads −ω² r towards the axis."""
    world, body = box_world(gravity=(0, 0, 0), angular_velocity=(0, 0, 3.0))
    world.integrator = "rk4"
    imu = world.add_sensor(IMU(body, position=(0.1, 0.0, 0.0)))
    world.simulate(round(0.5 / dt) * dt, dt)
    specific_force, angular_velocity = imu.read()
    # The mean over a step of a turning acceleration is shorter by ω² r (ω dt)²/24 (3.4e-7 at dt 1e-3, 3.4e-5 at
    # 1e-2): within 1.1 times that, so a first-order error (ω dt)/2 would be caught at every step size.
    shortfall = 0.9 * (3.0 * dt) ** 2 / 24
    np.testing.assert_allclose(specific_force, (-0.9, 0.0, 0.0), atol=1.1 * shortfall + 1e-9)
    np.testing.assert_allclose(angular_velocity, (0, 0, 3.0), atol=1e-12)


def imu_samples(seed, steps=20000, **noise):
    world, body = box_world(gravity=(0, 0, 0))
    imu = world.add_sensor(IMU(body, seed=seed, **noise))
    samples, biases = [], []
    world.add_controller(lambda w, t: (samples.append(np.concatenate(imu.read())), biases.append(imu.accel_bias)))
    world.simulate(steps * 1e-3, 1e-3)
    return np.array(samples[1:]), np.array(biases[1:])


def test_imu_noise_has_the_standard_deviation_asked_for_and_a_seed_repeats_it():
    samples, _ = imu_samples(7, accel_noise=0.2, gyro_noise=0.01)
    n = samples.shape[0]
    np.testing.assert_allclose(samples[:, :3].mean(axis=0), 0.0, atol=4 * 0.2 / math.sqrt(n))
    np.testing.assert_allclose(samples[:, 3:].mean(axis=0), 0.0, atol=4 * 0.01 / math.sqrt(n))
    # The sample standard deviation's own spread is σ / √(2n): 0.5 % here; 3 % is six of them.
    np.testing.assert_allclose(samples[:, :3].std(axis=0), 0.2, rtol=0.03)
    np.testing.assert_allclose(samples[:, 3:].std(axis=0), 0.01, rtol=0.03)
    again, _ = imu_samples(7, steps=100, accel_noise=0.2, gyro_noise=0.01)
    np.testing.assert_array_equal(again, samples[:99])
    other, _ = imu_samples(8, steps=100, accel_noise=0.2, gyro_noise=0.01)
    assert not np.array_equal(other, again)


def test_imu_bias_walks_by_its_density_times_root_dt():
    _, biases = imu_samples(3, steps=20000, accel_bias_walk=0.05)
    steps = np.diff(biases, axis=0)
    np.testing.assert_allclose(steps.std(axis=0), 0.05 * math.sqrt(1e-3), rtol=0.03)


def test_pose_noise_has_the_standard_deviation_asked_for():
    world, body = box_world(gravity=(0, 0, 0), position=(1, 2, 3), orientation=quat_from_axis_angle((0, 0, 1), 1.0))
    pose = world.add_sensor(Pose(body, position_noise=0.002, orientation_noise=0.01, seed=11))
    readings = []
    world.add_controller(lambda w, t: readings.append(pose.read()))
    world.simulate(10.0, 1e-3)
    positions = np.array([p for p, _ in readings[1:]])
    turns = quat_to_rotvec(quat_multiply(np.array([q for _, q in readings[1:]]), quat_conjugate(body.orientation)))
    np.testing.assert_allclose(positions.mean(axis=0), (1, 2, 3), atol=4 * 0.002 / math.sqrt(len(positions)))
    np.testing.assert_allclose(positions.std(axis=0), 0.002, rtol=0.03)
    np.testing.assert_allclose(turns.std(axis=0), 0.01, rtol=0.03)


def test_readings_do_not_depend_on_how_often_they_are_read():
    def last_reading(read_every_step):
        world, body = box_world(gravity=(0, 0, 0))
        imu = world.add_sensor(IMU(body, accel_noise=1.0, seed=5))
        if read_every_step:
            world.add_controller(lambda w, t: imu.read())
        world.simulate(0.1, 1e-3)
        return imu.read()

    np.testing.assert_array_equal(last_reading(True)[0], last_reading(False)[0])


def test_a_pose_sensor_without_noise_reads_the_pose():
    world, body = box_world(velocity=(1, 0, 0))
    pose = world.add_sensor(Pose(body))
    np.testing.assert_array_equal(pose.read()[0], body.position)  # before any step: the pose now
    world.step(0.01)
    np.testing.assert_array_equal(pose.read()[0], body.position)
    np.testing.assert_array_equal(pose.read()[1], body.orientation)


@pytest.mark.parametrize(
    ("make", "error", "message"),
    [
        (lambda b: IMU(b, accel_noise=-1), ValueError, r"accel_noise must be >= 0, got -1.0"),
        (lambda b: IMU(b, gyro_noise=math.nan), ValueError, r"gyro_noise must be finite"),
        (lambda b: IMU(b, accel_bias_walk=-0.1), ValueError, r"accel_bias_walk must be >= 0"),
        (lambda b: IMU(b, gyro_bias_walk=-0.1), ValueError, r"gyro_bias_walk must be >= 0"),
        (lambda b: IMU(b, position=(0, 0)), ValueError, r"position"),
        (lambda b: IMU(b, seed=-1), ValueError, r"seed must be an integer >= 0 or None, got -1"),
        (lambda b: IMU(b, seed=1.5), ValueError, r"seed must be an integer >= 0 or None, got 1.5"),
        (lambda b: Pose(b, position_noise=-1), ValueError, r"position_noise must be >= 0"),
        (lambda b: Pose(b, orientation_noise=-1), ValueError, r"orientation_noise must be >= 0"),
        (lambda b: Pose("body"), TypeError, r"body must be a tumble.Body"),
    ],
)
def test_bad_sensors_are_refused(make, error, message):
    _, body = box_world()
    with pytest.raises(error, match=message):
        make(body)


def test_sensors_need_a_dynamic_body_of_this_world():
    world, body = box_world()
    ground = world.add_static(tumble.Plane(), name="ground")
    _, other = box_world()
    with pytest.raises(ValueError, match="belongs to another world; a sensor needs a body of this one"):
        world.add_sensor(IMU(other))
    with pytest.raises(ValueError, match="body 'ground' is static: a sensor needs a dynamic body"):
        world.add_sensor(Pose(ground))
    with pytest.raises(TypeError, match="sensor must be a tumble.sensors.IMU or Pose"):
        world.add_sensor(body)
    imu = world.add_sensor(IMU(body))
    with pytest.raises(ValueError, match="in a world already"):
        world.add_sensor(imu)
    assert world.sensors == [imu]
