"""Brute-force η bifurcation diagrams at four stop angles: the code figs 7 and 12 share.

Each panel is an *experimenter sweep*: η increases in small steps, every
point starting from the final state of the previous one (one sequential
chunk per panel, so that coexisting attractors are followed as in the
laboratory rather than re-chosen every few points).  The panels run in
parallel, one process per core.  Each panel also gets

* the grazing points of the nonimpacting period-1 orbit (the stop ignored,
  followed through folds: :func:`grazing.orbits.find_grazings`), drawn as
  vertical lines;
* the continuation of the impacting period-1 orbit found in the sweep, up and
  down in η, which locates the period-doubling that ends the period-2 window
  and the fold that ends the impacting region;
* optionally a magnified sweep just past the first grazing, where the
  period-adding cascade lives.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import grazing
from grazing.errors import GrazingError
from grazing.orbits import continue_orbit, find_grazings, find_orbit
from grazing.plotting import mark_grazings, plot_bifurcation
from grazing.report.base import save_png
from grazing.sweeps import sweep
from grazing.sweeps.windows import Window, find_windows

APPRECIABLE_WIDTH = 1e-3
"""A periodic window is *appreciable* when it spans at least this much in η."""


@dataclass(frozen=True)
class Panel:
    """One panel: a stop angle and the η range swept.

    Attributes
    ----------
    key
        The panel letter (``"a"``).
    theta_hat_deg
        The stop angle in degrees.
    eta_range
        The η interval of the main diagram.
    zoom
        If set, an extra magnified sweep over ``(η_g + zoom[0], η_g + zoom[1])``
        around the first grazing ``η_g``.
    """

    key: str
    theta_hat_deg: float
    eta_range: tuple[float, float]
    zoom: tuple[float, float] | None = None


@dataclass(frozen=True)
class Settings:
    """Resolution and cost of the diagrams.

    Attributes
    ----------
    points
        η values per main panel.
    zoom_points
        η values per magnified panel.
    transient, periods
        Forcing periods discarded and sampled at each η (the transient stops
        early once the samples repeat; see :func:`grazing.sweeps.sweep`).
    workers
        Processes (default: all cores).
    """

    points: int = 1000
    zoom_points: int = 400
    transient: int = 400
    periods: int = 100
    workers: int | None = None


@dataclass(frozen=True)
class Grazing:
    """A grazing of the nonimpacting period-1 orbit."""

    eta: float
    multipliers: tuple[complex, ...]
    abs_lambda: float


@dataclass(frozen=True)
class Special:
    """A special point on the impacting period-1 branch (fold, period-doubling, ...)."""

    kind: str
    eta: float
    impacts: int


@dataclass
class PanelRun:
    """What was computed for one panel (main or magnified)."""

    panel: Panel
    zoomed: bool
    eta_range: tuple[float, float]
    ds: Any
    grazings: list[Grazing]
    specials: list[Special] = field(default_factory=list)
    seconds: float = 0.0
    cpu_seconds: float = 0.0

    @property
    def windows(self) -> list[Window]:
        """All runs of equal period (:func:`grazing.sweeps.windows.find_windows`)."""
        return find_windows(self.ds)

    @property
    def first_grazing(self) -> float:
        return self.grazings[0].eta if self.grazings else math.nan

    def after_grazing(self, min_points: int = 2) -> list[Window]:
        """Periodic impacting windows after the first grazing, up to and with the first impacting period 1.

        Windows of fewer than ``min_points`` points are left out.
        """
        out = []
        for w in self.windows:
            if w.start <= self.first_grazing or not w.impacting or w.period < 1 or w.points < min_points:
                continue
            out.append(w)
            if w.period == 1:
                break
        return out

    def first_appreciable(self) -> Window | None:
        """The first periodic window after the first grazing spanning at least :data:`APPRECIABLE_WIDTH`."""
        return next((w for w in self.after_grazing(1) if w.width >= APPRECIABLE_WIDTH), None)

    def aperiodic_fraction(self) -> float:
        """Fraction of the impacting points that are aperiodic (period 0)."""
        imp = np.asarray(self.ds.impacts_per_period.values) > 0
        per = np.asarray(self.ds.period.values)
        return float(np.mean(per[imp] == 0)) if imp.any() else 0.0

    def impacting_end(self) -> float:
        """The largest η of the impacting region that starts at the first grazing (nan if none)."""
        v = np.asarray(self.ds.value.values)
        imp = np.asarray(self.ds.impacts_per_period.values) > 0
        idx = np.flatnonzero(imp & (v > self.first_grazing))
        if idx.size == 0:
            return math.nan
        non = np.flatnonzero(~imp & (v > v[idx[0]]))
        return float(v[non[0] - 1]) if non.size else float(v[-1])


def zoom_of(run: PanelRun, zoomed: Sequence[PanelRun]) -> PanelRun | None:
    """The magnified sweep of ``run``'s panel among ``zoomed`` (None if that panel has none)."""
    return next((z for z in zoomed if z.panel == run.panel), None)


