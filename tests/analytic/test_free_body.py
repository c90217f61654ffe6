"""Free rigid bodies against closed-form mechanics and a tight ODE reference (Euler's equations)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import tumble
from tumble.rotation import quat_derivative, quat_to_matrix

INERTIA = np.diag([1.0, 2.0, 3.0])
OMEGA0 = np.array([0.01, 5.0, 0.01])  # near the intermediate axis: the Dzhanibekov flip
INTEGRATORS = ["euler", "symplectic", "rk4", "midpoint", "auto"]


def tumbling_world(integrator="auto", omega=OMEGA0, inertia=INERTIA):
    world = tumble.World(gravity=(0.0, 0.0, 0.0), integrator=integrator)
    body = world.add_body(None, mass=1.0, inertia=inertia, angular_velocity=omega)
    return world, body


def euler_equations_reference(t_end, omega0=OMEGA0, inertia=INERTIA, t_eval=None):
    """Body-frame ω from Euler's equations I ω̇ = (I ω) × ω, solved tightly (DOP853, rtol 1e-12)."""
    moments = np.diag(inertia)

    def rhs(_, w):
        return np.cross(moments * w, w) / moments

    return solve_ivp(rhs, (0.0, t_end), omega0, method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t_eval)


def full_state_reference(t_end, q0, omega0_world, inertia=INERTIA):
    """(q, L) of a torque-free body from a tight solve_ivp: q̇ = ½ (0, ω) ⊗ q, ω = R I⁻¹ Rᵀ L, L constant."""
    angmom = quat_to_matrix(q0) @ inertia @ quat_to_matrix(q0).T @ omega0_world
    inv_inertia = np.linalg.inv(inertia)

    def rhs(_, q):
        r = quat_to_matrix(q / np.linalg.norm(q))
        return quat_derivative(q, r @ inv_inertia @ r.T @ angmom)

    sol = solve_ivp(rhs, (0.0, t_end), q0, method="DOP853", rtol=1e-13, atol=1e-15)
    q = sol.y[:, -1] / np.linalg.norm(sol.y[:, -1])
    r = quat_to_matrix(q)
    return q, r @ inv_inertia @ r.T @ angmom


def half_periods(times, omega_body_y):
    """Times between successive sign changes of ω_y (the flips), by linear interpolation."""
    s = np.sign(omega_body_y)
    idx = np.flatnonzero(s[1:] != s[:-1])
    crossings = times[idx] - omega_body_y[idx] * (times[idx + 1] - times[idx]) / (
        omega_body_y[idx + 1] - omega_body_y[idx]
    )
    return np.diff(crossings)


@pytest.mark.parametrize("integrator", ["symplectic", "rk4", "midpoint", "auto"])
def test_dzhanibekov_flip_half_period_matches_euler_equations(integrator):
    world, _ = tumbling_world(integrator)
    traj = world.simulate(20.0, 1e-3)
    measured = half_periods(traj.time, traj.angular_velocity_body()[:, 0, 1])
    ref = euler_equations_reference(20.0, t_eval=traj.time)
    expected = half_periods(ref.t, ref.y[1])
    assert len(measured) >= 2 and len(measured) == len(expected)
    # 0.5 % is the bound; measured: rk4 4e-9, midpoint 4e-7, symplectic 1.3e-4 relative.
    np.testing.assert_allclose(measured, expected, rtol=5e-3)


def test_symmetric_top_precesses_in_the_body_frame_at_the_textbook_rate():
    """I1 = I2: body-frame ω turns about e3 at Ω = (I3 − I1)/I1 · ω3 (Euler's equations, closed form)."""
    inertia = np.diag([2.0, 2.0, 3.0])
    w0 = np.array([0.3, 0.0, 4.0])
    world, _ = tumbling_world("rk4", omega=w0, inertia=inertia)
    traj = world.simulate(5.0, 1e-3)
    w = traj.angular_velocity_body()[:, 0]
    rate = (3.0 - 2.0) / 2.0 * 4.0
    # ω1 = a cos(Ω t), ω2 = a sin(Ω t) for I ω̇ = (Iω) × ω with I3 > I1.
    expected = np.stack([0.3 * np.cos(rate * traj.time), 0.3 * np.sin(rate * traj.time)], axis=-1)
    np.testing.assert_allclose(w[:, :2], expected, atol=1e-9)  # measured 3e-12 (RK4, dt=1e-3)
    np.testing.assert_allclose(w[:, 2], 4.0, atol=1e-12)


