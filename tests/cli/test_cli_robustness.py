"""The command line under bad and edge input: every former traceback is one line, no option is
silently ignored, memory is checked before work, and a property test over random argument lists."""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import grazing
from grazing.cli import main
from grazing.cli.limits import MEMORY_ENV, MemoryLimitError, check_memory, parse_size
from grazing.experiment.synthetic import synthetic_sweep


def _files(root: Path) -> dict[str, bytes | str | None]:
    """Every file's bytes (a symbolic link: where it points) and every folder under ``root``."""

    def content(p: Path) -> bytes | str | None:
        return os.readlink(p) if p.is_symlink() else p.read_bytes() if p.is_file() else None

    return {str(p.relative_to(root)): content(p) for p in root.rglob("*")}


def _big_field_csv(path: Path, in_header: bool = False) -> None:
    huge = "x" * 140_000  # over the csv module's 128 kB field limit
    head = f"time,angle,{huge}" if in_header else "time,angle"
    rows = [f"{k / 10},0.1" + (",1" if in_header else "") for k in range(40)]
    if not in_header:
        rows[3] = f"0.3,{huge}"
    path.write_text("\n".join([head, *rows]) + "\n")


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """Files the commands read: a good recording, a folder of them, files with a huge field."""
    root = tmp_path_factory.mktemp("inputs")
    synthetic_sweep(root / "folder", 40.0, [0.43, 0.446], periods=10, transient=10, sample_rate=100.0)
    shutil.copy(next((root / "folder").glob("*.csv")), root / "rec.csv")
    _big_field_csv(root / "big.csv")
    _big_field_csv(root / "bighead.csv", in_header=True)
    bad = root / "forty"
    shutil.copytree(root / "folder", bad)
    for side in bad.glob("*.json"):
        side.write_text(side.read_text().replace('"theta_hat_deg": 40.0', '"theta_hat_deg": "forty"'))
    # issue 26: files -- a user's files where outputs go
    (root / "notes.csv").write_text("my,notes\n1,2\n")
    (root / "mine.nc").write_bytes(b"my data")
    (root / "mine.png").write_bytes(b"my picture")
    (root / "keep.json").write_text('{"mine": 1}\n')
    (root / "myreport").mkdir()
    (root / "myreport" / "index.html").write_text("<p>my page</p>\n")
    (root / "link.nc").symlink_to("mine.nc")
    _model_files(root)  # issue 26: models
    return root


MODEL_FILE = """
import sympy as sp
import grazing

x, v, t, w, r = sp.symbols("x v t w r")


def model(term=sp.tanh(x) + sp.atan(v) / 10, r_default=0.8):
    params = [grazing.Parameter("w", 1.2, lower=0, lower_open=True),
              grazing.Parameter("r", r_default, lower=0, upper=1)]
    field = [v, -0.1 * v - term + sp.cos(w * t)]
    return grazing.HybridModel("user", [x, v], t, params, vector_field=field, guard=0.5 - x,
                               reset=[x, -r * v], period=2 * sp.pi / w, contact_direction=[0, 1])
"""
"""A model file (issue 26: models): tanh and atan, or any term and default of r."""


def _model_files(root: Path) -> None:
    """Model files: smooth functions, a non-smooth one, a bad default, one that exits, one that prints."""
    (root / "smooth.py").write_text(MODEL_FILE)
    (root / "nonsmooth.py").write_text(MODEL_FILE + "\nabs_model = lambda: model(sp.Abs(x))\n")
    (root / "baddefault.py").write_text(MODEL_FILE + "\nbad = model(r_default=1.5)\n")
    (root / "exits.py").write_text('import sys\nprint("bye")\nsys.exit(0)\n')
    (root / "prints.py").write_text('print("hello from a model file")\n' + MODEL_FILE)


@contextlib.contextmanager
def _workspace(template: Path):
    """A fresh copy of ``template`` as the current folder."""
    old = Path.cwd()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp) / "w"
        shutil.copytree(template, work, symlinks=True)
        os.chdir(work)
        try:
            yield work
        finally:
            os.chdir(old)


def _one_line_error(argv, capsys, template, code_expected=None):
    with _workspace(template) as work:
        before = _files(work)
        code = main(argv)
        out, err = capsys.readouterr()
        assert code != 0 and out == "", (argv, out, err)
        if code_expected is not None:
            assert code == code_expected
        assert err.startswith("grazing: error: ") and err.count("\n") == 1, err
        assert _files(work) == before  # nothing written, nothing changed
    return err.strip()


SWEEP = ["sweep", "--param", "eta", "--start", "0.4", "--stop", "0.41", "--num", "2", "--periods", "3"]
MAP = [
    "map",
    "--param1",
    "eta",
    "--start1",
    "0.4",
    "--stop1",
    "0.41",
    "--num1",
    "2",
    "--param2",
    "theta-hat",
    "--start2",
    "30",
    "--stop2",
    "31",
    "--num2",
    "2",
    "--periods",
    "3",
]

# issue 27: curves
CURVE = "curve --param eta --start 0.446 --stop 0.44 --param2 theta-hat --range 39,41".split()
BASINS = ["basins", "--model", "bouncing-ball", "--x-range", "0,1", "--y-range", "-1,1", "--num", "2,2"]
ATTRACTORS = ["attractors", "--model", "bouncing-ball", "--param", "amplitude", "--start", "0.5", "--stop",
              "0.8", "--num", "2", "--x-range", "0,1", "--y-range", "-1,1", "--num-grid", "2,2"]  # fmt: skip

FORMER_TRACEBACKS = [
    ([*MAP, "--tol", "nan"], "--tol must be in (0, 0.01), got nan"),
    ([*MAP, "--tol", "0"], "--tol must be in (0, 0.01), got 0"),
    ([*MAP, "--tol", "-1"], "--tol must be in (0, 0.01), got -1"),
    ([*MAP, "--tol", "10"], "--tol must be in (0, 0.01), got 10"),
    ([*SWEEP, "--tol", "10"], "--tol must be in (0, 0.01), got 10"),
    (["damping", "--recording", "big.csv"], "big.csv: line 5: not a valid CSV row (field larger than"),
    (["analyze", "big.csv", "--forcing-hz", "0.46"], "big.csv: line 5: not a valid CSV row"),
    (["analyze", "bighead.csv", "--forcing-hz", "0.46"], "bighead.csv: line 1: not a valid CSV row"),
    (
        ["synthesize", "--eta", "0.446", "--sample-rate", "1e9", "--out", "x.csv"],
        "--sample-rate must be in (0, 1e+06] Hz, got 1e+09",
    ),
    (
        ["synthesize", "--eta", "0.446", "--seed", "-1", "--out", "x.csv"],
        "'--seed': -1 is not in the range x>=0",
    ),
    (["analyze", "forty"], 'theta_hat_deg must be a number of degrees in (-180, 180), got "forty"'),
    # issue 26: models
    (
        ["simulate", "--model", "nonsmooth.py:abs_model"],
        "--model: abs_model() in nonsmooth.py failed: Abs is not smooth (Abs(x) in the vector field (v')): "
        "model it as a stop (a guard and a reset), see docs/user-models.md",
    ),
]

