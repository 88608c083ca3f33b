"""Figure 7 of the paper: brute-force η bifurcation diagrams of case B at θ̂ = 10°, 20°, 30°, 40°.

The stroboscopic angle θ(τ = 2πk) is plotted against η, each η started from
the final state of the previous one (an experimenter sweep upwards in η,
starting on the nonimpacting orbit).  Three sets of panels: the range of the
experiment (§2.2), where the cascades live; magnified sweeps just past the
first grazing; and overviews out to the end of the impacting region, on which
the impacting period-1 orbit is continued.  The computation is shared with
figs 10 and 12 (:mod:`grazing.report.diagrams`).
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from grazing.report import diagrams, paper
from grazing.report.base import Comparison, DataFile, FigureResult, Image, Say
from grazing.report.diagrams import Panel, PanelRun, Runs, Settings
from grazing.report.rules import criterion_row, numeric_row

FIGURE_ID = "7"
CASE = "B"
CASE_LABEL = "case B"

PANELS: tuple[Panel, ...] = (
    Panel("a", 10.0, (0.32, 0.40), zoom=(-1e-6, 1.2e-5), overview=(0.30, 1.0)),
    Panel("b", 20.0, (0.38, 0.50), zoom=(-1e-4, 2e-3), overview=(0.37, 0.87)),
    Panel("c", 30.0, (0.41, 0.50), zoom=(-1e-3, 0.05), overview=(0.40, 0.76)),
    Panel("d", 40.0, (0.43, 0.50), zoom=(-1e-3, 0.036), overview=(0.42, 0.68)),
)
"""Main ranges around the experiment's (§2.2), magnified sweeps past η_g, overviews to the fold."""

SETTINGS = Settings()
"""Resolution used by the report (tests patch a smaller one)."""

ALPHA_AL_PANELS = ("a", "b")
"""The panels recomputed with α = A/L (main and magnified sweeps): where the captions' α = 0.2254 shows no
chaos past grazing, and where fig 9(a) fits only A/L."""

HEAD_FOLD = (
    "The impacting region ends at a fold (saddle-node) of the impacting period-1 orbit beyond the second "
    "grazing, not with the period-2 window at the second grazing: past the period-2 window our sweeps stay "
    "on impacting period 1 (swept downwards, they would stay nonimpacting: hysteresis)"
)


def _angles(ths: list[float]) -> str:
    return ", ".join(f"{t:g}°" for t in ths) or "no angle"


def chaos_width_text(theta_hat_deg: float, width: float) -> str:
    """How much aperiodic motion a sweep found past grazing, in words true to the number.

    Examples
    --------
    >>> chaos_width_text(10.0, 5.3e-6), chaos_width_text(20.0, 0.0)
    ('aperiodic over 5.3e-06 in η at 10°', 'no aperiodic point at 20°')
    """
    if width <= 0:
        return f"no aperiodic point at {theta_hat_deg:g}°"
    return f"aperiodic over {width:.1e} in η at {theta_hat_deg:g}°"


def headlines(runs: Runs) -> dict[str, str]:
    """The one-line differences of the figure, naming the stop angles where they occur."""
    no_chaos, no_cascade, mus, widths = [], [], [], []
    for p in PANELS:
        main, fine = runs.of(p, "main"), runs.finest(p)
        assert main is not None
        width = max(fine.aperiodic_width(), main.aperiodic_width())
        if width < diagrams.APPRECIABLE_WIDTH:
            no_chaos.append(p.theta_hat_deg)
            widths.append(chaos_width_text(p.theta_hat_deg, width))
            if main.grazings:
                z = main.grazings[0].multipliers[0]
                mus.append(f"{z.real:.2f} ± {abs(z.imag):.2f}i".replace("-", "−"))
        if not diagrams.is_reverse_adding([w.period for w in diagrams.cascade(fine)]):
            no_cascade.append(p.theta_hat_deg)
    diffs = [
        (r.panel.theta_hat_deg, r.first_grazing - paper.EXPERIMENT[f"{r.panel.theta_hat_deg:g}"].eta_c.value)
        for r in runs.main
    ]
    off = [(t, d) for t, d in diffs if abs(d) > paper.EXPERIMENT[f"{t:g}"].eta_c.tolerance]
    return {
        "chaos": f"Chaos past the first grazing is too narrow to see at the paper's scale (under "
        f"{diagrams.APPRECIABLE_WIDTH:g} in η) at θ̂ = {_angles(no_chaos)} (case B): {'; '.join(widths)}. "
        f"The grazing orbit's multipliers there ({'; '.join(mus)}) are complex, near the negative or the "
        "imaginary axis, where eq. 21's test on |λ| alone does not apply",
        "cascade": f"No reverse period-adding cascade (≥ 3 windows, periods falling by one) at θ̂ = "
        f"{_angles(no_cascade)} (case B)",
        "eta_c": (
            f"Case B's first grazing lies {min(abs(d) for _, d in off):.4f}–"
            f"{max(abs(d) for _, d in off):.4f} "
            f"from the experiment's η_c at θ̂ = {_angles([t for t, _ in off])}: case B was fitted to the "
            "experiment at 40° only (§3)"
        )
        if off
        else "",
    }


