"""The report's folder: grazing's as a whole, marked by a file in it.

A folder is a report folder of grazing's when it holds :data:`MARKER` (a small
hidden JSON file with grazing's mark), which a build writes first.  A build goes
into such a folder, into a new folder, or into an empty folder; any other folder
(a report of a grazing without the marker, a folder of yours) is refused in one
line and left untouched, unless ``overwrite`` is given, which lets the build
replace the files of the report's names in it.  (``grazing report`` makes a new
folder only in an existing one, as every command refuses a missing folder; in
Python, :func:`claim_report_folder` makes the missing parents too.)

Examples
--------
>>> import tempfile, pathlib
>>> root = pathlib.Path(tempfile.mkdtemp())
>>> claim_report_folder(root / "report")
>>> sorted(p.name for p in (root / "report").iterdir())
['.grazing-report']
>>> (root / "mine").mkdir(); _ = (root / "mine" / "index.html").write_text("my page")
>>> check_report_folder(root / "mine")
Traceback (most recent call last):
...
grazing.errors.ForeignFileError: ... exists and is not a report folder of grazing; it was left untouched: ...
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

from grazing.atomic import resolved
from grazing.errors import ForeignFileError
from grazing.outputs import PYTHON_HINT, write_json

MARKER = ".grazing-report"
"""The file that makes a folder a report folder of grazing's."""


def _legacy(folder: Path) -> bool:
    """Whether ``folder`` looks like a report of a grazing that wrote no marker."""
    return (folder / "results").is_dir() and (folder / "comparisons.json").is_file()


def check_report_folder(path: str | Path, *, overwrite: bool = False, hint: str = PYTHON_HINT) -> None:
    """Raise unless a report may be built at ``path`` (read only: nothing is made or changed).

    Raises
    ------
    ForeignFileError
        If ``path`` is a file, or a folder that is neither empty nor a report
        folder of grazing's (and ``overwrite`` is not given).
    """
    shown = Path(path)
    target = resolved(shown)
    if not os.path.lexists(target):
        return
    if not target.is_dir():
        raise ForeignFileError(f"{shown} exists and is not a folder; it was left untouched: name a folder")
    if (target / MARKER).is_file() or overwrite or not any(target.iterdir()):
        return
    legacy = _legacy(target) and " (it looks like a report of an earlier grazing, which left no marker)"
    raise ForeignFileError(
        f"{shown} exists and is not a report folder of grazing{legacy or ''}; it was left untouched: {hint}"
    )


def claim_report_folder(path: str | Path) -> None:
    """Make the folder ``path`` if missing and mark it as grazing's (after :func:`check_report_folder`).

    Where the mark cannot be written (a full disk), the folders this call made are removed again: the
    error says that nothing was written.
    """
    target = resolved(path)
    made = [p for p in (target, *target.parents) if not os.path.lexists(p)]
    target.mkdir(parents=True, exist_ok=True)
    if not (target / MARKER).is_file():
        try:
            write_json(target / MARKER, {"grazing_report": 1}, overwrite=True)
        except BaseException:
            for folder in made:  # (innermost first; each empty: the failed write left nothing)
                with contextlib.suppress(OSError):
                    folder.rmdir()
            raise