def _grazings(model: grazing.HybridModel) -> list[Grazing]:
    points, _ = find_grazings(model, "eta", 0.2, 1.0)
    return [
        Grazing(float(p.model.params["eta"]), tuple(complex(z) for z in p.multipliers), p.abs_lambda)
        for p in points
    ]


def _impacting_branch(model: grazing.HybridModel, ds: Any, lo: float, hi: float) -> list[Special]:
    """Continue the widest impacting period-1 window's orbit both ways; its special points."""
    ones = [w for w in find_windows(ds) if w.period == 1 and w.impacting and w.points >= 3]
    if not ones:
        return []
    w = max(ones, key=lambda w: w.points)
    i = (w.first + w.last) // 2
    eta = float(ds.value.values[i])
    m = model.with_params(eta=eta)
    out: list[Special] = []
    try:
        orbit = find_orbit(m, np.asarray(ds.samples.values[i, -1, :]), period=1)
    except GrazingError:
        return out
    for end in (lo, hi):
        try:
            br = continue_orbit(model, "eta", eta, end, orbit=orbit, detect=("fold", "period-doubling"))
        except GrazingError:
            continue
        out += [Special(s.kind, float(s.param), int(s.orbit.impacts)) for s in br.special]
    return sorted(out, key=lambda s: s.eta)


def start_state(model: grazing.HybridModel) -> np.ndarray | None:
    """The state (at τ = 0) of the stable nonimpacting period-1 orbit, if there is one; else None (rest).

    A sweep that starts just below a grazing from rest may land on an impacting
    attractor coexisting with the nonimpacting orbit; the experimenter, who
    arrives from lower η, is on the nonimpacting one.
    """
    try:
        orbit = find_orbit(model, virtual=True, period=1)
    except GrazingError:
        return None
    return orbit.state.copy() if orbit.stable and orbit.guard_min > 0 else None


def run_panel(
    case: str,
    panel: Panel,
    settings: Settings,
    zoomed: bool = False,
    alpha: float | None = None,
    method: str = "flow",
) -> PanelRun:
    """Compute one panel: the grazings, the sweep and (main panels) the impacting branch.

    With ``method="map"`` the sweep iterates the discontinuity-map Poincare map
    built at the panel's first grazing (fig 10) instead of the impacting flow.

    Examples
    --------
    >>> run = run_panel("B", Panel("d", 40.0, (0.44, 0.49)), Settings(points=40, periods=40))
    >>> [round(g.eta, 4) for g in run.grazings]
    [0.4451, 0.5473]
    """
    start, cpu = time.perf_counter(), time.process_time()
    extra = {} if alpha is None else {"alpha": alpha}
    model = grazing.models.pendulum(case, theta_hat=math.radians(panel.theta_hat_deg), **extra)
    grazings = _grazings(model)
    if zoomed:
        if panel.zoom is None or not grazings:
            raise ValueError(f"panel {panel.key} has no zoom or no grazing")
        lo, hi = grazings[0].eta + panel.zoom[0], grazings[0].eta + panel.zoom[1]
        n = settings.zoom_points
    else:
        (lo, hi), n = panel.eta_range, settings.points
    zdm = None
    if method == "map":
        from grazing.normalform import find_grazing_point, normal_form_at

        zdm = normal_form_at(find_grazing_point(model, "eta", 0.2, 1.0)).discontinuity_map()
    ds = sweep(
        model, "eta", np.linspace(lo, hi, n), x0=start_state(model.with_params(eta=lo)),
        transient=settings.transient, periods=settings.periods, lyapunov=False, chunk_size=0, workers=1,
        zdm=zdm,
    )  # fmt: skip
    specials = [] if (zoomed or method == "map") else _impacting_branch(model, ds, lo, hi)
    return PanelRun(
        panel,
        zoomed,
        (lo, hi),
        ds,
        grazings,
        specials,
        time.perf_counter() - start,
        time.process_time() - cpu,
    )


