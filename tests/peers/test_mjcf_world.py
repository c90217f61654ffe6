"""``tumble.load_mjcf``: MJCF models in a World, colliding, with the world's joints.

Gymnasium's ant (a free torso, eight single-hinge leg segments with limits, capsules, a plane) loads with its
bodies where MuJoCo puts them, its masses, and MuJoCo's collision filter (the ant's geoms touch the floor, not each
other); dropped, it comes to rest in MuJoCo's pose. Models whose bodies have several joints are refused naming the body.
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

import tumble
from tumble.models.build_world import _filters
from tumble.models.mjcf import read_mjcf

mujoco = pytest.importorskip("mujoco")
gymnasium = pytest.importorskip("gymnasium")
pytestmark = pytest.mark.peers

ASSETS = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets")
ANT = os.path.join(ASSETS, "ant.xml")


def quiet_load(source, **placement):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return tumble.load_mjcf(source, **placement)


def test_the_ant_loads_where_mujoco_puts_it_with_its_masses():
    world = quiet_load(ANT)
    model = mujoco.MjModel.from_xml_path(ANT)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    moving = {b.name: b for b in world.bodies if not b.is_static}
    assert len(world.joints) == 8 and all(j.kind == "hinge" for j in world.joints)
    # the jointless upper legs are welded into the torso: its mass is theirs too
    torso = model.body("torso").id
    welded = [i for i in range(model.nbody) if model.body_jntnum[i] == 0 and model.body_parentid[i] == torso]
    assert moving["torso"].mass == pytest.approx(model.body_mass[torso] + model.body_mass[welded].sum(), rel=1e-12)
    jointed = [i for i in range(model.nbody) if model.body_jntnum[i] > 0]  # in order, as the world's bodies
    bodies = [b for b in world.bodies if not b.is_static]
    assert len(bodies) == len(jointed)
    for body, i in zip(bodies, jointed, strict=True):
        np.testing.assert_allclose(body.position, data.xpos[i], rtol=0, atol=1e-12)
        assert abs(abs(np.dot(body.orientation, data.xquat[i])) - 1.0) < 1e-14
        if i != torso:
            assert body.mass == pytest.approx(model.body_mass[i], rel=1e-12)
    assert sum(b.mass for b in bodies) == pytest.approx(model.body_mass.sum(), rel=1e-12)


@pytest.mark.parametrize("rate", [240, pytest.param(1000, marks=pytest.mark.slow)])
def test_the_ant_dropped_rests_in_mujocos_pose_touching_only_the_floor(rate):
    """Loaded with its ankles at 0°, outside their 30–70° range, the ant is pushed into range as it falls, lands,
    splays onto the ankles' 30° stops and rests within 2 s, as MuJoCo's does by 15 s (its armature 1 slows it):
    hips and ankles within 0.05° of MuJoCo's, the torso level, and its height MuJoCo's less the gap MuJoCo's
    contacts keep open (the floor's and the feet's margins, 1 cm each, which a World does not model) within 1 mm.
    Before limits pushed out at contact_push_max at most, the ankles flew on to their 70° stops and the ant stood
    0.24 m too tall."""
    world = quiet_load(ANT)
    for _ in range(2 * rate):
        world.step(1 / rate)
    model = mujoco.MjModel.from_xml_path(ANT)
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=round(20.0 / model.opt.timestep))
    assert np.abs(data.qvel).max() < 1e-6
    speeds = [np.linalg.norm(b.velocity) for b in world.bodies if not b.is_static]
    assert max(speeds) < 1e-3
    # The world's joints in the file's order, as MuJoCo's qpos after the free joint's 7.
    angles = np.array([joint.angle for joint in world.joints])
    np.testing.assert_allclose(np.degrees(angles), np.degrees(data.qpos[7:]), atol=0.05)
    torso = next(b for b in world.bodies if b.name == "torso")
    gap = np.array([data.contact[i].dist for i in range(data.ncon)])
    assert data.ncon == 4 and np.ptp(gap) < 1e-9  # the four feet, each 19.7 mm above the floor
    assert abs(torso.position[2] - (data.qpos[2] - gap[0])) < 1e-3
    assert abs(abs(np.dot(torso.orientation, data.qpos[3:7])) - 1.0) < 1e-6
    contacts = world.contacts()
    floor = next(b for b in world.bodies if b.is_static)
    assert len(contacts) > 0
    touching = (contacts.body_a == floor.index) | (contacts.body_b == floor.index)
    assert touching.all()  # MuJoCo's filter: the ant's geoms touch the floor, never each other
    assert contacts.separation.min() > -0.005


def test_collision_filters_pair_what_mujoco_pairs():
    description = read_mjcf(ANT)
    filters = _filters(description)
    for (ct1, ca1), (g1, m1) in filters.items():
        for (ct2, ca2), (g2, m2) in filters.items():
            assert bool((g1 & m2) and (g2 & m1)) == bool((ct1 & ca2) or (ct2 & ca1))


def test_a_model_is_placed_and_added_to_an_existing_world():
    world = tumble.World(gravity=(0.0, 0.0, -1.0))
    world.add_static(tumble.Plane())
    turn = (np.cos(0.25), 0.0, 0.0, np.sin(0.25))
    quiet_load(os.path.join(ASSETS, "inverted_pendulum.xml"), world=world, position=(1.0, 2.0, 0.5), orientation=turn)
    alone = quiet_load(os.path.join(ASSETS, "inverted_pendulum.xml"))
    pole = next(b for b in world.bodies if b.name == "pole")
    reference = next(b for b in alone.bodies if b.name == "pole")
    expected = np.array([1.0, 2.0, 0.5]) + tumble.rotation.quat_rotate(np.array(turn), reference.position)
    np.testing.assert_allclose(pole.position, expected, atol=1e-12)
    np.testing.assert_array_equal(world.gravity, (0.0, 0.0, -1.0))  # an existing world keeps its gravity


def test_a_body_with_joints_a_world_joint_cannot_make_and_bad_arguments_are_refused():
    slide_and_hinge = """<mujoco><worldbody><body name="cart"><joint name="x" type="slide" axis="1 0 0"/>
      <joint name="turn" type="hinge" axis="1 0 0"/><geom type="box" size=".1 .1 .1"/></body></worldbody></mujoco>"""
    with pytest.raises(ValueError, match=r"line 1: body 'cart' has joints slide 'x', hinge 'turn'; a tumble World "
                                         r"joins two bodies with one joint, which several make only as"):  # fmt: skip
        quiet_load(slide_and_hinge)
    skew = """<mujoco><worldbody><body name="arm"><joint name="a" axis="1 0 0"/><joint name="b" axis="1 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -1" size=".05"/></body></worldbody></mujoco>"""
    with pytest.raises(ValueError, match=r"body 'arm' has joints hinge 'a', hinge 'b'"):
        quiet_load(skew)
    world = quiet_load(ANT)
    count = len(world.bodies)
    with pytest.raises(ValueError, match=r"ant\.xml: the name 'torso' is taken in the world"):
        quiet_load(ANT, world=world)
    assert len(world.bodies) == count and len(world.joints) == 8  # nothing of the second ant was added
    with pytest.raises(TypeError, match="world must be a tumble.World or None"):
        tumble.load_mjcf(ANT, world="mine")
    with pytest.raises(ValueError, match="orientation"):
        tumble.load_mjcf(ANT, orientation=(0, 0, 0, 0))
    with pytest.warns(UserWarning, match=r"ant\.xml: a tumble World's joints do not simulate joint armature \(yet"):
        ant = tumble.load_mjcf(ANT)
    assert ant.ctrl.shape == (8,)  # its eight motors


WHEEL = """<mujoco><compiler angle="radian"/><option gravity="0 0 0" timestep="0.001"/>
  <worldbody><body name="wheel"><joint name="axle" axis="0 0 1" ref="0.2"/>
    <geom type="sphere" size="0.05" pos="0.5 0 0" mass="2"/></body></worldbody>
  <actuator><motor name="motor" joint="axle" gear="3" ctrlrange="-1 1"/>{servo}</actuator></mujoco>"""


def test_a_motor_and_a_servo_drive_a_world_hinge_as_mujoco_does():
    """A motor (gear 3) and a position servo (kp 10, kv 1) on one hinge, 2 s at 1 kHz in both engines: the servo
    pulls towards its target against the motor (0.2 + 3 × 0.4 / 10 rad), ringing alike in both; critically damped,
    it holds it."""
    xml = WHEEL.format(servo='<position name="servo" joint="axle" kp="10" kv="1"/>')
    world = quiet_load(xml)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    world.ctrl = data.ctrl[:] = [0.4, 0.2]
    for _ in range(2000):
        world.step(0.001)
        mujoco.mj_step(model, data)
        assert 0.2 + world.joints[0].angle == pytest.approx(data.qpos[0], abs=3e-4)  # measured 1.2e-4
    np.testing.assert_allclose(world.actuator_forces(), data.actuator_force, atol=2e-3)
    damped = quiet_load(WHEEL.format(servo='<position name="servo" joint="axle" kp="10" kv="4.5"/>'))  # ζ = 1
    damped.ctrl = [0.4, 0.2]
    for _ in range(3000):
        damped.step(0.001)
    # what is left of the 0.12 rad approach after 3 s: (1 + ω t) e^(-ω t) 0.12 = 3e-6, ω = √(kp / I) = 4.5 /s
    assert 0.2 + damped.joints[0].angle == pytest.approx(0.2 + 3 * 0.4 / 10, abs=1e-5)
    np.testing.assert_allclose(damped.actuator_forces(), [0.4, -1.2], atol=1e-4)


# The motor's torque is exact at any step; the soft hinge that holds the sphere on its circle drains a little of the
# speed, more at coarse steps (measured: 5e-6 at 3 rad/s and 1 kHz, 1.3e-3 at 60 Hz)
@pytest.mark.parametrize(("ctrl", "dt", "rel"), [(0.4, 1 / 1000, 2e-5), (7.0, 1 / 1000, 2e-5), (0.4, 1 / 240, 2e-5),
                                                 (7.0, 1 / 60, 3e-3)])  # fmt: skip
def test_a_motor_spins_a_wheel_up_at_gear_times_its_clipped_control(ctrl, dt, rel):
    world = quiet_load(WHEEL.format(servo=""))
    world.ctrl = [ctrl]
    inertia = 2.0 * 0.5**2 + 0.4 * 2.0 * 0.05**2
    steps = round(0.5 / dt)
    for _ in range(steps):
        world.step(dt)
    expected = 3.0 * min(ctrl, 1.0) / inertia * steps * dt
    assert world.joints[0].angular_speed == pytest.approx(expected, rel=rel)
    assert world.ctrl.tolist() == [ctrl]


def test_joint_actuators_refuse_bad_controls_and_joints_and_checkpoints():
    world = quiet_load(WHEEL.format(servo=""))
    with pytest.raises(ValueError, match="ctrl"):
        world.ctrl = [1.0, 2.0]
    with pytest.raises(ValueError, match="ctrl"):
        world.ctrl = [float("nan")]
    assert world.ctrl.tolist() == [0.0]
    weld = world.add_joint(tumble.FixedJoint(world.bodies[0], None))
    with pytest.raises(ValueError, match="a joint actuator drives a hinge, slider, universal or ball joint, got a "
                                         "fixed joint"):  # fmt: skip
        world.add_joint_actuator(weld)
    ball = world.add_joint(tumble.BallJoint(world.bodies[0], None, (0.0, 0.0, 0.0)))
    with pytest.raises(ValueError, match="axes must be given for a ball joint's actuator and only for it, got None"):
        world.add_joint_actuator(ball)
    with pytest.raises(ValueError, match=r"axes must be three orthonormal rows, got \[\[1.0, 0.0, 0.0\], \[1.0"):
        world.add_joint_actuator(ball, axes=[[1, 0, 0], [1, 1, 0], [0, 0, 1]])
    with pytest.raises(ValueError, match="coordinate must be an integer in 0 to 2 for a ball joint, got 3"):
        world.add_joint_actuator(ball, axes=np.eye(3), coordinate=3)
    with pytest.raises(ValueError, match="axes must be given for a ball joint's actuator and only for it, got"):
        world.add_joint_actuator(world.joints[0], axes=np.eye(3))
    with pytest.raises(ValueError, match="coordinate must be an integer in 0 to 0 for a hinge joint, got True"):
        world.add_joint_actuator(world.joints[0], coordinate=True)
    assert world.ctrl.tolist() == [0.0]
    with pytest.raises(TypeError, match="joint must be a joint of this world"):
        tumble.World().add_joint_actuator(world.joints[0])
    with pytest.raises(ValueError, match=r"ctrl_range must be \(low, high\) with low <= high"):
        world.add_joint_actuator(world.joints[0], ctrl_range=(1, 0))
    with pytest.raises(ValueError, match=r"save: the world has 1 joint actuators \(world.ctrl\)"):
        world.save("never.npz")


@pytest.mark.parametrize("parent", ["world", "cart"])
def test_a_hinge_limit_stops_the_arm_where_mujocos_does(parent):
    """An arm falling about a hinge with range -10° to 20° stops at +20° (positive turns about +y take +x down),
    hinged to the world or to a heavy cart on a horizontal slide, in both engines."""
    arm = ('<body name="arm" pos="0 0 1"><joint name="elbow" axis="0 1 0" range="-10 20"/>'
           '<geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.02" mass="1"/></body>')  # fmt: skip
    if parent == "cart":
        arm = ('<body name="cart"><joint type="slide" axis="1 0 0"/><geom type="box" size="0.1 0.1 0.1" mass="1000" '
               f'contype="0" conaffinity="0"/>{arm}</body>')  # fmt: skip
    xml = f"<mujoco><option timestep='0.002'/><worldbody>{arm}</worldbody></mujoco>"
    world = quiet_load(xml)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=1000)
    for _ in range(480):
        world.step(1 / 240)
    elbow = world.joints[-1]
    assert (elbow.body_b is None) == (parent == "world")
    assert data.qpos[model.joint("elbow").qposadr[0]] == pytest.approx(np.radians(20.0), abs=0.01)
    assert elbow.angle == pytest.approx(np.radians(20.0), abs=0.01)


def test_to_mjcf_writes_the_actuators_so_that_mujoco_and_load_mjcf_push_alike():
    """The ant driven for 0.3 s and the wheel's motor and servo (its hinge counted from ``ref``, with a range) written
    back: MuJoCo's ``actuator_force`` at the keyframe ``now`` (which holds the controls) is tumble's, and that of the
    world ``load_mjcf`` rebuilds from the text (at rest) is MuJoCo's at rest."""
    for source, ctrl, dt in ((ANT, np.sin(np.arange(8) * 1.7), 0.01),
                             (WHEEL.format(servo='<position name="servo" joint="axle" kp="10" kv="1"/>'), [0.4, 0.2],
                              0.001)):  # fmt: skip
        world = quiet_load(source)
        world.ctrl = ctrl
        for _ in range(30):
            world.step(dt)
        xml = world.to_mjcf(timestep=dt)
        model = mujoco.MjModel.from_xml_string(xml)
        data = mujoco.MjData(model)
        mujoco.mj_resetDataKeyframe(model, data, 0)
        mujoco.mj_forward(model, data)
        np.testing.assert_allclose(data.ctrl, ctrl, rtol=0, atol=0)
        np.testing.assert_allclose(data.actuator_force, world.actuator_forces(), rtol=1e-12, atol=1e-12)
        rebuilt = quiet_load(xml)  # at rest in the pose (load_mjcf does not apply keyframes)
        rebuilt.ctrl = ctrl
        data.qvel[:] = 0.0
        mujoco.mj_forward(model, data)
        np.testing.assert_allclose(rebuilt.actuator_forces(), data.actuator_force, rtol=1e-12, atol=1e-12)


