"""The package's one pool of worker processes: :func:`map_unordered`, whose workers die with their parent.

Sweeps on local cores, the report's panels and kernel precompilation all run
through :func:`map_unordered`.  It keeps at most a few jobs queued ahead of
the results (so a huge job list is never all in flight), and when the
consumer stops (Ctrl-C, an error) it cancels the queued jobs and kills the
workers at once: the jobs in flight are thrown away, not waited for.  Every
worker runs :func:`init_worker`, and then

- asks Linux to kill it when its parent dies (``prctl(PR_SET_PDEATHSIG,
  SIGKILL)``: the parent killed by SIGKILL, the OOM killer or a closed terminal
  takes its workers with it instead of leaving them blocked on a pipe for ever);
- watches its parent's PID from a daemon thread, on every platform (a worker
  whose parent has gone is re-parented, so its parent PID changes), and exits
  within :data:`WATCH_INTERVAL` seconds of the parent's death;
- ignores SIGINT (where the parent stops its workers itself on Ctrl-C): Ctrl-C in
  a terminal reaches the whole process group, and the parent, not each worker,
  decides what to cancel;
- takes SIGTERM's default action back (the command's handler, which ends it as
  Ctrl-C does, is the parent's).
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from grazing.clib import libc
from grazing.errors import SimulationError

PR_SET_PDEATHSIG = 1
"""``prctl`` option: the signal a process receives when its parent thread exits (Linux)."""

WATCH_INTERVAL = 0.5
"""Seconds between two looks at the parent's PID."""


def pid_alive(pid: int) -> bool:
    """Whether a process with this PID exists on this machine.

    >>> pid_alive(os.getpid())
    True
    """
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def set_parent_death_signal(sig: int = signal.SIGKILL) -> bool:
    """Have the kernel send ``sig`` to this process when its parent dies (Linux only).

    Returns
    -------
    bool
        True if the request was accepted (False elsewhere than Linux).
    """
    lib = libc()
    try:
        return lib is not None and lib.prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0) == 0
    except AttributeError:  # pragma: no cover - a C library without prctl
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
    if signal.getsignal(signal.SIGTERM) != signal.SIG_DFL:  # (the command's own, forked: a pool's end
        signal.signal(signal.SIGTERM, signal.SIG_DFL)  # of its workers by SIGTERM ends them)
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


def in_flight(workers: int) -> int:
    """Jobs submitted ahead of the results: enough to keep ``workers`` busy, few enough to hold."""
    return 2 * max(1, workers) + 2


def map_unordered(
    fn: Callable[[Any], Any],
    jobs: Sequence[Any],
    workers: int,
    *,
    initializer: Callable[..., None] | None = None,
    initargs: tuple[Any, ...] = (),
    start_method: str = "fork",
    ignore_sigint: bool = True,
    first: Sequence[Any] = (),
) -> Iterator[Any]:
    """``fn(job)`` for every job on up to ``workers`` processes, yielded as each finishes.

    ``first`` are jobs run to the end before any of ``jobs`` starts, on the
    same workers (compiling or loading what the jobs need, say, once); their
    results are yielded first.  With one worker (or one job) everything runs
    in this process.  Each worker
    runs ``initializer(parent_pid, *initargs)`` if given (it must call
    :func:`init_worker`), else :func:`init_worker`.  ``start_method`` is
    ``"fork"`` (falls back to spawn where fork does not exist) or ``"spawn"``
    (a fresh interpreter per worker).  With ``ignore_sigint`` the workers leave
    Ctrl-C to this process, which stops them; otherwise Ctrl-C reaches them too.
    A worker killed by the system is reported as one line
    (:class:`~grazing.errors.SimulationError`).

    Examples
    --------
    >>> sorted(map_unordered(abs, [-1, 2, -3], workers=1))
    [1, 2, 3]
    >>> list(map_unordered(abs, [-2], workers=1, first=[-1]))
    [1, 2]
    """
    stages = [list(first), list(jobs)] if len(first) else [list(jobs)]
    n = min(workers, max(len(stage) for stage in stages))
    if n <= 1:
        for job in (job for stage in stages for job in stage):
            yield fn(job)
        return
    import multiprocessing as mp
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    method = start_method if start_method in mp.get_all_start_methods() else "spawn"
    ctx = mp.get_context(method)
    if initializer is None:
        initializer, initargs = init_worker, (os.getpid(), ignore_sigint)
    else:
        initargs = (os.getpid(), *initargs)
    ex = ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=initializer, initargs=initargs)
    pending: set[Any] = set()
    try:
        for stage in stages:
            queue = iter(stage)
            while True:
                for job in queue:
                    pending.add(ex.submit(fn, job))
                    if len(pending) >= in_flight(n):
                        break
                if not pending:
                    break
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for fut in finished:
                    yield fut.result()
    except BaseException as exc:
        stop_pool_processes(ex)  # first: shutdown() forgets the processes
        ex.shutdown(wait=False, cancel_futures=True)
        if isinstance(exc, BrokenProcessPool):
            raise SimulationError(
                "a worker process died (killed by the system: out of memory?); the finished chunks "
                "are kept in a result store (store=): run it again to resume"
            ) from None
        raise
    ex.shutdown(wait=True)
