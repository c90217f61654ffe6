"""How deep the contacts of a pile go (issue 44): the deepest overlap any step's contacts report, into static
geometry (the ground, the bowl) and between two bodies, and the lowest any body's centre of mass went. For
``tests/analytic/test_scenes.py`` and for the sweeps of docs/contact.md ("Deep overlaps in piles"):

    python tests/overlap_depths.py drop|bowl RATE SEED [SEED ...] [--substeps N]

``drop`` is ``scenes.mixed_drop(60, seed)`` for 3 s, ``bowl`` is ``scenes.mixed_pile(50, seed)`` for 4 s.
"""

from __future__ import annotations

import argparse

import numpy as np

from tumble import World, scenes


def overlap_depths(world: World, rate: float, duration: float) -> tuple[float, float, float]:
    """Step ``world`` at ``rate`` Hz for ``duration`` s: the deepest overlap into static bodies and between two
    bodies that any step's contacts report [m] (0 if none overlapped), and the lowest height (z) any body's
    centre of mass reached [m].

    Overlaps the scene was built with are not the simulation's: a pair overlapping at the first step counts only
    once it has come apart (``scenes.mixed_pile`` drops some hulls into each other's bounds, 3-5 cm deep)."""
    static = np.array([body.is_static for body in world.bodies])
    into_static = between_bodies = 0.0
    lowest = np.inf
    as_built: set[tuple[int, int]] | None = None
    for _ in range(round(duration * rate)):
        world.step(1.0 / rate)
        contacts = world.contacts()
        pairs = list(zip(contacts.shape_a.tolist(), contacts.shape_b.tolist(), strict=True))
        overlapping = {pair for pair, separation in zip(pairs, contacts.separation, strict=True) if separation < 0.0}
        as_built = overlapping if as_built is None else as_built & overlapping
        counted = np.array([pair not in as_built for pair in pairs], dtype=bool)
        on_static = static[contacts.body_a] | static[contacts.body_b]
        into_static = max(into_static, -contacts.separation[counted & on_static].min(initial=0.0))
        between_bodies = max(between_bodies, -contacts.separation[counted & ~on_static].min(initial=0.0))
        lowest = min(lowest, world.state.body_pos[~static, 2].min())
    return into_static, between_bodies, lowest


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", choices=("drop", "bowl"))
    parser.add_argument("rate", type=float)
    parser.add_argument("seeds", type=int, nargs="+")
    parser.add_argument("--substeps", type=int, default=8)
    args = parser.parse_args()
    for seed in args.seeds:
        if args.scene == "drop":
            world, duration = scenes.mixed_drop(60, seed, substeps=args.substeps), 3.0
        else:
            world, duration = scenes.mixed_pile(50, seed, substeps=args.substeps), 4.0
        into_static, between_bodies, lowest = overlap_depths(world, args.rate, duration)
        print(f"{args.scene} seed {seed} at {args.rate:g} Hz: into static {100 * into_static:.2f} cm, between bodies "
              f"{100 * between_bodies:.2f} cm, lowest centre {100 * lowest:.2f} cm")  # fmt: skip


if __name__ == "__main__":
    main()
