"""The articulation as flat arrays: the model (what it *is*) and the work buffers of one evaluation.

Everything lives in three contiguous buffers: ``ints`` (int64) and ``reals`` (float64) for the model, ``work``
(float64) for what an evaluation computes. :func:`model_views` and :func:`work_views` carve them into a few
wide 2-D arrays, one row per link (or degree of freedom, or loop closure) and named column offsets, as
MuJoCo's ``jnt_*``/``body_*`` arrays. Few, wide arrays keep every call cheap: Numba unboxes each array
argument of a kernel called from Python, and copies and reference-counts each array passed between compiled
functions, so forty narrow arrays would cost more than a whole step of a small chain.

Index conventions: links are numbered in the order they were added, so ``link_ints[i, PARENT] < i`` (``-1``
is the base). Degrees of freedom (rows of ``qd``) are numbered the same way, and ``dof_ints[k, DOF_PARENT]
< k`` is the previous degree of freedom on the path to the base (``-1`` at the base): the tree structure
that the sparse factorisation of the mass matrix follows (Featherstone 2008, §6.5).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._jit import inline

__all__ = ["Model", "Work", "counts", "model_views", "pack_model", "python_function", "work_size", "work_views"]

# link_ints columns
PARENT, JOINT, Q_START, V_START, DOF_TIP = 0, 1, 2, 3, 4
LINK_INT_WIDTH = 5
# link_reals columns: joint axis (link frame), origin pose in the parent frame, mass, centre of mass and
# inertia about it (link frame, row-major 3x3)
AXIS, ORIGIN_POS, ORIGIN_QUAT, MASS, COM, INERTIA = 0, 3, 6, 10, 11, 14
LINK_REAL_WIDTH = 23
# dof_ints columns
DOF_PARENT, DOF_LINK = 0, 1
# world entries
GRAVITY, BASE_POS, BASE_QUAT = 0, 3, 6
WORLD_WIDTH = 10
# loop_ints / loop_reals columns
LINK_A, LINK_B = 0, 1
POINT_A, POINT_B = 0, 3

# link_work columns: world pose, spatial velocity, velocity-product acceleration, spatial acceleration and
# transmitted force (6 each), spatial inertia of the link and of its subtree (10 each); the articulated-body
# inertia (21: a symmetric 6x6) and bias force (6) that children hand to the link in the ABA, and whether
# they did (1.0) or not (0.0)
POS, QUAT, VEL, VEL_PRODUCT, ACC, FORCE, INERTIA_WORLD, COMPOSITE = 0, 3, 7, 13, 19, 25, 31, 41
ART_INERTIA, ART_BIAS, ART_STORED = 51, 72, 78
LINK_WORK_WIDTH = 79
# dof_params columns: the joint's passive terms on each degree of freedom
DAMPING, ARMATURE, STIFFNESS, SPRINGREF = 0, 1, 2, 3
DOF_PARAM_WIDTH = 4
# scalar_reals columns: a scalar is a joint's coordinate or a fixed tendon, ``L = scalar_q · q`` and
# ``L̇ = scalar_v · q̇`` (constraints.py). Its limits (LIMITED 1.0 or 0.0, LOWER, UPPER, MARGIN and MuJoCo's solref (2)
# and solimp (5) of the limit), its dry friction (FRICTIONLOSS and its solref, solimp), ``INVWEIGHT`` (MuJoCo's
# ``invweight0``: ``J H⁻¹ Jᵀ`` at the initial coordinates), and a tendon's spring and damper (a joint's own are in
# dof_params)
LIMITED, LOWER, UPPER, MARGIN, LIMIT_SOLREF, LIMIT_SOLIMP = 0, 1, 2, 3, 4, 6
FRICTIONLOSS, FRICTION_SOLREF, FRICTION_SOLIMP, INVWEIGHT = 11, 12, 14, 19
TENDON_STIFFNESS, TENDON_SPRINGLENGTH, TENDON_DAMPING = 20, 21, 22
# a joint's scalar is one coordinate: its rows of q and qd (-1 for a tendon), read without the dense coefficients
JOINT_Q, JOINT_V = 23, 24
SCALAR_WIDTH = 25
# act_reals columns: an actuator on scalar ``act_ints[a, 0]`` pulls along ``l = GEAR · L`` with the force
# ``FORCE0 + BIAS_LENGTH l + BIAS_SPEED l̇`` (FORCE0 = gain · clipped control + bias₀), clipped to
# ``[FORCE_LOW, FORCE_HIGH]``
GEAR, FORCE0, BIAS_LENGTH, BIAS_SPEED, FORCE_LOW, FORCE_HIGH = 0, 1, 2, 3, 4, 5
ACT_WIDTH = 6
# geom_ints / geom_reals columns: a collision geom on a link (-1: the world), MuJoCo's primitive type and size
# (sphere: radius; capsule: radius, half length along z; plane: its normal is z), its pose in the link frame
GEOM_LINK, GEOM_TYPE = 0, 1
GEOM_INT_WIDTH = 2
GEOM_SIZE, GEOM_POS, GEOM_QUAT = 0, 3, 6
GEOM_REAL_WIDTH = 10
PLANE, SPHERE, CAPSULE = 0, 2, 3  # MuJoCo's mjtGeom numbers
GEOM_POSE_WIDTH = 7
# pair_ints / pair_reals columns: two geoms that may touch (geom A's type <= geom B's), the contact's dimension (1: no
# friction, 3: a pyramid of four edges), and MuJoCo's mixed settings: friction, margin, solref (2), solimp (5) and the
# regulariser's weight (``diagApprox``: both bodies' ``invweight0``, and for a pyramid ``2 μ² (1 + μ²) / impratio``)
PAIR_A, PAIR_B, PAIR_CONDIM = 0, 1, 2
PAIR_INT_WIDTH = 3
PAIR_FRICTION, PAIR_MARGIN, PAIR_SOLREF, PAIR_SOLIMP, PAIR_WEIGHT = 0, 1, 2, 4, 9
PAIR_REAL_WIDTH = 10
# contact_work columns: a contact's point (world), normal (from geom A to B), distance, pair, and the direction its
# first tangent is made from (zero: MuJoCo's default)
CONTACT_POINT, CONTACT_NORMAL, CONTACT_DIST, CONTACT_PAIR, CONTACT_TANGENT = 0, 3, 6, 7, 8
CONTACT_WIDTH = 11
# dof_work rows
BIAS, RHS, QDD, DIAG, QD_START, QD_STAGE, QDD_SUM, QD_SUM, CHART, APPLIED = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9
DOF_WORK_ROWS = 10
# loop_work rows
LOOP_RHS, LOOP_LAMBDA, LOOP_ACTIVE, LOOP_ERROR = 0, 1, 2, 3
LOOP_WORK_ROWS = 4
# efc_work rows, one column per constraint row (at most three a scalar: its friction and its two limits; four a
# contact): the scalar (or -1 - contact), MuJoCo's reference acceleration and regulariser R, the force's bounds,
# the force, and ``J q̈_smooth - aref``
EFC_SCALAR, EFC_AREF, EFC_R, EFC_LOW, EFC_HIGH, EFC_FORCE, EFC_OFFSET = 0, 1, 2, 3, 4, 5, 6
# and the solver's (dual_solver.py): the diagonal of J H⁻¹ Jᵀ, and the pivoting's state of each row (0 free, -1 at
# its lower bound, 1 at its upper) and its force
EFC_DIAG, EFC_STATE, EFC_TRIAL = 7, 8, 9
EFC_WORK_ROWS = 10

# ints[0:9] = link_count, q_count, v_count, loop_count, scalar_count, actuator_count, geom_count, pair_count and
# the contacts the pairs can make at most
_HEADER = 9


class Model(NamedTuple):
    """What the articulation is. ``n`` links, ``nv`` degrees of freedom, ``L`` loop closures.

    Attributes:
        link_ints: (n, 5) int64: ``PARENT`` (-1: the base), ``JOINT`` (a
            :class:`~tumble.articulation.joints.JointType`), ``Q_START``/``V_START`` (first row of the joint in
            ``q``/``qd``), ``DOF_TIP`` (the last degree of freedom at or above the link; -1: none).
        link_reals: (n, 23) float64: ``AXIS`` (3, unit, link frame), ``ORIGIN_POS`` (3) [m] and ``ORIGIN_QUAT``
            (4): the link frame in the parent frame at zero displacement; ``MASS`` [kg]; ``COM`` (3) [m] and
            ``INERTIA`` (9) [kg m²] about it, link frame.
        dof_ints: (nv, 2) int64: ``DOF_PARENT`` (-1: none) and ``DOF_LINK``.
        dof_params: (nv, 4): ``DAMPING`` [N m s/rad or N s/m], ``ARMATURE`` (a rotor's inertia added to the
            degree of freedom's own, [kg m²] or [kg]), ``STIFFNESS`` [N m/rad or N/m] and ``SPRINGREF`` (the
            spring's rest coordinate) of the joint: the force ``-damping q̇ - stiffness (q - springref)``.
        world: (10,): ``GRAVITY`` (3) [m/s²], ``BASE_POS`` (3) [m], ``BASE_QUAT`` (4).
        loop_ints: (L, 2) int64: ``LINK_A``, ``LINK_B`` (-1: the world).
        loop_reals: (L, 6): ``POINT_A``, ``POINT_B`` [m], in the frames of link a and link b (or the world).
        scalar_q: (S, nq), scalar_v: (S, nv): each scalar's coefficients (a joint's or a fixed tendon's length).
        scalar_reals: (S, 25): its limits, dry friction, tendon spring and joint rows (the columns above).
        act_ints: (A, 1) int64: each actuator's scalar; act_reals: (A, 6): its force law (the columns above).
        geom_ints: (G, 2) int64, geom_reals: (G, 10): the collision geoms; pair_ints: (P, 3) int64, pair_reals:
            (P, 10): the pairs that may touch (the columns above).
    """

    link_ints: np.ndarray
    link_reals: np.ndarray
    dof_ints: np.ndarray
    dof_params: np.ndarray
    world: np.ndarray
    loop_ints: np.ndarray
    loop_reals: np.ndarray
    scalar_q: np.ndarray
    scalar_v: np.ndarray
    scalar_reals: np.ndarray
    act_ints: np.ndarray
    act_reals: np.ndarray
    geom_ints: np.ndarray
    geom_reals: np.ndarray
    pair_ints: np.ndarray
    pair_reals: np.ndarray


class Work(NamedTuple):
    """What an evaluation computes; world frame throughout.

    Spatial vectors are Featherstone's (2008, ch. 2): 6 numbers ``(angular, linear)`` taken at the world
    origin. A spatial inertia is 10 numbers ``(m, m c, I_O)`` with ``I_O`` the rotational inertia about the
    world origin stored as ``(xx, yy, zz, xy, xz, yz)``.

    Attributes:
        link_work: (n, 79): ``POS`` (3) [m], ``QUAT`` (4), ``VEL``, ``VEL_PRODUCT`` (the acceleration ``Ṡ q̇``
            the joint adds), ``ACC``, ``FORCE`` (transmitted by the joint, RNEA) (6 each), ``INERTIA_WORLD``,
            ``COMPOSITE`` (of the subtree, CRBA) (10 each), ``ART_INERTIA`` (21), ``ART_BIAS`` (6) and
            ``ART_STORED`` (ABA).
        dof_motion: (nv, 6): the motion subspace column of each degree of freedom.
        dof_u: (nv, 6): the ABA's ``U = I^A S`` column of each degree of freedom.
        mass_matrix: (nv, nv): the joint-space inertia matrix, or its LTDL factor after factorisation.
        dof_work: (10, nv): rows ``BIAS``, ``RHS``, ``QDD``, ``DIAG`` (``H``'s diagonal, or the ABA's pivots),
            the integrator's ``QD_START``, ``QD_STAGE``, ``QDD_SUM``, ``QD_SUM``, ``CHART``, and ``APPLIED`` (the
            joint forces with the actuators' and tendons').
        q_start, q_stage: (nq,): the integrator's coordinates at the start of a step and at an RK4 stage.
        loop_jac, loop_minv_jt: (3L, nv): the closure Jacobian ``J`` and ``(H⁻¹ Jᵀ)ᵀ``.
        loop_matrix: (3L, 3L): ``J H⁻¹ Jᵀ`` or its factor.
        loop_work: (4, 3L): rows ``LOOP_RHS`` (γ), ``LOOP_LAMBDA``, ``LOOP_ACTIVE``, ``LOOP_ERROR`` (φ).
        energy: (2,) [J]: kinetic and potential.
        efc_count: (1,): the number of constraint rows of the last solve (``integrators.accelerations``).
        contact_work: (C, 11): the contacts found (the ``CONTACT_*`` columns), C the most the pairs can make.
        efc_jac: (rows, nv): the Jacobian of each active constraint row, rows = 3S + 4C, turned into ``L⁻ᵀ Jᵀ`` (``H =
            Lᵀ D L``) in place by the solve; efc_factor: (nv, nv): the pivoting's Cholesky factor; efc_z: (nv,): ``Σ fᵢ
            L⁻ᵀ Jᵢᵀ``; efc_inverse_pivots: (nv,): ``D⁻¹``; efc_work: (10, rows): the rows' data (``EFC_*``).
        geom_pose: (G, 7): each geom's world position and quaternion at the state.
    """

    link_work: np.ndarray
    dof_motion: np.ndarray
    dof_u: np.ndarray
    mass_matrix: np.ndarray
    dof_work: np.ndarray
    q_start: np.ndarray
    q_stage: np.ndarray
    loop_jac: np.ndarray
    loop_minv_jt: np.ndarray
    loop_matrix: np.ndarray
    loop_work: np.ndarray
    energy: np.ndarray
    efc_count: np.ndarray
    contact_work: np.ndarray
    efc_jac: np.ndarray
    efc_factor: np.ndarray
    efc_z: np.ndarray
    efc_inverse_pivots: np.ndarray
    efc_work: np.ndarray
    geom_pose: np.ndarray


def _int_size(n: int, nv: int, loops: int, actuators: int, geoms: int, pairs: int) -> int:
    return (_HEADER + LINK_INT_WIDTH * n + 2 * nv + 2 * loops + actuators + GEOM_INT_WIDTH * geoms
            + PAIR_INT_WIDTH * pairs)  # fmt: skip


def _real_size(n: int, nq: int, nv: int, loops: int, scalars: int, actuators: int, geoms: int, pairs: int) -> int:
    return (WORLD_WIDTH + LINK_REAL_WIDTH * n + DOF_PARAM_WIDTH * nv + 6 * loops + scalars * (nq + nv + SCALAR_WIDTH)
            + ACT_WIDTH * actuators + GEOM_REAL_WIDTH * geoms + PAIR_REAL_WIDTH * pairs)  # fmt: skip


def work_size(n: int, nq: int, nv: int, loops: int, scalars: int, contacts: int, geoms: int) -> int:
    """The length of the work buffer that :func:`work_views` carves."""
    nc, nr = 3 * loops, 3 * scalars + 4 * contacts
    return (LINK_WORK_WIDTH * n + 12 * nv + nv * nv + DOF_WORK_ROWS * nv + 2 * nq + 2 * nc * nv + nc * nc + 4 * nc + 3
            + CONTACT_WIDTH * contacts + nr * nv + nv * nv + 2 * nv + EFC_WORK_ROWS * nr
            + GEOM_POSE_WIDTH * geoms)  # fmt: skip


@inline
def _rows(buffer, start, count, width):
    """``buffer[start:start + count * width]`` seen as a (count, width) C-contiguous array, without a copy.

    (``reshape`` is a runtime call in Numba, about 40 ns; ``as_strided`` is free but types the view as
    non-contiguous, which makes the kernels 40 % slower.)
    """
    return buffer[start : start + count * width].reshape((count, width))


@inline
def model_views(ints, reals):
    """Carve ``ints`` and ``reals`` into a :class:`Model` of views (no copies)."""
    n, nq, nv, nl, ns, na, ng, npairs = ints[0], ints[1], ints[2], ints[3], ints[4], ints[5], ints[6], ints[7]
    i = _HEADER
    link_ints = _rows(ints, i, n, LINK_INT_WIDTH)
    i += LINK_INT_WIDTH * n
    dof_ints = _rows(ints, i, nv, 2)
    i += 2 * nv
    loop_ints = _rows(ints, i, nl, 2)
    i += 2 * nl
    act_ints = _rows(ints, i, na, 1)
    i += na
    geom_ints = _rows(ints, i, ng, GEOM_INT_WIDTH)
    i += GEOM_INT_WIDTH * ng
    pair_ints = _rows(ints, i, npairs, PAIR_INT_WIDTH)
    r = WORLD_WIDTH
    link_reals = _rows(reals, r, n, LINK_REAL_WIDTH)
    r += LINK_REAL_WIDTH * n
    dof_params = _rows(reals, r, nv, DOF_PARAM_WIDTH)
    r += DOF_PARAM_WIDTH * nv
    loop_reals = _rows(reals, r, nl, 6)
    r += 6 * nl
    scalar_q = _rows(reals, r, ns, nq)
    r += ns * nq
    scalar_v = _rows(reals, r, ns, nv)
    r += ns * nv
    scalar_reals = _rows(reals, r, ns, SCALAR_WIDTH)
    r += ns * SCALAR_WIDTH
    act_reals = _rows(reals, r, na, ACT_WIDTH)
    r += na * ACT_WIDTH
    geom_reals = _rows(reals, r, ng, GEOM_REAL_WIDTH)
    r += ng * GEOM_REAL_WIDTH
    pair_reals = _rows(reals, r, npairs, PAIR_REAL_WIDTH)
    return Model(link_ints, link_reals, dof_ints, dof_params, reals[0:WORLD_WIDTH], loop_ints, loop_reals, scalar_q,
                 scalar_v, scalar_reals, act_ints, act_reals, geom_ints, geom_reals, pair_ints, pair_reals)  # fmt: skip


@inline
def work_views(work, n, nq, nv, nl, ns, ncontacts, ngeoms):
    """Carve ``work`` into a :class:`Work` of views."""
    nc, nr = 3 * nl, 3 * ns + 4 * ncontacts
    link_work = _rows(work, 0, n, LINK_WORK_WIDTH)
    w = LINK_WORK_WIDTH * n
    dof_motion = _rows(work, w, nv, 6)
    dof_u = _rows(work, w + 6 * nv, nv, 6)
    w += 12 * nv
    mass_matrix = _rows(work, w, nv, nv)
    w += nv * nv
    dof_work = _rows(work, w, DOF_WORK_ROWS, nv)
    w += DOF_WORK_ROWS * nv
    q_start, q_stage = work[w : w + nq], work[w + nq : w + 2 * nq]
    w += 2 * nq
    loop_jac = _rows(work, w, nc, nv)
    loop_minv_jt = _rows(work, w + nc * nv, nc, nv)
    w += 2 * nc * nv
    loop_matrix = _rows(work, w, nc, nc)
    w += nc * nc
    loop_work = _rows(work, w, LOOP_WORK_ROWS, nc)
    w += LOOP_WORK_ROWS * nc
    energy, efc_count = work[w : w + 2], work[w + 2 : w + 3]
    w += 3
    contact_work = _rows(work, w, ncontacts, CONTACT_WIDTH)
    w += ncontacts * CONTACT_WIDTH
    efc_jac = _rows(work, w, nr, nv)
    w += nr * nv
    efc_factor = _rows(work, w, nv, nv)
    w += nv * nv
    efc_z, efc_inverse_pivots = work[w : w + nv], work[w + nv : w + 2 * nv]
    w += 2 * nv
    efc_work = _rows(work, w, EFC_WORK_ROWS, nr)
    w += EFC_WORK_ROWS * nr
    geom_pose = _rows(work, w, ngeoms, GEOM_POSE_WIDTH)
    return Work(link_work, dof_motion, dof_u, mass_matrix, dof_work, q_start, q_stage, loop_jac, loop_minv_jt,
                loop_matrix, loop_work, energy, efc_count, contact_work, efc_jac, efc_factor, efc_z,
                efc_inverse_pivots, efc_work, geom_pose)  # fmt: skip


def python_function(compiled):
    """The plain Python function behind a compiled one (itself when ``NUMBA_DISABLE_JIT=1``)."""
    return getattr(compiled, "py_func", compiled)


def counts(ints: np.ndarray) -> tuple[int, int, int, int, int, int, int]:
    """``(link_count, q_count, v_count, loop_count, scalar_count, contact capacity, geom_count)`` from the header of
    ``ints``: the arguments of :func:`work_size` and :func:`work_views`."""
    return int(ints[0]), int(ints[1]), int(ints[2]), int(ints[3]), int(ints[4]), int(ints[8]), int(ints[6])


def _most_contacts(geoms, pairs) -> int:
    """The most contacts the pairs can make at once: a capsule on a plane touches at both ends, any other pair at one
    point (``contacts.find_contacts``)."""
    kinds = [int(int_columns[GEOM_TYPE]) for int_columns, _ in geoms]
    return sum(2 if (kinds[int(c[PAIR_A])], kinds[int(c[PAIR_B])]) == (PLANE, CAPSULE) else 1 for c, _ in pairs)


def pack_model(links, loops, gravity, base_pos, base_quat, scalars=(), actuators=(), geoms=(),
               pairs=()) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Build ``(ints, reals)`` from link and loop descriptions.

    Args:
        links: sequence of :class:`~tumble.articulation.articulation.Link` (parents before children).
        loops: sequence of :class:`~tumble.articulation.loops.LoopClosure`.
        gravity, base_pos: (3,); base_quat: (4,), unit.
        scalars: sequence of ``(q coefficients (nq,), v coefficients (nv,), the SCALAR_WIDTH columns)``.
        actuators: sequence of ``(scalar, the ACT_WIDTH columns)``.
        geoms: sequence of ``(the GEOM_INT_WIDTH columns, the GEOM_REAL_WIDTH columns)``; pairs: likewise.
    """
    n, nl, ns, na, ng, npairs = len(links), len(loops), len(scalars), len(actuators), len(geoms), len(pairs)
    nq = sum(link.joint.nq for link in links)
    nv = sum(link.joint.nv for link in links)
    ints = np.zeros(_int_size(n, nv, nl, na, ng, npairs), dtype=np.int64)
    reals = np.zeros(_real_size(n, nq, nv, nl, ns, na, ng, npairs), dtype=np.float64)
    ints[:_HEADER] = (n, nq, nv, nl, ns, na, ng, npairs, _most_contacts(geoms, pairs))
    m = python_function(model_views)(ints, reals)
    m.world[GRAVITY : GRAVITY + 3], m.world[BASE_POS : BASE_POS + 3] = gravity, base_pos
    m.world[BASE_QUAT : BASE_QUAT + 4] = base_quat
    for i, link in enumerate(links):
        joint = link.joint
        above = -1 if link.parent is None else m.link_ints[link.parent, DOF_TIP]
        for k in range(link.v_slice.start, link.v_slice.stop):
            m.dof_ints[k] = (above, i)
            m.dof_params[k] = (link.damping, link.armature, link.stiffness, link.springref)
            above = k
        m.link_ints[i] = (-1 if link.parent is None else link.parent, int(joint.type), link.q_slice.start,
                          link.v_slice.start, above)  # fmt: skip
        row = m.link_reals[i]
        row[AXIS : AXIS + 3] = getattr(joint, "axis", (0.0, 0.0, 0.0))
        row[ORIGIN_POS : ORIGIN_POS + 3] = link.position
        row[ORIGIN_QUAT : ORIGIN_QUAT + 4] = link.orientation
        if link.mass_properties is not None:
            row[MASS] = link.mass_properties.mass
            row[COM : COM + 3] = link.mass_properties.com
            row[INERTIA : INERTIA + 9] = link.mass_properties.inertia.ravel()
    for s, (q_coefficients, v_coefficients, columns) in enumerate(scalars):
        m.scalar_q[s], m.scalar_v[s], m.scalar_reals[s] = q_coefficients, v_coefficients, columns
    for a, (scalar, columns) in enumerate(actuators):
        m.act_ints[a, 0], m.act_reals[a] = scalar, columns
    for g, (int_columns, real_columns) in enumerate(geoms):
        m.geom_ints[g], m.geom_reals[g] = int_columns, real_columns
    for k, (int_columns, real_columns) in enumerate(pairs):
        m.pair_ints[k], m.pair_reals[k] = int_columns, real_columns
    for k, loop in enumerate(loops):
        m.loop_ints[k] = (loop.link_a, -1 if loop.link_b is None else loop.link_b)
        m.loop_reals[k, POINT_A : POINT_A + 3] = loop.point_a
        m.loop_reals[k, POINT_B : POINT_B + 3] = loop.point_b
    return ints, reals
