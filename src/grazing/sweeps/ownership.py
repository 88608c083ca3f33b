"""Which folders are grazing's sweep stores, and how one comes into being all at once.

A sweep store is a Zarr group whose sub-group ``grazing`` carries grazing's
marker in its attributes (:data:`MARKER`) and holds the store's lock file.
Nothing else is a sweep store: whatever else is found at a store's path (a
Zarr store written by xarray, an empty folder, a file) is refused and never
modified.

A store is built in a hidden folder beside its path (``.NAME.creating-PID-*``):
the marker first, then the lock, then the arrays; the finished folder is then
renamed to the path in one step that never replaces anything.  So a store is
either absent or complete.  A build interrupted by SIGKILL leaves its hidden
folder, which the next creation of the same store removes once its process is
gone.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from grazing.atomic import remove_dead_folders, rename_noreplace
from grazing.errors import ForeignFileError, GrazingError, WriteError
from grazing.sweeps.lock import StoreLock

MARKER_GROUP = "grazing"
"""Sub-group holding the marker (its attributes) and the lock file."""

LOCK_FILE = "lock"
"""The lock file inside :data:`MARKER_GROUP`."""

MARKER_KEY = "grazing_store"
MARKER = {MARKER_KEY: "sweep", "grazing_store_format": 1}
"""The attributes that make a Zarr group a grazing sweep store."""


class ForeignStoreError(ForeignFileError):
    """Something that grazing did not make is at a store's path (it is left untouched)."""


class StoreDamagedError(GrazingError):
    """A grazing store cannot be read (a chunk or its metadata is corrupt or missing)."""


def marker_path(path: str | Path) -> Path:
    """The marker's metadata file of the store at ``path``."""
    return Path(path) / MARKER_GROUP / "zarr.json"


def lock_for(path: str | Path) -> StoreLock:
    """The lock of the store at ``path``."""
    return StoreLock(Path(path) / MARKER_GROUP / LOCK_FILE, str(path))


def check_is_store(path: str | Path) -> None:
    """Raise :class:`ForeignStoreError` unless ``path`` is a grazing sweep store (read only)."""
    path = Path(path)
    if not path.is_dir():
        raise ForeignStoreError(f"{path} exists and is not a grazing sweep store; use another store (store=)")
    meta = marker_path(path)
    if not meta.is_file():
        raise ForeignStoreError(_foreign_message(path))
    try:
        attrs = json.loads(meta.read_text(encoding="utf-8")).get("attributes", {})
    except (OSError, ValueError, AttributeError):
        raise StoreDamagedError(
            f"sweep store {path} is damaged (unreadable marker); delete it (or move it away) and run the "
            "command again to recompute it"
        ) from None
    if not isinstance(attrs, dict) or attrs.get(MARKER_KEY) != MARKER[MARKER_KEY]:
        raise ForeignStoreError(_foreign_message(path))


def _foreign_message(path: Path) -> str:
    legacy = ""
    try:
        root = json.loads((path / "zarr.json").read_text(encoding="utf-8")).get("attributes", {})
        if isinstance(root, dict) and "initialized" in root and "fingerprint" in root:
            legacy = " (it looks like a sweep store of an earlier grazing, which had no ownership marker)"
    except (OSError, ValueError, AttributeError):
        pass
    return (
        f"{path} exists and is not a grazing sweep store{legacy}; it was left untouched: "
        "use another store (store=), or delete it yourself"
    )


def _build_prefix(path: Path) -> str:
    return f".{path.name}.creating-"


def remove_stale_builds(path: str | Path) -> list[Path]:
    """Remove the hidden build folders of ``path`` left by processes that no longer exist.

    Only folders named like grazing's builds, whose process is gone, and that
    hold nothing but a marked (possibly partial) store or nothing at all, are
    removed.  Returns the removed folders.
    """
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    return remove_dead_folders(
        parent, _build_prefix(path), lambda f: not any(f.iterdir()) or marker_path(f).is_file()
    )


def create_store(path: str | Path, build: Callable[[Path], None], marker: dict[str, Any]) -> StoreLock | None:
    """Build a store beside ``path`` and rename it into place; return its lock, held.

    Parameters
    ----------
    path
        Where the store goes (must not exist).
    build
        Writes the store's arrays into the folder it is given.
    marker
        Extra attributes of the marker (the sweep's fingerprint...).

    Returns
    -------
    StoreLock or None
        The store's lock, already held by this process; None if another
        process created a store at ``path`` first (nothing of ours is left).
    """
    import zarr

    path = Path(path)
    remove_stale_builds(path)
    parent = path.parent if str(path.parent) else Path(".")
    tmp = Path(tempfile.mkdtemp(dir=parent, prefix=f"{_build_prefix(path)}{os.getpid()}-"))
    lock = None
    try:
        zarr.open_group(str(tmp / MARKER_GROUP), mode="w-", attributes={**MARKER, **marker})
        lock = StoreLock(tmp / MARKER_GROUP / LOCK_FILE, str(path))
        lock.acquire()  # a fresh file: always free
        build(tmp)
        os.chmod(tmp, 0o777 & ~_umask())
        try:
            rename_noreplace(tmp, path)
        except FileExistsError:
            lock.release()
            shutil.rmtree(tmp, ignore_errors=True)
            return None
    except BaseException as exc:
        if lock is not None:
            lock.release()
        shutil.rmtree(tmp, ignore_errors=True)
        if isinstance(exc, OSError) and not isinstance(exc, GrazingError):  # a full disk
            raise WriteError(
                f"cannot create sweep store {path}: {exc.strerror or exc}; nothing was written"
            ) from None
        raise
    lock.name = str(path)
    lock.path = path / MARKER_GROUP / LOCK_FILE
    return lock


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
