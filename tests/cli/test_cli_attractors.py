"""``grazing basins``, ``grazing attractors`` and ``grazing sweep --direction both`` on the command line."""

from __future__ import annotations

import json
import math

import numpy as np

from grazing.cli import main

BALL = ["--model", "bouncing-ball", "--set", "amplitude=0.8", "--set", "r=0.8"]
GRID = ["--x-range", "-1,6", "--y-range", "-4,4", "--num", "7,5"]


def run_json(argv, capsys):
    assert main([*argv, "--json"]) == 0
    out, _ = capsys.readouterr()
    return json.loads(out)


def test_basins_json(capsys):
    res = run_json(["basins", *BALL, *GRID], capsys)
    assert res["x"] == np.linspace(-1, 6, 7).tolist() and res["y"] == np.linspace(-4, 4, 5).tolist()
    labels = np.array(res["labels"])
    assert labels.shape == (5, 7)  # N2 rows (along y) of N1 ids
    ids = {a["id"] for a in res["attractors"]}
    assert set(labels.ravel().tolist()) == ids
    assert math.isclose(sum(res["fractions"].values()), 1.0)
    for a in res["attractors"]:
        assert set(a) >= {"id", "kind", "period", "impacts_per_period", "points", "lyapunov"}
        assert res["fractions"][str(a["id"])] == (labels == a["id"]).mean()
    kinds = {a["kind"]: a for a in res["attractors"]}
    assert set(kinds) == {"invalid", "periodic", "sticking"}
    assert (labels[:, 0] == kinds["invalid"]["id"]).all()  # y = -1: below the table
    assert kinds["periodic"]["period"] == 1 and kinds["periodic"]["impacts_per_period"] == 1
    assert res["states"] == ["y", "v"]


def test_basins_files(tmp_path, capsys, monkeypatch):
    nc, png, store = tmp_path / "b.nc", tmp_path / "b.png", tmp_path / "b.zarr"
    assert main(["basins", *BALL, *GRID, "--out", str(nc), "--plot", str(png)]) == 0
    text = capsys.readouterr().out
    assert "sticking" in text and "saved to" in text and "plot written to" in text
    import xarray as xr

    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert ds.attrs["written_by"].startswith("grazing")
        assert ds.label.shape == (5, 7)
    assert b"Software" in png.read_bytes()[:4096]
    first = run_json(["basins", *BALL, *GRID, "--out", str(store), "--chunk-size", "8"], capsys)
    import grazing.sweeps.executor as executor

    monkeypatch.setattr(
        executor, "chunk_results", lambda *a, **k: (_ for _ in ()).throw(AssertionError("again"))
    )
    again = run_json(["basins", *BALL, *GRID, "--out", str(store), "--chunk-size", "8"], capsys)
    assert again["labels"] == first["labels"]


def test_attractors_json(capsys):
    argv = (
        "attractors --model bouncing-ball --set r=0.8 --param amplitude --start 0.3 --stop 0.8 --num 3 "
        "--x-range 0,6 --y-range -4,4 --num-grid 8,8"
    ).split()
    res = run_json(argv, capsys)
    assert res["values"] == [0.3, 0.55, 0.8]
    assert len(res["fractions"]) == 3
    for fr in res["fractions"]:
        assert math.isclose(sum(fr.values()), 1.0)
    by_id = {a["id"]: a for a in res["attractors"]}
    riding = [a for a in by_id.values() if a["kind"][0] == "sticking"]
    assert len(riding) == 1 and riding[0]["present"] == [True, True, True]
    orbit = [a for a in by_id.values() if a["kind"][1] == "periodic" and a["period"][1] == 1]
    assert len(orbit) == 1 and orbit[0]["present"] == [False, True, True]  # born past the fold (0.349)


def test_sweep_both_directions(capsys):
    argv = (
        "sweep --model two-sided-oscillator --set amp=0.5 --set gap_left=1.5 --param omega --start 1.2 "
        "--stop 1.6 --num 21 --direction both --transient 300 --periods 32 --chunk-size 5"
    ).split()
    res = run_json(argv, capsys)
    assert res["direction"] == "both"
    assert set(res["period"]) == {"up", "down"} and len(res["period"]["up"]) == 21
    assert res["impacts_per_period"]["down"][-1] == 0 and res["impacts_per_period"]["up"][-2] > 0
    (loop,) = [h for h in res["hysteresis"] if h["points"] > 5]  # the wide hysteresis loop
    assert loop["stop"] >= 1.58 and loop["down"] == "1 (no impacts)"
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "up:" in text and "down:" in text and "up and down differ at" in text


DAMPER_CHAOS = (
    "basins --model impact-damper --set omega=0.825 --states x1,v1 --fixed x2=0.5 "
    "--x-range -0.1,0.1 --y-range -0.1,0.1 --num 8,8"
).split()


def test_basins_cell_merges_a_chaotic_attractor_larger_than_the_box(capsys):
    merged = run_json(DAMPER_CHAOS, capsys)
    assert [a["kind"] for a in merged["attractors"]] == ["chaotic"] and merged["cell"] == 0.05
    split = run_json([*DAMPER_CHAOS, "--cell", "0"], capsys)  # (cells of the box: it falls apart)
    assert len(split["attractors"]) > 1 and split["cell"] == 0


def test_basins_neutral_and_polished_on_the_command_line(capsys):
    argv = (
        "basins --model impact-damper --set mu=0.3 --set r=0.8 --set omega=1.408 --states x1,v1 "
        "--fixed x2=0.5 --x-range -1,1 --y-range -1,1 --num 5,5 --transient 100 --refine 0"
    ).split()
    res = run_json(argv, capsys)
    assert sorted(a["kind"] for a in res["attractors"]) == ["neutral", "periodic"] and res["polished"] > 0
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "neutral, period 1, no impacts" in text and "not an isolated attractor" in text


def test_bad_cell_is_one_line(capsys):
    for bad in ("-0.1", "2", "nan", "x"):
        assert main([*DAMPER_CHAOS, "--cell", bad]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and "--cell" in err, err
