"""ArticulationBatch: many copies of an articulation in one call, each bit for bit the articulation alone."""

from __future__ import annotations

import os

import numpy as np
import pytest

from compiled import compiled_only
from tumble import SimulationError
from tumble.articulation import Articulation, ArticulationBatch, Ball, Free, Prismatic, Revolute
from tumble.articulation.chain import BLOCK, serial_chain
from tumble.articulation.model import model_views, python_function
from tumble.dynamics.integrate import using_threads
from tumble.mass import MassProperties
from tumble.shapes import Box


def cart_pole() -> Articulation:
    art = Articulation()
    cart = art.add_link(Prismatic((1, 0, 0)), mass=1.0, damping=0.05)
    art.add_link(Revolute((0, 1, 0)), parent=cart, shape=Box((0.04, 0.04, 1.0)), mass=0.1,
                 shape_position=(0, 0, 0.5))  # fmt: skip
    return art


def ball_chain() -> Articulation:
    """A ball-jointed link under a hinged one: quaternion coordinates and a spring."""
    art = Articulation()
    top = art.add_link(Ball(), shape=Box((0.1, 0.1, 0.6)), mass=1.0, shape_position=(0, 0, -0.3))
    art.add_link(Revolute((1, 0, 0)), parent=top, position=(0, 0, -0.6), mass=0.5, shape_position=(0, 0, -0.4),
                 stiffness=3.0, springref=0.2)  # fmt: skip
    return art


def four_bar() -> Articulation:
    """A crank-rocker closed by a loop (ground 0.55, crank 0.2, coupler 0.6, rocker 0.5 m)."""
    art = Articulation()
    crank = art.add_link(Revolute((0, 1, 0)), mass=0.3, shape_position=(0.1, 0, 0))
    coupler = art.add_link(Revolute((0, 1, 0)), parent=crank, position=(0.2, 0, 0), mass=0.6,
                           shape_position=(0.3, 0, 0))  # fmt: skip
    rocker = art.add_link(Revolute((0, 1, 0)), position=(0.55, 0, 0), mass=0.5, shape_position=(0.25, 0, 0))
    art.add_loop_closure(coupler, (0.6, 0, 0), rocker, (0.5, 0, 0))
    art.q = [-1.2, 1.0, -1.8]
    art.project_loop_closures()
    return art


def free_body() -> Articulation:
    art = Articulation(gravity=(0.0, 0.0, -9.81))
    art.add_link(Free(), mass_properties=MassProperties(2.0, np.zeros(3), np.diag([0.1, 0.2, 0.3])))
    art.qd = [0.1, 0.0, 0.2, 1.0, 2.0, 3.0]  # a tumbling throw: the intermediate axis is unstable
    return art


def slide_hinge_chain() -> Articulation:
    """A serial chain of six slides and hinges (the short-chain path, ``articulation/chain.py``) with all it handles:
    tilted gravity, turned joint frames and axes, offset masses, damping, springs and armature."""
    art = Articulation(gravity=(0.3, -0.2, -9.81))
    link = art.add_link(Prismatic((0.6, 0.8, 0.0)), mass=2.0, damping=0.3, armature=0.01, position=(0.1, 0.2, 0.3),
                        orientation=(0.9, 0.1, 0.3, 0.2))  # fmt: skip
    for i in range(5):
        joint = Revolute((0.2, 1.0, 0.1)) if i % 2 == 0 else Prismatic((0.0, 0.3, 1.0))
        link = art.add_link(joint, parent=link, position=(0.1, 0.05 * i, 0.4), orientation=(1.0, 0.2 * i, 0.0, 0.1),
                            shape=Box((0.1, 0.05, 0.3)), mass=0.5 + 0.1 * i, shape_position=(0.02, 0.01, 0.2),
                            damping=0.05 * i, stiffness=2.0 * (i % 3), springref=0.1, armature=0.001 * i)  # fmt: skip
    return art


def _spread(art: Articulation, batch: ArticulationBatch, rng) -> None:
    """Different starts and joint forces per copy (quaternions stay unit: the hinges' rows only)."""
    quat_rows = {row for start, _ in art._quat_starts for row in range(start, start + 4)}
    for k in range(art.nq):
        if k not in quat_rows and not (art.links[0].joint.nq == 7 and k < 3):
            batch.q[:, k] += rng.uniform(-0.1, 0.1, batch.n)
    batch.qd[...] += rng.uniform(-0.5, 0.5, batch.qd.shape)
    batch.tau[...] = rng.uniform(-1.0, 1.0, batch.tau.shape)


