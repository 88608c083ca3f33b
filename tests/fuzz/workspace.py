"""The folder every fuzz case runs in: a user's files of every kind, grazing's own files, model files.

:func:`build_template` makes it once; each case runs in a fresh copy (:func:`fresh_copy`), and
:func:`snapshot` records every path's kind, bytes (SHA-256), mode and link target before and after.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import os
import shutil
import stat
from dataclasses import dataclass
from pathlib import Path

from tests.fuzz.cases import SWEEP

MODEL_BODY = """
import sympy as sp
import grazing

x, v, t, w, r = sp.symbols("x v t w r")


def model(term=sp.tanh(x) + sp.atan(v) / 10, r_default=0.8, contact=True):
    params = [grazing.Parameter("w", 1.2, lower=0, lower_open=True),
              grazing.Parameter("r", r_default, lower=0, upper=1)]
    field = [v, -0.1 * v - term + sp.cos(w * t)]
    extra = {"contact_direction": [0, 1]} if contact else {}
    return grazing.HybridModel("user", [x, v], t, params, vector_field=field, guard=0.5 - x,
                               reset=[x, -r * v], period=2 * sp.pi / w, **extra)
"""
"""A user model (a forced oscillator with one stop), the base of the model files."""

PRINTED_BY_MODEL = "hello from a model file"
"""What ``prints.py`` prints when it is loaded (on stderr: stdout stays clean for ``--json``)."""

MODEL_FILES: dict[str, str] = {
    "smooth.py": MODEL_BODY,
    "prints.py": f'print("{PRINTED_BY_MODEL}")\n' + MODEL_BODY,
    "nocd.py": MODEL_BODY + "\nnocd = lambda: model(contact=False)\n",
    "nonsmooth.py": MODEL_BODY + "\nabs_model = lambda: model(sp.Abs(x))\n",
    "baddefault.py": MODEL_BODY + "\nbad = model(r_default=1.5)\n",
    "exits.py": 'import sys\nprint("bye")\nsys.exit(0)\n',
    "exitstr.py": 'import sys\nsys.exit("bye")\n',
    "syntax.py": "def model(:\n",
    "raises.py": 'raise ValueError("not today")\n',
    "callraises.py": "def model():\n    return 1 / 0\n",
    "recursion.py": "def model():\n    return model()\n",
    "notmodel.py": "model = 42\n",
    "base.py": 'raise BaseException("boom")\n',
    "basecall.py": 'def model():\n    raise BaseException("in the call")\n',
    "genexit.py": "raise GeneratorExit\n",
    "kbi.py": "raise KeyboardInterrupt\n",
}
"""Model files: good ones, and every way a user's file can fail (``name.py`` -> its text)."""


def _recording_files(root: Path) -> None:
    from grazing.experiment.synthetic import synthetic_recording, synthetic_sweep, write_recording

    rec = synthetic_recording(0.446, 40.0, periods=12, transient=50, sample_rate=100.0)
    write_recording(rec, root / "rec.csv")
    synthetic_sweep(root / "folder", 40.0, [0.43, 0.446], periods=10, transient=10, sample_rate=100.0)
    huge = "x" * 140_000  # over the csv module's 128 kB field limit
    (root / "big.csv").write_text("time,angle\n0,0.1\n0.1," + huge + "\n")
    (root / "empty.csv").write_text("")
    (root / "header.csv").write_text("time,angle\n")
    (root / "nanrec.csv").write_text("time,angle\n" + "".join(f"{k / 10},nan\n" for k in range(50)))
    (root / "garbage.csv").write_bytes(bytes(range(256)) * 4)
    bad = root / "forty"
    shutil.copytree(root / "folder", bad)
    for side in bad.glob("*.json"):
        side.write_text(side.read_text().replace('"theta_hat_deg": 40.0', '"theta_hat_deg": "forty"'))


