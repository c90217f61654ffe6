"""An articulation living in a world: its links become bodies that collide, its joints world joints.

``World.add_articulation(art)`` copies an :class:`~tumble.articulation.Articulation` at its current ``q`` and
``qd`` into the world: every link becomes a dynamic body (its shape, its mass properties, placed at its link
frame), every joint the matching world joint (``Revolute`` → :class:`~tumble.HingeJoint`, ``Prismatic`` →
:class:`~tumble.SliderJoint`, ``Ball`` → :class:`~tumble.BallJoint`, ``Fixed`` → :class:`~tumble.FixedJoint`; a
``Free`` joint leaves the link free), and every loop closure a ball joint. From then on the world's soft step
moves it with everything else (maximal coordinates): links collide with other bodies and with each other
(except across a joint). The :class:`WorldArticulation` handle reads the joint coordinates ``q`` and ``qd``
back from the bodies in the articulation's own layout and applies joint forces. For the exact dynamics of
generalised coordinates (no joint drift, RK4), step the articulation on its own.
"""

from __future__ import annotations

import numpy as np

from ._validate import as_array
from .handles import Body, Joint
from .joints import BallJoint, FixedJoint, HingeJoint, SliderJoint
from .rotation import quat_conjugate, quat_multiply, quat_rotate

__all__ = ["WorldArticulation", "add_articulation"]


def _check(art) -> None:
    from .articulation import Articulation

    if not isinstance(art, Articulation):
        raise TypeError(f"articulation must be a tumble.articulation.Articulation, got {art!r} ({type(art).__name__})")
    if art.actuators:
        raise ValueError(
            f"the articulation has {len(art.actuators)} actuators: world joints have none; step the "
            "articulation on its own, or apply their forces (WorldArticulation.apply_joint_forces)"
        )
    if art.tendons or art.geoms:
        raise ValueError(f"the articulation has {len(art.tendons)} tendons and {len(art.geoms)} geoms: a world "
                         "collides its bodies' shapes, and its joints have no tendons; step the articulation on its "
                         "own")  # fmt: skip
    for link in art.links:
        label = link.name or link.index
        if link.limits is not None or link.frictionloss != 0.0:
            raise ValueError(f"link {label!r} has joint limits or frictionloss: an articulation's limits do not carry "
                             "over to world joints (yet); step the articulation on its own")  # fmt: skip
        if link.mass_properties is None or not link.mass_properties.mass > 0.0:
            raise ValueError(f"link {label!r} has no mass: every link of an articulation in a world becomes a body")
        for name in ("armature", "stiffness"):
            if getattr(link, name) != 0.0:
                raise ValueError(f"link {label!r} has joint {name} {getattr(link, name)!r}: world joints have none; "
                                 "step the articulation on its own")  # fmt: skip
        if link.damping != 0.0:
            raise ValueError(
                f"link {label!r} has joint damping {link.damping!r}: world joints have none; step the articulation "
                "on its own, or apply the damping as joint forces (WorldArticulation.apply_joint_forces)"
            )


def add_articulation(world, art) -> WorldArticulation:
    """Copy ``art`` at its current state into ``world`` (see the module docstring)."""
    from .articulation import Ball, Fixed, Free, Prismatic, Revolute

    _check(art)
    positions, quats = art.link_poses()
    linear, angular = art.link_velocities()
    bodies: list[Body] = []
    for link in art.links:
        shape = None if link.shape is None else [(link.shape, link.shape_position, link.shape_orientation)]
        com = positions[link.index] + quat_rotate(quats[link.index], link.mass_properties.com)
        bodies.append(
            world.add_body(
                shape,
                mass_properties=link.mass_properties,
                position=positions[link.index],
                orientation=quats[link.index],
                velocity=linear[link.index] + np.cross(angular[link.index], com - positions[link.index]),
                angular_velocity=angular[link.index],
                name=None if link.name is None else f"{art.name or 'articulation'}/{link.name}",
            )
        )
    joints: list[Joint | None] = []
    for link in art.links:
        child = bodies[link.index]
        parent = None if link.parent is None else bodies[link.parent]
        origin = positions[link.index]
        joint = link.joint
        if isinstance(joint, Free):
            joints.append(None)
            continue
        if isinstance(joint, (Revolute, Prismatic)):
            axis = quat_rotate(quats[link.index], joint.axis)
            a, b = (child, None) if parent is None else (parent, child)  # coordinates of the child either way
            if isinstance(joint, Revolute):
                description = HingeJoint(a, b, origin, axis)
            else:
                description = SliderJoint(a, b, axis, anchor=origin)
        elif isinstance(joint, Ball):
            description = BallJoint(child, parent, origin)
        elif isinstance(joint, Fixed):
            description = FixedJoint(child, parent, anchor=origin)
        else:  # pragma: no cover - every joint type is handled above
            raise TypeError(f"unknown joint type {joint!r}")
        joints.append(world.add_joint(description))
    closures = []
    for loop in art.loop_closures:
        point = positions[loop.link_a] + quat_rotate(quats[loop.link_a], loop.point_a)
        other = None if loop.link_b is None else bodies[loop.link_b]
        closures.append(world.add_joint(BallJoint(bodies[loop.link_a], other, point)))
    return WorldArticulation(world, art, bodies, joints, closures, art.q.copy())


