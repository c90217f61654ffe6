"""The tendons and actuators of an :class:`~tumble.articulation.Articulation`: building them, their controls, and
what they pull (a mixin of the facade, which holds the links, the state and the compiled model it reads and
invalidates).
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from .._validate import _show, as_array, as_float
from .actuators import Actuator, actuator_forces
from .joints import Prismatic, Revolute
from .limits import SoftConstraint, Tendon, check_limits, readonly
from .model import FORCE0

__all__ = ["JointDrives"]


def softness(name: str, value) -> SoftConstraint:
    """``value`` as a :class:`SoftConstraint` (``None``: MuJoCo's defaults)."""
    if value is None:
        return SoftConstraint()
    if not isinstance(value, SoftConstraint):
        raise TypeError(f"{name} must be a SoftConstraint or None, got {_show(value)}")
    return value


class JointDrives:
    """Tendons and actuators. Expects of the class it is mixed into: ``_links``, ``_loops``, ``_q``, ``_qd``,
    ``_tendons``, ``_actuators``, ``_ctrl``, ``_law`` (None), ``_compiled`` (reset to ``None`` when the model
    changes), ``nv`` and ``_check_link``, ``_check_q``, ``_check_vector``."""

    def add_tendon(self, links, coefficients, *, limits=None, margin=0.0, frictionloss=0.0, limit_softness=None,
                   friction_softness=None, stiffness=0.0, damping=0.0, springlength=None,
                   name=None) -> int:  # fmt: skip
        """Add a fixed tendon, the length ``L = Σ coefficients[i] q[links[i]]`` over Revolute and Prismatic links'
        coordinates (MuJoCo's ``<fixed>``); returns its index.

        Args:
            links: link indices; coefficients: as many finite numbers.
            limits, margin, frictionloss, limit_softness, friction_softness: as :meth:`add_link`'s, on ``L``.
            stiffness, damping: >= 0, the force ``-stiffness (L - springlength) - damping L̇`` along it;
                springlength: its rest length (default the length at the initial coordinates, as MuJoCo's).
            name: optional unique label.
        """
        if isinstance(links, (str, bytes)) or not hasattr(links, "__len__") or len(links) == 0:
            raise ValueError(f"links must be a non-empty sequence of link indices, got {_show(links)}")
        links = tuple(self._check_link("links", link) for link in links)
        for link in links:
            if not isinstance(self._links[link].joint, (Revolute, Prismatic)):
                raise ValueError(f"links: link {link} has a {self._links[link].joint!r} joint; a tendon runs over "
                                 "Revolute and Prismatic joints")  # fmt: skip
        coefficients = tuple(float(v) for v in as_array("coefficients", coefficients, (len(links),), batch=False))
        limits = check_limits("limits", limits)
        margin = as_float("margin", margin, nonnegative=True)
        frictionloss = as_float("frictionloss", frictionloss, nonnegative=True)
        stiffness = as_float("stiffness", stiffness, nonnegative=True)
        damping = as_float("damping", damping, nonnegative=True)
        if springlength is None:
            springlength = self._scalar(self._q, links, coefficients)
        springlength = as_float("springlength", springlength)
        if name is not None and not isinstance(name, str):
            raise TypeError(f"name must be a string or None, got {_show(name)}")
        if name is not None and any(t.name == name for t in self._tendons):
            raise ValueError(f"name must be unique among the tendons, got {name!r}")
        if self._loops:
            raise ValueError("tendons are not simulated with loop closures (yet); this articulation has loop closures")
        self._tendons.append(Tendon(len(self._tendons), name, links, coefficients, limits, margin, frictionloss,
                                    softness("limit_softness", limit_softness),
                                    softness("friction_softness", friction_softness), stiffness, damping,
                                    springlength))  # fmt: skip
        self._compiled = None
        return len(self._tendons) - 1

    @property
    def tendons(self) -> tuple[Tendon, ...]:
        return tuple(self._tendons)

    def tendon_lengths(self, q=None) -> np.ndarray:
        """(number of tendons,) each tendon's length at ``q`` (default the current coordinates)."""
        q = self._q if q is None else self._check_q("q", q)
        return np.array([self._scalar(q, t.links, t.coefficients) for t in self._tendons])

    def add_actuator(self, link=None, *, tendon=None, gear=1.0, gain=1.0, bias=(0.0, 0.0, 0.0), ctrl_range=None,
                     force_range=None, name=None) -> int:  # fmt: skip
        """Drive ``link``'s Revolute or Prismatic joint, or pull ``tendon``, from ``ctrl``; returns the actuator's
        index in ``ctrl``.

        The actuator pulls along its length ``l = gear · L`` (``L`` the joint's coordinate or the tendon's length)
        with ``f = gain · c + bias[0] + bias[1] l + bias[2] l̇`` (``c`` the control, clipped to ``ctrl_range``; ``f``
        clipped to ``force_range``) and pushes along ``L`` with ``gear · f``: a motor is the default (``gear ·
        ctrl``), a position servo ``gain=kp, bias=(0, -kp, -kv)``, a velocity servo ``gain=kv, bias=(0, 0, -kv)``
        (MuJoCo's actuators on a joint or tendon; see ``actuators.py``). Its control starts at 0.

        Args:
            link: a link index, or ``None`` with ``tendon``: a tendon index; gear, gain: finite; bias: (3,);
                ctrl_range, force_range: ``(low, high)`` with low <= high, or ``None``; name: optional unique label.
        """
        if (link is None) == (tendon is None):
            raise ValueError(f"give one of link and tendon, got link={_show(link)} and tendon={_show(tendon)}")
        if link is not None:
            link = self._check_link("link", link)
            joint = self._links[link].joint
            if not isinstance(joint, (Revolute, Prismatic)):
                raise ValueError(f"link {link} has a {joint!r} joint: an actuator drives a Revolute or Prismatic one")
        elif not isinstance(tendon, numbers.Integral) or not 0 <= tendon < len(self._tendons):
            raise ValueError(f"tendon must be the index of a tendon (0..{len(self._tendons) - 1}), got {_show(tendon)}")
        gear, gain = as_float("gear", gear), as_float("gain", gain)
        bias = readonly(as_array("bias", bias, (3,), batch=False))
        ranges = []
        for label, value in (("ctrl_range", ctrl_range), ("force_range", force_range)):
            if value is not None:
                low, high = (float(v) for v in as_array(label, value, (2,), batch=False))
                if not low <= high:
                    raise ValueError(f"{label} must be (low, high) with low <= high, got {_show(value)}")
                value = (low, high)
            ranges.append(value)
        if name is not None and not isinstance(name, str):
            raise TypeError(f"name must be a string or None, got {_show(name)}")
        if name is not None and any(a.name == name for a in self._actuators):
            raise ValueError(f"name must be unique among the actuators, got {name!r}")
        self._actuators.append(Actuator(len(self._actuators), name, link, gear, gain, bias, ranges[0],
                                        None if tendon is None else int(tendon), ranges[1]))  # fmt: skip
        self._ctrl = np.append(self._ctrl, 0.0)
        self._compiled = None
        return len(self._actuators) - 1

    @property
    def actuators(self) -> tuple[Actuator, ...]:
        return tuple(self._actuators)

    @property
    def ctrl(self) -> np.ndarray:
        """(number of actuators,) the controls (a copy), held until set again; clipped to each actuator's
        ``ctrl_range`` where it acts, kept as given here."""
        return self._ctrl.copy()

    @ctrl.setter
    def ctrl(self, value) -> None:
        self._ctrl = self._check_vector("ctrl", value, len(self._actuators))
        if self._compiled is not None:
            # each actuator's gain · (control clipped to its range) + bias₀, as pack_actuators packs it
            gain, bias, low, high = self._control_law()
            self._compiled.views()[0].act_reals[:, FORCE0] = gain * np.minimum(np.maximum(self._ctrl, low), high) + bias

    def _control_law(self):
        """``(gain, bias₀, low, high)`` of every actuator, made once per set of actuators."""
        if self._law is None or len(self._law[0]) != len(self._actuators):
            ranges = [a.ctrl_range or (-math.inf, math.inf) for a in self._actuators]
            self._law = (np.array([a.gain for a in self._actuators]), np.array([a.bias[0] for a in self._actuators]),
                         np.array([r[0] for r in ranges]), np.array([r[1] for r in ranges]))  # fmt: skip
        return self._law

    def actuator_forces(self, q=None, qd=None) -> np.ndarray:
        """Each actuator's force along its length at the state (default the current one), before its gear:
        MuJoCo's ``actuator_force``."""
        q = self._q if q is None else self._check_q("q", q)
        qd = self._qd if qd is None else self._check_vector("qd", qd, self.nv)
        terms = [self._terms(a) for a in self._actuators]
        lengths = [self._scalar(q, links, coefficients) for links, coefficients in terms]
        speeds = [self._scalar(qd, links, coefficients, rates=True) for links, coefficients in terms]
        return actuator_forces(self._actuators, lengths, speeds, self._ctrl)

    def _terms(self, actuator: Actuator):
        """``(links, coefficients)`` of the joint or tendon an actuator pulls."""
        if actuator.tendon is None:
            return (actuator.link,), (1.0,)
        tendon = self._tendons[actuator.tendon]
        return tendon.links, tendon.coefficients

    def _scalar(self, values, links, coefficients, rates=False) -> float:
        """``Σ cᵢ values[row of links[i]]``: a tendon's (or joint's) length from ``q``, or its rate from ``qd``."""
        rows = [(self._links[k].v_slice if rates else self._links[k].q_slice).start for k in links]
        return math.fsum(c * values[row] for row, c in zip(rows, coefficients, strict=True))
