"""Where sweep results go: memory, or a resumable Zarr store.

The Zarr store is created with every variable filled with NaN, chunked along
``point`` exactly like the sweep, and a ``chunk_done`` flag per chunk.  Each
finished chunk writes its region, *then* sets its flag; a run killed at any
moment leaves at most one chunk without its flag, and re-running the same
command recomputes only the chunks whose flag is unset.  A store made with a
different sweep (other parameters, values, transient...) is refused.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np

from grazing.errors import GrazingError, InvalidParameterError
from grazing.sweeps.brute_force import ChunkResult, SweepSpec, spec_summary


class StoreMismatchError(GrazingError, ValueError):
    """An existing result store was made by a different sweep."""


def _empty_arrays(spec: SweepSpec) -> dict[str, np.ndarray]:
    n, m, p = spec.model.n_states, spec.periods, spec.n_points
    return {
        "samples": np.full((p, m, n), np.nan),
        "period": np.full(p, -1, dtype=np.int32),
        "impacts": np.full(p, -1, dtype=np.int32),
        "lyapunov": np.full(p, np.nan),
        "transient_used": np.full(p, -1, dtype=np.int32),
        "x_final": np.full((p, n), np.nan),
    }


def build_dataset(spec: SweepSpec, arrays: dict[str, np.ndarray], attrs: dict[str, Any] | None = None) -> Any:
    """The xarray Dataset of a sweep from its flat per-point arrays."""
    import xarray as xr

    pts = np.asarray(spec.points, dtype=float)
    period = arrays["period"]
    impacts = arrays["impacts"]
    with np.errstate(invalid="ignore", divide="ignore"):
        ipp = np.where(impacts >= 0, impacts / spec.periods * np.maximum(period, 1), np.nan)
    data = {
        "samples": (("point", "sample", "component"), arrays["samples"]),
        "period": ("point", period),
        "impacts": ("point", impacts),
        "impacts_per_period": ("point", ipp),
        "lyapunov": ("point", arrays["lyapunov"]),
        "transient_used": ("point", arrays["transient_used"]),
        "x_final": (("point", "component"), arrays["x_final"]),
    }
    coords: dict[str, Any] = {
        "component": list(spec.model.state_names),
        "sample": np.arange(spec.periods),
    }
    for j, name in enumerate(spec.params):
        coords[name] = ("point", pts[:, j])
    if len(spec.params) == 1:
        coords["value"] = ("point", pts[:, 0])
    ds = xr.Dataset(data, coords=coords)
    ds["period"].attrs["description"] = (
        "smallest p <= 64 with the samples p-periodic to 1e-6; 0 none; -1 failed"
    )
    ds["impacts_per_period"].attrs["description"] = (
        "impacts per period p of the detected orbit (per forcing period when p = 0)"
    )
    ds["lyapunov"].attrs["description"] = (
        "largest Lyapunov exponent per unit time (nan: not computed / sticking)"
    )
    summary = spec_summary(spec)
    ds.attrs.update(
        {
            "spec": json.dumps(summary, sort_keys=True),
            "fingerprint": summary["fingerprint"],
            "params": ",".join(spec.params),
            "model": spec.model.name,
            "grazing_version": summary["grazing_version"],
        }
    )
    for k, v in spec.model.params.items():
        if k not in spec.params:
            ds.attrs[f"param_{k}"] = v
    ds.attrs.update(attrs or {})
    if len(spec.shape) == 2:
        n2, n1 = spec.shape
        p1, p2 = spec.params
        ds = ds.assign_coords(
            {
                p1 + "_index": ("point", np.tile(np.arange(n1), n2)),
                p2 + "_index": ("point", np.repeat(np.arange(n2), n1)),
            }
        )
        ds = ds.set_index(point=[p2 + "_index", p1 + "_index"]).unstack("point")
        ds = ds.assign_coords({p1: (p1 + "_index", pts[:n1, 0]), p2: (p2 + "_index", pts[::n1, 1])})
        ds = ds.swap_dims({p1 + "_index": p1, p2 + "_index": p2}).drop_vars([p1 + "_index", p2 + "_index"])
    return ds


class MemoryStore:
    """Results kept in memory."""

    def __init__(self, spec: SweepSpec, attrs: dict[str, Any] | None = None):
        self.spec = spec
        self.arrays = _empty_arrays(spec)
        self.done = np.zeros(spec.n_chunks, dtype=bool)
        self.attrs = attrs or {}

    def is_done(self, i: int) -> bool:
        return bool(self.done[i])

    def write(self, res: ChunkResult) -> None:
        sl = self.spec.chunk(res.index)
        for key in self.arrays:
            self.arrays[key][sl] = getattr(res, key)
        self.done[res.index] = True

    def dataset(self) -> Any:
        return build_dataset(self.spec, self.arrays, self.attrs)


class ZarrStore:
    """A resumable Zarr store for one sweep (see the module docstring).

    Parameters
    ----------
    path
        Directory of the store (``*.zarr``).
    spec
        The sweep; an existing store must have been made by the same sweep.
    attrs
        Extra attributes (for example the command line).
    """

    def __init__(self, path: str | Path, spec: SweepSpec, attrs: dict[str, Any] | None = None):
        import zarr

        self.path = Path(path)
        self.spec = spec
        self.attrs = attrs or {}
        if self.path.exists():
            try:
                group = zarr.open_group(str(self.path), mode="r")
                stored = dict(group.attrs)
            except Exception:  # not a Zarr store, or a creation that was interrupted
                stored = {}
            if not stored.get("initialized"):
                if (self.path / "zarr.json").exists() or not any(self.path.iterdir()):
                    shutil.rmtree(self.path)  # an interrupted creation: nothing computed yet
                else:
                    raise InvalidParameterError(f"{self.path} exists and is not a grazing sweep store")
            else:
                self._check_same(stored)
        if not self.path.exists():
            self._create()
        self._done = np.asarray(zarr.open_array(str(self.path / "chunk_done"), mode="r")[:], dtype=bool)

    def _check_same(self, stored: dict[str, Any]) -> None:
        if stored.get("fingerprint") == self.spec.fingerprint():
            return
        old = json.loads(stored.get("spec", "{}"))
        new = spec_summary(self.spec)
        diffs = [
            f"{k} ({old.get(k)!r} in the store, {new.get(k)!r} now)"
            for k in sorted(set(old) | set(new))
            if k != "fingerprint" and old.get(k) != new.get(k)
        ]
        raise StoreMismatchError(
            f"{self.path} holds a different sweep; differs in "
            + ", ".join(diffs[:4])
            + ("" if len(diffs) <= 4 else f" and {len(diffs) - 4} more")
            + "; use another --out or delete it"
        )

    def _create(self) -> None:
        import xarray as xr

        ds = build_dataset_flat(self.spec, _empty_arrays(self.spec), self.attrs)
        ds["chunk_done"] = xr.DataArray(np.zeros(self.spec.n_chunks, dtype=np.int8), dims="chunk")
        c = self.spec.size
        encoding = {
            name: {"chunks": (c, *ds[name].shape[1:])} for name in ds.data_vars if name != "chunk_done"
        }
        encoding["chunk_done"] = {"chunks": (1,)}
        tmp_attrs = dict(ds.attrs)
        ds.attrs = {}
        ds.to_zarr(str(self.path), mode="w", encoding=encoding, consolidated=False)
        import zarr

        group = zarr.open_group(str(self.path), mode="r+")
        group.attrs.update({**tmp_attrs, "initialized": 1})

    def is_done(self, i: int) -> bool:
        return bool(self._done[i])

    def write(self, res: ChunkResult) -> None:
        import xarray as xr

        sl = self.spec.chunk(res.index)
        part = xr.Dataset(
            {
                "samples": (("point", "sample", "component"), res.samples),
                "period": ("point", res.period),
                "impacts": ("point", res.impacts),
                "lyapunov": ("point", res.lyapunov),
                "transient_used": ("point", res.transient_used),
                "x_final": (("point", "component"), res.x_final),
            }
        )
        part.to_zarr(str(self.path), region={"point": sl}, consolidated=False)
        flag = xr.Dataset({"chunk_done": ("chunk", np.ones(1, dtype=np.int8))})
        flag.to_zarr(str(self.path), region={"chunk": slice(res.index, res.index + 1)}, consolidated=False)
        self._done[res.index] = True

    def dataset(self) -> Any:
        import xarray as xr

        raw = xr.open_zarr(str(self.path), consolidated=False).load()
        missing = int((raw["chunk_done"].values == 0).sum())
        if missing:
            raise GrazingError(f"{self.path} is incomplete: {missing} chunk(s) not computed")
        arrays = {k: raw[k].values for k in _empty_arrays(self.spec)}
        attrs = {k: v for k, v in raw.attrs.items() if k not in ("initialized",)}
        return build_dataset(self.spec, arrays, {**attrs, **self.attrs})


def build_dataset_flat(spec: SweepSpec, arrays: dict[str, np.ndarray], attrs: dict[str, Any]) -> Any:
    """The flat (``point``-indexed) raw arrays as stored on disk, with the spec attributes.

    No string coordinates are stored (component names come from the spec on
    loading), so the store uses only Zarr v3's numeric types.
    """
    import xarray as xr

    ds = xr.Dataset(
        {
            "samples": (("point", "sample", "component"), arrays["samples"]),
            "period": ("point", arrays["period"]),
            "impacts": ("point", arrays["impacts"]),
            "lyapunov": ("point", arrays["lyapunov"]),
            "transient_used": ("point", arrays["transient_used"]),
            "x_final": (("point", "component"), arrays["x_final"]),
        }
    )
    summary = spec_summary(spec)
    ds.attrs.update({"spec": json.dumps(summary, sort_keys=True), "fingerprint": summary["fingerprint"]})
    ds.attrs.update(attrs)
    return ds


def open_store(path: str | Path, spec: SweepSpec, attrs: dict[str, Any] | None = None) -> ZarrStore:
    """Create or reopen the Zarr store for ``spec`` at ``path``."""
    return ZarrStore(path, spec, attrs)
