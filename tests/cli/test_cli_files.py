"""Every command that writes a file: what grazing wrote is rewritten, a file it did not write only with
``--overwrite``, a symbolic link is followed and stays a link, and a full disk is one line, no crash,
nothing left behind.  (A user's file refused and left byte-identical: the tables of
``test_cli_robustness.py``.)"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from grazing.cli import main
from grazing.experiment.synthetic import synthetic_recording, write_recording
from grazing.outputs import written_by_grazing
from grazing.report.folder import MARKER
from tests.processes import limit_file_size

SWEEP = ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.45", "--num", "40", "--periods", "10",
         "--transient", "20", "--workers", "1"]  # fmt: skip
MAP = ["map", "--param1", "eta", "--start1", "0.44", "--stop1", "0.45", "--num1", "6", "--param2",
       "theta-hat", "--start2", "30", "--stop2", "31", "--num2", "6", "--periods", "10", "--transient", "20",
       "--workers", "1"]  # fmt: skip

CURVE = (
    "curve --kind period-doubling --param eta --start 0.446 --stop 0.44 --param2 theta-hat "
    "--range 39.95,40.05 --out"
).split()  # issue 27: curves

COMMANDS = {
    "simulate": (["simulate", "--periods", "3", "--transient", "10", "--trajectory"], ".csv"),
    "iso-damping": (["iso-damping", "--relation", "paper", "--num", "400", "--out"], ".csv"),
    "sweep": ([*SWEEP, "--out"], ".nc"),
    "map": ([*MAP, "--out"], ".nc"),
    "continue": (["continue", "--param", "eta", "--start", "0.446", "--stop", "0.4455", "--out"], ".nc"),
    "graze-curve": (["graze-curve", "--start-deg", "30", "--max-step", "0.2", "--out"], ".nc"),
    "synthesize": (["synthesize", "--eta", "0.446", "--periods", "8", "--transient", "0", "--out"], ".csv"),
    "analyze": (["analyze", "rec.csv", "--plot"], ".png"),
    # issue 27: curves
    "curve": (CURVE, ".nc"),
}
"""Each command with cheap arguments, ending with its output option; the output's suffix."""


@pytest.fixture
def work(tmp_path, monkeypatch):
    """An empty folder as the current folder, with a recording for ``analyze``."""
    rec = synthetic_recording(0.446, 40.0, periods=12, transient=50, sample_rate=100.0)
    write_recording(rec, tmp_path / "rec.csv")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _run(argv, capsys) -> tuple[int, str]:
    code = main(argv)
    err = capsys.readouterr().err
    return code, err


@pytest.mark.parametrize("cmd", list(COMMANDS))
def test_what_grazing_wrote_is_rewritten_a_user_file_only_with_overwrite(cmd, work, capsys):
    argv, suffix = COMMANDS[cmd]
    out = work / f"out{suffix}"
    code, err = _run([*argv, out.name], capsys)
    assert code == 0, err
    assert written_by_grazing(out)
    code, err = _run([*argv, out.name], capsys)  # grazing's own file: rewritten without asking
    assert code == 0 and written_by_grazing(out), err
    with open(out, "ab") as fh:  # a line added by hand; an image or a data file replaced by the user's own
        fh.write(b"1,2\n") if suffix == ".csv" else fh.truncate(0) or fh.write(b"mine")
    before = out.read_bytes()
    code, err = _run([*argv, out.name], capsys)
    assert code != 0 and err.count("\n") == 1 and "or was changed since" in err, err
    assert out.read_bytes() == before
    code, err = _run([*argv, out.name, "--overwrite"], capsys)
    assert code == 0 and written_by_grazing(out), err
    hidden = [p.name for p in work.iterdir() if p.name.startswith(".")]
    assert hidden == []


@pytest.mark.parametrize("cmd", ["simulate", "sweep", "analyze"])
def test_a_symbolic_link_at_the_output_is_followed_and_stays_a_link(cmd, work, capsys):
    argv, suffix = COMMANDS[cmd]
    (work / "data").mkdir()
    target, link = work / "data" / f"real{suffix}", work / f"link{suffix}"
    link.symlink_to(Path("data") / target.name)  # the file it names does not exist yet: made
    code, err = _run([*argv, link.name], capsys)
    assert code == 0, err
    assert link.is_symlink() and written_by_grazing(target)
    target.write_bytes(b"mine")
    code, err = _run([*argv, link.name], capsys)
    assert code != 0 and f"{link.name} (a link to {target.resolve()}) exists and was not written" in err
    assert target.read_bytes() == b"mine" and link.is_symlink()
    code, err = _run([*argv, link.name, "--overwrite"], capsys)
    assert code == 0 and link.is_symlink() and written_by_grazing(target), err


