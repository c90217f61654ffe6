"""Contacts in generalised coordinates against MuJoCo (issue 47): the same contacts, the same constraint forces, the
same motion, and the locomotion models at rest where MuJoCo's rest.

An articulation's contacts are MuJoCo's soft constraints on the same points with the same Jacobians, impedances and
regularisers (``tumble/articulation/contacts.py``), solved to the same optimum, so where MuJoCo's solver converges
(Newton, tolerance 1e-15) the accelerations agree to rounding and trajectories to far below a millimetre.
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")
gymnasium = pytest.importorskip("gymnasium")

from tumble.articulation import Articulation, Fixed, Revolute, from_mjcf  # noqa: E402
from tumble.models.mjcf import MJCFError, MJCFWarning  # noqa: E402

ASSETS = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets")

# a capsule and a sphere on one free body, a second free sphere, and a tilted plane: every pair type, every setting
_SCENE = """<mujoco><option timestep="0.001" integrator="RK4" impratio="1.5"/>
<worldbody><geom name="floor" type="plane" size="5 5 .1" friction="0.7 0.1 0.1" margin="0.005" euler="3 -2 0"/>
<body name="a" pos="0.1 0.2 0.12" euler="10 20 30"><freejoint/>
  <geom name="rod" type="capsule" fromto="-0.1 0 0 0.1 0 0" size="0.05" mass="2" friction="0.9 0.1 0.1" margin="0.02"
        solref="0.03 1.1" solimp="0.8 0.9 0.002 0.5 2" solmix="2"/>
  <geom name="knob" type="sphere" pos="0 0.1 0" size="0.04" mass="0.5" condim="1"/></body>
<body name="b" pos="0.05 0.1 0.3"><freejoint/><geom name="ball" type="sphere" size="0.06" mass="0.7"/></body>
</worldbody></mujoco>"""


def _mujoco(xml: str):
    model = mujoco.MjModel.from_xml_string(xml)
    model.opt.tolerance, model.opt.ls_tolerance, model.opt.iterations = 1e-15, 1e-15, 1000
    return model, mujoco.MjData(model)


def _mujoco_names(model, data):
    """Each of MuJoCo's contacts as the sorted names of its two geoms."""
    return [
        tuple(sorted((model.geom(int(a)).name, model.geom(int(b)).name))) for a, b in data.contact.geom[: data.ncon]
    ]


def _names(art, contacts):
    return [tuple(sorted((art.geoms[a].name, art.geoms[b].name))) for a, b in contacts.geoms]


def _closest(names, distances):
    """``{pair: smallest distance}``."""
    out = {}
    for key, distance in zip(names, distances, strict=True):
        out[key] = min(out.get(key, np.inf), distance)
    return out


def test_contacts_and_accelerations_equal_mujocos_at_random_overlapping_states():
    """Plane-sphere, plane-capsule (two points), sphere-sphere, sphere-capsule and capsule-capsule contacts: the same
    points, normals and distances as MuJoCo's, and ``q̈`` equal to its ``qacc``, with friction pyramids, a
    frictionless contact, mixed margins, solref/solimp mixed by solmix and impratio 1.5."""
    art = from_mjcf(_SCENE)
    model, data = _mujoco(_SCENE)
    rng = np.random.default_rng(7)
    kinds = set()
    for _ in range(60):
        for start in (0, 7):
            data.qpos[start : start + 3] = [*rng.uniform(-0.08, 0.08, 2), rng.uniform(0.0, 0.12)]
            quat = rng.normal(size=4)
            data.qpos[start + 3 : start + 7] = quat / np.linalg.norm(quat)
        data.qvel[:] = rng.normal(size=model.nv)
        mujoco.mj_forward(model, data)
        art.q, art.qd = data.qpos, data.qvel
        ours = art.contacts()
        theirs = sorted(zip(_mujoco_names(model, data), data.contact.dist[: data.ncon], strict=True))
        mine = sorted(zip(_names(art, ours), ours.distance, strict=True))
        assert [pair for pair, _ in mine] == [pair for pair, _ in theirs]
        np.testing.assert_allclose([d for _, d in mine], [d for _, d in theirs], rtol=0, atol=1e-14)
        kinds |= {pair for pair, _ in mine}
        scale = max(1.0, np.max(np.abs(data.qacc)))
        np.testing.assert_allclose(art.forward_dynamics(), data.qacc, rtol=0, atol=1e-9 * scale)
    assert {("ball", "floor"), ("floor", "rod"), ("floor", "knob"), ("ball", "rod"), ("ball", "knob")} <= kinds


