"""``tumble.load_urdf`` and ``tumble.articulation.from_urdf`` on the URDFs shipped in pybullet_data, against MuJoCo's
own URDF import (which fuses links on fixed joints as the World welds them) and PyBullet's masses.

Every moving body has MuJoCo's mass, centre of mass, inertia and frame to round-off, each joint its kind and its
parent; the kuka arm's mass matrix and forward dynamics are MuJoCo's to 1e-9. Where MuJoCo refuses a file that
PyBullet loads (a package path it cannot resolve), every link weighs what PyBullet's ``getDynamicsInfo`` says.
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

import tumble
from tumble.articulation import from_urdf
from tumble.models.urdf import URDFError, read_urdf

mujoco = pytest.importorskip("mujoco")
pybullet = pytest.importorskip("pybullet")
pybullet_data = pytest.importorskip("pybullet_data")
pytestmark = pytest.mark.peers

DATA = pybullet_data.getDataPath()
# pybullet_data's robots that MuJoCo's URDF import accepts
MUJOCO_LOADS = ["r2d2.urdf", "kuka_iiwa/model.urdf", "cartpole.urdf", "humanoid/humanoid.urdf", "pendulum5.urdf",
                "quadruped/quadruped.urdf", "quadruped/minitaur.urdf", "a1/a1.urdf",
                "racecar/racecar.urdf"]  # fmt: skip
KINDS = {int(mujoco.mjtJoint.mjJNT_HINGE): "hinge", int(mujoco.mjtJoint.mjJNT_SLIDE): "slider",
         int(mujoco.mjtJoint.mjJNT_BALL): "ball"}  # fmt: skip


def _quiet(load, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(*args, **kwargs)


@pytest.mark.parametrize("name", MUJOCO_LOADS)
def test_moving_bodies_weigh_sit_and_join_as_in_mujocos_import(name):
    path = os.path.join(DATA, name)
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    world = _quiet(tumble.load_urdf, path)
    moving = {b.name: b for b in world.bodies if not b.is_static}
    mujocos = [i for i in range(1, model.nbody) if model.body_jntnum[i] > 0]
    assert sorted(moving) == sorted(model.body(i).name for i in mujocos)
    for i in mujocos:
        body = moving[model.body(i).name]
        assert body.mass == pytest.approx(model.body_mass[i], rel=1e-12)
        np.testing.assert_allclose(body.position, data.xpos[i], rtol=0, atol=1e-12)
        assert abs(abs(np.dot(body.orientation, data.xquat[i])) - 1.0) < 1e-12
        np.testing.assert_allclose(body.center_of_mass, data.xipos[i], rtol=0, atol=1e-12)
        frame = data.ximat[i].reshape(3, 3)
        tensor = frame @ np.diag(model.body_inertia[i]) @ frame.T
        np.testing.assert_allclose(body.inertia_world, tensor, rtol=0, atol=1e-12 * np.abs(tensor).max())
    # each joint: its kind, the body it moves and that body's parent (static parts are the world's: None)
    # (a joint to the world is (body, None); between two bodies (parent, child))
    ours = [(j.body_a.name, j.body_b.name, j.kind) if j.body_b is not None else (None, j.body_a.name, j.kind)
            for j in world.joints]  # fmt: skip
    theirs = []
    for j in range(model.njnt):
        body, parent = model.jnt_bodyid[j], model.body_parentid[model.jnt_bodyid[j]]
        theirs.append((model.body(parent).name if model.body_jntnum[parent] else None, model.body(body).name,
                       KINDS[int(model.jnt_type[j])]))  # fmt: skip
    assert sorted(ours, key=str) == sorted(theirs, key=str)


def test_the_kuka_arms_mass_matrix_and_forward_dynamics_equal_mujocos():
    path = os.path.join(DATA, "kuka_iiwa", "model.urdf")
    model = mujoco.MjModel.from_xml_path(path)
    # contact-free: MuJoCo's links collide with each other at random poses, and tumble's articulation has no limits
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    data = mujoco.MjData(model)
    art = from_urdf(path)
    assert (art.nq, art.nv) == (model.nq, model.nv) == (7, 7)
    rng = np.random.default_rng(27)
    for _ in range(4):
        q, qd = rng.uniform(-2.0, 2.0, 7), rng.normal(size=7)
        data.qpos[:], data.qvel[:] = q, qd
        mujoco.mj_forward(model, data)
        full = np.zeros((7, 7))
        mujoco.mj_fullM(model, data, full)
        np.testing.assert_allclose(art.mass_matrix(q), full, rtol=0, atol=1e-12 * np.abs(full).max())
        # the arm's joint damping (0.5 N m s) is in both engines' passive forces
        acc = art.forward_dynamics(q, qd)
        np.testing.assert_allclose(acc, data.qacc, rtol=0, atol=1e-9 * max(1.0, np.abs(data.qacc).max()))


def test_where_mujoco_cannot_resolve_the_meshes_every_link_weighs_what_pybullet_says():
    """The panda's meshes are ``package://meshes/...`` with the package folder as the file's own: MuJoCo looks for
    ``package:/meshes`` and stops; tumble finds them beside the file, and every link weighs what PyBullet weighs."""
    path = os.path.join(DATA, "franka_panda", "panda.urdf")
    with pytest.raises(ValueError, match="package:"):
        mujoco.MjModel.from_xml_path(path)
    client = pybullet.connect(pybullet.DIRECT)
    try:
        robot = pybullet.loadURDF(path, flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
        theirs = {pybullet.getBodyInfo(robot, physicsClientId=client)[0].decode():
                  pybullet.getDynamicsInfo(robot, -1, physicsClientId=client)[0]}  # fmt: skip
        for j in range(pybullet.getNumJoints(robot, physicsClientId=client)):
            link = pybullet.getJointInfo(robot, j, physicsClientId=client)[12].decode()
            theirs[link] = pybullet.getDynamicsInfo(robot, j, physicsClientId=client)[0]
    finally:
        pybullet.disconnect(client)
    description = _quiet(read_urdf, path)
    ours = {b.name: (b.mass_properties.mass if b.mass_properties is not None else 0.0) for b in description.bodies}
    assert ours.keys() == theirs.keys()
    for link, mass in theirs.items():
        assert ours[link] == pytest.approx(mass, rel=1e-12)
    world = _quiet(tumble.load_urdf, path)
    assert len([b for b in world.bodies if not b.is_static]) == len(world.joints) == 9  # 7 arm joints, 2 fingers
    assert _quiet(from_urdf, path).nq == 9


def test_files_mujoco_refuses_for_their_inertia_are_refused_naming_the_link():
    """MuJoCo refuses both for their inertia too (A + B >= C); PyBullet loads them as written."""
    with pytest.raises(URDFError, match=r"mini_cheetah\.urdf, line \d+, <inertia>: link 'thigh_fr'"):
        read_urdf(os.path.join(DATA, "mini_cheetah", "mini_cheetah.urdf"))
    with pytest.raises(URDFError, match=r"line 123, <inertia>: link 'link_1': .* fail the triangle inequality"):
        read_urdf(os.path.join(DATA, "TwoJointRobot_w_fixedJoints.urdf"))


@pytest.mark.parametrize(
    "rate", [60, pytest.param(240, marks=pytest.mark.slow), pytest.param(1000, marks=pytest.mark.slow)]
)
def test_a_floating_base_robot_dropped_on_the_floor_rests_where_mujocos_does(rate):
    """r2d2 free (``floating_base=True``) dropped from 0.6 m onto a plane, and the same file in MuJoCo with a free
    joint added to its root: both rest on the legs' box feet with the base 0.470 m up (within 1 mm), level (within
    0.01 rad), where it fell (within 1 cm: the landing's small slide). With its base welded, as MuJoCo's import
    makes it by default, the base and legs are the world's geometry."""
    path = os.path.join(DATA, "r2d2.urdf")
    spec = mujoco.MjSpec.from_file(path)
    spec.body("base_link").add_freejoint()
    spec.body("base_link").pos = [0.0, 0.0, 0.6]
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5.0, 5.0, 0.1])
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=round(3.0 / model.opt.timestep))
    assert np.abs(data.qvel).max() < 1e-3
    theirs = model.body("base_link").id
    world = tumble.World()
    world.add_static(tumble.Plane())
    _quiet(tumble.load_urdf, path, world=world, position=(0, 0, 0.6), floating_base=True)
    base = next(b for b in world.bodies if b.name == "base_link")
    assert base.mass > 10.0  # the base and the legs welded to it
    for _ in range(3 * rate):
        world.step(1 / rate)
    assert max(np.linalg.norm(b.velocity) for b in world.bodies if not b.is_static) < 1e-3
    assert abs(base.position[2] - data.xpos[theirs][2]) < 1e-3  # measured 0.3 mm at 60 Hz, 0.1 mm at 240
    assert np.linalg.norm(base.position[:2] - data.xpos[theirs][:2]) < 0.01  # measured 7 mm
    assert abs(np.dot(base.orientation, data.xquat[theirs])) > np.cos(0.005)
    assert world.contacts().separation.min() > -0.001
    welded = _quiet(tumble.load_urdf, path)
    moving = [b.name for b in welded.bodies if not b.is_static]
    assert len(moving) == 8 and "base_link" not in moving
