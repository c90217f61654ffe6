"""Articulations against MuJoCo: the same trees built in both, mass matrices and RK4 trajectories compared.

MuJoCo's coordinates are tumble's (hinge/slide angle or displacement, ball quaternion with the local angular
velocity, free joint position + quaternion with the world linear and local angular velocity), so ``qpos`` and
``qvel`` compare entry by entry. The MJCF is generated from the tumble links: body ``pos``/``quat`` = link
``position``/``orientation``, one joint at the body origin, ``inertial`` = the link's mass properties.
"""

from __future__ import annotations

import numpy as np
import pytest

from tumble.articulation import Articulation, Ball, Free, Prismatic, Revolute
from tumble.shapes import Box, Capsule

mujoco = pytest.importorskip("mujoco")
pytestmark = pytest.mark.peers


def _vec(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def _joint_xml(joint) -> str:
    if isinstance(joint, Revolute):
        return f'<joint type="hinge" axis="{_vec(joint.axis)}"/>'
    if isinstance(joint, Prismatic):
        return f'<joint type="slide" axis="{_vec(joint.axis)}"/>'
    if isinstance(joint, Ball):
        return '<joint type="ball"/>'
    if isinstance(joint, Free):
        return "<freejoint/>"
    return ""


def mjcf(art: Articulation, dt: float, integrator: str = "RK4") -> str:
    """The MJCF of ``art`` (no geometry, so no contacts), integrated by MuJoCo's ``integrator`` at ``dt``."""
    children = {}
    for link in art.links:
        children.setdefault(link.parent, []).append(link)

    def body(link) -> str:
        mp = link.mass_properties
        inertia = mp.inertia
        full = (inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2])
        inner = "".join(body(child) for child in children.get(link.index, []))
        return (
            f'<body name="l{link.index}" pos="{_vec(link.position)}" quat="{_vec(link.orientation)}">'
            f"{_joint_xml(link.joint)}"
            f'<inertial pos="{_vec(mp.com)}" mass="{mp.mass!r}" fullinertia="{_vec(full)}"/>{inner}</body>'
        )

    roots = "".join(body(link) for link in children.get(None, []))
    if np.any(art.base_position) or art.base_orientation[0] != 1.0:  # MuJoCo wants free joints at the top level
        roots = f'<body pos="{_vec(art.base_position)}" quat="{_vec(art.base_orientation)}">{roots}</body>'
    return (
        f'<mujoco><option timestep="{dt!r}" gravity="{_vec(art.gravity)}" integrator="{integrator}"/>'
        f"<worldbody>{roots}</worldbody></mujoco>"
    )


def double_pendulum() -> Articulation:
    """Two capsules of 1 m hanging from hinges about y, the second with its own hinge at the first's tip."""
    art = Articulation(base_position=(0.0, 0.0, 2.0))
    rod = Capsule(0.05, 0.9)
    down = (np.cos(np.pi / 4), 0.0, np.sin(np.pi / 4), 0.0)  # the capsule's z axis along the link's x
    first = art.add_link(Revolute((0, 1, 0)), shape=rod, mass=1.0, shape_position=(0.5, 0, 0), shape_orientation=down)
    art.add_link(Revolute((0, 1, 0)), parent=first, position=(1.0, 0, 0), shape=rod, mass=0.7,
                 shape_position=(0.5, 0, 0), shape_orientation=down)  # fmt: skip
    return art


def spatial_chain() -> Articulation:
    """Hinges about x, y, z and a skew axis, a slider and a ball, offsets and turned origins: a 3-D tree."""
    art = Articulation(gravity=(0.5, -0.3, -9.81), base_orientation=(0.9, 0.1, -0.2, 0.3))
    box = Box((0.3, 0.1, 0.2))
    turned = np.array([0.8, 0.3, -0.4, 0.2]) / np.linalg.norm([0.8, 0.3, -0.4, 0.2])
    a = art.add_link(Revolute((1, 0, 0)), shape=box, mass=1.0, shape_position=(0.1, 0.05, -0.1))
    b = art.add_link(Revolute((0, 1, 1)), parent=a, position=(0.3, 0.0, -0.1), orientation=turned, shape=box,
                     mass=0.8, shape_position=(0.15, 0, 0), shape_orientation=turned)  # fmt: skip
    c = art.add_link(Prismatic((1, -1, 0.5)), parent=b, position=(0.3, 0.1, 0.0), shape=box, mass=0.5,
                     shape_position=(0.0, 0.0, -0.1))  # fmt: skip
    art.add_link(Ball(), parent=c, position=(0.0, 0.2, -0.2), orientation=turned, shape=box, mass=0.6,
                 shape_position=(0.1, 0.1, 0.1))  # fmt: skip
    art.add_link(Revolute((0, 0, 1)), parent=a, position=(0.0, 0.2, 0.0), shape=box, mass=0.4,
                 shape_position=(0.1, 0.0, 0.0))  # fmt: skip
    return art


