"""``grazing damping``, ``iso-damping``, ``fit``, ``analyze``, ``synthesize``: the experimental side.

:data:`COMMANDS` are added to the ``grazing`` command group.  Like every
``grazing`` command they print a summary, or one JSON object with
``--json``; malformed input gets one line on stderr, a non-zero exit status,
and nothing is written.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import click
import numpy as np

from grazing.cli.common import (
    OVERWRITE_HINT,
    InputError,
    Progress,
    check_folder,
    check_out,
    emit_json,
    json_option,
    overwrite_option,
    write_table,
)
from grazing.cli.limits import (
    check_memory,
    count_text,
    curve_bytes,
    decay_bytes,
    recording_bytes,
    sweep_bytes,
)
from grazing.cli.validate import (
    AMPLITUDE_DEG,
    ANGLE_DEG,
    FINITE,
    NON_NEGATIVE,
    POSITIVE,
    SAMPLE_RATE,
    SEED,
    count,
    path_type,
    refuse_unused,
)
from grazing.core.options import DEFAULT_TRANSIENT, MAX_PERIOD
from grazing.experiment.signal import DEFAULT_CUTOFF_MULTIPLE, DEFAULT_MAX_PERIOD
from grazing.experiment.synthetic import NOISE, RECORDED_PERIODS
from grazing.experiment.synthetic import SAMPLE_RATE as RIG_SAMPLE_RATE
from grazing.models.pendulum import CASES, DEFAULT_CASE, case_values

_RELATIONS = ["model", "paper", "protocol"]
_DEFAULT_AMPLITUDE_DEG = math.degrees(0.5)


def _none_if_nan(v: float) -> float | None:
    return None if not math.isfinite(v) else float(v)


def _save_png(fig: Any, path: Path, overwrite: bool) -> None:
    """Save a figure all at once (never half-written), with grazing's mark."""
    from grazing.outputs import save_png

    save_png(fig, path, dpi=150, overwrite=overwrite, hint=OVERWRITE_HINT)


def _r_beta(case: str, r: float | None, beta: float | None) -> tuple[float, float]:
    vals = case_values(case)
    return (vals["r"] if r is None else r), (vals["beta"] if beta is None else beta)


def _amplitude_rad(amplitude: float) -> float:
    """The release angle in radians (its range is checked by the option's type)."""
    return math.radians(amplitude)


def _check_decay_memory(r: float, beta: float, amplitude_rad: float, peaks: int) -> None:
    """Refuse a free decay (``--peaks``) whose trajectory would not fit in memory."""
    from grazing.experiment import damping as dmp

    n = dmp.decay_peaks(r, beta, amplitude_rad, peaks)
    check_memory(
        decay_bytes(dmp.decay_cycles(n, amplitude_rad)),
        f"a free decay of {count_text(n)} peaks",
        "ask for fewer --peaks",
    )


def _check_peaks(points: Iterable[tuple[float, float]], amplitude_rad: float, peaks: int) -> None:
    """Refuse ``--peaks`` beyond what a free decay at every ``(r, beta)`` of ``points`` has.

    A free decay is followed until its swing falls below
    :data:`~grazing.experiment.damping.MIN_SWING` (``decay_peaks``); asking
    for more peaks than that would silently use fewer.
    """
    from grazing.experiment import damping as dmp

    fewest = min(((dmp.decay_peaks(r, b, amplitude_rad, peaks), r, b) for r, b in points), default=None)
    if fewest is not None and fewest[0] < peaks:
        n, r, b = fewest
        raise InputError(
            f"--peaks {peaks}: the free decay at r = {r:g}, beta = {b:g} falls below "
            f"{dmp.MIN_SWING:g} rad after {n} peaks; ask for at most {n} --peaks"
        )


