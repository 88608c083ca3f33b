"""CLI: orbit, graze, graze-curve, continue."""

from __future__ import annotations

import json

import pytest

from grazing.cli import main


def run_json(argv, capsys):
    code = main([*argv, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_orbit_json(capsys):
    res = run_json(["orbit", "--theta-hat", "40", "--eta", "0.446"], capsys)
    assert res["period"] == 5 and res["impacts"] == 1 and res["stable"] is True
    assert len(res["state"]) == 2
    assert len(res["multipliers"]) == 2 and len(res["multipliers"][0]) == 2
    assert res["max_theta_deg"] == pytest.approx(40.0, abs=1e-9)  # it impacts: max angle is the stop


def test_orbit_nonimpacting_max_theta(capsys):
    res = run_json(["orbit", "--theta-hat", "40", "--eta", "0.40", "--period", "1"], capsys)
    assert res["impacts"] == 0 and res["period"] == 1
    assert 20 < res["max_theta_deg"] < 40


def test_graze_json(capsys):
    res = run_json(["graze", "--theta-hat", "40"], capsys)
    etas = [g["eta"] for g in res["grazings"]]
    assert etas == pytest.approx([0.4451, 0.5473], abs=2e-4)
    for g in res["grazings"]:
        assert set(g) >= {"eta", "multipliers", "abs_lambda", "t_graze"}
        assert 0 <= g["t_graze"] < 6.2832


def test_graze_curve_json(capsys, tmp_path):
    out = tmp_path / "curve.nc"
    res = run_json(["graze-curve", "--out", str(out)], capsys)
    assert 54 < res["theta_max_deg"] < 57
    assert 0.45 < res["eta_at_theta_max"] < 0.50
    assert len(res["curve"]) > 20
    assert out.exists()


def test_continue_json_and_netcdf(capsys, tmp_path):
    out = tmp_path / "branch.nc"
    argv = ["continue", "--param", "eta", "--start", "0.40", "--stop", "0.60", "--out", str(out)]
    res = run_json(argv, capsys)
    kinds = [s["kind"] for s in res["special"]]
    assert kinds == ["grazing", "grazing"]
    assert res["values"][0] == 0.40 and res["values"][-1] == pytest.approx(0.60)
    assert out.exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["orbit", "--r", "3"], "r = 3 is outside"),
        (["graze", "--eta-min", "0.5", "--eta-max", "0.4"], "need 0 < --eta-min < --eta-max"),
        (["continue", "--param", "eta", "--start", "0.4", "--stop", "0.4"], "must be finite and differ"),
        (["continue", "--param", "gamma", "--start", "0", "--stop", "1"], "unknown parameter 'gamma'"),
        (["continue", "--param", "eta", "--start", "0.4", "--stop", "0.5", "--out", "x.txt"],
         "--out must name a .nc file"),
        (["graze-curve", "--out", "/nonexistent/c.nc"], "does not exist"),
    ],
)  # fmt: skip
def test_errors_are_one_line(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = main(argv)
    _out, err = capsys.readouterr()
    assert code != 0
    assert message in err
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_newton_failure_is_reported(capsys):
    argv = ["orbit", "--eta", "0.4458", "--period", "2", "--initial", "0.6,0.6"]
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 1 and out == ""
    assert err.startswith("grazing: error: Newton did not converge to a period-2 orbit: residual")
    assert "after 30 iterations; try another initial guess" in err
    assert len(err.strip().splitlines()) == 1
