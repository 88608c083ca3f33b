"""The discontinuity map, the normal form, and the scenario predictions."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import grazing
from grazing.cli import main
from grazing.models import pendulum
from grazing.normalform import find_grazing_point, normal_form_at, observe, predict, predicted_windows
from grazing.normalform.prediction import (
    PERIOD_ADDING_CHAOS,
    PERIOD_ONE,
    RESONANT,
    ROBUST_CHAOS,
    classify_iterates,
)
from grazing.orbits import grazing_curve

UNFOLD = ("eta", "theta_hat")

DEG = math.pi / 180


@pytest.fixture(scope="module")
def nf40():
    """Normal form at the first grazing of case B at theta_hat = 40 deg (eta = 0.44512)."""
    return normal_form_at(find_grazing_point(pendulum("B", theta_hat=40 * DEG), "eta", 0.4, 0.47), UNFOLD)


def _shifted(nf, frac):
    """A point of the grazing orbit a fraction of a period before the contact, and its time."""
    m, T, ts = nf.model, nf.model.period, nf.point.t_graze
    s = grazing.simulate(m, nf.contact, t0=ts, periods=1, phase=2 * math.pi * ((ts + (1 - frac) * T) / T % 1),
                         events=False)  # fmt: skip
    return s.x_final, s.t_final


# --------------------------------------------------------------------------
# The discontinuity map itself


def test_zdm_is_the_restitution_law_on_the_stop(nf40):
    """D(on the stop, moving in at speed v) = the reset: theta' -> -r theta'."""
    r = nf40.model.params["r"]
    for v in (1e-3, 1e-2, 0.1):
        x = np.array([nf40.contact[0], v])
        np.testing.assert_allclose(nf40.zdm(x), [nf40.contact[0], -r * v], atol=1e-12)


def test_zdm_inactive_away_from_the_stop(nf40):
    x = nf40.contact + np.array([-1e-3, 1e-3])  # the local parabola peaks below the stop
    np.testing.assert_array_equal(nf40.zdm(x), x)


def test_map_error_shrinks_like_sqrt_of_penetration(nf40):
    """One shallow impact of depth d: ZDM vs the exact impacting flow; error/jump ~ C sqrt(d)."""
    x0, t0 = _shifted(nf40, 0.25)
    T = nf40.model.period
    t1 = t0 + 0.5 * T
    ratios = []
    for d in (1e-4, 1e-6, 1e-8):
        md = nf40.model.with_params(theta_hat=nf40.model.params["theta_hat"] - d)
        kw = dict(t0=t0, periods=1, phase=2 * math.pi * (t1 / T % 1), impacts="all")
        exact = grazing.simulate(md, x0, **kw)
        zdm = grazing.simulate(md, x0, zdm=nf40.discontinuity_map(), **kw)
        free = grazing.simulate(md, x0, t0=t0, periods=1, phase=kw["phase"], events=False)
        assert exact.n_impacts == zdm.n_impacts == 1
        jump = np.linalg.norm(exact.x_final - free.x_final)
        rel = np.linalg.norm(exact.x_final - zdm.x_final) / jump
        ratios.append(rel / math.sqrt(d))
        assert zdm.impacts.speed[0] == pytest.approx(exact.impacts.speed[0], rel=2 * math.sqrt(d) + 1e-6)
    # the same constant at every depth: error = C sqrt(d) (leading order), C ~ 1.8 here
    assert max(ratios) / min(ratios) < 1.05
    assert ratios[0] < 3


def test_map_without_impact_is_the_linearised_stroboscopic_map(nf40):
    """Away from the stop Pi is the smooth map, and the normal form's linear part is M."""
    step = nf40.normal_form("eta")
    u = np.array([-2e-4, 1e-4])  # no penetration: D inactive
    un, s = step(u, 0.0)
    assert s == 0.0
    np.testing.assert_allclose(un, nf40.monodromy @ u, atol=1e-15)
    # The nonlinear map from the contact section (ZDM inactive) is the flow; its Jacobian is M.
    m, ts = nf40.model, nf40.point.t_graze
    eps = 1e-7
    cols = []
    for j in range(2):
        dx = np.zeros(2)
        dx[j] = eps
        kw = dict(t0=ts, periods=1, phase=2 * math.pi * (ts / m.period % 1), zdm=nf40.discontinuity_map())
        a = grazing.simulate(m, nf40.contact - 1e-4 * np.array([1, 0]) + dx, **kw).x_final
        b = grazing.simulate(m, nf40.contact - 1e-4 * np.array([1, 0]) - dx, **kw).x_final
        cols.append((a - b) / (2 * eps))
    np.testing.assert_allclose(np.array(cols).T, nf40.monodromy, atol=2e-3)


