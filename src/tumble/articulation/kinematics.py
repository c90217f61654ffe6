"""Forward kinematics of the tree, the configuration update, and the energies.

One pass from the base outwards (parents come before children) gives every link's pose, the world-frame
motion subspace ``S`` of each degree of freedom, the spatial velocity ``v_i = v_λ + S q̇`` and the
velocity-product acceleration ``c_i = Ṡ q̇`` (Featherstone 2008, §3.2 and §5.3, here in world coordinates).
``S`` columns that are fixed in the link move with ``v_i``, so they contribute ``v_i ×ₘ (S q̇)``; the linear
columns of a free joint are fixed in the parent and contribute ``v_λ ×ₘ (S q̇)``.

Quaternion coordinates (ball and free joints) are updated on the group: ``q ← q ⊗ exp(½ ω h)`` with ``ω`` the
link-frame angular velocity, which keeps them unit (up to rounding; they are renormalised).
"""

from __future__ import annotations

import math

from .. import elementary
from .._jit import inline
from ..math3d import (
    add,
    add_scaled,
    cross,
    dot,
    mat_column,
    quat_exp,
    quat_mul,
    quat_normalize,
    quat_rotate,
    quat_to_mat33,
)
from .joints import JointType
from .model import (
    AXIS,
    BASE_POS,
    BASE_QUAT,
    COM,
    GRAVITY,
    INERTIA,
    INERTIA_WORLD,
    JOINT,
    MASS,
    ORIGIN_POS,
    ORIGIN_QUAT,
    PARENT,
    POS,
    Q_START,
    QUAT,
    V_START,
    VEL,
    VEL_PRODUCT,
)
from .spatial import (
    ZERO3,
    ZERO6,
    add6,
    cross_motion,
    get3,
    get4,
    get6,
    get9,
    get10,
    inertia_world,
    kinetic_energy,
    put3,
    put4,
    put6,
    put10,
    scale6,
    vec3,
    vec4,
)

__all__ = [
    "axis_angle_quat",
    "axis_angle_quat_near",
    "energies",
    "forward_kinematics",
    "integrate_configuration",
    "joint_quat",
    "link_inertia",
    "one_dof_link",
    "quat_exp",
]

_REVOLUTE = int(JointType.REVOLUTE)
_PRISMATIC = int(JointType.PRISMATIC)
_BALL = int(JointType.BALL)
_FREE = int(JointType.FREE)
_NO_TURN = (1.0, 0.0, 0.0, 0.0)


@inline
def joint_quat(q, start):
    """The unit quaternion stored at ``q[start:start + 4]``."""
    return quat_normalize((q[start], q[start + 1], q[start + 2], q[start + 3]))


@inline
def axis_angle_quat(axis, angle):
    """The unit quaternion of a turn by ``angle`` about the unit ``axis``."""
    if not math.isfinite(angle):  # as in quat_exp
        return (math.nan, math.nan, math.nan, math.nan)
    s = elementary.sin(0.5 * angle)
    return (elementary.cos(0.5 * angle), axis[0] * s, axis[1] * s, axis[2] * s)


@inline(into_callers=True)
def axis_angle_quat_near(axis, angle):
    """:func:`axis_angle_quat` for a finite ``|angle| <= 2 elementary.SIN_COS_RANGE``, the same bits without a
    branch (``elementary.sin_cos``): for loops over many copies that vectorise."""
    s, c = elementary.sin_cos(0.5 * angle)
    return (c, axis[0] * s, axis[1] * s, axis[2] * s)


@inline
def _rotation_dof(dof_motion, k, pos, a):
    """Store and return the motion subspace of a rotation about the unit world axis ``a`` through ``pos``."""
    s = (a, cross(pos, a))
    put6(dof_motion, k, 0, s)
    return s


