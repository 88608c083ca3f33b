"""Brute-force η bifurcation diagrams at four stop angles: the code figs 7, 10 and 12 share.

Each panel is an *experimenter sweep*: η increases in small steps, every
point starting from the final state of the previous one (one sequential
chunk per panel, so that coexisting attractors are followed as in the
laboratory rather than re-chosen every few points).  The sweeps run in
parallel, one process per core.  A panel has up to three views:

* ``main``: the range of the experiment's fig 2 as §2.2 describes it, where
  the cascade past the first grazing lives;
* ``zoom``: a magnified sweep just past the first grazing ``η_g``;
* ``overview``: a coarser sweep out to the end of the impacting region, on
  which the impacting period-1 orbit is continued (its period-doubling and
  the fold that ends the impacting region).

Each panel also gets the grazing points of the nonimpacting period-1 orbit
(the stop ignored, followed through folds: :func:`grazing.orbits.find_grazings`),
drawn as vertical lines.
"""

from __future__ import annotations

import itertools
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
from grazing.parallel import map_unordered
from grazing.plotting import label_windows, mark_grazings, plot_bifurcation, visible_windows
from grazing.report.base import save_png
from grazing.report.data import slim_sweep, write_csv, write_groups
from grazing.sweeps import sweep
from grazing.sweeps.windows import Window, find_windows

APPRECIABLE_WIDTH = 1e-3
"""A periodic window is *appreciable* when it spans at least this much in η (the paper does not say)."""

VIEWS = ("main", "zoom", "overview")
"""The views of a panel, in the order they are drawn."""


@dataclass(frozen=True)
class Panel:
    """One panel: a stop angle and the η ranges swept.

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
    overview
        If set, an extra coarser sweep over this wider η range, out to the end of
        the impacting region; the impacting period-1 branch is continued on it.
    """

    key: str
    theta_hat_deg: float
    eta_range: tuple[float, float]
    zoom: tuple[float, float] | None = None
    overview: tuple[float, float] | None = None

    def has(self, view: str) -> bool:
        """Whether the panel has this view."""
        return view == "main" or getattr(self, view) is not None


@dataclass(frozen=True)
class Settings:
    """Resolution and cost of the diagrams.

    Attributes
    ----------
    points
        η values per main panel.
    zoom_points
        η values per magnified panel.
    overview_points
        η values per overview panel.
    transient, periods
        Forcing periods discarded and sampled at each η (the transient stops
        early once the samples repeat; see :func:`grazing.sweeps.sweep`).
    workers
        Processes (default: all cores).
    """

    points: int = 1000
    zoom_points: int = 400
    overview_points: int = 500
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
    """What was computed for one view of one panel."""

    panel: Panel
    view: str
    eta_range: tuple[float, float]
    ds: Any
    grazings: list[Grazing]
    specials: list[Special] = field(default_factory=list)
    seconds: float = 0.0
    cpu_seconds: float = 0.0

    @property
    def zoomed(self) -> bool:
        return self.view == "zoom"

    @property
    def windows(self) -> list[Window]:
        """All runs of equal period (:func:`grazing.sweeps.windows.find_windows`)."""
        return find_windows(self.ds)

    @property
    def first_grazing(self) -> float:
        return self.grazings[0].eta if self.grazings else math.nan

    @property
    def step(self) -> float:
        """The η step of the sweep."""
        v = np.asarray(self.ds.value.values)
        return float((v[-1] - v[0]) / max(len(v) - 1, 1))

    def after_grazing(self, min_points: int = 2) -> list[Window]:
        """Periodic impacting windows after the first grazing, up to and with the first impacting period 1.

        Windows of fewer than ``min_points`` points are left out.
        """
        out = []
        for w in self.windows:
            if w.stop <= self.first_grazing or not w.impacting or w.period < 1 or w.points < min_points:
                continue
            out.append(w)
            if w.period == 1:
                break
        return out

    def first_appreciable(self) -> Window | None:
        """The first periodic window after the first grazing spanning at least :data:`APPRECIABLE_WIDTH`."""
        return next((w for w in self.after_grazing(1) if w.width >= APPRECIABLE_WIDTH), None)

    def aperiodic_windows(self) -> list[Window]:
        """Aperiodic impacting runs past the first grazing, before the first impacting period-1 window."""
        one = next((w for w in self.after_grazing(1) if w.period == 1), None)
        end = one.start if one is not None else math.inf
        return [
            w
            for w in self.windows
            if w.period == 0 and w.impacting and w.stop > self.first_grazing and w.stop < end
        ]

    def aperiodic_width(self) -> float:
        """Total η extent of :meth:`aperiodic_windows`."""
        return float(sum(w.width for w in self.aperiodic_windows()))

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


