"""The compiled entry point of the articulation: one kernel for every query and for the time loop.

It takes the model buffers ``ints``/``reals`` and the ``work`` buffer (``model.py``) plus the state, so a call
unboxes a handful of arrays; the step loop of ``simulate`` runs inside it. One kernel rather than one per
query: the code they share (kinematics, ABA, CRBA, loop closures) is compiled and optimised once, which
halves the cold start. Flags are run-time arguments, never literal constants at a call site, for the same
reason (Numba compiles a function again for each literal it is called with). Kernels never raise: they
return status codes that the facade turns into errors.
"""

from __future__ import annotations

import numpy as np

from .._jit import inline, kernel
from ..math3d import add, cross, dot, scale, sub
from .chain import chain_steps, takes_short_chain
from .constraints import applied_forces
from .contacts import contact_wrenches, find_contacts
from .dynamics import crba, joint_energies, rnea
from .integrators import accelerations, step
from .kinematics import energies, forward_kinematics
from .loops import loop_jacobian, project_loop_closures
from .model import INERTIA_WORLD, PARENT, POS, QDD, RHS, VEL, model_views, work_views
from .spatial import assign, fill, fill_matrix, get3, get6, put3

__all__ = [
    "FORWARD",
    "INVERSE",
    "KINEMATICS",
    "MASS_MATRIX",
    "PROJECT",
    "SIMULATE",
    "CONTACTS",
    "articulation_kernel",
    "batch_kernel",
    "READOUT_INERTIA",
    "READOUT_ORIGIN",
    "READOUT_POINT",
    "READOUT_VELOCITY",
    "READOUT_WRENCH",
    "READOUT_WIDTH",
]

KINEMATICS, INVERSE, MASS_MATRIX, FORWARD, PROJECT, SIMULATE, CONTACTS = 0, 1, 2, 3, 4, 5, 6
# batch_kernel's readout columns, per link (_read_links): MuJoCo's cinert (10), cvel (6) and cfrc_ext (6), the point
# they are about (3) and the link frame's origin (3)
READOUT_INERTIA, READOUT_VELOCITY, READOUT_WRENCH, READOUT_POINT, READOUT_ORIGIN = 0, 10, 16, 22, 25
READOUT_WIDTH = 28


@inline
def _energies(m, w, q, qd):
    """Kinetic and potential energy after the kinematics: the links', the joints' rotors' and springs'."""
    kinetic, potential = energies(m.world, w.link_work)
    rotors, springs = joint_energies(m.link_ints, m.dof_params, q, qd)
    return kinetic + rotors, potential + springs


