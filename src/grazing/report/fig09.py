"""Figure 9 of the paper (numerical time series) and fig 3(b),(d)-style delay plots.

The paper (§6.1, fig 9) shows θ(τ) for case B at θ̂ = 10°, η = 0.33294
("chaotic") and at θ̂ = 40°, η = 0.446 ("period-5"), as the numerical
counterparts of its experimental fig 3.  Here the same runs are simulated,
drawn as time series and as Takens delay plots (θ(τ) against θ(τ − π/2),
as the paper does for the experiment in fig 3(b),(d)), and classified by the
period of their stroboscopic samples and their largest Lyapunov exponent.

The θ̂ = 10° point turns out to sit within 2·10⁻⁴ in η of the grazing
bifurcation, where the outcome hinges on the fifth significant digit of the
forcing amplitude α: the module therefore runs it at the tabulated α = 0.2254,
at the α = 0.2258 printed in §3 and at α = A/L = 50.8/225 (the definition in
eq. 3 with the apparatus of §2.1), and reports all three.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

import grazing
from grazing.plotting import plot_delay, plot_time_series
from grazing.report import paper
from grazing.report.base import (
    Comparison,
    DataFile,
    Dynamics,
    FigureResult,
    Image,
    Say,
    save_png,
    signed,
)
from grazing.report.data import write_groups
from grazing.report.rules import criterion_row

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

FIGURE_ID = "9"

ALPHA_TABLE = paper.ALPHA_TABLE.value
"""α of case B as tabulated (fig 7 caption; docs/equations.md)."""
ALPHA_PRINTED = paper.ALPHA_PRINTED.value
"""α printed in §3: "In the experimental data the amplitude was set at α = 0.2258"."""
ALPHA_APPARATUS = paper.ALPHA_APPARATUS
"""α = A/L (eq. 3) with A = 50.8 mm and L = 225 mm (§2.1)."""
_ETA_A, _ETA_B = paper.FIG9[0][1].value, paper.FIG9[1][1].value
_SRC = "fig 9 and its caption; §6.1"

TRANSIENT = 1000
"""Forcing periods discarded before anything is recorded."""
DENSE_PERIODS = 200
"""Forcing periods of dense trajectory (time series, delay plot, period detection)."""
POINTS_PER_PERIOD = 200
"""Dense-output points per forcing period (a quarter period is then exactly 50 points)."""
SHOWN_PERIODS = 40
"""Forcing periods drawn in the time series."""
FINE_POINTS = 4000
"""Dense-output points per period for the magnified inset (resolves the peaks to ~1e-5 degrees)."""
LYAPUNOV_PERIODS = 5000
"""Forcing periods averaged for the Lyapunov exponent."""
MULTISTART = 16
"""Random initial states tried where our result differs from the paper's."""


@dataclass(frozen=True)
class Case:
    """One parameter point of the figure."""

    key: str
    panel: str
    theta_hat_deg: float
    eta: float
    alpha: float
    alpha_label: str
    paper: str
    source: str
    plotted: bool = True
    inset: bool = False


CASES: tuple[Case, ...] = (
    Case(
        "a", "(a)", 10.0, _ETA_A, ALPHA_TABLE, "α = 0.2254 (case B as tabulated)", "chaotic", _SRC, inset=True
    ),
    Case(
        "a-printed",
        "(a)",
        10.0,
        _ETA_A,
        ALPHA_PRINTED,
        "α = 0.2258 (as printed in §3)",
        "chaotic",
        _SRC,
        plotted=False,
    ),
    Case(
        "a-apparatus",
        "(a′)",
        10.0,
        _ETA_A,
        ALPHA_APPARATUS,
        "α = A/L = 50.8/225 = 0.225778",
        "chaotic",
        _SRC,
        inset=True,
    ),
    Case("b", "(b)", 40.0, _ETA_B, ALPHA_TABLE, "α = 0.2254 (case B as tabulated)", "period-5", _SRC),
    Case(
        "b-045",
        "(b, η = 0.45)",
        40.0,
        paper.FIG7D_CHAOTIC.value,
        ALPHA_TABLE,
        "α = 0.2254 (case B as tabulated)",
        "chaotic",
        paper.FIG7D_CHAOTIC.source,
        plotted=False,
    ),
)
"""The paper's two points (fig 9), the first with three readings of α, and η = 0.45 at 40° (§6.1)."""


