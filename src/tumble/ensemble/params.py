"""The members' parameters: a grid (every combination) or random samples, and the checks every list of them passes."""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Mapping, Sequence

import numpy as np

__all__ = ["grid", "sample", "as_members"]


def _plain(value):
    """NumPy scalars as Python numbers (a scene's integer fields refuse ``np.int64``; JSON wants plain types)."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value


def _axis_values(name: str, values) -> list:
    if isinstance(values, (str, bytes)) or not isinstance(values, (Sequence, np.ndarray)):
        raise TypeError(f"{name}: give a sequence of values, got {values!r}")
    values = [_plain(v) for v in values]
    if not values:
        raise ValueError(f"{name}: no values")
    return values


def grid(axes: Mapping[str, Sequence]) -> list[dict]:
    """Every combination of the axes' values, the first axis varying slowest (as ``itertools.product``).

    >>> grid({"friction": [0.1, 0.5], "world.gravity[2]": [-9.81, -1.62]})[1]
    {'friction': 0.1, 'world.gravity[2]': -1.62}
    """
    if not isinstance(axes, Mapping) or not axes:
        raise ValueError(f"axes must be a non-empty mapping of names to values, got {axes!r}")
    names = list(axes)
    columns = [_axis_values(f"axes[{name!r}]", axes[name]) for name in names]
    return [dict(zip(names, combination, strict=True)) for combination in itertools.product(*columns)]


def sample(count: int, *, seed: int | None = None, uniform: Mapping[str, tuple[float, float]] | None = None,
           choice: Mapping[str, Sequence] | None = None) -> list[dict]:  # fmt: skip
    """``count`` members drawn at random: each ``uniform`` name from ``[low, high)``, each ``choice`` name from its
    values (equally likely); the same ``seed`` gives the same members.

    >>> sample(2, seed=1, uniform={"friction": (0.0, 1.0)}, choice={"every": [1, 2]})[0].keys()
    dict_keys(['friction', 'every'])
    """
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise ValueError(f"count must be a whole number >= 1, got {count!r}")
    uniform, choice = dict(uniform or {}), dict(choice or {})
    if not uniform and not choice:
        raise ValueError("give the names to draw: uniform={name: (low, high)} and/or choice={name: values}")
    both = set(uniform) & set(choice)
    if both:
        raise ValueError(f"{sorted(both)} given both as uniform and as choice")
    rng = np.random.default_rng(seed)
    columns = {}
    for name, bounds in uniform.items():
        low, high = bounds if isinstance(bounds, (tuple, list)) and len(bounds) == 2 else (None, None)
        if not all(isinstance(b, (int, float)) and math.isfinite(b) for b in (low, high)) or not low < high:
            raise ValueError(f"uniform[{name!r}]: give (low, high) with low < high, both finite, got {bounds!r}")
        columns[name] = rng.uniform(low, high, int(count)).tolist()
    for name, values in choice.items():
        values = _axis_values(f"choice[{name!r}]", values)
        columns[name] = [values[k] for k in rng.integers(0, len(values), int(count))]
    return [{name: columns[name][k] for name in columns} for k in range(int(count))]


def as_members(params, reserved: Sequence[str]) -> list[dict]:
    """``params`` checked as a list of members: each a dict of names (str, none of ``reserved``, the table's own
    columns) to JSON values, NumPy scalars made plain."""
    if isinstance(params, Mapping) or isinstance(params, (str, bytes)) or not isinstance(params, Sequence):
        raise TypeError(f"params must be a list of dicts (one per member; tumble.ensemble.grid makes one), got "
                        f"{type(params).__name__}")  # fmt: skip
    if not params:
        raise ValueError("params: no members (an empty list)")
    members = []
    for k, member in enumerate(params):
        if not isinstance(member, Mapping):
            raise TypeError(f"params[{k}] must be a dict of names to values, got {member!r}")
        plain = {}
        for name, value in member.items():
            if not isinstance(name, str):
                raise TypeError(f"params[{k}]: names must be strings, got {name!r}")
            if name in reserved:
                raise ValueError(f"params[{k}]: {name!r} is a column of the results table; call the parameter "
                                 "something else")  # fmt: skip
            value = _plain(value)
            try:
                json.dumps(value, allow_nan=True)
            except (TypeError, ValueError):
                raise TypeError(f"params[{k}][{name!r}] must be a number, a string, a bool or a list of them (it "
                                f"is stored with the trajectory), got {value!r}") from None  # fmt: skip
            plain[name] = value
        members.append(plain)
    return members
