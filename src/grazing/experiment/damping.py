"""Free decay and logarithmic-decrement damping (paper section 2.1 eq. 1, section 3 eq. 6, fig 4).

The rig's damping was measured by letting the pendulum swing freely (no
forcing) with the stop at equilibrium (``theta_hat = 0``), reading successive
peak amplitudes ``A_k`` and forming a logarithmic decrement.  Each peak is one
swing away from the stop; between two peaks the pendulum hits the stop once.

Normalisation.  Eq. 1 as printed is ``D = ln(A_k / A_{k+k_hat}) / (4 pi k_hat)``.
For the model (eq. 4 with ``theta_hat = 0``) the small-amplitude ratio of two
successive peaks is ``ln(A_k / A_{k+1}) = 2 pi beta / sqrt(1 - 4 beta^2) - ln r``
(half a natural cycle of damping, one impact), so eq. 1 would give
``D = beta / 2`` for ``r = 1``, contradicting eq. 6 (``D = beta`` without impact
loss).  The estimator here therefore divides by ``2 pi k_hat``
(``normalisation="eq6"``, the default), which satisfies eq. 6 up to the factor
``1 / sqrt(1 - 4 beta^2)`` (1.009 at ``beta = 0.068``) and the softening of the
pendulum at large amplitude; ``normalisation="eq1"`` applies eq. 1 as printed.
The paper's fig 4(b) points satisfy ``D = beta - ln(r) / (4 pi)`` instead
(:func:`paper_relation`), which is what eq. 1 as printed gives for the model
with *twice* its damping (:func:`paper_protocol_damping`, the damping
``kappa = 4 omega_0 beta`` that the paper's quoted numbers use).  See
``docs/experiment.md`` for the numbers.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from grazing.errors import InvalidParameterError

if TYPE_CHECKING:  # pragma: no cover
    from grazing.experiment.recording import Recording

Normalisation = Literal["eq6", "eq1"]
Relation = Literal["model", "paper", "protocol"]

DEFAULT_AMPLITUDE = 0.5
"""Initial angle (rad, below the stop) of the simulated free decay."""

DEFAULT_PEAKS = 10
"""Peaks after the release used by the model's damping estimate."""

MIN_SWING = 1e-10
"""Smallest swing (rad) a simulated free decay is followed to."""

PAPER_DAMPING = 0.07
"""The damping ratio measured on the rig (paper section 2.1)."""

PAPER_POINTS = {
    "A": (0.4707, 0.010),
    "B": (0.7675, 0.048),
    "C": (0.8778, 0.058),
    "D": (1.0, 0.068),
}
"""The paper's fig 4(b) points ``(r, beta)`` (point D's ``beta = 0.68`` in the caption is 0.068)."""

FIG4A = (0.7148, 0.0426)
"""``(r, beta)`` of the paper's fig 4(a) free decay."""


def _norm_factor(normalisation: str) -> float:
    if normalisation == "eq6":
        return 2.0 * math.pi
    if normalisation == "eq1":
        return 4.0 * math.pi
    raise InvalidParameterError(f"normalisation must be 'eq6' or 'eq1', got {normalisation!r}")


def _check_r_beta(r: float, beta: float) -> tuple[float, float]:
    r, beta = float(r), float(beta)
    if not (math.isfinite(r) and 0.0 < r <= 1.0):
        raise InvalidParameterError(f"r = {r:g} is outside (0, 1] (a free decay needs r > 0)")
    if not (math.isfinite(beta) and 0.0 <= beta < 0.5):
        raise InvalidParameterError(f"beta = {beta:g} is outside [0, 0.5) (underdamped free decay)")
    return r, beta


# ----------------------------------------------------------------------------
# Free decay of the model


