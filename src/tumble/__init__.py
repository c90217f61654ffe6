"""tumble: rigid-body physics for Python."""

from __future__ import annotations

__version__ = "0.1.0"

from .errors import SimulationError

__all__ = ["SimulationError", "__version__"]
