"""MJCF files nobody here wrote, loaded by tumble and by MuJoCo: the compiled models and their dynamics compared.

MuJoCo is the oracle for what a file means. Gymnasium's MuJoCo assets (ant, half_cheetah, hopper, humanoid, …),
dm_control's suite (the dog with its 162 bone meshes included) and models written here to exercise the rest of the
format (default classes, childclass, every orientation, fromto, refs, several joints in a body, ``inertial`` and
geoms) are read by :func:`tumble.articulation.from_mjcf` and by ``mujoco.MjModel``; bodies, masses, inertias, joint
frames, mass matrices and accelerations must agree to round-off (tests/peers/test_mjcf_meshes.py has the small mesh
cases). Armature, joint damping and springs (``springdamper`` too) are simulated by both; what tumble's articulation
does not simulate yet (joint friction, a viscous medium, limits, tendons) is switched off on MuJoCo's side through
``MjSpec`` and reported by tumble's warnings.
"""

from __future__ import annotations

import importlib.util
import os
import warnings
from dataclasses import replace

import numpy as np
import pytest

from tumble.articulation import from_mjcf
from tumble.mass import MassProperties
from tumble.models.build import to_articulation
from tumble.models.mjcf import MJCFWarning, read_mjcf
from tumble.rotation import quat_to_matrix

mujoco = pytest.importorskip("mujoco")
gymnasium = pytest.importorskip("gymnasium")
pytestmark = pytest.mark.peers

ASSETS = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets")
GYMNASIUM = sorted(name for name in os.listdir(ASSETS) if name.endswith(".xml"))
# dm_control's suite, found without importing dm_control (which opens a window system on import)
_DM_CONTROL = importlib.util.find_spec("dm_control")
SUITE_DIR = os.path.join(os.path.dirname(_DM_CONTROL.origin), "suite") if _DM_CONTROL else None
SUITE = sorted(f"suite/{n}" for n in os.listdir(SUITE_DIR) if n.endswith(".xml")) if SUITE_DIR else []
# MuJoCo turns each mesh's inertia to its principal axes by a Jacobi iteration that stops when the off-diagonal
# terms of the per-unit-density tensor fall under 1e-12 m⁵ (mju_eig3's absolute threshold): a mesh geom's inertia in
# MuJoCo's compiled model is off by up to that, times the geom's density. tumble keeps the tensor as integrated.
EIG3_THRESHOLD = 1e-12

