"""Joint types of an articulation: how a link moves relative to its parent.

Each joint owns ``nq`` position coordinates and ``nv`` velocity coordinates (``nq != nv`` where a quaternion
is involved, as in MuJoCo). The link frame is the joint frame; the axes of ``Revolute`` and ``Prismatic`` are
unit vectors in that frame.

=============  ====  ====  =========================================================================
joint          nq    nv    coordinates
=============  ====  ====  =========================================================================
``Fixed``      0     0     none: the link is welded to its parent at its origin pose
``Revolute``   1     1     angle [rad] about ``axis``; velocity [rad/s]
``Prismatic``  1     1     displacement [m] along ``axis``; velocity [m/s]
``Ball``       4     3     q: unit quaternion relative to the origin orientation; qd: angular velocity
                           [rad/s] relative to the parent, in the link frame
``Free``       7     6     q: position [m] and unit quaternion of the link frame in the parent frame;
                           qd: linear velocity [m/s] of the link origin in the parent frame, then angular
                           velocity [rad/s] relative to the parent in the link frame
=============  ====  ====  =========================================================================
"""

from __future__ import annotations

from enum import IntEnum

import numpy as np

from .._validate import as_unit_vector3

__all__ = ["Ball", "Fixed", "Free", "Joint", "JointType", "Prismatic", "Revolute"]


class JointType(IntEnum):
    """The joint codes stored in the model arrays (``link_joint_type``)."""

    FIXED = 0
    REVOLUTE = 1
    PRISMATIC = 2
    BALL = 3
    FREE = 4


def _unit_axis(axis) -> np.ndarray:
    unit = as_unit_vector3("axis", axis)
    unit.flags.writeable = False
    return unit


class Joint:
    """Base class of the joint types; immutable."""

    __slots__ = ()
    type: JointType
    nq: int
    nv: int

    def __setattr__(self, name, value):
        raise AttributeError(f"{type(self).__name__} is immutable; cannot set {name!r}")

    def __eq__(self, other) -> bool:
        return type(other) is type(self) and np.array_equal(getattr(self, "axis", 0), getattr(other, "axis", 0))

    def __hash__(self) -> int:
        return hash((type(self).__name__, tuple(np.ravel(getattr(self, "axis", ())).tolist())))

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class _AxisJoint(Joint):
    __slots__ = ("_axis",)
    nq = 1
    nv = 1

    def __init__(self, axis) -> None:
        object.__setattr__(self, "_axis", _unit_axis(axis))

    @property
    def axis(self) -> np.ndarray:
        """(3,) float64, unit length, in the link (joint) frame (read-only array)."""
        return self._axis

    def __repr__(self) -> str:
        return f"{type(self).__name__}(axis={self._axis.tolist()!r})"


class Revolute(_AxisJoint):
    """A hinge: rotation ``q`` [rad] about ``axis`` through the link origin (right-hand rule)."""

    __slots__ = ()
    type = JointType.REVOLUTE


class Prismatic(_AxisJoint):
    """A slider: translation ``q`` [m] along ``axis``."""

    __slots__ = ()
    type = JointType.PRISMATIC


class Ball(Joint):
    """A spherical joint about the link origin: 4 coordinates (a unit quaternion), 3 velocities."""

    __slots__ = ()
    type = JointType.BALL
    nq = 4
    nv = 3


class Free(Joint):
    """Six degrees of freedom: position and quaternion (7 coordinates), linear and angular velocity (6)."""

    __slots__ = ()
    type = JointType.FREE
    nq = 7
    nv = 6


class Fixed(Joint):
    """No motion: the link is rigidly attached to its parent."""

    __slots__ = ()
    type = JointType.FIXED
    nq = 0
    nv = 0
