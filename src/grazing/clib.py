"""The C library of this process, for the few calls Python does not offer (``renameat2``, ``prctl``)."""

from __future__ import annotations

import ctypes
import functools
import sys


@functools.cache
def libc() -> ctypes.CDLL | None:
    """The C library, with ``errno`` kept (``ctypes.get_errno``); None elsewhere than Linux or if not found.

    ``ctypes.util`` is imported here, not at a module's top: it imports
    ``subprocess`` and ``shutil``, a few milliseconds of every command's start.

    Examples
    --------
    >>> lib = libc()
    >>> lib is None or hasattr(lib, "getpid")
    True
    """
    if not sys.platform.startswith("linux"):
        return None
    import ctypes.util

    try:
        return ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
    except OSError:  # pragma: no cover - a Linux without a C library to load
        return None