EXERCISE = """<mujoco model="exercise">
  <compiler angle="degree" eulerseq="zyX" autolimits="true"/>
  <option timestep="0.004" gravity="0.3 -0.2 -9.7"/>
  <default>
    <joint damping="0.2"/>
    <geom density="700"/>
    <default class="limb">
      <geom type="capsule" size="0.04"/>
      <joint axis="0 1 0"/>
      <default class="heavy"><geom density="2500"/></default>
    </default>
  </default>
  <worldbody>
    <geom type="plane" size="3 3 0.1"/>
    <body name="torso" pos="0.1 -0.2 1.2" euler="10 -20 30">
      <freejoint name="root"/>
      <geom type="box" size="0.2 0.12 0.06"/>
      <geom type="ellipsoid" size="0.05 0.08 0.03" pos="0 0 0.1" axisangle="1 1 0 40"/>
      <body name="thigh" pos="0.2 0 0" childclass="limb" xyaxes="0 1 0 -1 0.2 0">
        <joint name="hip_y" pos="0.01 0 0" ref="15" range="-60 60" armature="0.02" stiffness="3" springref="10"/>
        <joint name="hip_x" axis="1 0 0" pos="0.02 0.01 0"/>
        <geom fromto="0 0 0 0.3 0 -0.2"/>
        <body name="shin" pos="0.3 0 -0.2" zaxis="0.2 0.1 1">
          <joint name="knee" type="slide" axis="0 0 1" ref="0.05" damping="1.5" stiffness="40" springref="-0.02"
                 armature="0.01"/>
          <geom class="heavy" type="cylinder" fromto="0 0 0 0 0 -0.3" size="0.03"/>
          <body name="foot" pos="0 0.1 -0.3" quat="0.9 0.1 -0.2 0.3">
            <joint type="ball" pos="0 0 0.02"/>
            <inertial pos="0.01 0.02 0.03" mass="0.3" diaginertia="0.01 0.02 0.025" euler="30 20 10"/>
          </body>
        </body>
      </body>
      <body name="tail" pos="-0.25 0 0">
        <inertial pos="-0.05 0 0" mass="0.4" fullinertia="0.003 0.004 0.005 0.0005 -0.0002 0.0001"/>
        <body name="tip" pos="-0.1 0 0.05"><joint type="hinge" axis="0 0 1"/><geom type="sphere" size="0.05"/></body>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def _source(name: str) -> str:
    if name == "exercise":
        return EXERCISE
    if name.startswith("suite/"):
        return os.path.join(SUITE_DIR, name.removeprefix("suite/"))
    return os.path.join(ASSETS, name)


def _switch_off(element, name: str) -> None:
    """Set a spring or damper coefficient to zero: three numbers in MuJoCo 4 (a polynomial), one before."""
    try:
        setattr(element, name, np.zeros(3))
    except TypeError:
        setattr(element, name, 0.0)


def _mesh_density(spec) -> dict[str, float]:
    """Each body's mesh geoms' densities, summed."""
    return {body.name: sum(g.density for g in body.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH)
            for body in spec.bodies}  # fmt: skip


def _with_mujocos_inertia(description, model):
    """The description with each body's mass properties as MuJoCo compiled them, for the dynamics compared on the
    same inertias where MuJoCo's eigen-solver rounds a mesh's (``EIG3_THRESHOLD``; the difference is bounded in
    the test of the compiled model)."""
    bodies = []
    for index, body in enumerate(description.bodies, start=1):
        if body.mass_properties is not None:
            rotation = quat_to_matrix(model.body_iquat[index])
            inertia = rotation @ np.diag(model.body_inertia[index]) @ rotation.T
            body = replace(body, mass_properties=MassProperties(model.body_mass[index], model.body_ipos[index],
                                                                0.5 * (inertia + inertia.T)))  # fmt: skip
        bodies.append(body)
    return replace(description, bodies=tuple(bodies))


def _load(name: str, mujocos_mesh_inertia: bool = False):
    """tumble's articulation and description, and MuJoCo's model with what tumble does not simulate switched off
    (with ``mujocos_mesh_inertia``, a model with mesh geoms is built on MuJoCo's compiled inertias)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MJCFWarning)
        description = read_mjcf(_source(name))
    # the tree's dynamics alone: limits, dry friction and tendons' springs are compared in test_mjcf_joint_physics.py
    art = to_articulation(_without_constraints(description))
    spec = mujoco.MjSpec.from_string(EXERCISE) if name == "exercise" else mujoco.MjSpec.from_file(_source(name))
    for joint in spec.joints:
        joint.frictionloss = 0.0
    for tendon in spec.tendons:  # a tendon's spring and damper are passive forces, outside the constraints
        _switch_off(tendon, "stiffness")
        _switch_off(tendon, "damping")
    spec.option.viscosity = spec.option.density = 0.0
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT  # no contacts, limits or equalities
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # half_cheetah's deprecated settotalmass
        model = spec.compile()
    driven = _driven(model)
    for index in set(range(model.nu)) - set(driven):  # what tumble does not load pushes nothing in MuJoCo either
        spec.actuators[index].gear = np.zeros(6)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = spec.compile()
    assert len(art.actuators) == len(driven)
    if mujocos_mesh_inertia and any(_mesh_density(spec).values()):
        art = to_articulation(_without_constraints(_with_mujocos_inertia(description, model)))
    return art, description, model


def _without_constraints(description):
    """The description with its joints' and tendons' limits and dry friction, its tendons' springs and its geoms'
    contacts taken out (the geoms' mass is already in the bodies')."""
    bodies = tuple(replace(body, joints=tuple(replace(j, range=None, frictionloss=0.0) for j in body.joints),
                           geoms=()) for body in description.bodies)  # fmt: skip
    tendons = tuple(replace(t, range=None, frictionloss=0.0, stiffness=0.0, damping=0.0) for t in description.tendons)
    return replace(description, bodies=bodies, tendons=tendons, world_geoms=())


def _driven(model) -> list[int]:
    """MuJoCo's actuators that tumble simulates: on a hinge, a slide or a fixed tendon, fixed gain, affine bias or
    none, no activation dynamics (in the model's order, as ``art.ctrl``)."""
    joint, tendon = int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_TENDON)
    hinge, slide = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)
    affine = (int(mujoco.mjtBias.mjBIAS_NONE), int(mujoco.mjtBias.mjBIAS_AFFINE))
    return [i for i in range(model.nu)
            if ((model.actuator_trntype[i] == joint and model.jnt_type[model.actuator_trnid[i, 0]] in (hinge, slide))
                or (model.actuator_trntype[i] == tendon and model.tendon_num[model.actuator_trnid[i, 0]] > 0
                    and model.wrap_type[model.tendon_adr[model.actuator_trnid[i, 0]]]
                    == int(mujoco.mjtWrap.mjWRAP_JOINT)))
            and model.actuator_dyntype[i] == int(mujoco.mjtDyn.mjDYN_NONE)
            and model.actuator_gaintype[i] == int(mujoco.mjtGain.mjGAIN_FIXED)
            and model.actuator_biastype[i] in affine]  # fmt: skip


