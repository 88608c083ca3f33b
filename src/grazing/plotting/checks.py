"""Checks on drawn figures: an axes that shows no data is a figure that went wrong.

A plot can come out blank with nothing raising: the data drawn in radians on an axis set
in degrees, a time span outside the recorded one, an empty selection.  :func:`empty_axes`
finds such axes in a matplotlib figure; the documentation's notebooks run it on every
figure they show (``docs/_ext/ipython_startup.py``), so that a blank figure fails the build.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def _in_view(artist: Any, ax: Any) -> bool:
    """Whether ``artist`` (drawn in data coordinates) has something inside the axes' view limits."""
    from matplotlib.collections import Collection
    from matplotlib.image import AxesImage
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())

    def inside(xy: np.ndarray) -> bool:
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        ok = np.all(np.isfinite(xy), axis=1)
        x, y = xy[ok, 0], xy[ok, 1]
        return bool(np.any((x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)))

    def overlaps(bx0: float, bx1: float, by0: float, by1: float) -> bool:
        return min(bx0, bx1) <= x1 and max(bx0, bx1) >= x0 and min(by0, by1) <= y1 and max(by0, by1) >= y0

    if isinstance(artist, Line2D):
        return inside(artist.get_xydata())
    if isinstance(artist, AxesImage):
        left, right, bottom, top = artist.get_extent()
        return overlaps(left, right, bottom, top)
    if isinstance(artist, Collection):
        offsets = artist.get_offsets()
        if len(offsets) and artist.get_offset_transform() is ax.transData:
            return inside(offsets)
        lim = artist.get_datalim(ax.transData)
        return bool(np.all(np.isfinite(lim.extents))) and overlaps(*lim.intervalx, *lim.intervaly)
    if isinstance(artist, Patch):
        ext = artist.get_path().get_extents(artist.get_patch_transform())
        return overlaps(*ext.intervalx, *ext.intervaly)
    return True


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
    out = []
    axes = fig.get_axes()
    for i, ax in enumerate(axes, 1):
        if not ax.axison or hasattr(ax, "_colorbar") or ax.get_label() == "<colorbar>":
            continue
        artists = [*ax.lines, *ax.collections, *ax.images, *ax.patches]
        drawn = [a for a in artists if a.get_visible() and a.get_transform() is ax.transData]
        drawn += [c for c in ax.collections if c.get_visible() and c.get_offset_transform() is ax.transData
                  and len(c.get_offsets()) and c not in drawn]  # fmt: skip
        if any(_in_view(a, ax) for a in drawn):
            continue
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        title = f" ({ax.get_title()!r})" if ax.get_title() else ""
        limits = f"x in [{x0:.4g}, {x1:.4g}], y in [{y0:.4g}, {y1:.4g}]"
        out.append(f"axes {i} of {len(axes)}{title}: no data inside {limits}")
    return out
