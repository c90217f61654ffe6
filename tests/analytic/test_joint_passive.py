"""An articulation's joint armature and springs against closed-form motions (MuJoCo's models use both; the
comparisons with MuJoCo are in tests/peers/test_mjcf_models.py).

Armature ``a`` adds to a degree of freedom's inertia (the reflected inertia of a motor's rotor): a pendulum of
moment ``I`` about its hinge swings with ``ω² = m g l / (I + a)``. A spring ``k`` on a slide carrying ``m`` makes
``ω² = k / (m + a)`` about ``springref``; its energy ``½ k (q - q_ref)²`` and the rotor's ``½ a q̇²`` count in the
articulation's energies.
"""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble.articulation import Articulation, Ball, Prismatic, Revolute


def slider(mass=2.0, armature=0.5, stiffness=30.0, springref=0.2) -> Articulation:
    art = Articulation(gravity=(0.0, 0.0, 0.0))
    art.add_link(Prismatic((1, 0, 0)), mass=mass, armature=armature, stiffness=stiffness, springref=springref)
    return art


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_a_spring_on_a_slide_oscillates_at_the_rate_of_its_mass_and_armature(dt):
    art = slider()
    art.q = [0.5]
    omega = np.sqrt(30.0 / 2.5)
    trajectory = art.simulate(3.0, dt, integrator="rk4")
    exact = 0.2 + 0.3 * np.cos(omega * trajectory.time)
    # RK4's global error ~ (ω dt)⁴ ω t: 2e-11 at 1 ms, 2e-7 at 10 ms (3 s, ω = 3.5 rad/s)
    np.testing.assert_allclose(trajectory.q[:, 0], exact, rtol=0, atol=20 * (omega * dt) ** 4)
    energy = trajectory.energy  # ½ (m + a) q̇² + ½ k (q - q_ref)², constant
    np.testing.assert_allclose(energy, 0.5 * 30.0 * 0.3**2, rtol=20 * (omega * dt) ** 4)


def test_armature_slows_a_pendulum_as_added_inertia_about_its_hinge():
    length, mass, armature = 0.8, 1.5, 0.4
    art = Articulation(gravity=(0.0, 0.0, -9.81))
    art.add_link(Revolute((0, 1, 0)), mass=mass, shape_position=(0.0, 0.0, -length), armature=armature)
    inertia = mass * length**2 + armature
    np.testing.assert_allclose(art.mass_matrix([0.3]), [[inertia]], rtol=1e-15)
    art.q = [1e-3]  # small swings: a harmonic oscillator
    trajectory = art.simulate(4.0, 1e-3, integrator="rk4")
    expected = 1e-3 * np.cos(np.sqrt(mass * 9.81 * length / inertia) * trajectory.time)
    np.testing.assert_allclose(trajectory.q[:, 0], expected, rtol=0, atol=1e-9)  # the pendulum's cubic term: 4e-10


def test_inverse_dynamics_inverts_forward_dynamics_with_armature_damping_and_springs():
    art = Articulation(gravity=(0.1, -0.2, -9.81))
    a = art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0.3, 0, 0), armature=0.2, damping=0.3,
                     stiffness=4.0, springref=0.1)  # fmt: skip
    b = art.add_link(Ball(), parent=a, position=(0.3, 0, 0), mass=0.5, shape_position=(0, 0, -0.2), armature=0.05)
    art.add_link(Prismatic((0, 0, 1)), parent=b, mass=0.3, shape_position=(0.1, 0, 0), armature=0.1, stiffness=8.0,
                 springref=-0.05, damping=0.2)  # fmt: skip
    rng = np.random.default_rng(3)
    q = np.concatenate([[0.4], rng.normal(size=4), [0.07]])
    q[1:5] /= np.linalg.norm(q[1:5])
    qd, tau = rng.normal(size=art.nv), rng.normal(size=art.nv)
    qdd = art.forward_dynamics(q, qd, tau)
    np.testing.assert_allclose(art.inverse_dynamics(q, qd, qdd), tau, rtol=0, atol=1e-12)
    # H q̈ + bias = τ, with the armature on H's diagonal and the springs in the bias
    np.testing.assert_allclose(art.mass_matrix(q) @ qdd + art.bias_forces(q, qd), tau, rtol=0, atol=1e-12)
    free = Articulation(gravity=(0.1, -0.2, -9.81))  # the same tree without them
    for link in art.links:
        free.add_link(link.joint, parent=link.parent, position=link.position, orientation=link.orientation,
                      mass_properties=link.mass_properties, damping=link.damping)  # fmt: skip
    np.testing.assert_allclose(art.mass_matrix(q) - free.mass_matrix(q), np.diag([0.2, 0.05, 0.05, 0.05, 0.1]),
                               rtol=0, atol=1e-15)  # fmt: skip
    springs = np.array([4.0 * (0.4 - 0.1), 0, 0, 0, 8.0 * (0.07 + 0.05)])
    np.testing.assert_allclose(art.bias_forces(q, qd) - free.bias_forces(q, qd), springs, rtol=0, atol=1e-13)


@pytest.mark.parametrize(
    ("joint", "options", "match"),
    [
        (Ball(), {"stiffness": 1.0}, r"stiffness=1.0 needs a Revolute or Prismatic joint"),
        (Revolute((0, 0, 1)), {"armature": -1.0}, r"armature must be >= 0"),
        (Revolute((0, 0, 1)), {"stiffness": float("nan")}, r"stiffness"),
        (Revolute((0, 0, 1)), {"springref": float("inf")}, r"springref"),
    ],
)
def test_bad_armature_and_springs_are_refused_by_name(joint, options, match):
    with pytest.raises(ValueError, match=match):
        Articulation().add_link(joint, mass=1.0, **options)


def test_a_world_refuses_an_articulation_with_armature_or_springs():
    world = tumble.World()
    with pytest.raises(ValueError, match=r"link 0 has joint armature 0.5: world joints have none"):
        world.add_articulation(slider(armature=0.5, stiffness=0.0))
