"""Signals at several moments for every long command (issue 43; slow): Ctrl-C (SIGINT) ends with status 130
and one line, SIGTERM with 143 and one line, and after SIGKILL the same command run again succeeds, its
store resumed to what an uninterrupted run gives, nothing left behind.  Also: Ctrl-C while the kernels
compile for the first time, a new cache folder with missing parents, and bad frames sent to the explorer."""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import signal
import socket
import subprocess
import time
from dataclasses import replace
from pathlib import Path

import pytest

from tests.fuzz.cases import COMMANDS, LONG_COMMANDS, Case
from tests.fuzz.check import Template, describe
from tests.fuzz.invariants import file_violations, status_violations
from tests.fuzz.runner import Outcome, run_process, start, stop_group
from tests.fuzz.workspace import fresh_copy, snapshot
from tests.processes import all_gone, descendants

pytestmark = [pytest.mark.slow, pytest.mark.skipif(os.name != "posix", reason="signals, process groups")]

MOMENTS = (0.3, 2.0, 5.0)
"""When a signal is sent, in seconds after the start: while Python imports, at work, later at work."""

BOUNDED = {"continue": (0.3,), "graze-curve": (0.3,)}
"""Long commands whose runs are bounded (a continuation's 2000 points: about a second), and the moments
they are signalled at."""

SIGNALLED = [(name, moment) for name in LONG_COMMANDS for moment in BOUNDED.get(name, MOMENTS)]
"""Each long command and each moment it is signalled at."""


def _signalled(
    template: Template, tmp: Path, case: Case, signum: int, moment: float
) -> tuple[Outcome, list[str]]:
    """Run ``case``, send ``signum`` to its group after ``moment`` s; its outcome and what is wrong."""
    work = fresh_copy(template.root, tmp / "w")
    t0 = time.monotonic()
    proc = start(case, work, subprocess.PIPE)
    try:
        time.sleep(moment)
        running = proc.poll() is None
        kids = descendants(proc.pid)
        if running:
            os.killpg(proc.pid, signum)
        out, err = proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        stop_group(proc)
        return Outcome(-9, "", "", hung=True), ["hung after the signal"]
    outcome = Outcome(
        proc.returncode,
        out.decode(errors="replace"),
        err.decode(errors="replace"),
        seconds=time.monotonic() - t0,
    )
    problems = [] if running else [f"ended before the signal at {moment} s: make the command longer"]
    problems += status_violations(case, outcome, sent=signum)
    if signum != signal.SIGKILL:
        code = {signal.SIGINT: 130, signal.SIGTERM: 143}[signum]
        if outcome.returncode != code:
            problems.append(f"exit {outcome.returncode} after {signal.Signals(signum).name}, not {code}")
        if outcome.stdout:
            problems.append("interrupted, yet it printed a result on stdout")
        problems += file_violations(
            case,
            outcome.returncode,
            work,
            template.entries,
            snapshot(work),
            template.grazings,
            interrupted=True,
        )
    if not all_gone(kids, limit=30):
        problems.append("a process it started is still running")
    return outcome, problems


def _long_case(name: str) -> Case:
    return Case(f"{name}/long", COMMANDS[name].long_argv, "signal", name, process=True)


@pytest.mark.parametrize(("name", "moment"), SIGNALLED)
def test_ctrl_c_ends_with_130_and_one_line(name, moment, template, tmp_path):
    case = _long_case(name)
    outcome, problems = _signalled(template, tmp_path, case, signal.SIGINT, moment)
    assert not problems, describe(case, outcome, problems)


@pytest.mark.parametrize(("name", "moment"), SIGNALLED)
def test_sigterm_ends_with_143_and_one_line(name, moment, template, tmp_path):
    case = _long_case(name)
    outcome, problems = _signalled(template, tmp_path, case, signal.SIGTERM, moment)
    assert not problems, describe(case, outcome, problems)


RESUMED_SWEEP = (
    "sweep",
    "--param",
    "eta",
    "--start",
    "0.44",
    "--stop",
    "0.45",
    "--num",
    "24",
    "--chunk-size",
    "3",
    "--workers",
    "1",
    "--periods",
    "20",
    "--transient",
    "100",
)
"""A sweep of 8 chunks, the same to a Zarr store and to a NetCDF file."""


