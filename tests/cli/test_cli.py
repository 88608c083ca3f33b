"""The command line: JSON keys, trajectory files, and one-line errors."""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys

import pytest

from grazing.cli import main


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_simulate_json_keys_and_values(capsys):
    code, out, err = run(["simulate", "--transient", "500", "--periods", "20", "--json"], capsys)
    assert code == 0, err
    res = json.loads(out)
    for key in ("params", "samples", "impacts", "sticking_intervals", "period"):
        assert key in res
    assert res["params"]["theta_hat_deg"] == 40.0
    assert res["params"]["case"] == "B"
    assert res["params"]["r"] == 0.7675
    assert len(res["samples"]) == 20 and len(res["samples"][0]) == 2
    assert res["period"] == 5  # paper fig 9(b): period five at theta_hat = 40 deg, eta = 0.446
    assert res["impacts"] > 0
    assert res["sticking_intervals"] == []


def test_explicit_parameters_override_the_case(capsys):
    argv = ["simulate", "--case", "A", "--beta", "0.02", "--eta", "0.5", "--theta-hat", "30"]
    code, out, _ = run([*argv, "--periods", "2", "--transient", "0", "--json"], capsys)
    p = json.loads(out)["params"]
    assert code == 0
    assert (p["r"], p["beta"], p["eta"], p["case"]) == (0.4707, 0.02, 0.5, "A")
    assert p["theta_hat"] == pytest.approx(math.radians(30))


def test_chattering_case_reports_sticking(capsys):
    argv = ["simulate", "--theta-hat", "-10", "--eta", "0.45", "--initial", "-0.5,0"]
    code, out, _ = run([*argv, "--transient", "5", "--periods", "10", "--json"], capsys)
    res = json.loads(out)
    assert code == 0
    assert len(res["sticking_intervals"]) >= 10
    assert all(b > a for a, b in res["sticking_intervals"])


def test_trajectory_csv(tmp_path, capsys):
    path = tmp_path / "traj.csv"
    argv = ["simulate", "--transient", "10", "--periods", "3", "--trajectory", str(path)]
    code, _, _ = run([*argv, "--points-per-period", "20", "--json"], capsys)
    assert code == 0
    rows = list(csv.reader(path.open()))
    assert rows.pop()[0].startswith("# written by grazing ")  # the mark: a comment line at the end
    assert rows[0] == ["tau", "theta", "dtheta"]
    taus = [float(r[0]) for r in rows[1:]]
    assert taus[0] == pytest.approx(10 * 2 * math.pi)
    assert taus[-1] == pytest.approx(13 * 2 * math.pi)
    assert len(rows) - 1 >= 3 * 20 + 1
    assert all(float(r[1]) <= math.radians(40) + 1e-12 for r in rows[1:])


def test_human_output(capsys):
    code, out, _ = run(["simulate", "--transient", "500", "--periods", "20"], capsys)
    assert code == 0
    assert "period 5" in out


BAD = [
    (["--r", "1.5"], "r = 1.5 is outside [0, 1]"),
    (["--r", "-0.5"], "r = -0.5 is outside"),
    (["--eta", "0"], "eta = 0 is outside"),
    (["--eta", "-0.3"], "eta = -0.3 is outside"),
    (["--beta", "-0.01"], "beta = -0.01 is outside"),
    (["--theta-hat", "180"], "--theta-hat must be in (-180, 180) degrees"),
    (["--theta-hat", "-200"], "--theta-hat must be in (-180, 180) degrees"),
    (["--initial", "0.9,0"], "beyond the stop"),
    (["--case", "Q"], "unknown case 'Q'"),
    (["--alpha", "abc"], "'abc' is not a valid float"),
    (["--alpha", "nan"], "alpha must be finite"),
    (["--eta", "nan"], "eta must be finite"),
    (["--theta-hat", "nan"], "--theta-hat must be in"),
    (["--initial", "nan,0"], "--initial must be finite"),
    (["--initial", "0;0"], "--initial must be THETA,THETADOT"),
    (["--periods", "-2"], "'--periods': -2 is not in the range"),
    (["--transient", "-1"], "'--transient': -1 is not in the range"),
    (["--periods", "1.5"], "'--periods'"),
    (["--trajectory", "/nonexistent-dir/x.csv"], "does not exist"),
]


