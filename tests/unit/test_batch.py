"""tumble.Batch: copies of one world stepped together equal separate worlds bit for bit; overrides, resets, loads,
one copy as a world, and errors at the boundary."""

from __future__ import annotations

import os

import numpy as np
import pytest

import tumble
from compiled import compiled_only
from tumble import Batch
from tumble import mass as tm
from tumble.dynamics import integrate

two_cores = pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="needs two cores")
compiled = compiled_only("a minute as plain Python")
THREADS = [1, pytest.param(2, marks=two_cores)]
BODY_FIELDS = ("body_pos", "body_quat", "body_linvel", "body_angmom")


def _spinning(k: int, *, gravity=(0.0, 0.0, -9.81), integrator="auto") -> tumble.World:
    """Two free bodies without shapes (a box's and a sphere's mass), with motion that depends on ``k``."""
    world = tumble.World(gravity=gravity, integrator=integrator)
    world.add_body(mass_properties=tm.box((0.2, 0.3, 0.5), mass=2.0), velocity=(k, 0, 1),
                   angular_velocity=(1 + 0.1 * k, 5, 0.1))  # fmt: skip
    world.add_body(mass_properties=tm.solid_sphere(0.2, mass=1.0), position=(1, 0, 0), angular_velocity=(0.2, -k, 3))
    return world


def _pile(k: int, *, gravity=(0.0, 0.0, -9.81), friction=0.5, restitution=0.0, throw=2.0) -> tumble.World:
    """Three boxes dropped on a plane and a sphere thrown at them (at ``throw + k`` m/s)."""
    world = tumble.World(gravity=gravity)
    world.add_static(tumble.Plane(), friction=friction, restitution=restitution)
    for level in range(3):
        world.add_body(tumble.Box((0.5, 0.5, 0.5)), mass=1.0, position=(0.05 * level, 0, 0.3 + 0.55 * level),
                       friction=friction, restitution=restitution)  # fmt: skip
    world.add_body(tumble.Sphere(0.2), mass=0.5, position=(-2, 0, 0.5), velocity=(throw + k, 0, 1),
                   angular_velocity=(0, k, 0), friction=friction, restitution=restitution)  # fmt: skip
    return world


def _chain(k: int, *, spring_target=0.0) -> tumble.World:
    """A three-link hinge chain hung from the world, the first link sprung towards ``spring_target``."""
    world = tumble.World()
    links = [world.add_body(tumble.Capsule(0.05, 0.4), mass=1.0, position=(0.5 * i + 0.25, 0, 0),
                            orientation=(0.7071067811865476, 0, 0.7071067811865476, 0)) for i in range(3)]  # fmt: skip
    links[0].angular_velocity = (0, 0.3 * k, 0)
    world.add_joint(tumble.HingeJoint(links[0], None, (0, 0, 0), (0, 1, 0), spring_hertz=2.0,
                                      spring_damping_ratio=0.1, spring_target=spring_target))  # fmt: skip
    for a, b in zip(links[:-1], links[1:], strict=True):
        world.add_joint(tumble.HingeJoint(a, b, (0.5 * (a.index + 1), 0, 0), (0, 1, 0)))
    return world


def _batch_of(worlds: list[tumble.World]) -> Batch:
    """A batch of the first world's model whose copies start from each world's state."""
    batch = Batch(worlds[0], len(worlds))
    for c, world in enumerate(worlds):
        for f in BODY_FIELDS:
            getattr(batch.state, f)[c] = getattr(world.state, f)
    return batch


def _assert_copies_equal(batch: Batch, worlds: list[tumble.World]) -> None:
    for c, world in enumerate(worlds):
        for f in (*BODY_FIELDS, "body_sleep_time", "body_sleeping"):
            assert np.array_equal(getattr(batch.state, f)[c], getattr(world.state, f)), (c, f)
    assert batch.time == worlds[0].time and batch.step_count == worlds[0].step_count


# --- copies are separate worlds -----------------------------------------------------------------------


@pytest.mark.parametrize("threads", THREADS)
@pytest.mark.parametrize("integrator", ["auto", "rk4", "symplectic", "euler", "midpoint"])
def test_free_copies_equal_separate_worlds_bit_for_bit(integrator, threads, monkeypatch):
    monkeypatch.setattr(integrate, "PARALLEL_MIN_WORK", 1)  # split the rows over the threads at this small size
    worlds = [_spinning(k, integrator=integrator) for k in range(6)]
    batch = _batch_of(worlds)
    with integrate.using_threads(threads):
        batch.step(1e-3, steps=200)
        batch.step(1e-3)
    for world in worlds:
        for _ in range(201):
            world.step(1e-3)
    _assert_copies_equal(batch, worlds)