@pytest.mark.parametrize("dt", [1e-3, 1 / 240])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_tumbling_body_lands_and_rests_as_mujocos_does(seed, dt):
    """Two free bodies thrown onto a tilted plane (and onto each other) with random velocities: two seconds of RK4 at
    1 kHz and at 240 Hz follow MuJoCo's trajectory at the same step to 1e-7 m (impacts, sliding, rolling and rest; at
    240 Hz the contacts' time constants are held at twice the step, in both engines). Measured: 4e-12 at 1 kHz; at
    240 Hz the two solvers' last digits (KKT to 1e-12 here, Newton to 1e-15 there) part at the first impact and the
    bodies' collisions grow that to 3e-11 to 7e-9."""
    art = from_mjcf(_SCENE)
    model, data = _mujoco(_SCENE)
    model.opt.timestep = dt
    data.qvel[:] = np.random.default_rng(seed).normal(scale=1.5, size=model.nv)
    art.qd = data.qvel
    worst, touching = 0.0, 0
    for _ in range(round(2.0 / dt)):
        mujoco.mj_step(model, data)
        art.step(dt, integrator="rk4")
        worst = max(worst, np.max(np.abs(art.q - data.qpos)))
        touching = max(touching, data.ncon)
    assert worst < 1e-7
    assert touching >= 2


def _pose_at_random(model, rng):
    """A random pose of the humanoid within its joint ranges, lifted clear of the floor."""
    qpos = model.qpos0.copy()
    qpos[2] = 3.0
    for j in range(1, model.njnt):
        low, high = model.jnt_range[j]
        qpos[model.jnt_qposadr[j]] = rng.uniform(low, high)
    return qpos


def test_the_humanoids_limbs_touch_each_other_as_mujocos_do():
    """At random poses within the joint ranges the humanoid's limbs touch in the same pairs as MuJoCo's, at the same
    distances: its filter (contype/conaffinity, a body and its parent, one rigid body) is MuJoCo's."""
    path = os.path.join(ASSETS, "humanoid.xml")
    art = from_mjcf(path)
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(11)
    seen = set()
    for _ in range(200):
        data.qpos[:] = _pose_at_random(model, rng)
        mujoco.mj_forward(model, data)
        ours = art.contacts(q=data.qpos)
        theirs = _closest(_mujoco_names(model, data), data.contact.dist[: data.ncon])
        mine = _closest(_names(art, ours), ours.distance)
        assert mine.keys() == theirs.keys()
        for key, distance in mine.items():
            assert distance == pytest.approx(theirs[key], abs=1e-12)
        seen |= mine.keys()
    assert len(seen) >= 10


REST = {"hopper": 1e-9, "walker2d_v5": 1e-6, "half_cheetah": 1e-6, "ant": 1e-9}