@pytest.mark.parametrize(("args", "message"), BAD)
def test_bad_input_is_one_line_and_nonzero(args, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(["simulate", "--periods", "2", "--transient", "0", *args], capsys)
    assert code != 0
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("grazing: error: ")
    assert message in lines[0]
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_console_script_exit_status_and_stderr():
    proc = subprocess.run(
        [sys.executable, "-m", "grazing.cli", "simulate", "--r", "2"], capture_output=True, text=True
    )
    assert proc.returncode != 0
    assert proc.stdout == ""
    assert proc.stderr.strip() == "grazing: error: r = 2 is outside [0, 1] (coefficient of restitution)"
    assert "Traceback" not in proc.stderr


def test_help_and_version(capsys):
    assert run(["--help"], capsys)[0] == 0
    code, out, _ = run(["--version"], capsys)
    assert code == 0 and "grazing" in out


def test_sweep_without_a_store_builds_no_dataset(tmp_path):
    """A sweep printed or emitted as JSON keeps its arrays: xarray (and the dask it imports) stay unloaded;
    asking for a NetCDF file builds the dataset, with the same periods."""
    code = (
        "import json, sys\n"
        "from grazing.cli import main\n"
        "sys.argv = ['grazing', 'sweep', '--param', 'eta', '--start', '0.44', '--stop', '0.45',\n"
        "            '--num', '4', '--transient', '20', '--periods', '8', '--workers', '1'] + sys.argv[1:]\n"
        "try:\n"
        "    main()\n"
        "except SystemExit as exc:\n"
        "    assert not exc.code, exc.code\n"
        "print(json.dumps(['xarray' in sys.modules, 'dask' in sys.modules]))\n"
    )
    quiet = subprocess.run(
        [sys.executable, "-c", code, "--json"], capture_output=True, text=True, timeout=600
    )
    assert quiet.returncode == 0, quiet.stderr
    first, flags = quiet.stdout.strip().splitlines()
    assert json.loads(flags) == [False, False]
    nc = tmp_path / "s.nc"
    saved = subprocess.run([sys.executable, "-c", code, "--out", str(nc)], capture_output=True, text=True,
                           timeout=600)  # fmt: skip
    assert saved.returncode == 0, saved.stderr
    assert json.loads(saved.stdout.strip().splitlines()[-1])[0] is True
    import xarray as xr

    with xr.open_dataset(nc) as ds:
        assert ds.sortby("value").period.values.tolist() == json.loads(first)["period"]


def test_bare_grazing_prints_the_help(capsys):
    code, out, err = run([], capsys)
    assert code == 0 and err == ""
    assert out.startswith("Usage: grazing [OPTIONS] COMMAND [ARGS]...\n")
    assert "\nCommands:\n" in out and "  simulate " in out


def test_the_simulate_summary_has_no_cut_or_dangling_lines(capsys):
    # A model with many parameters: its header is one line, whatever the terminal's width, and no
    # line ends with a separator (a line cut at the width once left "sticking intervals: 0; ").
    argv = ["simulate", "--model", "two-sided-oscillator", "--set", "omega=0.8", "--transient", "20"]
    code, out, err = run([*argv, "--periods", "4"], capsys)
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0].startswith("two-sided-oscillator ") and lines[0].rstrip().endswith("r=0.8")
    assert "sticking intervals: 0" in out
    assert not [line for line in lines if line.rstrip().endswith((";", ","))]


def test_damping_refuses_more_peaks_than_its_free_decay_has(capsys):
    from grazing.experiment.damping import MIN_SWING, free_decay
    from grazing.models.pendulum import case_values

    # Case B released 0.5 rad below the stop: each peak is smaller by the factor
    # exp(-2 pi beta / sqrt(1 - 4 beta^2)) r (small-amplitude decay, impact at zero angle), so the
    # swing falls below MIN_SWING after floor(ln(0.5 / MIN_SWING) / per-peak) peaks.
    b = case_values("B")
    per_peak = 2 * math.pi * b["beta"] / math.sqrt(1 - 4 * b["beta"] ** 2) - math.log(b["r"])
    most = math.floor(math.log(0.5 / MIN_SWING) / per_peak)
    code, out, err = run(["damping", "--peaks", str(most), "--json"], capsys)
    assert code == 0, err
    assert len(json.loads(out)["amplitudes"]) == most + 1  # the release and every peak asked for
    assert free_decay(b["r"], b["beta"], peaks=most).amplitudes[-1] > MIN_SWING
    code, out, err = run(["damping", "--peaks", str(most + 1)], capsys)
    assert code == 2 and out == ""
    assert err == (
        f"grazing: error: --peaks {most + 1}: the free decay at r = 0.7675, beta = 0.048 falls below "
        f"1e-10 rad after {most} peaks; ask for at most {most} --peaks\n"
    )


def test_every_command_is_loaded_on_first_use_and_listed():
    """The group imports a command's module only when it runs; the table names every command once."""
    import subprocess
    import sys

    import click

    from grazing.cli import COMMANDS, cli

    code = (
        "import sys; from grazing.cli import main; main(['sweep', '--help'])\n"
        "print(sorted(m for m in sys.modules if m.startswith('grazing.cli.') or m == 'grazing.orbits'))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    loaded = out.strip().splitlines()[-1]
    assert "grazing.cli.sweeps" in loaded
    assert "grazing.cli.attractors" not in loaded and "grazing.orbits'" not in loaded
    ctx = click.Context(cli)
    commands = {name: cli.get_command(ctx, name) for name in cli.list_commands(ctx)}
    assert set(commands) == set(COMMANDS) and all(c is not None and c.name == n for n, c in commands.items())
