"""Special points, curve points and margins as typed records (issue 44, part 1).

* The kinds are enums whose values are the words that ``--json``, the datasets and the docs print
  (docs/continuation.md, docs/bifurcation-curves.md): a kind compares equal to its word, prints as it
  and is written as it.
* Every special point that its locator bracketed carries that bracket (``interval``) and how well its
  parameter is known (``precision``): a point inside the bracket, known far better than the bracket's
  width where its locator converged.
* ``grazing_margin`` is a named record, checked against the closed forms of the bouncing ball (an
  impact's ``v^2 / (2 |a|)``) and of the linear impact oscillator (the gap to the stop of its
  nonimpacting orbit).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from grazing.models import impact_oscillator
from grazing.orbits import continue_orbit, find_orbit, follow_curve
from grazing.orbits.continuation import (
    SPECIAL_KINDS,
    BranchEnd,
    GrazingMargin,
    ImpactChange,
    SpecialPoint,
    grazing_margin,
)
from grazing.orbits.curves import CURVE_KINDS
from grazing.orbits.kinds import CurveKind, SpecialKind
from tests.orbits.test_closed_forms import (
    G,
    R,
    W,
    ball_fold,
    ball_orbit,
    ball_period_doubling,
    oscillator_amplitude,
)

JSON_KINDS = ["fold", "branch point", "period-doubling", "neimark-sacker", "grazing", "unlocated"]
"""The ``kind`` of a special point in ``grazing continue --json`` (docs/continuation.md)."""

CLI_CURVE_KINDS = ["fold", "period-doubling", "neimark-sacker", "branch-point", "grazing"]
"""The choices of ``grazing curve --kind`` (docs/bifurcation-curves.md)."""


def test_the_kinds_are_the_words_that_json_prints():
    assert [k.value for k in SpecialKind] == JSON_KINDS
    assert list(SPECIAL_KINDS) == JSON_KINDS[:-1]  # (continue_orbit's detect, in this order)
    assert [k.value for k in CurveKind] == CLI_CURVE_KINDS and list(CURVE_KINDS) == CLI_CURVE_KINDS
    for kind, word in zip(SpecialKind, JSON_KINDS):
        assert kind == word and hash(kind) == hash(word) and SpecialKind(word) is kind
        assert str(kind) == word and f"{kind}" == word and f"{kind:16s}" == f"{word:16s}"
        assert json.dumps({"kind": kind}) == json.dumps({"kind": word})
        assert np.array([kind], dtype=str)[0] == word and repr([kind]) == repr([word])
    # A curve follows the special point of its kind (the one spelling of each: the member's name).
    assert {k: k.start for k in CurveKind} == {
        CurveKind.FOLD: SpecialKind.FOLD,
        CurveKind.PERIOD_DOUBLING: SpecialKind.PERIOD_DOUBLING,
        CurveKind.NEIMARK_SACKER: SpecialKind.NEIMARK_SACKER,
        CurveKind.BRANCH_POINT: SpecialKind.BRANCH_POINT,
        CurveKind.GRAZING: SpecialKind.GRAZING,
    }
    assert SpecialKind.BRANCH_POINT.curve is CurveKind.BRANCH_POINT and SpecialKind.UNLOCATED.curve is None


def test_the_cli_takes_the_curve_kinds_by_their_words():
    from grazing.cli.curves import curve

    option = next(p for p in curve.params if p.name == "kind")
    for word in CLI_CURVE_KINDS:  # (click takes an enum's members by their names: not ours to show)
        assert option.type.convert(word, option, None) == word


def test_special_points_are_built_by_keyword():
    with pytest.raises(TypeError):
        SpecialPoint(SpecialKind.FOLD, 0, 1.0, None)  # type: ignore[misc]


def assert_bracketed(sp: SpecialPoint) -> None:
    """A special point located in a bracket carries it, holds its value, and knows its value far better
    than the bracket's width (its locator converged to a test-function tolerance of 1e-9)."""
    assert isinstance(sp.kind, SpecialKind)
    assert sp.interval is not None, sp
    lo, hi = sp.interval
    scale = max(1.0, abs(sp.param))
    # (a grazing solved from the grazing equations may lie 1e-8 outside the points around it: the test of
    # continuation._locate_grazing; any other point lies in its bracket, which holds it in the parameter
    # even where the branch bends, as at a fold, between the bracket's ends)
    slack = 1e-8 * scale if sp.kind is SpecialKind.GRAZING else 0.0
    assert lo - slack <= sp.param <= hi + slack, sp
    assert math.isfinite(sp.precision) and 0 <= sp.precision <= max(hi - lo, 1e-12 * scale), sp
    assert sp.precision < 1e-7 * scale, sp


@pytest.mark.parametrize("n", [1])
def test_the_ball_fold_and_period_doubling_carry_their_brackets(n):
    a_fold, a_pd = ball_fold(n), ball_period_doubling(n)
    mid = 0.5 * (a_fold + a_pd)
    orbit = ball_orbit(n, mid)
    down = continue_orbit(orbit.model, "amplitude", mid, a_fold - 0.3, orbit=orbit)
    up = continue_orbit(orbit.model, "amplitude", mid, a_pd + 0.3, orbit=orbit)
    points = down.special + up.special
    assert {sp.kind for sp in points} >= {SpecialKind.FOLD, SpecialKind.PERIOD_DOUBLING}
    for sp in points:
        assert_bracketed(sp)
    fold = next(sp for sp in points if sp.kind is SpecialKind.FOLD)
    pd = next(sp for sp in points if sp.kind is SpecialKind.PERIOD_DOUBLING)
    for sp, exact in ((fold, a_fold), (pd, a_pd)):  # the bracket holds the closed form
        lo, hi = sp.interval
        assert lo - 2 * sp.precision <= exact <= hi + 2 * sp.precision
    for branch in (down, up):
        assert isinstance(branch.outcome, BranchEnd) and len(branch.segment_outcome) == len(
            branch.segment_status
        )


