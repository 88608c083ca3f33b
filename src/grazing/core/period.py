"""Period detection on stroboscopic samples; a periodic orbit's impacts per period from a count."""

from __future__ import annotations

import math

import numpy as np

from grazing.core.options import MAX_PERIOD, PERIOD_TOL

DEFAULT_PERIOD_TOL = PERIOD_TOL
DEFAULT_MAX_PERIOD = MAX_PERIOD


def sample_scale(samples: np.ndarray) -> float:
    """``max(1, max |s|)`` over the finite entries of ``samples``: the scale that the period tolerances
    are relative to (:data:`~grazing.core.options.PERIOD_TOL`).

    Examples
    --------
    >>> sample_scale(np.array([[0.5, -2.0], [np.inf, np.nan]])), sample_scale(np.array([1e-5]))
    (2.0, 1.0)
    """
    s = np.abs(np.asarray(samples, dtype=float))
    finite = s[np.isfinite(s)]
    return float(max(1.0, finite.max())) if finite.size else 1.0


def detect_period(
    samples: np.ndarray,
    tol: float = DEFAULT_PERIOD_TOL,
    max_period: int = DEFAULT_MAX_PERIOD,
) -> int:
    """Smallest ``p <= max_period`` such that the samples are p-periodic to ``tol``.

    The sequence ``s_0, s_1, ...`` (rows of ``samples``) is p-periodic when
    ``max |s_{i+p} - s_i| <= tol * scale`` over all components and all ``i``, with ``scale`` the
    samples' :func:`sample_scale` (``max(1, max |s|)``: ``tol`` is absolute for samples of size up to
    1, relative beyond).  Only
    periods up to half the number of samples are tested, so that every point
    of a cycle is seen at least twice.  Returns 0 when no period fits
    (chaos, quasi-periodicity, or a transient that has not died out).

    Parameters
    ----------
    samples
        The samples, one per row (shape ``(n,)`` or ``(n, components)``), in
        order; a NaN anywhere makes them aperiodic.
    tol
        Absolute tolerance to which the samples must repeat.
    max_period
        Longest period tried (and at most half the number of samples).

    Returns
    -------
    int
        The smallest period, or 0 when none fits.

    Examples
    --------
    >>> detect_period(np.array([1.0, 2.0, 1.0, 2.0, 1.0, 2.0]))
    2
    >>> detect_period(np.array([0.1, 0.5, 0.3, 0.9]))
    0
    >>> detect_period(1e5 * np.array([1.0, 2.0, 1.0, 2.0]) + [0.0, 0.0, 1e-2, 0.0])  # (in other units)
    2
    >>> detect_period(np.array([1.0, 2.0, 1.0, 2.0 + 1e-4]), tol=1e-3)
    2

    The samples of a simulation (:meth:`grazing.Solution.period` calls it):

    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> detect_period(grazing.simulate(m, [0.0, 0.0], transient=400, periods=20).samples)
    5
    """
    s = np.asarray(samples, dtype=float)
    if s.ndim == 1:
        s = s[:, None]
    return int(detect_periods(s[None], tol, max_period)[0])


def detect_periods(
    samples: np.ndarray,
    tol: float = DEFAULT_PERIOD_TOL,
    max_period: int = DEFAULT_MAX_PERIOD,
) -> np.ndarray:
    """:func:`detect_period` of each run: ``samples`` of shape ``(runs, samples, components)``.

    Examples
    --------
    >>> s = np.array([[[1.0], [2.0], [1.0], [2.0]], [[0.1], [0.5], [0.3], [0.9]]])
    >>> detect_periods(s).tolist()
    [2, 0]
    """
    s = np.asarray(samples, dtype=float)
    if s.ndim != 3:
        raise ValueError(f"samples must have shape (runs, samples, components), got {s.shape}")
    found = np.zeros(s.shape[0], dtype=np.int64)
    todo = np.arange(s.shape[0])
    m = s.shape[1]
    if m == 0:
        return found
    magnitude = np.where(np.isfinite(s), np.abs(s), 0.0)
    scaled = tol * np.maximum(1.0, magnitude.max(axis=(1, 2)))  # (sample_scale of each run)
    for p in range(1, min(max_period, m // 2) + 1):
        if todo.size == 0:
            break
        part = s[todo]
        # (a NaN anywhere makes the maximum NaN, which is not <= tol: not periodic)
        with np.errstate(invalid="ignore"):  # (inf - inf: NaN, not periodic)
            periodic = np.max(np.abs(part[:, p:] - part[:, :-p]), axis=(1, 2)) <= scaled[todo]
        found[todo[periodic]] = p
        todo = todo[~periodic]
    return found


def repeats_with_period(samples: np.ndarray, count: int, tol: float, max_period: int) -> int:
    """:func:`detect_period` of ``samples[:count]`` (rows of a 2-d array), written as loops that make no
    array: the test the sweeps' compiled lanes inline to end a transient once it repeats
    (:mod:`grazing.engine.driver.lanes`).

    The same test as :func:`detect_periods`, one run at a time: a period ``p`` fits when every
    ``|s_{i+p} - s_i| <= tol * scale`` (``scale`` the :func:`sample_scale` of ``samples[:count]``; a
    NaN fails it, as it makes the other's maximum NaN), periods up to ``count // 2``
    (``tests/core/test_period.py`` checks that the two agree).

    Examples
    --------
    >>> repeats_with_period(np.array([[1.0], [2.0], [1.0], [2.0], [9.0]]), 4, 1e-9, 64)
    2
    """
    n = samples.shape[1]
    scale = 1.0
    for i in range(count):
        for c in range(n):
            size = abs(samples[i, c])
            if size > scale and size < math.inf:  # (NaN and inf do not count)
                scale = size
    tol = tol * scale
    for p in range(1, min(max_period, count // 2) + 1):
        ok = True
        for i in range(count - p):
            for c in range(n):
                if not abs(samples[i + p, c] - samples[i, c]) <= tol:  # (NaN: not periodic)
                    ok = False
                    break
            if not ok:
                break
        if ok:
            return p
    return 0


def orbit_impacts(count: np.ndarray, period: np.ndarray, periods: int) -> np.ndarray:
    """Impacts per period of a periodic orbit (per forcing period where ``period`` is 0 or less) from
    ``count``, the impacts in a window of ``periods`` forcing periods (negative: a failed point, nan).

    A period-``p`` orbit with ``k`` impacts per period has ``k`` in every ``p`` forcing periods; the
    window holds ``q = periods // p`` whole ones and a part of one more, so ``k*q <= count <=
    k*(q + 1)``.  Where one whole number ``k`` alone satisfies that, it is the answer, exact (the
    ratio ``count * p / periods`` is off by up to ``k*p/periods``: 33 impacts of a period-3 orbit in
    100 periods gave 0.99); where several do (more impacts in a period than periods in the window),
    the ratio.

    Examples
    --------
    >>> orbit_impacts(np.array([33, 17, 33, 100, 37, -1]), np.array([3, 6, 6, 1, 0, 2]), 100).tolist()
    [1.0, 1.0, 2.0, 1.0, 0.37, nan]
    """
    count = np.asarray(count, dtype=float)
    p = np.broadcast_to(np.maximum(np.asarray(period), 1), count.shape)
    q = periods // p
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = count / periods * p
        low, high = np.ceil(count / (q + 1)), np.floor(count / q)
    exact = (np.asarray(period) > 0) & (q > 0) & (low == high)
    return np.where(count >= 0, np.where(exact, low, ratio), np.nan)
