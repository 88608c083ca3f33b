"""The experimental side of the paper as figures: fig 4(a, b), fig 2- and fig 3-style panels.

Each function computes what it shows, draws it into the axes (or figure) it is
given, or into a new figure saved as a PNG at ``path``, and returns the
numbers as plain JSON-serialisable data (the paper's values beside ours), for
the report to tabulate.  Figures 2 and 3 are drawn from **synthetic**
recordings simulated from the model (the paper's measurements are not
public); every label says so.

matplotlib is imported only inside the functions; no pyplot state is used.
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from grazing.experiment.damping import (
    DEFAULT_AMPLITUDE,
    DEFAULT_PEAKS,
    FIG4A,
    PAPER_DAMPING,
    PAPER_POINTS,
    beta_for_damping,
    free_decay,
    iso_damping,
    log_decrement,
    paper_protocol_damping,
    paper_relation,
)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

DPI = 150


def _paper_fig3() -> tuple[tuple[float, float], ...]:
    """``(theta_hat_deg, eta)`` of the paper's fig 3 (:data:`grazing.report.paper.FIG3_POINTS`)."""
    from grazing.report.paper import FIG3_POINTS

    return tuple((th, eta) for th, eta, _ in FIG3_POINTS)


def _paper_theta_hats() -> tuple[float, ...]:
    """The stop angles of the paper's figs 2 and 3 (degrees)."""
    from grazing.report.paper import EXPERIMENT

    return tuple(p.theta_hat_deg for p in EXPERIMENT.values())


def _paper_eta_c(theta_hat_deg: float) -> float | None:
    """The grazing frequency the paper observed on the rig at a stop angle (§2.2), if it gives one."""
    from grazing.report.paper import EXPERIMENT

    p = EXPERIMENT.get(f"{theta_hat_deg:g}")
    return p.eta_c.value if p is not None else None


def _new_figure(nrows: int, ncols: int, size: tuple[float, float]) -> tuple[Figure, np.ndarray]:
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    axes = np.atleast_2d(fig.subplots(nrows, ncols, squeeze=False))
    return fig, axes


def _finish(fig: Figure | None, path: str | Path | None, dpi: int) -> str | None:
    if fig is None or path is None:
        return None
    fig.savefig(path, dpi=dpi)
    return str(path)


# ----------------------------------------------------------------------------
# Fig 4(a)


def figure_4a(
    path: str | Path | None = None,
    ax: Axes | None = None,
    *,
    r: float = FIG4A[0],
    beta: float = FIG4A[1],
    amplitude: float = DEFAULT_AMPLITUDE,
    peaks: int = DEFAULT_PEAKS,
    dpi: int = DPI,
) -> dict[str, Any]:
    """Free decay of the impacting pendulum (``alpha = 0``, ``theta_hat = 0``), as fig 4(a).

    Returns
    -------
    dict
        ``r``, ``beta``, ``amplitudes`` (release and peaks), ``log_ratio``
        (mean per peak), ``D_eq6`` (our estimator), ``D_eq1`` (eq. 1 as
        printed), ``D_protocol`` (:func:`paper_protocol_damping`),
        ``D_paper_relation``, ``paper_D`` (0.07), ``image``.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> res = figure_4a(ax=Figure().add_subplot())
    >>> round(res["D_eq6"], 4), round(res["D_protocol"], 3)
    (0.0964, 0.07)
    """
    dec = free_decay(r, beta, amplitude=amplitude, peaks=peaks)
    est = log_decrement(dec.amplitudes)
    est1 = log_decrement(dec.amplitudes, normalisation="eq1")
    proto = paper_protocol_damping(r, beta, amplitude=amplitude, peaks=peaks).damping
    fig = None
    if ax is None:
        fig, axes = _new_figure(1, 1, (6.4, 3.4))
        ax = axes[0, 0]
    end = dec.peak_t[-1] + math.pi
    sel = dec.t <= end
    ax.plot(dec.t[sel], np.degrees(dec.angle[sel]), lw=0.9, color="tab:blue", label="θ (model, free decay)")
    ax.plot(dec.peak_t, -np.degrees(dec.amplitudes), "o", ms=3.5, color="k", label="peaks A_k")
    ax.axhline(0.0, color="tab:red", ls="--", lw=0.8, label="stop θ̂ = 0")
    ax.set_xlabel("ω₀ t")
    ax.set_ylabel("θ (degrees)")
    ax.set_title(
        f"free decay, r = {r:g}, β = {beta:g}: D = {est.damping:.4f} (eq. 6 norm.)", fontsize="medium"
    )
    ax.legend(loc="lower right", fontsize="small")
    return {
        "r": float(r),
        "beta": float(beta),
        "amplitude": float(amplitude),
        "amplitudes": dec.amplitudes.tolist(),
        "log_ratio": est.log_ratio,
        "D_eq6": est.damping,
        "D_eq1": est1.damping,
        "D_protocol": proto,
        "D_paper_relation": paper_relation(r, beta),
        "paper_D": PAPER_DAMPING,
        "image": _finish(fig, path, dpi),
    }