ACCEPTED_BUT_WRONG = [
    (["continue", "--param", "r", "--start", "0.5", "--stop", "2"], "r = 2 is outside [0, 1]"),
    (["continue", "--param", "eta", "--start", "0.4", "--stop", "-1"], "eta = -1 is outside"),
    (
        ["continue", "--param", "theta-hat", "--start", "30", "--stop", "190"],
        "--stop for theta-hat must be in (-180, 180) degrees, got 190",
    ),
    (["orbit", "--transient", "0", "--period", "100000"], "'--period': 100000 is not in the range 1<=x<=64"),
    ([*SWEEP, "--which", "second"], "--which is not used without --method map"),
    (["damping", "--recording", "rec.csv", "--r", "0.5"], "--r is not used with --recording"),
    (["report", "--out", ""], "--out must name a file or folder, got an empty string"),
    ([*SWEEP, "--out", ""], "--out must name a file or folder, got an empty string"),
    (["analyze", ""], "FILE.csv|DIR must name a file or folder, got an empty string"),
    # issue 26: files
    (["iso-damping", "--out", "notes.csv"], "notes.csv exists and was not written by grazing"),
    (["simulate", "--trajectory", "notes.csv"], "notes.csv exists and was not written by grazing"),
    (["synthesize", "--eta", "0.446", "--out", "notes.csv"], "notes.csv exists and was not written"),
    (["synthesize", "--eta", "0.446", "--out", "keep.csv"], "keep.json exists and was not written"),
    ([*SWEEP, "--out", "mine.nc"], "mine.nc exists and was not written by grazing"),
    ([*MAP, "--out", "mine.nc"], "mine.nc exists and was not written by grazing"),
    (
        ["continue", "--param", "eta", "--start", "0.446", "--stop", "0.44", "--out", "mine.nc"],
        "mine.nc exists and was not written by grazing",
    ),
    (["graze-curve", "--out", "mine.nc"], "mine.nc exists and was not written by grazing"),
    (["analyze", "rec.csv", "--plot", "mine.png"], "mine.png exists and was not written by grazing"),
    ([*SWEEP, "--out", "link.nc"], "link.nc (a link to "),
    (["report", "--out", "myreport"], "myreport exists and is not a report folder of grazing"),
    (["report", "--out", "a/b/c"], "folder 'a/b' does not exist"),
    (["synthesize", "--eta", "0.446", "--out", "s8.txt"], "'s8.txt' is neither a .csv file nor a folder"),
    (["synthesize", "--eta", "0.446", "--eta", "0.45", "--out", "new/fold"], "folder 'new' does not exist"),
    # issue 26: models
    (
        ["simulate", "--model", "baddefault.py:bad"],
        "--model: baddefault.py failed to load: the default of parameter r is invalid: "
        "r = 1.5 is outside [0, 1]",
    ),
    (
        ["simulate", "--model", "exits.py:model"],
        "--model: exits.py failed to load: it called sys.exit(0) (it printed: bye)",
    ),
    # issue 27: curves
    ([*CURVE, "--kind", "flip"], "Invalid value for '--kind': 'flip' is not one of 'fold', 'period-doubling"),
    ([*CURVE, "--kind", "fold", "--param2", "eta"], "--param2 must differ from --param (both are eta)"),
    (
        [*CURVE, "--kind", "fold", "--range", "41,42"],
        "--range 41,42 excludes the start value of --param2 theta_hat: theta_hat = 40 deg",
    ),
    ([*CURVE, "--kind", "fold", "--range", "41,39"], "--range: LO must be below HI, got 41,39"),
    (
        [*CURVE, "--kind", "fold"],
        "--kind fold: no fold on the period-5 branch from eta = 0.446 to eta = 0.4451212: met "
        "period-doubling at eta = 0.44539259, grazing at eta = 0.44512118 instead; the branch ended at a "
        "grazing",
    ),
    ([*CURVE, "--kind", "fold", "--out", "mine.nc"], "mine.nc exists and was not written by grazing"),
    ([*CURVE, "--kind", "fold", "--out", "c.txt"], "--out must name a .nc file, got 'c.txt'"),
    (
        "curve --model bouncing-ball --kind fold --param r --start 0.5 --stop 2 --param2 amplitude "
        "--range 0,1".split(),
        "r = 2 is outside [0, 1]",
    ),
    (
        "curve --model bouncing-ball --kind fold --param amplitude --start 1.5 --stop 0.5 --param2 rr "
        "--range 0,1".split(),
        "--param2: unknown parameter 'rr' for model 'bouncing-ball' (known: amplitude, omega, gravity, r)",
    ),
    # issue 28: attractors
    ([*BASINS[:-1], "0,5"], "--num must be at least 1 along each state (an empty grid), got '0,5'"),
    ([*BASINS[:-1], "3"], "--num must be N1,N2 (two whole numbers), got '3'"),
    (
        [*BASINS, "--states", "0,5"],
        "--states: state index 5 is out of range: model 'bouncing-ball' has 2 states",
    ),
    ([*BASINS, "--states", "y,w"], "--states: unknown state 'w' for model 'bouncing-ball'"),
    ([*BASINS, "--states", "1,1"], "--states: the two states of the grid must differ"),
    (
        [
            "basins",
            "--model",
            "impact-damper",
            "--x-range",
            "0,1",
            "--y-range",
            "-1,1",
            "--num",
            "2,2",
            "--fixed",
            "w=1",
        ],
        "--fixed: unknown fixed state 'w' for model 'impact-damper'",
    ),
    ([*BASINS, "--fixed", "y=1"], "--fixed: state y is varied by the grid: it cannot be fixed"),
    ([*BASINS, "--fixed", "y"], "--fixed 'y': expected STATE=VALUE (a number)"),
    ([*BASINS[:4], "1,0", *BASINS[5:]], "the range of y must have LO < HI"),
    ([*BASINS[:4], "0,nan", *BASINS[5:]], "--x-range must be finite numbers, got '0,nan'"),
    ([*BASINS, "--out", "mine.nc"], "mine.nc exists and was not written by grazing"),
    ([*BASINS, "--plot", "mine.png"], "mine.png exists and was not written by grazing"),
    ([*BASINS, "--out", "b.txt"], "--out must end in .nc or .zarr, got 'b.txt'"),
    ([*ATTRACTORS, "--out", "b.zarr"], "--out must end in .nc, got 'b.zarr'"),
    ([*ATTRACTORS[:4], "r", *ATTRACTORS[5:8], "2", *ATTRACTORS[9:]], "r = 2 is outside [0, 1]"),
    ([*ATTRACTORS[:-1], "0,2"], "--num-grid must be at least 1 along each state (an empty grid)"),
    # issue 31: explore
    (["explore", "--param", "r", "--range", "0.5,2"], "--range: r = 2 is outside [0, 1]"),
    (
        ["explore", "--model", "impact-oscillator"],
        "explore needs --param NAME --range LO,HI (or --params P1,P2 with a --range for each) for model "
        "impact-oscillator",
    ),
    (["explore", "--range", "0.44,0.49"], "explore needs --param NAME --range LO,HI"),
    (["explore", "--param", "eta", "--range", "0.49,0.44"], "--range: LO must be below HI, got 0.49,0.44"),
    (["explore", "--param", "eta", "--range", "0.44,nan"], "--range must be finite numbers, got '0.44,nan'"),
    (["explore", "--param", "eta"], "give one --range LO,HI for each explored parameter (1), got 0"),
    (["explore", "--params", "eta", "--range", "0.44,0.49"], "--params must be P1,P2 (two parameters)"),
    (["explore", "--params", "eta,eta", "--range", "0.4,0.5", "--range", "0.4,0.5"], "must differ"),
    (["explore", "--param", "omega", "--range", "1,2"], "--param: unknown parameter 'omega'"),
    (
        ["explore", "--param", "eta", "--range", "0.44,0.49", "--component", "x"],
        "--component: model pendulum has no state 'x' (states: theta, dtheta)",
    ),
    (
        ["explore", "--param", "eta", "--range", "0.44,0.49", "--num", "100000"],
        "--num 100000 is more than the page can show: at most 20000 for a diagram",
    ),
    (["explore", "--port", "70000"], "70000 is not in the range 0<=x<=65535"),
    (["explore", "--param", "theta-hat", "--range", "30,200"], "theta_hat = 200 deg is outside"),
]

