"""Synthetic recordings: the model simulated in dimensional time and measured like the rig.

The paper's measured data are not public.  These generators simulate the
model (paper eqs. 4-5), convert its time ``tau = omega t`` to seconds with the
apparatus (``omega = eta omega_0``, ``omega_0 = 2 sqrt(g_e / L)``) and
"measure" the angle like the rig: sampled at 1 kHz, with Gaussian sensor
noise, quantisation (a 12-bit converter over one turn), a slow drift of the
potentiometer's zero, and trigger pulses once per forcing cycle.  Every
recording says ``"synthetic": true`` in its metadata and sidecar; they are
test and demonstration data, never the paper's measurements.  The files carry
grazing's mark (:mod:`grazing.outputs`): a file of the same name that grazing
did not write is never replaced, unless ``overwrite`` is given.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import numpy as np

from grazing.atomic import atomic_path
from grazing.core.options import DEFAULT_TRANSIENT
from grazing.errors import InvalidParameterError
from grazing.experiment.apparatus import PAPER_RIG, Apparatus
from grazing.experiment.recording import Recording, from_arrays
from grazing.outputs import PYTHON_HINT, check_replaceable, marked_json, write_marked_csv

SAMPLE_RATE = 1000.0
"""The rig's sampling rate (Hz)."""

NOISE = 1e-3
"""Standard deviation of the synthetic sensor noise (rad)."""

RECORDED_PERIODS = 100
"""Forcing periods in a synthetic recording (:func:`synthetic_recording`, ``grazing synthesize``)."""

QUANTUM = 2.0 * math.pi / 4096
"""Quantisation step: a 12-bit converter over one turn (rad)."""

DRIFT = 2e-3
"""Drift of the sensor's zero over a whole record (rad)."""


def _hermite(t: np.ndarray, x: np.ndarray, v: np.ndarray, t_out: np.ndarray) -> np.ndarray:
    """Cubic Hermite interpolation of a dense trajectory; impacts (repeated times) split it."""
    i = np.searchsorted(t, t_out, side="right") - 1
    i = np.clip(i, 0, t.size - 2)
    h = t[i + 1] - t[i]
    h = np.where(h > 0, h, 1.0)
    s = np.clip((t_out - t[i]) / h, 0.0, 1.0)
    s2, s3 = s * s, s * s * s
    return (
        (2 * s3 - 3 * s2 + 1) * x[i]
        + (s3 - 2 * s2 + s) * h * v[i]
        + (-2 * s3 + 3 * s2) * x[i + 1]
        + (s3 - s2) * h * v[i + 1]
    )


def _measure(
    angle: np.ndarray, duration: float, t: np.ndarray, noise: float, quantum: float, drift: float, seed: int
) -> np.ndarray:
    """Add sensor noise, a slow drift and quantisation to a true angle."""
    for name, val in (("noise", noise), ("quantum", quantum), ("drift", drift)):
        if not (math.isfinite(val) and val >= 0):
            raise InvalidParameterError(f"{name} must be a non-negative number, got {val!r}")
    rng = np.random.default_rng(seed)
    u = t / max(duration, 1e-300)
    with np.errstate(over="ignore", invalid="ignore"):  # (checked below, in one line)
        y = angle + noise * rng.standard_normal(angle.size) + drift * (0.7 * u + 0.3 * np.sin(math.pi * u))
        if quantum > 0:
            y = np.round(y / quantum) * quantum
    if not np.all(np.isfinite(y)):
        raise InvalidParameterError(
            f"the measured angle overflows with noise {noise:g} rad and drift {drift:g} rad: give a noise "
            "level of the order of the angle's"
        )
    return y


