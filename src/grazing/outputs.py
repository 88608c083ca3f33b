"""Files grazing writes: the mark each one carries, the check before one is replaced, and the writers.

Every file grazing writes says so, together with a SHA-256 digest of what it holds:

==========  ===========================================================================
CSV         a last line ``# written by grazing X.Y.Z (sha256 of the lines above: …)``
NetCDF      the global attribute ``written_by``: ``grazing X.Y.Z (sha256 of the file: …)``
PNG         the text chunk ``Software``: ``grazing X.Y.Z (sha256 of the image: …)``
JSON        the key ``written_by``: ``grazing X.Y.Z (sha256 of the other keys: …)``
==========  ===========================================================================

A file is grazing's (:func:`written_by_grazing`) when its mark is there and its
digest matches what the file holds: a file changed after grazing wrote it
(edited by hand, appended to, re-saved by a program that kept the attribute) is
no longer grazing's.  A NetCDF file's digest is of every byte of the file (its
own 64 digits read as zeros), so any change to it counts, however it was made:
an attribute or a group added with h5py, a byte appended.  (A NetCDF file of an
earlier grazing, whose mark covered its data only, is no longer taken for
grazing's: it is refused unless ``overwrite`` is given.)

Before a file is written, :func:`check_replaceable` refuses to replace a file
that is not grazing's, with a one-line :class:`~grazing.errors.ForeignFileError`,
unless ``overwrite`` is given; a file grazing wrote is replaced, and so is any
file in a folder that is grazing's as a whole (a report's folder, inside
:func:`owned_folder`).  A symbolic link
is followed: the file it points to is checked and replaced, never the link.  A
folder, a device or a pipe is never replaced.  Every file is written all at once
(:mod:`grazing.atomic`); a NetCDF file is serialised in memory first and written
with plain file I/O, so that libhdf5 never sees a full disk: a failed write is
one :class:`~grazing.errors.WriteError` and leaves nothing.

The CSV mark is a comment line: numpy's ``loadtxt`` and ``genfromtxt`` skip it
as they are, pandas with ``read_csv(path, comment="#")``, and grazing's
recording reader skips comment lines.

Examples
--------
>>> import tempfile, pathlib
>>> p = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
>>> write_csv(p, lambda fh: fh.write("r,beta\\n0.5,0.01\\n"))
>>> p.read_text().splitlines()[:2], written_by_grazing(p)
(['r,beta', '0.5,0.01'], True)
>>> _ = p.write_text(p.read_text().replace("0.01", "0.02"))  # changed by hand: no longer grazing's
>>> written_by_grazing(p)
False
>>> write_csv(p, lambda fh: fh.write("r,beta\\n"))
Traceback (most recent call last):
...
grazing.errors.ForeignFileError: ... exists and was not written by grazing (or was changed since); ...
"""

from __future__ import annotations

import functools
import hashlib
import io
import json
import os
import re
import stat
import struct
import zlib
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from grazing.atomic import resolved, write_bytes_atomic, write_text_atomic
from grazing.errors import ForeignFileError, WriteError

MARK_KEY = "written_by"
"""The NetCDF global attribute and the JSON key that hold the mark."""

PNG_MARK_KEY = "Software"
"""The PNG text chunk that holds the mark (the standard keyword for the program that made the image)."""

CSV_MARK_PREFIX = "# written by "
"""The start of the last line of a CSV file grazing wrote."""

PYTHON_HINT = "write elsewhere, or pass overwrite=True to replace it"
"""How a refusal ends for a caller in Python (the CLI says ``--overwrite``)."""

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"

COMPRESSION = {"zlib": True, "complevel": 4}
"""The encoding of compressed float variables (:func:`write_netcdf` with ``compress=True``)."""

_MARK = re.compile(r"grazing (\S+) \(sha256 of [a-z ]+: ([0-9a-f]{64})\)")
_MAX_SMALL_FILE = 256 * 2**20
"""JSON and PNG files larger than this are not grazing's (it writes none so large)."""


