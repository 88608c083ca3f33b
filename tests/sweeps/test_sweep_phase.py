"""Sweeps in a parameter that sets the forcing period keep the forcing phase (issue 11, case 3).

A continuation sweep carries each point's last sample (at the stroboscopic phase)
to the next point, which has another period: the next point must start at that
phase of its own period.  Swept down from the nonimpacting orbit, the impact
oscillator must not impact above its closed-form grazing frequency, and every
point must agree with the same chain simulated point by point.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import grazing
from grazing.models import impact_oscillator
from grazing.sweeps import sweep

SIGMA, ZETA = 0.1, 0.05
TRANSIENT, PERIODS = 150, 20


def grazing_omega() -> float:
    return brentq(lambda w: 1 / math.hypot(1 - w * w, 2 * ZETA * w) - SIGMA, 2.5, 4.0, xtol=1e-15)


def point_by_point(model, values, x0, phase):
    """The same chain as a continuation sweep, one ``simulate`` per point, at the same phase."""
    x = np.asarray(x0, dtype=float)
    samples = []
    for i, w in enumerate(values):
        m = model.with_params(omega=w)
        t0 = 0.0 if i == 0 else phase / (2 * math.pi) * m.period
        sol = grazing.simulate(m, x, t0=t0, transient=TRANSIENT, periods=PERIODS, phase=phase, tol=1e-10)
        samples.append(sol.samples)
        x = sol.x_final
    return np.array(samples)


@pytest.mark.parametrize(("direction", "phase"), [("down", 0.0), ("down", 1.3), ("up", 0.0)])
def test_sweep_in_omega_agrees_with_point_by_point_simulation(direction, phase):
    model = impact_oscillator(sigma=SIGMA, zeta=ZETA)
    values = np.linspace(3.30, 3.60, 31)
    order = values if direction == "up" else values[::-1]
    # Start on the nonimpacting orbit of the first point (closed form at t = 0); from rest
    # the oscillator may settle on a coexisting impacting orbit instead.
    w = order[0]
    H = 1 / (1 - w * w + 2j * ZETA * w)
    x0 = [H.real, (1j * w * H).real]
    ds = sweep(
        model, "omega", values, x0=x0, transient=TRANSIENT, periods=PERIODS, phase=phase, direction=direction,
        chunk_size=0, adaptive=False, lyapunov=False, workers=1,
    )  # fmt: skip
    reference = point_by_point(model, order, x0, phase)
    got = ds.sortby("value").samples.values
    expected = reference if direction == "up" else reference[::-1]
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-8)
    if direction == "down":
        # From the nonimpacting orbit downwards: no impact well above the grazing frequency.
        # (Just above it the transient after a step in omega may touch the stop and settle on
        # the coexisting impacting orbit; the point-by-point chain above does the same.)
        above = ds.value.values > grazing_omega() + 0.03
        assert above.sum() >= 20
        assert (ds.impacts.values[above] == 0).all()
