"""The compiled entry point of the articulation: one kernel for every query and for the time loop.

It takes the model buffers ``ints``/``reals`` and the ``work`` buffer (``model.py``) plus the state, so a call
unboxes a handful of arrays; the step loop of ``simulate`` runs inside it. One kernel rather than one per
query: the code they share (kinematics, ABA, CRBA, loop closures) is compiled and optimised once, which
halves the cold start. Flags are run-time arguments, never literal constants at a call site, for the same
reason (Numba compiles a function again for each literal it is called with). Kernels never raise: they
return status codes that the facade turns into errors.
"""

from __future__ import annotations

from .._jit import inline, kernel
from .constraints import applied_forces
from .contacts import find_contacts
from .dynamics import crba, joint_energies, rnea
from .integrators import accelerations, step
from .kinematics import energies, forward_kinematics
from .loops import loop_jacobian, project_loop_closures
from .model import QDD, RHS, model_views, work_views
from .spatial import assign, fill, fill_matrix

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
]

KINEMATICS, INVERSE, MASS_MATRIX, FORWARD, PROJECT, SIMULATE, CONTACTS = 0, 1, 2, 3, 4, 5, 6


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


@kernel
def batch_kernel(ints, reals, q, qd, tau, work, external, h, method, steps, first, last, failures):  # fmt: skip
    """``steps`` time steps of copies ``first..last-1`` of one articulation (``ArticulationBatch``); releases the GIL.

    Args:
        ints, reals: the shared model buffers; work: one work buffer (``model.work_size``) for this call's copies.
        q: (copies, nq), qd: (copies, nv): the states, advanced in place; tau: (copies, nv) joint forces held
            over the steps. external: (n, 6) zeros (no external loads).
        failures: (copies, 3) int64: ``(step, status, where)`` of each copy's failing step, written only for a
            copy that fails (it stops there with its state from before that step).

    Returns the number of copies that failed. A copy's arithmetic is :func:`articulation_kernel`'s (the same
    ``step``), so each copy advances bit for bit as the articulation alone: a step reads nothing of the work
    buffer that it did not write first, so one buffer serves copy after copy (and stays in the cache).
    """
    m = model_views(ints, reals)
    w = work_views(work, ints[0], ints[1], ints[2], ints[3], ints[4], ints[8], ints[6])
    failed = 0
    for c in range(first, last):
        q_c, qd_c, tau_c = q[c], qd[c], tau[c]
        for n in range(steps):
            status, where = step(m, w, q_c, qd_c, tau_c, external, False, h, method)
            if status != 0:
                failures[c, 0], failures[c, 1], failures[c, 2] = n, status, where
                failed += 1
                break
    return failed
