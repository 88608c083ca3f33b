"""Process-tree helpers of the tests (Linux ``/proc``): who are a process's descendants, are they gone."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable


def _stat(pid: int) -> list[str] | None:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            text = fh.read()
    except (FileNotFoundError, ProcessLookupError):
        return None
    # the command name (field 2) is in parentheses and may hold spaces
    return [text[: text.index(" ")], "comm", *text[text.rindex(")") + 2 :].split()]


def alive(pid: int) -> bool:
    """Running (not gone, not a zombie waiting to be reaped)."""
    st = _stat(pid)
    return st is not None and st[2] not in ("Z", "X")


def descendants(pid: int) -> set[int]:
    """PIDs of the living descendants of ``pid``."""
    children: dict[int, list[int]] = {}
    for name in os.listdir("/proc"):
        if name.isdigit():
            st = _stat(int(name))
            if st is not None and st[2] not in ("Z", "X"):
                children.setdefault(int(st[3]), []).append(int(name))
    out: set[int] = set()
    todo = [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            if c not in out:
                out.add(c)
                todo.append(c)
    return out


def wait_until(cond: Callable[[], bool], limit: float = 120.0, step: float = 0.05) -> bool:
    """Poll ``cond`` until it holds (a bound against hanging, not a timing requirement)."""
    end = time.monotonic() + limit
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(step)
    return cond()


def all_gone(pids: Iterable[int], limit: float = 60.0) -> bool:
    """Whether every process of ``pids`` is gone (zombies count as gone) within ``limit`` seconds."""
    pids = list(pids)
    return wait_until(lambda: not any(alive(p) for p in pids), limit)


def limit_file_size(limit: int) -> None:
    """In this process: no file may grow past ``limit`` bytes, and a write past it fails with EFBIG
    (SIGXFSZ ignored) -- a full disk, as a test without root can make one."""
    import resource
    import signal

    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))


def _limited_child(limit: int, fn: Callable[..., object], args: tuple, results: object) -> None:
    limit_file_size(limit)
    try:
        fn(*args)
    except BaseException as exc:  # reported to the parent: the test judges it
        results.put((type(exc).__name__, str(exc)))  # type: ignore[attr-defined]
    else:
        results.put(None)  # type: ignore[attr-defined]


def with_full_disk(fn: Callable[..., object], *args: object, limit: int = 4096) -> tuple[str, str] | None:
    """Run ``fn(*args)`` in a forked child whose files cannot grow past ``limit`` bytes.

    Returns None if it returned, else ``(exception class name, message)``; the
    child's exit code must be 0 (it did not crash).
    """
    import multiprocessing as mp

    ctx = mp.get_context("fork")
    results = ctx.Queue()
    child = ctx.Process(target=_limited_child, args=(limit, fn, args, results))
    child.start()
    got = results.get(timeout=300)
    child.join(60)
    assert child.exitcode == 0, child.exitcode
    return got  # type: ignore[no-any-return]
