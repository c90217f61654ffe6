"""The scene file's structure, as pydantic models: what may be written where, with its type and range.

One structure serves TOML and JSON. Unknown keys are errors (a typo must not be silently ignored). Vectors are
lists of numbers; quaternions ``[w, x, y, z]``; angles in radians; SI units throughout.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    Strict,
    StrictBool,
    field_validator,
    model_validator,
)

# Numbers are strict: an integer or a float, never a boolean (``radius = true`` is not 1) nor a string; and finite
# unless said otherwise.
Finite = Annotated[float, Strict(), Field(allow_inf_nan=False)]
Positive = Annotated[float, Strict(), Field(gt=0.0, allow_inf_nan=False)]
NonNegative = Annotated[float, Strict(), Field(ge=0.0, allow_inf_nan=False)]
Vector3 = tuple[Finite, Finite, Finite]
Quaternion = tuple[Finite, Finite, Finite, Finite]
Index = Annotated[int, Strict(), Field(ge=0, le=2**31 - 1)]  # into a list of vertices


def _without_nul(text: str) -> str:
    if "\x00" in text:
        raise ValueError("must not hold a NUL character (\\x00): HDF5 strings and file names end there")
    return text


# A name goes into every output format, a path to the operating system.
Name = Annotated[str, Field(min_length=1), AfterValidator(_without_nul)]
Path = Annotated[str, Field(min_length=1), AfterValidator(_without_nul)]
Bits = Annotated[int, Strict(), Field(ge=0, le=0xFFFFFFFF)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


# --- shapes --------------------------------------------------------------------------------------------


class SphereShape(_Strict):
    type: Literal["sphere"]
    radius: Positive


class BoxShape(_Strict):
    type: Literal["box"]
    extents: tuple[Positive, Positive, Positive]


class CapsuleShape(_Strict):
    type: Literal["capsule"]
    radius: Positive
    length: NonNegative


class CylinderShape(_Strict):
    type: Literal["cylinder"]
    radius: Positive
    height: Positive


class PlaneShape(_Strict):
    type: Literal["plane"]
    normal: Vector3 = (0.0, 0.0, 1.0)
    offset: Finite = 0.0


class HullShape(_Strict):
    type: Literal["hull"]
    points: list[Vector3] = Field(min_length=4)


class MeshShape(_Strict):
    """A triangle mesh: a file (STL, OBJ, … read with trimesh; the path relative to the scene file) or the
    vertices and faces written out."""

    type: Literal["mesh"]
    path: Path | None = None
    vertices: list[Vector3] | None = None
    faces: list[tuple[Index, Index, Index]] | None = None

    @model_validator(mode="after")
    def _one_source(self):
        if (self.path is None) == (self.vertices is None):
            raise ValueError("give either path or vertices and faces")
        if (self.vertices is None) != (self.faces is None):
            raise ValueError("vertices and faces go together")
        return self


Shape = Annotated[
    SphereShape | BoxShape | CapsuleShape | CylinderShape | PlaneShape | HullShape | MeshShape,
    Field(discriminator="type"),
]


class Part(_Strict):
    """One shape of a compound body, placed in the body frame."""

    shape: Shape
    position: Vector3 = (0.0, 0.0, 0.0)
    orientation: Quaternion = (1.0, 0.0, 0.0, 0.0)


# --- materials and bodies ------------------------------------------------------------------------------


class Material(_Strict):
    friction: NonNegative = 0.5
    restitution: Annotated[float, Strict(), Field(ge=0.0, le=1.0)] = 0.0
    rolling_resistance: NonNegative = 0.0


class _Placed(_Strict):
    name: Name | None = None
    shape: Shape | None = None
    shapes: list[Part] | None = None
    position: Vector3 = (0.0, 0.0, 0.0)
    orientation: Quaternion = (1.0, 0.0, 0.0, 0.0)
    material: str | None = None
    friction: NonNegative | None = None
    restitution: Annotated[float, Strict(), Field(ge=0.0, le=1.0)] | None = None
    rolling_resistance: NonNegative | None = None
    collision_group: Bits = 1
    collision_mask: Bits = 0xFFFFFFFF

    @model_validator(mode="after")
    def _one_geometry(self):
        if self.shape is not None and self.shapes is not None:
            raise ValueError("give shape or shapes, not both")
        return self


class Body(_Placed):
    """A dynamic body: ``mass`` or ``density`` (with geometry), or ``mass`` and ``inertia`` (without)."""

    mass: Positive | None = None
    density: Positive | None = None
    inertia: Vector3 | tuple[Vector3, Vector3, Vector3] | None = None
    velocity: Vector3 = (0.0, 0.0, 0.0)
    angular_velocity: Vector3 = (0.0, 0.0, 0.0)
    linear_damping: NonNegative = 0.0
    angular_damping: NonNegative = 0.0
    constant_force: Vector3 = (0.0, 0.0, 0.0)  # [N] world frame, at the COM, in every step
    constant_torque: Vector3 = (0.0, 0.0, 0.0)  # [N m] world frame, in every step

    @model_validator(mode="after")
    def _mass(self):
        if (self.mass is None) == (self.density is None):
            raise ValueError("give exactly one of mass and density")
        if self.shape is None and self.shapes is None and (self.mass is None or self.inertia is None):
            raise ValueError("a body without shape needs mass and inertia")
        return self


class Static(_Placed):
    """Fixed geometry: planes, meshes, any shape."""

    @model_validator(mode="after")
    def _geometry(self):
        if self.shape is None and self.shapes is None:
            raise ValueError("static geometry needs shape or shapes")
        return self


# --- joints -------------------------------------------------------------------------------------------


class _Joint(_Strict):
    a: str = Field(min_length=1)
    b: str | None = None  # None or "world": the world
    collide_connected: StrictBool = False

    @field_validator("b")
    @classmethod
    def _world(cls, value):
        return None if value == "world" else value


class BallJoint(_Joint):
    type: Literal["ball"]
    anchor: Vector3
    axis: Vector3 | None = None
    cone_angle: Annotated[float, Strict(), Field(gt=0.0, le=math.pi)] | None = None
    twist_lower: Annotated[float, Strict(), Field(ge=-math.pi, le=math.pi)] | None = None
    twist_upper: Annotated[float, Strict(), Field(ge=-math.pi, le=math.pi)] | None = None


class _Drive(_Joint):
    lower: Finite | None = None
    upper: Finite | None = None
    motor_speed: Finite = 0.0
    spring_hertz: NonNegative = 0.0
    spring_damping_ratio: NonNegative = 0.0
    spring_target: Finite = 0.0
    damping: NonNegative = 0.0


class HingeJoint(_Drive):
    type: Literal["hinge"]
    anchor: Vector3
    axis: Vector3
    max_motor_torque: NonNegative = 0.0


class SliderJoint(_Drive):
    type: Literal["slider"]
    axis: Vector3
    anchor: Vector3 | None = None
    max_motor_force: NonNegative = 0.0


class FixedJoint(_Joint):
    type: Literal["fixed"]
    anchor: Vector3 | None = None


class DistanceJoint(_Joint):
    """A rod (default), a rope (``min_length = 0``) or, with ``spring_hertz > 0``, a spring."""

    type: Literal["distance", "spring", "rope"]
    anchor_a: Vector3
    anchor_b: Vector3
    length: NonNegative | None = None
    min_length: NonNegative | None = None
    max_length: NonNegative | None = None
    spring_hertz: NonNegative = 0.0
    spring_damping_ratio: NonNegative = 0.0


class PlanarJoint(_Joint):
    type: Literal["planar"]
    normal: Vector3
    anchor: Vector3 | None = None


class UniversalJoint(_Joint):
    type: Literal["universal"]
    anchor: Vector3
    axis_a: Vector3
    axis_b: Vector3


Joint = Annotated[
    BallJoint | HingeJoint | SliderJoint | FixedJoint | DistanceJoint | PlanarJoint | UniversalJoint,
    Field(discriminator="type"),
]


# --- articulations -------------------------------------------------------------------------------------


class LinkJoint(_Strict):
    type: Literal["revolute", "prismatic", "ball", "free", "fixed"]
    axis: Vector3 | None = None

    @model_validator(mode="after")
    def _axis(self):
        if (self.type in ("revolute", "prismatic")) != (self.axis is not None):
            raise ValueError("revolute and prismatic joints need an axis, the others take none")
        return self


class Link(_Strict):
    """One link: its joint to ``parent`` (a link name; omitted: the base), its frame in the parent's frame at
    zero displacement, its geometry and mass in its own frame."""

    name: Name
    joint: LinkJoint
    parent: str | None = None
    position: Vector3 = (0.0, 0.0, 0.0)
    orientation: Quaternion = (1.0, 0.0, 0.0, 0.0)
    shape: Shape | None = None
    shape_position: Vector3 = (0.0, 0.0, 0.0)
    shape_orientation: Quaternion = (1.0, 0.0, 0.0, 0.0)
    mass: Positive | None = None
    density: Positive | None = None


class Articulation(_Strict):
    """A tree of links (``tumble.Articulation``) put into the world at its coordinates ``q``, ``qd``: its links
    become bodies named ``NAME/LINK``, its joints world joints (``World.add_articulation``)."""

    name: Name
    base_position: Vector3 = (0.0, 0.0, 0.0)
    base_orientation: Quaternion = (1.0, 0.0, 0.0, 0.0)
    links: list[Link] = Field(min_length=1)
    q: list[Finite] | None = None
    qd: list[Finite] | None = None


class Model(_Strict):
    """A model file put into the world: MJCF (``.xml``) with ``tumble.load_mjcf``, URDF (``.urdf``) with
    ``tumble.load_urdf``; ``path`` relative to the scene file, the whole model at ``position``/``orientation``; its
    bodies keep the model's names (scene joints may refer to them). A URDF's ``floating_base`` frees its root link,
    and its ``package://`` meshes are looked up in ``package_dirs`` (relative to the scene file) first."""

    path: Path
    position: Vector3 = (0.0, 0.0, 0.0)
    orientation: Quaternion = (1.0, 0.0, 0.0, 0.0)
    floating_base: bool | None = None  # a URDF's root free (None: welded, as False)
    package_dirs: list[Path] | None = None


