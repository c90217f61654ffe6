"""Broad phase: world bounds (update_aabbs) and sort-and-sweep pairs (find_pairs) against the brute force.

Scenes are built straight from shapes with ``pack_geometry``, so these tests need no World. Sizes stay in
the hundreds so the whole file also runs quickly with ``NUMBA_DISABLE_JIT=1``.
"""

from __future__ import annotations

import numpy as np
import pytest

from tumble import shapes as S
from tumble.geometry import broad_phase as bp
from tumble.geometry.packing import pack_geometry
from tumble.rotation import quat_normalize, quat_to_matrix

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


class Scene:
    """Shapes on bodies at poses, packed, with everything ``find_pairs`` takes."""

    def __init__(self, specs, body_pos, body_quat=None, body_is_dynamic=None, body_linvel=None):
        """``specs``: (shape, body, pos_local, quat_local) per shape."""
        self.shapes = [s for s, *_ in specs]
        self.geom = pack_geometry(
            self.shapes,
            np.array([b for _, b, *_ in specs], np.int64),
            np.array([p for *_, p, _ in specs], float).reshape(-1, 3),
            np.array([q for *_, q in specs], float).reshape(-1, 4),
        )
        self.body_pos = np.asarray(body_pos, float).reshape(-1, 3)
        n = len(self.body_pos)
        self.body_quat = np.tile(IDENTITY, (n, 1)) if body_quat is None else np.asarray(body_quat, float)
        self.body_is_dynamic = np.ones(n, bool) if body_is_dynamic is None else np.asarray(body_is_dynamic, bool)
        self.body_linvel = np.zeros((n, 3)) if body_linvel is None else np.asarray(body_linvel, float)

    def aabbs(self, margin=0.0, h=0.0):
        lo, hi = np.zeros((len(self.shapes), 3)), np.zeros((len(self.shapes), 3))
        bp.update_aabbs(self.geom, self.body_pos, self.body_quat, self.body_linvel, margin, h, lo, hi)
        return lo, hi

    def pairs(self, margin=0.0, h=0.0, brute_force=False, **filters):
        lo, hi = self.aabbs(margin, h)
        find = bp.find_pairs_brute_force if brute_force else bp.find_pairs
        a, b = find(self.geom, self.body_pos, self.body_quat, lo, hi, self.body_is_dynamic, margin=margin, **filters)
        return list(zip(a.tolist(), b.tolist(), strict=True))


def random_shape(rng, kinds=("sphere", "box", "capsule", "cylinder", "hull")):
    kind = kinds[rng.integers(len(kinds))]
    if kind == "sphere":
        return S.Sphere(rng.uniform(0.1, 0.6))
    if kind == "box":
        return S.Box(rng.uniform(0.1, 1.2, 3))
    if kind == "capsule":
        return S.Capsule(rng.uniform(0.1, 0.4), rng.uniform(0.0, 1.0))
    if kind == "cylinder":
        return S.Cylinder(rng.uniform(0.1, 0.5), rng.uniform(0.1, 1.0))
    return S.ConvexHull(rng.normal(size=(8, 3)) * 0.4)


def random_quats(rng, n):
    return quat_normalize(rng.normal(size=(n, 4)))


