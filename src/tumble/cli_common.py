"""What every ``tumble`` command shares: exit statuses, the one-line errors, consoles, argument types, loading a
scene file, the progress bar and the Ctrl-C/SIGTERM latch (``tumble.cli`` and the commands in their own modules,
``tumble.cli_batch``, import them from here).
"""

from __future__ import annotations

import argparse
import math
import os
import signal
import sys
import time
import warnings
import weakref
from pathlib import Path

from numba.core import event as numba_event  # numba is loaded with tumble anyway

from ._validate import MAX_COUNT

__all__ = ["EXIT_OK", "EXIT_SIMULATION", "EXIT_BAD_INPUT", "EXIT_INTERRUPTED", "EXIT_TERMINATED", "BadInput"]

EXIT_OK = 0
EXIT_SIMULATION = 1
EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143  # 128 + SIGTERM (15), as a shell reports a process that a signal ended


class BadInput(Exception):
    """Input the command cannot use: printed as one line, exit status 2."""


def _error(message: str) -> None:
    for line in str(message).splitlines() or [""]:
        print(f"tumble: error: {line}", file=sys.stderr)


def _note(message: str) -> None:
    print(f"tumble: {message}", file=sys.stderr)


class _PipeClosed(Exception):
    """The reader of stdout went away (``tumble info big.toml | head``): stop quietly."""


def _consoles():
    """(stdout console, stderr console). Off a terminal the width is fixed (no wrapping at 80 columns)."""
    from rich.console import Console

    class _Console(Console):
        def on_broken_pipe(self) -> None:  # rich's own exits with status 1, which here means a simulation error
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            raise _PipeClosed

    width = None if sys.stdout.isatty() or "COLUMNS" in os.environ else 160
    return _Console(width=width, highlight=False), _Console(stderr=True, highlight=False)