_case_option = click.option(
    "--case",
    default=DEFAULT_CASE,
    show_default=True,
    metavar="NAME",
    help=f"Paper parameter case for r and beta: {', '.join(CASES)}.",
)
_amplitude_option = click.option(
    "--amplitude",
    type=AMPLITUDE_DEG,
    default=_DEFAULT_AMPLITUDE_DEG,
    show_default="28.65 (0.5 rad)",
    metavar="DEG",
    help="Release angle of the free decay below the stop, degrees.",
)
_peaks_option = click.option(
    "--peaks", type=count(1), default=10, show_default=True, help="Peaks after the release used."
)
_norm_option = click.option(
    "--normalisation",
    type=click.Choice(["eq6", "eq1"]),
    default="eq6",
    show_default=True,
    help="eq6: ln ratio / (2 pi k) so that D = beta at r = 1; eq1: / (4 pi k) as printed.",
)


# ----------------------------------------------------------------------------
# damping


@click.command("damping")
@_case_option
@click.option("--r", "r", type=float, help="Coefficient of restitution in (0, 1].")
@click.option("--beta", type=float, help="Linear damping.")
@_amplitude_option
@_peaks_option
@click.option("--k-hat", "k_hat", type=count(1), multiple=True,
              help="Peak spacing(s) to average over (repeatable; default 1).")  # fmt: skip
@_norm_option
@click.option("--recording", type=path_type(dir_okay=False), metavar="FILE.csv",
              help="Estimate D from a recorded free decay (time,angle) instead of the model.")  # fmt: skip
@click.option("--degrees", is_flag=True, help="The recording's angle is in degrees.")
@json_option
def damping_cmd(
    case: str, r: float | None, beta: float | None, amplitude: float, peaks: int, k_hat: tuple[int, ...],
    normalisation: str, recording: Path | None, degrees: bool, as_json: bool,
) -> None:  # fmt: skip
    """Logarithmic-decrement damping D (paper eq. 1) of the model's free decay, or of a recording."""
    from grazing.experiment import damping as dmp

    model_only = ["case", "r", "beta", "amplitude", "peaks"]
    refuse_unused(model_only, recording is not None, "with --recording (it sets the model's free decay)")
    refuse_unused(["degrees"], recording is None, "without --recording")
    ks = k_hat or (1,)
    if recording is not None:
        from grazing.experiment.recording import load_recording

        rec = load_recording(recording, degrees=degrees)
        res = dmp.recorded_damping(rec, k_hat=ks, normalisation=normalisation)  # type: ignore[arg-type]
        out = {
            "source": str(recording),
            "D": res.estimate.damping,
            "log_ratio": res.estimate.log_ratio,
            "spread": res.estimate.spread,
            "k_hat": list(ks),
            "normalisation": normalisation,
            "amplitudes": res.amplitudes,
            "peak_times": res.peak_t,
            "rest_angle": res.rest_angle,
            "noise": res.noise,
        }
        if as_json:
            emit_json(out)
            return
        click.echo(
            f"{recording}: D = {res.estimate.damping:.5f} ({normalisation} normalisation) from "
            f"{res.amplitudes.size} peaks; ln ratio per peak {res.estimate.log_ratio:.5f}; "
            f"noise {res.noise:.2g} rad"
        )
        return
    rv, bv = _r_beta(case, r, beta)
    amp = _amplitude_rad(amplitude)
    dmp._check_r_beta(rv, bv)
    if max(ks) > peaks:
        raise InputError(f"--k-hat {max(ks)} needs at least as many --peaks (got {peaks})")
    _check_peaks([(rv, bv)], amp, peaks)
    _check_decay_memory(rv, bv, amp, peaks)
    dec = dmp.free_decay(rv, bv, amplitude=amp, peaks=peaks)
    est = dmp.log_decrement(dec.amplitudes, ks, normalisation=normalisation)  # type: ignore[arg-type]
    out = {
        "r": rv,
        "beta": bv,
        "D": est.damping,
        "log_ratio": est.log_ratio,
        "spread": est.spread,
        "k_hat": list(ks),
        "normalisation": normalisation,
        "amplitude_deg": amplitude,
        "amplitudes": dec.amplitudes,
        "D_eq6": dmp.log_decrement(dec.amplitudes, ks).damping,
        "D_eq1": dmp.log_decrement(dec.amplitudes, ks, normalisation="eq1").damping,
        "D_linear": dmp.linear_damping(rv, bv),
        "D_paper_relation": dmp.paper_relation(rv, bv),
        "D_protocol": dmp.paper_protocol_damping(rv, bv, amplitude=amp, peaks=peaks, k_hat=ks).damping,
    }
    if as_json:
        emit_json(out)
        return
    click.echo(f"free decay r = {rv:g}, beta = {bv:g}, released {amplitude:.4g} deg below the stop at 0")
    click.echo(f"  D = {est.damping:.5f} ({normalisation}), ln(A_k/A_k+1) per impact = {est.log_ratio:.5f}")
    click.echo(
        f"  eq. 1 as printed: {out['D_eq1']:.5f}; small-amplitude formula: {out['D_linear']:.5f}; "
        f"paper's relation beta - ln(r)/(4 pi): {out['D_paper_relation']:.5f}"
    )