def _random_controls(art, model, rng):
    """Controls for both engines (``art.ctrl`` set), a quarter beyond their ranges (each engine clips them)."""
    ctrl = rng.normal(size=model.nu)
    for i in range(model.nu):
        if model.actuator_ctrllimited[i]:
            low, high = model.actuator_ctrlrange[i]
            ctrl[i] = rng.uniform(low - 0.25 * (high - low), high + 0.25 * (high - low))
    art.ctrl = ctrl[_driven(model)]
    return ctrl


NAMES = ["exercise", *GYMNASIUM, *SUITE]
MODELS = NAMES


@pytest.mark.parametrize("name", MODELS)
def test_bodies_masses_inertias_and_joints_equal_mujocos_compiled_model(name):
    _, description, model = _load(name)
    spec = mujoco.MjSpec.from_string(EXERCISE) if name == "exercise" else mujoco.MjSpec.from_file(_source(name))
    mesh_density = _mesh_density(spec)
    assert len(description.bodies) == model.nbody - 1
    for index, body in enumerate(description.bodies, start=1):
        assert body.name == (model.body(index).name or None)
        assert body.parent + 1 == model.body_parentid[index]
        np.testing.assert_allclose(body.pos, model.body_pos[index], rtol=0, atol=1e-12)
        assert abs(abs(np.dot(body.quat, model.body_quat[index])) - 1.0) < 1e-12
        mp = body.mass_properties
        assert (mp.mass if mp is not None else 0.0) == pytest.approx(model.body_mass[index], rel=1e-12, abs=1e-15)
        if mp is not None:
            np.testing.assert_allclose(mp.com, model.body_ipos[index], rtol=0, atol=1e-12)
            rotation = quat_to_matrix(model.body_iquat[index])
            tensor = rotation @ np.diag(model.body_inertia[index]) @ rotation.T
            eig3 = EIG3_THRESHOLD * mesh_density.get(body.name, 0.0)
            np.testing.assert_allclose(mp.inertia, tensor, rtol=0, atol=1e-9 * max(np.abs(tensor).max(), 1e-12) + eig3)
        first = model.body_jntadr[index]
        assert len(body.joints) == model.body_jntnum[index]
        for k, joint in enumerate(body.joints):
            j = first + k
            assert joint.type == ("free", "ball", "slide", "hinge")[model.jnt_type[j]]
            if joint.type in ("hinge", "slide"):
                np.testing.assert_allclose(joint.axis, model.jnt_axis[j], rtol=0, atol=1e-12)
                np.testing.assert_allclose(joint.pos, model.jnt_pos[j], rtol=0, atol=1e-12)
                # springdamper's are computed from the effective mass: equal to round-off
                assert joint.damping == pytest.approx(model.dof_damping[model.jnt_dofadr[j]], rel=1e-12)
                stiffness = np.atleast_1d(model.jnt_stiffness[j])[0]  # MuJoCo 4: a polynomial's coefficients
                assert joint.stiffness == pytest.approx(stiffness, rel=1e-12)


def _random_state(model, rng):
    q = model.qpos0 + 0.4 * rng.normal(size=model.nq)
    for j in range(model.njnt):
        if model.jnt_type[j] in (mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_BALL):
            start = model.jnt_qposadr[j] + (3 if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE else 0)
            q[start : start + 4] /= np.linalg.norm(q[start : start + 4])
    return q, rng.normal(size=model.nv)