@dataclass
class Runs:
    """All views of all panels of one figure, each list in panel order."""

    main: list[PanelRun]
    zoom: list[PanelRun] = field(default_factory=list)
    overview: list[PanelRun] = field(default_factory=list)

    def of(self, panel: Panel, view: str) -> PanelRun | None:
        """The run of ``panel`` in ``view`` (None if the panel has no such view)."""
        return next((r for r in getattr(self, view) if r.panel == panel), None)

    def finest(self, panel: Panel) -> PanelRun:
        """The magnified run of the panel where there is one, else its main run."""
        return self.of(panel, "zoom") or self.of(panel, "main")  # type: ignore[return-value]

    def widest(self, panel: Panel) -> PanelRun:
        """The overview run of the panel where there is one, else its main run."""
        return self.of(panel, "overview") or self.of(panel, "main")  # type: ignore[return-value]

    def all(self) -> list[PanelRun]:
        return self.main + self.zoom + self.overview


_GRAZING_POINTS: dict[tuple[str, float, float | None], list[Any]] = {}
"""The grazings of each panel's model found in this process (all views and figs 7 and 10 share them)."""


def panel_model(case: str, theta_hat_deg: float, alpha: float | None = None) -> grazing.HybridModel:
    """The pendulum of a panel: ``case`` at the stop angle ``theta_hat_deg`` (and ``alpha`` if given)."""
    extra = {} if alpha is None else {"alpha": alpha}
    return grazing.models.pendulum(case, theta_hat=math.radians(theta_hat_deg), **extra)


def grazing_points(case: str, theta_hat_deg: float, alpha: float | None = None) -> list[Any]:
    """The grazings of the nonimpacting period-1 orbit for η in [0.2, 1] (computed once per process).

    The :class:`~grazing.orbits.contact.GrazingPoint` objects of
    :func:`grazing.orbits.find_grazings`, in its order.
    """
    key = (case, float(theta_hat_deg), alpha)
    if key not in _GRAZING_POINTS:
        _GRAZING_POINTS[key] = find_grazings(panel_model(*key), "eta", 0.2, 1.0)[0]
    return _GRAZING_POINTS[key]


def first_grazing(model: grazing.HybridModel, points: Sequence[Any]) -> Any:
    """The grazing of lowest η among ``points`` (:func:`grazing_points` of ``model``), as
    :func:`grazing.normalform.find_grazing_point` picks it; its one-line error if there is none."""
    from grazing.normalform import find_grazing_point

    if not points:
        return find_grazing_point(model, "eta", 0.2, 1.0)
    return min(points, key=lambda g: g.model.params["eta"])


def _grazings(points: Sequence[Any]) -> list[Grazing]:
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


def _view_range(
    panel: Panel, view: str, grazings: list[Grazing], settings: Settings
) -> tuple[float, float, int]:
    if view == "zoom":
        if panel.zoom is None or not grazings:
            raise ValueError(f"panel {panel.key} has no zoom or no grazing")
        return grazings[0].eta + panel.zoom[0], grazings[0].eta + panel.zoom[1], settings.zoom_points
    if view == "overview":
        if panel.overview is None:
            raise ValueError(f"panel {panel.key} has no overview")
        return panel.overview[0], panel.overview[1], settings.overview_points
    return panel.eta_range[0], panel.eta_range[1], settings.points


