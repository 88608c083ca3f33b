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


# --------------------------------------------------------------------------
# issue 43: SIGTERM is handled as Ctrl-C is; a compile does not hold up Ctrl-C; what a killed or failed
# run made is not left behind

TERMINATED = {
    "simulate": LONG_RUNNING["simulate"],  # (in the compiled driver: its signal counter)
    "sweep": LONG_RUNNING["sweep"],  # (threads)
    "map": LONG_RUNNING["map"],  # (a NetCDF file at the end)
    "synthesize into a folder": ["synthesize", "--eta", "0.446", "--eta", "0.45", "--transient", "10000000",
                                 "--periods", "8", "--out", "recs"],  # (a hidden folder beside it)
}  # fmt: skip


@pytest.mark.parametrize("name", list(TERMINATED))
def test_sigterm_ends_the_command_as_ctrl_c_does_with_143(name, warm, tmp_path):
    # (``kill PID``: to the process only, not its group)
    proc = subprocess.Popen([*ENTRY, *TERMINATED[name]], cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        time.sleep(2.0)
        assert proc.poll() is None, proc.communicate()
        proc.terminate()
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert (proc.returncode, err, out) == (143, "grazing: terminated\n", "")
    assert list(tmp_path.iterdir()) == []  # its temporaries removed


def test_sigterm_while_the_command_line_is_imported():
    """The console script's own handler until grazing.cli's: one line and 143 at any moment."""
    script = (
        "import signal, sys, _grazing_entry\n"
        "sys.modules.pop('grazing.cli', None)\n"
        "class Finder:\n"
        "    def find_spec(self, name, *args):\n"
        "        if name == 'grazing.cli':\n"
        "            signal.raise_signal(signal.SIGTERM)\n"
        "sys.meta_path.insert(0, Finder())\n"
        "sys.exit(_grazing_entry.main())\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=False)
    assert (done.returncode, done.stderr) == (143, "grazing: terminated\n")


@pytest.mark.parametrize(
    ("signame", "code", "line"), [("SIGTERM", 143, "terminated"), ("SIGINT", 130, "interrupted")]
)
def test_a_signal_that_an_import_turns_into_its_own_error_ends_as_the_signal(signame, code, line):
    """A SIGTERM or a Ctrl-C while an extension module is imported is raised inside its initialisation,
    which turns it into its own error (scipy's HiGHS: ``ImportError: initialization failed``, found by the
    signal fuzz on ``iso-damping``, for both): one line and 143 or 130 all the same, not the import's
    traceback."""
    script = (
        "import signal, sys, _grazing_entry\n"
        "import grazing.experiment.damping as damping\n"
        "def importing(*args, **kwargs):\n"
        "    try:\n"
        f"        signal.raise_signal(signal.{signame})\n"
        "    except BaseException:\n"
        "        raise ImportError('initialization failed') from None\n"
        "damping.iso_damping = importing\n"
        "sys.argv = ['grazing', 'iso-damping', '--num', '10']\n"
        "sys.exit(_grazing_entry.main())\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=False)
    assert (done.returncode, done.stderr) == (code, f"grazing: {line}\n")


def test_a_folder_left_by_a_killed_synthesize_is_removed_by_the_next_run(warm, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    dead = tmp_path / ".recs.partial-999999999-abc123"  # (a PID above any system's pid_max: gone)
    dead.mkdir()
    (dead / "p40_eta0.44600.csv").write_text("time,angle\n")
    (dead / ".p40_eta0.44600.csv.x1y2.tmp").write_text("")
    alive = tmp_path / f".recs.partial-{os.getpid()}-def456"  # (a running process's: left alone)
    alive.mkdir()
    argv = ["synthesize", "--eta", "0.446", "--eta", "0.45", "--periods", "8", "--transient", "2", "--out",
            "recs"]  # fmt: skip
    assert main(argv) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [alive.name, "recs"]


def test_a_report_whose_folder_cannot_be_marked_leaves_no_folder(tmp_path):
    """A full disk: "nothing was written", and the new folder it made is gone too."""
    from tests.processes import limit_file_size

    done = subprocess.run(
        [*ENTRY, "report", "--only", "eq", "--out", "rep"], cwd=tmp_path, capture_output=True, text=True,
        timeout=300, check=False, preexec_fn=lambda: limit_file_size(0),
    )  # fmt: skip
    assert (done.returncode, done.stderr) == (
        1, "grazing: error: cannot write rep/.grazing-report: File too large; nothing was written\n"
    )  # fmt: skip
    assert list(tmp_path.iterdir()) == []


CONSOLE = [sys.executable, "-c", "from _grazing_entry import console; console()"]
"""The ``grazing`` console script, as installed (it ends by ``quick_exit``)."""


COMPILING = {
    "sweep": ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.45", "--num", "3", "--periods", "5",
              "--json"],
    "simulate": ["simulate", "--transient", "3", "--periods", "3"],
}  # fmt: skip
"""A command of each driver (the sweeps' lanes, the scalar integrator) that compiles it the first time."""


@pytest.mark.slow
@pytest.mark.parametrize("command", sorted(COMPILING))
@pytest.mark.parametrize("after", [3.0, 8.0])
def test_ctrl_c_during_the_first_compile_ends_the_command_within_a_second(command, after, tmp_path):
    """A driver compiles (about 40 s) in a thread of its own; Ctrl-C ended the command only when the compile
    had: 35-40 s late (the sweep), or was lost in one of llvmlite's callbacks, exit 0 (simulate)."""
    env = {**os.environ, "GRAZING_CACHE_DIR": str(tmp_path / "cache")}
    argv = COMPILING[command]
    proc = subprocess.Popen(
        [*CONSOLE, *argv], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
        start_new_session=True, preexec_fn=_default_sigint,
    )  # fmt: skip
    try:
        time.sleep(after)
        assert proc.poll() is None, proc.communicate()
        os.killpg(proc.pid, signal.SIGINT)
        sent = time.monotonic()
        out, err = proc.communicate(timeout=120)
        took = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
    assert (proc.returncode, err, out) == (130, "grazing: interrupted\n", "")
    assert took < 1.0, took


ZARR_BUSY = """
import asyncio, sys, time
import zarr.core.sync as sync
loop = sync._get_loop()
loop.call_soon_threadsafe(time.sleep, 30)  # (zarr's thread held, as by a write in flight at a Ctrl-C)
time.sleep(0.2)
if sys.argv[1] == "interrupted":
    from grazing.cli import quiet_store_exit
    quiet_store_exit()
"""


@pytest.mark.parametrize("how", ["interrupted", "as zarr ends"])
def test_an_interrupt_during_a_store_write_ends_without_zarrs_traceback(how, tmp_path):
    # A Ctrl-C while zarr's thread was writing: zarr's exit hook logged a line and raised closing the running
    # loop (a traceback after "grazing: interrupted", seen by the fuzz's signal suite under load).
    script = tmp_path / "busy.py"
    script.write_text(ZARR_BUSY)
    done = subprocess.run([sys.executable, str(script), how], capture_output=True, text=True, timeout=60)
    if how == "interrupted":
        assert (done.returncode, done.stderr) == (0, "")
    elif "Cannot close a running event loop" not in done.stderr:  # (without it: the case is real)
        pytest.skip("this zarr's exit hook ends a busy thread quietly: nothing to silence")


ZARR_PENDING = """
import asyncio, sys, time
import zarr.core.sync as sync


async def write():  # (a store's write in flight at a Ctrl-C: gathering chunk writes that never finish)
    await asyncio.gather(asyncio.sleep(3600))


asyncio.run_coroutine_threadsafe(write(), sync._get_loop())
time.sleep(0.2)
if sys.argv[1] == "interrupted":
    from grazing.cli import quiet_store_exit
    quiet_store_exit()
"""


@pytest.mark.parametrize("how", ["interrupted", "as zarr ends"])
def test_an_interrupt_during_a_store_write_ends_without_asyncios_pending_task_lines(how, tmp_path):
    # The tasks pending in zarr's loop at exit were logged by asyncio ("Task was destroyed but it is
    # pending!" and the task, after "grazing: interrupted"; seen in the default suite under load).
    script = tmp_path / "pending.py"
    script.write_text(ZARR_PENDING)
    done = subprocess.run([sys.executable, str(script), how], capture_output=True, text=True, timeout=60)
    if how == "interrupted":
        assert (done.returncode, done.stderr) == (0, "")
    else:  # (the case is real: without the silencing, asyncio says so)
        assert "Task was destroyed but it is pending!" in done.stderr
