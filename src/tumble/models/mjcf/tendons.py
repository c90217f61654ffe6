"""MJCF ``<tendon>``: fixed tendons, and the soft-constraint settings (``solref``/``solimp``) that joints and tendons
share.

A fixed tendon's length is ``L = Σ coef · q`` over hinges and slides (MuJoCo documentation, *XML reference*:
"tendon/fixed"). tumble simulates its ``range`` (with ``limited``, ``margin``, ``solreflimit``, ``solimplimit``),
``frictionloss`` (``solreffriction``, ``solimpfriction``), ``stiffness`` about ``springlength`` (its length at
``qpos0`` when not given) and ``damping``, and actuators pull it (``tendon=``). Spatial tendons are named in one
warning and not loaded. A tendon naming a joint that does not exist, or one that is not a hinge or slide, is an error
naming the element and its line.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..description import TendonDescription
from .attributes import flag, number, numbers
from .xml import Node

__all__ = ["TENDON_ATTRIBUTES", "describe_tendons", "softness"]

TENDON_ATTRIBUTES = {"name", "class", "group", "range", "limited", "margin", "frictionloss", "stiffness", "damping",
                     "springlength", "solreflimit", "solimplimit", "solreffriction", "solimpfriction", "rgba",
                     "material", "width", "user", "armature", "actuatorfrcrange", "actuatorfrclimited"}  # fmt: skip
# MuJoCo's defaults (``mj_defaultSolRefImp``)
_SOLREF = (0.02, 1.0)
_SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)


def softness(node: Node, a: dict[str, str], kind: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``(solref, solimp)`` of a joint's or tendon's ``kind`` (``"limit"`` or ``"friction"``), or a geom's (``""``);
    an ``solimp`` may give fewer than five numbers, the rest MuJoCo's defaults."""
    solref = tuple(float(v) for v in numbers(node, a, f"solref{kind}", 2, list(_SOLREF)))
    given = numbers(node, a, f"solimp{kind}", (1, 2, 3, 4, 5), list(_SOLIMP))
    solimp = tuple(float(v) for v in given) + _SOLIMP[given.size :]
    if not (min(solref) > 0.0 or max(solref) <= 0.0):
        raise node.error(f"solref{kind}={a.get(f'solref{kind}')!r} must be two positive numbers or two numbers <= 0")
    return solref, solimp


def describe_tendons(section: Node, resolve: Callable[[Node], dict[str, str]], joint_types: dict[str, str],
                     autolimits: bool, note: Callable[[Node, str, str], None]) -> list[TendonDescription]:  # fmt: skip
    """The fixed tendons of one ``<tendon>`` section; ``resolve(node)`` gives an element's attributes over its class."""
    found = []
    for node in section.children:
        if node.tag != "fixed":
            note(node, "element", "tumble loads fixed tendons only; not loaded")
            continue
        a = resolve(node)
        for name in a:
            if name not in TENDON_ATTRIBUTES:
                note(node, name, "not supported by tumble; ignored")
        joints, coefficients = [], []
        for child in node.children:
            if child.tag != "joint":
                raise child.error(f"<{child.tag}> in a fixed tendon: it holds <joint> elements only")
            joint = child.attrib.get("joint")
            if joint not in joint_types:
                raise child.error(f"joint={joint!r} names no joint")
            if joint_types[joint] not in ("hinge", "slide"):
                raise child.error(f"joint={joint!r} is a {joint_types[joint]}: a fixed tendon runs over hinges and "
                                  "slides")  # fmt: skip
            joints.append(joint)
            coefficients.append(number(child, child.attrib, "coef", 0.0))
        if not joints:
            raise node.error("a fixed tendon needs at least one <joint>")
        found.append(TendonDescription(
            name=a.get("name"), joints=tuple(joints), coefficients=tuple(coefficients),
            range=_range(node, a, autolimits), margin=number(node, a, "margin", 0.0, nonnegative=True),
            frictionloss=number(node, a, "frictionloss", 0.0, nonnegative=True),
            stiffness=number(node, a, "stiffness", 0.0, nonnegative=True),
            damping=number(node, a, "damping", 0.0, nonnegative=True), springlength=_springlength(node, a, note),
            limit_softness=softness(node, a, "limit"), friction_softness=softness(node, a, "friction"),
            line=node.line,
        ))  # fmt: skip
    return found


def _range(node: Node, a: dict[str, str], autolimits: bool) -> tuple[float, float] | None:
    limited = flag(node, a, "limited", "auto")
    if limited == "auto" and "range" in a and not autolimits:
        raise node.error("range without limited=... needs compiler autolimits='true'")
    if limited == "false" or (limited == "auto" and "range" not in a):
        return None
    low, high = numbers(node, a, "range", 2, [0.0, 0.0])
    if not low < high:
        raise node.error(f"range={a.get('range')!r} must have its lower bound below the upper")
    return float(low), float(high)


def _springlength(node: Node, a: dict[str, str], note: Callable[[Node, str, str], None]) -> float | None:
    """The spring's rest length, or ``None`` (MuJoCo's -1: the length at ``qpos0``)."""
    values = numbers(node, a, "springlength", (1, 2), [-1.0])
    if values.size == 2 and values[0] != values[1]:
        note(node, "springlength", "a dead band (two lengths) is not simulated by tumble; the first is used")
    return None if np.all(values == -1.0) else float(values[0])
