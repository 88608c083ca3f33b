"""Signal processing for recorded angles: filtering, noise, stroboscopic samples, embedding, period.

The rig's pipeline (paper section 2.2): the potentiometer's angle is low-pass
filtered (Butterworth), sampled once per forcing cycle at a fixed phase (the
Poincaré section of the bifurcation diagrams, fig 2), and shown in delay
coordinates with a delay of a quarter forcing cycle (fig 3 b, d).

Period detection on noisy samples: the samples of a period-p orbit form p
tight clusters, so ``s[i + p] - s[i]`` is pure noise for every ``i``.  A period
``p`` fits when those differences (after removing their median, which takes
out a slow drift) stay within a few times the noise level expected for them;
the smallest fitting ``p <= max_period`` is the period, 0 when none fits
(chaos, also banded chaos whose bands are wider than the noise).  The noise
level comes from the raw signal (:func:`estimate_noise`) and the filter's
noise gain (:func:`noise_gain`), so it is estimated, not assumed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from grazing.core.options import MAX_PERIOD_NOISY
from grazing.errors import InvalidParameterError

if TYPE_CHECKING:  # pragma: no cover
    from grazing.experiment.apparatus import Apparatus
    from grazing.experiment.recording import Recording

DEFAULT_CUTOFF_MULTIPLE = 20.0
"""Default low-pass cutoff, in multiples of the forcing frequency."""

FILTER_ORDER = 4
"""Order of the Butterworth filter (applied forwards and backwards: zero phase)."""

DEFAULT_MAX_PERIOD = MAX_PERIOD_NOISY
"""Largest period tested on recorded samples (:data:`grazing.core.options.MAX_PERIOD_NOISY`)."""

SAMPLE_NOISE_FLOOR = 1e-5
"""Smallest noise level assumed on a stroboscopic sample, relative to the signal's range."""

PERIOD_FACTOR = 4.0
"""A period fits when the 95th percentile of the centred differences is within this
many noise levels (Gaussian noise gives 1.96; the margin absorbs errors in the
noise estimate)."""


def _check_cutoff(fs: float, cutoff_hz: float) -> None:
    if not (math.isfinite(cutoff_hz) and cutoff_hz > 0):
        raise InvalidParameterError(f"the cutoff frequency must be positive, got {cutoff_hz:g} Hz")
    if cutoff_hz >= 0.5 * fs:
        raise InvalidParameterError(
            f"the cutoff {cutoff_hz:g} Hz must be below the Nyquist frequency {0.5 * fs:g} Hz"
        )


@lru_cache(maxsize=32)
def _sos(order: int, wn: float) -> np.ndarray:
    from scipy.signal import butter

    return butter(order, wn, btype="low", output="sos")


def lowpass(x: np.ndarray, fs: float, cutoff_hz: float, *, order: int = FILTER_ORDER) -> np.ndarray:
    """Zero-phase Butterworth low-pass filter (``scipy.signal.sosfiltfilt``).

    Parameters
    ----------
    x
        Uniformly sampled signal (no NaN; bridge gaps first).
    fs
        Sampling rate in Hz.
    cutoff_hz
        Cutoff frequency in Hz (below ``fs / 2``).
    order
        Filter order (the forward-backward pass doubles it).

    Returns
    -------
    numpy.ndarray
        The filtered signal (same length).

    Examples
    --------
    >>> t = np.arange(0, 10, 1e-3)
    >>> y = lowpass(np.sin(2 * np.pi * t) + np.sin(2 * np.pi * 100 * t), 1000.0, 10.0)
    >>> bool(np.max(np.abs(y - np.sin(2 * np.pi * t))[1000:-1000]) < 1e-3)
    True
    """
    from scipy.signal import sosfiltfilt

    _check_cutoff(fs, cutoff_hz)
    x = np.asarray(x, dtype=float)
    sos = _sos(int(order), float(cutoff_hz) / (0.5 * fs))
    padlen = min(x.size - 1, 3 * (2 * len(sos) + 1) * 10)
    try:
        return sosfiltfilt(sos, x, padlen=padlen)
    except np.linalg.LinAlgError:  # (a cutoff so far below the sampling rate that the filter is singular)
        raise InvalidParameterError(
            f"the cutoff {cutoff_hz:g} Hz is too low for a filter at {fs:g} samples per second"
        ) from None


