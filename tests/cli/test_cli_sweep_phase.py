"""``grazing sweep --phase`` and ``grazing map --phase``: the stroboscopic phase of the samples."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import grazing
from grazing.cli import main

SHORT = ["--transient", "20", "--periods", "4", "--no-lyapunov", "--no-adaptive", "--tol", "1e-10",
         "--workers", "1", "--json"]  # fmt: skip


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("phase", [0.0, 1.3])
def test_sweep_samples_at_the_phase(capsys, phase):
    """The first point of a sweep (from rest at t = 0) is ``simulate``'s run sampled at that phase."""
    argv = [
        "sweep",
        "--param",
        "eta",
        "--start",
        "0.44",
        "--stop",
        "0.45",
        "--num",
        "2",
        "--phase",
        str(phase),
    ]
    code, out, err = run([*argv, *SHORT], capsys)
    assert code == 0, err
    res = json.loads(out)
    assert res["phase"] == phase and res["periods"] == 4
    m = grazing.models.pendulum("B", eta=0.44)
    sol = grazing.simulate(m, [0.0, 0.0], transient=20, periods=4, phase=phase, tol=1e-10)
    np.testing.assert_allclose(res["samples"][0], sol.samples[:, 0], atol=1e-8)  # (the first state's)
    if phase:  # (another phase is another section: not the phase-0 samples)
        zero = grazing.simulate(m, [0.0, 0.0], transient=20, periods=4, phase=0.0, tol=1e-10)
        assert np.max(np.abs(np.asarray(res["samples"][0]) - zero.samples[:, 0])) > 1e-3


def test_map_samples_at_the_phase(capsys, tmp_path):
    """``map --phase``: in the JSON and in the saved dataset's spec, whose samples are at that phase."""
    out_file = tmp_path / "m.nc"
    argv = ["map", "--param1", "eta", "--start1", "0.44", "--stop1", "0.45", "--num1", "2", "--param2", "r",
            "--start2", "0.7", "--stop2", "0.75", "--num2", "2", "--phase", "2.5"]  # fmt: skip
    code, out, err = run([*argv, *SHORT], capsys)
    assert code == 0, err
    assert json.loads(out)["phase"] == 2.5
    code, _, err = run([*argv, *SHORT[:-1], "--out", str(out_file)], capsys)
    assert code == 0, err
    import xarray as xr

    with xr.open_dataset(out_file) as ds:
        first = ds.samples.isel(eta=0, r=0).values if "eta" in ds.samples.dims else None
    m = grazing.models.pendulum("B", eta=0.44, r=0.7)
    sol = grazing.simulate(m, [0.0, 0.0], transient=20, periods=4, phase=2.5, tol=1e-10)
    assert first is not None
    np.testing.assert_allclose(first, sol.samples, atol=1e-8)


@pytest.mark.parametrize("command", ["sweep", "map"])
@pytest.mark.parametrize("bad", ["nan", "inf", "abc"])
def test_a_bad_phase_is_one_line(capsys, command, bad):
    argv = (
        ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.45", "--num", "2"]
        if command == "sweep"
        else ["map", "--param1", "eta", "--start1", "0.44", "--stop1", "0.45", "--num1", "2",
              "--param2", "r", "--start2", "0.7", "--stop2", "0.75", "--num2", "2"]
    )  # fmt: skip
    code, out, err = run([*argv, "--phase", bad], capsys)
    assert code != 0 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "--phase" in lines[0] and "Traceback" not in err, err


def test_the_phase_is_in_the_help(capsys):
    for command in ("sweep", "map"):
        code, out, _ = run([command, "--help"], capsys)
        assert code == 0 and "--phase PHI" in out and "radians" in out


def test_a_phase_beyond_2_pi_is_that_phase(capsys):
    """PHI and PHI + 2 pi sample the same section."""
    argv = ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.44", "--num", "1"]
    samples = []
    for phase in (1.0, 1.0 + 2 * math.pi):
        code, out, err = run([*argv, "--phase", repr(phase), *SHORT], capsys)
        assert code == 0, err
        samples.append(np.asarray(json.loads(out)["samples"][0]))
    np.testing.assert_allclose(samples[0], samples[1], atol=1e-9)
