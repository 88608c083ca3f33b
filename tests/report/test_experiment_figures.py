"""The figure functions draw and return the numbers (paper beside ours)."""

from __future__ import annotations

import json

import pytest

from grazing.report import fig02, fig04


def test_figure_4a_and_4b_write_pngs_and_numbers(tmp_path):
    a = fig04.figure_4a(tmp_path / "fig4a.png")
    assert (tmp_path / "fig4a.png").stat().st_size > 10_000
    assert a["D_eq6"] == pytest.approx(0.0964, abs=2e-4)
    assert a["D_protocol"] == pytest.approx(0.07, abs=1e-3)
    b = fig04.figure_4b(tmp_path / "fig4b.png", num=4)
    assert (tmp_path / "fig4b.png").is_file()
    assert b["points"]["A"]["beta_model_curve"] is None  # A lies beyond the model's curve (r < r_min)
    assert b["points"]["D"]["D_paper_relation"] == pytest.approx(0.068)
    json.dumps([a, b])  # plain data


def test_figure_3_and_2_synthetic(tmp_path):
    res = fig02.figure_3_synthetic(
        tmp_path / "fig3.png", cases=[(40.0, 0.446), (40.0, 0.4504)], periods=36, sample_rate=250.0
    )
    assert [r["period"] for r in res["rows"]] == [5, 0]
    assert [r["model_period"] for r in res["rows"]] == [5, 0]
    assert res["synthetic"] is True and (tmp_path / "fig3.png").is_file()
    res = fig02.figure_2_synthetic(
        tmp_path / "fig2.png",
        theta_hats=[40.0],
        num=3,
        span=(-0.015, 0.001),
        periods=20,
        transient=200,
        sample_rate=200.0,
        model_num=3,
        workers=1,
    )
    row = res["40"]
    assert row["eta_graze"] == pytest.approx(0.44512, abs=1e-5) and row["paper_eta_c"] == 0.446
    assert row["period"][0] == 1 and len(row["model_period"]) == 3
    json.dumps(res)