def build(out_dir: Path, progress: Say | None = None, settings: Settings | None = None) -> FigureResult:
    """Compute fig 7, write its PNGs and data into ``out_dir`` and describe them."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    s = settings or SETTINGS
    runs = diagrams.run_panels(CASE, PANELS, s, progress=say, tag="fig 7: ")
    alt = diagrams.run_panels(
        CASE,
        [p for p in PANELS if p.key in ALPHA_AL_PANELS],
        s,
        views=("main", "zoom"),
        alpha=paper.ALPHA_APPARATUS,
        progress=say,
        tag="fig 7 (α = A/L): ",
    )
    say("fig 7: drawing")
    names = ("fig07_bifurcation.png", "fig07_magnified.png", "fig07_overview.png")
    views = (runs.main, runs.zoom, runs.overview)
    *_, (nc, csv) = diagrams.run_calls(
        [(diagrams.draw_panels, (r, out_dir / n), {"case_label": CASE_LABEL}) for r, n in zip(views, names)]
        + [(diagrams.write_data, (runs, out_dir, "fig07_sweeps", CASE), {})]
    )
    alt_nc, _ = diagrams.write_data(alt, out_dir, "fig07_sweeps_alpha_al", CASE)
    images = (
        Image(
            names[0],
            f"Brute-force bifurcation diagrams of case B (r = 0.7675, β = 0.048, α = 0.2254): θ at τ = 2πk "
            f"({s.periods} samples per η after a transient of up to {s.transient} forcing periods) against "
            f"η, {s.points} η values per panel over the range of the experiment (§2.2), η increasing, each η "
            "starting from the final state of the previous one. Shaded: nonimpacting period-1 motion. Dashed "
            "red: grazings of the nonimpacting period-1 orbit (continuation). Blue bars and numbers: "
            "periodic windows and their periods (unlabelled when too narrow to label; all are in the data).",
            "Bifurcation diagrams of the stroboscopic angle against eta at four stop angles, case B",
        ),
        Image(
            names[1],
            f"Magnified sweeps just past the first grazing η_g ({s.zoom_points} η values each, same method). "
            "At θ̂ = 10° the whole cascade fits into about 10⁻⁵ in η (note the axis); at 20° period 2 starts "
            "at grazing.",
            "Magnified bifurcation diagrams past the first grazing, case B",
        ),
        Image(
            names[2],
            f"Overviews out to the end of the impacting region ({s.overview_points} η values each): the "
            "impacting period-1 orbit persists past the second grazing (dashed, right) up to its fold "
            "(purple, dotted; from its continuation), where the pendulum drops to the nonimpacting orbit.",
            "Overview bifurcation diagrams out to the end of the impacting region, case B",
        ),
    )
    data = (
        DataFile(
            nc.name,
            "every sweep of the figure, NetCDF, one group per panel and view (a_main, a_zoom, "
            "a_overview, ...): θ samples (rad), period, impacts per period",
        ),
        DataFile(csv.name, "every window (run of equal period) of every sweep, CSV"),
        DataFile(
            alt_nc.name,
            f"the sweeps of panels {', '.join(ALPHA_AL_PANELS)} (main and magnified) with α = A/L = "
            f"{paper.ALPHA_APPARATUS:.6f}, NetCDF, groups as above (their windows: "
            f"{alt_nc.stem}_windows.csv)",
        ),
    )
    cpu = sum(r.cpu_seconds for r in runs.all())
    summary = (
        "The paper's fig 7 recomputed by direct simulation (event-driven, exact impacts) of case B at the "
        "four stop angles. Every sweep is sequential, so coexisting attractors are followed the way an "
        "experimenter increasing η follows them. The grazing points come from the continuation of the "
        "nonimpacting orbit with the stop ignored; the period-doubling and fold points from the continuation "
        f"of the impacting period-1 orbit found in each overview. Compute time {cpu:.1f} CPU seconds."
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="Figure 7: bifurcation diagrams in η, case B, θ̂ = 10°, 20°, 30°, 40°",
        images=images,
        summary=summary,
        comparisons=comparisons(runs) + alpha_rows(alt),
        notes=notes(runs),
        seconds=time.perf_counter() - start,
        data=data,
    )


def _window_text(w: diagrams.Window | None) -> str:
    return "none ≥ 0.001 wide" if w is None else f"period {w.period} (η {w.start:.4f}–{w.stop:.4f})"


def comparisons(runs: Runs) -> tuple[Comparison, ...]:
    rows: list[Comparison] = []
    heads = headlines(runs)
    for p in PANELS:
        rows += panel_rows(runs, p, heads)
    zd = runs.finest(PANELS[-1])
    for pp in (paper.FIG7D_CHAOTIC, paper.FIG9[1][1]):
        i = int(np.argmin(np.abs(zd.ds.value.values - pp.value)))
        per = int(zd.ds.period.values[i])
        want = "chaotic" if pp is paper.FIG7D_CHAOTIC else "period-5"
        ours = f"period-{per}" if per > 0 else "aperiodic"
        holds = per == 0 if want == "chaotic" else per == 5
        rows.append(
            criterion_row(
                FIGURE_ID,
                f"(d) θ̂ = 40°, η = {pp.text}",
                want,
                ours,
                holds,
                kind="paper",
                rule="agree when the sweep point nearest to the paper's η has the paper's period "
                "(aperiodic: no period ≤ 50, for “chaotic”)",
                source=pp.source,
                ours_text=f"{ours} at η = {float(zd.ds.value.values[i]):.5f}",
            )
        )
    for r in runs.main:
        exp = paper.EXPERIMENT[f"{r.panel.theta_hat_deg:g}"]
        rows.append(
            numeric_row(
                FIGURE_ID,
                f"({r.panel.key}) θ̂ = {r.panel.theta_hat_deg:g}°: first grazing η, model vs experiment's η_c",
                exp.eta_c,
                r.first_grazing,
                kind="experiment",
                headline=heads["eta_c"],
                note="Case B was fitted to put the grazing at 40° at the observed η ≈ 0.445 (§3); the other "
                "stop angles are predictions of the model.",
            )
        )
    return tuple(rows)


def alpha_rows(alt: Runs) -> tuple[Comparison, ...]:
    """Chaos and the cascade past the first grazing at 10° and 20° with α = A/L (rules as with 0.2254)."""
    label = f"α = A/L = {paper.ALPHA_APPARATUS:.6f}"
    widths, seqs = [], []
    for run in alt.main:
        fine = alt.finest(run.panel)
        widths.append(
            chaos_width_text(run.panel.theta_hat_deg, max(fine.aperiodic_width(), run.aperiodic_width()))
        )
        seqs.append(f"{run.panel.theta_hat_deg:g}°: " + (" → ".join(map(str, _sequence(fine))) or "—"))
    head_chaos = (
        f"With {label} too (the α that fits fig 9(a)), chaos past the first grazing stays too narrow to see: "
        + "; ".join(widths)
    )
    head_cascade = f"With {label} too, no reverse period-adding cascade: " + "; ".join(seqs)
    rows: list[Comparison] = []
    for run in alt.main:
        p, fine = run.panel, alt.finest(run.panel)
        width = max(fine.aperiodic_width(), run.aperiodic_width())
        tag = f"({p.key}) θ̂ = {p.theta_hat_deg:g}°, {label}"
        rows.append(
            _chaos_row(
                tag,
                width,
                rule=f"as with α = 0.2254: agree when aperiodic impacting motion spans at least "
                f"{diagrams.APPRECIABLE_WIDTH:g} in η in total past the first grazing (main and magnified "
                "sweeps)",
                source="§6.1; §2.1 (A/L)",
                headline=head_chaos,
                note=f"First grazing with this α: η_g = {run.first_grazing:.6f}." + _fig9_note(p, fine),
            )
        )
        seq = _sequence(fine)
        rows.append(
            _cascade_row(
                tag,
                seq,
                rule="as with α = 0.2254: agree when the clearly resolved windows past the first grazing are "
                "at least three with periods decreasing by one",
                source="§6.1; §2.1 (A/L)",
                headline=head_cascade,
            )
        )
    return tuple(rows)


def _fig9_note(p: Panel, fine: PanelRun) -> str:
    """Where fig 9(a)'s η lies against the aperiodic band of this sweep (at fig 9(a)'s stop angle)."""
    th, eta, _ = paper.FIG9[0]
    if p.theta_hat_deg != th:
        return ""
    inside = any(w.lo <= eta.value <= w.hi for w in fine.aperiodic_windows())
    return (
        f" Fig 9(a)'s η = {eta.text} lies {'inside' if inside else 'outside'} the aperiodic band of this "
        "sweep (fig 9 finds it chaotic with this α)."
    )


def _sequence(run: PanelRun) -> list[int]:
    """The periods of the clearly resolved windows past the first grazing (:func:`diagrams.cascade`)."""
    return [w.period for w in diagrams.cascade(run)]


def _chaos_row(tag: str, width: float, *, rule: str, source: str, headline: str, note: str) -> Comparison:
    """The row "chaos past the first grazing" of a sweep whose aperiodic impacting motion spans ``width``."""
    return criterion_row(
        FIGURE_ID,
        f"{tag}: chaos past the first grazing",
        "a jump to impacting chaotic motion",
        width,
        width >= diagrams.APPRECIABLE_WIDTH,
        kind="paper",
        rule=rule,
        source=source,
        paper_text="jump to chaos",
        ours_text=f"aperiodic over {width:.1e} in η" if width > 0 else "no aperiodic motion",
        headline=headline,
        note=note,
    )


def _cascade_row(
    tag: str, seq: list[int], *, rule: str, source: str, headline: str, note: str = ""
) -> Comparison:
    """The row "reverse period-adding cascade past η_g" of a sweep whose resolved windows are ``seq``."""
    return criterion_row(
        FIGURE_ID,
        f"{tag}: reverse period-adding cascade past η_g",
        "periods decreasing by one",
        ", ".join(map(str, seq)) or "—",
        diagrams.is_reverse_adding(seq),
        kind="paper",
        rule=rule,
        source=source,
        paper_text="…, 4, 3, 2, 1",
        ours_text=" → ".join(map(str, seq)) or "—",
        headline=headline,
        note=note,
    )


def panel_rows(runs: Runs, p: Panel, heads: dict[str, str]) -> list[Comparison]:
    """The rows of one panel: first window, chaos past grazing, reverse period adding, end of impacts."""
    main, fine, wide = runs.of(p, "main"), runs.finest(p), runs.widest(p)
    assert main is not None
    th = p.theta_hat_deg
    tag = f"({p.key}) θ̂ = {th:g}°"
    rows = []
    want = paper.FIRST_WINDOW[th]
    first = fine.first_appreciable() or main.first_appreciable()
    rows.append(
        criterion_row(
            FIGURE_ID,
            f"{tag}: period of the first appreciable window past η_g",
            want,
            first.period if first else "none",
            first is not None and first.period == want,
            kind="paper",
            rule=f"agree when the first periodic window past the first grazing at least "
            f"{diagrams.APPRECIABLE_WIDTH:g} wide in η (“appreciable”; magnified sweep where there is "
            "one) has the paper's period",
            source="§6.1",
            paper_text=f"period {want}" + (" (“actually, briefly, five”)" if th == 40.0 else ""),
            ours_text=_window_text(first),
            note=f"Windows of ≥ 2 points past η_g = {main.first_grazing:.5f}: "
            + diagrams.describe_windows(
                fine.after_grazing(2), origin=fine.first_grazing if fine.zoomed else None
            ),
        )
    )
    width = max(fine.aperiodic_width(), main.aperiodic_width())
    g = main.grazings[0] if main.grazings else None
    mu = f"{g.multipliers[0].real:.3f} ± {abs(g.multipliers[0].imag):.3f}i".replace("-", "−") if g else "—"
    rows.append(
        _chaos_row(
            tag,
            width,
            rule=f"agree when aperiodic impacting motion (no period ≤ 50) spans at least "
            f"{diagrams.APPRECIABLE_WIDTH:g} in η in total between the first grazing and impacting "
            "period 1: chaos one could see in a diagram of the paper's range",
            source="§6.1",
            headline=heads["chaos"],
            note=f"The grazing orbit's multipliers are {mu} (|λ| = {g.abs_lambda:.3f}); eq. 21 looks at "
            "|λ| only, but with complex multipliers the argument decides (docs/normal-form.md §4)."
            if g
            else "",
        )
    )
    seq = _sequence(fine)
    rows.append(
        _cascade_row(
            tag,
            seq,
            rule="agree when the clearly resolved windows past the first grazing (≥ 3 points and ≥ 1 % of "
            "the sweep's span, period-doubled satellites left out), up to impacting period 1, are at least "
            "three with periods decreasing by one",
            source="§6.1",
            headline=heads["cascade"],
            note="All windows of ≥ 2 points: "
            + ", ".join(str(w.period) for w in fine.after_grazing(2))
            + ".",
        )
    )
    if th > 10.0:
        end = diagrams.impacting_end(wide)
        rows.append(
            criterion_row(
                FIGURE_ID,
                f"{tag}: how the impacting region ends",
                "grazing, destroying a period-2 orbit",
                end.short(),
                end.paper_like,
                kind="paper",
                rule="agree when the last period-2 window is followed by nonimpacting period-1 motion (the "
                "paper's second grazing)",
                source="§6.1",
                paper_text="2 → no impacts (2nd grazing)",
                ours_text=end.short(),
                headline=HEAD_FOLD,
                note="In our model the period-2 window gives way to impacting period-1 motion (the impacting "
                "period-1 orbit is stable above its period-doubling"
                + (f" at η = {end.period_doubling:.5f}" if math.isfinite(end.period_doubling) else "")
                + "), which persists past the second grazing up to a saddle-node of the impacting "
                "orbit. Sweeping η downwards from the nonimpacting side, the pendulum would stay "
                "nonimpacting down to the second grazing (hysteresis).",
            )
        )
    return rows


def _prediction_text(run: PanelRun) -> str:
    """The normal-form prediction past the panel's first grazing (docs/normal-form.md)."""
    from grazing.normalform import normal_form_at
    from grazing.normalform.prediction import predict

    th = run.panel.theta_hat_deg
    try:
        point = diagrams.first_grazing(diagrams.panel_model(CASE, th), diagrams.grazing_points(CASE, th))
        return predict(normal_form_at(point, ("eta", "theta_hat")), "eta").scenario
    except Exception as exc:  # pragma: no cover - reported, not fatal
        return f"(not computed: {exc})"