# --- vehicles and wind (docs/quadrotor.md) ----------------------------------------------------------------

Gain = Finite | Vector3  # one number for every axis, or one per axis


class QuadrotorParams(_Strict):
    """A parameter set: a shipped one (``base``) with any of its values replaced."""

    base: Literal["crazyflie", "hummingbird"] = "crazyflie"
    mass: Positive | None = None
    inertia: Vector3 | tuple[Vector3, Vector3, Vector3] | None = None
    arm_length: Positive | None = None
    k_thrust: Positive | None = None
    k_moment: NonNegative | None = None
    k_drag: NonNegative | None = None
    k_inflow: NonNegative | None = None
    speed_min: NonNegative | None = None
    speed_max: Positive | None = None
    time_constant: NonNegative | None = None
    rotor_directions: tuple[Literal[-1, 1], Literal[-1, 1], Literal[-1, 1], Literal[-1, 1]] | None = None
    drag_coefficients: Vector3 | None = None
    kp_att: NonNegative | None = None
    kd_att: NonNegative | None = None


class SE3ControllerSpec(_Strict):
    type: Literal["se3"]
    rate: Positive | None = None  # Hz; omitted: every step
    kp_pos: Gain | None = None
    kd_pos: Gain | None = None
    ki_pos: Gain | None = None
    kp_att: Finite | None = None
    kd_att: Finite | None = None
    integral_limit: Finite | None = None
    feedforward: StrictBool = False


