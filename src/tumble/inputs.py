"""Inputs: the forces and torques the user applies for the next step; cleared after it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Inputs"]


@dataclass(eq=False)
class Inputs:
    """Applied loads, accumulated by ``apply_force``/``apply_torque`` and cleared by each step.

    Attributes:
        body_force: (body_count, 3) float64 [N], world frame, acting at the COM.
        body_torque: (body_count, 3) float64 [N m], world frame, about the COM (includes ``r × F``
            of forces applied away from the COM).
    """

    body_force: np.ndarray
    body_torque: np.ndarray

    @classmethod
    def zeros(cls, body_count: int) -> Inputs:
        return cls(np.zeros((body_count, 3)), np.zeros((body_count, 3)))

    def grown(self, added: int) -> Inputs:
        """These loads with ``added`` zero rows after them (for bodies added since)."""
        zeros = np.zeros((added, 3))
        return Inputs(np.concatenate([self.body_force, zeros]), np.concatenate([self.body_torque, zeros]))

    def clear(self) -> None:
        self.body_force.fill(0.0)
        self.body_torque.fill(0.0)
