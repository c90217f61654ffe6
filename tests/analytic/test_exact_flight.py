"""``integrator="auto"`` on free bodies: the exact flight where the motion has a closed form, RK4 bit for bit elsewhere.

A body under a constant force with no torque and no damping follows the parabola ``x0 + v0 t + ½ a t²``; if its
inertia is isotropic (sphere, cube) its spin ``ω = L / I`` is constant too, and its orientation is
``exp(½ ω t) ⊗ q0`` (course 002, quaternion kinematics). ``auto`` steps such bodies by that closed form, so it is
exact at any step size, where RK4 is only fourth order.
"""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble.rotation import quat_conjugate, quat_from_axis_angle, quat_from_rotvec, quat_multiply

GRAVITY = np.array([0.0, 0.0, -9.81])
X0, V0 = np.array([0.5, -1.0, 2.0]), np.array([3.0, 1.0, 8.0])
OMEGA = np.array([3.0, -40.0, 7.0])  # fast: h|ω|/2 = 0.34 at 60 Hz, where RK4's turn is visibly off
Q0 = quat_from_axis_angle((1.0, 2.0, -0.5), 0.9)
SHAPES = {"sphere": tumble.Sphere(0.2), "cube": tumble.Box((0.3, 0.3, 0.3))}


def flying(integrator: str, shape: str, omega=OMEGA) -> tuple[tumble.World, tumble.Body]:
    world = tumble.World(gravity=GRAVITY, integrator=integrator)
    body = world.add_body(SHAPES[shape], mass=2.5, position=X0, orientation=Q0, velocity=V0, angular_velocity=omega,
                          collision_mask=0)  # fmt: skip
    return world, body


def closed_form(t: np.ndarray, omega=OMEGA) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.asarray(t)[:, None]
    x = X0 + V0 * t + 0.5 * GRAVITY * t**2
    q = quat_multiply(quat_from_rotvec(omega * t), Q0)
    return x, q, V0 + GRAVITY * t


def orientation_error(q: np.ndarray, reference: np.ndarray) -> float:
    """Largest angle between the two orientations (from the vector part: arccos of ``q·ref`` loses half the digits)."""
    d = quat_multiply(quat_conjugate(reference), q)
    return float(np.max(2.0 * np.arctan2(np.linalg.norm(d[..., 1:], axis=-1), np.abs(d[..., 0]))))


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("dt", [1 / 60, 1 / 240, 1e-3])
def test_auto_flies_an_isotropic_body_exactly_at_any_step(shape, dt):
    world, _ = flying("auto", shape)
    angmom = world.state.body_angmom.copy()
    traj = world.simulate(2.0, dt)
    x, q, v = closed_form(traj.time)
    steps = len(traj.time) - 1  # round-off grows with the steps, by about one ulp of each quantity a step
    np.testing.assert_allclose(traj.position[:, 0], x, rtol=0, atol=1e-15 * steps)
    np.testing.assert_allclose(traj.velocity[:, 0], v, rtol=0, atol=1e-15 * steps)
    assert orientation_error(traj.orientation[:, 0], q) < 4e-16 * steps
    # L never changes in flight, bit for bit, and the energy is kept to round-off.
    np.testing.assert_array_equal(world.state.body_angmom, angmom)
    energy = traj.total_energy
    assert np.max(np.abs(energy - energy[0])) < 1e-16 * np.max(np.abs(energy)) * steps


def test_rk4_stays_rk4_and_auto_is_the_more_accurate_where_it_flies():
    """``integrator="rk4"`` asked for by name is the classical scheme (its turn is off by ~1e-4 rad here after 2 s
    at 60 Hz); ``auto`` is exact to round-off on the same body."""
    errors = {}
    for integrator in ("rk4", "auto"):
        world, _ = flying(integrator, "sphere")
        traj = world.simulate(2.0, 1 / 60)
        errors[integrator] = orientation_error(traj.orientation[:, 0], closed_form(traj.time)[1])
    assert errors["rk4"] > 1e-5 and errors["auto"] < 1e-12


