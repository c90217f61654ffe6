"""From the MJCF tree to a :class:`~tumble.models.description.ModelDescription`: ``compiler`` settings, ``default``
classes, and every body, joint and geom with its attributes resolved (MuJoCo's rules, MuJoCo's defaults).

An element's attributes are its class's defaults overlaid by its own; its class is its ``class`` attribute, else the
``childclass`` of the nearest body that has one, else ``main`` (the top ``<default>``). A nested ``<default
class=...>`` starts from its parent class. What tumble does not model (or not yet) is reported by one warning per
element and attribute, naming the first line; what cannot be read is an :class:`~.xml.MJCFError` naming the file,
element and line.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ... import portable
from ...mass import MassProperties
from ...rotation import quat_multiply, quat_rotate, quat_to_matrix
from ..description import (
    ActuatorDescription,
    BodyDescription,
    GeomDescription,
    JointDescription,
    MeshDescription,
    ModelDescription,
    TendonDescription,
)
from .actuators import ACTUATOR_TAGS, describe_actuator
from .attributes import flag as _flag
from .attributes import keyword as _keyword
from .attributes import number as _number
from .attributes import numbers as _numbers
from .frames import ORIENTATIONS, orientation, quat_z_to
from .inertia import (
    VOLUME_TYPES,
    bounded,
    geom_area,
    geom_mass_properties,
    geom_volume,
    shell_mass_properties,
)
from .mesh_inertia import MeshInertia, mesh_inertia
from .meshes import MESH_ATTRIBUTES, MESH_COSMETIC, read_mesh
from .tendons import describe_tendons, softness
from .xml import Node

__all__ = ["MJCFWarning", "describe"]


class MJCFWarning(UserWarning):
    """Part of a model file that tumble reads but does not simulate (or not yet)."""


# Elements that hold nothing an articulation simulates: read past without a word.
_SILENT = {"site", "camera", "light", "visual", "statistic", "size", "texture", "material", "hfield", "skin",
           "custom", "extension"}  # fmt: skip
# Attributes that only matter to collision or drawing, which an articulation has no use for.
_COSMETIC = {"rgba", "material", "group", "user", "margin", "gap", "solref", "solimp", "solmix", "priority", "condim",
             "hfield", "contype", "conaffinity", "friction", "solreflimit", "solimplimit", "solreffriction",
             "solimpfriction", "class", "childclass", "name", "texture", "emission", "specular", "shininess",
             "reflectance"}  # fmt: skip
_JOINT = {"type", "pos", "axis", "range", "limited", "ref", "springref", "stiffness", "damping", "armature",
          "frictionloss", "actuatorfrcrange", "actuatorfrclimited", "springdamper"}  # fmt: skip
_GEOM = {"type", "size", "fromto", "pos", "mass", "density", "shellinertia", "mesh", "fitscale", *ORIENTATIONS}
_BODY = {"pos", *ORIENTATIONS}
_INERTIAL = {"pos", "mass", "diaginertia", "fullinertia", *ORIENTATIONS}
_COMPILER_READ = {"angle", "eulerseq", "inertiafromgeom", "boundmass", "boundinertia", "autolimits",
                  "inertiagrouprange", "coordinate", "settotalmass", "meshdir", "assetdir", "texturedir",
                  "strippath", "fitaabb"}  # fmt: skip
_COMPILER_SWITCHES = {"balanceinertia", "fusestatic", "discardvisual", "alignfree"}  # fine while "false"
_JOINT_TYPES = ("hinge", "slide", "ball", "free")
# <option><flag>: switching these off changes what the articulation computes (gravity is read; contacts, limits and
# the other constraints are not in an articulation, and the energy and solver switches change nothing it does)
_FLAGS_THAT_MOVE = {"passive", "spring", "damper"}
_GEOM_TYPES = ("plane", "hfield", "sphere", "capsule", "ellipsoid", "cylinder", "box", "mesh", "sdf")


@dataclass
class _Compiler:
    degrees: bool = True
    eulerseq: str = "xyz"
    inertiafromgeom: str = "auto"
    boundmass: float = 0.0
    boundinertia: float = 0.0
    autolimits: bool = True
    inertiagrouprange: tuple[int, int] = (0, 5)
    settotalmass: float = -1.0
    meshdir: str | None = None
    assetdir: str | None = None
    strippath: bool = False
    fitaabb: bool = False


@dataclass
class _Reader:
    """The state of one read: compiler settings, default classes, and the warnings gathered."""

    compiler: _Compiler = field(default_factory=_Compiler)
    defaults: dict[str, dict[str, dict[str, str]]] = field(default_factory=lambda: {"main": {}})
    notes: dict[tuple[str, str], list[Node]] = field(default_factory=dict)
    meshes: dict[str, tuple[MeshDescription, Node]] = field(default_factory=dict)
    mesh_inertias: dict[str, MeshInertia] = field(default_factory=dict)

    def mesh(self, node: Node, name: str) -> tuple[MeshDescription, MeshInertia]:
        """The mesh a geom names and its inertia (computed once per mesh)."""
        if name not in self.meshes:
            raise node.error(f"mesh={name!r} names no <mesh> asset")
        mesh, mesh_node = self.meshes[name]
        if name not in self.mesh_inertias:
            try:
                self.mesh_inertias[name] = mesh_inertia(mesh.vertices, mesh.faces, mesh.inertia)
            except ValueError as error:
                raise mesh_node.error(f"mesh {name!r} ({mesh.source}): {error}") from None
        return mesh, self.mesh_inertias[name]

    def note(self, node: Node, what: str, message: str) -> None:
        """Gather a warning; one is issued per element and attribute, at the end."""
        self.notes.setdefault((f"<{node.tag}> {what}", message), []).append(node)

    def warn_all(self, source: str) -> None:
        for (what, message), nodes in self.notes.items():
            more = f" and {len(nodes) - 1} more" if len(nodes) > 1 else ""
            warnings.warn(f"{source}: {what} (line {nodes[0].line}{more}): {message}", MJCFWarning, stacklevel=5)


# --- attributes --------------------------------------------------------------------------------------


def _frame_quat(reader: _Reader, node: Node, attrib: dict[str, str]) -> np.ndarray:
    given = [kind for kind in ORIENTATIONS if kind in attrib]
    if len(given) > 1:
        raise node.error(f"give at most one orientation, got {', '.join(given)}")
    if not given:
        return np.array([1.0, 0.0, 0.0, 0.0])
    kind = given[0]
    values = _numbers(node, attrib, kind, {"quat": 4, "axisangle": 4, "euler": 3, "xyaxes": 6, "zaxis": 3}[kind])
    try:
        return orientation(kind, values, reader.compiler.degrees, reader.compiler.eulerseq)
    except ValueError as error:
        raise node.error(str(error)) from None


def _check_known(reader: _Reader, node: Node, attrib: dict[str, str], used: set[str]) -> None:
    for name in attrib:
        if name not in used and name not in _COSMETIC:
            reader.note(node, name, "not supported by tumble; ignored")


# --- compiler, option, defaults ------------------------------------------------------------------------


def _read_compiler(reader: _Reader, node: Node) -> None:
    a, c = node.attrib, reader.compiler
    c.degrees = _keyword(node, a, "angle", "degree" if c.degrees else "radian", ("degree", "radian")) == "degree"
    c.eulerseq = a.get("eulerseq", c.eulerseq)
    if len(c.eulerseq) != 3 or any(axis not in "xyzXYZ" for axis in c.eulerseq):
        raise node.error(f"eulerseq={c.eulerseq!r} must be three of x, y, z, X, Y, Z")
    c.inertiafromgeom = _flag(node, a, "inertiafromgeom", c.inertiafromgeom)
    c.boundmass = _number(node, a, "boundmass", c.boundmass, nonnegative=True)
    c.boundinertia = _number(node, a, "boundinertia", c.boundinertia, nonnegative=True)
    c.autolimits = _keyword(node, a, "autolimits", "true" if c.autolimits else "false", ("true", "false")) == "true"
    if "inertiagrouprange" in a:
        low, high = _numbers(node, a, "inertiagrouprange", 2)
        c.inertiagrouprange = (int(low), int(high))
    c.settotalmass = _number(node, a, "settotalmass", c.settotalmass)
    c.meshdir, c.assetdir = a.get("meshdir", c.meshdir), a.get("assetdir", c.assetdir)
    c.fitaabb = _keyword(node, a, "fitaabb", "true" if c.fitaabb else "false", ("true", "false")) == "true"
    c.strippath = _keyword(node, a, "strippath", "true" if c.strippath else "false", ("true", "false")) == "true"
    if a.get("coordinate", "local") != "local":
        raise node.error("coordinate='global' was removed from MJCF (MuJoCo 2.3.3); use local coordinates")
    for name, value in a.items():
        if name not in _COMPILER_READ and not (name in _COMPILER_SWITCHES and value == "false"):
            reader.note(node, name, "not supported by tumble; ignored")


def _read_defaults(reader: _Reader, node: Node, parent: str | None) -> None:
    name = node.attrib.get("class", "main" if parent is None else None)
    if name is None:
        raise node.error("a nested <default> needs a class attribute")
    if name in reader.defaults and parent is not None:
        raise node.error(f"default class {name!r} is defined twice")
    inherited = reader.defaults.get(parent, {}) if parent is not None else {}
    classes = {tag: dict(attrib) for tag, attrib in inherited.items()}
    for child in node.children:
        if child.tag == "default":
            continue
        classes.setdefault(child.tag, {}).update(child.attrib)
    reader.defaults[name] = classes
    for child in node.children:
        if child.tag == "default":
            _read_defaults(reader, child, name)


def _resolved(reader: _Reader, node: Node, childclass: str) -> dict[str, str]:
    """The element's attributes over its class's defaults."""
    name = node.attrib.get("class", childclass)
    if name not in reader.defaults:
        raise node.error(f"class={name!r} names no default class")
    return {**reader.defaults[name].get(node.tag, {}), **node.attrib}


# --- bodies, joints, geoms ---------------------------------------------------------------------------


def _joint(reader: _Reader, node: Node, childclass: str, is_top: bool) -> JointDescription:
    if node.tag == "freejoint":
        a = {"type": "free", **{k: v for k, v in node.attrib.items() if k in ("name", "group")}}
        _check_known(reader, node, node.attrib, {"align"})
    else:
        a = _resolved(reader, node, childclass)
        _check_known(reader, node, a, _JOINT)
    kind = _keyword(node, a, "type", "hinge", _JOINT_TYPES)
    if kind == "free" and not is_top:
        raise node.error("a free joint can only be in a top-level body (a child of <worldbody>)")
    axis = _numbers(node, a, "axis", 3, [0.0, 0.0, 1.0])
    if kind in ("hinge", "slide"):
        if portable.norm(axis) < 1e-14:
            raise node.error(f"axis={a['axis']!r} is zero")
        axis = axis / portable.norm(axis)
    # angles (a hinge's or ball's range, a hinge's ref and springref) in the compiler's unit
    scale = np.pi / 180.0 if kind in ("hinge", "ball") and reader.compiler.degrees else 1.0
    stiffness = _numbers(node, a, "stiffness", (1, 2, 3), [0.0])
    if stiffness[0] < 0.0:
        raise node.error(f"stiffness={a['stiffness']!r} must be >= 0")
    limited = _flag(node, a, "limited", "auto")
    has_range = "range" in a
    if limited == "auto" and not reader.compiler.autolimits and has_range:
        raise node.error("range without limited=... needs compiler autolimits='true'")
    is_limited = limited == "true" or (limited == "auto" and has_range)
    bounds = None
    if is_limited and kind != "free":
        low, high = _numbers(node, a, "range", 2, [0.0, 0.0]) * scale
        if kind != "ball" and low >= high:
            raise node.error(f"range={a.get('range')!r} must have its lower bound below the upper")
        bounds = (float(low), float(high))
        if kind == "ball":
            reader.note(node, "range", "a ball joint's limit (a cone) is not simulated by tumble's Articulation (yet)")
    joint = JointDescription(
        name=a.get("name"),
        type=kind,
        pos=_numbers(node, a, "pos", 3, [0.0, 0.0, 0.0]) if kind != "free" else np.zeros(3),
        axis=axis,
        range=bounds,
        ref=_number(node, a, "ref", 0.0) * scale,
        springref=_number(node, a, "springref", 0.0) * scale,
        stiffness=float(stiffness[0]),
        damping=_number(node, a, "damping", 0.0, nonnegative=True),
        armature=_number(node, a, "armature", 0.0, nonnegative=True),
        frictionloss=_number(node, a, "frictionloss", 0.0, nonnegative=True),
        line=node.line,
        springdamper=_springdamper(reader, node, a, kind),
        margin=_number(node, a, "margin", 0.0, nonnegative=True),
        limit_softness=softness(node, a, "limit"),
        friction_softness=softness(node, a, "friction"),
    )
    if np.any(stiffness[1:] != 0.0):
        reader.note(node, "stiffness", "only the linear spring (its first number) is simulated by tumble")
    if stiffness[0] != 0.0 and kind in ("ball", "free"):
        reader.note(node, "stiffness", f"a spring on a {kind} joint is not simulated by tumble; ignored")
    if kind == "free" and "pos" in a and np.any(_numbers(node, a, "pos", 3)):
        reader.note(node, "pos", "ignored on a free joint: its coordinates are the body's pose")
    return joint


def _fitted(reader: _Reader, node: Node, kind: str, mesh: str, a: dict[str, str], pos, quat):
    """A primitive geom that names a mesh is fitted to it (MuJoCo's rule): centred on the mesh's centre of mass,
    along its principal axes, sized from the box of equal inertia, times ``fitscale``."""
    _, inertia = reader.mesh(node, mesh)
    axes, (x, y, z) = inertia.principal_frame()
    radius = 0.5 * (x + y)
    size = {"sphere": [(x + y + z) / 3.0, 0.0, 0.0], "capsule": [radius, max(0.0, z - 0.5 * radius), 0.0],
            "cylinder": [radius, z, 0.0], "ellipsoid": [x, y, z], "box": [x, y, z]}[kind]  # fmt: skip
    if reader.compiler.fitaabb:
        reader.note(node, "fitaabb", "tumble fits primitives to the mesh's box of equal inertia, not its bounds")
    size = np.array(size) * _number(node, a, "fitscale", 1.0)
    return size, pos + quat_rotate(quat, inertia.com), quat_multiply(quat, axes)


def _springdamper(reader: _Reader, node: Node, a: dict[str, str], kind: str) -> tuple[float, float] | None:
    """``springdamper="timeconst dampratio"``: both positive, the spring and damper are sized from the joint's
    effective mass (``read_mjcf`` does it, once the tree is known)."""
    timeconst, dampratio = _numbers(node, a, "springdamper", 2, [0.0, 0.0])
    if timeconst <= 0.0 or dampratio <= 0.0:
        return None
    if kind not in ("hinge", "slide"):
        reader.note(node, "springdamper", f"a spring on a {kind} joint is not simulated by tumble; ignored")
        return None
    return float(timeconst), float(dampratio)


def _geom(reader: _Reader, node: Node, childclass: str) -> tuple[GeomDescription, MassProperties | None]:
    """The geom and its mass properties in the body frame (``None``: no mass, or excluded by the group range)."""
    a = _resolved(reader, node, childclass)
    _check_known(reader, node, a, _GEOM)
    kind = _keyword(node, a, "type", "sphere", _GEOM_TYPES)
    mesh = a.get("mesh")
    if kind == "mesh" and mesh is None:
        raise node.error("a mesh geom needs mesh=... naming a <mesh> asset")
    size = np.zeros(3)
    given = _numbers(node, a, "size", (1, 2, 3), [0.0])
    size[: given.size] = given
    pos = _numbers(node, a, "pos", 3, [0.0, 0.0, 0.0])
    quat = _frame_quat(reader, node, a)
    if "fromto" in a:
        if "pos" in node.attrib:
            raise node.error("give pos or fromto, not both")
        if kind not in ("capsule", "cylinder", "box", "ellipsoid"):
            raise node.error(f"fromto places a capsule, cylinder, box or ellipsoid, not a {kind}")
        ends = _numbers(node, a, "fromto", 6)
        segment = ends[3:] - ends[:3]
        length = float(portable.norm(segment))
        if length < 1e-14:
            raise node.error(f"fromto={a['fromto']!r} has zero length")
        pos, quat = 0.5 * (ends[:3] + ends[3:]), quat_z_to(segment)
        size[1 if kind in ("capsule", "cylinder") else 2] = 0.5 * length
    elif mesh is not None and kind in VOLUME_TYPES:
        size, pos, quat = _fitted(reader, node, kind, mesh, a, pos, quat)
    group = int(_number(node, a, "group", 0.0))
    geom = GeomDescription(
        name=a.get("name"), type=kind, size=size, pos=pos, quat=quat, group=group,
        contype=int(_number(node, a, "contype", 1.0)), conaffinity=int(_number(node, a, "conaffinity", 1.0)),
        friction=_numbers(node, a, "friction", (1, 2, 3), [1.0, 0.005, 0.0001]), line=node.line, mesh=mesh,
        margin=_number(node, a, "margin", 0.0, nonnegative=True), condim=_condim(node, a),
        softness=softness(node, a, ""), solmix=_number(node, a, "solmix", 1.0, nonnegative=True),
        priority=int(_number(node, a, "priority", 0.0)),
    )  # fmt: skip
    low, high = reader.compiler.inertiagrouprange
    if not low <= group <= high:
        return geom, None
    shell = _keyword(node, a, "shellinertia", "false", ("true", "false")) == "true"
    if kind == "mesh":
        if shell:
            raise node.error("shellinertia on a mesh geom: a mesh's inertia is its <mesh inertia=...>")
        _, inertia = reader.mesh(node, mesh)
        mass = _geom_mass(node, a, inertia.measure)
        if mass == 0.0:
            return geom, None
        return geom, inertia.mass_properties(mass).transformed(rotation=quat, translation=pos)
    if kind not in VOLUME_TYPES:
        if kind != "plane":
            reader.note(node, f"type={kind!r}", "its mass is not computed by tumble (yet); the geom adds none")
        return geom, None
    needed = {"sphere": 1, "capsule": 2, "cylinder": 2, "ellipsoid": 3, "box": 3}[kind]
    if np.any(size[:needed] <= 0.0):
        raise node.error(f"size={a.get('size')!r}: a {kind} needs {needed} positive sizes")
    mass = _geom_mass(node, a, geom_area(kind, size) if shell else geom_volume(kind, size))
    if mass == 0.0:
        return geom, None
    properties = (shell_mass_properties if shell else geom_mass_properties)(kind, size, mass)
    return geom, properties.transformed(rotation=quat, translation=pos)


def _geom_mass(node: Node, a: dict[str, str], measure: float) -> float:
    """The geom's ``mass``, else ``density`` (1000 by default) times its volume (or area, for a shell)."""
    if "mass" in a:
        return _number(node, a, "mass", 0.0, nonnegative=True)
    return _number(node, a, "density", 1000.0, nonnegative=True) * measure


def _condim(node: Node, a: dict[str, str]) -> int:
    value = _number(node, a, "condim", 3.0)
    if value not in (1.0, 3.0, 4.0, 6.0):
        raise node.error(f"condim={a.get('condim')!r} must be 1, 3, 4 or 6")
    return int(value)


def _read_contact(reader: _Reader, node: Node, excludes: list[tuple[str, str]]) -> None:
    """``<contact>``: the ``<exclude>`` pairs; explicit ``<pair>`` elements are warned about."""
    for child in node.children:
        if child.tag == "exclude":
            body1, body2 = child.attrib.get("body1"), child.attrib.get("body2")
            if body1 is None or body2 is None:
                raise child.error("an <exclude> names body1= and body2=")
            excludes.append((body1, body2))
        else:
            reader.note(child, "element", "explicit contact pairs are not simulated by tumble (yet); ignored")


def _inertial(reader: _Reader, node: Node) -> MassProperties:
    a = node.attrib
    _check_known(reader, node, a, _INERTIAL)
    if "mass" not in a:
        raise node.error("inertial needs a mass")
    mass = _number(node, a, "mass", 0.0)
    if mass <= 0.0:
        raise node.error(f"mass={a['mass']!r} must be > 0")
    pos = _numbers(node, a, "pos", 3)
    if pos is None:
        raise node.error("inertial needs a pos")
    if "diaginertia" in a and "fullinertia" in a:
        raise node.error("give diaginertia or fullinertia, not both")
    if "fullinertia" in a:
        if any(kind in a for kind in ORIENTATIONS):
            raise node.error("fullinertia is in the body frame: it takes no orientation")
        xx, yy, zz, xy, xz, yz = _numbers(node, a, "fullinertia", 6)
        tensor = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    elif "diaginertia" in a:
        rotation = quat_to_matrix(_frame_quat(reader, node, a))
        tensor = portable.matmul(rotation * _numbers(node, a, "diaginertia", 3), rotation.T)
    else:
        raise node.error("inertial needs diaginertia or fullinertia")
    try:
        return MassProperties(mass, pos, tensor)
    except ValueError as error:
        raise node.error(f"non-physical inertia: {error}") from None


def _body(reader: _Reader, node: Node, parent: int, childclass: str,
          out: list[BodyDescription]) -> tuple[list[Node], str]:  # fmt: skip
    """Append the body ``node``; return its child bodies and the class they inherit."""
    a = node.attrib
    _check_known(reader, node, a, _BODY)
    childclass = a.get("childclass", childclass)
    if childclass not in reader.defaults:
        raise node.error(f"childclass={childclass!r} names no default class")
    joints, geoms, parts, inertial, children = [], [], [], None, []
    for child in node.children:
        if child.tag in ("joint", "freejoint"):
            joints.append(_joint(reader, child, childclass, parent < 0))
        elif child.tag == "geom":
            geom, properties = _geom(reader, child, childclass)
            geoms.append(geom)
            parts += [properties] if properties is not None else []
        elif child.tag == "inertial":
            if inertial is not None:
                raise child.error("a body has at most one inertial")
            inertial = _inertial(reader, child)
        elif child.tag == "body":
            children.append(child)
        elif child.tag not in _SILENT:
            reader.note(child, "element", "not supported by tumble; ignored")
    if any(j.type == "free" for j in joints) and len(joints) > 1:
        raise node.error("a body with a free joint can have no other joint")
    use_geoms = reader.compiler.inertiafromgeom == "true" or (
        reader.compiler.inertiafromgeom == "auto" and inertial is None
    )
    properties = (sum(parts) if parts else None) if use_geoms else inertial
    properties = bounded(properties, reader.compiler.boundmass, reader.compiler.boundinertia)
    out.append(BodyDescription(
        name=a.get("name"), parent=parent, pos=_numbers(node, a, "pos", 3, [0.0, 0.0, 0.0]),
        quat=_frame_quat(reader, node, a), mass_properties=properties, joints=tuple(joints), geoms=tuple(geoms),
        line=node.line,
    ))  # fmt: skip
    return children, childclass


def _body_tree(reader: _Reader, top: Node, out: list[BodyDescription]) -> None:
    """The bodies from ``top`` down in document order (parents first: MuJoCo's numbering), on a stack of its own:
    a chain of a thousand nested bodies is past Python's recursion limit."""
    stack = [(top, -1, "main")]
    while stack:
        node, parent, childclass = stack.pop()
        children, childclass = _body(reader, node, parent, childclass, out)
        index = len(out) - 1
        stack.extend((child, index, childclass) for child in reversed(children))


def _read_option_extras(reader: _Reader, node: Node) -> None:
    """Warn about what in ``<option>`` changes the dynamics but is not simulated: a medium (density, viscosity,
    wind) and the ``<flag>`` switches; the solver's settings concern contacts and constraints only."""
    for name in ("density", "viscosity"):
        if _number(node, node.attrib, name, 0.0) != 0.0:
            reader.note(node, name, "the medium's forces are not simulated by tumble; ignored")
    if np.any(_numbers(node, node.attrib, "wind", 3, [0.0, 0.0, 0.0]) != 0.0):
        reader.note(node, "wind", "the medium's forces are not simulated by tumble; ignored")
    for child in node.children:
        if child.tag != "flag":
            reader.note(child, "element", "not supported by tumble; ignored")
            continue
        for name, value in child.attrib.items():
            if name in _FLAGS_THAT_MOVE and value == "disable":
                reader.note(child, name, "switching this off is not supported by tumble; ignored")


def _read_assets(reader: _Reader, node: Node, base: Path) -> None:
    """The ``<mesh>`` assets of one ``<asset>``; textures, materials and the rest are for drawing."""
    directory = base / (reader.compiler.meshdir or reader.compiler.assetdir or "")
    for child in node.children:
        if child.tag != "mesh":
            if child.tag not in _SILENT:
                reader.note(child, "element", "not supported by tumble; ignored")
            continue
        a = _resolved(reader, child, "main")
        _check_known(reader, child, a, MESH_ATTRIBUTES | MESH_COSMETIC)
        if np.any(_numbers(child, a, "refquat", 4, [1.0, 0.0, 0.0, 0.0]) != [1.0, 0.0, 0.0, 0.0]):
            reader.note(child, "refquat", "not supported by tumble; ignored")
        mesh = read_mesh(child, a, directory, reader.compiler.strippath)
        if mesh.name in reader.meshes:
            raise child.error(f"mesh {mesh.name!r} is defined twice (first on line {reader.meshes[mesh.name][1].line})")
        reader.meshes[mesh.name] = (mesh, child)


def _joint_types(bodies: list[BodyDescription]) -> dict[str, str]:
    return {j.name: j.type for body in bodies for j in body.joints if j.name is not None}


def _tendon_resolved(reader: _Reader, node: Node) -> dict[str, str]:
    """A tendon's attributes over its class's ``<tendon>`` defaults (MuJoCo's one default for every tendon kind)."""
    name = node.attrib.get("class", "main")
    if name not in reader.defaults:
        raise node.error(f"class={name!r} names no default class")
    return {**reader.defaults[name].get("tendon", {}), **node.attrib}


def _read_tendons(reader: _Reader, root: Node, bodies: list[BodyDescription]) -> tuple[TendonDescription, ...]:
    """The fixed tendons of every ``<tendon>`` section, once the joints are known."""
    joint_types, found = _joint_types(bodies), []
    for section in (child for child in root.children if child.tag == "tendon"):
        found += describe_tendons(section, lambda node: _tendon_resolved(reader, node), joint_types,
                                  reader.compiler.autolimits, reader.note)  # fmt: skip
    return tuple(found)


def _read_actuators(reader: _Reader, root: Node, bodies: list[BodyDescription],
                    tendons: tuple[TendonDescription, ...]) -> tuple[ActuatorDescription, ...]:  # fmt: skip
    """The actuators tumble simulates, from every ``<actuator>`` section, once the joints and tendons are known."""
    joint_types = _joint_types(bodies)
    tendon_names = {tendon.name for tendon in tendons if tendon.name is not None}
    found = []
    for node in (child for section in root.children if section.tag == "actuator" for child in section.children):
        name = node.attrib.get("class", "main")
        if name not in reader.defaults:
            raise node.error(f"class={name!r} names no default class")
        defaults = reader.defaults[name]
        a = {key: value for tag in ACTUATOR_TAGS for key, value in defaults.get(tag, {}).items()} | node.attrib
        actuator = describe_actuator(node, a, joint_types, tendon_names, reader.compiler.autolimits, reader.note)
        found += [actuator] if actuator is not None else []
    return tuple(found)


def _gravity_switched_off(node: Node) -> bool:
    """``<option><flag gravity="disable"/></option>``."""
    return any(child.tag == "flag" and child.attrib.get("gravity") == "disable" for child in node.children)


def _scaled_to_total(bodies: list[BodyDescription], total: float) -> list[BodyDescription]:
    """``compiler settotalmass``: every body's mass and inertia scaled by one factor so that the masses sum to
    ``total``."""
    mass = sum(b.mass_properties.mass for b in bodies if b.mass_properties is not None)
    if mass <= 0.0:
        return bodies
    return [b if b.mass_properties is None else replace(b, mass_properties=b.mass_properties.scaled_to(
        b.mass_properties.mass * total / mass)) for b in bodies]  # fmt: skip


def describe(root: Node, base: Path) -> ModelDescription:
    """The description of a ``<mujoco>`` tree (``include`` already expanded); warnings for what is not simulated."""
    reader = _Reader()
    for node in root.children:  # compiler settings and classes first: MuJoCo reads them before the bodies
        if node.tag == "compiler":
            _read_compiler(reader, node)
    for node in root.children:
        if node.tag == "default":
            _read_defaults(reader, node, None)
    for node in root.children:  # assets before the bodies that use them, wherever the file writes them
        if node.tag == "asset":
            _read_assets(reader, node, base)
    gravity, timestep, integrator, impratio = np.array([0.0, 0.0, -9.81]), 0.002, "Euler", 1.0
    excludes: list[tuple[str, str]] = []
    bodies: list[BodyDescription] = []
    world_geoms: list[GeomDescription] = []
    for node in root.children:
        if node.tag == "option":
            _read_option_extras(reader, node)
            gravity = _numbers(node, node.attrib, "gravity", 3, gravity)
            if _gravity_switched_off(node):
                gravity = np.zeros(3)
            timestep = _number(node, node.attrib, "timestep", timestep)
            if timestep <= 0:
                raise node.error(f"timestep={node.attrib['timestep']!r} must be > 0")
            integrator = _keyword(node, node.attrib, "integrator", integrator,
                                  ("Euler", "RK4", "implicit", "implicitfast"))  # fmt: skip
            impratio = _number(node, node.attrib, "impratio", impratio)
            if impratio <= 0:
                raise node.error(f"impratio={node.attrib['impratio']!r} must be > 0")
        elif node.tag == "worldbody":
            for child in node.children:
                if child.tag == "body":
                    _body_tree(reader, child, bodies)
                elif child.tag == "geom":
                    world_geoms.append(_geom(reader, child, "main")[0])
                elif child.tag not in _SILENT:
                    reader.note(child, "element", "not supported by tumble; ignored")
        elif node.tag == "contact":
            _read_contact(reader, node, excludes)
        elif node.tag not in _SILENT and node.tag not in ("compiler", "default", "asset", "actuator", "tendon"):
            reader.note(node, "element", "not loaded by tumble (yet); ignored")
    tendons = _read_tendons(reader, root, bodies)
    actuators = _read_actuators(reader, root, bodies, tendons)
    if reader.compiler.settotalmass > 0:
        bodies = _scaled_to_total(bodies, reader.compiler.settotalmass)
    reader.warn_all(root.file)
    return ModelDescription(
        name=root.attrib.get("model", "MuJoCo Model"), source=root.file, bodies=tuple(bodies),
        world_geoms=tuple(world_geoms), gravity=gravity, timestep=timestep, integrator=integrator,
        meshes={name: mesh for name, (mesh, _) in reader.meshes.items()}, actuators=actuators, tendons=tendons,
        excludes=tuple(excludes), impratio=impratio,
    )  # fmt: skip