def _pitch(body) -> float:
    rotation = tumble.rotation.quat_to_matrix(body.orientation)
    return float(np.arctan2(rotation[0, 2], rotation[0, 0]))


@pytest.mark.parametrize("dt", [0.002, pytest.param(1 / 240, marks=pytest.mark.slow),
                                pytest.param(0.001, marks=pytest.mark.slow)])  # fmt: skip
def test_the_hopper_on_its_planar_root_falls_and_rests_as_mujocos_does(dt):
    """Gymnasium's hopper dropped from its model pose with no control. Its root (slides x and z, hinge y) is one
    PlanarJoint; its thigh, leg and foot hinges keep their damping. Both engines tip it backwards onto its back, the
    leg and foot at their limits; the thigh and the pitch differ by up to 0.15 rad because MuJoCo's joints carry
    armature 1 (rotor inertia), which a World's joints leave out (without it MuJoCo's hopper rolls right over: the
    fall is that sensitive)."""
    path = os.path.join(ASSETS, "hopper.xml")
    world = quiet_load(path)
    assert [j.kind for j in world.joints] == ["planar", "hinge", "hinge", "hinge"]
    world.simulate(3.0, dt)
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    for _ in range(round(3.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    bodies = {b.name: b for b in world.bodies}
    assert max(np.linalg.norm(b.velocity) for b in world.bodies) < 1e-3  # at rest (MuJoCo: 4e-3 rad/s)
    torso = bodies["torso"]
    assert abs(torso.position[1]) < 1e-9  # in its plane
    # measured, tumble at 500 Hz: x -0.213, z 0.183, pitch -2.300, thigh -0.526; MuJoCo below: -0.262, 0.174, -2.226,
    # -0.397 (without the damping, tumble's thigh rests at -0.634)
    _, _, pitch, thigh, leg, foot = data.qpos
    x, _, z = data.xpos[model.body("torso").id]
    assert torso.position[0] == pytest.approx(x, abs=0.08)
    assert torso.position[2] == pytest.approx(z, abs=0.015)
    assert _pitch(torso) == pytest.approx(pitch, abs=0.12)
    angles = [j.angle for j in world.joints[1:]]
    assert angles[0] == pytest.approx(thigh, abs=0.2)
    assert [j.damping for j in world.joints[1:]] == [1.0, 1.0, 1.0]
    np.testing.assert_allclose(angles[1:], [leg, foot], atol=0.01)  # both at a limit
    assert max(j.position_error for j in world.joints) < 1e-4


@pytest.mark.parametrize("dt", [1 / 240, pytest.param(0.002, marks=pytest.mark.slow)])
def test_the_humanoid_falls_and_rests_without_its_links_interpenetrating(dt):
    """Gymnasium's humanoid dropped with no control: its two-hinge abdomen and shoulders become UniversalJoints,
    its three-hinge hips BallJoints (their ranges left out, with a warning)."""
    path = os.path.join(ASSETS, "humanoid.xml")
    with pytest.warns(tumble.models.mjcf.MJCFWarning, match=r"the ranges of joints 'abdomen_z', 'abdomen_y', "):
        world = tumble.load_mjcf(path)
    kinds = [j.kind for j in world.joints]
    assert kinds.count("universal") == 3 and kinds.count("ball") == 2 and kinds.count("hinge") == 5
    assert world.ctrl.shape == (17,)  # every motor, those of the merged hinges on the joints' angles
    world.simulate(3.0, dt)  # at rest after 2.5 s at 240 Hz, 1 s at 500 Hz
    moving = [b for b in world.bodies if not b.is_static]
    assert max(np.linalg.norm(b.velocity) for b in moving) < 1e-3
    assert 0.05 < world.bodies[0].position[2] < 0.6  # the torso has come down (lying, or sitting)
    contacts = world.contacts()
    assert len(contacts) > 4 and contacts.separation.min() > -5e-3  # no link into another or the floor by 5 mm
    assert max(j.position_error for j in world.joints) < 1e-4


# A two-hinge shoulder (a UniversalJoint to the world) carrying a three-hinge hip (a BallJoint; its axes x, z, y
# are a left-handed basis), and the other way round with a ref and a gear, held by position servos.
SHOULDER_THEN_HIP = """<mujoco><option timestep="0.001"/><worldbody>
 <body name="upper" pos="0 0 2"><joint name="s1" axis="1 0 0"/><joint name="s2" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.3 0 -0.4" size="0.05" contype="0" conaffinity="0"/>
  <body name="lower" pos="0.3 0 -0.4"><joint name="h1" axis="1 0 0"/><joint name="h2" axis="0 0 1"/>
   <joint name="h3" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0.3 -0.3" size="0.08" contype="0"
   conaffinity="0"/></body></body></worldbody>
 <actuator><position joint="s1" kp="50" kv="3"/><position joint="s2" kp="50" kv="3"/><position joint="h1" kp="20"
  kv="0.5"/><position joint="h2" kp="20" kv="0.5"/><position joint="h3" kp="20" kv="0.5"/></actuator></mujoco>"""
HIP_THEN_SHOULDER = """<mujoco><option timestep="0.001"/><worldbody>
 <body name="upper" pos="0 0 2"><joint name="s1" axis="0 1 0"/><joint name="s2" axis="1 0 0"/>
  <joint name="s3" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.3 0 -0.4" size="0.05" contype="0"
  conaffinity="0"/>
  <body name="lower" pos="0.3 0 -0.4"><joint name="h1" axis="0 0 1" ref="0.2"/><joint name="h2" axis="1 0 0"/>
   <geom type="capsule" fromto="0 0 0 0 0.3 -0.3" size="0.08" contype="0" conaffinity="0"/></body></body></worldbody>
 <actuator><position joint="s1" kp="50" kv="3"/><position joint="s2" kp="50" kv="3" gear="2"/><position joint="s3"
  kp="50" kv="3"/><position joint="h1" kp="20" kv="0.5"/><position joint="h2" kp="20" kv="0.5"/></actuator>
</mujoco>"""


@pytest.mark.parametrize("xml", [SHOULDER_THEN_HIP, HIP_THEN_SHOULDER], ids=["shoulder_then_hip", "hip_then_shoulder"])
def test_servos_on_merged_hinges_move_the_limbs_as_in_mujoco(xml):
    """Position servos on the hinges a universal and a ball joint stand for, driven to targets under gravity: the
    limbs and the servos' forces follow MuJoCo's for 2 s (measured: 1.1 mm and 0.10 N of 27 N at most; the
    soft joints and the integrators differ)."""
    ctrl = [0.3, -0.2, 0.4, 0.3, -0.5]
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.ctrl[:] = ctrl
    world = quiet_load(xml)
    assert sorted(j.kind for j in world.joints) == ["ball", "universal"]
    world.ctrl = ctrl
    for until in (0.5, 1.0, 2.0):
        while data.time < until - 1e-9:
            mujoco.mj_step(model, data)
        world.simulate(until - world.time, 0.001)
        for body in world.bodies:
            np.testing.assert_allclose(body.position, data.xpos[model.body(body.name).id], rtol=0, atol=2e-3)
        np.testing.assert_allclose(world.actuator_forces(), data.actuator_force, rtol=0, atol=0.15)  # of up to 28 N


def test_ranges_of_merged_hinges_are_named_in_a_warning_and_left_out():
    xml = """<mujoco><worldbody><body name="arm">
      <joint axis="1 0 0" range="-10 10"/>
      <joint name="pitch" axis="0 1 0" range="-20 20"/>
      <geom type="capsule" fromto="0 0 0 0 0 -1" size=".05"/></body></worldbody></mujoco>"""
    with pytest.warns(tumble.models.mjcf.MJCFWarning, match=r"the ranges of joints 'line 2', 'pitch' are not enforced"):
        world = tumble.load_mjcf(xml)
    assert [j.kind for j in world.joints] == ["universal"]
