"""Invariants of the broad phase and of ray casts on random scenes (hypothesis).

- Sort-and-sweep finds exactly the brute force's pairs, whatever the shapes, poses, filters and margins. Body
  positions sit on a 0.25 m grid, so boxes that touch exactly (the closed-interval edge case) come up often.
- A ray's hit point lies on the shape's surface, its normal points out of the shape and against the ray, and a
  ray aimed from outside at a point inside the shape always hits it before reaching that point.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from strategies import unit_quaternions, unit_vectors3
from tumble import shapes as S
from tumble.geometry import broad_phase as bp
from tumble.geometry.packing import pack_geometry
from tumble.geometry.raycast import cast_ray
from tumble.rotation import quat_rotate, quat_to_matrix

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])

sizes = st.floats(0.1, 1.0)
grid = st.integers(-8, 8).map(lambda k: 0.25 * k)
grid_points = st.tuples(grid, grid, grid).map(np.array)
orientations = st.one_of(st.just(IDENTITY), unit_quaternions())
primitives = st.one_of(
    sizes.map(S.Sphere),
    st.tuples(sizes, sizes, sizes).map(S.Box),
    st.tuples(sizes, sizes).map(lambda a: S.Capsule(0.5 * a[0], a[1])),
    st.tuples(sizes, sizes).map(lambda a: S.Cylinder(a[0], a[1])),
)


@st.composite
def scenes(draw):
    """Up to 12 bodies of one or two shapes, and perhaps a plane on its own static body."""
    body_count = draw(st.integers(1, 12))
    specs = []
    for b in range(body_count):
        for _ in range(draw(st.integers(1, 2))):
            specs.append((draw(primitives), b, draw(grid_points) * 0.5, draw(orientations)))
    body_pos = [draw(grid_points) for _ in range(body_count)]
    body_quat = [draw(orientations) for _ in range(body_count)]
    dynamic = [draw(st.booleans()) for _ in range(body_count)]
    if draw(st.booleans()):
        normal = draw(st.one_of(st.just(np.array([0.0, 0.0, 1.0])), unit_vectors3()))
        specs.append((S.Plane(normal, draw(grid)), body_count, np.zeros(3), IDENTITY))
        body_pos.append(draw(grid_points))
        body_quat.append(draw(orientations))
        dynamic.append(draw(st.booleans()))
    n, m = len(specs), len(body_pos)
    geom = pack_geometry(
        [s for s, *_ in specs],
        np.array([b for _, b, *_ in specs]),
        np.array([p for *_, p, _ in specs]),
        np.array([q for *_, q in specs]),
    )
    bits = st.integers(0, 7).map(np.uint32)
    filters = {}
    if draw(st.booleans()):
        filters["shape_group"] = np.array(draw(st.lists(bits, min_size=n, max_size=n)), np.uint32)
        filters["shape_mask"] = np.array(draw(st.lists(bits, min_size=n, max_size=n)), np.uint32)
    if draw(st.booleans()):
        body = st.integers(0, m - 1)
        filters["excluded_body_pairs"] = np.array(draw(st.lists(st.tuples(body, body), max_size=6)), np.int64)
    velocity = np.array([draw(grid_points) * 4.0 for _ in range(m)])
    return geom, np.array(body_pos), np.array(body_quat), np.array(dynamic), velocity, filters


@settings(max_examples=150)
@given(scene=scenes(), margin=st.sampled_from([0.0, 0.02, 0.25]), h=st.sampled_from([0.0, 1 / 60]))
def test_sweep_and_prune_equals_brute_force(scene, margin, h):
    geom, body_pos, body_quat, dynamic, velocity, filters = scene
    lo, hi = np.zeros((len(geom.shape_type), 3)), np.zeros((len(geom.shape_type), 3))
    bp.update_aabbs(geom, body_pos, body_quat, velocity, margin, h, lo, hi)
    args = (geom, body_pos, body_quat, lo, hi, dynamic)
    a, b = bp.find_pairs(*args, margin=margin, buffer=bp.PairBuffer(2), **filters)
    ref_a, ref_b = bp.find_pairs_brute_force(*args, margin=margin, **filters)
    np.testing.assert_array_equal(a, ref_a)
    np.testing.assert_array_equal(b, ref_b)


# --- ray casts -------------------------------------------------------------------------------------------


def hull_planes(shape):
    """Outward unit normals and offsets of a hull's triangles, from its vertices (independent of packing)."""
    v, f = shape.vertices, shape.faces
    normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return normals, np.einsum("ij,ij->i", normals, v[f[:, 0]])


