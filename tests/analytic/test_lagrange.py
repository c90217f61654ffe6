"""tumble.lagrange against textbook mechanics: Lagrange's equations, periods, energy, constraints, statics.

The closed forms come from the course deck ``course/004_…`` (pendulum, particle in a vertical plane,
slider–crank, virtual work) and standard texts (Atwood machine, bead on a rotating hoop, the two-link
mass matrix of Spong, Hutchinson & Vidyasagar, "Robot Modeling and Control", §7.4).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import sympy as sp
from scipy.special import ellipk

import tumble
from tumble import lagrange

t = lagrange.dynamicsymbols._t
m, g, l, k, b = sp.symbols("m g l k b", positive=True)
EARTH = {"m": 1.3, "g": 9.81, "l": 0.8}


def is_zero(expression) -> bool:
    """True when SymPy simplifies the expression (or every entry of a matrix) to zero."""
    if isinstance(expression, sp.MatrixBase):
        return all(sp.simplify(entry) == 0 for entry in expression)
    return sp.simplify(expression) == 0


@pytest.fixture(scope="module")
def pendulum():
    """A simple pendulum in the x–z plane from its Lagrangian (course: L = ½ m l² θ̇² + m g l cos θ)."""
    theta = lagrange.dynamicsymbols("theta")
    L = m * l**2 * theta.diff() ** 2 / 2 + m * g * l * sp.cos(theta)
    return lagrange.System(theta, L, parameters=EARTH)


@pytest.fixture(scope="module")
def double_pendulum_bodies():
    """Two uniform bars (tumble box mass properties) on revolute joints about y, relative angles."""
    q1, q2 = lagrange.dynamicsymbols("q1 q2")
    bar1 = tumble.mass.box((0.04, 0.06, 1.0), mass=2.0).transformed(translation=(0, 0, -0.5))
    bar2 = tumble.mass.box((0.05, 0.05, 0.8), mass=1.5).transformed(translation=(0, 0, -0.4))
    link1 = lagrange.RigidBody(bar1, (0, 0, 0), lagrange.rotation_y(q1))
    link2 = lagrange.RigidBody(bar2, link1.rotation * sp.Matrix([0, 0, -1.0]), lagrange.rotation_y(q1 + q2))
    return lagrange.System.from_bodies([q1, q2], [link1, link2]), (bar1, bar2)


# --- Lagrange's equations: the textbook forms -------------------------------------------------------


def test_pendulum_lagrangian_yields_the_course_equation(pendulum):
    theta = pendulum.coordinates[0]
    (equation,) = pendulum.equations
    assert is_zero(equation / (m * l**2) - (theta.diff(t, 2) + g / l * sp.sin(theta)))
    assert is_zero(pendulum.accelerations()[0] + g / l * sp.sin(theta))
    assert is_zero(pendulum.mass_matrix[0, 0] - m * l**2)


def test_particle_in_a_vertical_plane_falls_freely():
    x, y = lagrange.dynamicsymbols("x y")
    particle = lagrange.Particle(m, (x, 0, y))
    system = lagrange.System.from_bodies([x, y], [particle], gravity=(0, 0, -g))
    assert list(system.accelerations()) == [0, -g]
    assert is_zero(system.lagrangian - (m * (x.diff() ** 2 + y.diff() ** 2) / 2 - m * g * y))


def test_atwood_machine_accelerates_at_the_mass_ratio():
    x = lagrange.dynamicsymbols("x")
    m1, m2 = sp.symbols("m1 m2", positive=True)
    rope = [lagrange.Particle(m1, (0, 0, -x)), lagrange.Particle(m2, (1, 0, x))]  # x: how far m1 went down
    system = lagrange.System.from_bodies(x, rope, gravity=(0, 0, -g))
    assert is_zero(system.accelerations()[0] - (m1 - m2) * g / (m1 + m2))


@pytest.fixture(scope="module")
def hoop():
    """A bead on a hoop of radius R spinning at a fixed rate w about the vertical (a rheonomic system)."""
    theta = lagrange.dynamicsymbols("theta")
    R, w = sp.symbols("R w", positive=True)
    bead = lagrange.Particle(
        m, (R * sp.sin(theta) * sp.cos(w * t), R * sp.sin(theta) * sp.sin(w * t), -R * sp.cos(theta))
    )
    return lagrange.System.from_bodies(theta, [bead], gravity=(0, 0, -g)), (R, w)


def test_bead_on_rotating_hoop_equation(hoop):
    system, (R, w) = hoop
    theta = system.coordinates[0]
    textbook = m * R**2 * theta.diff(t, 2) - m * R**2 * w**2 * sp.sin(theta) * sp.cos(theta) + m * g * R * sp.sin(theta)
    assert is_zero(system.equations[0] - textbook)


def test_bead_on_rotating_hoop_rests_off_the_bottom_when_fast(hoop):
    system, _ = hoop
    values = {"m": 0.1, "g": 9.81, "R": 0.5, "w": 7.0}  # w² = 49 > g/R = 19.6
    (angle,) = system.equilibrium([1.0], values)  # θ = 0 is an (unstable) equilibrium too
    assert np.cos(angle) == pytest.approx(9.81 / (49.0 * 0.5), rel=1e-10)


def test_damped_spring_with_a_generalised_force():
    x = lagrange.dynamicsymbols("x")
    L = m * x.diff() ** 2 / 2 - k * x**2 / 2
    system = lagrange.System(x, L, forces=[-b * x.diff()])
    assert is_zero(system.equations[0] - (m * x.diff(t, 2) + b * x.diff() + k * x))
    # numerically: the amplitude decays as exp(-b t / 2m)
    motion = system.simulate([1.0], [0.0], (0.0, 4.0), parameters={"m": 1.0, "k": 40.0, "b": 0.3}, t_eval=[4.0])
    wd = np.sqrt(40.0 - 0.15**2)
    exact = np.exp(-0.15 * 4.0) * (np.cos(wd * 4.0) + 0.15 / wd * np.sin(wd * 4.0))
    assert motion.q[-1, 0] == pytest.approx(exact, abs=1e-9)  # measured 3e-11


def test_compound_pendulum_from_tumble_mass_properties():
    theta = lagrange.dynamicsymbols("theta")
    bar = tumble.Box((0.1, 0.05, 1.2)).mass_properties(mass=3.0).transformed(translation=(0, 0, -0.6))
    system = lagrange.System.from_bodies(theta, [lagrange.RigidBody(bar, (0, 0, 0), lagrange.rotation_y(theta))])
    pivot_moment = bar.inertia_about((0, 0, 0))[1, 1]
    rate = 3.0 * 9.81 * 0.6 / pivot_moment  # m g d / I_pivot
    acceleration = sp.lambdify(theta, system.accelerations()[0])
    for angle in np.linspace(-3.0, 3.0, 7):
        assert acceleration(angle) == pytest.approx(-rate * np.sin(angle), rel=1e-12, abs=1e-12)


def test_shape_with_mass_is_a_rigid_body():
    theta = lagrange.dynamicsymbols("theta")
    disc = lagrange.RigidBody(tumble.Cylinder(0.2, 0.05), (0, 0, 0), lagrange.rotation_z(theta), mass=2.0)
    system = lagrange.System.from_bodies(theta, [disc])
    assert float(system.mass_matrix[0, 0]) == pytest.approx(0.5 * 2.0 * 0.2**2, rel=1e-12)


# --- numerics ---------------------------------------------------------------------------------------


def test_pendulum_released_at_90_degrees_has_the_elliptic_period(pendulum):
    def through_bottom(time, q, qd):
        return q[0]

    motion = pendulum.simulate([np.pi / 2], [0.0], (0.0, 4.0), events=[through_bottom])
    crossings = motion.t_events[0]
    assert crossings.size >= 2
    period = 2.0 * (crossings[1] - crossings[0])
    exact = 4.0 * np.sqrt(0.8 / 9.81) * ellipk(np.sin(np.pi / 4) ** 2)
    assert period == pytest.approx(exact, rel=1e-5)
    assert abs(period / exact - 1.0) < 1e-9  # measured 2e-12 with DOP853 at rtol 1e-10


def test_double_pendulum_mass_matrix_matches_the_hand_derivation():
    q1, q2 = lagrange.dynamicsymbols("q1 q2")
    m1, m2, l1, c1, c2, I1, I2 = sp.symbols("m1 m2 l1 c1 c2 I1 I2", positive=True)
    link1 = lagrange.RigidBody.symbolic(m1, (0, I1, 0), (0, 0, 0), lagrange.rotation_y(q1), com=(0, 0, -c1))
    elbow = link1.rotation * sp.Matrix([0, 0, -l1])
    link2 = lagrange.RigidBody.symbolic(m2, (0, I2, 0), elbow, lagrange.rotation_y(q1 + q2), com=(0, 0, -c2))
    M = lagrange.System.from_bodies([q1, q2], [link1, link2], gravity=(0, 0, -g)).mass_matrix
    # Spong et al. §7.4, relative angles
    M11 = m1 * c1**2 + m2 * (l1**2 + c2**2 + 2 * l1 * c2 * sp.cos(q2)) + I1 + I2
    M12 = m2 * (c2**2 + l1 * c2 * sp.cos(q2)) + I2
    M22 = m2 * c2**2 + I2
    assert is_zero(M - sp.Matrix([[M11, M12], [M12, M22]]))


def test_double_pendulum_from_mass_properties_numerically(double_pendulum_bodies):
    system, (bar1, bar2) = double_pendulum_bodies
    numeric = system.lambdify()
    I1, I2 = bar1.inertia[1, 1], bar2.inertia[1, 1]
    for q2 in (0.0, 0.7, 2.5):
        M11 = I1 + I2 + 2.0 * 0.5**2 + 1.5 * (1.0 + 0.4**2 + 2 * 0.4 * np.cos(q2))
        M12 = I2 + 1.5 * (0.4**2 + 0.4 * np.cos(q2))
        M22 = I2 + 1.5 * 0.4**2
        expected = np.array([[M11, M12], [M12, M22]])
        np.testing.assert_allclose(numeric.mass_matrix([0.3, q2]), expected, rtol=1e-13)


def test_double_pendulum_conserves_energy(double_pendulum_bodies):
    system, _ = double_pendulum_bodies
    motion = system.simulate([1.2, -0.4], [0.0, 2.0], (0.0, 5.0))
    drift = np.max(np.abs(motion.energy / motion.energy[0] - 1.0))
    assert drift < 1e-8  # measured 1.2e-11
    assert motion.energy[0] == pytest.approx(system.energy([1.2, -0.4], [0.0, 2.0]))


def test_cartesian_pendulum_matches_the_angle_pendulum_and_its_multiplier_is_the_tension(pendulum):
    x, z = lagrange.dynamicsymbols("x z")
    L = m * (x.diff() ** 2 + z.diff() ** 2) / 2 - m * g * z
    rod = (x**2 + z**2 - l**2) / 2  # with this scaling λ = tension / l
    cartesian = lagrange.System([x, z], L, constraints=[rod], parameters=EARTH)
    theta0, omega0 = 1.1, -0.5
    start = [0.8 * np.sin(theta0), -0.8 * np.cos(theta0)]
    start_rate = [0.8 * np.cos(theta0) * omega0, 0.8 * np.sin(theta0) * omega0]
    times = np.linspace(0.0, 3.0, 31)
    motion = cartesian.simulate(start, start_rate, (0.0, 3.0), t_eval=times)
    reference = pendulum.simulate([theta0], [omega0], (0.0, 3.0), t_eval=times)
    theta, omega = reference.q[:, 0], reference.qd[:, 0]
    np.testing.assert_allclose(motion.q[:, 0], 0.8 * np.sin(theta), atol=1e-8)  # measured 8e-11
    np.testing.assert_allclose(motion.q[:, 1], -0.8 * np.cos(theta), atol=1e-8)
    assert motion.max_constraint_residual < 1e-9  # measured 4e-11 with Baumgarte (5, 5)
    tension = 1.3 * (9.81 * np.cos(theta) + 0.8 * omega**2)
    np.testing.assert_allclose(motion.multipliers[:, 0], tension / 0.8, rtol=1e-7)  # measured 5e-10


def test_constrained_accelerations_eliminate_the_multiplier():
    x, z = lagrange.dynamicsymbols("x z")
    L = m * (x.diff() ** 2 + z.diff() ** 2) / 2 - m * g * z
    system = lagrange.System([x, z], L, constraints=[(x**2 + z**2 - l**2) / 2])
    (lam,) = system.multiplier_expressions()
    speed2 = x.diff() ** 2 + z.diff() ** 2
    on_circle = {x**2: l**2 - z**2}
    assert is_zero((lam - m * (speed2 - g * z) / l**2).subs(on_circle))
    assert system.mass_matrix_full.shape == (5, 5)
    assert system.forcing_full.shape == (5, 1)
    assert list(system.constraint_jacobian) == [x, z]


# --- statics by virtual work --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def slider_crank():
    """Crank r at angle θ, rod l, piston at x(θ) = r cos θ + √(l² - r² sin² θ) pulled by F along +x."""
    theta = lagrange.dynamicsymbols("theta")
    r, rod, F, tau = sp.symbols("r l F tau", positive=True)
    piston = r * sp.cos(theta) + sp.sqrt(rod**2 - r**2 * sp.sin(theta) ** 2)
    loads = [lagrange.Force((piston, 0, 0), (F, 0, 0)), lagrange.Torque(lagrange.rotation_z(theta), (0, 0, tau))]
    return lagrange.System(theta, sp.S(0), forces=loads), (r, rod, F, tau)


def crank_torque(theta, r=0.1, rod=0.35, F=250.0):
    """τ = F r sin θ (1 + r cos θ / √(l² - r² sin² θ)) (the virtual-work balance δW = τ δθ + F δx = 0)."""
    return F * r * np.sin(theta) * (1.0 + r * np.cos(theta) / np.sqrt(rod**2 - r**2 * np.sin(theta) ** 2))


def test_slider_crank_balancing_torque_by_virtual_work(slider_crank):
    system, (r, rod, F, tau) = slider_crank
    values = {"r": 0.1, "l": 0.35, "F": 250.0}
    for angle in np.linspace(-3.0, 3.0, 9):
        found = system.balancing(tau, [angle], values)[tau]
        assert found == pytest.approx(crank_torque(angle), rel=1e-12, abs=1e-12)
    expression = system.balancing_expressions(tau)[tau].subs({r: 0.1, rod: 0.35, F: 250.0})
    at = sp.lambdify(system.coordinates[0], expression)
    for angle in (-2.0, 0.3, 1.3):
        assert at(angle) == pytest.approx(crank_torque(angle), rel=1e-12)


def test_slider_crank_in_constrained_coordinates_needs_the_same_torque():
    theta, phi, x = lagrange.dynamicsymbols("theta phi x")
    r, rod, F, tau = sp.symbols("r l F tau", positive=True)
    loop = [r * sp.cos(theta) + rod * sp.cos(phi) - x, r * sp.sin(theta) - rod * sp.sin(phi)]
    loads = [lagrange.Force((x, 0, 0), (F, 0, 0)), lagrange.Torque(lagrange.rotation_z(theta), (0, 0, tau))]
    system = lagrange.System([theta, phi, x], sp.S(0), forces=loads, constraints=loop)
    values = {"r": 0.1, "l": 0.35, "F": 250.0}
    for angle in (0.4, 1.7, 2.9):
        rod_angle = np.arcsin(0.1 * np.sin(angle) / 0.35)
        q = [angle, rod_angle, 0.1 * np.cos(angle) + 0.35 * np.cos(rod_angle)]
        assert system.balancing(tau, q, values)[tau] == pytest.approx(crank_torque(angle), rel=1e-12)
    # the classic closed form τ = F r sin(θ + φ) / cos φ
    assert is_zero(system.balancing_expressions(tau)[tau] - F * r * sp.sin(theta + phi) / sp.cos(phi))


def test_pendulum_under_a_horizontal_force_rests_at_tan_theta_p_over_mg():
    theta = lagrange.dynamicsymbols("theta")
    P = sp.Symbol("P")
    bob = lagrange.Particle(m, (l * sp.sin(theta), 0, -l * sp.cos(theta)))
    system = lagrange.System.from_bodies(theta, [bob], gravity=(0, 0, -g))
    push = [lagrange.Force(bob.position, (P, 0, 0))]
    # δW = (-m g l sin θ + P l cos θ) δθ (course: δW = -m g l sin θ δθ without P)
    assert is_zero(system.generalized_forces(push)[0] - (-m * g * l * sp.sin(theta) + P * l * sp.cos(theta)))
    for force in (0.5, 5.0, -12.0):
        (angle,) = system.equilibrium([0.0], {**EARTH, "P": force}, applied=push)
        assert np.tan(angle) == pytest.approx(force / (1.3 * 9.81), rel=1e-12)


def test_spring_mass_hangs_at_mg_over_k():
    y = lagrange.dynamicsymbols("y")
    rest = sp.Symbol("y0")
    L = m * y.diff() ** 2 / 2 - (k * (y - rest) ** 2 / 2 + m * g * y)
    system = lagrange.System(y, L, parameters={"m": 2.0, "g": 9.81, "k": 150.0, "y0": 1.0})
    (height,) = system.equilibrium([0.0])
    assert height == pytest.approx(1.0 - 2.0 * 9.81 / 150.0, rel=1e-13)


def test_constrained_equilibrium_of_a_cartesian_pendulum_under_a_side_force():
    x, z = lagrange.dynamicsymbols("x z")
    P = sp.Symbol("P")
    L = m * (x.diff() ** 2 + z.diff() ** 2) / 2 - m * g * z
    system = lagrange.System([x, z], L, forces=[P, 0], constraints=[(x**2 + z**2 - l**2) / 2])
    qx, qz = system.equilibrium([0.1, -0.7], {**EARTH, "P": 4.0})
    assert np.arctan2(qx, -qz) == pytest.approx(np.arctan(4.0 / (1.3 * 9.81)), rel=1e-12)
    assert np.hypot(qx, qz) == pytest.approx(0.8, rel=1e-13)


def test_loads_reach_lagranges_method_with_their_virtual_work():
    """The forcelist route (SymPy partial velocities) and the virtual-work route (∂r/∂q) agree."""
    q1, q2 = lagrange.dynamicsymbols("q1 q2")
    Fx, Fz, T = sp.symbols("Fx Fz T")
    R = lagrange.rotation_y(q1) * lagrange.rotation_y(q2)
    tip = lagrange.rotation_y(q1) * sp.Matrix([0, 0, -l]) + R * sp.Matrix([0, 0, -l])
    loads = [lagrange.Force(tip, (Fx, 0, Fz)), lagrange.Torque(R, (0, T, 0))]
    system = lagrange.System([q1, q2], sp.S(0), forces=loads)
    assert is_zero(system.forcing - lagrange.virtual_work([q1, q2], loads))
    assert is_zero(lagrange.virtual_work([q1, q2], loads[1:]) - sp.Matrix([T, T]))


# --- the articulation bridge --------------------------------------------------------------------------


class Revolute:  # a stand-in with the public shape of tumble.articulation.Revolute
    def __init__(self, axis):
        self.axis = np.asarray(axis, dtype=float)


class Fixed:
    axis = None


def chain(joint_types, *, gravity=(0.0, 0.0, -9.81)):
    """A two-bar pendulum hanging along -z, hinged about y, as an articulation's public description."""
    revolute, fixed = joint_types
    bar1 = tumble.mass.box((0.04, 0.06, 1.0), mass=2.0).transformed(translation=(0, 0, -0.5))
    bar2 = tumble.mass.box((0.05, 0.05, 0.8), mass=1.5).transformed(translation=(0, 0, -0.4))
    tip = tumble.mass.solid_sphere(0.05, mass=0.3)
    identity = np.array([1.0, 0.0, 0.0, 0.0])

    def link(index, name, parent, joint, position, mass_properties):
        return SimpleNamespace(
            index=index, name=name, parent=parent, joint=joint, position=np.asarray(position, dtype=float),
            orientation=identity, mass_properties=mass_properties,
        )  # fmt: skip

    links = [
        link(0, "shoulder", None, revolute(axis=np.array([0.0, 1.0, 0.0])), (0, 0, 0), bar1),
        link(1, "elbow", 0, revolute(axis=np.array([0.0, 1.0, 0.0])), (0, 0, -1.0), bar2),
        link(2, "weight", 1, fixed(), (0, 0, -0.8), tip),
    ]
    return SimpleNamespace(
        links=links, gravity=np.asarray(gravity), base_position=np.zeros(3), base_orientation=identity
    )


