"""The energy cap of a joint bounce (``contact_solver._energy_safe_share``, issue 50): scaled by the share it gives,
a bounce's impulses leave a body exactly the energy it had, and a bounce that gives energy back is left whole."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from tumble.dynamics.contact_solver import _apply_impulse, _energy_safe_share

MASS = 2.0
INERTIA = np.array([[0.30, 0.02, 0.00], [0.02, 0.20, 0.01], [0.00, 0.01, 0.10]])  # world frame, anisotropic
NORMAL = (0.0, 0.0, 1.0)
ARMS = np.array([[0.15, 0.10, -0.05], [-0.15, 0.05, -0.05], [0, 0, 0], [0, 0, 0]])  # two points touching
ZERO = (0.0, 0.0, 0.0)


def bounce(impulses, g_n=0.0, lead=0.0):
    """A body (b) closing on the ground (a, fixed) takes ``impulses`` at its two points: the share, and its
    energy change over what the loads take back (``g_n · lead · Σλ``), before and after the share is applied."""
    inv_inertia = tuple(np.linalg.inv(INERTIA).ravel())
    v, w = (0.3, -0.1, -2.0), (4.0, -7.0, 2.5)
    v2, w2 = v, w
    for arm, impulse in zip(ARMS[:2], impulses, strict=True):
        _, _, v2, w2 = _apply_impulse(tuple(arm), tuple(arm), (0.0, 0.0, impulse), 0.0, (0.0,) * 9, 1 / MASS,
                                      inv_inertia, ZERO, ZERO, v2, w2)  # fmt: skip
    impulse = np.array([*impulses, 0.0, 0.0])
    u_surface = np.array([1.0, 1.0, -1.0, -1.0])
    rows = SimpleNamespace(point_count=np.array([2]))
    share = _energy_safe_share(rows, 0, NORMAL, impulse, u_surface, ARMS, ARMS, ZERO, ZERO, v, w, ZERO, ZERO, v2, w2,
                               g_n, lead)  # fmt: skip

    def energy(velocity, spin):
        return 0.5 * MASS * np.dot(velocity, velocity) + 0.5 * np.dot(spin, INERTIA @ np.asarray(spin))

    def change(s):  # the impulses scaled by s: the velocities move by s times their change
        scaled_v = np.add(v, s * np.subtract(v2, v))
        scaled_w = np.add(w, s * np.subtract(w2, w))
        return energy(scaled_v, scaled_w) - energy(v, w) - g_n * lead * s * sum(impulses)

    return share, change(1.0), change(share), energy(v, w)


@pytest.mark.parametrize(("g_n", "lead"), [(0.0, 0.0), (9.81, 0.001), (9.81, -0.001)])
def test_a_bounce_that_would_add_energy_is_scaled_to_add_none(g_n, lead):
    share, whole, capped, start = bounce([4.0, 3.0], g_n, lead)
    assert whole > 0.1 * start  # the impulses as given add energy
    assert 0.0 < share < 1.0
    assert abs(capped) < 1e-12 * start  # the cap is the root of A s + B s²: exactly none


def test_a_bounce_that_takes_energy_is_left_whole():
    share, whole, _, _ = bounce([0.5, 0.3])
    assert whole < 0.0
    assert share == 1.0
