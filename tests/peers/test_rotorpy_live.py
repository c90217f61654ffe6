"""The quadrotor against RotorPy itself (issue 19): the stored reference flights are what RotorPy flies today, and
tumble flies them as it does. Skipped unless RotorPy (3.0 or later) is installed."""

from __future__ import annotations

import numpy as np
import pytest

from rotorpy_reference import CASES, DATA, FIELDS, STORE_EVERY, rotorpy_flight, tumble_flight

pytest.importorskip("rotorpy")
pytestmark = pytest.mark.peers


@pytest.mark.parametrize("name", list(CASES))
def test_rotorpy_flies_the_stored_references_and_tumble_flies_them_too(name):
    case = CASES[name]
    live = rotorpy_flight(case)
    every = STORE_EVERY if "trajectory" in case else 1
    with np.load(DATA) as stored:
        for field in FIELDS:
            np.testing.assert_allclose(live[field][::every], stored[f"{name}/{field}"], atol=1e-8, err_msg=field)
    ours = tumble_flight(case, dt=1e-3 if "trajectory" not in case else None)
    assert np.abs(ours["position"] - live["position"]).max() < 1e-6