def notes(runs: Runs) -> tuple[str, ...]:
    pred = "; ".join(f"{r.panel.theta_hat_deg:g}°: {_prediction_text(r)}" for r in runs.main)
    out = [
        "Window detection: the period of the stroboscopic samples at each η (tolerance 1e-6, periods up to "
        "50); consecutive η values with the same period (and the same impacting or nonimpacting character) "
        "form a window. Aperiodic means no period up to 50 was found; the Lyapunov exponent is not computed "
        "here (see fig 9 for chaos confirmed by a positive exponent). “Appreciable” (0.001 in η) is our "
        "choice: the paper does not quantify it.",
        "What the grazing normal form predicts past each first grazing (the two-dimensional normal form "
        f"iterated, docs/normal-form.md): {pred}. Eq. 21 (1/4 < |λ| < 2/3) would predict period adding at "
        f"all four angles; it holds for real multipliers, and the multipliers here are complex.",
        "Hysteresis: between the second grazing and the fold of the impacting orbit both period-1 motions "
        "are stable; a sweep downwards in η from the nonimpacting side would stay nonimpacting there, down "
        "to the second grazing.",
    ]
    allr = runs.all()
    slow = max(allr, key=lambda r: r.seconds)
    out.append(
        f"Cost: {sum(r.cpu_seconds for r in allr):.1f} CPU seconds over {len(allr)} sweeps; the slowest, "
        f"panel ({slow.panel.key}) {slow.view}, took {slow.seconds:.1f} s."
    )
    return tuple(out)