def run_panel(
    case: str,
    panel: Panel,
    settings: Settings,
    view: str = "main",
    alpha: float | None = None,
    method: str = "flow",
    points: Sequence[Any] | None = None,
) -> PanelRun:
    """Compute one view of a panel: the grazings, the sweep and (overview) the impacting branch.

    With ``method="map"`` the sweep iterates the discontinuity-map Poincare map
    built at the panel's first grazing (fig 10) instead of the impacting flow.
    The impacting period-1 branch is continued on the overview (on the main
    view of a panel without one).  ``points`` are the panel's grazings
    (:func:`grazing_points`, computed here if not given).

    Examples
    --------
    >>> run = run_panel("B", Panel("d", 40.0, (0.44, 0.49)), Settings(points=40, periods=40))
    >>> [round(g.eta, 4) for g in run.grazings]
    [0.4451, 0.5473]
    """
    if view not in VIEWS:
        raise ValueError(f"view must be one of {VIEWS}, got {view!r}")
    start, cpu = time.perf_counter(), time.process_time()
    model = panel_model(case, panel.theta_hat_deg, alpha)
    if points is None:
        points = grazing_points(case, panel.theta_hat_deg, alpha)
    grazings = _grazings(points)
    lo, hi, n = _view_range(panel, view, grazings, settings)
    zdm = None
    if method == "map":
        from grazing.normalform import normal_form_at

        zdm = normal_form_at(first_grazing(model, points), ("eta", "theta_hat")).discontinuity_map()
    ds = sweep(
        model,
        "eta",
        np.linspace(lo, hi, n),
        x0=start_state(model.with_params(eta=lo)),
        transient=settings.transient,
        periods=settings.periods,
        lyapunov=False,
        chunk_size=0,
        workers=1,
        zdm=zdm,
    )
    branch_here = view == "overview" or (view == "main" and panel.overview is None)
    specials = _impacting_branch(model, ds, lo, hi) if (branch_here and method == "flow") else []
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    return PanelRun(panel, view, (lo, hi), ds, grazings, specials, wall, cpu)


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


def _job(args: tuple[str, Panel, Settings, str, float | None, str, Sequence[Any]]) -> PanelRun:
    *view, points = args
    return run_panel(*view, points=points)


def _grazing_job(key: tuple[str, float, float | None]) -> tuple[tuple[str, float, float | None], list[Any]]:
    return key, grazing_points(*key)


def run_parallel(
    fn: Callable[[Any], Any], jobs: Sequence[Any], workers: int, done: Callable[[Any], None] | None = None
) -> list[Any]:
    """``[fn(job) for job in jobs]`` on up to ``workers`` forked processes, in completion order.

    ``done`` is called with each result as it arrives.  With one worker (or
    one job) everything runs in this process.  The pool is
    :func:`grazing.parallel.map_unordered`: the workers die with this process.
    """
    results: list[Any] = []
    for res in map_unordered(fn, list(jobs), workers, ignore_sigint=False):
        results.append(res)
        if done is not None:
            done(res)
    return results


def run_calls(calls: Sequence[tuple[Callable[..., Any], tuple[Any, ...], dict[str, Any]]]) -> list[Any]:
    """``[fn(*args, **kwargs) for fn, args, kwargs in calls]`` on a process per core; the results in order.

    A figure's images and data files are drawn and written at once (each
    call in its own process: matplotlib and the netCDF writer hold the GIL).
    """
    workers = min(os.cpu_count() or 1, max(len(calls), 1))
    tagged = run_parallel(_call, list(enumerate(calls)), workers)
    return [res for _, res in sorted(tagged, key=lambda t: t[0])]


def _call(item: tuple[int, tuple[Callable[..., Any], tuple[Any, ...], dict[str, Any]]]) -> tuple[int, Any]:
    i, (fn, args, kwargs) = item
    return i, fn(*args, **kwargs)


