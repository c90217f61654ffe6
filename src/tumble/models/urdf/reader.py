"""A URDF file into a :class:`~tumble.models.description.ModelDescription`, the same plain data the MJCF reader makes.

URDF (ROS's robot description; https://wiki.ros.org/urdf/XML) names links and the joints between them. Each joint
places its child link: the child's frame is the joint's ``origin`` (``xyz``, fixed-axis ``rpy``: R = Rz(yaw)
Ry(pitch) Rx(roll)) in the parent's frame, and the joint's ``axis`` is in that frame. So a link becomes a body at
its joint's origin, its joint at the body's own origin; a ``fixed`` joint leaves the body jointless, which the
builders weld to its parent (MuJoCo's URDF import fuses such links too). The one link that is no joint's child is
the root: welded to the world, or free with ``floating_base=True``. Mass properties come from ``inertial`` (the
tensor about the centre of mass in the ``origin`` frame), collision shapes from ``collision`` (box, cylinder,
sphere, mesh); ``visual`` and materials are drawing only and read past.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np

from ... import portable
from ...mass import MassProperties
from ...rotation import quat_from_axis_angle, quat_multiply
from ..description import BodyDescription, GeomDescription, JointDescription, MeshDescription, ModelDescription
from ..mjcf import MJCFError, MJCFWarning
from ..mjcf.attributes import numbers
from ..mjcf.mesh_inertia import convex_hull_faces
from ..mjcf.meshes import read_mesh_file
from ..mjcf.xml import Node, parse_xml

__all__ = ["URDFError", "URDFWarning", "read_urdf"]

# "spherical" is pybullet's (and MuJoCo's URDF import's) ball joint, beyond the URDF standard
_JOINT_TYPES = {"revolute": "hinge", "continuous": "hinge", "prismatic": "slide", "fixed": None, "floating": "free",
                "spherical": "ball"}  # fmt: skip
_FREE = ("free", np.zeros(3), np.zeros(3))


class URDFError(MJCFError):
    """A URDF file that cannot be loaded; the message names the file, the element and its line. (A subclass of
    :class:`~tumble.models.mjcf.MJCFError`, which every model file's error is.)"""


class URDFWarning(MJCFWarning):
    """Something in a URDF file that tumble reads past or does not simulate (a subclass of ``MJCFWarning``)."""


def _numbers(node: Node, name: str, count: int, default=None) -> np.ndarray:
    """``count`` finite numbers of ``name``, else ``default``; refused by name when missing without one."""
    if name not in node.attrib and default is None:
        raise node.error(f"needs {name}= ({count} numbers)")
    return numbers(node, node.attrib, name, count, default)


def _number(node: Node, name: str, default: float | None = None) -> float:
    return float(_numbers(node, name, 1, None if default is None else [default])[0])


def _children(node: Node, tag: str) -> list[Node]:
    return [child for child in node.children if child.tag == tag]


def _child(node: Node, tag: str) -> Node | None:
    """The one ``<tag>`` child of ``node``, or None; two are refused."""
    found = _children(node, tag)
    if len(found) > 1:
        raise found[1].error(f"a <{node.tag}> takes one <{tag}>")
    return found[0] if found else None


def _quat_from_rpy(rpy: np.ndarray) -> np.ndarray:
    """URDF's fixed-axis roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    qx = quat_from_axis_angle((1.0, 0.0, 0.0), rpy[0])
    qy = quat_from_axis_angle((0.0, 1.0, 0.0), rpy[1])
    qz = quat_from_axis_angle((0.0, 0.0, 1.0), rpy[2])
    return quat_multiply(qz, quat_multiply(qy, qx))


def _origin(node: Node) -> tuple[np.ndarray, np.ndarray]:
    """The pose of an element's ``<origin>`` (identity when it has none)."""
    origin = _child(node, "origin")
    if origin is None:
        return np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])
    xyz = _numbers(origin, "xyz", 3, [0.0, 0.0, 0.0])
    return xyz, _quat_from_rpy(_numbers(origin, "rpy", 3, [0.0, 0.0, 0.0]))


