"""Resets that move the state off their guard: the root at the next step's start is not divided out.

A forced oscillator of unusual names (``wobbler``: ``q'' + 2 kap q' + q = frc cos(om tau)``) hits a wall at
``q = barrier`` (guard ``barrier - q``) and its reset moves it back by ``kick`` as it rebounds
(``q <- q - kick``, ``p <- -rest p``): after the reset the guard is ``kick``, not 0.  The engine divided
the root at ``u = 0`` out of the next step's guard polynomial all the same, so with a slow rebound
(``rest`` small) it took the return of the guard to ``kick`` within that step for an impact: spurious
impacts at the phantom wall ``q = barrier - kick``, each kicking the state further, until the events came
at zero time and the run failed ("events repeat at zero time").  The exact reference (matrix exponentials
and Brent's method, tests/piecewise_exact.py, with the affine reset) is independent of the engine.  A reset
that puts the state beyond the wall ends the run with ``OUTSIDE_MODE`` and a one-line message.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import sympy as sp

import grazing
from grazing import HybridModel, Parameter
from grazing.core.options import SweepSettings
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_lanes import assert_lanes_equal_the_oracle
from tests.piecewise_exact import LinearMode, PiecewiseLinearModel

q, p, tau = sp.symbols("q p tau")
kap, frc, om, barrier, kick, rest = sp.symbols("kap frc om barrier kick rest")
VALUES = {"kap": 0.05, "frc": 1.0, "om": 1.3, "barrier": 0.3, "kick": 0.05, "rest": 0.02}


def wobbler(**values: float) -> HybridModel:
    """The oscillator whose reset at the wall moves it back by ``kick`` (off the wall's guard)."""
    model = HybridModel(
        "wobbler", [q, p], tau, [Parameter(k, v) for k, v in VALUES.items()],
        vector_field=[p, -2 * kap * p - q + frc * sp.cos(om * tau)], guard=barrier - q,
        reset=[q - kick, -rest * p], period=2 * sp.pi / om,
    )  # fmt: skip
    return model.with_params(**values)


def exact_impacts(pv: dict, x0, t1: float) -> tuple[list[float], np.ndarray]:
    """The impact times in ``(0, t1]`` from ``x0`` at 0 and the state at ``t1`` (exact)."""
    A = np.array([[0.0, 1.0], [-1.0, -2 * pv["kap"]]])
    wall = (np.array([-1.0, 0.0]), pv["barrier"], 0)
    ref = PiecewiseLinearModel([LinearMode(A, np.array([0.0, pv["frc"]]), np.zeros(2), (wall,))], pv["om"])
    R, shift = np.diag([1.0, -pv["rest"]]), np.array([-pv["kick"], 0.0])
    x, t, times = np.asarray(x0, dtype=float), 0.0, []
    while (ev := ref.first_exit(0, x, t, t1)) is not None:
        tz = ev[0]
        times.append(tz)
        x, t = R @ ref.flow(0, x, t, tz) + shift, tz
    return times, ref.flow(0, x, t, t1)


@pytest.mark.parametrize("values", [{}, {"rest": 0.05, "frc": 2.0}, {"rest": 0.01, "kick": 0.001}])
def test_impacts_after_resets_off_the_wall_are_the_exact_ones(values: dict) -> None:
    model = wobbler(**values)
    periods = 8
    T = 2 * math.pi / model.params["om"]
    times, x_end = exact_impacts(dict(model.params), [0.0, 0.0], periods * T)
    sol = grazing.simulate(model, [0.0, 0.0], transient=0, periods=periods, impacts="all")
    assert len(times) >= 9
    assert len(sol.impacts) == len(times)
    assert np.abs(np.asarray(sol.impacts.t) - times).max() < 1e-9
    assert np.abs(sol.samples[-1] - x_end).max() < 1e-9
    after = np.asarray(sol.impacts.state)[:, 0] - model.params["barrier"]  # (every impact on the wall itself)
    assert np.abs(after).max() < 1e-9


def test_the_lanes_equal_the_scalar_driver() -> None:
    settings = SweepSettings(transient=6, periods=6, chunk_size=2, adaptive=False, lyapunov=False)
    spec = sweep_spec(wobbler(), "rest", [0.01, 0.02, 0.05, 0.3], x0=(0.0, 0.0), settings=settings)
    assert_lanes_equal_the_oracle(dataclasses.replace(spec, polish=False))


def test_a_reset_beyond_the_wall_ends_the_run_saying_so() -> None:
    beyond = wobbler(kick=-0.05)  # (q <- q + 0.05: past the wall)
    with pytest.raises(grazing.SimulationError) as caught:
        grazing.simulate(beyond, [0.0, 0.0], transient=0, periods=3)
    message = str(caught.value)
    assert message.startswith("an impact's reset at t = 0.8555") and "beyond stop 'stop'" in message
    assert "h = -0.05 < 0" in message and "\n" not in message
