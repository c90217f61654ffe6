"""A seeded mutation fuzzer over the shipped scenes, for ``tests/test_cli_fuzz.py`` (issue 21).

``mutant(seed, index)`` is the same file every time: the scene it starts from, what was done to it, and the bytes
to write. Mutations act on the scene's structure (a value replaced by one of another type or an extreme one, a key
or an item deleted, an item or a table duplicated, a value nested deep) or on its bytes (flipped, cut, inserted,
re-encoded). Replay one with ``python -c "from scene_fuzz import mutant; print(mutant(SEED, INDEX))"`` from
``tests/``.
"""

from __future__ import annotations

import copy
import json
import math
import random
import tomllib
from dataclasses import dataclass

from tumble import scene_file

__all__ = ["Mutant", "mutant"]

# Values a leaf may become: other types, the edges of the float range, what no format stores.
ODD_VALUES = [0, -1, 1, 2.5, -1e308, 1e308, 5e-324, 1e-320, math.nan, math.inf, -math.inf, True, False, "",
              "x", "\x00", "é", "../elsewhere.h5", [], {}, [1, 2], [[1, 2, 3]], 2**70, -(2**70), {"type": "x"},
              "sphere", "ball", "rk4", [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], 1e200, 1e-200]  # fmt: skip
SCALES = [0.0, -1.0, 1e-6, 1e6, 1e-300, 1e300, 0.5, 3.0]  # a number kept a number, made extreme
STRUCTURAL = ("scale", "scale", "scale", "replace", "replace", "delete", "duplicate", "nest", "swap_tables")
BYTE_LEVEL = ("flip", "cut", "insert", "reencode", "deep_text")


@dataclass(frozen=True)
class Mutant:
    seed: int
    index: int
    scene: str  # the shipped scene it starts from
    what: str  # what was done, to read in a failure
    suffix: str  # ".toml" or ".json"
    data: bytes

    def __str__(self) -> str:
        return f"mutant(seed={self.seed}, index={self.index}) of {self.scene}: {self.what}"


def _scenes() -> list[tuple[str, str]]:
    return [(path.stem, path.read_text(encoding="utf-8")) for path in scene_file.shipped()]


def _places(node, prefix=()):
    """Every (path, value) below ``node``, tables and lists included."""
    yield prefix, node
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _places(value, (*prefix, key))
    elif isinstance(node, list):
        for k, value in enumerate(node):
            yield from _places(value, (*prefix, k))


def _parent(tree, path):
    for key in path[:-1]:
        tree = tree[key]
    return tree


def _mutate_structure(rng: random.Random, tree: dict) -> str:
    places = [(path, value) for path, value in _places(tree) if path]
    kind = rng.choice(STRUCTURAL)
    numbers = [(p, v) for p, v in places if isinstance(v, (int, float)) and not isinstance(v, bool)]
    path, value = rng.choice(numbers if kind == "scale" and numbers else places)
    parent, key = _parent(tree, path), path[-1]
    if kind == "scale" and numbers:
        parent[key] = value * rng.choice(SCALES)
        return f"{path} = {parent[key]!r} (was {value!r})"
    if kind in ("replace", "scale"):
        new = copy.deepcopy(rng.choice(ODD_VALUES))
        parent[key] = new
        return f"{path} = {new!r}"
    if kind == "delete":
        del parent[key]
        return f"deleted {path}"
    if kind == "duplicate" and isinstance(value, list) and value:
        value.extend(copy.deepcopy(value[: rng.randint(1, len(value))]))
        return f"duplicated items of {path}"
    if kind == "nest":
        depth = rng.choice([1, 2, 5, 50])
        for _ in range(depth):
            value = [value]
        parent[key] = value
        return f"{path} nested {depth} deep"
    tables = [p for p, v in places if isinstance(v, dict)]
    source = rng.choice(tables) if tables else path
    parent[key] = copy.deepcopy(_parent(tree, source)[source[-1]])
    return f"{path} replaced by a copy of {source}"


def _mutate_bytes(rng: random.Random, text: str) -> tuple[bytes, str]:
    data = bytearray(text.encode("utf-8"))
    kind = rng.choice(BYTE_LEVEL)
    at = rng.randrange(len(data))
    if kind == "flip":
        data[at] ^= 1 << rng.randrange(8)
        return bytes(data), f"bit flipped in byte {at}"
    if kind == "cut":
        return bytes(data[:at]), f"cut after byte {at}"
    if kind == "insert":
        junk = bytes(rng.randrange(256) for _ in range(rng.randint(1, 8)))
        return bytes(data[:at] + junk + data[at:]), f"{junk!r} inserted at byte {at}"
    if kind == "reencode":
        encoding = rng.choice(["utf-16", "utf-32", "latin-1", "cp1252"])
        return text.encode(encoding, errors="replace"), f"encoded as {encoding}"
    depth = rng.choice([100, 5000])
    return text.encode() + f"\ndeep = {'[' * depth}{']' * depth}\n".encode(), f"an array nested {depth} deep appended"


def mutant(seed: int, index: int) -> Mutant:
    """The ``index``-th mutant of the run seeded ``seed``."""
    rng = random.Random(f"{seed}:{index}")
    name, text = rng.choice(_scenes())
    if rng.random() < 0.25:
        data, what = _mutate_bytes(rng, text)
        return Mutant(seed, index, name, what, ".toml", data)
    tree = tomllib.loads(text)
    whats = [_mutate_structure(rng, tree) for _ in range(rng.choice([1, 1, 2, 3]))]
    as_toml = rng.random() < 0.5
    if as_toml:
        try:
            return Mutant(seed, index, name, "; ".join(whats), ".toml", scene_file.dumps(tree).encode())
        except Exception:  # noqa: BLE001 - the TOML writer takes scene-shaped dicts only: JSON then
            pass
    try:
        data = json.dumps(tree).encode()
    except (ValueError, RecursionError):
        data = b"{}"
    return Mutant(seed, index, name, "; ".join(whats), ".json", data)