class WorldArticulation:
    """The handle of an articulation in a world: its bodies and joints, and its coordinates read back.

    Attributes:
        articulation: the source :class:`~tumble.articulation.Articulation` (not changed by the world).
        bodies: one :class:`~tumble.Body` per link, in link order.
        joints: one :class:`~tumble.Joint` per link (``None`` for a ``Free`` link), in link order.
        loop_joints: the ball joints that close the loops.
    """

    def __init__(self, world, articulation, bodies, joints, loop_joints, q0: np.ndarray):
        self._world = world
        self.articulation = articulation
        self.bodies = list(bodies)
        self.joints = list(joints)
        self.loop_joints = list(loop_joints)
        self._q0 = q0

    def _parent_pose(self, link) -> tuple[np.ndarray, np.ndarray]:
        if link.parent is None:
            return self.articulation.base_position, self.articulation.base_orientation
        body = self.bodies[link.parent]
        return body.position, body.orientation

    @property
    def q(self) -> np.ndarray:
        """(nq,) the joint coordinates now, in the articulation's layout (from the bodies' poses)."""
        from .articulation import Ball, Free, Prismatic, Revolute

        q = np.zeros(self.articulation.nq)
        for link, body, joint in zip(self.articulation.links, self.bodies, self.joints, strict=True):
            rows = link.q_slice
            if isinstance(link.joint, Revolute):
                q[rows] = self._q0[rows] + joint.angle
            elif isinstance(link.joint, Prismatic):
                q[rows] = self._q0[rows] + joint.translation
            elif isinstance(link.joint, (Ball, Free)):
                parent_pos, parent_quat = self._parent_pose(link)
                relative = quat_multiply(quat_conjugate(parent_quat), body.orientation)
                if isinstance(link.joint, Ball):
                    q[rows] = _positive(quat_multiply(quat_conjugate(link.orientation), relative))
                else:
                    offset = quat_rotate(quat_conjugate(parent_quat), body.position - parent_pos)
                    q[rows] = np.concatenate([offset, _positive(relative)])
        return q

    @property
    def qd(self) -> np.ndarray:
        """(nv,) the joint velocities now, in the articulation's layout (from the bodies' velocities)."""
        from .articulation import Ball, Free, Prismatic, Revolute

        qd = np.zeros(self.articulation.nv)
        for link, body, joint in zip(self.articulation.links, self.bodies, self.joints, strict=True):
            rows = link.v_slice
            if isinstance(link.joint, Revolute):
                qd[rows] = joint.angular_speed
            elif isinstance(link.joint, Prismatic):
                qd[rows] = joint.speed
            elif isinstance(link.joint, (Ball, Free)):
                omega_parent, velocity_at_origin, parent_quat = self._parent_motion(link, body.position)
                omega = quat_rotate(quat_conjugate(body.orientation), body.angular_velocity - omega_parent)
                if isinstance(link.joint, Ball):
                    qd[rows] = omega
                else:
                    relative = body.point_velocity(body.position) - velocity_at_origin
                    qd[rows] = np.concatenate([quat_rotate(quat_conjugate(parent_quat), relative), omega])
        return qd

    def _parent_motion(self, link, point) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The parent's angular velocity, the velocity of its frame's point at ``point``, and its orientation."""
        if link.parent is None:
            return np.zeros(3), np.zeros(3), self.articulation.base_orientation
        parent = self.bodies[link.parent]
        return parent.angular_velocity, parent.point_velocity(point), parent.orientation

    def apply_joint_forces(self, tau) -> None:
        """Apply generalised forces ``tau`` (nv,) during the next step: a hinge's torque about its axis (and
        the opposite on the parent), a slider's force along its axis, a ball joint's torque (link frame), a free
        link's force (parent frame) and torque (link frame)."""
        from .articulation import Ball, Free, Prismatic, Revolute

        tau = as_array("tau", tau, (self.articulation.nv,), batch=False)
        for link, body in zip(self.articulation.links, self.bodies, strict=True):
            values = tau[link.v_slice]
            if not np.any(values):
                continue
            parent = None if link.parent is None else self.bodies[link.parent]
            if isinstance(link.joint, (Revolute, Prismatic)):
                axis = quat_rotate(body.orientation, link.joint.axis)
                load = axis * values[0]
                if isinstance(link.joint, Revolute):
                    body.apply_torque(load)
                    if parent is not None:
                        parent.apply_torque(-load)
                else:
                    body.apply_force(load, body.position)  # along the axis through the link origin
                    if parent is not None:
                        parent.apply_force(-load, body.position)
            elif isinstance(link.joint, Ball):
                torque = quat_rotate(body.orientation, values)
                body.apply_torque(torque)
                if parent is not None:
                    parent.apply_torque(-torque)
            elif isinstance(link.joint, Free):
                _, _, parent_quat = self._parent_motion(link, body.position)
                body.apply_force(quat_rotate(parent_quat, values[:3]), body.position)
                body.apply_torque(quat_rotate(body.orientation, values[3:]))

    def __repr__(self) -> str:
        return f"WorldArticulation({self.articulation.name or 'articulation'!r}, links={len(self.bodies)})"


def _positive(quat: np.ndarray) -> np.ndarray:
    """The same rotation with ``w >= 0`` (q and −q are one rotation)."""
    return -quat if quat[0] < 0.0 else quat
