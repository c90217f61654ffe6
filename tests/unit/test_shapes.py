"""tumble.shapes: kernel data (type, params, vertices, faces), mass properties, bounds, support, errors."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
import trimesh

from tumble import mass
from tumble.shapes import Box, Capsule, ConvexHull, Cylinder, Plane, Shape, ShapeType, Sphere, TriMesh

# Shape data are the constructor arguments halved or copied: exact, or one rounding (~1e-16 relative).
EXACT = 1e-12

CUBE_CORNERS = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-1.0, 1.0) for z in (-1.5, 1.5)])


def cube_hull_with_inside_points(seed=0):
    rng = np.random.default_rng(seed)
    inside = rng.uniform(-0.4, 0.4, size=(30, 3)) * np.array([1.0, 2.0, 3.0])
    return ConvexHull(np.concatenate([inside[:15], CUBE_CORNERS, inside[15:]]))


def box_faces():
    """The 12 outward triangles of ``CUBE_CORNERS`` (index = 4 (x > 0) + 2 (y > 0) + (z > 0))."""
    return np.array(
        [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
         (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    )  # fmt: skip


# --- ShapeType ----------------------------------------------------------------------------------------------


def test_shape_type_values_are_fixed():
    # collide_<a>_<b> kernels and stored models depend on these numbers; new kinds are appended.
    assert [(t.name, int(t)) for t in ShapeType] == [
        ("SPHERE", 0), ("CAPSULE", 1), ("BOX", 2), ("CYLINDER", 3),
        ("CONVEX_HULL", 4), ("PLANE", 5), ("TRIMESH", 6),
    ]  # fmt: skip


@pytest.mark.parametrize(
    ("shape", "kind"),
    [
        (Sphere(1.0), ShapeType.SPHERE),
        (Capsule(0.5, 1.0), ShapeType.CAPSULE),
        (Box((1.0, 2.0, 3.0)), ShapeType.BOX),
        (Cylinder(0.5, 1.0), ShapeType.CYLINDER),
        (ConvexHull(CUBE_CORNERS), ShapeType.CONVEX_HULL),
        (Plane(), ShapeType.PLANE),
        (TriMesh(CUBE_CORNERS, box_faces()), ShapeType.TRIMESH),
    ],
)
def test_every_shape_has_its_type_and_packable_data(shape, kind):
    assert isinstance(shape, Shape)
    assert shape.type is kind
    assert shape.params.shape == (4,) and shape.params.dtype == np.float64
    if kind in (ShapeType.CONVEX_HULL, ShapeType.TRIMESH):
        assert shape.vertices.dtype == np.float64 and shape.vertices.shape[1:] == (3,)
        assert shape.faces.dtype == np.int64 and shape.faces.shape[1:] == (3,)
        assert np.all(shape.params == 0.0)
    else:
        assert shape.vertices is None and shape.faces is None
    with pytest.raises(AttributeError, match="immutable"):
        shape.foo = 1
    with pytest.raises(ValueError, match="read-only"):
        shape.params[0] = 2.0
    assert pickle.loads(pickle.dumps(shape)) == shape


# --- params, volume, mass properties ------------------------------------------------------------------------


def test_sphere():
    s = Sphere(0.5)
    assert s.params.tolist() == [0.5, 0.0, 0.0, 0.0]
    assert s.volume == pytest.approx(4 / 3 * math.pi * 0.125, rel=EXACT)
    assert s.mass_properties(density=2.0).isclose(mass.solid_sphere(0.5, density=2.0), rtol=EXACT)
    assert repr(s) == "Sphere(radius=0.5)"


def test_box_params_are_half_extents():
    b = Box((1.0, 2.0, 3.0))
    assert b.params.tolist() == [0.5, 1.0, 1.5, 0.0]
    assert b.extents.tolist() == [1.0, 2.0, 3.0]
    assert b.volume == pytest.approx(6.0, rel=EXACT)
    assert b.mass_properties(mass=3.0).isclose(mass.box((1.0, 2.0, 3.0), mass=3.0), rtol=EXACT)
    assert eval(repr(b), {"Box": Box}) == b


def test_capsule():
    c = Capsule(0.5, 2.0)
    assert c.params.tolist() == [0.5, 1.0, 0.0, 0.0]
    assert c.volume == pytest.approx(math.pi * 0.25 * 2.0 + 4 / 3 * math.pi * 0.125, rel=EXACT)
    assert c.mass_properties(density=3.0).isclose(mass.capsule(0.5, 2.0, density=3.0), rtol=EXACT)
    assert c.mass_properties(density=3.0).mass == pytest.approx(3.0 * c.volume, rel=EXACT)


def test_cylinder():
    c = Cylinder(0.5, 2.0)
    assert c.params.tolist() == [0.5, 1.0, 0.0, 0.0]
    assert c.volume == pytest.approx(math.pi * 0.25 * 2.0, rel=EXACT)
    assert c.mass_properties(mass=2.0).isclose(mass.solid_cylinder(0.5, 2.0, mass=2.0), rtol=EXACT)


def test_plane_normalises_and_has_no_mass():
    p = Plane((0.0, 0.0, 2.0), offset=1.5)
    assert p.params.tolist() == [0.0, 0.0, 1.0, 1.5]
    assert p.volume == math.inf
    assert Plane().params.tolist() == [0.0, 0.0, 1.0, 0.0]
    with pytest.raises(ValueError, match=r"a Plane is static only and has no mass properties"):
        p.mass_properties(mass=1.0)
    lo, hi = p.local_bounds()
    assert np.all(lo == -math.inf) and np.all(hi == math.inf)
    with pytest.raises(ValueError, match=r"Plane is unbounded"):
        p.support((0, 0, 1))


def test_plane_errors():
    with pytest.raises(ValueError, match=r"normal must be a non-zero vector, got \[0.0, 0.0, 0.0\]"):
        Plane((0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"normal must be finite"):
        Plane((0.0, math.nan, 1.0))
    with pytest.raises(ValueError, match=r"offset must be finite"):
        Plane(offset=math.inf)
    with pytest.raises(ValueError, match=r"normal must have shape \(3\)"):
        Plane((0.0, 1.0))


def test_convex_hull_of_cube_corners_and_inside_points_is_the_box():
    hull = cube_hull_with_inside_points()
    # Only the 8 corners survive; 6 square facets make 12 triangles.
    assert hull.vertices.shape == (8, 3) and hull.faces.shape == (12, 3)
    assert sorted(map(tuple, hull.vertices)) == sorted(map(tuple, CUBE_CORNERS))
    assert hull.volume == pytest.approx(6.0, rel=EXACT)
    # Exact polyhedral integration of a box: measured bit-exact here.
    assert hull.mass_properties(mass=2.0).isclose(mass.box((1.0, 2.0, 3.0), mass=2.0), rtol=EXACT)
    lo, hi = hull.local_bounds()
    assert lo.tolist() == [-0.5, -1.0, -1.5] and hi.tolist() == [0.5, 1.0, 1.5]


@pytest.mark.parametrize("seed", range(6))
def test_convex_hull_faces_point_outward(seed):
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(60, 3)) * rng.uniform(0.3, 3.0, 3) + rng.uniform(-10, 10, 3)
    hull = ConvexHull(points)
    v, f = hull.vertices, hull.faces
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    normals = np.cross(b - a, c - a)
    centroid = v.mean(axis=0)  # strictly inside a convex hull
    # Every face normal points away from an interior point.
    assert np.all(np.einsum("ij,ij->i", normals, (a + b + c) / 3 - centroid) > 0.0)
    signed_volume = np.einsum("ij,ij->i", a - centroid, np.cross(b - centroid, c - centroid)).sum() / 6
    assert signed_volume > 0.0
    # An independent oracle: trimesh sees a watertight, consistently wound surface of the same volume.
    reference = trimesh.Trimesh(v, f, process=False)
    assert reference.is_watertight and reference.is_winding_consistent
    assert hull.volume == pytest.approx(reference.volume, rel=1e-12)  # measured max 7e-16 over seeds 0..19
    # Mass properties against trimesh (density 1, inertia about the COM): measured max 8e-16 (com,
    # relative to the coordinates) and 3.3e-14 (inertia, relative to its largest entry) over seeds 0..19.
    p = hull.mass_properties(density=1.0)
    assert np.allclose(p.com, reference.center_mass, rtol=0, atol=1e-9 * np.abs(points).max())
    assert np.allclose(p.inertia, reference.moment_inertia, rtol=0, atol=1e-9 * np.abs(p.inertia).max())


@pytest.mark.parametrize(
    ("points", "message"),
    [
        (CUBE_CORNERS[:3], r"points must have shape \(n, 3\) with n >= 4"),
        (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.3, 0.7, 0]]), r"points must span a volume"),
        (np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]]), r"points must span a volume"),
        (np.ones((5, 3)), r"points must span a volume"),
        (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, math.nan]]), r"points must be finite"),
    ],
    ids=["three-points", "coplanar", "collinear", "one-point", "nan"],
)
def test_degenerate_hulls_are_refused(points, message):
    with pytest.raises(ValueError, match=message):
        ConvexHull(points)


def test_trimesh_closed_and_open():
    closed = TriMesh(CUBE_CORNERS, box_faces())
    assert closed.is_closed
    assert closed.volume == pytest.approx(6.0, rel=EXACT)
    assert closed.mass_properties(mass=1.0).isclose(mass.box((1.0, 2.0, 3.0), mass=1.0), rtol=EXACT)
    assert closed.mass_properties(mass=1.0).isclose(mass.mesh(CUBE_CORNERS, box_faces(), mass=1.0), rtol=0.0)

    terrain = TriMesh(CUBE_CORNERS, box_faces()[:4])  # an open surface is a valid static mesh
    assert not terrain.is_closed
    with pytest.raises(ValueError, match=r"is not closed: \d+ boundary edges"):
        terrain.mass_properties(mass=1.0)
    with pytest.raises(ValueError, match=r"is not closed"):
        _ = terrain.volume

    inward = TriMesh(CUBE_CORNERS, box_faces()[:, ::-1])
    assert inward.is_closed  # closed and consistent, only inside out
    with pytest.raises(ValueError, match=r"inward-wound"):
        inward.mass_properties(density=1.0)


def test_trimesh_validates_indices():
    with pytest.raises(ValueError, match=r"out of range"):
        TriMesh(CUBE_CORNERS, [[0, 1, 8]])
    with pytest.raises(TypeError, match=r"faces must hold integer vertex indices"):
        TriMesh(CUBE_CORNERS, [[0.0, 1.0, 2.0]])
    with pytest.raises(ValueError, match=r"degenerate"):
        TriMesh(CUBE_CORNERS, [[0, 1, 1]])


# --- bounds and support -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("shape", "lo", "hi"),
    [
        (Sphere(0.5), [-0.5] * 3, [0.5] * 3),
        (Box((1.0, 2.0, 3.0)), [-0.5, -1.0, -1.5], [0.5, 1.0, 1.5]),
        (Capsule(0.5, 2.0), [-0.5, -0.5, -1.5], [0.5, 0.5, 1.5]),
        (Cylinder(0.5, 2.0), [-0.5, -0.5, -1.0], [0.5, 0.5, 1.0]),
        (TriMesh(CUBE_CORNERS + 1.0, box_faces()), [0.5, 0.0, -0.5], [1.5, 2.0, 2.5]),
    ],
)
def test_local_bounds(shape, lo, hi):
    low, high = shape.local_bounds()
    assert low.dtype == np.float64 and high.dtype == np.float64
    assert low.tolist() == pytest.approx(lo, abs=0) and high.tolist() == pytest.approx(hi, abs=0)


def surface_samples(shape, count=4000, seed=3):
    """Points on or inside the shape, from rejection sampling of its bounds (for brute-force support)."""
    rng = np.random.default_rng(seed)
    lo, hi = shape.local_bounds()
    points = rng.uniform(lo, hi, size=(count * 4, 3))
    if isinstance(shape, Sphere):
        keep = np.linalg.norm(points, axis=1) <= shape.radius
    elif isinstance(shape, Capsule):
        z = np.clip(points[:, 2], -shape.length / 2, shape.length / 2)
        keep = np.linalg.norm(points - np.c_[0 * z, 0 * z, z], axis=1) <= shape.radius
    elif isinstance(shape, Cylinder):
        keep = np.hypot(points[:, 0], points[:, 1]) <= shape.radius
    else:
        keep = np.ones(len(points), dtype=bool)
    return points[keep]


@pytest.mark.parametrize("shape", [Sphere(0.5), Box((1.0, 2.0, 3.0)), Capsule(0.5, 2.0), Cylinder(0.5, 2.0)])
def test_support_is_on_the_shape_and_farthest(shape):
    rng = np.random.default_rng(11)
    samples = surface_samples(shape)
    for direction in rng.normal(size=(50, 3)):
        s = shape.support(direction)
        # No sampled point of the solid lies farther along the direction than the support point.
        assert s @ direction >= np.max(samples @ direction) - 1e-12
        # The support point belongs to the closed solid (distances from the analytic surface: rounding).
        lo, hi = shape.local_bounds()
        assert np.all(s >= lo - 1e-12) and np.all(s <= hi + 1e-12)


def test_support_closed_forms():
    assert Sphere(2.0).support((0, 3, 4)).tolist() == pytest.approx([0, 1.2, 1.6], abs=1e-15)
    assert Box((1, 2, 3)).support((1, -1, 0.1)).tolist() == [0.5, -1.0, 1.5]
    assert Capsule(0.5, 2.0).support((0, 0, -1)).tolist() == [0, 0, -1.5]
    assert Capsule(0.5, 2.0).support((1, 0, 0)).tolist() == [0.5, 0, 1.0]  # dz = 0 picks the top end
    assert Cylinder(0.5, 2.0).support((3, 4, -1)).tolist() == pytest.approx([0.3, 0.4, -1.0], abs=1e-15)
    assert Cylinder(0.5, 2.0).support((0, 0, 1)).tolist() == [0, 0, 1.0]
    hull = cube_hull_with_inside_points()
    assert hull.support((1, 1, 1)).tolist() == [0.5, 1.0, 1.5]
    assert hull.support((-1, 0.1, -2)).tolist() == [-0.5, 1.0, -1.5]
    with pytest.raises(ValueError, match=r"direction must be a non-zero vector"):
        Sphere(1.0).support((0, 0, 0))


# --- construction errors ------------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [-1.0, 0.0, math.nan, math.inf])
@pytest.mark.parametrize(
    ("name", "build"),
    [
        ("radius", lambda v: Sphere(v)),
        ("extents", lambda v: Box((1.0, 1.0, v))),
        ("radius", lambda v: Capsule(v, 1.0)),
        ("radius", lambda v: Cylinder(v, 1.0)),
        ("height", lambda v: Cylinder(1.0, v)),
    ],
)
def test_bad_sizes_name_the_argument(name, build, bad):
    with pytest.raises(ValueError, match=rf"^{name} must be"):
        build(bad)


def test_capsule_length_zero_is_a_sphere():
    sphere = Sphere(0.5).mass_properties(mass=1.0)
    assert Capsule(0.5, 0.0).mass_properties(mass=1.0).isclose(sphere, rtol=EXACT)
    with pytest.raises(ValueError, match=r"length must be >= 0"):
        Capsule(0.5, -0.1)


def test_mass_properties_need_exactly_one_of_mass_or_density():
    with pytest.raises(TypeError, match=r"exactly one of mass= or density="):
        Box((1, 1, 1)).mass_properties()
    with pytest.raises(TypeError, match=r"exactly one of mass= or density="):
        Sphere(1.0).mass_properties(mass=1.0, density=1.0)


def test_equal_shapes_are_equal_values():
    assert Box((1, 2, 3)) == Box([1.0, 2.0, 3.0])
    assert hash(Sphere(1.0)) == hash(Sphere(1))
    assert Sphere(1.0) != Sphere(1.1)
    assert Cylinder(0.5, 1.0) != Capsule(0.5, 1.0)  # same params, different kinds


@pytest.mark.parametrize(
    "make",
    [lambda: Sphere(5.6e102), lambda: Box((1e200, 1e200, 1e200)), lambda: Capsule(1e103, 1.0),
     lambda: Cylinder(1e200, 1e200)],
)  # fmt: skip
def test_a_shape_whose_volume_overflows_is_refused_by_name(make):
    with pytest.raises(ValueError, match=r"is too large: its volume overflows"):
        make()