def _users_files(root: Path) -> None:
    """Files grazing did not write, where outputs go: every kind a user may have there."""
    (root / "notes.csv").write_text("my,notes\n1,2\n")
    (root / "mine.nc").write_bytes(b"my data")
    (root / "mine.png").write_bytes(b"my picture")
    (root / "keep.csv").write_text("mine\n")
    (root / "keep.json").write_text('{"mine": 1}\n')
    (root / "random.bin").write_bytes(hashlib.sha256(b"fuzz").digest() * 64)
    for name in ("readonly.csv", "readonly.nc", "readonly.png"):
        (root / name).write_bytes(b"read only")
        (root / name).chmod(0o444)
    for name in ("adir.csv", "adir.nc", "adir.png", "adir.zarr"):
        (root / name).mkdir()
        (root / name / "inside.txt").write_text("mine\n")
    (root / "user.zarr").mkdir()
    (root / "user.zarr" / ".zgroup").write_text('{"zarr_format": 2}\n')
    (root / "myreport").mkdir()
    (root / "myreport" / "index.html").write_text("<p>my page</p>\n")
    (root / "emptydir").mkdir()
    for suffix, target in ((".nc", "mine.nc"), (".csv", "notes.csv"), (".png", "mine.png")):
        (root / f"link{suffix}").symlink_to(target)
        (root / f"dangling{suffix}").symlink_to(f"gone{suffix}")


def _grazings_files(root: Path) -> None:
    """Files grazing wrote (replaceable without --overwrite), and copies of them a user edited (not)."""
    from grazing.cli import main

    runs = [
        [*SWEEP, "--out", "ours.nc"],
        [*SWEEP, "--out", "ours.zarr"],
        ["simulate", "--transient", "3", "--periods", "3", "--trajectory", "ours.csv"],
        ["analyze", "rec.csv", "--plot", "ours.png"],
    ]
    here = os.getcwd()
    os.chdir(root)
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
            for argv in runs:
                assert main(argv) == 0, (argv, err.getvalue())
    finally:
        os.chdir(here)
    import xarray as xr

    with xr.open_dataset(root / "ours.nc") as ds:  # re-saved by a program that kept the attributes
        edited = ds.load()
    first = next(iter(edited.data_vars))
    edited[first] = edited[first] * 0 + 1
    edited.to_netcdf(root / "edited.nc")
    shutil.copy(root / "ours.nc", root / "edited-attrs.nc")  # (only an attribute: a note of the user's)
    import h5py

    with h5py.File(root / "edited-attrs.nc", "r+") as h5:
        h5.attrs["note"] = "my note"
    (root / "edited.csv").write_bytes((root / "ours.csv").read_bytes() + b"1,2\n")
    (root / "edited.png").write_bytes((root / "ours.png").read_bytes() + b"\0")


def build_template(root: Path) -> Path:
    """Make the case template in ``root`` (an empty folder); returns ``root``."""
    root.mkdir(parents=True, exist_ok=True)
    for name, text in MODEL_FILES.items():
        (root / name).write_text(text)
    (root / "adir.py").mkdir()
    _recording_files(root)
    _users_files(root)
    _grazings_files(root)
    return root


def fresh_copy(template: Path, dest: Path) -> Path:
    """A copy of ``template`` at ``dest`` (links copied as links, modes kept)."""
    shutil.copytree(template, dest, symlinks=True)
    return dest


@dataclass(frozen=True)
class Entry:
    """One path of a snapshot: its kind, and its bytes' digest, link target or mode."""

    kind: str  # "file", "dir", "link", "other"
    digest: str = ""
    mode: int = 0


def snapshot(root: Path) -> dict[str, Entry]:
    """Every path under ``root`` (hidden ones too; links not followed) -> :class:`Entry`."""
    out: dict[str, Entry] = {}
    for folder, dirs, files in os.walk(root):
        for name in dirs + files:
            path = Path(folder) / name
            rel = str(path.relative_to(root))
            st = path.lstat()
            if stat.S_ISLNK(st.st_mode):
                out[rel] = Entry("link", os.readlink(path))
            elif stat.S_ISDIR(st.st_mode):
                out[rel] = Entry("dir", "", stat.S_IMODE(st.st_mode))
            elif stat.S_ISREG(st.st_mode):
                out[rel] = Entry(
                    "file", hashlib.sha256(path.read_bytes()).hexdigest(), stat.S_IMODE(st.st_mode)
                )
            else:
                out[rel] = Entry("other")
    return out


def grazings(root: Path, entries: dict[str, Entry]) -> set[str]:
    """The files of ``entries`` that grazing wrote (its mark, unchanged since)."""
    from grazing.outputs import written_by_grazing

    return {rel for rel, e in entries.items() if e.kind == "file" and written_by_grazing(root / rel)}
