"""A two-parameter period map of the (η, θ̂) plane for case B (not in the paper).

Every row (fixed θ̂) is an experimenter sweep upwards in η from rest; each
point is coloured by the period of its stroboscopic samples, the nonimpacting
period-1 motion apart from the impacting one.  The grazing curve of fig 6
(the largest angle of the nonimpacting orbit) is drawn over it: below it the
nonimpacting orbit passes through the stop, so every point there must impact,
which the map checks.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import grazing
from grazing.models.pendulum import max_angle
from grazing.orbits import find_orbit, grazing_curve
from grazing.plotting import plot_period_map
from grazing.report import diagrams
from grazing.report.base import Comparison, DataFile, FigureResult, Image, Say, save_png
from grazing.report.data import write_dataset
from grazing.report.rules import criterion_row
from grazing.sweeps import parameter_map

FIGURE_ID = "map"
FAR = 3.0
"""A stop angle (radians) out of the nonimpacting orbit's way."""


@dataclass(frozen=True)
class Settings:
    """Resolution and cost of the map."""

    eta: tuple[float, float, int] = (0.28, 0.92, 160)
    """η range and number of columns."""
    theta_hat_deg: tuple[float, float, int] = (2.0, 60.0, 60)
    """θ̂ range (degrees) and number of rows."""
    transient: int = 400
    periods: int = 64
    workers: int | None = None


SETTINGS = Settings()
"""Resolution used by the report (tests pass a smaller one to :func:`build`)."""


@dataclass
class MapRun:
    """The map and what is drawn over it."""

    ds: Any
    max_angle: np.ndarray
    """Largest angle (radians) of the nonimpacting period-1 orbit at each η column."""
    curve: Any
    seconds: float
    cpu_seconds: float


def max_angles(etas: np.ndarray) -> np.ndarray:
    """The largest angle of case B's nonimpacting period-1 orbit at each η (each solve from the last)."""
    model = grazing.models.pendulum("B", theta_hat=FAR)
    out = np.empty(len(etas))
    x = None
    for i, eta in enumerate(etas):
        orbit = find_orbit(model.with_params(eta=float(eta)), x, period=1, virtual=True)
        x = orbit.state
        out[i] = max_angle(orbit)
    return out


def period_map(s: Settings, say: Say, label: str = "map") -> tuple[Any, float, float]:
    """Case B's period map at the resolution of ``s``: the dataset, its wall and CPU seconds.

    The CPU seconds include the worker processes'.  ``label`` starts the progress messages.
    """
    start, cpu = time.perf_counter(), cpu_seconds()
    diagrams.warm_up("B")
    etas = np.linspace(*s.eta[:2], s.eta[2])
    ths = np.radians(np.linspace(*s.theta_hat_deg[:2], s.theta_hat_deg[2]))
    rows_done = [0]

    def tick(done: int, total: int) -> None:
        if done >= total or done - rows_done[0] >= total // 4:
            rows_done[0] = done
            say(f"{label}: {done}/{total} points after {time.perf_counter() - start:.1f} s")

    ds = parameter_map(
        grazing.models.pendulum("B"),
        "eta",
        etas,
        "theta_hat",
        ths,
        transient=s.transient,
        periods=s.periods,
        lyapunov=False,
        workers=s.workers,
        progress=tick,
    )
    return ds, time.perf_counter() - start, cpu_seconds() - cpu


def compute(s: Settings, progress: Say | None = None) -> MapRun:
    say = progress or (lambda _msg: None)
    start, cpu = time.perf_counter(), cpu_seconds()
    ds, _, _ = period_map(s, say)
    angles = max_angles(np.asarray(ds["eta"].values))
    curve = grazing_curve(
        grazing.models.pendulum("B"), ("eta", "theta_hat"), math.radians(5.0), search=(0.2, 1.0)
    )
    return MapRun(ds, angles, curve, time.perf_counter() - start, cpu_seconds() - cpu)


def cpu_seconds() -> float:
    """CPU time of this process and of its finished child processes (the map's workers) so far."""
    import resource

    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + ru.ru_utime + ru.ru_stime


