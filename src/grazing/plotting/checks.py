"""Checks on drawn figures: an axes that shows no data is a figure that went wrong.

A plot can come out blank with nothing raising: the data drawn in radians on an axis set
in degrees, a time span outside the recorded one, an empty selection.  :func:`empty_axes`
finds such axes in a matplotlib figure; the documentation's notebooks run it on every
figure they show (``docs/_ext/ipython_startup.py``), so that a blank figure fails the build.

A saved image can be judged too: :func:`axes_layout` records where each plot area of a
figure lies in the image, its background colour, whether data lie inside its limits and
how far its labels reach; :func:`grazing.outputs.save_png` writes that record into every
PNG grazing saves (a ``grazing:axes`` text chunk, :data:`LAYOUT_KEY`), and
``make check-report`` (:func:`grazing.report.browser.image_problems`) reads it back and
looks at the pixels of each plot area.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

LAYOUT_KEY = "grazing:axes"
"""The PNG text chunk holding a figure's :func:`axes_layout` (JSON)."""


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


def _judged(fig: Any) -> list[tuple[int, Any]]:
    """The axes of ``fig`` that :func:`empty_axes` judges (visible plot areas, colour bars aside), from 1."""
    return [
        (i, ax)
        for i, ax in enumerate(fig.get_axes(), 1)
        if ax.axison and not hasattr(ax, "_colorbar") and ax.get_label() != "<colorbar>"
    ]


def _shows_data(ax: Any) -> bool:
    """Whether one of ``ax``'s artists drawn in data coordinates has a point inside its view limits."""
    artists = [*ax.lines, *ax.collections, *ax.images, *ax.patches]
    drawn = [a for a in artists if a.get_visible() and a.get_transform() is ax.transData]
    drawn += [c for c in ax.collections if c.get_visible() and c.get_offset_transform() is ax.transData
              and len(c.get_offsets()) and c not in drawn]  # fmt: skip
    return any(_in_view(a, ax) for a in drawn)


def _name(i: int, n: int, ax: Any) -> str:
    text = next((t for loc in ("center", "left", "right") if (t := ax.get_title(loc=loc))), "")
    title = f" ({text!r})" if text else ""
    return f"axes {i} of {n}{title}"


def _limits(ax: Any) -> str:
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    return f"x in [{x0:.4g}, {x1:.4g}], y in [{y0:.4g}, {y1:.4g}]"


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
    return [
        f"{_name(i, n, ax)}: no data inside {_limits(ax)}" for i, ax in _judged(fig) if not _shows_data(ax)
    ]


@dataclass(frozen=True)
class AxesLayout:
    """Where one plot area of a saved figure lies, and what it should show.

    Boxes are ``(left, top, right, bottom)`` as fractions of the image's width
    and height, measured from its top-left corner (so that they scale to the
    pixels of the image at any resolution).

    Attributes
    ----------
    name
        ``"axes i of n ('title')"``, as :func:`empty_axes` names it.
    box
        The plot area (inside the axes' frame).
    outer
        Everything the axes draws: tick labels, axis labels and title included.
    facecolor
        The plot area's background, 8-bit RGB.
    data_in_view
        Whether data drawn in data coordinates lie inside the view limits.
    limits
        The view limits, as text.
    """

    name: str
    box: tuple[float, float, float, float]
    outer: tuple[float, float, float, float]
    facecolor: tuple[int, int, int]
    data_in_view: bool
    limits: str


def axes_layout(fig: Any) -> list[AxesLayout]:
    """The :class:`AxesLayout` of every plot area of ``fig`` as last drawn (call it after saving).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import io
    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots(figsize=(4, 3))
    >>> _ = ax.plot([0, 1], [0, 1]); fig.savefig(io.BytesIO(), format="png")
    >>> (layout,) = axes_layout(fig)
    >>> layout.name, layout.data_in_view, layout.facecolor
    ('axes 1 of 1', True, (255, 255, 255))
    >>> [round(v, 3) for v in layout.box]    # matplotlib's default subplot margins
    [0.125, 0.12, 0.9, 0.89]
    >>> plt.close(fig)
    """
    from matplotlib.colors import to_rgb

    n = len(fig.get_axes())
    width, height = fig.bbox.width, fig.bbox.height

    def fractions(bbox: Any) -> tuple[float, float, float, float]:
        x0, y0, x1, y1 = bbox.extents
        return (float(x0 / width), float(1 - y1 / height), float(x1 / width), float(1 - y0 / height))

    out = []
    for i, ax in _judged(fig):
        rgb = tuple(round(255 * c) for c in to_rgb(ax.get_facecolor()))
        out.append(
            AxesLayout(
                name=_name(i, n, ax),
                box=fractions(ax.get_window_extent()),
                outer=fractions(ax.get_tightbbox()),
                facecolor=rgb,  # type: ignore[arg-type]
                data_in_view=_shows_data(ax),
                limits=_limits(ax),
            )
        )
    return out


def layout_text(layouts: list[AxesLayout]) -> str:
    """``layouts`` as the JSON text of a PNG's :data:`LAYOUT_KEY` chunk (read back by :func:`read_layout`)."""
    return json.dumps([asdict(lay) for lay in layouts], separators=(",", ":"))


def read_layout(text: str) -> list[AxesLayout]:
    """The :class:`AxesLayout` list of :func:`layout_text`'s JSON (ValueError if it is not one).

    Examples
    --------
    >>> box = (0.1, 0.1, 0.9, 0.9)
    >>> lay = AxesLayout("axes 1 of 1", box, (0, 0, 1, 1), (255, 255, 255), True, "x in [0, 1]")
    >>> read_layout(layout_text([lay])) == [lay]
    True
    """
    try:
        return [
            AxesLayout(
                name=str(d["name"]),
                box=tuple(float(v) for v in d["box"]),  # type: ignore[arg-type]
                outer=tuple(float(v) for v in d["outer"]),  # type: ignore[arg-type]
                facecolor=tuple(int(v) for v in d["facecolor"]),  # type: ignore[arg-type]
                data_in_view=bool(d["data_in_view"]),
                limits=str(d["limits"]),
            )
            for d in json.loads(text)
        ]
    except (TypeError, KeyError, ValueError) as exc:
        raise ValueError(f"not a figure layout: {exc}") from None