@compiled  # the other tests' piles run the batch's contact kernels as plain Python
@pytest.mark.parametrize("threads", THREADS)
def test_copies_with_contacts_equal_separate_worlds_bit_for_bit(threads):
    worlds = [_pile(k) for k in range(5)]  # two blocks (one per core) of two and three copies
    batch = _batch_of(worlds)
    with integrate.using_threads(threads):
        batch.step(1 / 60, steps=40)
        for _ in range(20):
            batch.step(1 / 60)
    for world in worlds:
        for _ in range(60):
            world.step(1 / 60)
    _assert_copies_equal(batch, worlds)
    assert not np.array_equal(batch.state.body_pos[0], batch.state.body_pos[4])  # the copies did differ


@compiled
def test_copies_whose_fast_pairs_find_contacts_again_within_steps_equal_separate_worlds():
    """A pair that closes fast finds its contacts again within the step by its own motion only (issue 44), so a
    copy's fast sphere changes nothing in the copies beside it."""
    worlds = [_pile(k, throw=2.0 if k % 2 == 0 else 30.0) for k in range(5)]
    batch = _batch_of(worlds)
    batch.step(1 / 60, steps=60)
    for world in worlds:
        for _ in range(60):
            world.step(1 / 60)
    _assert_copies_equal(batch, worlds)
    # The fast spheres' pairs did find theirs again, in the batch and in the worlds of fast spheres.
    assert sum(block.scratch.steps_found_again for block in batch._blocks) > 0
    assert sum(world._scratch.steps_found_again for world in worlds) > 0


@compiled  # the reset test's chains run the batch's joint kernels as plain Python
@pytest.mark.parametrize("threads", THREADS)
def test_jointed_copies_equal_separate_worlds_bit_for_bit(threads):
    worlds = [_chain(k) for k in range(3)]
    batch = _batch_of(worlds)
    with integrate.using_threads(threads):
        batch.step(1 / 240, steps=120)
    for world in worlds:
        for _ in range(120):
            world.step(1 / 240)
    _assert_copies_equal(batch, worlds)


def _dropped_on(x: float) -> tumble.World:
    """A box at rest on a plane (asleep after half a second) and a second one dropped from 3 m at ``x``."""
    world = tumble.World()
    world.add_static(tumble.Plane())
    world.add_body(tumble.Box((0.5, 0.5, 0.5)), mass=1.0, position=(0, 0, 0.25))
    world.add_body(tumble.Box((0.3, 0.3, 0.3)), mass=1.0, position=(x, 0, 3.0))
    return world


def test_copies_sleep_and_wake_on_their_own_as_separate_worlds():
    """Copy 0's falling box lands on its sleeping box, copy 1's lands beside it: in the same place, but the first
    wakes only its own copy's island."""
    worlds = [_dropped_on(0.0), _dropped_on(2.0)]
    batch = _batch_of(worlds)
    batch.step(1 / 60, steps=40)
    assert batch.state.body_sleeping[:, 1].all()  # both resting boxes asleep before the drop
    batch.step(1 / 60, steps=16)
    for world in worlds:
        for _ in range(56):
            world.step(1 / 60)
    _assert_copies_equal(batch, worlds)
    assert not batch.state.body_sleeping[0, 1] and batch.state.body_sleeping[1, 1]
    assert batch.world(1).state.body_island[1] == 1  # islands numbered as in one world


def test_a_batch_of_one_is_the_world():
    world, twin = _pile(1), _pile(1)
    batch = Batch(twin, 1)
    for _ in range(45):
        world.step(1 / 60)
        batch.step(1 / 60)
    _assert_copies_equal(batch, [world])
    assert batch.world(0).state.digest() == world.state.digest()  # contacts and warm starts too


def test_the_state_is_one_block_copy_major():
    batch = Batch(_spinning(0), 3)
    assert batch.state.body_pos.shape == (3, 2, 3) and batch.state.body_quat.shape == (3, 2, 4)
    assert batch.state.body_sleeping.shape == (3, 2) and batch.inputs.body_force.shape == (3, 2, 3)
    flat = batch.state.body_pos.reshape(6, 3)
    assert np.shares_memory(flat, batch.state.body_pos)
    with pytest.raises(AttributeError):
        batch.state.body_pos = np.zeros((3, 2, 3))  # views are written into, not rebound


