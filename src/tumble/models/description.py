"""A model file as plain data: bodies in tree order with their frames, joints, geoms and mass properties.

The MJCF reader produces it (``models/mjcf``), the builders consume it (``models/build.py``); the URDF reader will
produce the same. Everything is resolved: defaults applied, angles in radians, orientations as unit quaternions,
mass properties computed. Frames follow MuJoCo: a body's ``pos``/``quat`` place it in its parent's frame, its
joints' ``pos``/``axis`` and its geoms are in its own frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..mass import MassProperties

__all__ = ["ActuatorDescription", "BodyDescription", "GeomDescription", "JointDescription", "MeshDescription",
           "ModelDescription", "TendonDescription"]  # fmt: skip


@dataclass(frozen=True)
class JointDescription:
    """One joint of a body. ``type``: ``"hinge"``, ``"slide"``, ``"ball"`` or ``"free"``."""

    name: str | None
    type: str
    pos: np.ndarray  # (3,) [m], body frame
    axis: np.ndarray  # (3,) unit, body frame (hinge, slide)
    range: tuple[float, float] | None  # [rad] or [m]; None: unlimited
    ref: float  # the coordinate at the model's pose (qpos0) [rad] or [m]
    springref: float  # the spring's rest coordinate
    stiffness: float
    damping: float
    armature: float
    frictionloss: float
    line: int
    # MJCF's (time constant [s], damping ratio) that sized ``stiffness`` and ``damping`` from the joint's mass
    springdamper: tuple[float, float] | None = None
    # the distance from a limit at which it acts, and MuJoCo's (solref, solimp) of the limits and dry friction
    margin: float = 0.0
    limit_softness: tuple[tuple[float, ...], tuple[float, ...]] | None = None
    friction_softness: tuple[tuple[float, ...], tuple[float, ...]] | None = None


@dataclass(frozen=True)
class TendonDescription:
    """A fixed tendon: the length ``Σ coefficients · q`` over named hinges and slides, with MuJoCo's limit, dry
    friction, spring and damper (``springlength`` None: the length at the model's pose)."""

    name: str | None
    joints: tuple[str, ...]
    coefficients: tuple[float, ...]
    range: tuple[float, float] | None
    margin: float
    frictionloss: float
    stiffness: float
    damping: float
    springlength: float | None
    limit_softness: tuple[tuple[float, ...], tuple[float, ...]]
    friction_softness: tuple[tuple[float, ...], tuple[float, ...]]
    line: int


@dataclass(frozen=True)
class GeomDescription:
    """One geom of a body, in the body frame. ``size`` is MuJoCo's (half sizes, radius, half length)."""

    name: str | None
    type: str
    size: np.ndarray  # (3,)
    pos: np.ndarray  # (3,)
    quat: np.ndarray  # (4,)
    group: int
    contype: int
    conaffinity: int
    friction: np.ndarray  # (3,) sliding, torsional, rolling
    line: int
    mesh: str | None = None  # a mesh geom's mesh (``ModelDescription.meshes``); a primitive fitted to one names it
    # MuJoCo's contact settings: margin [m], condim, (solref, solimp), solmix, priority
    margin: float = 0.0
    condim: int = 3
    softness: tuple[tuple[float, ...], tuple[float, ...]] = ((0.02, 1.0), (0.9, 0.95, 0.001, 0.5, 2.0))
    solmix: float = 1.0
    priority: int = 0


@dataclass(frozen=True)
class MeshDescription:
    """A triangle mesh asset in its own frame (the frame a mesh geom's ``pos``/``quat`` place). ``inertia`` says how
    a geom of it spreads its mass: ``"legacy"``, ``"exact"``, ``"convex"`` (a solid) or ``"shell"`` (the surface)."""

    name: str
    vertices: np.ndarray  # (n, 3) [m]
    faces: np.ndarray  # (f, 3) vertex indices, counter-clockwise seen from outside
    inertia: str
    source: str  # the file it was read from, or the model's for vertices written in it
    line: int


@dataclass(frozen=True)
class BodyDescription:
    """One body. ``parent`` indexes ``ModelDescription.bodies`` (-1: the world); parents come first."""

    name: str | None
    parent: int
    pos: np.ndarray  # (3,) in the parent's frame
    quat: np.ndarray  # (4,)
    mass_properties: MassProperties | None  # body frame; None: massless
    joints: tuple[JointDescription, ...]
    geoms: tuple[GeomDescription, ...]
    line: int


@dataclass(frozen=True)
class ActuatorDescription:
    """An actuator on a hinge or slide joint (or a fixed tendon): the force ``gain · ctrl + bias · (1, l, l̇)`` along
    its length ``l = gear · q``, the control clipped to ``ctrl_range`` and the force to ``force_range`` (see
    ``tumble.articulation.actuators``)."""

    name: str | None
    kind: str  # the element it was written as: "motor", "position", "velocity" or "general"
    joint: str | None
    gear: float
    gain: float
    bias: np.ndarray  # (3,)
    ctrl_range: tuple[float, float] | None
    line: int
    force_range: tuple[float, float] | None = None
    tendon: str | None = None


@dataclass(frozen=True)
class ModelDescription:
    """A whole model: the bodies (without the world), the world's own geoms, and the simulation options."""

    name: str
    source: str
    bodies: tuple[BodyDescription, ...]
    world_geoms: tuple[GeomDescription, ...]
    gravity: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -9.81]))
    timestep: float = 0.002
    integrator: str = "Euler"
    meshes: dict[str, MeshDescription] = field(default_factory=dict)
    actuators: tuple[ActuatorDescription, ...] = ()  # those tumble simulates, in the file's order
    tendons: tuple[TendonDescription, ...] = ()
    excludes: tuple[tuple[str, str], ...] = ()  # <contact><exclude>: pairs of body names that do not touch
    impratio: float = 1.0

    def body_index(self, name: str) -> int:
        for index, body in enumerate(self.bodies):
            if body.name == name:
                return index
        raise KeyError(f"no body named {name!r} in {self.source}")
