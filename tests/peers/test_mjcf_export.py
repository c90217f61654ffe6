"""``World.to_mjcf()``: shipped scenes written as MJCF, loaded by MuJoCo and by tumble's own reader.

Every shipped scene that MJCF can say loads in MuJoCo with each body where it is in the world, with its mass,
centre and inertia, and (from the keyframe ``now``) its velocity; the others are refused naming what MJCF cannot
say. A free body's motion is then the same in both engines; a jointed one is MuJoCo's exact joint against tumble's
soft one.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import tumble
import tumble.scene_file
from tumble.articulation import from_mjcf
from tumble.models.mjcf import MJCFWarning, read_mjcf
from tumble.rotation import quat_to_matrix

mujoco = pytest.importorskip("mujoco")
pytestmark = pytest.mark.peers

WRITTEN = ["box_pile", "dominoes", "dzhanibekov", "newtons_cradle", "pendulum", "pendulum_chain", "pyramid",
           "ragdoll_stairs", "robot_arm", "rope_bridge"]  # fmt: skip
REFUSED = {
    "flagship": r"body 'bowl' has a TriMesh, which MuJoCo collides as its convex hull",
    "four_bar": r"the hinge joint of 'crank' and None has a motor or spring",
    "quadrotor_landing": r"the world has vehicles or rotors and thrusters",
}


def scene(name: str) -> tumble.World:
    return tumble.load_scene(tumble.scene_file.shipped_scene(name))


def mujoco_now(xml: str):
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    return model, data


@pytest.mark.parametrize("name", WRITTEN)
def test_a_scene_loads_in_mujoco_with_every_body_its_pose_mass_and_velocity(name):
    world = scene(name)
    model, data = mujoco_now(world.to_mjcf(timestep=0.001))
    assert model.opt.timestep == 0.001
    np.testing.assert_array_equal(model.opt.gravity, world.gravity)
    dynamic = [b for b in world.bodies if not b.is_static]
    assert model.nbody - 1 == len(dynamic)
    for body in dynamic:
        i = model.body(body.name or f"body{body.index}").id
        np.testing.assert_allclose(data.xpos[i], body.position, rtol=0, atol=1e-12)
        assert abs(abs(np.dot(data.xquat[i], body.orientation)) - 1.0) < 1e-12
        assert model.body_mass[i] == pytest.approx(body.mass, rel=1e-14)
        np.testing.assert_allclose(data.xipos[i], body.center_of_mass, rtol=0, atol=1e-12)
        rotation = data.ximat[i].reshape(3, 3)
        np.testing.assert_allclose(rotation @ np.diag(model.body_inertia[i]) @ rotation.T, body.inertia_world,
                                   rtol=0, atol=1e-12 * np.abs(body.inertia_world).max())  # fmt: skip
        velocity = np.zeros(6)  # (angular, linear at the centre of mass), world
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, i, velocity, 0)
        np.testing.assert_allclose(velocity[:3], body.angular_velocity, rtol=0, atol=1e-12)
        np.testing.assert_allclose(velocity[3:], body.velocity, rtol=0, atol=1e-12)


@pytest.mark.parametrize(("name", "match"), sorted(REFUSED.items()))
def test_what_mjcf_cannot_say_is_refused_by_name(name, match):
    with pytest.raises(ValueError, match=match):
        scene(name).to_mjcf()


def test_timestep_must_be_positive():
    with pytest.raises(ValueError, match="timestep"):
        scene("pendulum").to_mjcf(timestep=-1.0)


def test_a_free_tumbling_body_moves_alike_in_both_engines():
    """The Dzhanibekov scene (a free body spinning near its intermediate axis) by RK4 at 1 kHz for 1 s in each."""
    world = scene("dzhanibekov")
    model, data = mujoco_now(world.to_mjcf(timestep=1e-3))
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    mujoco.mj_step(model, data, nstep=1000)
    world.integrator = "rk4"
    for _ in range(1000):
        world.step(1e-3)
    body = world.bodies[0]
    # Two RK4s on different coordinates (MuJoCo's body origin and local rates, tumble's centre and angular
    # momentum), each off the exact motion by ~(ω h)⁴ ω t = 2.5e-7: measured 4e-8 apart in orientation and rate,
    # 4e-9 m in the centre, which MuJoCo moves as the origin circles it
    np.testing.assert_allclose(data.xipos[1], body.center_of_mass, rtol=0, atol=1e-8)
    quat = body.orientation * np.sign(np.dot(body.orientation, data.xquat[1]))
    np.testing.assert_allclose(data.xquat[1], quat, rtol=0, atol=1e-6)
    np.testing.assert_allclose(data.qvel[3:], quat_to_matrix(body.orientation).T @ body.angular_velocity, atol=1e-6)


def test_tumbles_reader_reads_the_written_world_back():
    """``from_mjcf(world.to_mjcf())``: the robot arm's links where the world's bodies are, with their mass."""
    world = scene("robot_arm")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MJCFWarning)  # the crate's contact geoms' materials
        description = read_mjcf(world.to_mjcf())
        art = from_mjcf(world.to_mjcf())
    positions, quats = art.link_poses()
    for body in world.bodies:
        if body.is_static:
            continue
        index = description.body_index(body.name)
        mp = description.bodies[index].mass_properties
        assert mp.mass == pytest.approx(body.mass, rel=1e-14)
        link = art.link_index(body.name)
        anchor = description.bodies[index].joints[-1].pos if description.bodies[index].joints else np.zeros(3)
        np.testing.assert_allclose(positions[link], body.position + quat_to_matrix(body.orientation) @ anchor,
                                   atol=1e-12)  # fmt: skip
        assert abs(abs(np.dot(quats[link], body.orientation)) - 1.0) < 1e-12


AT_REST = ["box_pile", "pendulum", "pendulum_chain", "pyramid", "robot_arm"]


def _same_bodies(world, rebuilt) -> None:
    mine = {b.name: b for b in world.bodies if not b.is_static}
    theirs = {b.name: b for b in rebuilt.bodies if not b.is_static}
    assert mine.keys() == theirs.keys()
    for name, body in mine.items():
        other = theirs[name]
        assert other.mass == pytest.approx(body.mass, rel=1e-14)
        np.testing.assert_allclose(other.position, body.position, rtol=0, atol=1e-12)
        np.testing.assert_allclose(other.center_of_mass, body.center_of_mass, rtol=0, atol=1e-12)
        assert abs(abs(np.dot(other.orientation, body.orientation)) - 1.0) < 1e-14
        np.testing.assert_allclose(other.inertia_world, body.inertia_world, rtol=0,
                                   atol=1e-12 * np.abs(body.inertia_world).max())  # fmt: skip


@pytest.mark.parametrize("name", AT_REST)
def test_load_mjcf_of_to_mjcf_rebuilds_the_world_and_its_motion(name):
    """The bodies, masses, inertias, poses and joints come back; with the scene's joint stiffness (a solver setting,
    not in MJCF) the first second is the scene's, to round-off, where the bodies come back in the scene's order
    (the robot arm's crate comes after the arm, and the contacts' order changes the soft solve by 7 mm in 1 s: a
    second round trip, in the same order, moves as the first)."""
    world = scene(name)
    rebuilt = tumble.load_mjcf(world.to_mjcf())
    _same_bodies(world, rebuilt)
    assert sorted(j.kind for j in rebuilt.joints) == sorted(j.kind for j in world.joints)
    again = tumble.load_mjcf(rebuilt.to_mjcf())
    reference = world if name != "robot_arm" else again
    for w in (rebuilt, again):
        w.set_solver(joint_hertz=world.solver.joint_hertz)
    for _ in range(240):
        for w in {id(w): w for w in (world, rebuilt, reference)}.values():
            w.step(1 / 240)
    _same_moved = {b.name: b.position for b in reference.bodies if not b.is_static}
    for body in rebuilt.bodies:
        if not body.is_static:
            np.testing.assert_allclose(body.position, _same_moved[body.name], rtol=0, atol=1e-9)


def test_a_chain_deeper_than_the_recursion_limit_is_written():
    """The body tree is written from a stack of its own: a chain of 300 links under a recursion limit of 200 (as a
    chain of thousands under Python's 1000) loads in MuJoCo with its last link where the world has it."""
    import sys

    world = tumble.World()
    parent = None
    for i in range(300):
        body = world.add_body(tumble.Sphere(0.01), mass=0.1, position=(0.02 * i, 0.0, 1.0), name=f"link{i}")
        world.add_joint(tumble.HingeJoint(body, parent, (0.02 * i - 0.01, 0.0, 1.0), (0.0, 1.0, 0.0)))
        parent = body
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(200)
    try:
        xml = world.to_mjcf()
    finally:
        sys.setrecursionlimit(limit)
    model, data = mujoco_now(xml)
    assert model.nbody == 301 and model.njnt == 300
    np.testing.assert_allclose(data.xpos[model.body("link299").id], (0.02 * 299, 0.0, 1.0), atol=1e-12)


def _walker() -> tumble.World:
    """A box on a planar joint to the world with two legs hung from it by universal joints, each side of the joint
    first (the tree hangs the first leg's joint from its second body), all moving."""
    world = tumble.World(gravity=(0.0, 0.0, -9.81))
    hip = world.add_body(tumble.Box((0.4, 0.2, 0.1)), mass=1.0, position=(0, 0, 1), orientation=(0.9, 0.1, 0.3, 0.2),
                         name="hip")  # fmt: skip
    world.add_joint(tumble.PlanarJoint(hip, None, (0.0, 0.6, 0.8)))
    right = world.add_body(tumble.Box((0.1, 0.1, 0.5)), mass=1.0, position=(0.3, 0, 0.6), name="right")
    world.add_joint(tumble.UniversalJoint(right, hip, (0.3, 0, 0.85), (1, 0, 0), (0, 1, 0)))
    left = world.add_body(tumble.Box((0.1, 0.1, 0.5)), mass=1.0, position=(-0.3, 0, 0.6), name="left")
    world.add_joint(tumble.UniversalJoint(hip, left, (-0.3, 0, 0.85), (0, 1, 0), (1, 0, 0)))
    hip.velocity, hip.angular_velocity, right.angular_velocity = (0.3, 0.2, 0.1), (0.2, 0.1, 1.0), (1.0, 0.5, 0.3)
    world.simulate(0.2, 1 / 1000)
    return world


def test_planar_and_universal_joints_are_written_as_mujocos_joints_and_read_back():
    """A planar joint is two slides and a hinge, a universal joint two hinges with the parent's axis first: MuJoCo
    puts every body where it is and moves it as it moves; load_mjcf makes the same joints again."""
    world = _walker()
    xml = world.to_mjcf(timestep=0.001)
    model, data = mujoco_now(xml)
    assert list(model.jnt_type) == [mujoco.mjtJoint.mjJNT_SLIDE] * 2 + [mujoco.mjtJoint.mjJNT_HINGE] * 5
    for body in world.bodies:
        i = model.body(body.name).id
        np.testing.assert_allclose(data.xpos[i], body.position, rtol=0, atol=1e-12)
        assert abs(abs(np.dot(data.xquat[i], body.orientation)) - 1.0) < 1e-12
        velocity = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, i, velocity, 0)
        # MuJoCo's velocities are exactly jointed; tumble's soft joints leave 4e-4 rad/s across the planar normal
        np.testing.assert_allclose(velocity[:3], body.angular_velocity, rtol=0, atol=2e-3)
        np.testing.assert_allclose(velocity[3:], body.velocity, rtol=0, atol=2e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MJCFWarning)  # the keyframe
        rebuilt = tumble.load_mjcf(xml)
    assert [j.kind for j in rebuilt.joints] == ["planar", "universal", "universal"]
    _same_bodies(world, rebuilt)


def test_planar_and_universal_joints_go_through_a_scene_file(tmp_path):
    world = _walker()
    (tmp_path / "walker.toml").write_text(tumble.scene_file.dumps(world.to_scene()), encoding="utf-8")
    copy = tumble.scene_file.load(tmp_path / "walker.toml").world
    assert [j.kind for j in copy.joints] == ["planar", "universal", "universal"]
    for w in (world, copy):
        w.simulate(0.5, 1 / 1000)
    for body, other in zip(world.bodies, copy.bodies, strict=True):
        np.testing.assert_allclose(other.position, body.position, rtol=0, atol=1e-5)  # warm starts are not saved


def test_an_actuator_on_a_universal_joints_angle_is_refused_by_to_mjcf():
    world = _walker()
    world.add_joint_actuator(world.joints[1], coordinate=1)
    with pytest.raises(ValueError, match="to_mjcf: actuator 0 drives a universal joint's angle, which is not written"):
        world.to_mjcf()
