"""How often a step finds each manifold's contacts (``narrow_phase.contact_passes``, issue 44)."""

import numpy as np

from tumble.geometry.narrow_phase import MAX_CONTACT_PASSES, contact_passes

DT = 1.0 / 60.0


def _passes(linvel, pairs, moving=(False, True, True, True)):
    """Bodies 0 (the ground, static) to 3, one shape each (shape i on body i), 10 cm boxes: the passes of ``pairs``."""
    shape_body = np.arange(4, dtype=np.int64)
    centre = np.zeros((4, 3))
    half = np.full((4, 3), 0.05)
    half[0] = np.inf  # a plane's bounds
    shape_a = np.array([a for a, _ in pairs], dtype=np.int64)
    shape_b = np.array([b for _, b in pairs], dtype=np.int64)
    passes = np.zeros(len(pairs), dtype=np.int64)
    most = contact_passes(shape_body, centre, half, np.array(moving), shape_a, shape_b, len(pairs),
                          np.asarray(linvel, dtype=float), np.zeros((4, 3)), DT, passes)  # fmt: skip
    return most, passes.tolist()


def test_slow_pairs_find_their_contacts_once_and_fast_ones_up_to_the_cap():
    still = np.zeros((4, 3))
    assert _passes(still, [(0, 1), (0, 2)]) == (1, [1, 1])
    # A 10 cm box's bounding radius is 8.7 cm: at 1 m/s it closes 1.7 cm in the step, 0.19 of it and less than
    # PASS_TRAVEL (a quarter); at 2 m/s 3.3 cm, 0.38 of it, so twice.
    fast = still.copy()
    fast[3] = (0.0, 0.0, -1.0)
    assert _passes(fast, [(0, 3)]) == (1, [1])
    fast[3] = (0.0, 0.0, -2.0)
    assert _passes(fast, [(0, 3)]) == (2, [2])
    fast[3] = (0.0, 0.0, -100.0)
    assert _passes(fast, [(0, 3)]) == (MAX_CONTACT_PASSES, [MAX_CONTACT_PASSES])


def test_a_body_in_a_fast_pair_finds_all_its_contacts_as_often():
    # Box 1 rests on the ground, box 3 falls onto it at 10 m/s, box 2 rests on the ground beside them. Struck at the
    # start of the step, box 1 turns within it: its ground contacts are found as often as the pair that strikes it
    # (a hull struck so put a corner its manifold had left out 2.7 cm into the ground). Box 2 is not in a fast pair.
    linvel = np.zeros((4, 3))
    linvel[3] = (0.0, 0.0, -10.0)
    most, passes = _passes(linvel, [(0, 1), (0, 2), (1, 3)])
    assert most == MAX_CONTACT_PASSES
    assert passes == [MAX_CONTACT_PASSES, 1, MAX_CONTACT_PASSES]
    # A body that does not move (static or asleep) passes nothing on: the ground's other pairs keep their count.
    most, passes = _passes(linvel, [(0, 1), (0, 2), (0, 3)])
    assert passes == [1, 1, MAX_CONTACT_PASSES]