def test_batched_iteration_follows_the_normal_form_map(nf40):
    """Iterating many mu at once gives each mu's iteration of ``normal_form``'s map."""
    from grazing.normalform.prediction import iterate_normal_form

    step = nf40.normal_form("eta")
    mus = np.array([1e-5, -3e-4, 6e-4, 2.5e-3])
    states, speeds = iterate_normal_form(nf40, "eta", mus, n=60, keep=60)
    for i, mu in enumerate(mus):
        u = np.zeros(2)
        for k in range(60):
            u, s = step(u, mu)
            np.testing.assert_allclose(states[k, i], u, rtol=1e-12, atol=1e-18)
            assert speeds[k, i] == pytest.approx(s, rel=1e-12, abs=1e-18)
    assert np.array_equal(iterate_normal_form(nf40, "eta", mus[2], n=60, keep=60)[0], states[:, 2])


def test_normal_form_map_and_flow_agree_near_grazing(nf40):
    """Small mu: the linear 2-D normal form, the nonlinear-flow map and the exact impacting
    flow settle on orbits of the same period (windows of the period-adding cascade)."""
    from grazing.normalform.prediction import iterate_normal_form

    m, ts = nf40.model, nf40.point.t_graze
    eta_g = m.params["eta"]
    x0 = nf40.contact - np.array([1e-6, 0.0])
    found = []
    for mu in (1e-5, 1e-4, 6e-4, 2.5e-3):  # centres of the period-7, 6, 5 and 4 windows
        mm = m.with_params(eta=eta_g + mu)
        kw = dict(t0=ts, transient=2000, periods=200, phase=2 * math.pi * (ts / m.period % 1))
        p_flow = grazing.simulate(mm, x0, **kw).period()
        p_map = grazing.simulate(mm, x0, zdm=nf40.discontinuity_map(), **kw).period()
        states, _ = iterate_normal_form(nf40, "eta", mu)
        p_nf = grazing.detect_period(states, tol=1e-9 * max(1, np.max(np.abs(states))))
        assert p_flow == p_map == p_nf, (mu, p_flow, p_map, p_nf)
        found.append(p_flow)
    assert found == sorted(found, reverse=True) and len(set(found)) >= 3  # period adding


# --------------------------------------------------------------------------
# Predictions


def test_one_dimensional_windows():
    """Window formulas: high-period windows exist iff lambda < 2/3 (from 3 lambda^2 / 4 < 1 - lambda),
    neighbours overlap for large n iff lambda < 1/4 (their asymptotic ratio is lambda^2)."""
    assert [n for n, _, _ in predicted_windows(0.66, 30)] == list(range(2, 31))
    assert max(n for n, _, _ in predicted_windows(0.70, 30)) < 10  # only a few low periods survive
    w = predicted_windows(0.5, 10)
    assert [n for n, _, _ in w] == list(range(2, 11))
    assert all(w[i][1] > w[i + 1][2] for i in range(len(w) - 1))  # gaps: chaos between (1/4 < l < 2/3)
    w2 = predicted_windows(0.24, 10)
    assert all(w2[i][1] < w2[i + 1][2] for i in range(len(w2) - 1))  # overlaps
    w3 = predicted_windows(0.26, 10)
    assert all(w3[i][1] > w3[i + 1][2] for i in range(3, len(w3) - 1))  # large n: gaps again
    lo = [x for _, x, _ in w]
    np.testing.assert_allclose((np.array(lo[1:]) / np.array(lo[:-1]))[-3:], 0.25, rtol=0.01)  # -> lambda^2
    # iterate the 1-D map at the middle of each window: period n
    lam = 0.5
    for n, a, b in w[:5]:
        mu = 0.5 * (a + b)
        x, xs = 0.0, []
        for k in range(4000):
            x = lam * x + mu if x <= 0 else mu - math.sqrt(x)
            if k >= 3800:
                xs.append(x)
        assert grazing.detect_period(np.array(xs), tol=1e-10) == n