IGNORED_OPTIONS = [
    (["simulate", "--points-per-period", "10"], "--points-per-period is not used without --trajectory"),
    (
        ["simulate", "--case", "A", "--alpha", "0.2", "--beta", "0.1", "--r", "0.5"],
        "--case is not used when --alpha, --beta and --r are all given",
    ),
    (["orbit", "--initial", "0,0", "--transient", "3"], "--transient is not used with --initial"),
    (["graze", "--eta", "0.4"], "--eta is not used by graze"),
    (["graze-curve", "--theta-hat", "30"], "--theta-hat is not used by graze-curve"),
    (["normal-form", "--eta", "0.4"], "--eta is not used by normal-form"),
    (
        ["continue", "--param", "r", "--r", "0.3", "--start", "0.5", "--stop", "0.6"],
        "--r is not used with --param r",
    ),
    ([*SWEEP, "--eta", "0.3"], "--eta is not used with --param eta"),
    ([*MAP, "--theta-hat", "30"], "--theta-hat is not used with --param1 eta --param2 theta-hat"),
    ([*SWEEP, "--wait"], "--wait is not used without a Zarr store"),
    ([*SWEEP, "--wait", "--out", "s.nc"], "--wait is not used without a Zarr store"),
    ([*SWEEP, "--timeout", "3"], "--timeout is not used without --scheduler"),
    (
        [*SWEEP, "--workers", "2", "--scheduler", "tcp://127.0.0.1:1"],
        "--workers is not used with --scheduler",
    ),
    (["damping", "--degrees"], "--degrees is not used without --recording"),
    (["damping", "--recording", "rec.csv", "--peaks", "3"], "--peaks is not used with --recording"),
    (
        ["iso-damping", "--relation", "paper", "--normalisation", "eq1"],
        "--normalisation is not used with --relation paper",
    ),
    (["analyze", "rec.csv", "--theta-hat", "40"], "--theta-hat is not used for a single recording"),
    (["analyze", "folder", "--model-points", "5"], "--model-points is not used without --with-model"),
    (
        ["analyze", "rec.csv", "--cutoff-hz", "5", "--cutoff-multiple", "10"],
        "--cutoff-multiple is not used with --cutoff-hz",
    ),
    # issue 26: messages (a free decay has fewer peaks than asked: it was silently shortened)
    (["damping", "--peaks", "1000000"], "--peaks 1000000: the free decay at r = 0.7675, beta = 0.048"),
    (["iso-damping", "--peaks", "30"], "falls below 1e-10 rad after"),
    # issue 26: failed points
    ([*SWEEP[:8], "1"], "--stop is not used with --num 1 (its one value is --start"),
    ([*MAP[:8], "1", *MAP[9:]], "--stop1 is not used with --num1 1 (its one value is --start1"),
    ([*MAP[:16], "1", *MAP[17:]], "--stop2 is not used with --num2 1 (its one value is --start2"),
    # issue 26: orbits
    (
        "continue --param eta --start 0.4 --stop 0.5 --switch --virtual".split(),
        "--switch is not used with --virtual: a virtual branch ignores the stops",
    ),
    (
        "continue --model impact-oscillator --param omega --start 3 --stop 4 --virtual --switch".split(),
        "--switch is not used with --virtual",
    ),
    (
        "continue --param eta --start 0.4 --stop 0.5 --set eta=0.3".split(),
        "--set eta=0.3 is not used with --param eta: the branch starts at --start",
    ),
    (
        "continue --model two-sided-oscillator --param omega --start 0.5 --stop 0.9 --set omega=0.7".split(),
        "--set omega=0.7 is not used with --param omega",
    ),
    (["graze", "--set", "eta=0.4"], "--set eta=0.4 is not used by graze: it searches eta in"),
    (
        "graze --model impact-oscillator --param omega --range 2.5,4 --set omega=3".split(),
        "--set omega=3 is not used by graze: it searches --param over --range",
    ),
    (["normal-form", "--set", "eta=0.4"], "--set eta=0.4 is not used by normal-form"),
    (["graze-curve", "--set", "theta_hat=30"], "--set theta_hat=30 is not used by graze-curve"),
    (
        "graze-curve --model two-sided-oscillator --params omega,gap_right --range 0.5,0.75 --start-value 1 "
        "--set gap_right=2".split(),
        "--set gap_right=2 is not used by graze-curve: it moves both --params",
    ),
    # issue 26: files
    (["simulate", "--overwrite"], "--overwrite is not used without --trajectory"),
    (["iso-damping", "--overwrite"], "--overwrite is not used without --out"),
    (["analyze", "rec.csv", "--overwrite"], "--overwrite is not used without --plot"),
    (["graze-curve", "--overwrite"], "--overwrite is not used without --out"),
    (
        ["continue", "--param", "eta", "--start", "0.446", "--stop", "0.44", "--overwrite"],
        "--overwrite is not used without --out",
    ),
    ([*SWEEP, "--overwrite"], "--overwrite is not used without --out"),
    ([*MAP, "--overwrite", "--out", "m.zarr"], "--overwrite is not used with a Zarr store"),
    # issue 26: models
    (
        ["simulate", "--theta-hat", "30", "--set", "theta_hat=40"],
        "--theta-hat is not used with --set theta_hat=40 (give one of them)",
    ),
    (["orbit", "--set", "r=0.5", "--r", "0.6"], "--r is not used with --set r=0.5 (give one of them)"),
    (
        ["simulate", "--case", "A", "--alpha", "0.2", "--set", "beta=0.1", "--set", "r=0.5"],
        "--case is not used when alpha, beta and r are all given (by --alpha, --beta, --r or --set)",
    ),
    (
        [*SWEEP, "--set", "eta=0.45"],
        "--set eta=0.45 is not used with --param eta: the swept values replace it",
    ),
    (
        [
            "sweep",
            "--model",
            "impact-oscillator",
            "--param",
            "omega",
            "--start",
            "2",
            "--stop",
            "3",
            "--num",
            "2",
            "--set",
            "omega=2.5",
        ],
        "--set omega=2.5 is not used with --param omega: the swept values replace it",
    ),
    # issue 27: branch switching (at period-doublings and branch points too: still a physical branch's)
    (
        [
            "continue",
            "--model",
            f"{Path(__file__).resolve().parents[1] / 'orbits' / 'symmetric_models.py'}:walled_pendulum",
            *"--set A=0.3 --param Om --start 1.2 --stop 0.6 --virtual --switch".split(),
        ],
        "--switch is not used with --virtual: a virtual branch ignores the stops",
    ),
    (
        [
            "continue",
            "--model",
            "bouncing-ball",
            *"--param amplitude --start 1.3 --stop 1.6".split(),
            "--switch",
            "--period",
            "65",
        ],
        "'--period': 65 is not in the range 1<=x<=64",
    ),
    # issue 27: curves
    ([*CURVE, "--kind", "fold", "--eta", "0.45"], "--eta is not used with --param eta: the branch starts at"),
    ([*CURVE, "--kind", "fold", "--set", "eta=0.45"], "--set eta=0.45 is not used with --param eta"),
    ([*CURVE, "--kind", "fold", "--overwrite"], "--overwrite is not used without --out"),
    # issue 28: attractors
    ([*SWEEP, "--direction", "both", "--fresh"], "--fresh is not used with --direction both"),
    ([*BASINS, "--overwrite"], "--overwrite is not used without --out or --plot"),
    ([*BASINS, "--wait"], "--wait is not used without a Zarr store"),
    ([*BASINS, "--wait", "--out", "b.nc"], "--wait is not used without a Zarr store"),
    ([*ATTRACTORS, "--overwrite"], "--overwrite is not used without --out or --plot"),
    ([*ATTRACTORS, "--set", "amplitude=0.6"], "--set amplitude=0.6 is not used with --param amplitude"),
    (
        [
            "attractors",
            "--param",
            "eta",
            "--start",
            "0.44",
            "--stop",
            "0.45",
            "--num",
            "2",
            "--eta",
            "0.4",
            "--x-range",
            "0,0.5",
            "--y-range",
            "-1,1",
            "--num-grid",
            "2,2",
        ],
        "--eta is not used with --param eta",
    ),
    ([*ATTRACTORS[:10], "1", *ATTRACTORS[11:]], "--stop is not used with --num 1 (its one value is --start"),
    # issue 31: explore
    (["explore", "--eta", "0.45"], "--eta is not used by explore: it shows eta in [0.44, 0.49]"),
    (["explore", "--set", "eta=0.45"], "--set eta=0.45 is not used by explore: it shows eta in [0.44, 0.49]"),
    (
        ["explore", "--param", "eta", "--range", "0.44,0.49", "--set", "eta=0.45"],
        "--set eta=0.45 is not used with --param/--params: the explored values replace it",
    ),
    (
        ["explore", "--param", "theta-hat", "--range", "30,40", "--theta-hat", "35"],
        "--theta-hat is not used with --param/--params",
    ),
    (
        ["explore", "--param", "eta", "--params", "eta,r", "--range", "0.44,0.49"],
        "--params is not used with --param (give one of them)",
    ),
    (
        "explore --params eta,theta-hat --range 0.44,0.49 --range 30,40 --component theta".split(),
        "--component is not used with a period map (--params)",
    ),
]

