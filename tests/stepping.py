"""Stepping a world through changes, for the tests of what a step keeps between calls (the compiled record, the
prepared step): the same changes and steps with and without what is kept must give the same bits."""

from __future__ import annotations


def steps_through(world, dt: float, changes, before_each_step=None, seconds: float = 1.0 / 12.0) -> list[str]:
    """The digests after every step: ``seconds`` of steps (at least 5), then each change (a function of the world) and
    as many steps again; ``before_each_step(world)`` runs before every step (to drop what is kept)."""
    seen = []
    for change in [None, *changes]:
        if change is not None:
            change(world)
        for _ in range(max(5, round(seconds / dt))):
            if before_each_step is not None:
                before_each_step(world)
            world.step(dt)
            seen.append(world.state.digest())
    return seen
