"""The description side of joint limits, dry friction and fixed tendons: MuJoCo's softness settings, the tendon
record, and the packing of both into the model's scalar rows (``model.scalar_*``; solved in ``constraints.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import portable
from .._validate import _show, as_array
from .joints import Ball, Free, Prismatic, Revolute
from .model import (
    ACT_WIDTH,
    BIAS_LENGTH,
    BIAS_SPEED,
    FORCE0,
    FORCE_HIGH,
    FORCE_LOW,
    FRICTION_SOLIMP,
    FRICTION_SOLREF,
    FRICTIONLOSS,
    GEAR,
    JOINT_Q,
    JOINT_V,
    LIMIT_SOLIMP,
    LIMIT_SOLREF,
    LIMITED,
    LOWER,
    MARGIN,
    SCALAR_WIDTH,
    TENDON_DAMPING,
    TENDON_SPRINGLENGTH,
    TENDON_STIFFNESS,
    UPPER,
)

__all__ = ["SoftConstraint", "Tendon", "pack_actuators", "check_limits", "invweights", "readonly", "pack_scalars"]

# MuJoCo clamps an impedance into [mjMINIMP, mjMAXIMP]
_MIN_IMPEDANCE, _MAX_IMPEDANCE = 1e-4, 0.9999


def readonly(values) -> np.ndarray:
    """A float64 copy of ``values`` that cannot be written (the records' arrays)."""
    array = np.array(values, dtype=np.float64)
    array.flags.writeable = False
    return array


@dataclass(frozen=True)
class SoftConstraint:
    """How soft a limit or dry friction is, as MuJoCo's ``solref`` and ``solimp`` say (MuJoCo documentation,
    *Modeling*: "Solver parameters"); the defaults are MuJoCo's.

    Attributes:
        solref: ``(time constant [s], damping ratio)``, both > 0; or ``(-stiffness, -damping)``, both <= 0.
        solimp: ``(d_min, d_max, width [m or rad], midpoint, power)``: the impedance rises from ``d_min`` at no
            violation to ``d_max`` at ``width``. Impedances and the midpoint are clamped into [1e-4, 0.9999] and the
            power to at least 1, as MuJoCo clamps them.
    """

    solref: tuple[float, float] = (0.02, 1.0)
    solimp: tuple[float, float, float, float, float] = (0.9, 0.95, 0.001, 0.5, 2.0)

    def __post_init__(self):
        solref = tuple(float(v) for v in as_array("solref", self.solref, (2,), batch=False))
        if not (min(solref) > 0.0 or max(solref) <= 0.0):
            raise ValueError(f"solref must be two positive numbers or two numbers <= 0, got {_show(self.solref)}")
        low, high, width, middle, power = (float(v) for v in as_array("solimp", self.solimp, (5,), batch=False))
        if width < 0.0:
            raise ValueError(f"solimp's width (its third entry) must be >= 0, got {_show(self.solimp)}")
        low, high = (min(max(v, _MIN_IMPEDANCE), _MAX_IMPEDANCE) for v in (low, high))
        middle = min(max(middle, _MIN_IMPEDANCE), _MAX_IMPEDANCE)
        object.__setattr__(self, "solref", solref)
        object.__setattr__(self, "solimp", (low, high, width, middle, max(power, 1.0)))


@dataclass(frozen=True, eq=False)
class Tendon:
    """A fixed tendon (read-only): the length ``L = Σ coefᵢ qᵢ`` over Revolute and Prismatic links' coordinates.

    Attributes:
        index, name; links, coefficients: the terms; limits: ``(lower, upper)`` or ``None``; margin, frictionloss,
        limit_softness, friction_softness: as a link's; stiffness, damping, springlength: the force
        ``-stiffness (L - springlength) - damping L̇`` along it.
    """

    index: int
    name: str | None
    links: tuple[int, ...]
    coefficients: tuple[float, ...]
    limits: tuple[float, float] | None
    margin: float
    frictionloss: float
    limit_softness: SoftConstraint
    friction_softness: SoftConstraint
    stiffness: float
    damping: float
    springlength: float


def check_limits(name: str, limits) -> tuple[float, float] | None:
    """``limits`` as ``(lower, upper)`` with lower <= upper (finite), or ``None``."""
    if limits is None:
        return None
    lower, upper = (float(v) for v in as_array(name, limits, (2,), batch=False))
    if not lower <= upper:
        raise ValueError(f"{name} must be (lower, upper) with lower <= upper, got {_show(limits)}")
    return lower, upper


def _columns(limits, margin, frictionloss, limit_softness, friction_softness, spring=(0.0, 0.0, 0.0), rows=(-1, -1)):
    row = np.zeros(SCALAR_WIDTH)
    row[JOINT_Q], row[JOINT_V] = rows
    if limits is not None:
        row[LIMITED], row[LOWER], row[UPPER] = 1.0, limits[0], limits[1]
    row[MARGIN], row[FRICTIONLOSS] = margin, frictionloss
    row[LIMIT_SOLREF : LIMIT_SOLREF + 2] = limit_softness.solref
    row[LIMIT_SOLIMP : LIMIT_SOLIMP + 5] = limit_softness.solimp
    row[FRICTION_SOLREF : FRICTION_SOLREF + 2] = friction_softness.solref
    row[FRICTION_SOLIMP : FRICTION_SOLIMP + 5] = friction_softness.solimp
    row[TENDON_STIFFNESS], row[TENDON_SPRINGLENGTH], row[TENDON_DAMPING] = spring
    return row


def pack_scalars(links, tendons, actuated, nq: int, nv: int):
    """The scalars of the model (``pack_model``'s ``scalars``) and the index of each link's and tendon's scalar.

    A Revolute or Prismatic link gets one when it has limits, dry friction or an actuator (``actuated``: the set of
    such links); a Ball or Free link with dry friction gets one per degree of freedom (its friction only); every
    tendon gets one. Returns ``(rows, link_scalar: dict link -> index, tendon_scalar: list)``.
    """
    rows, link_scalar = [], {}
    for link in links:
        scalar_joint = isinstance(link.joint, (Revolute, Prismatic))
        if scalar_joint and (link.limits is not None or link.frictionloss > 0.0 or link.index in actuated):
            q_row, v_row = np.zeros(nq), np.zeros(nv)
            q_row[link.q_slice.start], v_row[link.v_slice.start] = 1.0, 1.0
            link_scalar[link.index] = len(rows)
            rows.append((q_row, v_row, _columns(link.limits, link.margin, link.frictionloss, link.limit_softness,
                                                link.friction_softness,
                                                rows=(link.q_slice.start, link.v_slice.start))))  # fmt: skip
        elif not scalar_joint and link.frictionloss > 0.0:
            for k in range(link.v_slice.start, link.v_slice.stop):
                v_row = np.zeros(nv)
                v_row[k] = 1.0
                rows.append((np.zeros(nq), v_row, _columns(None, 0.0, link.frictionloss, link.limit_softness,
                                                           link.friction_softness, rows=(-1, k))))  # fmt: skip
    tendon_scalar = []
    for tendon in tendons:
        q_row, v_row = np.zeros(nq), np.zeros(nv)
        for link, coefficient in zip(tendon.links, tendon.coefficients, strict=True):
            q_row[links[link].q_slice.start] += coefficient
            v_row[links[link].v_slice.start] += coefficient
        tendon_scalar.append(len(rows))
        rows.append((q_row, v_row, _columns(tendon.limits, tendon.margin, tendon.frictionloss, tendon.limit_softness,
                                            tendon.friction_softness,
                                            (tendon.stiffness, tendon.springlength, tendon.damping))))  # fmt: skip
    return rows, link_scalar, tendon_scalar


def pack_actuators(actuators, scalar_of, ctrl: np.ndarray):
    """``pack_model``'s ``actuators``: each actuator's scalar (``scalar_of(actuator)``) and force law at the controls
    ``ctrl``."""
    rows = []
    for actuator in actuators:
        row = np.zeros(ACT_WIDTH)
        row[GEAR] = actuator.gear
        row[FORCE0] = actuator.gain * actuator.control(ctrl) + actuator.bias[0]
        row[BIAS_LENGTH], row[BIAS_SPEED] = actuator.bias[1], actuator.bias[2]
        low, high = (-math.inf, math.inf) if actuator.force_range is None else actuator.force_range
        row[FORCE_LOW], row[FORCE_HIGH] = low, high
        rows.append((scalar_of(actuator), row))
    return rows


def invweights(links, scalar_v: np.ndarray, inverse: np.ndarray) -> np.ndarray:
    """MuJoCo's ``invweight0`` of each scalar from ``H⁻¹`` (``inverse``) at the initial coordinates: ``J H⁻¹ Jᵀ`` for a
    tendon or a hinge's or slide's coordinate; for a degree of freedom of a ball (free) joint the mean of ``H⁻¹``'s
    diagonal over the joint's rotations (and, apart, its translations), as MuJoCo's ``mj_setConst`` averages them."""
    inverse_diagonal = np.diag(inverse).copy()
    for link in links:
        if isinstance(link.joint, (Ball, Free)):
            first = link.v_slice.start
            for start in range(first, link.v_slice.stop, 3):
                inverse_diagonal[start : start + 3] = inverse_diagonal[start : start + 3].mean()
    weights = np.zeros(scalar_v.shape[0])
    for s, row in enumerate(scalar_v):
        support = np.flatnonzero(row)
        if len(support) == 1 and row[support[0]] == 1.0:
            weights[s] = inverse_diagonal[support[0]]
        else:
            weights[s] = math.fsum(row * portable.matvec(inverse, row))
    return weights