MEMORY = [
    (
        ["simulate", "--periods", "1000000", "--trajectory", "t.csv", "--points-per-period", "100000"],
        "with a trajectory of 1e+11 points needs about",
    ),
    (["simulate", "--periods", "1000000000000"], "simulating 1e+12 sampled periods needs about"),
    (
        ["sweep", "--param", "eta", "--start", "0.4", "--stop", "0.5", "--num", "1000000000"],
        "a sweep of 1e+09 points x 100 periods needs about",
    ),
    (
        [
            "sweep",
            "--param",
            "eta",
            "--start",
            "0.4",
            "--stop",
            "0.5",
            "--num",
            "1000000000",
            "--out",
            "h.zarr",
        ],
        "split it into several runs over parts of the range",
    ),
    ([*MAP[:-2], "--num1", "100000", "--num2", "100000"], "a map of 1e+10 points"),
    (["iso-damping", "--num", "100000000"], "a curve of 1e+08 points needs about"),
    (["synthesize", "--eta", "0.446", "--periods", "10000000", "--out", "x.csv"], "a recording of"),
    (["damping", "--r", "1", "--beta", "0", "--peaks", "1000000000000"], "a free decay of 1e+12 peaks"),
    # issue 28: attractors
    ([*BASINS[:-1], "100000,100000"], "a basin of 1e+10 initial states needs about"),
    ([*BASINS[:-1], "100000,100000", "--out", "b.zarr"], "use a coarser grid (--num)"),
    ([*ATTRACTORS[:10], "1000", *ATTRACTORS[11:-1], "30000,30000"], "1000 basins of 9e+08 initial states"),
]


@pytest.mark.parametrize(("argv", "message"), FORMER_TRACEBACKS + ACCEPTED_BUT_WRONG + IGNORED_OPTIONS)
def test_one_line_and_nothing_written(argv, message, capsys, inputs):
    assert message in _one_line_error(argv, capsys, inputs)


# issue 26: orbits.  Where the default guess (a simulation from rest) cannot start Newton's method,
# the error says what happened and to give --initial; parameters are in their display unit.
NEG = f"{Path(__file__).resolve().parents[1] / 'orbits' / 'negative_damping.py'}:negative_damping"
DIVERGED = (
    r"cannot guess the orbit by simulating from rest with the stops ignored: the state became non-finite"
)
GUESS = r"give an initial guess \(--initial\) near the orbit, from which Newton's method finds it"
STICKS = r"the default initial guess sticks: simulated from rest for 500 forcing periods, the motion "
NOT_STICKING = r"give an initial guess \(--initial\) near an orbit that does not stick"
ORBIT_MESSAGES = [
    (["orbit", "--model", "bouncing-ball"], f"{STICKS}ends riding on the stop, .*{NOT_STICKING}"),
    (
        ["orbit", "--r", "0", "--theta-hat", "10"],
        f"{STICKS}sticks to the stop 128 times in 128 .*{NOT_STICKING}",
    ),
    (
        ["orbit", "--model", "two-sided-oscillator", "--set", "r=0", "--set", "amp=3"],
        f"{STICKS}sticks to stop '(right|left)' 12. times and to stop '(left|right)' 12. times .*"
        f"{NOT_STICKING}",
    ),
    (["graze", "--model", NEG, "--param", "w", "--range", "0.5,1.5"], f"{DIVERGED}.*{GUESS}"),
    (["normal-form", "--model", NEG, "--param", "w", "--range", "0.5,1.5"], f"{DIVERGED}.*{GUESS}"),
    (
        ["graze-curve", "--model", NEG, "--params", "w,upper", "--range", "0.5,1.5", "--start-value", "2"],
        f"{DIVERGED}.*{GUESS}",
    ),
    (
        ["continue", "--model", NEG, "--param", "w", "--start", "0.5", "--stop", "1.5", "--virtual"],
        f"{DIVERGED}.*{GUESS}",
    ),
    (
        ["orbit", "--theta-hat", "-10"],
        rf"simulating from rest: initial state \[0.0, 0.0\] is beyond the stop .*{GUESS}",
    ),
    (
        ["orbit", "--model", "impact-oscillator", "--set", "sigma=-0.1"],
        rf"simulating from rest: initial state \[0.0, 0.0\] is beyond the stop .*{GUESS}",
    ),
    (
        ["normal-form", "--param", "theta_hat", "--range", "30,50", "--eta", "0.44", "--which", "second"],
        r"no second grazing of the period-1 orbit for theta_hat in \[30, 50\] deg \(found 1\)",
    ),
    (
        [
            "normal-form",
            "--model",
            NEG,
            *"--param upper --range 1,3 --set w=0.7 --initial 0,0 --which second".split(),
        ],
        r"no second grazing of the period-1 orbit for upper in \[1, 3\] m \(found 1\)",
    ),
    (
        ["graze-curve", "--params", "theta_hat,eta", "--range", "10,50", "--start-value", "0.3"],
        r"no grazing of the period-1 orbit for theta_hat in \[10, 50\] deg at eta = 0.3$",
    ),
]


