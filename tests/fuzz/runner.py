"""One fuzz case run: in this process (through :func:`grazing.cli.main`) or as a process of its own."""

from __future__ import annotations

import contextlib
import io
import os
import signal
import subprocess
import sys
import time
import traceback
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from tests.fuzz.cases import Case
from tests.processes import limit_file_size

CONSOLE = [sys.executable, "-c", "from _grazing_entry import console; console()"]
"""The ``grazing`` console script (pyproject.toml's entry point)."""

MODULE = [sys.executable, "-m", "grazing"]

MEMORY_LIMIT = 4 * 2**30
"""Address space of a case's process (a command that would allocate without bound fails instead of
taking the machine's memory)."""

HEAD_BYTES = 100
"""How much of the output a ``head`` reader reads before it closes the pipe."""


@dataclass
class Outcome:
    """What a run did: its exit status (negative: killed by that signal), its output and error text, an
    exception that escaped :func:`grazing.cli.main` (in this process), and whether it hung."""

    returncode: int
    stdout: str
    stderr: str
    escaped: str | None = None
    hung: bool = False
    sent: int | None = None
    """The signal the test sent the process (a case's ``interrupt_after``), if it did."""
    stdout_read: bool = True
    """Whether ``stdout`` holds all the command wrote (not for a closed pipe, /dev/full, ...)."""
    seconds: float = 0.0


class CaseTimeout(BaseException):
    """The case ran past its time (raised in this process by a timer)."""


class ServedError(Exception):
    """``explore`` passed every check and would serve its page now (in this process: not served)."""


@contextlib.contextmanager
def _environment(env: tuple[tuple[str, str], ...]) -> Iterator[None]:
    saved = {k: os.environ.get(k) for k, _ in env}
    os.environ.update(dict(env))
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


@contextlib.contextmanager
def _time_limit(seconds: float) -> Iterator[None]:
    def expired(*_args: object) -> None:
        raise CaseTimeout

    old = signal.signal(signal.SIGALRM, expired)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def _show_on_stderr(message, category, filename, lineno, file=None, line=None) -> None:
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


def _serve_stub(*_args: object, **_kwargs: object) -> None:
    raise ServedError


def run_in_process(case: Case, cwd: Path) -> Outcome:
    """Run ``case`` through :func:`grazing.cli.main` in ``cwd`` (``explore``'s server stubbed)."""
    import grazing.explore.server as server
    from grazing.cli import main

    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    start = time.perf_counter()
    escaped, hung, code = None, False, 0
    real_serve = server.serve
    server.serve = _serve_stub
    os.chdir(cwd)
    try:
        with _environment(case.env), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            with warnings.catch_warnings(), _time_limit(case.timeout):
                warnings.simplefilter("always")  # (on stderr, as a process shows them; not pytest's record)
                warnings.showwarning = _show_on_stderr
                code = main(list(case.argv))
    except ServedError:
        code = 0
    except CaseTimeout:
        hung = True
        code = -1
    except BaseException:  # the command let it escape: what the test reports
        escaped = traceback.format_exc()
        code = -1
    finally:
        os.chdir(here)
        server.serve = real_serve
    return Outcome(
        code, out.getvalue(), err.getvalue(), escaped, hung, None, True, time.perf_counter() - start
    )


def _preexec(fsize: int | None) -> Callable[[], None]:
    def setup() -> None:
        import resource

        signal.signal(signal.SIGINT, signal.SIG_DFL)  # (a test runner's worker may ignore it)
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
        if fsize is not None:
            limit_file_size(fsize)

    return setup


