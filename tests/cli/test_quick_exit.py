"""A command's process ends without Python's teardown, but not before what Python's exit must do."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest


def run_script(body: str, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    script = tmp_path / "script.py"
    script.write_text(textwrap.dedent(body))
    command = [sys.executable, str(script)]
    return subprocess.run(command, capture_output=True, text=True, cwd=tmp_path, timeout=60)


def test_handlers_run_streams_flushed_and_status_kept(tmp_path: Path) -> None:
    done = run_script(
        """
        import atexit, sys
        from grazing.cli.quick_exit import quick_exit
        atexit.register(lambda: open("handler-ran", "w").write("yes"))
        sys.stdout.write("x" * 100000)  # (no newline: still in the buffer)
        sys.stderr.write("to stderr")
        quick_exit(3)
        """,
        tmp_path,
    )
    assert done.returncode == 3
    assert done.stdout == "x" * 100000
    assert done.stderr == "to stderr"
    assert (tmp_path / "handler-ran").read_text() == "yes"


def test_a_running_thread_is_waited_for(tmp_path: Path) -> None:
    done = run_script(
        """
        import threading, time
        from grazing.cli.quick_exit import others_running, quick_exit
        def work():
            time.sleep(0.5)
            open("thread-finished", "w").write("yes")
        threading.Thread(target=work).start()
        assert others_running()
        quick_exit(0)
        """,
        tmp_path,
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "thread-finished").read_text() == "yes"


def test_skips_the_teardown(tmp_path: Path) -> None:
    """An object's finaliser at Python's teardown does not run (what makes the exit quick)."""
    done = run_script(
        """
        import sys
        from grazing.cli.quick_exit import quick_exit
        class Loud:
            def __del__(self):
                sys.stdout.write("finalised")
        kept = Loud()
        quick_exit(0)
        """,
        tmp_path,
    )
    assert done.returncode == 0 and done.stdout == ""


@pytest.mark.parametrize("entry", ["-m grazing", "console script"])
def test_commands_end_with_their_status(entry: str, tmp_path: Path) -> None:
    command = (
        [sys.executable, "-m", "grazing"]
        if entry == "-m grazing"
        else [sys.executable, "-c", "from _grazing_entry import console; console()"]
    )

    def run(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([*command, *args], capture_output=True, text=True, cwd=tmp_path, timeout=120)

    ok = run("simulate", "--transient", "3", "--periods", "2", "--json")
    assert ok.returncode == 0 and ok.stdout.rstrip().endswith("}"), ok.stderr
    bad = run("simulate", "--periods", "-3")
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and bad.stderr.startswith("grazing: error:")
