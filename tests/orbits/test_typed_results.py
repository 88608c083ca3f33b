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
from grazing.orbits.curve_data import CurveEnd
from grazing.orbits.curves import CURVE_KINDS
from grazing.orbits.kinds import CurveKind, SpecialKind
from grazing.orbits.palc import PalcEnd
from tests.orbits.test_closed_forms import (
    G,
    R,
    W,
    ball_fold,
    ball_orbit,
    ball_period_doubling,
    oscillator_amplitude,
)

JSON_KINDS = ["fold", "branch point", "period-doubling", "neimark-sacker", "grazing", "grazing-sliding",
              "crossing-sliding", "switching-sliding", "adding-sliding", "double grazing",
              "unlocated"]  # fmt: skip
"""The ``kind`` of a special point in ``grazing continue --json`` (docs/continuation.md)."""

CLI_CURVE_KINDS = ["fold", "period-doubling", "neimark-sacker", "branch-point", "grazing"]
"""The choices of ``grazing curve --kind`` (docs/bifurcation-curves.md)."""

ATTRACTOR_KINDS = ["periodic", "sticking", "neutral", "chaotic", "quasiperiodic", "aperiodic", "escaping",
                   "failed", "invalid"]  # fmt: skip
"""The ``kind`` of an attractor in ``grazing basins --json`` and the basins datasets (docs/attractors.md)."""

CURVE_ENDS = ["bound", "grazing", "double grazing", "1:1 resonance", "1:2 resonance", "not persistent",
              "stuck", "resection", "no section", "max points", "closed"]  # fmt: skip
"""The ``outcomes`` of ``grazing curve --json`` (docs/bifurcation-curves.md)."""


def assert_prints_as_its_word(kind, word: str) -> None:
    """A string enum member is its word wherever it is printed or written."""
    assert kind == word and hash(kind) == hash(word) and type(kind)(word) is kind
    assert str(kind) == word and f"{kind}" == word and f"{kind:16s}" == f"{word:16s}"
    assert json.dumps({"kind": kind}) == json.dumps({"kind": word})
    assert np.array([kind], dtype=str)[0] == word and repr([kind]) == repr([word])
    assert type(str(kind)) is str


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


def test_attractor_kinds_and_curve_ends_are_the_words_that_json_prints():
    from grazing.attractors import KINDS, AttractorKind

    assert [k.value for k in AttractorKind] == ATTRACTOR_KINDS and list(KINDS) == ATTRACTOR_KINDS
    assert [k.value for k in CurveEnd] == CURVE_ENDS
    for enum, words in ((AttractorKind, ATTRACTOR_KINDS), (CurveEnd, CURVE_ENDS)):
        for kind, word in zip(enum, words):
            assert_prints_as_its_word(kind, word)
        messages = [k.message for k in enum]  # (a few words each, for people: one per member)
        assert all(m and m == m.strip() for m in messages) and len(set(messages)) == len(messages)
    assert [k for k in AttractorKind if k.outcome] == ["escaping", "failed", "invalid"]
    assert [k for k in AttractorKind if k.aperiodic] == ["chaotic", "quasiperiodic", "aperiodic"]
    # A direction's last continuation, where nothing ended it, says why it stopped.
    assert [CurveEnd.of(e) for e in PalcEnd] == [
        CurveEnd.MAX_POINTS, CurveEnd.BOUND, CurveEnd.STUCK, CurveEnd.STUCK, CurveEnd.RESECTION
    ]  # fmt: skip
    # The resonances that end a Neimark-Sacker curve are the curve's codimension-two kinds' words.
    from grazing.orbits.extended import ENDING

    assert {CurveEnd(k) for k in ENDING["neimark-sacker"]} == {CurveEnd.RESONANCE_1_1, CurveEnd.RESONANCE_1_2}


def test_every_curve_end_has_one_status_that_says_it():
    """The words each end's status starts with (tests/orbits/curve_outcomes.py, which conftest.py checks
    every curve the orbit tests follow against) name each outcome once."""
    from tests.orbits.curve_outcomes import STATUS_STARTS, ends, said

    assert sorted(o.value for _, o in STATUS_STARTS) == sorted(CURVE_ENDS)
    for start, outcome in STATUS_STARTS:
        assert said(start + " at x = 1") is outcome
    first, last = ends(
        "at the first point: reached the bound r = 0.3; at the last point: step size fell below 1e-08"
    )
    assert (said(first), said(last)) == (CurveEnd.BOUND, CurveEnd.STUCK)
    with pytest.raises(AssertionError, match="no outcome says"):
        said("reached a boundary of the curve's domain at x = 1")


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


