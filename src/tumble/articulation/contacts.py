"""Contacts in generalised coordinates, as MuJoCo makes them: the geoms' contacts, and their soft-constraint rows.

Each pair of geoms that may touch (``model.pair_*``, filtered as MuJoCo filters them: ``geoms.py``) is tested at the
state's link poses. A contact is MuJoCo's (its ``mjc_*`` collision functions): the point midway between the two
surfaces, the normal from geom A to geom B, the signed distance, kept while the distance is below the pair's margin.
The primitives the locomotion models use are collided: a sphere or a capsule (as the spheres at its ends) on a plane,
and spheres and capsules with each other (at their closest points).

A contact is a soft constraint on the relative velocity at its point, ``J = J_B(p) - J_A(p)`` through the tree, solved
with the limits (``constraints.solve_constraints``). With ``condim`` 1 it is one row along the normal; with 3 it is
MuJoCo's pyramid, four rows ``J_n ± μ J_t1``, ``J_n ± μ J_t2`` whose forces are at least zero, the tangents from the
normal as ``mju_makeFrame`` makes them. Every row takes the contact's distance less its margin for its impedance and
reference acceleration, and the pair's weight for its regulariser (MuJoCo documentation, *Computation*: "Contact").
"""

from __future__ import annotations

import math

from .._jit import inline
from ..math3d import add, cross, dot, length3, quat_mul, quat_rotate, scale, sub
from .constraints import soft_row
from .model import (
    CAPSULE,
    CONTACT_DIST,
    CONTACT_NORMAL,
    CONTACT_PAIR,
    CONTACT_POINT,
    CONTACT_TANGENT,
    DOF_PARENT,
    DOF_TIP,
    EFC_FORCE,
    EFC_SCALAR,
    GEOM_LINK,
    GEOM_POS,
    GEOM_QUAT,
    GEOM_SIZE,
    GEOM_TYPE,
    PAIR_A,
    PAIR_B,
    PAIR_CONDIM,
    PAIR_FRICTION,
    PAIR_MARGIN,
    PAIR_SOLIMP,
    PAIR_SOLREF,
    PAIR_WEIGHT,
    PLANE,
    POS,
    QUAT,
    SPHERE,
)
from .spatial import vec3

__all__ = ["contact_rows", "contact_wrenches", "find_contacts"]


@inline
def _geom_pose(m, link_work, g):
    """World pose of geom ``g``: its link's frame composed with the geom's pose in it (a world geom's own)."""
    local_pos = vec3(m.geom_reals[g], GEOM_POS)
    local_quat = (m.geom_reals[g, GEOM_QUAT], m.geom_reals[g, GEOM_QUAT + 1], m.geom_reals[g, GEOM_QUAT + 2],
                  m.geom_reals[g, GEOM_QUAT + 3])  # fmt: skip
    link = m.geom_ints[g, GEOM_LINK]
    if link < 0:
        return local_pos, local_quat
    link_pos = vec3(link_work[link], POS)
    link_quat = (link_work[link, QUAT], link_work[link, QUAT + 1], link_work[link, QUAT + 2],
                 link_work[link, QUAT + 3])  # fmt: skip
    return add(link_pos, quat_rotate(link_quat, local_pos)), quat_mul(link_quat, local_quat)


@inline
def _segment(m, g, pos, quat):
    """The ends of a capsule's segment (a sphere's centre twice)."""
    if m.geom_ints[g, GEOM_TYPE] != CAPSULE:
        return pos, pos
    axis = quat_rotate(quat, (0.0, 0.0, m.geom_reals[g, GEOM_SIZE + 1]))
    return sub(pos, axis), add(pos, axis)


@inline
def _put(contacts, count, k, point, normal, distance, tangent):
    row = contacts[count]
    for i in range(3):
        row[CONTACT_POINT + i] = point[i]
        row[CONTACT_NORMAL + i] = normal[i]
        row[CONTACT_TANGENT + i] = tangent[i]
    row[CONTACT_DIST], row[CONTACT_PAIR] = distance, k
    return count + 1


@inline
def _balls(contacts, count, k, a, radius_a, b, radius_b, margin):
    """Two spheres: the normal from ``a`` to ``b`` (up when the centres coincide)."""
    gap = sub(b, a)
    length = length3(gap)
    normal = scale(gap, 1.0 / length) if length > 1e-15 else (0.0, 0.0, 1.0)
    distance = length - radius_a - radius_b
    if distance >= margin:
        return count
    point = add(a, scale(normal, radius_a + 0.5 * distance))
    return _put(contacts, count, k, point, normal, distance, (0.0, 0.0, 0.0))


@inline
def _closest_on_segment(p0, p1, x):
    d = sub(p1, p0)
    length2 = dot(d, d)
    t = 0.0 if length2 <= 0.0 else min(max(dot(sub(x, p0), d) / length2, 0.0), 1.0)
    return add(p0, scale(d, t))


