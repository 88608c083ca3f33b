"""Files written all at once: a temporary next to the target, moved into place on success.

A failed or interrupted write leaves nothing behind (the CLI's promise: bad
input or an error writes no half-file).

>>> import tempfile, pathlib
>>> p = pathlib.Path(tempfile.mkdtemp()) / "x.csv"
>>> write_text_atomic(p, lambda fh: fh.write("a,b\\n"))
>>> p.read_text()
'a,b\\n'
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_path(path: str | Path, suffix: str = ".tmp") -> Iterator[str]:
    """Yield a temporary file name next to ``path``; move it to ``path`` if the block succeeds.

    The file gets the usual permissions (``0666 & ~umask``; ``mkstemp`` alone
    would leave 0600).  On any exception the temporary file is removed.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
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
    """Write a text file through ``write(file_handle)``, all at once."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
        write(fh)
