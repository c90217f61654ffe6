"""Building is linear: the model is packed once, before the first step, however the world is described.

Timing is never asserted (``benchmarks/build.py`` measures it); what is counted is the number of times the
builder packs the whole world, which is what made building quadratic: once per body or joint added.
"""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble import scene_file
from tumble.builder import ModelBuilder
from tumble.rotation import quat_from_axis_angle


@pytest.fixture
def finalize_calls(monkeypatch):
    """The number of ``ModelBuilder.finalize`` calls so far (a one-element list, read after building)."""
    calls = [0]
    original = ModelBuilder.finalize

    def counted(self, gravity):
        calls[0] += 1
        return original(self, gravity)

    monkeypatch.setattr(ModelBuilder, "finalize", counted)
    return calls


def _free_bodies(n: int) -> tumble.World:
    """``n`` named boxes, each read and written through its handle while the world is built."""
    world = tumble.World()
    for i in range(n):
        body = world.add_body(tumble.Box((0.2, 0.3, 0.4)), mass=1.0 + i % 3, position=(0.5 * i, 0.0, 1.0),
                              orientation=quat_from_axis_angle((0, 0, 1), 0.1 * i), name=f"box{i}")  # fmt: skip
        body.constant_force = (0.0, 0.0, 0.5)
        body.constant_torque = (0.0, 0.01, 0.0)
        body.velocity = body.velocity + (0.1, 0.0, 0.0)
        body.angular_velocity = (0.0, 0.0, 0.2)
        assert world.body(f"box{i}") == body
        assert body.position[0] == pytest.approx(0.5 * i)
    world.add_static(tumble.Plane((0, 0, 1), 0.0))
    return world


def _chain(n: int) -> tumble.World:
    """A hanging chain of ``n`` links, each joined to the one before (the first to the world)."""
    world = tumble.World()
    previous = None
    for i in range(n):
        link = world.add_body(tumble.Capsule(0.05, 0.2), mass=0.5, position=(0.3 * i, 0.0, 2.0))
        world.add_joint(tumble.BallJoint(link, previous, anchor=(0.3 * i - 0.15, 0.0, 2.0)))
        joint = world.joints[-1]
        assert np.allclose(joint.anchor_a, joint.anchor_b)
        previous = link
    return world


@pytest.mark.parametrize("n", [25, 100])
def test_the_api_packs_the_model_once_for_bodies_and_for_joints(finalize_calls, n):
    for build in (_free_bodies, _chain):
        finalize_calls[0] = 0
        world = build(n)
        assert finalize_calls[0] == 0, f"{build.__name__}({n}) packed the model while building"
        world.step(1 / 240)
        world.step(1 / 240)
        assert finalize_calls[0] == 1, f"{build.__name__}({n}) packed the model {finalize_calls[0]} times"


def _scene_text(n: int) -> str:
    parts = ["[world]\ngravity = [0, 0, -9.81]\n\n[materials.rubber]\nfriction = 0.9\n"]
    for i in range(n):
        parts.append(f'[[bodies]]\nname = "b{i}"\nshape = {{ type = "box", extents = [0.1, 0.1, 0.1] }}\n'
                     f'mass = 1.0\nposition = [{0.2 * i}, 0, 1]\nconstant_force = [0, 0, 2]\n'
                     f'constant_torque = [0, 0, 0.01]\nmaterial = "rubber"\n')  # fmt: skip
    parts.append('[[joints]]\ntype = "ball"\na = "b0"\nanchor = [-0.1, 0, 1]\n')
    parts += [f'[[joints]]\ntype = "hinge"\na = "b{i}"\nb = "b{i - 1}"\nanchor = [{0.2 * i - 0.1}, 0, 1]\n'
              f'axis = [0, 1, 0]\n' for i in range(1, n)]  # fmt: skip
    parts.append('[[static]]\nshape = { type = "plane", normal = [0, 0, 1], offset = 0 }\n')
    return "\n".join(parts)


@pytest.mark.parametrize("n", [25, 100])
def test_a_scene_file_packs_the_model_once(finalize_calls, tmp_path, n):
    path = tmp_path / "chain.toml"
    path.write_text(_scene_text(n))
    world = scene_file.load(path).world
    world.step(1 / 240)
    assert finalize_calls[0] == 1
    assert len(world.bodies) == n + 1 and len(world.joints) == n
    np.testing.assert_array_equal(world.model.body_constant_force[:n], np.tile([0.0, 0.0, 2.0], (n, 1)))
    np.testing.assert_array_equal(world.model.shape_friction[:n], 0.9)


def test_reading_the_state_grows_it_without_packing_the_model(finalize_calls):
    world = _free_bodies(10)
    assert world.state.body_count == 11 and world.inputs.body_force.shape == (11, 3)
    assert finalize_calls[0] == 0
    world.model  # noqa: B018 - packs the model
    assert finalize_calls[0] == 1


