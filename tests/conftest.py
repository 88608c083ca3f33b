"""Shared fixtures."""

from __future__ import annotations

import math

import pytest

import grazing


@pytest.fixture(scope="session")
def pendulum_b():
    """Case B at theta_hat = 40 deg, eta = 0.446 (paper fig 9b: period-5)."""
    return grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))


@pytest.fixture(scope="session")
def period5_orbit(pendulum_b):
    """A point on the stable period-5 impacting orbit of case B, and its time."""
    sol = grazing.simulate(pendulum_b, [0.0, 0.0], transient=600, periods=10)
    assert sol.period() == 5
    return sol.samples[-1].copy(), float(sol.t[-1])