@functools.cache
def _version() -> str:
    import grazing

    return str(grazing.__version__)


def mark_text(what: str, digest: str) -> str:
    """The mark: ``grazing VERSION (sha256 of WHAT: DIGEST)``.

    Parameters
    ----------
    what
        What the digest is of (``"the lines above"``, ``"the image"`` ...).
    digest
        The SHA-256 digest, 64 hexadecimal digits.

    Returns
    -------
    str
        The mark, with this grazing's version.

    Examples
    --------
    >>> import grazing
    >>> mark_text("the image", "0" * 64) == f"grazing {grazing.__version__} (sha256 of the image: {'0' * 64})"
    True
    """
    return f"grazing {_version()} (sha256 of {what}: {digest})"


def _digest_of_mark(text: Any) -> str | None:
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    m = _MARK.fullmatch(str(text).strip())
    return m.group(2) if m else None


# ----------------------------------------------------------------------------
# Ownership


_OWNED: list[Path] = []
"""Folders that are grazing's as a whole while this process (and the workers it forks) writes them."""


@contextmanager
def owned_folder(root: str | Path) -> Iterator[None]:
    """Within the block, any file under ``root`` may be replaced: ``root`` is grazing's as a whole.

    The caller has checked it (a report's folder).  Workers forked inside the block inherit it.

    Parameters
    ----------
    root
        The folder.

    Yields
    ------
    None
        Inside the ``with`` block, files under ``root`` are replaceable.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> root = Path(tempfile.mkdtemp())
    >>> _ = (root / "old.csv").write_text("a user's file")
    >>> with owned_folder(root):
    ...     check_replaceable(root / "old.csv")  # no error: the folder is grazing's
    >>> check_replaceable(root / "old.csv")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    grazing.errors.ForeignFileError: .../old.csv exists and was not written by grazing ...
    """
    key = Path(root).resolve()
    _OWNED.append(key)
    try:
        yield
    finally:
        _OWNED.remove(key)


def _in_owned_folder(path: Path) -> bool:
    if not _OWNED:
        return False
    here = path.resolve().parent
    return any(here == root or root in here.parents for root in _OWNED)


def written_by_grazing(path: str | Path) -> bool:
    """Whether the file at ``path`` carries grazing's mark and is unchanged since grazing wrote it.

    Anything that cannot be read or parsed, or is no regular file, is not grazing's.

    Parameters
    ----------
    path
        The file (CSV, JSON, PNG or NetCDF, told by its first bytes).

    Returns
    -------
    bool
        True when the mark is there and its digest matches the file.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> path = Path(tempfile.mkdtemp()) / "result.json"
    >>> write_json(path, {"period": 5})
    >>> written_by_grazing(path), written_by_grazing(path.parent), written_by_grazing(path.parent / "none")
    (True, False, False)
    """
    try:
        target = resolved(path)
        if not stat.S_ISREG(os.stat(target).st_mode):  # (a pipe would block the read)
            return False
        with open(target, "rb") as fh:
            head = fh.read(8)
            if head == HDF5_SIGNATURE:
                fh.seek(0)
                return _netcdf_is_ours(fh)
            size = os.fstat(fh.fileno()).st_size
            if head == PNG_SIGNATURE:
                return size <= _MAX_SMALL_FILE and _png_is_ours(head + fh.read())
            if head.lstrip().startswith(b"{"):
                return size <= _MAX_SMALL_FILE and _json_is_ours(head + fh.read())
            return _csv_is_ours(fh, size)
    except Exception:  # unreadable, or not the format its first bytes say: the mark cannot be confirmed
        return False


