"""A mesh geom's volume, centre of mass and inertia, as MuJoCo's compiler computes them (``<mesh inertia=...>``).

MuJoCo splits the mesh into pyramids, one per face. The first pass puts their apex at the area-weighted centroid of
the faces and gives the centre of mass; the second puts it at that centre and sums each pyramid's second moment,
``∫ x xᵀ dV = V/20 (D Dᵀ + E Eᵀ + F Fᵀ + S Sᵀ)`` for a face ``(D, E, F)`` seen from the apex and ``S = D + E + F``
(Tonon 2004, J. Math. Stat. 1(1); a triangle's area moment is the same with ``A/12``). The modes:

- ``"exact"``: signed pyramid volumes, the divergence theorem: exact for any closed, consistently wound mesh
  (``tumble.mass.mesh`` gives the same to round-off);
- ``"legacy"`` (MuJoCo's default): each pyramid's volume taken positive, which counts twice what a non-convex
  mesh's apex sees from behind: MuJoCo's historic result, kept so that models weigh what their authors saw;
- ``"convex"``: the exact solid of the mesh's convex hull;
- ``"shell"``: the surface carries the mass (``mass = density × area``), its centre the faces' centroid.

Faces whose cross product is under ``1e-15`` (MuJoCo's ``mjMINVAL``) count for nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from ... import portable
from ...mass import MassProperties
from ...rotation import matrix_to_quat

__all__ = ["MeshInertia", "convex_hull_faces", "mesh_inertia"]

_MIN = 1e-15  # MuJoCo's mjMINVAL
# MuJoCo's tolerance on the principal moments' triangle inequality A + B >= C
_INEQUALITY_RTOL, _INEQUALITY_ATOL = 1e-6, 1e-9


@dataclass(frozen=True)
class MeshInertia:
    """A mesh's measure (volume [m³], area [m²] for a shell), centre and inertia per unit density, in its frame."""

    measure: float
    com: np.ndarray  # (3,)
    inertia: np.ndarray  # (3, 3) about ``com`` [m⁵] (a shell's [m⁴])

    def mass_properties(self, mass: float) -> MassProperties:
        """The geom's mass properties in the mesh frame for a total ``mass``."""
        return MassProperties(mass, self.com, self.inertia * (mass / self.measure))

    def principal_frame(self) -> tuple[np.ndarray, np.ndarray]:
        """``(quat, box)``: the principal axes (largest moment first, a proper rotation) and the half sizes of the
        uniform box with the same measure and moments: MuJoCo fits a primitive geom given a mesh to that box."""
        moments, axes = portable.eigh(self.inertia)
        moments, axes = moments[::-1], axes[:, ::-1]
        if portable.det(axes) < 0.0:
            axes[:, 2] = -axes[:, 2]
        a, b, c = moments / self.measure
        box = 0.5 * np.sqrt(np.maximum(6.0 * np.array([b + c - a, a + c - b, a + b - c]), 0.0))
        return matrix_to_quat(axes), box


def convex_hull_faces(vertices: np.ndarray) -> np.ndarray:
    """The triangles of the convex hull of ``vertices``, wound counter-clockwise seen from outside.

    Raises:
        ValueError: fewer than four points, or points that span no volume (flat, on a line).
    """
    try:
        hull = ConvexHull(vertices)
    except (QhullError, ValueError) as error:
        raise ValueError(f"its vertices span no volume: no convex hull ({str(error).splitlines()[0]})") from None
    faces = hull.simplices.copy()
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    inward = portable.dot(np.cross(b - a, c - a), hull.equations[:, :3]) < 0.0
    faces[inward] = faces[inward][:, ::-1]
    return faces


def _triangles(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each triangle's area (zero under MuJoCo's threshold), unit normal and centroid."""
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(cross, axis=1)
    counted = length >= _MIN
    normal = np.divide(cross, length[:, None], out=np.zeros_like(cross), where=counted[:, None])
    return np.where(counted, 0.5 * length, 0.0), normal, corners.sum(axis=1) / 3.0


def _pyramids(mode: str, area: np.ndarray, normal: np.ndarray, centre: np.ndarray, apex: np.ndarray) -> np.ndarray:
    """Each face's share: its pyramid's volume from ``apex`` (positive in legacy mode), or its area for a shell."""
    if mode == "shell":
        return area
    volume = portable.dot(centre - apex, normal) * area / 3.0
    return np.abs(volume) if mode == "legacy" else volume


def _inconsistent_edge(faces: np.ndarray, area: np.ndarray) -> tuple[int, int] | None:
    """A directed edge walked by two faces (their windings disagree), among faces that are not slivers."""
    kept = faces[area > np.sqrt(_MIN)]
    edges = np.stack([kept, np.roll(kept, -1, axis=1)], axis=2).reshape(-1, 2)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    twice = unique[counts > 1]
    return (int(twice[0, 0]), int(twice[0, 1])) if twice.size else None


def mesh_inertia(vertices: np.ndarray, faces: np.ndarray, mode: str) -> MeshInertia:
    """The measure, centre and inertia per unit density of a mesh in ``mode`` (module docstring).

    Raises:
        ValueError: what is wrong (the caller names the mesh, file and line): no area, no or negative volume
            (misoriented faces), an inconsistent winding in exact mode, or moments that break the triangle inequality.
    """
    if mode == "convex":
        faces = convex_hull_faces(vertices)
    corners = vertices[faces]
    area, normal, centre = _triangles(corners)
    total_area = float(area.sum())
    if total_area < _MIN:
        raise ValueError(f"its surface area is too small ({total_area:.3g} m²)")
    if mode == "exact" and (edge := _inconsistent_edge(faces, area)) is not None:
        raise ValueError(f"its faces are inconsistently wound (two faces walk the edge {edge[0]} -> {edge[1]})")
    face_centroid = portable.weighted_sum(area, centre) / total_area
    share = _pyramids(mode, area, normal, centre, face_centroid)
    measure = float(share.sum())
    if measure < _MIN:
        if measure < 0.0:
            raise ValueError(f"its volume is negative ({measure:.3g} m³): the faces point inwards")
        raise ValueError(f"its volume is too small ({measure:.3g} m³); inertia='shell' spreads the mass on the surface")
    com = portable.weighted_sum(share, 0.75 * centre + 0.25 * face_centroid) / measure
    # second pass: pyramids from the centre of mass (their volumes, recomputed, give the measure MuJoCo keeps)
    corners = corners - com
    area, normal, centre = _triangles(corners)
    share = _pyramids(mode, area, normal, centre, np.zeros(3))
    s = corners.sum(axis=1)
    weighted = corners * share[:, None, None]
    rows = weighted.reshape(-1, 3)
    second = portable.outer_sum(np.ones(len(rows)), rows, corners.reshape(-1, 3)) + portable.outer_sum(share, s, s)
    second /= 12.0 if mode == "shell" else 20.0
    inertia = np.trace(second) * np.eye(3) - second
    moments = portable.eigh(inertia)[0]
    if moments[0] <= 0.0:
        raise ValueError(f"its principal moments {moments.tolist()} are not all positive")
    a, b, c = moments
    if a + b < c * (1.0 - _INEQUALITY_RTOL) - _INEQUALITY_ATOL:
        raise ValueError(f"its principal moments {moments.tolist()} violate A + B >= C")
    return MeshInertia(float(share.sum()), com, 0.5 * (inertia + inertia.T))