@inline(counted=False)
def forward_kinematics(link_ints, link_reals, world, q, qd, link_work, dof_motion):
    """Poses, motion subspaces, velocities, velocity products and spatial inertias of all links.

    Args:
        link_ints, link_reals, world: the model (``model.py``).
        q: (nq,) coordinates; qd: (nv,) velocities.
        link_work: (n, 51), writes ``POS``, ``QUAT``, ``VEL``, ``VEL_PRODUCT``, ``INERTIA_WORLD``.
        dof_motion: (nv, 6), writes every column ``S``.
    """
    base_pos, base_quat = vec3(world, BASE_POS), vec4(world, BASE_QUAT)
    for i in range(link_ints.shape[0]):
        parent = link_ints[i, PARENT]
        if parent < 0:
            parent_pos, parent_quat, parent_vel = base_pos, base_quat, ZERO6
        else:
            parent_pos, parent_quat = get3(link_work, parent, POS), get4(link_work, parent, QUAT)
            parent_vel = get6(link_work, parent, VEL)
        kind, qs, vs = link_ints[i, JOINT], link_ints[i, Q_START], link_ints[i, V_START]
        axis = get3(link_reals, i, AXIS)
        # the link frame in the parent frame
        rel_pos, rel_quat = get3(link_reals, i, ORIGIN_POS), get4(link_reals, i, ORIGIN_QUAT)
        if kind == _REVOLUTE or kind == _PRISMATIC:
            turn = axis_angle_quat(axis, q[qs]) if kind == _REVOLUTE else _NO_TURN
            pos, quat, s, vel, product = one_dof_link(kind, parent_pos, parent_quat, parent_vel, rel_pos, rel_quat,
                                                      axis, turn, q[qs], qd[vs])  # fmt: skip
            _store_link(link_reals, link_work, i, pos, quat, vel, product)
            put6(dof_motion, vs, 0, s)
            continue
        if kind == _BALL:
            rel_quat = quat_mul(rel_quat, joint_quat(q, qs))
        elif kind == _FREE:
            rel_pos, rel_quat = (q[qs], q[qs + 1], q[qs + 2]), joint_quat(q, qs + 3)
        quat = quat_mul(parent_quat, rel_quat)
        pos = add(parent_pos, quat_rotate(parent_quat, rel_pos))
        # the joint's velocity; its columns fixed in the link turn with the link's velocity
        vel, product = parent_vel, ZERO6
        if kind == _BALL or kind == _FREE:
            first = vs
            if kind == _FREE:
                # the linear columns are fixed in the parent: they turn with the parent's velocity
                parent_axes = quat_to_mat33(parent_quat)
                moving_parent = ZERO6
                for k in range(3):
                    s = (ZERO3, mat_column(parent_axes, k))
                    put6(dof_motion, vs + k, 0, s)
                    moving_parent = add6(moving_parent, scale6(s, qd[vs + k]))
                vel = add6(vel, moving_parent)
                product = cross_motion(parent_vel, moving_parent)
                first = vs + 3
            axes = quat_to_mat33(quat)
            moving_link = ZERO6
            for k in range(3):
                s = _rotation_dof(dof_motion, first + k, pos, mat_column(axes, k))
                moving_link = add6(moving_link, scale6(s, qd[first + k]))
            vel = add6(vel, moving_link)
            product = add6(product, cross_motion(vel, moving_link))
        _store_link(link_reals, link_work, i, pos, quat, vel, product)


@inline(into_callers=True)
def one_dof_link(kind, parent_pos, parent_quat, parent_vel, rel_pos, rel_quat, axis, turn, coordinate, rate):
    """``(pos, quat, S, vel, product)`` of a link on a hinge (``kind`` revolute, ``turn`` its
    :func:`axis_angle_quat`) or a slide: the pose, the world-frame motion column, the spatial velocity
    ``v_λ + S q̇`` and the velocity product ``v ×ₘ S q̇`` (``S`` is fixed in the link and turns with it)."""
    if kind == _REVOLUTE:
        rel_quat = quat_mul(rel_quat, turn)
    else:
        rel_pos = add_scaled(rel_pos, quat_rotate(rel_quat, axis), coordinate)
    quat = quat_mul(parent_quat, rel_quat)
    pos = add(parent_pos, quat_rotate(parent_quat, rel_pos))
    if kind == _REVOLUTE:
        a = quat_rotate(quat, axis)
        s = (a, cross(pos, a))
    else:
        s = (ZERO3, quat_rotate(quat, axis))
    joint_vel = scale6(s, rate)
    vel = add6(parent_vel, joint_vel)
    return pos, quat, s, vel, cross_motion(vel, joint_vel)


@inline(into_callers=True)
def link_inertia(link_reals, i, pos, quat):
    """Link ``i``'s spatial inertia at the pose ``(pos, quat)``."""
    return inertia_world(link_reals[i, MASS], get3(link_reals, i, COM), get9(link_reals, i, INERTIA), pos, quat)


@inline
def _store_link(link_reals, link_work, i, pos, quat, vel, product):
    put3(link_work, i, POS, pos)
    put4(link_work, i, QUAT, quat)
    put6(link_work, i, VEL, vel)
    put6(link_work, i, VEL_PRODUCT, product)
    put10(link_work, i, INERTIA_WORLD, link_inertia(link_reals, i, pos, quat))


@inline
def energies(world, link_work):
    """``(kinetic, potential)`` energy [J] from the last :func:`forward_kinematics` pass.

    The potential is ``-g · Σ m c``: zero with every centre of mass at the world origin.
    """
    kinetic = 0.0
    first_moment = ZERO3
    for i in range(link_work.shape[0]):
        inertia = get10(link_work, i, INERTIA_WORLD)
        kinetic += kinetic_energy(inertia, get6(link_work, i, VEL))
        first_moment = add(first_moment, (inertia[1], inertia[2], inertia[3]))
    return kinetic, -dot(vec3(world, GRAVITY), first_moment)


@inline(counted=False)
def integrate_configuration(link_ints, q, v, h, out):
    """``out = q ⊕ h v``: advance the coordinates ``q`` (nq,) by the velocity ``v`` (nv,) for ``h`` seconds.

    Angles and displacements add; quaternions turn by ``exp(½ ω h)`` on the right (``ω`` in the link frame).
    ``out`` may be ``q`` itself.
    """
    for i in range(link_ints.shape[0]):
        kind, qs, vs = link_ints[i, JOINT], link_ints[i, Q_START], link_ints[i, V_START]
        if kind == _REVOLUTE or kind == _PRISMATIC:
            out[qs] = q[qs] + h * v[vs]
        elif kind == _BALL or kind == _FREE:
            if kind == _FREE:
                for k in range(3):
                    out[qs + k] = q[qs + k] + h * v[vs + k]
                qs += 3
                vs += 3
            turned = quat_normalize(quat_mul(joint_quat(q, qs), quat_exp((v[vs], v[vs + 1], v[vs + 2]), h)))
            for k in range(4):
                out[qs + k] = turned[k]