def floating_base() -> Articulation:
    """A free box with two hinged boxes: the ``Free`` joint's coordinates as MuJoCo's."""
    art = Articulation(gravity=(0.0, 0.0, -9.81))
    box = Box((0.4, 0.2, 0.1))
    base = art.add_link(Free(), position=(0.1, -0.2, 1.0), orientation=(0.9, 0.2, 0.1, -0.3), shape=box, mass=2.0)
    art.add_link(Revolute((0, 1, 0)), parent=base, position=(0.2, 0, 0), shape=box, mass=0.5,
                 shape_position=(0.2, 0, 0))  # fmt: skip
    art.add_link(Revolute((1, 0, 0)), parent=base, position=(-0.2, 0, 0), shape=box, mass=0.5,
                 shape_position=(0.0, 0.1, 0))  # fmt: skip
    return art


MODELS = {"double_pendulum": double_pendulum, "spatial_chain": spatial_chain, "floating_base": floating_base}


def _random_state(art: Articulation, rng) -> tuple[np.ndarray, np.ndarray]:
    q = art.q
    for link in art.links:
        if isinstance(link.joint, (Ball, Free)):
            quat = rng.normal(size=4)
            q[link.q_slice.stop - 4 : link.q_slice.stop] = quat / np.linalg.norm(quat)
        elif link.joint.nq == 1:
            q[link.q_slice] = rng.uniform(-1.5, 1.5)
    return q, rng.normal(size=art.nv)


def _mujoco(art: Articulation, dt: float, integrator: str = "RK4"):
    model = mujoco.MjModel.from_xml_string(mjcf(art, dt, integrator))
    return model, mujoco.MjData(model)


@pytest.mark.parametrize("name", sorted(MODELS))
def test_mass_matrix_matches_mj_fullM(name):
    art = MODELS[name]()
    model, data = _mujoco(art, 1e-3)
    assert (model.nq, model.nv) == (art.nq, art.nv)
    rng = np.random.default_rng(4)
    for _ in range(5):
        q, qd = _random_state(art, rng)
        data.qpos[:], data.qvel[:] = q, qd
        mujoco.mj_forward(model, data)
        full = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, full)
        # measured max difference 3.8e-15 (entries up to 3 kg m²)
        np.testing.assert_allclose(art.mass_matrix(q), full, rtol=0, atol=1e-10)
        # the bias forces too: MuJoCo's qfrc_bias is C(q, q̇) q̇ + g(q)
        np.testing.assert_allclose(art.bias_forces(q, qd), data.qfrc_bias, rtol=0, atol=1e-10)  # measured 1.8e-14


@pytest.mark.parametrize("integrators", [("rk4", "RK4"), ("symplectic", "Euler")], ids=["rk4", "symplectic"])
@pytest.mark.parametrize("name", sorted(MODELS))
def test_trajectory_matches_mujoco(name, integrators):
    """tumble's RK4 is MuJoCo's RK4, and its semi-implicit Euler is MuJoCo's ``Euler`` (also semi-implicit)."""
    dt, steps = 1e-3, 1000
    art = MODELS[name]()
    q, qd = _random_state(art, np.random.default_rng(7))
    art.q, art.qd = q, 0.5 * qd
    model, data = _mujoco(art, dt, integrators[1])
    data.qpos[:], data.qvel[:] = art.q, art.qd
    trajectory = art.simulate(steps * dt, dt, integrator=integrators[0])
    qpos, qvel = [data.qpos.copy()], [data.qvel.copy()]
    for _ in range(steps):
        mujoco.mj_step(model, data)
        qpos.append(data.qpos.copy())
        qvel.append(data.qvel.copy())
    qpos, qvel = np.array(qpos), np.array(qvel)
    for link in art.links:  # q and -q are the same rotation
        if isinstance(link.joint, (Ball, Free)):
            rows = slice(link.q_slice.stop - 4, link.q_slice.stop)
            sign = np.sign(np.sum(qpos[:, rows] * trajectory.q[:, rows], axis=1, keepdims=True))
            qpos[:, rows] *= sign
    # The same schemes (RK4 in Munthe-Kaas form for the quaternions); measured max difference over 1 s:
    # 6.3e-15 in q, 3.7e-14 in qd for RK4 (a second-order quaternion update would differ by ~1e-5 here),
    # 4e-15 and 2.7e-14 for the Euler schemes.
    np.testing.assert_allclose(trajectory.q, qpos, rtol=0, atol=1e-10)
    np.testing.assert_allclose(trajectory.qd, qvel, rtol=0, atol=1e-10)
