"""The discontinuity map on a model with several stops: kicks at the map's phase, whatever the other stops do.

Two identical forced oscillators that do not touch (states ``x_a``, ``y_b``), each with its own stop:
the map stands for ``Upper_A`` (at 0.999 of the free amplitude: the free motion grazes it every
period), and ``y_b`` hits ``ledge_B`` a little below the same amplitude, so a moment before the map's
phase, inside the step that ends there.  The map kicks at its phase ``t*`` (the free motion's maximum,
in closed form) and nowhere else: before the fix an impact on ``ledge_B`` in that step took the map
with it (a kick at the impact's time, the period's kick at ``t*`` skipped).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import grazing
from grazing import Parameter, Stop
from grazing.engine.runner import DiscontinuityMap
from grazing.sweeps.run import run_chunks
from grazing.sweeps.spec import sweep_spec


def twin_rattle() -> grazing.HybridModel:
    import sympy as sp

    x, v, y, w, t = sp.symbols("x_a v_a y_b w_b t")
    z, om, amp, g1, g2, r = sp.symbols("z Om amp g_1 g_2 r")
    force = amp * sp.cos(om * t)
    return grazing.HybridModel(
        "twin rattle", [x, v, y, w], t,
        [Parameter("z", 0.1), Parameter("Om", 0.8), Parameter("amp", 1.0), Parameter("g_1", 1.0),
         Parameter("g_2", 3.0), Parameter("r", 0.8)],
        vector_field=[v, -2 * z * v - x + force, w, -2 * z * w - y + force],
        stops=[Stop("Upper_A", g1 - x, [x, -r * v, y, w], [0, 1, 0, 0]),
               Stop("ledge_B", g2 - y, [x, v, y, -r * w], [0, 0, 0, 1])],
        period=2 * sp.pi / om,
    )  # fmt: skip


def free_motion(model: grazing.HybridModel) -> tuple[float, float, float]:
    """The free response's amplitude, its phase lag and its maximum's local time ``t*`` (closed form)."""
    p = model.params
    om, z, amp = p["Om"], p["z"], p["amp"]
    amplitude = amp / math.hypot(1 - om**2, 2 * z * om)
    lag = math.atan2(2 * z * om, 1 - om**2)
    return amplitude, lag, (lag / om) % model.period


@pytest.mark.parametrize("below", [0.999, 0.995, 0.99, 0.98])
def test_every_kick_is_at_the_maps_phase_with_another_stop_hit_just_before(below: float) -> None:
    base = twin_rattle()
    amplitude, lag, t_star = free_motion(base)
    model = base.with_params(g_1=0.999 * amplitude, g_2=below * amplitude)
    T, om = model.period, model.params["Om"]
    zdm = DiscontinuityMap(phase=t_star, accel=om**2 * amplitude, direction=(0.0, 1.8, 0.0, 0.0),
                           window=T / 4, stop=0)  # fmt: skip
    x0 = [amplitude * math.cos(lag), amplitude * math.sin(lag)] * 2  # (the free motion at t = 0, twice)
    sol = grazing.simulate(model, x0=x0, transient=0, periods=60, zdm=zdm)
    kicks, ledge = sol.impacts.stop == 0, sol.impacts.stop == 1
    assert kicks.sum() >= 10 and ledge.sum() >= 30
    before = t_star - np.mod(sol.impacts.t[ledge], T)
    assert np.all((before > 0) & (before < 0.35))  # (each ledge impact a moment before the map's phase)
    off = np.abs(np.mod(sol.impacts.t[kicks] - t_star + T / 2, T) - T / 2)
    assert off.max() < 1e-9 * T
    # the lanes (a sweep's kicks counted on the map's stop) kick as often as the scalar driver
    spec = sweep_spec(model, "amp", [1.0], x0=x0, zdm=zdm, settings=grazing.SweepSettings(
        transient=0, periods=60, adaptive=False, lyapunov=False, fresh=True))  # fmt: skip
    (res,) = run_chunks(spec, [0])
    assert res.impacts_by_stop[0].tolist() == [int(kicks.sum()), int(ledge.sum())]
