"""tumble.mass: closed forms, the parallel-axis theorem, composites, transforms, meshes and bad input.

Every expected value is written here independently of the implementation, with its source: the course
deck ``002_ea6177634d64fff8.txt`` ("Inertia of Primitive Shapes"), standard tables, integrals derived in
this file (disc slicing with ``scipy.integrate.quad``, Dirichlet simplex integrals), or trimesh as an
independent oracle for meshes.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
import trimesh
from scipy import integrate

from tumble import mass
from tumble.mass import MassProperties

# Closed form against closed form: both are a few float64 operations, so agreement is ~1e-16 relative;
# 1e-12 leaves room for rearranged arithmetic and still catches any wrong coefficient.
EXACT = 1e-12


def rodrigues(axis, angle) -> np.ndarray:
    """Rotation matrix about ``axis`` by ``angle`` (Rodrigues' formula), written here for the tests."""
    e = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0.0, -e[2], e[1]], [e[2], 0.0, -e[0]], [-e[1], e[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * k @ k


def hat(r) -> np.ndarray:
    """The course's hat (skew) matrix: ``hat(a) @ b == cross(a, b)`` (deck 000)."""
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def assert_tensor(actual, expected, rtol=EXACT):
    """Compare tensors relative to the largest entry (products of inertia near 0 compare to the size)."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    scale = max(float(np.max(np.abs(expected))), 1e-300)
    err = float(np.max(np.abs(actual - expected))) / scale
    assert err <= rtol, f"relative error {err:.3g} > {rtol:g}\nactual={actual}\nexpected={expected}"


def sliced_solid(radius_at, breaks, density=1.0):
    """Mass properties of a solid of revolution about z by integrating thin discs (course deck 002).

    A disc of radius ρ and mass dm = density π ρ² dz at height z has ``dI_zz = ρ²/2 dm`` and, about the
    x axis through the base ``z0 = breaks[0]``, ``dI_xx = (ρ²/4 + (z - z0)²) dm``. ``breaks`` are the
    z values where ``radius_at`` has kinks; each smooth piece goes to ``quad`` separately, and every
    integrand is non-negative so a relative tolerance is meaningful. Returns mass, com_z and
    ``(I_xx, I_zz)`` about the centre of mass.
    """
    z0 = breaks[0]

    def quad(f):
        pieces = zip(breaks[:-1], breaks[1:], strict=True)
        return sum(integrate.quad(f, a, b, epsabs=0.0, epsrel=1e-13)[0] for a, b in pieces)

    dm = lambda z: density * math.pi * radius_at(z) ** 2  # noqa: E731
    m = quad(dm)
    height = quad(lambda z: (z - z0) * dm(z)) / m
    izz = quad(lambda z: 0.5 * radius_at(z) ** 2 * dm(z))
    ixx_base = quad(lambda z: (0.25 * radius_at(z) ** 2 + (z - z0) ** 2) * dm(z))
    return m, z0 + height, (ixx_base - m * height * height, izz)


# --- primitives against their closed forms ------------------------------------------------------------------


def test_solid_sphere_is_two_fifths_m_r_squared():
    # course deck 002: I = 2/5 m r² on every axis.
    p = mass.solid_sphere(0.7, mass=3.0)
    assert p.mass == 3.0
    assert_tensor(p.com, np.zeros(3))
    assert_tensor(p.inertia, np.eye(3) * 2 / 5 * 3.0 * 0.49)


def test_hollow_sphere_is_two_thirds_m_r_squared():
    # course deck 002: thin shell, I = 2/3 m r².
    p = mass.hollow_sphere(0.7, mass=3.0)
    assert_tensor(p.inertia, np.eye(3) * 2 / 3 * 3.0 * 0.49)


def test_solid_ellipsoid_closed_form():
    # course deck 002: I = m/5 diag(b² + c², a² + c², a² + b²).
    a, b, c, m = 1.0, 2.0, 3.0, 5.0
    p = mass.solid_ellipsoid(a, b, c, mass=m)
    assert_tensor(p.inertia, np.diag([m * (4 + 9) / 5, m * (1 + 9) / 5, m * (1 + 4) / 5]))


def test_box_is_m_over_12_not_the_deck_typo():
    # course deck 002 (and deck 000 with its m/10 corrected to m/12): I_x = m/12 (b² + c²), ...
    p = mass.box((1.0, 2.0, 3.0), mass=6.0)
    assert_tensor(p.inertia, np.diag([6 / 12 * 13, 6 / 12 * 10, 6 / 12 * 5]))
    assert p.inertia[2, 2] == pytest.approx(2.5, rel=EXACT)  # m/10 would give 3.0


def test_solid_cylinder_closed_form():
    # course deck 002: I_xx = I_yy = m (3r² + h²)/12, I_zz = m r²/2.
    r, h, m = 0.5, 2.0, 4.0
    p = mass.solid_cylinder(r, h, mass=m)
    side = m * (3 * r * r + h * h) / 12
    assert_tensor(p.inertia, np.diag([side, side, m * r * r / 2]))


def test_solid_cylinder_matches_disc_slicing():
    # An independent route: integrate discs of constant radius (scipy quad; measured exact here).
    r, h = 0.5, 2.0
    m, zc, (ixx, izz) = sliced_solid(lambda z: r, (-h / 2, h / 2))
    p = mass.solid_cylinder(r, h, density=1.0)
    assert p.mass == pytest.approx(m, rel=EXACT)
    assert_tensor(p.inertia, np.diag([ixx, ixx, izz]))


def test_hollow_cylinder_closed_form():
    # course deck 002: open thin tube, I_xx = I_yy = m (6r² + h²)/12, I_zz = m r².
    r, h, m = 0.5, 2.0, 4.0
    p = mass.hollow_cylinder(r, h, mass=m)
    side = m * (6 * r * r + h * h) / 12
    assert_tensor(p.inertia, np.diag([side, side, m * r * r]))


@pytest.mark.parametrize(("radius", "length"), [(0.5, 2.0), (1.0, 0.3), (0.2, 5.0)])
def test_capsule_matches_disc_slicing(radius, length):
    # The capsule's discs: radius r on the cylinder, sqrt(r² - (|z| - L/2)²) on the caps. Integrated piece
    # by piece between the kinks at ±L/2, quad agrees with the closed form to 9e-16 relative (measured).
    half = length / 2

    def radius_at(z):
        over = abs(z) - half
        return radius if over <= 0 else math.sqrt(max(radius * radius - over * over, 0.0))

    m, zc, (ixx, izz) = sliced_solid(radius_at, (-half - radius, -half, half, half + radius), density=2.0)
    p = mass.capsule(radius, length, density=2.0)
    assert p.mass == pytest.approx(m, rel=EXACT)
    assert abs(zc) < 1e-14  # symmetric: measured 9e-16 of rounding in the quad sums
    assert_tensor(p.inertia, np.diag([ixx, ixx, izz]))


def test_capsule_of_zero_length_is_a_sphere():
    assert mass.capsule(0.4, 0.0, mass=2.0).isclose(mass.solid_sphere(0.4, mass=2.0), rtol=EXACT)


def test_capsule_is_bracketed_by_its_inscribed_cylinder_and_enclosing_cylinder():
    # At equal density the capsule contains the cylinder (r, L) and lies inside the cylinder (r, L + 2r),
    # and the moment is monotone under inclusion (more mass, farther out).
    r, length = 0.5, 1.0
    inner = mass.solid_cylinder(r, length, density=1.0)
    outer = mass.solid_cylinder(r, length + 2 * r, density=1.0)
    p = mass.capsule(r, length, density=1.0)
    assert inner.mass < p.mass < outer.mass
    assert np.all(np.diag(inner.inertia) < np.diag(p.inertia))
    assert np.all(np.diag(p.inertia) < np.diag(outer.inertia))


def test_cone_closed_form_and_centre_of_mass():
    # Standard table (e.g. Wikipedia "List of moments of inertia"): about the apex, transverse
    # 3/5 m h² + 3/20 m r², axial 3/10 m r²; the centroid is 3h/4 from the apex, so about it the
    # transverse moment is 3/80 m (4 r² + h²).
    r, h, m = 0.6, 1.5, 2.0
    p = mass.cone(r, h, mass=m)
    assert_tensor(p.com, [0.0, 0.0, h / 4])
    transverse = 3 / 80 * m * (4 * r * r + h * h)
    assert_tensor(p.inertia, np.diag([transverse, transverse, 3 / 10 * m * r * r]))
    apex = p.inertia_about((0.0, 0.0, h))
    assert apex[0, 0] == pytest.approx(3 / 5 * m * h * h + 3 / 20 * m * r * r, rel=EXACT)


def test_cone_matches_disc_slicing():
    r, h = 0.6, 1.5
    m, zc, (ixx, izz) = sliced_solid(lambda z: r * (1 - z / h), (0.0, h), density=3.0)
    p = mass.cone(r, h, density=3.0)
    assert p.mass == pytest.approx(m, rel=EXACT)
    assert p.com[2] == pytest.approx(zc, rel=EXACT)
    assert_tensor(p.inertia, np.diag([ixx, ixx, izz]))


# --- density gives mass = density x volume (or area for the shells) -----------------------------------------


@pytest.mark.parametrize(
    ("build", "measure"),
    [
        (lambda **k: mass.solid_sphere(0.5, **k), 4 / 3 * math.pi * 0.125),
        (lambda **k: mass.hollow_sphere(0.5, **k), 4 * math.pi * 0.25),  # areal density
        (lambda **k: mass.solid_ellipsoid(1.0, 2.0, 0.5, **k), 4 / 3 * math.pi * 1.0),
        (lambda **k: mass.box((1.0, 2.0, 3.0), **k), 6.0),
        (lambda **k: mass.solid_cylinder(0.5, 2.0, **k), math.pi * 0.25 * 2.0),
        (lambda **k: mass.hollow_cylinder(0.5, 2.0, **k), 2 * math.pi * 0.5 * 2.0),  # areal, no caps
        (lambda **k: mass.capsule(0.5, 2.0, **k), math.pi * 0.25 * 2.0 + 4 / 3 * math.pi * 0.125),
        (lambda **k: mass.cone(0.5, 2.0, **k), math.pi * 0.25 * 2.0 / 3),
    ],
)
def test_density_gives_mass(build, measure):
    assert build(density=7.0).mass == pytest.approx(7.0 * measure, rel=EXACT)
    # Same shape, so mass= and density= give the same inertia per unit mass.
    by_density = build(density=7.0)
    assert by_density.isclose(build(mass=by_density.mass), rtol=EXACT)


# --- particles ----------------------------------------------------------------------------------------------


def test_particles_against_minus_m_hat_hat():
    rng = np.random.default_rng(1)
    masses = rng.uniform(0.5, 2.0, 7)
    points = rng.normal(size=(7, 3))
    p = mass.particles(masses, points)
    com = (masses[:, None] * points).sum(axis=0) / masses.sum()
    expected = sum(-m * hat(x - com) @ hat(x - com) for m, x in zip(masses, points, strict=True))
    assert p.mass == pytest.approx(masses.sum(), rel=EXACT)
    assert_tensor(p.com, com)
    assert_tensor(p.inertia, expected)


def test_particles_on_a_line_have_a_zero_moment_and_are_accepted():
    p = mass.particles([1.0, 2.0, 1.0], [(-1.0, 0, 0), (0.0, 0, 0), (1.0, 0, 0)])
    assert p.inertia[0, 0] == 0.0
    assert_tensor(p.inertia, np.diag([0.0, 2.0, 2.0]))


# --- parallel axis and composites ---------------------------------------------------------------------------


def test_two_halves_of_a_box_are_the_box():
    whole = mass.box((1.0, 2.0, 3.0), mass=6.0)
    half = mass.box((0.5, 2.0, 3.0), mass=3.0)
    left, right = half.transformed(translation=(-0.25, 0, 0)), half.transformed(translation=(0.25, 0, 0))
    assert (left + right).isclose(whole, rtol=EXACT)


def test_box_plus_displaced_sphere_by_hand():
    # Box 2x2x2 of 3 kg at the origin (I = 3/12 (4 + 4) = 2), ball r=1 of 1 kg at z=2 (I = 0.4).
    # COM z = (3*0 + 1*2)/4 = 0.5. Transverse: 2 + 3*0.5² + 0.4 + 1*1.5² = 5.4; axial: 2 + 0.4 = 2.4.
    ball = mass.solid_sphere(1.0, mass=1.0).transformed(translation=(0, 0, 2))
    body = mass.box((2.0, 2.0, 2.0), mass=3.0) + ball
    assert body.mass == 4.0
    assert_tensor(body.com, [0.0, 0.0, 0.5])
    assert_tensor(body.inertia, np.diag([5.4, 5.4, 2.4]))


def test_composite_off_axis_products_of_inertia_by_hand():
    # A 1 kg point at (1, 2, 0) and a 1 kg point at (-1, -2, 0): COM at 0, I = Σ m (|r|² E - r rᵀ)
    # = 2 [[5-1, -2, 0], [-2, 5-4, 0], [0, 0, 5]].
    a = mass.particles([1.0], [(1.0, 2.0, 0.0)])
    b = mass.particles([1.0], [(-1.0, -2.0, 0.0)])
    assert_tensor((a + b).inertia, 2 * np.array([[4.0, -2.0, 0.0], [-2.0, 1.0, 0.0], [0.0, 0.0, 5.0]]))


def test_sum_starts_from_zero_and_matches_repeated_add():
    parts = [mass.solid_sphere(0.3, mass=1.0).transformed(translation=t) for t in np.eye(3)]
    assert sum(parts).isclose(parts[0] + parts[1] + parts[2], rtol=EXACT)
    with pytest.raises(TypeError):
        _ = 1 + parts[0]


def test_inertia_about_a_cube_corner():
    # Standard result: a cube of side a about a corner has diagonal 2/3 m a² and products -1/4 m a².
    a, m = 2.0, 3.0
    p = mass.box((a, a, a), mass=m)
    expected = m * a * a * (11 / 12 * np.eye(3) - 1 / 4 * np.ones((3, 3)))  # 11/12 - 1/4 = 2/3
    assert_tensor(p.inertia_about((-a / 2, -a / 2, -a / 2)), expected)


def test_moment_about_the_body_diagonal_and_an_edge():
    # Box (a, b, c): about its body diagonal through the COM, m/6 (a²b² + b²c² + c²a²)/(a² + b² + c²);
    # about an edge parallel to z, m/3 (a² + b²).
    a, b, c, m = 1.0, 2.0, 3.0, 6.0
    p = mass.box((a, b, c), mass=m)
    diagonal = m / 6 * (a * a * b * b + b * b * c * c + c * c * a * a) / (a * a + b * b + c * c)
    assert p.moment_about((a, b, c)) == pytest.approx(diagonal, rel=EXACT)
    # Any point of the edge line gives the same moment.
    edge = m / 3 * (a * a + b * b)
    for z in (-c / 2, 0.0, 10.0):
        assert p.moment_about((0, 0, -2.0), point=(a / 2, b / 2, z)) == pytest.approx(edge, rel=EXACT)


def test_moment_about_zero_axis_is_refused():
    with pytest.raises(ValueError, match=r"axis must be a non-zero vector"):
        mass.box((1, 1, 1), mass=1.0).moment_about((0, 0, 0))


# --- transforms and principal axes --------------------------------------------------------------------------


def test_transformed_rotates_the_tensor_and_moves_the_com():
    p = mass.cone(0.5, 2.0, mass=3.0)
    rot = rodrigues((1.0, -2.0, 0.5), 0.9)
    t = np.array([1.0, 2.0, -3.0])
    q = p.transformed(rot, t)
    assert q.mass == p.mass
    assert_tensor(q.com, rot @ p.com + t)
    assert_tensor(q.inertia, rot @ p.inertia @ rot.T)


def test_transformed_accepts_a_quaternion():
    axis, angle = np.array([1.0, -2.0, 0.5]) / math.sqrt(5.25), 0.9
    # Course deck 002: q = (cos θ/2, sin θ/2 ê), scalar first.
    quat = np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])
    p = mass.box((1.0, 2.0, 3.0), mass=2.0)
    by_matrix = p.transformed(rodrigues(axis, angle), (1, 2, 3))
    assert p.transformed(quat, (1, 2, 3)).isclose(by_matrix, rtol=EXACT)


def test_transformed_refuses_a_reflection():
    with pytest.raises(ValueError, match=r"rotation must be a proper rotation"):
        mass.box((1, 2, 3), mass=1.0).transformed(np.diag([1.0, 1.0, -1.0]))


def test_principal_of_a_rotated_box_recovers_moments_and_axes():
    p = mass.box((1.0, 2.0, 3.0), mass=6.0)
    rot = rodrigues((0.3, 1.0, -0.4), 2.1)
    moments, axes = p.transformed(rot).principal()
    # Ascending moments of the unrotated box: I_z = 2.5 < I_y = 5.0 < I_x = 6.5.
    assert_tensor(moments, [2.5, 5.0, 6.5])
    assert np.linalg.det(axes) == pytest.approx(1.0, abs=1e-12)  # orthonormal to rounding
    # The axes are the rotated z, y, x axes, each up to sign: |cos| = 1 (eigh: ~1e-15 here).
    for k, column in enumerate((2, 1, 0)):
        assert abs(axes[:, k] @ rot[:, column]) == pytest.approx(1.0, abs=1e-12)
    assert_tensor(axes @ np.diag(moments) @ axes.T, rot @ p.inertia @ rot.T)


def test_scaled_to_keeps_the_shape():
    p = mass.cone(0.5, 2.0, mass=3.0)
    q = p.scaled_to(6.0)
    assert q.mass == 6.0
    assert_tensor(q.com, p.com)
    assert_tensor(q.inertia, 2 * p.inertia)


# --- the value object itself --------------------------------------------------------------------------------


def test_mass_properties_is_immutable_and_float64():
    p = MassProperties(2, [0, 0, 1], np.diag([1, 2, 2]))
    assert p.com.dtype == np.float64 and p.inertia.dtype == np.float64
    with pytest.raises(AttributeError, match="immutable"):
        p.mass = 3.0
    with pytest.raises(ValueError, match="read-only"):
        p.com[0] = 5.0
    with pytest.raises(ValueError, match="read-only"):
        p.inertia[0, 0] = 5.0


def test_constructor_copies_its_input():
    inertia = np.diag([1.0, 2.0, 2.0])
    p = MassProperties(1.0, np.zeros(3), inertia)
    inertia[0, 0] = 100.0
    assert p.inertia[0, 0] == 1.0


def test_repr_round_trips_and_pickle_works():
    p = mass.cone(0.5, 2.0, mass=3.0).transformed(rodrigues((1, 1, 0), 0.3))
    assert eval(repr(p), {"MassProperties": MassProperties}).isclose(p, rtol=0.0, atol=0.0)
    assert pickle.loads(pickle.dumps(p)).isclose(p, rtol=0.0, atol=0.0)


def test_isclose_detects_a_difference():
    p = mass.box((1, 2, 3), mass=1.0)
    assert not p.isclose(p.transformed(translation=(1e-6, 0, 0)))
    assert not p.isclose(p.scaled_to(1.0 + 1e-6))
    assert p.isclose(p.scaled_to(1.0 + 1e-13))


# --- meshes -------------------------------------------------------------------------------------------------


def box_mesh(extents, center=(0.0, 0.0, 0.0)):
    """A box as 12 outward (counter-clockwise from outside) triangles, written out by hand."""
    hx, hy, hz = np.asarray(extents, dtype=float) / 2
    corners = np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    # Corner index = 4 * (x > 0) + 2 * (y > 0) + (z > 0).
    faces = [
        (0, 1, 3), (0, 3, 2),  # -x
        (4, 6, 7), (4, 7, 5),  # +x
        (0, 4, 5), (0, 5, 1),  # -y
        (2, 3, 7), (2, 7, 6),  # +y
        (0, 2, 6), (0, 6, 4),  # -z
        (1, 5, 7), (1, 7, 3),  # +z
    ]  # fmt: skip
    return corners + np.asarray(center), np.array(faces, dtype=np.int64)


def test_box_mesh_is_exact():
    vertices, faces = box_mesh((1.0, 2.0, 3.0), center=(10.0, -5.0, 2.0))
    p = mass.mesh(vertices, faces, density=2.0)
    # Box closed form (course deck 002), mass = 2 * 6 = 12.
    assert p.mass == pytest.approx(12.0, rel=EXACT)
    assert_tensor(p.com, [10.0, -5.0, 2.0])
    assert_tensor(p.inertia, np.diag([12 / 12 * 13, 12 / 12 * 10, 12 / 12 * 5]))


def test_mesh_far_from_the_origin_keeps_its_digits():
    # A unit box 1e5 m away: integrating about the origin would cancel ~(1e5)² of 1e-16 rounding into
    # the inertia (~1e-6 relative); the implementation integrates about the vertex mean and stays exact
    # here (measured 0 difference).
    vertices, faces = box_mesh((1.0, 2.0, 3.0), center=(1e5, -2e5, 3e5))
    p = mass.mesh(vertices, faces, mass=6.0)
    assert_tensor(p.com, [1e5, -2e5, 3e5])
    assert_tensor(p.inertia, np.diag([6 / 12 * 13, 6 / 12 * 10, 6 / 12 * 5]))


def test_right_corner_tetrahedron_against_dirichlet_integrals():
    # Tetrahedron 0, a e1, b e2, c e3. Dirichlet's integral over it:
    # ∫ x^p y^q z^r dV = a^(p+1) b^(q+1) c^(r+1) p! q! r! / (p+q+r+3)!,
    # so V = abc/6, ∫x = a²bc/24, ∫x² = a³bc/60, ∫xy = a²b²c/120.
    a, b, c = 1.0, 2.0, 3.0
    vertices = np.array([[0, 0, 0], [a, 0, 0], [0, b, 0], [0, 0, c]], dtype=float)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    p = mass.mesh(vertices, faces, density=1.0)
    volume = a * b * c / 6
    assert p.mass == pytest.approx(volume, rel=EXACT)
    com = np.array([a, b, c]) / 4  # (a²bc/24) / (abc/6) = a/4
    assert_tensor(p.com, com)
    size = np.array([a, b, c])
    second = np.outer(size, size) * a * b * c / 120 + np.diag(size**2 * a * b * c / 120)  # ∫ x xᵀ about 0
    second -= volume * np.outer(com, com)  # about the centroid
    assert_tensor(p.inertia, np.trace(second) * np.eye(3) - second)


def test_general_tetrahedron_against_the_affine_map_of_the_unit_simplex():
    # x = v0 + A u maps the unit simplex onto the tetrahedron; with ∫du = 1/6, ∫u du = 1/24 (1,1,1) and
    # ∫u uᵀ du = (E + 1 1ᵀ)/120: ∫ x xᵀ dV = |det A| (v0 v0ᵀ/6 + v0 (A m1)ᵀ + (A m1) v0ᵀ + A M2 Aᵀ).
    rng = np.random.default_rng(7)
    v = rng.normal(size=(4, 3)) + np.array([3.0, -1.0, 2.0])
    jac = (v[1:] - v[0]).T
    if np.linalg.det(jac) < 0:
        v[[2, 3]] = v[[3, 2]]
        jac = (v[1:] - v[0]).T
    det = np.linalg.det(jac)
    m1, m2 = np.full(3, 1 / 24), (np.eye(3) + np.ones((3, 3))) / 120
    volume = det / 6
    first = det * (v[0] / 6 + jac @ m1)
    mean = jac @ m1
    second = det * (np.outer(v[0], v[0]) / 6 + np.outer(v[0], mean) + np.outer(mean, v[0]) + jac @ m2 @ jac.T)
    com = first / volume
    second_c = second - volume * np.outer(com, com)
    # Faces counter-clockwise from outside for a positively oriented (v0, v1, v2, v3).
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    p = mass.mesh(v, faces, density=1.0)
    assert p.mass == pytest.approx(volume, rel=EXACT)
    assert_tensor(p.com, com)
    assert_tensor(p.inertia, np.trace(second_c) * np.eye(3) - second_c)


@pytest.mark.parametrize("seed", range(5))
def test_random_convex_hulls_match_trimesh(seed):
    rng = np.random.default_rng(seed)
    hull = trimesh.convex.convex_hull(rng.normal(size=(40, 3)) * rng.uniform(0.2, 3.0, 3))
    rot = rodrigues(rng.normal(size=3), rng.uniform(0, math.pi))
    vertices = hull.vertices @ rot.T + rng.uniform(-20, 20, 3)
    reference = trimesh.Trimesh(vertices, hull.faces, process=False)  # density 1; inertia about the COM
    p = mass.mesh(vertices, hull.faces, density=1.0)
    # Two exact integrations of the same polyhedron; measured max relative difference 2.2e-13 over seeds
    # 0..19 (trimesh integrates about the origin, so the 20 m offset costs it a few digits); 1e-9 is
    # safe and still catches any wrong coefficient.
    assert p.mass == pytest.approx(reference.volume, rel=1e-9)
    assert_tensor(p.com, reference.center_mass, rtol=1e-9)
    assert_tensor(p.inertia, reference.moment_inertia, rtol=1e-9)


def test_icosphere_converges_to_two_fifths_m_r_squared():
    errors = []
    for subdivisions in range(1, 6):
        sphere = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
        p = mass.mesh(sphere.vertices, sphere.faces, mass=1.0)
        # Isotropic to rounding (icosahedral symmetry): products ~1e-17, measured.
        assert_tensor(p.inertia, np.eye(3) * p.inertia[0, 0], rtol=1e-12)
        errors.append(abs(p.inertia[0, 0] / 0.4 - 1.0))
    # Measured 8.6e-2, 2.3e-2, 5.7e-3, 1.4e-3, 3.6e-4: each subdivision divides the error by ~4.
    assert all(later < earlier for earlier, later in zip(errors, errors[1:], strict=False))
    assert errors[-1] < 1e-3


# --- bad input ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [-1.0, 0.0, math.nan, math.inf])
@pytest.mark.parametrize(
    ("name", "build"),
    [
        ("radius", lambda v: mass.solid_sphere(v, mass=1.0)),
        ("radius", lambda v: mass.hollow_sphere(v, mass=1.0)),
        ("b", lambda v: mass.solid_ellipsoid(1.0, v, 1.0, mass=1.0)),
        ("extents", lambda v: mass.box((1.0, v, 1.0), mass=1.0)),
        ("radius", lambda v: mass.solid_cylinder(v, 1.0, mass=1.0)),
        ("height", lambda v: mass.solid_cylinder(1.0, v, mass=1.0)),
        ("height", lambda v: mass.hollow_cylinder(1.0, v, mass=1.0)),
        ("radius", lambda v: mass.capsule(v, 1.0, mass=1.0)),
        ("height", lambda v: mass.cone(1.0, v, mass=1.0)),
        ("mass", lambda v: mass.box((1.0, 1.0, 1.0), mass=v)),
        ("density", lambda v: mass.solid_sphere(1.0, density=v)),
    ],
)
def test_bad_sizes_name_the_argument(name, build, bad):
    with pytest.raises(ValueError, match=rf"^{name} must be"):
        build(bad)


def test_capsule_length_may_be_zero_but_not_negative():
    with pytest.raises(ValueError, match=r"length must be >= 0, got -1.0"):
        mass.capsule(1.0, -1.0, mass=1.0)


def test_message_shows_the_value():
    with pytest.raises(ValueError, match=r"radius must be > 0, got -1.0"):
        mass.solid_sphere(-1.0, mass=1.0)


def test_sizes_of_the_wrong_type():
    with pytest.raises(TypeError, match=r"radius must be a real number"):
        mass.solid_sphere("1", mass=1.0)


def test_mass_and_density_exactly_one():
    with pytest.raises(TypeError, match=r"exactly one of mass= or density="):
        mass.solid_sphere(1.0, mass=1.0, density=1.0)
    with pytest.raises(TypeError, match=r"exactly one of mass= or density="):
        mass.box((1, 1, 1))
    with pytest.raises(TypeError):
        mass.box((1, 1, 1), 2.0)  # mass is keyword-only


def test_particles_errors():
    with pytest.raises(ValueError, match=r"masses must all be > 0"):
        mass.particles([1.0, -1.0], [(0, 0, 0), (1, 0, 0)])
    with pytest.raises(ValueError, match=r"points must have shape \(2, 3\)"):
        mass.particles([1.0, 1.0], [(0, 0, 0)])
    with pytest.raises(ValueError, match=r"masses must be a non-empty 1-D array"):
        mass.particles([], np.zeros((0, 3)))


def test_open_mesh_is_refused_with_boundary_edges():
    vertices, faces = box_mesh((1, 1, 1))
    with pytest.raises(ValueError, match=r"is not closed: 3 boundary edges .* e\.g\. edge \["):
        mass.mesh(vertices, faces[:-1], mass=1.0)


def test_inward_mesh_is_refused():
    vertices, faces = box_mesh((1, 1, 1))
    with pytest.raises(ValueError, match=r"inward-wound \(faces point inside\); reverse the face winding"):
        mass.mesh(vertices, faces[:, ::-1], mass=1.0)


def test_inconsistent_winding_is_refused():
    vertices, faces = box_mesh((1, 1, 1))
    faces[0] = faces[0, ::-1]
    message = r"inconsistently wound: 3 edges are traversed twice in the same direction"
    with pytest.raises(ValueError, match=message):
        mass.mesh(vertices, faces, mass=1.0)


def test_non_manifold_mesh_is_refused():
    vertices, faces = box_mesh((1, 1, 1))
    doubled = np.concatenate([faces, faces])
    with pytest.raises(ValueError, match=r"used by more than two faces"):
        mass.mesh(vertices, doubled, mass=1.0)


def test_zero_volume_mesh_is_refused():
    # Two triangles back to back: closed and consistently wound, but flat.
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
    with pytest.raises(ValueError, match=r"encloses zero volume"):
        mass.mesh(vertices, [[0, 1, 2], [0, 2, 1]], mass=1.0)


def test_bad_face_indices_are_refused():
    vertices, faces = box_mesh((1, 1, 1))
    bad = faces.copy()
    bad[3, 1] = 8
    with pytest.raises(ValueError, match=r"faces index vertices out of range 0\.\.7: 1 faces, e\.g\. face 3"):
        mass.mesh(vertices, bad, mass=1.0)
    bad[3, 1] = -1
    with pytest.raises(ValueError, match=r"out of range"):
        mass.mesh(vertices, bad, mass=1.0)
    with pytest.raises(TypeError, match=r"faces must hold integer vertex indices, got dtype float64"):
        mass.mesh(vertices, faces.astype(float), mass=1.0)
    repeated = faces.copy()
    repeated[0] = (0, 0, 3)
    with pytest.raises(ValueError, match=r"three distinct vertices \(degenerate\)"):
        mass.mesh(vertices, repeated, mass=1.0)
    with pytest.raises(ValueError, match=r"faces must have shape \(f, 3\)"):
        mass.mesh(vertices, faces[:, :2], mass=1.0)
    with pytest.raises(ValueError, match=r"vertices must be finite"):
        mass.mesh(np.where(vertices == 0.5, np.nan, vertices), faces, mass=1.0)


def test_non_psd_inertia_is_refused():
    with pytest.raises(ValueError, match=r"inertia must be positive semi-definite, got eigenvalues"):
        MassProperties(1.0, np.zeros(3), np.diag([1.0, 1.0, -0.5]))


def test_triangle_inequality_violation_is_refused():
    # Eigenvalues 1, 1, 3: no mass distribution has I1 + I2 < I3.
    with pytest.raises(ValueError, match=r"inertia violates the triangle inequality"):
        MassProperties(1.0, np.zeros(3), np.diag([1.0, 1.0, 3.0]))
    # A measured tensor within 1 % of the trace of the inequality is legal (the Crazyflie's, Förster 2015, misses it
    # by 0.5 %); 2.4 % is refused.
    MassProperties(0.03, np.zeros(3), np.diag([1.43e-5, 1.43e-5, 2.89e-5]))
    with pytest.raises(ValueError, match=r"inertia violates the triangle inequality"):
        MassProperties(1.0, np.zeros(3), np.diag([1.0, 1.0, 2.1]))
    # A lamina (I1 + I2 = I3 exactly) is legal.
    MassProperties(1.0, np.zeros(3), np.diag([1.0, 2.0, 3.0]))


def test_asymmetric_inertia_is_refused():
    tensor = np.diag([2.0, 2.0, 2.0])
    tensor[0, 1] = 0.1
    with pytest.raises(ValueError, match=r"inertia must be symmetric, got"):
        MassProperties(1.0, np.zeros(3), tensor)


def test_bad_mass_com_and_inertia_shapes():
    with pytest.raises(ValueError, match=r"mass must be > 0, got 0.0"):
        MassProperties(0.0, np.zeros(3), np.eye(3))
    with pytest.raises(ValueError, match=r"com must have shape \(3\)"):
        MassProperties(1.0, np.zeros(2), np.eye(3))
    with pytest.raises(ValueError, match=r"inertia must be finite"):
        MassProperties(1.0, np.zeros(3), np.diag([1.0, 1.0, math.inf]))
    with pytest.raises(ValueError, match=r"inertia must have shape \(3, 3\)"):
        MassProperties(1.0, np.zeros(3), np.eye(2))