@pytest.mark.parametrize("build", [cart_pole, slide_hinge_chain, ball_chain, four_bar, free_body])
@pytest.mark.parametrize("integrator", ["rk4", "symplectic", "euler"])
def test_every_copy_moves_bit_for_bit_as_the_articulation_alone(build, integrator):
    art = build()
    batch = ArticulationBatch(art, 5)
    _spread(art, batch, np.random.default_rng(3))
    q0, qd0 = batch.q.copy(), batch.qd.copy()
    batch.step(1e-3, steps=40, integrator=integrator)
    batch.step(1e-3, steps=10, integrator=integrator)
    assert batch.time == pytest.approx(0.05, abs=1e-15)
    for c in range(batch.n):
        alone = build()
        alone.q, alone.qd = q0[c], qd0[c]
        for _ in range(50):
            alone.step(1e-3, tau=batch.tau[c], integrator=integrator)
        np.testing.assert_array_equal(batch.q[c], alone.q)
        np.testing.assert_array_equal(batch.qd[c], alone.qd)
    assert np.ptp(batch.q[:, -1]) > 0.0  # the copies differ


def _branched() -> Articulation:
    art = Articulation()
    root = art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -0.5))
    for side in (-1.0, 1.0):
        art.add_link(Revolute((1, 0, 0)), parent=root, position=(side, 0, -1), mass=0.5, shape_position=(0, 0, -0.3))
    return art


def _limited() -> Articulation:
    art = cart_pole()
    art.add_link(Revolute((0, 1, 0)), parent=1, position=(0, 0, 1), mass=0.1, shape_position=(0, 0, 0.2),
                 limits=(-0.5, 0.5))  # fmt: skip
    return art


@pytest.mark.parametrize(
    ("build", "takes_it"),
    [(cart_pole, True), (slide_hinge_chain, True), (ball_chain, False), (four_bar, False), (free_body, False),
     (_branched, False), (_limited, False)],
)  # fmt: skip
def test_the_short_chain_path_takes_serial_chains_of_hinges_and_slides_with_nothing_to_solve(build, takes_it):
    compiled = build()._compile()
    model = python_function(model_views)(compiled.ints, compiled.reals)
    assert python_function(serial_chain)(model) is takes_it


@compiled_only("150 copies over 40 steps: minutes as plain Python")
@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("integrator", ["rk4", "symplectic", "euler"])
def test_a_chain_stepped_side_by_side_in_blocks_moves_bit_for_bit_as_alone(threads, integrator):
    """The short-chain path steps its copies in blocks (``chain.BLOCK``): two full blocks and part of a third, split
    over the threads, each copy the bits of the articulation alone at 60 Hz and 1 kHz."""
    art = slide_hinge_chain()
    for dt in (1 / 60, 1e-3):
        batch = ArticulationBatch(art, 2 * BLOCK + 22)
        _spread(art, batch, np.random.default_rng(11))
        q0, qd0 = batch.q.copy(), batch.qd.copy()
        with using_threads(min(threads, os.cpu_count() or 1)):
            batch.step(dt, steps=30, integrator=integrator)
            batch.step(dt, steps=10, integrator=integrator)
        for c in (0, BLOCK - 1, BLOCK, 2 * BLOCK + 21):
            alone = slide_hinge_chain()
            alone.q, alone.qd = q0[c], qd0[c]
            for _ in range(40):
                alone.step(dt, tau=batch.tau[c], integrator=integrator)
            np.testing.assert_array_equal(batch.q[c], alone.q)
            np.testing.assert_array_equal(batch.qd[c], alone.qd)


@compiled_only("a 20-link chain's copies over 20 steps: minutes as plain Python")
@pytest.mark.parametrize("dt", [1 / 240, 1e-3])
def test_a_long_chain_on_the_short_chain_path_keeps_its_bits(dt):
    """Twenty links (the block's rows grow with the chain, 60 kB a link): copies in a full and a part block, each the
    bits of the articulation alone, at 240 Hz and 1 kHz."""

    def long_chain() -> Articulation:
        art, link = Articulation(), None
        for i in range(20):
            joint = Revolute((0.1, 1.0, 0.2)) if i % 3 else Prismatic((1.0, 0.0, 0.3))
            link = art.add_link(joint, parent=link, position=(0, 0, 0) if link is None else (0, 0, -0.3), mass=1.0,
                                shape_position=(0.05, 0, -0.15), damping=0.01 * i)  # fmt: skip
        return art

    batch = ArticulationBatch(long_chain(), BLOCK + 6)
    batch.q[:] = np.random.default_rng(20).uniform(-0.3, 0.3, batch.q.shape)
    q0 = batch.q.copy()
    batch.step(dt, steps=20, integrator="rk4")
    for c in (0, BLOCK - 1, BLOCK + 5):
        alone = long_chain()
        alone.q = q0[c]
        for _ in range(20):
            alone.step(dt, integrator="rk4")
        np.testing.assert_array_equal(batch.q[c], alone.q)
        np.testing.assert_array_equal(batch.qd[c], alone.qd)


