"""Every comparison is a record with a rule, and every verdict follows from its rule.

The first tests read ``comparisons.json`` of the report built for the session
(quick resolutions) and check every row; the others check the rules on
hand-made cases: numbers against printed numbers, windows against windows.
"""

from __future__ import annotations

import json
import math
import re

import pytest

from grazing.orbits import continue_orbit, find_orbit
from grazing.report import FIGURES, diagrams, paper
from grazing.report.base import (
    KINDS,
    VERDICTS,
    Comparison,
    consistency_problem,
    intervals_overlap,
    is_interval,
    is_number,
)
from grazing.report.html import scoreboard
from grazing.report.rules import complex_row, criterion_row, majority, match_windows, numeric_row
from grazing.sweeps.windows import Window

FIELDS = ("figure", "quantity", "paper", "ours", "kind", "rule", "tolerance", "verdict")


@pytest.fixture(scope="module")
def data(built) -> dict:
    return json.loads((built.out / "comparisons.json").read_text(encoding="utf-8"))


def test_every_row_has_the_fields_and_allowed_values(data: dict) -> None:
    rows = data["rows"]
    assert len(rows) >= 60
    for r in rows:
        for f in FIELDS:
            assert f in r, (f, r["quantity"])
        assert r["kind"] in KINDS and r["verdict"] in VERDICTS, r["quantity"]
        assert isinstance(r["rule"], str) and len(r["rule"]) > 10, r["quantity"]
        assert r["quantity"] and r["figure"] and r["id"]
        assert r["paper"] is not None and r["ours"] is not None, r["quantity"]
        assert r["tolerance"] is None or (is_number(r["tolerance"]) and r["tolerance"] >= 0)
    assert len({r["id"] for r in rows}) == len(rows)
    assert {r["figure"] for r in rows} == {m.FIGURE_ID for m in FIGURES}


def test_numeric_verdicts_follow_the_tolerance(data: dict) -> None:
    checked = 0
    for r in data["rows"]:
        assert consistency_problem(r) == "", (r["quantity"], consistency_problem(r))
        p, o, tol = r["paper"], r["ours"], r["tolerance"]
        if is_number(p) and is_number(o) and tol is not None:
            assert (r["verdict"] == "agree") == (abs(o - p) <= tol), r["quantity"]
            checked += 1
        elif r["delta"] is not None and tol is not None:
            assert (r["verdict"] == "agree") == (abs(r["delta"]) <= tol), r["quantity"]
            checked += 1
        if is_interval(p) and is_interval(o) and r["verdict"] == "agree":
            assert intervals_overlap(p, o), r["quantity"]
    assert checked >= 30


def test_no_synthetic_row_agrees_with_the_paper(data: dict) -> None:
    synthetic = [r for r in data["rows"] if r["synthetic"]]
    assert synthetic, "the synthetic pipeline rows are missing"
    for r in synthetic:
        assert r["kind"] == "self-check", r["quantity"]
    for r in data["rows"]:
        if r["kind"] in ("paper", "experiment") and r["verdict"] == "agree":
            assert not r["synthetic"] and "synthetic" not in r["quantity"].lower(), r["quantity"]


def test_scoreboard_counts_the_rows(data: dict, built) -> None:
    rows = [Comparison.from_json(r) for r in data["rows"]]
    assert data["scoreboard"] == scoreboard(rows)
    for kind, counts in data["scoreboard"].items():
        cells = re.search(rf'kind-{kind}">{kind}</span>.*?</tr>', built.page, flags=re.S)
        assert cells is not None
        nums = [int(x) for x in re.findall(r'<td class="num">(\d+)</td>', cells.group(0))]
        assert nums == [
            counts["agree"],
            counts["differ"],
            counts["erratum"],
            counts["not comparable"],
            sum(counts.values()),
        ]
    # the errata count apart from the disagreements: the two columns share no row
    errata = sum(r["erratum"] for r in data["rows"])
    assert errata >= 5 and data["scoreboard"]["paper"]["erratum"] == errata
    differ = sum(r["verdict"] == "differ" and not r["erratum"] for r in data["rows"] if r["kind"] == "paper")
    assert data["scoreboard"]["paper"]["differ"] == differ