@pytest.mark.parametrize(("argv", "pattern"), ORBIT_MESSAGES)
def test_orbit_messages_say_what_happened_and_what_to_do(argv, pattern, capsys, inputs):
    err = _one_line_error(argv, capsys, inputs, code_expected=1)
    assert re.search(pattern, err.removeprefix("grazing: error: ")), err


@pytest.mark.parametrize(("argv", "message"), MEMORY)
def test_memory_is_checked_before_any_work(argv, message, capsys, inputs, monkeypatch):
    monkeypatch.delenv(MEMORY_ENV, raising=False)
    for name in ("simulate",):  # nothing may start: the estimate comes first
        monkeypatch.setattr(grazing, name, lambda *a, **k: pytest.fail("work started"))
    monkeypatch.setattr(grazing.cli.limits, "physical_memory", lambda: 16 * 10**9)  # a stated, fixed bound
    err = _one_line_error(argv, capsys, inputs, code_expected=1)
    assert message in err
    assert "more than the limit of 8 GB (half of this machine's memory; set GRAZING_MAX_MEMORY" in err


def test_the_bound_can_be_set_and_is_applied_exactly(monkeypatch, capsys, inputs):
    monkeypatch.setenv(MEMORY_ENV, "1M")
    err = _one_line_error(["simulate", "--periods", "100000", "--transient", "0"], capsys, inputs)
    assert "more than the limit of 1 MB (set by GRAZING_MAX_MEMORY)" in err
    with _workspace(inputs):
        assert main(["simulate", "--periods", "10", "--transient", "0", "--json"]) == 0
    capsys.readouterr()
    monkeypatch.setenv(MEMORY_ENV, "lots")
    err = _one_line_error(["simulate", "--periods", "10"], capsys, inputs)
    assert err == "grazing: error: GRAZING_MAX_MEMORY='lots' is not a size such as 8G or 512M"


def test_check_memory_bound(monkeypatch):
    assert parse_size("2.5G") == 2_500_000_000
    monkeypatch.setenv(MEMORY_ENV, "1000")
    check_memory(1000, "x", "y")  # at the bound: accepted
    with pytest.raises(MemoryLimitError, match="x needs about 1 kB of memory, more than the limit of 1 kB"):
        check_memory(1001, "x", "y")
    with pytest.raises(MemoryLimitError):
        check_memory(float("nan"), "x", "y")


def test_click_messages_are_one_line(capsys, inputs):
    err = _one_line_error(["sweep", "--start", "0.4"], capsys, inputs)
    assert "Missing option '--param'" in err


# --------------------------------------------------------------------------
# issue 26: failed points are counted with their reasons, and --json is strict JSON

CLOCK_MODEL = """
import sympy as sp
from grazing import HybridModel, Parameter

q, p, t, w, c = sp.symbols("q p t w c")
model = HybridModel(
    "clock-stop", states=[q, p], time=t,
    parameters=[Parameter("w", 1.0, lower=0, lower_open=True), Parameter("c", 1.5)],
    vector_field=[p, -q], guard=c + sp.cos(w * t), reset=[q, -p], period=2 * sp.pi / w,
)
"""
"""A stop whose guard depends on time only: for |c| < 1 it is reached and the reset does not move it."""

QUICK = ["--transient", "3", "--periods", "3", "--workers", "1"]
FAILED_POINTS = [
    # issue 26: failed points (the commands of the issue; each point's reason follows from its values)
    (
        ["sweep", "--param", "alpha", "--start", "0", "--stop", "1e300", "--num", "5", *QUICK],
        {"ok": 1, "non-finite state": 4},
    ),
    (
        ["sweep", "--param", "eta", "--start", "1e-300", "--stop", "0.5", "--num", "3", *QUICK],
        {"non-finite state": 1, "ok": 2},
    ),
    (
        ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.44", "--num", "1", "--tol", "1e-300",
         "--transient", "0", "--periods", "1"],
        {"step limit": 1},
    ),
    (
        ["sweep", "--model", "clock.py:model", "--param", "c", "--start", "-0.5", "--stop", "2", "--num", "6",
         *QUICK],
        {"accumulating impacts": 4, "ok": 2},
    ),
    (
        ["map", "--param1", "eta", "--start1", "0.4", "--stop1", "0.41", "--num1", "2", "--param2", "alpha",
         "--start2", "0.2254", "--stop2", "1e300", "--num2", "2", *QUICK],
        {"ok": 2, "non-finite state": 2},
    ),
]  # fmt: skip


def _strict_json(text: str) -> dict:
    def refuse(constant: str) -> None:
        raise ValueError(f"not strict JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


@pytest.mark.parametrize(("argv", "outcomes"), FAILED_POINTS)
def test_failed_points_are_counted_and_the_json_is_strict(argv, outcomes, capsys, inputs):
    with _workspace(inputs) as work:
        (work / "clock.py").write_text(CLOCK_MODEL)
        assert main([*argv, "--json"]) == 0
        res = _strict_json(capsys.readouterr().out)
        status = np.ravel(res["status"])
        assert {why: int((status == why).sum()) for why in set(status)} == outcomes
        assert all((per == -1) == (why != "ok") for per, why in zip(np.ravel(res["period"]), status))
        assert main(argv) == 0
        out = capsys.readouterr().out
    failed = {why: n for why, n in outcomes.items() if why != "ok"}
    detail = ", ".join(f"{why}: {n}" for why, n in sorted(failed.items(), key=lambda item: -item[1]))
    assert f"failed: {sum(failed.values())} ({detail})" in out


# --------------------------------------------------------------------------
# The property: random argument lists per command


class ReachedError(Exception):
    """The command passed every check and started its work (the work itself is stubbed)."""


WORK = [
    (grazing, "simulate"),
    ("grazing.orbits", "find_orbit"),
    ("grazing.orbits", "find_grazings"),
    ("grazing.orbits", "grazing_curve"),
    ("grazing.orbits", "continue_orbit"),
    ("grazing.normalform", "find_grazing_point"),
    ("grazing.sweeps.api", "run_sweep"),
    ("distributed", "Client"),
    ("grazing.experiment.damping", "free_decay"),
    ("grazing.experiment.damping", "recorded_damping"),
    ("grazing.experiment.damping", "iso_damping"),
    ("grazing.experiment.fit", "fit_parameters"),
    ("grazing.experiment.signal", "analyze_recording"),
    ("grazing.experiment.diagram", "load_diagram"),
    ("grazing.experiment.synthetic", "synthetic_recording"),
    ("grazing.experiment.synthetic", "synthetic_sweep"),
    ("grazing.report", "build_report"),
    ("grazing.orbits", "follow_curve"),  # issue 27: curves
    ("grazing.attractors.basins", "find_attractors"),  # issue 28: attractors
    ("grazing.attractors.continuation", "continue_attractors"),
    ("grazing.explore.server", "serve"),  # issue 31: explore
]


def _stub(*args, **kwargs):
    raise ReachedError


BAD = ["nan", "inf", "-inf", "0", "-0", "-1", "1e300", "-1e300", "1e-300", "99999999999999999999", "abc", "",
       "1,2", "-", "--json"]  # fmt: skip
NUMBER = st.one_of(
    st.sampled_from(BAD),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**20), 10**20).map(str),
)

