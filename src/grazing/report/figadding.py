"""The period-adding structure in two parameters (case B; not a figure of the paper).

A zoom of the period map (:func:`grazing.report.figmap.period_map`: every row
of fixed θ̂ an upward sweep in η from rest) on the part of the (η, θ̂) plane
where the impacting motion past the first grazing has its windows of period
2 ... 5, with the boundaries of the windows from continuation drawn on top.
Each window's orbit has one impact per period; it is started from the map
itself (a cell of the window in the row nearest θ̂ = 40°, its final state the
guess) and followed in (η, θ̂) by :func:`grazing.orbits.follow_curve`:

* its period-doubling curve (the window's lower-η boundary: below it the
  orbit period-doubles into chaos),
* its grazing curve (the upper-η boundary: the orbit touches the stop between
  its impacts and gains an impact),
* its fold curve where there is one: where the period-doubling curve ends at a
  grazing (the orbit loses its impact), the lower-η boundary goes on as a fold,
  started from a row of the map below that end,

and the grazing curve of the nonimpacting period-1 orbit (the curve of fig 6).
A rule (:func:`grazing.report.rules.curve_on_map`) checks that every curve lies
on a change of the map's colour, within the map's resolution.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import grazing
from grazing.errors import GrazingError
from grazing.orbits import BifurcationCurve, find_orbit, follow_curve
from grazing.plotting import plot_period_map
from grazing.plotting.diagrams import period_classes
from grazing.report import figmap
from grazing.report.base import Comparison, DataFile, FigureResult, Image, Say, save_png
from grazing.report.data import write_dataset, write_groups
from grazing.report.rules import CurveOnMap, criterion_row, curve_on_map

FIGURE_ID = "adding"
PERIODS = (2, 3, 4, 5)
"""The windows whose boundaries are continued."""
HEADLINE = "Boundaries of the period-adding windows from continuation not everywhere on a change in the map"
"""The line of every differing row of the section in the list of differences (one line links them all)."""
MAX_PERIOD = 8
"""Longest period with a colour of its own in the map (as in the map of the whole plane)."""
COLOURS = MAX_PERIOD + 4
"""The number of colour classes of :func:`period_classes` (failed, aperiodic, period 1 without and with
impacts, periods 2 ... MAX_PERIOD, longer): a class of :meth:`AddingRun.classes` is
``colour + COLOURS * impacts per period``."""


@dataclass(frozen=True)
class Settings:
    """The window of the plane, the map's resolution and where the curves start."""

    eta: tuple[float, float, int] = (0.41, 0.485, 251)
    """η range and number of columns."""
    theta_hat_deg: tuple[float, float, int] = (24.0, 54.0, 101)
    """θ̂ range (degrees) and number of rows."""
    transient: int = 400
    periods: int = 64
    workers: int | None = None
    start_deg: float = 40.0
    """The curves of each window start from the map's row nearest this stop angle (figs 7(d), 9, 11)."""
    tries: int = 4
    """Rows of the map tried for a curve's start before it is reported missing."""


SETTINGS = Settings()
"""Resolution used by the report (tests pass a smaller one to :func:`build`)."""


@dataclass(frozen=True)
class WindowCurve:
    """A continued boundary of a window.

    Attributes
    ----------
    period
        The period of the window's orbit (1: the nonimpacting orbit's grazing curve).
    kind
        ``"period-doubling"``, ``"fold"`` or ``"grazing"``.
    curve
        The curve (:func:`grazing.orbits.follow_curve`).
    row_deg, eta
        The map cell it was started from.
    """

    period: int
    kind: str
    curve: BifurcationCurve
    row_deg: float
    eta: float

    @property
    def name(self) -> str:
        """``pd5``, ``fold4``, ``grazing3``, ``grazing1`` (the data file's group)."""
        return {"period-doubling": "pd"}.get(self.kind, self.kind) + str(self.period)

    @property
    def bounding(self) -> np.ndarray:
        """The points that bound a window: all of them, but on a grazing curve only those where the
        grazing orbit is stable (an unstable orbit is no window of the map)."""
        if self.kind != "grazing":
            return np.ones(len(self.curve), dtype=bool)
        return np.array([p.stable for p in self.curve.points], dtype=bool)

    @property
    def label(self) -> str:
        if self.period == 1:
            return "grazing curve of the nonimpacting orbit (fig 6)"
        return f"period-{self.period} {self.kind} curve"