def check_replaceable(path: str | Path, *, overwrite: bool = False, hint: str = PYTHON_HINT) -> None:
    """Raise :class:`~grazing.errors.ForeignFileError` unless a file may be written at ``path``.

    A file may be written where nothing is, or where grazing's file is (or any
    regular file, with ``overwrite``); a symbolic link is followed.  Never a
    folder, a device or a pipe.  Nothing is modified.

    Parameters
    ----------
    path
        Where the file is to go.
    overwrite
        Replace a regular file that grazing did not write.
    hint
        How the message ends (what the caller can do instead).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> folder = Path(tempfile.mkdtemp())
    >>> check_replaceable(folder / "new.csv")  # nothing there: fine
    >>> check_replaceable(folder)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    grazing.errors.ForeignFileError: ... is a folder; it was left untouched: name a file
    """
    shown = Path(path)
    target = resolved(shown)
    if not os.path.lexists(target):
        return
    if target != shown:
        shown = Path(f"{shown} (a link to {target})")
    try:
        mode = os.stat(target).st_mode
    except OSError as exc:
        raise ForeignFileError(f"{shown} cannot be checked ({exc.strerror}); it was left untouched") from None
    if stat.S_ISDIR(mode):
        raise ForeignFileError(f"{shown} is a folder; it was left untouched: name a file")
    if not stat.S_ISREG(mode):
        raise ForeignFileError(f"{shown} is not a regular file; it was left untouched: name a file")
    if overwrite or _in_owned_folder(target) or written_by_grazing(target):
        return
    raise ForeignFileError(
        f"{shown} exists and was not written by grazing (or was changed since); it was left untouched: {hint}"
    )


# ----------------------------------------------------------------------------
# CSV (and other text tables)


class _HashingWriter:
    """A text file handle that also hashes what is written (as the UTF-8 bytes that reach the file)."""

    def __init__(self, fh: Any):
        self.fh = fh
        self.sha = hashlib.sha256()
        self.last = "\n"

    def write(self, text: str) -> int:
        if text:
            self.sha.update(text.encode("utf-8"))
            self.last = text[-1]
        return self.fh.write(text)


def write_csv(
    path: str | Path, write: Callable[[Any], Any], *, overwrite: bool = False, hint: str = PYTHON_HINT
) -> None:
    """Write a text table through ``write(file_handle)``, all at once, with grazing's mark as its last line.

    ``path`` is checked first (:func:`check_replaceable`).

    Parameters
    ----------
    path
        Where the file goes.
    write
        Called with the open text file; writes the table (``numpy.savetxt``,
        ``csv.writer``, ``fh.write`` ...).
    overwrite
        Replace a regular file that grazing did not write.
    hint
        How a refusal's message ends (what the caller can do instead; the CLI
        names ``--overwrite``).

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from pathlib import Path
    >>> path = Path(tempfile.mkdtemp()) / "table.csv"
    >>> write_csv(path, lambda fh: np.savetxt(fh, [[0.5, 0.01]], delimiter=",", header="r,beta"))
    >>> np.loadtxt(path, delimiter=",").tolist()  # the mark is a comment line
    [0.5, 0.01]
    """
    check_replaceable(path, overwrite=overwrite, hint=hint)
    write_text_atomic(path, lambda fh: write_marked_csv(fh, write))


def write_marked_csv(fh: Any, write: Callable[[Any], Any]) -> None:
    """Write a text table into the open file ``fh`` through ``write(file_handle)``, then grazing's mark.

    Parameters
    ----------
    fh
        An open text file (a temporary file that is then moved into place).
    write
        Called with a handle that writes to ``fh`` and hashes what it writes.

    Examples
    --------
    >>> import io
    >>> fh = io.StringIO()
    >>> write_marked_csv(fh, lambda out: out.write("a,b\\n1,2"))
    >>> fh.getvalue().splitlines()[1], fh.getvalue().splitlines()[2].startswith("# written by grazing")
    ('1,2', True)
    """
    out = _HashingWriter(fh)
    write(out)
    if out.last != "\n":
        out.write("\n")
    fh.write(f"{CSV_MARK_PREFIX}{mark_text('the lines above', out.sha.hexdigest())}\n")


