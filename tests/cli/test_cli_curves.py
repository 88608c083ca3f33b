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
    for p in points:  # a multiplier -1 at every point, as accurately as the point says
        mu = np.array([complex(*z) for z in p["multipliers"]])
        assert np.min(np.abs(mu + 1)) <= p["accuracy"] < 1e-6
    assert res["special"] == [] and res["status"].count("reached the bound theta_hat = ") == 2
    assert res["outcomes"] == ["bound", "bound"]  # (each end's CurveEnd, by its word)
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


def test_curve_says_where_its_multipliers_are_known_only_roughly(capsys, tmp_path):
    """A random model's fold curve ends at a grazing: next to it the monodromy is so far from normal
    that its multiplier 1 is known only to ~1e-5 (tests/orbits/test_curves.py measures it); the
    summary says so, and --json gives every point's accuracy."""
    path = tmp_path / "near.py"
    path.write_text(
        "from tests.orbits.test_curves import NEAR_GRAZING_FOLD\nMODEL = NEAR_GRAZING_FOLD.model()\n"
    )
    argv = (
        f"curve --model {path}:MODEL --kind fold --param T --start 1.0 --stop 0.3 --param2 J "
        "--range 0.7503125,0.7809375 --initial 0,1.8 --period 1"
    ).split()
    text = run(argv, capsys)
    assert "ended at a grazing" in text
    note = next(line for line in text.splitlines() if line.startswith("note: the multipliers of "))
    worst = float(note.split("known only to ")[1].split(":")[0])
    res = json.loads(run([*argv, "--json"], capsys))
    assert res["status"].count("ended at a grazing") == 1 and "grazing" in res["outcomes"]
    accuracy = [p["accuracy"] for p in res["points"]]
    assert worst == pytest.approx(max(accuracy), rel=0.5) and worst > 1e-6
    assert int(note.split()[4]) == sum(a > 1e-6 for a in accuracy) >= 1
    assert sum(a < 1e-9 for a in accuracy) >= len(accuracy) // 2  # away from the grazing