# ----------------------------------------------------------------------------
# Fig 4(b)


def figure_4b(
    path: str | Path | None = None,
    ax: Axes | None = None,
    *,
    damping: float = PAPER_DAMPING,
    num: int = 21,
    dpi: int = DPI,
) -> dict[str, Any]:
    """The equal-damping curve ``D = 0.07`` (fig 4b): the model's, the paper's relation, the paper's points.

    Three curves: the model's (root-finding on the eq.-6-normalised estimator),
    the relation ``D = beta - ln(r) / (4 pi)`` that the paper's points satisfy,
    and our reconstruction of the paper's computation (eq. 1 as printed on the
    model with doubled damping, :func:`paper_protocol_damping`).

    Returns
    -------
    dict
        ``damping``; ``curves``: for ``model``, ``paper``, ``protocol`` the
        lists ``r``, ``beta`` and the ends ``r_min``, ``beta_max``;
        ``points``: for A-D, ``r``, ``beta`` (paper), ``D_model``, ``D_eq1``,
        ``D_paper_relation``, ``D_protocol``, ``beta_model_curve`` (the
        model's ``beta`` at that ``r`` for ``D``, None below its ``r_min``),
        ``beta_protocol_curve``; ``image``.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> res = figure_4b(ax=Figure().add_subplot(), num=3)
    >>> round(res["points"]["B"]["D_model"], 4), round(res["curves"]["protocol"]["beta_max"], 4)
    (0.0905, 0.0673)
    """
    from grazing.experiment.damping import model_damping

    curves = {}
    for rel in ("model", "paper", "protocol"):
        c = iso_damping(damping, num=num, relation=rel)  # type: ignore[arg-type]
        curves[rel] = {"r": c.r.tolist(), "beta": c.beta.tolist(), "r_min": c.r_min, "beta_max": c.beta_max}
    points = {}
    for name, (r, b) in PAPER_POINTS.items():
        row: dict[str, Any] = {"r": r, "beta": b}
        row["D_model"] = model_damping(r, b).damping
        row["D_eq1"] = model_damping(r, b, normalisation="eq1").damping
        row["D_paper_relation"] = paper_relation(r, b)
        row["D_protocol"] = paper_protocol_damping(r, b).damping
        for rel in ("model", "protocol"):
            try:
                row[f"beta_{rel}_curve"] = beta_for_damping(r, damping, relation=rel)  # type: ignore[arg-type]
            except ValueError:
                row[f"beta_{rel}_curve"] = None
        points[name] = row
    fig = None
    if ax is None:
        fig, axes = _new_figure(1, 1, (6.0, 4.2))
        ax = axes[0, 0]
    styles = {
        "model": ("tab:blue", "-", "model, eq. 6 normalisation (this package)"),
        "protocol": ("tab:orange", "--", "eq. 1 as printed, damping doubled (reconstruction)"),
        "paper": ("0.4", ":", "D = β − ln(r)/(4π) (relation of the paper's points)"),
    }
    for rel, (color, ls, label) in styles.items():
        ax.plot(curves[rel]["r"], curves[rel]["beta"], color=color, ls=ls, lw=1.4, label=label)
    for name, row in points.items():
        ax.plot(row["r"], row["beta"], "o", color="k", ms=5)
        ax.annotate(name, (row["r"], row["beta"]), textcoords="offset points", xytext=(5, -11))
    ax.plot([], [], "o", color="k", ms=5, label="paper's points A-D")
    ax.set_xlabel("r")
    ax.set_ylabel("β")
    ax.set_xlim(0.35, 1.02)
    ax.set_ylim(-0.002, 0.08)
    ax.set_title(f"equal damping D = {damping:g}", fontsize="medium")
    ax.legend(loc="upper left", fontsize="small")
    return {"damping": float(damping), "curves": curves, "points": points, "image": _finish(fig, path, dpi)}


