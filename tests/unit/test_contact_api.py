"""The contact side of the World API: contacts(), sleeping, filters, solver settings, queries, bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import tumble

DT = 1 / 60


def resting_box(**world_settings):
    world = tumble.World(**world_settings)
    ground = world.add_static(tumble.Plane(), name="ground")
    box = world.add_body(tumble.Box((0.4, 0.4, 0.4)), density=500.0, position=(0, 0, 0.2), name="box")
    return world, ground, box


def test_contacts_report_points_normals_and_the_impulse_that_holds_the_weight():
    world, ground, box = resting_box()
    world.simulate(1.0, DT)
    contacts = world.contacts()
    touching = contacts.separation <= 0.0
    assert touching.sum() == 4  # the four bottom corners
    assert set(contacts.body_a.tolist()) | set(contacts.body_b.tolist()) == {ground.index, box.index}
    # The normal points from a to b; the ground pushes the box up.
    up = np.where(contacts.body_b[:, None] == box.index, contacts.normal, -contacts.normal)
    np.testing.assert_allclose(up[touching], np.tile([0, 0, 1], (4, 1)), atol=1e-9)
    # Over one step the contact impulses carry the weight: Σ λ = m g dt (to 1e-3, the box is at rest).
    assert contacts.normal_impulse.sum() == pytest.approx(box.mass * 9.81 * DT, rel=1e-3)
    np.testing.assert_allclose(np.abs(contacts.point[touching, :2]), 0.2, atol=1e-6)
    assert np.all(contacts.separation[touching] > -5e-3)  # sunk less than 5 mm


def test_a_box_at_rest_falls_asleep_and_wakes_when_pushed():
    world, _, box = resting_box()
    world.simulate(2.0, DT)
    assert box.sleeping
    np.testing.assert_array_equal(box.velocity, 0.0)
    box.apply_impulse((20.0, 0.0, 0.0))
    assert not box.sleeping
    world.step(DT)
    # It slides: the push, less one step of Coulomb friction (μ = 0.5 by default) on its weight.
    assert box.velocity[0] == pytest.approx(20.0 / box.mass - 0.5 * 9.81 * DT, rel=0.02)


def test_a_sleeping_stack_wakes_when_a_ball_hits_it():
    world = tumble.World()
    world.add_static(tumble.Plane())
    stack = [
        world.add_body(tumble.Box((0.4, 0.4, 0.4)), density=500.0, position=(0, 0, 0.2 + 0.4 * k)) for k in range(3)
    ]
    world.simulate(2.0, DT)
    assert all(b.sleeping for b in stack)
    world.add_body(tumble.Sphere(0.1), density=2000.0, position=(-1.0, 0, 1.0), velocity=(8.0, 0, 0))
    world.simulate(0.5, DT)
    assert not stack[-1].sleeping or np.linalg.norm(stack[-1].position[:2]) > 0.01


def test_sleep_can_be_turned_off():
    world, _, box = resting_box(sleep=False)
    world.simulate(2.0, DT)
    assert not box.sleeping


def test_collision_filter_bits():
    world = tumble.World()
    world.add_static(tumble.Plane(), collision_group=0b01)
    ghost = world.add_body(tumble.Sphere(0.1), density=100.0, position=(0, 0, 0.5), collision_mask=0b10)
    solid = world.add_body(tumble.Sphere(0.1), density=100.0, position=(1, 0, 0.5))
    world.simulate(1.0, DT)
    assert ghost.position[2] < -1.0  # fell through the floor it does not collide with
    assert solid.position[2] == pytest.approx(0.1, abs=5e-3)


def test_shapes_of_one_compound_body_do_not_collide_with_each_other():
    world = tumble.World(gravity=(0, 0, 0))
    body = world.add_body([(tumble.Sphere(0.2), (0, 0, 0)), (tumble.Sphere(0.2), (0.1, 0, 0))], density=100.0)
    world.simulate(0.5, DT)
    np.testing.assert_allclose(body.velocity, 0.0, atol=1e-15)


def test_free_integrators_refuse_a_world_with_contacts():
    world, _, _ = resting_box(integrator="rk4")
    with pytest.raises(ValueError, match="integrator='rk4'"):
        world.step(DT)


@pytest.mark.parametrize(
    ("substeps", "hertz", "dt", "taken"),
    [(8, 60.0, 1 / 60, 8), (1, 60.0, 1 / 60, 8), (1, 60.0, 1 / 30, 16), (1, 60.0, 1 / 120, 4), (1, 60.0, 1 / 480, 1),
     (1, 60.0, 1 / 1000, 1), (4, 60.0, 1 / 1000, 4), (1, 30.0, 1 / 60, 4), (1, 120.0, 1 / 60, 16), (3, 60.0, 0.05, 24)],
)  # fmt: skip
def test_a_step_takes_at_least_eight_substeps_per_contact_period(substeps, hertz, dt, taken):
    """Static contacts at 2 contact_hertz hold up to a quarter of the substep rate: the rate is 8 contact_hertz at
    least (1/60 s times 480 Hz is 8.000000000000002 in floating point, and still 8 substeps)."""
    assert tumble.World(substeps=substeps, contact_hertz=hertz).solver.substeps_for(dt) == taken


def test_a_world_says_the_substeps_it_runs_and_warns_once_where_it_raises_them():
    """``World(substeps=n)`` runs n substeps; where contacts need more, ``world.substeps`` says what runs and a
    warning names the numbers and why, once for each, at the user's line (API.md, "Substeps")."""
    world, _, _ = resting_box()
    world.set_solver(substeps=4)
    assert world.substeps == 4  # before a step: what was asked
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        world.step(1 / 60)
        world.step(1 / 60)  # the fast path of an unchanged world
        world.simulate(0.1, 1 / 60)
        assert world.substeps == 8
        world.step(1 / 30)
        assert world.substeps == 16
        world.step(1 / 30)
        world.step(1 / 240)
        assert world.substeps == 4
    told = [w for w in caught if issubclass(w.category, tumble.SubstepsRaisedWarning)]
    assert [str(w.message).split(":")[0] for w in told] == [
        "World(substeps=4) runs 8 substeps at dt=0.0166667",
        "World(substeps=4) runs 16 substeps at dt=0.0333333",
    ]
    assert "contact_hertz=60" in str(told[0].message) and all(w.filename == __file__ for w in told)
    world.set_solver(contact_hertz=15.0)  # softer contacts take a 30 Hz step in 4 substeps
    assert world.substeps == 4
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        world.step(1 / 30)
        batch = tumble.Batch(world, 2)
        batch.step(1 / 30)
    with pytest.warns(tumble.SubstepsRaisedWarning, match=r"Batch\(substeps=4\) runs 8 substeps"):
        batch.step(1 / 15)


