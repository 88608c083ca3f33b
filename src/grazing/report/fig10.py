"""Figure 10 of the paper: the fig 7 diagrams computed with the discontinuity map.

Each panel iterates the map of the paper's eq. 20 — the flow with the stop
ignored and Nordmark's discontinuity map applied once per period at the
grazing phase, with the coefficients of the first grazing orbit at that stop
angle — over the same η values as fig 7, from the same starting state.  The
periodic windows of the map are compared with those of the direct simulation
(fig 7), window by window: where each starts and ends, and how the agreement
degrades with the distance from the grazing point.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from grazing.report import diagrams, fig07
from grazing.report.base import Comparison, FigureResult, Image, Progress
from grazing.report.diagrams import PanelRun, Settings
from grazing.sweeps.windows import WindowComparison, compare_windows

FIGURE_ID = "10"


def _rows_for(flow: PanelRun, mapped: PanelRun) -> list[WindowComparison]:
    """Windows past the first grazing, direct simulation against the map."""
    eta_g = flow.first_grazing
    rows = compare_windows(flow.ds, mapped.ds, eta_g, min_points=2)
    return [r for r in rows if r.reference.start > eta_g and r.period >= 2]


def _describe(rows: list[WindowComparison], limit: int = 6) -> str:
    parts = []
    for r in rows[:limit]:
        ref = f"{r.reference.start:.5f}–{r.reference.stop:.5f}"
        oth = "missing" if r.other is None else f"{r.other.start:.5f}–{r.other.stop:.5f}"
        parts.append(f"period {r.period}: simulation {ref}, map {oth}")
    return "; ".join(parts) if parts else "no periodic windows past grazing"


def degradation(rows: list[WindowComparison]) -> list[tuple[float, float]]:
    """(distance from grazing, relative error of the window's edges) for the paired windows.

    The relative error is ``(|Δstart| + |Δstop|) / (2 * distance)``: how far the
    map's window edges are from the simulation's, in units of the distance
    from the grazing point.
    """
    out = []
    for r in rows:
        if r.other is not None and r.distance > 0:
            out.append((r.distance, (abs(r.start_error) + abs(r.end_error)) / (2 * r.distance)))
    return sorted(out)


def build(out_dir: Path, progress: Progress | None = None, settings: Settings | None = None) -> FigureResult:
    """Compute fig 10, write its PNGs into ``out_dir`` and describe them."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    s = settings or fig07.SETTINGS
    flow_main, flow_zoom = diagrams.run_panels(
        fig07.CASE, fig07.PANELS, s, progress=say, tag="fig 10 (flow): "
    )
    map_main, map_zoom = diagrams.run_panels(
        fig07.CASE, fig07.PANELS, s, method="map", progress=say, tag="fig 10 (map): "
    )
    say("fig 10: drawing")
    name, zname = "fig10_map_bifurcation.png", "fig10_map_magnified.png"
    diagrams.draw_panels(map_main, out_dir / name)
    diagrams.draw_panels(map_zoom, out_dir / zname, ncols=1, width=9.0, height=3.2)

    comparisons: list[Comparison] = []
    all_rows: list[WindowComparison] = []
    for fm, mm in zip(flow_main, map_main):
        th = fm.panel.theta_hat_deg
        zf = next((z for z in flow_zoom if z.panel == fm.panel), None)
        zm = next((z for z in map_zoom if z.panel == mm.panel), None)
        rows = _rows_for(fm, mm)
        zrows = _rows_for(zf, zm) if zf is not None and zm is not None else []
        all_rows += rows + zrows
        paired = [r for r in rows + zrows if r.other is not None]
        comparisons.append(
            Comparison(
                f"fig 10({fm.panel.key}): θ̂ = {th:g}°, periodic windows past the first grazing "
                f"(η_g = {fm.first_grazing:.5f})",
                "the period-adding cascades are captured (clearly in (c), (d)), “but the intervals in "
                "which they appear are somewhat shortened”",
                "§6.1, fig 10",
                ("magnified sweep: " + _describe(zrows) + ". Main sweep: " if zrows else "")
                + _describe(rows),
                bool(paired) if rows or zrows else None,
                f"{len(paired)} of {len(rows) + len(zrows)} windows of the simulation have a window of the "
                "same period in the map.",
            )
        )
    deg = degradation(all_rows)
    if deg:
        near = [e for d, e in deg if d < 1e-3]
        far = [e for d, e in deg if d >= 1e-2]
        mid = [e for d, e in deg if 1e-3 <= d < 1e-2]

        def stat(xs: list[float]) -> str:
            return f"median {np.median(xs):.2f} ({len(xs)} windows)" if xs else "no windows"

        comparisons.append(
            Comparison(
                "how the map's windows drift from the simulation's with the distance d from grazing",
                "good qualitative agreement even relatively far from grazing; windows shortened",
                "§6.1",
                "window edges' error in units of d: "
                f"d < 10⁻³: {stat(near)}; 10⁻³ ≤ d < 10⁻²: {stat(mid)}; d ≥ 10⁻²: {stat(far)}",
                None,
                "The map is exact at leading order in the distance from grazing: its error grows with d "
                "(the ZDM's relative error is O(√penetration), and the flow pieces are the exact "
                "nonlinear ones).",
            )
        )
    cpu = sum(r.cpu_seconds for r in map_main + map_zoom)
    images = (
        Image(
            name,
            "The diagrams of fig 7 (same η values, same starting state, each η from the previous final "
            "state) computed by iterating the discontinuity-map Poincaré map built at the first grazing "
            "of each panel. Shaded: nonimpacting period 1. Dashed red: grazings (continuation). "
            "Numbers: windows.",
            "Bifurcation diagrams computed with the discontinuity map",
        ),
        Image(
            zname,
            "The magnified sweeps of fig 7, computed with the map.",
            "Magnified bifurcation diagrams computed with the discontinuity map",
        ),
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="Figure 10: the same diagrams from the discontinuity map",
        images=images,
        summary=(
            "The map needs only the grazing orbit: its contact phase t*, the grazing acceleration "
            "a = L_f²h and the reset's direction e = (0, 1 + r) (see docs/normal-form.md). The engine "
            "integrates the flow with the stop ignored and applies the map once per period at t*. "
            f"Compute time {cpu:.1f} CPU seconds."
        ),
        comparisons=tuple(comparisons),
        notes=(
            "Far from grazing the map has no reason to be right: it knows nothing of the second grazing "
            "or of impacts away from the grazing phase; its diagrams there are shown for completeness.",
        ),
        seconds=time.perf_counter() - start,
    )


__all__ = ["FIGURE_ID", "build", "degradation"]
