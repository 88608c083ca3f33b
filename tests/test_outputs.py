"""The files grazing writes: each carries a mark that its content has not changed since, a file without
it is never replaced (unless asked), symbolic links are followed, and a full disk leaves nothing."""

from __future__ import annotations

import hashlib
import io
import json
import os
import re
import struct
import zlib

import numpy as np
import pytest

from grazing.atomic import write_bytes_atomic, write_text_atomic
from grazing.errors import ForeignFileError, WriteError
from grazing.outputs import (
    check_replaceable,
    mark_png,
    owned_folder,
    save_png,
    write_csv,
    write_json,
    write_netcdf,
    written_by_grazing,
)
from tests.processes import with_full_disk


def _dataset(n: int = 5):
    import xarray as xr

    return xr.Dataset(
        {"period": ("point", np.arange(n, dtype=np.int32)), "samples": (("point", "k"), np.ones((n, 3)))},
        coords={"value": ("point", np.linspace(0.4, 0.5, n)), "stop": ["a", "bb"]},
        attrs={"params": "eta", "grazing_version": "0.1.0"},
    )


def _figure():
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 1.5))
    fig.add_subplot().plot([0, 1, 2], [1, 0, 1])
    return fig


def _table(fh) -> None:
    fh.write("r,beta\n")
    np.savetxt(fh, np.column_stack([np.linspace(0.5, 1, 4), np.linspace(0, 0.07, 4)]), delimiter=",")


# A writer of each kind: path -> None (writes the file with grazing's mark, refusing foreign files)
WRITERS = {
    "csv": lambda p, **kw: write_csv(p, _table, **kw),
    "json": lambda p, **kw: write_json(p, {"eta": 0.446, "synthetic": True, "x": [1.5, float("nan")]}, **kw),
    "png": lambda p, **kw: save_png(_figure(), p, dpi=40, **kw),
    "nc": lambda p, **kw: write_netcdf(p, _dataset(), **kw),
    "nc groups": lambda p, **kw: write_netcdf(p, {"a": _dataset(3), "b": _dataset(4)}, compress=True, **kw),
}
SUFFIX = {"csv": ".csv", "json": ".json", "png": ".png", "nc": ".nc", "nc groups": ".nc"}


@pytest.mark.parametrize("kind", WRITERS)
def test_what_grazing_writes_is_its_own_and_is_rewritten(kind, tmp_path):
    path = tmp_path / f"out{SUFFIX[kind]}"
    WRITERS[kind](path)
    assert written_by_grazing(path)
    first = path.read_bytes()
    WRITERS[kind](path)  # no overwrite needed: grazing wrote it
    assert written_by_grazing(path) and sorted(p.name for p in tmp_path.iterdir()) == [path.name]
    assert len(path.read_bytes()) == len(first)


@pytest.mark.parametrize("kind", WRITERS)
def test_a_file_grazing_did_not_write_is_refused_and_left_as_it_was(kind, tmp_path):
    path = tmp_path / f"out{SUFFIX[kind]}"
    path.write_bytes(b"my own notes\n")
    with pytest.raises(ForeignFileError, match=r"out\.\w+ exists and was not written by grazing") as err:
        WRITERS[kind](path)
    assert "\n" not in str(err.value)
    assert path.read_bytes() == b"my own notes\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]  # no temporary left
    WRITERS[kind](path, overwrite=True)
    assert written_by_grazing(path)


def _edit_csv(path):
    text = path.read_text()
    assert "e-01" in text
    path.write_text(text.replace("e-01", "e-02", 1))


def _append_csv(path):
    with open(path, "a") as fh:
        fh.write("0.9,0.01\n")


def _edit_json(path):
    obj = json.loads(path.read_text())
    obj["eta"] = 0.45
    path.write_text(json.dumps(obj))


def _repaint_png(path):
    """Another picture under the same (copied) mark chunk."""
    data = path.read_bytes()
    mark = next(c for c in _chunks(data) if c[0] == b"tEXt")
    buf = io.BytesIO()
    fig = _figure()
    fig.axes[0].plot([0, 1], [0, 0])
    fig.savefig(buf, format="png", dpi=40, metadata={"Software": None})
    chunks = _chunks(buf.getvalue())
    chunks.insert(1, mark)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + b"".join(_chunk(*c) for c in chunks))