def _mass_properties(link: Node) -> MassProperties | None:
    """``<inertial>``: mass and the inertia tensor about the centre of mass, axes of its ``origin`` frame."""
    inertial = _child(link, "inertial")
    if inertial is None:
        return None
    mass_node, inertia_node = _child(inertial, "mass"), _child(inertial, "inertia")
    if mass_node is None:
        raise inertial.error(f"link {link.attrib.get('name')!r}: an <inertial> needs a <mass>")
    mass = _number(mass_node, "value")
    if mass < 0.0:
        raise mass_node.error(f"link {link.attrib.get('name')!r}: value={mass!r} must be >= 0")
    if mass == 0.0:
        return None
    if inertia_node is None:
        raise inertial.error(f"link {link.attrib.get('name')!r}: an <inertial> needs an <inertia>")
    xx, xy, xz, yy, yz, zz = (_number(inertia_node, key) for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
    tensor = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    com, quat = _origin(inertial)
    try:
        local = MassProperties(mass, np.zeros(3), tensor)
    except ValueError as error:
        raise inertia_node.error(f"link {link.attrib.get('name')!r}: a non-physical inertia: {error}") from None
    # MassProperties forgives 1 % of the trace (round-off of meshes); a tensor written by hand gets the last digits'
    # worth, as MuJoCo refuses these files (pybullet_data's mini_cheetah and TwoJointRobot fail it by 0.4-3 %)
    moments = portable.eigh(tensor)[0]
    if moments[0] + moments[1] < moments[2] - 1e-6 * moments.sum():
        raise inertia_node.error(f"link {link.attrib.get('name')!r}: a non-physical inertia: its principal moments "
                                 f"{np.array2string(moments, precision=6)} fail the triangle inequality "
                                 f"I1 + I2 >= I3 (by {moments[2] - moments[0] - moments[1]:.3g} kg m²)")  # fmt: skip
    return local.transformed(rotation=quat, translation=com)


def _package_path(node: Node, name: str, base: Path, package_dirs: tuple[Path, ...]) -> Path:
    """A mesh's file: ``package://pkg/rest`` looked up as ``dir/pkg/rest``, then ``dir/rest``, in each of
    ``package_dirs`` and then the URDF file's folder and its parents; ``file://`` absolute; else relative to the
    URDF file's folder."""
    if name.startswith("package://"):
        package, _, rest = name[len("package://") :].partition("/")
        roots = [*package_dirs, base, *base.parents]
        candidates = [root / package / rest for root in roots] + [root / rest for root in roots]
        for path in candidates:
            if path.is_file():
                return path
        searched = ", ".join(str(d) for d in [*package_dirs, base])
        raise node.error(f"filename={name!r}: package {package!r} not found (package_dirs and the file's folder "
                         f"and its parents searched: {searched})")  # fmt: skip
    path = Path(name[len("file://") :]) if name.startswith("file://") else base / name
    if not path.is_file():
        raise node.error(f"filename={name!r}: no such mesh file ({path})")
    return path


def _geometry(link: Node, collision: Node, index: int, base: Path, package_dirs, meshes) -> GeomDescription:
    geometry = _child(collision, "geometry")
    shapes = [] if geometry is None else geometry.children
    if len(shapes) != 1:
        raise (geometry or collision).error("a <collision> needs a <geometry> with one shape")
    shape = shapes[0]
    pos, quat = _origin(collision)
    size, mesh = np.zeros(3), None
    if shape.tag == "box":
        size = 0.5 * _numbers(shape, "size", 3)
    elif shape.tag == "sphere":
        size[0] = _number(shape, "radius")
    elif shape.tag in ("cylinder", "capsule"):  # along z; MuJoCo's size is (radius, half length)
        size[:2] = _number(shape, "radius"), 0.5 * _number(shape, "length")
    elif shape.tag == "mesh":
        name = shape.attrib.get("filename")
        if not name:
            raise shape.error("a <mesh> needs a filename")
        path = _package_path(shape, name, base, package_dirs)
        scale = _numbers(shape, "scale", 3, [1.0, 1.0, 1.0])
        mesh = f"{link.attrib['name']}/collision{index}"
        meshes[mesh] = _mesh(shape, path, scale, mesh)
    else:
        raise shape.error(f"<{shape.tag}> is not a URDF shape: box, cylinder, sphere or mesh")
    if np.any(size[: {"box": 3, "sphere": 1}.get(shape.tag, 2)] <= 0.0) and mesh is None:
        raise shape.error("a shape's sizes must be > 0")
    friction = np.array([1.0, 0.005, 0.0001])  # MuJoCo's defaults, as its URDF import gives every geom
    return GeomDescription(collision.attrib.get("name"), shape.tag, size, pos, quat, 0, 1, 1, friction, shape.line,
                           mesh)  # fmt: skip


def _mesh(node: Node, path: Path, scale: np.ndarray, name: str) -> MeshDescription:
    vertices, faces = read_mesh_file(node, path)
    vertices = vertices.astype(np.float32).astype(np.float64) * scale
    if np.prod(scale) < 0.0:
        faces = faces[:, ::-1]
    if len(faces) == 0:
        faces = convex_hull_faces(vertices)
    return MeshDescription(name, vertices, np.ascontiguousarray(faces), "legacy", str(path), node.line)


def _joint(node: Node, links: dict[str, Node]) -> tuple[str, str, JointDescription | None, np.ndarray, np.ndarray]:
    """``(parent, child, joint or None for fixed, origin position, origin quaternion)`` of one ``<joint>``."""
    name, kind = node.attrib.get("name"), node.attrib.get("type")
    if not name:
        raise node.error("a <joint> needs a name")
    if kind == "planar":
        raise node.error(f"joint {name!r}: type='planar' is not supported (a World's PlanarJoint is the motion in a "
                         "plane through a point, which URDF's planar joint does not fix); use two prismatic joints "
                         "and a revolute")  # fmt: skip
    if kind not in _JOINT_TYPES:
        raise node.error(f"joint {name!r}: type={kind!r} must be one of {', '.join(_JOINT_TYPES)}")
    ends = []
    for tag in ("parent", "child"):
        element = _child(node, tag)
        if element is None or not element.attrib.get("link"):
            raise node.error(f"joint {name!r} needs a <{tag} link=...>")
        if element.attrib["link"] not in links:
            raise element.error(f"joint {name!r}: no link named {element.attrib['link']!r}")
        ends.append(element.attrib["link"])
    pos, quat = _origin(node)
    if _JOINT_TYPES[kind] in (None, "free", "ball"):
        description = None if kind == "fixed" else JointDescription(name, _JOINT_TYPES[kind], *_FREE[1:], None, 0.0,
                                                                     0.0, 0.0, 0.0, 0.0, 0.0, node.line)  # fmt: skip
        return ends[0], ends[1], description, pos, quat
    axis_node = _child(node, "axis")
    axis = np.array([1.0, 0.0, 0.0]) if axis_node is None else _numbers(axis_node, "xyz", 3)
    norm = float(portable.norm(axis))
    if norm < 1e-12:
        raise axis_node.error(f"joint {name!r}: axis xyz={axis_node.attrib['xyz']!r} has no direction")
    joint_range = None
    limit = _child(node, "limit")
    if kind != "continuous" and limit is not None:
        lower, upper = _number(limit, "lower", 0.0), _number(limit, "upper", 0.0)
        if lower > upper:
            raise limit.error(f"joint {name!r}: lower={lower!r} is above upper={upper!r}")
        joint_range = (lower, upper) if lower < upper else None  # MuJoCo too leaves lower == upper unlimited
    dynamics = _child(node, "dynamics")
    damping = 0.0 if dynamics is None else _number(dynamics, "damping", 0.0)
    friction = 0.0 if dynamics is None else _number(dynamics, "friction", 0.0)
    if damping < 0.0 or friction < 0.0:
        raise dynamics.error(f"joint {name!r}: damping and friction must be >= 0")
    if friction > 0.0:
        warnings.warn(f"{dynamics.where()}: joint {name!r}: friction={friction!r} (dry friction) is not simulated "
                      "(yet); ignored", URDFWarning, stacklevel=4)  # fmt: skip
    if _child(node, "mimic") is not None:
        warnings.warn(f"{node.where()}: joint {name!r}: <mimic> is not simulated (yet); the joint moves freely",
                      URDFWarning, stacklevel=4)  # fmt: skip
    joint = JointDescription(name, _JOINT_TYPES[kind], np.zeros(3), axis / norm, joint_range, 0.0, 0.0, 0.0, damping,
                             0.0, friction, node.line)  # fmt: skip
    return ends[0], ends[1], joint, pos, quat


def read_urdf(path: str | os.PathLike, *, package_dirs=(), floating_base: bool = False) -> ModelDescription:
    """The description of the URDF file at ``path``.

    Raises:
        URDFError: malformed XML, a link or joint that cannot be read, a tree that is not one (no root, several
            roots, a link with two parents, a joint naming a missing link), a missing mesh, a non-physical inertia;
            the message names the file, the element and its line.
    """
    file = Path(path)
    if not file.is_file():
        raise URDFError(f"{file}: no such URDF file")
    # a trailing NUL (pybullet_data's humanoid.urdf ends in one) is past the document: MuJoCo reads it too
    root = parse_xml(file.read_bytes().rstrip(b"\x00"), str(file), "robot", URDFError)
    if isinstance(package_dirs, (str, os.PathLike)):
        package_dirs = (package_dirs,)
    package_dirs = tuple(Path(d) for d in package_dirs)
    base = file.resolve().parent
    links: dict[str, Node] = {}
    for link in _children(root, "link"):
        name = link.attrib.get("name")
        if not name:
            raise link.error("a <link> needs a name")
        if name in links:
            raise link.error(f"link {name!r} is defined twice (first on line {links[name].line})")
        links[name] = link
    if not links:
        raise root.error("a robot needs at least one <link>")
    parent_of: dict[str, tuple[str, JointDescription | None, np.ndarray, np.ndarray, Node]] = {}
    for node in _children(root, "joint"):
        parent, child, joint, pos, quat = _joint(node, links)
        if child in parent_of:
            raise node.error(f"link {child!r} has two parents: joints {parent_of[child][4].attrib['name']!r} and "
                             f"{node.attrib['name']!r}")  # fmt: skip
        parent_of[child] = (parent, joint, pos, quat, node)
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        detail = "every link is some joint's child: the joints make a loop" if not roots else ", ".join(roots)
        raise root.error(f"a robot is a tree with one root link; found {len(roots)} ({detail})")
    children: dict[str, list[str]] = {name: [] for name in links}
    for child, (parent, *_rest) in parent_of.items():
        children[parent].append(child)
    order, index = [roots[0]], {}
    for name in order:  # breadth first: parents before children
        order.extend(children[name])
    if len(order) != len(links):
        looped = sorted(set(links) - set(order))
        raise root.error(f"links {', '.join(map(repr, looped))} are not connected to the root {roots[0]!r}: "
                         "their joints make a loop")  # fmt: skip
    meshes: dict[str, MeshDescription] = {}
    bodies = []
    for name in order:
        link = links[name]
        geoms = tuple(_geometry(link, c, k, base, package_dirs, meshes) for k, c in
                      enumerate(_children(link, "collision")))  # fmt: skip
        if name == roots[0]:
            joints = (JointDescription(None, *_FREE, None, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, link.line),) if floating_base \
                else ()  # fmt: skip
            parent, pos, quat = -1, np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])
        else:
            parent_name, joint, pos, quat, _node = parent_of[name]
            parent, joints = index[parent_name], (() if joint is None else (joint,))
        index[name] = len(bodies)
        bodies.append(BodyDescription(name, parent, pos, quat, _mass_properties(link), joints, geoms, link.line))
    return ModelDescription(root.attrib.get("name") or file.stem, str(file), tuple(bodies), (), meshes=meshes)
