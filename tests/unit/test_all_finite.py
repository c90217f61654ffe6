"""``_validate.all_finite``, the finite check of every array a public call takes (issue 46: it runs before every
step of a controller that passes ``tau``): a small array is summed first, so the sum's edge cases must not fool it."""

from __future__ import annotations

import numpy as np
import pytest

import tumble
from tumble._validate import all_finite
from tumble.envs.double_pendulum import DoublePendulumTask


@pytest.mark.parametrize("size", [1, 2, 21, 64, 65, 1000])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_nan_or_an_infinity_anywhere_is_found(size, bad):
    for where in {0, size // 2, size - 1}:
        array = np.linspace(-1.0, 1.0, size)
        array[where] = bad
        assert not all_finite(array)
        assert not all_finite(array.reshape(1, size))


@pytest.mark.parametrize("size", [2, 64, 65])
def test_finite_values_whose_sum_overflows_are_finite(size):
    array = np.full(size, 1.7e308)
    array[1::2] = -1.7e308 if size > 64 else 1.7e308
    assert all_finite(array)
    assert all_finite(np.array([1.7e308, 1.7e308, -np.finfo(float).max]))


def test_infinities_of_both_signs_are_not_finite():
    assert not all_finite(np.array([np.inf, -np.inf]))
    assert all_finite(np.zeros(0)) and all_finite(np.zeros((3, 0)))


def test_articulation_step_still_names_a_non_finite_tau():
    art = DoublePendulumTask().articulation()
    assert art.nv == 3
    with pytest.raises(ValueError, match=r"tau must be finite, got \[1.0, nan, 0.0\]"):
        art.step(0.01, [1.0, np.nan, 0.0])
    with pytest.raises(ValueError, match=r"tau must be finite, got \[inf, -inf, 0.0\]"):
        art.step(0.01, [np.inf, -np.inf, 0.0])
    before = art.q.copy()
    with pytest.raises(tumble.SimulationError):  # finite, however large: accepted, and the state that fails is named
        art.step(0.01, [1.7e308, 1.7e308, 1.7e308])
    np.testing.assert_array_equal(art.q, before)
