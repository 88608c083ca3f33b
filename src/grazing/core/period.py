"""Period detection on stroboscopic samples."""

from __future__ import annotations

import numpy as np

from grazing.core.options import MAX_PERIOD, PERIOD_TOL

DEFAULT_PERIOD_TOL = PERIOD_TOL
DEFAULT_MAX_PERIOD = MAX_PERIOD


def detect_period(
    samples: np.ndarray,
    tol: float = DEFAULT_PERIOD_TOL,
    max_period: int = DEFAULT_MAX_PERIOD,
) -> int:
    """Smallest ``p <= max_period`` such that the samples are p-periodic to ``tol``.

    The sequence ``s_0, s_1, ...`` (rows of ``samples``) is p-periodic when
    ``max |s_{i+p} - s_i| <= tol`` over all components and all ``i``.  Only
    periods up to half the number of samples are tested, so that every point
    of a cycle is seen at least twice.  Returns 0 when no period fits
    (chaos, quasi-periodicity, or a transient that has not died out).

    Examples
    --------
    >>> detect_period(np.array([1.0, 2.0, 1.0, 2.0, 1.0, 2.0]))
    2
    >>> detect_period(np.array([0.1, 0.5, 0.3, 0.9]))
    0
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
    for p in range(1, min(max_period, m // 2) + 1):
        if todo.size == 0:
            break
        part = s[todo]
        # (a NaN anywhere makes the maximum NaN, which is not <= tol: not periodic)
        periodic = np.max(np.abs(part[:, p:] - part[:, :-p]), axis=(1, 2)) <= tol
        found[todo[periodic]] = p
        todo = todo[~periodic]
    return found