def test_synthesize_into_a_folder_replaces_only_its_own_recordings(work, capsys):
    from grazing.experiment.synthetic import recording_name

    argv = ["synthesize", "--eta", "0.446", "--eta", "0.45", "--periods", "8", "--transient", "0",
            "--sample-rate", "100", "--out", "fold"]  # fmt: skip
    assert _run(argv, capsys)[0] == 0
    names = sorted(p.name for p in (work / "fold").iterdir())
    assert names == sorted(f"{n[:-4]}{s}" for n in (recording_name(40, 0.446), recording_name(40, 0.45))
                           for s in (".csv", ".json"))  # fmt: skip
    assert _run(argv, capsys)[0] == 0  # its own recordings: rewritten
    (work / "fold" / "notes.txt").write_text("mine")
    side = work / "fold" / recording_name(40, 0.45).replace(".csv", ".json")
    side.write_text('{"theta_hat_deg": 40, "note": "corrected by hand"}')
    code, err = _run(argv, capsys)
    assert code != 0 and f"{side.name} exists and was not written by grazing" in err
    assert side.read_text().endswith('by hand"}') and (work / "fold" / "notes.txt").read_text() == "mine"
    assert sorted(p.name for p in work.iterdir() if p.name.startswith(".")) == []


# --------------------------------------------------------------------------
# A full disk


def _full_disk_run(argv: list[str], cwd: Path, limit: int = 4096) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    return subprocess.run(
        [sys.executable, "-m", "grazing", *argv], cwd=cwd, env=env, capture_output=True, text=True,
        preexec_fn=lambda: limit_file_size(limit), timeout=600,
    )  # fmt: skip


def _listing(folder: Path) -> dict[str, bytes | None]:
    return {str(p.relative_to(folder)): p.read_bytes() if p.is_file() else None for p in folder.rglob("*")}


@pytest.mark.parametrize("cmd", list(COMMANDS))
def test_a_full_disk_is_one_line_no_crash_and_nothing_left(cmd, work):
    argv, suffix = COMMANDS[cmd]
    before = _listing(work)
    proc = _full_disk_run([*argv, f"out{suffix}"], work)
    assert proc.returncode == 1, (proc.returncode, proc.stderr)  # not a crash (a negative code: a signal)
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith("grazing: error: cannot write "), proc.stderr
    assert "File too large; nothing was written" in proc.stderr
    assert _listing(work) == before  # no output, no hidden temporary


def test_a_full_disk_while_writing_a_sweep_store_keeps_what_was_finished(work):
    argv = [*SWEEP, "--chunk-size", "20", "--periods", "40", "--out", "s.zarr"]
    proc = _full_disk_run(argv, work, limit=4096)
    assert proc.returncode == 1 and proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith("grazing: error: cannot write to sweep store s.zarr: File too large")
    hidden = sorted(p.name for p in work.iterdir() if p.name.startswith("."))
    assert hidden == []  # no half-built store beside it
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-m", "grazing", *argv], cwd=work, env=env, capture_output=True,
                          text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr  # resumed once there is room


# --------------------------------------------------------------------------
# The report's folder


def test_the_report_goes_into_its_own_folder_an_empty_one_or_a_new_one(work, capsys):
    from grazing.report.folder import check_report_folder, claim_report_folder

    check_report_folder(work / "new")  # a new folder in an existing one
    claim_report_folder(work / "new")
    assert (work / "new" / MARKER).is_file() and written_by_grazing(work / "new" / MARKER)
    (work / "empty").mkdir()
    check_report_folder(work / "empty")
    (work / "old").mkdir()
    (work / "old" / "results").mkdir()
    (work / "old" / "comparisons.json").write_text("{}")
    with pytest.raises(Exception, match="looks like a report of an earlier grazing, which left no marker"):
        check_report_folder(work / "old")


def test_report_overwrite_builds_into_a_folder_of_the_user_and_keeps_their_other_files(work, capsys):
    (work / "site").mkdir()
    (work / "site" / "index.html").write_text("<p>my page</p>")
    (work / "site" / "notes.txt").write_text("mine")
    code, err = _run(["report", "--only", "eq", "--out", "site"], capsys)
    assert code == 1 and "site exists and is not a report folder of grazing" in err
    assert (work / "site" / "index.html").read_text() == "<p>my page</p>"
    code, err = _run(["report", "--only", "eq", "--out", "site", "--overwrite"], capsys)
    assert code == 0, err
    assert (work / "site" / MARKER).is_file() and "my page" not in (work / "site" / "index.html").read_text()
    assert (work / "site" / "notes.txt").read_text() == "mine"
    code, err = _run(["report", "--only", "eq", "--out", "site"], capsys)  # now grazing's: rebuilt
    assert code == 0, err


def test_a_full_disk_during_a_report_is_one_line_and_leaves_no_partial_file(work):
    proc = _full_disk_run(["report", "--only", "eq", "--out", "rep"], work)
    assert proc.returncode == 1, proc.stderr
    errors = [line for line in proc.stderr.splitlines() if line.startswith("grazing: error: ")]
    assert len(errors) == 1 and proc.stderr.rstrip("\n").endswith("File too large; nothing was written")
    left = sorted(str(p.relative_to(work / "rep")) for p in (work / "rep").rglob("*"))
    assert left in ([MARKER, "results"], [MARKER]), left  # the marked folder, no partial file or temporary
