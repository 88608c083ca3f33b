"""Coexisting attractors at the paper's second grazing (case B, θ̂ = 40°): hysteresis, basins, from rest.

Past the second grazing (η = 0.5473) the nonimpacting period-1 orbit exists
again, but the impacting period-1 orbit goes on beside it up to its fold: two
attractors coexist.  Sweeps up and down in η (:func:`grazing.sweeps.sweep`
with ``direction="both"``, chunks checked to be one chain each) show the
hysteresis loop; a grid of initial states at one η inside it
(:func:`grazing.attractors.basins`) shows the two basins; and sweeps from rest
at every η (``fresh``) show what an experiment switching the forcing on at
each frequency would see.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import grazing
from grazing.attractors import basins
from grazing.attractors.classify import set_distance
from grazing.attractors.grid import start_time
from grazing.attractors.kinds import AttractorKind
from grazing.core.options import SWEEP_TOL
from grazing.core.period import detect_period
from grazing.orbits import find_grazings
from grazing.plotting import mark_grazings, plot_basins, plot_bifurcation
from grazing.report import paper
from grazing.report.base import Comparison, DataFile, FigureResult, Image, Say, new_figure, save_png
from grazing.report.data import write_dataset
from grazing.report.rules import criterion_row, numeric_row
from grazing.sweeps import sweep

FIGURE_ID = "attractors"
THETA_HAT_DEG = 40.0


@dataclass(frozen=True)
class Settings:
    """Resolution and cost of the section."""

    eta: tuple[float, float, int] = (0.50, 0.70, 161)
    """η range and number of sweep points."""
    transient: int = 300
    periods: int = 50
    chunk_size: int = 20
    """Points per chunk of the sweeps (each checked against one chain)."""
    basin_eta: float = 0.60
    """The η of the basins: inside the hysteresis loop."""
    grid: tuple[int, int] = (90, 90)
    """Initial states along θ and θ′."""
    theta_range: tuple[float, float] = (-1.5, math.radians(THETA_HAT_DEG))
    dtheta_range: tuple[float, float] = (-1.5, 1.5)
    checked_cells: int = 16
    """Initial states of the grid simulated on their own, as a check."""
    workers: int | None = None


SETTINGS = Settings()
"""Resolution used by the report (tests pass a smaller one to :func:`build`)."""


@dataclass
class Run:
    """Everything the section shows."""

    model: Any
    both: Any
    chain: Any
    rest: Any
    basins: Any
    grazing_eta: float
    seconds: float


def compute(s: Settings, progress: Say | None = None) -> Run:
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    model = grazing.models.pendulum("B", theta_hat=math.radians(THETA_HAT_DEG))
    etas = np.linspace(*s.eta[:2], s.eta[2])
    kw = {"transient": s.transient, "periods": s.periods, "workers": s.workers}
    say(f"attractors: sweeps up and down in η, {etas.size} points each, and from rest")
    both = sweep(model, "eta", etas, direction="both", chunk_size=s.chunk_size, **kw)
    chain = {d: sweep(model, "eta", etas, direction=d, chunk_size=0, **kw) for d in ("up", "down")}
    rest = sweep(model, "eta", etas, fresh=True, **kw)
    grazings, _ = find_grazings(model, "eta", s.eta[0], s.eta[1])
    say(f"attractors: basins at η = {s.basin_eta:g}, {s.grid[0]} × {s.grid[1]} initial states")
    at = model.with_params(eta=s.basin_eta)
    ds = basins(
        at, s.theta_range, s.dtheta_range, s.grid, transient=s.transient, periods=s.periods, workers=s.workers
    )
    eta_g = float(grazings[0].model.params["eta"]) if grazings else math.nan
    return Run(model, both, chain, rest, ds, eta_g, time.perf_counter() - start)


def impacting(ds: Any) -> np.ndarray:
    """Whether each point of a sweep (by value) impacts."""
    return np.asarray(ds.impacts_per_period.values, dtype=float) > 0


def loop(run: Run) -> tuple[float, float]:
    """The hysteresis loop: the last nonimpacting value swept down, the last impacting value swept up."""
    eta = run.both.value.values
    down = impacting(run.both.sel(direction="down"))
    up = impacting(run.both.sel(direction="up"))
    return float(eta[~down].min()), float(eta[up].max())


def _kinds(run: Run) -> dict[str, Any]:
    """The basin dataset's impacting and nonimpacting period-1 orbits (by the impacts of each)."""
    ds = run.basins
    out = {}
    for k in range(ds.attractor.size):
        if str(ds.kind.values[k]) == AttractorKind.PERIODIC and int(ds.period.values[k]) == 1:
            out["impacting" if ds.impacts_per_period.values[k] > 0 else "nonimpacting"] = k
    return out