# ----------------------------------------------------------------------------
# iso-damping


def _write_curve_csv(r: np.ndarray, beta: np.ndarray, fh: Any) -> None:
    fh.write("r,beta\n")
    np.savetxt(fh, np.column_stack([r, beta]), delimiter=",", fmt="%.12g")


@click.command("iso-damping")
@click.option("--damping", "damping", type=float, default=0.07, show_default=True, metavar="D",
              help="Target damping D.")  # fmt: skip
@click.option("--num", type=count(2), default=21, show_default=True, help="Points on the curve.")
@click.option("--relation", type=click.Choice(_RELATIONS), default="model", show_default=True,
              help="model: root-finding on the model (eq. 6 normalisation); paper: D = beta - ln(r)/(4 pi); "
                   "protocol: eq. 1 on the model with doubled damping.")  # fmt: skip
@_amplitude_option
@_peaks_option
@_norm_option
@click.option("--out", type=path_type(dir_okay=False), metavar="FILE.csv",
              help="Write the curve (r,beta) to a CSV file.")  # fmt: skip
@overwrite_option
@json_option
def iso_damping_cmd(
    damping: float, num: int, relation: str, amplitude: float, peaks: int, normalisation: str,
    out: Path | None, overwrite: bool, as_json: bool,
) -> None:  # fmt: skip
    """The curve of (r, beta) along which the measured damping is D (fig 4b)."""
    from grazing.experiment import damping as dmp

    refuse_unused(["normalisation"], relation != "model", f"with --relation {relation}")
    amp = _amplitude_rad(amplitude)
    check_out(out, ".csv", overwrite=overwrite)
    check_memory(curve_bytes(num), f"a curve of {count_text(num)} points", "ask for fewer --num")
    for pr, pb in dmp.PAPER_POINTS.values():
        _check_decay_memory(pr, pb, amp, peaks)
    _check_peaks(dmp.PAPER_POINTS.values(), amp, peaks)
    protocol: dict[str, Any] = {}
    if relation == "model":
        protocol = {"amplitude": amp, "peaks": peaks, "normalisation": normalisation}
    elif relation == "protocol":
        protocol = {"amplitude": amp, "peaks": peaks}
    curve = dmp.iso_damping(damping, num=num, relation=relation, **protocol)  # type: ignore[arg-type]
    if protocol:  # every point of the curve measured with --peaks peaks
        _check_peaks(zip(curve.r, curve.beta), amp, peaks)
    points = {}
    for name, (pr, pb) in dmp.PAPER_POINTS.items():
        points[name] = {
            "r": pr,
            "beta": pb,
            "D_model": dmp.model_damping(pr, pb, amplitude=amp, peaks=peaks).damping,
            "D_paper_relation": dmp.paper_relation(pr, pb),
            "D_protocol": dmp.paper_protocol_damping(pr, pb, amplitude=amp, peaks=peaks).damping,
        }
    if out is not None:
        write_table(out, lambda fh: _write_curve_csv(curve.r, curve.beta, fh), overwrite)
    res = {
        "damping": curve.damping,
        "relation": relation,
        "r": curve.r,
        "beta": curve.beta,
        "r_min": curve.r_min,
        "beta_max": curve.beta_max,
        "paper_points": points,
        "out": str(out) if out else None,
    }
    if as_json:
        emit_json(res)
        return
    click.echo(
        f"D = {curve.damping:g} ({relation}): from r = {curve.r_min:.4f} at beta = 0 "
        f"to beta = {curve.beta_max:.4f} at r = 1"
    )
    for rv, bv in zip(curve.r, curve.beta):
        click.echo(f"  r = {rv:.4f}   beta = {bv:.5f}")
    for name, p in points.items():
        click.echo(
            f"  paper's {name} (r = {p['r']:g}, beta = {p['beta']:g}): model D = {p['D_model']:.4f}, "
            f"beta - ln(r)/(4 pi) = {p['D_paper_relation']:.4f}"
        )
    if out is not None:
        click.echo(f"curve written to {out}")


