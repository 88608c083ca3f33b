"""``grazing basins``, ``grazing attractors``: coexisting attractors, their basins, their continuation."""

from __future__ import annotations

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
    InputError,
    Progress,
    check_folder,
    check_out,
    check_span,
    emit_json,
    json_option,
    model_options,
    model_parameter,
    model_params_json,
    overwrite_option,
    parse_pair,
    refuse_varied,
    save_dataset,
    spaced_values,
)
from grazing.cli.limits import basin_bytes, check_memory, count_text
from grazing.cli.validate import FINITE, TOLERANCE, WORKERS, Number, count, path_type, refuse_unused
from grazing.core.options import (
    BASIN_CHUNK,
    BASIN_PERIODS,
    BASIN_REFINE,
    BASIN_TRANSIENT,
    CELL_FRACTION,
    SWEEP_TOL,
)
from grazing.gpu.device import DEFAULT_DEVICE, DEVICES, check_device

CELL = Number(0.0, 1.0, low_open=False, high_open=False)
"""A recurrence cell as a fraction of an attractor's extent (``--cell``)."""


def _grid_options(num_name: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """The options of a grid of initial states (``--num`` or ``--num-grid`` for its counts) and its runs."""

    def decorate(func: Callable[..., Any]) -> Callable[..., Any]:
        options = [
            click.option(
                "--x-range",
                "x_range",
                required=True,
                metavar="LO,HI",
                help="Range of the first state of the grid (--states).",
            ),
            click.option(
                "--y-range",
                "y_range",
                required=True,
                metavar="LO,HI",
                help="Range of the second state of the grid.",
            ),
            click.option(
                num_name,
                "num_grid",
                required=True,
                metavar="N1,N2",
                help="Initial states along x and along y (at least 1 each).",
            ),
            click.option(
                "--states",
                default="0,1",
                show_default=True,
                metavar="I,J",
                help="The two states of the grid, by index (from 0) or name.",
            ),
            click.option(
                "--fixed",
                multiple=True,
                metavar="STATE=VALUE",
                help="Value of another state (by index or name; repeatable; default 0).",
            ),
            click.option(
                "--phase",
                type=FINITE,
                default=0.0,
                show_default=True,
                metavar="PHI",
                help="Forcing phase of the initial states and of the samples, in radians.",
            ),
            click.option(
                "--transient",
                type=count(0),
                default=BASIN_TRANSIENT,
                show_default=True,
                help="Forcing periods run from each initial state before sampling.",
            ),
            click.option(
                "--periods",
                type=count(2),
                default=BASIN_PERIODS,
                show_default=True,
                help="Forcing periods sampled on the attractor.",
            ),
            click.option(
                "--refine",
                type=count(0),
                default=BASIN_REFINE,
                show_default=True,
                help="Times an aperiodic end state is run on for another transient.",
            ),
            click.option("--no-lyapunov", is_flag=True, help="Skip the Lyapunov exponents."),
            click.option(
                "--cell",
                "cell_fraction",
                type=CELL,
                default=CELL_FRACTION,
                show_default=True,
                metavar="FRACTION",
                help="Recurrence cell of a chaotic or quasi-periodic attractor, as a fraction of its own "
                "extent in each state (0: the grid box over 64): end states whose samples come within "
                "one cell are on one attractor.",
            ),
            click.option(
                "--tol",
                type=TOLERANCE,
                default=SWEEP_TOL,
                show_default=True,
                help="Integrator tolerance, in (0, 0.01).",
            ),
            click.option("--workers", type=WORKERS, help="Local threads (default: all cores)."),
            click.option(
                "--device",
                type=click.Choice(DEVICES),
                default=DEFAULT_DEVICE,
                show_default=True,
                help="Where the runs go: the CPU lanes, an NVIDIA GPU (one CUDA thread per initial state, "
                "the runs with Lyapunov exponents and models with modes too), or the GPU when one is present "
                "and the grid is large (auto).",
            ),
            click.option(
                "--plot",
                type=path_type(dir_okay=False),
                metavar="FILE.png",
                help="Draw the basins (basins) or the basin fractions (attractors).",
            ),
            overwrite_option,
            json_option,
        ]
        for opt in reversed(options):
            func = opt(func)
        return func

    return decorate


def _counts(text: str, option: str) -> tuple[int, int]:
    """``N1,N2``: two counts of at least 1 (an empty grid is refused)."""
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        n1, n2 = (int(p) for p in parts)
    except ValueError:
        raise InputError(f"{option} must be N1,N2 (two whole numbers), got {text!r}") from None
    if n1 < 1 or n2 < 1:
        raise InputError(f"{option} must be at least 1 along each state (an empty grid), got {text!r}")
    return n1, n2


def _fixed(items: tuple[str, ...]) -> dict[str, float]:
    """``--fixed STATE=VALUE`` (repeatable, last wins)."""
    out: dict[str, float] = {}
    for item in items:
        name, eq, text = item.partition("=")
        try:
            if not eq or not name.strip():
                raise ValueError
            value = float(text)
        except ValueError:
            raise InputError(f"--fixed {item!r}: expected STATE=VALUE (a number)") from None
        out[name.strip()] = value
    return out


def _grid(
    model: grazing.HybridModel,
    x_range: str,
    y_range: str,
    num: str,
    num_option: str,
    states: str,
    fixed: tuple[str, ...],
    phase: float,
) -> Any:
    """The grid of initial states the options describe; one line for anything wrong with it."""
    from grazing.attractors.grid import state_grid

    xr_ = parse_pair(x_range, "--x-range", "LO,HI")
    yr_ = parse_pair(y_range, "--y-range", "LO,HI")
    check_span(*xr_, "--x-range")
    check_span(*yr_, "--y-range")
    n = _counts(num, num_option)
    names = [s.strip() for s in states.split(",")]
    if len(names) != 2 or not all(names):
        raise InputError(f"--states must be I,J (two state indices or names), got {states!r}")
    try:
        return state_grid(model, xr_, yr_, n, states=names, fixed=_fixed(fixed), phase=phase)
    except grazing.InvalidParameterError as exc:
        option = (
            "--fixed"
            if "fixed" in str(exc)
            else ("--states" if "state" in str(exc) else "--x-range/--y-range")
        )
        raise InputError(f"{option}: {exc}") from None


def _check_outputs(out: Path | None, plot: Path | None, overwrite: bool, wait: bool, zarr_ok: bool) -> bool:
    """Check ``--out`` and ``--plot`` before any work; whether ``--out`` is a Zarr store."""
    suffixes = (".nc", ".zarr") if zarr_ok else (".nc",)
    if out is not None and out.suffix.lower() not in suffixes:
        raise InputError(f"--out must end in {' or '.join(suffixes)}, got {str(out)!r}")
    zarr_out = out is not None and out.suffix.lower() == ".zarr"
    if zarr_out:
        check_folder(out)
        if out.exists():
            from grazing.sweeps.ownership import check_is_store

            check_is_store(out)
    elif out is not None:
        check_out(out, ".nc", overwrite=overwrite)
    if plot is not None:
        check_out(plot, ".png", "--plot", overwrite)
    refuse_unused(["overwrite"], out is None and plot is None, "without --out or --plot")
    no_file = "with a Zarr store and no --plot (a store is never replaced)"
    refuse_unused(["overwrite"], zarr_out and plot is None, no_file)
    refuse_unused(["wait"], not zarr_out, "without a Zarr store (--out FILE.zarr)")
    return zarr_out


def _settings(
    transient: int, periods: int, phase: float, refine: int, no_lyapunov: bool, tol: float, chunk_size: int
) -> Any:
    from grazing.core.options import BasinSettings

    return BasinSettings(
        transient=transient,
        periods=periods,
        phase=phase,
        refine=refine,
        lyapunov=not no_lyapunov,
        tol=tol,
        chunk_size=chunk_size,
    )


def _attractor_lines(atts: list[Any], model: grazing.HybridModel) -> list[str]:
    from grazing.attractors.kinds import AttractorKind
    from grazing.plotting.attractors import describe

    lines = []
    for a in atts:
        words = describe(a.kind, a.period, a.impacts_per_period)
        if a.reason and a.kind is not AttractorKind.PERIODIC:
            words += f" ({a.reason})"
        if np.isfinite(a.lyapunov):
            words += f", lyapunov {a.lyapunov:+.4g}"
        elif a.lyapunov == -np.inf:
            words += ", lyapunov -inf (every motion near it lands on it exactly: reached in finite time)"
        if a.kind is AttractorKind.NEUTRAL:
            words += " (a double multiplier 1: a family of motions, not an isolated attractor)"
        if a.mode:
            words += f", in mode {a.mode}"
        if len(a.points) and not a.kind.aperiodic:
            pt = ", ".join(f"{n} = {v:.6g}" for n, v in zip(model.state_names, a.points[0]))
            words += f"; at {pt}"
        lines.append(f"  {a.id}: {words}: {a.count} initial states ({100 * a.fraction:.2f}%)")
    return lines


@click.command("basins")
@model_options(any_model=True, modes=True)
@_grid_options("--num")
@click.option(
    "--chunk-size",
    type=count(1),
    default=BASIN_CHUNK,
    show_default=True,
    help="Initial states per chunk: the unit of parallel work and of saving.",
)
@click.option(
    "--out",
    type=path_type(),
    metavar="FILE.nc|FILE.zarr",
    help="The basins as NetCDF, or a Zarr store of the end states (resumable; one run at a time).",
)
@click.option(
    "--wait", is_flag=True, help="If another run is writing the --out store, wait for it instead of stopping."
)
def basins_cmd(
    model: grazing.HybridModel,
    case: str,
    x_range: str,
    y_range: str,
    num_grid: str,
    states: str,
    fixed: tuple[str, ...],
    phase: float,
    transient: int,
    periods: int,
    refine: int,
    no_lyapunov: bool,
    cell_fraction: float,
    tol: float,
    workers: int | None,
    plot: Path | None,
    overwrite: bool,
    as_json: bool,
    chunk_size: int,
    out: Path | None,
    wait: bool,
    device: str,
) -> None:
    """Attractors and their basins on a grid of initial states (a slice of two states at a phase)."""
    from grazing.attractors.basins import find_attractors, to_dataset

    grid = _grid(model, x_range, y_range, num_grid, "--num", states, fixed, phase)
    zarr_out = _check_outputs(out, plot, overwrite, wait, zarr_ok=True)
    check_device(device)  # (before a store is made: an error writes nothing)
    n = grid.size
    need = basin_bytes(
        n,
        periods,
        model.n_states,
        chunk_points=chunk_size,
        workers=workers or os.cpu_count() or 1,
        as_json=as_json,
    )
    check_memory(
        need,
        f"a basin of {count_text(n)} initial states",
        "use a coarser grid (--num), or split the ranges into several runs",
    )
    settings = _settings(transient, periods, phase, refine, no_lyapunov, tol, chunk_size)
    store: Any = None
    bar = Progress("basins", enabled=not as_json, unit="initial states")
    start = time.perf_counter()
    try:
        if zarr_out:
            from grazing.attractors.basins import basin_spec, outside
            from grazing.attractors.grid import start_time
            from grazing.sweeps.store import ZarrStore

            x = grid.states_array()
            valid = x[~outside(model, x, start_time(model, phase))]
            if valid.size:
                spec = basin_spec(model, valid, settings, not no_lyapunov and refine == 0)
                store = ZarrStore(
                    out,
                    spec,
                    attrs={"command": " ".join(["grazing", *sys.argv[1:]])},
                    wait=wait,
                    on_wait=lambda pid: click.echo(
                        f"grazing: {out} is being written by another grazing run"
                        + (f" (PID {pid})" if pid is not None else "")
                        + "; waiting",
                        err=True,
                    ),
                )
        found = find_attractors(
            model,
            grid.states_array(),
            settings=settings,
            cell_fraction=cell_fraction,
            workers=workers,
            store=store,
            progress=bar,
            device=device,
        )
    finally:
        bar.close()
        if store is not None:
            store.close()
    elapsed = time.perf_counter() - start
    ds = to_dataset(model, grid, found)
    if out is not None and not zarr_out:
        save_dataset(ds, out, overwrite)
    if plot is not None:
        _plot(lambda ax: _draw_basins(ax, ds), plot, overwrite)
    i, j = grid.states
    if as_json:
        emit_json(
            {
                "params": model_params_json(model, case),
                "states": [model.state_names[i], model.state_names[j]],
                "initial_state": list(grid.base),
                "phase": phase,
                "transient": transient,
                "periods": periods,
                "cell": cell_fraction,
                "polished": found.polished,
                "x": grid.x,
                "y": grid.y,
                "labels": found.labels.reshape(grid.shape),
                "attractors": [a.to_json() for a in found.attractors],
                "fractions": {str(a.id): a.fraction for a in found.attractors},
                "elapsed_s": elapsed,
                "out": str(out) if out else None,
                "plot": str(plot) if plot else None,
            }
        )
        return
    names = model.state_names
    click.echo(
        f"{grid.size} initial states ({grid.x.size} x {grid.y.size} in {names[i]}, {names[j]}) in "
        f"{elapsed:.1f} s: {len(found.attractors)} attractors and outcomes"
    )
    for line in _attractor_lines(list(found.attractors), model):
        click.echo(line)
    if out is not None:
        click.echo(f"saved to {out}")
    if plot is not None:
        click.echo(f"plot written to {plot}")


@click.command("attractors")
@model_options(any_model=True, modes=True)
@click.option(
    "--param", "aparam", required=True, metavar="NAME", help="Parameter to vary (angles in degrees)."
)
@click.option("--start", type=FINITE, required=True, help="First parameter value.")
@click.option("--stop", type=FINITE, required=True, help="Last parameter value.")
@click.option("--num", type=count(1), required=True, help="Number of parameter values.")
@_grid_options("--num-grid")
@click.option(
    "--seeds",
    type=count(0),
    default=8,
    show_default=True,
    help="Points of each attractor run again as initial states at the next value.",
)
@click.option(
    "--out", type=path_type(dir_okay=False), metavar="FILE.nc", help="Save the continuation as NetCDF."
)
def attractors_cmd(
    model: grazing.HybridModel,
    case: str,
    aparam: str,
    start: float,
    stop: float,
    num: int,
    x_range: str,
    y_range: str,
    num_grid: str,
    states: str,
    fixed: tuple[str, ...],
    phase: float,
    transient: int,
    periods: int,
    refine: int,
    no_lyapunov: bool,
    cell_fraction: float,
    tol: float,
    workers: int | None,
    plot: Path | None,
    overwrite: bool,
    as_json: bool,
    seeds: int,
    out: Path | None,
    device: str,
) -> None:
    """Global continuation: the attractors and their basin fractions along a parameter."""
    from grazing.attractors.continuation import continue_attractors

    par = model_parameter(model, aparam)
    refuse_varied([par.name], f"with --param {aparam}: the values of --start/--stop replace it")
    refuse_unused(
        ["stop"],
        num == 1 and stop != start,
        f"with --num 1 (its one value is --start {start:g}: give the same value to both, or --num 2 or more)",
    )
    for v in (start, stop):  # (the ends' values, before the --num values are made: after the check below)
        model.with_params(**{par.name: par.from_display(v)})
    grid = _grid(model, x_range, y_range, num_grid, "--num-grid", states, fixed, phase)
    _check_outputs(out, plot, overwrite, False, zarr_ok=False)
    check_device(device)
    need = basin_bytes(
        grid.size,
        periods,
        model.n_states,
        chunk_points=BASIN_CHUNK,
        workers=workers or os.cpu_count() or 1,
        as_json=as_json,
        values=num,
    )
    check_memory(
        need,
        f"{count_text(num)} basins of {count_text(grid.size)} initial states",
        "use a coarser grid (--num-grid) or fewer values",
    )
    shown = spaced_values(start, stop, num, "--start/--stop")
    values = np.array([par.from_display(v) for v in shown])
    settings = _settings(transient, periods, phase, refine, no_lyapunov, tol, BASIN_CHUNK)
    bar = Progress("attractors", enabled=not as_json, unit="values")
    t0 = time.perf_counter()
    try:
        names = [s.strip() for s in states.split(",")]
        ds = continue_attractors(
            model,
            par.name,
            values,
            grid.x[[0, -1]],
            grid.y[[0, -1]],
            (grid.x.size, grid.y.size),
            states=names,
            fixed=_fixed(fixed),
            settings=settings,
            seeds=seeds,
            cell_fraction=cell_fraction,
            workers=workers,
            progress=bar,
            device=device,
        )
    finally:
        bar.close()
    elapsed = time.perf_counter() - t0
    if out is not None:
        save_dataset(ds, out, overwrite)
    if plot is not None:
        from grazing.plotting.attractors import plot_fractions

        _plot(lambda ax: plot_fractions(ax, ds), plot, overwrite)
    ids = [int(a) for a in ds.attractor.values]
    if as_json:
        emit_json(
            {
                "params": model_params_json(model, case),
                "param": aparam,
                "values": shown,
                "states": str(ds.attrs["states"]).split(","),
                "attractors": [_followed_json(ds, k, ident) for k, ident in enumerate(ids)],
                "fractions": [
                    {
                        str(ident): float(ds.fraction.values[i, k])
                        for k, ident in enumerate(ids)
                        if ds.present.values[i, k]
                    }
                    for i in range(num)
                ],
                "elapsed_s": elapsed,
                "out": str(out) if out else None,
                "plot": str(plot) if plot else None,
            }
        )
        return
    click.echo(
        f"{num} values of {aparam}, {grid.size} initial states each, in {elapsed:.1f} s: "
        f"{len(ids)} attractors and outcomes followed"
    )
    for k, ident in enumerate(ids):
        here = np.flatnonzero(ds.present.values[:, k])
        kinds = sorted({str(x) for x in ds.kind.values[here, k]})
        lo, hi = shown[here].min(), shown[here].max()
        top = float(ds.fraction.values[here, k].max())
        click.echo(
            f"  {ident}: {', '.join(kinds)}; {aparam} in [{lo:.6g}, {hi:.6g}] ({here.size} values), "
            f"largest basin fraction {top:.3f}"
        )
    if out is not None:
        click.echo(f"saved to {out}")
    if plot is not None:
        click.echo(f"plot written to {plot}")


def _followed_json(ds: Any, k: int, ident: int) -> dict[str, Any]:
    """One followed attractor of ``attractors --json``: per value (null where it is not found)."""
    present = ds.present.values[:, k]
    pts = ds.points.values[:, k]

    def per_value(values: np.ndarray, cast: Callable[[Any], Any]) -> list[Any]:
        return [cast(v) if p else None for v, p in zip(values, present)]

    return {
        "id": ident,
        "present": present,
        "kind": per_value(ds.kind.values[:, k], str),
        "period": per_value(ds.period.values[:, k], lambda v: int(v) if v >= 0 else None),
        "impacts_per_period": per_value(ds.impacts_per_period.values[:, k], float),
        "lyapunov": per_value(ds.lyapunov.values[:, k], float),
        "points": [p_[~np.isnan(p_).any(axis=1)] if p else None for p_, p in zip(pts, present)],
    }


def _draw_basins(ax: Any, ds: Any) -> None:
    from grazing.plotting.attractors import plot_basins

    plot_basins(ax, ds)


def _plot(draw: Callable[[Any], None], path: Path, overwrite: bool) -> None:
    """Draw on a new figure and write it as a PNG of grazing's (all at once)."""
    from matplotlib.figure import Figure

    from grazing.cli.common import OVERWRITE_HINT
    from grazing.outputs import save_png

    fig = Figure(figsize=(9.0, 5.0), layout="constrained")
    draw(fig.add_subplot())
    save_png(fig, path, dpi=150, overwrite=overwrite, hint=OVERWRITE_HINT)


COMMANDS = (basins_cmd, attractors_cmd)
