"""Exceptions raised by tumble."""

from __future__ import annotations

__all__ = ["SimulationError"]


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
