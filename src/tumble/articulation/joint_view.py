"""A named joint of an articulation, read and set as a World's joint handle is: ``art.joint("knee").angle``."""

from __future__ import annotations

import numpy as np

from .joints import Prismatic, Revolute

__all__ = ["ArticulationJoint"]


class ArticulationJoint:
    """A view of one link's joint (``Articulation.joint(name)``): ``angle`` and ``angular_speed`` of a
    ``Revolute`` [rad, rad/s], ``translation`` and ``speed`` of a ``Prismatic`` [m, m/s], settable; ``q`` and ``qd``
    of any joint (its rows of the articulation's state, copies). MuJoCo's coordinates: a hinge's angle is its ``qpos``
    (``ref`` at the model's pose)."""

    __slots__ = ("_art", "link", "name")

    def __init__(self, art, link: int, name: str) -> None:
        self._art, self.link, self.name = art, link, name

    @property
    def joint(self):
        """The joint type (``Revolute(axis)``, ``Prismatic(axis)``, ``Ball()``, ``Free()``)."""
        return self._art.links[self.link].joint

    @property
    def q(self) -> np.ndarray:
        return self._art.q[self._art.links[self.link].q_slice]

    @property
    def qd(self) -> np.ndarray:
        return self._art.qd[self._art.links[self.link].v_slice]

    def _scalar(self, kind, label: str) -> None:
        if not isinstance(self.joint, kind):
            raise AttributeError(f"joint {self.name!r} is a {self.joint!r}: {label} belongs to a {kind.__name__} "
                                 "joint; read q and qd instead")  # fmt: skip

    @property
    def angle(self) -> float:
        self._scalar(Revolute, "angle")
        return float(self.q[0])

    @angle.setter
    def angle(self, value) -> None:
        self._scalar(Revolute, "angle")
        self._art.set_joint(self.link, q=value)

    @property
    def angular_speed(self) -> float:
        self._scalar(Revolute, "angular_speed")
        return float(self.qd[0])

    @angular_speed.setter
    def angular_speed(self, value) -> None:
        self._scalar(Revolute, "angular_speed")
        self._art.set_joint(self.link, qd=value)

    @property
    def translation(self) -> float:
        self._scalar(Prismatic, "translation")
        return float(self.q[0])

    @translation.setter
    def translation(self, value) -> None:
        self._scalar(Prismatic, "translation")
        self._art.set_joint(self.link, q=value)

    @property
    def speed(self) -> float:
        self._scalar(Prismatic, "speed")
        return float(self.qd[0])

    @speed.setter
    def speed(self, value) -> None:
        self._scalar(Prismatic, "speed")
        self._art.set_joint(self.link, qd=value)

    def __repr__(self) -> str:
        return f"ArticulationJoint({self.name!r}, link={self.link}, {self.joint!r})"