# ----------------------------------------------------------------------------
# fit


@click.command("fit")
@click.option("--theta-hat", "theta_hat", type=ANGLE_DEG, default=40.0, show_default=True, metavar="DEG",
              help="Stop angle of the observed grazing, degrees.")  # fmt: skip
@click.option("--eta-graze", "eta_graze", type=POSITIVE, default=0.445, show_default=True, metavar="E",
              help="Observed eta of the primary grazing.")  # fmt: skip
@click.option("--damping", "damping", type=float, default=0.07, show_default=True, metavar="D",
              help="Measured damping D.")  # fmt: skip
@click.option("--alpha", type=POSITIVE, default=CASES["B"]["alpha"], show_default=True, help="Forcing A/L.")
@click.option("--relation", type=click.Choice(_RELATIONS), default="model", show_default=True,
              help="Which equal-damping curve (see iso-damping).")  # fmt: skip
@json_option
def fit_cmd(
    theta_hat: float, eta_graze: float, damping: float, alpha: float, relation: str, as_json: bool
) -> None:
    """Fit beta and r: the point of the equal-damping curve whose primary grazing is at the observed eta."""
    from grazing.experiment.fit import fit_parameters

    fit = fit_parameters(theta_hat, eta_graze, damping, alpha=alpha, relation=relation)  # type: ignore[arg-type]
    res = {
        "beta": fit.beta,
        "r": fit.r,
        "eta_graze": fit.eta_graze,
        "theta_hat_deg": fit.theta_hat_deg,
        "damping": fit.damping,
        "alpha": fit.alpha,
        "relation": fit.relation,
        "beta_max": fit.beta_max,
        "r_min": _none_if_nan(fit.r_min),
        "evaluations": fit.evaluations,
    }
    if as_json:
        emit_json(res)
        return
    click.echo(
        f"beta = {fit.beta:.5f}, r = {fit.r:.4f}  (primary grazing at theta-hat = {theta_hat:g} deg "
        f"at eta = {fit.eta_graze:.6f}; D = {damping:g}, {relation} curve; "
        f"{fit.evaluations} grazing computations)"
    )


# ----------------------------------------------------------------------------
# analyze


def _analysis_json(a: Any, rec: Any) -> dict[str, Any]:
    ok = np.isfinite(a.samples)
    return {
        "file": a.source,
        "forcing_hz": a.forcing_hz,
        "eta": a.eta,
        "period": a.period,
        "samples": [float(v) if math.isfinite(v) else None for v in a.samples],
        "quarter": [float(v) if math.isfinite(v) else None for v in a.quarter],
        "sample_times": a.sample_times,
        "n_samples": int(ok.sum()),
        "noise": a.noise,
        "sample_noise": a.sample_noise,
        "cutoff_hz": a.cutoff_hz,
        "phase": a.phase,
        "from_trigger": a.from_trigger,
        "sample_rate_hz": rec.sample_rate,
        "duration_s": rec.duration,
        "resampled": a.resampled,
        "gaps": [list(g) for g in a.gaps],
        "synthetic": bool(rec.metadata.get("synthetic", False)),
    }