@dataclass(frozen=True)
class FreeDecay:
    """A simulated free decay (``alpha = 0``, ``theta_hat = 0``).

    Attributes
    ----------
    t
        Time ``omega_0 t`` (the model's ``tau`` with ``eta = 1``; one impacting
        cycle is about ``2 pi``), with both states at every impact.
    angle, velocity
        ``theta`` (rad) and ``d theta / d(omega_0 t)`` along the decay.
    peak_t, amplitudes
        Times and amplitudes ``A_k = -theta`` of the peaks (the release is
        ``A_0``).
    r, beta
        The model's restitution and damping.

    Examples
    --------
    The paper's point B (r = 0.7675, beta = 0.048) released 0.5 rad from the
    stop: one impact a cycle of about ``2 pi``, the swing never past the stop:

    >>> dec = free_decay(0.7675, 0.048, peaks=3)
    >>> dec.amplitudes.round(4).tolist(), dec.peak_t.round(2).tolist(), bool(dec.angle.max() <= 1e-12)
    ([0.5, 0.281, 0.1588, 0.09], [0.0, 6.38, 12.72, 19.03], True)
    """

    t: np.ndarray
    angle: np.ndarray
    velocity: np.ndarray
    peak_t: np.ndarray
    amplitudes: np.ndarray
    r: float
    beta: float


def free_decay(
    r: float,
    beta: float,
    *,
    amplitude: float = DEFAULT_AMPLITUDE,
    peaks: int = DEFAULT_PEAKS,
    points_per_cycle: int = 200,
    eta: float = 1.0,
) -> FreeDecay:
    """Simulate the unforced pendulum released at rest ``amplitude`` rad below the stop at 0.

    With ``alpha = 0`` the frequency ratio ``eta`` only rescales time (the
    model's time is ``tau = eta omega_0 t``); the result is reported in
    ``omega_0 t`` whatever ``eta``, and the amplitudes do not depend on it.

    Parameters
    ----------
    r, beta
        Restitution (in (0, 1]) and linear damping.
    amplitude
        Release angle below the stop, in radians (in (0, pi)).
    peaks
        Number of peaks after the release to simulate (fewer if the swing
        would decay below :data:`MIN_SWING` first).
    points_per_cycle
        Resolution of the dense trajectory (per ``2 pi`` of ``omega_0 t``).
    eta
        Time scale of the simulation (no effect on the amplitudes).

    Returns
    -------
    FreeDecay
        The trajectory, its peaks and their amplitudes.

    Examples
    --------
    >>> dec = free_decay(1.0, 0.048, peaks=3)
    >>> dec.amplitudes.round(4).tolist()
    [0.5, 0.3668, 0.27, 0.199]
    """
    from grazing.engine.simulate import simulate
    from grazing.models.pendulum import pendulum

    r, beta = _check_r_beta(r, beta)
    if not (math.isfinite(amplitude) and 0.0 < amplitude < math.pi):
        raise InvalidParameterError(f"amplitude must be in (0, pi) rad, got {amplitude:g}")
    if int(peaks) < 1:
        raise InvalidParameterError(f"peaks must be >= 1, got {peaks}")
    model = pendulum(None, alpha=0.0, beta=beta, r=r, eta=eta, theta_hat=0.0)
    n = decay_peaks(r, beta, amplitude, peaks)
    cycles = decay_cycles(n, amplitude)
    periods = max(1, math.ceil(cycles * eta))
    ppp = max(8, math.ceil(points_per_cycle / eta))
    sol = simulate(model, [-amplitude, 0.0], periods=periods, trajectory=ppp)
    assert sol.trajectory is not None and sol.trajectory_t is not None
    t = sol.trajectory_t * (1.0 / eta)
    th = sol.trajectory[:, 0]
    om = sol.trajectory[:, 1] * eta
    pt, pa = _trajectory_minima(t, th, om)
    peak_t = np.concatenate([[0.0], pt])[: n + 1]
    amps = np.concatenate([[amplitude], -pa])[: n + 1]
    return FreeDecay(t=t, angle=th, velocity=om, peak_t=peak_t, amplitudes=amps, r=r, beta=beta)


