"""Forward dynamics of a tree by the articulated-body algorithm (Featherstone 2008, §7.3, Table 7.1).

``O(n)``: after the kinematics pass, one sweep inwards builds each link's articulated-body inertia ``I^A`` and
bias force ``p^A`` (the subtree as it feels to a force applied at the link, joints free), and one sweep
outwards gives the accelerations. In world coordinates at the world origin, as everywhere here, the
coordinate transforms of the textbook are identities. Per degree of freedom, with ``S`` its motion column:

    U = I^A S,  D = Sᵀ U + a,  u = τ - d q̇ - k (q - q_r) - Sᵀ p^A
                                        (a: armature, d: damping, k, q_r: the joint's spring)
    I^A ← I^A - U Uᵀ / D,   p^A ← p^A + U u / D            then, for the parent:
    I^A_λ += I^A,   p^A_λ += p^A + I^A c                    (c: the joint's velocity product)
    a' = a_λ + c,   q̈ = (u - Uᵀ a') / D,   a ← a' + S q̈    (outwards; a_base = -g)

A joint of several degrees of freedom (ball, free) is handled as a chain of one-degree-of-freedom joints
through massless links, eliminated last to first on the way in and solved first to last on the way out:
the same block elimination as ``D⁻¹`` of the textbook, with scalars only. ``I^A`` is stored as the 21
numbers of its symmetric blocks ``[[A, B], [Bᵀ, C]]``: ``A`` and ``C`` as ``(xx, yy, zz, xy, xz, yz)``, ``B``
row-major. Loop closures need ``H`` itself, so articulations with loops use the CRBA path instead.
"""

from __future__ import annotations

from .._jit import inline
from ..math3d import add, scale
from .dynamics import SINGULAR_RTOL, passive_force
from .model import (
    ACC,
    ARMATURE,
    ART_BIAS,
    ART_INERTIA,
    ART_STORED,
    GRAVITY,
    INERTIA_WORLD,
    PARENT,
    Q_START,
    V_START,
    VEL,
    VEL_PRODUCT,
)
from .spatial import (
    ZERO3,
    ZERO6,
    add6,
    cross_force,
    dot6,
    get3,
    get4,
    get6,
    get10,
    inertia_apply,
    put6,
    scale6,
    sub6,
    vec3,
)

__all__ = [
    "aba",
    "add_articulated",
    "dof_inwards",
    "dof_outwards",
    "eliminate_dof",
    "handed_bias",
    "link_articulated",
    "pivot_scale",
]

_ZERO21 = (0.0,) * 21


@inline(into_callers=True)
def _from_inertia(inertia):
    """The 21 numbers of the 6x6 matrix of a spatial inertia ``(m, h, I_O)``: ``A = I_O``, ``B = [h]×``, ``C = m E``."""
    m, hx, hy, hz = inertia[0], inertia[1], inertia[2], inertia[3]
    return (
        inertia[4], inertia[5], inertia[6], inertia[7], inertia[8], inertia[9],
        0.0, -hz, hy, hz, 0.0, -hx, -hy, hx, 0.0,
        m, m, m, 0.0, 0.0, 0.0,
    )  # fmt: skip


@inline(into_callers=True)
def _apply(a, v):
    """``I^A v`` for the 21-number articulated inertia ``a`` and a spatial vector ``v``."""
    w, x = v[0], v[1]
    ang = (
        a[0] * w[0] + a[3] * w[1] + a[4] * w[2] + a[6] * x[0] + a[7] * x[1] + a[8] * x[2],
        a[3] * w[0] + a[1] * w[1] + a[5] * w[2] + a[9] * x[0] + a[10] * x[1] + a[11] * x[2],
        a[4] * w[0] + a[5] * w[1] + a[2] * w[2] + a[12] * x[0] + a[13] * x[1] + a[14] * x[2],
    )
    lin = (
        a[6] * w[0] + a[9] * w[1] + a[12] * w[2] + a[15] * x[0] + a[18] * x[1] + a[19] * x[2],
        a[7] * w[0] + a[10] * w[1] + a[13] * w[2] + a[18] * x[0] + a[16] * x[1] + a[20] * x[2],
        a[8] * w[0] + a[11] * w[1] + a[14] * w[2] + a[19] * x[0] + a[20] * x[1] + a[17] * x[2],
    )
    return (ang, lin)