def run_panels(
    case: str,
    panels: Sequence[Panel],
    settings: Settings,
    *,
    views: Sequence[str] = VIEWS,
    alpha: float | None = None,
    method: str = "flow",
    progress: Callable[[str], None] | None = None,
    tag: str = "",
) -> Runs:
    """Compute the views of all panels in parallel (those computed before in this process are reused).

    The grazings of the panels are found first (a panel at a time, in
    parallel) and given to each of its views.
    """
    say = progress or (lambda _msg: None)
    wanted = [(case, p, settings, v, alpha, method) for v in VIEWS if v in views for p in panels if p.has(v)]
    jobs = [j for j in wanted if j not in _RUNS]
    workers = min(settings.workers or os.cpu_count() or 1, max(len(jobs), 1))
    if jobs:
        warm_up(case)
    keys = list(dict.fromkeys((case, float(j[1].theta_hat_deg), alpha) for j in jobs))
    missing = [k for k in keys if k not in _GRAZING_POINTS]
    _GRAZING_POINTS.update(run_parallel(_grazing_job, missing, min(workers, max(len(missing), 1))))

    def report(run: PanelRun) -> None:
        lo, hi = run.eta_range
        say(
            f"{tag}{run.view} ({run.panel.key}) θ̂ = {run.panel.theta_hat_deg:g}°: {run.ds.sizes['point']} "
            f"η values in [{lo:.6g}, {hi:.6g}] in {run.seconds:.1f} s (CPU {run.cpu_seconds:.1f} s)"
        )

    tasks = [(*j, _GRAZING_POINTS[(case, float(j[1].theta_hat_deg), alpha)]) for j in jobs]
    for run in run_parallel(_job, tasks, workers, report):  # completion order: match by panel and view
        _RUNS[next(j for j in jobs if j[1] == run.panel and j[3] == run.view)] = run
    out = Runs(main=[])
    for v in VIEWS:
        setattr(out, v, [_RUNS[j] for j in wanted if j[3] == v])
    return out


# ---------------------------------------------------------------------------- drawing


