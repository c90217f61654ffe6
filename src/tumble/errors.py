"""Exceptions raised by tumble."""

from __future__ import annotations

import os
import sys
import warnings

__all__ = ["SimulationError", "SubstepsRaisedWarning", "warn_user"]

_PACKAGE = os.path.dirname(os.path.abspath(__file__))


class SimulationError(RuntimeError):
    """A step produced a non-finite value, or a controller raised before it; the world keeps the state it had
    before that step.

    Attributes:
        body: name (or index) of the first body whose state became non-finite (``None`` for a controller).
        step: the index of the step that failed (``world.step_count`` before it).
        controller: the name of the controller that raised (``None`` for a non-finite state); the exception it
            raised is the ``__cause__``.
    """

    def __init__(
        self, message: str, *, body: str | int | None = None, step: int | None = None, controller: str | None = None
    ):
        super().__init__(message)
        self.body = body
        self.step = step
        self.controller = controller


class SubstepsRaisedWarning(UserWarning):
    """A step runs more substeps than the world was asked for: its contacts need them (``World.substeps``)."""


def warn_user(message: str, category: type[Warning]) -> None:
    """Warn at the user's line: the first caller outside the tumble package (however deep the call came)."""
    frame, level = sys._getframe(1), 2
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, category, stacklevel=level)