def check_chain_mass_matrix(system, reference) -> None:
    """The chain's M is the two bars' (from_bodies) plus the fixed tip weight, a link with c = 0.8."""
    tip_inertia = 2.0 / 5.0 * 0.3 * 0.05**2  # about y; the tip turns at q̇1 + q̇2, so it adds to all four
    ours, theirs = system.lambdify(), reference.lambdify()
    for q1, q2 in ((0.2, 0.0), (-1.0, 1.1), (2.0, -2.4)):
        tip = 0.3 * np.array([[1.0 + 0.64 + 1.6 * np.cos(q2), 0.64 + 0.8 * np.cos(q2)], [0.0, 0.64]])
        tip[1, 0] = tip[0, 1]
        expected = theirs.mass_matrix([q1, q2]) + tip + tip_inertia
        np.testing.assert_allclose(ours.mass_matrix([q1, q2]), expected, rtol=1e-12)
    # gravity: 2 kg at 0.5 m, 1.5 kg at 1.4 m and 0.3 kg at 1.8 m from the shoulder (q2 = 0)
    forcing = ours.forcing([0.3, 0.0], [0.0, 0.0])
    assert forcing[0] == pytest.approx(-9.81 * (1.0 + 2.1 + 0.54) * np.sin(0.3), rel=1e-12)