def _text(value) -> object:
    """Plain text for a table cell (no rich markup: names like ``box[3]`` stay as written)."""
    from rich.text import Text

    return Text(str(value))


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not (math.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return value


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer, got {text!r}") from None
    if not 1 <= value <= MAX_COUNT:
        raise argparse.ArgumentTypeError(f"must be an integer from 1 to {MAX_COUNT}, got {text!r}")
    return value


def _scene_path(text: str) -> Path:
    """The scene file ``text`` names: a path, or the name of a shipped scene (``flagship``)."""
    path = Path(text)
    if path.exists():
        if not path.is_file():
            raise BadInput(f"{text}: not a file")
        return path
    if not path.suffix and len(path.parts) == 1:
        for shipped in _shipped_scenes():
            if shipped.stem == text:
                return shipped
    raise BadInput(f"{text}: no such scene file (nor a shipped scene; tumble examples lists them)")


def _load_scene(text: str):
    """``(path, loaded scene)``; a SceneError or a missing file becomes :class:`BadInput`."""
    from . import scene_file

    path = _scene_path(text)
    try:
        with warnings.catch_warnings(record=True) as heard:
            warnings.simplefilter("always")
            loaded = scene_file.load(path)
    except scene_file.SceneError as error:
        raise BadInput(str(error)) from None
    from .models.mjcf import MJCFWarning

    for message in dict.fromkeys(str(w.message) for w in heard if issubclass(w.category, MJCFWarning)):
        _note(message)  # a model file's: what tumble does not simulate
    for w in heard:
        if not issubclass(w.category, MJCFWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return path, loaded


SIMULATING = "simulating"
COMPILING = "compiling kernels (first run only)…"


class _Progress:
    """A rich progress bar fed by ``recording.record``'s callback; it also times the chunks, so that the steps/s
    of the summary leave out the first chunk (which pays for loading the compiled kernels).

    On a first run the first chunk waits while Numba compiles the kernels (a minute or more on a fresh machine):
    the bar's label then says so, with the count of functions compiled, from Numba's ``numba:compile`` events."""

    def __init__(self, console, total_steps: int, start_step: int, duration: float, enabled: bool) -> None:
        self.start_step = start_step
        self.first_chunk: tuple[float, int] | None = None  # (time.perf_counter(), steps) after the first chunk
        self.last: tuple[float, int] | None = None
        self.compiled = 0  # functions Numba compiled while the bar was up
        self._bar = None
        self._watch = None
        if enabled:
            from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn, TimeRemainingColumn

            self._bar = Progress(
                TextColumn("{task.fields[stage]}"),
                BarColumn(),
                TaskProgressColumn(),
                TextColumn("t = {task.fields[t]:.3g} / {task.fields[duration]:.3g} s"),
                TimeRemainingColumn(),
                console=console,
                transient=True,
            )
            self._task = self._bar.add_task("run", total=total_steps, t=0.0, duration=duration, stage=SIMULATING)
            self._watch = _CompileWatch(self._compiled)

    def __enter__(self):
        if self._bar is not None:
            numba_event.register("numba:compile", self._watch)
            self._bar.start()
        return self

    def __exit__(self, *exc) -> None:
        if self._bar is not None:
            numba_event.unregister("numba:compile", self._watch)
            self._bar.stop()

    def _compiled(self) -> None:
        self.compiled += 1
        if self.first_chunk is None:
            self._bar.update(self._task, stage=f"{COMPILING} {self.compiled} functions")

    def __call__(self, world, writer) -> None:
        now, steps = time.perf_counter(), world.step_count - self.start_step
        if self.first_chunk is None:
            self.first_chunk = (now, steps)
        self.last = (now, steps)
        if self._bar is not None:
            self._bar.update(self._task, completed=steps, t=world.time, stage=SIMULATING)

    def steps_per_second(self, steps: int, wall: float) -> tuple[float, str]:
        """``(steps/s, what it covers)``: after the first chunk when there were several (the first pays for loading
        the compiled kernels), else ``steps`` over the whole ``wall`` time."""
        if self.first_chunk is not None and self.last is not None and self.last[1] > self.first_chunk[1]:
            (t1, s1), (t2, s2) = self.first_chunk, self.last
            if t2 > t1:
                return (s2 - s1) / (t2 - t1), "after the first chunk (which loads the compiled kernels)"
        return (steps / wall if wall > 0 else math.inf), "whole run, loading the compiled kernels included"


class _CompileWatch(numba_event.Listener):
    """Calls ``on_compile()`` at the end of each Numba compilation (not for a load from the cache)."""

    def __init__(self, on_compile) -> None:
        self._on_compile = on_compile

    def on_start(self, event) -> None:
        pass

    def on_end(self, event) -> None:
        self._on_compile()


class _Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, a job scheduler's end of time), raised where Ctrl-C would be, so that it stops a run the
    same way: the recording closed with status 'interrupted', a message, and :data:`EXIT_TERMINATED`."""


def _stop_signals() -> list[int]:
    return [getattr(signal, name) for name in ("SIGINT", "SIGTERM") if hasattr(signal, name)]


class _InterruptLatch:
    """Ctrl-C and SIGTERM that cannot be lost. Python raises ``KeyboardInterrupt`` wherever the main thread is, and
    drops it, with a traceback on stderr, when that is a weakref callback or a ``__del__`` ("Exception ignored in
    ..."): the run then went on. The latch raises it at once unless it landed in one of those, and remembers it, so
    that the next chunk's callback raises it in any case. SIGTERM raises :class:`_Terminated`, a KeyboardInterrupt."""

    def __init__(self) -> None:
        self.requested: int | None = None  # the signal received
        self._previous: dict[int, object] = {}

    def __enter__(self):
        for number in _stop_signals():
            self._previous[number] = signal.signal(number, self._handle)
        return self

    def __exit__(self, *exc) -> None:
        for number, previous in self._previous.items():
            signal.signal(number, previous)

    def _handle(self, signum, frame) -> None:
        self.requested = signum
        if frame is not None and (frame.f_code.co_name == "__del__" or frame.f_code.co_filename == weakref.__file__):
            return  # Python would drop it here: the next chunk raises it
        if _within_numba_unpickle(frame):
            return  # compiled code rebuilding an object: it would end the run with a SystemError, not stop it
        self.check()

    def check(self) -> None:
        if self.requested is not None:
            raise _Terminated if self.requested == getattr(signal, "SIGTERM", None) else KeyboardInterrupt


def _within_numba_unpickle(frame) -> bool:
    """Whether ``frame`` runs within Numba's ``_numba_unpickle``, which compiled code calls to rebuild a Python object:
    an exception raised there comes out as ``SystemError: ... returned a result with an exception set`` (a
    SIGTERM that landed there once in a busy ``make test`` ended a run with status 1 instead of 143)."""
    while frame is not None:
        if frame.f_code.co_name == "_numba_unpickle":
            return True
        frame = frame.f_back
    return False


def _shipped_scenes() -> list[Path]:
    from . import scene_file

    return list(scene_file.shipped())
