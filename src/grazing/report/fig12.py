"""Figure 12 of the paper: the fig 7 diagrams with the forcing amplitude reduced to 0.71 α (case A-reduced).

Case A-reduced is r = 0.4707, β = 0.010 and α = 0.71 × 0.2254 (§6.2): less
viscous damping and a smaller forcing, which the paper found to match the
experiment's bifurcation diagrams (its fig 2) much better than case B.  The
computation is that of fig 7 (:mod:`grazing.report.diagrams`); the comparison
is with the experiment as §2.2 describes it, window by window.
"""

from __future__ import annotations

import time
from pathlib import Path

from grazing.report import diagrams, fig07, paper
from grazing.report.base import Comparison, DataFile, FigureResult, Image, Say
from grazing.report.diagrams import Panel, PanelRun, Runs, Settings, Window
from grazing.report.rules import criterion_row, fmt_delta, numeric_row, overlap_length, span

FIGURE_ID = "12"
CASE = "A-reduced"
CASE_LABEL = "case A-reduced"

PANELS: tuple[Panel, ...] = (
    Panel("a", 10.0, (0.33, 0.40), zoom=(-1e-3, 0.013), overview=(0.30, 1.0)),
    Panel("b", 20.0, (0.39, 0.50), zoom=(-1e-3, 0.06), overview=(0.37, 0.87)),
    Panel("c", 30.0, (0.42, 0.50), zoom=(-1e-3, 0.05), overview=(0.40, 0.76)),
    Panel("d", 40.0, (0.43, 0.50), zoom=(-1e-3, 0.04), overview=(0.42, 0.68)),
)
"""Main ranges around the experiment's (§2.2), magnified sweeps over each cascade, overviews to the fold."""

SETTINGS = Settings()
"""Resolution used by the report (tests patch a smaller one)."""

HEAD_WINDOW = (
    "Case A-reduced does not have the experiment's first significant window (its period, at least 0.001 "
    "wide, in "
    "the experiment's η range) at every stop angle: the paper's “uncannily similar” does not survive a "
    "window-by-window check"
)


