"""Files written all at once, and the scratch folder of a folder being written by several processes."""

from __future__ import annotations

import multiprocessing as mp
import os
import signal
import subprocess
import sys

import pytest

from grazing.atomic import SCRATCH_PREFIX, atomic_path, scratch_folder, write_text_atomic
from tests.processes import wait_until


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "a.csv"
    target.write_text("old")
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        with open(tmp, "w") as fh:
            fh.write("half")
        raise RuntimeError("interrupted")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.csv"]


def test_text_is_utf8_whatever_the_locale(tmp_path):
    write_text_atomic(tmp_path / "t.txt", lambda fh: fh.write("θ̂ = 40°"))
    assert (tmp_path / "t.txt").read_bytes().decode("utf-8") == "θ̂ = 40°"


def _write_forever(path: str, started: str) -> None:
    with atomic_path(path, suffix=".png") as tmp, open(tmp, "w") as fh:
        fh.write("partial")
        fh.flush()
        open(started, "w").close()
        signal.pause()  # killed here, in the middle of its write


def test_a_worker_killed_while_writing_leaves_nothing_in_the_folder(tmp_path):
    out = tmp_path / "report"
    (out / "sub").mkdir(parents=True)
    started = tmp_path / "started"
    with scratch_folder(out) as scratch:
        assert scratch.parent == out and scratch.name.startswith(f"{SCRATCH_PREFIX}{os.getpid()}-")
        target = str(out / "sub" / "f.png")
        worker = mp.get_context("fork").Process(target=_write_forever, args=(target, started))
        worker.start()
        assert wait_until(started.exists)
        assert len(list(scratch.iterdir())) == 1  # the temporary is in the scratch folder, not beside f.png
        os.kill(worker.pid, signal.SIGKILL)
        worker.join()
    assert sorted(p.name for p in out.rglob("*")) == ["sub"]


def test_scratch_folders_of_dead_processes_are_removed_and_no_other(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True)
    pid = int(dead.stdout)
    stale = tmp_path / f"{SCRATCH_PREFIX}{pid}-abc"
    stale.mkdir()
    (stale / ".f.png.x1y2.png").write_text("partial")
    alive = tmp_path / f"{SCRATCH_PREFIX}{os.getppid()}-def"  # a process that exists
    alive.mkdir()
    mine = tmp_path / f"{SCRATCH_PREFIX}{pid}-ghi"  # named like one, holding a file grazing never makes
    mine.mkdir()
    (mine / "notes.txt").write_text("a user's")
    with scratch_folder(tmp_path):
        pass
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([alive.name, mine.name])


def test_a_temporary_left_by_a_killed_writer_is_removed_by_the_next_write(tmp_path):
    """A process killed outright while it wrote ``t.csv`` left its temporary beside it (found by the signal
    fuzz: ``simulate --trajectory t.csv`` killed, then run again); the next write of ``t.csv`` removes it,
    and nothing else: a running process's temporary, a file not of grazing's form."""
    from grazing.atomic import atomic_path

    dead = tmp_path / ".t.csv.999999999-ab12.tmp"  # (a PID above any system's pid_max: gone)
    alive = tmp_path / f".t.csv.{os.getpid()}-cd34.tmp"
    theirs = tmp_path / ".t.csv.notes.tmp"
    for p in (dead, alive, theirs):
        p.write_text("x")
    with atomic_path(tmp_path / "t.csv") as tmp:
        assert f".t.csv.{os.getpid()}-" in tmp
        with open(tmp, "w") as f:
            f.write("done")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([alive.name, theirs.name, "t.csv"])
