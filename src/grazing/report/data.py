"""Write each figure's data beside its PNG: NetCDF for sweeps and branches, CSV for small tables.

A sweep is written without the angular velocity and with its samples
compressed (``theta`` in radians, one row per swept value, one column per
stroboscopic sample), together with the detected period and the impacts per
period.  Several sweeps of one figure go into one NetCDF file, one group per
panel: ``xarray.open_dataset(path, group="d")``.  The NetCDF files carry
grazing's mark (:mod:`grazing.outputs`), the small CSV tables do not: the
report's folder as a whole is grazing's (:mod:`grazing.report.folder`).

Examples
--------
>>> import tempfile, pathlib
>>> p = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
>>> write_csv(p, ["eta", "period"], [(0.44, 1), (0.45, 5)])
>>> p.read_text().splitlines()
['eta,period', '0.44,1', '0.45,5']
"""

from __future__ import annotations

import csv
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from grazing.atomic import write_text_atomic
from grazing.outputs import write_netcdf


def slim_sweep(ds: Any, **attrs: Any) -> Any:
    """The parts of a sweep dataset worth sharing: θ samples, period, impacts per period.

    Parameters
    ----------
    ds
        A dataset of :func:`grazing.sweeps.sweep` (``samples`` along ``point``, ``sample``,
        ``component``).
    **attrs
        Extra attributes (panel, stop angle, case, ...).
    """
    import xarray as xr

    name = str(ds.attrs.get("params", "value")).split(",")[0]
    out = xr.Dataset(
        {
            "theta": (
                ("point", "sample"),
                np.asarray(ds["samples"].values[:, :, 0], dtype=float),
                {"units": "rad", "long_name": "θ at τ = 2πk (stroboscopic samples)"},
            ),
            "period": (
                "point",
                np.asarray(ds["period"].values, dtype=np.int32),
                {"long_name": "detected period (0: none found, -1: failed)"},
            ),
            "impacts_per_period": ("point", np.asarray(ds["impacts_per_period"].values, dtype=float)),
        },
        coords={name: ("point", np.asarray(ds["value"].values, dtype=float))},
    )
    keep = {k: v for k, v in ds.attrs.items() if isinstance(v, (str, int, float, np.floating, np.integer))}
    out.attrs.update(keep)
    out.attrs.update({k: v for k, v in attrs.items() if v is not None})
    return out


def write_groups(path: Path, groups: Mapping[str, Any]) -> Path:
    """Write datasets as the groups of one NetCDF file (replacing it, all at once), floats compressed."""
    return write_netcdf(path, dict(groups), compress=True)


def write_dataset(path: Path, ds: Any) -> Path:
    """Write one dataset to NetCDF (replacing the file, all at once), float variables compressed."""
    return write_netcdf(path, ds, compress=True)


def write_csv(path: Path, header: Sequence[str], rows: Iterable[Sequence[Any]]) -> None:
    """Write a small table as CSV (numbers with full precision), all at once."""

    def write(fh: Any) -> None:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(header)
        for row in rows:
            w.writerow([repr(float(x)) if isinstance(x, (float, np.floating)) else x for x in row])

    write_text_atomic(path, write)
