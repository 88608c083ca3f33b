"""Ctrl-C ends every long-running command with exit status 130 and one line, leaving no file.

(The sweep into a Zarr store and the report have their own tests, which also check what they keep:
tests/sweeps/test_store_safety.py and tests/report/test_schedule.py.)
"""

from __future__ import annotations

import builtins
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import _grazing_entry
from grazing.cli import main

pytestmark = pytest.mark.skipif(os.name != "posix", reason="sends SIGINT to a process group")

ENTRY = [sys.executable, "-c", "import sys; from _grazing_entry import main; sys.exit(main())"]
"""The ``grazing`` console script (pyproject.toml's entry point)."""

LONG_RUNNING = {
    "simulate": ["simulate", "--transient", "100000000", "--periods", "20"],
    "orbit": ["orbit", "--transient", "100000000"],
    "synthesize": ["synthesize", "--eta", "0.446", "--transient", "10000000", "--periods", "8", "--out",
                   "x.csv"],
    "sweep": ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.49", "--num", "20000", "--json"],
    "map": ["map", "--param1", "eta", "--start1", "0.4", "--stop1", "0.5", "--num1", "300", "--param2",
            "theta-hat", "--start2", "30", "--stop2", "40", "--num2", "300", "--out", "m.nc"],
    "iso-damping": ["iso-damping", "--num", "100000", "--out", "c.csv"],
}  # fmt: skip
"""Each command with settings that take minutes (the tests stop them after a few seconds)."""

WARM_UP = [
    ["simulate", "--transient", "3", "--periods", "2"],
    ["orbit"],
    ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.45", "--num", "2", "--periods", "3"],
    ["iso-damping", "--num", "2"],
]


@pytest.fixture(scope="module")
def warm(tmp_path_factory):
    """The kernels the commands use, compiled and cached (a fresh machine compiles them on first use)."""
    here = os.getcwd()
    os.chdir(tmp_path_factory.mktemp("warm"))
    try:
        for argv in WARM_UP:
            assert main(argv) == 0
    finally:
        os.chdir(here)


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize("name", list(LONG_RUNNING))
def test_ctrl_c_ends_the_command_with_one_line(name, warm, tmp_path):
    # As from a terminal: Ctrl-C's default disposition (a test runner's worker may ignore SIGINT),
    # sent to the whole process group.
    proc = subprocess.Popen([*ENTRY, *LONG_RUNNING[name]], cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=_default_sigint)  # fmt: skip
    try:
        time.sleep(2.0)  # at work by now (imports take a few tenths of a second)
        assert proc.poll() is None, proc.communicate()
        os.killpg(proc.pid, signal.SIGINT)
        sent = time.monotonic()
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, (proc.returncode, err)
    assert err == "grazing: interrupted\n"  # (one line: no empty one before it where stderr is no terminal)
    assert out == ""
    assert time.monotonic() - sent < 60.0  # a bound against hanging, not a timing requirement
    assert list(tmp_path.iterdir()) == []  # nothing written, nothing left half-written


def test_ctrl_c_while_the_command_line_is_imported(monkeypatch, capsys):
    real_import = builtins.__import__

    def interrupted(name, *args, **kwargs):
        if name == "grazing.cli":
            raise KeyboardInterrupt
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", interrupted)
    assert _grazing_entry.main() == 130
    assert capsys.readouterr().err == "grazing: interrupted\n"


def test_the_command_runs_one_blas_thread_unless_told_otherwise():
    # OpenBLAS's threads would spin beside the command's own (issue 29: 0.1 s of CPU per command); the
    # setting must be made before numpy is imported, which the command line imports.
    script = (
        "import os, sys; from _grazing_entry import main; sys.argv = ['grazing', '--help']\n"
        "try:\n    main()\nexcept SystemExit:\n    pass\n"
        "print(os.environ['OPENBLAS_NUM_THREADS'], 'numpy' in sys.modules)"
    )
    import grazing

    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    # (this tree's entry module: an editable install keeps a copy of it, made when it was installed)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(Path(grazing.__file__).resolve().parents[1]), env.get("PYTHONPATH", "")]
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.splitlines()[-1] == "1 True"
    env["OPENBLAS_NUM_THREADS"] = "2"  # (a user's setting stays)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.splitlines()[-1] == "2 True"