@kernel
def articulation_kernel(ints, reals, q, qd, vec_in, external, use_external, work, vec_out, record, h, method, steps,
                        record_every, mode):  # fmt: skip
    """One query, or ``steps`` time steps. Returns ``(steps_done, status, where)``.

    Args:
        ints, reals, work: the buffers of ``model.py``.
        q: (nq,), qd: (nv,): the state, changed in place by ``SIMULATE`` and ``PROJECT``.
        vec_in: (nv,) ``q̈`` for ``INVERSE``, else the joint forces ``τ`` (held constant over a simulation).
        external: (n, 6) world-frame rows (force at each link's centre of mass, torque), if ``use_external``.
        vec_out: (nv,): ``τ`` (``INVERSE``) or ``q̈`` (``FORWARD``).
        record: (frames, nq + nv + 1): ``SIMULATE`` records ``(q, qd, energy)`` of frame 0 and of every
            ``record_every``-th step there when it has rows.
        h [s], method (``integrators.EULER``/``SYMPLECTIC``/``RK4``), steps: the time loop of ``SIMULATE``.
        mode: ``KINEMATICS`` (poses, velocities, energies, closure errors in ``work``), ``INVERSE``,
            ``MASS_MATRIX`` (``H`` in ``work``), ``FORWARD``, ``PROJECT`` (``q``, ``qd`` onto the loop
            closures), ``SIMULATE``, ``CONTACTS`` (the contacts in ``work``; their count is the first result).

    ``status``: 0 done; 1 a singular mass matrix (``where`` its row); 2 a non-finite state (``where`` the link;
    ``SIMULATE`` only, the state is that before the failing step).
    """
    m = model_views(ints, reals)
    w = work_views(work, ints[0], ints[1], ints[2], ints[3], ints[4], ints[8], ints[6])
    if mode == FORWARD or mode == PROJECT:
        bad = accelerations(m, w, q, qd, vec_in, external, use_external, 0.0)
        if bad >= 0:
            return 0, 1, bad
        if mode == FORWARD:
            assign(vec_out, w.dof_work[QDD])
        elif m.loop_ints.shape[0] > 0:
            project_loop_closures(m, w, q, qd)
        return 0, 0, -1
    if mode != SIMULATE:
        forward_kinematics(m.link_ints, m.link_reals, m.world, q, qd, w.link_work, w.dof_motion)
        if mode == CONTACTS:
            return find_contacts(m, w), 0, -1
        if mode == KINEMATICS:
            w.energy[0], w.energy[1] = _energies(m, w, q, qd)
            if m.loop_ints.shape[0] > 0:
                loop_jacobian(m.link_ints, m.dof_ints, m.loop_ints, m.loop_reals, w.link_work, w.dof_motion,
                              w.loop_jac, w.loop_work)  # fmt: skip
        elif mode == INVERSE:
            rnea(m.link_ints, m.world, m.dof_params, w.link_work, w.dof_motion, q, qd, vec_in, external, use_external,
                 vec_out)  # fmt: skip
            fill(w.dof_work[RHS], 0.0)  # less the actuators' and tendons' forces, which drive beside τ
            drive = applied_forces(m, w, q, qd, w.dof_work[RHS])
            for k in range(vec_out.shape[0]):
                vec_out[k] -= drive[k]
        elif mode == MASS_MATRIX:
            fill_matrix(w.mass_matrix, 0.0)  # the CRBA writes only the entries of pairs on one path to the base
            crba(m.link_ints, m.dof_ints, m.dof_params, w.link_work, w.dof_motion, w.mass_matrix)
        return 0, 0, -1
    nq, nv = q.shape[0], qd.shape[0]
    for n in range(steps + 1):
        # record (q, qd, energy) at frame 0 and after every record_every-th step
        if record.shape[0] > 0 and n % record_every == 0:
            forward_kinematics(m.link_ints, m.link_reals, m.world, q, qd, w.link_work, w.dof_motion)
            kinetic, potential = _energies(m, w, q, qd)
            frame = n // record_every
            assign(record[frame, :nq], q)
            assign(record[frame, nq : nq + nv], qd)
            record[frame, nq + nv] = kinetic + potential
        if n == steps:
            break
        status, where = step(m, w, q, qd, vec_in, external, use_external, h, method)
        if status != 0:
            return n, status, where
    return steps, 0, -1


@inline
def _read_links(m, w, q, qd, tau, external, h, out, evaluate):
    """The links at the last evaluation of the dynamics into ``out`` (links, ``READOUT_WIDTH``), as MuJoCo's
    "com-based" ``cinert``, ``cvel`` and ``cfrc_ext``: world axes, about the centre of mass ``p`` of the link's tree
    (the links under its base link, MuJoCo's ``subtree_com`` of the body's root), which ``READOUT_POINT`` holds, with
    the link frame's origin (MuJoCo's ``xpos`` of a body whose joint sits at its origin) in ``READOUT_ORIGIN``.

    ``cinert`` is ``(I_xx, I_yy, I_zz, I_xy, I_xz, I_yz, m (c - p), m)``, ``cvel`` ``(ω, velocity of the point at p)``,
    ``cfrc_ext`` ``(moment about p, force)`` of the link's contacts. The evaluation is the step's last (an RK4 step's
    fourth stage, an Euler step's start), as MuJoCo's ``mjData`` holds them after ``mj_step``; with ``evaluate``
    (no step taken), a fresh one at ``(q, qd)`` under ``tau``. The kinematics give the inertia about the world
    origin ``(m, h = m c, I_O)``; the parallel-axis theorem written with ``h`` moves it to ``p``:
    ``I_p = I_O + (m|p|² - 2 h·p) E - (m p pᵀ - h pᵀ - p hᵀ)``.
    """
    bad = accelerations(m, w, q, qd, tau, external, False, h) if evaluate else -1
    n, link_ints, link_work = out.shape[0], m.link_ints, w.link_work
    for i in range(n):  # each base link's tree: its mass and first moment, then its centre of mass
        if link_ints[i, PARENT] >= 0:
            continue
        mass, first = 0.0, (0.0, 0.0, 0.0)
        for j in range(i, n):
            if _base(link_ints, j) == i:
                mass += link_work[j, INERTIA_WORLD]
                first = add(first, get3(link_work, j, INERTIA_WORLD + 1))
        point = scale(first, 1.0 / mass) if mass > 0.0 else get3(link_work, i, POS)
        for j in range(i, n):
            if _base(link_ints, j) == i:
                put3(out, j, READOUT_POINT, point)
    for i in range(n):
        p = get3(out, i, READOUT_POINT)
        mass = link_work[i, INERTIA_WORLD]
        first = get3(link_work, i, INERTIA_WORLD + 1)
        hp, pp = dot(first, p), dot(p, p)
        k = READOUT_INERTIA
        for a, b in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)):
            shift = mass * p[a] * p[b] - first[a] * p[b] - p[a] * first[b]
            out[i, k] = link_work[i, INERTIA_WORLD + 4 + k - READOUT_INERTIA] - shift
            if a == b:
                out[i, k] += mass * pp - 2.0 * hp
            k += 1
        put3(out, i, READOUT_INERTIA + 6, sub(first, scale(p, mass)))
        out[i, READOUT_INERTIA + 9] = mass
        velocity = get6(link_work, i, VEL)
        put3(out, i, READOUT_VELOCITY, velocity[0])
        put3(out, i, READOUT_VELOCITY + 3, add(velocity[1], cross(velocity[0], p)))
        put3(out, i, READOUT_ORIGIN, get3(link_work, i, POS))
        for k in range(6):
            out[i, READOUT_WRENCH + k] = 0.0
    if bad < 0 and m.pair_ints.shape[0] > 0:
        contact_wrenches(m, w, out, READOUT_WRENCH)  # about the world origin: moved to p below
        for i in range(n):
            moment = sub(
                get3(out, i, READOUT_WRENCH), cross(get3(out, i, READOUT_POINT), get3(out, i, READOUT_WRENCH + 3))
            )
            put3(out, i, READOUT_WRENCH, moment)
    return bad