@lru_cache(maxsize=32)
def noise_gain(fs: float, cutoff_hz: float, order: int = FILTER_ORDER) -> float:
    """Standard deviation of white unit noise after :func:`lowpass` (from its impulse response).

    Examples
    --------
    >>> round(noise_gain(1000.0, 10.0), 3)
    0.134
    """
    n = int(max(64, 40 * fs / cutoff_hz))
    imp = np.zeros(2 * n + 1)
    imp[n] = 1.0
    h = lowpass(imp, fs, cutoff_hz, order=order)
    return float(math.sqrt(np.sum(h * h)))


def estimate_noise(x: np.ndarray, fs: float) -> float:
    """Robust standard deviation of the white measurement noise in a uniformly sampled signal.

    The signal minus its low-pass copy (cutoff ``fs / 10``) holds nearly only
    noise (and the short transients of impacts, which the median absolute
    deviation ignores); its spread is scaled by the share of white noise that
    such a residual keeps.

    Parameters
    ----------
    x
        The signal, uniformly sampled (no NaN).
    fs
        Sampling rate in Hz.

    Returns
    -------
    float
        The noise's standard deviation, in the signal's units.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(0, 20, 1e-3)
    >>> x = 0.5 * np.sin(2 * np.pi * 0.5 * t) + 0.002 * rng.standard_normal(t.size)
    >>> round(estimate_noise(x, 1000.0) / 0.002, 1)
    1.0
    """
    x = np.asarray(x, dtype=float)
    fc = fs / 10.0
    resid = x - lowpass(x, fs, fc)
    mad = float(np.median(np.abs(resid - np.median(resid))))
    keep = _residual_gain(float(fs), fc)
    return 1.4826 * mad / keep


@lru_cache(maxsize=32)
def _residual_gain(fs: float, fc: float) -> float:
    n = int(max(64, 40 * fs / fc))
    imp = np.zeros(2 * n + 1)
    imp[n] = 1.0
    r = imp - lowpass(imp, fs, fc)
    return float(math.sqrt(np.sum(r * r)))


def stroboscopic(time: np.ndarray, x: np.ndarray, sample_times: np.ndarray) -> np.ndarray:
    """The signal at the given times, by linear interpolation (times outside the record are dropped).

    Parameters
    ----------
    time
        Sample times of the signal, increasing.
    x
        The signal.
    sample_times
        The times wanted (the forcing's reference times plus the phase).

    Returns
    -------
    numpy.ndarray
        The signal at the sample times inside the record.

    Examples
    --------
    >>> stroboscopic(np.array([0.0, 1.0, 2.0]), np.array([0.0, 2.0, 4.0]), np.array([0.5, 1.5, 3.0]))
    array([1., 3.])
    """
    ts = np.asarray(sample_times, dtype=float)
    ts = ts[(ts >= time[0]) & (ts <= time[-1])]
    return np.interp(ts, time, x)


def delay_embedding(x: np.ndarray, lag: int, dim: int = 2) -> np.ndarray:
    """Takens delay vectors ``(x[i], x[i + lag], ..., x[i + (dim - 1) lag])`` of a uniform signal.

    With ``lag`` a quarter forcing period in samples, columns 0 and 1 are the
    paper's fig 3(b, d) coordinates ``theta(t - T/4)`` and ``theta(t)``.

    Parameters
    ----------
    x
        The signal, uniformly sampled.
    lag
        The delay, in samples.
    dim
        The embedding dimension.

    Returns
    -------
    numpy.ndarray
        One delay vector per row, ``len(x) - (dim - 1) lag`` rows.

    Examples
    --------
    >>> delay_embedding(np.arange(6.0), 2).tolist()
    [[0.0, 2.0], [1.0, 3.0], [2.0, 4.0], [3.0, 5.0]]
    """
    x = np.asarray(x, dtype=float)
    lag, dim = int(lag), int(dim)
    if lag < 1 or dim < 2:
        raise InvalidParameterError(f"need lag >= 1 and dim >= 2, got lag={lag}, dim={dim}")
    n = x.size - (dim - 1) * lag
    if n < 1:
        raise InvalidParameterError("the signal is shorter than the embedding window")
    return np.column_stack([x[j * lag : j * lag + n] for j in range(dim)])


@dataclass(frozen=True)
class PeriodFit:
    """Outcome of :func:`detect_period_noisy`.

    Attributes
    ----------
    period
        The smallest fitting period, 0 if none ``<= max_period`` fits.
    noise
        The noise level of the samples used (standard deviation).
    spread
        For every tested ``p`` (index ``p - 1``), the 95th percentile of the
        centred differences ``|s[i + p] - s[i] - median|`` divided by
        ``sqrt(2) * noise`` (the largest over the sample's components).
    """

    period: int
    noise: float
    spread: np.ndarray


