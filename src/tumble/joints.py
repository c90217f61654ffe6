"""World joints: what the user writes to join two bodies (``world.add_joint(tumble.HingeJoint(a, b, ...))``).

A joint description holds bodies and world-frame anchors and axes *as given at creation*; ``World.add_joint``
turns it into body-frame data (``JointSpec``) from the bodies' poses at that moment, and returns a
:class:`~tumble.handles.Joint` handle. ``b=None`` joins ``a`` to the world. The joints are solved with the
contacts in the soft step (``dynamics/joint_solver.py``).

Optional parts of a hinge or slider, each off unless given:

- limits ``lower``/``upper`` on the angle [rad] or translation [m] (``None``: unbounded on that side);
- a velocity motor: ``motor_speed`` [rad/s or m/s] reached with at most ``max_motor_torque`` [N m] /
  ``max_motor_force`` [N] (the motor is on when the maximum is positive);
- a spring towards ``spring_target`` of frequency ``spring_hertz`` [Hz] and damping ratio
  ``spring_damping_ratio`` (on when ``spring_hertz > 0``). As in Box2D, the stiffness is relative to the
  joint's effective mass along its free axis, here with the rest of the joint held (for a body hinged to the
  world: its moment of inertia about the hinge): ``k = m_eff (2π f)²``, so a body on a spring to the world
  oscillates at ``f``.

A :class:`DistanceJoint` keeps two anchors at ``length`` (a rigid rod), or, with ``spring_hertz > 0``, pulls
them towards it as a damped spring, and ``min_length``/``max_length`` bound it (a rope: ``min_length=0``).

A :class:`PlanarJoint` keeps ``b`` moving in a plane of ``a`` (two translations and the turn about the normal: the
root of MuJoCo's 2-D walkers); a :class:`UniversalJoint` is a Hooke's joint (a common point, two perpendicular
axes, one carried by each body). Neither has limits, motors or springs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import portable
from ._validate import as_float, as_unit_vector3, as_vector3
from .builder import JointSpec
from .dynamics.joint_solver import JointKind
from .handles import Body
from .rotation import matrix_to_quat, quat_conjugate, quat_multiply, quat_rotate

__all__ = [
    "BallJoint",
    "DistanceJoint",
    "FixedJoint",
    "HingeJoint",
    "JointKind",
    "PlanarJoint",
    "SliderJoint",
    "UniversalJoint",
]


def _bounds(name_lower: str, lower, name_upper: str, upper) -> tuple[float, float]:
    lo = -math.inf if lower is None else as_float(name_lower, lower)
    hi = math.inf if upper is None else as_float(name_upper, upper)
    if lo > hi:
        raise ValueError(f"{name_lower} must not exceed {name_upper}, got {name_lower}={lo!r}, {name_upper}={hi!r}")
    return lo, hi


@dataclass(frozen=True)
class _Drive:
    """Limits, motor and spring along a joint's free axis (hinge: angle; slider: translation)."""

    lower: float
    upper: float
    motor_speed: float
    max_motor: float
    spring_hertz: float
    spring_damping_ratio: float
    spring_target: float
    cone: float = math.inf  # ball joints: the largest swing [rad]
    damping: float = 0.0  # hinges and sliders: the torque (force) per unit rate, −damping · q̇ [N m s/rad, N s/m]

    @classmethod
    def checked(cls, lower, upper, motor_speed, max_motor_name, max_motor, spring_hertz, spring_damping_ratio,
                spring_target, damping) -> _Drive:  # fmt: skip
        lo, hi = _bounds("lower", lower, "upper", upper)
        return cls(
            lo, hi, as_float("motor_speed", motor_speed), as_float(max_motor_name, max_motor, nonnegative=True),
            as_float("spring_hertz", spring_hertz, nonnegative=True),
            as_float("spring_damping_ratio", spring_damping_ratio, nonnegative=True),
            as_float("spring_target", spring_target), damping=as_float("damping", damping, nonnegative=True),
        )  # fmt: skip


_NO_DRIVE = _Drive(-math.inf, math.inf, 0.0, 0.0, 0.0, 0.0, 0.0)


class _JointBase:
    """Two bodies (``b=None``: the world) and whether they may still collide with each other; read-only."""

    kind = JointKind.BALL

    def __setattr__(self, name, value):
        raise AttributeError(f"{type(self).__name__} is read-only; create a new joint (or use the handle)")

    def __repr__(self) -> str:
        def label(body):
            return "world" if body is None else repr(getattr(body, "name", None) or getattr(body, "index", body))

        return f"{type(self).__name__}(a={label(self.a)}, b={label(self.b)})"

    def _set_bodies(self, a, b, collide_connected) -> None:
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)
        if not isinstance(collide_connected, (bool, np.bool_)):
            raise TypeError(f"collide_connected must be True or False, got {collide_connected!r}")
        object.__setattr__(self, "collide_connected", bool(collide_connected))

    def _set(self, name: str, value) -> None:
        object.__setattr__(self, name, value)


