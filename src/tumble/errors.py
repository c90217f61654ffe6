"""Exceptions raised by tumble."""

from __future__ import annotations

__all__ = ["SimulationError"]


class SimulationError(RuntimeError):
    """A step produced a non-finite value; the world keeps the state it had before that step.

    Attributes:
        body: name (or index) of the first body whose state became non-finite.
        step: the index of the step that failed (``world.step_count`` before it).
    """

    def __init__(self, message: str, *, body: str | int | None = None, step: int | None = None):
        super().__init__(message)
        self.body = body
        self.step = step