@inline(into_callers=True)
def _downdate(a, u, f):
    """``I^A - f U Uᵀ`` (21 numbers) for the spatial vector ``U``."""
    p, q = u[0], u[1]
    return (
        a[0] - f * p[0] * p[0], a[1] - f * p[1] * p[1], a[2] - f * p[2] * p[2],
        a[3] - f * p[0] * p[1], a[4] - f * p[0] * p[2], a[5] - f * p[1] * p[2],
        a[6] - f * p[0] * q[0], a[7] - f * p[0] * q[1], a[8] - f * p[0] * q[2],
        a[9] - f * p[1] * q[0], a[10] - f * p[1] * q[1], a[11] - f * p[1] * q[2],
        a[12] - f * p[2] * q[0], a[13] - f * p[2] * q[1], a[14] - f * p[2] * q[2],
        a[15] - f * q[0] * q[0], a[16] - f * q[1] * q[1], a[17] - f * q[2] * q[2],
        a[18] - f * q[0] * q[1], a[19] - f * q[0] * q[2], a[20] - f * q[1] * q[2],
    )  # fmt: skip


@inline
def _get21(array, i, c):
    return (
        array[i, c], array[i, c + 1], array[i, c + 2], array[i, c + 3], array[i, c + 4], array[i, c + 5],
        array[i, c + 6], array[i, c + 7], array[i, c + 8], array[i, c + 9], array[i, c + 10], array[i, c + 11],
        array[i, c + 12], array[i, c + 13], array[i, c + 14], array[i, c + 15], array[i, c + 16],
        array[i, c + 17], array[i, c + 18], array[i, c + 19], array[i, c + 20],
    )  # fmt: skip


@inline
def _put21(array, i, c, a):
    for k in range(21):
        array[i, c + k] = a[k]


@inline
def _external_force(external, i, inertia):
    """The spatial force (at the world origin) of row ``i`` of ``external``: a force at the centre of mass and a
    torque, world frame."""
    applied = get3(external, i, 0)
    mass = inertia[0]
    com = scale((inertia[1], inertia[2], inertia[3]), 1.0 / mass) if mass > 0.0 else ZERO3
    moment = add(get3(external, i, 3), (com[1] * applied[2] - com[2] * applied[1],
                                        com[2] * applied[0] - com[0] * applied[2],
                                        com[0] * applied[1] - com[1] * applied[0]))  # fmt: skip
    return (moment, applied)


@inline(into_callers=True)
def pivot_scale(largest, own):
    """The scale of the pivots so far, with a link of spatial inertia ``own``: the largest mass or moment about the
    origin."""
    return max(largest, own[0], own[4], own[5], own[6])


@inline(into_callers=True)
def link_articulated(own, vel):
    """A link's own articulated inertia (21 numbers) and bias force ``v ×_f I v``, before its children's."""
    return _from_inertia(own), cross_force(vel, inertia_apply(own, vel))


@inline(into_callers=True)
def dof_inwards(inertia, bias, s, params, tau, spring_q, rate):
    """``(U, D, u)`` of a degree of freedom (motion column ``s``, its row ``params`` of ``dof_params``, force ``tau``,
    its joint's coordinate ``spring_q`` and its rate) under the articulated inertia and bias so far."""
    u_vec = _apply(inertia, s)
    pivot = dot6(s, u_vec) + params[ARMATURE]
    return u_vec, pivot, tau - passive_force(params, spring_q, rate) - dot6(s, bias)


@inline(into_callers=True)
def eliminate_dof(inertia, bias, u_vec, pivot, u):
    """``I^A - U Uᵀ / D`` and ``p^A + U u / D``: the degree of freedom made free."""
    return _downdate(inertia, u_vec, 1.0 / pivot), add6(bias, scale6(u_vec, u / pivot))


@inline(into_callers=True)
def handed_bias(inertia, bias, product):
    """The bias force a link hands its parent: ``p^A + I^A c`` (``c`` its velocity product)."""
    return add6(bias, _apply(inertia, product))


@inline(into_callers=True)
def dof_outwards(acc, u_vec, s, pivot, u):
    """``(q̈, a + S q̈)`` of a degree of freedom from the acceleration ``acc`` so far."""
    qdd = (u - dot6(u_vec, acc)) / pivot
    return qdd, add6(acc, scale6(s, qdd))