@inline
def _closest_between_segments(p0, p1, q0, q1):
    """The closest points of two segments (Ericson, *Real-Time Collision Detection*, 2005, §5.1.9)."""
    d1, d2, r = sub(p1, p0), sub(q1, q0), sub(p0, q0)
    a, e, f = dot(d1, d1), dot(d2, d2), dot(d2, r)
    if a <= 1e-30 and e <= 1e-30:
        return p0, q0
    if a <= 1e-30:
        return p0, add(q0, scale(d2, min(max(f / e, 0.0), 1.0)))
    c = dot(d1, r)
    if e <= 1e-30:
        return add(p0, scale(d1, min(max(-c / a, 0.0), 1.0))), q0
    b = dot(d1, d2)
    denominator = a * e - b * b
    s = min(max((b * f - c * e) / denominator, 0.0), 1.0) if denominator > 1e-30 * a * e else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        t, s = 0.0, min(max(-c / a, 0.0), 1.0)
    elif t > 1.0:
        t, s = 1.0, min(max((b - c) / a, 0.0), 1.0)
    return add(p0, scale(d1, s)), add(q0, scale(d2, t))


@inline
def _pose(poses, g):
    return (poses[g, 0], poses[g, 1], poses[g, 2]), (poses[g, 3], poses[g, 4], poses[g, 5], poses[g, 6])


@inline
def _reach(m, g):
    """A sphere about a geom's centre that holds it (a plane has none: -1)."""
    kind = m.geom_ints[g, GEOM_TYPE]
    if kind == PLANE:
        return -1.0
    return m.geom_reals[g, GEOM_SIZE] + (m.geom_reals[g, GEOM_SIZE + 1] if kind == CAPSULE else 0.0)


@inline(counted=False)
def find_contacts(m, w):
    """The contacts of every pair at the link poses in ``w.link_work`` into ``w.contact_work``; returns their count."""
    contacts, poses = w.contact_work, w.geom_pose
    for g in range(m.geom_ints.shape[0]):
        pos, quat = _geom_pose(m, w.link_work, g)
        for i in range(3):
            poses[g, i] = pos[i]
        for i in range(4):
            poses[g, 3 + i] = quat[i]
    count = 0
    for k in range(m.pair_ints.shape[0]):
        ga, gb = m.pair_ints[k, PAIR_A], m.pair_ints[k, PAIR_B]
        margin = m.pair_reals[k, PAIR_MARGIN]
        pos_a, quat_a = _pose(poses, ga)
        pos_b, quat_b = _pose(poses, gb)
        reach_a = _reach(m, ga)
        if reach_a >= 0.0 and length3(sub(pos_b, pos_a)) > reach_a + _reach(m, gb) + margin:
            continue  # their bounding spheres are apart
        radius_b = m.geom_reals[gb, GEOM_SIZE]
        b0, b1 = _segment(m, gb, pos_b, quat_b)
        if m.geom_ints[ga, GEOM_TYPE] == PLANE:  # mjc_PlaneSphere, and mjc_PlaneCapsule's two end spheres
            normal = quat_rotate(quat_a, (0.0, 0.0, 1.0))
            capsule = m.geom_ints[gb, GEOM_TYPE] == CAPSULE
            # a capsule's contacts take their first tangent along its axis
            tangent = quat_rotate(quat_b, (0.0, 0.0, 1.0)) if capsule else (0.0, 0.0, 0.0)
            for end in range(2 if capsule else 1):
                centre = b0 if end == 0 else b1
                distance = dot(sub(centre, pos_a), normal) - radius_b
                if distance < margin:
                    point = sub(centre, scale(normal, radius_b + 0.5 * distance))
                    count = _put(contacts, count, k, point, normal, distance, tangent)
            continue
        radius_a = m.geom_reals[ga, GEOM_SIZE]
        a0, a1 = _segment(m, ga, pos_a, quat_a)
        if m.geom_ints[ga, GEOM_TYPE] == SPHERE:
            count = _balls(contacts, count, k, a0, radius_a, _closest_on_segment(b0, b1, a0), radius_b, margin)
        else:
            near_a, near_b = _closest_between_segments(a0, a1, b0, b1)
            count = _balls(contacts, count, k, near_a, radius_a, near_b, radius_b, margin)
    return count


@inline
def _frame(normal, hint):
    """MuJoCo's tangents of a contact frame (``mju_makeFrame``): ``hint`` (or, when it is shorter than 0.5, y, or z
    for a normal near y) made normal to it, then n × t₁."""
    guess = hint
    if length3(hint) < 0.5:
        guess = (0.0, 1.0, 0.0) if abs(normal[1]) < 0.5 else (0.0, 0.0, 1.0)
    t1 = sub(guess, scale(normal, dot(normal, guess)))
    t1 = scale(t1, 1.0 / length3(t1))
    return t1, cross(normal, t1)


