"""Changing values of a scene by their place in the file: ``{"bodies[0].friction": 0.3, "world.gravity[2]": -1.62}``.

A place is written as errors name it (``bodies[3].shape.extents[0]``): keys joined by dots, list items by their
index in brackets. The value replaces what the scene holds there, defaults included (``world.gravity[2]`` works in a
file that never sets gravity), and the changed scene is validated again, so an unknown key or a value out of range
is the usual :class:`SceneError` naming the place. ``tumble sweep`` and :func:`tumble.ensemble.run` build their
members this way.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from .build import SceneError

__all__ = ["apply", "parse_place"]

_STEP = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[(\d+)\]")


def parse_place(place: str) -> list[str | int]:
    """``"bodies[0].shape.extents[2]"`` → ``["bodies", 0, "shape", "extents", 2]``.

    Raises:
        SceneError: not a place of that form (names of letters, digits and ``_``; indices of digits).
    """
    if not isinstance(place, str):
        raise SceneError(f"a place in a scene must be a string like 'bodies[0].friction', got {place!r}")
    steps: list[str | int] = []
    at = 0
    while at < len(place):
        if steps and place[at] == ".":
            at += 1
        match = _STEP.match(place, at)
        if match is None or (match.group(1) is not None and steps and place[at - 1] != "."):
            raise SceneError(f"{place!r} is not a place in a scene: write keys joined by dots and list items by "
                             "their index, like 'bodies[0].friction' or 'world.gravity[2]'")  # fmt: skip
        steps.append(match.group(1) if match.group(1) is not None else int(match.group(2)))
        at = match.end()
    if not steps or isinstance(steps[0], int):
        raise SceneError(f"{place!r} is not a place in a scene: it must start with a key, like 'bodies[0].friction'")
    return steps


def _shown(steps: list[str | int]) -> str:
    return "".join(f"[{s}]" if isinstance(s, int) else (f".{s}" if i else s) for i, s in enumerate(steps))


def apply(data: dict, overrides: Mapping[str, object], label: str = "<scene>") -> dict:
    """``data`` (a scene as a dict, every default filled in) with each place of ``overrides`` set to its value.

    Only the containers along the changed places are copied: ``data`` itself is left as it was.

    Raises:
        SceneError: a place that is not written as one, or that the scene does not have: a list index past its end
            (naming how many items there are), or a key inside something the scene does not hold (``wind.mean``
            in a scene without wind). An unknown last key is left to the validation that follows.
    """
    out = dict(data)
    for place, value in overrides.items():
        steps = parse_place(place)
        node = out
        for depth, step in enumerate(steps):
            last = depth == len(steps) - 1
            shown = _shown(steps[: depth + 1])
            if isinstance(step, int):
                if not isinstance(node, list):
                    raise SceneError(f"{label}: {place}: {_shown(steps[:depth]) or 'the scene'} is not a list")
                if step >= len(node):
                    raise SceneError(f"{label}: {place}: {shown} is past the end ({_shown(steps[:depth])} has "
                                     f"{len(node)} item{'s' if len(node) != 1 else ''})")  # fmt: skip
            elif not isinstance(node, dict):
                raise SceneError(f"{label}: {place}: {_shown(steps[:depth])} is a {type(node).__name__}, not a table "
                                 "of keys")  # fmt: skip
            elif not last and node.get(step) is None:
                raise SceneError(f"{label}: {place}: the scene has no {shown}")
            if last:
                node[step] = value
            else:
                child = node[step]
                node[step] = child = list(child) if isinstance(child, list) else dict(child)
                node = child
    return out
