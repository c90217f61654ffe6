"""Inverse dynamics (RNEA), the mass matrix (CRBA) and its sparse factorisation.

* RNEA, the recursive Newton–Euler algorithm (Featherstone 2008, §5.3): accelerations outwards from the base
  (gravity enters as a base acceleration ``-g``), then the forces each joint transmits inwards; the
  generalised force of a degree of freedom is ``Sᵀ f``.
* CRBA, the composite-rigid-body algorithm (§6.2): ``H_jk = S_jᵀ I^c_j S_k`` for ``k`` on the path from ``j``
  to the base, ``I^c`` the composite inertia of the subtree. World-frame spatial quantities make every
  composite a plain sum.
* LTDL (§6.5): ``H = Lᵀ D L`` following ``dof_parent``, so branches of the tree cost nothing; forward dynamics
  is ``H q̈ = τ - C(q, q̇)`` solved with it (§6.1; ``integrators.accelerations``).

The joints' own forces are part of the bias: ``C = RNEA(q, q̇, 0) + D q̇ + K (q - q_ref) - a(q, q̇)`` with ``D``
and ``K`` the diagonals of the damping and stiffness in ``dof_params`` and ``a`` the drive of the actuators at their
present controls, so inverse dynamics returns the joint force that produces ``q̈`` beside them. A joint's armature
(the reflected inertia of a motor's rotor, as in MuJoCo) adds to ``H``'s diagonal.
"""

from __future__ import annotations

from .._jit import inline
from ..math3d import add, cross, scale, sub
from .model import (
    ACC,
    ARMATURE,
    COMPOSITE,
    DAMPING,
    DOF_LINK,
    DOF_PARENT,
    FORCE,
    GRAVITY,
    INERTIA_WORLD,
    PARENT,
    POS,
    Q_START,
    SPRINGREF,
    STIFFNESS,
    V_START,
    VEL,
    VEL_PRODUCT,
)
from .spatial import (
    ZERO3,
    add6,
    cross_force,
    dot6,
    get3,
    get4,
    get6,
    get10,
    inertia_add,
    inertia_apply,
    put6,
    put10,
    scale6,
    vec3,
)

__all__ = ["crba", "dl_solve", "lt_solve", "ltdl_factor", "ltdl_solve", "rnea"]

# A pivot below this fraction of the largest diagonal entry means a degree of freedom moves no mass:
# float64 rounding leaves ~1e-16 relative, a real model's lightest link is far above 1e-12.
SINGULAR_RTOL = 1e-12


@inline
def _dof_stop(link_ints, i, v_count):
    """One past the last row of ``qd`` of link ``i``'s joint."""
    return link_ints[i + 1, V_START] if i + 1 < link_ints.shape[0] else v_count


@inline
def joint_energies(link_ints, dof_params, q, qd):
    """``(½ Σ armature q̇², ½ Σ stiffness (q - springref)²)``: the kinetic energy of the joints' rotors and the
    potential energy of their springs, beside the links' own (``kinematics.energies``)."""
    kinetic, potential = 0.0, 0.0
    n, nv = link_ints.shape[0], qd.shape[0]
    for i in range(n):
        first = link_ints[i, V_START]
        for k in range(first, _dof_stop(link_ints, i, nv)):
            kinetic += 0.5 * dof_params[k, ARMATURE] * qd[k] * qd[k]
            if dof_params[k, STIFFNESS] != 0.0:
                stretch = q[link_ints[i, Q_START] + k - first] - dof_params[k, SPRINGREF]
                potential += 0.5 * dof_params[k, STIFFNESS] * stretch * stretch
    return kinetic, potential


@inline
def joint_force(dof_params, k, q_value, qd_value):
    """The joint's own force against degree of freedom ``k``: ``damping q̇ + stiffness (q - springref)`` (springs
    only on a hinge or slide, whose coordinate ``q_value`` is its own; elsewhere the stiffness is zero)."""
    return passive_force(get4(dof_params, k, 0), q_value, qd_value)


@inline(into_callers=True)
def passive_force(params, q_value, qd_value):
    """:func:`joint_force` from the row ``params = (damping, armature, stiffness, springref)`` of ``dof_params``."""
    force = params[DAMPING] * qd_value
    if params[STIFFNESS] != 0.0:
        force += params[STIFFNESS] * (q_value - params[SPRINGREF])
    return force