@compiled_only("150 copies: minutes as plain Python")
def test_a_chain_copy_that_blows_up_mid_block_is_named_and_every_copy_keeps_its_state():
    """A copy that overflows in the middle of a block of the short-chain path: the error names it and its step as the
    per-copy path does, and no copy moves; without it, the block steps on."""
    art = slide_hinge_chain()
    batch = ArticulationBatch(art, 2 * BLOCK + 22)
    _spread(art, batch, np.random.default_rng(5))
    before = (batch.q.copy(), batch.qd.copy())
    batch.qd[BLOCK + 5, 2] = 1e200
    qd_set = batch.qd.copy()
    with pytest.raises(SimulationError, match=rf"copy {BLOCK + 5}: link #\d got a non-finite .* at step 0 ") as caught:
        batch.step(0.01, steps=5, integrator="rk4")
    assert caught.value.copy == BLOCK + 5
    np.testing.assert_array_equal(batch.q, before[0])
    np.testing.assert_array_equal(batch.qd, qd_set)
    batch.qd[BLOCK + 5, 2] = 0.0
    batch.step(0.01, steps=5, integrator="rk4")
    assert np.all(np.isfinite(batch.q)) and batch.time > 0.0


# As plain Python the short-chain path's arithmetic is NumPy scalars', which warn of the zero pivot it then discards.
@pytest.mark.filterwarnings("ignore:divide by zero:RuntimeWarning", "ignore:invalid value:RuntimeWarning")
def test_a_chain_with_a_massless_end_is_singular_as_on_the_per_copy_path():
    art = Articulation()
    hinge = art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -0.5))
    art.add_link(Prismatic((0, 0, 1)), parent=hinge)  # moves no mass: a zero pivot
    batch = ArticulationBatch(art, 3)
    with pytest.raises(SimulationError, match=r"copy 0: link #1 got a singular mass matrix at step 0"):
        batch.step(0.01, integrator="rk4")
    with pytest.raises(SimulationError, match=r"singular at degree of freedom 1 \(joint of link #1\)"):
        art.step(0.01, integrator="rk4")


@compiled_only("two threads only matter compiled")
def test_two_threads_give_the_bits_of_one():
    art = ball_chain()
    results = []
    for count in (1, 2):
        batch = ArticulationBatch(art, 64)
        _spread(art, batch, np.random.default_rng(8))
        with using_threads(min(count, os.cpu_count() or 1)):
            batch.step(1e-3, steps=20, integrator="rk4")
        results.append((batch.q.copy(), batch.qd.copy()))
    np.testing.assert_array_equal(results[0][0], results[1][0])
    np.testing.assert_array_equal(results[0][1], results[1][1])


def test_a_free_links_joint_forces_are_a_world_force_and_a_body_torque():
    """For a Free joint ``tau`` = (force, world frame; torque about the origin, link frame): a 2 kg body turned
    90 deg about z, pushed along world x and twisted about its own x axis, accelerates along world x at F/m and
    spins up about its own x at T/Ixx (from rest, no gyroscopic term)."""
    art = Articulation(gravity=(0.0, 0.0, 0.0))
    quarter = (np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4))
    art.add_link(Free(), orientation=quarter,
                 mass_properties=MassProperties(2.0, np.zeros(3), np.diag([0.1, 0.2, 0.3])))  # fmt: skip
    batch = ArticulationBatch(art, 2)
    batch.tau[:] = (4.0, 0.0, 0.0, 0.05, 0.0, 0.0)
    batch.tau[1] *= 2.0
    batch.step(1e-3, steps=100, integrator="rk4")
    for c, scale in enumerate((1.0, 2.0)):
        np.testing.assert_allclose(batch.qd[c, :3], (scale * 2.0 * 0.1, 0.0, 0.0), atol=1e-12)
        np.testing.assert_allclose(batch.q[c, :3], (scale * 0.5 * 2.0 * 0.1**2, 0.0, 0.0), atol=1e-12)
        np.testing.assert_allclose(batch.qd[c, 3:], (scale * 0.5 * 0.1, 0.0, 0.0), atol=1e-12)