def synthetic_recording(
    eta: float,
    theta_hat_deg: float,
    *,
    case: str | None = "B",
    periods: int = RECORDED_PERIODS,
    transient: int = DEFAULT_TRANSIENT,
    x0: Sequence[float] = (0.0, 0.0),
    sample_rate: float = SAMPLE_RATE,
    noise: float = NOISE,
    quantum: float = QUANTUM,
    drift: float = DRIFT,
    trigger_phase: float = 0.0,
    seed: int = 0,
    apparatus: Apparatus = PAPER_RIG,
    **params: float,
) -> Recording:
    """A synthetic rig recording of the forced pendulum at one forcing frequency.

    The model runs ``transient`` forcing periods from ``x0``, then the
    recording starts (``t = 0`` at forcing phase 0) and lasts ``periods``
    forcing periods.  The trigger marks the sample nearest to each passage of
    the forcing through ``trigger_phase``.

    Parameters
    ----------
    eta, theta_hat_deg
        Frequency ratio and stop angle (degrees).
    case, **params
        Parameter case and overrides (``alpha``, ``beta``, ``r``) as in
        :func:`grazing.models.pendulum`.
    periods, transient
        Forcing periods recorded, and simulated before the recording.
    x0
        State ``(theta, theta')`` where the transient starts.
    sample_rate, noise, quantum, drift
        Sampling (Hz), sensor noise (rad, standard deviation), quantisation
        step (rad; 0 for none), drift of the zero over the record (rad).
    trigger_phase
        Forcing phase (radians) that the trigger marks.
    seed
        Seed of the noise (the recording is reproducible).
    apparatus
        Rig for the dimensional time.

    Returns
    -------
    Recording
        With ``metadata``: ``synthetic``, ``forcing_hz``, ``eta``,
        ``theta_hat_deg``, the parameters, the noise settings, ``x_final``
        (the model's state at the end, at phase 0) and ``model_samples``
        (the model's noise-free angles at the recording's phase-0 times
        ``t = k / forcing_hz``, ``k = 0 ... periods``).

    Examples
    --------
    >>> rec = synthetic_recording(0.446, 40.0, periods=20, sample_rate=200.0)
    >>> rec.metadata["synthetic"], round(rec.metadata["forcing_hz"], 5), rec.trigger_times.size
    (True, 0.45923, 21)
    """
    from grazing.engine.simulate import simulate
    from grazing.models.pendulum import pendulum

    if int(periods) < 1 or int(transient) < 0:
        raise InvalidParameterError(f"need periods >= 1 and transient >= 0, got {periods} and {transient}")
    if not (math.isfinite(sample_rate) and sample_rate > 0):
        raise InvalidParameterError(f"sample rate must be positive, got {sample_rate!r}")
    if not -180.0 < float(theta_hat_deg) < 180.0:
        raise InvalidParameterError(f"theta_hat must be in (-180, 180) degrees, got {theta_hat_deg:g}")
    model = pendulum(case, eta=float(eta), theta_hat=math.radians(theta_hat_deg), **params)
    omega = apparatus.omega(eta)
    forcing_hz = apparatus.forcing_hz(eta)
    duration = periods / forcing_hz
    n = math.floor(duration * sample_rate) + 1
    ppp = 400
    sol = simulate(model, list(x0), transient=transient, periods=periods + 1, trajectory=ppp)
    assert sol.trajectory is not None and sol.trajectory_t is not None
    t = np.arange(n) / sample_rate
    tau0 = 2.0 * math.pi * transient
    true = _hermite(sol.trajectory_t, sol.trajectory[:, 0], sol.trajectory[:, 1], tau0 + omega * t)
    angle = _measure(true, duration, t, noise, quantum, drift, seed)
    T = 1.0 / forcing_hz
    marks = (np.arange(periods + 1) + (trigger_phase / (2 * math.pi)) % 1.0) * T
    trig = np.zeros(n)
    idx = np.round(marks * sample_rate).astype(int)
    trig[idx[idx < n]] = 1.0
    p = dict(model.params)
    meta: dict[str, Any] = {
        "synthetic": True,
        "note": "synthetic recording simulated from the model, not measured data",
        "forcing_hz": forcing_hz,
        "eta": float(eta),
        "theta_hat_deg": float(theta_hat_deg),
        "params": {k: p[k] for k in ("alpha", "beta", "r")},
        "case": case,
        "sample_rate_hz": float(sample_rate),
        "noise_rad": float(noise),
        "quantum_rad": float(quantum),
        "drift_rad": float(drift),
        "trigger_phase": float(trigger_phase),
        "transient_periods": int(transient),
        "seed": int(seed),
        "apparatus": {"L_m": apparatus.length, "g_e": apparatus.g_effective, "A_m": apparatus.amplitude},
        "x_final": [float(v) for v in sol.samples[periods - 1]],
        "model_samples": [float(sol.trajectory[0, 0])] + [float(v) for v in sol.samples[:periods, 0]],
    }
    return from_arrays(
        t, angle, trig, source=f"synthetic eta={eta:g} theta_hat={theta_hat_deg:g}", metadata=meta
    )