@pytest.mark.parametrize("dt", [0.0, -0.01, float("nan"), "fast"])
def test_substeps_for_names_a_bad_step(dt):
    with pytest.raises((ValueError, TypeError), match="dt"):
        tumble.World().solver.substeps_for(dt)


def test_a_step_that_needs_more_than_65536_contact_substeps_is_refused_before_anything_moves():
    """A step of 1e5 s once asked for 4.8e7 substeps (minutes of work, uninterruptible); the cap names both knobs."""
    assert tumble.World().solver.substeps_for(136.0) == 65280
    with pytest.raises(ValueError, match=r"contact_hertz=60.0 at dt=137.0 needs 6.58e\+04 substeps"):
        tumble.World().solver.substeps_for(137.0)
    world, _, _ = resting_box()
    seen = []
    world.add_controller(lambda w, t: seen.append(t))
    before = world.state.digest()
    for dt in (137.0, 1e5, 1e300):
        with pytest.raises(ValueError, match="dt="):
            world.step(dt)
        with pytest.raises(ValueError, match="dt="):
            world.simulate(1e6, dt)
    assert world.state.digest() == before and seen == []
    assert tumble.World(contact_hertz=1.0).solver.substeps_for(1e3) == 8000  # softer contacts allow a longer step
    # Bodies free of contacts and joints take no substeps: a long step is theirs to take.
    free = tumble.World(gravity=(0, 0, 0))
    ball = free.add_body(tumble.Sphere(0.1), mass=1.0, velocity=(1.0, 0, 0))
    free.step(1e6)
    assert ball.position[0] == pytest.approx(1e6)


def test_solver_settings_are_validated():
    world = tumble.World(substeps=8, contact_hertz=60.0)
    assert world.solver.substeps == 8 and world.solver.contact_hertz == 60.0
    with pytest.raises(ValueError, match="substeps"):
        world.set_solver(substeps=0)
    with pytest.raises(ValueError, match="contact_hertz"):
        world.set_solver(contact_hertz=-1.0)
    with pytest.raises(TypeError, match="unknown solver setting"):
        world.set_solver(iterations=10)
    with pytest.raises(ValueError, match="collision_mask"):
        world.add_body(tumble.Sphere(1.0), mass=1.0, collision_mask=-1)


def test_query_ray_hits_the_nearest_surface():
    world, ground, box = resting_box()
    hit = world.query_ray((0.1, 0.0, 5.0), (0, 0, -2.0))
    assert hit.body == box and hit.distance == pytest.approx(4.6) and hit.normal == pytest.approx([0, 0, 1])
    hit = world.query_ray((3.0, 0.0, 5.0), (0, 0, -1.0))
    assert hit.body == ground and hit.point == pytest.approx([3, 0, 0])
    assert world.query_ray((3.0, 0.0, 5.0), (0, 0, 1.0)) is None
    assert world.query_ray((0.1, 0.0, 5.0), (0, 0, -1.0), max_distance=1.0) is None
    with pytest.raises(ValueError, match="direction"):
        world.query_ray((0, 0, 0), (0, 0, 0))
