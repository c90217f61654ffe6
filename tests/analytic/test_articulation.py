"""Articulations against closed-form mechanics and against themselves (RNEA, CRBA and ABA must agree)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline
from scipy.special import ellipk

from tumble.articulation import Articulation, Ball, Fixed, Free, Prismatic, Revolute
from tumble.mass import MassProperties
from tumble.rotation import quat_conjugate, quat_multiply, quat_rotate, quat_to_matrix, quat_to_rotvec
from tumble.shapes import Box, Capsule

G = 9.81
ALONG_X = (math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0)  # turns a shape's z axis onto the link's x axis


def _random_box(rng) -> MassProperties:
    turn = rng.normal(size=4)
    box = Box(rng.uniform(0.1, 0.5, size=3)).mass_properties(mass=rng.uniform(0.5, 2.0))
    return box.transformed(turn / np.linalg.norm(turn), rng.normal(size=3) * 0.2)


def mixed_tree(seed: int = 0, damping: float = 1.0) -> Articulation:
    """Every joint type, a branch, turned origins, joint damping (times ``damping``) and a tilted gravity."""
    rng = np.random.default_rng(seed)
    art = Articulation(gravity=(0.3, -0.2, -G), base_position=(0.1, 0.0, 0.5), base_orientation=(0.9, 0.0, 0.3, 0.1))
    a = art.add_link(
        Free(), position=(0.1, 0.2, 0.3), orientation=(0.9, 0.1, 0.2, 0.3), mass_properties=_random_box(rng)
    )
    b = art.add_link(Revolute((1, 2, 3)), parent=a, position=(0.3, 0, 0), orientation=(1, 0.2, 0, 0),
                     mass_properties=_random_box(rng), damping=0.3 * damping)  # fmt: skip
    art.add_link(Ball(), parent=b, position=(0, 0.3, 0), mass_properties=_random_box(rng), damping=0.05 * damping)
    d = art.add_link(Prismatic((0, 1, 1)), parent=a, position=(0, 0, -0.2), mass_properties=_random_box(rng),
                     damping=0.1 * damping)  # fmt: skip
    e = art.add_link(Fixed(), parent=d, position=(0.1, 0, 0), mass_properties=_random_box(rng))
    art.add_link(Revolute((0, 0, 1)), parent=e, position=(0.1, 0, 0.1), mass_properties=_random_box(rng))
    return art


def _random_state(art: Articulation, rng) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    q = rng.normal(size=art.nq)  # quaternion blocks are renormalised by the setter
    art.q = q
    return art.q, rng.normal(size=art.nv), rng.normal(size=art.nv)


def chain(n: int, *, length=0.2, mass=0.5, tilt=0.0) -> Articulation:
    """``n`` boxes hanging from hinges about y, straight down, the first hinge turned by ``tilt``."""
    art = Articulation()
    parent = None
    for i in range(n):
        origin = (0, 0, 0) if i == 0 else (0, 0, -length)
        parent = art.add_link(Revolute((0, 1, 0)), parent=parent, position=origin, shape=Box((0.03, 0.03, length)),
                              mass=mass, shape_position=(0, 0, -length / 2))  # fmt: skip
    art.set_joint(0, q=tilt)
    return art


# --- closed forms ----------------------------------------------------------------------------------------


def _crossing_times(time, angle, rate) -> np.ndarray:
    """Times where ``angle`` crosses zero upwards, from the cubic Hermite interpolant of (angle, rate)."""
    spline = CubicHermiteSpline(time, angle, rate)
    roots = spline.roots(extrapolate=False)
    return np.array([t for t in roots if spline(t, 1) > 0.0])


def test_pendulum_period_matches_the_elliptic_integral():
    length, theta0 = 1.0, math.pi / 2
    art = Articulation(gravity=(0, 0, -G))
    art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -length))  # a point mass: θ̈ = -(g/l) sin θ
    art.set_joint(0, q=theta0)
    trajectory = art.simulate(6.0, 1e-3, integrator="rk4")
    crossings = _crossing_times(trajectory.time, trajectory.q[:, 0], trajectory.qd[:, 0])
    period = float(np.mean(np.diff(crossings)))
    expected = 4.0 * math.sqrt(length / G) * ellipk(math.sin(theta0 / 2) ** 2)
    assert len(crossings) >= 2
    assert period == pytest.approx(expected, rel=1e-5)  # measured 4e-13 relative


def test_prismatic_slide_falls_as_half_g_t_squared():
    art = Articulation(gravity=(0, 0, -G))
    art.add_link(Prismatic((0, 0, -1)), shape=Box((0.1, 0.1, 0.1)), mass=2.0)
    dt, steps = 1e-3, 1000
    trajectory = art.simulate(steps * dt, dt, integrator="rk4")
    # RK4 is exact for a constant acceleration: measured 3e-14 m (rounding over 1000 steps)
    np.testing.assert_allclose(trajectory.q[:, 0], 0.5 * G * trajectory.time**2, rtol=0, atol=1e-12)
    # semi-implicit Euler has its own exact discrete solution q_n = g dt² n (n + 1) / 2
    art.q, art.qd = [0.0], [0.0]
    symplectic = art.simulate(steps * dt, dt, integrator="symplectic")
    n = np.arange(steps + 1)
    np.testing.assert_allclose(symplectic.q[:, 0], 0.5 * G * dt**2 * n * (n + 1), rtol=0, atol=1e-12)


def test_five_link_chain_conserves_energy_with_rk4():
    art = chain(5, tilt=math.radians(30))
    trajectory = art.simulate(10.0, 1e-3, integrator="rk4", record_every=10)
    energy = trajectory.energy
    drift = np.max(np.abs(energy - energy[0])) / abs(energy[0])
    assert drift < 1e-6  # measured 9e-11 (E0 = -10.6 J: potential zero at the world origin, the hinge)


def test_free_body_keeps_angular_momentum_and_energy():
    art = Articulation(gravity=(0, 0, 0))
    inertia = np.diag([1.0, 2.0, 3.0])
    art.add_link(Free(), mass_properties=MassProperties(1.0, (0, 0, 0), inertia))
    art.qd = [0.1, -0.2, 0.3, 0.01, 5.0, 0.01]  # spin near the unstable middle axis: it flips
    trajectory = art.simulate(10.0, 1e-3, integrator="rk4", record_every=10)
    quat, omega_body = trajectory.q[:, 3:7], trajectory.qd[:, 3:6]
    momentum = quat_rotate(quat, omega_body @ inertia)
    drift = np.max(np.linalg.norm(momentum - momentum[0], axis=1)) / np.linalg.norm(momentum[0])
    assert drift < 1e-9  # measured 7e-12
    assert np.max(np.abs(trajectory.energy - trajectory.energy[0])) / trajectory.energy[0] < 1e-9  # measured 4e-13
    assert np.ptp(omega_body[:, 1]) > 9.0  # it did flip: ω_y went from +5 to about -5
    # the centre of mass moves in a straight line at the initial velocity
    np.testing.assert_allclose(trajectory.q[-1, :3], 10.0 * np.array([0.1, -0.2, 0.3]), atol=1e-11)  # 5e-13


def test_external_force_and_torque_on_a_free_body():
    art = Articulation(gravity=(0, 0, 0))
    inertia = np.diag([1.0, 2.0, 3.0])
    art.add_link(Free(), orientation=(math.cos(0.4), math.sin(0.4), 0.0, 0.0),
                 mass_properties=MassProperties(2.0, (0.1, 0.0, 0.0), inertia))  # fmt: skip
    force, torque = np.array([1.0, -2.0, 0.5]), np.array([0.0, 0.3, 0.0])
    external = np.array([[*force, *torque]])
    qdd = art.forward_dynamics(external=external)
    # at rest: the centre of mass accelerates by F / m and the body turns by I⁻¹ τ (world frame)
    rot = quat_to_matrix(art.q[3:])
    alpha = rot @ qdd[3:]
    com_acc = qdd[:3] + np.cross(alpha, rot @ np.array([0.1, 0.0, 0.0]))
    np.testing.assert_allclose(com_acc, force / 2.0, atol=1e-14)
    np.testing.assert_allclose(alpha, np.linalg.solve(rot @ inertia @ rot.T, torque), atol=1e-14)
    # held over a run, a pure force moves the centre of mass by ½ F/m t² (exact for RK4)
    art.simulate(1.0, 1e-2, integrator="rk4", external=[[*force, 0.0, 0.0, 0.0]])
    com = art.q[:3] + quat_rotate(art.q[3:], np.array([0.1, 0.0, 0.0]))
    start = quat_rotate(np.array([math.cos(0.4), math.sin(0.4), 0.0, 0.0]), np.array([0.1, 0.0, 0.0]))
    np.testing.assert_allclose(com - start, 0.5 * force / 2.0, atol=1e-12)


def test_damping_dissipates_energy_monotonically():
    art = chain(3, tilt=1.0)
    damped = Articulation()
    parent = None
    for link in art.links:
        parent = damped.add_link(link.joint, parent=parent, position=link.position,
                                 mass_properties=link.mass_properties, damping=0.05)  # fmt: skip
    damped.q = art.q
    energy = damped.simulate(3.0, 1e-3, integrator="rk4", record_every=10).energy
    assert np.all(np.diff(energy) < 0.0)
    assert energy[-1] < energy[0] - 0.1


# --- the algorithms agree with each other ------------------------------------------------------------


def test_mass_matrix_is_symmetric_positive_definite():
    art = mixed_tree()
    rng = np.random.default_rng(1)
    for _ in range(20):
        q, _, _ = _random_state(art, rng)
        h = art.mass_matrix(q)
        np.testing.assert_array_equal(h, h.T)
        assert np.linalg.eigvalsh(h)[0] > 1e-6


def test_inverse_then_forward_dynamics_is_the_identity():
    art = mixed_tree()
    rng = np.random.default_rng(2)
    for _ in range(10):
        q, qd, qdd = _random_state(art, rng)
        external = rng.normal(size=(art.link_count, 6))
        tau = art.inverse_dynamics(q, qd, qdd, external=external)
        # forward dynamics of a tree runs the ABA; inverse dynamics the RNEA: measured 4.4e-13
        np.testing.assert_allclose(art.forward_dynamics(q, qd, tau, external=external), qdd, rtol=0, atol=1e-9)


def test_crba_equals_rnea_column_by_column():
    art = mixed_tree()
    rng = np.random.default_rng(3)
    q, _, _ = _random_state(art, rng)
    zero = np.zeros(art.nv)
    gravity_only = art.inverse_dynamics(q, zero, zero)
    columns = np.column_stack([art.inverse_dynamics(q, zero, unit) - gravity_only for unit in np.eye(art.nv)])
    np.testing.assert_allclose(art.mass_matrix(q), columns, rtol=0, atol=1e-12)  # measured 8e-14


def test_aba_equals_the_factorised_mass_matrix():
    art = mixed_tree()
    rng = np.random.default_rng(4)
    q, qd, _ = _random_state(art, rng)
    tau = rng.normal(size=art.nv)
    expected = np.linalg.solve(art.mass_matrix(q), tau - art.bias_forces(q, qd))
    np.testing.assert_allclose(art.forward_dynamics(q, qd, tau), expected, rtol=0, atol=1e-10)  # measured 8e-13


def test_bias_forces_include_damping():
    art = mixed_tree()
    rng = np.random.default_rng(5)
    q, qd, _ = _random_state(art, rng)
    damping = np.concatenate([np.full(link.joint.nv, link.damping) for link in art.links])
    undamped = mixed_tree(damping=0.0)
    assert np.count_nonzero(damping) == 5
    np.testing.assert_allclose(art.bias_forces(q, qd) - undamped.bias_forces(q, qd), damping * qd, atol=1e-12)


# --- kinematics ---------------------------------------------------------------------------------------


def _pose_rate(art, q, v, link, point, eps=1e-6):
    """Central differences of a link point's world position and of the link's orientation along ``v``."""
    plus, minus = art.integrate(q, v, eps), art.integrate(q, v, -eps)
    (pos_p, quat_p), (pos_m, quat_m) = art.link_poses(plus), art.link_poses(minus)
    x_p = pos_p[link] + quat_rotate(quat_p[link], point)
    x_m = pos_m[link] + quat_rotate(quat_m[link], point)
    turn = quat_to_rotvec(quat_multiply(quat_p[link], quat_conjugate(quat_m[link])))
    return (x_p - x_m) / (2 * eps), turn / (2 * eps)


def test_jacobian_matches_finite_differences_of_link_poses():
    art = mixed_tree()
    rng = np.random.default_rng(6)
    for _ in range(3):
        q, v, _ = _random_state(art, rng)
        for link in range(art.link_count):
            point = rng.normal(size=3) * 0.3
            jac = art.jacobian(link, point, q=q)
            linear, angular = _pose_rate(art, q, v, link, point)
            np.testing.assert_allclose(jac[:3] @ v, linear, atol=1e-7)  # measured 4e-10 (differences of step 1e-6)
            np.testing.assert_allclose(jac[3:] @ v, angular, atol=1e-7)  # measured 2e-10


def test_link_velocities_are_the_jacobian_times_qd():
    art = mixed_tree()
    q, qd, _ = _random_state(art, np.random.default_rng(7))
    linear, angular = art.link_velocities(q, qd)
    for link in range(art.link_count):
        jac = art.jacobian(link, q=q)
        np.testing.assert_allclose(linear[link], jac[:3] @ qd, atol=1e-12)
        np.testing.assert_allclose(angular[link], jac[3:] @ qd, atol=1e-12)


def test_free_joint_coordinates_are_mujoco_s():
    """Free: q = (position, quaternion) in the parent frame, qd = (linear velocity in the parent frame,
    angular velocity in the link frame)."""
    art = Articulation(base_orientation=(math.cos(0.3), 0.0, 0.0, math.sin(0.3)))
    art.add_link(Free(), shape=Box((0.1, 0.2, 0.3)), mass=1.0)
    q = np.array([0.1, 0.2, 0.3, 0.8, 0.1, -0.4, 0.2])
    qd = np.array([1.0, -2.0, 0.5, 0.3, 0.2, -0.1])
    art.q, art.qd = q, qd
    base = quat_to_matrix(art.base_orientation)
    position, orientation = art.link_poses()
    np.testing.assert_allclose(position[0], base @ q[:3], atol=1e-15)
    np.testing.assert_allclose(orientation[0], quat_multiply(art.base_orientation, art.q[3:]), atol=1e-15)
    linear, angular = art.link_velocities()
    np.testing.assert_allclose(linear[0], base @ qd[:3], atol=1e-15)
    np.testing.assert_allclose(angular[0], quat_to_matrix(orientation[0]) @ qd[3:], atol=1e-15)


def test_com_and_kinetic_energy_agree_with_the_links():
    art = mixed_tree()
    q, qd, _ = _random_state(art, np.random.default_rng(8))
    positions, quats = art.link_poses(q)
    linear, angular = art.link_velocities(q, qd)
    mass, first_moment, kinetic = 0.0, np.zeros(3), 0.0
    for link in art.links:
        mp, i = link.mass_properties, link.index
        rot = quat_to_matrix(quats[i])
        com = positions[i] + rot @ mp.com
        com_velocity = linear[i] + np.cross(angular[i], rot @ mp.com)
        inertia = rot @ mp.inertia @ rot.T
        mass += mp.mass
        first_moment += mp.mass * com
        kinetic += 0.5 * mp.mass * com_velocity @ com_velocity + 0.5 * angular[i] @ inertia @ angular[i]
    np.testing.assert_allclose(art.com(q), first_moment / mass, atol=1e-14)
    assert art.kinetic_energy(q, qd) == pytest.approx(kinetic, rel=1e-12)
    assert art.kinetic_energy(q, qd) == pytest.approx(0.5 * qd @ art.mass_matrix(q) @ qd, rel=1e-12)
    assert art.potential_energy(q) == pytest.approx(-mass * art.gravity @ art.com(q), rel=1e-12)


def test_step_loop_and_simulate_agree_bit_for_bit():
    a, b = mixed_tree(), mixed_tree()
    q, qd, _ = _random_state(a, np.random.default_rng(9))
    a.q, a.qd, b.q, b.qd = q, 0.3 * qd, q, 0.3 * qd
    for _ in range(50):
        a.step(1e-3, integrator="rk4")
    trajectory = b.simulate(50e-3, 1e-3, integrator="rk4")
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.qd, b.qd)
    np.testing.assert_array_equal(trajectory.q[-1], b.q)
    assert a.time == pytest.approx(b.time, abs=1e-15)


def test_adding_a_link_keeps_the_state():
    art = chain(2, tilt=0.3)
    art.simulate(0.1, 1e-3)
    q, qd, time = art.q, art.qd, art.time
    tip = art.add_link(Ball(), parent=1, position=(0, 0, -0.2), shape=Box((0.05, 0.05, 0.05)), mass=0.2)
    assert (art.nq, art.nv) == (6, 5)
    np.testing.assert_array_equal(art.q, [*q, 1.0, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(art.qd, [*qd, 0.0, 0.0, 0.0])
    assert art.time == time
    assert art.links[tip].q_slice == slice(2, 6) and art.links[tip].v_slice == slice(2, 5)
    energy = art.simulate(1.0, 1e-3, integrator="rk4").energy
    assert np.max(np.abs(energy - energy[0])) / abs(energy[0]) < 1e-8


# --- loop closures ----------------------------------------------------------------------------------------


def slider_crank(crank=0.1, rod=0.3) -> Articulation:
    """Crank and connecting rod hinged about y, a piston sliding along x, the rod's end pinned to the piston."""
    art = Articulation(gravity=(0, 0, 0))
    arm = Capsule(0.01, 0.05)
    c = art.add_link(Revolute((0, 1, 0)), shape=arm, mass=1.0, shape_position=(crank / 2, 0, 0),
                     shape_orientation=ALONG_X)  # fmt: skip
    r = art.add_link(Revolute((0, 1, 0)), parent=c, position=(crank, 0, 0), shape=arm, mass=0.5,
                     shape_position=(rod / 2, 0, 0), shape_orientation=ALONG_X)  # fmt: skip
    p = art.add_link(Prismatic((1, 0, 0)), shape=Box((0.05, 0.05, 0.05)), mass=0.8)
    art.add_loop_closure(r, (rod, 0, 0), p, (0, 0, 0))
    art.q = [0.3, -0.2, crank + rod]  # a rough guess; project_loop_closures assembles it
    art.qd = [8.0, 0.0, 0.0]
    art.project_loop_closures()
    return art