# --- overrides ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("make", [_spinning, _pile], ids=["free", "contacts"])
def test_copies_with_their_own_gravity_equal_worlds_built_with_it(make):
    gravities = [(0, 0, -9.81), (0, 0, -1.62), (0.5, -0.2, -3.7), (0, 0, 0)]
    worlds = [make(1, gravity=g) for g in gravities]
    batch = _batch_of([make(1) for _ in gravities])
    batch.override(gravity=np.array(gravities))
    batch.step(1 / 60, steps=40)
    for world in worlds:
        for _ in range(40):
            world.step(1 / 60)
    _assert_copies_equal(batch, worlds)
    assert np.array_equal(batch.gravity, np.array(gravities, float))


def test_copies_with_their_own_friction_and_restitution_equal_worlds_built_with_them():
    values = [(0.5, 0.0), (0.1, 0.0), (0.9, 0.6), (0.0, 1.0)]
    worlds = [_pile(2, friction=f, restitution=e) for f, e in values]
    batch = Batch(_pile(2), len(values))
    shapes = batch.friction.shape[1]
    batch.override([2, 3], friction=[[0.9] * shapes, [0.0] * shapes], restitution=[[0.6] * shapes, [1.0] * shapes])
    batch.override(np.array([False, True, False, False]), friction=np.full(shapes, 0.1))
    batch.step(1 / 60, steps=40)
    for world in worlds:
        for _ in range(40):
            world.step(1 / 60)
    _assert_copies_equal(batch, worlds)


def _loaded(box_mass: float, sphere_mass: float) -> tumble.World:
    """The pile with a heavier sphere and a spinning box beside it."""
    world = tumble.World()
    world.add_static(tumble.Plane())
    for level in range(3):
        world.add_body(tumble.Box((0.5, 0.5, 0.5)), mass=1.0, position=(0.05 * level, 0, 0.3 + 0.55 * level))
    world.add_body(tumble.Sphere(0.2), mass=sphere_mass, position=(-2, 0, 0.5), velocity=(3, 0, 1))
    world.add_body(tumble.Box((0.3, 0.3, 0.3)), mass=box_mass, position=(1.5, 0, 0.3), velocity=(2, 0, 0))
    return world


def test_copies_with_their_own_masses_match_worlds_built_with_them():
    masses = [(1.0, 0.5), (0.3, 0.5), (3.7, 1.9)]
    worlds = [_loaded(*m) for m in masses]
    batch = Batch(_loaded(1.0, 0.5), len(masses))
    table = batch.mass
    table[:, -2:] = [(s, b) for b, s in masses]
    batch.override(mass=table)
    batch.step(1 / 60, steps=45)
    for world in worlds:
        for _ in range(45):
            world.step(1 / 60)
    for c, world in enumerate(worlds):  # inertia scaled, not recomputed: equal to round-off, not bit for bit
        np.testing.assert_allclose(batch.state.body_pos[c], world.state.body_pos, rtol=0, atol=1e-9)
        np.testing.assert_allclose(batch.state.body_linvel[c], world.state.body_linvel, rtol=0, atol=1e-8)
    assert not np.allclose(batch.state.body_pos[0], batch.state.body_pos[2], atol=1e-3)  # mass mattered
    model = batch.world(2).model  # one copy as a world has the copy's masses and inertias
    assert model.body_mass[-1] == 3.7 and model.body_mass[-2] == 1.9
    np.testing.assert_allclose(model.body_inertia_local[-1], worlds[2].model.body_inertia_local[-1], rtol=1e-15)


def test_copies_with_their_own_spring_targets_equal_worlds_built_with_them():
    targets = [0.0, 0.4, -0.8]
    worlds = [_chain(1, spring_target=t) for t in targets]
    batch = Batch(_chain(1), len(targets))
    batch.override(drive_target=[[t, 0.0, 0.0] for t in targets])
    batch.step(1 / 120, steps=60)
    for world in worlds:
        for _ in range(60):
            world.step(1 / 120)
    _assert_copies_equal(batch, worlds)


# --- resets, loads, one copy as a world --------------------------------------------------------------


@pytest.mark.parametrize("make", [_pile, _chain], ids=["contacts", "joints"])
def test_reset_returns_chosen_copies_to_the_initial_state_and_replays_them_bit_for_bit(make):
    batch = Batch(make(1), 4)  # two blocks: copies 0, 1 and 2, 3
    batch.step(1 / 60, steps=20)
    after_20 = batch.state.copy()
    batch.step(1 / 60, steps=10)
    batch.reset([1, 3])
    for f in BODY_FIELDS:
        assert np.array_equal(getattr(batch.state, f)[[1, 3]], getattr(batch.initial_state, f)[[1, 3]])
    batch.reset(np.array([True, False, False, False]))
    batch.step(1 / 60, steps=20)  # copies 0, 1 and 3 ran 20 steps from the start, with the world's warm start
    for f in BODY_FIELDS:
        assert np.array_equal(getattr(batch.state, f)[[0, 1, 3]], getattr(after_20, f)[[0, 1, 3]]), f