RESUMED: dict[str, tuple[str, ...]] = {
    "simulate": ("simulate", "--transient", "20000", "--periods", "200", "--trajectory", "t.csv"),
    "sweep": (*RESUMED_SWEEP, "--out", "s.zarr"),
    "sweep-nc": (*RESUMED_SWEEP, "--out", "s.nc"),
    "map": (
        "map",
        "--param1",
        "eta",
        "--start1",
        "0.44",
        "--stop1",
        "0.45",
        "--num1",
        "5",
        "--param2",
        "theta-hat",
        "--start2",
        "30",
        "--stop2",
        "31",
        "--num2",
        "5",
        "--chunk-size",
        "3",
        "--workers",
        "1",
        "--periods",
        "20",
        "--transient",
        "100",
        "--out",
        "m.zarr",
    ),
    "basins": (
        "basins",
        "--model",
        "bouncing-ball",
        "--x-range",
        "0,1",
        "--y-range",
        "-1,1",
        "--num",
        "20,20",
        "--chunk-size",
        "40",
        "--workers",
        "1",
        "--out",
        "b.zarr",
    ),
    "attractors": (
        "attractors",
        "--model",
        "bouncing-ball",
        "--param",
        "amplitude",
        "--start",
        "0.5",
        "--stop",
        "0.8",
        "--num",
        "6",
        "--x-range",
        "0,1",
        "--y-range",
        "-1,1",
        "--num-grid",
        "6,6",
        "--workers",
        "1",
        "--out",
        "a.nc",
    ),
    "synthesize": (
        "synthesize",
        "--eta",
        "0.446",
        "--transient",
        "20000",
        "--periods",
        "8",
        "--out",
        "x.csv",
    ),
    "iso-damping": ("iso-damping", "--num", "200", "--out", "c.csv"),
    "continue": (
        "continue",
        "--param",
        "eta",
        "--start",
        "0.446",
        "--stop",
        "0.40",
        "--max-step",
        "0.001",
        "--out",
        "c.nc",
    ),
    "report": ("report", "--out", "rep", "--only", "eq"),
}
"""A command line of each long command that ends in seconds, writing a file (a store: resumed)."""


def _dataset(path: Path) -> dict[str, object]:
    """The results in a store or NetCDF file (not the clock times of its chunks)."""
    import xarray as xr

    opened = xr.open_zarr(path) if path.suffix == ".zarr" else xr.open_dataset(path)
    with opened as ds:
        return {k: ds[k].values for k in ds.data_vars if "time" not in k}


@pytest.mark.parametrize("moment", (0.3, 1.5))
@pytest.mark.parametrize("name", list(RESUMED))
def test_killed_then_run_again_succeeds_and_resumes(name, moment, template, tmp_path):
    import numpy as np

    argv = RESUMED[name]
    cmd = argv[0]
    case = Case(f"{name}/kill-then-rerun", argv, "signal", cmd, process=True)
    outcome, problems = _signalled(template, tmp_path, case, signal.SIGKILL, moment)
    problems = [p for p in problems if not p.startswith("ended before the signal")]  # (a fast machine)
    assert outcome.returncode in (0, -signal.SIGKILL), describe(case, outcome, problems)
    work = tmp_path / "w"
    again = run_process(replace(case, id=case.id + "-again"), work, tmp_path)
    problems += status_violations(case, again)
    assert again.returncode == 0, describe(case, again, problems)
    problems += file_violations(case, 0, work, template.entries, snapshot(work), template.grazings)
    assert not problems, describe(case, again, problems)
    out = work / case.outputs()[0]
    if out.suffix == ".zarr":  # resumed: what an uninterrupted run gives
        ref_work = fresh_copy(template.root, tmp_path / "ref")
        ref = run_process(replace(case, id=case.id + "-ref"), ref_work, tmp_path)
        assert ref.returncode == 0, ref.stderr
        got, want = _dataset(out), _dataset(ref_work / out.name)
        assert got.keys() == want.keys()
        for k in want:
            np.testing.assert_array_equal(got[k], want[k], err_msg=k)


# --------------------------------------------------------------------------
# The first compile, the cache folder


def test_ctrl_c_during_the_first_compile(template, tmp_path):
    cache = tmp_path / "cache"
    cache.mkdir()
    case = Case(
        "simulate/ctrl-c-compiling",
        ("simulate", "--transient", "3", "--periods", "3"),
        "signal",
        "simulate",
        process=True,
        env=(("GRAZING_CACHE_DIR", str(cache)),),
    )
    outcome, problems = _signalled(template, tmp_path, case, signal.SIGINT, 5.0)
    assert not problems, describe(case, outcome, problems)
    assert not [p for p in cache.rglob("*") if p.name.startswith(".") or p.suffix == ".tmp"]