def test_default_integrator_conserves_angular_momentum_and_energy():
    world, body = tumbling_world()
    L0, E0 = body.angular_momentum, world.total_energy()
    traj = world.simulate(20.0, 1e-3, record_every=100)
    L = traj.angular_momentum()
    # Issue targets: |L| to round-off (< 1e-12 relative), energy better than 1e-9 relative over 20 s.
    assert np.max(np.linalg.norm(L - L0, axis=-1)) / np.linalg.norm(L0) < 1e-12  # measured ~2e-15
    assert np.max(np.abs(traj.total_energy - E0)) / E0 < 1e-9  # measured ~1e-11


def test_midpoint_conserves_both_quadratic_invariants_to_round_off_even_at_a_large_step():
    world, body = tumbling_world("midpoint")
    L0, E0 = body.angular_momentum, world.total_energy()
    traj = world.simulate(20.0, 1e-2)
    L = traj.angular_momentum()
    assert np.max(np.linalg.norm(L - L0, axis=-1)) / np.linalg.norm(L0) < 1e-13  # measured 3e-15
    assert np.max(np.abs(traj.total_energy - E0)) / E0 < 1e-13  # measured 2e-15 (RK4 here: 4e-8)


def test_explicit_euler_gains_energy_as_the_course_warns():
    world, _ = tumbling_world("euler")
    traj = world.simulate(2.0, 1e-3, record_every=100)
    gain = np.diff(traj.total_energy)
    assert np.all(gain > 0.0)
    assert traj.total_energy[-1] > traj.total_energy[0] * (1 + 5e-5)  # measured +8e-5 over 2 s


@pytest.mark.parametrize(("integrator", "order"), [("euler", 1), ("symplectic", 1), ("midpoint", 2), ("rk4", 4)])
def test_integrators_converge_at_their_order(integrator, order):
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    w0 = np.array([0.4, 1.0, -0.6])
    t_end = 1.0
    q_ref, w_ref = full_state_reference(t_end, q0, w0)
    errors = []
    for dt in (1e-2, 5e-3, 2.5e-3):
        world, body = tumbling_world(integrator, omega=w0)
        world.simulate(t_end, dt, record_every=round(t_end / dt))
        errors.append(np.linalg.norm(body.angular_velocity - w_ref))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    # Halving dt divides the error by ≈ 2^order; measured ≈ 2.0 / 2.0 / 4.0 / 16.0.
    np.testing.assert_allclose(ratios, 2.0**order, rtol=0.15)


def test_force_at_a_point_changes_both_momenta_by_force_times_dt():
    for integrator in INTEGRATORS:
        world = tumble.World(gravity=(0, 0, 0), integrator=integrator)
        body = world.add_body(tumble.Box((1.0, 0.5, 0.2)), mass=2.0, position=(1.0, 2.0, 3.0))
        force, point, dt = np.array([0.0, 3.0, 1.0]), np.array([1.5, 2.0, 3.1]), 1e-3
        body.apply_force(force, point=point)
        world.step(dt)
        np.testing.assert_allclose(body.linear_momentum, force * dt, rtol=1e-12, atol=1e-15)
        expected_L = np.cross(point - np.array([1.0, 2.0, 3.0]), force) * dt
        # Exact for the momentum integrators; semi-implicit Euler carries the new body-frame spin with the new
        # orientation, which turns L by the step's rotation angle h|ω| (measured 1.4e-5 relative here).
        rtol = 1e-4 if integrator == "symplectic" else 1e-12
        np.testing.assert_allclose(body.angular_momentum, expected_L, rtol=rtol, atol=1e-15)
        # The force acted for one step only.
        v1 = body.velocity
        world.step(dt)
        np.testing.assert_allclose(body.velocity, v1, rtol=0, atol=1e-15)


def test_apply_torque_spins_up_at_tau_over_i():
    world = tumble.World(gravity=(0, 0, 0), integrator="rk4")
    body = world.add_body(None, mass=1.0, inertia=np.diag([2.0, 3.0, 4.0]))
    body.apply_torque((0.0, 0.0, 8.0))
    world.step(0.5)
    np.testing.assert_allclose(body.angular_velocity, [0.0, 0.0, 1.0], atol=1e-14)


