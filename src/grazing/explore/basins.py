"""The basins of attraction around a clicked point's motion (:func:`grazing.attractors.basins`).

Near a grazing an impacting system often has several attractors at once, and which one a
diagram's chain shows depends on where it came from.  :func:`basins_at` answers for the
clicked parameters: the attractors found from a grid of initial states in the plane of the
first two states, over twice the extent of the clicked motion (less what lies beyond a stop),
and the basin of each.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grazing.attractors.kinds import AttractorKind
from grazing.core.model import HybridModel
from grazing.errors import InvalidParameterError
from grazing.explore.point import PointReport

__all__ = ["BASIN_GRID", "BasinView", "basins_at"]

BASIN_GRID = (40, 40)
"""Initial states of the basins' grid (along the first state, along the second)."""

CLIP_PROBE = 8
"""The grid is clipped to the stops on a probe this many times finer than it along each side."""


@dataclass(frozen=True)
class BasinView:
    """Basins on a grid: its ranges (model units) and initial states along each, each initial state's
    attractor label (0: beyond a stop), each attractor's id (the label of its basin), kind, period and
    points, and one line per attractor."""

    x_range: tuple[float, float]
    y_range: tuple[float, float]
    num: tuple[int, int]
    label: np.ndarray
    ids: tuple[int, ...]
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
    ranges = within_stops(model, ranges, num)
    ds = basins(model, ranges[0], ranges[1], num)
    lines = []
    columns = ("attractor", "kind", "period", "impacts_per_period", "fraction")
    for k, kind, period, ipp, fraction in zip(*(ds[c].values for c in columns)):
        if kind == AttractorKind.INVALID:
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
        ids=tuple(int(i) for i in ds.attractor.values),
        kinds=tuple(ds.kind.values.tolist()),
        periods=tuple(int(p) for p in ds.period.values),
        points=points,
        lines=tuple(lines),
    )


Ranges = list[tuple[float, float]]


def within_stops(model: HybridModel, ranges: Ranges, num: tuple[int, int]) -> Ranges:
    """``ranges`` (of the first two states) less the columns and rows of initial states that all lie
    beyond a stop (not run: the basins would show them blank), on a probe grid :data:`CLIP_PROBE`
    times finer; unchanged where none or all do.  In a model with modes, beyond a stop is in no mode's
    region (:func:`grazing.attractors.basins.outside`: a soft stop's contact is a mode, not beyond it).

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> [round(v, 3) for v in within_stops(m, [(-1.4, 1.4), (-2.0, 2.0)], (40, 40))[0]]
    [-1.4, 0.698]
    """
    from grazing.attractors.basins import outside
    from grazing.attractors.grid import start_time, state_grid

    probe = tuple(CLIP_PROBE * max(2, int(n)) for n in num)
    grid = state_grid(model, ranges[0], ranges[1], probe)
    beyond = outside(model, grid.states_array(), start_time(model, 0.0)).reshape(grid.shape)
    if beyond.all() or not beyond.any():
        return ranges
    xs, ys = grid.x[~beyond.all(axis=0)], grid.y[~beyond.all(axis=1)]
    return [(float(xs.min()), float(xs.max())), (float(ys.min()), float(ys.max()))]