# ----------------------------------------------------------------------------
# Fig 2 style: bifurcation diagrams from synthetic recordings


def figure_2_synthetic(
    path: str | Path | None = None,
    fig: Figure | None = None,
    *,
    theta_hats: Sequence[float] | None = None,
    num: int = 25,
    span: tuple[float, float] = (-0.01, 0.04),
    periods: int = 60,
    transient: int = 300,
    sample_rate: float = 1000.0,
    model_num: int = 101,
    workdir: str | Path | None = None,
    workers: int | None = None,
    progress: Callable[[str], None] | None = None,
    dpi: int = DPI,
) -> dict[str, Any]:
    """Fig 2-style diagrams from synthetic recordings, over the model's sweep, one panel per stop angle.

    For each ``theta_hat`` (default: the paper's 10°, 20°, 30°, 40°): the model's primary grazing
    ``eta_g`` is found,
    ``num`` synthetic recordings (case B) are written at ``eta`` from
    ``eta_g + span[0]`` to ``eta_g + span[1]`` (an experimenter's sweep, see
    :func:`~grazing.experiment.synthetic_sweep`), read back and analysed
    (:func:`~grazing.experiment.load_diagram`), and drawn over the model's
    sweep at ``model_num`` values.

    Returns
    -------
    dict
        Per stop angle (key ``"10"``, ...): ``eta_graze`` (model),
        ``paper_eta_c`` (observed on the rig), ``eta``, ``period`` (detected
        on the synthetic recordings), ``noise``, ``model_eta``,
        ``model_period``; and ``image``, ``synthetic: True``.

    Examples
    --------
    >>> res = figure_2_synthetic(theta_hats=[40.0], num=2, span=(-0.015, 0.001), periods=20,
    ...                          transient=100, sample_rate=100.0, model_num=2, workers=1)
    >>> res["40"]["period"], res["40"]["model_period"]
    ([1, 5], [1, 5])
    """
    from grazing.experiment.diagram import load_diagram, model_sweep, plot_diagram
    from grazing.experiment.fit import grazing_eta
    from grazing.experiment.synthetic import synthetic_sweep
    from grazing.models.pendulum import CASES

    say = progress or (lambda _m: None)
    theta_hats = _paper_theta_hats() if theta_hats is None else theta_hats
    n = len(theta_hats)
    own = fig is None
    if own:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(6.4, 2.6 * n), layout="constrained")
    axes = fig.subplots(n, 1, squeeze=False)[:, 0]
    out: dict[str, Any] = {"synthetic": True}
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(workdir) if workdir is not None else Path(tmp)
        for ax, th in zip(axes, theta_hats):
            eg = grazing_eta(th, CASES["B"]["beta"], alpha=CASES["B"]["alpha"])
            centre = eg if eg is not None else 0.45
            etas = np.linspace(centre + span[0], centre + span[1], num)
            folder = base / f"theta{th:g}"
            say(f"synthetic recordings at theta_hat = {th:g} deg ({num} frequencies)")
            synthetic_sweep(folder, th, etas, periods=periods, transient=transient, sample_rate=sample_rate)
            diag = load_diagram(folder)
            model = model_sweep(
                th, np.linspace(etas[0], etas[-1], model_num), periods=periods, workers=workers
            )
            plot_diagram(ax, diag, model, label="synthetic recordings")
            if eg is not None:
                ax.axvline(eg, color="tab:red", lw=0.7, ls="--")
            ax.set_title(
                f"θ̂ = {th:g}°, case B (synthetic recordings, not the paper's data)", fontsize="medium"
            )
            out[f"{th:g}"] = {
                "eta_graze": eg,
                "paper_eta_c": _paper_eta_c(float(th)),
                "eta": diag.eta.tolist(),
                "period": diag.period.tolist(),
                "noise": diag.noise.tolist(),
                "model_eta": model["value"].values.tolist(),
                "model_period": model.period.values.tolist(),
            }
    out["image"] = _finish(fig if own else None, path, dpi)
    return out