def draw(run: Run, s: Settings, path: Path) -> None:
    from matplotlib.lines import Line2D

    from grazing.plotting.diagrams import DIRECTION_COLORS, DIRECTION_MARKERS

    fig, axes = new_figure(1, 2, (13.0, 4.8))
    ax1, ax2 = np.ravel(axes)
    plot_bifurcation(ax1, run.both, windows=False, nonimpacting=False)
    eta = run.rest.value.values
    theta = np.degrees(run.rest.samples.values[:, -1, 0])
    ax1.plot(eta, theta, "o", ms=5, mfc="none", mec="0.35", mew=0.6, zorder=1.5)
    _, hi = loop(run)
    ax1.axvspan(run.grazing_eta, hi, color="#f3e9df", lw=0, zorder=-1)
    mark_grazings(ax1, [run.grazing_eta], labels=[f"grazing η = {run.grazing_eta:.4f}"])
    ax1.axvline(s.basin_eta, color="0.4", lw=0.8, ls=":")
    handles = [
        *(
            Line2D(
                [],
                [],
                ls="none",
                color=DIRECTION_COLORS[way],
                label=f"swept {way}",
                **{**DIRECTION_MARKERS[way], "ms": 1.6 * DIRECTION_MARKERS[way]["ms"]},
            )
            for way in ("up", "down")
        ),  # (the plot's markers, a little larger)
        Line2D([], [], ls="none", marker="o", ms=5, mfc="none", mec="0.35", label="from rest (last sample)"),
    ]
    ax1.legend(handles=handles, loc="upper right", fontsize=8, frameon=False)
    ax1.set_title(
        f"case B, θ̂ = {THETA_HAT_DEG:g}°: swept up and down, and from rest at each η\n"
        f"(shaded: both period-1 orbits are stable, η in [{run.grazing_eta:.4f}, {hi:.4f}])",
        fontsize=10,
    )
    plot_basins(ax2, run.basins)
    ax2.plot([0.0], [0.0], "*", ms=14, mfc="white", mec="k", zorder=4)
    ax2.annotate("rest", (0.0, 0.0), xytext=(6, -12), textcoords="offset points", fontsize=9)
    ax2.set_title(f"basins at η = {s.basin_eta:g} (★: the pendulum at rest)", fontsize=10)
    save_png(fig, path)