def _csv_is_ours(fh: Any, size: int) -> bool:
    tail_start = max(0, size - 4096)
    fh.seek(tail_start)
    tail = fh.read()
    if not tail.endswith(b"\n"):
        return False
    cut = tail.rfind(b"\n", 0, len(tail) - 1) + 1
    if cut == 0 and tail_start > 0:
        return False  # a last line over 4 kB: not the mark
    last = tail[cut:-1].decode("utf-8", "replace")
    if not last.startswith(CSV_MARK_PREFIX):
        return False
    digest = _digest_of_mark(last[len(CSV_MARK_PREFIX) :])
    if digest is None:
        return False
    sha, left = hashlib.sha256(), tail_start + cut
    fh.seek(0)
    while left > 0:
        block = fh.read(min(left, 2**20))
        if not block:
            return False
        sha.update(block)
        left -= len(block)
    return sha.hexdigest() == digest


# ----------------------------------------------------------------------------
# JSON


def _canonical_json(obj: Any) -> bytes:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=True).encode()


def write_json(
    path: str | Path, obj: Mapping[str, Any], *, overwrite: bool = False, hint: str = PYTHON_HINT
) -> None:
    """Write a JSON object (indented), all at once, with grazing's mark as its last key.

    Parameters
    ----------
    path
        Where the file goes (checked first: :func:`check_replaceable`).
    obj
        The object: JSON's types only.
    overwrite
        Replace a regular file that grazing did not write.
    hint
        How a refusal's message ends (what the caller can do instead; the CLI
        names ``--overwrite``).

    Examples
    --------
    >>> import json, tempfile
    >>> from pathlib import Path
    >>> path = Path(tempfile.mkdtemp()) / "orbit.json"
    >>> write_json(path, {"period": 5, "impacts": 1})
    >>> sorted(json.loads(path.read_text()))
    ['impacts', 'period', 'written_by']
    >>> write_json(path, {"period": 4})  # grazing's own file: replaced
    """
    check_replaceable(path, overwrite=overwrite, hint=hint)
    text = marked_json(obj)
    write_text_atomic(path, lambda fh: fh.write(text))


def marked_json(obj: Mapping[str, Any]) -> str:
    """The text of a JSON object (indented) with grazing's mark as its last key (an earlier mark dropped).

    Parameters
    ----------
    obj
        The object: JSON's types only.

    Returns
    -------
    str
        The indented JSON text, ending in a newline.

    Examples
    --------
    >>> import json
    >>> list(json.loads(marked_json({"period": 5})))
    ['period', 'written_by']
    """
    body = {k: v for k, v in obj.items() if k != MARK_KEY}
    digest = hashlib.sha256(_canonical_json(body)).hexdigest()
    return json.dumps({**body, MARK_KEY: mark_text("the other keys", digest)}, indent=1) + "\n"


def _json_is_ours(data: bytes) -> bool:
    obj = json.loads(data.decode("utf-8"))
    if not isinstance(obj, dict):
        return False
    digest = _digest_of_mark(obj.pop(MARK_KEY, ""))
    return digest is not None and hashlib.sha256(_canonical_json(obj)).hexdigest() == digest


# ----------------------------------------------------------------------------
# PNG


def _png_chunks(data: bytes) -> list[tuple[bytes, bytes]]:
    """The ``(type, payload)`` of every chunk of a PNG file (ValueError if it is not one)."""
    if not data.startswith(PNG_SIGNATURE):
        raise ValueError("not a PNG file")
    chunks, i = [], len(PNG_SIGNATURE)
    while i < len(data):
        if i + 12 > len(data):
            raise ValueError("truncated PNG chunk")
        (length,) = struct.unpack(">I", data[i : i + 4])
        kind, payload = data[i + 4 : i + 8], data[i + 8 : i + 8 + length]
        if len(payload) != length:
            raise ValueError("truncated PNG chunk")
        chunks.append((kind, payload))
        i += 12 + length
        if kind == b"IEND":
            break
    if i != len(data) or not chunks or chunks[-1][0] != b"IEND":
        raise ValueError("not a whole PNG file (bytes after its end, or no end)")
    return chunks


