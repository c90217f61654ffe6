"""tumble.lagrange refuses bad input at the boundary with a message naming the argument and the value."""

from __future__ import annotations

import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest
import sympy as sp

import tumble
from tumble import lagrange

theta, phi = lagrange.dynamicsymbols("theta phi")
m, g, l = sp.symbols("m g l", positive=True)
PENDULUM_L = m * l**2 * theta.diff() ** 2 / 2 + m * g * l * sp.cos(theta)
VALUES = {"m": 1.0, "g": 9.81, "l": 1.0}


@pytest.fixture(scope="module")
def pendulum():
    return lagrange.System(theta, PENDULUM_L)


@pytest.fixture(scope="module")
def cartesian():
    x, z = lagrange.dynamicsymbols("x z")
    L = m * (x.diff() ** 2 + z.diff() ** 2) / 2 - m * g * z
    return lagrange.System([x, z], L, constraints=[(x**2 + z**2 - l**2) / 2], parameters=VALUES)


def test_import_tumble_does_not_import_sympy():
    # Nor SciPy's spatial and linalg (0.15 s): hulls, wind and the SciPy interop load them on first use (issue 23).
    code = (
        "import sys, tumble; heavy = [m for m in ('sympy', 'scipy.spatial', 'scipy.linalg') if m in sys.modules]; "
        "assert not heavy, f'import tumble imported {heavy}'"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr


# --- coordinates -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("coordinates", "error", "words"),
    [
        (1.0, TypeError, "got 1.0 (float)"),
        ([theta, 2], TypeError, "coordinates[1]"),
        ([sp.Symbol("x")], TypeError, "a Symbol is constant in time"),
        ("theta", TypeError, "got 'theta' (str)"),
        ([], ValueError, "at least one"),
        ([theta, theta], ValueError, "distinct"),
        ([sp.Function("y")(sp.Symbol("s"))], ValueError, "function of the time symbol t alone"),
    ],
)
def test_coordinates_must_be_distinct_functions_of_time(coordinates, error, words):
    with pytest.raises(error, match="coordinates") as raised:
        lagrange.System(coordinates, PENDULUM_L)
    assert words in str(raised.value)


def test_coordinates_may_not_look_like_sympy_multipliers():
    lam1 = lagrange.dynamicsymbols("lam1")
    with pytest.raises(ValueError, match="lam1"):
        lagrange.System([lam1, theta], PENDULUM_L + lam1.diff() ** 2, constraints=[lam1 - theta])


# --- the Lagrangian, forces and constraints ----------------------------------------------------------


@pytest.mark.parametrize("lagrangian", ["m*l**2", 3.0, [PENDULUM_L], sp.Matrix([PENDULUM_L]), None])
def test_lagrangian_must_be_a_sympy_expression(lagrangian):
    with pytest.raises(TypeError, match="lagrangian must be a scalar SymPy expression"):
        lagrange.System(theta, lagrangian)


def test_lagrangian_must_not_hold_accelerations():
    with pytest.raises(ValueError, match="lagrangian must not depend on accelerations"):
        lagrange.System(theta, PENDULUM_L + theta.diff(lagrange.dynamicsymbols._t, 2))


def test_generalised_forces_need_one_per_coordinate():
    with pytest.raises(ValueError, match=r"one generalised force per coordinate \(2\), got 1"):
        lagrange.System([theta, phi], PENDULUM_L + phi.diff() ** 2, forces=[sp.Symbol("tau")])


def test_forces_do_not_mix_generalised_forces_and_loads():
    load = lagrange.Force((theta, 0, 0), (1, 0, 0))
    with pytest.raises(TypeError, match="not a mix"):
        lagrange.System([theta, phi], PENDULUM_L + phi.diff() ** 2, forces=[load, 0])


@pytest.mark.parametrize("forces", ["tau", 3.0, [object()]])
def test_forces_of_the_wrong_type(forces):
    with pytest.raises(TypeError, match="forces"):
        lagrange.System(theta, PENDULUM_L, forces=forces)


def test_loads_need_three_components():
    with pytest.raises(ValueError, match=r"vector must have 3 entries, got 2"):
        lagrange.Force((theta, 0, 0), (1, 0))
    with pytest.raises(ValueError, match=r"rotation must be a 3x3 matrix"):
        lagrange.Torque(sp.eye(2), (0, 0, 1))


def test_constraints_must_be_holonomic_expressions_of_the_coordinates():
    with pytest.raises(ValueError, match=r"constraints\[0\] must be holonomic"):
        lagrange.System([theta, phi], PENDULUM_L, constraints=[theta.diff() - phi.diff()])
    with pytest.raises(ValueError, match=r"constraints\[0\] must involve at least one coordinate"):
        lagrange.System([theta, phi], PENDULUM_L, constraints=[l - 1])
    with pytest.raises(TypeError, match=r"constraints\[1\] must be a scalar SymPy expression, got 'x'"):
        lagrange.System([theta, phi], PENDULUM_L, constraints=[theta - phi, "x"])