class BallJoint(_JointBase):
    """Keeps one point of ``a`` and one of ``b`` together (3 rotational freedoms): a shoulder, a chain link.

    Optional limits, about a twist ``axis`` (world frame at creation; a ragdoll's limb direction): a swing cone
    (the axis carried by ``b`` stays within ``cone_angle`` of the one carried by ``a``) and twist limits
    ``twist_lower``/``twist_upper`` about it.

    Args:
        a, b: bodies (``b=None``: the world).
        anchor: (3,) the common point [m], world frame, at creation.
        axis: (3,) the twist axis, needed with any limit. cone_angle: [rad] in (0, π]. twist_lower, twist_upper:
            [rad] in [−π, π] (``None``: free on that side).
    """

    kind = JointKind.BALL

    def __init__(self, a, b, anchor, *, axis=None, cone_angle=None, twist_lower=None, twist_upper=None,
                 collide_connected: bool = False):  # fmt: skip
        self._set_bodies(a, b, collide_connected)
        self._set("anchor", as_vector3("anchor", anchor))
        limited = cone_angle is not None or twist_lower is not None or twist_upper is not None
        if limited and axis is None:
            raise ValueError(
                "axis must be given with cone_angle, twist_lower or twist_upper (the axis they are measured about)"
            )
        if axis is not None:
            self._set("axis", as_unit_vector3("axis", axis))
        cone = math.inf if cone_angle is None else as_float("cone_angle", cone_angle, positive=True)
        if cone != math.inf and cone > math.pi:
            raise ValueError(f"cone_angle must be in (0, π], got {cone!r}")
        lo, hi = _bounds("twist_lower", twist_lower, "twist_upper", twist_upper)
        for name, value in (("twist_lower", lo), ("twist_upper", hi)):
            if math.isfinite(value) and abs(value) > math.pi:
                raise ValueError(f"{name} must be in [-π, π], got {value!r}")
        self._set("drive", _Drive(lo, hi, 0.0, 0.0, 0.0, 0.0, 0.0, cone))


class HingeJoint(_JointBase):
    """A revolute joint: a common point and a common axis, one rotational freedom (a door, a wheel, a pendulum).

    The angle is that of ``b`` relative to ``a`` about ``axis`` (right-handed), zero at creation.

    Args:
        a, b: bodies (``b=None``: the world).
        anchor: (3,) a point on the axis [m], world frame. axis: (3,) non-zero, world frame.
        lower, upper: angle limits [rad] (``None``: free on that side).
        motor_speed: [rad/s] target of the motor; max_motor_torque: [N m] its bound (0: no motor).
        spring_hertz, spring_damping_ratio, spring_target: an angular spring towards ``spring_target`` [rad].
        damping: [N m s/rad] a torque ``−damping · ω`` against the turning (MJCF's joint ``damping``; implicit, so
            stable at any value).
    """

    kind = JointKind.HINGE

    def __init__(self, a, b, anchor, axis, *, lower=None, upper=None, motor_speed: float = 0.0,
                 max_motor_torque: float = 0.0, spring_hertz: float = 0.0, spring_damping_ratio: float = 0.0,
                 spring_target: float = 0.0, damping: float = 0.0, collide_connected: bool = False):  # fmt: skip
        self._set_bodies(a, b, collide_connected)
        self._set("anchor", as_vector3("anchor", anchor))
        self._set("axis", as_unit_vector3("axis", axis))
        self._set("drive", _Drive.checked(lower, upper, motor_speed, "max_motor_torque", max_motor_torque,
                                          spring_hertz, spring_damping_ratio, spring_target, damping))  # fmt: skip


class SliderJoint(_JointBase):
    """A prismatic joint: no relative rotation, motion only along ``axis`` (a piston, a drawer, a rail).

    The translation is that of ``b``'s anchor relative to ``a``'s along ``axis``, zero at creation.

    Args:
        a, b: bodies (``b=None``: the world).
        axis: (3,) non-zero, world frame. anchor: (3,) a point on the axis [m] (default: ``b``'s origin, or
            ``a``'s when ``b`` is None).
        lower, upper: translation limits [m]; motor_speed [m/s], max_motor_force [N]; spring_* as for hinges
            (target in metres); damping [N s/m] a force ``−damping · v`` along the axis.
    """

    kind = JointKind.SLIDER

    def __init__(self, a, b, axis, *, anchor=None, lower=None, upper=None, motor_speed: float = 0.0,
                 max_motor_force: float = 0.0, spring_hertz: float = 0.0, spring_damping_ratio: float = 0.0,
                 spring_target: float = 0.0, damping: float = 0.0, collide_connected: bool = False):  # fmt: skip
        self._set_bodies(a, b, collide_connected)
        self._set("anchor", None if anchor is None else as_vector3("anchor", anchor))
        self._set("axis", as_unit_vector3("axis", axis))
        self._set("drive", _Drive.checked(lower, upper, motor_speed, "max_motor_force", max_motor_force,
                                          spring_hertz, spring_damping_ratio, spring_target, damping))  # fmt: skip


