"""CLI: ``grazing curve`` (issue 27)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import xarray as xr

from grazing.cli import main

PD = "curve --kind period-doubling --param eta --start 0.446 --stop 0.44 --param2 theta-hat --range 39.9,40.1"
BALL = ["--model", "bouncing-ball", "--initial", "3.26,-2.34", "--period", "1"]


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


def test_curve_json_keys_and_display_units(capsys):
    res = json.loads(run([*PD.split(), "--json"], capsys))
    assert res["kind"] == "period-doubling" and res["params"] == ["eta", "theta_hat"]
    points = res["points"]
    assert {"eta", "theta_hat", "multipliers", "state", "period", "impacts"} <= set(points[0])
    theta = [p["theta_hat"] for p in points]  # degrees on the command line and in its output
    assert min(theta) == pytest.approx(39.9, abs=1e-9) and max(theta) == pytest.approx(40.1, abs=1e-9)
    assert {p["period"] for p in points} == {5} and {p["impacts"] for p in points} == {1}
    for p in points:  # a multiplier -1 at every point
        mu = np.array([complex(*z) for z in p["multipliers"]])
        assert np.min(np.abs(mu + 1)) < 1e-6
    assert res["special"] == [] and res["status"].count("reached the bound theta_hat = ") == 2
    assert res["start"]["theta_hat"] == pytest.approx(40.0) and res["start"]["eta"] == pytest.approx(
        0.4453926, abs=1e-7
    )


def test_curve_netcdf_text_and_rewrite(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    curve = "curve --kind fold --param amplitude --start 1.5 --stop 0.5 --param2 r --range 0.45,0.55"
    argv = [*curve.split(), *BALL, "--out", "fold.nc"]
    text = run(argv, capsys)
    assert "points of the fold curve of the period-1 orbit in (amplitude, r)" in text
    assert "curve saved to fold.nc" in text
    with xr.open_dataset(tmp_path / "fold.nc") as ds:
        a, r = ds.param1.values, ds.param2.values
        assert ds.param1.attrs["long_name"] == "amplitude" and ds.attrs["kind"] == "fold"
    np.testing.assert_allclose(a, math.pi * (1 - r) / (1 + r), atol=1e-7)
    run(argv, capsys)  # grazing wrote it: replaced without --overwrite


def test_curve_of_the_grazing_of_an_impacting_orbit(capsys):
    """The impact oscillator's impacting orbit loses its impact where the free response grazes."""
    argv = (
        "curve --model impact-oscillator --set zeta=0.05 --set sigma=0.5 --set r=0.8 --kind grazing --param "
        "omega --start 1.5 --stop 2.5 --param2 sigma --range 0.45,0.55 --period 1 --json"
    ).split()
    res = json.loads(run(argv, capsys))
    for p in res["points"]:
        w = p["omega"]
        assert p["sigma"] == pytest.approx(1 / math.sqrt((1 - w * w) ** 2 + (0.1 * w) ** 2), abs=1e-9)