def surface_distance(shape, p):
    """A function that is 0 exactly on the surface, < 0 inside, > 0 outside (the true distance for smooth
    surfaces and for points near a face; a lower bound near edges)."""
    r = shape.params[0]
    if shape.type == S.ShapeType.SPHERE:
        return np.linalg.norm(p) - r
    if shape.type == S.ShapeType.BOX:
        return np.max(np.abs(p) - shape.params[:3])
    if shape.type == S.ShapeType.CAPSULE:
        closest = np.array([0.0, 0.0, np.clip(p[2], -shape.params[1], shape.params[1])])
        return np.linalg.norm(p - closest) - r
    if shape.type == S.ShapeType.CYLINDER:
        return max(math.hypot(p[0], p[1]) - r, abs(p[2]) - shape.params[1])
    if shape.type == S.ShapeType.CONVEX_HULL:
        normals, offsets = hull_planes(shape)
        return np.max(normals @ p - offsets)
    return shape.params[:3] @ p - shape.params[3]  # plane


def hull_or_none(points):
    try:
        return S.ConvexHull(points)
    except ValueError:  # flat or degenerate draws
        return None


hulls = st.lists(st.tuples(sizes, sizes, sizes), min_size=6, max_size=10).map(hull_or_none).filter(bool)
solids = st.one_of(primitives, hulls)


@settings(max_examples=300)
@given(
    shape=st.one_of(solids, unit_vectors3().map(lambda n: S.Plane(n, 0.2))),
    body_pos=grid_points,
    body_quat=unit_quaternions(),
    pos_local=grid_points,
    quat_local=orientations,
    toward=unit_vectors3(),
    miss_by=st.one_of(st.just(np.zeros(3)), grid_points),
)
def test_ray_hits_lie_on_the_surface(shape, body_pos, body_quat, pos_local, quat_local, toward, miss_by):
    geom = pack_geometry([shape], [0], pos_local[None], quat_local[None])
    to_world = quat_to_matrix(body_quat) @ quat_to_matrix(quat_local)
    shape_origin = body_pos + quat_rotate(body_quat, pos_local)
    # A point inside the shape (the vertex mean of a hull; the origin, inside every primitive and the plane).
    inside_local = np.zeros(3) if shape.vertices is None else shape.vertices.mean(axis=0)
    inside = shape_origin + to_world @ inside_local
    origin = inside + 10.0 * toward
    aim = inside + miss_by
    hit = cast_ray(geom, body_pos[None], body_quat[None], origin, aim - origin)
    if not miss_by.any():
        # Aimed at an inside point: a hit, no farther than that point (the plane: unless it starts inside).
        assert hit is not None
        assert hit.distance <= np.linalg.norm(aim - origin) + 1e-9
    if hit is None:
        return
    direction = (aim - origin) / np.linalg.norm(aim - origin)
    # The point is computed as origin + t d; normals are normalised: round-off of a few ulps only.
    np.testing.assert_allclose(hit.point, origin + hit.distance * direction, atol=1e-12)
    assert abs(np.linalg.norm(hit.normal) - 1.0) < 1e-12
    assert hit.normal @ direction <= 1e-12  # a grazing hit has normal ⊥ direction
    if hit.distance == 0.0:
        # Started inside: the normal faces back along the ray.
        assert surface_distance(shape, to_world.T @ (origin - shape_origin)) <= 1e-12
        np.testing.assert_allclose(hit.normal, -direction, atol=1e-15)
        return
    local_point = to_world.T @ (hit.point - shape_origin)
    local_normal = to_world.T @ hit.normal
    # On the surface: within round-off of coordinates ~10 m (measured worst 8e-15 m over 300 draws).
    assert abs(surface_distance(shape, local_point)) < 1e-9
    # The normal points out: a step of 1 µm along it leaves the shape by about that much.
    assert surface_distance(shape, local_point + 1e-6 * local_normal) > 0.5e-6
