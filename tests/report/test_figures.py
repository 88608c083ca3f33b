"""Figures 6, 7, 8, 12 and the period map: built at quick resolution (see conftest.py), numbers checked."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from grazing.report import FIGURES, diagrams, fig06, fig07, fig08, fig12, figmap
from grazing.report.base import Comparison, FigureResult
from grazing.report.diagrams import Panel, Settings

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _images_ok(out: Path, result: FigureResult) -> None:
    assert result.images
    for img in result.images:
        data = (out / img.filename).read_bytes()
        assert data.startswith(PNG_SIGNATURE), img.filename
        assert len(data) > 10_000, (img.filename, len(data))
        assert img.caption


def _row(result: FigureResult, text: str) -> Comparison:
    row = next(r for r in result.comparisons if text in r.item)
    assert row.agrees is None or type(row.agrees) is bool
    return row


def _built(module, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, FigureResult]:
    out = tmp_path_factory.mktemp(f"fig{module.FIGURE_ID}")
    messages: list[str] = []
    result = module.build(out, messages.append)
    assert messages and any(" s" in m for m in messages), "no timed progress messages"
    return out, result


@pytest.fixture(scope="module")
def built6(tmp_path_factory):
    return _built(fig06, tmp_path_factory)


@pytest.fixture(scope="module")
def built7(tmp_path_factory):
    return _built(fig07, tmp_path_factory)


@pytest.fixture(scope="module")
def built8(tmp_path_factory):
    return _built(fig08, tmp_path_factory)


@pytest.fixture(scope="module")
def built12(tmp_path_factory):
    return _built(fig12, tmp_path_factory)


@pytest.fixture(scope="module")
def builtmap(tmp_path_factory):
    return _built(figmap, tmp_path_factory)


def test_registered_in_page_order() -> None:
    ids = [m.FIGURE_ID for m in FIGURES]
    for fid in ("6", "7", "8", "12", "map"):
        assert fid in ids
    assert ids.index("6") < ids.index("7") < ids.index("8") < ids.index("12")


# ----------------------------------------------------------------------------- fig 6


def test_fig06_images_and_grazings_at_40_degrees(built6) -> None:
    out, res = built6
    _images_ok(out, res)
    row = _row(res, "grazings at θ̂ = 40°")
    assert "0.4451" in row.ours and "0.5473" in row.ours and row.agrees is True
    b = _row(res, "inset (b)")
    assert "0.4612 ± 0.2127i" in b.ours and b.agrees is True
    c = _row(res, "inset (c)")
    assert "0.2548 ± 0.5170i" in c.ours and c.agrees is True


def test_fig06_theta_max_two_ways(built6) -> None:
    _, res = built6
    row = _row(res, "θ̂_max")
    values = [float(v) for v in re.findall(r"(\d+\.\d+)°", row.ours)]
    assert len(values) == 2 and all(55.0 < v < 57.0 for v in values)
    assert abs(values[0] - values[1]) < 1e-3 and row.agrees is True


def test_fig06_errata_rows(built6) -> None:
    _, res = built6
    lam = _row(res, "|λ| at the first grazing")
    assert "0.5079" in lam.ours and lam.agrees is False and "0.5078" in lam.note
    a = _row(res, "where the grazing at θ̂ = 10° is")
    assert "0.3331" in a.ours and "−0.4042 ± 0.0132i" in a.ours and a.agrees is False
    mod = _row(res, "|λ| at the grazing for θ̂ = 10°")
    assert mod.agrees is True
    second = _row(res, "no second grazing")
    assert second.agrees is True and "12.91°" in second.ours


# ----------------------------------------------------------------------------- fig 7


def test_fig07_window_sequence_at_40_degrees() -> None:
    """4, 3, 2 in decreasing order past the first grazing, then impacting period 1 (a fine sweep)."""
    run = diagrams.run_panel(
        "B", Panel("d", 40.0, (0.44, 0.49)), Settings(points=250, transient=300, periods=60)
    )
    assert [round(g.eta, 4) for g in run.grazings] == [0.4451, 0.5473]
    seq = [w.period for w in run.after_grazing(2)]
    pos = [seq.index(p) for p in (4, 3, 2)]
    assert pos == sorted(pos), seq
    assert seq[-1] == 1
    pd = [s.eta for s in run.specials if s.kind == "period-doubling"]
    assert pd and abs(pd[0] - 0.47825) < 1e-3  # ends the period-2 window
    first = run.first_appreciable()
    assert first is not None and first.period == 4


def test_fig07_build(built7) -> None:
    out, res = built7
    _images_ok(out, res)
    rows = {r.item: r for r in res.comparisons}
    firsts = [r for r in res.comparisons if "first appreciable" in r.item]
    assert len(firsts) == 4
    assert all(r.agrees for r in firsts[:3]), [r.ours for r in firsts]
    ends = _row(res, "how the impacting region ends")
    assert ends.agrees is False and "fold" in ends.ours
    assert any("experiment's η_c" in k for k in rows)


# ----------------------------------------------------------------------------- fig 8


def test_fig08_grazing_angle_and_cascade(built8) -> None:
    out, res = built8
    _images_ok(out, res)
    g = _row(res, "grazing stop angle")
    assert "41.333°" in g.ours and g.agrees is True
    cas = _row(res, "period-adding cascade")
    periods = [int(p) for p in re.findall(r"(\d+) \(θ̂", cas.ours)]
    assert periods[:4] == [2, 3, 4, 5] and cas.agrees is True
    ab = _row(res, "case A (smaller β) against case B")
    fa, fb = (int(v) for v in re.findall(r"(\d+)% \((?:A|B)\)", ab.ours)[:2])
    assert fa > fb


# ----------------------------------------------------------------------------- fig 12


def test_fig12_build(built12) -> None:
    out, res = built12
    _images_ok(out, res)
    d = _row(res, "fig 12(d)")
    assert "period-5" in d.ours and d.agrees is True
    assert len(res.comparisons) == 6


# ----------------------------------------------------------------------------- map


def test_map_consistent_with_grazing_curve(builtmap) -> None:
    out, res = builtmap
    _images_ok(out, res)
    below = _row(res, "below the grazing curve")
    assert below.ours.startswith("0 of the") and below.agrees is True


def test_map_classify_counts(tmp_path: Path) -> None:
    run = figmap.compute(figmap.Settings(eta=(0.42, 0.5, 6), theta_hat_deg=(30.0, 60.0, 4), periods=40))
    assert run.ds.period.shape == (4, 6)
    c = figmap.classify(run)
    assert c["below_no_impact"] == 0
    assert abs(math.degrees(c["th_max"]) - 55.856) < 0.01
    assert np.all(np.diff(run.max_angle[:3]) > 0)  # rising branch of the response below the peak
