"""Worker processes that die with their parent.

Every process pool grazing starts (sweeps on local cores, the report's
panels, kernel precompilation) runs :func:`init_worker` in each worker.  The
worker then

- asks Linux to kill it when its parent dies (``prctl(PR_SET_PDEATHSIG,
  SIGKILL)``: the parent killed by SIGKILL, the OOM killer or a closed terminal
  takes its workers with it instead of leaving them blocked on a pipe for ever);
- watches its parent's PID from a daemon thread, on every platform (a worker
  whose parent has gone is re-parented, so its parent PID changes), and exits
  within :data:`WATCH_INTERVAL` seconds of the parent's death;
- ignores SIGINT (where the parent stops its workers itself on Ctrl-C): Ctrl-C in
  a terminal reaches the whole process group, and the parent, not each worker,
  decides what to cancel.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time

PR_SET_PDEATHSIG = 1
"""``prctl`` option: the signal a process receives when its parent thread exits (Linux)."""

WATCH_INTERVAL = 0.5
"""Seconds between two looks at the parent's PID."""


def set_parent_death_signal(sig: int = signal.SIGKILL) -> bool:
    """Have the kernel send ``sig`` to this process when its parent dies (Linux only).

    Returns
    -------
    bool
        True if the request was accepted (False elsewhere than Linux).
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        return libc.prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch(parent_pid: int) -> None:
    while True:
        if os.getppid() != parent_pid:
            os._exit(1)
        time.sleep(WATCH_INTERVAL)


def init_worker(parent_pid: int, ignore_sigint: bool = True) -> None:
    """Initializer of every worker process: die with the parent ``parent_pid``; ignore SIGINT.

    Pass it to a pool as ``initializer=init_worker, initargs=(os.getpid(),)``.
    If the parent is already gone when the worker starts, the worker exits at
    once.  ``ignore_sigint=False`` keeps Ctrl-C's default effect, for pools
    whose parent does not stop its workers itself on Ctrl-C.
    """
    if ignore_sigint:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    set_parent_death_signal()
    if os.getppid() != parent_pid:  # the parent died before the request took effect
        os._exit(1)
    threading.Thread(target=_watch, args=(parent_pid,), name="grazing-parent-watch", daemon=True).start()


def stop_pool_processes(executor: object) -> None:
    """Kill the worker processes of a :class:`concurrent.futures.ProcessPoolExecutor` now.

    Used on Ctrl-C and on errors: the chunks in flight are thrown away instead
    of waited for.  (Python 3.14 has ``terminate_workers``; earlier versions
    keep the processes in ``_processes``.)
    """
    kill = getattr(executor, "kill_workers", None)
    if callable(kill):
        kill()
        return
    processes = getattr(executor, "_processes", None) or {}
    for proc in list(processes.values()):
        try:
            proc.kill()
        except (OSError, ValueError, AttributeError):
            pass
