"""``grazing sweep``, ``grazing map``: brute-force bifurcation diagrams and two-parameter maps."""

from __future__ import annotations

import math
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click
import numpy as np

import grazing
from grazing.cli.common import (
    PENDULUM_UNFOLDING,
    InputError,
    Progress,
    check_folder,
    check_out,
    complex_list,
    emit_json,
    json_option,
    model_options,
    model_parameter,
    model_params_json,
    overwrite_option,
    parse_state,
    refuse_varied,
    save_dataset,
    spaced_values,
)
from grazing.cli.hints import flag_hints
from grazing.cli.limits import POINT_OVERHEAD, check_memory, count_text, sweep_bytes
from grazing.cli.validate import FINITE, POSITIVE, TOLERANCE, WORKERS, count, path_type, refuse_unused
from grazing.core.options import CHUNK_SIZE, SweepSettings
from grazing.core.solution import Status
from grazing.gpu.device import DEFAULT_DEVICE, DEVICES

ONE_VALUE = "with {num} 1 (its one value is {start}: give the same value to both, or {num} 2 or more)"
"""Why the last value is refused with one value: ``--stop is not used with --num 1 (...)``."""

SWEEP_DEFAULTS = SweepSettings()
"""The defaults of ``sweep`` and ``map``'s options: those of :class:`~grazing.core.options.SweepSettings`."""


def _sweep_options(func: Callable[..., Any]) -> Callable[..., Any]:
    options = [
        click.option("--transient", type=count(0), default=SWEEP_DEFAULTS.transient, show_default=True,
                     help="Forcing periods discarded at each point.")
        ,
        click.option("--periods", type=count(1), default=SWEEP_DEFAULTS.periods, show_default=True,
                     help="Forcing periods sampled at each point."),
        click.option("--phase", type=FINITE, default=SWEEP_DEFAULTS.phase, show_default=True, metavar="PHI",
                     help="Stroboscopic phase in radians: each point sampled at tau = PHI mod 2 pi."),
        click.option("--initial", default=None, metavar="X1,X2,...",
                     help="Initial state (of every chunk; of every point with --fresh), one number per "
                     "state; default zero."),
        click.option("--fresh", is_flag=True, help="Start every point from --initial."),
        click.option("--chunk-size", type=count(0), default=None,
                     help="Points per chunk: the unit of parallel work and of saving (0: one chunk)."),
        click.option("--workers", type=WORKERS, help="Local threads (default: all cores)."),
        click.option("--scheduler", metavar="tcp://HOST:PORT", help="Run the chunks on a Dask cluster."),
        click.option("--timeout", type=POSITIVE, metavar="SECONDS",
                     help="With --scheduler: give up after this long without any Dask worker "
                          "(default: wait; a message after 5 s)."),
        click.option("--device", type=click.Choice(DEVICES), default=DEFAULT_DEVICE, show_default=True,
                     help="Where the points run: the CPU lanes, an NVIDIA GPU (one CUDA thread per point, "
                     "Lyapunov exponents, models with modes, chains of several chunks and the "
                     "discontinuity map included), or the GPU when one is present and the sweep is large "
                     "(auto)."),
        click.option("--no-lyapunov", is_flag=True, help="Skip the Lyapunov exponents."),
        click.option("--no-adaptive", is_flag=True, help="Always run the full transient."),
        click.option("--tol", type=TOLERANCE, default=SWEEP_DEFAULTS.tol, show_default=True,
                     help="Integrator tolerance, in (0, 0.01)."),
        click.option("--out", type=path_type(), metavar="FILE.zarr|FILE.nc",
                     help="Zarr store (resumable; one run at a time) or NetCDF file."),
        click.option("--wait", is_flag=True,
                     help="If another run is writing the --out store, wait for it instead of stopping."),
        overwrite_option,
        json_option,
    ]  # fmt: skip
    for opt in reversed(options):
        func = opt(func)
    return func


