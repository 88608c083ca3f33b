"""issue 45: the report's section on grazing a switching surface (figswitch), built on its own (seconds).

Every row's printed rule must hold where it says "agree"; the rows' numbers must be those of the data
file and of the figure; the closed forms are recomputed here independently (complex arithmetic); and a
map made wrong (its coefficient, its power, its sign) must make rows differ.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

import grazing.normalform.switching as switching
from grazing.normalform.switching_check import loglog_slope
from grazing.report import build_report, figswitch, select
from grazing.report.base import FigureResult, consistency_problem


@pytest.fixture(scope="module")
def section(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, FigureResult]:
    out = tmp_path_factory.mktemp("switch")
    return out, figswitch.build(out)


@pytest.fixture(scope="module")
def run() -> figswitch.Run:
    return figswitch.compute(figswitch.SETTINGS)


def _row(res: FigureResult, *words: str):
    (row,) = [r for r in res.comparisons if all(w in r.quantity for w in words)]
    return row


def _csv(out: Path) -> dict[str, dict[str, np.ndarray]]:
    with open(out / "switch_zdm.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    sets: dict[str, dict[str, np.ndarray]] = {}
    for which in figswitch.FAMILIES:
        mine = [r for r in rows if r["set"] == which]
        sets[which] = {k: np.array([float(r[k]) for r in mine]) for k in mine[0] if k != "set"}
    return sets


def test_every_row_agrees_and_its_printed_rule_holds(section) -> None:
    out, res = section
    assert len(res.comparisons) == 14
    for r in res.comparisons:
        assert r.kind == "self-check" and r.reference and r.rule, r.quantity
        assert r.verdict == "agree", (r.quantity, r.ours, r.rule)
        assert consistency_problem(r) == ""
        if r.tolerance is not None:  # a numeric row: the rule as printed, re-applied
            assert abs(r.ours - r.paper) <= r.tolerance
    # the slopes as the rules print them, from the data file
    data = _csv(out)
    for which, power in figswitch.POWERS.items():
        d = data[which]
        size, error = loglog_slope(d["delta"], d["size"]), loglog_slope(d["delta"], d["error"])
        assert abs(size - 1.5) <= 0.01 and abs(error - power) <= 0.05
        label = figswitch.LABELS[which]
        assert (
            _row(res, label, "slope of |Δ|").ours == size
            and "≤ 0.01" in _row(res, label, "slope of |Δ|").rule
        )
        assert _row(res, label, "slope of the map's error").ours == error
        ratios = d["error"] / d["size"] / d["delta"] ** figswitch.RELATIVE_POWERS[which]
        one_c = _row(res, label, "one C")
        assert one_c.delta == ratios.max() / ratios.min() <= 1.05 and "≤ 1.05" in one_c.rule
        asked = d["delta_asked"]
        assert asked.max() / asked.min() == pytest.approx(1e4) and len(asked) >= 13  # four decades


def test_the_closed_forms_recomputed_here(section) -> None:
    """The free orbit ``x = Re(X exp(i omega t))``, ``X = a / (1 - omega^2 + 2 i zeta omega)``: it grazes
    where ``|X| = gap``, at its largest ``x``; there ``x'' = -omega^2 gap`` and the map's coefficient is
    ``(4/3) sqrt(2 / (omega^2 gap))``."""
    _, res = section
    p = figswitch.DEFAULTS
    z = 1 - p["omega"] ** 2 + 2j * p["zeta"] * p["omega"]
    a_star = p["gap"] * abs(z)
    assert _row(res, "forcing amplitude a*").paper == pytest.approx(a_star, rel=0, abs=1e-15)
    assert _row(res, "forcing amplitude a*").ours == pytest.approx(a_star, rel=0, abs=1e-10)
    t_star = _row(res, "time t*").paper
    X = a_star / z
    assert (X * np.exp(1j * p["omega"] * t_star)).real == pytest.approx(p["gap"], abs=1e-15)
    assert abs((1j * p["omega"] * X * np.exp(1j * p["omega"] * t_star)).real) < 1e-14
    assert 0 <= t_star < 2 * math.pi / p["omega"]
    assert _row(res, "a = L_f² h").paper == pytest.approx(p["omega"] ** 2 * p["gap"], rel=1e-15)
    coef = 4 / 3 * math.sqrt(2 / (p["omega"] ** 2 * p["gap"]))
    assert _row(res, "the map's coefficient").paper == pytest.approx(coef, rel=1e-15)
    assert _row(res, "the simulation's coefficient").paper == pytest.approx(coef, rel=1e-15)


def test_the_figure_and_the_data_are_the_computed_ones(section, run, tmp_path: Path) -> None:
    out, res = section
    assert [i.filename for i in res.images] == ["switch_zdm.png"]
    assert [d.filename for d in res.data] == ["switch_zdm.csv"]
    assert (out / "switch_zdm.png").stat().st_size > 10_000
    data = _csv(out)
    fig = figswitch.draw(run, tmp_path / "again.png")
    for ax, which in zip(fig.axes, figswitch.FAMILIES):
        c = run.checks[which]
        d = data[which]
        np.testing.assert_array_equal(d["delta_asked"], run.nominal[which])
        np.testing.assert_array_equal(d["delta"], c.depth)
        np.testing.assert_array_equal(np.c_[d["actual_x"], d["actual_v"]], c.actual)
        np.testing.assert_array_equal(np.c_[d["predicted_x"], d["predicted_v"]], c.predicted)
        np.testing.assert_array_equal(d["error"], np.linalg.norm(c.actual - c.predicted, axis=1))
        drawn = {line.get_label().split(":")[0].split(" (")[0]: line for line in ax.get_lines()}
        assert set(drawn) == {"|Δ|", "the map's prediction", "ε = |Δ − prediction|"}
        for key, values in (("|Δ|", c.size), ("the map's prediction", c.predicted_size),
                            ("ε = |Δ − prediction|", c.error)):  # fmt: skip
            np.testing.assert_array_equal(drawn[key].get_xdata(), c.depth)
            np.testing.assert_array_equal(drawn[key].get_ydata(), values)
        assert ax.get_xscale() == ax.get_yscale() == "log" and ax.get_xlabel() and ax.get_ylabel()
        assert ax.get_legend() is not None
    # the section's own numbers: a second computation gives the same (the rows are the drawn data's)
    assert _row(res, "simulation's coefficient").ours == run.coefficient


FAMILY, OFF = figswitch.LABELS["family"], figswitch.LABELS["off"]
ERRORS = {
    label: (f"{label}: log-log slope of the map's error", f"{label}: ε / |Δ|") for label in (FAMILY, OFF)
}


BOTH = ERRORS[FAMILY] + ERRORS[OFF]


def _wrong(factor: float = 1.0, power: float = 1.5):
    """A correction ``-factor * coefficient * delta^power * w`` in place of the map's."""

    def correction(m, x, t=None, model=None):
        delta = m.penetration(x, t, model)
        if delta <= 0:
            return np.zeros(m.model.n_states)
        return -factor * m.coefficient * delta**power * m.jump

    return correction


