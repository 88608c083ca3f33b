"""Checks on drawn figures: an axes that shows no data is a figure that went wrong.

A plot can come out blank with nothing raising: the data drawn in radians on an axis set
in degrees, a time span outside the recorded one, an empty selection.  :func:`empty_axes`
finds such axes in a matplotlib figure; the documentation's notebooks run it on every
figure they show (``docs/_ext/ipython_startup.py``), so that a blank figure fails the build.
A saved figure is judged from the record of its plot areas (:mod:`grazing.plot_areas`).
"""

from __future__ import annotations

from typing import Any

from grazing.plot_areas import axes_name, judged, shows_data, view_limits


def empty_axes(fig: Any) -> list[str]:
    """The axes of ``fig`` that show no data, one line each.

    An axes shows data when one of its lines, collections, images or patches
    drawn in data coordinates has a finite point inside its view limits.
    Reference lines and spans (``axhline``, ``axvspan``: partly in axes
    coordinates), text, colour bars and axes turned off do not count and are
    not judged.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> fig, (a, b) = plt.subplots(1, 2)
    >>> _ = a.plot([0, 1], [0, 1]); _ = b.plot([5, 6], [5, 6]); _ = b.axhline(0.5)
    >>> _ = b.set(xlim=(0, 1), ylim=(0, 1), title="outside")
    >>> empty_axes(fig)
    ["axes 2 of 2 ('outside'): no data inside x in [0, 1], y in [0, 1]"]
    >>> plt.close(fig)
    """
    n = len(fig.get_axes())
    empty = [(i, ax) for i, ax in judged(fig) if not shows_data(ax)]
    return [f"{axes_name(i, n, ax)}: no data inside {view_limits(ax)}" for i, ax in empty]
