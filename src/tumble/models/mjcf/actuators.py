"""MJCF ``<actuator>``: motors, position and velocity servos and general actuators on hinges, slides and fixed
tendons.

MuJoCo's actuator pulls along its transmission's length ``l`` with ``gain · ctrl + bias₀ + bias₁ l + bias₂ l̇``;
``motor`` (gain 1), ``position`` (``kp``, ``kv``: gain ``kp``, bias ``(0, -kp, -kv)``) and ``velocity`` (``kv``:
gain ``kv``, bias ``(0, 0, -kv)``) are shortcuts for it. tumble simulates those with a joint transmission (``joint=``
a hinge or slide; ``l = gear · q``) or a fixed tendon's (``tendon=``), a fixed gain, an affine bias or none, the
force clipped to ``forcerange``, and no activation dynamics. Any other
actuator is named in one warning and not loaded, so ``art.ctrl`` holds the loaded ones in the file's order. A
default class's actuator settings, from whichever actuator element wrote them, apply to every kind, as in MuJoCo,
where they are the class's one ``general`` default.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..description import ActuatorDescription
from .attributes import flag, keyword, number, numbers
from .xml import Node

__all__ = ["ACTUATOR_TAGS", "describe_actuator"]

ACTUATOR_TAGS = ("general", "motor", "position", "velocity", "intvelocity", "damper", "cylinder", "muscle",
                 "adhesion", "plugin")  # fmt: skip
_KNOWN = {"name", "class", "group", "joint", "tendon", "gear", "ctrlrange", "ctrllimited", "forcerange", "forcelimited",
          "user", "lengthrange"}  # fmt: skip
_OWN = {"motor": set(), "position": {"kp", "kv"}, "velocity": {"kv"},
        "general": {"gaintype", "biastype", "dyntype", "gainprm", "biasprm", "dynprm", "actlimited", "actrange",
                    "actdim", "actearly"}}  # fmt: skip
_TRANSMISSIONS = ("site", "body", "jointinparent", "cranksite", "slidersite")
_UP_TO_TEN = tuple(range(1, 11))


def _law(node: Node, kind: str, a: dict[str, str]) -> tuple[float, np.ndarray] | str:
    """``(gain, bias)``, or why tumble does not simulate this actuator."""
    if kind == "motor":
        return 1.0, np.zeros(3)
    if kind == "position":
        kp, kv = number(node, a, "kp", 1.0, nonnegative=True), number(node, a, "kv", 0.0, nonnegative=True)
        return kp, np.array([0.0, -kp, -kv])
    if kind == "velocity":
        kv = number(node, a, "kv", 1.0, nonnegative=True)
        return kv, np.array([0.0, 0.0, -kv])
    dyntype = keyword(node, a, "dyntype", "none", ("none", "integrator", "filter", "filterexact", "muscle", "user"))
    gaintype = keyword(node, a, "gaintype", "fixed", ("fixed", "affine", "muscle", "user"))
    biastype = keyword(node, a, "biastype", "none", ("none", "affine", "muscle", "user"))
    if dyntype != "none":
        return f"dyntype={dyntype!r}: activation dynamics are not simulated by tumble"
    if gaintype != "fixed" or biastype not in ("none", "affine"):
        return f"gaintype={gaintype!r}, biastype={biastype!r}: tumble simulates a fixed gain and an affine bias"
    gain = numbers(node, a, "gainprm", _UP_TO_TEN, [1.0])
    bias = np.zeros(3)
    if biastype == "affine":
        given = numbers(node, a, "biasprm", _UP_TO_TEN, [0.0])
        bias[: min(3, given.size)] = given[:3]
    return float(gain[0]), bias


def _limited(node: Node, a: dict[str, str], name: str, autolimits: bool) -> tuple[float, float] | None:
    """``ctrlrange`` or ``forcerange`` when ``ctrllimited``/``forcelimited`` (``auto``: when the range is given)."""
    limited = flag(node, a, name.replace("range", "limited"), "auto")
    if limited == "auto" and name in a and not autolimits:
        raise node.error(f"{name} without {name.replace('range', 'limited')}=... needs compiler autolimits='true'")
    if limited == "false" or (limited == "auto" and name not in a):
        return None
    low, high = numbers(node, a, name, 2, [0.0, 0.0])
    if not low < high:
        raise node.error(f"{name}={a.get(name)!r} must have its lower bound below the upper")
    return float(low), float(high)


def describe_actuator(node: Node, a: dict[str, str], joint_types: dict[str, str], tendons: set[str],
                      autolimits: bool,
                      note: Callable[[Node, str, str], None]) -> ActuatorDescription | None:  # fmt: skip
    """The actuator ``node`` (its attributes ``a`` resolved against the defaults), or None after a warning through
    ``note`` when tumble does not simulate it. ``joint_types``: each named joint's type; ``tendons``: the names of
    the fixed tendons."""
    kind = node.tag
    if kind not in _OWN:
        note(node, "element", "this actuator is not simulated by tumble; not loaded")
        return None
    for name in a:
        if name not in _KNOWN and name not in _OWN[kind] and name not in _TRANSMISSIONS:
            note(node, name, "not supported by tumble; ignored")
    given = [name for name in _TRANSMISSIONS if name in a]
    if given or ("joint" not in a and "tendon" not in a):
        note(node, given[0] if given else "joint", "tumble drives joints and fixed tendons only; not loaded")
        return None
    joint, tendon = a.get("joint"), a.get("tendon")
    if joint is not None and tendon is not None:
        raise node.error("an actuator has one transmission: joint= or tendon=, not both")
    if tendon is not None and tendon not in tendons:
        raise node.error(f"tendon={tendon!r} names no fixed tendon")
    if joint is not None and joint not in joint_types:
        raise node.error(f"joint={joint!r} names no joint")
    if joint is not None and joint_types[joint] not in ("hinge", "slide"):
        note(node, "joint", f"tumble drives hinges and slides, not a {joint_types[joint]}; not loaded")
        return None
    law = _law(node, kind, a)
    if isinstance(law, str):
        note(node, "element", f"{law}; not loaded")
        return None
    gear = numbers(node, a, "gear", (1, 2, 3, 4, 5, 6), [1.0])
    return ActuatorDescription(a.get("name"), kind, joint, float(gear[0]), law[0], law[1],
                               _limited(node, a, "ctrlrange", autolimits), node.line,
                               _limited(node, a, "forcerange", autolimits), tendon)  # fmt: skip
