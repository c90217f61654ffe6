"""Many copies of one articulation stepped together: :class:`ArticulationBatch`.

The copies share the model buffers (``model.py``) and each has its own state row and work buffer; one compiled
call (``kernels.batch_kernel``) advances every copy by any number of steps, the copies split over the threads of
``tumble.dynamics.integrate`` (``using_threads``) when there are enough of them. A copy's arithmetic is the
articulation's own ``step``, so each copy moves bit for bit as the articulation stepped alone.
"""

from __future__ import annotations

import numpy as np

from .._validate import _show, all_finite, as_array, as_count, as_step, require_memory
from ..dynamics.integrate import thread_pool, threads
from ..errors import SimulationError
from .articulation import Articulation, _check_integrator, unit_quaternions
from .chain import serial_chain
from .integrators import DAMPED, NOT_FINITE
from .kernels import READOUT_WIDTH, batch_kernel
from .model import counts, model_views, python_function, work_size

__all__ = ["ArticulationBatch"]

# Below this many copy-steps a call stays on the calling thread: a hand-off to the pool and back costs 20-200 µs. A
# copy-step of the short-chain path (chain.py) costs a tenth of the per-copy path's, so it needs ten times as many
# (1024 cart-poles, one step: 0.2 ms on one thread, 0.3 ms on two).
_PARALLEL_MIN_STEPS = 256
_CHAIN_PARALLEL_MIN_STEPS = 4096
_NO_READOUT = np.zeros((0, 0, READOUT_WIDTH))