def test_slider_crank_piston_follows_the_crank_formula():
    crank, rod = 0.1, 0.3
    art = slider_crank(crank, rod)
    assert np.max(np.abs(art.loop_closure_error())) < 1e-12
    trajectory = art.simulate(2.0, 1e-3, integrator="rk4", record_every=5)
    theta, piston = trajectory.q[:, 0], trajectory.q[:, 2]
    assert np.ptp(theta) > 4 * math.pi  # the crank turned round at least twice
    expected = crank * np.cos(theta) + np.sqrt(rod**2 - crank**2 * np.sin(theta) ** 2)
    assert np.max(np.abs(piston - expected)) < 1e-3  # measured 1.2e-12 m
    # no gravity, no damping: the projection after each step costs almost no energy
    assert np.max(np.abs(trajectory.energy - trajectory.energy[0])) / trajectory.energy[0] < 1e-6  # measured 1.5e-8


def four_bar() -> Articulation:
    """A Grashof crank–rocker: ground 0.55, crank 0.2, coupler 0.6, rocker 0.5 (m), hinges about y, gravity."""
    art = Articulation(gravity=(0, 0, -G))
    bar = Box((0.02, 0.02, 1.0))

    def shape_args(length, mass):
        return {"shape": bar, "mass": mass, "shape_position": (length / 2, 0, 0), "shape_orientation": ALONG_X}

    crank = art.add_link(Revolute((0, 1, 0)), **shape_args(0.2, 0.3))
    coupler = art.add_link(Revolute((0, 1, 0)), parent=crank, position=(0.2, 0, 0), **shape_args(0.6, 0.6))
    rocker = art.add_link(Revolute((0, 1, 0)), position=(0.55, 0, 0), **shape_args(0.5, 0.5))
    art.add_loop_closure(coupler, (0.6, 0, 0), rocker, (0.5, 0, 0))
    art.q = [-1.2, 1.0, -1.8]  # crank up, rocker up: a guess near an assembly
    art.project_loop_closures()
    return art


def test_four_bar_constraint_drift_stays_small():
    art = four_bar()
    trajectory = art.simulate(5.0, 1e-3, integrator="rk4", record_every=10)
    errors = [np.max(np.abs(art.loop_closure_error(q))) for q in trajectory.q]
    assert max(errors) < 1e-10  # measured 1e-12 m: the projection after each step stops at 1e-12
    assert np.ptp(trajectory.q[:, 0]) > 1.0  # it moved
    drift = np.max(np.abs(trajectory.energy - trajectory.energy[0])) / abs(trajectory.energy[0])
    assert drift < 1e-6  # measured 4e-11


def test_symplectic_euler_closes_loops_too():
    art = four_bar()
    art.simulate(1.0, 1e-3, integrator="symplectic")
    assert np.max(np.abs(art.loop_closure_error())) < 1e-10
