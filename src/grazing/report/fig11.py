"""Figure 11 of the paper: delay plots of the chaotic attractor just past grazing.

The paper shows ``theta_{k+1}`` against ``theta_k`` on the section ``tau = 0`` at
theta_hat = 40 deg, eta = 0.4458 (case B), (a) from direct simulation and (b)
from the discontinuity map, both with the "fingered" shape that the
square-root singularity produces.

In our computation eta = 0.4458 lies in the period-5 window (0.44541-0.44603;
the paper's own fig 9(b) has period 5 at eta = 0.446), so the figure is drawn
at the nearest eta where both the direct simulation and the map are chaotic
(the band between the period-6 and period-5 windows), and the paper's eta is
reported beside it.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

import grazing
from grazing.models import pendulum
from grazing.normalform import find_grazing_point, normal_form_at
from grazing.report import paper
from grazing.report.base import CHAOS_THRESHOLD, DataFile, FigureResult, Image, Say, save_png, signed
from grazing.report.data import write_dataset
from grazing.report.rules import criterion_row

FIGURE_ID = "11"
PAPER_ETA = paper.FIG11_ETA.value
THETA_HAT_DEG = paper.FIG11_THETA_HAT_DEG
DISTANCE_TOL = 0.2
"""Largest total-variation distance between the simulation's and the map's θ_k distributions that agrees."""
TRANSIENT = 2000
SAMPLES = 20000
CANDIDATES = np.linspace(0.44535, 0.44539, 5)
"""Where to look for a chaotic attractor of both the flow and the map (just past grazing)."""


def _run(model, x0, t0, zdm=None, periods=SAMPLES, lyapunov=False):
    return grazing.simulate(
        model, x0, t0=t0, transient=TRANSIENT, periods=periods, zdm=zdm, lyapunov=lyapunov, impacts="none"
    )


def _histogram_distance(a: np.ndarray, b: np.ndarray, bins: int = 60) -> float:
    """Total-variation distance between the two sample distributions (0 = same, 1 = disjoint)."""
    lo, hi = min(a.min(), b.min()), max(a.max(), b.max())
    ha, _ = np.histogram(a, bins=bins, range=(lo, hi))
    hb, _ = np.histogram(b, bins=bins, range=(lo, hi))
    return 0.5 * float(np.abs(ha / ha.sum() - hb / hb.sum()).sum())


def build(out_dir: Path, progress: Say | None = None) -> FigureResult:
    """Compute fig 11, write its PNG into ``out_dir`` and describe it."""
    import matplotlib.pyplot as plt

    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    base = pendulum("B", theta_hat=math.radians(THETA_HAT_DEG))
    point = find_grazing_point(base, "eta", 0.40, 0.47)
    nf = normal_form_at(point, ("eta", "theta_hat"))
    zdm = nf.discontinuity_map()
    eta_g = point.model.params["eta"]
    x0 = np.zeros(2)

    say("fig 11: the paper's eta and the chaotic band just past grazing")
    at_paper = {
        k: _run(base.with_params(eta=PAPER_ETA), x0, 0.0, z, periods=400).period()
        for k, z in (("flow", None), ("map", zdm))
    }
    # the same with α = A/L: the map rebuilt at that α's own grazing orbit
    base_al = base.with_params(alpha=paper.ALPHA_APPARATUS)
    nf_al = normal_form_at(find_grazing_point(base_al, "eta", 0.40, 0.47), ("eta", "theta_hat"))
    at_paper_al = {
        k: _run(base_al.with_params(eta=PAPER_ETA), x0, 0.0, z, periods=400).period()
        for k, z in (("flow", None), ("map", nf_al.discontinuity_map()))
    }
    chosen, flow, mapped = None, None, None
    for eta in CANDIDATES:
        m = base.with_params(eta=float(eta))
        f = _run(m, x0, 0.0)
        g = _run(m, x0, 0.0, zdm)
        if f.period() == 0 and g.period() == 0:
            chosen, flow, mapped = float(eta), f, g
            break
    if chosen is None:  # pragma: no cover - would mean the engine changed
        chosen = float(CANDIDATES[2])
        m = base.with_params(eta=chosen)
        flow, mapped = _run(m, x0, 0.0), _run(m, x0, 0.0, zdm)
    m = base.with_params(eta=chosen)
    lyap_flow = float(np.max(_run(m, x0, 0.0, periods=4000, lyapunov=True).lyapunov))
    lyap_map = float(np.max(_run(m, x0, 0.0, zdm, periods=4000, lyapunov=True).lyapunov))

    say("fig 11: drawing")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8), sharex=True, sharey=True, constrained_layout=True)
    for ax, sol, tag in (
        (axes[0], flow, "(a) direct simulation"),
        (axes[1], mapped, "(b) discontinuity map"),
    ):
        th = np.degrees(sol.samples[:, 0])
        ax.plot(th[:-1], th[1:], ls="none", marker=".", ms=2.0, mew=0, color="k", rasterized=True)
        ax.set_title(f"{tag}: θ̂ = {THETA_HAT_DEG:g}°, case B, η = {chosen:.5f}", loc="left", fontsize=10.5)
        ax.set_xlabel(r"$\theta_k$ (degrees)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel(r"$\theta_{k+1}$ (degrees)")
    name = "fig11_delay.png"
    save_png(fig, out_dir / name)
    plt.close(fig)
    import xarray as xr

    nc = write_dataset(
        out_dir / "fig11_samples.nc",
        xr.Dataset(
            {
                "theta_flow": (
                    "k",
                    flow.samples[:, 0],
                    {"units": "rad", "long_name": "θ_k, direct simulation"},
                ),
                "theta_map": (
                    "k",
                    mapped.samples[:, 0],
                    {"units": "rad", "long_name": "θ_k, discontinuity map"},
                ),
            },
            attrs={"theta_hat_deg": THETA_HAT_DEG, "eta": chosen, "case": "B", "eta_graze": eta_g},
        ),
    )

    dist = _histogram_distance(flow.samples[:, 0], mapped.samples[:, 0])
    both = lyap_flow > CHAOS_THRESHOLD and lyap_map > CHAOS_THRESHOLD
    comparisons = (
        criterion_row(
            FIGURE_ID,
            f"θ̂ = 40°, η = {PAPER_ETA} (the paper's fig 11): the attractor",
            "chaotic, fingered, in the simulation and the map",
            f"period {at_paper['flow']} (simulation), period {at_paper['map']} (map)",
            at_paper["flow"] == 0 and at_paper["map"] == 0,
            kind="paper",
            rule="agree when both the simulation and the map are aperiodic at the paper's η (no period ≤ 50 "
            "in 400 stroboscopic samples after 2000 transient periods)",
            source="§6.1, fig 11",
            paper_text="chaotic in both",
            ours_text=f"period {at_paper['flow']} (simulation), {at_paper['map']} (map)",
            headline=f"Drawn at η = {chosen:.5f}, in our chaotic band: at the paper's η = "
            f"{PAPER_ETA} our attractor is period 5",
            note=(
                f"In our computation η = {PAPER_ETA} is inside the period-5 window, which also contains the "
                f"paper's own period-5 point η = 0.446 (fig 9(b)); the chaotic band just past grazing (η_g = "
                f"{eta_g:.5f}) lies about 4·10⁻⁴ lower. With α = A/L: next row."
            ),
        ),
        criterion_row(
            FIGURE_ID,
            f"θ̂ = 40°, η = {PAPER_ETA}, α = A/L = {paper.ALPHA_APPARATUS:.6f}: the attractor",
            "chaotic, fingered, in the simulation and the map",
            f"period {at_paper_al['flow']} (simulation), period {at_paper_al['map']} (map)",
            at_paper_al["flow"] == 0 and at_paper_al["map"] == 0,
            kind="paper",
            rule="as the row above, with α = A/L (the map built at that α's grazing orbit)",
            source="§6.1, fig 11; §2.1 (A/L)",
            paper_text="chaotic in both",
            ours_text=f"period {at_paper_al['flow']} (simulation), {at_paper_al['map']} (map)",
            headline=f"Fig 11 at the paper's η = {PAPER_ETA} with α = A/L too: period "
            f"{at_paper_al['flow']} (simulation), {at_paper_al['map']} (map), not chaos",
            note=f"The grazing with α = A/L is at η = {nf_al.point.model.params['eta']:.5f}.",
        ),
        criterion_row(
            FIGURE_ID,
            f"θ̂ = 40°, η = {chosen:.5f} (our chaotic band): simulation against map",
            0.0,
            dist,
            both and dist <= DISTANCE_TOL,
            kind="self-check",
            rule=f"agree when both are chaotic (λ₁ > {CHAOS_THRESHOLD:g}) and the total-variation distance "
            f"between their distributions of θ_k is at most {DISTANCE_TOL:g} (0: identical, 1: disjoint)",
            source="§6.1, fig 11",
            paper_text="same attractor (distance 0)",
            ours_text=f"distance {dist:.2f}; λ₁ = {signed(lyap_flow, 3)} (sim.), {signed(lyap_map, 3)} (map)",
            headline="The map's attractor differs from the simulation's",
            note="The fingers (the near-vertical branches at the left) come from the square-root term.",
        ),
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="Figure 11: delay plots of the attractor just past grazing, simulation and map",
        images=(
            Image(
                name,
                f"θ_(k+1) against θ_k on the section τ = 0 (k-th stroboscopic sample), {SAMPLES} samples "
                f"after {TRANSIENT} transient periods from rest, case B, θ̂ = 40°, η = {chosen:.5f}: "
                "(a) the impacting pendulum simulated directly; (b) the map Π of eq. 20: the flow with "
                "the stop ignored and Nordmark's discontinuity map applied once per period at the "
                f"grazing phase, with the coefficients of the grazing orbit at η = {eta_g:.5f}.",
                "Delay plots of the chaotic attractor from simulation and from the discontinuity map",
            ),
        ),
        summary=(
            "The discontinuity map is built from the grazing orbit alone (contact state, grazing "
            "acceleration a = L_f²h, reset direction e = (0, 1 + r)); iterating it with the nonlinear flow "
            "reproduces the attractor of the impacting system."
        ),
        comparisons=comparisons,
        notes=(),
        seconds=time.perf_counter() - start,
        data=(DataFile(nc.name, f"the {SAMPLES} samples θ_k of the simulation and of the map, NetCDF"),),
    )