def test_a_cache_folder_whose_parents_are_missing(template, tmp_path):
    """``GRAZING_CACHE_DIR`` in a folder that does not exist: not a tree of folders made silently."""
    work = fresh_copy(template.root, tmp_path / "w")
    case = Case(
        "simulate/cache-dir-missing-parents",
        ("simulate", "--transient", "3", "--periods", "3"),
        "env",
        "simulate",
        process=True,
        env=(("GRAZING_CACHE_DIR", str(work / "no" / "such" / "cache")),),
        timeout=300,
    )
    outcome = run_process(case, work, tmp_path)
    problems = status_violations(case, outcome)
    problems += file_violations(
        case, outcome.returncode, work, template.entries, snapshot(work), template.grazings
    )
    assert not problems, describe(case, outcome, problems)


# --------------------------------------------------------------------------
# The explorer's server, sent what no page sends


def _bad_frames(port: int) -> None:
    """Open connections to the explorer and send it garbage: a raw line, a bad HTTP request, a websocket
    upgrade without a key, and frames of junk on an upgraded connection."""
    payloads = [
        b"\x00\xff garbage\r\n\r\n",
        b"GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\r\n",
        b"GET /ws HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nOrigin: http://127.0.0.1:%d\r\nUpgrade: websocket\r\n"
        b"Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
        b"Sec-WebSocket-Protocol: bokeh, nonsense\r\n\r\n"
        % (port, port)
        + bytes([0x81, 0xFE, 0xFF, 0xFF])
        + os.urandom(64)
        + bytes([0x88, 0x80])
        + os.urandom(16),
        b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: -5\r\n\r\n",
    ]
    for data in payloads:
        with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), timeout=5) as s:
            s.sendall(data)
            with contextlib.suppress(OSError):
                s.recv(4096)
    with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), timeout=5) as s:
        s.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")
        page = b""
        while chunk := s.recv(65536):
            page += chunk
    token = re.search(rb'"token":\s*"([^"]+)"', page or b"")
    if token:  # a websocket the page could have opened, sent a frame of junk (masked, as a client must)
        import base64

        key = base64.b64encode(os.urandom(16))
        head = (
            b"GET /ws HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nOrigin: http://127.0.0.1:%d\r\nUpgrade: websocket\r\n"
            b"Connection: Upgrade\r\nSec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n"
            b"Sec-WebSocket-Protocol: bokeh, %s\r\n\r\n" % (port, port, key, token.group(1))
        )
        junk = b"{not json"
        mask = os.urandom(4)
        frame = bytes([0x81, 0x80 | len(junk)]) + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(junk))
        with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), timeout=5) as s:
            s.sendall(head)
            s.recv(4096)
            s.sendall(frame * 3)
            time.sleep(0.5)
            with contextlib.suppress(OSError):
                s.recv(4096)


SERVER_LINE = re.compile(
    r"([A-Z]+:[\w.]+:)?(grazing explore: refused a (request|websocket message) \("
    r"|Failed sending message as connection was closed$|[45]\d\d (GET|POST|HEAD) )"
)
"""A line the explorer's server logs of a request it refused (after the logger's level and name)."""


def test_explorer_given_bad_frames_stays_quiet_and_ends_on_ctrl_c(template, tmp_path):
    pytest.importorskip("panel")
    work = fresh_copy(template.root, tmp_path / "w")
    case = Case("explore/bad-frames", COMMANDS["explore"].argv, "signal", "explore", process=True)
    proc = start(case, work, subprocess.PIPE)
    try:
        line = proc.stdout.readline().decode() if proc.stdout else ""
        port = re.search(r"127\.0\.0\.1:(\d+)", line)
        assert port, line
        _bad_frames(int(port.group(1)))
        time.sleep(1.0)
        assert proc.poll() is None, "the explorer ended"
        os.killpg(proc.pid, signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            stop_group(proc)
    # What the server logs of the requests it refused, one line each (its own, and Tornado's access lines
    # of 4xx answers), then the one line of the Ctrl-C: no traceback.
    lines = err.decode(errors="replace").splitlines(keepends=True)
    served = [x for x in lines if SERVER_LINE.match(x)]
    rest = "".join(x for x in lines if x not in served)
    outcome = Outcome(proc.returncode, line + out.decode(errors="replace"), rest)
    problems = [p for p in status_violations(case, outcome, sent=signal.SIGINT) if "stdout" not in p]
    if proc.returncode != 130:
        problems.append(f"exit {proc.returncode} after Ctrl-C")
    shutil.rmtree(work, ignore_errors=True)
    assert not problems, describe(case, outcome, problems)
