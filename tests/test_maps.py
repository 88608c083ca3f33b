"""The Poincare maps as discrete systems: iterating, linearising, the impact map."""

from __future__ import annotations

import math

import numpy as np

import grazing
from grazing.maps import ImpactMap, StroboscopicMap
from grazing.models import bouncing_ball, pendulum


def test_stroboscopic_map_iterates_are_the_samples_of_one_run():
    m = pendulum("B", eta=0.446, theta_hat=math.radians(40))
    P = StroboscopicMap(m)
    x0 = np.array([0.1, -0.2])
    its = P.iterate(x0, 12)
    sol = grazing.simulate(m, x0, periods=12, impacts="none")
    np.testing.assert_array_equal(its, sol.samples)
    np.testing.assert_allclose(P(x0), its[0], atol=1e-13)
    # P^5 applied once is the fifth iterate of P (a different split of the same flow).
    np.testing.assert_allclose(StroboscopicMap(m, periods=5)(x0), its[4], atol=1e-12)


def test_linearisation_is_the_jacobian_of_the_map():
    m = pendulum("B", eta=0.446, theta_hat=math.radians(40))
    P = StroboscopicMap(m, periods=5)
    x = np.array([-0.48, 0.47])  # near the period-5 orbit, which impacts once
    lin = P.linearize(x)
    assert lin.impacts >= 1
    fd = np.column_stack([(P(x + e) - P(x - e)) / 2e-7 for e in np.eye(2) * 1e-7])
    np.testing.assert_allclose(lin.jacobian, fd, atol=1e-5 * max(1.0, np.abs(fd).max()))


def test_impact_map_of_a_ball_on_a_floor():
    """Bounce k leaves with speed r^k v1: consecutive impact times differ by 2 r^k v1 / g."""
    g, r = 1.0, 0.5
    m = bouncing_ball(amplitude=0.0, gravity=g, r=r)
    first = ImpactMap(m).iterate([1.0, 0.0], 0.0, 1)
    v1 = first.speed[0]
    np.testing.assert_allclose(v1, math.sqrt(2 * g), rtol=1e-12)
    after = m.reset(first.state[0], first.t[0])
    nxt = ImpactMap(m).iterate(after, first.t[0], 4)
    expected_t = first.t[0] + np.cumsum([2 * r**k * v1 / g for k in range(1, 5)])
    np.testing.assert_allclose(nxt.t, expected_t, atol=1e-12)
    np.testing.assert_allclose(nxt.speed, v1 * r ** np.arange(1, 5), rtol=1e-11)
