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