class CascadedPIDSpec(_Strict):
    type: Literal["cascaded_pid"]
    rate: Positive | None = None
    kp_pos: Gain | None = None
    kp_vel: Gain | None = None
    ki_vel: Gain | None = None
    kp_att: Finite | None = None
    kp_rate: Finite | None = None
    integral_limit: Finite | None = None


FlightController = Annotated[SE3ControllerSpec | CascadedPIDSpec, Field(discriminator="type")]


class HoverSpec(_Strict):
    type: Literal["hover"]
    position: Vector3
    yaw: Finite = 0.0


class CircleSpec(_Strict):
    type: Literal["circle"]
    center: Vector3
    radius: Positive
    frequency: NonNegative
    yaw: Finite = 0.0


class LissajousSpec(_Strict):
    type: Literal["lissajous"]
    A: NonNegative
    B: NonNegative
    a: Finite
    b: Finite
    delta: Finite = 0.0
    center: Vector3 = (0.0, 0.0, 0.0)
    yaw: Finite = 0.0


class MinimumSnapSpec(_Strict):
    type: Literal["minimum_snap"]
    waypoints: list[Vector3] = Field(min_length=2)
    times: list[Finite] | None = None
    average_speed: Positive = 1.0
    yaw: Finite = 0.0


Reference = Annotated[HoverSpec | CircleSpec | LissajousSpec | MinimumSnapSpec, Field(discriminator="type")]


