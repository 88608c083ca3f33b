"""Files written all at once: a temporary next to the target, moved into place on success.

A failed or interrupted write leaves nothing behind (the CLI's promise: bad
input or an error writes no half-file).  A process killed in the middle of a
write (a worker stopped on Ctrl-C) cannot remove its temporary file; inside
:func:`scratch_folder` the temporaries of the files under a folder are made
in a hidden folder of it instead, removed as a whole at the end.

>>> import tempfile, pathlib
>>> p = pathlib.Path(tempfile.mkdtemp()) / "x.csv"
>>> write_text_atomic(p, lambda fh: fh.write("a,b\\n"))
>>> p.read_text()
'a,b\\n'
"""

from __future__ import annotations

import ctypes
import ctypes.util
import errno
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


SCRATCH_PREFIX = ".grazing-partial-"
"""Scratch folders are named ``<prefix><pid>-<random>`` (the PID of the process that made them)."""

_SCRATCH: dict[Path, Path] = {}
"""Folders being written by this process (and the workers it forks): their scratch folders."""


@contextmanager
def scratch_folder(root: str | Path) -> Iterator[Path]:
    """Within the block, temporary files of :func:`atomic_path` for files under ``root`` go to one folder.

    The folder (hidden, in ``root``, made by this call) is removed with all it
    holds when the block ends, however it ends: what workers forked inside the
    block and killed while writing left is removed too, never a file of
    ``root`` itself.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> root = pathlib.Path(tempfile.mkdtemp())
    >>> with scratch_folder(root) as scratch:
    ...     write_text_atomic(root / "a.txt", lambda fh: fh.write("a"))
    ...     scratch.parent == root
    True
    >>> sorted(p.name for p in root.iterdir())
    ['a.txt']
    """
    key = Path(root).resolve()
    remove_stale_scratch(key)
    folder = Path(tempfile.mkdtemp(dir=key, prefix=f"{SCRATCH_PREFIX}{os.getpid()}-"))
    _SCRATCH[key] = folder
    try:
        yield folder
    finally:
        if _SCRATCH.get(key) == folder:
            del _SCRATCH[key]
        shutil.rmtree(folder, ignore_errors=True)


def remove_dead_folders(parent: str | Path, prefix: str, removable: Callable[[Path], bool]) -> list[Path]:
    """Remove the folders ``<prefix><pid>-...`` of ``parent`` whose process is gone, if ``removable``.

    The folders grazing makes beside or inside a user's files carry the PID of
    the process that made them; one whose process no longer exists (killed
    outright) is removed if ``removable(folder)`` says it holds only what
    grazing puts there.  Returns the removed folders.
    """
    from grazing.parallel import pid_alive

    removed: list[Path] = []
    try:
        found = [p for p in Path(parent).iterdir() if p.name.startswith(prefix) and p.is_dir()]
    except OSError:
        return removed
    for folder in found:
        pid = folder.name[len(prefix) :].split("-", 1)[0]
        if not pid.isdigit() or pid_alive(int(pid)) or not removable(folder):
            continue
        shutil.rmtree(folder, ignore_errors=True)
        removed.append(folder)
    return removed


def remove_stale_scratch(root: str | Path) -> list[Path]:
    """Remove the scratch folders of ``root`` left by processes that no longer exist (killed).

    Only folders named like :func:`scratch_folder`'s, whose process is gone and
    that hold nothing but hidden files (temporaries) are removed.  Returns them.
    """
    return remove_dead_folders(
        root, SCRATCH_PREFIX, lambda f: all(p.is_file() and p.name.startswith(".") for p in f.iterdir())
    )


def _temporary_folder(path: Path) -> Path:
    """The folder of ``path``'s temporary file: the scratch folder of an enclosing root, else its own."""
    folder = path.parent if str(path.parent) else Path(".")
    if _SCRATCH:
        here = folder.resolve()
        for root, scratch in _SCRATCH.items():
            if here == root or root in here.parents:
                return scratch
    return folder


@contextmanager
def atomic_path(path: str | Path, suffix: str = ".tmp") -> Iterator[str]:
    """Yield a temporary file name next to ``path``; move it to ``path`` if the block succeeds.

    The file gets the usual permissions (``0666 & ~umask``; ``mkstemp`` alone
    would leave 0600).  On any exception the temporary file is removed.
    Inside :func:`scratch_folder` the temporary file is in its folder.
    """
    path = Path(path)
    folder = _temporary_folder(path)
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{path.name}.", suffix=suffix)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_text_atomic(path: str | Path, write: Callable[[Any], Any]) -> None:
    """Write a UTF-8 text file through ``write(file_handle)``, all at once."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        write(fh)


_AT_FDCWD = -100
_RENAME_NOREPLACE = 1


def rename_noreplace(src: str | Path, dst: str | Path) -> None:
    """Rename ``src`` to ``dst`` only if ``dst`` does not exist, atomically where the system allows.

    On Linux this is ``renameat2(RENAME_NOREPLACE)``: a folder or file that
    appears at ``dst`` meanwhile is never replaced.  Elsewhere ``dst`` is
    checked just before an ordinary rename.

    Raises
    ------
    FileExistsError
        If ``dst`` exists.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> (d / "a").mkdir(); (d / "b").mkdir()
    >>> rename_noreplace(d / "a", d / "c"); sorted(p.name for p in d.iterdir())
    ['b', 'c']
    >>> rename_noreplace(d / "c", d / "b")
    Traceback (most recent call last):
    ...
    FileExistsError: [Errno 17] File exists: ...
    """
    src, dst = os.fsencode(src), os.fsencode(dst)
    fn = _renameat2()
    if fn is not None:
        if fn(_AT_FDCWD, src, _AT_FDCWD, dst, _RENAME_NOREPLACE) == 0:
            return
        err = ctypes.get_errno()
        if err not in (errno.ENOSYS, errno.EINVAL):
            raise OSError(err, os.strerror(err), os.fsdecode(dst))
    if os.path.lexists(dst):
        raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), os.fsdecode(dst))
    os.rename(src, dst)


def _renameat2() -> Any:
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return None
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    fn.restype = ctypes.c_int
    return fn