@dataclass
class AddingRun:
    """The map, the curves, and what could not be continued."""

    ds: Any
    curves: list[WindowCurve] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    """Notes on the curves that could not be continued or were not searched."""
    absent: list[str] = field(default_factory=list)
    """The labels of the curves searched for and not found (each a row of the table: not comparable)."""
    map_seconds: float = 0.0
    map_cpu_seconds: float = 0.0
    curve_seconds: float = 0.0
    curve_cpu_seconds: float = 0.0
    transient: int = 0
    periods: int = 0

    def classes(self) -> np.ndarray:
        """What the rule compares at every cell (rows θ̂, columns η): the colour class
        (:func:`period_classes`) and, for a periodic motion, its impacts per period (a grazing curve
        of an impacting orbit changes those, not always the period)."""
        codes, _, _ = period_classes(
            self.ds["period"].values, self.ds["impacts_per_period"].values, MAX_PERIOD
        )
        per = np.asarray(self.ds["period"].values)
        impacts = np.where(per > 0, np.round(np.nan_to_num(self.ds["impacts_per_period"].values)), 0)
        return np.asarray(codes) + COLOURS * impacts.astype(int)

    def check(self, wc: WindowCurve) -> CurveOnMap:
        """The rule for one curve: on a change of the map's colour, within one cell."""
        return curve_on_map(
            wc.curve.values("eta"),
            np.degrees(wc.curve.values("theta_hat")),
            self.ds["eta"].values,
            np.degrees(self.ds["theta_hat"].values),
            self.classes(),
            where=wc.bounding,
        )


def window_runs(ds: Any, row: int, period: int) -> list[tuple[int, int]]:
    """The runs ``(first, last)`` of the map's cells in ``row`` on an orbit of ``period`` with one impact
    per period, the longest first."""
    per = np.asarray(ds["period"].values[row])
    ipp = np.asarray(ds["impacts_per_period"].values[row])
    ok = (per == period) & (np.round(np.nan_to_num(ipp)) == 1)
    runs: list[tuple[int, int]] = []
    for j in np.flatnonzero(ok):
        if runs and runs[-1][1] == j - 1:
            runs[-1] = (runs[-1][0], int(j))
        else:
            runs.append((int(j), int(j)))
    return sorted(runs, key=lambda r: r[0] - r[1])


def rows_near(ds: Any, deg: float, below: float | None = None) -> list[int]:
    """The map's rows, nearest to ``deg`` first; only those below ``below`` (degrees) if given."""
    th = np.degrees(np.asarray(ds["theta_hat"].values))
    rows = [int(i) for i in np.argsort(np.abs(th - deg), kind="stable")]
    return [i for i in rows if below is None or th[i] < below]


def start_cells(
    ds: Any, rows: list[int], period: int, tries: int, upwards: bool
) -> Iterator[tuple[int, int]]:
    """Up to ``tries`` cells of the window of ``period``, one per row, in the order of ``rows``.

    Each is the second cell of the row's longest run from the end the continuation goes to
    (the upper one when ``upwards``): the one-parameter branch to the boundary is then short.
    """
    n = 0
    for row in rows:
        runs = window_runs(ds, row, period)
        if runs and n < tries:
            n += 1
            first, last = runs[0]
            mid = (first + last) // 2
            yield row, max(last - 1, mid) if upwards else min(first + 1, mid)


