"""The end of a ``grazing`` process, without the interpreter's teardown once nothing needs it.

Python's finalisation clears every module and collects their objects: with
numpy, llvmlite and click loaded it takes 15-30 ms (measured 2026-11-26 on
this project's 2-core machine: ``os._exit`` after the same imports, 2-4 ms),
a part of every command that does not run in parallel (issue 29: the serial
part of a sweep) and more than some commands' own work.  Once a command has
returned, nothing of grazing needs it: what it writes is closed before
(atomic writes, stores closed by their context managers), and a store's lock
is released by the operating system with the process (``flock``).

So :func:`quick_exit` does what Python's exit does that matters -- it runs
the handlers registered with :mod:`atexit` (logging, coverage, Dask) and
flushes the standard streams -- and then ends the process with
``os._exit``.  Where another thread that is not a daemon still runs (Python
would wait for it), where the exit handlers cannot be run, or where a stream
cannot be flushed (a closed pipe), it ends as ``sys.exit`` does.
"""

from __future__ import annotations

import atexit
import os
import sys
import threading
from typing import NoReturn


def others_running() -> bool:
    """Whether a thread other than this one, not a daemon, is still running (Python's exit waits for it).

    Examples
    --------
    >>> import time
    >>> worker = threading.Thread(target=time.sleep, args=(0.2,))
    >>> worker.start(); others_running()
    True
    >>> worker.join()
    """
    me = threading.current_thread()
    return any(t is not me and t.is_alive() and not t.daemon for t in threading.enumerate())


def quick_exit(code: int) -> NoReturn:
    """End the process with status ``code`` (see the module): the exit handlers, the streams, then at once."""
    run_handlers = getattr(atexit, "_run_exitfuncs", None)  # (CPython's and PyPy's; else the full exit)
    if run_handlers is None or others_running():
        sys.exit(code)
    run_handlers()
    try:
        for stream in (sys.stdout, sys.stderr):
            if stream is not None:
                stream.flush()
    except (OSError, ValueError):  # (a closed pipe, a closed stream: Python's own exit reports it)
        sys.exit(code)
    os._exit(code)
