"""Figure 4 of the paper: free decay (a) and the curve of equal damping in (r, beta) (b).

The estimator, its normalisation (eq. 1 against eq. 6) and the three curves
are explained in ``docs/experiment.md``: the model's own curve (eq. 6
normalisation), the relation ``D = beta - ln(r) / (4 pi)`` that the paper's
points A-D satisfy, and our reconstruction of how the paper computed them
(eq. 1 as printed, applied to the model with twice its damping, the kappa of
the eq. 3 erratum).
"""

from __future__ import annotations

import time
from pathlib import Path

from grazing.experiment.damping import FIG4A, PAPER_DAMPING
from grazing.experiment.figures import figure_4a, figure_4b
from grazing.report.base import Comparison, FigureResult, Image, Progress

FIGURE_ID = "4"


def build(out_dir: Path, progress: Progress | None = None) -> FigureResult:
    """Compute fig 4 (a, b), write the PNGs into ``out_dir`` and describe them."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    say("fig 4: free decay and the equal-damping curves")
    a = figure_4a(out_dir / "fig04a_free_decay.png")
    b = figure_4b(out_dir / "fig04b_iso_damping.png")
    pts = b["points"]
    model_d = ", ".join(f"{k} {v['D_model']:.4f}" for k, v in pts.items())
    proto_d = ", ".join(f"{k} {v['D_protocol']:.4f}" for k, v in pts.items())
    rel_d = ", ".join(f"{k} {v['D_paper_relation']:.4f}" for k, v in pts.items())
    curves = b["curves"]
    rows = (
        Comparison(
            f"fig 4(a): free decay, r = {FIG4A[0]}, β = {FIG4A[1]}",
            f"damping ratio D ≈ {PAPER_DAMPING} (7% of critical)",
            "§3, fig 4(a)",
            f"D = {a['D_eq6']:.4f} (eq. 6 normalisation), {a['D_eq1']:.4f} (eq. 1 as printed), "
            f"{a['D_protocol']:.4f} (eq. 1 with doubled damping, our reconstruction of the paper's)",
            abs(a["D_protocol"] - PAPER_DAMPING) < 2e-3,
            "Eq. 1 as printed gives D = β/2 at r = 1, contradicting eq. 6 (D = β); with the eq. 6 "
            "normalisation this decay has D = 0.09, not 0.07. The paper's number is reproduced by eq. 1 "
            "applied to the model with twice its damping (see docs/experiment.md).",
        ),
        Comparison(
            "fig 4(b): the points A–D lie on the curve D = 0.07",
            "A (0.4707, 0.010), B (0.7675, 0.048), C (0.8778, 0.058), D (1, 0.068) on one curve",
            "§3, fig 4(b) (SPEC erratum: D's β is 0.068, not 0.68)",
            f"the model's D: {model_d}; the relation β − ln(r)/(4π): {rel_d}; the reconstruction: {proto_d}",
            False,
            "Literally, the model does not give one D for A–D (point A lies off the model's D = 0.07 curve, "
            f"which starts at r = {curves['model']['r_min']:.3f} for β = 0); the points satisfy "
            "D = β − ln(r)/(4π) ≈ 0.07, and the reconstruction reproduces them to 0.001.",
        ),
        Comparison(
            "fig 4(b): the ends of the curve",
            "β = 0 ↔ r close to 0.42; r = 1 ↔ β ≈ 0.068",
            "§3",
            f"model: r = {curves['model']['r_min']:.3f} at β = 0, β = {curves['model']['beta_max']:.4f} "
            f"at r = 1; reconstruction: r = {curves['protocol']['r_min']:.3f}, "
            f"β = {curves['protocol']['beta_max']:.4f}",
            None,
            "The reconstruction matches both ends of the paper's curve.",
        ),
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="Figure 4: free decay and the curve of equal damping",
        images=(
            Image(
                "fig04a_free_decay.png",
                f"Free decay (α = 0, stop at θ̂ = 0) for r = {FIG4A[0]}, β = {FIG4A[1]}, released at rest "
                "0.5 rad from the stop; the peaks used by the logarithmic-decrement estimator are marked.",
                "Free decay of the impacting pendulum",
            ),
            Image(
                "fig04b_iso_damping.png",
                f"Curves of equal damping D = {PAPER_DAMPING} in the (r, β) plane: the model's (eq. 6 "
                "normalisation), the relation the paper's points satisfy, and our reconstruction of the "
                "paper's computation, with the paper's points A–D.",
                "Curves of equal damping with the paper's points A-D",
            ),
        ),
        summary=(
            "The logarithmic decrement of eq. 1 measured on simulated free decay (peaks one impact apart, "
            "averaged over 10 peaks), normalised so that eq. 6 holds (D = β at r = 1). "
            "The curve of equal damping is found by root-finding in β for each r."
        ),
        comparisons=rows,
        seconds=time.perf_counter() - start,
    )