def follow_from_map(
    ds: Any, kind: str, period: int, cells: Iterator[tuple[int, int]], towards: float
) -> tuple[WindowCurve | None, list[str]]:
    """Follow the first curve of ``kind`` met from a cell of ``cells``, continuing towards η = ``towards``.

    Returns the curve (None if no cell gives one) and why each cell tried failed.
    """
    th = np.asarray(ds["theta_hat"].values)
    etas = np.asarray(ds["eta"].values)
    x_final = ds["x_final"].transpose("theta_hat", "eta", "component").values
    failures = []
    for row, col in cells:
        eta, theta_hat = float(etas[col]), float(th[row])
        model = grazing.models.pendulum("B", eta=eta, theta_hat=theta_hat)
        where = f"η = {eta:.5f}, θ̂ = {math.degrees(theta_hat):.2f}°"
        try:
            guess = np.array(x_final[row, col], dtype=float)  # (a contiguous copy: the kernels need one)
            orbit = find_orbit(model, guess, period=period, virtual=period == 1)
            if orbit.period != period or orbit.impacts != (0 if period == 1 else 1):
                failures.append(
                    f"at {where} the orbit found has period {orbit.period}, {orbit.impacts} impacts"
                )
                continue
            curve = follow_curve(
                model, kind, "eta", eta, towards, "theta_hat", (float(th[0]), float(th[-1])), orbit=orbit
            )
        except GrazingError as exc:
            failures.append(f"from {where}: {str(exc).splitlines()[0]}")
            continue
        return WindowCurve(period, kind, curve, math.degrees(theta_hat), eta), failures
    return None, failures


def compute(s: Settings, progress: Say | None = None) -> AddingRun:
    say = progress or (lambda _msg: None)
    ds, seconds, cpu = figmap.period_map(
        figmap.Settings(eta=s.eta, theta_hat_deg=s.theta_hat_deg, transient=s.transient, periods=s.periods,
                        workers=s.workers),
        say,
        label="period adding: map",
    )  # fmt: skip
    run = AddingRun(ds, map_seconds=seconds, map_cpu_seconds=cpu, transient=s.transient, periods=s.periods)
    start, cpu = time.perf_counter(), figmap.cpu_seconds()
    lo, hi = float(ds["eta"].values[0]), float(ds["eta"].values[-1])
    near = rows_near(ds, s.start_deg)

    def add(kind: str, period: int, cells: Iterator[tuple[int, int]], towards: float) -> WindowCurve | None:
        t = time.perf_counter()
        wc, failures = follow_from_map(ds, kind, period, cells, towards)
        what = "the nonimpacting orbit's grazing" if period == 1 else f"the period-{period} {kind}"
        if wc is None:
            why = "; ".join(failures) if failures else "no cell of its window in the rows tried"
            run.missing.append(f"No {what} curve: {why}.")
            run.absent.append(f"{what.removeprefix('the ')} curve")
            say(f"period adding: no {what} curve")
            return None
        run.curves.append(wc)
        say(f"period adding: {what} curve, {len(wc.curve)} points in {time.perf_counter() - t:.1f} s")
        return wc

    first = _nonimpacting_cells(ds, near, s.tries)
    add("grazing", 1, first, hi)
    for n in PERIODS:
        pd = add("period-doubling", n, start_cells(ds, near, n, s.tries, upwards=False), lo)
        add("grazing", n, start_cells(ds, near, n, s.tries, upwards=True), hi)
        if pd is None:
            continue
        end = math.degrees(float(pd.curve.values("theta_hat").min()))
        if not any(sp.kind == "grazing" for sp in pd.curve.special):
            run.missing.append(
                f"No period-{n} fold curve searched: the period-{n} period-doubling curve does not end at a "
                f"grazing in the map (it reaches θ̂ = {end:.2f}°)."
            )
            continue
        add("fold", n, start_cells(ds, rows_near(ds, end, below=end), n, s.tries, upwards=False), lo)
    run.curve_seconds = time.perf_counter() - start
    run.curve_cpu_seconds = figmap.cpu_seconds() - cpu
    return run