def _is_png_mark(kind: bytes, payload: bytes) -> bool:
    key, sep, text = payload.partition(b"\0")
    ours = kind == b"tEXt" and sep == b"\0" and key == PNG_MARK_KEY.encode()
    return ours and _digest_of_mark(text) is not None


def _png_digest(chunks: list[tuple[bytes, bytes]]) -> str:
    sha = hashlib.sha256()
    for kind, payload in chunks:
        if not _is_png_mark(kind, payload):
            sha.update(kind + struct.pack(">I", len(payload)) + payload)
    return sha.hexdigest()


def _png_chunk(kind: bytes, payload: bytes) -> bytes:
    return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", zlib.crc32(kind + payload))


def _with_text(chunks: list[tuple[bytes, bytes]], key: str, text: str) -> bytes:
    """The PNG file of ``chunks`` with a text chunk ``key`` right after the header."""
    out = [PNG_SIGNATURE]
    for kind, payload in chunks:
        out.append(_png_chunk(kind, payload))
        if kind == b"IHDR":
            out.append(_png_chunk(b"tEXt", f"{key}\0{text}".encode("latin-1")))
    return b"".join(out)


def mark_png(data: bytes) -> bytes:
    """A PNG file's bytes with grazing's mark (a ``Software`` text chunk right after the header).

    Parameters
    ----------
    data
        The bytes of a PNG file (an earlier mark in it is dropped).

    Returns
    -------
    bytes
        The same image, marked.

    Examples
    --------
    >>> import io
    >>> from PIL import Image
    >>> buf = io.BytesIO(); Image.new("RGB", (2, 2)).save(buf, format="png")
    >>> png_text(mark_png(buf.getvalue()), "Software").startswith("grazing ")
    True
    """
    chunks = [c for c in _png_chunks(data) if not _is_png_mark(*c)]
    return _with_text(chunks, PNG_MARK_KEY, mark_text("the image", _png_digest(chunks)))


def _png_is_ours(data: bytes) -> bool:
    chunks = _png_chunks(data)
    marks = [_digest_of_mark(p.partition(b"\0")[2]) for k, p in chunks if _is_png_mark(k, p)]
    return len(marks) == 1 and marks[0] == _png_digest(chunks)


def save_png(
    fig: Any, path: str | Path, *, dpi: float, overwrite: bool = False, hint: str = PYTHON_HINT
) -> Path:
    """Save a matplotlib figure as a PNG with grazing's mark, all at once; return the path.

    The image also records its plot areas (:mod:`grazing.plot_areas`), which
    ``make check-report`` reads.

    Parameters
    ----------
    fig
        The figure.
    path
        Where the file goes (checked first: :func:`check_replaceable`).
    dpi
        Resolution, dots per inch.
    overwrite
        Replace a regular file that grazing did not write.
    hint
        How a refusal's message ends (what the caller can do instead; the CLI
        names ``--overwrite``).

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(2, 1)); _ = fig.add_subplot().plot([0, 1], [1, 0])
    >>> path = save_png(fig, Path(tempfile.mkdtemp()) / "line.png", dpi=50)
    >>> path.name, written_by_grazing(path)
    ('line.png', True)
    """
    from grazing.plot_areas import LAYOUT_KEY, axes_layout, layout_text

    check_replaceable(path, overwrite=overwrite, hint=hint)
    buf = io.BytesIO()
    fig.savefig(buf, dpi=dpi, format="png", metadata={"Software": None})
    data = add_png_text(buf.getvalue(), LAYOUT_KEY, layout_text(axes_layout(fig)))
    write_bytes_atomic(path, mark_png(data))
    return Path(path)


