"""The discontinuity map on a model with modes: a stop of one mode, kicked only while the run is in it.

The bumper oscillator (``tests/engine/zdm_modes_model.py``): a soft spring beyond a gap (mode ``Taut_2``)
and a rigid bumper ``Bumper_9`` inside it.  Its period-1 orbit grazes the bumper at ``F_0 = F*``; the map
is the normal form's there.  Nordmark's map at leading order replaces the impact by a kick
``S = sqrt(2 a delta)`` whose error is of the next order, ``O(delta)``: over one period from the grazing
orbit, the map's state differs from the impacting flow's by ``O(mu)`` while the kick is ``O(sqrt(mu))``
(``mu`` the distance past the grazing, ``delta ~ mu``), and a sweep of the map has the flow's periods near
the grazing (the paper's point: the map's orbits approximate the true ones).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import grazing
from grazing.engine.runner import DiscontinuityMap
from grazing.errors import InvalidParameterError
from grazing.normalform import find_grazing_point, normal_form_at
from grazing.sweeps.run import run_chunks
from grazing.sweeps.spec import sweep_spec
from tests.engine.zdm_modes_model import bumper_oscillator

MUS = (-1e-3, 1e-5, 1e-4, 1e-3, 1e-2)
"""Relative distances from the grazing in ``F_0``: below it, then past it."""


@pytest.fixture(scope="module")
def grazed() -> tuple[object, DiscontinuityMap]:
    """The grazing of ``Bumper_9`` in ``F_0`` and the map there."""
    point = find_grazing_point(bumper_oscillator(), "F_0", 0.2, 1.5, "first", "Bumper_9")
    return point, normal_form_at(point, ("F_0",)).discontinuity_map()


def orbit_state(point, phase: float) -> tuple[np.ndarray, float, str]:
    """The grazing orbit's state at local time ``phase``: ``(x, t, mode)`` (the bumper ignored)."""
    start = point.contact - [1e-9, 0.0]
    sol = grazing.simulate(point.model, start, t0=point.t_graze, mode="Taut_2", events=False, periods=1,
                           transient=0, phase=2 * math.pi * phase / point.model.period)  # fmt: skip
    return sol.samples[0], float(sol.t[0]), sol.mode_final


def test_the_map_is_built_at_the_grazing_of_a_stop_of_one_mode(grazed) -> None:
    point, zdm = grazed
    assert point.mode == "Taut_2" and point.stop_name == "Bumper_9" and zdm.stop == 1
    assert abs(point.contact[0] - 1.5) < 1e-9 and abs(point.contact[1]) < 1e-9
    assert np.allclose(zdm.direction, [0.0, 1.8])  # (p <- -r p: e = (0, 1 + r))
    # a = L_f^2 h = -p' at the contact, from mode Taut_2's field
    p = point.model.params
    t = point.t_graze
    accel = -(-1.5 + p["F_0"] * math.cos(p["Om"] * t) - p["k_soft"] * (1.5 - p["d_gap"]))
    assert abs(zdm.accel - accel) < 1e-8


def test_one_period_of_the_map_differs_from_the_impact_by_the_next_order(grazed) -> None:
    """From the grazing orbit half a period before the contact (in mode ``Slack_1``), one period: the
    map's error falls tenfold per decade of ``mu`` (order ``mu``), the kick by sqrt(10) (order
    sqrt(mu)), and the impact and the kick are one each."""
    point, zdm = grazed
    T = point.model.period
    x, t0, mode = orbit_state(point, (point.phase - T / 2) % T)
    assert mode == "Slack_1"
    errors, kicks = [], []
    for mu in (1e-3, 1e-4, 1e-5, 1e-6):
        m = point.model.with_params(F_0=point.model.params["F_0"] * (1 + mu))
        kw = dict(t0=t0, periods=1, transient=0, mode=mode, phase=2 * math.pi * (t0 % T) / T, impacts="all")
        flow, mapped = grazing.simulate(m, x, **kw), grazing.simulate(m, x, zdm=zdm, **kw)
        kw.pop("impacts")
        virtual = grazing.simulate(m, x, events=False, **kw)
        assert len(flow.impacts) == 1 and len(mapped.impacts) == 1
        assert abs(mapped.impacts.t[0] % T - zdm.phase) < 1e-9  # (the kick at the map's phase)
        errors.append(np.abs(flow.samples[-1] - mapped.samples[-1]).max())
        kicks.append(np.abs(virtual.samples[-1] - mapped.samples[-1]).max())
    for a, b in itertools.pairwise(errors):
        assert 0.07 < b / a < 0.13, errors
    for a, b in itertools.pairwise(kicks):
        assert 0.25 < b / a < 0.4, kicks
    assert errors[-1] < 0.01 * kicks[-1]