MODEL = {
    "--case": ["A", "B", "C", "D", "A-reduced"],
    "--alpha": ["0.2254", "0.1"],
    "--beta": ["0.048"],
    "--r": ["0.7675", "1", "0"],
    "--eta": ["0.446", "0.5"],
    "--theta-hat": ["40", "-10"],
    "--set": ["theta_hat=35", "eta=0.45", "r=0.5", "alpha=0.2", "beta=0.05"],  # issue 26: models
}
RUN = {"--transient": ["0", "3"], "--periods": ["1", "3"], "--initial": ["0,0", "-0.5,0.1", "0;0"]}
SWEEPS = {
    **RUN,
    "--fresh": None,
    "--chunk-size": ["0", "1"],
    "--workers": ["1", "2"],
    "--scheduler": ["tcp://127.0.0.1:1"],
    "--timeout": ["1"],
    "--no-lyapunov": None,
    "--no-adaptive": None,
    "--tol": ["1e-10", "1e-8"],
    "--out": ["s.zarr", "s.nc", "s.txt", "nodir/s.zarr"],
    "--wait": None,
    "--json": None,
}
PARAMS = ["eta", "theta-hat", "alpha", "beta", "r", "gamma"]
COMMANDS: dict[str, dict[str, list[str] | None]] = {
    "simulate": {
        **MODEL,
        **RUN,
        "--phase": ["0", "1.5"],
        "--trajectory": ["t.csv", "t.txt", "nodir/t.csv"],
        "--points-per-period": ["4", "20"],
        "--json": None,
    },
    "orbit": {
        **MODEL,
        "--period": ["1", "5", "64"],
        "--initial": ["0,0"],
        "--transient": ["0", "3"],
        "--json": None,
    },
    "graze": {**MODEL, "--eta-min": ["0.3", "0.44"], "--eta-max": ["0.5", "0.46"], "--json": None},
    "graze-curve": {
        **MODEL,
        "--start-deg": ["5", "30"],
        "--eta-min": ["0.3"],
        "--eta-max": ["0.5"],
        "--max-step": ["0.05"],
        "--out": ["c.nc", "c.txt"],
        "--json": None,
    },
    "continue": {
        **MODEL,
        "--param": PARAMS,
        "--start": ["0.4", "30", "0.5"],
        "--stop": ["0.5", "35", "0.9"],
        "--period": ["1", "2"],
        "--initial": ["0,0"],
        "--virtual": None,
        "--physical": None,
        "--max-step": ["0.04"],
        "--out": ["b.nc"],
        "--json": None,
    },
    "sweep": {
        **MODEL,
        "--param": PARAMS,
        "--start": ["0.4", "30"],
        "--stop": ["0.41", "31"],
        "--num": ["1", "2"],
        "--direction": ["up", "down"],
        "--method": ["flow", "map"],
        "--which": ["first", "second"],
        **SWEEPS,
    },
    "map": {
        **MODEL,
        "--param1": PARAMS,
        "--start1": ["0.4"],
        "--stop1": ["0.41"],
        "--num1": ["1", "2"],
        "--param2": PARAMS,
        "--start2": ["30"],
        "--stop2": ["31"],
        "--num2": ["1", "2"],
        **SWEEPS,
    },
    "normal-form": {
        **MODEL,
        "--which": ["first", "second"],
        "--eta-min": ["0.3"],
        "--eta-max": ["0.5"],
        "--check": None,
        "--json": None,
    },
    "damping": {
        "--case": MODEL["--case"],
        "--r": ["0.5", "1"],
        "--beta": ["0.05"],
        "--amplitude": ["28", "10"],
        "--peaks": ["3", "10"],
        "--k-hat": ["1", "2"],
        "--normalisation": ["eq6", "eq1"],
        "--recording": ["rec.csv", "missing.csv", "big.csv"],
        "--degrees": None,
        "--json": None,
    },
    "iso-damping": {
        "--damping": ["0.07"],
        "--num": ["2", "5"],
        "--relation": ["model", "paper", "protocol"],
        "--amplitude": ["28"],
        "--peaks": ["3"],
        "--normalisation": ["eq6", "eq1"],
        "--out": ["c.csv", "c.txt"],
        "--json": None,
    },
    "fit": {
        "--theta-hat": ["40"],
        "--eta-graze": ["0.445"],
        "--damping": ["0.07"],
        "--alpha": ["0.2254"],
        "--relation": ["model", "paper"],
        "--json": None,
    },
    "analyze": {
        "PATH": ["rec.csv", "folder", "missing.csv", "big.csv", "forty"],
        "--forcing-hz": ["0.46"],
        "--phase": ["0"],
        "--degrees": None,
        "--cutoff-hz": ["5"],
        "--cutoff-multiple": ["20"],
        "--max-period": ["32"],
        "--noise": ["0.001"],
        "--theta-hat": ["40"],
        "--with-model": None,
        "--case": ["B"],
        "--model-points": ["3"],
        "--plot": ["p.png", "p.txt"],
        "--json": None,
    },
    "synthesize": {
        "--eta": ["0.43", "0.446"],
        "--theta-hat": ["40"],
        "--case": ["B"],
        "--periods": ["8", "10"],
        "--transient": ["0", "5"],
        "--sample-rate": ["100", "1000"],
        "--noise": ["0.001", "0"],
        "--seed": ["0", "3"],
        "--out": ["one.csv", "fold"],
        "--json": None,
    },
    "report": {"--out": ["rep", ""]},
}
# issue 28: attractors
GRID = {
    "--x-range": ["0,1", "-1,1", "1,0", "0,nan"],
    "--y-range": ["-1,1", "0,0"],
    "--states": ["0,1", "y,v", "0,2", "1,1"],
    "--fixed": ["y=1", "v=0", "w=1", "v"],
    "--phase": ["0", "1.5"],
    "--transient": ["0", "3"],
    "--periods": ["1", "2", "3"],
    "--refine": ["0", "1"],
    "--cell": ["0", "0.05", "1", "-1", "2"],
    "--no-lyapunov": None,
    "--tol": ["1e-10"],
    "--workers": ["1", "2"],
    "--plot": ["b.png", "b.txt", "mine.png"],
    "--overwrite": None,
    "--json": None,
}
COMMANDS["basins"] = {
    "--model": ["bouncing-ball", "pendulum"],
    **GRID,
    "--num": ["2,2", "1,3", "0,2", "3"],
    "--chunk-size": ["1", "100"],
    "--out": ["b.nc", "b.zarr", "b.txt", "mine.nc", "nodir/b.nc"],
    "--wait": None,
}
COMMANDS["attractors"] = {
    "--model": ["bouncing-ball"],
    "--param": ["amplitude", "r", "gamma"],
    "--start": ["0.5"],
    "--stop": ["0.8", "0.5"],
    "--num": ["1", "2"],
    **GRID,
    "--num-grid": ["2,2", "0,1"],
    "--seeds": ["0", "3"],
    "--out": ["a.nc", "a.zarr", "mine.nc"],
}
COMMANDS["sweep"]["--direction"] = [*COMMANDS["sweep"]["--direction"], "both"]
# issue 26: orbits
for _cmd in ("graze", "normal-form", "graze-curve"):
    COMMANDS[_cmd]["--initial"] = ["0,0", "-0.5,0.1", "0;0"]