# ----------------------------------------------------------------------------
# Fig 3 style: time series and delay embeddings


def figure_3_synthetic(
    path: str | Path | None = None,
    fig: Figure | None = None,
    *,
    cases: Sequence[tuple[float, float]] | None = None,
    periods: int = 40,
    shown: int = 12,
    sample_rate: float = 1000.0,
    seed: int = 0,
    dpi: int = DPI,
) -> dict[str, Any]:
    """Fig 3-style time series and delay embeddings of synthetic recordings, beside the model.

    One row per ``(theta_hat_deg, eta)`` (default: the paper's fig 3 points): the filtered
    synthetic angle against
    time with its stroboscopic samples and the model's noise-free ones (last
    ``shown`` forcing periods), and the delay embedding
    ``(theta(t - T/4), theta(t))`` with the stroboscopic points on it.

    Returns
    -------
    dict
        ``rows``: per case ``theta_hat_deg``, ``eta``, ``forcing_hz``,
        ``period`` (detected on the synthetic recording), ``model_period``
        (of the model's noise-free samples), ``noise``, ``samples`` (the
        last stroboscopic angles, rad); ``image``; ``synthetic: True``.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> res = figure_3_synthetic(fig=Figure(), cases=[(40.0, 0.446)], periods=20, sample_rate=200.0)
    >>> res["rows"][0]["period"], res["rows"][0]["model_period"]
    (5, 5)
    """
    from grazing.core.period import detect_period
    from grazing.experiment.signal import analyze_recording
    from grazing.experiment.synthetic import synthetic_recording

    cases = _paper_fig3() if cases is None else cases
    n = len(cases)
    own = fig is None
    if own:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(9.0, 2.8 * n), layout="constrained")
    axes = fig.subplots(n, 2, squeeze=False, width_ratios=[2.2, 1.0])
    rows = []
    for j, (th, eta) in enumerate(cases):
        rec = synthetic_recording(eta, th, periods=periods, sample_rate=sample_rate, seed=seed + j)
        res = analyze_recording(rec)
        model_samples = np.asarray(rec.metadata["model_samples"])
        mp = detect_period(model_samples, tol=1e-6, max_period=32)
        T = 1.0 / res.forcing_hz
        t0 = rec.time[-1] - shown * T
        sel = res.time >= t0
        ax = axes[j, 0]
        ax.plot(
            res.time[sel],
            np.degrees(res.filtered[sel]),
            lw=0.7,
            color="tab:blue",
            label="synthetic, filtered",
        )
        ok = (res.sample_times >= t0) & np.isfinite(res.samples)
        ax.plot(
            res.sample_times[ok], np.degrees(res.samples[ok]), "o", ms=3.5, color="k", label="once per cycle"
        )
        tm = np.arange(model_samples.size) * T
        om = tm >= t0
        ax.plot(tm[om], np.degrees(model_samples[om]), "x", ms=5, color="tab:red", label="model, noise-free")
        ax.axhline(th, color="tab:red", lw=0.7, ls="--")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("θ (degrees)")
        kind = f"period {res.period}" if res.period else "no period ≤ 32"
        ax.set_title(f"θ̂ = {th:g}°, η = {eta:g}, case B (synthetic recording): {kind}", fontsize="medium")
        if j == 0:
            ax.legend(loc="lower left", fontsize="small", ncol=3)
        ax = axes[j, 1]
        emb = res.embedding()  # row i: (theta(t_i), theta(t_i + T/4))
        tail = emb[int(np.searchsorted(res.time, t0)) :]
        ax.plot(np.degrees(tail[:, 0]), np.degrees(tail[:, 1]), lw=0.5, color="tab:blue")
        ax.plot(np.degrees(res.samples[ok]), np.degrees(res.quarter[ok]), "o", ms=3, color="k")
        ax.set_xlabel("θ(t − T/4) (deg)")
        ax.set_ylabel("θ(t) (deg)")
        rows.append(
            {
                "theta_hat_deg": float(th),
                "eta": float(eta),
                "forcing_hz": res.forcing_hz,
                "period": int(res.period),
                "model_period": int(mp),
                "noise": res.noise,
                "samples": res.samples[np.isfinite(res.samples)][-16:].tolist(),
            }
        )
    return {"rows": rows, "image": _finish(fig if own else None, path, dpi), "synthetic": True}