def random_scene(rng, body_count=120, *, spread=6.0, plane=True, mesh=True, static_fraction=0.25):
    """Bodies of one to three shapes (compounds) scattered in a cube, some static, over a tilted plane and a
    static triangle-mesh terrain; about 200 shapes for 120 bodies."""
    specs, body_pos, body_quat, dynamic = [], [], [], []
    if plane:
        normal = np.array([0.1, -0.05, 1.0])
        specs.append((S.Plane(normal, -0.5), len(body_pos), np.zeros(3), IDENTITY))
        body_pos.append(np.zeros(3))
        body_quat.append(IDENTITY)
        dynamic.append(False)
    if mesh:
        g = np.linspace(-2.0, 2.0, 4)
        xx, yy = np.meshgrid(g, g)
        vertices = np.column_stack([xx.ravel(), yy.ravel(), 0.2 * np.sin(xx.ravel() + yy.ravel())])
        faces = [(i * 4 + j, i * 4 + j + 1, i * 4 + j + 4) for i in range(3) for j in range(3)]
        faces += [(i * 4 + j + 1, i * 4 + j + 5, i * 4 + j + 4) for i in range(3) for j in range(3)]
        specs.append((S.TriMesh(vertices, faces), len(body_pos), np.zeros(3), IDENTITY))
        body_pos.append(np.array([0.0, 0.0, 0.3]))
        body_quat.append(random_quats(rng, 1)[0])
        dynamic.append(False)
    first = len(body_pos)
    for b in range(first, first + body_count):
        for _ in range(rng.choice([1, 1, 2, 3])):
            specs.append((random_shape(rng), b, rng.uniform(-0.5, 0.5, 3), random_quats(rng, 1)[0]))
        body_pos.append(rng.uniform(-spread / 2, spread / 2, 3) + [0, 0, spread / 2])
        body_quat.append(random_quats(rng, 1)[0])
        dynamic.append(rng.uniform() > static_fraction)
    n = len(body_pos)
    return Scene(specs, body_pos, body_quat, dynamic, rng.normal(size=(n, 3)) * 3.0)


