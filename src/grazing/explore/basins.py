"""The basins of attraction around a clicked point's motion (:func:`grazing.attractors.basins`).

Near a grazing an impacting system often has several attractors at once, and which one a
diagram's chain shows depends on where it came from.  :func:`basins_at` answers for the
clicked parameters: the attractors found from a grid of initial states in the plane of the
first two states, over twice the extent of the clicked motion, and the basin of each.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grazing.errors import InvalidParameterError
from grazing.explore.point import PointReport

__all__ = ["BASIN_GRID", "BasinView", "basins_at"]

BASIN_GRID = (40, 40)
"""Initial states of the basins' grid (along the first state, along the second)."""


@dataclass(frozen=True)
class BasinView:
    """Basins on a grid: its ranges (model units) and initial states along each, each initial state's
    attractor label (0: beyond a stop), each attractor's kind, period and points, and one line per
    attractor."""

    x_range: tuple[float, float]
    y_range: tuple[float, float]
    num: tuple[int, int]
    label: np.ndarray
    kinds: tuple[str, ...]
    periods: tuple[int, ...]
    points: tuple[np.ndarray, ...]
    lines: tuple[str, ...]


def basins_at(point: PointReport, num: tuple[int, int] = BASIN_GRID) -> BasinView:
    """The basins of attraction at the clicked parameters, over twice the extent of its motion.

    Raises
    ------
    InvalidParameterError
        A model with one state (no plane of initial states).
    """
    from grazing.attractors import basins

    model = point.model
    if model.n_states < 2:
        raise InvalidParameterError(
            f"model {model.name} has one state: no plane of initial states for basins"
        )
    ranges = []
    for i in (0, 1):
        lo, hi = float(np.min(point.trajectory[:, i])), float(np.max(point.trajectory[:, i]))
        half = max(hi - lo, 1e-3 * max(1.0, abs(lo)))
        ranges.append((lo - half / 2, hi + half / 2))
    ds = basins(model, ranges[0], ranges[1], num)
    lines = []
    for k, (kind, period, ipp, fraction) in enumerate(
        zip(ds.kind.values, ds.period.values, ds.impacts_per_period.values, ds.fraction.values)
    ):
        if kind == "invalid":
            lines.append(f"beyond a stop (not run): {fraction:.1%} of the grid")
            continue
        what = f"period {period} with {ipp:g} impacts per period" if period > 0 else "no period"
        lines.append(f"attractor {k}: {kind}, {what}: {fraction:.1%} of the grid")
    points = tuple(ds.points.values[k, : int(n)] for k, n in enumerate(ds.n_points.values))
    return BasinView(
        x_range=ranges[0],
        y_range=ranges[1],
        num=(int(num[0]), int(num[1])),
        label=ds.label.values,
        kinds=tuple(ds.kind.values.tolist()),
        periods=tuple(int(p) for p in ds.period.values),
        points=points,
        lines=tuple(lines),
    )