def test_assigned_states_are_validated_and_quaternions_renormalised():
    art = ball_chain()
    batch = ArticulationBatch(art, 3)
    q = batch.q.copy()
    q[1, :4] = (2.0, 0.0, 0.0, 0.0)
    batch.q = q
    np.testing.assert_array_equal(batch.q[1, :4], (1.0, 0.0, 0.0, 0.0))
    q[2, :4] = 0.0
    with pytest.raises(ValueError, match=r"q\[2, 0:4\] \(link 0\) must be a non-zero quaternion"):
        batch.q = q
    np.testing.assert_array_equal(batch.q[2, :4], (1.0, 0.0, 0.0, 0.0))  # refused: nothing changed
    with pytest.raises(ValueError, match="qd"):
        batch.qd = np.zeros((3, 5))
    with pytest.raises(ValueError, match="tau"):
        batch.tau = np.zeros((2, 4))


@pytest.mark.parametrize(
    ("args", "error", "match"),
    [
        (("not an articulation", 2), TypeError, "articulation must be an Articulation"),
        ((Articulation(), 2), ValueError, "no links"),
        ((cart_pole(), 0), ValueError, "n must be"),
        ((cart_pole(), 2.5), ValueError, "n must be an integer"),
        ((cart_pole(), 2**31 - 1), ValueError, r"n=2147483647 copies of a 2-coordinate articulation would take"),
    ],
)
def test_bad_construction_names_the_argument(args, error, match):
    with pytest.raises(error, match=match):
        ArticulationBatch(*args)


def test_bad_steps_name_the_argument_and_change_nothing():
    batch = ArticulationBatch(cart_pole(), 2)
    batch.q[:, 1] = 0.3
    with pytest.raises(ValueError, match="integrator must be one of"):
        batch.step(0.01, integrator="verlet")
    with pytest.raises(ValueError, match="dt"):
        batch.step(-0.01)
    with pytest.raises(ValueError, match="steps must be"):
        batch.step(0.01, steps=0)
    batch.tau[1, 0] = np.nan
    with pytest.raises(ValueError, match=r"tau\[1, 0\] must be finite, got nan"):
        batch.step(0.01)
    np.testing.assert_array_equal(batch.q[:, 1], 0.3)
    assert batch.time == 0.0


def test_a_copy_that_blows_up_names_itself_and_every_copy_keeps_its_state():
    batch = ArticulationBatch(cart_pole(), 4)
    batch.step(0.01, steps=2)
    before = (batch.q.copy(), batch.qd.copy(), batch.time)
    batch.qd[2, 1] = 1e200  # squared in the centripetal terms: overflows
    qd_set = batch.qd.copy()
    with pytest.raises(SimulationError, match=r"copy 2: link #\d got a non-finite") as caught:
        batch.step(0.01, steps=5, integrator="rk4")
    assert caught.value.copy == 2
    assert caught.value.body in (0, 1)
    np.testing.assert_array_equal(batch.q, before[0])
    np.testing.assert_array_equal(batch.qd, qd_set)
    assert batch.time == before[2]
    batch.qd[2, 1] = 0.0
    batch.step(0.01)  # the others step on
    assert batch.time > before[2]


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240, 1e-3])
@pytest.mark.parametrize("steps", [1, 16])
def test_copies_match_the_articulation_at_every_rate_and_steps_per_call(dt, steps):
    """The same bits at 60 Hz, 240 Hz and 1 kHz, whether a call takes 1 or 16 steps."""
    art = cart_pole()
    batch = ArticulationBatch(art, 3)
    _spread(art, batch, np.random.default_rng(1))
    q0, qd0 = batch.q.copy(), batch.qd.copy()
    for _ in range(32 // steps):
        batch.step(dt, steps=steps, integrator="rk4")
    for c in range(batch.n):
        alone = cart_pole()
        alone.q, alone.qd = q0[c], qd0[c]
        for _ in range(32):
            alone.step(dt, tau=batch.tau[c], integrator="rk4")
        np.testing.assert_array_equal(batch.q[c], alone.q)
        np.testing.assert_array_equal(batch.qd[c], alone.qd)
    assert batch.time == pytest.approx(32 * dt, rel=1e-12)
