"""Periodic windows of a one-parameter sweep, and their comparison between two sweeps."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Window:
    """A run of consecutive sweep points with the same detected period.

    Attributes
    ----------
    period
        The detected period (0: aperiodic, no period up to the detection
        limit; -1: the point could not be simulated).
    impacting
        Whether the points have impacts (a nonimpacting period-1 orbit and an
        impacting one are different windows).
    first, last
        Indices of the first and last point of the run (in increasing
        parameter order).
    start, stop
        Parameter values of the first and last point (in the dataset's units,
        radians for angles).
    lo, hi
        The extent of the run on the parameter axis: half-way to the
        neighbouring points outside it (the end points at the ends of the sweep).

    Examples
    --------
    :func:`find_windows` splits a sweep into windows:

    >>> import math, numpy as np, grazing
    >>> from grazing.sweeps import sweep
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> ds = sweep(m, "eta", np.linspace(0.44, 0.45, 5), transient=300, periods=40, lyapunov=False, workers=1)
    >>> [(w.label, w.points, w.start) for w in find_windows(ds)]
    [('1 (no impacts)', 3, 0.44), ('4', 1, 0.4475), ('aperiodic', 1, 0.45)]
    >>> w = find_windows(ds)[1]
    >>> w.period, w.impacting, round(w.lo, 5), round(w.hi, 5), round(w.width, 4)
    (4, True, 0.44625, 0.44875, 0.0025)
    """

    period: int
    impacting: bool
    first: int
    last: int
    start: float
    stop: float
    lo: float
    hi: float

    @property
    def points(self) -> int:
        """Number of sweep points in the run."""
        return self.last - self.first + 1

    @property
    def width(self) -> float:
        """``hi - lo``: the extent of the run on the parameter axis."""
        return self.hi - self.lo

    @property
    def center(self) -> float:
        """Middle of the run's extent."""
        return 0.5 * (self.lo + self.hi)

    @property
    def label(self) -> str:
        """``"5"``, ``"1 (no impacts)"``, ``"aperiodic"`` or ``"failed"``."""
        if self.period > 0:
            return f"{self.period}" if self.impacting or self.period > 1 else "1 (no impacts)"
        return "aperiodic" if self.period == 0 else "failed"


def find_windows(ds: Any) -> list[Window]:
    """Split a one-parameter sweep into runs of equal period (and impacting or not).

    Parameters
    ----------
    ds
        A dataset from :func:`grazing.sweeps.sweep` (variables ``period`` and
        ``impacts_per_period`` along ``point``, coordinate ``value``).

    Returns
    -------
    list of Window
        Every run, in increasing parameter order, covering all points:
        periodic windows, aperiodic stretches (period 0) and failed points
        (period -1) alike.  Filter them as needed.

    Examples
    --------
    >>> import xarray as xr
    >>> ds = xr.Dataset(
    ...     {"period": ("point", [1, 1, 0, 3, 3, 3, 1]),
    ...      "impacts_per_period": ("point", [0, 0, 0.7, 1, 1, 1, 1.0])},
    ...     coords={"value": ("point", [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7])})
    >>> [(w.label, w.points) for w in find_windows(ds)]
    [('1 (no impacts)', 2), ('aperiodic', 1), ('3', 3), ('1', 1)]
    >>> w = find_windows(ds)[2]
    >>> round(w.lo, 3), round(w.hi, 3)
    (0.35, 0.65)
    """
    order = np.argsort(np.asarray(ds["value"].values, dtype=float), kind="stable")
    value = np.asarray(ds["value"].values, dtype=float)[order]
    period = np.asarray(ds["period"].values, dtype=int)[order]
    impacting = np.asarray(ds["impacts_per_period"].values, dtype=float)[order] > 0
    n = value.size
    if n == 0:
        return []
    # boundaries of the runs: where the period or the impacting flag changes
    change = np.flatnonzero((np.diff(period) != 0) | (np.diff(impacting) != 0)) + 1
    starts = np.concatenate(([0], change))
    ends = np.concatenate((change - 1, [n - 1]))
    mid = 0.5 * (value[1:] + value[:-1])
    out = []
    for i, j in zip(starts, ends):
        lo = value[0] if i == 0 else mid[i - 1]
        hi = value[-1] if j == n - 1 else mid[j]
        out.append(
            Window(
                period=int(period[i]), impacting=bool(impacting[i]), first=int(i), last=int(j),
                start=float(value[i]), stop=float(value[j]), lo=float(lo), hi=float(hi),
            )
        )  # fmt: skip
    return out


