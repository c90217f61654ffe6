"""tumble: rigid-body physics for Python.

>>> import tumble
>>> world = tumble.World()
>>> ball = world.add_body(tumble.Sphere(0.1), density=1000.0, position=(0.0, 0.0, 1.0))
>>> world.step(0.01)
>>> round(float(ball.velocity[2]), 4)
-0.0981
"""

from __future__ import annotations

from . import actuators, control, mass, rotation, sensors, shapes, vehicles, wind
from ._version import __version__
from .batch import Batch
from .errors import SimulationError, SubstepsRaisedWarning
from .handles import Body, Joint
from .joints import BallJoint, DistanceJoint, FixedJoint, HingeJoint, PlanarJoint, SliderJoint, UniversalJoint
from .mass import MassProperties
from .shapes import Box, Capsule, ConvexHull, Cylinder, Plane, Shape, ShapeType, Sphere, TriMesh
from .trajectory import Trajectory
from .world import World

_ARTICULATION_NAMES = ("Articulation", "Ball", "Fixed", "Free", "Prismatic", "Revolute")


def __getattr__(name: str):
    """``tumble.Articulation`` and its joint types, imported on first use (they add 50 ms to ``import tumble``)."""
    if name in _ARTICULATION_NAMES:
        from . import articulation

        return getattr(articulation, name)
    raise AttributeError(f"module 'tumble' has no attribute {name!r}")


def load_mjcf(path_or_xml, *, world=None, position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0)) -> World:
    """An MJCF model (a file path, or XML text starting with ``<``) in a world: ``world``, or a new one with the
    model's gravity; the whole model placed at ``position``/``orientation``. Bodies with one joint each (or free, or
    welded to a neighbour) collide and move with the world's joints; see docs/model_files.md."""
    from .models.build_world import load_mjcf as load

    return load(path_or_xml, world=world, position=position, orientation=orientation)


def load_urdf(path, *, package_dirs=(), floating_base: bool = False, world=None, position=(0.0, 0.0, 0.0),
              orientation=(1.0, 0.0, 0.0, 0.0)) -> World:  # fmt: skip
    """A URDF robot in a world, as :func:`load_mjcf` loads an MJCF model: its links with their ``inertial`` and
    ``collision`` shapes, its joints as the world's joints (``fixed`` ones weld a link to its parent), the root link
    welded to the world, or free with ``floating_base=True``. ``package://`` mesh paths are looked up in
    ``package_dirs``, then beside the file; see docs/model_files.md."""
    from .models.build_world import load_urdf as load

    return load(path, package_dirs=package_dirs, floating_base=floating_base, world=world, position=position,
                orientation=orientation)  # fmt: skip


def load_scene(path) -> World:
    """The world described by the scene file at ``path`` (TOML or JSON; see ``docs/scenes.md``)."""
    from .scene_file import load

    return load(path).world


__all__ = [
    "Articulation",
    "Ball",
    "BallJoint",
    "Batch",
    "Body",
    "Box",
    "Capsule",
    "ConvexHull",
    "Cylinder",
    "DistanceJoint",
    "Fixed",
    "FixedJoint",
    "Free",
    "HingeJoint",
    "Joint",
    "MassProperties",
    "Plane",
    "PlanarJoint",
    "Prismatic",
    "Revolute",
    "Shape",
    "ShapeType",
    "SimulationError",
    "SubstepsRaisedWarning",
    "SliderJoint",
    "Sphere",
    "Trajectory",
    "TriMesh",
    "UniversalJoint",
    "World",
    "__version__",
    "actuators",
    "control",
    "load_mjcf",
    "load_urdf",
    "load_scene",
    "mass",
    "rotation",
    "sensors",
    "shapes",
    "vehicles",
    "wind",
]
