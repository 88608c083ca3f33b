"""A run whose samples contract towards a cycle, polished by Newton's method into the orbit it approaches.

A stable periodic orbit whose largest Floquet multiplier is near the unit
circle (``|mu| = 0.9968``) is approached so slowly that a run's samples do not
repeat to the period detector's 1e-6 after hundreds of periods: it looked
aperiodic ("no period <= 64"), and its Lyapunov exponent, ``ln|mu| / T``
(-0.0007), within 1e-3 of zero, made it "quasiperiodic".  The dynamics say
more than the window: the differences ``|x[k + p] - x[k]|`` of such a run
shrink (:func:`contracting_periods`), and Newton's method on the stroboscopic
map (:func:`grazing.orbits.find_orbit`) from its last sample converges to the
orbit.  Where that orbit is stable (and isolated) and the run's samples
approach it (:func:`approaches`), the run is on that periodic attractor
(:func:`polish`).  A failed attempt (Newton does not converge, or finds an
unstable orbit: the fixed point inside a torus) changes nothing: the run keeps
the label its samples give.

Used by the sweeps (:meth:`grazing.sweeps.run.LaneBatch.results`: a point's
period) and the basins (:class:`grazing.attractors.classify.Catalogue`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.options import (
    MAX_PERIOD,
    POLISH_CANDIDATES,
    POLISH_MAX_ITER,
    POLISH_RATIO,
)
from grazing.errors import GrazingError


@dataclass(frozen=True)
class Polished:
    """The stable periodic orbit a run approaches.

    Attributes
    ----------
    period
        Its period in forcing periods.
    cycle
        Its points at the run's sampling times ``t0 + j T`` (``j = 1 .. period``; the last is the
        orbit's point at ``t0``), one row each.
    impacts
        Impacts per period.
    multipliers
        Its Floquet multipliers, largest modulus first.
    lyapunov
        Its largest Lyapunov exponent per unit time, ``ln |mu|_max / (period T)``.
    """

    period: int
    cycle: np.ndarray
    impacts: int
    multipliers: np.ndarray
    lyapunov: float


def _differences(samples: np.ndarray, p: int) -> np.ndarray:
    """``max_i |x[k + p, i] - x[k, i]|`` for every ``k``."""
    return np.max(np.abs(samples[p:] - samples[:-p]), axis=1)


def contracting_periods(
    samples: np.ndarray,
    max_period: int = MAX_PERIOD,
    ratio: float = POLISH_RATIO,
    most: int = POLISH_CANDIDATES,
) -> list[int]:
    """The shortest periods ``p <= max_period`` (at most ``most``) towards whose cycles ``samples`` contract.

    They contract towards a period-``p`` cycle where the largest difference ``|x[k + p] - x[k]|``
    falls from each quarter of the samples to the next, over the last quarter to under ``ratio`` of
    the largest over the first, and is not zero (the samples of a run that has settled repeat: it is
    periodic, not contracting).  Only periods up to a third of the samples are tried (each quarter
    then holds a difference or more).  (Chaotic runs pass this too, but less often than a fall from
    the first half to the second: on the pendulum's 1000-point sweep, 102 candidates in 170 runs
    without a period instead of 295; Newton's method then fails on them, which tells them apart.)

    Examples
    --------
    >>> k = np.arange(50.0)[:, None]
    >>> spiral = 0.1 * 0.997**k * np.hstack([np.cos(2.77 * k), np.sin(2.77 * k)])   # |mu| = 0.997
    >>> torus = np.hstack([np.cos(2.77 * k), np.sin(2.77 * k)])                      # no contraction
    >>> three = np.where(k % 3 == 0, 1.0, -1.0) * np.ones((1, 2)) + 1e-3 * 0.9**k    # to a 3-cycle
    >>> contracting_periods(spiral), contracting_periods(torus), contracting_periods(three)[:1]
    ([1, 2], [], [3])
    """
    s = np.asarray(samples, dtype=float)
    out: list[int] = []
    if s.ndim != 2 or not np.all(np.isfinite(s)):
        return out
    floor = 1e3 * np.finfo(float).eps * (1.0 + float(np.max(np.abs(s))))  # (rounding: a periodic run)
    for p in range(1, min(max_period, s.shape[0] // 3) + 1):
        d = _differences(s, p)
        edges = [round(i * d.size / 4) for i in range(5)]
        quarters = [float(d[a:b].max()) for a, b in itertools.pairwise(edges) if b > a]
        falling = all(b < a for a, b in itertools.pairwise(quarters))
        if quarters[0] > floor and falling and quarters[-1] < ratio * quarters[0]:
            out.append(p)
            if len(out) >= most:
                break
    return out


def approaches(
    samples: np.ndarray, cycle: np.ndarray, largest: float = 1.0, ratio: float = POLISH_RATIO
) -> bool:
    """Whether ``samples`` approach the periodic orbit of points ``cycle`` whose largest multiplier has
    modulus ``largest``, as a run in its basin does.

    Their distance to its nearest point (largest component difference) over their second half must be
    under ``ratio`` of that over their first half, and no more than the square root of what the
    multiplier allows over half the samples (``largest ** (h / p)``, ``h`` samples a half, ``p`` the
    period): a run near an orbit with multipliers of modulus 0.64 is on it to 1e-6 within 32
    periods; one whose distance shrinks more slowly is passing by (a chaotic run), not converging.
    Samples on the orbit to rounding approach it.

    Examples
    --------
    >>> k = np.arange(40.0)[:, None]
    >>> origin = np.zeros((1, 1))
    >>> spiral = 0.5 * 0.99**k * np.cos(2.7 * k)
    >>> approaches(spiral, origin, 0.99), approaches(np.cos(k), origin), approaches(spiral, origin, 0.5)
    (True, False, False)
    """
    s, c = np.asarray(samples, dtype=float), np.asarray(cycle, dtype=float)
    e = np.min(np.max(np.abs(s[:, None, :] - c[None, :, :]), axis=2), axis=1)
    h = e.size // 2
    scale = 1.0 + float(np.max(np.abs(c)))
    last, first = float(np.max(e[-h:])), float(np.max(e[:h]))
    if last <= 1e3 * np.finfo(float).eps * scale:
        return True
    allowed = min(ratio, math.sqrt(min(1.0, float(largest)) ** (h / c.shape[0])))
    return last < allowed * first


def is_neutral(monodromy: np.ndarray, multipliers: np.ndarray | None = None) -> bool:
    """Whether a periodic orbit of monodromy ``M`` is neutral: it is not isolated, its multiplier 1 double
    (a Jordan block or an eigenspace: :func:`grazing.orbits.periodic.is_isolated`).  ``multipliers`` is
    not needed (kept for callers that pass it).

    The impact damper's free particle at rest in its cavity, never reaching a wall, is periodic
    only because its velocity is exactly zero: its monodromy has the block ``[[1, T], [0, 1]]``.

    Examples
    --------
    >>> particle = np.array([[0.5, 0.0, 0.0], [0.0, 1.0, 5.2], [0.0, 0.0, 1.0]])
    >>> is_neutral(particle), is_neutral(np.diag([0.5, 1.0]))
    (True, False)
    """
    from grazing.orbits.periodic import is_isolated

    return not is_isolated(np.asarray(monodromy, dtype=float))


def mode_there(model: HybridModel, state: np.ndarray, t: float) -> str | None:
    """The mode a run from ``state`` at time ``t`` starts in (:meth:`HybridModel.mode_at`); None
    without modes."""
    return model.mode_at(state, t) if model.has_modes else None


def run_mode(model: HybridModel, index: int, state: np.ndarray, t: float) -> str | None:
    """The mode a run from ``state`` at time ``t`` that a run left in mode ``index`` starts in: that mode
    where it is a real one (a state of a hysteretic switch lies in two modes' regions: the one it was
    in is the right one), else (-1: unknown; a sliding pseudo-mode, where no run starts) the one it lies
    in (:func:`mode_there`; it slides on from the surface).  None without modes.

    Examples
    --------
    >>> import grazing
    >>> m = grazing.models.soft_impact_oscillator(gap=0.5)
    >>> run_mode(m, 1, np.array([0.5, 0.0]), 0.0), run_mode(m, -1, np.array([0.5, 0.0]), 0.0)
    ('contact', 'free')
    """
    if not model.has_modes:
        return None
    real = len(model.mode_names) - len(model.sliding_modes)
    return model.mode_names[int(index)] if 0 <= int(index) < real else mode_there(model, state, t)


def cycle_points(model: HybridModel, state: np.ndarray, t0: float, period: int,
                 mode: str | None = None) -> np.ndarray:  # fmt: skip
    """The points of the period-``period`` orbit through ``state`` (in ``mode``, by default the one it lies
    in) at times ``t0 + j T``, ``j = 1 .. period`` (the last is ``state`` again, to the orbit's
    accuracy)."""
    from grazing.engine.simulate import simulate

    phase = 2 * math.pi * (t0 / float(model.period) % 1.0)
    mode = mode_there(model, state, t0) if mode is None else mode
    sol = simulate(model, state, t0=t0, transient=0, periods=period, phase=phase, mode=mode)
    return np.asarray(sol.samples, dtype=float)[-period:]


def polish(
    model: HybridModel,
    samples: np.ndarray,
    t0: float,
    *,
    max_period: int = MAX_PERIOD,
    candidates: list[int] | None = None,
    max_iter: int = POLISH_MAX_ITER,
    mode: str | None = None,
) -> Polished | None:
    """The stable periodic orbit that ``samples`` (a run's, at times ``t0 + k T``) approach, or None.

    For each of the run's :func:`contracting_periods` (or ``candidates``), shortest first, Newton's
    method (:func:`grazing.orbits.find_orbit`, at most ``max_iter`` iterations) from the run's last
    sample; the first orbit it converges to that is stable, not neutral (:func:`is_neutral`) and
    that the samples :func:`approaches` is the answer.  None where there is no candidate, Newton
    fails, or the orbits it finds are unstable (a torus around an unstable orbit, chaos): then the
    run is what its samples say.  ``mode``: the mode of the last sample (a model with modes; by default
    the one it lies in, :func:`mode_there`).

    Examples
    --------
    >>> import grazing
    >>> from grazing.attractors.grid import start_time
    >>> m = grazing.models.impact_damper(mu=0.3, r=0.8, omega=1.408)   # |mu| = 0.996
    >>> run = grazing.simulate(m, [0.0, 0.0, 0.5, 0.0], transient=300, periods=50)
    >>> from grazing.core.period import detect_period
    >>> orbit = polish(m, run.samples, 0.0)
    >>> detect_period(run.samples), orbit.period, orbit.impacts, bool(np.abs(orbit.multipliers).max() < 1)
    (0, 1, 2, True)
    """
    from grazing.orbits.shooting import find_orbit

    s = np.asarray(samples, dtype=float)
    tries = contracting_periods(s, max_period) if candidates is None else list(candidates)
    mode = mode_there(model, s[-1], float(t0)) if mode is None else mode
    for p in tries:
        try:
            orbit = find_orbit(
                model, s[-1], period=int(p), t0=float(t0), max_iter=max_iter, through_stops=False,
                mode=mode,
            )  # fmt: skip
        except (GrazingError, ArithmeticError, np.linalg.LinAlgError):
            continue
        if not orbit.stable or is_neutral(orbit.monodromy, orbit.multipliers):
            continue
        try:
            cycle = cycle_points(model, orbit.state, float(t0), int(p), mode)
        except (GrazingError, ArithmeticError):
            continue
        if not approaches(s, cycle, orbit.abs_lambda):
            continue
        lyapunov = math.log(max(orbit.abs_lambda, 1e-300)) / (p * float(model.period))
        return Polished(int(p), cycle, int(orbit.impacts), np.asarray(orbit.multipliers), lyapunov)
    return None
