"""Pack a world's shapes into the structure-of-arrays the collision kernels read (:class:`GeometryArrays`).

Hulls and meshes share one vertex array, addressed per shape by a start and a count. Convex hulls also get
polygon faces (coplanar triangles merged, each face an ordered counter-clockwise loop of vertex indices seen
from outside) and their unique edges, which the separating-axis tests and face clipping need. Triangle
meshes keep their triangles as faces.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import portable
from ..shapes import ConvexHull, Shape, ShapeType, TriMesh

__all__ = ["GeometryArrays", "pack_geometry", "hull_polygons"]


class GeometryArrays(NamedTuple):
    """Every shape of a world, for the kernels.

    Attributes:
        shape_type: (n,) int64 ShapeType codes.
        shape_params: (n, 4) float64, per-type sizes (``Shape.params``).
        shape_body: (n,) int64 body row.
        shape_pos_local: (n, 3) float64 [m], shape origin relative to the body COM, body frame.
        shape_quat_local: (n, 4) float64, shape orientation in the body frame.
        shape_aabb_center_local: (n, 3) float64 [m], centre of the shape's bounds, body frame (from the COM).
        shape_aabb_half_local: (n, 3) float64 [m], half-widths of a box around the shape, body frame axes
            (``inf`` for planes).
        vertex_local: (V, 3) float64 [m], hull and mesh vertices in their shape frame.
        shape_vertex_start, shape_vertex_count: (n,) int64 ranges into ``vertex_local``.
        face_loop: (L,) int64 global vertex indices; face ``f`` is the ``face_loop_count[f]`` entries from
            ``face_loop_start[f]``, counter-clockwise seen from outside.
        face_loop_start, face_loop_count: (F,) int64.
        face_normal: (F, 3) float64, outward unit normals in the shape frame.
        face_offset: (F,) float64 [m], ``n · x`` of the face plane in the shape frame.
        shape_face_start, shape_face_count: (n,) int64 ranges into the face arrays.
        edge_vertex: (E, 2) int64 global vertex indices of hull edges (each undirected edge once).
        shape_edge_start, shape_edge_count: (n,) int64 ranges into ``edge_vertex``.
    """

    shape_type: np.ndarray
    shape_params: np.ndarray
    shape_body: np.ndarray
    shape_pos_local: np.ndarray
    shape_quat_local: np.ndarray
    shape_aabb_center_local: np.ndarray
    shape_aabb_half_local: np.ndarray
    vertex_local: np.ndarray
    shape_vertex_start: np.ndarray
    shape_vertex_count: np.ndarray
    face_loop: np.ndarray
    face_loop_start: np.ndarray
    face_loop_count: np.ndarray
    face_normal: np.ndarray
    face_offset: np.ndarray
    shape_face_start: np.ndarray
    shape_face_count: np.ndarray
    edge_vertex: np.ndarray
    shape_edge_start: np.ndarray
    shape_edge_count: np.ndarray


def hull_polygons(vertices: np.ndarray, triangles: np.ndarray) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """Merge the coplanar triangles of a convex hull into polygons.

    Returns:
        ``(loops, normals, offsets)``: one counter-clockwise vertex loop per face, its outward unit normal and
        its plane offset ``n · x``.
    """
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    normals = np.cross(b - a, c - a)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    offsets = portable.dot(normals, a)
    scale = max(float(np.ptp(vertices, axis=0).max()), 1e-12)
    unassigned = list(range(len(triangles)))
    loops, face_normals, face_offsets = [], [], []
    while unassigned:
        t = unassigned[0]
        # Triangles of one hull face share its plane (Qhull triangulates facets); 1e-9 of the size tolerates
        # the round-off of the triangulation.
        group = [
            u
            for u in unassigned
            if portable.dot(normals[u], normals[t]) > 1.0 - 1e-9 and abs(offsets[u] - offsets[t]) <= 1e-9 * scale
        ]
        unassigned = [u for u in unassigned if u not in group]
        loops.append(_boundary_loop(triangles[group]))
        mean = normals[group].mean(axis=0)
        mean /= portable.norm(mean)
        face_normals.append(mean)
        face_offsets.append(float(np.mean([portable.dot(mean, vertices[v]) for v in loops[-1]])))
    return loops, np.array(face_normals), np.array(face_offsets)


def _boundary_loop(triangles: np.ndarray) -> np.ndarray:
    """The outer loop of a fan of consistently wound triangles: directed edges used once, chained."""
    directed = [(int(t[i]), int(t[(i + 1) % 3])) for t in triangles for i in range(3)]
    inner = set(directed) & {(j, i) for i, j in directed}
    following = {i: j for i, j in directed if (i, j) not in inner}
    start = next(iter(following))
    loop, v = [start], following[start]
    while v != start:
        loop.append(v)
        v = following[v]
    return np.array(loop, dtype=np.int64)


def _local_bounds(shapes: list[Shape]) -> tuple[np.ndarray, np.ndarray]:
    """``(lo, hi)``, each (n, 3): every shape's ``local_bounds``, those of the primitives worked out by class in one
    vectorised call (a world of 100 000 boxes would otherwise make 100 000 calls)."""
    n = len(shapes)
    lo, hi = np.zeros((n, 3)), np.zeros((n, 3))
    by_class: dict[type, list[int]] = {}
    for k, shape in enumerate(shapes):
        by_class.setdefault(type(shape), []).append(k)
    for cls, rows in by_class.items():
        if hasattr(cls, "_half_widths"):
            half = cls._half_widths(np.array([shapes[k].params for k in rows], np.float64).reshape(-1, 4))
            lo[rows], hi[rows] = -half, half
        else:
            for k in rows:
                lo[k], hi[k] = shapes[k].local_bounds()
    return lo, hi


def pack_geometry(shapes: list[Shape], shape_body, pos_local: np.ndarray, quat_local: np.ndarray) -> GeometryArrays:
    """Pack shapes placed in their bodies (``pos_local`` relative to the body COM) into :class:`GeometryArrays`.

    A hull or mesh object used by many shapes is packed once: its shapes share its vertex, face and edge ranges.
    """
    from ..rotation import quat_rotate, quat_to_matrix

    n = len(shapes)
    pos_local = np.asarray(pos_local, dtype=np.float64).reshape(n, 3)
    quat_local = np.asarray(quat_local, dtype=np.float64).reshape(n, 4)
    vertex_blocks, loops, normals, offsets, edges = [], [], [], [], []
    v_start, v_count = np.zeros(n, np.int64), np.zeros(n, np.int64)
    f_start, f_count = np.zeros(n, np.int64), np.zeros(n, np.int64)
    e_start, e_count = np.zeros(n, np.int64), np.zeros(n, np.int64)
    packed: dict[int, int] = {}  # id of a hull or mesh -> the first shape that packed it
    v_total = 0
    for k, shape in enumerate(shapes):
        if not isinstance(shape, (ConvexHull, TriMesh)):
            v_start[k], f_start[k], e_start[k] = v_total, len(loops), len(edges)
            continue
        first = packed.setdefault(id(shape), k)
        if first != k:
            v_start[k], v_count[k], f_start[k] = v_start[first], v_count[first], f_start[first]
            f_count[k], e_start[k], e_count[k] = f_count[first], e_start[first], e_count[first]
            continue
        v_start[k], f_start[k], e_start[k] = v_total, len(loops), len(edges)
        vertices = np.asarray(shape.vertices, dtype=np.float64)
        vertex_blocks.append(vertices)
        v_count[k] = len(vertices)
        if isinstance(shape, ConvexHull):
            shape_loops, shape_normals, shape_offsets = hull_polygons(vertices, np.asarray(shape.faces))
            undirected = {
                tuple(sorted((int(f[i]), int(f[(i + 1) % len(f)])))) for f in shape_loops for i in range(len(f))
            }
            edges.extend((a + v_total, b + v_total) for a, b in sorted(undirected))
        else:
            faces = np.asarray(shape.faces, dtype=np.int64)
            shape_loops = list(faces)
            p0, p1, p2 = (vertices[faces[:, i]] for i in range(3))
            shape_normals = np.cross(p1 - p0, p2 - p0)
            lengths = np.linalg.norm(shape_normals, axis=1, keepdims=True)
            shape_normals = shape_normals / np.where(lengths > 0.0, lengths, 1.0)
            shape_offsets = portable.dot(shape_normals, p0)
        loops.extend(loop + v_total for loop in shape_loops)
        normals.extend(shape_normals)
        offsets.extend(shape_offsets)
        v_total += len(vertices)
        f_count[k], e_count[k] = len(loops) - f_start[k], len(edges) - e_start[k]
    # Bounds in the body frame: each shape's local box turned by its local rotation (centre R c, half-widths |R| h).
    lo, hi = _local_bounds(shapes)
    # A plane is unbounded: its box is centred on its origin, infinite.
    bounded = np.array([shape.type != ShapeType.PLANE for shape in shapes], bool).reshape(n)
    lo, hi = lo[bounded], hi[bounded]
    centers, halves = pos_local.copy(), np.full((n, 3), np.inf)
    centers[bounded] += quat_rotate(quat_local[bounded], 0.5 * (lo + hi))
    halves[bounded] = portable.matvec(np.abs(quat_to_matrix(quat_local[bounded])), 0.5 * (hi - lo))
    loop_counts = np.array([len(lp) for lp in loops], dtype=np.int64)
    loop_starts = (
        np.concatenate([[0], np.cumsum(loop_counts)[:-1]]).astype(np.int64) if loops else np.zeros(0, np.int64)
    )
    return GeometryArrays(
        shape_type=np.array([int(s.type) for s in shapes], dtype=np.int64),
        shape_params=np.array([s.params for s in shapes], dtype=np.float64).reshape(n, 4),
        shape_body=np.asarray(shape_body, dtype=np.int64).reshape(n),
        shape_pos_local=pos_local,
        shape_quat_local=quat_local,
        shape_aabb_center_local=centers,
        shape_aabb_half_local=halves,
        vertex_local=np.concatenate(vertex_blocks) if vertex_blocks else np.zeros((0, 3)),
        shape_vertex_start=v_start,
        shape_vertex_count=v_count,
        face_loop=np.concatenate(loops).astype(np.int64) if loops else np.zeros(0, np.int64),
        face_loop_start=loop_starts,
        face_loop_count=loop_counts,
        face_normal=np.array(normals, dtype=np.float64).reshape(-1, 3),
        face_offset=np.array(offsets, dtype=np.float64),
        shape_face_start=f_start,
        shape_face_count=f_count,
        edge_vertex=np.array(edges, dtype=np.int64).reshape(-1, 2),
        shape_edge_start=e_start,
        shape_edge_count=e_count,
    )