def decay_peaks(r: float, beta: float, amplitude: float, peaks: int) -> int:
    """Peaks a free decay simulates: ``peaks``, or fewer if the swing decays below :data:`MIN_SWING` first.

    (A few hundred cycles of round-off later the impacts would accumulate at
    the stop; the small-amplitude decay per peak bounds the count.)

    >>> decay_peaks(1.0, 0.048, 0.5, 3), decay_peaks(0.5, 0.048, 0.5, 10**9)
    (3, 22)
    """
    per_peak = 2.0 * math.pi * beta / math.sqrt(1.0 - 4.0 * beta * beta) - math.log(r)
    n = int(peaks)
    if per_peak > 0:
        n = min(n, max(1, math.floor(math.log(amplitude / MIN_SWING) / per_peak)))
    return n


def decay_cycles(n_peaks: int, amplitude: float) -> int:
    """Forcing-free cycles simulated for ``n_peaks`` peaks after a release at ``amplitude`` rad.

    One cycle lasts 2 pi in omega_0 t at small amplitude, longer at large ones.
    """
    return math.ceil((n_peaks + 1) * 1.1 * _period_factor(amplitude)) + 2


def _period_factor(amplitude: float) -> float:
    """Pendulum period at this amplitude over the small-amplitude one (complete elliptic integral)."""
    from scipy.special import ellipk

    k = math.sin(amplitude / 2.0)
    return float(ellipk(k * k)) / (math.pi / 2.0)