class Vehicle(_Strict):
    """A quadrotor (``tumble.vehicles.Quadrotor``): its body and four rotors, and what flies it: a ``controller``
    following a ``trajectory`` (both or neither), or fixed rotor ``commands``."""

    type: Literal["quadrotor"]
    name: Name | None = None
    params: Literal["crazyflie", "hummingbird"] | QuadrotorParams = "crazyflie"
    layout: Literal["x", "+"] = "x"
    position: Vector3 = (0.0, 0.0, 0.0)
    orientation: Quaternion = (1.0, 0.0, 0.0, 0.0)
    velocity: Vector3 = (0.0, 0.0, 0.0)
    angular_velocity: Vector3 = (0.0, 0.0, 0.0)
    rotor_speeds: Literal["rest", "hover"] | tuple[NonNegative, NonNegative, NonNegative, NonNegative] = "rest"
    commands: tuple[NonNegative, NonNegative, NonNegative, NonNegative] | None = None
    controller: FlightController | None = None
    trajectory: Reference | None = None

    @model_validator(mode="after")
    def _flown(self):
        if (self.controller is None) != (self.trajectory is None):
            raise ValueError("give a controller and a trajectory together, or neither")
        if self.controller is not None and self.commands is not None:
            raise ValueError("commands are for a vehicle without a controller")
        return self


class ConstantWind(_Strict):
    type: Literal["constant"]
    velocity: Vector3


class SinusoidWind(_Strict):
    type: Literal["sinusoid"]
    mean: Vector3
    amplitude: Vector3
    frequency: NonNegative


class DrydenWind(_Strict):
    type: Literal["dryden"]
    mean: Vector3
    sigma: Gain
    length_scale: Gain
    seed: Annotated[int, Strict(), Field(ge=0)] | None = None


Wind = Annotated[ConstantWind | SinusoidWind | DrydenWind, Field(discriminator="type")]


# --- the whole file ---------------------------------------------------------------------------------


class WorldSettings(_Strict):
    gravity: Vector3 = (0.0, 0.0, -9.81)
    dt: Positive = 1.0 / 60.0
    duration: Positive = 5.0
    integrator: Literal["auto", "euler", "symplectic", "rk4", "midpoint"] = "auto"
    substeps: Annotated[int, Strict(), Field(ge=1, le=1000)] | None = None
    contact_hertz: Positive | None = None
    contact_damping_ratio: NonNegative | None = None
    joint_hertz: Annotated[float, Strict(), Field(gt=0.0)] | None = None  # inf: as stiff as the substeps allow
    joint_damping_ratio: NonNegative | None = None
    sleep: StrictBool | None = None


class Recording(_Strict):
    every: Annotated[int, Strict(), Field(ge=1, le=2**31 - 1)] = 1
    path: Path | None = None


class Scene(_Strict):
    """A scene file: ``[world]``, ``[materials.NAME]``, ``[[bodies]]``, ``[[static]]``, ``[[joints]]``,
    ``[[articulations]]``, ``[[models]]``, ``[[vehicles]]``, ``[wind]``, ``[recording]``, and a free-text
    ``description``."""

    description: str = ""
    world: WorldSettings = WorldSettings()
    materials: dict[str, Material] = {}
    bodies: list[Body] = []
    static: list[Static] = []
    joints: list[Joint] = []
    articulations: list[Articulation] = []
    models: list[Model] = []
    vehicles: list[Vehicle] = []
    wind: Wind | None = None
    recording: Recording = Recording()
