"""MJCF ``<mesh>`` assets: triangle meshes from STL and OBJ files (read by trimesh), MuJoCo's binary MSH files, or
vertices and faces written in the model; ``scale`` and ``refpos`` applied as MuJoCo applies them.

A file is found in ``compiler meshdir`` (else ``assetdir``, else the model's directory), relative to the model's
directory; a relative file name may not climb out of that directory. Coordinates are single precision in every
source MuJoCo reads (STL and MSH store floats, its OBJ reader and the XML's ``vertex`` parse floats), so they are
rounded to float32 here too, and a model weighs to the last digit what it weighs in MuJoCo. Vertices without faces
stand for their convex hull. A negative ``scale`` product mirrors the mesh, and the faces are turned to keep
pointing out.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..description import MeshDescription
from .attributes import numbers
from .mesh_inertia import convex_hull_faces
from .xml import Node

__all__ = ["MESH_ATTRIBUTES", "MESH_COSMETIC", "read_mesh", "read_mesh_file"]

MESH_ATTRIBUTES = {"name", "class", "file", "vertex", "face", "scale", "refpos", "refquat", "inertia"}
# what only drawing or collision uses: read past
MESH_COSMETIC = {"normal", "texcoord", "facetexcoord", "smoothnormal", "maxhullvert", "content_type", "material"}
_INERTIA = ("legacy", "exact", "convex", "shell")


def _read_msh(node: Node, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """MuJoCo's MSH: four int32 counts (vertices, normals, texture coordinates, faces), then float32 vertices,
    normals and texture coordinates, then int32 faces."""
    data = path.read_bytes()
    if len(data) < 16:
        raise node.error(f"{path} is not an MSH file: {len(data)} bytes, shorter than its header")
    nvert, nnormal, ntexcoord, nface = (int(n) for n in np.frombuffer(data, np.int32, 4))
    floats = 3 * nvert + 3 * nnormal + 2 * ntexcoord
    if min(nvert, nnormal, ntexcoord, nface) < 0 or len(data) != 16 + 4 * (floats + 3 * nface):
        raise node.error(f"{path} is not an MSH file: its size does not match the counts in its header")
    vertices = np.frombuffer(data, np.float32, 3 * nvert, 16).reshape(-1, 3)
    faces = np.frombuffer(data, np.int32, 3 * nface, 16 + 4 * floats).reshape(-1, 3)
    return vertices.astype(np.float64), faces.astype(np.int64)


def _read_with_trimesh(node: Node, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """An STL (binary or text) or OBJ file's vertices and triangles. STL goes straight to trimesh's parser: building
    a ``Trimesh`` costs twenty times the parse, 2.5 ms a file, which the dog's 162 bones would pay."""
    try:
        import trimesh
    except ImportError:
        raise node.error(f"reading {path.suffix} meshes needs trimesh: pip install 'tumble[mesh]'") from None
    try:
        if path.suffix.lower() == ".stl":
            with path.open("rb") as file:
                mesh = trimesh.exchange.stl.load_stl(file)
            return np.asarray(mesh["vertices"], dtype=np.float64), np.asarray(mesh["faces"], dtype=np.int64)
        mesh = trimesh.load_mesh(path, file_type="obj", process=False)
    except Exception as error:  # trimesh raises whatever its parsers raise
        raise node.error(f"cannot read the mesh file {path}: {error}") from None
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


def read_mesh_file(node: Node, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The vertices and triangles of an STL, OBJ or MSH file that ``node`` names, checked."""
    if path.suffix.lower() not in (".stl", ".obj", ".msh"):
        raise node.error(f"file={path.name!r}: a mesh file is .stl, .obj or .msh")
    vertices, faces = (_read_msh if path.suffix.lower() == ".msh" else _read_with_trimesh)(node, path)
    if len(vertices) < 4 or not np.all(np.isfinite(vertices)):
        raise node.error(f"{path}: a mesh needs at least four finite vertices, found {len(vertices)}")
    if np.any((faces < 0) | (faces >= len(vertices))):
        raise node.error(f"{path}: faces index vertices outside 0..{len(vertices) - 1}")
    return vertices, faces


def _file_path(node: Node, name: str, directory: Path, strip: bool) -> Path:
    file = Path(name)
    if strip:
        file = Path(file.name)
    path = (directory / file).resolve()
    if not file.is_absolute() and not path.is_relative_to(directory.resolve()):
        raise node.error(f"file={name!r} leaves the mesh directory {directory}")
    if not path.is_file():
        raise node.error(f"file={name!r}: no such mesh file ({path})")
    return path


def _written(node: Node, attrib: dict[str, str]) -> tuple[np.ndarray, np.ndarray | None]:
    """Vertices and faces written in the model."""
    values = numbers(node, attrib, "vertex", None)
    if values.size < 12 or values.size % 3:
        raise node.error(f"vertex holds {values.size} numbers: at least four vertices, three finite numbers each")
    vertices = values.reshape(-1, 3)
    text = attrib.get("face")
    if text is None:
        return vertices, None
    try:
        faces = np.array([int(word) for word in text.split()], dtype=np.int64)
    except ValueError:
        raise node.error(f"face={text[:40]!r} is not a list of integer vertex indices") from None
    if faces.size == 0 or faces.size % 3:
        raise node.error(f"face holds {faces.size} numbers: triangles of three vertex indices")
    faces = faces.reshape(-1, 3)
    if np.any((faces < 0) | (faces >= len(vertices))):
        raise node.error(f"face indexes vertices outside 0..{len(vertices) - 1}")
    return vertices, faces


def read_mesh(node: Node, attrib: dict[str, str], directory: Path, strip: bool) -> MeshDescription:
    """The mesh of one ``<mesh>`` (its attributes resolved against the default classes) as a description."""
    if ("file" in attrib) == ("vertex" in attrib):
        raise node.error("a mesh takes its vertices from a file or from vertex=..., one of the two")
    if "file" in attrib:
        path = _file_path(node, attrib["file"], directory, strip)
        vertices, faces = read_mesh_file(node, path)
        source, name = str(path), attrib.get("name", path.stem)
    else:
        vertices, faces = _written(node, attrib)
        source, name = node.file, attrib.get("name")
        if not name:
            raise node.error("a mesh written in the model needs a name")
    vertices = vertices.astype(np.float32).astype(np.float64)
    refpos, scale = numbers(node, attrib, "refpos", 3), numbers(node, attrib, "scale", 3)
    if refpos is not None:
        vertices = vertices - refpos
    if scale is not None:
        vertices = vertices * scale
    if faces is None:
        try:
            faces = convex_hull_faces(vertices)
        except ValueError as error:
            raise node.error(f"mesh {name!r}: {error}") from None
    elif scale is not None and np.prod(scale) < 0.0:
        faces = faces[:, ::-1]
    inertia = attrib.get("inertia", "legacy")
    if inertia not in _INERTIA:
        raise node.error(f"inertia={inertia!r} must be one of {', '.join(_INERTIA)}")
    return MeshDescription(name, vertices, np.ascontiguousarray(faces), inertia, source, node.line)
