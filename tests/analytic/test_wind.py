"""Wind (issue 17, part 4): constant, sinusoidal and Dryden winds, and what drag and rotors make of them."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import tumble
from tumble.actuators import Rotor
from tumble.wind import Constant, Dryden, Sinusoid


def autocorrelation(x: np.ndarray, lags: np.ndarray) -> np.ndarray:
    x = x - x.mean()
    n = x.size
    return np.array([np.dot(x[: n - lag], x[lag:]) / (n - lag) for lag in lags]) / x.var()


@pytest.mark.parametrize("dt", [pytest.param(1e-3, marks=pytest.mark.slow), 1e-2])  # 1e-3: a million steps, 20 s
def test_dryden_gusts_have_the_intensity_and_correlation_time_of_the_spectrum(dt):
    """σ = (1, 0.7, 0.5) m/s, L = 0.5 m carried at 5 m/s (T = 0.1 s), 1000 s: the standard deviations, and the
    correlation times fitted to e^(−τ/T) (u) and (1 − τ/2T) e^(−τ/T) (v, w), within 10 % (measured within 4 %)."""
    sigma, t_corr = np.array([1.0, 0.7, 0.5]), 0.1
    wind = Dryden((0.0, 5.0, 0.0), sigma, 0.5, seed=1)
    gusts = np.array([wind.velocity(0.0, dt) - wind.mean for _ in range(round(1000 / dt))]) @ wind.axes
    np.testing.assert_allclose(gusts.std(axis=0), sigma, rtol=0.10)
    lags = np.arange(0, round(3 * t_corr / dt) + 1, max(1, round(0.1 * t_corr / dt)))
    shapes = [lambda tau, t: np.exp(-tau / t)] + 2 * [lambda tau, t: (1 - tau / (2 * t)) * np.exp(-tau / t)]
    for k, shape in enumerate(shapes):
        measured = autocorrelation(gusts[:, k], lags)
        fit = minimize_scalar(lambda t, m=measured, f=shape: np.sum((f(lags * dt, t) - m) ** 2),
                              bounds=(t_corr / 10, 10 * t_corr), method="bounded")  # fmt: skip
        assert fit.x == pytest.approx(t_corr, rel=0.10), f"gust component {'uvw'[k]}"


def test_dryden_repeats_with_its_seed_and_blows_along_its_mean():
    a, b, c = (Dryden((3.0, 4.0, 0.0), 1.0, 10.0, seed=s) for s in (4, 4, 5))
    first = [a.velocity(0.0, 0.01) for _ in range(100)]
    np.testing.assert_array_equal(first, [b.velocity(0.0, 0.01) for _ in range(100)])
    assert not np.array_equal(first, [c.velocity(0.0, 0.01) for _ in range(100)])
    np.testing.assert_allclose(a.axes[:, 0], (0.6, 0.8, 0.0))  # u along the mean wind
    np.testing.assert_allclose(a.axes[:, 2], (0.0, 0.0, 1.0))  # w vertical
    np.testing.assert_allclose(a.axes.T @ a.axes, np.eye(3), atol=1e-15)


def test_a_body_with_drag_slows_to_the_wind_as_the_closed_form():
    """Quadratic drag in a 1-D wind: m u̇ = −c |u| u for the air-relative speed u, so u = u0 / (1 + c u0 t / m)."""
    world = tumble.World(gravity=(0, 0, 0), integrator="rk4")
    body = world.add_body(tumble.Sphere(0.1), mass=1.5)
    world.add_drag(body, (0.8, 0.8, 0.8))
    world.wind = Constant((4.0, 0.0, 0.0))
    world.simulate(3.0, 1e-3)
    relative = 4.0 / (1 + 0.8 * 4.0 * 3.0 / 1.5)
    np.testing.assert_allclose(body.velocity, (4.0 - relative, 0.0, 0.0), atol=1e-9)


def test_a_rotor_in_a_crosswind_feels_its_drag_and_inflow():
    """At rest in a wind, the hub's air velocity is −wind: explicit Euler's first step is the force itself."""
    world = tumble.World(gravity=(0, 0, 0), integrator="euler")
    body = world.add_body(tumble.Sphere(0.1), mass=2.0)
    rotor = world.add_actuator(Rotor(body, (0, 0, 0), (0, 0, 1), 1, 1e-6, 0.0, k_drag=3e-4, k_inflow=5e-4))
    rotor.speed = 1000.0
    rotor.command(1000.0)
    world.wind = (2.0, 0.0, -1.0)
    world.step(1e-4)
    air = np.array([-2.0, 0.0, 1.0])
    across, along = air * (1, 1, 0), air[2] * np.array([0, 0, 1])
    force = 1e-6 * 1000.0**2 * np.array([0, 0, 1]) - 1000.0 * (3e-4 * across + 5e-4 * along)
    np.testing.assert_allclose(body.velocity, force / 2.0 * 1e-4, rtol=1e-12)


def test_a_steady_sinusoid_is_a_constant_wind_step_by_step_or_in_one_call():
    """The same wind through the stepwise path (Sinusoid) and the compiled one (Constant): the same bits."""

    def drifting(wind):
        world = tumble.World()
        world.add_static(tumble.Plane())
        body = world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=1.0, position=(0, 0, 2.0))
        world.add_drag(body, (0.5, 0.5, 0.5))
        world.wind = wind
        world.simulate(1.0, 1 / 120)
        return world.state.body_pos.copy()

    np.testing.assert_array_equal(drifting(Sinusoid((3, 1, 0), (0, 0, 0), 1.0)), drifting(Constant((3, 1, 0))))
    assert not np.array_equal(drifting(Sinusoid((3, 1, 0), (2, 0, 0), 1.0)), drifting(Constant((3, 1, 0))))


def test_a_sinusoid_is_taken_at_the_middle_of_each_step():
    wind = Sinusoid((1, 0, 0), (0, 2, 0), 0.5)
    np.testing.assert_allclose(wind.velocity(0.4, 0.2), (1, 2 * math.sin(math.pi * 0.5), 0), rtol=1e-15)


def test_a_world_in_dryden_wind_repeats_with_the_seed():
    def flown(seed):
        world = tumble.World(gravity=(0, 0, 0))
        body = world.add_body(tumble.Sphere(0.1), mass=0.5)
        world.add_drag(body, (0.1, 0.1, 0.1))
        world.wind = Dryden((2.0, 0.0, 0.0), 0.5, 5.0, seed=seed)
        world.simulate(2.0, 0.01)
        return body.position

    np.testing.assert_array_equal(flown(9), flown(9))
    assert not np.array_equal(flown(9), flown(10))


@pytest.mark.parametrize(
    ("make", "error", "message"),
    [
        (lambda: Dryden((0, 0, 0), 1.0, 5.0), ValueError, r"mean must be a non-zero wind"),
        (lambda: Dryden((1, 0, 0), -1.0, 5.0), ValueError, r"sigma must be a number > 0 or three of them"),
        (lambda: Dryden((1, 0, 0), 1.0, (5.0, 0.0, 1.0)), ValueError, r"length_scale must be a number > 0"),
        (lambda: Dryden((1, 0, 0), 1.0, 5.0, seed=-2), ValueError, r"seed must be an integer >= 0 or None, got -2"),
        (lambda: Sinusoid((1, 0, 0), (1, 0, 0), -1.0), ValueError, r"frequency must be >= 0, got -1.0"),
        (lambda: Constant((1, 0)), ValueError, r"v"),
    ],
)
def test_bad_winds_are_refused(make, error, message):
    with pytest.raises(error, match=message):
        make()


def test_the_world_takes_a_model_a_vector_or_none():
    world = tumble.World()
    world.wind = (1.0, 2.0, 3.0)
    assert isinstance(world.wind, Constant) and world.wind.v.tolist() == [1.0, 2.0, 3.0]
    world.wind = None
    assert world.wind is None
    with pytest.raises(TypeError, match=r"wind must be None, a 3-vector or a tumble.wind model"):
        world.wind = "gusty"
