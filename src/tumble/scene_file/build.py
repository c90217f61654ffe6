"""A validated :class:`~tumble.scene_file.schema.Scene` turned into a :class:`~tumble.World`.

Errors the world raises while a body or joint is added (a degenerate hull, a joint naming an unknown body)
are re-raised as :class:`SceneError` with the place in the file (``bodies[3]``), as validation errors are.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import joints as joint_types
from ..shapes import Box, Capsule, ConvexHull, Cylinder, Plane, Sphere, TriMesh
from ..world import World
from . import schema
from .vehicles import build_vehicle, build_wind

__all__ = ["SceneError", "build_world"]


class SceneError(ValueError):
    """A scene file that cannot be read or built; the message names the file and the place in it."""


def _mesh(shape: schema.MeshShape, base: Path, place: str, label: str) -> TriMesh:
    if shape.path is None:
        return TriMesh(np.array(shape.vertices, float), np.array(shape.faces, np.int64))
    path = (base / shape.path).resolve()
    if not path.is_file():
        raise SceneError(f"{label}: {place}.path: no mesh file {shape.path!r} (looked for {path})")
    try:
        import trimesh
    except ImportError as error:  # pragma: no cover - trimesh is in the mesh extra
        raise SceneError(
            f"{label}: {place}.path: reading mesh files needs trimesh (pip install tumble[mesh])"
        ) from error
    try:
        mesh = trimesh.load(path, force="mesh")
    except Exception as error:  # trimesh raises many kinds for unreadable files
        raise SceneError(f"{label}: {place}.path: cannot read {shape.path!r}: {error}") from error
    return TriMesh(np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64))


def _shape(shape, base: Path, place: str, label: str):
    if isinstance(shape, schema.SphereShape):
        return Sphere(shape.radius)
    if isinstance(shape, schema.BoxShape):
        return Box(shape.extents)
    if isinstance(shape, schema.CapsuleShape):
        return Capsule(shape.radius, shape.length)
    if isinstance(shape, schema.CylinderShape):
        return Cylinder(shape.radius, shape.height)
    if isinstance(shape, schema.PlaneShape):
        return Plane(shape.normal, shape.offset)
    if isinstance(shape, schema.HullShape):
        return ConvexHull(np.array(shape.points, float))
    return _mesh(shape, base, place, label)


class _Shapes:
    """The scene's shapes, one object for each distinct description: the bodies of a pile share their shape, so a
    mesh file is read once and a hull packed once, however many bodies use it."""

    def __init__(self, base: Path, label: str) -> None:
        self.base, self.label = base, label
        self._made: dict = {}

    def __call__(self, shape, place: str):
        key = (type(shape), shape)  # the shape models are frozen: equal descriptions hash alike
        try:
            hash(key)
        except TypeError:  # a hull's or a mesh's lists of points
            key = (type(shape), shape.model_dump_json())
        if key not in self._made:
            self._made[key] = _shape(shape, self.base, place, self.label)
        return self._made[key]

    def geometry(self, item: schema._Placed, place: str):
        if item.shape is not None:
            return self(item.shape, f"{place}.shape")
        if item.shapes is not None:
            return [(self(part.shape, f"{place}.shapes[{k}].shape"), part.position, part.orientation)
                    for k, part in enumerate(item.shapes)]  # fmt: skip
        return None


def _material(item: schema._Placed, materials: dict[str | None, dict], place: str, label: str) -> dict:
    """The item's friction, restitution and rolling resistance: its named material (``materials``: each one's
    values, ``None`` the default's) with what the item gives itself on top."""
    if item.material not in materials:
        known = sorted(name for name in materials if name is not None)
        raise SceneError(f"{label}: {place}.material: no material {item.material!r}; materials: {known}")
    values = dict(materials[item.material])
    for key in values:
        given = getattr(item, key)
        if given is not None:
            values[key] = given
    return values


