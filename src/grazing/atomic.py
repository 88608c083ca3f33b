"""Files written all at once: a temporary next to the target, moved into place on success.

A failed or interrupted write leaves nothing behind (the CLI's promise: bad
input or an error writes no half-file): the temporary is removed and a write
that the system refuses (a full disk, a file-size limit, a read-only folder)
is a :class:`~grazing.errors.WriteError` naming the file, one line.  A
symbolic link is followed: the file it points to is replaced, never the link.
A process killed in the middle of a
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
import errno
import os
import shutil
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import Any

from grazing.clib import libc
from grazing.errors import GrazingError, WriteError


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


def remove_dead_temporaries(folder: str | Path, name: str, suffix: str = ".tmp") -> list[Path]:
    """Remove the temporary files of :func:`atomic_path` for ``name`` in ``folder`` whose process is gone.

    They are named ``.<name>.<pid>-<random><suffix>``: a process killed outright (SIGKILL) while it
    wrote leaves one, which the next write of the same file removes.  Only regular files of that form
    whose process no longer exists are touched.  Returns them.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> dead = d / ".t.csv.999999999-x1y2.tmp"; _ = dead.write_text("")     # (no such process)
    >>> alive = d / f".t.csv.{os.getpid()}-x1y2.tmp"; _ = alive.write_text("")
    >>> mine = d / ".t.csv.notapid.tmp"; _ = mine.write_text("")             # (not of that form)
    >>> [p.name for p in remove_dead_temporaries(d, "t.csv")]
    ['.t.csv.999999999-x1y2.tmp']
    >>> alive.exists(), mine.exists(), dead.exists()
    (True, True, False)
    """
    from grazing.parallel import pid_alive

    prefix = f".{name}."
    removed: list[Path] = []
    try:
        found = [p for p in Path(folder).iterdir() if p.name.startswith(prefix) and p.name.endswith(suffix)]
    except OSError:
        return removed
    for p in found:
        pid = p.name[len(prefix) :].split("-", 1)[0]
        if "-" not in p.name[len(prefix) :] or not pid.isdigit() or pid_alive(int(pid)):
            continue
        with suppress(OSError):
            if p.is_file() and not p.is_symlink():
                p.unlink()
                removed.append(p)
    return removed


def _temporary_folder(path: Path) -> Path:
    """The folder of ``path``'s temporary file: the scratch folder of an enclosing root, else its own."""
    folder = path.parent if str(path.parent) else Path(".")
    if _SCRATCH:
        here = folder.resolve()
        for root, scratch in _SCRATCH.items():
            if here == root or root in here.parents:
                return scratch
    return folder


def resolved(path: str | Path) -> Path:
    """``path`` with its symbolic links followed: the file a write to ``path`` replaces.

    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> (d / "link.csv").symlink_to(d / "data.csv")
    >>> resolved(d / "link.csv") == (d / "data.csv").resolve()
    True
    """
    path = Path(path)
    return Path(os.path.realpath(path)) if os.path.islink(path) else path


def _write_error(path: Path, exc: OSError) -> WriteError:
    reason = exc.strerror or str(exc) or type(exc).__name__
    err = WriteError(f"cannot write {path}: {reason}; nothing was written")
    err.strerror = reason  # (the reason alone, for a caller that names the file otherwise)
    return err


@contextmanager
def atomic_path(path: str | Path, suffix: str = ".tmp") -> Iterator[str]:
    """Yield a temporary file name next to ``path``; move it to ``path`` if the block succeeds.

    The file gets the usual permissions (``0666 & ~umask``; ``mkstemp`` alone
    would leave 0600).  On any exception the temporary file is removed; an
    :class:`OSError` (a full disk...) becomes a :class:`~grazing.errors.WriteError`
    naming ``path``.  A symbolic link at ``path`` is followed (:func:`resolved`):
    its target is replaced.  Inside :func:`scratch_folder` the temporary file is
    in its folder.
    """
    shown = Path(path)
    path = resolved(shown)
    folder = _temporary_folder(path)
    remove_dead_temporaries(folder, path.name, suffix)
    try:
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{path.name}.{os.getpid()}-", suffix=suffix)
    except OSError as exc:
        raise _write_error(shown, exc) from None
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException as exc:
        with suppress(OSError):
            Path(tmp).unlink(missing_ok=True)
        if isinstance(exc, OSError) and not isinstance(exc, GrazingError):
            raise _write_error(shown, exc) from None
        raise


def write_text_atomic(path: str | Path, write: Callable[[Any], Any]) -> None:
    """Write a UTF-8 text file through ``write(file_handle)``, all at once."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        write(fh)


def write_bytes_atomic(path: str | Path, data: bytes | memoryview) -> None:
    """Write ``data`` to ``path`` all at once (plain file I/O: a full disk is a :class:`WriteError`)."""
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)


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
    fn = getattr(libc(), "renameat2", None)  # (None: not Linux, or a C library without it)
    if fn is None:
        return None
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    fn.restype = ctypes.c_int
    return fn