def test_impulse_at_a_point_changes_velocity_and_spin_at_once():
    world = tumble.World(gravity=(0, 0, 0))
    body = world.add_body(tumble.Sphere(0.5), mass=4.0)
    impulse, point = np.array([2.0, 0.0, 0.0]), np.array([0.0, 0.0, 0.5])
    body.apply_impulse(impulse, point=point)
    np.testing.assert_allclose(body.velocity, impulse / 4.0, rtol=1e-15)
    np.testing.assert_allclose(body.angular_momentum, np.cross(point, impulse), rtol=1e-12)
    np.testing.assert_allclose(world.angular_momentum(), np.cross(point, impulse), rtol=1e-12)


def test_projectile_is_exact_for_rk4_and_midpoint_and_matches_the_discrete_euler_solutions():
    g = np.array([0.0, 0.0, -9.81])
    x0, v0, h, n = np.array([0.0, 0.0, 1.0]), np.array([3.0, 1.0, 8.0]), 1e-2, 150
    t = n * h
    for exact in (
        "rk4",
        "midpoint",
    ):  # RK4 and the kick-drift-kick midpoint integrate a constant force exactly
        world = tumble.World(integrator=exact)
        body = world.add_body(tumble.Sphere(0.1), mass=1.0, position=x0, velocity=v0)
        world.simulate(n * h, h)
        np.testing.assert_allclose(body.position, x0 + v0 * t + 0.5 * g * t**2, rtol=0, atol=1e-12)
        np.testing.assert_allclose(body.velocity, v0 + g * t, rtol=0, atol=1e-12)
    # Semi-implicit Euler: v_k = v0 + k h g, x_n = x0 + n h v0 + h² g n (n + 1) / 2.
    world = tumble.World(integrator="symplectic")
    body = world.add_body(tumble.Sphere(0.1), mass=1.0, position=x0, velocity=v0)
    world.simulate(n * h, h)
    np.testing.assert_allclose(body.position, x0 + n * h * v0 + h * h * g * n * (n + 1) / 2, atol=1e-12)
    # Explicit Euler: x_n = x0 + n h v0 + h² g n (n − 1) / 2.
    world = tumble.World(integrator="euler")
    body = world.add_body(tumble.Sphere(0.1), mass=1.0, position=x0, velocity=v0)
    world.simulate(n * h, h)
    np.testing.assert_allclose(body.position, x0 + n * h * v0 + h * h * g * n * (n - 1) / 2, atol=1e-12)


def test_projectile_energy_is_conserved_by_rk4():
    world = tumble.World()
    world.add_body(tumble.Box((0.2, 0.3, 0.4)), density=500.0, velocity=(1, 2, 10), angular_velocity=(3, -1, 2))
    traj = world.simulate(2.0, 1e-3, record_every=50)
    e = traj.total_energy
    assert np.max(np.abs(e - e[0])) / abs(e[0]) < 1e-9  # measured ~1e-12


@pytest.mark.parametrize(
    ("integrator", "rtol"), [("rk4", 1e-10), ("midpoint", 2e-3), ("symplectic", 2e-3), ("euler", 2e-3)]
)
def test_linear_damping_decays_velocity_exponentially(integrator, rtol):
    world = tumble.World(gravity=(0, 0, 0), integrator=integrator)
    body = world.add_body(tumble.Sphere(0.1), mass=1.0, velocity=(2.0, 0.0, 0.0), linear_damping=0.5)
    world.simulate(2.0, 1e-3)
    np.testing.assert_allclose(body.velocity[0], 2.0 * np.exp(-1.0), rtol=rtol)


def test_angular_damping_decays_spin_of_a_sphere():
    world = tumble.World(gravity=(0, 0, 0), integrator="rk4")
    body = world.add_body(tumble.Sphere(0.1), mass=1.0, angular_velocity=(0, 0, 10.0), angular_damping=2.0)
    world.simulate(1.0, 1e-3)
    np.testing.assert_allclose(body.angular_velocity[2], 10.0 * np.exp(-2.0), rtol=1e-10)


def test_offset_shape_spins_about_its_centre_of_mass():
    """A sphere placed 1 m from the body origin: the COM stays put, the origin circles it."""
    world = tumble.World(gravity=(0, 0, 0))
    body = world.add_body([(tumble.Sphere(0.2), (1.0, 0.0, 0.0))], mass=1.0, angular_velocity=(0, 0, np.pi))
    np.testing.assert_allclose(body.center_of_mass, [1.0, 0.0, 0.0])
    world.simulate(1.0, 1e-3)  # half a turn
    np.testing.assert_allclose(body.center_of_mass, [1.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(body.position, [2.0, 0.0, 0.0], atol=1e-9)