def test_constraint_given_as_an_equation_is_accepted():
    system = lagrange.System([theta, phi], PENDULUM_L + phi.diff() ** 2, constraints=[sp.Eq(theta, 2 * phi)])
    assert system.constraints == (theta - 2 * phi,)


# --- bodies ------------------------------------------------------------------------------------------


def test_a_body_needs_mass_properties():
    with pytest.raises(TypeError, match="mass_properties must be a tumble MassProperties.*got None"):
        lagrange.RigidBody(None, (0, 0, 0))
    with pytest.raises(TypeError, match="exactly one of mass= or density="):
        lagrange.RigidBody(tumble.Box((1, 1, 1)), (0, 0, 0))


def test_bodies_must_be_particles_or_rigid_bodies():
    properties = tumble.mass.solid_sphere(0.1, mass=1.0)
    with pytest.raises(TypeError, match=r"bodies\[0\] must be a lagrange.Particle or lagrange.RigidBody.*wrap it"):
        lagrange.System.from_bodies(theta, [properties])
    with pytest.raises(ValueError, match="bodies must hold at least one"):
        lagrange.System.from_bodies(theta, [])


def test_particle_mass_and_position_are_checked():
    with pytest.raises(ValueError, match="mass must be > 0, got -1"):
        lagrange.Particle(-1.0, (theta, 0, 0))
    with pytest.raises(ValueError, match="position must have 3 entries, got 2"):
        lagrange.Particle(1.0, (theta, 0))
    with pytest.raises(TypeError, match=r"position\[1\] must be a real number or a SymPy expression, got 'y'"):
        lagrange.Particle(1.0, (theta, "y", 0))


def test_symbolic_inertia_must_be_symmetric():
    with pytest.raises(ValueError, match="inertia must be symmetric"):
        lagrange.RigidBody.symbolic(m, [[1, 2, 0], [0, 1, 0], [0, 0, 1]], (0, 0, 0))


# --- numerics ----------------------------------------------------------------------------------------


def test_lambdify_names_the_symbols_without_values(pendulum):
    with pytest.raises(ValueError, match="missing values for the symbols g, l"):
        pendulum.lambdify({"m": 1.0})


def test_lambdify_refuses_parameters_the_system_does_not_have(pendulum):
    with pytest.raises(ValueError, match="symbols the system does not have: L"):
        pendulum.lambdify({**VALUES, "L": 2.0})


@pytest.mark.parametrize(
    ("parameters", "error"), [([1.0], TypeError), ({"m": "one"}, TypeError), ({"m": np.nan}, ValueError)]
)
def test_parameter_values_are_numbers(pendulum, parameters, error):
    with pytest.raises(error, match="parameters"):
        pendulum.lambdify(parameters)


def test_unknown_function_of_time_is_named():
    tau = lagrange.dynamicsymbols("tau")
    system = lagrange.System(theta, PENDULUM_L, forces=[tau])
    with pytest.raises(ValueError, match=r"depends on tau\(t\), which is neither a coordinate nor its rate"):
        system.lambdify(VALUES)


def test_simulate_checks_the_start(pendulum):
    with pytest.raises(ValueError, match="q0 must have 1 entries"):
        pendulum.simulate([0.1, 0.2], [0.0], (0, 1), parameters=VALUES)
    with pytest.raises(ValueError, match="qd0 must be finite"):
        pendulum.simulate([0.1], [np.inf], (0, 1), parameters=VALUES)
    with pytest.raises(TypeError, match="t_span must be a pair"):
        pendulum.simulate([0.1], [0.0], 1.0, parameters=VALUES)
    with pytest.raises(ValueError, match="t_span must have t0 != t1"):
        pendulum.simulate([0.1], [0.0], (1.0, 1.0), parameters=VALUES)
    with pytest.raises(TypeError, match=r"events\[0\] must be a callable"):
        pendulum.simulate([0.1], [0.0], (0, 1), parameters=VALUES, events=[3])


def test_simulate_refuses_a_start_off_the_constraints(cartesian):
    with pytest.raises(ValueError, match=r"q0 violates constraint 0"):
        cartesian.simulate([0.5, -0.5], [0.0, 0.0], (0, 1))
    with pytest.raises(ValueError, match=r"qd0 violates constraint 0"):
        cartesian.simulate([0.6, -0.8], [1.0, 1.0], (0, 1))


def test_baumgarte_gains_are_non_negative(cartesian):
    with pytest.raises(ValueError, match="baumgarte must be >= 0"):
        cartesian.lambdify(baumgarte=(-1.0, 5.0))
    with pytest.raises(TypeError, match="baumgarte must be a pair"):
        cartesian.lambdify(baumgarte=5.0)


def test_a_coordinate_without_inertia_makes_a_singular_mass_matrix():
    system = lagrange.System([theta, phi], PENDULUM_L + phi**2)
    with pytest.raises(ValueError, match="mass matrix is singular"):
        system.simulate([0.1, 0.0], [0.0, 0.0], (0, 1), parameters=VALUES)


# --- statics -----------------------------------------------------------------------------------------


