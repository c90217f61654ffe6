"""Reading MJCF attribute values: lists of numbers, numbers, keywords and ``true``/``false``/``auto`` flags, each
refused with an :class:`~.xml.MJCFError` naming the element, its line and the text when it cannot be read."""

from __future__ import annotations

import numpy as np

from .xml import Node

__all__ = ["flag", "keyword", "number", "numbers"]


def numbers(node: Node, attrib: dict[str, str], name: str, count: int | tuple[int, ...] | None, default=None):
    """The finite numbers of ``attrib[name]`` (``count`` of them, one of the counts, or any number for None), else
    ``default`` (or None)."""
    text = attrib.get(name)
    if text is None:
        return None if default is None else np.array(default, dtype=float)
    shown = repr(text if len(text) <= 40 else text[:37] + "...")  # a mesh's vertex list is long
    try:
        values = np.array([float(word) for word in text.split()], dtype=float)
    except ValueError:
        raise node.error(f"{name}={shown} is not a list of numbers") from None
    counts = (count,) if isinstance(count, int) else count
    if (counts is not None and values.size not in counts) or not np.all(np.isfinite(values)):
        wanted = "" if counts is None else " or ".join(str(c) for c in counts) + " "
        raise node.error(f"{name}={shown} must be {wanted}finite numbers")
    return values


def number(node: Node, attrib: dict[str, str], name: str, default: float, nonnegative: bool = False) -> float:
    value = float(numbers(node, attrib, name, 1, [default])[0])
    if nonnegative and value < 0:
        raise node.error(f"{name}={attrib[name]!r} must be >= 0")
    return value


def keyword(node: Node, attrib: dict[str, str], name: str, default: str, allowed: tuple[str, ...]) -> str:
    value = attrib.get(name, default)
    if value not in allowed:
        raise node.error(f"{name}={value!r} must be one of {', '.join(allowed)}")
    return value


def flag(node: Node, attrib: dict[str, str], name: str, default: str) -> str:
    return keyword(node, attrib, name, default, ("true", "false", "auto"))
