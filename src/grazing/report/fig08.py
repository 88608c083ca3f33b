"""Figure 8 of the paper: bifurcation diagrams in the stop angle θ̂ at η = 0.447, cases B and A.

At fixed η = 0.447 the nonimpacting period-1 orbit does not depend on θ̂; it
grazes the stop placed at its largest angle, θ̂_g.  Below θ̂_g it impacts.
The sweeps run downwards in θ̂ from above θ̂_g, starting on the nonimpacting
orbit, so that the grazing bifurcation is met as its onset (each θ̂ starts
from the final state of the previous one); the diagrams are drawn with θ̂
increasing to the right, as in the paper.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import grazing
from grazing.models.pendulum import max_angle
from grazing.orbits import find_orbit
from grazing.plotting import mark_grazings, plot_bifurcation
from grazing.report import diagrams, paper
from grazing.report.base import Comparison, DataFile, FigureResult, Image, Say, save_png
from grazing.report.data import slim_sweep, write_csv, write_groups
from grazing.report.rules import criterion_row, numeric_row
from grazing.sweeps import sweep
from grazing.sweeps.windows import Window, find_windows

FIGURE_ID = "8"
ETA = paper.FIG8_ETA.value
"""The fixed forcing frequency (fig 8 caption)."""


@dataclass(frozen=True)
class Panel:
    """One panel: a damping case and the θ̂ range (degrees)."""

    key: str
    case: str
    label: str
    theta_range: tuple[float, float]


PANELS = (
    Panel("a", "B", "case B: r = 0.7675, β = 0.048", (25.0, 44.0)),
    Panel("b", "A", "case A: r = 0.4707, β = 0.010", (25.0, 88.0)),
)
"""Each range runs from well inside the period-2 region to a few degrees past the grazing."""


@dataclass(frozen=True)
class Settings:
    """Resolution and cost: θ̂ values per panel, transient and sampled periods, processes."""

    points: int = 1000
    transient: int = 400
    periods: int = 100
    workers: int | None = None


SETTINGS = Settings()
"""Resolution used by the report (tests pass a smaller one to :func:`build`)."""


@dataclass
class PanelRun:
    """What was computed for one panel."""

    panel: Panel
    ds: Any
    theta_graze: float
    """Largest angle of the nonimpacting orbit at η = 0.447 (radians): the grazing stop angle."""
    abs_lambda: float
    """Largest nontrivial multiplier modulus of that orbit (the grazing orbit's |λ|)."""
    seconds: float
    cpu_seconds: float

    @property
    def windows(self) -> list[Window]:
        return find_windows(self.ds)

    def impacting_windows(self, min_points: int = 2) -> list[Window]:
        """Periodic impacting windows below the grazing, in increasing θ̂."""
        return [w for w in self.windows if w.impacting and w.period >= 1 and w.points >= min_points]

    def aperiodic_fraction(self, lo_deg: float = -math.inf, hi_deg: float = math.inf) -> float:
        """Fraction of the impacting points with ``lo_deg <= θ̂ <= hi_deg`` (degrees) that have no period."""
        th = np.degrees(np.asarray(self.ds.value.values))
        imp = (np.asarray(self.ds.impacts_per_period.values) > 0) & (th >= lo_deg) & (th <= hi_deg)
        per = np.asarray(self.ds.period.values)
        return float(np.mean(per[imp] == 0)) if imp.any() else 0.0

    def widest(self, period: int) -> Window | None:
        ws = [w for w in self.impacting_windows(1) if w.period == period]
        return max(ws, key=lambda w: w.width) if ws else None

    def first_nonimpacting(self) -> float:
        """Smallest θ̂ (radians) with nonimpacting motion."""
        th = np.asarray(self.ds.value.values)
        non = np.asarray(self.ds.impacts_per_period.values) == 0
        return float(th[non].min()) if non.any() else math.nan


def run_panel(args: tuple[Panel, Settings]) -> PanelRun:
    """Compute one panel: the nonimpacting orbit (grazing angle, |λ|) and the downward sweep."""
    panel, s = args
    start, cpu = time.perf_counter(), time.process_time()
    model = grazing.models.pendulum(panel.case, eta=ETA)
    orbit = find_orbit(model.with_params(theta_hat=3.0), period=1, virtual=True)
    lo, hi = panel.theta_range
    ds = sweep(
        model,
        "theta_hat",
        np.radians(np.linspace(lo, hi, s.points)),
        x0=orbit.state,
        direction="down",
        transient=s.transient,
        periods=s.periods,
        lyapunov=False,
        chunk_size=0,
        workers=1,
    )
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    return PanelRun(panel, ds, max_angle(orbit), orbit.abs_lambda, wall, cpu)


def draw(runs: list[PanelRun], path: Path) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(12.4, 4.2), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, run in zip(axes, runs):
        plot_bifurcation(ax, run.ds)
        mark_grazings(
            ax,
            [run.theta_graze],
            scale=180 / math.pi,
            labels=[f"grazing θ̂ = {math.degrees(run.theta_graze):.2f}°"],
        )
        ax.set_title(f"({run.panel.key}) {run.panel.label}, η = {ETA:g}", loc="left", fontsize=10.5)
    save_png(fig, path)


def build(out_dir: Path, progress: Say | None = None, settings: Settings | None = None) -> FigureResult:
    """Compute fig 8, write its PNG into ``out_dir`` and describe it."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    s = settings or SETTINGS
    diagrams.warm_up("B")

    def report(run: PanelRun) -> None:
        lo, hi = run.panel.theta_range
        say(
            f"fig 8: panel ({run.panel.key}) case {run.panel.case}: {run.ds.sizes['point']} θ̂ values in "
            f"[{lo:g}°, {hi:g}°] in {run.seconds:.1f} s (CPU {run.cpu_seconds:.1f} s)"
        )

    import os

    workers = min(s.workers or os.cpu_count() or 1, len(PANELS))
    done = diagrams.run_parallel(run_panel, [(p, s) for p in PANELS], workers, report)
    runs = [next(r for r in done if r.panel == p) for p in PANELS]
    say("fig 8: drawing")
    name = "fig08_theta_hat.png"
    draw(runs, out_dir / name)
    image = Image(
        name,
        f"Brute-force bifurcation diagrams in the stop angle θ̂ at η = {ETA:g} (α = 0.2254): θ at τ = 2πk "
        f"against θ̂, {s.points} values per panel. The sweep runs downwards in θ̂ from the nonimpacting "
        "orbit (shaded), each θ̂ starting from the final state of the previous one; dashed red: the grazing "
        "angle (the largest angle of the nonimpacting orbit). Blue bars and numbers: periodic windows.",
        "Bifurcation diagrams against the stop angle at eta = 0.447, cases B and A",
    )
    cpu = sum(r.cpu_seconds for r in runs)
    data = write_data(runs, out_dir)
    summary = (
        "The paper's fig 8 recomputed by direct simulation. At fixed η the nonimpacting orbit is the same "
        "for every θ̂, so its largest angle is the grazing stop angle; below it the pendulum impacts. "
        f"Compute time {cpu:.1f} CPU seconds."
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title=f"Figure 8: bifurcation diagrams in θ̂ at η = {ETA:g}, cases B and A",
        images=(image,),
        summary=summary,
        comparisons=comparisons(runs),
        notes=notes(runs),
        seconds=time.perf_counter() - start,
        data=data,
    )


def write_data(runs: list[PanelRun], out_dir: Path) -> tuple[DataFile, ...]:
    groups = {
        r.panel.key: slim_sweep(
            r.ds, panel=r.panel.key, case=r.panel.case, eta=ETA, theta_graze_deg=math.degrees(r.theta_graze)
        )
        for r in runs
    }
    nc = write_groups(out_dir / "fig08_sweeps.nc", groups)
    csv = out_dir / "fig08_windows.csv"
    write_csv(
        csv,
        ["panel", "case", "period", "impacting", "points", "theta_hat_start_deg", "theta_hat_stop_deg"],
        [
            (
                r.panel.key,
                r.panel.case,
                w.period,
                int(w.impacting),
                w.points,
                math.degrees(w.start),
                math.degrees(w.stop),
            )
            for r in runs
            for w in r.windows
        ],
    )
    return (
        DataFile(nc.name, "the two sweeps in θ̂ (radians), NetCDF, groups a (case B) and b (case A)"),
        DataFile(csv.name, "every window of the two sweeps, θ̂ in degrees, CSV"),
    )


def cascade(run: PanelRun) -> list[Window]:
    """The windows of the period-adding sequence below the grazing, in θ̂ order.

    Windows of at least 3 points, without the period-doubled satellites at the
    edges of a window (:func:`grazing.report.diagrams.drop_doublings`).
    """
    return diagrams.drop_doublings(run.impacting_windows(3))


def _deg(w: Window) -> str:
    return f"{w.period} (θ̂ {math.degrees(w.start):.2f}°–{math.degrees(w.stop):.2f}°)"


def comparisons(runs: list[PanelRun]) -> tuple[Comparison, ...]:
    b, a = runs
    rows = []
    gb = math.degrees(b.theta_graze)
    onset = math.degrees(b.first_nonimpacting())
    rows.append(
        numeric_row(
            FIGURE_ID,
            f"(a) case B, η = {ETA:g}: grazing stop angle θ̂_g (degrees)",
            paper.FIG8_GRAZING,
            gb,
            kind="paper",
            decimals=3,
            note=f"The largest angle of the nonimpacting orbit; in the sweep the motion is nonimpacting from "
            f"θ̂ = {onset:.2f}° up. The grazing orbit's |λ| = {b.abs_lambda:.3f}, inside 1/4 < |λ| < 2/3 "
            "(eq. 21).",
        )
    )
    seq = cascade(b)
    near = [w for w in seq if w.period >= 2]
    per = [w.period for w in near]
    rising = len(per) >= 3 and all(y == x + 1 for x, y in itertools.pairwise(per))
    others = ", ".join(_deg(w) for w in b.impacting_windows(2) if w not in near and w.period >= 2)
    rows.append(
        criterion_row(
            FIGURE_ID,
            "(a) the period-adding cascade below the grazing",
            "“the onset of a period-adding cascade, where the period increases with θ̂”",
            " → ".join(map(str, per)),
            rising,
            kind="paper",
            rule="agree when the clearly resolved windows below the grazing (≥ 3 points, period-doubled "
            "satellites left out), in increasing θ̂, are at least three with periods increasing by one",
            source="§6.1",
            paper_text="periods increasing by one with θ̂",
            ours_text=" → ".join(map(str, per)),
            headline="(a): no period-adding cascade in θ̂",
            note="Windows: "
            + ", ".join(_deg(w) for w in near)
            + (f". Others (≥ 2 points): {others}." if others else "."),
        )
    )
    lo = max(b.panel.theta_range[0], a.panel.theta_range[0])
    fb, fa = b.aperiodic_fraction(lo), a.aperiodic_fraction(lo)
    fa_common = a.aperiodic_fraction(lo, math.degrees(b.theta_graze))
    wide = []
    wider = True
    for p in (3, 4, 5):
        wb, wa = b.widest(p), a.widest(p)
        if wb is None or wa is None:
            continue
        db, da = math.degrees(wb.width), math.degrees(wa.width)
        wide.append(f"{p}: {da:.2f}° vs {db:.2f}°")
        wider &= da > db
    rows.append(
        criterion_row(
            FIGURE_ID,
            "(b) against (a): case A (smaller β) against case B",
            "“significantly wider intervals of chaos and also wider ... windows of the higher-period "
            "periodic windows”",
            f"aperiodic {fa:.0%} vs {fb:.0%}; widest windows (A vs B) " + "; ".join(wide),
            fa > fb and wider and bool(wide),
            kind="paper",
            rule="agree when case A has a larger aperiodic share of its impacting points (from θ̂ = 25° to "
            "the grazing) and wider widest windows of periods 3, 4 and 5 than case B",
            source="§6.2",
            paper_text="A: wider chaos, wider windows",
            ours_text=f"aperiodic {fa:.0%} (A) vs {fb:.0%} (B); windows wider in A: "
            f"{'yes' if wider else 'no'}",
            headline="Case A's chaos or windows are not wider than case B's",
            note=f"Over B's θ̂ range only, A is aperiodic at {fa_common:.0%} of its impacting points. Widths: "
            + "; ".join(wide)
            + f". Case A grazes at θ̂_g = {math.degrees(a.theta_graze):.2f}° at this η "
            f"(case B at {gb:.2f}°): its response is much larger (fig 6, left).",
        )
    )
    return tuple(rows)


def notes(runs: list[PanelRun]) -> tuple[str, ...]:
    _, a = runs
    ga = math.degrees(a.theta_graze)
    near_a = [w for w in a.impacting_windows(2) if ga - 5.0 < math.degrees(w.start) < ga and w.period >= 2]
    big = [w for w in cascade(a) if w.period >= 3]
    gap = f"{math.degrees(big[-1].stop):.1f}°" if big else "—"
    return (
        f"Case A at η = {ETA:g} grazes at θ̂_g = {ga:.2f}° with |λ| = {a.abs_lambda:.3f}, above 2/3: "
        f"outside the period-adding range of eq. 21. Its windows in the 5° below the grazing: "
        + (", ".join(_deg(w) for w in near_a) or "none")
        + f"; its windows of period 3, 4, 5 lie far below the grazing, and from the last of them ({gap}) "
        "almost up to the grazing the motion is aperiodic. The paper says nothing about this range.",
        "Sweeping θ̂ upwards from the period-2 region instead gives the same windows for case B; for case "
        "A, starting from rest, it stays on an impacting period-1 orbit beyond the grazing angle (a "
        "coexisting attractor), which the downward sweep from the nonimpacting orbit avoids.",
        f"Cost: {sum(r.cpu_seconds for r in runs):.1f} CPU seconds for "
        f"{sum(r.ds.sizes['point'] for r in runs)} θ̂ values.",
    )