def _check_sweep_options(
    out: Path | None, scheduler: str | None, chunk_size: int | None, n_points: int, periods: int,
    n_states: int, workers: int | None, as_json: bool, what: str, overwrite: bool = False,
) -> None:  # fmt: skip
    """The checks shared by ``sweep`` and ``map``, before any work: output, options used together, memory."""
    if out is not None and out.suffix.lower() not in (".zarr", ".nc"):
        raise InputError(f"--out must end in .zarr or .nc, got {str(out)!r}")
    zarr_out = out is not None and out.suffix.lower() == ".zarr"
    if out is not None and not zarr_out:
        check_out(out, ".nc", overwrite=overwrite)
    elif out is not None:
        check_folder(out)
    refuse_unused(["overwrite"], out is None, "without --out")
    refuse_unused(["overwrite"], zarr_out, "with a Zarr store (a store is never replaced)")
    refuse_unused(["wait"], not zarr_out, "without a Zarr store (--out FILE.zarr)")
    refuse_unused(["timeout"], scheduler is None, "without --scheduler")
    refuse_unused(
        ["workers"], scheduler is not None, "with --scheduler (the cluster's workers run the chunks)"
    )
    if zarr_out and out is not None and out.exists():
        from grazing.sweeps.ownership import check_is_store

        check_is_store(out)  # refuse what grazing did not make before computing anything
    streamed = zarr_out and not as_json
    chunk = n_points if not chunk_size else min(chunk_size, n_points)
    n_workers = workers or os.cpu_count() or 1
    need = sweep_bytes(n_points, periods, n_states, streamed=streamed, as_json=as_json, chunk_points=chunk,
                       workers=n_workers)  # fmt: skip
    chunks_dominate = streamed and need > 2 * n_points * POINT_OVERHEAD  # the samples in flight, mostly
    check_memory(
        need,
        f"{what} of {count_text(n_points)} points x {count_text(periods)} periods",
        "use a smaller --chunk-size (or fewer --workers): the chunks in flight hold their samples"
        if chunks_dominate
        else "split it into several runs over parts of the range"
        + ("" if streamed else ", or stream the results to a Zarr store (--out FILE.zarr, without --json)"),
    )


class _SweepRun:
    """What a sweep run returns to its command: the dataset, or (streamed to a store) the periods and
    statuses only, or (``arrays``: results kept in memory and no dataset asked for) the per-point arrays.

    ``period`` and ``status`` are flat along the spec's points (in visiting order) in every case.
    """

    def __init__(
        self, ds: Any, period: np.ndarray, status: np.ndarray, arrays: dict[str, np.ndarray] | None = None,
        impacts: np.ndarray | None = None, rows: Any = None,
    ):  # fmt: skip
        self.ds = ds
        self.period = period
        self.status = status
        self.arrays = arrays
        self.impacts = impacts
        self.rows = rows  # (arrays and --json: the samples' JSON text, grazing.cli.sweep_json.SampleRows)