class ArticulationBatch:
    """``n`` copies of an articulation, each with its own ``q``, ``qd`` and joint forces, stepped in one call.

    Args:
        articulation: the :class:`~tumble.articulation.Articulation` to copy: its links, loop closures, gravity,
            joint damping, springs and actuators (at its present ``ctrl``, the same for every copy) are fixed
            when the batch is built; every copy starts at its ``q``, ``qd``.
        n: the number of copies (>= 1).

    Attributes:
        q: (n, nq) and qd: (n, nv): the copies' coordinates and velocities, row ``c`` copy ``c``'s. Write into them
            (``batch.q[3] = ...``) or assign whole arrays (validated); quaternions are renormalised on assignment.
        tau: (n, nv) the joint forces [N m or N] each copy feels, held over the steps until changed (zero at
            first). For a ``Free`` joint, its six rows are the world-frame force on the link and the torque about
            the link origin in the link frame.
        time: [s] the batch's clock.

    >>> from tumble.articulation import Articulation, ArticulationBatch, Revolute
    >>> pendulum = Articulation()
    >>> _ = pendulum.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -1))
    >>> batch = ArticulationBatch(pendulum, 3)
    >>> batch.q[:, 0] = (0.1, 0.2, 0.3)
    >>> batch.step(0.01, steps=100, integrator="rk4")
    >>> batch.q.shape
    (3, 1)
    """

    def __init__(self, articulation, n) -> None:
        if not isinstance(articulation, Articulation):
            raise TypeError(f"articulation must be an Articulation, got {_show(articulation)}")
        n = as_count("n", n)
        if not articulation.links:
            raise ValueError("articulation has no links; add one with add_link")
        compiled = articulation._compile()
        self._links = articulation.links
        self._quat_starts = list(articulation._quat_starts)
        self._ints, self._reals = compiled.ints.copy(), compiled.reals.copy()
        links, nq, nv, loops, scalars, contacts, geoms = counts(self._ints)
        # each copy: q, qd and tau (8 bytes an entry), and its failure row (3 int64)
        need = 8.0 * n * (nq + 2 * nv + 3)
        require_memory(need, f"n={n} copies of a {nq}-coordinate articulation", "use fewer copies")
        self._work_size = work_size(links, nq, nv, loops, scalars, contacts, geoms)
        self._serial_chain = python_function(serial_chain)(python_function(model_views)(self._ints, self._reals))
        self._work = np.zeros((1, self._work_size))  # one work buffer per thread, grown as threads are used
        self._external = np.zeros((links, 6))
        self._failures = np.zeros((n, 3), dtype=np.int64)
        self._q = np.ascontiguousarray(np.repeat(articulation.q[None], n, axis=0))
        self._qd = np.ascontiguousarray(np.repeat(articulation.qd[None], n, axis=0))
        self._tau = np.zeros((n, nv))
        self._n = n
        self.time = float(articulation.time)

    # --- state ---------------------------------------------------------------------------------------

    @property
    def n(self) -> int:
        """The number of copies."""
        return self._n

    @property
    def nq(self) -> int:
        return self._q.shape[1]

    @property
    def nv(self) -> int:
        return self._qd.shape[1]

    @property
    def q(self) -> np.ndarray:
        return self._q

    @q.setter
    def q(self, value) -> None:
        q = np.array(as_array("q", value, (self._n, self.nq), batch=False), dtype=np.float64)
        self._q[...] = unit_quaternions("q", q, self._quat_starts)

    @property
    def qd(self) -> np.ndarray:
        return self._qd

    @qd.setter
    def qd(self, value) -> None:
        self._qd[...] = as_array("qd", value, (self._n, self.nv), batch=False)

    @property
    def tau(self) -> np.ndarray:
        return self._tau

    @tau.setter
    def tau(self, value) -> None:
        self._tau[...] = as_array("tau", value, (self._n, self.nv), batch=False)

    # --- stepping ------------------------------------------------------------------------------------

    def step(self, dt, steps=1, integrator="symplectic") -> None:
        """Advance every copy by ``steps`` steps of ``dt`` seconds under its joint forces ``tau``, in one call.

        ``integrator``: ``"symplectic"``, ``"rk4"`` or ``"euler"`` (:meth:`Articulation.step`'s). A copy whose state
        turns non-finite (or whose mass matrix turns singular) raises :class:`~tumble.SimulationError` with
        ``error.copy`` and ``error.body`` (the link) of the first such copy; every copy then keeps the state it
        had before the call, and the clock stands.
        """
        dt = as_step("dt", dt, self.time)
        steps = as_count("steps", steps)
        method = _check_integrator(integrator)
        if not all_finite(self._tau):
            bad = np.argwhere(~np.isfinite(self._tau))[0]
            raise ValueError(f"tau[{bad[0]}, {bad[1]}] must be finite, got {float(self._tau[tuple(bad)])!r}")
        self._advance(dt, steps, method)

    def _advance(self, dt: float, steps: int, method: int, copies=None, readout=None) -> None:
        """:meth:`step` with its arguments already checked (the environments' path: they check their actions), of
        the copies ``copies`` (int64 indices; all by default). ``readout`` (n, links, ``kernels.READOUT_WIDTH``):
        each copy's links at the last evaluation of its step, or at its state with ``steps`` 0
        (``kernels.batch_kernel``), for observations."""
        copies = np.arange(self._n, dtype=np.int64) if copies is None else copies
        readout = _NO_READOUT if readout is None else readout
        before = (self._q.copy(), self._qd.copy())
        workers = min(threads(), len(copies))
        # chain.takes_short_chain, with the model's part asked once when the batch was built
        chain = self._serial_chain and readout.shape[0] == 0 and method != DAMPED
        least = _CHAIN_PARALLEL_MIN_STEPS if chain else _PARALLEL_MIN_STEPS
        if workers < 2 or len(copies) * max(steps, 1) < least:
            failed = batch_kernel(self._ints, self._reals, self._q, self._qd, self._tau, self._work[0], self._external,
                                  dt, method, steps, copies, self._failures, readout)  # fmt: skip
        else:
            if self._work.shape[0] < workers:
                self._work = np.zeros((workers, self._work_size))
            futures = [thread_pool().submit(batch_kernel, self._ints, self._reals, self._q, self._qd, self._tau,
                                             self._work[k], self._external, dt, method, steps, part, self._failures,
                                             readout)
                       for k, part in enumerate(np.array_split(copies, workers))]  # fmt: skip
            failed = sum(f.result() for f in futures)
        if failed:
            raise self._failure(before, failed)
        self.time += steps * dt

    def _failure(self, before, failed: int) -> SimulationError:
        """Put every copy back to ``before`` and describe the first copy that failed (from its failure row)."""
        self._q[...], self._qd[...] = before
        copy = int(np.flatnonzero(self._failures[:, 1])[0])
        step, status, where = (int(v) for v in self._failures[copy])
        self._failures[:] = 0
        if status != NOT_FINITE:  # a singular pivot reports its degree of freedom: name the joint's link
            where = next(link.index for link in self._links if link.v_slice.start <= where < link.v_slice.stop)
        link = self._links[where]
        label = repr(link.name) if link.name is not None else f"#{link.index}"
        what = "a non-finite coordinate or velocity" if status == NOT_FINITE else "a singular mass matrix"
        error = SimulationError(
            f"copy {copy}: link {label} got {what} at step {step} of this call ({failed} of {self._n} copies "
            "failed); every copy keeps its state from before the call",
            body=link.name if link.name is not None else link.index,
            step=step,
        )
        error.copy = copy
        return error

    def __repr__(self) -> str:
        return f"ArticulationBatch(n={self._n}, nq={self.nq}, nv={self.nv}, time={self.time!r})"