def process_env(case: Case) -> dict[str, str]:
    """The environment of ``case``'s process: this one's (its PYTHONPATH: this tree), and the case's."""
    import grazing

    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONUNBUFFERED", "COLUMNS")}
    src = str(Path(grazing.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([src, env.get("PYTHONPATH", "")])
    env.update(dict(case.env))
    return env


def start(case: Case, cwd: Path, stdout: int | None) -> subprocess.Popen:
    """Start ``case`` as a process in ``cwd``, in a session of its own, its output to ``stdout``."""
    argv = [*(CONSOLE if case.entry == "console" else MODULE), *case.argv]
    return subprocess.Popen(
        argv,
        cwd=cwd,
        env=process_env(case),
        stdin=subprocess.DEVNULL,
        stdout=stdout,
        stderr=subprocess.PIPE,
        start_new_session=True,
        preexec_fn=_preexec(case.fsize),
    )


def stop_group(proc: subprocess.Popen) -> None:
    """Kill ``proc``'s process group (a case that hung) and reap it."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()


def _head(fd: int, deadline: float) -> bytes:
    """Read up to :data:`HEAD_BYTES` from ``fd`` (to its end if it holds fewer), then close it."""
    import select

    out = b""
    try:
        while len(out) < HEAD_BYTES and time.monotonic() < deadline:
            ready, _, _ = select.select([fd], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                break
            chunk = os.read(fd, HEAD_BYTES - len(out))
            if not chunk:
                break
            out += chunk
    finally:
        os.close(fd)
    return out


SERVING = b"http://127.0.0.1:"
"""What ``explore`` prints on its standard output once it serves its page (then it serves until Ctrl-C)."""


def serves(case: Case) -> bool:
    """Whether ``case``, run as a process, may start a server that runs until Ctrl-C (``explore``: in this
    process, its server is stubbed instead; as a process, a valid call serves, by design, and gets a
    Ctrl-C once it says so: it must then end as after any Ctrl-C, 130 and one line)."""
    return case.command == "explore" and case.stdout == "pipe"


def _until_served(fd: int, deadline: float) -> tuple[bytes, bool]:
    """What ``fd`` gives until the serving line (or its end, or ``deadline``); whether it came."""
    import select

    out = b""
    while SERVING not in out and time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], max(0.0, deadline - time.monotonic()))
        if not ready:
            break
        chunk = os.read(fd, 4096)
        if not chunk:
            break
        out += chunk
    return out, SERVING in out


def run_process(case: Case, cwd: Path, scratch: Path) -> Outcome:
    """Run ``case`` as a process in ``cwd``; ``scratch`` (outside ``cwd``) holds its output file."""
    t0 = time.perf_counter()
    read_all = case.stdout in ("pipe", "file")
    target: int | None
    reader = None
    if case.stdout == "pipe":
        target = subprocess.PIPE
    elif case.stdout in ("closed", "head"):
        reader, target = os.pipe()
        if case.stdout == "closed":
            os.close(reader)
            reader = None
    elif case.stdout == "full":
        target = os.open("/dev/full", os.O_WRONLY)
    else:
        target = os.open(scratch / "stdout.txt", os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    try:
        proc = start(case, cwd, target)
    finally:
        if isinstance(target, int) and target != subprocess.PIPE:
            os.close(target)
    hung = False
    out = b""
    try:
        if reader is not None:  # read 100 bytes (or to the end, if there are fewer), then close
            out = _head(reader, time.monotonic() + case.timeout)
            reader = None
        sent = None
        if serves(case) and proc.stdout is not None:
            wait = case.interrupt_after if case.interrupt_after is not None else case.timeout
            out, served = _until_served(proc.stdout.fileno(), time.monotonic() + wait)
            if served and proc.poll() is None:
                sent = signal.SIGINT
                os.killpg(proc.pid, signal.SIGINT)
        if case.interrupt_after is not None and sent is None:
            try:
                proc.wait(timeout=case.interrupt_after)
            except subprocess.TimeoutExpired:
                sent = signal.SIGINT
                os.killpg(proc.pid, signal.SIGINT)
        got_out, got_err = proc.communicate(timeout=case.timeout)
    except subprocess.TimeoutExpired:
        hung = True
        stop_group(proc)
        got_out, got_err = b"", proc.stderr.read() if proc.stderr else b""
    finally:
        if reader is not None:
            os.close(reader)
    if case.stdout == "pipe":
        out += got_out or b""
    elif case.stdout == "file":
        out = (scratch / "stdout.txt").read_bytes()
    return Outcome(
        proc.returncode if not hung else -9,
        out.decode(errors="replace"),
        got_err.decode(errors="replace"),
        None,
        hung,
        sent,
        read_all,
        time.perf_counter() - t0,
    )