@inline
def _add_point_jacobian(m, w, link, point, direction, sign, row):
    """``row += sign · directionᵀ J_link(point)``: the velocity of ``point`` carried by ``link`` along ``direction``."""
    if link < 0:
        return
    k = m.link_ints[link, DOF_TIP]
    motion = w.dof_motion
    while k >= 0:
        angular = (motion[k, 0], motion[k, 1], motion[k, 2])
        linear = add((motion[k, 3], motion[k, 4], motion[k, 5]), cross(angular, point))
        row[k] += sign * dot(direction, linear)
        k = m.dof_ints[k, DOF_PARENT]


@inline
def _relative_jacobian(m, w, ga, gb, point, direction, row):
    for k in range(row.shape[0]):
        row[k] = 0.0
    _add_point_jacobian(m, w, m.geom_ints[gb, GEOM_LINK], point, direction, 1.0, row)
    _add_point_jacobian(m, w, m.geom_ints[ga, GEOM_LINK], point, direction, -1.0, row)


@inline(counted=False)
def contact_rows(m, w, found, count, qd, h):
    """The constraint rows of the ``found`` contacts after the ``count`` rows already in ``w.efc_*``; returns the
    new count."""
    jac, contacts = w.efc_jac, w.contact_work
    for c in range(found):
        k = int(contacts[c, CONTACT_PAIR])
        pair = m.pair_reals[k]
        ga, gb = m.pair_ints[k, PAIR_A], m.pair_ints[k, PAIR_B]
        point = vec3(contacts[c], CONTACT_POINT)
        normal = vec3(contacts[c], CONTACT_NORMAL)
        distance, margin, weight = contacts[c, CONTACT_DIST], pair[PAIR_MARGIN], pair[PAIR_WEIGHT]
        refs, imps = pair[PAIR_SOLREF : PAIR_SOLREF + 2], pair[PAIR_SOLIMP : PAIR_SOLIMP + 5]
        if m.pair_ints[k, PAIR_CONDIM] == 1:
            _relative_jacobian(m, w, ga, gb, point, normal, jac[count])
            count = soft_row(w, count, -1 - c, distance, margin, refs, imps, weight, 0.0, math.inf, h, qd)
            continue
        t1, t2 = _frame(normal, vec3(contacts[c], CONTACT_TANGENT))
        _relative_jacobian(m, w, ga, gb, point, normal, jac[count + 1])
        _relative_jacobian(m, w, ga, gb, point, t1, jac[count + 2])
        _relative_jacobian(m, w, ga, gb, point, t2, jac[count + 3])
        mu = pair[PAIR_FRICTION]
        for i in range(qd.shape[0]):  # the pyramid's edges J_n ± μ J_t
            along, first, second = jac[count + 1, i], jac[count + 2, i], jac[count + 3, i]
            jac[count, i], jac[count + 1, i] = along + mu * first, along - mu * first
            jac[count + 2, i], jac[count + 3, i] = along + mu * second, along - mu * second
        for _ in range(4):
            count = soft_row(w, count, -1 - c, distance, margin, refs, imps, weight, 0.0, math.inf, h, qd)
    return count


@inline
def contact_wrenches(m, w, out, column):
    """Add each link's contact wrench (world axes, about the world origin: moment, then force) to ``out[link,
    column : column + 6]`` from the forces of the last solve (its ``w.efc_count`` rows).

    A contact's force on geom B is ``Σfᵢ n + μ (f₀ - f₁) t₁ + μ (f₂ - f₃) t₂`` over its pyramid's rows (MuJoCo
    documentation, *Computation*: "Contact"), acting at the contact point; geom A takes the opposite.
    """
    e, contacts = w.efc_work, w.contact_work
    rows = int(w.efc_count[0])
    r = 0
    while r < rows:
        scalar = e[EFC_SCALAR, r]
        if scalar >= 0.0:
            r += 1
            continue
        c = int(-1.0 - scalar)
        k = int(contacts[c, CONTACT_PAIR])
        normal = vec3(contacts[c], CONTACT_NORMAL)
        if m.pair_ints[k, PAIR_CONDIM] == 1:
            force = scale(normal, e[EFC_FORCE, r])
            r += 1
        else:
            f0, f1, f2, f3 = e[EFC_FORCE, r], e[EFC_FORCE, r + 1], e[EFC_FORCE, r + 2], e[EFC_FORCE, r + 3]
            t1, t2 = _frame(normal, vec3(contacts[c], CONTACT_TANGENT))
            mu = m.pair_reals[k, PAIR_FRICTION]
            force = add(scale(normal, f0 + f1 + f2 + f3), add(scale(t1, mu * (f0 - f1)), scale(t2, mu * (f2 - f3))))
            r += 4
        moment = cross(vec3(contacts[c], CONTACT_POINT), force)
        for geom, sign in ((m.pair_ints[k, PAIR_B], 1.0), (m.pair_ints[k, PAIR_A], -1.0)):
            link = m.geom_ints[geom, GEOM_LINK]
            if link >= 0:
                for i in range(3):
                    out[link, column + i] += sign * moment[i]
                    out[link, column + 3 + i] += sign * force[i]
