"""Invariants of tumble.mass on random bodies (hypothesis): what any mass distribution must satisfy."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tumble import mass
from tumble.mass import MassProperties

# Sizes well inside float64's comfortable range: 1e-2..1e1 m, 1e-1..1e2 kg.
sizes = st.floats(min_value=0.01, max_value=10.0, allow_nan=False, allow_infinity=False)
masses = st.floats(min_value=0.1, max_value=100.0, allow_nan=False, allow_infinity=False)
coordinates = st.floats(min_value=-5.0, max_value=5.0, allow_nan=False, allow_infinity=False)
vectors = st.tuples(coordinates, coordinates, coordinates).map(np.array)


def quat_matrix(q) -> np.ndarray:
    """The rotation matrix of a unit quaternion [w, x, y, z] (standard formula, written for this test)."""
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


unit = st.floats(min_value=-1.0, max_value=1.0, allow_nan=False)
rotations = (
    st.tuples(unit, unit, unit, unit)
    .map(np.array)
    .filter(lambda q: np.linalg.norm(q) > 0.1)
    .map(lambda q: quat_matrix(q / np.linalg.norm(q)))
)
directions = vectors.filter(lambda v: np.linalg.norm(v) > 0.1)


@st.composite
def boxes(draw) -> MassProperties:
    extents = (draw(sizes), draw(sizes), draw(sizes))
    return mass.box(extents, mass=draw(masses)).transformed(draw(rotations), draw(vectors))


@st.composite
def point_clouds(draw) -> MassProperties:
    count = draw(st.integers(min_value=1, max_value=8))
    weights = [draw(masses) for _ in range(count)]
    points = [draw(vectors) for _ in range(count)]
    return mass.particles(weights, points)


bodies = st.one_of(boxes(), point_clouds())


def scale_of(p: MassProperties) -> float:
    """The size of an inertia tensor, for relative tolerances (never 0: a lone particle has I = 0)."""
    return max(float(np.max(np.abs(p.inertia))), 1e-300)


@settings(deadline=None)
@given(bodies)
def test_inertia_is_symmetric_psd_and_meets_the_triangle_inequality(p):
    assert np.array_equal(p.inertia, p.inertia.T)  # stored symmetrised
    moments = np.linalg.eigvalsh(p.inertia)
    # eigvalsh of a PSD tensor: rounding of ~1e-16 of the largest moment (measured max 3.6e-16 for the
    # PSD bound and 8.9e-16 for laminae on the triangle bound, over 2000 examples); 1e-12 is 1e4 eps.
    assert moments[0] >= -1e-12 * scale_of(p)
    assert moments[0] + moments[1] >= moments[2] - 1e-12 * scale_of(p)


@settings(deadline=None)
@given(bodies, rotations, vectors)
def test_principal_moments_are_invariant_under_rigid_motion(p, rotation, translation):
    moved = p.transformed(rotation, translation)
    before, _ = p.principal()
    after, axes = moved.principal()
    # Eigenvalues are well conditioned (Weyl): a rotation in float64 perturbs them by ~1e-15 of the
    # largest (measured max 2.0e-15 over 2000 examples).
    assert np.allclose(after, before, rtol=0.0, atol=1e-12 * scale_of(p))
    assert np.linalg.det(axes) > 0.0  # right-handed
    assert np.allclose(axes.T @ axes, np.eye(3), atol=1e-12)
    # |com| <= 5√3 and |t| <= 5√3: rounding of ~1e-15 m; 1e-12 m is a wide margin.
    assert np.allclose(moved.com, rotation @ p.com + translation, rtol=0.0, atol=1e-12)


@settings(deadline=None)
@given(bodies, bodies, bodies)
def test_composition_is_associative(a, b, c):
    left, right = (a + b) + c, a + (b + c)
    # Both orders are exact formulas evaluated differently; mass ratios up to 1e3 and offsets up to 10 m
    # leave rounding only (measured max 6.6e-16 relative over 2000 examples).
    assert left.isclose(right, rtol=1e-12, atol=1e-12)
    assert left.isclose(sum([a, b, c]), rtol=1e-12, atol=1e-12)


@settings(deadline=None)
@given(bodies, directions, vectors)
def test_the_centre_of_mass_minimises_the_moment(p, axis, point):
    # Parallel-axis theorem: I_line(point) = I_line(com) + m d², d the distance between the lines.
    through_com = p.moment_about(axis)
    through_point = p.moment_about(axis, point)
    e = axis / np.linalg.norm(axis)
    offset = p.com - point
    distance_sq = offset @ offset - (offset @ e) ** 2
    # Sums of terms each rounded to ~1e-16 of their size (measured max 5.4e-16 of this scale).
    tolerance = 1e-12 * (scale_of(p) + p.mass * (offset @ offset))
    assert through_point >= through_com - tolerance
    assert abs(through_point - (through_com + p.mass * distance_sq)) <= tolerance
    # The whole shift is positive semi-definite: no axis has a smaller moment away from the com.
    shift = p.inertia_about(point) - p.inertia
    assert np.linalg.eigvalsh(shift)[0] >= -tolerance