def add_png_text(data: bytes, key: str, text: str) -> bytes:
    """A PNG file's bytes with a text chunk ``key`` (replacing one of that key) right after the header.

    Parameters
    ----------
    data
        The bytes of a PNG file.
    key
        The chunk's keyword (Latin-1).
    text
        Its text (Latin-1).

    Returns
    -------
    bytes
        The same image with the text chunk.

    Examples
    --------
    >>> import io
    >>> from PIL import Image
    >>> buf = io.BytesIO(); Image.new("RGB", (2, 2)).save(buf, format="png")
    >>> png_text(add_png_text(buf.getvalue(), "note", "hello"), "note")
    'hello'
    """
    same_key = key.encode("latin-1") + b"\0"
    chunks = [(k, p) for k, p in _png_chunks(data) if not (k == b"tEXt" and p.startswith(same_key))]
    return _with_text(chunks, key, text)


def png_text(data: bytes, key: str) -> str | None:
    """The text of a PNG file's ``tEXt`` chunk ``key``, or None (ValueError if ``data`` is not a PNG file).

    Parameters
    ----------
    data
        The bytes of a PNG file.
    key
        The chunk's keyword.

    Returns
    -------
    str or None
        The chunk's text; None when the file has no such chunk.

    Examples
    --------
    >>> import io
    >>> from PIL import Image
    >>> buf = io.BytesIO(); Image.new("RGB", (2, 2)).save(buf, format="png")
    >>> png_text(buf.getvalue(), "Software") is None
    True
    >>> png_text(b"not a png", "Software")
    Traceback (most recent call last):
    ...
    ValueError: not a PNG file
    """
    for kind, payload in _png_chunks(data):
        name, sep, text = payload.partition(b"\0")
        if kind == b"tEXt" and sep and name == key.encode("latin-1"):
            return text.decode("latin-1")
    return None


def write_png_bytes(
    path: str | Path, data: bytes, *, overwrite: bool = False, hint: str = PYTHON_HINT
) -> None:
    """Write a PNG image given as bytes (a screenshot...) with grazing's mark, all at once.

    Parameters
    ----------
    path
        Where the file goes (checked first: :func:`check_replaceable`).
    data
        The bytes of a PNG file.
    overwrite
        Replace a regular file that grazing did not write.
    hint
        How a refusal's message ends (what the caller can do instead; the CLI
        names ``--overwrite``).

    Examples
    --------
    >>> import io, tempfile
    >>> from pathlib import Path
    >>> from PIL import Image
    >>> buf = io.BytesIO(); Image.new("RGB", (2, 2)).save(buf, format="png")
    >>> path = Path(tempfile.mkdtemp()) / "shot.png"
    >>> write_png_bytes(path, buf.getvalue())
    >>> written_by_grazing(path), Image.open(path).size
    (True, (2, 2))
    """
    check_replaceable(path, overwrite=overwrite, hint=hint)
    write_bytes_atomic(path, mark_png(data))


# ----------------------------------------------------------------------------
# NetCDF


FILE_DIGEST_WHAT = "the file"
"""What a NetCDF file's mark says its digest is of: the whole file, the digest's own 64 digits as zeros."""

_PLACEHOLDER = b"0" * 64
_FILE_MARK = re.compile(rb"grazing \S+ \(sha256 of the file: ([0-9a-f]{64})\)")


def _file_digest(data: Any, at: int) -> str:
    """SHA-256 of the bytes ``data`` with the 64 bytes from ``at`` (the digest's place) read as zeros."""
    sha = hashlib.sha256()
    with memoryview(data) as view:
        sha.update(view[:at])
        sha.update(_PLACEHOLDER)
        sha.update(view[at + len(_PLACEHOLDER) :])
    return sha.hexdigest()


def _netcdf_is_ours(fh: Any) -> bool:
    """Whether an HDF5 file's bytes hold exactly one mark whose digest is that of the whole file."""
    import mmap

    with mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as data:
        marks = _FILE_MARK.finditer(data)
        first = next(marks, None)
        if first is None or next(marks, None) is not None:  # (two marks: which one would be the file's?)
            return False
        return _file_digest(data, first.start(1)) == first.group(1).decode()