def draw(run: MapRun, path: Path) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11.0, 5.6), layout="constrained")
    ax = fig.subplots()
    plot_period_map(ax, run.ds, max_period=8)
    curve = run.curve
    ax.plot(
        curve.values("eta"),
        np.degrees(curve.values("theta_hat")),
        color="tab:red",
        lw=1.6,
        label="grazing curve (fig 6)",
    )
    if curve.fold is not None:
        fe, ft = curve.fold.model.params["eta"], math.degrees(curve.fold.model.params["theta_hat"])
        ax.plot(fe, ft, "*", ms=11, color="tab:red", mec="k", mew=0.5, label=f"θ̂_max = {ft:.2f}°")
    for th in (10, 20, 30, 40):
        ax.axhline(th, color="0.25", lw=0.7, ls=":")
        ax.text(
            0.99,
            th,
            f"fig 7: {th}° ",
            transform=ax.get_yaxis_transform(),
            ha="right",
            va="bottom",
            fontsize=9,
            color="0.25",
        )
    ax.axvline(0.447, color="0.25", lw=0.7, ls=":")
    ax.text(
        0.449,
        0.99,
        "fig 8: η = 0.447",
        transform=ax.get_xaxis_transform(),
        color="0.25",
        fontsize=9,
        va="top",
    )
    eta = run.ds["eta"].values
    th = np.degrees(run.ds["theta_hat"].values)
    ax.set_xlim(eta[0] - 0.5 * (eta[1] - eta[0]), eta[-1] + 0.5 * (eta[1] - eta[0]))
    ax.set_ylim(th[0] - 0.5 * (th[1] - th[0]), th[-1] + 0.5 * (th[1] - th[0]))
    ax.legend(loc="upper right", fontsize=8.5, framealpha=0.9)
    ax.set_title(
        "Case B (r = 0.7675, β = 0.048, α = 0.2254): detected period in the (η, θ̂) plane; dotted: "
        "the stop angles of fig 7 and the η of fig 8",
        loc="left",
        fontsize=10,
    )
    save_png(fig, path)


def build(out_dir: Path, progress: Say | None = None, settings: Settings | None = None) -> FigureResult:
    """Compute the map, write its PNG into ``out_dir`` and describe it."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    s = settings or SETTINGS
    ne, nt = s.eta[2], s.theta_hat_deg[2]
    say(f"map: {ne} × {nt} points (η × θ̂), {s.transient} + {s.periods} periods each")
    run = compute(s, say)
    say(f"map: computed in {run.seconds:.1f} s (CPU {run.cpu_seconds:.1f} s); drawing")
    name = "map_eta_theta_hat.png"
    draw(run, out_dir / name)
    image = Image(
        name,
        f"Case B (r = 0.7675, β = 0.048, α = 0.2254): the detected period at {ne} × {nt} points of the "
        f"(η, θ̂) plane, η from {s.eta[0]:g} to {s.eta[1]:g}, θ̂ from {s.theta_hat_deg[0]:g}° to "
        f"{s.theta_hat_deg[1]:g}°. Every row is swept upwards in η from rest, each point starting from the "
        f"previous one's final state; after a transient of up to {s.transient} forcing periods the period of "
        f"{s.periods} stroboscopic samples is detected (black: none up to {s.periods // 2}). Red: the "
        "grazing curve.",
        "Period map of the eta, theta-hat plane for case B with the grazing curve",
    )
    summary = (
        "Not a figure of the paper: the two-parameter picture behind figs 6, 7 and 8. The impacting region "
        "is bounded by the grazing curve on the left and, sweeping η upwards, by the fold of the impacting "
        "period-1 orbit on the right (beyond the curve's falling branch); the period-adding cascades sit in "
        f"a thin band along the rising branch. Compute time {run.cpu_seconds:.1f} CPU seconds."
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="Extra: period map of the (η, θ̂) plane, case B",
        images=(image,),
        summary=summary,
        comparisons=comparisons(run),
        notes=notes(run, s),
        seconds=time.perf_counter() - start,
        data=(write_data(run, out_dir),),
    )


def write_data(run: MapRun, out_dir: Path) -> DataFile:
    """The map's periods and impacts (the samples left out) as NetCDF."""
    ds = run.ds[["period", "impacts_per_period"]].copy()
    ds["max_angle"] = (
        "eta",
        run.max_angle,
        {"units": "rad", "long_name": "largest angle of the nonimpacting period-1 orbit"},
    )
    ds.attrs = {k: v for k, v in run.ds.attrs.items() if isinstance(v, (str, int, float))}
    path = write_dataset(out_dir / "map_eta_theta_hat.nc", ds)
    return DataFile(
        path.name,
        "the detected period and impacts per period at every (θ̂, η) point, and the "
        "nonimpacting orbit's largest angle at every η, NetCDF",
    )