def _nonimpacting_cells(ds: Any, rows: list[int], tries: int) -> Iterator[tuple[int, int]]:
    """The first column of the map in each row where it is on the nonimpacting period-1 orbit."""
    per, ipp = ds["period"].values, ds["impacts_per_period"].values
    n = 0
    for row in rows:
        if per[row, 0] == 1 and ipp[row, 0] == 0 and n < tries:
            n += 1
            yield row, 0


STYLES: dict[str, dict[str, Any]] = {
    "period-doubling": {"color": "#ffe119", "ls": "-", "lw": 1.4},
    "fold": {"color": "#ffe119", "ls": (0, (4, 2)), "lw": 1.6},
    "grazing": {"color": "white", "ls": "-", "lw": 1.3},
}
"""How each kind of curve is drawn (the nonimpacting orbit's grazing curve: :data:`NONIMPACTING`)."""
NONIMPACTING = {"color": "magenta", "ls": "-", "lw": 2.0}
UNSTABLE = {"color": "white", "ls": "-", "lw": 0.7}
"""A grazing curve where the grazing orbit is unstable (it bounds no window)."""
MEETS = {"ls": "", "marker": "o", "ms": 5.5, "color": "white", "mec": "black", "mew": 1.0}
"""The marker of a codimension-two point where a curve ends at a grazing."""


def draw(run: AddingRun, path: Path) -> None:
    from matplotlib import patheffects
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    fig = Figure(figsize=(11.0, 7.0), layout="constrained")
    ax = fig.subplots()
    plot_period_map(ax, run.ds, max_period=MAX_PERIOD)
    edge = [patheffects.withStroke(linewidth=2.8, foreground="0.2")]
    thin = [patheffects.withStroke(linewidth=1.8, foreground="0.2")]
    for wc in run.curves:
        style = NONIMPACTING if wc.period == 1 else STYLES[wc.kind]
        eta, th = wc.curve.values("eta"), np.degrees(wc.curve.values("theta_hat"))
        bound = wc.bounding
        ax.plot(eta, np.where(bound, th, np.nan), **style, path_effects=None if wc.period == 1 else edge)
        if not bound.all():  # (widened by a point, so that the two parts meet)
            unstable = np.convolve(~bound, [1, 1, 1], mode="same") > 0
            ax.plot(eta, np.where(unstable, th, np.nan), **UNSTABLE, path_effects=thin)
        for sp in wc.curve.special:
            if sp.kind in ("grazing", "double grazing"):
                ax.plot(sp.values[0], math.degrees(sp.values[1]), **MEETS)
    eta = run.ds["eta"].values
    th = np.degrees(run.ds["theta_hat"].values)
    ax.set_xlim(eta[0] - 0.5 * (eta[1] - eta[0]), eta[-1] + 0.5 * (eta[1] - eta[0]))
    ax.set_ylim(th[0] - 0.5 * (th[1] - th[0]), th[-1] + 0.5 * (th[1] - th[0]))
    handles = [
        Line2D([], [], **STYLES["period-doubling"], path_effects=edge, label="period-doubling curves"),
        Line2D([], [], **STYLES["fold"], path_effects=edge, label="fold curves"),
        Line2D([], [], **STYLES["grazing"], path_effects=edge, label="grazing curves (an impact is gained)"),
        Line2D(
            [], [], **UNSTABLE, path_effects=thin, label="grazing curves of an unstable orbit (no window)"
        ),
        Line2D([], [], **NONIMPACTING, label="grazing curve of the nonimpacting orbit"),
        Line2D([], [], **MEETS, label="a curve ends at a grazing"),
    ]
    fig.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=9, frameon=False)
    ax.set_title(
        "Case B: the windows of period 2–5 past the first grazing, the detected period (colours) and the "
        "continued boundaries of the windows",
        loc="left",
        fontsize=10,
    )
    save_png(fig, path)