def test_reset_to_given_states_and_to_a_written_initial_state():
    worlds = [_spinning(k) for k in range(3)]
    batch = Batch(_spinning(9), 3)
    batch.step(1e-3, steps=10)
    batch.reset(None, **{f: np.stack([getattr(w.state, f) for w in worlds]) for f in BODY_FIELDS})
    batch.step(1e-3, steps=50)
    for world in worlds:
        world.simulate(0.05, 1e-3)
    for c, world in enumerate(worlds):
        for f in BODY_FIELDS:
            assert np.array_equal(getattr(batch.state, f)[c], getattr(world.state, f))
    batch.initial_state.body_pos[2, 0] = (5.0, 0.0, 0.0)
    batch.reset(2)
    assert np.array_equal(batch.state.body_pos[2, 0], [5.0, 0.0, 0.0])
    batch.reset([0], body_pos=np.zeros((2, 3)))  # one row for all chosen copies; the rest from the initial state
    assert np.array_equal(batch.state.body_pos[0], np.zeros((2, 3)))
    assert np.array_equal(batch.state.body_quat[0], batch.initial_state.body_quat[0])


@pytest.mark.parametrize("make", [_spinning, _pile], ids=["free", "contacts"])
def test_loads_per_copy_equal_loads_on_separate_worlds(make):
    worlds = [make(k) for k in range(3)]
    batch = _batch_of(worlds)
    forces = np.array([(0.0, 0.0, 30.0), (5.0, -2.0, 0.0), (0.0, 0.0, 0.0)])
    point = (0.1, 0.2, 0.3)
    body = 1 if make is _spinning else 3
    batch.apply_force(body, forces, point)
    batch.apply_torque(body, (0.0, 0.5, 0.0))
    batch.step(1 / 60)
    batch.step(1 / 60)  # loads act in one step only
    for world, force in zip(worlds, forces, strict=True):
        world.bodies[body].apply_force(force, point)
        world.bodies[body].apply_torque((0.0, 0.5, 0.0))
        world.step(1 / 60)
        world.step(1 / 60)
    _assert_copies_equal(batch, worlds)
    assert not batch.inputs.body_force.any()


def test_one_copy_as_a_world_is_a_copy_that_steps_as_the_copy_does():
    batch = Batch(_pile(0), 3)
    batch.override(1, gravity=(0, 0, -2.0), friction=np.full(5, 0.3))
    batch.step(1 / 60, steps=20)
    world = batch.world(1)
    assert np.array_equal(world.gravity, [0, 0, -2.0]) and world.time == batch.time
    assert all(s.friction == 0.3 for s in world._builder.rows[0].shapes)
    before = batch.state.copy()
    for _ in range(25):
        world.step(1 / 60)
    assert np.array_equal(batch.state.body_pos, before.body_pos)  # stepping the world left the batch alone
    batch.step(1 / 60, steps=25)
    for f in BODY_FIELDS:
        assert np.array_equal(getattr(batch.state, f)[1], getattr(world.state, f))


# --- errors at the boundary ---------------------------------------------------------------------------


@pytest.mark.parametrize("n", [0, -3, 2.0, True, "4"])
def test_a_batch_needs_a_whole_number_of_copies(n):
    with pytest.raises(ValueError, match="^n must be an integer from 1"):
        Batch(_spinning(0), n)


def test_a_batch_is_made_of_a_world():
    with pytest.raises(TypeError, match="world must be a tumble.World, got str"):
        Batch("scene.toml", 3)