@dataclass(frozen=True)
class CaseRun:
    """What was computed for one case."""

    case: Case
    model: grazing.HybridModel
    dense: grazing.Solution
    dynamics: Dynamics
    stop_gap: float
    """θ̂ − max θ over the dense span (radians; 0 when it impacts)."""
    fine: grazing.Solution | None = None
    """The periods shown, with :data:`FINE_POINTS` points per period (for the magnified inset)."""


def _model(case: Case, alpha: float | None = None) -> grazing.HybridModel:
    return grazing.models.pendulum(
        "B",
        eta=case.eta,
        theta_hat=math.radians(case.theta_hat_deg),
        alpha=case.alpha if alpha is None else alpha,
    )


def classify(model: grazing.HybridModel, x0: np.ndarray | list[float] | None = None) -> Dynamics:
    """Period, largest Lyapunov exponent and impact rate of the attractor reached from ``x0``.

    Runs :data:`TRANSIENT` periods, then :data:`LYAPUNOV_PERIODS` periods with
    the tangent dynamics.  The period is detected on the last 200 samples.

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> classify(m).verdict
    'period-5'
    """
    x0 = [0.0, 0.0] if x0 is None else x0
    sol = grazing.simulate(model, x0, transient=TRANSIENT, periods=LYAPUNOV_PERIODS, lyapunov=True)
    period = grazing.detect_period(sol.samples[-DENSE_PERIODS:])
    lyap = float(np.max(sol.lyapunov)) if sol.lyapunov is not None else math.nan
    return Dynamics(period, lyap, len(sol.impacts) / LYAPUNOV_PERIODS)


def run_case(case: Case) -> CaseRun:
    """Simulate one case: a dense trajectory and the classification of its attractor."""
    model = _model(case)
    dense = grazing.simulate(
        model,
        [0.0, 0.0],
        transient=TRANSIENT,
        periods=DENSE_PERIODS,
        trajectory=POINTS_PER_PERIOD,
        guard_min=True,
    )
    fine = None
    if case.inset:
        fine = grazing.simulate(
            model, [0.0, 0.0], transient=TRANSIENT, periods=SHOWN_PERIODS, trajectory=FINE_POINTS
        )
    dyn = classify(model)
    gap = dense.guard_min[0] if dense.guard_min is not None else math.nan
    return CaseRun(case, model, dense, dyn, gap, fine)


def grazing_eta(theta_hat: float, alpha: float, eta_lo: float = 0.25, tol: float = 1e-8) -> float:
    """The η at which the nonimpacting period-1 orbit first reaches the stop.

    The orbit is computed with the stop moved out of the way (θ̂ = 3 rad) and
    its maximum angle compared with ``theta_hat``: η is scanned upwards from
    ``eta_lo`` in steps of 0.005 to bracket the first crossing, which is then
    bisected to ``tol``.

    Examples
    --------
    >>> import math
    >>> round(grazing_eta(math.radians(10), 0.2254), 4)
    0.3331
    """

    def excess(eta: float) -> float:
        far = grazing.models.pendulum("B", eta=eta, theta_hat=3.0, alpha=alpha)
        sol = grazing.simulate(far, [0.0, 0.0], transient=300, periods=2, guard_min=True)
        assert sol.guard_min is not None
        return (3.0 - sol.guard_min[0]) - theta_hat

    lo, step = eta_lo, 0.005
    if excess(lo) >= 0:
        raise ValueError(f"the nonimpacting orbit already reaches the stop at eta = {lo}")
    hi = lo + step
    while excess(hi) < 0:
        lo, hi = hi, hi + step
        if hi > 1.0:
            raise ValueError("no grazing below eta = 1")
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