def synthetic_free_decay(
    r: float,
    beta: float,
    *,
    amplitude: float = 0.5,
    duration: float = 20.0,
    sample_rate: float = SAMPLE_RATE,
    noise: float = NOISE,
    quantum: float = QUANTUM,
    drift: float = 0.0,
    seed: int = 0,
    apparatus: Apparatus = PAPER_RIG,
) -> Recording:
    """A synthetic recording of the rig's damping test: free decay against the stop at equilibrium.

    Parameters
    ----------
    r
        Restitution, in (0, 1].
    beta
        Linear damping.
    amplitude
        Release angle below the stop, in radians.
    duration
        Length of the record in seconds.
    sample_rate
        Samples per second.
    noise
        Standard deviation of the white measurement noise, in radians.
    quantum
        The quantisation step of the angle (a 12-bit converter over one turn by default), in radians
        (0: none).
    drift
        A slow drift of the angle's zero over the record, in radians.
    seed
        Seed of the noise.
    apparatus
        The rig (converts the model's time to seconds).

    Returns
    -------
    Recording
        The record (no trigger column), marked synthetic in its metadata.

    Examples
    --------
    >>> rec = synthetic_free_decay(0.7148, 0.0426, duration=5.0)
    >>> rec.metadata["synthetic"], rec.trigger_times is None, float(rec.time[-1])
    (True, True, 5.0)
    """
    from grazing.experiment.damping import free_decay

    cycles = duration * apparatus.omega0 / (2.0 * math.pi)
    dec = free_decay(r, beta, amplitude=amplitude, peaks=math.ceil(cycles) + 1)
    n = math.floor(duration * sample_rate) + 1
    t = np.arange(n) / sample_rate
    true = _hermite(dec.t, dec.angle, dec.velocity, apparatus.omega0 * t)
    angle = _measure(true, duration, t, noise, quantum, drift, seed)
    meta = {
        "synthetic": True,
        "note": "synthetic free decay simulated from the model, not measured data",
        "r": float(r),
        "beta": float(beta),
        "amplitude_rad": float(amplitude),
        "theta_hat_deg": 0.0,
        "sample_rate_hz": float(sample_rate),
        "noise_rad": float(noise),
        "quantum_rad": float(quantum),
        "drift_rad": float(drift),
        "seed": int(seed),
    }
    return from_arrays(t, angle, source=f"synthetic free decay r={r:g} beta={beta:g}", metadata=meta)