@inline
def _base(link_ints, i):
    """The base link (no parent) of link ``i``'s tree."""
    while link_ints[i, PARENT] >= 0:
        i = link_ints[i, PARENT]
    return i


@kernel
def batch_kernel(ints, reals, q, qd, tau, work, external, h, method, steps, copies, failures, readout):  # fmt: skip
    """``steps`` time steps of the copies ``copies`` (indices) of one articulation (``ArticulationBatch``); releases
    the GIL.

    Args:
        ints, reals: the shared model buffers; work: one work buffer (``model.work_size``) for this call's copies.
        q: (copies, nq), qd: (copies, nv): the states, advanced in place; tau: (copies, nv) joint forces held
            over the steps. external: (n, 6) zeros (no external loads).
        failures: (copies, 3) int64: ``(step, status, where)`` of each copy's failing step, written only for a
            copy that fails (it stops there with its state from before that step).
        readout: (copies, links, ``READOUT_WIDTH``), or no rows: after its steps, each copy's links as
            :func:`_read_links` reads them at the last step's last evaluation, or (``steps`` 0) at the state (for
            observations: the environments).

    Returns the number of copies that failed. A copy's arithmetic is :func:`articulation_kernel`'s (the same
    ``step``), so each copy advances bit for bit as the articulation alone: a step reads nothing of the work
    buffer that it did not write first, so one buffer serves copy after copy (and stays in the cache). A serial chain
    of hinges and slides takes the short-chain path (``chain.py``: the same arithmetic, many copies side by side);
    the blocks of copies it hands back, one of whose copies failed, are stepped here copy by copy.
    """
    m = model_views(ints, reals)
    w = work_views(work, ints[0], ints[1], ints[2], ints[3], ints[4], ints[8], ints[6])
    if steps > 0 and takes_short_chain(m, method, readout.shape[0] > 0):
        # the short-chain path (chain.py); the blocks it could not finish are stepped again copy by copy below
        unfinished = np.empty_like(copies)
        left = chain_steps(m, q, qd, tau, h, method, steps, copies, unfinished)
        if left == 0:
            return 0
        copies = unfinished[:left]
    return _step_copies(m, w, q, qd, tau, external, h, method, steps, copies, failures, readout)


@inline
def _step_copies(m, w, q, qd, tau, external, h, method, steps, copies, failures, readout):
    """:func:`batch_kernel` copy after copy; returns the number that failed."""
    failed = 0
    for c in copies:
        q_c, qd_c, tau_c = q[c], qd[c], tau[c]
        status, where = 0, -1
        for n in range(steps):
            status, where = step(m, w, q_c, qd_c, tau_c, external, False, h, method)
            if status != 0:
                failures[c, 0], failures[c, 1], failures[c, 2] = n, status, where
                failed += 1
                break
        if status == 0 and readout.shape[0] > 0:
            bad = _read_links(m, w, q_c, qd_c, tau_c, external, h, readout[c], steps == 0)
            if bad >= 0:
                failures[c, 0], failures[c, 1], failures[c, 2] = steps, 1, bad
                failed += 1
    return failed
