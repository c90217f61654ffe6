"""The quadrotor against RotorPy (issue 19, part 1): the same Crazyflie, gains, references and wind, RotorPy's
flights stored by ``tests/rotorpy_reference.py`` in ``tests/data/rotorpy_reference.npz`` (no RotorPy needed here;
``tests/peers/test_rotorpy_live.py`` flies RotorPy itself when it is installed)."""

from __future__ import annotations

import numpy as np
import pytest

from rotorpy_reference import CASES, DATA, FIELDS, STORE_EVERY, error_statistics, tumble_flight

OPEN_LOOP = [name for name, case in CASES.items() if "trajectory" not in case]
CLOSED_LOOP = [name for name, case in CASES.items() if "trajectory" in case]


@pytest.fixture(scope="module")
def rotorpy():
    with np.load(DATA) as data:
        return {key: data[key] for key in data.files}


def _same_sign(q: np.ndarray, reference: np.ndarray) -> np.ndarray:
    return q * np.sign(np.sum(q * reference, axis=1))[:, None]


def deviation(flight: dict, rotorpy: dict, name: str, every: int = 1) -> dict[str, float]:
    """The largest difference of each state field over the stored samples."""
    out = {}
    for field in FIELDS:
        ours, theirs = flight[field][::every], rotorpy[f"{name}/{field}"]
        if field == "orientation":
            ours = _same_sign(ours, theirs)
        out[field] = float(np.abs(ours - theirs).max())
    return out


@pytest.mark.parametrize("name", OPEN_LOOP)
def test_open_loop_states_agree_with_rotorpy_to_1e_6_over_one_second(name, rotorpy):
    """Fixed rotor commands (the unequal set rolls and yaws the vehicle to 22 rad/s): tumble's RK4 at dt 1e-3 with
    the motors' exact lag against RotorPy's DOP853 at rtol 1e-10. Measured: 1.7e-7 rad/s on the body rates, 2e-9 on
    the quaternion, 3e-11 m on the position."""
    flight = tumble_flight(CASES[name], dt=1e-3)
    for field, value in deviation(flight, rotorpy, name).items():
        assert value < 1e-6, (field, value)


def test_the_open_loop_difference_shrinks_as_the_fourth_power_of_the_step(rotorpy):
    """Against an independent solver, RK4's error falls 10⁴-fold for a 10-fold smaller step."""
    coarse, fine = (deviation(tumble_flight(CASES["open_loop_unequal"], dt=dt), rotorpy, "open_loop_unequal")
                    for dt in (1e-2, 1e-3))  # fmt: skip
    ratio = coarse["angular_velocity_body"] / fine["angular_velocity_body"]
    assert 3e3 < ratio < 3e4


@pytest.mark.parametrize("name", CLOSED_LOOP)
def test_closed_loop_flights_follow_rotorpy_within_a_centimetre(name, rotorpy):
    """The SE(3) controller at 100 Hz, tumble's world at the control period: the positions agree to 1e-7 m over
    the 10 s (the issue asks for 1 cm over the first 5 s), the error statistics to 0.1 %."""
    flight = tumble_flight(CASES[name])
    gap = np.linalg.norm(flight["position"][::STORE_EVERY] - rotorpy[f"{name}/position"], axis=1)
    assert gap.max() < 1e-6
    np.testing.assert_allclose(flight["time"][::STORE_EVERY], rotorpy[f"{name}/time"], atol=1e-12)
    error = np.linalg.norm(flight["position"] - flight["reference"], axis=1)
    np.testing.assert_allclose(error_statistics(flight["time"], error), rotorpy[f"{name}/statistics"], rtol=1e-3)


@pytest.mark.parametrize("name", CLOSED_LOOP)
def test_closed_loop_flights_hold_at_a_finer_world_step(name, rotorpy):
    """The world at 1 kHz under the 100 Hz controller: the statistics within 10 % of RotorPy's (the flights differ
    only by the integration of each control period)."""
    flight = tumble_flight(CASES[name], dt=1e-3)
    error = np.linalg.norm(flight["position"] - flight["reference"], axis=1)
    np.testing.assert_allclose(error_statistics(flight["time"], error), rotorpy[f"{name}/statistics"], rtol=0.1)
    gap = np.linalg.norm(flight["position"][:501:STORE_EVERY] - rotorpy[f"{name}/position"][:101], axis=1)
    assert gap.max() < 0.01