def write_recording(
    rec: Recording,
    path: str | Path,
    *,
    trigger: bool = True,
    sidecar: bool = True,
    overwrite: bool = False,
    hint: str = PYTHON_HINT,
) -> Path:
    """Write a recording as CSV (``time,angle[,trigger]``) and its metadata as a sidecar JSON.

    Both files carry grazing's mark and are checked first: a file at either
    path that grazing did not write is refused
    (:class:`~grazing.errors.ForeignFileError`) unless ``overwrite``.  Both are
    written through temporaries and renamed together at the end, so a failure
    leaves nothing half-written.

    Parameters
    ----------
    rec
        The recording.
    path
        Where the CSV file goes (the sidecar beside it, ``.json``).
    trigger
        Write the trigger column (from :attr:`Recording.trigger_times`).
    sidecar
        Write the metadata's sidecar.
    overwrite
        Replace files that grazing did not write.
    hint
        How a refusal's message ends.

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from grazing.experiment.recording import load_recording
    >>> rec = synthetic_recording(0.446, 40.0, periods=10, sample_rate=100.0)
    >>> p = write_recording(rec, pathlib.Path(tempfile.mkdtemp()) / "f.csv")
    >>> back = load_recording(p)
    >>> bool(np.allclose(back.angle, rec.angle)), back.metadata["synthetic"]
    (True, True)
    """
    path = Path(path)
    side = path.with_suffix(".json") if sidecar and rec.metadata else None
    for target in (path, side):
        if target is not None:
            check_replaceable(target, overwrite=overwrite, hint=hint)
    cols = [rec.time, rec.angle]
    head = "time,angle"
    if trigger and rec.trigger_times is not None:
        g = np.zeros(rec.time.size)
        g[np.searchsorted(rec.time, rec.trigger_times)] = 1.0
        cols.append(g)
        head += ",trigger"
    row = ",".join(["%.6f", "%.9g", "%d"][: len(cols)])

    def write_csv(fh: Any) -> None:  # the bytes of np.savetxt, 2.4x faster
        fh.write(head + "\n")
        if rec.time.size:
            fh.write("\n".join(map(row.__mod__, zip(*(c.tolist() for c in cols)))) + "\n")

    with ExitStack() as stack:  # (both temporaries written before either is renamed)
        if side is not None:
            tmp_side = stack.enter_context(atomic_path(side))
        tmp = stack.enter_context(atomic_path(path))
        with open(tmp, "w", newline="", encoding="utf-8") as fh:
            write_marked_csv(fh, write_csv)
        if side is not None:
            text = marked_json(rec.metadata)
            with open(tmp_side, "w", newline="", encoding="utf-8") as fh:
                fh.write(text)
    return path


def recording_name(theta_hat_deg: float, eta: float, apparatus: Apparatus = PAPER_RIG) -> str:
    """The file name of a recording of :func:`synthetic_sweep`: ``theta<deg>_<forcing_hz>Hz.csv``.

    >>> recording_name(40.0, 0.446)
    'theta40_0.459234Hz.csv'
    """
    return f"theta{theta_hat_deg:g}_{apparatus.forcing_hz(eta):.6f}Hz.csv"


def synthetic_sweep(
    folder: str | Path,
    theta_hat_deg: float,
    etas: Sequence[float],
    *,
    periods: int = 60,
    transient: int = 300,
    seed: int = 0,
    overwrite: bool = False,
    **kwargs: Any,
) -> list[Path]:
    """Synthetic recordings at several forcing frequencies, as an experimenter sweeps.

    The frequencies are visited in the order given; each recording starts
    from the model's state at the end of the previous one (the rig keeps
    running while the frequency is changed), then runs ``transient`` periods
    before recording.  Files are named ``theta<deg>_<forcing_hz>Hz.csv`` with
    a sidecar JSON each.

    Parameters
    ----------
    folder
        Where to write (created if missing).
    theta_hat_deg, etas
        Stop angle (degrees) and frequency ratios.
    periods, transient, seed
        As in :func:`synthetic_recording` (the seed is varied per file).
    overwrite
        Replace files of the same names that grazing did not write (checked
        for every file before any work; see :func:`write_recording`).
    **kwargs
        Further :func:`synthetic_recording` arguments.

    Returns
    -------
    list of pathlib.Path
        The recordings written (with their sidecars), in the order of ``etas``.

    Examples
    --------
    >>> import tempfile
    >>> paths = synthetic_sweep(tempfile.mkdtemp(), 40.0, [0.44, 0.446], periods=10, sample_rate=100.0)
    >>> [p.name for p in paths]
    ['theta40_0.453056Hz.csv', 'theta40_0.459234Hz.csv']
    """
    out = Path(folder)
    x = tuple(kwargs.pop("x0", (0.0, 0.0)))
    rig = kwargs.get("apparatus", PAPER_RIG)
    targets = [out / recording_name(theta_hat_deg, eta, rig) for eta in etas]
    for target in targets:
        for p in (target, target.with_suffix(".json")):
            check_replaceable(p, overwrite=overwrite)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for j, (eta, target) in enumerate(zip(etas, targets)):
        rec = synthetic_recording(
            float(eta), theta_hat_deg, periods=periods, transient=transient, x0=x, seed=seed + j, **kwargs
        )
        x = tuple(rec.metadata["x_final"])
        paths.append(write_recording(rec, target, overwrite=overwrite))
    return paths
