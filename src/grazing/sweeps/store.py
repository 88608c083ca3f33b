"""Where sweep results go: memory, or a resumable Zarr store.

The Zarr store holds every variable chunked along ``point`` exactly like the
sweep (unwritten chunks read as NaN, or -1 for the integer variables) and a
``chunk_done`` flag per chunk.  Each finished chunk writes its region, *then*
sets its flag; a run killed at any moment leaves at most one chunk without its
flag, and re-running the same command recomputes only the chunks whose flag is
unset.  A store made with a different sweep (other parameters, values,
transient...) is refused; so is anything at the path that grazing did not make
(:mod:`grazing.sweeps.ownership`), and a store another process is writing
(:mod:`grazing.sweeps.lock`).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from grazing.core.period import orbit_impacts
from grazing.errors import GrazingError, WriteError
from grazing.sweeps.chain import ChainStart, start_after
from grazing.sweeps.lock import StoreBusyError, StoreLock
from grazing.sweeps.ownership import (
    ForeignStoreError,
    StoreDamagedError,
    check_is_store,
    create_store,
    lock_for,
)
from grazing.sweeps.spec import DIRECTIONS, ChunkResult, SweepSpec, spec_summary
from grazing.sweeps.status import NOT_COMPUTED, STATUS_DTYPE, status_attrs

__all__ = [
    "ForeignStoreError",
    "MemoryStore",
    "StoreBusyError",
    "StoreDamagedError",
    "StoreMismatchError",
    "ZarrStore",
    "build_dataset",
    "impacts_per_period",
    "open_store",
]


class StoreMismatchError(GrazingError, ValueError):
    """An existing result store was made by a different sweep."""


@dataclass(frozen=True)
class _Variable:
    """A per-point variable as a store holds it: its dimensions, dtype and value before it is computed."""

    dims: tuple[str, ...]
    dtype: Any
    fill: float | int


_STORED = {
    "samples": _Variable(("point", "sample", "component"), np.float64, np.nan),
    "period": _Variable(("point",), np.int32, -1),
    "impacts": _Variable(("point",), np.int32, -1),
    "lyapunov": _Variable(("point",), np.float64, np.nan),
    "transient_used": _Variable(("point",), np.int32, -1),
    "x_final": _Variable(("point", "component"), np.float64, np.nan),
    "impacts_by_stop": _Variable(("point", "stop"), np.int32, -1),
    "status": _Variable(("point",), STATUS_DTYPE, NOT_COMPUTED),
}
"""The per-point variables of a sweep, as the stores hold them (flat along ``point``)."""
_VARIABLES = tuple(_STORED)

END_TIME = "chunk_end_time"
END_MODE = "chunk_end_mode"
"""Per chunk of a model with modes: the mode its last point ends in (-1: failed), where a chain goes on."""
"""Per chunk: the time its last point ended at, where a chain goes on from (a model that is not periodic)."""
POINT_MODE = "point_end_mode"
"""Per point of a model with modes: the mode its last sample is in (-1: failed), what tells two attractors
with the same samples in two modes apart (:mod:`grazing.attractors.classify`; a store made before it
existed gives each chunk's last point's only)."""


def _shapes(spec: SweepSpec) -> dict[str, tuple[int, ...]]:
    """The shape of each stored variable."""
    size = {"point": spec.n_points, "sample": spec.periods, "component": spec.model.n_states,
            "stop": spec.model.n_stops}  # fmt: skip
    return {name: tuple(size[d] for d in var.dims) for name, var in _STORED.items()}


def _flat(arrays: dict[str, np.ndarray]) -> Any:
    """The stored variables (``arrays``, or a chunk's part of them) as a Dataset along ``point``."""
    import xarray as xr

    return xr.Dataset({name: (_STORED[name].dims, arrays[name]) for name in _VARIABLES})


def _stop_levels(spec: SweepSpec) -> np.ndarray:
    """Each point's :meth:`~grazing.core.model.HybridModel.stop_level` of each state component (nan: none)."""
    n = spec.model.n_states
    out = np.full((spec.n_points, n), np.nan)
    first = spec.model_at(spec.points[0])
    system = spec.model.symbolic
    swept = {sym for sym in system.params if str(sym) in spec.params}
    constant = not (system.stops[0].guard.free_symbols & swept)  # (the first stop's, as stop_level's)
    for c in range(n):
        level0 = first.stop_level(c)
        if level0 is None:
            continue
        if constant:  # (the guard does not depend on the swept parameters: one level for every point)
            out[:, c] = level0
            continue
        for i, pt in enumerate(spec.points):
            level = spec.model_at(pt).stop_level(c)
            out[i, c] = np.nan if level is None else level
    return out


def impacts_per_period(spec: SweepSpec, arrays: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Impacts per period of each point's detected orbit (per forcing period where none), in all and per stop.

    Computed from a sweep's flat per-point arrays (nan where a point failed);
    the dataset's ``impacts_per_period`` and ``impacts_per_period_by_stop``
    (:func:`~grazing.core.period.orbit_impacts`).
    """
    period, impacts, by_stop = arrays["period"], arrays["impacts"], arrays["impacts_by_stop"]
    ipp = orbit_impacts(impacts, period, spec.periods)
    ipp_stop = orbit_impacts(by_stop, period[:, None], spec.periods)
    return ipp, ipp_stop


def build_dataset(
    spec: SweepSpec,
    arrays: dict[str, np.ndarray],
    attrs: dict[str, Any] | None = None,
    levels: np.ndarray | None = None,
) -> Any:
    """The xarray Dataset of a sweep from its flat per-point arrays (``levels``: its stop levels if known)."""
    import xarray as xr

    pts = np.asarray(spec.points, dtype=float)
    period = arrays["period"]
    impacts = arrays["impacts"]
    by_stop = arrays["impacts_by_stop"]
    ipp, ipp_stop = impacts_per_period(spec, arrays)
    data = {
        "samples": (("point", "sample", "component"), arrays["samples"]),
        "period": ("point", period),
        "impacts": ("point", impacts),
        "impacts_per_period": ("point", ipp),
        "lyapunov": ("point", arrays["lyapunov"]),
        "transient_used": ("point", arrays["transient_used"]),
        "x_final": (("point", "component"), arrays["x_final"]),
        "impacts_by_stop": (("point", "stop"), by_stop),
        "impacts_per_period_by_stop": (("point", "stop"), ipp_stop),
        "status": ("point", arrays["status"]),
    }
    coords: dict[str, Any] = {
        "component": list(spec.model.state_names),
        "stop": list(spec.model.stop_names),
        "sample": np.arange(spec.periods),
    }
    for j, name in enumerate(spec.params):
        coords[name] = ("point", pts[:, j])
    if len(spec.params) == 1:
        coords["value"] = ("point", pts[:, 0])
    data["stop_level"] = (("point", "component"), _stop_levels(spec) if levels is None else levels)
    ds = xr.Dataset(data, coords=coords)
    ds["stop_level"].attrs["description"] = (
        "the state component's value on the stop, where the guard depends on that component alone (else nan)"
    )
    ds["period"].attrs["description"] = (
        "smallest p <= 64 with the samples p-periodic to 1e-6; 0 none; -1 failed"
    )
    ds["impacts_per_period"].attrs["description"] = (
        "impacts per period p of the detected orbit (per forcing period when p = 0)"
    )
    ds["impacts_per_period_by_stop"].attrs["description"] = "impacts_per_period on each stop"
    ds["lyapunov"].attrs["description"] = (
        "largest Lyapunov exponent per unit time (nan: not computed / sticking)"
    )
    ds["status"].attrs.update(status_attrs())
    summary = spec_summary(spec)
    ds.attrs.update(
        {
            "spec": json.dumps(summary, sort_keys=True),
            "fingerprint": summary["fingerprint"],
            "params": ",".join(spec.params),
            "model": spec.model.name,
            "grazing_version": summary["grazing_version"],
            "state_labels": json.dumps(list(spec.model.state_labels)),
            "state_units": json.dumps(list(spec.model.state_units)),
            "time_label": spec.model.time_label,
            "forcing_period": spec.model_at(spec.points[0]).period,
        }
    )
    for k, v in spec.model.params.items():
        if k not in spec.params:
            ds.attrs[f"param_{k}"] = v
    ds.attrs.update(attrs or {})
    if len(spec.params) == 1 and spec.segments == 2:  # up and down (direction "both"): each by value
        n = spec.segment_points
        halves = [ds.isel(point=slice(k * n, (k + 1) * n)).sortby("value") for k in range(2)]
        halves = [h.assign_coords(point=np.arange(n)) for h in halves]
        both = xr.concat([h.drop_vars(["stop_level"]) for h in halves], dim="direction", coords="minimal",
                         compat="override")  # fmt: skip
        ds = both.assign_coords(direction=list(DIRECTIONS[:2])).drop_vars("point")
        ds["stop_level"] = halves[0]["stop_level"].drop_vars("point")
        ds.attrs["directions"] = (
            "up, down: the values visited upwards, then downwards from x0 again (two chains)"
        )
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
    _label_parameters(ds, spec)  # last: reshaping a map (or a sweep up and down) rebuilds the coordinates
    return ds


def _label_parameters(ds: Any, spec: SweepSpec) -> None:
    """Give each parameter coordinate what plots need to label its axis: symbol, units, angle."""
    for name in spec.params:
        par = spec.model.parameter(name)
        meta = {"long_name": par.description or name, "symbol": par.label, "units": par.unit}
        ds[name].attrs.update({**meta, "angle": int(par.angle)})


class MemoryStore:
    """Results kept in memory.

    The arrays are taken from the system untouched and each chunk's part is
    written when the chunk is (while the threads compute the next ones); the
    chunks not written are given their values before computing (NaN, -1...)
    only when :attr:`arrays` is read.  (Filling 50 MB of samples at once, a
    32000-point sweep's, took 0.01 to 0.15 s before the threads started.)
    """

    def __init__(self, spec: SweepSpec, attrs: dict[str, Any] | None = None):
        self.spec = spec
        self._arrays = {
            name: np.empty(shape, dtype=_STORED[name].dtype) for name, shape in _shapes(spec).items()
        }
        self._set = np.zeros(spec.n_chunks, dtype=bool)  # (the chunks whose part of the arrays holds values)
        self.done = np.zeros(spec.n_chunks, dtype=bool)
        self.end_time = np.full(spec.n_chunks, np.nan)
        self.end_mode = np.full(spec.n_chunks, -1, dtype=np.int64)
        self.attrs = attrs or {}
        self._levels: np.ndarray | None = None  # (the stop levels, once prepared)

    @property
    def arrays(self) -> dict[str, np.ndarray]:
        """The stored variables, flat along the points (a chunk not written: its values before computing)."""
        if not self._set.all():
            for i in np.flatnonzero(~self._set):
                sl = self.spec.chunk(int(i))
                for name, array in self._arrays.items():
                    array[sl] = _STORED[name].fill
            self._set[:] = True
        return self._arrays

    def is_done(self, i: int) -> bool:
        return bool(self.done[i])

    def write(self, res: ChunkResult) -> None:
        sl = self.spec.chunk(res.index)
        for key, array in self._arrays.items():
            array[sl] = getattr(res, key)
        self.end_time[res.index] = _end_time(res)
        self.end_mode[res.index] = _end_mode(res)
        self._set[res.index] = True
        self.done[res.index] = True

    def chain_start(self, i: int) -> ChainStart:
        """Where the chain goes on after chunk ``i`` (written): :func:`~grazing.sweeps.chain.start_after`."""
        last = self.spec.chunk(i).stop - 1
        x, status = self.arrays["x_final"][last], int(self.arrays["status"][last])
        return start_after(self.spec, i, status, x, float(self.end_time[i]), int(self.end_mode[i]))

    def prepare(self) -> None:
        """Do, once, what :meth:`dataset` needs that the results do not: import xarray and make its first
        array (xarray then imports dask.array, to ask whether an array is one), and find the stops' levels
        (for a built-in model, importing sympy).  :func:`~grazing.sweeps.api.run_sweep` calls it once the
        first chunk is in, while the cores compute the others: done after the last one, it was about 1 s
        of a process's first sweep in which the cores waited (issue 29)."""
        if self._levels is not None:
            return
        import xarray as xr

        xr.Variable(("point",), np.zeros(1))
        self._levels = _stop_levels(self.spec)

    def dataset(self) -> Any:
        return build_dataset(self.spec, self.arrays, self.attrs, self._levels)


class ZarrStore:
    """A resumable Zarr store for one sweep, written by one process at a time.

    Opening the store takes its lock (:mod:`grazing.sweeps.lock`) for as long
    as the store is open: use it as a context manager, or call :meth:`close`.
    Only a grazing sweep store (:mod:`grazing.sweeps.ownership`) is ever
    opened; anything else at ``path`` is refused and left untouched.  A new
    store is built beside ``path`` and renamed into place when complete.

    Parameters
    ----------
    path
        Directory of the store (``*.zarr``).
    spec
        The sweep; an existing store must have been made by the same sweep.
    attrs
        Extra attributes (for example the command line).
    wait
        If another process holds the store, wait for it instead of raising
        :class:`~grazing.sweeps.lock.StoreBusyError`.
    on_wait
        Called with the other process's PID before waiting.

    Raises
    ------
    ForeignStoreError
        ``path`` holds something grazing did not make.
    StoreMismatchError
        ``path`` holds a different sweep.
    StoreBusyError
        Another process is writing the store (and ``wait`` is false).
    StoreDamagedError
        The store cannot be read.
    """

    def __init__(
        self,
        path: str | Path,
        spec: SweepSpec,
        attrs: dict[str, Any] | None = None,
        *,
        wait: bool = False,
        on_wait: Callable[[int | None], None] | None = None,
    ):
        self.path = Path(path)
        self.spec = spec
        self.attrs = attrs or {}
        self._lock: StoreLock | None = None
        if not os.path.lexists(self.path):
            self._lock = create_store(self.path, self._build, {"fingerprint": spec.fingerprint()})
        if self._lock is None:  # it existed, or another run created it first
            check_is_store(self.path)
            self._check_same(self._read_attrs())
            lock = lock_for(self.path)
            lock.acquire(wait=wait, on_wait=on_wait)
            self._lock = lock
        try:
            self._done = self._read("chunk_done", lambda z: np.asarray(z[:], dtype=bool))
            if self._done.shape != (spec.n_chunks,):
                raise StoreDamagedError(self._damaged("chunk_done has the wrong shape"))
            self._has_end_time = (self.path / END_TIME).is_dir()  # (not in earlier fresh sweeps' stores)
            self._has_end_mode = (self.path / END_MODE).is_dir()  # (models with modes only)
            self._has_point_mode = (self.path / POINT_MODE).is_dir()  # (and not in earlier stores)
        except BaseException:
            self.close()
            raise

    # ------------------------------------------------------------------ lifetime

    def close(self) -> None:
        """Release the store's lock (the store stays; reopen it to resume)."""
        if self._lock is not None:
            self._lock.release()
            self._lock = None

    def __enter__(self) -> ZarrStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        lock = getattr(self, "_lock", None)
        if lock is not None:
            lock.release()

    # ------------------------------------------------------------------ reading

    def _damaged(self, what: str) -> str:
        return (
            f"sweep store {self.path} is damaged ({what}); delete it (or move it away) and run the "
            "command again to recompute it"
        )

    def _read(self, name: str, get: Callable[[Any], Any]) -> Any:
        import zarr

        try:
            return get(zarr.open_array(str(self.path / name), mode="r"))
        except Exception as exc:  # corrupt chunk, missing array, bad metadata
            raise StoreDamagedError(self._damaged(f"cannot read {name!r}: {_short(exc)}")) from None

    def _read_attrs(self) -> dict[str, Any]:
        import zarr

        try:
            return dict(zarr.open_group(str(self.path), mode="r").attrs)
        except Exception as exc:
            raise StoreDamagedError(self._damaged(f"cannot read its attributes: {_short(exc)}")) from None

    def _check_same(self, stored: dict[str, Any]) -> None:
        if stored.get("fingerprint") == self.spec.fingerprint():
            return
        try:
            old = json.loads(stored.get("spec", "{}"))
        except (TypeError, ValueError):
            old = {}
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
            + "; use another store (store=) or delete it"
        )

    def _build(self, folder: Path) -> None:
        """Write the store's metadata into ``folder``: arrays of fill values, no chunk written."""
        import dask.array as da
        import xarray as xr

        c = self.spec.size
        data: dict[str, Any] = {}
        encoding: dict[str, Any] = {}
        for name, shape in _shapes(self.spec).items():
            var = _STORED[name]
            chunks = (c, *shape[1:])
            data[name] = (var.dims, da.full(shape, var.fill, dtype=var.dtype, chunks=chunks))
            encoding[name] = {"chunks": chunks, "fill_value": var.fill}
        nc = self.spec.n_chunks
        data["chunk_done"] = ("chunk", da.zeros(nc, dtype=np.int8, chunks=min(nc, 1 << 20)))
        encoding["chunk_done"] = {"chunks": (1,), "fill_value": 0}
        data[END_TIME] = ("chunk", da.full(nc, np.nan, dtype=np.float64, chunks=min(nc, 1 << 20)))
        encoding[END_TIME] = {"chunks": (1,), "fill_value": np.nan}
        if self.spec.model.has_modes:
            data[END_MODE] = ("chunk", da.full(nc, -1, dtype=np.int64, chunks=min(nc, 1 << 20)))
            encoding[END_MODE] = {"chunks": (1,), "fill_value": -1}
            n = self.spec.n_points
            data[POINT_MODE] = ("point", da.full(n, -1, dtype=np.int64, chunks=c))
            encoding[POINT_MODE] = {"chunks": (c,), "fill_value": -1}
        ds = xr.Dataset(data)
        ds["status"].attrs.update(status_attrs())
        summary = spec_summary(self.spec)
        ds.attrs.update({"spec": json.dumps(summary, sort_keys=True), "fingerprint": summary["fingerprint"]})
        ds.attrs.update(self.attrs)
        ds.to_zarr(str(folder), mode="a", encoding=encoding, compute=False, consolidated=False)

    # ------------------------------------------------------------------ the store protocol

    def is_done(self, i: int) -> bool:
        return bool(self._done[i])

    @property
    def n_done(self) -> int:
        """Chunks already computed."""
        return int(self._done.sum())

    def write(self, res: ChunkResult) -> None:
        import xarray as xr

        sl = self.spec.chunk(res.index)
        part = _flat({name: getattr(res, name) for name in _VARIABLES})
        if self._has_point_mode:
            ended = (
                np.full(sl.stop - sl.start, -1, dtype=np.int64) if res.mode_final is None else res.mode_final
            )
            part[POINT_MODE] = ("point", np.asarray(ended, dtype=np.int64))
        flag = xr.Dataset({"chunk_done": ("chunk", np.ones(1, dtype=np.int8))})
        if self._has_end_time:
            flag[END_TIME] = ("chunk", np.array([_end_time(res)]))
        if self._has_end_mode:
            flag[END_MODE] = ("chunk", np.array([_end_mode(res)], dtype=np.int64))
        try:
            part.to_zarr(str(self.path), region={"point": sl}, consolidated=False)
            flag.to_zarr(
                str(self.path), region={"chunk": slice(res.index, res.index + 1)}, consolidated=False
            )
        except OSError as exc:  # a full disk: the chunk stays unflagged and is computed again on resume
            raise WriteError(
                f"cannot write to sweep store {self.path}: {exc.strerror or exc}; the chunks finished "
                "before are kept: make room and run the command again to resume"
            ) from None
        self._done[res.index] = True

    def read_chunk(self, i: int) -> ChunkResult:
        """The stored results of chunk ``i`` (done)."""
        sl = self.spec.chunk(i)
        got = {name: self._read(name, lambda z: np.asarray(z[sl])) for name in _VARIABLES}
        t = float(self._read(END_TIME, lambda z: z[i])) if self._has_end_time else math.nan
        t_final = np.full(sl.stop - sl.start, np.nan)
        t_final[-1] = t
        mode_final = None
        if self._has_point_mode:
            mode_final = self._read(POINT_MODE, lambda z: np.asarray(z[sl], dtype=np.int64))
        elif self._has_end_mode:  # (a store made before POINT_MODE: the mode of the last point only)
            mode_final = np.full(sl.stop - sl.start, -1, dtype=np.int64)
            mode_final[-1] = int(self._read(END_MODE, lambda z: z[i]))
        return ChunkResult(index=i, t_final=t_final, mode_final=mode_final, **got)

    def chain_start(self, i: int) -> ChainStart:
        """Where the chain goes on after chunk ``i`` (done): :func:`~grazing.sweeps.chain.start_after`."""
        last = self.spec.chunk(i).stop - 1
        x = self._read("x_final", lambda z: np.asarray(z[last], dtype=float))
        status = int(self._read("status", lambda z: z[last]))
        t = float(self._read(END_TIME, lambda z: z[i])) if self._has_end_time else math.nan
        mode = int(self._read(END_MODE, lambda z: z[i])) if self._has_end_mode else -1
        return start_after(self.spec, i, status, x, t, mode)

    def _check_complete(self) -> None:
        missing = int((~self._done).sum())
        if missing:
            raise GrazingError(f"{self.path} is incomplete: {missing} chunk(s) not computed")

    def read(self, name: str) -> np.ndarray:
        """One stored variable, flat along ``point`` (for example ``"period"``) — without the others."""
        return self._read(name, lambda z: np.asarray(z[:]))

    def dataset(self) -> Any:
        self._check_complete()
        arrays = {k: self.read(k) for k in _VARIABLES}
        attrs = {k: v for k, v in self._read_attrs().items() if k not in ("initialized",)}
        return build_dataset(self.spec, arrays, {**attrs, **self.attrs})


def _end_mode(res: ChunkResult) -> int:
    """The mode a chunk's last point ended in (-1: failed, or a model of one mode)."""
    return -1 if res.mode_final is None else int(res.mode_final[-1])


def _end_time(res: ChunkResult) -> float:
    """The time a chunk's last point ended at (nan: failed, or not known)."""
    return math.nan if res.t_final is None else float(res.t_final[-1])


def _short(exc: BaseException) -> str:
    """An exception as a short single line."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 160 else text[:157] + "..."


def open_store(
    path: str | Path, spec: SweepSpec, attrs: dict[str, Any] | None = None, *, wait: bool = False
) -> ZarrStore:
    """Create or reopen the Zarr store for ``spec`` at ``path`` (see :class:`ZarrStore`)."""
    return ZarrStore(path, spec, attrs, wait=wait)