class FixedJoint(_JointBase):
    """Welds ``b`` to ``a`` (no relative motion) in their poses at creation.

    Args:
        a, b: bodies (``b=None``: the world). anchor: (3,) the weld point [m] (default: ``b``'s origin, or
            ``a``'s when ``b`` is None); where the reaction torque is reported about.
    """

    kind = JointKind.FIXED

    def __init__(self, a, b, *, anchor=None, collide_connected: bool = False):
        self._set_bodies(a, b, collide_connected)
        self._set("anchor", None if anchor is None else as_vector3("anchor", anchor))
        self._set("drive", _NO_DRIVE)


class DistanceJoint(_JointBase):
    """Keeps ``anchor_a`` on ``a`` and ``anchor_b`` on ``b`` at a distance: a rod, a rope or a spring.

    Args:
        a, b: bodies (``b=None``: the world, ``anchor_b`` then fixed in it). anchor_a, anchor_b: (3,) [m], world.
        length: rest length [m] (default: the distance at creation).
        min_length, max_length: bounds [m] (default: ``length``, a rod; ``min_length=0`` makes a rope).
        spring_hertz, spring_damping_ratio: a spring towards ``length`` instead of a rigid rod (0: rigid).
    """

    kind = JointKind.DISTANCE

    def __init__(self, a, b, anchor_a, anchor_b, *, length=None, min_length=None, max_length=None,
                 spring_hertz: float = 0.0, spring_damping_ratio: float = 0.0,
                 collide_connected: bool = False):  # fmt: skip
        self._set_bodies(a, b, collide_connected)
        anchor_a, anchor_b = as_vector3("anchor_a", anchor_a), as_vector3("anchor_b", anchor_b)
        self._set("anchor", anchor_a)
        self._set("anchor_b", anchor_b)
        distance = float(portable.norm(anchor_b - anchor_a))
        rest = distance if length is None else as_float("length", length, nonnegative=True)
        if rest < 1e-6:
            raise ValueError(
                f"length must be at least 1e-6 m (the direction between the anchors must be defined), got {rest!r}"
            )
        lo = rest if min_length is None else as_float("min_length", min_length, nonnegative=True)
        hi = rest if max_length is None else as_float("max_length", max_length, nonnegative=True)
        if not lo <= rest <= hi:
            raise ValueError(
                f"min_length <= length <= max_length must hold, got min_length={lo!r}, length={rest!r}, "
                f"max_length={hi!r}"
            )
        self._set(
            "drive",
            _Drive(
                lo,
                hi,
                0.0,
                0.0,
                as_float("spring_hertz", spring_hertz, nonnegative=True),
                as_float("spring_damping_ratio", spring_damping_ratio, nonnegative=True),
                rest,
            ),
        )

    @property
    def length(self) -> float:
        return self.drive.spring_target


class PlanarJoint(_JointBase):
    """``b`` slides in a plane of ``a`` and turns only about its normal (3 freedoms): the root of a planar walker,
    a puck on a table.

    Args:
        a, b: bodies (``b=None``: the world). normal: (3,) non-zero, world frame at creation.
        anchor: (3,) a point of the plane [m] (default: ``b``'s origin, or ``a``'s when ``b`` is None).
    """

    kind = JointKind.PLANAR

    def __init__(self, a, b, normal, *, anchor=None, collide_connected: bool = False):
        self._set_bodies(a, b, collide_connected)
        self._set("anchor", None if anchor is None else as_vector3("anchor", anchor))
        self._set("normal", as_unit_vector3("normal", normal))
        self._set("drive", _NO_DRIVE)


class UniversalJoint(_JointBase):
    """A Hooke's joint (2 rotational freedoms): a common point, ``b`` turning about ``axis_a`` (carried by ``a``)
    and about ``axis_b`` (carried by ``b``), which stay perpendicular: a cardan shaft, a two-hinge shoulder.

    Args:
        a, b: bodies (``b=None``: the world). anchor: (3,) the common point [m], world frame at creation.
        axis_a, axis_b: (3,) perpendicular (within 1e-6 rad), world frame at creation.
    """

    kind = JointKind.UNIVERSAL

    def __init__(self, a, b, anchor, axis_a, axis_b, *, collide_connected: bool = False):
        self._set_bodies(a, b, collide_connected)
        self._set("anchor", as_vector3("anchor", anchor))
        axis_a, axis_b = as_unit_vector3("axis_a", axis_a), as_unit_vector3("axis_b", axis_b)
        cosine = float(portable.dot(axis_a, axis_b))
        if abs(cosine) > 1e-6:
            raise ValueError(
                f"axis_a and axis_b must be perpendicular (a Hooke's joint), got {axis_a.tolist()} and "
                f"{axis_b.tolist()} at {math.degrees(math.acos(min(abs(cosine), 1.0))):.6g}°"
            )
        self._set("axis_a", axis_a)
        self._set("axis_b", axis_b)
        self._set("drive", _NO_DRIVE)