def warm_up(case: str = "B") -> None:
    """Load the compiled kernels (simulation, sweeps, shooting) here, before worker processes fork.

    Forked workers inherit them instead of each loading them again (about a
    second per process).  Cheap when already loaded.
    """
    model = grazing.models.pendulum(case, eta=0.4, theta_hat=math.radians(20))
    grazing.simulate(model, [0.0, 0.0], periods=2)
    sweep(model, "eta", [0.4], transient=1, periods=1, lyapunov=False, workers=1)
    find_grazings(model, "eta", 0.39, 0.41)


_RUNS: dict[tuple[Any, ...], PanelRun] = {}
"""Panels computed in this process (figs 7 and 10 share the direct-simulation panels)."""


def _job(args: tuple[str, Panel, Settings, bool, float | None, str]) -> PanelRun:
    return run_panel(*args)


def run_parallel(
    fn: Callable[[Any], Any], jobs: Sequence[Any], workers: int, done: Callable[[Any], None] | None = None
) -> list[Any]:
    """``[fn(job) for job in jobs]`` on up to ``workers`` forked processes, in completion order.

    ``done`` is called with each result as it arrives.  With one worker (or
    one job) everything runs in this process.
    """
    results: list[Any] = []
    if workers <= 1 or len(jobs) <= 1:
        for job in jobs:
            results.append(fn(job))
            if done is not None:
                done(results[-1])
        return results
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from grazing.workers import init_worker

    ctx = mp.get_context("fork" if "fork" in mp.get_all_start_methods() else "spawn")
    n = min(workers, len(jobs))
    # The workers die with this process (grazing.workers); Ctrl-C still reaches them.
    with ProcessPoolExecutor(n, ctx, initializer=init_worker, initargs=(os.getpid(), False)) as ex:
        futures = [ex.submit(fn, job) for job in jobs]
        for fut in as_completed(futures):
            results.append(fut.result())
            if done is not None:
                done(results[-1])
    return results


def run_panels(
    case: str,
    panels: Sequence[Panel],
    settings: Settings,
    *,
    zooms: bool = True,
    alpha: float | None = None,
    method: str = "flow",
    progress: Callable[[str], None] | None = None,
    tag: str = "",
) -> tuple[list[PanelRun], list[PanelRun]]:
    """Compute all panels (and their magnified sweeps) in parallel.

    Returns
    -------
    main, zoomed
        The main panels in the order given, and the magnified ones.
    """
    say = progress or (lambda _msg: None)
    wanted = [(case, p, settings, False, alpha, method) for p in panels]
    if zooms:
        wanted += [(case, p, settings, True, alpha, method) for p in panels if p.zoom is not None]
    jobs = [j for j in wanted if j not in _RUNS]
    workers = min(settings.workers or os.cpu_count() or 1, max(len(jobs), 1))
    if jobs:
        warm_up(case)

    def report(run: PanelRun) -> None:
        lo, hi = run.eta_range
        what = "magnified" if run.zoomed else "panel"
        say(
            f"{tag}{what} ({run.panel.key}) θ̂ = {run.panel.theta_hat_deg:g}°: {run.ds.sizes['point']} "
            f"η values in [{lo:.6g}, {hi:.6g}] in {run.seconds:.1f} s (CPU {run.cpu_seconds:.1f} s)"
        )

    for run in run_parallel(_job, jobs, workers, report):  # completion order: match by panel
        _RUNS[next(j for j in jobs if j[1] == run.panel and j[3] == run.zoomed)] = run
    results = [_RUNS[j] for j in wanted]
    main = [next(r for r in results if r.panel == p and not r.zoomed) for p in panels]
    zoomed = [r for p in panels for r in results if r.panel == p and r.zoomed]
    return main, zoomed