def _plot_recording(a: Any, path: Path, overwrite: bool) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 3.2), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2, width_ratios=[2.2, 1.0])
    T = 1.0 / a.forcing_hz
    t0 = max(a.time[0], a.time[-1] - 12 * T)
    sel = a.time >= t0
    ax1.plot(a.time[sel], np.degrees(a.filtered[sel]), lw=0.7)
    ok = (a.sample_times >= t0) & np.isfinite(a.samples)
    ax1.plot(a.sample_times[ok], np.degrees(a.samples[ok]), "o", ms=3, color="k")
    ax1.set_xlabel("t (s)")
    ax1.set_ylabel("θ (degrees)")
    kind = f"period {a.period}" if a.period else "no period ≤ 32"
    ax1.set_title(f"{a.source}: η = {a.eta:.4f}, {kind}", fontsize="medium")
    emb = a.embedding()[int(np.searchsorted(a.time, t0)) :]
    ax2.plot(np.degrees(emb[:, 0]), np.degrees(emb[:, 1]), lw=0.5)
    ax2.set_xlabel("θ(t − T/4) (deg)")
    ax2.set_ylabel("θ(t) (deg)")
    _save_png(fig, path, overwrite)


@click.command("analyze")
@click.argument("path", type=path_type(), metavar="FILE.csv|DIR")
@click.option("--forcing-hz", "forcing_hz", type=POSITIVE, metavar="F",
              help="Forcing frequency, Hz (needed without a trigger column; t = 0 is phase 0).")  # fmt: skip
@click.option("--phase", type=FINITE, default=0.0, show_default=True, metavar="PHI",
              help="Sampling phase in radians after the reference (trigger or t = 0).")  # fmt: skip
@click.option("--degrees", is_flag=True, help="The angle column is in degrees.")
@click.option("--cutoff-hz", type=POSITIVE,
              help="Low-pass cutoff in Hz (default: a multiple of the forcing).")  # fmt: skip
@click.option("--cutoff-multiple", type=POSITIVE, default=DEFAULT_CUTOFF_MULTIPLE, show_default=True,
              help="Default cutoff in multiples of the forcing frequency.")  # fmt: skip
@click.option("--max-period", type=click.IntRange(min=1, max=MAX_PERIOD), default=DEFAULT_MAX_PERIOD,
              show_default=True,
              help="Largest period tested.")  # fmt: skip
@click.option("--noise", type=POSITIVE, help="Noise level of the angle in rad (default: estimated).")
@click.option("--theta-hat", "theta_hat", type=ANGLE_DEG, metavar="DEG",
              help="Stop angle for a folder (default: from the sidecar JSON files).")  # fmt: skip
@click.option("--with-model", is_flag=True, help="For a folder: also sweep the model (case, same theta-hat).")
@_case_option
@click.option("--model-points", type=count(2), default=101, show_default=True,
              help="Model sweep points (with --with-model).")  # fmt: skip
@click.option("--plot", type=path_type(dir_okay=False), metavar="FILE.png",
              help="Draw the time series and embedding (file) or the diagram (folder).")  # fmt: skip