def test_self_checks_name_their_reference_not_the_paper(data: dict, built) -> None:
    """A self-check's reference is ours (a closed form, another computation): never in a "paper" column."""
    page = built.page
    for r in data["rows"]:
        if r["kind"] != "self-check":
            assert not r["reference"], r["quantity"]
            continue
        start = page.index(f'<tr id="{r["id"]}">')
        table = page.rfind("<table", 0, start)
        header = page[table : page.index("</thead>", table)]
        assert "<th>reference</th>" in header and "<th>paper</th>" not in header, r["id"]
    closed = [r for r in data["rows"] if r["figure"] == "stops" and r["reference"] == "closed form"]
    assert len(closed) >= 6
    liouville = next(r for r in data["rows"] if "Liouville" in r["quantity"])
    assert "closed form" in liouville["reference"]


def test_every_difference_is_listed_at_the_top_with_a_link(data: dict, built) -> None:
    top = built.page[: built.page.index('<section id="fig')]
    for r in data["rows"]:
        if r["verdict"] != "agree":
            assert f'href="#{r["id"]}"' in top, r["quantity"]


def test_the_generous_verdicts_of_issue_14_are_gone(data: dict) -> None:
    """Each verdict below stays when the quick sweeps are shifted by a third or two thirds of their
    spacing, run with 270 or 340 transient periods or 64 samples, or started 1e-4 away; the margins
    are given next to each, and the fig 12 (c) window is checked by continuation."""
    rows = data["rows"]

    def find(fig: str, *words: str) -> list[dict]:
        return [r for r in rows if r["figure"] == fig and all(w in r["quantity"] for w in words)]

    # figs 2/3: the rows on synthetic recordings are self-checks; the model at fig 3's points differs
    assert all(r["kind"] == "self-check" for r in rows if r["figure"] == "2" and r["synthetic"])
    assert {r["verdict"] for r in find("2", "fig 3", "against the measurement")} == {"differ"}
    # fig 4(a): D = 0.0964 with the eq. 6 normalisation is not 0.07
    (d4,) = find("4", "(a) damping D", "eq. 6")
    assert d4["verdict"] == "differ" and abs(d4["ours"] - 0.0964) < 2e-3
    # fig 7: panel (a) is in the reverse period-adding verdicts; 10° and 20° show no visible chaos
    # (aperiodic over 5e-6 and 0 in η, against the 1e-3 a visible chaos needs)
    adding = [r for r in find("7", "reverse period-adding") if "A/L" not in r["quantity"]]
    assert len(adding) == 4 and adding[0]["quantity"].startswith("(a)")
    chaos = [r for r in find("7", "chaos past the first grazing") if "A/L" not in r["quantity"]]
    assert [r["verdict"] for r in chaos][:2] == ["differ", "differ"]
    assert all(r["ours"] < 1e-4 for r in chaos[:2])
    # fig 7 / 12: the impacting region ends at a fold, not with the period-2 window
    ends = find("7", "how the impacting region ends") + find("12", "how the impacting region ends")
    assert ends and all(r["verdict"] == "differ" and "fold" in r["ours"] for r in ends)
    # fig 12(a): the period-2 window (0.368-0.372) is not in the experiment's η range (0.35-0.36)
    (a12,) = find("12", "(a)", "first significant window")
    assert a12["verdict"] == "differ" and a12["ours"][0] > a12["paper"][1] + 5e-3
    # (c): no period-4 window in 0.44-0.45: ours ends below 0.44, at a fold of its orbit
    (c12,) = find("12", "(c)", "first significant window")
    assert c12["verdict"] == "differ" and c12["ours"][1] < c12["paper"][0]
    model = diagrams.panel_model("A-reduced", 30.0)
    orbit = find_orbit(model.with_params(eta=0.4394), period=4, transient=600)
    up = continue_orbit(model, "eta", 0.4394, 0.442, orbit=orbit)
    assert orbit.stable and [s.kind for s in up.special] == ["fold"]
    assert c12["ours"][1] <= up.special[0].param < c12["paper"][0]
    # fig 10: the window rows are self-checks decided by a majority of overlapping windows
    for r in find("10", "found by the map"):
        assert r["kind"] == "self-check" and "overlaps" in r["rule"] and "more than 50%" in r["rule"]
    # fig 11 at the paper's η is period 5, not chaotic
    assert find("11", str(paper.FIG11_ETA.value))[0]["verdict"] == "differ"


