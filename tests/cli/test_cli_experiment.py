"""The experiment commands: JSON keys, values, and one-line errors with nothing written."""

from __future__ import annotations

import json
import math
import shutil

import pytest

from grazing.experiment.synthetic import synthetic_sweep


def run(main, argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_the_experiment_commands_are_in_the_group():
    from grazing.cli import cli
    from grazing.cli.experiment import COMMANDS

    for cmd in COMMANDS:
        assert cli.get_command(None, cmd.name) is cmd


def test_damping_json(cli, capsys):
    code, out, err = run(cli, ["damping", "--r", "1", "--beta", "0.048", "--json"], capsys)
    assert code == 0, err
    res = json.loads(out)
    for key in ("D", "log_ratio", "amplitudes", "D_eq1", "D_linear", "D_paper_relation", "D_protocol"):
        assert key in res
    assert res["D"] == pytest.approx(0.048, rel=0.015)
    assert res["log_ratio"] == pytest.approx(2 * math.pi * res["D"])
    assert res["D_eq1"] == pytest.approx(res["D"] / 2)
    code, out, _ = run(cli, ["damping", "--case", "A", "--k-hat", "1", "--k-hat", "2", "--json"], capsys)
    res = json.loads(out)
    assert (res["r"], res["beta"], res["k_hat"]) == (0.4707, 0.01, [1, 2])


def test_damping_of_a_recording(cli, capsys, tmp_path):
    from grazing.experiment.synthetic import synthetic_free_decay, write_recording

    path = write_recording(synthetic_free_decay(0.7675, 0.048, duration=8.0, seed=2), tmp_path / "decay.csv")
    code, out, err = run(cli, ["damping", "--recording", str(path), "--json"], capsys)
    assert code == 0, err
    res = json.loads(out)
    assert res["D"] == pytest.approx(0.0905, rel=0.02)
    assert len(res["amplitudes"]) >= 3


def test_iso_damping_json_and_csv(cli, capsys, tmp_path):
    out_csv = tmp_path / "curve.csv"
    argv = ["iso-damping", "--damping", "0.07", "--num", "4", "--out", str(out_csv), "--json"]
    code, out, err = run(cli, argv, capsys)
    assert code == 0, err
    res = json.loads(out)
    assert len(res["r"]) == 4 and res["beta"][0] == 0.0 and res["r"][-1] == 1.0
    assert set(res["paper_points"]) == {"A", "B", "C", "D"}
    assert res["paper_points"]["B"]["D_model"] == pytest.approx(0.0905, abs=2e-4)
    assert out_csv.read_text().splitlines()[0] == "r,beta"
    code, out, _ = run(cli, ["iso-damping", "--relation", "paper", "--num", "2", "--json"], capsys)
    assert json.loads(out)["r_min"] == pytest.approx(math.exp(-4 * math.pi * 0.07))


def test_fit_json(cli, capsys):
    code, out, err = run(
        cli, ["fit", "--theta-hat", "40", "--eta-graze", "0.445", "--damping", "0.07", "--json"], capsys
    )
    assert code == 0, err
    res = json.loads(out)
    # the fit's two conditions, checked directly: case B's grazing at 40 deg is at the given eta, and
    # the damping of (r, beta) by the model's free decay (the default relation) is the given D
    from grazing.experiment import grazing_eta, model_damping

    assert res["eta_graze"] == pytest.approx(0.445, abs=1e-7)
    assert grazing_eta(40.0, res["beta"]) == pytest.approx(0.445, abs=1e-7)
    assert model_damping(res["r"], res["beta"]).damping == pytest.approx(0.07, abs=1e-5)
    # regression pins of the solution (close to the paper's case B, beta = 0.048, r = 0.7675, which
    # it fitted with another relation: tests/experiment/test_fit.py)
    assert res["beta"] == pytest.approx(0.0478, abs=2e-4)
    assert res["r"] == pytest.approx(0.872, abs=2e-3)


def test_analyze_file_json_and_plot(cli, capsys, tmp_path, period5_csv):
    plot = tmp_path / "rec.png"
    code, out, err = run(cli, ["analyze", str(period5_csv), "--plot", str(plot), "--json"], capsys)
    assert code == 0, err
    res = json.loads(out)
    for key in ("period", "samples", "noise", "forcing_hz", "eta", "gaps", "resampled", "synthetic"):
        assert key in res
    assert res["period"] == 5 and res["synthetic"] is True
    assert res["forcing_hz"] == pytest.approx(0.459234, rel=1e-5)
    assert plot.stat().st_size > 10_000


def test_analyze_without_trigger_needs_the_frequency(cli, capsys, tmp_path, period5_recording):
    from grazing.experiment.synthetic import write_recording

    path = write_recording(period5_recording, tmp_path / "run.csv", trigger=False, sidecar=False)
    code, _, err = run(cli, ["analyze", str(path), "--json"], capsys)
    assert code != 0 and err.count("\n") == 1 and "--forcing-hz" in err
    hz = period5_recording.metadata["forcing_hz"]
    code, out, err = run(cli, ["analyze", str(path), "--forcing-hz", str(hz), "--json"], capsys)
    assert code == 0, err
    res = json.loads(out)
    assert res["period"] == 5 and res["from_trigger"] is False


def test_analyze_folder_diagram(cli, capsys, tmp_path):
    folder = tmp_path / "sweep"
    synthetic_sweep(folder, 40.0, [0.43, 0.446, 0.4504], periods=36, transient=600, sample_rate=250.0)
    plot = tmp_path / "diagram.png"
    argv = ["analyze", str(folder), "--with-model", "--model-points", "3", "--plot", str(plot), "--json"]
    code, out, err = run(cli, argv, capsys)
    assert code == 0, err
    res = json.loads(out)
    assert res["theta_hat_deg"] == 40.0 and res["synthetic"] is True
    assert res["eta"] == pytest.approx([0.43, 0.446, 0.4504], abs=2e-5)
    assert res["period"] == [1, 5, 0]
    assert len(res["samples"]) == 3 and res["model"]["period"][0] == 1
    assert plot.is_file()


def test_synthesize(cli, capsys, tmp_path):
    out = tmp_path / "one.csv"
    argv = [
        "synthesize",
        "--eta",
        "0.446",
        "--periods",
        "10",
        "--sample-rate",
        "100",
        "--out",
        str(out),
        "--json",
    ]
    code, text, err = run(cli, argv, capsys)
    assert code == 0, err
    assert json.loads(text)["synthetic"] is True
    assert out.is_file() and out.with_suffix(".json").is_file()


# Malformed input through the CLI: one line on stderr, non-zero exit, nothing written.

_UNSORTED = [0, 0.2, 0.1] + [0.3 + 0.1 * k for k in range(30)]
_DUPLICATED = [0, 0.1, 0.1] + [0.2 + 0.1 * k for k in range(30)]
BAD_FILES = {
    "missing column": "time,theta\n0,1\n",
    "non-numeric": "time,angle\n0,0.1\n0.1,x\n",
    "unsorted": "time,angle\n" + "".join(f"{t},0.1\n" for t in _UNSORTED),
    "duplicated": "time,angle\n" + "".join(f"{t},0.1\n" for t in _DUPLICATED),
    "too short": "time,angle\n" + "".join(f"{0.01 * k:.2f},0.1\n" for k in range(100)),
    "empty": "",
}


@pytest.mark.parametrize("case", list(BAD_FILES))
def test_malformed_recordings_through_the_cli(cli, capsys, tmp_path, case):
    path = tmp_path / "bad.csv"
    path.write_text(BAD_FILES[case])
    before = sorted(p.name for p in tmp_path.iterdir())
    code, out, err = run(
        cli,
        ["analyze", str(path), "--forcing-hz", "0.46", "--plot", str(tmp_path / "p.png"), "--json"],
        capsys,
    )
    assert code != 0 and out == ""
    assert err.startswith("grazing: error: ") and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == before


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["damping", "--r", "1.5"], "r = 1.5"),
        (["damping", "--amplitude", "200"], "--amplitude"),
        (["damping", "--peaks", "2", "--k-hat", "3"], "--k-hat 3"),
        (["damping", "--case", "Z"], "unknown case"),
        (["iso-damping", "--damping", "0"], "damping D"),
        (["iso-damping", "--out", "x.txt"], ".csv"),
        (["fit", "--eta-graze", "0.40"], "even with beta = 0"),
        (["fit", "--theta-hat", "200"], "--theta-hat"),
        (["analyze", "nowhere.csv"], "no such file"),
        (["analyze", "nowhere.csv", "--plot", "out.txt"], ".png"),
        (["synthesize", "--eta", "0.4", "--eta", "0.5", "--out", "one.csv"], "folder"),
    ],
)
def test_bad_options_one_line(cli, capsys, tmp_path, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(cli, argv, capsys)
    assert code != 0 and out == ""
    assert err.count("\n") == 1 and message in err
    assert list(tmp_path.iterdir()) == []


def test_bad_file_in_a_folder_names_it(cli, capsys, tmp_path):
    folder = tmp_path / "sweep"
    synthetic_sweep(folder, 40.0, [0.43], periods=10, transient=10, sample_rate=100.0)
    (folder / "run7.csv").write_text("time,angle\n0,1\n")
    code, _, err = run(cli, ["analyze", str(folder), "--json"], capsys)
    assert code != 0 and "run7.csv" in err and err.count("\n") == 1
    shutil.rmtree(folder)
    folder.mkdir()
    code, _, err = run(cli, ["analyze", str(folder)], capsys)
    assert code != 0 and "no .csv recordings" in err