@pytest.mark.parametrize("name", MODELS)
def test_link_frames_mass_matrix_and_accelerations_equal_mujocos(name):
    art, description, model = _load(name, mujocos_mesh_inertia=True)
    if model.nv == 0:
        pytest.skip("nothing in this model moves")
    data = mujoco.MjData(model)
    assert (art.nq, art.nv) == (model.nq, model.nv)
    np.testing.assert_allclose(art.q, model.qpos0, rtol=0, atol=1e-15)  # it starts at qpos0, refs included
    rng = np.random.default_rng(25)
    for _ in range(3):
        q, qd = _random_state(model, rng)
        data.qpos[:], data.qvel[:] = q, qd
        data.ctrl[:] = _random_controls(art, model, rng)
        mujoco.mj_forward(model, data)
        # A body's last link is the body frame moved to its last joint's pos (a welded body's: the body frame).
        positions, quats = art.link_poses(q)
        for index, body in enumerate(description.bodies, start=1):
            if body.name is None:
                continue
            link = art.link_index(body.name)
            anchor = body.joints[-1].pos if body.joints else np.zeros(3)
            expected = data.xpos[index] + data.xmat[index].reshape(3, 3) @ anchor
            np.testing.assert_allclose(positions[link], expected, rtol=0, atol=1e-12)
            assert abs(abs(np.dot(quats[link], data.xquat[index])) - 1.0) < 1e-12
        full = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, full)
        scale = np.abs(full).max()
        np.testing.assert_allclose(art.mass_matrix(q), full, rtol=0, atol=1e-12 * scale)  # measured < 1e-15 relative
        # tumble's bias holds the joints' own forces: damping, springs and the actuators' drive
        np.testing.assert_allclose(art.bias_forces(q, qd), data.qfrc_bias - data.qfrc_passive - data.qfrc_actuator,
                                   rtol=0, atol=1e-10 * max(1.0, np.abs(data.qfrc_bias).max()))  # fmt: skip
        np.testing.assert_allclose(art.actuator_forces(q, qd), data.actuator_force[_driven(model)], rtol=1e-12,
                                   atol=1e-12)  # fmt: skip
        acc = art.forward_dynamics(q, qd)
        np.testing.assert_allclose(acc, data.qacc, rtol=0, atol=1e-9 * max(1.0, np.abs(data.qacc).max()))


def test_the_warnings_name_what_is_not_simulated_once_each_with_its_line():
    with warnings.catch_warnings():
        warnings.simplefilter("error", MJCFWarning)  # the humanoid's limits, tendons and 17 motors are all simulated
        humanoid = from_mjcf(os.path.join(ASSETS, "humanoid.xml"))
    assert len(humanoid.actuators) == 17 and len(humanoid.tendons) == 2
    with pytest.warns(MJCFWarning) as record:
        from_mjcf(os.path.join(SUITE_DIR, "dog.xml"))
    messages = [str(w.message) for w in record]
    assert len(messages) == len(set(messages))
    assert any("<general> element (line " in m and "more)" in m and "dyntype" in m for m in messages)
    assert all("dog.xml" in m for m in messages)


# Models tuned for MuJoCo's Euler, whose damping is implicit: without their contacts and limits, a light link behind
# a damped joint is too stiff for explicit RK4 at the model's timestep, in MuJoCo as in tumble (MuJoCo's RK4 resets
# the manipulator and the stacker after a few steps, and amplifies round-off on the reacher and the quadruped until
# the engines part by 1e-6 within the 2 s; the dog's tail joints, whose springdamper="0.001 50" damps at 2/τ =
# 2000 /s, blow up in both at once). These run at a fraction of their timestep, where both agree to 1e-12.
RK4_SUBSTEPS = {"suite/dog.xml": 10, "suite/finger.xml": 10, "suite/quadruped.xml": 10, "suite/reacher.xml": 10,
                "suite/manipulator.xml": 100, "suite/stacker.xml": 100}  # fmt: skip


RK4_MODELS = [
    pytest.param(name, marks=pytest.mark.slow) if RK4_SUBSTEPS.get(name, 1) > 10  # 200 000 steps: 10 s
    else name
    for name in NAMES
]  # fmt: skip


@pytest.mark.parametrize("name", RK4_MODELS)
def test_rk4_tracks_mujocos_rk4_for_two_seconds(name):
    """Both engines integrate the model by RK4 at its own timestep (or a fraction, see ``RK4_SUBSTEPS``) from the
    same state: the same motion, the difference growing from round-off (contacts, limits and what tumble does not
    simulate switched off)."""
    art, _, model = _load(name, mujocos_mesh_inertia=True)
    if model.nv == 0:
        pytest.skip("nothing in this model moves")
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.timestep /= RK4_SUBSTEPS.get(name, 1)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(2)
    q, qd = _random_state(model, rng)
    art.q, art.qd = q, 0.5 * qd
    data.qpos[:], data.qvel[:] = art.q, art.qd
    # gentle controls: strong motors on a contact-free, unlimited model spin it until round-off grows chaotically
    data.ctrl[:] = 0.02 * _random_controls(art, model, rng)
    art.ctrl = data.ctrl[_driven(model)]
    dt = float(model.opt.timestep)
    steps = round(2.0 / dt)
    mujoco.mj_step(model, data, nstep=steps)  # (a reset after a bad acceleration would show as a difference)
    trajectory = art.simulate(steps * dt, dt, integrator="rk4", record_every=steps)
    np.testing.assert_allclose(trajectory.q[-1], data.qpos, rtol=0, atol=1e-6)
    np.testing.assert_allclose(trajectory.qd[-1], data.qvel, rtol=0, atol=1e-6 * max(1.0, np.abs(data.qvel).max()))
