"""What a new and a hostile user still found (issue 43): each is one line and a non-zero exit, nothing
written, no option ignored, every large count refused before memory is taken."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tracemalloc

import pytest

from grazing.cli import main
from grazing.cli.limits import MEMORY_ENV
from grazing.experiment.synthetic import synthetic_sweep
from tests.cli.test_cli_robustness import CURVE, MODEL_FILE, _one_line_error

NO_DIRECTION = MODEL_FILE.replace(", contact_direction=[0, 1]", "")
assert NO_DIRECTION != MODEL_FILE

RAISES = {
    "generatorexit.py": 'raise GeneratorExit("closed")\n',
    "baseexception.py": 'class Halt(BaseException):\n    pass\n\n\nraise Halt("stopped")\n',
}


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """A recording, and model files: one without a contact direction, some raising BaseExceptions."""
    root = tmp_path_factory.mktemp("inputs")
    synthetic_sweep(root / "folder", 40.0, [0.45], periods=40, transient=10, sample_rate=100.0)
    shutil.copy(next((root / "folder").glob("*.csv")), root / "rec.csv")
    shutil.rmtree(root / "folder")
    (root / "nodirection.py").write_text(NO_DIRECTION)
    for name, text in RAISES.items():
        (root / name).write_text(text)
    return root


NO_SAMPLE = "rad lies in the recording (0 s to "
BASINS = ["basins", "--model", "bouncing-ball", "--y-range", "-1,1", "--num", "2,2"]

WARNED_SYNTHESIZE = "synthesize --eta 0.45 --periods 40 --transient 10 --noise 1e308 --out n.csv".split()

ONE_LINE = [
    # former tracebacks
    (["analyze", "rec.csv", "--cutoff-hz", "1e-320"], f"no sampling time at phase 0 {NO_SAMPLE}"),
    (["analyze", "rec.csv", "--cutoff-multiple", "1e-320"], f"no sampling time at phase 0 {NO_SAMPLE}"),
    (
        ["normal-form", "--model", "nodirection.py:model", "--param", "w", "--range", "1,1.5"],
        "--model: model 'user' defines no contact direction for stop 'stop'; the grazing normal form needs "
        "one (HybridModel(..., contact_direction=[...]))",
    ),
    (
        ["simulate", "--model", "generatorexit.py:model"],
        "generatorexit.py failed to load: GeneratorExit: closed",
    ),
    (["simulate", "--model", "baseexception.py:model"], "baseexception.py failed to load: Halt: stopped"),
    # a value just outside its interval, said with the digits that put it outside (found by the fuzz)
    (["orbit", "--r", "1.0000001"], "r = 1.0000001 is outside [0, 1] (coefficient of restitution)"),
    # options ignored
    (["analyze", "rec.csv", "--phase", "1e308"], f"no sampling time at phase 1e+308 {NO_SAMPLE}"),
    (
        ["continue", "--param", "eta", "--start", "0.446", "--stop", "0.44", "--initial", ""],
        "--initial must be THETA,THETADOT in radians, got ''",
    ),
    ([*CURVE, "--kind", "fold", "--initial", ""], "--initial must be THETA,THETADOT in radians, got ''"),
    (  # (a store is never replaced: sweep and map refuse it so; found by the fuzz)
        [*BASINS, "--x-range", "0,1", "--periods", "3", "--out", "b.zarr", "--overwrite"],
        "--overwrite is not used with a Zarr store and no --plot (a store is never replaced)",
    ),
    # multi-line errors (numpy's warnings before the line: see also the test in a process below)
    ([*BASINS, "--x-range", "-1e308,1e308"], "--x-range: the range from -1e+308 to 1e+308 is wider than"),
    (
        "map --model bouncing-ball --param1 amplitude --start1 -1e308 --stop1 1e308 --num1 2 --param2 omega "
        "--start2 1 --stop2 2 --num2 2 --periods 3".split(),
        "--start1/--stop1: the range from -1e+308 to 1e+308 is wider than floats can hold",
    ),
    (WARNED_SYNTHESIZE, "the measured angle overflows with noise 1e+308 rad"),
]


@pytest.mark.parametrize(("argv", "message"), ONE_LINE)
def test_one_line_and_nothing_written(argv, message, capsys, inputs):
    assert message in _one_line_error(argv, capsys, inputs)


WARNED = {
    "basins": [*BASINS, "--x-range", "-1e308,1e308"],
    "synthesize": WARNED_SYNTHESIZE,
}


@pytest.mark.parametrize("name", list(WARNED))
def test_no_warning_comes_before_the_error_line(name, inputs, tmp_path):
    """numpy's RuntimeWarnings are printed by a process (a test run collects them instead)."""
    done = subprocess.run(
        [sys.executable, "-m", "grazing", *WARNED[name]], cwd=tmp_path, capture_output=True, text=True,
        timeout=300, check=False, env={**os.environ, "PYTHONWARNINGS": "default"},
    )  # fmt: skip
    assert done.returncode != 0 and done.stdout == ""
    assert done.stderr.startswith("grazing: error: ") and done.stderr.count("\n") == 1, done.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_huge_count_of_parameter_values_is_refused_before_they_are_made(monkeypatch, capsys, inputs):
    """attractors made its --num values (a Python float each) before the memory check: 1e9 of them grew
    by 230 MB/s until killed.  Here 3e6 of them: refused with next to no memory taken."""
    monkeypatch.setenv(MEMORY_ENV, "100M")
    argv = ["attractors", "--param", "eta", "--start", "0.44", "--stop", "0.45", "--num", "3000000",
            "--x-range", "-0.5,0.5", "--y-range", "-0.5,0.5", "--num-grid", "3,3"]  # fmt: skip
    tracemalloc.start()
    try:
        err = _one_line_error(argv, capsys, inputs, code_expected=1)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert "3e+06 basins of 9 initial states needs about" in err
    assert peak < 10e6  # (the values alone: 24 MB as an array, 72 MB as Python floats)