def draw_panels(
    runs: Sequence[PanelRun],
    path: Path,
    *,
    suptitle: str = "",
    ncols: int = 2,
    width: float = 6.2,
    height: float = 3.6,
) -> None:
    """Draw the diagrams, one panel per run (``width`` x ``height`` inches each), windows labelled."""
    from matplotlib.figure import Figure

    nrows = math.ceil(len(runs) / ncols)
    size = (width * ncols, height * nrows + (0.4 if suptitle else 0.0))
    fig = Figure(figsize=size, layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    for ax, run in zip(axes, runs):
        p = run.panel
        zoom_kw = {"min_points": 2, "min_fraction": 0.004} if run.zoomed else None
        plot_bifurcation(ax, run.ds, window_kw=zoom_kw)
        lo, hi = ax.get_xlim()
        inside = [g for g in run.grazings if lo <= g.eta <= hi]
        mark_grazings(ax, [g.eta for g in inside], labels=[f"grazing η = {g.eta:.4f}" for g in inside])
        title = f"({p.key}) θ̂ = {p.theta_hat_deg:g}°"
        if run.zoomed:
            title += ", magnified past the first grazing"
            _offset_ticks(ax, run.first_grazing)
        ax.set_title(title, loc="left", fontsize=10)
    for ax in axes[len(runs) :]:
        ax.set_visible(False)
    if suptitle:
        fig.suptitle(suptitle, fontsize=11)
    save_png(fig, path)


_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _offset_ticks(ax: Any, eta_g: float) -> None:
    """For a very narrow magnified panel: ticks at round values of η − η_g, in units of a power of ten."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, MaxNLocator

    lo, hi = ax.get_xlim()
    span = hi - lo
    if not span > 0 or span > 5e-3:
        return
    exp = math.floor(math.log10(span)) - 1
    unit = 10.0**exp
    ticks = MaxNLocator(7, steps=[1, 2, 5, 10]).tick_values((lo - eta_g) / unit, (hi - eta_g) / unit)
    ax.xaxis.set_major_locator(FixedLocator([eta_g + t * unit for t in ticks]))
    ax.xaxis.set_major_formatter(
        FuncFormatter(lambda x, _pos: f"{round((x - eta_g) / unit):d}".replace("-", "−"))
    )
    ax.set_xlim(lo, hi)
    ax.set_xlabel(f"(η − η_g) × 10{str(-exp).translate(_SUPERSCRIPT)},   first grazing η_g = {eta_g:.7f}")


def describe_windows(windows: Sequence[Window], digits: int = 4, origin: float | None = None) -> str:
    """``"5 (η 0.4455–0.446), 4 (η 0.4468–0.4494), ..."``; impacting period 1 as ``"1 impacting"``.

    With ``origin`` (a grazing η_g), the ranges are given as η − η_g.

    Examples
    --------
    >>> ws = [Window(4, True, 0, 3, 0.1, 0.13, 0.095, 0.135), Window(1, True, 4, 9, 0.14, 0.2, 0.135, 0.2)]
    >>> describe_windows(ws, digits=3)
    '4 (η 0.1–0.13), 1 impacting (η 0.14–0.2)'
    >>> describe_windows(ws[:1], origin=0.1)
    '4 (η − η_g = 0 to 0.03)'
    """
    parts = []
    for w in windows:
        name = "1 impacting" if w.period == 1 else str(w.period)
        if origin is None:
            parts.append(f"{name} (η {w.start:.{digits}g}–{w.stop:.{digits}g})")
        else:
            a, b = w.start - origin, w.stop - origin
            parts.append(f"{name} (η − η_g = {_g(a)} to {_g(b)})")
    return ", ".join(parts) if parts else "none"


def _g(x: float) -> str:
    """Two significant digits, exact zero as ``0``, a proper minus sign."""
    return ("0" if abs(x) < 1e-15 else f"{x:.2g}").replace("-", "−")


def drop_doublings(windows: Sequence[Window], gap: int = 3) -> list[Window]:
    """Leave out period-doubled satellites: a period-2p window within ``gap`` points of a period-p window.

    Such windows are the ends of the period-doubling cascades at the edges of
    a period-p window, not new windows of the period-adding sequence.

    Examples
    --------
    >>> ws = [Window(2, True, 0, 9, 0, 9, 0, 9), Window(4, True, 10, 12, 10, 12, 10, 12),
    ...       Window(3, True, 20, 29, 20, 29, 20, 29)]
    >>> [w.period for w in drop_doublings(ws)]
    [2, 3]
    """
    out = []
    for w in windows:
        sat = any(
            v.period * 2 == w.period and (0 <= w.first - v.last <= gap or 0 <= v.first - w.last <= gap)
            for v in windows
        )
        if not sat:
            out.append(w)
    return out


def sequence(windows: Sequence[Window]) -> list[int]:
    """The periods of the windows in order (impacting period 1 included)."""
    return [w.period for w in windows]


def grazing_text(run: PanelRun) -> str:
    """``"η_g = 0.4451 (|λ| = 0.508), 0.5473 (|λ| = 0.576)"``."""
    if not run.grazings:
        return "no grazing for η in [0.2, 1]"
    return ", ".join(f"{g.eta:.4f} (|λ| = {g.abs_lambda:.3f})" for g in run.grazings)


def end_of_impacting(run: PanelRun) -> str:
    """How the impacting region of a main panel ends, with the continuation's special points."""
    v = np.asarray(run.ds.value.values)
    per = np.asarray(run.ds.period.values)
    end = run.impacting_end()
    parts = []
    twos = [w for w in run.after_grazing(2) if w.period == 2]
    pds = [s for s in run.specials if s.kind == "period-doubling"]
    folds = [s for s in run.specials if s.kind == "fold"]
    if twos:
        w = twos[-1]
        nxt = next((x for x in run.windows if x.first > w.last and x.points >= 3), None)
        if nxt is None:
            what = "the end of the sweep"
        elif nxt.period == 1:
            what = "impacting period-1 motion" if nxt.impacting else "nonimpacting period-1 motion"
        else:
            what = "aperiodic motion" if nxt.period == 0 else f"period-{nxt.period} motion"
        text = f"the last period-2 window ends at η ≈ {w.stop:.4f}, followed by {what}"
        near = [s for s in pds if abs(s.eta - w.stop) < 0.01]
        if near:
            pd = near[0].eta
            text += f" (the impacting period-1 orbit is stable above its period-doubling at η = {pd:.5f})"
        parts.append(text)
    if math.isfinite(end) and end < v[-1]:
        i = int(np.flatnonzero(v == end)[0])
        text = f"impacting motion (period {per[i]}) last seen at η = {end:.4f}, then nonimpacting period 1"
        near = [s for s in folds if abs(s.eta - end) < 0.01]
        if near:
            text += f"; the impacting period-1 orbit ends at a fold (saddle-node) at η = {near[0].eta:.5f}"
        parts.append(text)
    elif math.isfinite(end):
        parts.append(f"impacting motion up to the end of the panel (η = {v[-1]:.3f})")
    return "; ".join(parts) if parts else "no impacting region"
