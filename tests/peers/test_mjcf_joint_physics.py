"""Joint limits, dry friction, fixed tendons and clipped actuators, against MuJoCo (issue 47, part 1 and the
contact-free half of part 2).

The models are lifted out of contact (MuJoCo's contacts switched off; an articulation has none) and driven by
``ctrl_i(t) = 0.5 sin(2π(1 + i/4) t)``, held over each step, with RK4 at a tenth of the model's timestep on both
sides. MuJoCo solves its constraints with Newton to rounding (``tolerance`` 1e-15), as its own solvers all converge to
the one solution of the dual problem that tumble solves (``tumble/articulation/constraints.py``).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import replace

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")
gymnasium = pytest.importorskip("gymnasium")
dm_control = pytest.importorskip("dm_control")

from tumble.articulation import Articulation, Revolute, SoftConstraint, from_mjcf  # noqa: E402
from tumble.models.build import to_articulation  # noqa: E402
from tumble.models.mjcf import MJCFError, read_mjcf  # noqa: E402

GYMNASIUM = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets")
SUITE = os.path.join(os.path.dirname(dm_control.__file__), "suite")
LOCOMOTION = ("hopper", "walker2d_v5", "half_cheetah", "ant", "humanoid")
MODELS = [os.path.join(GYMNASIUM, f"{name}.xml") for name in LOCOMOTION]
MODELS += [os.path.join(SUITE, f"{name}.xml") for name in ("walker", "finger", "point_mass", "cheetah")]
DURATION = 0.5
TOLERANCE = 1e-6  # [rad] or [m]


def _mujoco(path: str, divisor: int):
    """MuJoCo's model without contacts, RK4 at its timestep / ``divisor``, constraints solved to rounding."""
    spec = mujoco.MjSpec.from_file(path)
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # settotalmass is deprecated in MuJoCo 4
        model = spec.compile()
    model.opt.solver = mujoco.mjtSolver.mjSOL_NEWTON
    model.opt.tolerance, model.opt.ls_tolerance, model.opt.iterations = 1e-15, 1e-15, 1000
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.timestep /= divisor
    return model, mujoco.MjData(model)


def _controls(count: int, t: float) -> np.ndarray:
    return 0.5 * np.sin(2.0 * np.pi * (1.0 + np.arange(count) / 4.0) * t)


def _mujoco_run(path: str, divisor: int, hold: int):
    """``qpos`` after each group of ``hold`` steps at timestep / ``divisor`` (the control held over the group), and
    the most constraint rows MuJoCo had at once."""
    model, data = _mujoco(path, divisor)
    dt = model.opt.timestep
    groups = round(DURATION / (dt * hold))
    out, rows = np.empty((groups, model.nq)), 0
    for g in range(groups):
        data.ctrl[:] = _controls(model.nu, g * hold * dt)
        for _ in range(hold):
            mujoco.mj_step(model, data)
            rows = max(rows, data.nefc)
        out[g] = data.qpos
    return out, rows


def _without_contacts(path: str):
    """The model's articulation with no geoms to collide, as MuJoCo's with its contacts switched off."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # what the articulation leaves out (sensors) is not in play here
        description = read_mjcf(path)
    bodies = tuple(replace(body, geoms=()) for body in description.bodies)
    return to_articulation(replace(description, bodies=bodies, world_geoms=()))


def _tumble_run(path: str):
    art = _without_contacts(path)
    model, _ = _mujoco(path, 10)
    dt = model.opt.timestep
    steps = round(DURATION / dt)
    out = np.empty((steps, art.nq))
    for n in range(steps):
        art.ctrl = _controls(len(art.ctrl), n * dt)
        art.step(dt, integrator="rk4")
        out[n] = art.q
    return out


@pytest.mark.parametrize("path", MODELS, ids=lambda p: os.path.basename(p))
def test_driven_models_follow_mujoco_through_their_limits(path):
    """The joint trajectory equals MuJoCo's to 1e-6 over 0.5 s, limits and friction engaged (the gymnasium
    models and the walker hit their limits: MuJoCo has up to 6 limit rows at once)."""
    theirs, rows = _mujoco_run(path, 10, 1)
    ours = _tumble_run(path)
    assert ours.shape == theirs.shape
    assert np.max(np.abs(ours - theirs)) < TOLERANCE
    name = os.path.basename(path)
    if name in ("hopper.xml", "walker2d_v5.xml", "ant.xml", "humanoid.xml", "walker.xml", "finger.xml"):
        assert rows > 0, "the run should engage a limit or friction"


@pytest.mark.parametrize("name", ["half_cheetah", "cartpole", "acrobot", "point_mass"])
def test_mujoco_against_itself_is_far_inside_the_tolerance_off_the_limits(name):
    """Where no limit engages, MuJoCo at dt/10 and dt/20 (the same held controls) agree far inside 1e-6: the
    comparison above tests the physics, not the integrator. Across a limit's onset RK4 is only first order (the
    limit's force jumps), so on the limited models the two step sizes differ by 1e-4 to 5e-3 rad: there the
    comparison at one step size is what shows the same physics, to rounding."""
    path = os.path.join(GYMNASIUM if name == "half_cheetah" else SUITE, f"{name}.xml")
    coarse, rows = _mujoco_run(path, 10, 1)
    fine, _ = _mujoco_run(path, 20, 2)
    assert rows == 0
    assert np.max(np.abs(coarse - fine)) < 0.01 * TOLERANCE


_PROBE = """<mujoco><option timestep="0.002"/>
<worldbody><body pos="0 0 1">
  <joint name="a" type="hinge" axis="0 1 0" range="-20 25" margin="0.05" frictionloss="0.7" armature="0.1"
         solreflimit="0.03 0.8" solimplimit="0.8 0.95 0.01 0.4 3" solreffriction="0.01 1.2"
         solimpfriction="0.7 0.9 0.02 0.5 2"/>
  <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05" mass="1"/>
  <body pos="0.5 0 0"><joint name="b" type="hinge" axis="0 1 0" range="-60 60" damping="0.2"/>
    <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.04" mass="0.5"/>
    <body pos="0.4 0 0"><joint name="c" type="ball" frictionloss="0.05"/>
      <geom type="sphere" size="0.05" mass="0.2" pos="0.1 0 0"/></body>
  </body>