def build(out_dir: Path, progress: Say | None = None, settings: Settings | None = None) -> FigureResult:
    """Compute fig 12, write its PNGs and data into ``out_dir`` and describe them."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    s = settings or SETTINGS
    runs = diagrams.run_panels(CASE, PANELS, s, progress=say, tag="fig 12: ")
    say("fig 12: drawing")
    names = ("fig12_bifurcation.png", "fig12_magnified.png", "fig12_overview.png")
    views = (runs.main, runs.zoom, runs.overview)
    *_, (nc, csv) = diagrams.run_calls(
        [(diagrams.draw_panels, (r, out_dir / n), {"case_label": CASE_LABEL}) for r, n in zip(views, names)]
        + [(diagrams.write_data, (runs, out_dir, "fig12_sweeps", CASE), {})]
    )
    cpu = sum(r.cpu_seconds for r in runs.all())
    images = (
        Image(
            names[0],
            "Brute-force bifurcation diagrams of case A-reduced (r = 0.4707, β = 0.010, α = 0.71 × 0.2254 = "
            f"0.16003): θ at τ = 2πk against η, {s.points} η values per panel over the range of the "
            "experiment (§2.2), η increasing, each η starting from the final state of the previous one. "
            "Shaded: nonimpacting period-1 motion. Dashed red: grazings of the nonimpacting period-1 orbit. "
            "Blue bars and numbers: periodic windows.",
            "Bifurcation diagrams against eta at four stop angles, case A-reduced",
        ),
        Image(
            names[1],
            f"The cascades past the first grazing η_g, magnified ({s.zoom_points} η values each).",
            "Magnified bifurcation diagrams past the first grazing, case A-reduced",
        ),
        Image(
            names[2],
            f"Overviews out to the end of the impacting region ({s.overview_points} η values each); "
            "purple dotted: the fold of the impacting period-1 orbit.",
            "Overview bifurcation diagrams, case A-reduced",
        ),
    )
    summary = (
        "The paper's fig 12: the fig 7 computation (direct simulation, experimenter sweeps upwards in η, "
        "grazings from continuation) for the reduced forcing amplitude 0.71 α with the damping of case A, "
        f"compared with the experiment as §2.2 describes it. Compute time {cpu:.1f} CPU seconds."
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="Figure 12: bifurcation diagrams in η, forcing reduced to 0.71 α (case A-reduced)",
        images=images,
        summary=summary,
        comparisons=comparisons(runs),
        notes=notes(runs),
        seconds=time.perf_counter() - start,
        data=(
            DataFile(
                nc.name, "every sweep, NetCDF, one group per panel and view (a_main, a_zoom, a_overview, ...)"
            ),
            DataFile(csv.name, "every window of every sweep, CSV"),
        ),
    )


def candidates(runs: Runs, p: Panel, period: int) -> list[Window]:
    """Appreciable impacting windows of ``period`` past the first grazing, magnified and main sweeps."""
    out = []
    for run in (runs.of(p, "zoom"), runs.of(p, "main")):
        if run is None:
            continue
        out += [
            w for w in run.after_grazing(2) if w.period == period and w.width >= diagrams.APPRECIABLE_WIDTH
        ]
    return out


def experiment_window_row(runs: Runs, p: Panel) -> Comparison:
    """The experiment's first significant window (period and η interval) against ours."""
    exp = paper.EXPERIMENT[f"{p.theta_hat_deg:g}"]
    cands = candidates(runs, p, exp.period)
    lo, hi = exp.window
    tag = f"({p.key}) θ̂ = {p.theta_hat_deg:g}°: first significant window, period {exp.period}"
    others = ", ".join(
        f"{w.period} ({w.start:.4f}–{w.stop:.4f})"
        for w in runs.finest(p).after_grazing(2)
        if w.width >= diagrams.APPRECIABLE_WIDTH
    )
    note = f"Our appreciable windows past η_g: {others or 'none'}."
    if hi is None:  # "starting around η = 0.45"
        start = paper.WINDOW_START_40
        best = min(cands, key=lambda w: abs(w.start - start.value), default=None)
        if best is None:
            return criterion_row(
                FIGURE_ID,
                tag,
                exp.window_text,
                "none",
                False,
                kind="experiment",
                rule=f"agree when we have an appreciable period-{exp.period} window starting within "
                f"{start.tolerance:g} of η = {start.text}",
                source="§2.2",
                headline=HEAD_WINDOW,
                note=note,
            )
        return numeric_row(
            FIGURE_ID,
            tag + ": where it starts",
            start,
            best.start,
            kind="experiment",
            source="§2.2 (experiment, fig 2(d))",
            headline=HEAD_WINDOW,
            ours_text=f"starts {best.start:.4f} (to {best.stop:.4f})",
            note=note,
        )
    best = max(cands, key=lambda w: overlap_length(span(w), (lo, hi)), default=None)
    hit = best is not None and overlap_length(span(best), (lo, hi)) >= 0
    ours: object = span(best) if best is not None else "none"
    if best is not None and not hit:
        gap = best.start - hi if best.start > hi else best.stop - lo
        note = f"Nearest such window misses the experiment's by {fmt_delta(gap, 4)} in η. " + note
    return criterion_row(
        FIGURE_ID,
        tag,
        (lo, hi),
        ours,
        hit,
        kind="experiment",  # type: ignore[arg-type]
        rule=f"agree when we have a period-{exp.period} window at least {diagrams.APPRECIABLE_WIDTH:g} wide "
        "(“significant”) whose η interval overlaps the experiment's",
        source="§2.2 (experiment, fig 2)",
        paper_text=f"period {exp.period}, {exp.window_text}",
        ours_text=(
            f"period {exp.period}, η {best.start:.4f}–{best.stop:.4f}"
            if best is not None
            else f"no period-{exp.period} window ≥ 0.001 wide"
        ),
        headline=HEAD_WINDOW,
        note=note,
    )


def large_window(run: PanelRun) -> tuple[Window | None, bool]:
    """The widest appreciable window of period ≥ 3 past the first grazing, and whether chaos surrounds it.

    "Both sides": aperiodic points between the first grazing and the window, and between the window
    and the last period-2 window.
    """
    cands = [w for w in run.after_grazing(2) if w.period >= 3 and w.width >= diagrams.APPRECIABLE_WIDTH]
    if not cands:
        return None, False
    big = max(cands, key=lambda w: w.width)
    twos = [w for w in run.after_grazing(2) if w.period == 2]
    end = twos[-1].first if twos else len(run.ds.value)
    ws = run.windows
    before = any(w.period == 0 and w.start > run.first_grazing and w.last < big.first for w in ws)
    after = any(w.period == 0 and w.first > big.last and w.last < end for w in ws)
    return big, before and after