# --------------------------------------------------------------------------
# Attractor kinds


def _chunk(samples, period, impacts, lyapunov, status):
    from grazing.sweeps.spec import ChunkResult

    samples = np.asarray(samples, dtype=float)
    m = samples.shape[0]
    return ChunkResult(
        index=0, samples=samples, period=np.asarray(period), impacts=np.asarray(impacts, dtype=float),
        lyapunov=np.asarray(lyapunov, dtype=float), transient_used=np.zeros(m), x_final=samples[:, -1],
        status=np.asarray(status),
    )  # fmt: skip


def test_the_catalogue_names_each_end_state_with_its_kind():
    """End states made up for each kind the samples decide (neutral needs a monodromy: test_dynamics):
    a repeating point with impacts, one at rest on the table, three aperiodic sets far apart with a
    positive, a zero and no exponent, one beyond the bound, one that overflowed and one at the step
    limit; and an initial state beyond a stop."""
    from grazing.attractors import AttractorKind
    from grazing.attractors.classify import CHAOS_THRESHOLD, Catalogue
    from grazing.core.solution import Status
    from grazing.models import bouncing_ball

    ball = bouncing_ball(amplitude=0.1, r=0.8)
    P = 8
    k = np.arange(P)[:, None]
    scatter = np.hstack([np.sin(1.3 * k * k), np.cos(2.1 * k)])  # (no period <= 8)
    samples = [
        np.tile([1.0, 2.0], (P, 1)),  # period 1 with impacts
        np.zeros((P, 2)),  # on the table (y = A sin(0) = 0), at rest, no impacts
        10.0 + scatter,
        20.0 + scatter,
        30.0 + scatter,
        np.full((P, 2), 500.0),  # beyond the bound (100)
        np.zeros((P, 2)),
        np.zeros((P, 2)),
    ]
    ok, nonfinite, limit = int(Status.OK), int(Status.NONFINITE), int(Status.STEP_LIMIT)
    res = _chunk(
        samples,
        period=[1, 1, 0, 0, 0, 1, 0, 0],
        impacts=[P, 0, P, P, P, P, 0, 0],
        lyapunov=[np.nan, np.nan, 10 * CHAOS_THRESHOLD, 0.0, np.nan, np.nan, np.nan, np.nan],
        status=[ok, ok, ok, ok, ok, ok, nonfinite, limit],
    )
    cat = Catalogue(ball, 9, np.full(2, 0.01), np.zeros(2), 100.0, P, 0.0, polish=False)
    cat.add(0, res)
    attractors, _ = cat.attractors(invalid=1)
    kinds = {a.first: a.kind for a in attractors}
    assert kinds == {
        -1: AttractorKind.INVALID, 0: AttractorKind.PERIODIC, 1: AttractorKind.STICKING,
        2: AttractorKind.CHAOTIC, 3: AttractorKind.QUASIPERIODIC, 4: AttractorKind.APERIODIC,
        5: AttractorKind.ESCAPING, 6: AttractorKind.ESCAPING, 7: AttractorKind.FAILED,
    }  # fmt: skip
    for a in attractors:
        assert type(a.kind) is AttractorKind
        assert type(a.to_json()["kind"]) is str and a.to_json()["kind"] == a.kind.value
    reasons = {a.first: a.reason for a in attractors if a.kind.outcome}
    assert reasons == {-1: "beyond a stop", 5: "left the bound", 6: "non-finite state", 7: "step limit"}


def test_found_attractors_carry_their_kind_and_write_its_word():
    """The ball on a vibrating table (basins' example): beyond the table, at rest on it, bouncing."""
    from grazing.attractors import AttractorKind, basins, find_attractors
    from grazing.models import bouncing_ball

    ball = bouncing_ball(amplitude=0.8, r=0.8)
    found = find_attractors(ball, [[0.0, 0.8], [3.6, -2.0], [-1.0, 0.0]], workers=1)
    assert [a.kind for a in found.attractors] == [
        AttractorKind.INVALID, AttractorKind.STICKING, AttractorKind.PERIODIC
    ]  # fmt: skip
    assert all(type(a.kind) is AttractorKind for a in found.attractors)
    ds = basins(ball, (-1.0, 6.0), (-4.0, 4.0), (4, 4), workers=1)
    assert {type(k) for k in ds.kind.values.tolist()} == {str}
    assert set(ds.kind.values.tolist()) <= set(ATTRACTOR_KINDS)