def _chunks(data):
    out, i = [], 8
    while i < len(data):
        (n,) = struct.unpack(">I", data[i : i + 4])
        out.append((data[i + 4 : i + 8], data[i + 8 : i + 8 + n]))
        i += 12 + n
    return out


def _chunk(kind, payload):
    return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", zlib.crc32(kind + payload))


def _subset_netcdf(path):
    """What a user does with xarray: a part of grazing's dataset, saved: its attributes come along."""
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as ds:
        part = ds.isel(point=slice(0, 2)).load()
    assert "written_by" in part.attrs
    part.to_netcdf(path, engine="h5netcdf")


def _edit_netcdf_in_place(path):
    import h5py

    with h5py.File(path, "r+") as f:
        f["period"][0] = 99


def _add_attribute_with_h5py(path):
    """The data untouched: a note added (issue 43: the mark covered the data only)."""
    import h5py

    with h5py.File(path, "r+") as f:
        f.attrs["note"] = "checked by hand"


def _change_a_variable_attribute(path):
    import h5py

    with h5py.File(path, "r+") as f:
        f["period"].attrs["long_name"] = "my own name"


def _add_a_group(path):
    import h5py

    with h5py.File(path, "r+") as f:
        f.create_group("mine").attrs["x"] = 1


def _append_a_byte(path):
    with open(path, "ab") as fh:
        fh.write(b"\0")


CHANGES = [
    ("csv", _edit_csv),
    ("csv", _append_csv),
    ("json", _edit_json),
    ("png", _repaint_png),
    ("nc", _subset_netcdf),
    ("nc", _edit_netcdf_in_place),
    ("nc", _add_attribute_with_h5py),
    ("nc", _change_a_variable_attribute),
    ("nc", _add_a_group),
    ("nc", _append_a_byte),
    ("nc groups", _append_a_byte),
]


@pytest.mark.parametrize(("kind", "change"), CHANGES, ids=[c.__name__ for _, c in CHANGES])
def test_a_file_changed_since_grazing_wrote_it_is_no_longer_grazing_s(kind, change, tmp_path):
    path = tmp_path / f"out{SUFFIX[kind]}"
    WRITERS[kind](path)
    change(path)
    assert not written_by_grazing(path)
    before = path.read_bytes()
    with pytest.raises(ForeignFileError, match="or was changed since"):
        WRITERS[kind](path)
    assert path.read_bytes() == before


def test_the_csv_mark_is_read_past_by_numpy_pandas_and_grazing(tmp_path):
    import pandas as pd

    from grazing.experiment.recording import load_recording

    path = tmp_path / "t.csv"
    write_csv(path, _table)
    assert path.read_text().splitlines()[-1].startswith("# written by grazing ")
    expected = np.column_stack([np.linspace(0.5, 1, 4), np.linspace(0, 0.07, 4)])
    np.testing.assert_array_equal(np.loadtxt(path, delimiter=",", skiprows=1), expected)
    named = np.genfromtxt(path, delimiter=",", names=True)
    np.testing.assert_array_equal(named["beta"], expected[:, 1])
    frame = pd.read_csv(path, comment="#")
    assert list(frame.columns) == ["r", "beta"] and frame.shape == (4, 2)
    rec = tmp_path / "rec.csv"
    t = np.arange(40) / 10
    write_csv(rec, lambda fh: fh.write("time,angle\n" + "".join(f"{a},{np.sin(a)}\n" for a in t)))
    np.testing.assert_array_equal(load_recording(rec).time, t)
    # a comment line before the header, as some loggers write, is read past too
    rec.write_text("# logger v2\n" + rec.read_text())
    np.testing.assert_array_equal(load_recording(rec).time, t)


def test_a_png_keeps_a_single_mark_and_reads_as_an_image(tmp_path):
    import matplotlib.image as mpimg

    path = tmp_path / "p.png"
    save_png(_figure(), path, dpi=40)
    data = path.read_bytes()
    assert mark_png(data) == data  # marking again changes nothing (one mark, the same digest)
    assert [k for k, _ in _chunks(data)][:2] == [b"IHDR", b"tEXt"]
    assert mpimg.imread(path).shape[2] == 4