def _trajectory_minima(t: np.ndarray, th: np.ndarray, om: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Minima of ``theta`` on a dense trajectory: cubic Hermite between the samples where ``theta'`` turns."""
    h = np.diff(t)
    i = np.nonzero((om[:-1] < 0.0) & (om[1:] >= 0.0) & (h > 0.0))[0]
    if i.size == 0:
        return np.empty(0), np.empty(0)
    h = h[i]
    y0, y1, v0, v1 = th[i], th[i + 1], om[i] * h, om[i + 1] * h
    c = v0
    delta = y1 - y0 - c
    b = 3.0 * delta - (v1 - c)
    a = delta - b
    s = -v0 / (v1 - v0)  # linear guess, then Newton on p'(s) = 0
    for _ in range(4):
        s = np.clip(s - (3 * a * s * s + 2 * b * s + c) / (6 * a * s + 2 * b), 0.0, 1.0)
    return t[i] + s * h, ((a * s + b) * s + c) * s + y0


# ----------------------------------------------------------------------------
# The estimator


@dataclass(frozen=True)
class DampingEstimate:
    """A logarithmic-decrement damping estimate.

    Attributes
    ----------
    damping
        ``D``: the mean log ratio per peak divided by ``2 pi`` (``"eq6"``) or
        ``4 pi`` (``"eq1"``).
    log_ratio
        Mean of ``ln(A_k / A_{k+k_hat}) / k_hat`` over the pairs used: the log
        ratio per peak (per impact, for a decay against the stop).
    values
        The individual ``ln(A_k / A_{k+k_hat}) / k_hat``, pair by pair.
    spread
        Standard deviation of :attr:`values` (0 for a single pair).
    k_hat
        The peak spacings used.
    normalisation
        ``"eq6"`` or ``"eq1"``.
    amplitudes
        The peak amplitudes the estimate used.

    Examples
    --------
    Amplitudes falling by ``exp(-2 pi 0.07)`` a peak: ``D = 0.07`` from every
    pair, at spacings 1 and 2 (five pairs and four):

    >>> import math
    >>> est = log_decrement([math.exp(-2 * math.pi * 0.07 * k) for k in range(6)], k_hat=(1, 2))
    >>> round(est.damping, 12), est.values.size, round(est.spread, 12), est.k_hat, est.normalisation
    (0.07, 9, 0.0, (1, 2), 'eq6')
    """

    damping: float
    log_ratio: float
    values: np.ndarray
    spread: float
    k_hat: tuple[int, ...]
    normalisation: str
    amplitudes: np.ndarray


def log_decrement(
    amplitudes: Sequence[float] | np.ndarray,
    k_hat: int | Sequence[int] = 1,
    *,
    normalisation: Normalisation = "eq6",
) -> DampingEstimate:
    """Logarithmic-decrement damping from successive peak amplitudes (paper eq. 1).

    For every spacing ``k_hat`` given and every ``k``, forms
    ``ln(A_k / A_{k+k_hat}) / k_hat`` and averages them all; ``D`` is that
    mean divided by ``2 pi`` (``"eq6"``, so that ``D = beta`` when ``r = 1``)
    or by ``4 pi`` (``"eq1"``, the formula as printed).

    Parameters
    ----------
    amplitudes
        Positive peak amplitudes ``A_0, A_1, ...`` (one per swing).
    k_hat
        A peak spacing, or several (the estimate averages over all of them).
    normalisation
        ``"eq6"`` (default) or ``"eq1"``.

    Returns
    -------
    DampingEstimate
        ``D``, its spread over the ratios, and the ratios used.

    Examples
    --------
    >>> import math
    >>> amps = [math.exp(-2 * math.pi * 0.07 * k) for k in range(6)]
    >>> round(log_decrement(amps, k_hat=(1, 2)).damping, 12)
    0.07
    >>> round(log_decrement(amps, normalisation="eq1").damping, 12)
    0.035
    """
    a = np.asarray(amplitudes, dtype=float).ravel()
    if a.size < 2:
        raise InvalidParameterError(f"need at least 2 peak amplitudes, got {a.size}")
    if not np.all(np.isfinite(a)) or np.any(a <= 0):
        raise InvalidParameterError("peak amplitudes must be positive finite numbers")
    ks = (int(k_hat),) if np.isscalar(k_hat) else tuple(int(k) for k in k_hat)  # type: ignore[arg-type]
    if not ks or min(ks) < 1:
        raise InvalidParameterError(f"k_hat must be positive integers, got {k_hat!r}")
    if max(ks) >= a.size:
        raise InvalidParameterError(f"k_hat = {max(ks)} needs more than {a.size} peak amplitudes")
    la = np.log(a)
    values = np.concatenate([(la[:-k] - la[k:]) / k for k in ks])
    mean = float(values.mean())
    return DampingEstimate(
        damping=mean / _norm_factor(normalisation),
        log_ratio=mean,
        values=values,
        spread=float(values.std()),
        k_hat=ks,
        normalisation=normalisation,
        amplitudes=a,
    )


def model_damping(
    r: float,
    beta: float,
    *,
    amplitude: float = DEFAULT_AMPLITUDE,
    peaks: int = DEFAULT_PEAKS,
    k_hat: int | Sequence[int] = 1,
    normalisation: Normalisation = "eq6",
) -> DampingEstimate:
    """The damping ``D`` that eq. 1's procedure measures on the model's free decay.

    Simulates :func:`free_decay` and applies :func:`log_decrement` to the
    release and the ``peaks`` peaks after it.

    Parameters
    ----------
    r
        Restitution, in (0, 1].
    beta
        Linear damping.
    amplitude
        Release angle below the stop, in radians.
    peaks
        Peaks after the release used.
    k_hat, normalisation
        As in :func:`log_decrement`.

    Returns
    -------
    DampingEstimate
        What eq. 1's procedure measures.

    Examples
    --------
    >>> round(model_damping(1.0, 0.048).damping, 4)  # eq. 6: D = beta (r = 1)
    0.0485
    >>> round(model_damping(0.7675, 0.048).damping, 4)  # point B
    0.0905
    """
    dec = free_decay(r, beta, amplitude=amplitude, peaks=peaks)
    if dec.amplitudes.size < 2:  # pragma: no cover - the pendulum always swings back for r > 0
        raise InvalidParameterError("the free decay has no peak after the release")
    return log_decrement(dec.amplitudes, k_hat, normalisation=normalisation)


def linear_damping(r: float, beta: float, *, normalisation: Normalisation = "eq6") -> float:
    """Small-amplitude ``D`` of the model in closed form.

    ``(2 pi beta / sqrt(1 - 4 beta^2) - ln r) / c`` with ``c = 2 pi`` (eq6)
    or ``4 pi`` (eq1): half a damped natural cycle and one impact per peak.

    Parameters
    ----------
    r
        Restitution, in (0, 1].
    beta
        Linear damping.
    normalisation
        ``"eq6"`` (default: ``D = beta`` at ``r = 1``) or ``"eq1"`` (the formula as printed).

    Returns
    -------
    float
        The damping ``D`` of small swings.

    Examples
    --------
    >>> round(linear_damping(1.0, 0.068), 4), round(linear_damping(0.7675, 0.048), 4)
    (0.0686, 0.0903)
    """
    r, beta = _check_r_beta(r, beta)
    per_peak = 2.0 * math.pi * beta / math.sqrt(1.0 - 4.0 * beta * beta) - math.log(r)
    return per_peak / _norm_factor(normalisation)


def paper_relation(r: float, beta: float) -> float:
    """``D = beta - ln(r) / (4 pi)``: the relation the paper's fig 4(b) points satisfy.

    Parameters
    ----------
    r
        Restitution, in (0, 1].
    beta
        Linear damping.

    Returns
    -------
    float
        The damping ``D``.

    Examples
    --------
    >>> [round(paper_relation(r, b), 4) for r, b in PAPER_POINTS.values()]
    [0.07, 0.0691, 0.0684, 0.068]
    """
    r, beta = _check_r_beta(r, beta)
    return beta - math.log(r) / (4.0 * math.pi)


def paper_protocol_damping(
    r: float,
    beta: float,
    *,
    amplitude: float = DEFAULT_AMPLITUDE,
    peaks: int = DEFAULT_PEAKS,
    k_hat: int | Sequence[int] = 1,
) -> DampingEstimate:
    """Our reconstruction of how the paper's fig 4 was computed: eq. 1 as printed, damping doubled.

    Eq. 1 (``1 / (4 pi k_hat)``) applied to the free decay of the model with
    ``2 beta`` in place of ``beta`` -- the model whose damping term is
    ``kappa / omega`` with ``kappa = 4 omega_0 beta``, the conversion the
    paper's quoted numbers follow (docs/equations.md, erratum on eq. 3).  It gives
    ``D = 0.070`` at the paper's points A, B, C and fig 4(a) and 0.071 at D,
    which the model itself (:func:`model_damping`) does not.

    Examples
    --------
    >>> [round(paper_protocol_damping(r, b).damping, 3) for r, b in PAPER_POINTS.values()]
    [0.07, 0.07, 0.07, 0.071]
    """
    _check_r_beta(r, 2.0 * float(beta))
    return model_damping(
        r, 2.0 * float(beta), amplitude=amplitude, peaks=peaks, k_hat=k_hat, normalisation="eq1"
    )


# ----------------------------------------------------------------------------
# Equal damping (fig 4b)


def _damping_fn(relation: str, protocol: dict[str, Any]) -> Callable[[float, float], float]:
    if relation == "model":
        return lambda r, b: model_damping(r, b, **protocol).damping
    if relation == "paper":
        return paper_relation
    if relation == "protocol":
        return lambda r, b: paper_protocol_damping(r, b, **protocol).damping
    raise InvalidParameterError(f"relation must be 'model', 'paper' or 'protocol', got {relation!r}")


def _check_damping(damping: float) -> float:
    d = float(damping)
    if not (math.isfinite(d) and 0.0 < d < 0.5):
        raise InvalidParameterError(f"damping D must be in (0, 0.5), got {d:g}")
    return d


def beta_for_damping(r: float, damping: float, *, relation: Relation = "model", **protocol: object) -> float:
    """The ``beta`` that gives damping ``D`` at restitution ``r`` (root-finding on the model).

    Raises :class:`~grazing.errors.InvalidParameterError` when even
    ``beta = 0`` gives more damping than ``D`` (impacts alone lose too much).

    Parameters
    ----------
    r
        Restitution, in (0, 1].
    damping
        The damping ``D`` wanted.
    relation
        ``"model"`` (eq. 1's procedure on the simulated free decay),
        ``"paper"`` (:func:`paper_relation`) or ``"protocol"`` (see :class:`IsoDampingCurve`).
    **protocol
        ``amplitude``, ``peaks``, ``k_hat``, ``normalisation`` for :func:`model_damping`.

    Returns
    -------
    float
        The linear damping ``beta``.

    Examples
    --------
    >>> b = beta_for_damping(0.7675, 0.0905)
    >>> round(b, 4), round(model_damping(0.7675, b).damping, 6)
    (0.048, 0.0905)
    """
    from scipy.optimize import brentq

    d = _check_damping(damping)
    fn = _damping_fn(relation, dict(protocol))
    r, _ = _check_r_beta(r, 0.0)
    if relation == "paper":
        beta = d + math.log(r) / (4.0 * math.pi)
        if beta < 0:
            raise InvalidParameterError(
                f"no beta >= 0 gives D = {d:g} at r = {r:g} (impacts alone give more)"
            )
        return beta
    f0 = fn(r, 0.0) - d
    if f0 > 0:
        raise InvalidParameterError(
            f"no beta >= 0 gives D = {d:g} at r = {r:g}: impacts alone give D = {f0 + d:.4g}"
        )
    if f0 == 0:
        return 0.0
    hi = max(1e-3, d + math.log(r) / (2.0 * math.pi) + 0.01)
    while fn(r, hi) - d < 0:
        hi = min(0.49, 1.5 * hi + 0.01)
        if hi >= 0.49 and fn(r, hi) - d < 0:
            raise InvalidParameterError(f"no beta < 0.49 gives D = {d:g} at r = {r:g}")
    return float(brentq(lambda b: fn(r, b) - d, 0.0, hi, xtol=1e-10, rtol=1e-12))


def r_for_damping(beta: float, damping: float, *, relation: Relation = "model", **protocol: object) -> float:
    """The restitution ``r`` in (0, 1] that gives damping ``D`` with linear damping ``beta``.

    Raises :class:`~grazing.errors.InvalidParameterError` when ``beta`` alone
    gives more damping than ``D`` (that would need ``r > 1``).

    Parameters
    ----------
    beta
        Linear damping.
    damping
        The damping ``D`` wanted.
    relation
        ``"model"``, ``"paper"`` or ``"protocol"`` (as :func:`beta_for_damping`).
    **protocol
        ``amplitude``, ``peaks``, ``k_hat``, ``normalisation`` for :func:`model_damping`.

    Returns
    -------
    float
        The restitution ``r``.

    Examples
    --------
    >>> d = model_damping(0.7675, 0.048).damping
    >>> round(r_for_damping(0.048, d), 6)
    0.7675
    """
    from scipy.optimize import brentq

    d = _check_damping(damping)
    _, beta = _check_r_beta(1.0, beta)
    fn = _damping_fn(relation, dict(protocol))
    g1 = fn(1.0, beta) - d
    if g1 > 0:
        raise InvalidParameterError(
            f"beta = {beta:g} alone gives D = {g1 + d:.4g} > {d:g}: no r <= 1 gives D = {d:g}"
        )
    if g1 == 0:
        return 1.0
    if relation == "paper":
        return math.exp(-4.0 * math.pi * (d - beta))
    lo = 0.9 * math.exp(-2.0 * math.pi * (d - beta))
    while fn(lo, beta) - d < 0:
        lo *= 0.5
    return float(brentq(lambda r: fn(r, beta) - d, lo, 1.0, xtol=1e-12, rtol=1e-12))


@dataclass(frozen=True)
class IsoDampingCurve:
    """The curve of ``(r, beta)`` giving one damping ``D`` (fig 4b).

    Attributes
    ----------
    damping
        The target ``D``.
    r, beta
        Points of the curve, ``r`` increasing from :attr:`r_min` to 1.
    r_min
        Where the curve meets ``beta = 0`` (impacts alone give ``D``).
    beta_max
        ``beta`` at ``r = 1`` (no impact loss).
    relation
        ``"model"`` (root-finding on the model's measured ``D``),
        ``"paper"`` (``D = beta - ln(r) / (4 pi)``) or ``"protocol"``
        (root-finding on :func:`paper_protocol_damping`).

    Examples
    --------
    The paper's relation: at ``beta = 0`` the impacts alone give ``D``, so
    ``r_min = exp(-4 pi D)``; at ``r = 1``, ``beta = D``:

    >>> import math
    >>> c = iso_damping(0.07, relation="paper", num=3)
    >>> c.r.round(4).tolist(), c.beta.round(4).tolist(), round(math.exp(-4 * math.pi * 0.07), 4)
    ([0.4149, 0.7075, 1.0], [0.0, 0.0425, 0.07], 0.4149)
    """

    damping: float
    r: np.ndarray
    beta: np.ndarray
    r_min: float
    beta_max: float
    relation: str


def iso_damping(
    damping: float = PAPER_DAMPING,
    *,
    num: int = 21,
    relation: Relation = "model",
    **protocol: object,
) -> IsoDampingCurve:
    """The curve in the ``(r, beta)`` plane along which the measured damping is ``D``.

    With ``relation="model"`` every point is found by root-finding on
    :func:`model_damping` (free decay simulated, eq. 1 procedure with the eq. 6
    normalisation unless ``normalisation="eq1"`` is passed in ``protocol``).

    Parameters
    ----------
    damping
        Target ``D`` (the rig's is 0.07).
    num
        Number of points, ``r`` evenly spaced from the curve's end at
        ``beta = 0`` to ``r = 1``.
    relation
        ``"model"``, ``"paper"`` or ``"protocol"`` (see :class:`IsoDampingCurve`).
    **protocol
        ``amplitude``, ``peaks``, ``k_hat``, ``normalisation`` for
        :func:`model_damping`.

    Returns
    -------
    IsoDampingCurve
        The curve's ``r`` and ``beta``.

    Examples
    --------
    >>> c = iso_damping(0.07, num=3)
    >>> c.r.round(4).tolist(), c.beta.round(4).tolist()
    ([0.6448, 0.8224, 1.0], [0.0, 0.0386, 0.0691])
    >>> round(model_damping(c.r[1], c.beta[1]).damping, 8)
    0.07
    """
    from scipy.optimize import brentq

    d = _check_damping(damping)
    if int(num) < 2:
        raise InvalidParameterError(f"num must be >= 2, got {num}")
    fn = _damping_fn(relation, dict(protocol))
    if fn(1.0, 0.0) >= d:  # pragma: no cover - D(1, 0) = 0
        raise InvalidParameterError(f"D = {d:g} is not reachable")
    if relation == "paper":
        r_min = math.exp(-4.0 * math.pi * d)
    else:
        lo = 0.5 * math.exp(-2.0 * math.pi * d)
        while fn(lo, 0.0) < d:
            lo *= 0.5
        r_min = float(brentq(lambda r: fn(r, 0.0) - d, lo, 1.0, xtol=1e-12, rtol=1e-12))
    rs = np.linspace(r_min, 1.0, int(num))
    betas = np.array(
        [0.0] + [beta_for_damping(r, d, relation=relation, **protocol) for r in rs[1:]]  # type: ignore[arg-type]
    )
    return IsoDampingCurve(
        damping=d, r=rs, beta=betas, r_min=r_min, beta_max=float(betas[-1]), relation=relation
    )


# ----------------------------------------------------------------------------
# Recorded free decay


def _stop_angle(xf: np.ndarray, minima: np.ndarray) -> float:
    """The stop's angle from the tops of the swings between the minima, extrapolated to zero amplitude."""
    tops = np.array([xf[a:b].max() for a, b in itertools.pairwise(minima)])
    if tops.size < 4:
        return float(np.median(tops))
    swing = tops - xf[minima[:-1]]
    design = np.column_stack([np.ones_like(swing), swing])
    coef = np.linalg.lstsq(design, tops, rcond=None)[0]
    return float(coef[0])


@dataclass(frozen=True)
class RecordedDecay:
    """Peaks found in a recorded free decay.

    Attributes
    ----------
    peak_t, amplitudes
        Times (s) and amplitudes (rad, below the rest angle) of the peaks.
    rest_angle
        The angle the amplitudes are measured from (the stop, where the
        pendulum comes to rest).
    noise
        Estimated noise level of the angle (rad).
    estimate
        The damping estimate from these peaks.
    """

    peak_t: np.ndarray
    amplitudes: np.ndarray
    rest_angle: float
    noise: float
    estimate: DampingEstimate


def recorded_damping(
    rec: Recording,
    *,
    k_hat: int | Sequence[int] = 1,
    normalisation: Normalisation = "eq6",
    rest_angle: float | None = None,
    min_amplitude: float | None = None,
    cutoff_hz: float | None = None,
) -> RecordedDecay:
    """Damping of a recorded free decay against a stop at equilibrium (the rig's eq. 1 procedure).

    The angle is low-pass filtered (zero phase; default cutoff a twentieth of
    the sampling rate), its minima are located and refined by a local
    parabola, and :func:`log_decrement` is applied to the amplitudes below
    the rest angle.  Peaks smaller than ``min_amplitude`` (default: 20 times
    the noise level) are left out, as the paper's choice of ``k_hat > 1``
    suggests, since their ratios are dominated by noise.

    Parameters
    ----------
    rec
        The recording (see :func:`grazing.experiment.load_recording`).
    k_hat, normalisation
        As in :func:`log_decrement`.
    rest_angle
        Angle of the stop (the rest position).  Default: from the largest
        angles between successive minima (each swing ends against the stop),
        extrapolated to zero amplitude, since the filter rounds the corner of
        every impact by an amount proportional to the impact speed.
    min_amplitude
        Smallest amplitude used, in radians.
    cutoff_hz
        Low-pass cutoff in Hz.

    Returns
    -------
    RecordedDecay
        The estimate (``estimate``: a :class:`DampingEstimate`) with the
        peaks and the rest angle it was measured from.

    Examples
    --------
    >>> from grazing.experiment.synthetic import synthetic_free_decay
    >>> rec = synthetic_free_decay(1.0, 0.048, duration=12.0, seed=1)
    >>> round(recorded_damping(rec).estimate.damping, 3)
    0.048
    """
    from scipy.signal import find_peaks

    from grazing.experiment.signal import estimate_noise, lowpass

    fs = rec.sample_rate
    x = rec.filled_angle()
    noise = estimate_noise(x, fs)
    fc = cutoff_hz if cutoff_hz is not None else fs / 20.0
    xf = lowpass(x, fs, fc)
    floor = 20.0 * noise if min_amplitude is None else float(min_amplitude)
    idx, _ = find_peaks(-xf, prominence=max(floor, 1e-12))
    if idx.size < 2:
        raise InvalidParameterError(
            f"the record has {idx.size} swing(s) larger than {floor:.3g} rad; "
            "need at least 2 to estimate damping"
        )
    if rest_angle is None:
        rest_angle = _stop_angle(xf, idx)
    y = xf - rest_angle
    spacing = float(np.median(np.diff(idx)))
    w = max(2, round(0.04 * spacing))
    times, amps = [], []
    for i in idx:
        lo, hi = max(0, i - w), min(y.size, i + w + 1)
        s = np.arange(lo, hi) - i
        c2, c1, c0 = np.polyfit(s, y[lo:hi], 2)
        s0 = float(np.clip(-c1 / (2 * c2), -w, w)) if c2 > 0 else 0.0
        times.append(rec.time[0] + (i + s0) / fs)
        amps.append(-(c0 + c1 * s0 + c2 * s0 * s0))
    amps_a, times_a = np.array(amps), np.array(times)
    keep = amps_a > floor
    # stop at the first peak that is too small: the ones after it are noise-dominated
    n = int(np.argmin(keep)) if not keep.all() else keep.size
    if n < 2:
        raise InvalidParameterError(
            f"fewer than 2 peaks above {floor:.3g} rad before the decay reaches the noise level"
        )
    est = log_decrement(amps_a[:n], k_hat, normalisation=normalisation)
    return RecordedDecay(
        peak_t=times_a[:n], amplitudes=amps_a[:n], rest_angle=float(rest_angle), noise=noise, estimate=est
    )