</body></worldbody>
<tendon><fixed name="t" range="-0.2 0.2" limited="true" frictionloss="0.3" stiffness="5" damping="0.4"
  springlength="0.05" solreflimit="-2000 -40"><joint joint="a" coef="1"/><joint joint="b" coef="-0.5"/></fixed></tendon>
<actuator><motor joint="a" gear="3" ctrlrange="-1 1" forcerange="-0.8 0.5"/>
  <position tendon="t" kp="20" kv="1" forcerange="-2 2"/></actuator>
</mujoco>"""


def test_constrained_accelerations_equal_mujocos_at_random_states():
    """Limits near and past their margins, joint and tendon friction (a ball joint's too), a tendon's limit with a
    direct (negative) solref, its spring and damper, and actuators clipped by forcerange and ctrlrange: ``q̈``
    equals MuJoCo's ``qacc`` (Newton to rounding) at random states."""
    art = from_mjcf(_PROBE)
    model = mujoco.MjModel.from_xml_string(_PROBE)
    model.opt.tolerance, model.opt.iterations = 1e-15, 1000
    data = mujoco.MjData(model)
    rng = np.random.default_rng(3)
    engaged = set()
    for _ in range(40):
        quat = rng.normal(size=4)
        data.qpos[:] = [*rng.uniform(-0.5, 0.5, 2), *(quat / np.linalg.norm(quat))]
        data.qvel[:] = rng.normal(scale=2.0, size=model.nv)
        data.ctrl[:] = rng.uniform(-2.0, 2.0, size=model.nu)
        mujoco.mj_forward(model, data)
        engaged |= set(data.efc_type[: data.nefc].tolist())
        art.q, art.qd, art.ctrl = data.qpos, data.qvel, data.ctrl
        np.testing.assert_allclose(art.actuator_forces(), data.actuator_force, rtol=0, atol=1e-12)
        np.testing.assert_allclose(art.tendon_lengths(), data.ten_length, rtol=0, atol=1e-14)
        scale = max(1.0, np.max(np.abs(data.qacc)))
        np.testing.assert_allclose(art.forward_dynamics(), data.qacc, rtol=0, atol=1e-9 * scale)
    kinds = mujoco.mjtConstraint
    assert {int(kinds.mjCNSTR_FRICTION_DOF), int(kinds.mjCNSTR_FRICTION_TENDON), int(kinds.mjCNSTR_LIMIT_JOINT),
            int(kinds.mjCNSTR_LIMIT_TENDON)} <= engaged  # fmt: skip


def test_a_hinge_rests_on_its_limit_where_the_soft_constraint_balances_gravity():
    """A horizontal rod held by its lower limit settles at the violation where the limit's spring ``k d r``
    (MuJoCo's reference acceleration, with its regulariser) carries gravity's torque; analytic steady state."""
    length = 0.5
    softness = SoftConstraint(solref=(0.02, 1.0), solimp=(0.9, 0.9, 0.001, 0.5, 2.0))  # a constant impedance d
    art = Articulation(gravity=(0, 0, -9.81))
    art.add_link(Revolute((0, -1, 0)), mass=1.0, shape_position=(length, 0, 0), limits=(0.0, 1.0),
                 limit_softness=softness)  # fmt: skip
    for dt in (1 / 60, 1 / 240, 1e-3):
        art.q, art.qd = [0.0], [0.0]
        art.simulate(3.0, dt, integrator="rk4")
        # at rest q̈ = a0 + A f = 0 and f minimises ½ (A + R) f² + (a0 - aref) f: so aref = -a0 R / A, with
        # aref = -k d r, R = (1 - d)/d · A (invweight0 = A = 1/(m l²)), a0 = -g cos(r)/l and k = 1/(d² τ²), τ at
        # least 2 dt
        d, k = 0.9, 1.0 / (0.81 * max(0.02, 2 * dt) ** 2)
        expected = 0.0
        for _ in range(5):  # the fixed point of r = a0(r) (1 - d)/(k d²)
            expected = -9.81 * np.cos(expected) / length * (1.0 - d) / (k * d * d)
        assert art.q[0] == pytest.approx(expected, rel=1e-12)
        assert expected < 0.0


def test_frictionloss_holds_a_joint_below_its_breakaway_torque_and_lets_it_go_above():
    """Dry friction of 2 N m on a rod whose gravity torque is 1.5 N m: MuJoCo's soft friction creeps at
    ``(1 - d) a0 / (d b)`` (its reference acceleration ``-b q̇``, impedance ``d = d_min`` at no violation, ``b = 2 /
    (d_max τ)``); at 2.5 N m the rod falls with the net 0.5 N m."""
    for torque in (1.5, 2.5):
        art = Articulation(gravity=(0, 0, -9.81))
        mass = torque / 9.81
        art.add_link(Revolute((0, -1, 0)), mass=mass, shape_position=(1.0, 0, 0), frictionloss=2.0)
        art.simulate(0.1, 1e-4, integrator="rk4")
        a0 = -torque / mass  # gravity's torque over the inertia m l², l = 1 m, near level
        if torque < 2.0:
            d, b = 0.9, 2.0 / (0.95 * 0.02)  # MuJoCo's default solimp and solref
            assert art.qd[0] == pytest.approx((1.0 - d) * a0 / (d * b), rel=1e-3)
        else:
            assert art.forward_dynamics()[0] == pytest.approx((2.0 - torque) / mass, rel=1e-3)


@pytest.mark.parametrize(
    ("xml", "message"),
    [
        ('<tendon><fixed name="t"><joint joint="nope" coef="1"/></fixed></tendon>', r"line 5.*'nope' names no joint"),
        ('<tendon><fixed><joint joint="ball" coef="1"/></fixed></tendon>', r"is a ball: a fixed tendon runs over"),
        ('<tendon><fixed range="1 0" limited="true"><joint joint="h" coef="1"/></fixed></tendon>', r"lower bound"),
        ('<actuator><motor tendon="missing"/></actuator>', r"tendon='missing' names no fixed tendon"),
        ('<actuator><motor joint="h" ctrlrange="1 -1" ctrllimited="true"/></actuator>', r"ctrlrange.*lower bound"),
    ],
)
def test_bad_tendons_and_actuators_are_refused_naming_the_element_and_line(xml, message):
    model = f"""<mujoco><worldbody><body><joint name="h" type="hinge"/><geom size="0.1"/>
    <body><joint name="ball" type="ball"/><geom size="0.1"/></body></body></worldbody>


    {xml}</mujoco>"""
    with pytest.raises(MJCFError, match=message):
        from_mjcf(model)


def test_a_negative_armature_is_refused_naming_the_element_and_line():
    with pytest.raises(MJCFError, match=r"line 2.*armature"):
        from_mjcf('<mujoco><worldbody><body>\n<joint armature="-1"/><geom size="0.1"/></body></worldbody></mujoco>')


@pytest.mark.parametrize("name", ["half_cheetah", "hopper"])
def test_mujocos_euler_is_symplectic_euler_with_the_damping_implicit(name):
    """MuJoCo's Euler integrator at the model's own timestep, contact-free and driven: ``symplectic_implicit_damping``
    follows it to 1e-9 over 0.5 s (explicit damping parts by 0.4 rad/s in one HalfCheetah control step)."""
    path = os.path.join(GYMNASIUM, f"{name}.xml")
    model, data = _mujoco(path, 1)
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    art = _without_contacts(path)
    dt = model.opt.timestep
    assert np.any(model.dof_damping > 0)
    for step in range(round(DURATION / dt)):
        data.ctrl[:] = art.ctrl = _controls(model.nu, step * dt)
        mujoco.mj_step(model, data)
        art.step(dt, integrator="symplectic_implicit_damping")
    np.testing.assert_allclose(art.q, data.qpos, rtol=0, atol=1e-9)
    np.testing.assert_allclose(art.qd, data.qvel, rtol=0, atol=1e-8)