COMMANDS["continue"]["--switch"] = None

# issue 26: files -- --overwrite wherever a command writes a file, and the user's files of `inputs` as outputs
OUTPUT_OPTION = {"simulate": "--trajectory", "analyze": "--plot"}
"""The option naming the file a command writes (``--out`` unless listed)."""
FOREIGN = {".nc": ["mine.nc", "link.nc"], ".csv": ["notes.csv", "keep.csv"], ".png": ["mine.png"]}
for _cmd, _suffix in (("simulate", ".csv"), ("graze-curve", ".nc"), ("continue", ".nc"), ("sweep", ".nc"),
                      ("map", ".nc"), ("iso-damping", ".csv"), ("analyze", ".png"), ("synthesize", ".csv"),
                      ("report", "")):  # fmt: skip
    _option = OUTPUT_OPTION.get(_cmd, "--out")
    COMMANDS[_cmd] = {**COMMANDS[_cmd], "--overwrite": None}
    COMMANDS[_cmd][_option] = [*COMMANDS[_cmd][_option], *FOREIGN.get(_suffix, ["myreport", "a/b/c"])]
REQUIRED = ["--param", "--start", "--stop", "--num", "--param1", "--start1", "--stop1", "--num1", "--param2",
            "--start2", "--stop2", "--num2", "PATH"]  # fmt: skip
# issue 27: curves
COMMANDS["curve"] = {
    **MODEL,
    "--kind": ["fold", "period-doubling", "neimark-sacker", "branch-point", "grazing", "flip"],
    "--param": PARAMS,
    "--start": ["0.4", "30", "0.5"],
    "--stop": ["0.5", "35", "0.9"],
    "--param2": PARAMS,
    "--range": ["30,50", "0.3,0.5", "0.1,0.9", "50,30", "1"],
    "--period": ["1", "5"],
    "--initial": ["0,0", "0;0"],
    "--stop-name": ["stop", "back", "front"],
    "--max-step": ["0.04"],
    "--out": ["c.nc", "c.txt", "nodir/c.nc", *FOREIGN[".nc"]],
    "--overwrite": None,
    "--json": None,
}
REQUIRED += ["--kind", "--range"]
REQUIRED += ["--x-range", "--y-range", "--num-grid"]  # issue 28: attractors
# issue 31: explore
COMMANDS["explore"] = {
    **MODEL,
    "--param": PARAMS,
    "--params": ["eta,theta-hat", "eta", "eta,eta", "r,alpha", "theta-hat,gamma"],
    "--range": ["0.44,0.49", "30,50", "0.49,0.44", "0.1,0.9", "1", "0,nan"],
    "--num": ["2", "3", "100000"],
    "--component": ["theta", "dtheta", "x"],
    "--port": ["0", "5006", "70000"],
    "--no-browser": None,
}
REAL_WORK = ("simulate", "sweep", "map", "damping", "synthesize", "analyze")


@st.composite
def argument_lists(draw, cmd: str, numbers=NUMBER):
    """``[cmd, options...]``: options of ``cmd`` drawn (some repeated, some missing), values
    mostly sensible, sometimes drawn from ``numbers`` (nan, inf, 0, negatives, huge, strings)."""
    table = COMMANDS[cmd]
    names = draw(st.lists(st.sampled_from(sorted(table)), max_size=6))
    if draw(st.integers(0, 3)):  # usually the required options too (otherwise "Missing option")
        names += [n for n in REQUIRED if n in table]
        names += ["--eta", "--out"] if cmd == "synthesize" else []
    argv = [cmd]
    for name in draw(st.permutations(names)):
        good = table[name]
        if good is None:
            argv.append(name)
            continue
        value = draw(st.sampled_from(good) if draw(st.integers(0, 5)) else numbers)
        argv += [value] if name == "PATH" else [name, value]
    return argv


def _given(argv: list[str]) -> dict[str, str | None]:
    """Options given (the last value of each), and the positional path."""
    out: dict[str, str | None] = {}
    i = 1
    flags = {n for t in COMMANDS.values() for n, v in t.items() if v is None}
    while i < len(argv):
        a = argv[i]
        if a in flags:
            out[a] = None
            i += 1
        elif a.startswith("--") and i + 1 < len(argv):
            out[a] = argv[i + 1]
            i += 2
        else:
            out["PATH"] = a
            i += 1
    return out


def _number(text: str | None) -> float | None:
    try:
        return float(text) if text is not None else None
    except ValueError:
        return None


def _sets(argv: list[str]) -> set[str]:
    """The parameters given by ``--set NAME=VALUE`` (every occurrence), as their options (``--theta-hat``)."""
    values = [argv[i + 1] for i in range(1, len(argv) - 1) if argv[i] == "--set"]
    return {"--" + v.partition("=")[0].strip().replace("_", "-") for v in values if "=" in v}