def comparisons(run: Run, s: Settings) -> tuple[Comparison, ...]:
    rows: list[Comparison] = []
    both = run.both
    eta = both.value.values
    step = float(eta[1] - eta[0])
    differ = 0
    for d in ("up", "down"):
        a, b = both.sel(direction=d), run.chain[d]
        same = (a.period.values == b.period.values) & (a.status.values == b.status.values)
        periodic = b.period.values > 0
        close = (
            np.nanmax(np.abs(a.samples.values[periodic] - b.samples.values[periodic]), axis=(1, 2)) <= 1e-5
        )
        differ += int((~same).sum() + (~close).sum())
    rows.append(
        criterion_row(
            FIGURE_ID,
            f"the sweeps up and down in chunks of {s.chunk_size} against one continuous chain each",
            "equal at every point",
            "equal at every point" if differ == 0 else f"differ at {differ} points",
            differ == 0,
            kind="self-check",
            rule="agree when every point has the chain's status and period, and on a periodic orbit its "
            "samples to 1e-5",
        )
    )
    lo, hi = loop(run)
    rows.append(
        numeric_row(
            FIGURE_ID,
            "swept down: the last η of the nonimpacting orbit, against the second grazing from continuation",
            run.grazing_eta,
            lo,
            kind="self-check",
            tolerance=2 * step,
            decimals=4,
            why_tolerance=f"two sweep steps, {2 * step:.2g}",
            paper_text=f"{run.grazing_eta:.6f}",
            note="going down, the nonimpacting orbit is kept until it grazes the stop; its basin shrinks to "
            "nothing at the grazing, so the jump of a step in η knocks the motion off it a step or so before",
        )
    )
    aperiodic = int(sum((both.sel(direction=d).period.values <= 0).sum() for d in ("up", "down")))
    rows.append(
        criterion_row(
            FIGURE_ID,
            f"θ̂ = 40°, η in [{s.eta[0]:g}, {s.eta[1]:g}] swept up and down: chaos at the return to "
            "nonimpacting motion",
            paper.SUDDEN_RETURN,
            f"{aperiodic} aperiodic points of {2 * eta.size}; period 1 throughout, with a hysteresis loop "
            f"over η in [{lo:.4f}, {hi:.4f}]",
            aperiodic == 0,
            kind="paper",
            rule="agree when no point of either sweep is aperiodic (no period ≤ 25)",
            source="§6.1",
            note="the return is sudden both ways, but not at one η: swept up, the impacting orbit is kept "
            f"past the grazing up to its fold near η = {hi:.3f}",
        )
    )
    kinds = _kinds(run)
    ds = run.basins
    cell = np.array(eval_cell(ds))
    found = {}
    for name, d in (("impacting", "up"), ("nonimpacting", "down")):
        sw = both.sel(direction=d)
        k = int(np.argmin(np.abs(eta - s.basin_eta)))
        orbit = sw.samples.values[k, -1:, :]
        if name in kinds:
            pts = ds.points.values[kinds[name], : int(ds.n_points.values[kinds[name]])]
            found[name] = set_distance(pts, orbit, cell)
    both_found = len(found) == 2 and max(found.values()) <= 1e-3
    fr = {n: float(ds.fraction.values[k]) for n, k in kinds.items()}
    rows.append(
        criterion_row(
            FIGURE_ID,
            f"basins at η = {s.basin_eta:g}: the two period-1 orbits, as the sweeps up and down end on them",
            "both found",
            ", ".join(f"{n} ({100 * f:.1f}% of the grid)" for n, f in fr.items()),
            both_found,
            kind="self-check",
            rule="agree when the grid finds an impacting and a nonimpacting period-1 orbit, each within 1e-3 "
            "cells of the sweep's (up, down) final sample at that η",
        )
    )
    rest_label = int(ds.label.sel(x=0.0, y=0.0, method="nearest"))
    k_rest = int(np.flatnonzero(ds.attractor.values == rest_label)[0])
    rest_orbit = run.rest.samples.values[int(np.argmin(np.abs(eta - s.basin_eta))), -1:, :]
    pts = ds.points.values[k_rest, : int(ds.n_points.values[k_rest])]
    d_rest = set_distance(pts, rest_orbit, cell)
    rows.append(
        criterion_row(
            FIGURE_ID,
            f"η = {s.basin_eta:g}, from rest: the attractor of the rest state on the grid, against a run",
            "the same orbit",
            f"{'impacting' if ds.impacts_per_period.values[k_rest] > 0 else 'nonimpacting'} period "
            f"{int(ds.period.values[k_rest])} (distance {d_rest:.1e} cells)",
            d_rest <= 1e-3,
            kind="self-check",
            rule="agree when the sweep from rest at that η ends within 1e-3 cells of the attractor the grid "
            "labels the rest state with",
        )
    )
    rows.append(cells_check(run, s, cell))
    return tuple(rows)


def eval_cell(ds: Any) -> list[float]:
    """The cell sizes the basins were computed with (the dataset's ``cell`` attribute)."""
    import json

    return json.loads(ds.attrs["cell"])


def cells_check(run: Run, s: Settings, cell: np.ndarray) -> Comparison:
    """Initial states of the grid simulated on their own (``grazing.simulate``): each on its attractor?"""
    ds = run.basins
    model = run.model.with_params(eta=s.basin_eta)
    rng = np.random.default_rng(28)
    n2, n1 = ds.label.shape
    picks = rng.choice(n1 * n2, size=min(s.checked_cells, n1 * n2), replace=False)
    ok = 0
    for flat in picks:
        j, i = divmod(int(flat), n1)
        label = int(ds.label.values[j, i])
        k = int(np.flatnonzero(ds.attractor.values == label)[0])
        x0 = [float(ds.x.values[i]), float(ds.y.values[j])]
        if str(ds.kind.values[k]) == AttractorKind.INVALID:
            ok += 1
            continue
        sol = grazing.simulate(
            model, x0, t0=start_time(model, 0.0), transient=3 * s.transient, periods=s.periods, tol=SWEEP_TOL
        )
        p = int(ds.period.values[k])
        pts = ds.points.values[k, : int(ds.n_points.values[k])]
        ok += int(detect_period(sol.samples) == p and set_distance(sol.samples[-p:], pts, cell) <= 1e-2)
    return criterion_row(
        FIGURE_ID,
        f"basins at η = {s.basin_eta:g}: {len(picks)} initial states of the grid simulated on their own",
        "each ends on its attractor",
        f"{ok} of {len(picks)}",
        ok == len(picks),
        kind="self-check",
        rule="agree when every one, simulated by grazing.simulate for three times the transient, has its "
        "attractor's period and ends within 0.01 cells of its points",
    )