@dataclass(frozen=True)
class WindowComparison:
    """The same window in a reference sweep (e.g. direct simulation) and in another one (e.g. the map)."""

    period: int
    reference: Window
    other: Window | None
    distance: float  # from the grazing value to the reference window's start

    @property
    def start_error(self) -> float:
        return float("nan") if self.other is None else self.other.start - self.reference.start

    @property
    def end_error(self) -> float:
        return float("nan") if self.other is None else self.other.stop - self.reference.stop


@dataclass(frozen=True)
class Hysteresis:
    """A run of consecutive values where a sweep up and a sweep down end on different attractors.

    Attributes
    ----------
    first, last
        Indices of the first and last point of the run (in increasing parameter order).
    start, stop
        Their parameter values (in the dataset's units).
    up, down
        The window labels (:attr:`Window.label`) of the two sweeps at the run's first point.
    """

    first: int
    last: int
    start: float
    stop: float
    up: str
    down: str

    @property
    def points(self) -> int:
        return self.last - self.first + 1


def orbits_differ(a: np.ndarray, b: np.ndarray, period: int, tol: float) -> bool:
    """Whether two runs of samples (``(samples, components)``) of one ``period`` are on different orbits.

    The last ``period`` samples of each are the orbit's points: the orbits differ when a point of one is
    farther than ``tol`` (in every component's largest difference) from every point of the other.

    Examples
    --------
    >>> a = np.array([[0.0], [1.0], [0.0], [1.0]])
    >>> orbits_differ(a, a[::-1], 2, 1e-9), orbits_differ(a, a + 0.5, 2, 1e-9)
    (False, True)
    """
    pa, pb = a[-period:], b[-period:]
    d = np.max(np.abs(pa[:, None, :] - pb[None, :, :]), axis=2)  # (points of a, points of b)
    return bool(max(d.min(axis=1).max(), d.min(axis=0).max()) > tol)


def find_hysteresis(ds: Any, tol: float = 1e-4) -> list[Hysteresis]:
    """The runs of values where a sweep with ``direction = "both"`` ends differently up and down.

    Two points differ when their statuses, periods or impacting differ, or when
    both are periodic with one period on different orbits (:func:`orbits_differ`,
    ``tol``; not compared without ``samples`` in ``ds``).  Aperiodic points of
    both directions count as alike.

    Examples
    --------
    >>> import xarray as xr
    >>> per = [[1, 1, 2, 2], [1, 3, 3, 2]]
    >>> ds = xr.Dataset(
    ...     {"period": (("direction", "point"), per),
    ...      "impacts_per_period": (("direction", "point"), np.ones((2, 4))),
    ...      "status": (("direction", "point"), np.zeros((2, 4), dtype=int)),
    ...      "samples": (("direction", "point", "sample", "component"), np.zeros((2, 4, 6, 1)))},
    ...     coords={"direction": ["up", "down"], "value": ("point", [0.1, 0.2, 0.3, 0.4])})
    >>> [(h.start, h.stop, h.up, h.down) for h in find_hysteresis(ds)]
    [(0.2, 0.3, '1', '3')]
    """
    up, down = ds.sel(direction="up"), ds.sel(direction="down")
    order = np.argsort(np.asarray(ds["value"].values, dtype=float), kind="stable")
    value = np.asarray(ds["value"].values, dtype=float)[order]
    pu, pd = (np.asarray(x["period"].values, dtype=int)[order] for x in (up, down))
    iu, idn = ((np.asarray(x["impacts_per_period"].values, dtype=float)[order] > 0) for x in (up, down))
    su, sd = (np.asarray(x["status"].values, dtype=int)[order] for x in (up, down))
    differ = (su != sd) | (pu != pd) | (iu != idn)
    if "samples" in ds:
        xu, xd = (np.asarray(x["samples"].values, dtype=float)[order] for x in (up, down))
        for k in np.flatnonzero(~differ & (pu > 0) & (su == 0)):
            differ[k] = orbits_differ(xu[k], xd[k], int(pu[k]), tol)

    def label(period: int, impacting: bool) -> str:
        return Window(period, impacting, 0, 0, 0.0, 0.0, 0.0, 0.0).label

    out = []
    k = 0
    n = value.size
    while k < n:
        if not differ[k]:
            k += 1
            continue
        j = k
        while j + 1 < n and differ[j + 1]:
            j += 1
        out.append(
            Hysteresis(k, j, float(value[k]), float(value[j]), label(pu[k], iu[k]), label(pd[k], idn[k]))
        )
        k = j + 1
    return out