def spans(values: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """The η extents (half-way to the neighbouring points) of the runs where ``mask`` holds.

    Examples
    --------
    >>> spans(np.array([0.0, 1.0, 2.0, 3.0]), np.array([True, True, False, True]))
    [(0.0, 1.5), (2.5, 3.0)]
    """
    out = []
    n = len(values)
    i = 0
    while i < n:
        if not mask[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and mask[j + 1]:
            j += 1
        lo = values[0] if i == 0 else 0.5 * (values[i - 1] + values[i])
        hi = values[-1] if j == n - 1 else 0.5 * (values[j] + values[j + 1])
        out.append((float(lo), float(hi)))
        i = j + 1
    return out


def quiet_only_here(run: PanelRun, reference: PanelRun | None) -> tuple[np.ndarray, np.ndarray]:
    """``(both, only_here)``: masks of the points of ``run`` on nonimpacting period 1 where ``reference``
    (the full system on the same η grid) is nonimpacting too, and where it impacts.

    Without a reference of the same grid every nonimpacting point counts as ``both``.  For the map's
    diagrams (fig 10) ``only_here`` is what is hatched: the map has no impacts but the full system has.
    """
    v = np.asarray(run.ds.value.values)
    per = np.asarray(run.ds.period.values)
    non = (per == 1) & (np.asarray(run.ds.impacts_per_period.values) == 0)
    if reference is None or reference.ds.sizes["point"] != len(v):
        return non, np.zeros_like(non)
    ref_imp = np.asarray(reference.ds.impacts_per_period.values) > 0
    return non & ~ref_imp, non & ref_imp


def _shade(ax: Any, run: PanelRun, reference: PanelRun | None) -> None:
    """Shade nonimpacting period-1 motion; hatch where the map has no impacts but the full system has."""
    v = np.asarray(run.ds.value.values)
    trans = ax.get_xaxis_transform()
    lo, hi = ax.get_xlim()
    both, only_map = quiet_only_here(run, reference)
    for a, b in spans(v, both):
        ax.axvspan(a, b, color="#dfe9f3", lw=0, zorder=-1)
        if b - a >= 0.25 * (hi - lo):
            ax.text(
                0.5 * (a + b),
                0.03,
                "period 1,\nno impacts",
                transform=trans,
                ha="center",
                va="bottom",
                fontsize=9,
                color="#4a6b8a",
            )
    for a, b in spans(v, only_map):
        ax.axvspan(a, b, facecolor="none", edgecolor="#d9a441", hatch="///", lw=0, zorder=-1)
        if b - a >= 0.25 * (hi - lo):
            ax.text(
                0.5 * (a + b),
                0.03,
                "map: no impacts\n(the full system\nimpacts here, fig 7)",
                transform=trans,
                ha="center",
                va="bottom",
                fontsize=9,
                color="#8a6514",
                bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 1.0},
            )


def draw_panels(
    runs: Sequence[PanelRun],
    path: Path,
    *,
    case_label: str,
    reference: Sequence[PanelRun] = (),
    suptitle: str = "",
    ncols: int = 2,
    width: float = 6.0,
    height: float = 3.8,
) -> None:
    """Draw the diagrams, one panel per run (``width`` x ``height`` inches each), windows labelled.

    Every panel's title states its letter, θ̂ and ``case_label``.  With
    ``reference`` (the direct-simulation runs of the same panels, for the map's
    diagrams), ranges where the map has no impacts but the full system does are
    hatched instead of shaded.  Overview panels mark the period-doubling and the
    fold of the impacting period-1 orbit.
    """
    from matplotlib.figure import Figure

    nrows = math.ceil(len(runs) / ncols)
    size = (width * ncols, height * nrows + (0.4 if suptitle else 0.0))
    fig = Figure(figsize=size, layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    for ax, run in zip(axes, runs):
        p = run.panel
        plot_bifurcation(ax, run.ds, windows=False, nonimpacting=False)
        ref = next((r for r in reference if r.panel == p and r.view == run.view), None)
        _shade(ax, run, ref)
        lo, hi = ax.get_xlim()
        min_points = 2 if run.zoomed else 3
        shown = visible_windows(run.windows, hi - lo, min_points=min_points, min_fraction=0.004)
        label_windows(ax, shown)
        inside = [g for g in run.grazings if lo <= g.eta <= hi]
        mark_grazings(ax, [g.eta for g in inside], labels=[f"grazing η = {g.eta:.4f}" for g in inside])
        for s in run.specials:
            if lo <= s.eta <= hi and s.kind == "fold":
                ax.axvline(s.eta, color="tab:purple", lw=1.0, ls=":", zorder=1)
                ax.text(
                    s.eta,
                    0.5,
                    f" fold of the impacting\n orbit, η = {s.eta:.4f}",
                    rotation=90,
                    transform=ax.get_xaxis_transform(),
                    ha="right",
                    va="center",
                    fontsize=9,
                    color="tab:purple",
                    bbox={"fc": "white", "ec": "none", "alpha": 0.75, "pad": 0.8},
                )
        title = f"({p.key}) θ̂ = {p.theta_hat_deg:g}°, {case_label}"
        if run.zoomed:
            title += ", zoomed past the first grazing"
            _offset_ticks(ax, run.first_grazing)
        ax.set_title(title, loc="left", fontsize=10.5)
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


# ---------------------------------------------------------------------------- data


def write_data(runs: Runs, out_dir: Path, stem: str, case: str) -> tuple[Path, Path]:
    """Write every sweep (NetCDF, one group ``<panel>_<view>`` each) and every window (CSV).

    Returns the two paths: ``<stem>.nc`` and ``<stem>_windows.csv``.
    """
    groups = {}
    rows = []
    for run in runs.all():
        p = run.panel
        groups[f"{p.key}_{run.view}"] = slim_sweep(
            run.ds,
            panel=p.key,
            view=run.view,
            case=case,
            theta_hat_deg=p.theta_hat_deg,
            first_grazing_eta=run.first_grazing,
        )
        for w in run.windows:
            rows.append(
                (p.key, run.view, p.theta_hat_deg, w.period, int(w.impacting), w.points, w.start, w.stop)
            )
    nc = write_groups(out_dir / f"{stem}.nc", groups)
    csv = out_dir / f"{stem}_windows.csv"
    write_csv(
        csv,
        ["panel", "view", "theta_hat_deg", "period", "impacting", "points", "eta_start", "eta_stop"],
        rows,
    )
    return nc, csv


# ---------------------------------------------------------------------------- text


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


def drop_doublings(windows: Sequence[Window], gap: int = 3, min_parent: int = 2) -> list[Window]:
    """Leave out period-doubled satellites: a period-2p window within ``gap`` points of a period-p window.

    Such windows are the ends of the period-doubling cascades at the edges of
    a period-p window, not new windows of the period-adding sequence.  Parents
    of period below ``min_parent`` do not count: the period-2 window that ends
    in the period-doubling of the impacting period-1 orbit belongs to the
    sequence.

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
            v.period >= min_parent
            and v.period * 2 == w.period
            and (0 <= w.first - v.last <= gap or 0 <= v.first - w.last <= gap)
            for v in windows
        )
        if not sat:
            out.append(w)
    return out


def cascade(run: PanelRun) -> list[Window]:
    """The clearly resolved windows past the first grazing, up to impacting period 1.

    Windows of ≥ 3 points and ≥ 1 % of the sweep's span, period-doubled satellites left out
    (:func:`drop_doublings`).
    """
    span = run.eta_range[1] - run.eta_range[0]
    return drop_doublings([w for w in run.after_grazing(3) if w.width >= 0.01 * span])


def is_reverse_adding(periods: Sequence[int], min_windows: int = 3) -> bool:
    """Whether periods decrease by one from window to window, with at least ``min_windows`` windows.

    Examples
    --------
    >>> is_reverse_adding([5, 4, 3, 2, 1]), is_reverse_adding([2, 1]), is_reverse_adding([5, 2, 1])
    (True, False, False)
    """
    return len(periods) >= min_windows and all(b == a - 1 for a, b in itertools.pairwise(periods))


def sequence(windows: Sequence[Window]) -> list[int]:
    """The periods of the windows in order (impacting period 1 included)."""
    return [w.period for w in windows]


@dataclass(frozen=True)
class ImpactingEnd:
    """How the impacting region of a panel ends as η increases (from its overview sweep).

    Attributes
    ----------
    last_two
        The η interval of the last period-2 window past the first grazing (None: none).
    after_two
        What follows it: ``"impacting period 1"``, ``"nonimpacting period 1"``, ``"aperiodic"``, ...
    period_doubling
        The period-doubling of the impacting period-1 orbit near the end of that window (nan: none).
    end
        The last η with impacts (nan: none).
    fold
        The fold of the impacting period-1 orbit near ``end`` (nan: none found).
    second_grazing
        The second grazing of the nonimpacting orbit (nan: none).
    """

    last_two: tuple[float, float] | None
    after_two: str
    period_doubling: float
    end: float
    fold: float
    second_grazing: float

    @property
    def paper_like(self) -> bool:
        """The paper's picture: the period-2 window is followed by nonimpacting period 1."""
        return self.last_two is not None and self.after_two == "nonimpacting period 1"

    def short(self) -> str:
        """``"2 → impacting 1 at 0.4471; impacts end at the fold 0.8404 (2nd grazing 0.7887)"``."""
        parts = []
        if self.last_two is not None:
            parts.append(f"2 → {self.after_two} at {self.last_two[1]:.4f}")
        if math.isfinite(self.fold):
            parts.append(f"impacts end at the fold η = {self.fold:.4f}")
        elif math.isfinite(self.end):
            parts.append(f"impacts end at η = {self.end:.4f}")
        if math.isfinite(self.second_grazing):
            parts.append(f"(2nd grazing {self.second_grazing:.4f})")
        return "; ".join(parts) if parts else "no impacting region"


def impacting_end(run: PanelRun) -> ImpactingEnd:
    """How the impacting region of ``run`` (an overview, with the continuation's special points) ends."""
    twos = [w for w in run.after_grazing(2) if w.period == 2]
    after = "none"
    last_two = None
    pd = math.nan
    if twos:
        w = twos[-1]
        last_two = (w.start, w.stop)
        nxt = next((x for x in run.windows if x.first > w.last and x.points >= 2), None)
        if nxt is None:
            after = "the end of the sweep"
        elif nxt.period == 1:
            after = "impacting period 1" if nxt.impacting else "nonimpacting period 1"
        else:
            after = "aperiodic" if nxt.period == 0 else f"period {nxt.period}"
        near = [s.eta for s in run.specials if s.kind == "period-doubling" and abs(s.eta - w.stop) < 0.01]
        pd = near[0] if near else math.nan
    end = run.impacting_end()
    v = np.asarray(run.ds.value.values)
    if math.isfinite(end) and end >= v[-1]:
        end = math.nan  # impacting up to the end of the sweep
    folds = [
        s.eta for s in run.specials if s.kind == "fold" and math.isfinite(end) and abs(s.eta - end) < 0.01
    ]
    second = run.grazings[1].eta if len(run.grazings) > 1 else math.nan
    return ImpactingEnd(last_two, after, pd, end, folds[0] if folds else math.nan, second)