JOINT_TYPES = (BallJoint, HingeJoint, SliderJoint, FixedJoint, DistanceJoint, PlanarJoint, UniversalJoint)


def _world_pose(world, body) -> tuple[np.ndarray, np.ndarray]:
    """COM and orientation of ``body`` now (the world frame for None)."""
    if body is None:
        return np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])
    com, quat, _, _ = world._body_row(body.index)
    return com.copy(), quat.copy()


def _frame_with_x_along(axis: np.ndarray) -> np.ndarray:
    """A unit quaternion whose frame's x axis is ``axis`` (y, z any right-handed completion)."""
    helper = np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    y = np.cross(helper, axis)
    y /= portable.norm(y)
    return matrix_to_quat(np.column_stack([axis, y, np.cross(axis, y)]))


def _check_body(world, name: str, body, allow_none: bool):
    if body is None and allow_none:
        return None
    if not isinstance(body, Body):
        expected = "a Body of this world or None (the world)" if allow_none else "a Body of this world"
        raise TypeError(f"{name} must be {expected}, got {body!r} ({type(body).__name__})")
    if body._world is not world:
        raise ValueError(f"{name} must be a body of this world, got body {body.name or body.index!r} of another world")
    return body


def joint_spec(joint, world) -> JointSpec:
    """Validate ``joint`` for ``world`` and express it in the bodies' frames at their current poses."""
    if not isinstance(joint, JOINT_TYPES):
        names = ", ".join(t.__name__ for t in JOINT_TYPES)
        raise TypeError(f"joint must be one of {names}, got {joint!r} ({type(joint).__name__})")
    a = _check_body(world, "a", joint.a, allow_none=False)
    b = _check_body(world, "b", joint.b, allow_none=True)
    if b is not None and a.index == b.index:
        raise ValueError(f"a joint needs two different bodies, got a = b = body {a.name or a.index!r}")
    if a.is_static and (b is None or b.is_static):
        raise ValueError(
            f"a joint needs a dynamic body: a={a.name or a.index!r} is static and b="
            f"{'the world' if b is None else repr(b.name or b.index)} is {'fixed' if b is None else 'static'}"
        )
    anchor = joint.anchor
    if anchor is None:  # slider, fixed and planar joints: b's origin, or a's when b is the world
        anchor = (b if b is not None else a).position
    anchor_b = getattr(joint, "anchor_b", anchor)
    axis = getattr(joint, "normal", getattr(joint, "axis", None))
    if isinstance(joint, UniversalJoint):
        # The solver's body a carries the frame's x axis, its body b the y axis (made exactly perpendicular); joined
        # to the world, the world takes a's place (below) and carries axis_b.
        x, y = (joint.axis_a, joint.axis_b) if b is not None else (joint.axis_b, joint.axis_a)
        y = y - portable.dot(y, x) * x
        y /= portable.norm(y)
        frame = matrix_to_quat(np.column_stack([x, y, np.cross(x, y)]))
    else:
        frame = _frame_with_x_along(axis) if axis is not None else np.array([1.0, 0.0, 0.0, 0.0])
    if b is None:
        # Joined to the world: the world takes a's place in the solver (body -1), so that the angle or translation
        # is that of the body relative to the world, as a user reads it.
        a, b, anchor, anchor_b = None, a, anchor_b, anchor
    (xa, qa), (xb, qb) = _world_pose(world, a), _world_pose(world, b)
    d = joint.drive
    return JointSpec(
        kind=int(joint.kind),
        body_a=-1 if a is None else a.index,
        body_b=b.index,
        local_anchor_a=quat_rotate(quat_conjugate(qa), anchor - xa),
        local_anchor_b=quat_rotate(quat_conjugate(qb), anchor_b - xb),
        local_frame_a=quat_multiply(quat_conjugate(qa), frame),
        local_frame_b=quat_multiply(quat_conjugate(qb), frame),
        drive=np.array(
            [
                d.lower,
                d.upper,
                d.motor_speed,
                d.max_motor,
                d.spring_hertz,
                d.spring_damping_ratio,
                d.spring_target,
                d.cone,
                d.damping,
            ],
            np.float64,
        ),  # fmt: skip
        collide_connected=joint.collide_connected,
        to_world=a is None,
    )