def test_a_missing_nested_grazing_cache_dir_is_refused_and_not_made(tmp_path, capsys):
    env = {**os.environ, "GRAZING_CACHE_DIR": str(tmp_path / "a" / "b" / "cache")}
    done = subprocess.run(
        [sys.executable, "-m", "grazing", "simulate", "--periods", "2", "--transient", "2"], cwd=tmp_path,
        capture_output=True, text=True, timeout=300, check=False, env=env,
    )  # fmt: skip
    assert done.returncode == 1 and done.stdout == ""
    assert done.stderr == (
        f"grazing: error: GRAZING_CACHE_DIR={tmp_path / 'a' / 'b' / 'cache'} cannot hold the compiled "
        f"kernels (its folder '{tmp_path / 'a' / 'b'}' does not exist): set it to a writable folder, or "
        "unset it\n"
    )
    assert list(tmp_path.iterdir()) == []


SWEEP = "sweep --param eta --start 0.44 --stop 0.45 --num 2 --periods 3 --transient 3 --out out.nc".split()


def _add_attribute(path):
    import h5py

    with h5py.File(path, "r+") as f:
        f.attrs["checked"] = "by me"


def _append_byte(path):
    with open(path, "ab") as fh:
        fh.write(b"\n")


@pytest.mark.parametrize("edit", [_add_attribute, _append_byte])
def test_a_netcdf_file_edited_after_grazing_wrote_it_is_not_replaced(edit, capsys, tmp_path, monkeypatch):
    """However it was edited, data untouched: refused without --overwrite, replaced with it."""
    monkeypatch.chdir(tmp_path)
    assert main(SWEEP) == 0
    assert main(SWEEP) == 0  # (grazing's own file: replaced)
    edit(tmp_path / "out.nc")
    before = (tmp_path / "out.nc").read_bytes()
    capsys.readouterr()
    assert main(SWEEP) == 1
    assert capsys.readouterr().err == (
        "grazing: error: out.nc exists and was not written by grazing (or was changed since); it was left "
        "untouched: use another name, or --overwrite to replace it\n"
    )
    assert (tmp_path / "out.nc").read_bytes() == before
    assert main([*SWEEP, "--overwrite"]) == 0
    assert (tmp_path / "out.nc").read_bytes() != before