def test_from_articulation_matches_from_bodies(double_pendulum_bodies):
    reference, _ = double_pendulum_bodies
    system = lagrange.from_articulation(chain((Revolute, Fixed)))
    assert [str(q.func) for q in system.coordinates] == ["shoulder", "elbow"]
    check_chain_mass_matrix(system, reference)


def agree_with_the_articulation(system, articulation, rng, samples=4) -> None:
    """M(q), f(q, q̇) = -bias (Coriolis, gravity, damping) and the energy, against CRBA / RNEA."""
    numeric = system.lambdify()
    n = len(system.coordinates)
    for _ in range(samples):
        q, qd = rng.uniform(-2.0, 2.0, n), rng.uniform(-3.0, 3.0, n)
        # measured: M to 8e-16, bias to 6e-15, energy to 2e-14, q̈ to 3e-14 (absolute)
        np.testing.assert_allclose(numeric.mass_matrix(q), articulation.mass_matrix(q), rtol=1e-11, atol=1e-12)
        bias = articulation.bias_forces(q, qd)
        np.testing.assert_allclose(numeric.forcing(q, qd), -bias, rtol=1e-10, atol=1e-10)
        assert numeric.energy(q, qd) == pytest.approx(articulation.energy(q, qd), rel=1e-11, abs=1e-11)
        qdd = articulation.forward_dynamics(q, qd)
        np.testing.assert_allclose(numeric.accelerations(q, qd), qdd, rtol=1e-9, atol=1e-10)