def test_a_handle_reads_and_writes_the_same_values_before_and_after_the_model_is_packed():
    def build():
        world = tumble.World(gravity=(0, 0, 0))
        parts = [(tumble.Sphere(0.2), (0.5, 0.0, 0.0)), (tumble.Box((0.2, 0.2, 0.2)), (-0.3, 0.1, 0.0))]
        body = world.add_body(parts, mass=2.0, position=(1, 2, 3), orientation=quat_from_axis_angle((1, 1, 0), 0.7),
                              angular_velocity=(0.3, -0.2, 1.0), velocity=(1, 0, 0))  # fmt: skip
        return world, body

    values = lambda b: (b.position, b.orientation, b.center_of_mass, b.velocity, b.angular_velocity, b.mass,  # noqa: E731
                        b.inertia_body, b.inertia_world, b.kinetic_energy, b.point_velocity((0, 0, 0)))  # fmt: skip
    world, body = build()
    before = values(body)
    world.model  # noqa: B018 - packs the model
    after = values(body)
    for a, b in zip(before, after, strict=True):
        np.testing.assert_array_equal(a, b)
    # Writes through a handle whose row is not yet in the state land in the state.
    fresh, unbuilt = build()
    for handle in (body, unbuilt):
        handle.position = (4, 5, 6)
        handle.orientation = quat_from_axis_angle((0, 0, 1), 0.3)
        handle.angular_velocity = (0, 0, 2)
        handle.apply_impulse((1, 0, 0), point=(4, 5, 7))
    for a, b in zip(values(body), values(unbuilt), strict=True):
        np.testing.assert_array_equal(a, b)
    world.step(0.01)
    fresh.step(0.01)
    assert world.state.digest() == fresh.state.digest()


def test_adding_bodies_to_a_world_that_has_stepped_keeps_its_state_and_contacts():
    def stack(world):
        world.add_static(tumble.Plane((0, 0, 1), 0.0))
        for k in range(3):
            world.add_body(tumble.Box((1, 1, 1)), mass=1.0, position=(0, 0, 0.5 + k))
        for _ in range(60):
            world.step(1 / 60)

    world = tumble.World()
    stack(world)
    before = world.state.copy()
    contacts = world.state.contact_count
    assert contacts > 0
    late = world.add_body(tumble.Sphere(0.2), mass=1.0, position=(5, 0, 3))
    assert late.position[2] == 3.0 and world.bodies[1].position[2] == pytest.approx(before.body_pos[1, 2])
    state = world.state
    np.testing.assert_array_equal(state.body_pos[:4], before.body_pos)
    np.testing.assert_array_equal(state.body_sleep_time[:4], before.body_sleep_time)
    assert state.contact_count == contacts  # warm-start impulses kept for the contacts that were there
    np.testing.assert_array_equal(state.contact_normal_impulse, before.contact_normal_impulse)
    world.step(1 / 60)
    assert world.bodies[-1].position[2] < 3.0


def test_bodies_sharing_one_hull_object_pack_it_once_and_move_as_with_copies():
    points = np.array([[x, y, z] for x in (-0.2, 0.2) for y in (-0.3, 0.3) for z in (-0.1, 0.1)]) * [1, 1, 1]
    shared = tumble.ConvexHull(points)

    def pile(hulls):
        world = tumble.World()
        world.add_static(tumble.Plane((0, 0, 1), 0.0))
        for k, hull in enumerate(hulls):
            world.add_body(hull, mass=1.0, position=(0.05 * k, 0, 0.15 + 0.25 * k),
                           orientation=quat_from_axis_angle((0, 0, 1), 0.4 * k))  # fmt: skip
        world.simulate(1.0, 1 / 120)
        return world

    one = pile([shared] * 4)
    copies = pile([tumble.ConvexHull(points) for _ in range(4)])
    geometry = one.model.geometry
    assert geometry.vertex_local.shape[0] == len(shared.vertices)
    assert np.unique(geometry.shape_vertex_start[1:]).size == 1
    assert copies.model.geometry.vertex_local.shape[0] == 4 * len(shared.vertices)
    assert one.state.digest() == copies.state.digest()


def test_a_name_index_answers_for_a_loaded_checkpoint(tmp_path):
    world = _free_bodies(5)
    world.step(0.01)
    world.save(tmp_path / "w.npz")
    loaded = tumble.World.load(tmp_path / "w.npz")
    assert loaded.body("box3").index == 3
    with pytest.raises(ValueError, match="'box3' is already taken"):
        loaded.add_body(tumble.Sphere(0.1), mass=1.0, name="box3")
    with pytest.raises(KeyError, match="no body named 'nope'"):
        loaded.body("nope")


def test_loading_a_scene_leaves_the_cyclic_collector_as_it_found_it(tmp_path):
    import gc

    path = tmp_path / "chain.toml"
    path.write_text(_scene_text(5))
    bad = tmp_path / "bad.toml"
    bad.write_text(_scene_text(5).replace("mass = 1.0", "mass = -1.0", 1))
    for enabled in (True, False):
        gc.enable() if enabled else gc.disable()
        try:
            scene_file.load(path)
            with pytest.raises(scene_file.SceneError, match=r"bodies\[0\]\.mass"):
                scene_file.load(bad)
            assert gc.isenabled() == enabled
        finally:
            gc.enable()
