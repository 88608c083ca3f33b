"""The colours of detected periods: one palette for the report, the docs and ``grazing explore``.

A point's period class (:func:`period_codes`) is one of: failed, aperiodic (no period found
up to the detection limit), period 1 without impacts, period 1 with impacts, periods 2 ...
``max_period``, longer.  :func:`~grazing.plotting.diagrams.plot_period_map` (the report's
and the docs' period maps) and the explorer's diagram and map colour them with
:func:`class_colours` and name them with :func:`class_labels`.  Plain data: no matplotlib,
no Bokeh.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "APERIODIC_COLOUR",
    "FAILED_COLOUR",
    "IMPACTING_ONE_COLOUR",
    "LONGER_COLOUR",
    "MAX_PERIOD",
    "MODE_COLOURS",
    "NONIMPACTING_ONE_COLOUR",
    "PERIOD_COLOURS",
    "class_colours",
    "class_labels",
    "period_codes",
]

MAX_PERIOD = 8
"""The longest period with a colour of its own (longer ones share :data:`LONGER_COLOUR`)."""

PERIOD_COLOURS = ("#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
                  "#17becf", "#bcbd22", "#7f7f7f", "#aec7e8", "#ffbb78", "#98df8a")  # fmt: skip
"""The colours of periods 2, 3, 4, ... in turn (repeated past the 13th)."""

MODE_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22")
"""The shading of the modes of a model with modes, in the order of its ``mode_names`` (repeated)."""

FAILED_COLOUR = "#ffffff"
"""A point whose simulation failed (white: no data)."""

APERIODIC_COLOUR = "#000000"
"""No period found up to the detection limit (chaos, or a long transient)."""

NONIMPACTING_ONE_COLOUR = "#bdbdbd"
"""The period-1 motion without impacts (mid grey: a background on a map, still visible as dots)."""

IMPACTING_ONE_COLOUR = "#9ecae1"
"""A period-1 motion with impacts (light blue)."""

LONGER_COLOUR = "#f7b6d2"
"""A period longer than the longest with a colour of its own."""


def period_codes(
    period: np.ndarray, impacts_per_period: np.ndarray, max_period: int = MAX_PERIOD
) -> np.ndarray:
    """The class of each point: 0 failed (period -1), 1 aperiodic (0), 2 period 1 without impacts,
    3 period 1 with impacts, ``p + 2`` for periods 2 ... ``max_period``, ``max_period + 3`` longer.

    Examples
    --------
    >>> period_codes(np.array([-1, 0, 1, 1, 5, 12]), np.array([0, 3, 0, 1, 1, 1]), 8).tolist()
    [0, 1, 2, 3, 7, 11]
    """
    period = np.asarray(period, dtype=int)
    imp = np.asarray(impacts_per_period, dtype=float) > 0
    codes = np.where(period == 0, 1, 0)  # failed points (period -1) stay 0
    codes = np.where(period == 1, np.where(imp, 3, 2), codes)
    codes = np.where((period >= 2) & (period <= max_period), period + 2, codes)
    return np.where(period > max_period, max_period + 3, codes)


def class_labels(max_period: int = MAX_PERIOD) -> list[str]:
    """The name of each class of :func:`period_codes`.

    Examples
    --------
    >>> class_labels(3)
    ['failed', 'aperiodic', '1, no impacts', '1, impacting', '2', '3', '> 3']
    """
    return ["failed", "aperiodic", "1, no impacts", "1, impacting"] + [
        str(p) for p in range(2, max_period + 1)
    ] + [f"> {max_period}"]  # fmt: skip


def class_colours(max_period: int = MAX_PERIOD) -> list[str]:
    """The colour of each class of :func:`period_codes`.

    Examples
    --------
    >>> class_colours(3)
    ['#ffffff', '#000000', '#bdbdbd', '#9ecae1', '#d62728', '#1f77b4', '#f7b6d2']
    """
    colours = [FAILED_COLOUR, APERIODIC_COLOUR, NONIMPACTING_ONE_COLOUR, IMPACTING_ONE_COLOUR]
    colours += [PERIOD_COLOURS[(p - 2) % len(PERIOD_COLOURS)] for p in range(2, max_period + 1)]
    return [*colours, LONGER_COLOUR]