def box_scene(body_count, size=1.0, spacing=1.01, layers=10, plane=True):
    """``body_count`` unit boxes stacked on a grid in ``layers`` layers over a plane: every box's enlarged bounds
    overlap its 26 neighbours' (a dense pile, the broad phase's busy case)."""
    side = int(np.ceil(np.sqrt(body_count / layers)))
    idx = np.arange(body_count)
    body_pos = np.column_stack([idx % side, (idx // side) % side, idx // (side * side)]) * spacing + 0.5
    specs = [(S.Box((size, size, size)), b, np.zeros(3), IDENTITY) for b in range(body_count)]
    dynamic = np.ones(body_count, bool)
    if plane:
        specs.append((S.Plane(), body_count, np.zeros(3), IDENTITY))
        body_pos = np.vstack([body_pos, np.zeros(3)])
        dynamic = np.append(dynamic, False)
    return Scene(specs, body_pos, None, dynamic)


# --- bounds --------------------------------------------------------------------------------------------


def world_support(scene, s, direction):
    """The point of shape ``s`` farthest along the world ``direction``."""
    b = scene.geom.shape_body[s]
    r_body = quat_to_matrix(scene.body_quat[b])
    r_shape = quat_to_matrix(scene.geom.shape_quat_local[s])
    local = scene.shapes[s].support(r_shape.T @ r_body.T @ direction)
    return scene.body_pos[b] + r_body @ (scene.geom.shape_pos_local[s] + r_shape @ local)


def test_aabbs_contain_every_support_point():
    rng = np.random.default_rng(1)
    scene = random_scene(rng, 60)
    lo, hi = scene.aabbs()
    directions = rng.normal(size=(40, 3))
    directions = np.vstack([directions, np.eye(3), -np.eye(3)])
    for s, shape in enumerate(scene.shapes):
        if shape.type == S.ShapeType.PLANE:
            continue
        for u in directions:
            p = world_support(scene, s, u)
            # Rotations round at 1e-16 relative; 1e-12 m leaves room (measured worst 9e-16 m).
            assert np.all(p >= lo[s] - 1e-12) and np.all(p <= hi[s] + 1e-12), (s, shape, p, lo[s], hi[s])


@pytest.mark.parametrize("shape", [S.Box((0.4, 1.0, 2.0)), S.Sphere(0.7), S.Capsule(0.3, 1.5), S.Cylinder(0.4, 1.2)])
def test_aabbs_of_primitives_are_tight(shape):
    """However a primitive is turned in its body and the body in the world, its box touches the shape: the
    support points along ±x, ±y, ±z lie on the box's faces."""
    rng = np.random.default_rng(2)
    for _ in range(10):
        scene = Scene(
            [(shape, 0, rng.normal(size=3), random_quats(rng, 1)[0])], [rng.normal(size=3)], random_quats(rng, 1)
        )
        lo, hi = scene.aabbs()
        for k in range(3):
            e = np.eye(3)[k]
            # Measured worst 1.1e-15 m.
            assert hi[0, k] == pytest.approx(world_support(scene, 0, e)[k], abs=1e-14)
            assert lo[0, k] == pytest.approx(world_support(scene, 0, -e)[k], abs=1e-14)


def test_margin_enlarges_and_velocity_sweeps_one_side():
    scene = Scene([(S.Sphere(1.0), 0, np.zeros(3), IDENTITY)], [[0.0, 0.0, 0.0]], body_linvel=[[6.0, -3.0, 0.0]])
    lo, hi = scene.aabbs(margin=0.02, h=0.5)
    np.testing.assert_allclose(lo[0], [-1.02, -1.02 - 1.5, -1.02], atol=1e-15)
    np.testing.assert_allclose(hi[0], [1.02 + 3.0, 1.02, 1.02], atol=1e-15)
    lo, hi = scene.aabbs(margin=0.0, h=0.0)
    np.testing.assert_array_equal(lo[0], [-1.0, -1.0, -1.0])


def test_planes_get_infinite_bounds():
    scene = Scene([(S.Plane((0, 1, 1), 2.0), 0, np.zeros(3), IDENTITY)], [[1.0, 2.0, 3.0]], body_is_dynamic=[False])
    lo, hi = scene.aabbs(margin=0.1, h=1.0)
    assert np.all(lo == -np.inf) and np.all(hi == np.inf)


# --- pairs: the sweep against the brute force ----------------------------------------------------------


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_sweep_equals_brute_force_on_random_scenes(seed):
    rng = np.random.default_rng(seed)
    scene = random_scene(rng, 150, spread=7.0)
    n = len(scene.shapes)
    filters = {}
    if seed >= 2:
        # Collision groups and an exclusion list too.
        filters["shape_group"] = (1 << rng.integers(0, 3, n)).astype(np.uint32)
        filters["shape_mask"] = rng.integers(0, 8, n).astype(np.uint32) | np.uint32(0xFFFFFFF0 * (seed == 3))
        filters["excluded_body_pairs"] = rng.integers(0, len(scene.body_pos), (40, 2))
    for margin, h in [(0.0, 0.0), (0.02, 1 / 60), (0.3, 0.1)]:
        sweep = scene.pairs(margin, h, **filters)
        brute = scene.pairs(margin, h, brute_force=True, **filters)
        assert sweep == brute
        assert len(sweep) > 20  # the scene is busy enough to mean something


@pytest.mark.parametrize("seed", [0, 1])
def test_segments_pair_only_within_themselves_as_each_copy_alone(seed):
    """A batch's copies, laid one after the other in the same place: each pairs as it would alone, never across."""
    one = random_scene(np.random.default_rng(seed), 60, spread=5.0)
    copies, shapes, bodies = 3, len(one.shapes), len(one.body_pos)
    specs = [(shape, int(one.geom.shape_body[s]) + c * bodies, np.zeros(3), IDENTITY)
             for c in range(copies) for s, shape in enumerate(one.shapes)]  # fmt: skip
    many = Scene(specs, np.tile(one.body_pos, (copies, 1)), np.tile(one.body_quat, (copies, 1)),
                 np.tile(one.body_is_dynamic, copies), np.tile(one.body_linvel, (copies, 1)))  # fmt: skip
    alone = Scene(specs[:shapes], one.body_pos, one.body_quat, one.body_is_dynamic, one.body_linvel)
    expected = [(a + c * shapes, b + c * shapes) for c in range(copies) for a, b in alone.pairs(0.02, 1 / 60)]
    assert many.pairs(0.02, 1 / 60, segment_size=shapes) == expected
    assert len(expected) > 3 * 20
    assert len(many.pairs(0.02, 1 / 60)) > len(expected)  # without segments the copies would pair


def test_sweep_equals_brute_force_on_a_column_and_on_a_pile():
    """Every box in one column overlaps all the others on the sweep axis unless the axis is chosen well."""
    column = Scene(
        [(S.Box((1, 1, 1)), b, np.zeros(3), IDENTITY) for b in range(40)], [[0, 0, 1.01 * b] for b in range(40)]
    )
    assert column.pairs(0.02) == column.pairs(0.02, brute_force=True)
    assert len(column.pairs(0.02)) == 39
    pile = box_scene(300)
    assert pile.pairs(0.02) == pile.pairs(0.02, brute_force=True)


def test_pairs_are_sorted_and_lower_type_first():
    rng = np.random.default_rng(5)
    scene = random_scene(rng, 150)
    pairs = scene.pairs(0.05)
    types = scene.geom.shape_type
    assert pairs == sorted(set(pairs))
    for a, b in pairs:
        assert types[a] < types[b] or (types[a] == types[b] and a < b)


def test_touching_boxes_pair_and_separated_boxes_do_not():
    scene = Scene(
        [(S.Box((1, 1, 1)), b, np.zeros(3), IDENTITY) for b in range(3)], [[0, 0, 0], [1.0, 0, 0], [2.5, 0, 0]]
    )
    assert scene.pairs() == [(0, 1)] == scene.pairs(brute_force=True)
    # With a margin of 0.25 each box reaches 0.5 further: the gap of 0.5 closes.
    assert scene.pairs(0.25) == [(0, 1), (1, 2)] == scene.pairs(0.25, brute_force=True)


def test_results_do_not_depend_on_shape_order_or_repeats():
    rng = np.random.default_rng(7)
    scene = random_scene(rng, 100, plane=False, mesh=False)
    first = scene.pairs(0.02)
    assert first == scene.pairs(0.02)
    # The same bodies with their shapes listed in another order: the same pairs, renamed.
    perm = rng.permutation(len(scene.shapes))
    specs = [
        (scene.shapes[s], scene.geom.shape_body[s], scene.geom.shape_pos_local[s], scene.geom.shape_quat_local[s])
        for s in perm
    ]
    shuffled = Scene(specs, scene.body_pos, scene.body_quat, scene.body_is_dynamic)
    types = scene.geom.shape_type

    def canonical(a, b):
        return (a, b) if (types[a], a) <= (types[b], b) else (b, a)

    renamed = {canonical(int(perm[a]), int(perm[b])) for a, b in shuffled.pairs(0.02)}
    assert renamed == {canonical(a, b) for a, b in first}


def test_buffer_grows_to_fit_and_is_reused():
    pile = box_scene(200, plane=False)
    lo, hi = pile.aabbs(0.02)
    buffer = bp.PairBuffer(4)
    args = (pile.geom, pile.body_pos, pile.body_quat, lo, hi, pile.body_is_dynamic)
    a, b = bp.find_pairs(*args, margin=0.02, buffer=buffer)
    assert buffer.capacity >= len(a) > 4
    capacity = buffer.capacity
    a2, b2 = bp.find_pairs(*args, margin=0.02, buffer=buffer)
    assert buffer.capacity == capacity
    np.testing.assert_array_equal(a, a2)
    np.testing.assert_array_equal(b, b2)
    ba, bb = bp.find_pairs_brute_force(*args, margin=0.02)
    np.testing.assert_array_equal(a, ba)
    np.testing.assert_array_equal(b, bb)


def test_empty_and_single_shape_scenes():
    scene = Scene([(S.Sphere(1.0), 0, np.zeros(3), IDENTITY)], [[0, 0, 0]])
    assert scene.pairs() == [] == scene.pairs(brute_force=True)
    empty = bp.find_pairs(
        scene.geom._replace(shape_type=np.zeros(0, np.int64)),
        *[np.zeros((0, k)) for k in (3, 4, 3, 3)],
        np.zeros(0, bool),
    )
    assert empty[0].shape == (0,) and empty[0].dtype == np.int64


# --- pairs: the rules ------------------------------------------------------------------------------------


def overlapping(shape_bodies, dynamic):
    """Unit spheres all at the origin, shape k on body ``shape_bodies[k]``."""
    specs = [(S.Sphere(1.0), b, np.zeros(3), IDENTITY) for b in shape_bodies]
    return Scene(specs, np.zeros((max(shape_bodies) + 1, 3)), None, dynamic)


def test_shapes_of_one_body_never_pair():
    scene = overlapping([0, 0, 0, 1], [True, True])
    assert scene.pairs() == [(0, 3), (1, 3), (2, 3)] == scene.pairs(brute_force=True)


def test_static_and_kinematic_pairs_are_skipped():
    scene = overlapping([0, 1, 2], [False, False, True])
    assert scene.pairs() == [(0, 2), (1, 2)] == scene.pairs(brute_force=True)
    scene = overlapping([0, 1], [False, False])
    assert scene.pairs() == []


@pytest.mark.parametrize(
    ("group", "mask", "collide"),
    [
        ((1, 1), (0xFFFFFFFF, 0xFFFFFFFF), True),  # the defaults
        ((1, 2), (0xFFFFFFFF, 0xFFFFFFFE), False),  # b ignores group 1
        ((1, 2), (0xFFFFFFFD, 0xFFFFFFFF), False),  # a ignores group 2
        ((1, 2), (2, 1), True),  # each lists the other
        ((0, 1), (0xFFFFFFFF, 0xFFFFFFFF), False),  # no group: collides with nothing
        ((0x80000000, 0x80000000), (0x80000000, 0x80000000), True),  # the top bit is a group like any other
    ],
)
def test_group_and_mask_filter_both_ways(group, mask, collide):
    scene = overlapping([0, 1], [True, True])
    filters = {"shape_group": np.array(group, np.uint32), "shape_mask": np.array(mask, np.uint32)}
    expected = [(0, 1)] if collide else []
    assert scene.pairs(**filters) == expected == scene.pairs(brute_force=True, **filters)


def test_excluded_body_pairs_in_any_order():
    scene = overlapping([0, 1, 2, 3], [True] * 4)
    everything = [(a, b) for a in range(4) for b in range(a + 1, 4)]
    assert scene.pairs() == everything
    for excluded in ([[2, 0], [3, 1], [0, 2]], np.array([[0, 2], [1, 3]]), bp.exclusion_table([[3, 1], [2, 0]])):
        expected = [p for p in everything if p not in {(0, 2), (1, 3)}]
        assert scene.pairs(excluded_body_pairs=excluded) == expected
        assert scene.pairs(brute_force=True, excluded_body_pairs=excluded) == expected
    assert scene.pairs(excluded_body_pairs=np.zeros((0, 2), np.int64)) == everything


def test_exclusion_table_normalises():
    table = bp.exclusion_table([[5, 1], [1, 5], [2, 2], [0, 9], [1, 3]])
    np.testing.assert_array_equal(table, [[0, 9], [1, 3], [1, 5]])
    assert table.dtype == np.int64
    assert bp.exclusion_table([]).shape == (0, 2)


def test_excluded_pairs_found_by_binary_search_in_a_long_table():
    scene = overlapping(list(range(30)), [True] * 30)
    excluded = [(a, b) for a in range(30) for b in range(a + 1, 30) if (a * 7 + b) % 3 == 0]
    expected = [(a, b) for a in range(30) for b in range(a + 1, 30) if (a * 7 + b) % 3 != 0]
    assert scene.pairs(excluded_body_pairs=excluded) == expected


# --- pairs: planes ---------------------------------------------------------------------------------------


def plane_scene(z_box, *, plane=None, plane_body_pos=(0.0, 0.0, 0.0), plane_body_quat=IDENTITY, box_quat=IDENTITY):
    plane = S.Plane() if plane is None else plane
    specs = [(S.Box((1, 1, 1)), 0, np.zeros(3), IDENTITY), (plane, 1, np.zeros(3), IDENTITY)]
    return Scene(specs, [[0, 0, z_box], plane_body_pos], [box_quat, plane_body_quat], [True, False])


@pytest.mark.parametrize(
    ("z_box", "margin", "paired"),
    [
        (0.6, 0.0, False),
        (0.5, 0.0, True),  # resting on it: touching counts
        (0.53, 0.02, True),  # 3 cm above: within margin (box) + margin (plane)
        (0.55, 0.02, False),  # 5 cm above: beyond both
        (-3.0, 0.0, True),  # deep below the surface
    ],
)
def test_box_over_a_plane(z_box, margin, paired):
    scene = plane_scene(z_box)
    assert scene.pairs(margin) == ([(0, 1)] if paired else []) == scene.pairs(margin, brute_force=True)


def test_plane_on_a_moved_and_turned_body():
    """A plane z = 1 in its shape frame, on a body 2 m up and turned by 90° about x: the world plane is
    -y = 1 + 0 (its normal is -y and it passes through (0, -1, 2))."""
    half_turn_x = np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0])
    for y_box, paired in [(-1.4, True), (-2.0, False), (0.0, True)]:
        specs = [(S.Box((1, 1, 1)), 0, np.zeros(3), IDENTITY), (S.Plane((0, 0, 1), 1.0), 1, np.zeros(3), IDENTITY)]
        scene = Scene(specs, [[0, y_box, 0], [0, 0, 2]], [IDENTITY, half_turn_x], [True, False])
        assert scene.pairs() == ([(0, 1)] if paired else []) == scene.pairs(brute_force=True), y_box


def test_tilted_plane_uses_the_lowest_corner():
    # A 45° plane through the origin: the box's lowest corner along n = (1, 0, 1)/√2 is (-0.5, ., z - 0.5), at
    # n · x = (z - 1)/√2, so the box reaches the plane for z <= 1 (its centre alone would say z <= 0).
    plane = S.Plane((1.0, 0.0, 1.0), 0.0)
    for z_box, paired in [(0.99, True), (1.01, False)]:
        assert plane_scene(z_box, plane=plane).pairs() == ([(0, 1)] if paired else [])


def test_planes_pair_in_type_order_and_never_with_planes():
    mesh = S.TriMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    specs = [
        (S.Plane(), 0, np.zeros(3), IDENTITY),
        (mesh, 1, np.zeros(3), IDENTITY),
        (S.Sphere(0.5), 2, np.zeros(3), IDENTITY),
        (S.Plane((0, 0, -1), 0.0), 3, np.zeros(3), IDENTITY),
    ]
    scene = Scene(specs, np.zeros((4, 3)), None, [False, True, True, False])
    # The (dynamic) mesh comes after the plane (TRIMESH > PLANE); the sphere before; plane-plane never.
    expected = [(0, 1), (2, 0), (2, 1), (2, 3), (3, 1)]
    assert scene.pairs() == expected == scene.pairs(brute_force=True)


def test_plane_pairs_obey_the_filters():
    scene = plane_scene(0.0)
    assert scene.pairs(shape_group=np.array([1, 2], np.uint32), shape_mask=np.array([1, 1], np.uint32)) == []
    assert scene.pairs(excluded_body_pairs=[[1, 0]]) == []
    scene.body_is_dynamic[0] = False
    assert scene.pairs() == []