def notes(run: Run, s: Settings) -> tuple[str, ...]:
    _, hi = loop(run)
    eta = run.rest.value.values
    rest_imp = impacting(run.rest)
    last = float(eta[rest_imp].max()) if rest_imp.any() else math.nan
    fr = {n: 100 * float(run.basins.fraction.values[k]) for n, k in _kinds(run).items()}
    return (
        f"Swept up in η, the pendulum stays on its impacting period-1 orbit past the second grazing up to "
        f"η = {hi:.4f} (the orbit's fold, between this sweep point and the next), then jumps to the "
        "nonimpacting orbit; swept down, it stays nonimpacting down to the grazing "
        f"(η = {run.grazing_eta:.4f}) and then impacts. Between the two, both period-1 orbits are stable: "
        f"at η = {s.basin_eta:g} the impacting one attracts {fr.get('impacting', math.nan):.1f}% of the "
        f"grid of initial states and the nonimpacting one {fr.get('nonimpacting', math.nan):.1f}%; the "
        "rest of the grid ends resting on the back of the stop (thrown over the top) or starts beyond it.",
        "What the experiment would see from rest (the forcing switched on with the pendulum hanging still, "
        f"at each η): the impacting orbit up to η = {last:.4f}, the nonimpacting one above — neither the up "
        f"sweep's η = {hi:.4f} nor the grazing's {run.grazing_eta:.4f}. The paper's experiment (§2.2) "
        f"reports at 20°–40° that {paper.END_OF_IMPACTING}; in the model, at 40°, where that jump happens "
        "depends on the history: a measured jump η locates the loop, not the grazing, unless the sweep goes "
        "down.",
    )


def write_data(run: Run, out_dir: Path) -> DataFile:
    import xarray as xr

    keep = ["period", "impacts_per_period", "lyapunov", "status"]
    sweeps = run.both[keep].rename({"point": "eta_index"}).drop_vars(["eta", "value"], errors="ignore")
    sweeps = sweeps.assign_coords(eta=("eta_index", run.both.value.values))
    sweeps["from_rest_period"] = ("eta_index", run.rest.period.values)
    sweeps["from_rest_impacts_per_period"] = ("eta_index", run.rest.impacts_per_period.values)
    basin = run.basins.drop_vars(["points"])
    basin = basin.rename({name: f"basin_{name}" for name in basin.data_vars})
    ds = xr.merge([sweeps, basin], combine_attrs="drop", compat="override", join="outer")
    ds.attrs = {"description": "case B, 40 deg: sweeps up and down and from rest in eta; basins at one eta"}
    path = write_dataset(out_dir / "attractors.nc", ds)
    return DataFile(path.name, "the sweeps' periods and impacts (up, down, from rest) and the basins, NetCDF")


def build(out_dir: Path, progress: Say | None = None, settings: Settings | None = None) -> FigureResult:
    """Compute the section, write its PNG and data into ``out_dir`` and describe it."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    s = settings or SETTINGS
    run = compute(s, say)
    name = "attractors_second_grazing.png"
    draw(run, s, out_dir / name)
    image = Image(
        name,
        f"Left: θ sampled at τ = 2πk against η, case B, θ̂ = 40°, {s.eta[2]} values swept upwards (blue) and "
        f"downwards (orange), each from the previous one's final state ({s.transient} transient and "
        f"{s.periods} sampled periods; in chunks of {s.chunk_size}, each checked to be one chain), and from "
        "rest at each η (grey circles: the last sample). Dashed: the second grazing from continuation; "
        f"shaded: the hysteresis loop. Right: the basins at η = {s.basin_eta:g} on a "
        f"{s.grid[0]} × {s.grid[1]} grid of initial states (θ, θ′) at τ = 0, each coloured by the attractor "
        "it ends on, the attractors' points drawn on top; the star is the pendulum at rest.",
        "Sweeps up and down through the second grazing at 40 degrees; the basins of the two period-1 orbits",
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="Extra: coexisting attractors at the second grazing (case B, θ̂ = 40°)",
        images=(image,),
        summary=(
            "Not a figure of the paper: near the second grazing the impacting and the nonimpacting period-1 "
            "orbits coexist. Sweeps up and down (each one continuous chain whatever its chunking), the "
            "basins of both at one η, and what an experiment starting from rest at each η would see. Compute "
            "time "
            f"{run.seconds:.1f} s."
        ),
        comparisons=comparisons(run, s),
        notes=notes(run, s),
        seconds=time.perf_counter() - start,
        data=(write_data(run, out_dir),),
    )