def ignored(argv: list[str]) -> list[str]:
    """The options that the rest of ``argv`` makes meaningless (what must be refused)."""
    cmd, g = argv[0], _given(argv)
    bad = []
    sets = _sets(argv)  # issue 26: models (a parameter given by --set counts as its option)
    if cmd in ("simulate", "orbit", "graze", "graze-curve", "continue", "sweep", "map", "normal-form",
               "curve", "explore"):  # fmt: skip
        if all(o in g or o in sets for o in ("--alpha", "--beta", "--r")) and "--case" in g:
            bad.append("--case")
        bad += [o for o in sets if o in g]  # the option and --set of one parameter
        g = {**{o: "" for o in sets}, **g}  # from here --set NAME counts as the option --NAME
    if cmd == "simulate" and "--points-per-period" in g and "--trajectory" not in g:
        bad.append("--points-per-period")
    if cmd == "orbit" and "--initial" in g and "--transient" in g:
        bad.append("--transient")
    if cmd in ("graze", "normal-form", "graze-curve") and "--eta" in g:
        bad.append("--eta")
    if cmd == "graze-curve" and "--theta-hat" in g:
        bad.append("--theta-hat")
    if cmd in ("continue", "sweep", "curve"):
        bad += [f"--{g['--param']}"] if f"--{g.get('--param')}" in g else []
    if cmd == "map":
        bad += [f"--{g[p]}" for p in ("--param1", "--param2") if f"--{g.get(p)}" in g]
    if cmd in ("sweep", "map"):
        if cmd == "sweep" and "--which" in g and g.get("--method") != "map":
            bad.append("--which")
        if "--wait" in g and not str(g.get("--out", "")).endswith(".zarr"):
            bad.append("--wait")
        if "--timeout" in g and "--scheduler" not in g:
            bad.append("--timeout")
        if "--workers" in g and "--scheduler" in g:
            bad.append("--workers")
        # issue 26: failed points (with one value, the last must equal the first)
        for num, start, stop in (("--num", "--start", "--stop"), ("--num1", "--start1", "--stop1"),
                                 ("--num2", "--start2", "--stop2")):  # fmt: skip
            if g.get(num) == "1" and stop in g and _number(g.get(stop)) != _number(g.get(start)):
                bad.append(stop)
    if cmd == "damping":
        model_only = ["--case", "--r", "--beta", "--amplitude", "--peaks"]
        bad += [o for o in model_only if o in g] if "--recording" in g else []
        bad += ["--degrees"] if "--degrees" in g and "--recording" not in g else []
    if cmd == "iso-damping" and "--normalisation" in g and g.get("--relation", "model") != "model":
        bad.append("--normalisation")
    if cmd == "analyze":
        bad += [o for o in ("--case", "--model-points") if o in g and "--with-model" not in g]
        bad += ["--cutoff-multiple"] if "--cutoff-multiple" in g and "--cutoff-hz" in g else []
        folder = g.get("PATH") in ("folder", "forty")
        bad += [o for o in ("--forcing-hz", "--cutoff-hz", "--noise") if folder and o in g]
        bad += [o for o in ("--theta-hat", "--with-model") if not folder and o in g]
    # issue 26: orbits
    if cmd == "continue" and "--switch" in g and _last_flag(argv, ("--virtual", "--physical")) == "--virtual":
        bad.append("--switch")
    # issue 26: files
    if "--overwrite" in g and cmd != "report" and OUTPUT_OPTION.get(cmd, "--out") not in g:
        bad.append("--overwrite")
    if cmd in ("sweep", "map") and "--overwrite" in g and str(g.get("--out", "")).endswith(".zarr"):
        bad.append("--overwrite")
    # issue 28: attractors
    if cmd == "sweep" and "--fresh" in g and g.get("--direction") == "both":
        bad.append("--fresh")
    if cmd in ("basins", "attractors"):
        bad = [b for b in bad if b != "--overwrite"]
        if "--overwrite" in g and "--out" not in g and "--plot" not in g:
            bad.append("--overwrite")
        if "--wait" in g and not str(g.get("--out", "")).endswith(".zarr"):
            bad.append("--wait")
    if cmd == "attractors":
        bad += [f"--{g['--param']}"] if f"--{g.get('--param')}" in g else []
        if g.get("--num") == "1" and "--stop" in g and _number(g.get("--stop")) != _number(g.get("--start")):
            bad.append("--stop")
    # issue 31: explore
    if cmd == "explore":
        if "--param" in g:
            bad += ["--params"] if "--params" in g else []
            explored = [str(g["--param"])]
        else:
            explored = str(g.get("--params", "eta")).split(",")  # (without either: the pendulum's eta)
        bad += [f"--{p}" for p in explored if f"--{p}" in g]
        if "--component" in g and "--params" in g and "--param" not in g:
            bad.append("--component")
    return bad


def _last_flag(argv: list[str], flags: tuple[str, ...]) -> str | None:
    """The last of ``flags`` in ``argv`` (a flag pair such as --virtual/--physical: the last one wins)."""
    return next((a for a in reversed(argv) if a in flags), None)


def _check_run(argv: list[str], capsys, template: Path) -> None:
    with _workspace(template) as work:
        before = _files(work)
        try:
            code = main(argv)
        except ReachedError:
            code = None
        out, err = capsys.readouterr()
        if code == 0 or code is None:  # passed every check: nothing it was given may be ignored
            assert not ignored(argv), (argv, ignored(argv))
            # issue 26: strict JSON (no NaN, no Infinity); --json as given (not the value of an option)
            if code == 0 and "--json" in _given(argv) and out:
                _strict_json(out)
            return
        assert err.startswith("grazing: error: ") and err.count("\n") == 1, (argv, err)
        assert out == "", (argv, out)
        assert _files(work) == before, argv  # a failed run leaves nothing and changes nothing


@pytest.fixture
def stubbed_work(monkeypatch):
    import importlib

    for owner, name in WORK:
        module = importlib.import_module(owner) if isinstance(owner, str) else owner
        monkeypatch.setattr(module, name, _stub)


PROPERTY = settings(
    deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture]
)


@pytest.mark.parametrize("cmd", list(COMMANDS))
@settings(PROPERTY, max_examples=6)
@given(data=st.data())
def test_random_argument_lists(cmd, data, capsys, inputs, stubbed_work):
    """Never a traceback, never a file left by a failed run, never an option ignored (work stubbed)."""
    _check_run(data.draw(argument_lists(cmd)), capsys, inputs)


@pytest.mark.slow
@pytest.mark.parametrize("cmd", list(COMMANDS))
@settings(PROPERTY, max_examples=300)
@given(data=st.data())
def test_random_argument_lists_many(cmd, data, capsys, inputs, stubbed_work):
    _check_run(data.draw(argument_lists(cmd)), capsys, inputs)


@pytest.mark.slow
@pytest.mark.parametrize("cmd", REAL_WORK)
@settings(PROPERTY, max_examples=40)
@given(data=st.data())
def test_random_argument_lists_with_real_work(cmd, data, capsys, inputs):
    """The same with the work done (cheap commands; sizes only from the small values and the bad ones)."""
    _check_run(data.draw(argument_lists(cmd, st.sampled_from(BAD))), capsys, inputs)


# --------------------------------------------------------------------------
# issue 26: models


def test_a_model_with_smooth_functions_runs_and_its_prints_leave_json_clean(capsys, inputs):
    """tanh and atan (a traceback before); a file that prints: its text on stderr, stdout pure JSON."""
    import json

    argv = ["simulate", "--periods", "2", "--transient", "2", "--json", "--model"]
    with _workspace(inputs):
        assert main([*argv, "smooth.py:model"]) == 0
        out, err = capsys.readouterr()
        assert json.loads(out)["params"] == {"w": 1.2, "r": 0.8} and err == ""
        assert main([*argv, "prints.py:model"]) == 0
        out, err = capsys.readouterr()
        assert json.loads(out)["periods"] == 2 and err == "hello from a model file\n"


def test_a_memory_bound_beyond_floats_is_one_line(monkeypatch, capsys, inputs):
    monkeypatch.setenv(MEMORY_ENV, "1e400")
    err = _one_line_error(["simulate", "--periods", "10"], capsys, inputs)
    assert err == "grazing: error: GRAZING_MAX_MEMORY='1e400' is not a size such as 8G or 512M"


# --------------------------------------------------------------------------
# issue 29: the fuzz test's own reading of --json


def test_json_given_as_an_options_value_asks_for_no_json(capsys, inputs):
    """``--amplitude --json --amplitude 28``: "--json" is the first amplitude (then replaced), the output text
    (hypothesis found it; the check of strict JSON read any "--json" in the list as the flag)."""
    argv = ["damping", "--amplitude", "--json", "--amplitude", "28"]
    assert "--json" not in _given(argv)
    _check_run(argv, capsys, inputs)