def classify(run: MapRun, margin_deg: float = 0.2) -> dict[str, Any]:
    """Points against the grazing curve: below it (must impact), above it (may coexist), and counts."""
    ds = run.ds
    th = np.asarray(ds["theta_hat"].values)[:, None]  # rows
    top = run.max_angle[None, :]
    imp = np.asarray(ds["impacts_per_period"].values) > 0
    per = np.asarray(ds["period"].values)
    margin = math.radians(margin_deg)
    below = th < top - margin
    above = th > top + margin
    fold = run.curve.fold
    th_max = fold.model.params["theta_hat"] if fold is not None else math.inf
    return {
        "below": int(below.sum()),
        "below_no_impact": int((below & ~imp).sum()),
        "above": int(above.sum()),
        "above_impact": int((above & imp).sum()),
        "above_impact_eta": np.asarray(ds["eta"].values)[np.any(above & imp, axis=0)],
        "over_max_impact": int((imp & (th > th_max + margin)).sum()),
        "over_max_eta": np.asarray(ds["eta"].values)[np.any(imp & (th > th_max + margin), axis=0)],
        "over_max_top": float(th[np.any(imp & (th > th_max + margin), axis=1), 0].max(initial=-np.inf)),
        "over_max": int(np.broadcast_to(th > th_max + margin, imp.shape).sum()),
        "aperiodic": int(((per == 0) & imp).sum()),
        "impacting": int(imp.sum()),
        "failed": int((per < 0).sum()),
        "periods": sorted({int(p) for p in np.unique(per[imp]) if p > 0}),
        "th_max": th_max,
    }


def comparisons(run: MapRun) -> tuple[Comparison, ...]:
    c = classify(run)
    return (
        criterion_row(
            FIGURE_ID,
            "points more than 0.2° below the grazing curve without impacts",
            0,
            c["below_no_impact"],
            None if c["below"] == 0 else c["below_no_impact"] == 0,
            kind="self-check",
            rule="below the curve the nonimpacting orbit passes through the stop, so the motion must impact: "
            "agree when no map point more than 0.2° below the curve is nonimpacting",
            source="fig 6 (the grazing curve)",
            paper_text="0 (must impact)",
            ours_text=f"{c['below_no_impact']} of {c['below']}",
            headline="Map points below the grazing curve without impacts",
        ),
    )


def notes(run: MapRun, s: Settings) -> tuple[str, ...]:
    c = classify(run)
    periods = ", ".join(map(str, c["periods"]))
    eta_co = c["above_impact_eta"]
    over = (
        f"{c['over_max_impact']} of the {c['over_max']} map points above θ̂_max = "
        f"{math.degrees(c['th_max']):.2f}° impact"
        + (
            f" (θ̂ ≤ {math.degrees(c['over_max_top']):.2f}°, η {c['over_max_eta'].min():.3f}–"
            f"{c['over_max_eta'].max():.3f})"
            if c["over_max_impact"]
            else ""
        )
        + ": grazing of the nonimpacting orbit cannot occur above θ̂_max (fig 6), but an impacting period-1 "
        "orbit coexisting with the nonimpacting one can be reached by a sweep's transient after an η step."
    )
    above = (
        f"{c['above_impact']} of the {c['above']} points more than 0.2° above the curve impact"
        + (f", at η from {eta_co.min():.3f} to {eta_co.max():.3f}" if eta_co.size else "")
        + ": beyond the falling branch of the curve the impacting period-1 orbit reached by the upward sweep "
        "persists up to its fold (as in fig 7), although the nonimpacting orbit is stable there too."
    )
    return (
        over,
        above,
        f"Of the {c['impacting']} impacting points, {c['aperiodic']} are aperiodic (no period ≤ "
        f"{s.periods // 2}); the "
        f"periods found are {periods}. Colours above 8 are lumped together."
        + (f" {c['failed']} points could not be simulated." if c["failed"] else ""),
        f"Each row is one sequential chunk; the rows run in parallel. Cost: {run.cpu_seconds:.1f} CPU "
        f"seconds for {s.eta[2] * s.theta_hat_deg[2]} points.",
    )