def multistart(case: Case, n: int = MULTISTART, seed: int = 9) -> dict[str, int]:
    """Verdicts reached from ``n`` random initial states (θ uniform in [−60°, θ̂), θ′ in [−1, 1]).

    Examples
    --------
    >>> multistart(CASES[3], n=2)
    {'period-5': 2}
    """
    model = _model(case)
    rng = np.random.default_rng(seed)
    th = math.radians(case.theta_hat_deg)
    counts: dict[str, int] = {}
    for _ in range(n):
        x0 = [rng.uniform(-math.radians(60), th - 1e-3), rng.uniform(-1.0, 1.0)]
        verdict = classify(model, x0).verdict
        counts[verdict] = counts.get(verdict, 0) + 1
    return counts


def _per_period_maxima(sol: grazing.Solution) -> np.ndarray:
    """The largest θ in each forcing period of a dense trajectory."""
    T = sol.model.period
    t, th = sol.trajectory_t, sol.trajectory[:, 0]
    k = np.floor((t - t[0]) / T + 1e-9).astype(int)
    n = int(np.rint((t[-1] - t[0]) / T))
    out = np.full(n, -np.inf)
    inside = k < n  # the very last point starts a new period
    np.maximum.at(out, k[inside], th[inside])
    return out


def _draw_time_series(runs: list[CaseRun], path: Path) -> None:
    from matplotlib.figure import Figure

    heights: list[float] = []
    for r in runs:  # a magnified panel of its own under each run that has one (no inset over the curve)
        heights += [2.8, 2.3] if r.fine is not None else [2.8]
    fig = Figure(figsize=(10.0, sum(heights) + 0.4), layout="constrained")
    all_axes = list(np.atleast_1d(fig.subplots(len(heights), 1, gridspec_kw={"height_ratios": heights})))
    axes = []
    for run in runs:
        ax = all_axes.pop(0)
        axes.append(ax)
        c = run.case
        t0 = (
            run.dense.t[0] / run.model.period - 1.0
        )  # the trajectory starts one period before the first sample
        span = (t0, t0 + SHOWN_PERIODS)
        plot_time_series(ax, run.dense, degrees=True, span=span)
        ax.set_title(
            f"{c.panel}  case B, θ̂ = {c.theta_hat_deg:g}°, η = {c.eta:g}, {c.alpha_label}: "
            f"{run.dynamics.verdict}",
            fontsize=10,
            loc="left",
        )
        ax.grid(alpha=0.3)
        if run.fine is not None:
            below = all_axes.pop(0)
            below.sharex(ax)
            ax.tick_params(labelbottom=False)
            ax.set_xlabel("")
            _draw_magnified(below, run)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside upper center", ncols=3, fontsize=9, frameon=False)
    save_png(fig, path)