@pytest.mark.parametrize("lyapunov", [False, True])
def test_a_sweep_of_the_map_has_the_flows_periods_near_the_grazing(grazed, lyapunov: bool) -> None:
    """The lanes, chained from the grazing orbit: period 1 below the grazing, then the flow's period-5
    orbit with one impact in five periods, which the map reproduces with one kick in five."""
    point, zdm = grazed
    model = bumper_oscillator(initial_mode="Taut_2")  # (the grazing orbit is in Taut_2 at t = 0)
    x0, _, mode = orbit_state(point, 0.0)
    assert mode == "Taut_2"
    values = [point.model.params["F_0"] * (1 + mu) for mu in MUS]
    settings = grazing.SweepSettings(transient=300, periods=20, lyapunov=lyapunov, chunk_size=0)
    flow, mapped = (run_chunks(sweep_spec(model, "F_0", values, x0=x0, zdm=z, settings=settings), [0])[0]
                    for z in (None, zdm))  # fmt: skip
    assert flow.period.tolist() == mapped.period.tolist() == [1, 5, 5, 5, 5]
    assert flow.impacts_by_stop.tolist() == mapped.impacts_by_stop.tolist() == [[0, 0, 0]] + [[0, 4, 0]] * 4
    assert (flow.status == 0).all() and (mapped.status == 0).all()


def test_no_kick_while_the_run_is_in_another_mode(grazed) -> None:
    """The same map standing for a bumper of mode ``Slack_1`` (never reached there): at the map's phase
    the run is in ``Taut_2``, past the bumper's guard, where the map would kick; it does not, and the run
    is the one without the map (to rounding: its steps are cut at the map's phase)."""
    point, zdm = grazed
    x0, _, _ = orbit_state(point, 0.0)
    for where, kicked in (("Taut_2", True), ("Slack_1", False)):
        model = bumper_oscillator(
            bumper_mode=where, initial_mode="Taut_2", F_0=point.model.params["F_0"] * 1.01
        )
        stop = model.stop_names.index("Bumper_9")
        z = DiscontinuityMap(zdm.phase, zdm.accel, zdm.direction, zdm.window, stop)
        mapped = grazing.simulate(model, x0, zdm=z, periods=30, transient=0, impacts="all", mode="Taut_2")
        assert (len(mapped.impacts) > 0) == kicked, where
        if kicked:
            continue
        plain = grazing.simulate(model, x0, periods=30, transient=0, impacts="all", mode="Taut_2")
        assert len(plain.impacts) == 0
        assert np.abs(mapped.samples - plain.samples).max() < 1e-10
        virtual = grazing.simulate(model, x0, periods=30, transient=0, mode="Taut_2", events=False)
        assert np.abs(virtual.samples - plain.samples).max() < 1e-10
        # the lanes: no kick either, the sweep's samples those of the run without the map
        settings = grazing.SweepSettings(transient=0, periods=30, lyapunov=False, fresh=True, adaptive=False)
        (res,) = run_chunks(
            sweep_spec(model, "F_0", [model.params["F_0"]], x0=x0, zdm=z, settings=settings), [0]
        )
        assert res.impacts_by_stop.tolist() == [[0, 0, 0]]


def test_the_map_refuses_a_transition_it_cannot_stand_for(grazed) -> None:
    _, zdm = grazed
    model = bumper_oscillator()
    for j, words in ((0, "has no reset"), (3, "is not a stop of")):
        z = DiscontinuityMap(zdm.phase, zdm.accel, zdm.direction, zdm.window, j)
        with pytest.raises(InvalidParameterError, match=words):
            grazing.simulate(model, [0.0, 0.0], periods=1, zdm=z)
        with pytest.raises(InvalidParameterError, match=words):
            sweep_spec(model, "F_0", [1.0], zdm=z)


def test_eight_lanes_of_the_map_are_the_scalar_runs(grazed) -> None:
    """Eight points in the lanes at once (the vector certificate of no event, which leaves the map's stop
    out): each point's kicks are the scalar driver's and its final state agrees (to 1e-4: the two
    drivers' steps differ and the kicks' square root magnifies that near ``delta = 0``; a missed switch
    of mode, as when the certificate left out the row numbered as the map's stop in every mode, is off
    by more than 1)."""
    point, zdm = grazed
    x0, _, _ = orbit_state(point, 0.0)
    model = bumper_oscillator(initial_mode="Taut_2")
    values = point.model.params["F_0"] * (1 + np.linspace(-0.02, 0.05, 8))
    settings = grazing.SweepSettings(transient=0, periods=30, lyapunov=False, fresh=True, adaptive=False)
    (res,) = run_chunks(sweep_spec(model, "F_0", values, x0=x0, zdm=zdm, settings=settings), [0])
    for i, value in enumerate(values):
        sol = grazing.simulate(model.with_params(F_0=value), x0, zdm=zdm, periods=30, transient=0,
                               mode="Taut_2", impacts="all")  # fmt: skip
        assert res.impacts_by_stop[i].tolist() == [0, len(sol.impacts), 0], i
        assert np.abs(sol.x_final - res.x_final[i]).max() < 1e-4, i
    assert res.impacts_by_stop[-1, 1] > 5  # (the map kicks)