def test_classifier_on_synthetic_attractors():
    mus = np.geomspace(1e-6, 1e-3, 8)
    small = np.sqrt(mus)
    yes = np.ones(8, dtype=bool)
    assert classify_iterates(mus, np.array([7, 7, 6, 0, 5, 0, 4, 3]), small, yes) == PERIOD_ADDING_CHAOS
    assert classify_iterates(mus, np.zeros(8, dtype=int), small, yes) == ROBUST_CHAOS
    assert classify_iterates(mus, np.ones(8, dtype=int), np.full(8, 0.9), yes) == PERIOD_ONE
    assert "jump" in classify_iterates(mus, np.array([4, 4, 4, 4, 4, 3, 3, 3]), np.full(8, 0.1), yes)


def test_prediction_at_40_degrees_is_the_papers_period_adding(nf40):
    pred = predict(nf40)
    assert pred.scenario == PERIOD_ADDING_CHAOS
    assert 0.25 < pred.abs_lambda < 2 / 3 and pred.kappa > 0 and pred.side == 1.0
    periods = [p for _, p in pred.windows]
    # windows spanning at least two values of mu (narrow secondary windows skipped)
    windows = [
        p
        for i, p in enumerate(periods[:-1])
        if p > 0 and periods[i + 1] == p and (i == 0 or periods[i - 1] != p)
    ]
    assert windows[:4] == [7, 6, 5, 4]  # the period decreases as eta moves away from grazing


def test_predictions_agree_with_simulation_along_the_grazing_curve():
    """Every non-resonant prediction matches direct simulation just past grazing."""
    curve = grazing_curve(pendulum("B"), ("eta", "theta_hat"), 15 * DEG, search=(0.2, 1.0))
    thetas = np.degrees(curve.values("theta_hat"))
    chosen = []
    for target in (15, 25, 35, 45, 52):
        for branch in (slice(0, curve.fold_index + 1), slice(curve.fold_index + 1, None)):
            idx = np.arange(len(thetas))[branch]
            if idx.size:
                chosen.append(idx[np.argmin(np.abs(thetas[idx] - target))])
    checked = 0
    for i in chosen:
        nf = normal_form_at(curve.points[i], UNFOLD)
        pred = predict(nf)
        if pred.scenario == RESONANT:
            continue
        obs = observe(nf, points=16, transient=1200, periods=160)
        assert obs.scenario == pred.scenario, (thetas[i], nf.model.params["eta"], pred, obs)
        checked += 1
    assert checked >= 7


# --------------------------------------------------------------------------
# CLI


def test_normal_form_cli_json(capsys):
    assert main(["normal-form", "--theta-hat", "40", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    for key in ("eta_graze", "multipliers", "abs_lambda", "prediction", "coefficients", "t_graze"):
        assert key in res
    assert res["eta_graze"] == pytest.approx(0.44512, abs=1e-4)
    assert res["prediction"]["scenario"] == PERIOD_ADDING_CHAOS
    assert res["coefficients"]["direction"] == pytest.approx([0.0, 1.7675], abs=1e-10)
    assert main(["normal-form", "--theta-hat", "40", "--which", "second", "--json"]) == 0
    res2 = json.loads(capsys.readouterr().out)
    assert res2["prediction"]["scenario"] == PERIOD_ONE and res2["coefficients"]["kappa"] < 0


def test_sweep_with_the_map_method(capsys):
    argv = "sweep --param eta --start 0.4456 --stop 0.4462 --num 4 --method map --workers 1 --periods 60"
    argv = [*argv.split(), "--json"]
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["method"] == "map" and res["grazing"]["value"] == pytest.approx(0.44512, abs=1e-4)
    assert res["period"] == [5, 5, 5, 5]  # the period-5 window, as in the direct simulation
    for key in ("param", "values", "period", "impacts_per_period", "lyapunov", "samples"):
        assert key in res


def test_normal_form_without_grazing_is_a_clear_error(capsys):
    code = main(["normal-form", "--theta-hat", "70"])
    err = capsys.readouterr().err
    assert code != 0 and "no first grazing" in err and len(err.strip().splitlines()) == 1