@overwrite_option
@json_option
def analyze_cmd(
    path: Path, forcing_hz: float | None, phase: float, degrees: bool, cutoff_hz: float | None,
    cutoff_multiple: float, max_period: int, noise: float | None, theta_hat: float | None, with_model: bool,
    case: str, model_points: int, plot: Path | None, overwrite: bool, as_json: bool,
) -> None:  # fmt: skip
    """Analyse a recording (period, stroboscopic samples, noise) or a folder of them (fig 2-style diagram)."""
    from grazing.experiment.recording import load_recording
    from grazing.experiment.signal import analyze_recording

    check_out(plot, ".png", "--plot", overwrite)
    case_values(case)
    refuse_unused(["case", "model_points"], not with_model, "without --with-model")
    refuse_unused(["cutoff_multiple"], cutoff_hz is not None, "with --cutoff-hz")
    if path.is_dir():
        for name, val in (("--forcing-hz", forcing_hz), ("--cutoff-hz", cutoff_hz), ("--noise", noise)):
            if val is not None:
                raise InputError(f"{name} applies to a single recording, not to a folder")
        if with_model:
            check_memory(
                sweep_bytes(model_points, 60, 2, streamed=False, as_json=as_json, chunk_points=50, workers=1),
                f"a model sweep of {count_text(model_points)} points",
                "ask for fewer --model-points",
            )
        _analyze_folder(path, phase, degrees, cutoff_multiple, max_period, theta_hat, with_model, case,
                        model_points, plot, overwrite, as_json)  # fmt: skip
        return
    if with_model:
        raise InputError("--with-model applies to a folder of recordings")
    refuse_unused(["theta_hat"], True, "for a single recording (it is the stop angle of a folder's diagram)")
    rec = load_recording(path, degrees=degrees)
    a = analyze_recording(
        rec, forcing_hz, phase=phase, cutoff_hz=cutoff_hz, cutoff_multiple=cutoff_multiple,
        max_period=max_period, noise=noise,
    )  # fmt: skip
    if plot is not None:
        _plot_recording(a, plot, overwrite)
    res = _analysis_json(a, rec)
    res["plot"] = str(plot) if plot else None
    if as_json:
        emit_json(res)
        return
    kind = f"period {a.period}" if a.period else f"no period <= {max_period} at this noise level"
    src = "trigger" if a.from_trigger else "--forcing-hz"
    click.echo(
        f"{path}: {kind}; forcing {a.forcing_hz:.6g} Hz ({src}), eta = {a.eta:.5f}; "
        f"{res['n_samples']} samples; noise {a.noise:.2g} rad"
    )
    if rec.metadata.get("synthetic"):
        click.echo("  (synthetic recording)")
    if a.resampled:
        click.echo("  non-uniform sampling: resampled on a uniform grid")
    for g0, g1 in a.gaps:
        click.echo(f"  gap in the angle from {g0:.6g} s to {g1:.6g} s (samples there left out)")
    last = [f"{math.degrees(v):.3f}" for v in a.samples[np.isfinite(a.samples)][-max(a.period, 8) :]]
    click.echo(f"  last samples (deg): {' '.join(last)}")
    if plot is not None:
        click.echo(f"plot written to {plot}")


