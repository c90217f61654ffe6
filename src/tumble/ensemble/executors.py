"""Where members run: a local process pool (the default), any ``concurrent.futures.Executor``, or a Dask cluster
(a ``distributed.Client``, its ``get_executor()``, or a scheduler's address)."""

from __future__ import annotations

import multiprocessing
import os
import pickle
import sys
from concurrent.futures import Executor, ProcessPoolExecutor
from contextlib import contextmanager

from ..dynamics.integrate import one_thread_for_this_process

__all__ = ["check_executor", "executor_for", "dask_client", "CONNECT_TIMEOUT"]

CONNECT_TIMEOUT = 10.0  # [s] to reach a Dask scheduler given by its address


def _check_sendable(name: str, function) -> None:
    """A process pool pickles the function by its name: refuse, now and naming it, what no worker could find."""
    if function is None or isinstance(function, str):
        return
    module = sys.modules.get(getattr(function, "__module__", None) or "")
    if getattr(function, "__module__", None) == "__main__" and not hasattr(module, "__file__"):
        raise ValueError(f"{name}: {function!r} is defined in an interactive session, which the pool's worker "
                         "processes cannot import: define it in a module (a .py file), or pass a Dask executor, "
                         "which sends functions by value")  # fmt: skip
    try:
        pickle.dumps(function)
    except Exception as error:
        raise ValueError(f"{name}: the local process pool sends it to each worker by pickling, and {function!r} "
                         f"cannot be pickled ({error}): define it at the top level of a module, or pass a Dask "
                         "executor, which sends functions by value") from None  # fmt: skip


def dask_client(address: str, name: str = "executor"):
    """A ``distributed.Client`` of the scheduler at ``address``; errors name the argument ``name`` gave it in."""
    try:
        from distributed import Client
    except ImportError:
        raise ValueError(f"{name}: the scheduler address {address!r} needs Dask: pip install 'tumble[dask]'") from None
    try:
        return Client(address, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError, ValueError) as error:
        raise ValueError(f"{name}: cannot reach the Dask scheduler at {address!r} within {CONNECT_TIMEOUT:g} s: "
                         f"{error}") from None  # fmt: skip


def check_executor(executor, build, summary) -> None:
    """Refuse, before anything runs, an executor of no known kind, and functions the local pool cannot send."""
    if executor is None:
        _check_sendable("build", build)
        _check_sendable("summary", summary)
    elif not (isinstance(executor, (str, Executor)) or hasattr(executor, "get_executor")
              or callable(getattr(executor, "submit", None))):  # fmt: skip
        raise TypeError(f"executor must be None (a local process pool), a concurrent.futures.Executor, a "
                        f"distributed.Client or a Dask scheduler's address, got {executor!r}")  # fmt: skip


@contextmanager
def executor_for(executor, workers: int | None, jobs: int):
    """The executor to submit ``jobs`` members to (checked by :func:`check_executor`), shut down after the block if
    this made it.

    ``executor``: None (a process pool of ``workers`` processes, default one per core, started fresh: nothing of
    this process's threads or locks is inherited; each steps its free bodies on one thread), a
    ``concurrent.futures.Executor``, a ``distributed.Client`` (its ``get_executor()``), or a Dask scheduler's
    address (a client is opened and closed again)."""
    if executor is None:
        size = max(1, min(workers or os.cpu_count() or 1, jobs))
        pool = ProcessPoolExecutor(max_workers=size, mp_context=multiprocessing.get_context("spawn"),
                                   initializer=one_thread_for_this_process)  # fmt: skip
        with _shut_down(pool):
            yield pool
    elif isinstance(executor, str):
        client = dask_client(executor)
        try:
            yield client.get_executor()
        finally:
            client.close()
    elif hasattr(executor, "get_executor") and not isinstance(executor, Executor):
        yield executor.get_executor()
    else:
        yield executor


@contextmanager
def _shut_down(pool: ProcessPoolExecutor):
    try:
        yield
    except BaseException:  # interrupted: members not started are dropped, running ones end by themselves
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
