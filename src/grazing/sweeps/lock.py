"""One writer per result store: an advisory lock on a file inside the store.

The lock is ``flock(LOCK_EX)`` on the store's lock file, taken before anything
is written and held until the run ends.  The operating system releases it when
the holder's process dies, however it dies, so a lock left by a dead process
is simply taken over.  The holder writes its PID into the file, so that a
second run can name it.  Forked children (pool workers) close their inherited
copy at once, and the holder unlocks before it closes (a child that has not
run yet still shares the lock): the lock belongs to the process that took it,
not to its workers.

Where the file system does not support ``flock`` (some network file systems),
the lock falls back to the PID in the file: it is taken over only when that
process no longer exists on this machine.
"""

from __future__ import annotations

import errno
import fcntl
import os
import time
from collections.abc import Callable
from pathlib import Path

from grazing.errors import GrazingError
from grazing.parallel import pid_alive

_HELD: set[int] = set()
"""File descriptors of the locks this process holds (closed in forked children)."""


def _close_inherited() -> None:
    for fd in list(_HELD):
        try:
            os.close(fd)
        except OSError:
            pass
    _HELD.clear()


os.register_at_fork(after_in_child=_close_inherited)


class StoreBusyError(GrazingError):
    """Another process is writing the store."""


def read_pid(path: str | Path) -> int | None:
    """The PID written in a lock file, or None."""
    try:
        text = Path(path).read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        return None
    return int(text) if text.isdigit() else None


class StoreLock:
    """The exclusive lock of one store (see the module docstring).

    Parameters
    ----------
    path
        The lock file (created if missing).
    name
        What is locked, for messages (the store's path).
    """

    def __init__(self, path: str | Path, name: str):
        self.path = Path(path)
        self.name = name
        self._fd: int | None = None

    @property
    def held(self) -> bool:
        return self._fd is not None

    def acquire(self, wait: bool = False, on_wait: Callable[[int | None], None] | None = None) -> None:
        """Take the lock, or raise :class:`StoreBusyError` naming the holder.

        Parameters
        ----------
        wait
            Block until the holder is done instead of raising.
        on_wait
            Called once with the holder's PID before blocking.
        """
        if self._fd is not None:
            return
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        try:
            if not self._flock(fd, blocking=False):
                holder = read_pid(self.path)
                if not wait:
                    who = f"PID {holder}" if holder is not None else "a process"
                    raise StoreBusyError(
                        f"{self.name} is being written by another grazing run ({who}); wait for it to "
                        "finish (wait=True) or use another store (store=)"
                    )
                if on_wait is not None:
                    on_wait(holder)
                while not self._flock(fd, blocking=True):  # only without flock: poll the holder's PID
                    time.sleep(0.5)
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
        except BaseException:
            os.close(fd)
            raise
        self._fd = fd
        _HELD.add(fd)

    def _flock(self, fd: int, blocking: bool) -> bool:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | (0 if blocking else fcntl.LOCK_NB))
            return True
        except BlockingIOError:
            return False
        except OSError as exc:
            if exc.errno not in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL):
                raise
        # No flock here: the PID in the file decides.
        holder = read_pid(self.path)
        return holder is None or holder == os.getpid() or not pid_alive(holder)

    def release(self) -> None:
        """Give the lock up (the file stays: it belongs to the store)."""
        if self._fd is None:
            return
        _HELD.discard(self._fd)
        try:
            os.ftruncate(self._fd, 0)
        except OSError:
            pass
        try:  # (unlocked, not only closed: a child forked a moment ago may not yet have closed its copy)
            fcntl.flock(self._fd, fcntl.LOCK_UN)
        except OSError:
            pass
        os.close(self._fd)
        self._fd = None

    def __del__(self) -> None:
        self.release()