def comparisons(runs: Runs) -> tuple[Comparison, ...]:
    rows: list[Comparison] = [experiment_window_row(runs, p) for p in PANELS]
    matched = {p.key: rows[i].verdict == "agree" for i, p in enumerate(PANELS)}
    rows.append(
        criterion_row(
            FIGURE_ID,
            "(a), (c), (d): “uncannily similar” to the experiment",
            "(a), (c), (d)",
            ", ".join(f"({k})" for k, v in matched.items() if v) or "none",
            all(matched[k] for k in paper.UNCANNY),
            kind="paper",
            rule="agree when in each of the panels the paper names the experiment's first significant window "
            "is matched (the rows above)",
            source="§6.2",
            paper_text="(a), (c), (d) match",
            headline=HEAD_WINDOW,
            ours_text="matched: " + (", ".join(f"({k})" for k, v in matched.items() if v) or "none"),
        )
    )
    parts, ok = [], True
    for p in PANELS:
        det = runs.finest(p)
        big, surrounded = large_window(det)
        seq = [w.period for w in det.after_grazing(2)]
        last_two = len(seq) >= 2 and seq[-1] == 1 and seq[-2] == 2
        good = big is not None and surrounded and last_two
        ok &= good
        what = f"{big.period} ({big.start:.4f}–{big.stop:.4f})" if big is not None else "no window ≥ 0.001"
        parts.append(f"({p.key}) {what}{'' if good else ' ✗'}")
    rows.append(
        criterion_row(
            FIGURE_ID,
            "all panels: one large window in chaos, then period 2",
            paper.FIG12_PATTERN,
            "; ".join(parts),
            ok,
            kind="paper",
            rule="agree when in every panel the widest window of period ≥ 3 past grazing is at least 0.001 "
            "wide, has aperiodic points (no period ≤ 50) on both sides, and the sequence ends with period 2 "
            "then impacting period 1 (magnified sweeps)",
            source="§6.2",
            paper_text="one large window in chaos, then 2",
            headline="Case A-reduced: not every panel has one large window surrounded by chaos",
        )
    )
    for r in runs.main:
        exp = paper.EXPERIMENT[f"{r.panel.theta_hat_deg:g}"]
        rows.append(
            numeric_row(
                FIGURE_ID,
                f"({r.panel.key}) θ̂ = {r.panel.theta_hat_deg:g}°: first grazing η, model vs the "
                "experiment's η_c",
                exp.eta_c,
                r.first_grazing,
                kind="experiment",
                headline="Case A-reduced's first grazing lies away from the experiment's η_c at some stop "
                "angles (it was not fitted to them)",
            )
        )
    for p in PANELS[1:]:
        end = diagrams.impacting_end(runs.widest(p))
        rows.append(
            criterion_row(
                FIGURE_ID,
                f"({p.key}) θ̂ = {p.theta_hat_deg:g}°: how the impacting region ends",
                paper.END_OF_IMPACTING,
                end.short(),
                end.paper_like,
                kind="experiment",
                rule="agree when the last period-2 window is followed by nonimpacting period-1 motion",
                source="§2.2",
                paper_text="2 → no impacts",
                headline=fig07.HEAD_FOLD,
                note="As for case B (fig 7): the period-2 window gives way to impacting period-1 motion, "
                "which lasts up to a fold of the impacting orbit beyond the second grazing.",
            )
        )
    return tuple(rows)


def notes(runs: Runs) -> tuple[str, ...]:
    lam = ", ".join(
        f"{r.panel.theta_hat_deg:g}°: {r.grazings[0].abs_lambda:.3f}" for r in runs.main if r.grazings
    )
    seqs = "; ".join(
        f"({p.key}) " + ", ".join(str(w.period) for w in runs.finest(p).after_grazing(2)) for p in PANELS
    )
    allr = runs.all()
    return (
        f"Windows of ≥ 2 points past the first grazing, magnified sweeps: {seqs}.",
        f"The first grazing's largest multiplier modulus |λ| is {lam} here, against 0.40–0.51 for case B: "
        "above 2/3, where eq. 21 no longer predicts a period-adding cascade; the windows here do not follow "
        "a by-one sequence.",
        f"Cost: {sum(r.cpu_seconds for r in allr):.1f} CPU seconds over {len(allr)} sweeps.",
        "η_g of the model against η_c of the experiment: "
        + ", ".join(
            f"{r.panel.theta_hat_deg:g}°: {r.first_grazing:.4f} vs "
            f"{paper.EXPERIMENT[f'{r.panel.theta_hat_deg:g}'].eta_c.text}"
            for r in runs.main
        )
        + ".",
    )