def _draw_magnified(inset: Axes, run: CaseRun) -> None:
    """Magnify the upper part of the time series (as the inset of the paper's fig 9(a)), in its own axes.

    Drawn from a separate run with :data:`FINE_POINTS` points per period over
    the periods shown, so that the peaks are resolved to ~1e-5 degrees, and
    as θ − θ̂, with the impacts marked.  The axes ``inset`` sit under the
    run's own, sharing its time axis.
    """
    sol = run.fine
    assert sol is not None and sol.trajectory is not None
    T = run.model.period
    stop = run.model.params["theta_hat"]
    maxima = _per_period_maxima(sol)
    depth = max(math.degrees(stop - float(maxima.min())), 1e-4)
    inset.plot(sol.trajectory_t / T, np.degrees(sol.trajectory[:, 0] - stop), color="tab:blue", lw=0.7)
    inset.axhline(0.0, color="tab:red", lw=1.0, ls="--")
    if len(sol.impacts):
        inset.plot(
            sol.impacts.t / T,
            np.zeros(len(sol.impacts)),
            ls="none",
            marker="v",
            ms=4,
            color="tab:red",
            label="impact",
        )
    inset.set_ylim(-3.0 * depth, 0.6 * depth)
    inset.tick_params(labelsize=8.5)
    inset.grid(alpha=0.3)
    inset.set_ylabel("θ − θ̂ (degrees)")
    inset.set_xlabel("τ / 2π (forcing periods)")
    n_imp = len(sol.impacts)
    head = f"{run.case.panel} magnified near the stop: "
    if n_imp:
        text = (
            f"{head}{n_imp} impacts (red triangles) in {SHOWN_PERIODS} periods;\n"
            f"the other peaks fall short of the stop by up to {depth:.2g}°"
        )
    else:
        text = f"{head}no impacts; every peak stays {depth:.3f}° below the stop"
    inset.set_title(text, fontsize=9.5, loc="left")


def _draw_delay(runs: list[CaseRun], path: Path) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4.0 * len(runs), 4.2), layout="constrained")
    axes = fig.subplots(1, len(runs))
    for ax, run in zip(np.atleast_1d(axes), runs):
        c = run.case
        plot_delay(ax, run.dense, math.pi / 2, degrees=True, line_kw={"lw": 0.4})
        ax.set_title(
            f"{c.panel}  case B, θ̂ = {c.theta_hat_deg:g}°, η = {c.eta:g}\n{c.alpha_label}",
            fontsize=9.5,
            loc="left",
        )
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    save_png(fig, path)