def build(out_dir: Path, progress: Say | None = None, settings: Settings | None = None) -> FigureResult:
    """Compute the map and the curves, write the PNG and the data into ``out_dir`` and describe them."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    s = settings or SETTINGS
    ne, nt = s.eta[2], s.theta_hat_deg[2]
    say(f"period adding: map of {ne} × {nt} points (η × θ̂), {s.transient} + {s.periods} periods each")
    run = compute(s, say)
    name = "period_adding_map.png"
    draw(run, out_dir / name)
    image = Image(
        name,
        f"Case B (r = 0.7675, β = 0.048, α = 0.2254): the detected period at {ne} × {nt} points of the "
        f"(η, θ̂) plane, η from {s.eta[0]:g} to {s.eta[1]:g} (steps of {_step(s.eta):.2g}), θ̂ from "
        f"{s.theta_hat_deg[0]:g}° to {s.theta_hat_deg[1]:g}° (steps of {_step(s.theta_hat_deg):.2g}°), every "
        "row swept upwards in η from rest as in the map of the whole plane. On top, from continuation: the "
        "period-doubling (yellow), fold (yellow, dashed) and grazing (white) curves of the impacting "
        "orbits of period 2–5 with one impact per period, each started from the map's cells of its window "
        "near "
        f"θ̂ = {s.start_deg:g}°, and the grazing curve of the nonimpacting period-1 orbit (magenta). "
        "Circles: where a curve ends because the orbit gains or loses an impact (a codimension-two point). "
        "Thin white: a grazing curve where the grazing orbit is unstable (beyond where the fold curve meets "
        "it); it bounds no window and is not checked against the map.",
        "Period map of the period-adding windows of case B with their continued boundaries",
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="The period-adding structure in two parameters",
        images=(image,),
        summary=summary(run),
        comparisons=comparisons(run),
        notes=notes(run, s),
        seconds=time.perf_counter() - start,
        data=write_data(run, out_dir),
    )


def _step(axis: tuple[float, float, int]) -> float:
    return (axis[1] - axis[0]) / (axis[2] - 1)


def summary(run: AddingRun) -> str:
    return (
        "Not a figure of the paper: the two-parameter picture behind its period-adding cascade (§6.1: “the "
        "period is decreased by one for each periodic window as η is increased”). Past the first grazing "
        "(the nonimpacting orbit's grazing curve) each window holds an orbit with one impact per period; it "
        "begins, as η rises, where the orbit is born in a period-doubling (or, lower down, a fold) and ends "
        "where it grazes and gains an impact; between the windows the motion is chaotic. Every boundary "
        "drawn comes from continuation and is checked against the brute-force map below."
    )


def comparisons(run: AddingRun) -> tuple[Comparison, ...]:
    rows = []
    for wc in run.curves:
        c = run.check(wc)
        rows.append(
            criterion_row(
                FIGURE_ID,
                f"{wc.label} on a change of period in the map",
                "on a change of period",
                c.fraction if c.inside else None,
                None if c.verdict == "not comparable" else c.verdict == "agree",
                kind="self-check",
                rule="at every point of the curve inside the map (on a grazing curve, where the grazing "
                "orbit is stable), the map's cells one cell width away on either side across the curve (one "
                "cell along each axis counting the same) differ in period or in impacts per period: agree "
                "when that holds at every point",
                source="continuation against the map",
                paper_text="every point",
                ours_text=f"{c.holds} of {c.inside} points" if c.inside else "no point inside the map",
                note=_failure_note(run, wc, c),
                headline=HEADLINE,
            )
        )
    for label in run.absent:
        rows.append(
            criterion_row(
                FIGURE_ID,
                f"{label} on a change of period in the map",
                "on a change of period",
                None,
                None,
                kind="self-check",
                rule="the curve could not be continued from the map's cells (see the notes): nothing checked",
                source="continuation against the map",
                paper_text="every point",
                ours_text="no curve",
                headline=f"No {label}",
            )
        )
    return tuple(rows)


def class_label(code: int) -> str:
    """The words for a class of :meth:`AddingRun.classes`.

    Examples
    --------
    >>> class_label(1), class_label(5 + COLOURS), class_label(2)
    ('aperiodic', 'period 3, 1 impact per period', 'period 1, 0 impacts per period')
    """
    _, labels, _ = period_classes(np.array([1]), np.array([0]), MAX_PERIOD)
    colour, impacts = code % COLOURS, code // COLOURS
    if colour < 2:
        return labels[colour]
    period = labels[colour].split(",")[0]
    return f"period {period}, {impacts} impact{'s' if impacts != 1 else ''} per period"


def _failure_note(run: AddingRun, wc: WindowCurve, c: CurveOnMap) -> str:
    """Where the rule fails on a curve, what the map shows on both sides there, and why."""
    if not c.failed:
        return ""
    th = [f[1] for f in c.failed]
    seen: dict[str, int] = {}
    for f in c.failed:
        seen[class_label(f[2])] = seen.get(class_label(f[2]), 0) + 1
    what = ", ".join(f"{k} ({v} point{'s' if v > 1 else ''})" for k, v in seen.items())
    return (
        f"It does not hold at {len(c.failed)} of the {c.inside} points, θ̂ from {min(th):.2f}° to "
        f"{max(th):.2f}°, where the map shows the same on both sides: {what}.{_why(run, wc, c)}"
    )


def _why(run: AddingRun, wc: WindowCurve, c: CurveOnMap) -> str:
    """What explains the misses, computed: for a fold, the sweep's hysteresis; for the boundaries of a
    window, its width there and, at a period-doubling, the slow convergence next to it."""
    cell = float(run.ds["eta"].values[1] - run.ds["eta"].values[0])
    th_fail = np.radians([f[1] for f in c.failed])
    if wc.kind == "fold":
        return _hysteresis(run, wc, cell)
    if wc.period == 1:
        return ""
    other = "grazing" if wc.kind == "period-doubling" else "period-doubling"
    twin = next((w for w in run.curves if w.period == wc.period and w.kind == other), None)
    out = ""
    if twin is not None:
        g_th, g_eta = twin.curve.values("theta_hat"), twin.curve.values("eta")
        order = np.argsort(g_th)
        near = (th_fail >= g_th.min()) & (th_fail <= g_th.max())
        if near.any():
            own = np.interp(th_fail[near], *_sorted(wc.curve.values("theta_hat"), wc.curve.values("eta")))
            width = np.abs(np.interp(th_fail[near], g_th[order], g_eta[order]) - own) / cell
            out += (
                f" The window (from its period-doubling to its grazing curve) is {width.min():.1f}–"
                f"{width.max():.1f} cells wide in η at those points."
            )
    if wc.kind == "period-doubling":
        out += _slow_convergence(run, wc, c, cell)
    return out


def _sorted(th: np.ndarray, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(th)
    return th[order], eta[order]


def _slow_convergence(run: AddingRun, wc: WindowCurve, c: CurveOnMap, cell: float) -> str:
    """How slowly the sweep converges one cell above the period-doubling, at the middle failing point."""
    from grazing.core.options import PERIOD_TOL

    mid = sorted(c.failed, key=lambda f: f[1])[len(c.failed) // 2]
    th = wc.curve.values("theta_hat")
    k = int(np.argmin(np.hypot(wc.curve.values("eta") - mid[0], np.degrees(th) - mid[1])))
    point = wc.curve.points[k]
    eta = point.values[0] + cell
    try:
        orbit = find_orbit(
            grazing.models.pendulum("B", eta=eta, theta_hat=point.values[1]),
            point.state,
            period=wc.period,
            t0=point.section_time,
        )
    except GrazingError:
        return ""
    mu = float(np.max(np.abs(orbit.multipliers)))
    if orbit.period != wc.period or not 0 < mu < 1:
        return ""
    factor = 1e-2 / PERIOD_TOL
    periods = wc.period * math.log(factor) / -math.log(mu)
    slow = periods > run.transient + run.periods
    return (
        f" One cell above the curve (η = {eta:.5f}, θ̂ = {math.degrees(point.values[1]):.2f}°) the period-"
        f"{wc.period} orbit's largest multiplier has modulus {mu:.4f}: a deviation shrinks from 1e-2 to the "
        f"period detection's {PERIOD_TOL:g} in about {periods:.0f} forcing periods"
        + (
            f", more than the sweep's {run.transient} + {run.periods}: next to a period-doubling the map "
            "does not see the period yet."
            if slow
            else f" (the sweep allows {run.transient} + {run.periods})."
        )
    )


def _hysteresis(run: AddingRun, wc: WindowCurve, cell: float) -> str:
    """The fold's distance to the nonimpacting orbit's grazing curve, where the upward sweep leaves that
    orbit."""
    first = next((w for w in run.curves if w.period == 1), None)
    if first is None:
        return ""
    g_th, g_eta = _sorted(first.curve.values("theta_hat"), first.curve.values("eta"))
    f_eta, f_th = wc.curve.values("eta"), wc.curve.values("theta_hat")
    inside = (f_th >= g_th.min()) & (f_th <= g_th.max())
    if not inside.any():
        return ""
    gap = np.interp(f_th[inside], g_th, g_eta) - f_eta[inside]
    return (
        f" The fold lies {gap.min() / cell:.1f}–{gap.max() / cell:.1f} cells (η) below the nonimpacting "
        "orbit's grazing: between them the window's orbit coexists with the nonimpacting one, which the "
        "upward sweep keeps until it grazes, so the map changes colour at the grazing, not at the fold."
    )


def notes(run: AddingRun, s: Settings) -> tuple[str, ...]:
    out = list(run.missing)
    ends = []
    for wc in run.curves:
        for sp in wc.curve.special:
            if sp.kind in ("grazing", "double grazing") and sp.located:
                ends.append(
                    f"{wc.label}: {sp.kind} at η = {sp.values[0]:.5f}, θ̂ = {math.degrees(sp.values[1]):.3f}°"
                )
    if ends:
        out.append("Where the curves end (located codimension-two points): " + "; ".join(ends) + ".")
    starts = ", ".join(f"{wc.name} from η = {wc.eta:.5f}, θ̂ = {wc.row_deg:.2f}°" for wc in run.curves)
    out.append(f"Curves started from the map's cells: {starts}.")
    out.append(
        f"Cost: the map {run.map_cpu_seconds:.1f} CPU seconds ({run.map_seconds:.1f} s) for "
        f"{s.eta[2] * s.theta_hat_deg[2]} points; the {len(run.curves)} curves "
        f"{run.curve_cpu_seconds:.1f} CPU seconds ({run.curve_seconds:.1f} s)."
    )
    return tuple(out)


def write_data(run: AddingRun, out_dir: Path) -> tuple[DataFile, ...]:
    """The map's periods and impacts, and every curve as a group of one NetCDF file."""
    ds = run.ds[["period", "impacts_per_period"]].copy()
    ds.attrs = {k: v for k, v in run.ds.attrs.items() if isinstance(v, (str, int, float))}
    map_path = write_dataset(out_dir / "period_adding_map.nc", ds)
    files = [
        DataFile(map_path.name, "the detected period and impacts per period at every (θ̂, η) point, NetCDF")
    ]
    if run.curves:
        path = write_groups(
            out_dir / "period_adding_curves.nc", {wc.name: wc.curve.to_dataset() for wc in run.curves}
        )
        names = ", ".join(wc.name for wc in run.curves)
        files.append(
            DataFile(
                path.name,
                f"the continued curves, one group each ({names}: pd = period-doubling, the number the "
                "period, grazing1 the nonimpacting orbit's grazing), NetCDF",
            )
        )
    return tuple(files)