# ---------------------------------------------------------------------------- the rules on hand-made cases


def w(period: int, start: float, stop: float, impacting: bool = True) -> Window:
    return Window(period, impacting, 0, 1, start, stop, start, stop)


def test_windows_match_only_when_they_overlap() -> None:
    # fig 10(d) of issue 14: period 2 at 0.46424-0.47804 in the simulation, 0.45800-0.46242 in the map
    (m,) = match_windows([w(2, 0.46424, 0.47804)], [w(2, 0.45800, 0.46242)])
    assert not m.matched and m.elsewhere is not None and m.elsewhere.start == 0.458
    # fig 10(c): the period-4 window at 0.43932 is not the map's at 0.42692 (same period elsewhere)
    (m,) = match_windows([w(4, 0.43932, 0.43944)], [w(4, 0.42692, 0.42781), w(2, 0.4393, 0.4395)])
    assert not m.matched and m.elsewhere.start == 0.42692
    # a partial overlap is a match; the largest overlap wins
    (m,) = match_windows([w(3, 0.45191, 0.45905)], [w(3, 0.45173, 0.45590), w(3, 0.4590, 0.4600)])
    assert m.matched and m.match.stop == 0.45590
    # touching at one point of the grid is an overlap; a nonimpacting window never matches an impacting one
    assert match_windows([w(5, 1.0, 2.0)], [w(5, 2.0, 3.0)])[0].matched
    assert not match_windows([w(1, 1.0, 2.0)], [w(1, 1.0, 2.0, impacting=False)])[0].matched
    assert not match_windows([w(5, 1.0, 2.0)], [])[0].matched


def test_majority_rule() -> None:
    hit = match_windows([w(2, 0, 1)], [w(2, 0, 1)])[0]
    miss = match_windows([w(2, 0, 1)], [w(2, 5, 6)])[0]
    assert majority([hit] * 5 + [miss]) == (5, 6, "agree")
    assert majority([hit] * 7 + [miss] * 3) == (7, 10, "agree")
    assert majority([hit] + [miss] * 4) == (1, 5, "differ")
    assert majority([hit, miss]) == (1, 2, "differ")  # exactly half is not a majority
    assert majority([]) == (0, 0, "not comparable")


def test_numeric_rule_and_printed_precision() -> None:
    p = paper.Printed("0.4450", "test")
    assert numeric_row("x", "q", p, 0.44504, kind="paper").verdict == "agree"
    assert numeric_row("x", "q", p, 0.44512, kind="paper").verdict == "differ"
    approx = paper.Printed("0.343", "test", approximate=True)
    assert approx.tolerance == pytest.approx(1e-3)
    row = numeric_row("x", "q", approx, 0.3331, kind="experiment")
    assert row.verdict == "differ" and row.delta == pytest.approx(-0.0099) and "≈" in row.rule
    assert numeric_row("x", "q", 0.0, 0.09, kind="self-check", tolerance=0.2).verdict == "agree"
    z = paper.PrintedComplex(paper.Printed("0.4606", "t"), paper.Printed("0.2137", "t"))
    assert complex_row("x", "q", z, complex(0.46060, -0.21372), kind="paper").verdict == "agree"
    assert complex_row("x", "q", z, complex(0.46117, 0.21271), kind="paper").verdict == "differ"
    assert math.isclose(z.tolerance, 5e-5 * math.sqrt(2))


def test_records_refuse_verdicts_their_rule_does_not_give() -> None:
    with pytest.raises(ValueError, match="tolerance"):
        Comparison("x", "q", 1.0, 1.2, "paper", "within 0.1", "agree", tolerance=0.1)
    with pytest.raises(ValueError, match="do not overlap"):
        Comparison("x", "q", (0.35, 0.36), (0.3677, 0.3723), "experiment", "overlap", "agree")
    with pytest.raises(ValueError, match="synthetic"):
        Comparison("x", "q", "chaotic", "chaotic", "paper", "same", "agree", synthetic=True)
    with pytest.raises(ValueError, match="kind"):
        Comparison("x", "q", 1, 1, "model", "same", "agree")
    with pytest.raises(ValueError, match="no rule"):
        Comparison("x", "q", 1, 1, "paper", "", "agree")
    row = criterion_row("x", "q", "a", "b", None, kind="paper", rule="r", headline="h")
    assert row.verdict == "not comparable"
    assert Comparison.from_json(json.loads(json.dumps(row.to_json()))) == row