def test_a_branch_point_and_the_grazing_that_ends_a_branch_carry_their_brackets():
    from tests.orbits.symmetric_models import walled_pendulum

    model = walled_pendulum().with_params(A=0.3)
    branch = continue_orbit(model, "Om", 1.2, 0.6)
    kinds = {sp.kind for sp in branch.special}
    assert SpecialKind.BRANCH_POINT in kinds, branch.status
    for sp in branch.special:
        if sp.kind is not SpecialKind.UNLOCATED:
            assert_bracketed(sp)


def test_a_fold_and_the_grazing_that_ends_a_branch_carry_their_brackets():
    """The impact oscillator's impacting orbit (sigma = 0.5) turns at a fold, then loses its impact at the
    grazing of the nonimpacting orbit (test_closed_forms), which is bracketed by the branch's last point
    and the first beyond it and solved by Newton's method on the grazing equations."""
    sigma = 0.5
    m = impact_oscillator(zeta=0.05, sigma=sigma, r=0.8)
    orbit = find_orbit(m.with_params(omega=1.5), period=1, t0=None)
    branch = continue_orbit(m, "omega", 1.5, 2.5, orbit=orbit)
    fold, graze = branch.special
    assert (fold.kind, graze.kind) == (SpecialKind.FOLD, SpecialKind.GRAZING), branch.status
    assert branch.outcome is BranchEnd.GRAZING and branch.status.startswith("ended at a grazing")
    for sp in (fold, graze):
        assert_bracketed(sp)
    expected = brentq(lambda w: oscillator_amplitude(w) - sigma, 1.2, 2.5, xtol=1e-15)
    lo, hi = graze.interval
    assert lo <= expected <= hi and abs(graze.param - expected) <= 2 * graze.precision + 1e-12
    # The grazing equations' Newton step: far below the distance between the branch's points.
    assert graze.precision < 1e-3 * (hi - lo)


def test_codimension_two_points_carry_their_brackets_in_both_parameters():
    """The impact oscillator's fold curve in (omega, sigma) ends where it meets the grazing curve, solved
    as their meeting point by Newton's method ahead of the curve's last point."""
    m = impact_oscillator(zeta=0.05, sigma=0.5, r=0.8, omega=1.5)
    orbit = find_orbit(m, period=1, t0=None)
    curve = follow_curve(m, "fold", "omega", 1.5, 2.5, "sigma", (0.3, 0.7), orbit=orbit)
    assert curve.kind is CurveKind.FOLD
    assert [sp.kind for sp in curve.special] == ["grazing"], curve.status
    for sp in curve.special:
        assert sp.interval is not None, sp
        assert all(math.isfinite(p) and p >= 0 for p in sp.precision), sp
        for (lo, hi), v, p in zip(sp.interval, sp.values, sp.precision):
            assert lo - p <= v <= hi + p, sp
            assert p < 1e-9 if sp.located else p == pytest.approx(hi - lo)  # only bracketed: its width
    ds = curve.to_dataset()
    assert ds.special_precision.shape == (1, 2) and ds.special_interval.shape == (1, 2, 2)
    assert ds.attrs["kind"] == "fold" and type(ds.attrs["kind"]) is str


def test_grazing_margin_of_an_impact_is_its_parabola_depth():
    """The ball's one-impact orbit leaves the table with speed ``g T / 2`` (test_closed_forms); it hits
    it with relative speed ``(g T / 2 - A w cos(phi)) / r`` while the gap ``y - A sin(w t)`` accelerates
    at ``-g + A w^2 sin(phi)``: the margin ``v^2 / (2 |a|)``, an impact the orbit loses at the grazing."""
    amplitude = 0.5 * (ball_fold(1) + ball_period_doubling(1))
    orbit = ball_orbit(1, amplitude)
    phi = math.acos(math.pi * (1 - R) * G / ((1 + R) * amplitude * W**2))
    v = (G * (2 * math.pi / W) / 2 - amplitude * W * math.cos(phi)) / R
    a = -G + amplitude * W**2 * math.sin(phi)
    margin = grazing_margin(orbit)
    assert isinstance(margin, GrazingMargin)
    assert margin.change is ImpactChange.LOSES and margin.change == "loses an impact"
    assert margin.delta == pytest.approx(v * v / (2 * abs(a)), rel=1e-8)
    assert margin.stop == 0
    assert math.fmod(margin.time * W - phi, 2 * math.pi) == pytest.approx(0.0, abs=1e-8)
    assert margin.contact is not None and margin.contact[0] == pytest.approx(amplitude * math.sin(phi))


def test_grazing_margin_of_a_nonimpacting_orbit_is_its_gap_to_the_stop():
    sigma, w = 2.0, 2.8
    orbit = find_orbit(impact_oscillator(zeta=0.05, omega=w, sigma=sigma, r=0.8))
    assert orbit.impacts == 0
    margin = grazing_margin(orbit)
    assert margin.change is ImpactChange.GAINS and f"the orbit {margin.change}" == "the orbit gains an impact"
    assert margin.delta == pytest.approx(sigma - oscillator_amplitude(w), abs=1e-10)
    assert margin.contact is not None and margin.contact[0] == pytest.approx(oscillator_amplitude(w))
    assert margin.stop == 0 and math.isfinite(margin.time)
    with pytest.raises(TypeError):
        GrazingMargin(1.0, None, 0.0, None, 0)  # type: ignore[misc]  (by keyword only)
