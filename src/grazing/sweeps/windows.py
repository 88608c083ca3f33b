"""Periodic windows of a one-parameter sweep, and their comparison between two sweeps."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Window:
    """A run of consecutive sweep points with the same detected period.

    Attributes
    ----------
    period
        The period (0 for a run of aperiodic points).
    start, end
        First and last parameter value of the run.
    count
        Number of points.
    """

    period: int
    start: float
    end: float
    count: int

    @property
    def width(self) -> float:
        return self.end - self.start


def window_runs(values: np.ndarray, periods: np.ndarray, min_points: int = 2) -> list[Window]:
    """Maximal runs of equal period in a sweep ordered by parameter value.

    Runs shorter than ``min_points`` are dropped (isolated points are not windows).

    Examples
    --------
    >>> window_runs(np.arange(8.0), np.array([1, 1, 0, 3, 3, 3, 0, 2]))
    [Window(period=1, start=0.0, end=1.0, count=2), Window(period=3, start=3.0, end=5.0, count=3)]
    """
    v = np.asarray(values, dtype=float)
    p = np.asarray(periods)
    order = np.argsort(v)
    v, p = v[order], p[order]
    out: list[Window] = []
    i = 0
    while i < v.size:
        j = i
        while j + 1 < v.size and p[j + 1] == p[i]:
            j += 1
        if j - i + 1 >= min_points and p[i] > 0:
            out.append(Window(int(p[i]), float(v[i]), float(v[j]), j - i + 1))
        i = j + 1
    return out


@dataclass(frozen=True)
class WindowComparison:
    """The same period's window in a reference sweep and in another one."""

    period: int
    reference: Window
    other: Window | None
    distance: float  # from the grazing value to the reference window's start

    @property
    def start_error(self) -> float:
        return float("nan") if self.other is None else self.other.start - self.reference.start

    @property
    def end_error(self) -> float:
        return float("nan") if self.other is None else self.other.end - self.reference.end


def compare_windows(
    values: np.ndarray, reference: np.ndarray, other: np.ndarray, origin: float, min_points: int = 2
) -> list[WindowComparison]:
    """Pair each window of ``reference`` (e.g. direct simulation) with ``other``'s window of that period.

    Windows are ordered by their distance from ``origin`` (the grazing value);
    when a period has several windows, the one nearest to the reference
    window is paired.
    """
    ref = window_runs(values, reference, min_points)
    oth = window_runs(values, other, min_points)
    rows = []
    for w in sorted(ref, key=lambda w: abs(w.start - origin)):
        same = [o for o in oth if o.period == w.period]
        best = min(same, key=lambda o: abs(o.start - w.start) + abs(o.end - w.end)) if same else None
        rows.append(WindowComparison(w.period, w, best, abs(w.start - origin)))
    return rows