def test_a_world_with_parts_that_run_python_is_refused():
    world = _spinning(0)
    world.add_controller(lambda w, t: None)
    world.wind = (1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match=r"world has controllers \(1\), wind: a Batch steps"):
        Batch(world, 2)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"gravity": (0, 0)}, ValueError, r"gravity must have shape \(\.\.\., 3\)"),
        ({"gravity": np.zeros((3, 3))}, ValueError, r"gravity must have shape \(3,\) or \(4, 3\) for 4 copies"),
        ({"friction": -np.ones(5)}, ValueError, "friction must be >= 0"),
        ({"restitution": np.full(5, 1.5)}, ValueError, r"restitution must be in \[0, 1\]"),
        ({"mass": [1.0, 1.0, 1.0, 1.0, 0.5]}, ValueError, "mass of body 0 must stay 0: it is static"),
        ({"mass": [0.0, 1.0, -1.0, 1.0, 0.5]}, ValueError, "mass must be > 0 for dynamic bodies"),
        ({"mass": [0.0, 1.0, 1.0, 1.0, 1e308]}, ValueError, "scales an inertia out of float range"),
        ({"drive_target": [1.0]}, ValueError, r"drive_target must have shape \(\.\.\., 0\)"),
        ({"gravity": (0, 0, np.nan)}, ValueError, "gravity must be finite"),
    ],
)
def test_overrides_that_do_not_fit_are_refused_and_change_nothing(kwargs, error, message):
    batch = Batch(_pile(0), 4)
    before = (batch.gravity, batch.mass, batch.friction, batch.restitution)
    with pytest.raises(error, match=message):
        batch.override(**kwargs)
    for old, new in zip(before, (batch.gravity, batch.mass, batch.friction, batch.restitution), strict=True):
        assert np.array_equal(old, new)


@pytest.mark.parametrize(
    ("which", "error", "message"),
    [
        (4, IndexError, "which holds copy 4, out of range for a batch of 4 copies"),
        ([0, -1], IndexError, "which holds copy -1, out of range"),
        (np.array([True, False]), ValueError, r"which as a mask must have shape \(4,\), got shape \(2,\)"),
        ([0.5], TypeError, "which must be None, a boolean mask or copy indices"),
    ],
)
def test_copies_out_of_range_are_named(which, error, message):
    batch = Batch(_spinning(0), 4)
    with pytest.raises(error, match=message):
        batch.reset(which)
    with pytest.raises(error, match=message):
        batch.override(which, gravity=(0, 0, 1))
    with pytest.raises(IndexError, match="i holds copy 7"):
        batch.world(7)


def test_bad_resets_and_loads_are_refused():
    batch = Batch(_pile(0), 2)
    with pytest.raises(ValueError, match="body_quat must hold unit quaternions"):
        batch.reset(body_quat=np.full((5, 4), 0.9))
    with pytest.raises(ValueError, match=r"body_linvel must be 0 for static bodies \[0\]"):
        batch.reset(body_linvel=np.ones((5, 3)))
    with pytest.raises(ValueError, match=r"body_pos must have shape \(5, 3\) or \(1, 5, 3\) for 1 copies"):
        batch.reset([1], body_pos=np.zeros((2, 5, 3)))
    with pytest.raises(ValueError, match="apply_force: body 0 is static"):
        batch.apply_force(0, (1, 0, 0))
    with pytest.raises(KeyError, match="no body named 'lid'"):
        batch.apply_torque("lid", (1, 0, 0))
    with pytest.raises(IndexError, match="body=9 is out of range for 5 bodies"):
        batch.apply_force(9, (1, 0, 0))
    batch.apply_force(1, (1e308, 0, 0))
    with pytest.raises(ValueError, match="overflow"):
        batch.apply_force(1, (1e308, 0, 0))
    assert batch.inputs.body_force[0, 1, 0] == 1e308  # the refused load added nothing
    for dt in (0.0, -1.0, np.inf):
        with pytest.raises(ValueError, match="dt"):
            batch.step(dt)
    with pytest.raises(ValueError, match="steps must be an integer"):
        batch.step(0.01, steps=0)


@pytest.mark.parametrize("make", [_spinning, _pile], ids=["free", "contacts"])
def test_a_copy_that_turns_non_finite_names_itself_and_every_copy_keeps_its_state(make):
    batch = Batch(make(0), 3)
    batch.step(1 / 60, steps=3)
    body = 1 if make is _spinning else 3
    batch.state.body_linvel[2, body] = (1.79e308, 0.0, 0.0)  # one push more overflows
    before = batch.state.copy()
    batch.apply_force(body, [(0, 0, 0), (0, 0, 0), (1e308, 0, 0)])
    with pytest.raises(tumble.SimulationError, match=f"copy 2: body #{body} became non-finite") as caught:
        with np.errstate(over="ignore", invalid="ignore"):  # the overflow is expected (the setting reaches the threads)
            batch.step(1 / 60)
    assert caught.value.copy == 2 and caught.value.body == body
    for f in BODY_FIELDS:
        assert np.array_equal(getattr(batch.state, f), getattr(before, f)), f
    assert batch.step_count == 3 and not batch.inputs.body_force.any()
    batch.reset(2)
    batch.step(1 / 60)  # and it goes on
