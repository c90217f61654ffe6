"""Broad-phase benchmark: world bounds (``update_aabbs``) and sort-and-sweep pairs (``find_pairs``) alone.

Run through ``python -m benchmarks.run --only broad_phase``.

Two worlds at each size of :attr:`Sizes.broad_phase_shapes`, built through the API and packed:

- ``pile``: boxes of 1 m, 1.01 m apart, in layers of 10 × 10 (each box touches its neighbours' margins);
- ``scatter``: spheres, boxes, capsules and cylinders of random size and orientation spread through a cube whose
  side grows as the cube root of the count (about constant density).

No peer exposes its broad phase alone (MuJoCo's and PyBullet's run inside their step), so this one reports
tumble's own times: the best of ``max(repeat, 3)`` calls after a warm-up, in milliseconds, with the pairs found.
"""

from __future__ import annotations

import time

import numpy as np

import tumble
from tumble.geometry.broad_phase import PairBuffer, find_pairs, update_aabbs

__all__ = ["bench_broad_phase", "pile", "scatter"]

MARGIN = 0.02  # [m] as the contact step's default speculative margin
DT = 1 / 60


def pile(n: int) -> tumble.World:
    """``n`` boxes of 1 m in layers of 10 × 10, 1.01 m apart."""
    world = tumble.World()
    box = tumble.Box((1.0, 1.0, 1.0))
    for i in range(n):
        layer, k = divmod(i, 100)
        world.add_body(box, mass=1.0, position=(1.01 * (k % 10), 1.01 * (k // 10), 0.5 + 1.01 * layer))
    return world


def scatter(n: int, seed: int = 0) -> tumble.World:
    """``n`` primitives of random kind, size and orientation in a cube of side ``1.3 n^(1/3)``."""
    rng = np.random.default_rng(seed)
    world = tumble.World()
    side = 1.3 * n ** (1 / 3)
    for _ in range(n):
        kind, (a, b) = rng.integers(4), rng.uniform(0.1, 0.5, 2)
        shape = [tumble.Sphere(a), tumble.Box((a, b, a + b)), tumble.Capsule(a, b), tumble.Cylinder(a, b)][kind]
        quat = rng.normal(size=4)
        world.add_body(shape, mass=1.0, position=rng.uniform(0.0, side, 3), orientation=quat / np.linalg.norm(quat))
    return world


def _time_broad_phase(world: tumble.World, repeat: int) -> tuple[float, float, int]:
    """Best seconds of ``update_aabbs`` and of ``find_pairs`` over ``repeat`` calls, and the pairs found."""
    model, state = world.model, world.state
    geom = model.geometry
    lo, hi = np.zeros((len(model.shape_body), 3)), np.zeros((len(model.shape_body), 3))
    buffer = PairBuffer()
    bounds_args = (geom, state.body_pos, state.body_quat, state.body_linvel, MARGIN, DT, lo, hi)

    def pairs():
        return find_pairs(geom, state.body_pos, state.body_quat, lo, hi, model.body_is_dynamic, margin=MARGIN,
                          buffer=buffer)  # fmt: skip

    update_aabbs(*bounds_args)
    found, _ = pairs()  # compile, size the buffer
    best_bounds = best_pairs = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        update_aabbs(*bounds_args)
        t1 = time.perf_counter()
        found, _ = pairs()
        t2 = time.perf_counter()
        best_bounds, best_pairs = min(best_bounds, t1 - t0), min(best_pairs, t2 - t1)
    return best_bounds, best_pairs, len(found)


def bench_broad_phase(sizes) -> list[dict]:
    """One row per world and size: ``update_aabbs_ms``, ``find_pairs_ms``, ``pairs``."""
    rows = []
    for n in sizes.broad_phase_shapes:
        for name, build in (("pile", pile), ("scatter", scatter)):
            bounds_s, pairs_s, count = _time_broad_phase(build(n), max(sizes.repeat, 3))
            rows.append({
                "benchmark": "broad_phase", "world": name, "shapes": n,
                "update_aabbs_ms": 1e3 * bounds_s, "find_pairs_ms": 1e3 * pairs_s, "pairs": count,
            })  # fmt: skip
    return rows