@pytest.mark.parametrize(
    ("wrong", "differ"),
    [
        pytest.param(_wrong(factor=1 + 1e-5), ERRORS[FAMILY], id="coefficient+1e-5"),
        pytest.param(_wrong(factor=-1.0), BOTH, id="sign"),
        pytest.param(_wrong(power=1.45), BOTH, id="power-1.45"),
    ],
)
def test_a_wrong_map_makes_its_rows_differ(monkeypatch, wrong, differ) -> None:
    """The rows could fail: the map's correction made wrong (a coefficient off by a relative 1e-5, the
    opposite sign, the power 1.45 for 1.5), the rows that check it against the flow differ, and only
    they (the grazing, the map's ingredients and the flow itself are not the correction's)."""
    monkeypatch.setattr(switching.SwitchingMap, "correction", wrong)
    run = figswitch.compute(figswitch.SETTINGS)
    rows = figswitch.comparisons(run, figswitch.SETTINGS)
    found = sorted(r.quantity for r in rows if r.verdict != "agree")
    assert len(found) == len(differ) and all(q.startswith(d) for q, d in zip(found, sorted(differ))), found


def test_a_wrong_coefficient_makes_its_row_differ(monkeypatch) -> None:
    monkeypatch.setattr(switching, "ZDM_COEFFICIENT", switching.ZDM_COEFFICIENT * (1 + 1e-6))
    run = figswitch.compute(figswitch.SETTINGS)
    rows = {r.quantity: r for r in figswitch.comparisons(run, figswitch.SETTINGS)}
    assert rows["the map's coefficient (4/3)√(2/a)"].verdict == "differ"
    # the simulation's coefficient does not depend on the map's: it still agrees with the closed form
    assert next(r for q, r in rows.items() if q.startswith("the simulation's coefficient")).verdict == "agree"


def test_the_section_alone_in_a_report(tmp_path: Path) -> None:
    """``grazing report --only switch``: the section, its rows in comparisons.json, its image and data."""
    assert [m.FIGURE_ID for m in select(["switch"])] == ["switch"]
    index = build_report(tmp_path / "report", only=["switch"])
    page = index.read_text(encoding="utf-8")
    assert 'id="figswitch"' in page
    assert '<a href="switch_zdm.png"><img src="switch_zdm.png"' in page and 'href="switch_zdm.csv"' in page
    rows = json.loads((index.parent / "comparisons.json").read_text(encoding="utf-8"))["rows"]
    assert len(rows) == 14 and {r["figure"] for r in rows} == {"switch"}
    assert all(r["verdict"] == "agree" for r in rows)