@pytest.mark.parametrize("name", list(REST))
def test_the_locomotion_models_come_to_rest_where_mujocos_do(name):
    """Zero control at each model's own timestep and integrator (MuJoCo's Euler is ``symplectic_implicit_damping``)
    for 15 s: the torso rests within 1 cm of MuJoCo's, and to REST [m]."""
    path = os.path.join(ASSETS, f"{name}.xml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # half_cheetah's deprecated settotalmass
        model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    art = from_mjcf(path)
    dt = model.opt.timestep
    steps = round(15.0 / dt)
    mujoco.mj_step(model, data, nstep=steps)
    rk4 = model.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4
    art.simulate(15.0, dt, integrator="rk4" if rk4 else "symplectic_implicit_damping", record_every=steps)
    torso = art.link_index("torso")
    ours, theirs = art.link_poses()[0][torso], data.xpos[model.body("torso").id]
    assert np.max(np.abs(ours - theirs)) < 0.01
    assert np.max(np.abs(ours - theirs)) < REST[name]
    assert np.max(np.abs(art.qd - data.qvel)) < 1e-3  # as still as MuJoCo's (the walker still sways by 6 mrad/s)
    scalar = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
    for j in (j for j in range(model.njnt) if model.jnt_type[j] in scalar):  # each joint by its name
        joint, theirs = art.joint(model.joint(j).name), data.joint(j)
        ours = joint.angle if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE else joint.translation
        assert ours == pytest.approx(theirs.qpos[0], abs=0.01)


@pytest.mark.parametrize("dt", [1 / 240, 1e-3])
@pytest.mark.parametrize("name", ["hopper", "ant"])
def test_models_rest_as_mujocos_do_at_240_hz_and_1_khz(name, dt):
    """The hopper and the ant dropped with zero control for 5 s at 240 Hz and at 1 kHz (RK4 in both engines): the
    torso where MuJoCo's is at the same step."""
    path = os.path.join(ASSETS, f"{name}.xml")
    model = mujoco.MjModel.from_xml_path(path)
    model.opt.timestep = dt
    data = mujoco.MjData(model)
    art = from_mjcf(path)
    steps = round(5.0 / dt)
    mujoco.mj_step(model, data, nstep=steps)
    art.simulate(5.0, dt, integrator="rk4", record_every=steps)
    ours, theirs = art.link_poses()[0][art.link_index("torso")], data.xpos[model.body("torso").id]
    assert np.max(np.abs(ours - theirs)) < 1e-6


@pytest.mark.parametrize("seed", [None, 1, 2])
def test_the_humanoid_falls_and_lies_with_no_shapes_overlapping_by_more_than_5_mm(seed):
    """From its model pose (``None``) and from two random pushes of its joints, in both engines alike."""
    path = os.path.join(ASSETS, "humanoid.xml")
    art = from_mjcf(path)
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    if seed is not None:
        data.qvel[6:] = np.random.default_rng(seed).normal(scale=2.0, size=model.nv - 6)
        art.qd = data.qvel
    dt = model.opt.timestep
    art.simulate(5.0, dt, integrator="rk4", record_every=1000)
    deepest = min(art.contacts().distance)
    for _ in range(round(1.0 / dt)):
        art.step(dt, integrator="rk4")
        deepest = min(deepest, min(art.contacts().distance))
    assert deepest > -0.005
    mujoco.mj_step(model, data, nstep=round(6.0 / dt))
    head = art.link_index("torso")
    assert art.link_poses()[0][head][2] == pytest.approx(data.xpos[model.body("torso").id][2], abs=0.01)


def _pairs(art):
    """The pairs of geom names that may touch."""
    return {frozenset((art.geoms[a].name, art.geoms[b].name)) for a, b in art.contact_pairs}


def test_contact_filters_one_body_its_parent_bits_and_exclusions():
    """MuJoCo's filter on an arm: a body and its parent body (through a massless gimbal) do not touch, nor links
    welded into one body, nor geoms whose contype and conaffinity bits do not meet, nor excluded bodies."""
    art = Articulation()
    below = (0.0, 0.0, -0.1)  # point masses off their joints' axes
    upper = art.add_link(Revolute((0, 1, 0)), position=(0, 0, 1), mass=1.0, shape_position=below)
    gimbal = art.add_link(Revolute((1, 0, 0)), parent=upper)  # massless, no geoms: part of the joint
    lower = art.add_link(Revolute((0, 1, 0)), parent=gimbal, position=(0, 0, -0.5), mass=1.0, shape_position=below)
    weld = art.add_link(Fixed(), parent=lower, position=(0, 0, -0.5), mass=0.5, shape_position=below)
    hand = art.add_link(Revolute((0, 1, 0)), parent=weld, position=(0, 0, -0.2), mass=0.2, shape_position=below)
    for link in (upper, lower, weld, hand):
        art.add_geom(link, "sphere", (0.3,), name=f"g{link}")
    art.add_geom(None, "plane", name="floor")
    art.add_geom(upper, "sphere", (0.3,), contype=2, conaffinity=2, name="shy")
    pairs = _pairs(art)
    assert frozenset(("g0", "g2")) not in pairs  # a body and its parent, through the massless gimbal
    assert frozenset(("g2", "g3")) not in pairs  # one rigid body
    assert frozenset(("g0", "g3")) not in pairs  # the welded link is part of the upper arm's child
    assert frozenset(("g3", "g4")) not in pairs  # the hand's parent body is the lower arm with its weld
    assert frozenset(("g0", "g4")) in pairs and frozenset(("floor", "g4")) in pairs
    assert not any("shy" in pair for pair in pairs)  # bits that meet no other geom's
    art.exclude_contacts(upper, hand)
    assert frozenset(("g0", "g4")) not in _pairs(art)
    assert len(art.contacts(q=np.zeros(4)).distance) > 0


def test_mjcf_exclusions_and_pairs():
    xml = """<mujoco><worldbody><geom name="floor" type="plane" size="1 1 1"/>
      <body name="a"><freejoint/><geom name="ga" size="0.1"/></body>
      <body name="b"><freejoint/><geom name="gb" size="0.1"/></body></worldbody>
      <contact><exclude body1="a" body2="b"/><exclude body1="world" body2="a"/><pair geom1="ga" geom2="gb"/></contact>
    </mujoco>"""
    with pytest.warns(MJCFWarning, match=r"<pair> element \(line 4\): explicit contact pairs are not simulated"):
        art = from_mjcf(xml)
    assert _pairs(art) == {frozenset(("floor", "gb"))}
    with pytest.raises(MJCFError, match=r"line 1, <exclude>: an <exclude> names body1= and body2="):
        from_mjcf('<mujoco><contact><exclude body1="a"/></contact></mujoco>')
    with pytest.raises(MJCFError, match=r"condim='2' must be 1, 3, 4 or 6"):
        from_mjcf('<mujoco><worldbody><geom condim="2" size="1"/></worldbody></mujoco>')