def _run_sweep_spec(
    spec: Any, out: Path | None, scheduler: str | None, workers: int | None, as_json: bool,
    wait: bool = False, timeout: float | None = None, arrays: bool = False, overwrite: bool = False,
    device: str = DEFAULT_DEVICE,
) -> _SweepRun:  # fmt: skip
    """Run a sweep spec with the CLI's storage, cluster and progress options.

    With a Zarr store and no ``--json``, the results stream to the store and
    only the detected periods are read back (for the summary).  With
    ``arrays`` and no Zarr store, the results stay in memory as per-point
    arrays and no xarray dataset is built unless a NetCDF file is asked for
    (importing xarray, and the dask it imports, costs about a second).
    """
    from grazing.gpu.device import resolve_device
    from grazing.sweeps.api import run_sweep

    device = resolve_device(device, spec, scheduler)  # (before a store or a cluster: an error writes nothing)
    zarr_out = out is not None and out.suffix.lower() == ".zarr"
    streamed = zarr_out and not as_json
    memory = arrays and not zarr_out
    client = None
    if scheduler is not None:
        try:
            from distributed import Client

            client = Client(scheduler, timeout="5s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"cannot connect to the Dask scheduler at {scheduler}: {exc}") from None
    store: Any = None
    bar = Progress("sweeping", enabled=not as_json, unit="points")
    try:
        if zarr_out:
            from grazing.sweeps.store import ZarrStore

            store = ZarrStore(
                out, spec, attrs={"command": " ".join(["grazing", *sys.argv[1:]])}, wait=wait,
                on_wait=lambda pid: click.echo(
                    f"grazing: {out} is being written by another grazing run"
                    + (f" (PID {pid})" if pid is not None else "") + "; waiting", err=True
                ),
            )  # fmt: skip
        elif memory and as_json:  # (the samples' JSON text made as the chunks arrive)
            from grazing.cli.sweep_json import JsonMemoryStore

            store = JsonMemoryStore(spec)
        elif memory:
            from grazing.sweeps.store import MemoryStore

            store = MemoryStore(spec)
        ds = run_sweep(
            spec, store=store, workers=workers, client=client, progress=bar, timeout=timeout,
            notice=lambda msg: click.echo(f"grazing: {flag_hints(msg)}", err=True),
            load=not (streamed or memory), device=device,
        )  # fmt: skip
        flat = {name: store.read(name) for name in ("period", "status", "impacts")} if streamed else None
    finally:
        bar.close()
        if store is not None and not memory:
            store.close()
        if client is not None:
            client.close()
    if memory:
        if out is not None:
            save_dataset(store.dataset(), out, overwrite)
        rows = getattr(store, "rows", None)
        return _SweepRun(None, store.arrays["period"], store.arrays["status"], store.arrays, rows=rows)
    if out is not None and out.suffix.lower() == ".nc":
        save_dataset(ds, out, overwrite)
    if flat is None:  # (the dataset's points, flattened: in visiting order, as the spec lists them)
        flat = {name: _visiting_order(ds, name) for name in ("period", "status")}
    return _SweepRun(ds, flat["period"], flat["status"], impacts=flat.get("impacts"))


def _visiting_order(ds: Any, name: str) -> np.ndarray:
    """A sweep dataset's variable along its points in visiting order (``--direction both``: up, then down)."""
    values = ds[name].values
    if "direction" in ds[name].dims:  # (each direction sorted by value: down is visited the other way)
        return np.concatenate([values[0], values[1][::-1]])
    return values.ravel()


def _sweep_json(spec: Any, run: _SweepRun, param: str, shown: np.ndarray) -> dict[str, Any]:
    """The sweep's ``--json`` keys, points sorted by value, from its arrays or its dataset."""
    from grazing.sweeps.store import impacts_per_period

    if run.arrays is not None:
        a = run.arrays
    elif "direction" in run.ds.dims:
        names = ("samples", "period", "impacts", "lyapunov", "transient_used", "impacts_by_stop", "status")
        a = {k: _visiting_order(run.ds, k) for k in names}
    else:
        a = {k: run.ds[k].values for k in ("samples", "period", "impacts", "lyapunov", "transient_used",
                                             "impacts_by_stop", "status")}  # fmt: skip
    ipp, ipp_stop = impacts_per_period(spec, a)
    if spec.segments == 2:  # --direction both: each per-point key is {"up": [...], "down": [...]}
        n = spec.segment_points
        halves = [slice(0, n), slice(n, 2 * n)]
        half = [{k: v[sl] for k, v in a.items()} for sl in halves]
        parts = [
            _point_keys(type(spec)(**{**spec.__dict__, "points": spec.points[sl], "segments": 1}), h, ipp[sl],
                        ipp_stop[sl], _rows_text(run, k))
            for k, (sl, h) in enumerate(zip(halves, half))
        ]  # fmt: skip
        return {"param": param, "values": np.sort(shown),
                **{key: {"up": parts[0][key], "down": parts[1][key]} for key in parts[0]}}  # fmt: skip
    keys = _point_keys(spec, a, ipp, ipp_stop, _rows_text(run, 0))
    return {"param": param, "values": np.sort(shown), **keys}


def _rows_text(run: _SweepRun, segment: int) -> Any:
    """The samples of chain ``segment`` as JSON text made while the sweep ran, or None."""
    return run.rows.text(segment) if run.rows is not None else None


def _point_keys(
    spec: Any, a: dict[str, np.ndarray], ipp: np.ndarray, ipp_stop: np.ndarray, samples_text: Any = None
) -> dict[str, Any]:
    """The per-point keys of a sweep's ``--json``, sorted by value (``samples_text``: the samples' JSON)."""
    from grazing.sweeps.status import reasons

    by_value = np.argsort(np.asarray(spec.points, dtype=float)[:, 0], kind="stable")
    return {
        "period": a["period"][by_value],
        "impacts_per_period": ipp[by_value],
        "lyapunov": a["lyapunov"][by_value],
        "samples": samples_text if samples_text is not None else a["samples"][by_value, :, 0],
        "transient_used": a["transient_used"][by_value],
        "impacts_per_period_by_stop": {
            str(name): ipp_stop[by_value, j] for j, name in enumerate(spec.model.stop_names)
        },
        "status": reasons(a["status"][by_value]),
    }


def _outcomes(period: np.ndarray, status: np.ndarray) -> tuple[int, int, str]:
    """Points with a period, points computed without one (<= 64), and the failed ones with their reasons."""
    from grazing.sweeps.status import failure_text

    ok = status == Status.OK
    return int((ok & (period > 0)).sum()), int((ok & (period == 0)).sum()), failure_text(status)


@click.command("sweep")
@model_options(any_model=True, modes=True)
@click.option("--param", "sparam", required=True, metavar="NAME",
              help="Parameter to sweep: any of the model's (the pendulum's eta, theta-hat, alpha, beta, r); "
              "angles in degrees.")  # fmt: skip
@click.option("--start", type=FINITE, required=True, help="First parameter value.")
@click.option("--stop", type=FINITE, required=True, help="Last parameter value.")
@click.option("--num", type=count(1), required=True, help="Number of parameter values.")
@click.option("--direction", type=click.Choice(["up", "down", "both"]), default="up", show_default=True,
              help="Order in which the values are visited; both: up, then down from --initial again, both "
              "kept (hysteresis).")  # fmt: skip
@click.option(
    "--method",
    type=click.Choice(["flow", "map"]),
    default="flow",
    show_default=True,
    help="flow: direct simulation; map: the discontinuity-map Poincare map built at a grazing.",
)
@click.option("--which", type=click.Choice(["first", "second"]), default="first", show_default=True,
              help="With --method map: the grazing the map is built at.")  # fmt: skip
@_sweep_options
def sweep_cmd(
    model: grazing.HybridModel, case: str,
    sparam: str, start: float, stop: float, num: int, direction: str, method: str, which: str,
    transient: int, periods: int, phase: float, initial: str, fresh: bool, chunk_size: int | None,
    workers: int | None, scheduler: str | None, timeout: float | None, device: str, no_lyapunov: bool,
    no_adaptive: bool,
    tol: float, out: Path | None, wait: bool, overwrite: bool, as_json: bool,
) -> None:  # fmt: skip
    """Brute-force bifurcation diagram: stroboscopic samples, periods, impacts and
    Lyapunov exponents along a parameter range."""
    from grazing.sweeps.spec import sweep_spec

    par = model_parameter(model, sparam)
    name = par.name
    refuse_varied([name], f"with --param {sparam}: the swept values replace it")
    refuse_unused(["stop"], num == 1 and stop != start, ONE_VALUE.format(num="--num", start="--start"))
    refuse_unused(["which"], method != "map", "without --method map")
    same = "with --direction both (from --initial at every point, both directions are the same)"
    refuse_unused(["fresh"], direction == "both", same)
    chunk_size = CHUNK_SIZE if chunk_size is None else chunk_size
    runs = 2 if direction == "both" else 1
    n_states = model.n_states
    _check_sweep_options(
        out, scheduler, chunk_size, runs * num, periods, n_states, workers, as_json, "a sweep", overwrite
    )
    shown = spaced_values(start, stop, num, "--start/--stop")
    vals = np.array([par.from_display(v) for v in shown])
    order = np.sort(vals) if direction != "down" else np.sort(vals)[::-1]
    x0 = parse_state(initial, model)
    for v in (order[0], order[-1]):
        model.with_params(**{name: v})
    zdm, graze_info = None, None
    if method == "map":
        zdm, graze_info = _map_for_sweep(model, name, float(vals.min()), float(vals.max()), which)
    settings = SweepSettings(
        transient=transient, periods=periods, phase=phase, fresh=fresh, chunk_size=chunk_size,
        adaptive=not no_adaptive, lyapunov=not no_lyapunov, tol=tol,
    )  # fmt: skip
    spec = sweep_spec(model, name, vals, x0=x0, direction=direction, settings=settings, zdm=zdm)
    t0 = time.perf_counter()
    run = _run_sweep_spec(
        spec, out, scheduler, workers, as_json, wait, timeout, arrays=True, overwrite=overwrite, device=device
    )
    elapsed = time.perf_counter() - t0
    if as_json:
        res = {"params": model_params_json(model, case), **_sweep_json(spec, run, sparam, shown)}
        res.update({"direction": direction, "fresh": fresh, "transient": transient, "periods": periods,
                    "phase": phase, "chunk_size": spec.size, "elapsed_s": elapsed,
                    "out": str(out) if out else None, "method": method, "grazing": graze_info})  # fmt: skip
        if direction == "both":
            res["hysteresis"] = [_hysteresis_json(h, par) for h in _hysteresis(spec, run)]
        emit_json(res)
        return
    click.echo(f"{num} values of {sparam} in {elapsed:.1f} s ({runs * num / elapsed:.0f} points/s)")
    for k, way in enumerate(["up", "down"] if direction == "both" else [direction]):
        here = slice(k * num, (k + 1) * num)  # (the points of one direction, in visiting order)
        by_value = np.argsort(order if way == "up" else order[::-1], kind="stable")
        if direction == "both":
            click.echo(f"{way}:")
        _summary(run.period[here][by_value], run.status[here][by_value], np.sort(shown), sparam)
    if direction == "both":
        found = _hysteresis(spec, run)
        click.echo(f"up and down differ at {sum(h.points for h in found)} values" + (":" if found else ""))
        for h in found:
            lo, hi = par.to_display(h.start), par.to_display(h.stop)
            click.echo(f"  {sparam} in [{lo:.6g}, {hi:.6g}] ({h.points} values): up {h.up}, down {h.down}")
    if out is not None:
        click.echo(f"saved to {out}")


def _summary(per: np.ndarray, status: np.ndarray, shown: np.ndarray, sparam: str) -> None:
    """The summary lines of a sweep's points (sorted by value): periodic windows, failed points."""
    from grazing.sweeps.status import failures, reasons

    periodic, aperiodic, failed = _outcomes(per, status)
    click.echo(f"periodic points: {periodic}, no period <= 64: {aperiodic}, {failed}")
    ok = status == Status.OK
    for p in sorted(set(per[ok & (per > 0)].tolist()))[:12]:
        sel = shown[ok & (per == p)]
        click.echo(f"  period {p:2d}: {sel.size} points, {sparam} in [{sel.min():.6g}, {sel.max():.6g}]")
    words = np.array(reasons(status))
    for why in failures(status):
        sel = shown[words == why]
        click.echo(f"  failed, {why}: {sel.size} points, {sparam} in [{sel.min():.6g}, {sel.max():.6g}]")


def _hysteresis(spec: Any, run: _SweepRun) -> list[Any]:
    """Where the sweep up and the sweep down (``--direction both``) end differently."""
    from grazing.sweeps.store import build_dataset
    from grazing.sweeps.windows import find_hysteresis

    if run.arrays is not None:
        return find_hysteresis(build_dataset(spec, run.arrays))
    if run.ds is not None:
        return find_hysteresis(run.ds)
    # Streamed to a store: from the periods and impacts read back (orbits of one period are not compared).
    import xarray as xr

    flat = {"period": run.period, "status": run.status, "impacts": run.impacts}
    n = spec.segment_points
    values = np.asarray(spec.points[:n], dtype=float)[:, 0]
    order = np.argsort(values, kind="stable")
    both = {k: np.stack([v[:n][order], v[n:][::-1][order]]) for k, v in flat.items()}
    dims = ("direction", "point")
    light = xr.Dataset(
        {"period": (dims, both["period"]), "status": (dims, both["status"]),
         "impacts_per_period": (dims, both["impacts"].astype(float))},
        coords={"direction": ["up", "down"], "value": ("point", values[order])},
    )  # fmt: skip
    return find_hysteresis(light)


def _hysteresis_json(h: Any, par: Any) -> dict[str, Any]:
    return {"start": par.to_display(h.start), "stop": par.to_display(h.stop), "points": h.points,
            "up": h.up, "down": h.down}  # fmt: skip


_GRAZE_SEARCH = {"eta": (0.2, 1.0), "theta_hat": (-3.1, 3.1)}


def _map_for_sweep(model: Any, name: str, lo: float, hi: float, which: str) -> tuple[Any, dict[str, Any]]:
    """The discontinuity map at the first/second grazing for a sweep in ``name`` over ``[lo, hi]``."""
    from grazing.engine.runner import map_stops
    from grazing.normalform import find_grazing_point, normal_form_at

    pendulum = model.name == "pendulum"
    a, b = _GRAZE_SEARCH.get(name, (lo, hi)) if pendulum else (lo, hi)
    stops = map_stops(model)  # (with modes: the first stop of a mode, not a switch)
    if not stops:
        raise InputError(
            f"--method map: model {model.name!r} has no stop of a mode (a transition with a reset back into "
            "the mode it leaves) for the discontinuity map to stand for"
        )
    point = find_grazing_point(model, name, min(a, lo), max(b, hi), which, stop_name=stops[0])
    nf = normal_form_at(point, PENDULUM_UNFOLDING if pendulum else (name,))
    back = math.degrees if name == "theta_hat" else float
    info = {
        "param": name,
        "value": back(point.model.params[name]),
        "stop": point.stop_name,
        "t_graze": point.phase,
        "multipliers": complex_list(point.multipliers),
        "accel": nf.accel,
        "direction": nf.direction,
    }
    return nf.discontinuity_map(), info


@click.command("map")
@model_options(any_model=True, modes=True)
@click.option("--param1", required=True, metavar="NAME", help="Horizontal parameter (any of the model's).")
@click.option("--start1", type=FINITE, required=True)
@click.option("--stop1", type=FINITE, required=True)
@click.option("--num1", type=count(1), required=True)
@click.option("--param2", required=True, metavar="NAME", help="Vertical parameter (any of the model's).")
@click.option("--start2", type=FINITE, required=True)
@click.option("--stop2", type=FINITE, required=True)
@click.option("--num2", type=count(1), required=True)
@_sweep_options
def map_cmd(
    model: grazing.HybridModel, case: str,
    param1: str, start1: float, stop1: float, num1: int, param2: str, start2: float, stop2: float, num2: int,
    transient: int, periods: int, phase: float, initial: str, fresh: bool, chunk_size: int | None,
    workers: int | None, scheduler: str | None, timeout: float | None, device: str, no_lyapunov: bool,
    no_adaptive: bool,
    tol: float, out: Path | None, wait: bool, overwrite: bool, as_json: bool,
) -> None:  # fmt: skip
    """Two-parameter map of periods, impacts and Lyapunov exponents."""
    from grazing.sweeps.spec import map_spec
    from grazing.sweeps.status import failures, reasons

    par1, par2 = model_parameter(model, param1, "--param1"), model_parameter(model, param2, "--param2")
    n1, n2 = par1.name, par2.name
    if n1 == n2:
        raise InputError("--param1 and --param2 must differ")
    refuse_varied([n1, n2], f"with --param1 {param1} --param2 {param2}: the mapped values replace it")
    refuse_unused(["stop1"], num1 == 1 and stop1 != start1, ONE_VALUE.format(num="--num1", start="--start1"))
    refuse_unused(["stop2"], num2 == 1 and stop2 != start2, ONE_VALUE.format(num="--num2", start="--start2"))
    chunk_size = num1 if chunk_size is None else chunk_size
    _check_sweep_options(out, scheduler, chunk_size, num1 * num2, periods, model.n_states, workers, as_json,
                         "a map", overwrite)  # fmt: skip
    s1 = spaced_values(start1, stop1, num1, "--start1/--stop1")
    s2 = spaced_values(start2, stop2, num2, "--start2/--stop2")
    v1 = np.array([par1.from_display(v) for v in s1])
    v2 = np.array([par2.from_display(v) for v in s2])
    v1, v2 = np.sort(v1), np.sort(v2)
    for a, b in ((v1[0], v2[0]), (v1[-1], v2[-1])):
        model.with_params(**{n1: a, n2: b})
    x0 = parse_state(initial, model)
    settings = SweepSettings(
        transient=transient, periods=periods, phase=phase, fresh=fresh, chunk_size=chunk_size,
        adaptive=not no_adaptive, lyapunov=not no_lyapunov, tol=tol,
    )  # fmt: skip
    spec = map_spec(model, n1, v1, n2, v2, x0=x0, settings=settings)
    t0 = time.perf_counter()
    run = _run_sweep_spec(
        spec, out, scheduler, workers, as_json, wait, timeout, overwrite=overwrite, device=device
    )
    elapsed = time.perf_counter() - t0
    if as_json:
        ds = run.ds
        res = {
            "params": model_params_json(model, case),
            "param1": param1, "values1": np.sort(s1), "param2": param2, "values2": np.sort(s2),
            "period": ds.period.values, "impacts_per_period": ds.impacts_per_period.values,
            "lyapunov": ds.lyapunov.values, "elapsed_s": elapsed, "out": str(out) if out else None,
            "status": reasons(ds.status.values), "phase": phase,
        }  # fmt: skip
        emit_json(res)
        return
    periodic, aperiodic, failed = _outcomes(run.period, run.status)
    click.echo(
        f"{num1} x {num2} map in {elapsed:.1f} s; periodic cells {periodic}, none {aperiodic}, {failed}"
    )
    words = np.array(reasons(run.status))
    for why in failures(run.status):
        cells = np.flatnonzero(words == why)  # (row by row: param2's index, then param1's)
        a, b = np.sort(s1)[cells % num1], np.sort(s2)[cells // num1]
        click.echo(
            f"  failed, {why}: {cells.size} cells, {param1} in [{a.min():.6g}, {a.max():.6g}], "
            f"{param2} in [{b.min():.6g}, {b.max():.6g}]"
        )
    if out is not None:
        click.echo(f"saved to {out}")
