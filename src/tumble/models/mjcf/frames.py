"""MJCF's ways of writing an orientation, as unit quaternions ``(w, x, y, z)``; MuJoCo's rules.

An element gives at most one of ``quat``, ``axisangle``, ``euler``, ``xyaxes``, ``zaxis``. Angles are in the
``compiler``'s unit (degrees unless ``angle="radian"``); ``euler`` follows ``compiler eulerseq``: a lowercase axis
turns with the frame (intrinsic, the rotation multiplies on the right), an uppercase axis is fixed (extrinsic, on
the left). ``fromto`` places a capsule, cylinder, box or ellipsoid along a segment: its centre at the middle, its
local z axis along the segment.
"""

from __future__ import annotations

import numpy as np

from ... import portable
from ...rotation import matrix_to_quat, quat_from_axis_angle, quat_multiply

__all__ = ["ORIENTATIONS", "orientation", "quat_z_to"]

ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


def quat_z_to(direction: np.ndarray) -> np.ndarray:
    """The shortest rotation taking the z axis onto ``direction`` (half a turn about x when they are opposite)."""
    z = direction / portable.norm(direction)
    axis = np.cross((0.0, 0.0, 1.0), z)
    s = float(portable.norm(axis))
    if s < 1e-14:
        return np.array([1.0, 0.0, 0.0, 0.0]) if z[2] > 0 else np.array([0.0, 1.0, 0.0, 0.0])
    return quat_from_axis_angle(axis / s, portable.arctan2(s, z[2]))


def orientation(kind: str, values: np.ndarray, degrees: bool, eulerseq: str) -> np.ndarray:
    """The unit quaternion of one orientation attribute (``kind`` of :data:`ORIENTATIONS`) with its numbers.

    Raises:
        ValueError: a zero quaternion, axis or direction (the caller names the element and line).
    """
    scale = np.pi / 180.0 if degrees else 1.0
    if kind == "quat":
        norm = portable.norm(values)
        if norm == 0:
            raise ValueError("quat is zero")
        return values / norm
    if kind == "axisangle":
        if portable.norm(values[:3]) == 0:
            raise ValueError("the axis of axisangle is zero")
        return quat_from_axis_angle(values[:3] / portable.norm(values[:3]), values[3] * scale)
    if kind == "euler":
        quat = np.array([1.0, 0.0, 0.0, 0.0])
        for axis, angle in zip(eulerseq, values, strict=True):
            turn = quat_from_axis_angle(_AXES[axis.lower()], angle * scale)
            quat = quat_multiply(quat, turn) if axis.islower() else quat_multiply(turn, quat)
        return quat
    if kind == "xyaxes":
        x, y = values[:3], values[3:]
        if portable.norm(x) == 0:
            raise ValueError("the x axis of xyaxes is zero")
        x = x / portable.norm(x)
        y = y - portable.dot(x, y) * x
        if portable.norm(y) < 1e-14:
            raise ValueError("the y axis of xyaxes is parallel to x")
        y = y / portable.norm(y)
        return matrix_to_quat(np.column_stack([x, y, np.cross(x, y)]))
    if portable.norm(values) == 0:  # zaxis
        raise ValueError("zaxis is zero")
    return quat_z_to(values)