@inline
def rnea(link_ints, world, dof_params, link_work, dof_motion, q, qd, qdd, external, use_external, out):
    """``out = H q̈ + C + D q̇ + K (q - q_ref)``: the generalised forces (nv,) that give the accelerations ``qdd``
    (``H`` with the joints' armature on its diagonal; ``D``, ``K``: the joints' damping and springs).

    Args:
        link_work: (n, 51) after :func:`~.kinematics.forward_kinematics`; writes ``ACC`` and ``FORCE``.
        dof_motion: (nv, 6); qd, qdd: (nv,).
        external: (n, 6) world-frame rows (force [N] at the link's centre of mass, torque [N m]), read only if
            ``use_external``.
        out: (nv,) generalised forces.
    """
    n, nv = link_ints.shape[0], dof_motion.shape[0]
    base_acc = (ZERO3, scale(vec3(world, GRAVITY), -1.0))
    for i in range(n):
        parent = link_ints[i, PARENT]
        acc = add6(base_acc if parent < 0 else get6(link_work, parent, ACC), get6(link_work, i, VEL_PRODUCT))
        for k in range(link_ints[i, V_START], _dof_stop(link_ints, i, nv)):
            acc = add6(acc, scale6(get6(dof_motion, k, 0), qdd[k]))
        put6(link_work, i, ACC, acc)
        inertia, vel = get10(link_work, i, INERTIA_WORLD), get6(link_work, i, VEL)
        force = add6(inertia_apply(inertia, acc), cross_force(vel, inertia_apply(inertia, vel)))
        if use_external:
            # a force f at the centre of mass c has the moment c × f about the origin
            applied = get3(external, i, 0)
            mass = inertia[0]
            com = scale((inertia[1], inertia[2], inertia[3]), 1.0 / mass) if mass > 0.0 else get3(link_work, i, POS)
            force = (sub(add(force[0], cross(applied, com)), get3(external, i, 3)), sub(force[1], applied))
        put6(link_work, i, FORCE, force)
    for i in range(n - 1, -1, -1):
        force = get6(link_work, i, FORCE)
        first = link_ints[i, V_START]
        for k in range(first, _dof_stop(link_ints, i, nv)):
            spring_q = q[link_ints[i, Q_START] + k - first]
            out[k] = (dot6(get6(dof_motion, k, 0), force) + joint_force(dof_params, k, spring_q, qd[k])
                      + dof_params[k, ARMATURE] * qdd[k])  # fmt: skip
        parent = link_ints[i, PARENT]
        if parent >= 0:
            put6(link_work, parent, FORCE, add6(get6(link_work, parent, FORCE), force))


@inline
def crba(link_ints, dof_ints, dof_params, link_work, dof_motion, h):
    """The joint-space inertia matrix ``H`` into ``h`` (nv, nv): the entries of every pair of degrees of
    freedom on one path to the base (both triangles), the joints' armature on the diagonal; the others are left
    as they were (zero in ``H``).

    Reads ``link_work[:, INERTIA_WORLD]`` and ``dof_motion``; writes ``link_work[:, COMPOSITE]``.
    """
    n = link_ints.shape[0]
    for i in range(n):
        put10(link_work, i, COMPOSITE, get10(link_work, i, INERTIA_WORLD))
    for i in range(n - 1, -1, -1):
        parent = link_ints[i, PARENT]
        if parent >= 0:
            put10(link_work, parent, COMPOSITE, inertia_add(get10(link_work, parent, COMPOSITE),
                                                            get10(link_work, i, COMPOSITE)))  # fmt: skip
    for j in range(dof_motion.shape[0]):
        # the momentum of the subtree moving with S_j, projected on every motion axis towards the base
        momentum = inertia_apply(get10(link_work, dof_ints[j, DOF_LINK], COMPOSITE), get6(dof_motion, j, 0))
        k = j
        while k >= 0:
            value = dot6(get6(dof_motion, k, 0), momentum)
            h[j, k] = value
            h[k, j] = value
            k = dof_ints[k, DOF_PARENT]
        h[j, j] += dof_params[j, ARMATURE]


@inline
def ltdl_factor(dof_ints, h, diag):
    """Factor ``h`` (nv, nv) in place as ``Lᵀ D L`` (Featherstone 2008, Table 6.3); returns -1 or a bad row.

    The strict lower triangle becomes ``L``'s (unit diagonal implied), the diagonal ``D``. Fill-in stays on
    the paths to the base, so only entries ``(k, i)`` with ``i`` an ancestor of ``k`` are read or written.
    A pivot that is not positive, relative to the largest diagonal entry, means the matrix is singular: the
    index of that row is returned (its degree of freedom moves no mass). ``diag`` (nv,) keeps ``H``'s
    diagonal.
    """
    nv = h.shape[0]
    largest = 0.0
    for k in range(nv):
        diag[k] = h[k, k]
        largest = max(largest, h[k, k])
    for k in range(nv - 1, -1, -1):
        pivot = h[k, k]
        if not pivot > SINGULAR_RTOL * largest:
            return k
        i = dof_ints[k, DOF_PARENT]
        while i >= 0:
            a = h[k, i] / pivot
            j = i
            while j >= 0:
                h[i, j] -= a * h[k, j]
                j = dof_ints[j, DOF_PARENT]
            h[k, i] = a
            i = dof_ints[i, DOF_PARENT]
    return -1


@inline
def ltdl_solve(dof_ints, h, x):
    """Solve ``Lᵀ D L x = b`` in place (``x`` holds ``b`` on entry), ``h`` from :func:`ltdl_factor` (Table 6.4)."""
    lt_solve(dof_ints, h, x)
    dl_solve(dof_ints, h, x)


@inline
def lt_solve(dof_ints, h, x):
    """The first half of :func:`ltdl_solve`: ``x ← L⁻ᵀ x``. Only the ancestors of ``x``'s non-zero entries become
    non-zero, so a sparse ``x`` (a constraint's Jacobian) stays sparse."""
    nv = h.shape[0]
    for i in range(nv - 1, -1, -1):
        if x[i] == 0.0:
            continue
        j = dof_ints[i, DOF_PARENT]
        while j >= 0:
            x[j] -= h[i, j] * x[i]
            j = dof_ints[j, DOF_PARENT]


@inline
def dl_solve(dof_ints, h, x):
    """The second half of :func:`ltdl_solve`: ``x ← L⁻¹ D⁻¹ x``."""
    nv = h.shape[0]
    for i in range(nv):
        x[i] /= h[i, i]
    for i in range(nv):
        j = dof_ints[i, DOF_PARENT]
        while j >= 0:
            x[i] -= h[i, j] * x[j]
            j = dof_ints[j, DOF_PARENT]