def _joint(spec, bodies: dict, place: str, label: str):
    def body(key: str, name):
        if name is None:
            return None
        if name not in bodies:
            raise SceneError(f"{label}: {place}.{key}: no body named {name!r}; bodies: {sorted(bodies)}")
        return bodies[name]

    a, b = body("a", spec.a), body("b", spec.b)
    options = spec.model_dump(exclude={"type", "a", "b"}, exclude_none=True)
    if isinstance(spec, schema.BallJoint):
        return joint_types.BallJoint(a, b, **options)
    if isinstance(spec, schema.HingeJoint):
        return joint_types.HingeJoint(a, b, **options)
    if isinstance(spec, schema.SliderJoint):
        return joint_types.SliderJoint(a, b, **options)
    if isinstance(spec, schema.FixedJoint):
        return joint_types.FixedJoint(a, b, **options)
    if isinstance(spec, schema.PlanarJoint):
        return joint_types.PlanarJoint(a, b, **options)
    if isinstance(spec, schema.UniversalJoint):
        return joint_types.UniversalJoint(a, b, **options)
    if spec.type == "rope" and "min_length" not in options:
        options["min_length"] = 0.0
    return joint_types.DistanceJoint(a, b, **options)


def _articulation(spec: schema.Articulation, gravity, base: Path, place: str, label: str):
    from ..articulation import Articulation, Ball, Fixed, Free, Prismatic, Revolute

    kinds = {"revolute": Revolute, "prismatic": Prismatic, "ball": Ball, "free": Free, "fixed": Fixed}
    art = Articulation(gravity, spec.base_position, spec.base_orientation, name=spec.name)
    index: dict[str, int] = {}
    for k, link in enumerate(spec.links):
        where = f"{place}.links[{k}]"
        if link.parent is not None and link.parent not in index:
            raise SceneError(f"{label}: {where}.parent: no earlier link named {link.parent!r}; links: {sorted(index)}")
        joint = kinds[link.joint.type](link.joint.axis) if link.joint.axis is not None else kinds[link.joint.type]()
        shape = None if link.shape is None else _shape(link.shape, base, f"{where}.shape", label)
        try:
            index[link.name] = art.add_link(
                joint, parent=None if link.parent is None else index[link.parent], position=link.position,
                orientation=link.orientation, shape=shape, mass=link.mass, density=link.density,
                shape_position=link.shape_position, shape_orientation=link.shape_orientation, name=link.name,
            )  # fmt: skip
        except (ValueError, TypeError) as error:
            raise SceneError(f"{label}: {where}: {error}") from error
    if spec.q is not None:
        art.q = spec.q
    if spec.qd is not None:
        art.qd = spec.qd
    return art


def _vehicles(world, specs, label: str) -> dict:
    """Build the ``[[vehicles]]``; their bodies by name."""
    named = {}
    for k, spec in enumerate(specs):
        try:
            body = build_vehicle(world, spec).body
        except (ValueError, TypeError) as error:
            raise SceneError(f"{label}: vehicles[{k}]: {error}") from error
        if spec.name is not None:
            named[spec.name] = body
    return named


def _model(world: World, spec: schema.Model, base: Path, place: str, label: str) -> dict:
    """Load the model file ``spec`` names into ``world``; its named bodies, for the scene's joints."""
    from ..models.build_world import load_mjcf, load_urdf
    from ..models.mjcf import MJCFError

    path = (base / spec.path).resolve()
    if not path.is_file():
        raise SceneError(f"{label}: {place}.path: no model file {spec.path!r} (looked for {path})")
    kind = path.suffix.lower()
    if kind not in (".xml", ".urdf"):
        raise SceneError(f"{label}: {place}.path: a model file is MJCF (.xml) or URDF (.urdf); got {spec.path!r}")
    if kind == ".xml" and (spec.floating_base is not None or spec.package_dirs is not None):
        raise SceneError(f"{label}: {place}: floating_base and package_dirs are a URDF's; {spec.path!r} is MJCF")
    before = len(world.bodies)
    try:
        if kind == ".urdf":
            load_urdf(path, package_dirs=[base / d for d in spec.package_dirs or ()],
                      floating_base=bool(spec.floating_base), world=world, position=spec.position,
                      orientation=spec.orientation)  # fmt: skip
        else:
            load_mjcf(path, world=world, position=spec.position, orientation=spec.orientation)
    except (MJCFError, ValueError, TypeError) as error:
        raise SceneError(f"{label}: {place}: {error}") from None
    return {body.name: body for body in world.bodies[before:] if body.name is not None}


