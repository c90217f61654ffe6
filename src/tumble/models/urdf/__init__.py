"""URDF, ROS's robot description: a file into a :class:`~tumble.models.description.ModelDescription` (``reader``),
which the MJCF builders turn into a World or an Articulation."""

from __future__ import annotations

from .reader import URDFError, URDFWarning, read_urdf

__all__ = ["URDFError", "URDFWarning", "read_urdf"]