def test_every_paper_number_lives_in_paper_py() -> None:
    """The experiment tools' defaults are the paper's numbers of paper.py (one source of truth)."""
    from grazing.experiment import damping
    from grazing.models.pendulum import CASES

    assert damping.PAPER_DAMPING == paper.DAMPING.value
    assert damping.FIG4A == (paper.FIG4A[0].value, paper.FIG4A[1].value)
    for name, (r, b) in paper.FIG4B_POINTS.items():
        assert damping.PAPER_POINTS[name] == (r.value, b.value)
    for name, c in paper.CASES.items():
        assert CASES[name]["r"] == float(c["r"]) and CASES[name]["beta"] == float(c["beta"])
    assert CASES["B"]["alpha"] == paper.ALPHA_TABLE.value
    assert CASES["A-reduced"]["alpha"] == pytest.approx(paper.REDUCED_FORCING.value * paper.ALPHA_TABLE.value)


def test_drift_counts_each_resolved_edge_at_its_own_distance() -> None:
    from grazing.report.fig10 import degradation

    ms = match_windows([w(3, 1.010, 1.050), w(2, 1.0001, 1.2)], [w(3, 1.012, 1.045), w(2, 1.0001, 1.1)])
    out = degradation(ms, 1.0, step=1e-3)
    # the period-2 window's start is within 3 steps of grazing: left out
    assert [round(d, 4) for d, _ in out] == [0.01, 0.05, 0.2]
    assert dict((round(d, 4), round(e, 4)) for d, e in out) == {0.01: 0.2, 0.05: 0.1, 0.2: 0.5}


def test_the_paper_claims_of_issue_30_have_rows(data: dict) -> None:
    """§3 (realistic r, β), §6.2 (case A), fig 11 and fig 7 (10°, 20°) with α = A/L: each a row, a rule."""
    from grazing.experiment.damping import paper_protocol_damping

    rows = data["rows"]

    def one(fig: str, *words: str) -> dict:
        found = [r for r in rows if r["figure"] == fig and all(w in r["quantity"] for w in words)]
        assert len(found) == 1, (fig, words, [r["quantity"] for r in found])
        return found[0]

    # §3: on the reconstruction of the paper's curve, r = 0.5 and 0.8 give the printed β (0.015, 0.05);
    # checked independently: the reconstruction's damping estimator gives D = 0.07 at (r, β)
    for r, printed in paper.REALISTIC_RANGE:
        row = one("4", f"β at r = {r:g}", "reconstruction")
        assert row["verdict"] == "agree" and row["source"].startswith("§3")
        assert paper_protocol_damping(r, row["ours"]).damping == pytest.approx(paper.DAMPING.value, abs=2e-4)
        assert abs(row["ours"] - printed.value) <= printed.half_unit
    model = one("4", "β at r = 0.5", "model's curve")
    assert model["verdict"] == "differ" and "starts at r = 0.6" in model["ours_text"]
    # §6.2: case A's θ̂_max is the top of its stable response, far above 50°
    a = one("6", "§6.2", "case A")
    assert a["verdict"] == "agree" and a["source"] == "§6.2"
    top_a = float(re.search(r"case A ([\d.]+)°", a["ours_text"]).group(1))
    top_b = float(re.search(r"case B ([\d.]+)°", a["ours_text"]).group(1))
    assert top_a > 100.0 and top_b == pytest.approx(55.86, abs=0.1)  # B: the fold of fig 6 (row 6.14)
    # fig 11 at the paper's η with α = A/L: period 5, as with 0.2254
    al = one("11", "0.4458", "A/L")
    assert al["verdict"] == "differ" and "period 5" in al["ours"]
    # fig 7 with α = A/L at 10° and 20°: chaos past grazing stays under the appreciable width
    for key in ("(a)", "(b)"):
        chaos = one("7", key, "A/L", "chaos past the first grazing")
        assert chaos["verdict"] == "differ" and chaos["ours"] < diagrams.APPRECIABLE_WIDTH
        assert one("7", key, "A/L", "reverse period-adding")["verdict"] == "differ"