def build(out_dir: Path, progress: Say | None = None) -> FigureResult:
    """Compute fig 9 and the delay plots, write the PNGs into ``out_dir`` and describe them."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    runs: list[CaseRun] = []
    for case in CASES:
        say(f"fig 9: θ̂ = {case.theta_hat_deg:g}°, η = {case.eta:g}, α = {case.alpha:.6g}")
        runs.append(run_case(case))
    by_key = {r.case.key: r for r in runs}

    say("fig 9: grazing points and a multistart check at θ̂ = 10°")
    th10 = math.radians(10.0)
    eta_g = {a: grazing_eta(th10, a) for a in (ALPHA_TABLE, ALPHA_PRINTED, ALPHA_APPARATUS)}
    starts = multistart(CASES[0])
    alt = {
        r.case.key: classify(_model(r.case, ALPHA_APPARATUS)) for r in runs if r.case.theta_hat_deg != 10.0
    }

    say("fig 9: drawing")
    shown = [r for r in runs if r.case.plotted]
    ts_name, delay_name = "fig09_time_series.png", "fig09_delay.png"
    _draw_time_series(shown, out_dir / ts_name)
    _draw_delay(shown, out_dir / delay_name)

    comparisons = tuple(_comparison(r, eta_g, starts, alt.get(r.case.key)) for r in runs)
    notes = _notes(by_key, eta_g, alt)
    span_text = f"{SHOWN_PERIODS} of the {DENSE_PERIODS} recorded forcing periods"
    images = (
        Image(
            ts_name,
            f"θ(τ) in degrees against τ/2π (forcing periods), {span_text}, after a transient of "
            f"{TRANSIENT} periods from rest (θ, θ′) = (0, 0) at τ = 0. Dashed red: the stop θ̂. "
            "Black dots: the stroboscopic samples at τ = 2πk. Under (a) and (a′), a panel of its own "
            "magnifies the upper part of the time series near the stop (θ − θ̂), as the inset of the paper's "
            "fig 9(a) does. Case B: r = 0.7675, "
            "β = 0.048.",
            "Simulated time series of the pendulum angle for the fig 9 parameter points",
        ),
        Image(
            delay_name,
            f"Delay plots θ(τ) against θ(τ − π/2) (a quarter of a forcing period, the delay the paper uses "
            f"for its measurements in fig 3(b),(d)), in degrees, from the simulated trajectory over "
            f"{DENSE_PERIODS} forcing periods ({POINTS_PER_PERIOD} points per period, impact points "
            "dropped and the trajectory resampled on a uniform grid). Dashed red: the stop θ̂.",
            "Delay plots of the simulated pendulum angle, a quarter period delay",
        ),
    )
    summary = (
        "Direct simulation of the impacting pendulum (event-driven, exact impact times) for the two "
        "parameter points of the paper's fig 9, classified by the period of the stroboscopic samples "
        f"(τ = 2πk, {DENSE_PERIODS} samples, tolerance 1e-6) and the largest Lyapunov exponent "
        f"(tangent dynamics with saltation matrices, averaged over {LYAPUNOV_PERIODS} periods after "
        f"{TRANSIENT} transient periods). The paper's θ̂ = 10° point lies right at the grazing "
        "bifurcation, so it is run with three values of the forcing amplitude α (see the notes)."
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="Figure 9: numerical time series (and fig 3(b),(d)-style delay plots)",
        images=images,
        summary=summary,
        comparisons=comparisons,
        notes=notes,
        seconds=time.perf_counter() - start,
        data=(write_data(runs, out_dir),),
    )


def write_data(runs: list[CaseRun], out_dir: Path) -> DataFile:
    """The dense trajectories of every case as NetCDF, one group per case."""
    import xarray as xr

    groups = {}
    for r in runs:
        c = r.case
        groups[c.key.replace("-", "_")] = xr.Dataset(
            {
                "theta": ("t", np.asarray(r.dense.trajectory[:, 0]), {"units": "rad"}),
                "samples": (
                    "k",
                    np.asarray(r.dense.samples[:, 0]),
                    {"units": "rad", "long_name": "θ at τ = 2πk"},
                ),
            },
            coords={"t": ("t", np.asarray(r.dense.trajectory_t), {"long_name": "τ"})},
            attrs={
                "theta_hat_deg": c.theta_hat_deg,
                "eta": c.eta,
                "alpha": c.alpha,
                "case": "B",
                "paper": c.paper,
                "ours": r.dynamics.verdict,
                "lyapunov": r.dynamics.lyapunov,
            },
        )
    path = write_groups(out_dir / "fig09_time_series.nc", groups)
    return DataFile(
        path.name,
        "the simulated trajectories θ(τ) and stroboscopic samples, NetCDF, one group per "
        "case: " + ", ".join(groups),
    )


HEAD_ALPHA = (
    "(a) θ̂ = 10°, η = 0.33294 is chaotic only with α = A/L = 0.225778 unrounded; with the tabulated "
    "α = 0.2254 this η lies below the grazing point, on the nonimpacting orbit. Our inference, not a "
    "printed error: the paper most likely computed fig 9(a) with α = A/L"
)
"""The headline of rows (a) with the printed α: a difference explained by an inference, not an erratum
(nothing printed is shown wrong by a computation; the α the paper used is not stated)."""


def _comparison(
    run: CaseRun, eta_g: dict[float, float], starts: dict[str, int], alt: Dynamics | None
) -> Comparison:
    c, d = run.case, run.dynamics
    item = f"{c.panel} θ̂ = {c.theta_hat_deg:g}°, η = {c.eta:g}, {c.alpha_label}"
    if c.key == "b-045":
        item = f"θ̂ = {c.theta_hat_deg:g}°, η = {c.eta:g} (fig 7(d)), {c.alpha_label}"
    agrees = d.verdict == c.paper
    if c.theta_hat_deg == 10.0:
        eg = eta_g[c.alpha]
        side = "below" if c.eta < eg else "above"
        note = (
            f"Our grazing point for this α is η_g = {eg:.6f}; η = {c.eta:g} lies {abs(c.eta - eg):.2g} "
            f"{side} it."
        )
        if c.eta < eg:
            gap = math.degrees(run.stop_gap)
            found = ", ".join(f"{v}× {k}" for k, v in starts.items())
            note += (
                f" The stable nonimpacting period-1 orbit stays {gap:.3f}° below the stop; "
                f"from {sum(starts.values())} random initial states we reach: {found}."
            )
        elif agrees:
            note += " Just past grazing the low-velocity impacts make the motion chaotic, as in the paper."
        else:
            note += (
                " Here the impacting period-1 orbit born just past grazing is already stable: the chaotic "
                "interval beyond grazing is narrower than the distance to it."
            )
    elif alt is not None:
        note = f"With α = A/L = 0.225778 instead: {alt.verdict} (λ₁ = {signed(alt.lyapunov, 3)})."
    else:
        note = ""
    return criterion_row(
        FIGURE_ID,
        item,
        c.paper,
        d.verdict,
        agrees,
        kind="paper",
        rule="agree when our attractor (period of 200 stroboscopic samples, tolerance 1e-6; chaotic: none ≤ "
        "64 and λ₁ > 10⁻³ per unit τ) is what the paper shows",
        source=c.source,
        ours_text=d.short(),
        note=note + f" In full: {d.describe()}.",
        headline=HEAD_ALPHA if c.theta_hat_deg == 10.0 else f"{item}: not {c.paper}",
    )


def _notes(
    by_key: dict[str, CaseRun], eta_g: dict[float, float], alt: dict[str, Dynamics]
) -> tuple[str, ...]:
    a, ap, pr = by_key["a"], by_key["a-apparatus"], by_key["a-printed"]
    notes = []
    text = (
        f"θ̂ = 10° sits on the grazing bifurcation. With α = 0.2254 (case B as in the fig 7 caption) the "
        f"nonimpacting period-1 orbit first touches the stop at η_g = {eta_g[ALPHA_TABLE]:.6f}, so the "
        f"paper's η = {a.case.eta:g} is {'below' if a.case.eta < eta_g[ALPHA_TABLE] else 'above'} grazing "
        f"and we find {a.dynamics.verdict} motion "
        f"({'no impacts' if a.dynamics.impacts_per_period == 0 else 'impacting'}). "
        f"The amplitude of that orbit grows with α: with α = A/L = 50.8/225 = 0.225778 (eq. 3 with the "
        f"apparatus of §2.1; §3 prints it rounded as 0.2258) grazing moves to η_g = "
        f"{eta_g[ALPHA_APPARATUS]:.6f}, and at η = {ap.case.eta:g} we find {ap.dynamics.verdict} motion "
        f"(λ₁ = {signed(ap.dynamics.lyapunov, 3)})."
    )
    if ap.dynamics.verdict == "chaotic" and a.dynamics.verdict != "chaotic":
        text += (
            " That is the paper's fig 9(a), chaos with irregular low-velocity impacts just past grazing, "
            "so the paper most likely computed fig 9(a) with α = A/L unrounded."
        )
    if pr.dynamics.verdict != ap.dynamics.verdict:
        text += (
            f" The interval past grazing where this happens is very narrow: with α = 0.2258 exactly "
            f"(η_g = {eta_g[ALPHA_PRINTED]:.6f}) the same η gives {pr.dynamics.verdict} motion."
        )
    notes.append(text)
    if alt:
        same = all(alt[k].verdict == by_key[k].dynamics.verdict for k in alt)
        notes.append(
            "θ̂ = 40°: "
            + (
                "the verdicts are the same with α = A/L = 0.225778 as with α = 0.2254."
                if same
                else "the verdicts change with α = A/L = 0.225778 (see the table)."
            )
        )
    notes.append(
        "Angles are in degrees in the plots (radians in the API). The Lyapunov exponent λ₁ is per unit "
        "of the nondimensional time τ (multiply by 2π for per forcing period); 'chaotic' means no period "
        "up to 64 in the stroboscopic samples and λ₁ > 10⁻³."
    )
    return tuple(notes)