def test_balancing_unknowns_must_appear_and_must_not_be_given(pendulum):
    tau, other = sp.symbols("tau other")
    torque = [tau]
    with pytest.raises(ValueError, match="the unknown other does not appear"):
        pendulum.balancing(other, [0.3], VALUES, applied=torque)
    with pytest.raises(ValueError, match="parameters give a value to the unknown tau"):
        pendulum.balancing(tau, [0.3], {**VALUES, "tau": 1.0}, applied=torque)
    with pytest.raises(TypeError, match=r"unknowns\[0\] must be a SymPy Symbol, got 'tau'"):
        pendulum.balancing(["tau"], [0.3], VALUES, applied=torque)
    assert pendulum.balancing(tau, [0.3], VALUES, applied=torque)[tau] == pytest.approx(9.81 * np.sin(0.3))


def test_balancing_refuses_a_configuration_off_the_constraints(cartesian):
    P = sp.Symbol("P")
    with pytest.raises(ValueError, match="q violates constraint 0"):
        cartesian.balancing(P, [0.3, -0.3], applied=[P, 0])


def test_balancing_reports_loads_that_cannot_balance(cartesian):
    P = sp.Symbol("P")
    x, z = cartesian.coordinates
    # a push along the rod cannot hold a pendulum at an angle: the rod takes it all
    with pytest.raises(ValueError, match="no values of P balance the system"):
        cartesian.balancing(P, [0.6, -0.8], applied=[P * x, P * z])


def test_equilibrium_reports_when_there_is_none():
    x = lagrange.dynamicsymbols("x")
    system = lagrange.System(x, m * x.diff() ** 2 / 2 - g * x)  # a constant force: no rest anywhere
    with pytest.raises(ValueError, match="no static equilibrium found near guess"):
        system.equilibrium([0.0], {"m": 1.0, "g": 9.81})


# --- the articulation bridge -------------------------------------------------------------------------


class Ball:  # stand-in joint classes: the bridge reads the class name (tumble.articulation's names)
    pass


class Revolute:
    axis = np.array([0.0, 1.0, 0.0])


def fake(joints):
    links = [
        SimpleNamespace(index=i, name=f"link{i}", parent=None if i == 0 else i - 1, joint=joint,
                        position=np.zeros(3), orientation=np.array([1.0, 0, 0, 0]),
                        mass_properties=tumble.mass.solid_sphere(0.1, mass=1.0))
        for i, joint in enumerate(joints)
    ]  # fmt: skip
    return SimpleNamespace(links=links, gravity=np.array([0, 0, -9.81]), base_position=np.zeros(3),
                           base_orientation=np.array([1.0, 0, 0, 0]))  # fmt: skip


def test_from_articulation_refuses_ball_and_free_joints():
    with pytest.raises(NotImplementedError, match=r"link 1 \('link1'\) has a Ball joint"):
        lagrange.from_articulation(fake([Revolute(), Ball()]))


def test_from_articulation_needs_links_and_coordinates():
    with pytest.raises(TypeError, match="articulation must have links"):
        lagrange.from_articulation(object())
    with pytest.raises(ValueError, match="articulation has no links"):
        lagrange.from_articulation(fake([]))
    cyclic = fake([Revolute(), Revolute()])
    cyclic.links[0].parent = 1
    with pytest.raises(ValueError, match="cycle"):
        lagrange.from_articulation(cyclic)


def test_balancing_reports_unknowns_that_are_not_determined(pendulum):
    tau1, tau2 = sp.symbols("tau1 tau2")
    with pytest.raises(ValueError, match="not determined"):
        pendulum.balancing([tau1, tau2], [0.3], VALUES, applied=[tau1 + tau2])


@pytest.mark.parametrize("passive", [{"armature": 0.1}, {"stiffness": 2.0}])
def test_an_articulation_with_armature_or_springs_is_refused_by_name(passive):
    from tumble.articulation import Articulation, Revolute

    art = Articulation()
    art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0.0, 0.0, -1.0), name="arm", **passive)
    with pytest.raises(ValueError, match=r"link 0 \('arm'\) has joint armature or stiffness"):
        lagrange.from_articulation(art)


def test_an_articulation_with_actuators_is_refused():
    from tumble.articulation import Articulation, Revolute

    art = Articulation()
    art.add_actuator(art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0.0, 0.0, -1.0)), gear=2.0)
    with pytest.raises(ValueError, match=r"articulation has 1 actuators, which the symbolic derivation"):
        lagrange.from_articulation(art)


def test_an_articulation_with_limits_friction_or_tendons_is_refused():
    from tumble.articulation import Articulation, Revolute

    for link_settings in ({"limits": (-1.0, 1.0)}, {"frictionloss": 0.5}):
        art = Articulation()
        art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0.0, 0.0, -1.0), name="arm", **link_settings)
        with pytest.raises(ValueError, match=r"link 0 \('arm'\) has joint limits or frictionloss"):
            lagrange.from_articulation(art)
    art = Articulation()
    art.add_tendon([art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0.0, 0.0, -1.0))], [1.0])
    with pytest.raises(ValueError, match=r"articulation has 1 tendons, which the symbolic derivation"):
        lagrange.from_articulation(art)