def detect_period_noisy(
    samples: np.ndarray,
    noise: float,
    *,
    max_period: int = DEFAULT_MAX_PERIOD,
    factor: float = PERIOD_FACTOR,
) -> PeriodFit:
    """Smallest ``p`` for which the samples form ``p`` clusters as tight as the noise.

    Parameters
    ----------
    samples
        Stroboscopic samples, shape ``(m,)`` or ``(m, k)`` (NaN rows are
        skipped in the differences).
    noise
        Standard deviation of the noise on each sample (> 0).
    max_period
        Largest period tested (also at most a third of the samples).
    factor
        Tolerance, in noise levels, on the 95th percentile of the centred
        differences.

    Returns
    -------
    PeriodFit
        The period (0: none up to ``max_period``) and how tight its clusters are.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> orbit = np.tile([0.1, 0.5, -0.2], 40) + 0.001 * rng.standard_normal(120)
    >>> detect_period_noisy(orbit, 0.001).period
    3
    >>> detect_period_noisy(rng.uniform(-1, 1, 120), 0.001).period
    0
    """
    s = np.asarray(samples, dtype=float)
    if s.ndim == 1:
        s = s[:, None]
    if not (math.isfinite(noise) and noise > 0):
        raise InvalidParameterError(f"noise must be positive, got {noise!r}")
    m = s.shape[0]
    top = min(int(max_period), m // 3)
    spread = np.full(max(top, 0), np.inf)
    for p in range(1, top + 1):
        d = s[p:] - s[:-p]
        d = d[np.all(np.isfinite(d), axis=1)]
        if d.shape[0] < 2:
            continue
        e = np.abs(d - np.median(d, axis=0))
        spread[p - 1] = float(np.max(np.percentile(e, 95, axis=0))) / (math.sqrt(2.0) * noise)
        if spread[p - 1] <= factor:
            return PeriodFit(period=p, noise=float(noise), spread=spread[:p])
    return PeriodFit(period=0, noise=float(noise), spread=spread)


# ----------------------------------------------------------------------------
# The whole pipeline for one recording


@dataclass(frozen=True)
class Analysis:
    """A recording run through the pipeline.

    Attributes
    ----------
    source
        The recording's name.
    forcing_hz, eta
        Forcing frequency (Hz) and frequency ratio (with the apparatus' ``omega_0``).
    phase
        Sampling phase (radians after the reference phase).
    sample_times, samples
        Stroboscopic sample times (s) and angles (rad) at the phase.
    quarter
        Angles a quarter forcing period later (the embedding's second coordinate).
    period
        Detected period (0: none <= ``max_period`` at this noise level).
    noise
        Estimated standard deviation of the raw angle's measurement noise (rad).
    sample_noise
        The noise expected on each stroboscopic sample after filtering (rad).
    cutoff_hz
        Low-pass cutoff used.
    time, filtered
        The record's times and its filtered angle (for plots).
    lag
        A quarter forcing period in samples (the delay of the embedding).
    from_trigger
        Whether the forcing phase came from a trigger column.
    gaps, resampled
        As in :class:`~grazing.experiment.recording.Recording`.

    Examples
    --------
    What :func:`analyze_recording` finds in a synthetic recording of the
    paper's period-5 motion at θ̂ = 40°, η = 0.446:

    >>> from grazing.experiment.synthetic import synthetic_recording
    >>> rec = synthetic_recording(0.446, 40.0, periods=40, sample_rate=250.0, seed=2)
    >>> res = analyze_recording(rec)
    >>> res.period, round(res.eta, 4), res.from_trigger, res.samples.shape == res.quarter.shape
    (5, 0.446, True, True)
    """

    source: str
    forcing_hz: float
    eta: float
    phase: float
    sample_times: np.ndarray
    samples: np.ndarray
    quarter: np.ndarray
    period: int
    noise: float
    sample_noise: float
    cutoff_hz: float
    time: np.ndarray
    filtered: np.ndarray
    lag: int
    from_trigger: bool
    gaps: tuple[tuple[float, float], ...]
    resampled: bool

    def embedding(self) -> np.ndarray:
        """Delay vectors ``(theta(t - T/4), theta(t))`` of the filtered angle."""
        return delay_embedding(self.filtered, self.lag, 2)


def analyze_recording(
    rec: Recording,
    forcing_hz: float | None = None,
    *,
    phase: float = 0.0,
    cutoff_hz: float | None = None,
    cutoff_multiple: float = DEFAULT_CUTOFF_MULTIPLE,
    max_period: int = DEFAULT_MAX_PERIOD,
    noise: float | None = None,
    apparatus: Apparatus | None = None,
) -> Analysis:
    """Filter, sample stroboscopically, embed and detect the period of one recording.

    Parameters
    ----------
    rec
        The recording.
    forcing_hz
        Forcing frequency (Hz); needed without a trigger column (then ``t = 0``
        is at phase 0).
    phase
        Sampling phase in radians after the reference phase.
    cutoff_hz
        Low-pass cutoff (Hz); default ``cutoff_multiple`` times the forcing
        frequency (capped below the Nyquist frequency).
    cutoff_multiple
        See ``cutoff_hz``.
    max_period
        Largest period tested.
    noise
        Noise level of the raw angle (rad), if known; default estimated.
    apparatus
        Rig used to convert the frequency to ``eta`` (default: the paper's).

    Returns
    -------
    Analysis
        The stroboscopic samples, their delay coordinates, the period and the noise.

    Examples
    --------
    >>> from grazing.experiment.synthetic import synthetic_recording
    >>> rec = synthetic_recording(0.446, 40.0, periods=40, sample_rate=250.0, seed=2)
    >>> res = analyze_recording(rec)
    >>> res.period, round(res.eta, 4)
    (5, 0.446)
    """
    from grazing.experiment.apparatus import PAPER_RIG
    from grazing.experiment.recording import forcing_clock

    if not math.isfinite(phase):
        raise InvalidParameterError(f"phase must be finite, got {phase}")
    rig = apparatus or PAPER_RIG
    clock = forcing_clock(rec, forcing_hz)
    fs = rec.sample_rate
    if cutoff_hz is None:
        if not (math.isfinite(cutoff_multiple) and cutoff_multiple > 0):
            raise InvalidParameterError(f"cutoff multiple must be positive, got {cutoff_multiple:g}")
        cutoff_hz = min(cutoff_multiple * clock.forcing_hz, 0.4 * fs)
    _check_cutoff(fs, cutoff_hz)
    T = clock.period
    margin = 1.0 / cutoff_hz  # (the filter's settling time, left out at both ends)
    ts = clock.sample_times(phase)
    ts = ts[(ts >= rec.time[0] + margin) & (ts + T / 4 <= rec.time[-1] - margin)]
    if ts.size == 0:  # (before the filter: a cutoff of 1e-300 Hz is no filter numpy can build)
        raise InvalidParameterError(
            f"no sampling time at phase {phase:g} rad lies in the recording ({rec.time[0]:g} s to "
            f"{rec.time[-1]:g} s) less the filter's settling time of 1/cutoff = {margin:.3g} s at both "
            "ends: give a phase within a few forcing periods, or a higher cutoff"
        )
    x = rec.filled_angle()
    xf = lowpass(x, fs, cutoff_hz)
    sigma = estimate_noise(x, fs) if noise is None else float(noise)
    if not (math.isfinite(sigma) and sigma >= 0):
        raise InvalidParameterError(f"noise must be a non-negative number, got {sigma!r}")
    # floor: a noise-free record still carries interpolation and filtering errors of ~1e-6 of its range
    floor = SAMPLE_NOISE_FLOOR * max(float(np.ptp(xf)), 1e-3)
    s_noise = max(sigma * noise_gain(float(fs), float(cutoff_hz)), floor)
    samples = stroboscopic(rec.time, xf, ts)
    quarter = stroboscopic(rec.time, xf, ts + T / 4)
    if rec.gaps:
        bad = rec.in_gap(ts, margin) | rec.in_gap(ts + T / 4, margin)
        samples[bad] = np.nan
        quarter[bad] = np.nan
    fit = detect_period_noisy(np.column_stack([samples, quarter]), s_noise, max_period=max_period)
    return Analysis(
        source=rec.source,
        forcing_hz=clock.forcing_hz,
        eta=rig.eta(clock.forcing_hz),
        phase=float(phase),
        sample_times=ts,
        samples=samples,
        quarter=quarter,
        period=fit.period,
        noise=sigma,
        sample_noise=s_noise,
        cutoff_hz=float(cutoff_hz),
        time=rec.time,
        filtered=xf,
        lag=max(1, round(fs * T / 4)),
        from_trigger=clock.from_trigger,
        gaps=rec.gaps,
        resampled=rec.resampled,
    )


# ----------------------------------------------------------------------------
# Dense trajectories: uniform resampling and delay coordinates


def uniform_resample(
    t: np.ndarray, x: np.ndarray, dt: float, *, start: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Linearly interpolate samples ``x(t)`` on the uniform grid ``start + k dt``.

    Repeated times (a dense trajectory holds both states at every impact) are
    dropped, keeping the first occurrence; for a position-like component that
    is continuous across impacts, the two states agree anyway.

    Parameters
    ----------
    t
        Nondecreasing sample times, shape ``(n,)``.
    x
        Samples, shape ``(n,)`` or ``(n, m)``.
    dt
        Grid step (> 0).
    start
        First grid time (default ``t[0]``); the grid runs while it stays
        within ``t[-1]`` (up to a rounding tolerance of ``1e-9 dt``).

    Returns
    -------
    t_grid, x_grid
        The grid and the interpolated samples (same trailing shape as ``x``).

    Examples
    --------
    >>> t = np.array([0.0, 0.5, 0.5, 2.0])
    >>> tg, xg = uniform_resample(t, 2 * t, 0.5)
    >>> tg.tolist(), xg.tolist()
    ([0.0, 0.5, 1.0, 1.5, 2.0], [0.0, 1.0, 2.0, 3.0, 4.0])
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if t.ndim != 1 or t.size < 2 or x.shape[0] != t.size:
        raise ValueError("t must be 1-d with at least 2 points and x must have len(t) rows")
    if not (dt > 0 and math.isfinite(dt)):
        raise ValueError(f"dt must be a positive finite number, got {dt!r}")
    if np.any(np.diff(t) < 0):
        raise ValueError("t must be nondecreasing")
    keep = np.concatenate(([True], np.diff(t) > 0))
    t, x = t[keep], x[keep]
    t0 = float(t[0]) if start is None else float(start)
    n = math.floor((t[-1] - t0) / dt + 1e-9) + 1
    if n < 1 or t0 < t[0] - 1e-9 * dt:
        raise ValueError("the grid start lies outside the sampled times")
    tg = t0 + dt * np.arange(n)
    tg = np.clip(tg, t[0], t[-1])  # the last point may exceed t[-1] by rounding
    if x.ndim == 1:
        return tg, np.interp(tg, t, x)
    return tg, np.column_stack([np.interp(tg, t, x[:, j]) for j in range(x.shape[1])])


def delay_coordinates(
    t: np.ndarray, x: np.ndarray, delay: float, *, dt: float | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Takens delay coordinates of a scalar signal sampled at any times: ``x(t - delay)`` and ``x(t)``.

    The signal is resampled on a uniform grid (see :func:`uniform_resample`)
    whose step divides ``delay`` exactly, then embedded with a whole number of
    grid steps by :func:`grazing.experiment.signal.delay_embedding`.

    Parameters
    ----------
    t, x
        Times and scalar samples (1-d, same length; repeated times allowed).
    delay
        The delay (> 0), in the units of ``t``.  The paper uses a quarter of a
        forcing period, ``pi/2`` in ``tau``.
    dt
        Grid step wanted; it is shrunk to ``delay / ceil(delay / dt)``.
        Default: the median positive spacing of ``t``.

    Returns
    -------
    t_now, x_delayed, x_now
        Grid times ``t`` (from ``t[0] + delay``), ``x(t - delay)`` and ``x(t)``.

    Examples
    --------
    A sine wave delayed by a quarter of its period gives the unit circle:

    >>> t = np.linspace(0.0, 4 * np.pi, 401)
    >>> _, xd, xn = delay_coordinates(t, np.sin(t), np.pi / 2)
    >>> bool(np.allclose(xd**2 + xn**2, 1.0, atol=1e-3))
    True
    """
    from grazing.experiment.signal import delay_embedding

    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if x.ndim != 1:
        raise ValueError("delay_coordinates takes a scalar signal (1-d x)")
    if not (delay > 0 and math.isfinite(delay)):
        raise ValueError(f"delay must be a positive finite number, got {delay!r}")
    if dt is None:
        steps = np.diff(t)
        steps = steps[steps > 0]
        if steps.size == 0:
            raise ValueError("t has no positive time steps")
        dt = float(np.median(steps))
    shift = max(1, math.ceil(delay / dt - 1e-9))
    tg, xg = uniform_resample(t, x, delay / shift)
    if tg.size <= shift:
        raise ValueError("the signal is shorter than the delay")
    vectors = delay_embedding(xg, shift, 2)
    return tg[shift:], vectors[:, 0], vectors[:, 1]