def test_from_articulation_agrees_with_the_articulation_solver(double_pendulum_bodies):
    module = pytest.importorskip("tumble.articulation")
    reference, (bar1, bar2) = double_pendulum_bodies
    art = module.Articulation()
    shoulder = art.add_link(module.Revolute((0, 1, 0)), mass_properties=bar1, name="shoulder")
    elbow = art.add_link(module.Revolute((0, 1, 0)), parent=shoulder, position=(0, 0, -1.0),
                         mass_properties=bar2, name="elbow", damping=0.25)  # fmt: skip
    art.add_link(module.Fixed(), parent=elbow, position=(0, 0, -0.8),
                 mass_properties=tumble.mass.solid_sphere(0.05, mass=0.3))  # fmt: skip
    system = lagrange.from_articulation(art)
    check_chain_mass_matrix(system, reference)
    agree_with_the_articulation(system, art, np.random.default_rng(4))


def test_from_articulation_of_a_turned_base_cart_and_pendulum():
    """Prismatic and revolute joints, turned link frames, a turned and raised base, joint damping."""
    module = pytest.importorskip("tumble.articulation")
    from tumble.rotation import quat_from_axis_angle

    art = module.Articulation(base_position=(0.2, -0.1, 1.0), base_orientation=quat_from_axis_angle((0, 0, 1), 0.6))
    cart = art.add_link(module.Prismatic((1, 0, 0)), orientation=quat_from_axis_angle((1, 1, 0), 0.3),
                        shape=tumble.Box((0.4, 0.2, 0.1)), mass=3.0, name="cart")  # fmt: skip
    art.add_link(module.Revolute((0, 1, 1)), parent=cart, position=(0.1, 0.0, 0.05),
                 orientation=quat_from_axis_angle((0, 0, 1), -0.4), mass=0.7, shape_position=(0.0, 0.3, -0.5),
                 damping=0.3, name="pole")  # fmt: skip
    system = lagrange.from_articulation(art)
    assert [str(q.func) for q in system.coordinates] == ["cart", "pole"]
    agree_with_the_articulation(system, art, np.random.default_rng(7))
