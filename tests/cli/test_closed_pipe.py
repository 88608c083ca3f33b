"""A command whose output's reader has gone (``grazing sweep --json | head``) ends quietly: status 141."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from grazing.cli.common import EXIT_CLOSED_PIPE, output_closed

pytestmark = pytest.mark.skipif(os.name != "posix", reason="pipes and poll")

CONSOLE = [sys.executable, "-c", "from _grazing_entry import console; console()"]
"""The ``grazing`` console script (pyproject.toml's entry point), which ends by ``quick_exit``."""

MODULE = [sys.executable, "-m", "grazing"]

COMMANDS = {
    "sweep --json": ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.45", "--num", "3",
                     "--periods", "5", "--json"],
    "simulate (a rich table)": ["simulate", "--transient", "3", "--periods", "4"],
    "orbit --json": ["orbit", "--json"],
}  # fmt: skip


def _run_into_closed_pipe(argv: list[str]) -> subprocess.CompletedProcess:
    """Run ``argv`` with its standard output a pipe whose reader closed before it started."""
    read, write = os.pipe()
    os.close(read)
    try:
        return subprocess.run(argv, stdout=write, stderr=subprocess.PIPE, timeout=300, check=False)
    finally:
        os.close(write)


@pytest.mark.parametrize("entry", [CONSOLE, MODULE], ids=["console script", "python -m grazing"])
@pytest.mark.parametrize("name", list(COMMANDS))
def test_output_into_a_closed_pipe_ends_quietly_with_status_141(entry, name):
    done = _run_into_closed_pipe([*entry, *COMMANDS[name]])
    assert done.stderr.decode() == ""
    assert done.returncode == EXIT_CLOSED_PIPE


def test_output_read_to_its_end_is_whole_and_ends_with_status_0():
    argv = [*CONSOLE, *COMMANDS["orbit --json"]]
    done = subprocess.run(argv, capture_output=True, timeout=300, check=False)
    assert done.returncode == 0 and done.stderr == b""
    assert done.stdout.rstrip().endswith(b"}")


def test_a_broken_pipe_that_is_not_the_output_is_an_error_line(monkeypatch, capsys):
    """A closed pipe elsewhere (a socket to a Dask scheduler...) is reported as any other OSError."""
    import grazing.cli as cli_module

    def broken(*_args, **_kwargs):
        raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(cli_module.cli, "invoke", broken)
    assert cli_module.main(["orbit"]) == 1
    assert capsys.readouterr().err == "grazing: error: Broken pipe\n"


def test_output_closed_is_false_for_a_file(tmp_path):
    with open(tmp_path / "out.txt", "w") as fh:
        assert not output_closed(fh.fileno())


# issue 43: with PYTHONUNBUFFERED=1 (which users set), Python's standard output has no buffer, and a write
# that the system takes only a part of lost the rest without an error: status 0 after ``| head -c 100``,
# and a truncated file with status 0 on a full disk.
UNBUFFERED = {**os.environ, "PYTHONUNBUFFERED": "1"}
LARGE = {
    "simulate": ["simulate", "--periods", "20000", "--transient", "10", "--json"],
    "sweep": "sweep --param eta --start .44 --stop .45 --num 2000 --periods 10 --transient 1 --json".split(),
}  # (over a megabyte and 500 kB of JSON: more than a pipe holds)


@pytest.mark.parametrize("name", list(LARGE))
def test_a_reader_that_leaves_after_a_few_bytes_ends_the_command_with_141(name):
    proc = subprocess.Popen([*CONSOLE, *LARGE[name]], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=UNBUFFERED)  # fmt: skip
    try:
        assert len(proc.stdout.read(100)) == 100  # (as head -c 100)
        proc.stdout.close()
        err = proc.stderr.read().decode()
        proc.wait(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert (proc.returncode, err) == (EXIT_CLOSED_PIPE, "")


def test_a_full_disk_under_the_standard_output_is_one_line_and_status_1(tmp_path):
    from tests.processes import limit_file_size

    with open(tmp_path / "out.json", "wb") as out:
        done = subprocess.run(
            [*CONSOLE, *LARGE["simulate"]], stdout=out, stderr=subprocess.PIPE, timeout=300, env=UNBUFFERED,
            preexec_fn=lambda: limit_file_size(100_000), check=False,
        )  # fmt: skip
    assert (done.returncode, done.stderr.decode()) == (1, "grazing: error: File too large\n")