def netcdf_bytes(data: Any, *, compress: bool = False) -> memoryview:
    """A dataset, or ``{group: dataset}``, as the bytes of a NetCDF-4 file with grazing's mark.

    The file is built in memory (h5netcdf on a :class:`io.BytesIO`): libhdf5
    writes nothing to disk.  With ``compress`` every float variable of one or
    more dimensions is compressed (:data:`COMPRESSION`).

    Parameters
    ----------
    data
        An :class:`xarray.Dataset`, or a mapping of group names to datasets.
    compress
        Compress the float variables.

    Returns
    -------
    memoryview
        The file's bytes.

    Examples
    --------
    >>> import io, xarray as xr
    >>> raw = netcdf_bytes(xr.Dataset({"period": ("point", [1, 5])}))
    >>> bytes(raw[:4]), xr.open_dataset(io.BytesIO(raw), engine="h5netcdf").period.values.tolist()
    (b'\\x89HDF', [1, 5])
    """
    import h5py

    groups = {None: data} if hasattr(data, "data_vars") else data  # (a Dataset is a Mapping too)
    buf = io.BytesIO()
    for i, (group, ds) in enumerate(groups.items()):
        enc = {}
        if compress:
            enc = {v: dict(COMPRESSION) for v in ds.data_vars if ds[v].ndim >= 1 and ds[v].dtype.kind == "f"}
        if MARK_KEY in ds.attrs:  # (a dataset read from a file of grazing's: its old mark is not this file's)
            ds = ds.copy(deep=False)
            del ds.attrs[MARK_KEY]
        ds.to_netcdf(buf, mode="w" if i == 0 else "a", group=group, engine="h5netcdf", encoding=enc)
    with h5py.File(buf, "r+") as h5:  # (a variable-length string: its bytes lie as they are in the file)
        h5.attrs[MARK_KEY] = mark_text(FILE_DIGEST_WHAT, _PLACEHOLDER.decode())
    data = buf.getbuffer()
    places = [m.start(1) for m in _FILE_MARK.finditer(data)]
    if len(places) != 1:  # pragma: no cover - a dataset whose own text holds a mark of grazing's
        raise WriteError("the dataset's text holds grazing's mark already; it was not written")
    at = places[0]
    data[at : at + len(_PLACEHOLDER)] = _file_digest(data, at).encode()
    return data


def write_netcdf(
    path: str | Path, data: Any, *, compress: bool = False, overwrite: bool = False, hint: str = PYTHON_HINT
) -> Path:
    """Write a dataset, or ``{group: dataset}``, to a NetCDF file with grazing's mark, all at once.

    ``path`` is checked first (:func:`check_replaceable`); the file is built in
    memory (:func:`netcdf_bytes`) and written with plain file I/O, so a full
    disk is a :class:`~grazing.errors.WriteError` and leaves nothing.

    Parameters
    ----------
    path
        Where the file goes.
    data
        An :class:`xarray.Dataset`, or a mapping of group names to datasets.
    compress
        Compress the float variables (:data:`COMPRESSION`).
    overwrite
        Replace a regular file that grazing did not write.
    hint
        How a refusal's message ends (what the caller can do instead; the CLI
        names ``--overwrite``).

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import tempfile, xarray as xr
    >>> from pathlib import Path
    >>> ds = xr.Dataset({"period": ("point", [1, 5])})
    >>> path = write_netcdf(Path(tempfile.mkdtemp()) / "sweep.nc", {"up": ds, "down": ds})
    >>> written_by_grazing(path), xr.open_dataset(path, group="down").period.values.tolist()
    (True, [1, 5])
    """
    check_replaceable(path, overwrite=overwrite, hint=hint)
    write_bytes_atomic(path, netcdf_bytes(data, compress=compress))
    return Path(path)