def build_world(scene: schema.Scene, base: Path, label: str) -> World:
    """The world a validated scene describes; ``base`` is the directory mesh paths are relative to."""
    settings = scene.world
    solver = settings.model_dump(include={"substeps", "contact_hertz", "contact_damping_ratio", "joint_hertz",
                                          "joint_damping_ratio", "sleep"}, exclude_none=True)  # fmt: skip
    try:
        world = World(settings.gravity, integrator=settings.integrator, **solver)
    except (ValueError, TypeError) as error:
        raise SceneError(f"{label}: world: {error}") from None
    named: dict = {}
    shapes = _Shapes(base, label)
    materials = {None: schema.Material().model_dump()} | {k: m.model_dump() for k, m in scene.materials.items()}
    for kind, items in (("bodies", scene.bodies), ("vehicles", scene.vehicles), ("static", scene.static)):
        if kind == "vehicles":  # after the bodies, before the static geometry: the order to_scene writes them in
            named.update(_vehicles(world, items, label))
            continue
        for k, item in enumerate(items):
            place = f"{kind}[{k}]"
            try:
                geometry = shapes.geometry(item, place)
                common = {
                    "name": item.name,
                    "position": item.position,
                    "orientation": item.orientation,
                    "collision_group": item.collision_group,
                    "collision_mask": item.collision_mask,
                    **_material(item, materials, place, label),
                }
                if kind == "bodies":
                    inertia = None if item.inertia is None else np.array(item.inertia, float)
                    if inertia is not None and inertia.ndim == 1:
                        inertia = np.diag(inertia)
                    body = world.add_body(geometry, mass=item.mass, density=item.density, inertia=inertia,
                                          velocity=item.velocity, angular_velocity=item.angular_velocity,
                                          linear_damping=item.linear_damping, angular_damping=item.angular_damping,
                                          **common)  # fmt: skip
                    if any(item.constant_force):  # zero unless set
                        body.constant_force = item.constant_force
                    if any(item.constant_torque):
                        body.constant_torque = item.constant_torque
                else:
                    body = world.add_static(geometry, **common)
            except SceneError:
                raise
            except (ValueError, TypeError) as error:
                raise SceneError(f"{label}: {place}: {error}") from error
            if item.name is not None:
                named[item.name] = body
    for k, spec in enumerate(scene.articulations):
        place = f"articulations[{k}]"
        try:
            copy = world.add_articulation(_articulation(spec, world.gravity, base, place, label))
        except SceneError:
            raise
        except (ValueError, TypeError) as error:
            raise SceneError(f"{label}: {place}: {error}") from error
        named.update({body.name: body for body in copy.bodies})
    for k, spec in enumerate(scene.models):
        named.update(_model(world, spec, base, f"models[{k}]", label))
    try:
        world.wind = build_wind(scene.wind)
    except (ValueError, TypeError) as error:
        raise SceneError(f"{label}: wind: {error}") from error
    for k, spec in enumerate(scene.joints):
        place = f"joints[{k}]"
        try:
            world.add_joint(_joint(spec, named, place, label))
        except SceneError:
            raise
        except (ValueError, TypeError) as error:
            raise SceneError(f"{label}: {place}: {error}") from error
    if settings.integrator not in ("auto", "symplectic") and world.model.has_constraints:
        raise SceneError(
            f"{label}: world.integrator: {settings.integrator!r} integrates free bodies only, and this scene's shapes "
            "can touch or its bodies are jointed (the contact and joint solver steps those): use 'auto' or "
            "'symplectic'"
        )
    return world
