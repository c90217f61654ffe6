"""The body terms an articulation batch reads for the environments (``articulation/kernels.py``, ``_read_links``),
against statics: a ball resting on the ground is held by a contact force of ``m g`` straight up through its centre.

Two balls of different masses on one plane are two trees: each link's terms are about its own tree's centre of mass
(MuJoCo's ``subtree_com`` of its root), so a ball's first moment about that point is zero and its contact moment
about it vanishes. Checked with one-row (condim 1) and pyramid (condim 3) contacts, at 60 Hz, 240 Hz and 1 kHz.
"""

from __future__ import annotations

import numpy as np
import pytest

from tumble import Sphere
from tumble.articulation import Articulation, ArticulationBatch, Free
from tumble.articulation.kernels import (
    READOUT_INERTIA,
    READOUT_ORIGIN,
    READOUT_POINT,
    READOUT_VELOCITY,
    READOUT_WIDTH,
    READOUT_WRENCH,
)

GRAVITY = 9.81
BALLS = ((0.1, 2.0, (0.0, 0.0, 0.1)), (0.05, 0.5, (1.0, 0.5, 0.05)))  # radius [m], mass [kg], resting centre [m]


def _balls(condim: int) -> Articulation:
    art = Articulation(gravity=(0.0, 0.0, -GRAVITY))
    art.add_geom(None, "plane", condim=condim)
    for radius, mass, _ in BALLS:
        link = art.add_link(Free(), shape=Sphere(radius), mass=mass)
        art.add_geom(link, "sphere", (radius,), condim=condim)
    q = art.q
    for k, (_, _, centre) in enumerate(BALLS):
        q[7 * k : 7 * k + 3] = centre
    art.q = q
    return art


@pytest.mark.parametrize("hz", [60, 240, 1000])
@pytest.mark.parametrize("condim", [1, 3])
def test_balls_at_rest_are_held_by_m_g_through_their_centres(condim, hz):
    art = _balls(condim)
    art.simulate(2.0, 1.0 / hz, integrator="rk4", record_every=round(2.0 * hz))  # settle into the soft contact
    assert np.max(np.abs(art.qd)) < 1e-6
    batch = ArticulationBatch(art, 1)
    links = np.zeros((1, len(art.links), READOUT_WIDTH))
    batch._advance(1.0 / hz, 0, 2, readout=links)  # a fresh evaluation at the state (RK4's method code)
    for k, (radius, mass, centre) in enumerate(BALLS):
        row = links[0, k]
        np.testing.assert_allclose(row[READOUT_POINT : READOUT_POINT + 3], art.q[7 * k : 7 * k + 3], atol=1e-15)
        np.testing.assert_allclose(row[READOUT_ORIGIN : READOUT_ORIGIN + 3], art.q[7 * k : 7 * k + 3], atol=1e-15)
        assert row[READOUT_INERTIA + 9] == mass
        np.testing.assert_allclose(row[READOUT_INERTIA + 6 : READOUT_INERTIA + 9], 0.0, atol=1e-15)  # m (c - p)
        np.testing.assert_allclose(row[READOUT_INERTIA : READOUT_INERTIA + 3], 0.4 * mass * radius**2, rtol=1e-12)
        np.testing.assert_allclose(row[READOUT_VELOCITY : READOUT_VELOCITY + 6], 0.0, atol=1e-6)
        force, moment = row[READOUT_WRENCH + 3 : READOUT_WRENCH + 6], row[READOUT_WRENCH : READOUT_WRENCH + 3]
        np.testing.assert_allclose(force, (0.0, 0.0, mass * GRAVITY), rtol=0, atol=1e-6 * mass * GRAVITY)
        np.testing.assert_allclose(moment, 0.0, atol=1e-6 * mass * GRAVITY * radius)
        assert abs(art.q[7 * k + 2] - centre[2]) < 1e-3  # resting in the soft contact, not through the ground