@inline(counted=False)
def aba(link_ints, world, dof_params, link_work, dof_motion, dof_u, dof_pivot, q, qd, tau, external, use_external,
        qdd):  # fmt: skip
    """``q̈`` (nv,) into ``qdd`` for the joint forces ``tau`` (nv,); returns -1 or the row of a singular pivot.

    Args:
        link_work: (n, width) after :func:`~.kinematics.forward_kinematics`; uses ``ART_INERTIA``,
            ``ART_BIAS``, ``ART_STORED``, ``ACC``.
        dof_motion: (nv, 6) ``S``; dof_u: (nv, 6) scratch for ``U``; dof_pivot: (nv,) scratch for ``D``.
        q: (nq,), qd: (nv,); external: (n, 6) world-frame rows (force at the link's centre of mass, torque), read if
            ``use_external``. ``qdd`` holds ``u`` between the two sweeps.
    """
    n, nv = link_ints.shape[0], dof_motion.shape[0]
    largest = 0.0  # the scale of the pivots: the largest mass or moment about the origin
    for i in range(n):
        largest = pivot_scale(largest, get10(link_work, i, INERTIA_WORLD))
        link_work[i, ART_STORED] = 0.0
    # inwards: articulated inertias and bias forces, one degree of freedom at a time. A link hands its
    # articulated inertia and bias to its parent in registers when the parent is the next link of the sweep
    # (along a chain), else through link_work[parent, ART_INERTIA / ART_BIAS] (ART_STORED marks them set).
    carried_inertia, carried_bias, carried_to = _ZERO21, ZERO6, -1
    for i in range(n - 1, -1, -1):
        first = link_ints[i, V_START]
        stop = link_ints[i + 1, V_START] if i + 1 < n else nv
        parent = link_ints[i, PARENT]
        own = get10(link_work, i, INERTIA_WORLD)
        inertia, bias = link_articulated(own, get6(link_work, i, VEL))
        if use_external:
            bias = sub6(bias, _external_force(external, i, own))
        if carried_to == i:
            inertia, bias = add_articulated(inertia, carried_inertia), add6(bias, carried_bias)
        if link_work[i, ART_STORED] > 0.0:
            inertia = add_articulated(inertia, _get21(link_work, i, ART_INERTIA))
            bias = add6(bias, get6(link_work, i, ART_BIAS))
        for k in range(stop - 1, first - 1, -1):
            s = get6(dof_motion, k, 0)
            spring_q = q[link_ints[i, Q_START] + k - first]
            u_vec, pivot, u = dof_inwards(inertia, bias, s, get4(dof_params, k, 0), tau[k], spring_q, qd[k])
            if not pivot > SINGULAR_RTOL * largest:
                return k
            put6(dof_u, k, 0, u_vec)
            dof_pivot[k] = pivot
            qdd[k] = u
            if k > first or parent >= 0:
                inertia, bias = eliminate_dof(inertia, bias, u_vec, pivot, u)
        carried_to = -1
        if parent < 0:
            continue
        bias = handed_bias(inertia, bias, get6(link_work, i, VEL_PRODUCT))
        if parent == i - 1:
            carried_inertia, carried_bias, carried_to = inertia, bias, parent
        elif link_work[parent, ART_STORED] > 0.0:
            _put21(link_work, parent, ART_INERTIA, add_articulated(_get21(link_work, parent, ART_INERTIA), inertia))
            put6(link_work, parent, ART_BIAS, add6(get6(link_work, parent, ART_BIAS), bias))
        else:
            _put21(link_work, parent, ART_INERTIA, inertia)
            put6(link_work, parent, ART_BIAS, bias)
            link_work[parent, ART_STORED] = 1.0
    # outwards: accelerations
    base_acc = (ZERO3, scale(vec3(world, GRAVITY), -1.0))
    for i in range(n):
        parent = link_ints[i, PARENT]
        acc = add6(base_acc if parent < 0 else get6(link_work, parent, ACC), get6(link_work, i, VEL_PRODUCT))
        stop = link_ints[i + 1, V_START] if i + 1 < n else nv
        for k in range(link_ints[i, V_START], stop):
            qdd[k], acc = dof_outwards(acc, get6(dof_u, k, 0), get6(dof_motion, k, 0), dof_pivot[k], qdd[k])
        put6(link_work, i, ACC, acc)
    return -1


@inline(into_callers=True)
def add_articulated(a, b):
    """The sum of two articulated inertias (21 numbers each)."""
    return (
        a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3], a[4] + b[4], a[5] + b[5], a[6] + b[6],
        a[7] + b[7], a[8] + b[8], a[9] + b[9], a[10] + b[10], a[11] + b[11], a[12] + b[12], a[13] + b[13],
        a[14] + b[14], a[15] + b[15], a[16] + b[16], a[17] + b[17], a[18] + b[18], a[19] + b[19], a[20] + b[20],
    )  # fmt: skip