def test_a_netcdf_file_reads_back_with_its_data_and_the_mark(tmp_path):
    import xarray as xr

    path = tmp_path / "s.nc"
    ds = _dataset()
    write_netcdf(path, ds)
    with xr.open_dataset(path, engine="h5netcdf") as back:
        xr.testing.assert_identical(back.drop_attrs(), ds.drop_attrs())
        assert back.attrs["written_by"].startswith("grazing ") and back.attrs["params"] == "eta"
    assert "written_by" not in ds.attrs  # the caller's dataset is not changed
    # the mark's digest is of the whole file, with its own 64 digits as zeros (an independent hash here)
    data = path.read_bytes()
    digest = re.fullmatch(r"grazing \S+ \(sha256 of the file: ([0-9a-f]{64})\)", back.attrs["written_by"])[1]
    assert data.count(digest.encode()) == 1
    assert hashlib.sha256(data.replace(digest.encode(), b"0" * 64)).hexdigest() == digest


# --------------------------------------------------------------------------
# What is never replaced, and links


def test_a_folder_or_a_pipe_is_never_replaced_even_with_overwrite(tmp_path):
    (tmp_path / "d.csv").mkdir()
    os.mkfifo(tmp_path / "f.csv")
    for name, what in (("d.csv", "is a folder"), ("f.csv", "is not a regular file")):
        with pytest.raises(ForeignFileError, match=what):
            check_replaceable(tmp_path / name, overwrite=True)
    assert (tmp_path / "d.csv").is_dir() and not (tmp_path / "f.csv").is_file()


def test_a_symbolic_link_is_followed_and_never_replaced(tmp_path):
    target, link = tmp_path / "data.csv", tmp_path / "link.csv"
    link.symlink_to(target.name)  # dangling: the file it names is made
    write_csv(link, _table)
    assert link.is_symlink() and written_by_grazing(target)
    write_csv(link, lambda fh: fh.write("a\n1\n"))  # grazing's file behind the link: rewritten
    assert link.is_symlink() and target.read_text().startswith("a\n1\n")
    target.write_text("mine\n")
    with pytest.raises(ForeignFileError, match=r"link\.csv \(a link to .*data\.csv\) exists and was not"):
        write_csv(link, _table)
    assert target.read_text() == "mine\n" and link.is_symlink()
    write_csv(link, _table, overwrite=True)
    assert link.is_symlink() and os.readlink(link) == "data.csv" and written_by_grazing(target)
    loop = tmp_path / "loop.csv"
    loop.symlink_to(loop.name)
    with pytest.raises(ForeignFileError, match="cannot be checked"):
        check_replaceable(loop, overwrite=True)
    assert loop.is_symlink()


def test_in_an_owned_folder_any_file_is_replaced(tmp_path):
    (tmp_path / "sub").mkdir()
    path = tmp_path / "sub" / "a.csv"
    path.write_text("an unmarked file of an earlier build\n")
    with pytest.raises(ForeignFileError):
        write_csv(path, _table)
    with owned_folder(tmp_path):
        write_csv(path, _table)
    assert written_by_grazing(path)
    path.write_text("again\n")
    with pytest.raises(ForeignFileError):  # only inside the block
        write_csv(path, _table)


# --------------------------------------------------------------------------
# A full disk: one error, nothing left


BIG = 20_000


def _writes():
    return {
        "text": lambda p: write_text_atomic(p, lambda fh: fh.write("x" * BIG)),
        "bytes": lambda p: write_bytes_atomic(p, b"x" * BIG),
        "csv": lambda p: write_csv(p, lambda fh: fh.write("a\n" * BIG)),
        "png": lambda p: save_png(_figure(), p, dpi=200),
        "netcdf": lambda p: write_netcdf(p, _dataset(2000)),
    }


@pytest.mark.parametrize("kind", list(_writes()))
def test_a_full_disk_is_one_write_error_and_leaves_the_old_file(kind, tmp_path):
    path = tmp_path / "out.dat"
    if kind in ("csv", "png", "netcdf"):
        _writes()[kind](path)  # (a file of grazing's, to be replaced)
    else:
        path.write_text("old\n")
    before = path.read_bytes()
    got = with_full_disk(_writes()[kind], path)
    assert got is not None, "the write was expected to fail"
    name, message = got
    assert name == WriteError.__name__, got
    assert message == f"cannot write {path}: File too large; nothing was written"
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.dat"]  # no temporary left