def _analyze_folder(
    path: Path, phase: float, degrees: bool, cutoff_multiple: float, max_period: int, theta_hat: float | None,
    with_model: bool, case: str, model_points: int, plot: Path | None, overwrite: bool, as_json: bool,
) -> None:  # fmt: skip
    from grazing.experiment.diagram import load_diagram, model_sweep, plot_diagram

    bar = Progress("analysing", enabled=not as_json)
    try:
        diag = load_diagram(
            path, theta_hat_deg=theta_hat, degrees=degrees, phase=phase, cutoff_multiple=cutoff_multiple,
            max_period=max_period, progress=bar,
        )  # fmt: skip
    finally:
        bar.close()
    model = None
    if with_model:
        if diag.theta_hat_deg is None:
            raise InputError(
                "--with-model needs the stop angle: give --theta-hat or theta_hat_deg in sidecars"
            )
        etas = np.linspace(diag.eta.min(), diag.eta.max(), model_points)
        bar = Progress("model sweep", enabled=not as_json)
        try:
            model = model_sweep(diag.theta_hat_deg, etas, case=case, progress=bar)
        finally:
            bar.close()
    if plot is not None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(7.0, 4.0), layout="constrained")
        label = "synthetic recordings" if diag.synthetic else "recordings"
        plot_diagram(fig.add_subplot(), diag, model, label=label)
        _save_png(fig, plot, overwrite)
    res: dict[str, Any] = {
        "folder": str(path),
        "theta_hat_deg": diag.theta_hat_deg,
        "files": list(diag.files),
        "synthetic": diag.synthetic,
        "forcing_hz": diag.forcing_hz,
        "eta": diag.eta,
        "period": diag.period,
        "noise": diag.noise,
        "samples": [s.tolist() for s in diag.samples()],
        "model": None,
        "plot": str(plot) if plot else None,
    }
    if model is not None:
        res["model"] = {
            "case": case,
            "eta": model["value"].values,
            "period": model.period.values,
            "samples": [[_none_if_nan(v) for v in row] for row in model.samples.values[..., 0]],
        }
    if as_json:
        emit_json(res)
        return
    th = f"{diag.theta_hat_deg:g} deg" if diag.theta_hat_deg is not None else "unknown"
    click.echo(f"{path}: {len(diag.files)} recordings, theta-hat {th}")
    for f, e, p in zip(diag.files, diag.eta, diag.period):
        click.echo(f"  eta = {e:.5f}  {'period ' + str(p) if p else 'no period'}   {f}")
    if plot is not None:
        click.echo(f"diagram written to {plot}")


# ----------------------------------------------------------------------------
# synthesize


@click.command("synthesize")
@click.option("--eta", "etas", type=POSITIVE, multiple=True, required=True,
              help="Frequency ratio (repeat for a sweep into a folder).")  # fmt: skip
@click.option("--theta-hat", "theta_hat", type=ANGLE_DEG, default=40.0, show_default=True, metavar="DEG",
              help="Stop angle, degrees.")  # fmt: skip
@_case_option
@click.option("--periods", type=count(8), default=RECORDED_PERIODS, show_default=True,
              help="Forcing periods recorded.")  # fmt: skip
@click.option("--transient", type=count(0), default=DEFAULT_TRANSIENT, show_default=True,
              help="Forcing periods simulated before recording.")  # fmt: skip
@click.option("--sample-rate", type=SAMPLE_RATE, default=RIG_SAMPLE_RATE, show_default=True,
              help="Samples per second, at most 1e6 (times are written to the microsecond).")  # fmt: skip
@click.option("--noise", type=NON_NEGATIVE, default=NOISE, show_default=True, help="Sensor noise, rad.")
@click.option("--seed", type=SEED, default=0, show_default=True, help="Seed of the noise (>= 0).")
@click.option("--out", type=path_type(), required=True, metavar="FILE.csv|DIR",
              help="A .csv file (one --eta; with a sidecar .json) or a folder (several; an existing folder, "
              "or a new one named without a suffix).")  # fmt: skip