def test_a_body_without_spin_keeps_its_orientation_bit_for_bit_whatever_its_inertia():
    world = tumble.World(gravity=GRAVITY)
    body = world.add_body(tumble.Box((0.1, 0.4, 0.9)), mass=2.5, position=X0, orientation=Q0, velocity=V0,
                          collision_mask=0)  # fmt: skip
    q0 = body.orientation.copy()
    traj = world.simulate(1.0, 1 / 60)
    assert np.all(traj.orientation[:, 0] == q0)
    np.testing.assert_allclose(traj.position[:, 0], closed_form(traj.time)[0], rtol=0, atol=1e-13)


def _one_body(integrator: str, shape: str = "sphere", inertia=None, **options) -> tuple[tumble.World, tumble.Body]:
    world = tumble.World(gravity=GRAVITY, integrator=integrator)
    if inertia is not None:
        body = world.add_body(None, mass=2.5, inertia=inertia, position=X0, velocity=V0, angular_velocity=OMEGA,
                              **options)  # fmt: skip
    else:
        body = world.add_body(SHAPES[shape], mass=2.5, position=X0, orientation=Q0, velocity=V0,
                              angular_velocity=OMEGA, collision_mask=0, **options)  # fmt: skip
    return world, body


def _with_torque(integrator: str) -> tumble.World:
    world, body = _one_body(integrator)
    body.constant_torque = (0.0, 0.3, -0.1)
    return world


def _with_drag(integrator: str) -> tumble.World:
    world, body = _one_body(integrator, "cube")
    world.add_drag(body, (0.4, 0.4, 0.4))
    return world


NOT_IN_FLIGHT = {
    "anisotropic inertia, spinning": lambda name: _one_body(name, inertia=np.diag([1.0, 2.0, 3.0]))[0],
    "linear damping": lambda name: _one_body(name, linear_damping=0.3)[0],
    "angular damping": lambda name: _one_body(name, "cube", angular_damping=0.3)[0],
    "a constant torque": _with_torque,
    "drag (an actuator)": _with_drag,
}


@pytest.mark.parametrize("case", NOT_IN_FLIGHT)
def test_auto_is_rk4_bit_for_bit_where_the_motion_has_no_closed_form(case):
    digests = []
    for integrator in ("auto", "rk4"):
        world = NOT_IN_FLIGHT[case](integrator)
        world.simulate(1.0, 1 / 240)
        digests.append(world.state.digest())
    assert digests[0] == digests[1]


def test_each_body_takes_its_own_path_in_one_world():
    """A tumbling body beside a sphere: the tumbler's row is RK4's bit for bit, the sphere's exact."""
    worlds = {}
    for integrator in ("auto", "rk4"):
        world, _ = _one_body(integrator, inertia=np.diag([1.0, 2.0, 3.0]))
        world.add_body(SHAPES["sphere"], mass=2.5, position=X0, orientation=Q0, velocity=V0, angular_velocity=OMEGA,
                       collision_mask=0)  # fmt: skip
        worlds[integrator] = world
        world.simulate(1.0, 1 / 60)
    auto, rk4 = worlds["auto"].state, worlds["rk4"].state
    for rows in ("body_pos", "body_quat", "body_linvel", "body_angmom"):
        np.testing.assert_array_equal(getattr(auto, rows)[0], getattr(rk4, rows)[0])
    _, q, _ = closed_form([1.0])
    assert orientation_error(auto.body_quat[1], q[0]) < 1e-13 < orientation_error(rk4.body_quat[1], q[0])


def test_a_torque_applied_for_one_step_takes_that_step_by_rk4_and_flies_after_it():
    worlds = {}
    for integrator in ("auto", "rk4"):
        world, body = _one_body(integrator)
        body.apply_torque((0.5, -0.2, 0.1))
        world.step(1 / 60)
        worlds[integrator] = world
    assert worlds["auto"].state.digest() == worlds["rk4"].state.digest()
    world = worlds["auto"]
    angmom = world.state.body_angmom.copy()
    world.simulate(1.0, 1 / 60)
    np.testing.assert_array_equal(world.state.body_angmom, angmom)