@overwrite_option
@json_option
def synthesize_cmd(
    etas: tuple[float, ...], theta_hat: float, case: str, periods: int, transient: int, sample_rate: float,
    noise: float, seed: int, out: Path, overwrite: bool, as_json: bool,
) -> None:  # fmt: skip
    """Write SYNTHETIC rig-like recordings simulated from the model (1 kHz, noise, drift, trigger)."""
    from grazing.experiment.apparatus import PAPER_RIG
    from grazing.experiment.recording import MIN_SAMPLES
    from grazing.experiment.synthetic import recording_name, synthetic_recording, write_recording
    from grazing.outputs import check_replaceable

    case_values(case)
    one_file = out.suffix.lower() == ".csv"
    if one_file and len(etas) != 1:
        raise InputError("several --eta values need a folder as --out, not a .csv file")
    if not one_file and out.exists() and not out.is_dir():
        raise InputError(f"--out {str(out)!r} exists and is not a folder")
    if not one_file and not out.is_dir() and out.suffix:
        raise InputError(
            f"--out {str(out)!r} is neither a .csv file nor a folder: name a .csv file (one --eta), "
            "or a folder (a new one without a suffix)"
        )
    check_folder(out)
    csvs = [out] if one_file else [out / recording_name(theta_hat, e) for e in etas]
    for target in (p for c in csvs for p in (c, c.with_suffix(".json"))):
        check_replaceable(target, overwrite=overwrite, hint=OVERWRITE_HINT)
    samples = {e: periods / PAPER_RIG.forcing_hz(e) * sample_rate for e in etas}
    fewest = min(samples, key=samples.__getitem__)
    if samples[fewest] < MIN_SAMPLES:
        raise InputError(
            f"a recording at --eta {fewest:g} would have {samples[fewest]:.3g} samples, fewer than "
            f"{MIN_SAMPLES}: raise --sample-rate or --periods"
        )
    check_memory(
        recording_bytes(max(samples.values()), periods),
        f"a recording of {count_text(max(samples.values()))} samples",
        "lower --sample-rate or --periods (each recording is written on its own: several --eta values "
        "into a folder need no more)",
    )
    kw = {"case": case, "sample_rate": sample_rate, "noise": noise}
    if one_file:
        rec = synthetic_recording(etas[0], theta_hat, periods=periods, transient=transient, seed=seed, **kw)
        paths = [write_recording(rec, out, overwrite=overwrite, hint=OVERWRITE_HINT)]
    else:
        kw.update(periods=periods, transient=transient, seed=seed)
        paths = _synthesize_folder(out, theta_hat, etas, **kw)
    if as_json:
        emit_json({"files": [str(p) for p in paths], "synthetic": True})
        return
    for p in paths:
        click.echo(f"wrote {p} (synthetic)")


def _synthesize_folder(out: Path, theta_hat: float, etas: tuple[float, ...], **kwargs: Any) -> list[Path]:
    """Synthetic recordings into the folder ``out``, all or nothing.

    They are written into a hidden folder beside ``out``, then moved into
    ``out`` (or the hidden folder renamed to ``out`` if it did not exist), so a
    failure part-way leaves nothing behind.  The files they replace in ``out``
    were checked before (grazing's, or ``--overwrite``); a symbolic link there
    is followed.  The hidden folder is named with the process's PID: one left
    by a process killed outright (SIGKILL) is removed by the next run.
    """
    import shutil
    import tempfile

    from grazing.atomic import remove_dead_folders, rename_noreplace, resolved, write_bytes_atomic
    from grazing.errors import WriteError
    from grazing.experiment.synthetic import synthetic_sweep

    parent = out.parent if str(out.parent) else Path(".")
    prefix = f".{out.name}.partial-"
    remove_dead_folders(
        parent, prefix, lambda f: all(p.is_file() and not p.is_symlink() for p in f.iterdir())
    )
    tmp = Path(tempfile.mkdtemp(dir=parent, prefix=f"{prefix}{os.getpid()}-"))
    try:
        written = synthetic_sweep(tmp, theta_hat, etas, **kwargs)
        if out.is_dir():
            for f in sorted(tmp.iterdir()):
                dest = resolved(out / f.name)
                try:
                    os.replace(f, dest)
                except OSError:  # (a link to another file system)
                    write_bytes_atomic(dest, f.read_bytes())
            shutil.rmtree(tmp)
        else:
            mask = os.umask(0)
            os.umask(mask)
            os.chmod(tmp, 0o777 & ~mask)
            rename_noreplace(tmp, out)
    except BaseException as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        if isinstance(exc, WriteError):  # (named by the hidden folder's path, which is gone)
            raise WriteError(
                f"cannot write the recordings into {out}: {exc.strerror}; nothing was written"
            ) from None
        raise
    return [out / p.name for p in written]


COMMANDS = (damping_cmd, iso_damping_cmd, fit_cmd, analyze_cmd, synthesize_cmd)
