"""Plots of brute-force sweeps: bifurcation diagrams with their periodic windows, period maps.

For the datasets of :func:`grazing.sweeps.sweep` and
:func:`grazing.sweeps.parameter_map`: :func:`plot_bifurcation` draws a
bifurcation diagram with its periodic windows labelled
(:func:`~grazing.sweeps.windows.find_windows`, :func:`visible_windows`,
:func:`label_windows`), :func:`mark_grazings` marks grazing points, and
:func:`plot_period_map` colours a two-parameter map by period.  Axis labels,
units and angles come from the dataset's metadata.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from grazing.plotting.labels import (
    angle_scale,
    dataset_parameter,
    dataset_states,
    param_label,
    param_scale,
    period_text,
    state_scale,
    state_unit,
    swept_parameter,
    with_unit,
)
from grazing.plotting.palette import class_colours, class_labels, period_codes
from grazing.sweeps.windows import Window, find_windows

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes


def visible_windows(
    windows: list[Window],
    span: float,
    *,
    min_period: int = 2,
    min_points: int = 3,
    min_fraction: float = 0.005,
    impacting_one: bool = True,
) -> list[Window]:
    """The periodic windows wide enough to be labelled on a diagram.

    Parameters
    ----------
    windows
        From :func:`find_windows`.
    span
        Width of the parameter axis (same units as the windows).
    min_period
        Smallest period labelled (period 1 with impacts is added by
        ``impacting_one``; nonimpacting period 1 is never in the list).
    min_points
        Fewest sweep points a window must hold.
    min_fraction
        Smallest width of a window as a fraction of ``span``.
    impacting_one
        Also keep impacting period-1 windows.

    Returns
    -------
    list of Window
        The windows kept, in the order given.

    Examples
    --------
    >>> ws = [Window(4, True, 0, 9, 0.0, 0.9, 0.0, 0.95), Window(5, True, 10, 10, 1.0, 1.0, 0.95, 1.05)]
    >>> [w.period for w in visible_windows(ws, 10.0)]
    [4]
    """
    out = []
    for w in windows:
        keep = w.period >= max(min_period, 2) or (impacting_one and w.period == 1 and w.impacting)
        if keep and w.points >= min_points and w.width >= min_fraction * span:
            out.append(w)
    return out


BAR_DROP = 0.25
"""How far a window's bar sits below its label's baseline, in units of the font size."""


def label_rows(height_pt: float, fontsize: float, count: int = 3) -> tuple[float, ...]:
    """Heights (axes fractions) of ``count`` label rows in axes ``height_pt`` points tall.

    A label's text (about 1.2 font sizes tall with its descent) sits on its
    row and its bar :data:`BAR_DROP` font sizes below; rows are 2 font sizes
    apart, which leaves half a font size between a text and the bar above it.

    Examples
    --------
    >>> [round(y, 3) for y in label_rows(200.0, 10.0)]
    [0.935, 0.835, 0.735]
    """
    top = 1.0 - 1.3 * fontsize / height_pt
    step = 2.0 * fontsize / height_pt
    return tuple(top - k * step for k in range(count))


def label_windows(
    ax: Axes,
    windows: list[Window],
    *,
    scale: float = 1.0,
    rows: tuple[float, ...] | None = None,
    fontsize: float = 9.0,
    min_gap: float = 0.006,
    color: str = "tab:blue",
) -> list[Window]:
    """Write the period above each window, with a bar showing its extent, without collisions.

    The labels sit near the top of the axes (``rows`` in axes fractions), each
    text above its bar.  Each label occupies its bar and its text (estimated
    from the font size and the axes width); the windows are placed widest
    first, each on the first row
    where it collides with nothing already placed there, ``min_gap`` (axes
    fraction) apart.  A window that fits on no row is left unlabelled: the
    caller lists the windows in a table anyway.  Draw the diagram and set the x
    limits first.

    Parameters
    ----------
    ax
        The diagram's axes.
    windows
        The windows to label (e.g. from :func:`visible_windows`).
    scale
        Factor from the windows' parameter units to the x axis (``180/pi``
        for an angle shown in degrees).
    rows
        Heights of the label rows, in axes fractions (default: three rows
        :func:`label_rows` apart, so that a text never touches the bar of the
        row above).
    fontsize
        Font size of the labels.
    min_gap
        Smallest distance between two labels' extents on one row, in axes fractions.
    color
        Colour of the labels and bars.

    Returns
    -------
    list of Window
        The windows labelled, in the order given.

    Examples
    --------
    Two windows far apart share the first row; one too close to the first
    goes to the next row:

    >>> from matplotlib.figure import Figure
    >>> from grazing.sweeps.windows import Window
    >>> ax = Figure().add_subplot()
    >>> _ = ax.set_xlim(0.0, 1.0)
    >>> ws = [Window(3, True, 0, 5, 0.10, 0.15, 0.10, 0.15),
    ...       Window(5, True, 6, 7, 0.135, 0.145, 0.135, 0.145),
    ...       Window(2, True, 8, 20, 0.5, 0.8, 0.5, 0.8)]
    >>> [w.period for w in label_windows(ax, ws)], [t.get_text() for t in ax.texts]
    ([3, 5, 2], ['3', '5', '2'])
    >>> ys = [t.get_position()[1] for t in ax.texts]
    >>> bool(ys[0] == ys[2] != ys[1])
    True
    """
    x0, x1 = ax.get_xlim()
    trans = ax.get_xaxis_transform()  # x in data, y in axes fraction
    width_pt = max(ax.get_position().width * ax.figure.get_figwidth() * 72.0, 1.0)
    height_pt = max(ax.get_position().height * ax.figure.get_figheight() * 72.0, 1.0)
    rows = label_rows(height_pt, fontsize) if rows is None else rows
    bar_drop = BAR_DROP * fontsize / height_pt

    def extent(w: Window) -> tuple[float, float]:
        c = (w.center * scale - x0) / (x1 - x0)
        half_text = 0.5 * 0.62 * fontsize * len(w.label.split(" ")[0]) / width_pt
        lo = min((w.lo * scale - x0) / (x1 - x0), c - half_text)
        hi = max((w.hi * scale - x0) / (x1 - x0), c + half_text)
        return lo, hi

    taken: list[list[tuple[float, float]]] = [[] for _ in rows]
    placed: dict[int, int] = {}
    for k in sorted(range(len(windows)), key=lambda i: -windows[i].width):
        lo, hi = extent(windows[k])
        for r, row in enumerate(taken):
            if all(hi + min_gap <= a or lo - min_gap >= b for a, b in row):
                row.append((lo, hi))
                placed[k] = r
                break
    out = []
    for k, w in enumerate(windows):
        if k not in placed:
            continue
        y = rows[placed[k]]
        c = w.center * scale
        ax.plot([w.lo * scale, w.hi * scale], [y - bar_drop, y - bar_drop], transform=trans, color=color,
                lw=1.4, solid_capstyle="butt", clip_on=False)  # fmt: skip
        ax.text(c, y, w.label.split(" ")[0], transform=trans, ha="center", va="bottom",
                fontsize=fontsize, color=color, clip_on=False)  # fmt: skip
        out.append(w)
    return out


def mark_grazings(
    ax: Axes,
    values: list[float] | np.ndarray,
    *,
    scale: float = 1.0,
    labels: list[str] | None = None,
    color: str = "tab:red",
    fontsize: float = 9.0,
) -> None:
    """Mark grazing points as dashed vertical lines (labelled at the bottom).

    Parameters
    ----------
    ax
        Axes whose x axis is the swept parameter.
    values
        Parameter values of the grazings (in the units before ``scale``).
    scale
        Factor to the x axis units.
    labels
        One text per line (default: the value, e.g. ``"0.4451"``).
    color, fontsize
        Style of the lines and labels.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> ax = Figure().add_subplot()
    >>> _ = ax.set_xlim(0.40, 0.60)
    >>> mark_grazings(ax, [0.44512, 0.54729])
    >>> [line.get_xdata()[0] for line in ax.lines], [t.get_text() for t in ax.texts]
    ([0.44512, 0.54729], [' 0.4451', ' 0.5473'])
    """
    trans = ax.get_xaxis_transform()
    for k, v in enumerate(values):
        x = float(v) * scale
        ax.axvline(x, color=color, lw=0.9, ls="--", zorder=1)
        text = labels[k] if labels is not None else f"{x:.4g}"
        ax.text(x, 0.015, f" {text}", transform=trans, rotation=90, ha="right", va="bottom",
                fontsize=fontsize, color=color,
                bbox={"fc": "white", "ec": "none", "alpha": 0.75, "pad": 0.8})  # fmt: skip


def plot_bifurcation(
    ax: Axes,
    ds: Any,
    *,
    component: int = 0,
    degrees: bool = True,
    windows: bool = True,
    nonimpacting: bool = True,
    stop: bool = False,
    label: str | None = None,
    dot_kw: dict[str, Any] | None = None,
    window_kw: dict[str, Any] | None = None,
) -> list[Window]:
    """Draw a brute-force bifurcation diagram: the sampled states against the parameter.

    Every stroboscopic sample of every point is a small black dot, as in the
    paper's figs 2, 7, 8, 10 and 12.  Works for any one-parameter dataset of
    :func:`grazing.sweeps.sweep` (direct simulation or discontinuity map); a
    sweep up and down (``direction="both"``) is drawn in two colours
    (:data:`DIRECTION_COLORS`, with a legend), its windows labelled from the
    sweep up.

    Parameters
    ----------
    ax
        Axes to draw on.
    ds
        The sweep's dataset.
    component
        Which state component to plot.
    degrees
        Show angles in degrees: the state component if its unit is radians
        (as :func:`~grazing.plotting.trajectories.plot_time_series` does) and
        the parameter if it is an angle.
    windows
        Label the periodic windows (:func:`visible_windows` with its defaults,
        or ``window_kw`` passed to it) with :func:`label_windows`.
    nonimpacting
        Shade the parameter ranges where the motion has no impacts (and say so
        when the range is wide enough); for a sweep up and down, where both
        sweeps have none, and hatch in a sweep's colour where it alone has none.
    stop
        Draw the stop where it is a level of this component (the dataset's
        ``stop_level``): a horizontal line, or a slanted one when the swept
        parameter moves it (off by default: the samples at a fixed forcing
        phase seldom come near it).
    label
        x-axis label (default: :func:`param_label`).
    dot_kw
        Extra keyword arguments for the dots (``ax.plot``).
    window_kw
        Keyword arguments for :func:`visible_windows` (``min_points``,
        ``min_fraction``, ...).

    Returns
    -------
    list of Window
        All the runs of the sweep (:func:`find_windows`), in parameter units.

    Examples
    --------
    >>> import math, numpy as np, grazing
    >>> from matplotlib.figure import Figure
    >>> from grazing.sweeps import sweep
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> ds = sweep(m, "eta", np.linspace(0.44, 0.46, 20), periods=20, workers=1, lyapunov=False)
    >>> ax = Figure().add_subplot()
    >>> runs = plot_bifurcation(ax, ds)
    >>> runs[0].label, ax.get_xlabel()
    ('1 (no impacts)', 'η')
    """
    name = swept_parameter(ds)
    par = dataset_parameter(ds, name)
    xscale = param_scale(par, degrees)
    labels, units = dataset_states(ds)
    yscale = state_scale(units[component], degrees) if units else angle_scale(degrees)
    value = np.asarray(ds["value"].values, dtype=float)
    ways = [str(d) for d in ds["direction"].values] if "direction" in ds.dims else [None]
    ys = []
    for way in ways:  # (a sweep up and down: each direction in its colour)
        part = ds if way is None else ds.sel(direction=way)
        samples = np.asarray(part["samples"].values, dtype=float)[:, :, component]  # (point, sample)
        x = np.repeat(value * xscale, samples.shape[1])
        y = samples.ravel() * yscale
        ok = np.isfinite(y)
        kw = {"ls": "none", "marker": ".", "ms": 1.2, "mew": 0.0, "color": "k", "rasterized": True}
        if way is not None:  # the sweep up as rings, the sweep down as dots inside them: both seen
            kw.update({"color": DIRECTION_COLORS[way], "label": f"swept {way}", **DIRECTION_MARKERS[way]})
        kw.update(dot_kw or {})
        ax.plot(x[ok], y[ok], **kw)
        ys.append(y[ok])
    y = np.concatenate(ys)
    ok = np.ones(y.size, dtype=bool)
    both_ways = ways[0] is not None
    if both_ways:
        down = find_windows(ds.sel(direction="down"))
        ds = ds.sel(direction="up")
    lo, hi = float(value.min() * xscale), float(value.max() * xscale)
    pad = 0.005 * (hi - lo) if hi > lo else 0.5
    ax.set_xlim(lo - pad, hi + pad)
    ymin, ymax = (float(y[ok].min()), float(y[ok].max())) if ok.any() else (0.0, 1.0)
    levels = ds["stop_level"].values[:, component] if "stop_level" in ds else np.full(value.size, np.nan)
    if stop and np.isfinite(levels).any():
        order = np.argsort(value)
        ax.plot(value[order] * xscale, levels[order] * yscale, color="tab:red", lw=0.8, alpha=0.6, zorder=0)
        ymax = max(ymax, float(np.nanmax(levels)) * yscale)
    rng = max(ymax - ymin, 1e-9)
    ax.set_ylim(ymin - 0.04 * rng, ymax + 0.32 * rng)  # headroom for three rows of window labels
    runs = find_windows(ds)
    if nonimpacting:
        trans = ax.get_xaxis_transform()
        free = [(w.lo, w.hi) for w in runs if w.period == 1 and not w.impacting]
        if both_ways:  # shaded where both sweeps are free of the stop; where one only, hatched in its colour
            free_down = [(w.lo, w.hi) for w in down if w.period == 1 and not w.impacting]
            for way, only in (("up", _minus(free, free_down)), ("down", _minus(free_down, free))):
                for k, (a, b) in enumerate(only):
                    ax.axvspan(a * xscale, b * xscale, facecolor="none", edgecolor=DIRECTION_COLORS[way],
                               hatch="////", lw=0, alpha=0.35, zorder=-1,
                               label=None if k else f"no impacts swept {way} only")  # fmt: skip
            free = _intersect(free, free_down)
        for a, b in free:
            ax.axvspan(a * xscale, b * xscale, color="#dfe9f3", lw=0, zorder=-1)
            if (b - a) * xscale >= 0.12 * (hi - lo):
                text = "period 1, no impacts\nswept up and down" if both_ways else "period 1,\nno impacts"
                ax.text((a + b) / 2 * xscale, 0.03, text, transform=trans,
                        ha="center", va="bottom", fontsize=9, color="#4a6b8a")  # fmt: skip
    if windows:
        shown = visible_windows(runs, (hi - lo) / xscale if hi > lo else 1.0, **(window_kw or {}))
        label_windows(ax, shown, scale=xscale)
    if both_ways:
        ax.legend(loc="lower left", fontsize=8, frameon=False)
    ax.set_xlabel(label if label is not None else param_label(par, degrees))
    sym = labels[component] if labels else f"x{component + 1}"
    tname = str(ds.attrs.get("time_label", "t"))
    period = period_text(float(ds.attrs.get("forcing_period", 0.0)))
    unit = state_unit(units[component], degrees) if units else ""
    ax.set_ylabel(f"{with_unit(sym, unit)} at {tname} = {period}k")
    return runs


DIRECTION_COLORS = {"up": "tab:blue", "down": "tab:orange"}
"""The colours of a sweep up and of a sweep down in :func:`plot_bifurcation`."""

DIRECTION_MARKERS = {
    "up": {"marker": "o", "ms": 4.0, "mfc": "none", "mew": 0.8},
    "down": {"marker": "o", "ms": 2.4, "mew": 0.0},
}
"""The markers of a sweep up (rings) and down (dots, inside the rings where the sweeps agree)."""


def _intersect(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The intervals common to two lists of disjoint intervals."""
    out = [(max(lo1, lo2), min(hi1, hi2)) for lo1, hi1 in a for lo2, hi2 in b]
    return [(lo, hi) for lo, hi in out if hi > lo]


def _minus(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The parts of the intervals ``a`` outside all the intervals ``b`` (each list disjoint).

    >>> _minus([(0.0, 1.0)], [(0.2, 0.3), (0.8, 2.0)])
    [(0.0, 0.2), (0.3, 0.8)]
    """
    out = []
    for lo, hi in a:
        pieces = [(lo, hi)]
        for blo, bhi in b:
            pieces = [p for x, y in pieces for p in ((x, min(y, blo)), (max(x, bhi), y)) if p[1] > p[0]]
        out += pieces
    return out


def period_classes(
    period: np.ndarray, impacts_per_period: np.ndarray, max_period: int = 8
) -> tuple[np.ndarray, list[str], list[str]]:
    """Map detected periods to the colour classes of :func:`plot_period_map` (the shared palette of
    :mod:`grazing.plotting.palette`).

    Classes, in order: failed (period -1), aperiodic (0), period 1 without
    impacts, period 1 with impacts, periods 2 ... ``max_period``, and longer
    periods.

    Parameters
    ----------
    period
        The detected period of each point (-1 failed, 0 aperiodic).
    impacts_per_period
        The impacts per period of each point (same shape).
    max_period
        The longest period with a class of its own.

    Returns
    -------
    codes, labels, colors
        An integer class per point (same shape as ``period``), and the label
        and colour of every class.

    Examples
    --------
    >>> codes, labels, _ = period_classes(np.array([1, 1, 0, 3, 12]), np.array([0, 1, 1, 1, 1]), 4)
    >>> codes.tolist(), [labels[c] for c in codes]
    ([2, 3, 1, 5, 7], ['1, no impacts', '1, impacting', 'aperiodic', '3', '> 4'])
    """
    codes = period_codes(period, impacts_per_period, max_period)
    labels, colors = class_labels(max_period), class_colours(max_period)
    return codes, labels, colors


def plot_period_map(
    ax: Axes,
    ds: Any,
    *,
    max_period: int = 8,
    degrees: bool = True,
    colorbar: bool = True,
) -> Any:
    """Colour a two-parameter map by the detected period.

    Aperiodic points (no period up to the detection limit) are black,
    nonimpacting period 1 grey, impacting period 1 light blue, periods
    2 ... ``max_period`` distinct colours (:func:`period_classes`).  Only the
    classes present get a colour-bar entry; the mesh's values index them.

    Parameters
    ----------
    ax
        Axes to draw on.
    ds
        A dataset from :func:`grazing.sweeps.parameter_map` (dimensions
        ``(param2, param1)``); param1 is on the x axis.
    max_period
        Longest period with a colour of its own.
    degrees
        Show angle parameters in degrees.
    colorbar
        Add a colour bar naming the classes.

    Returns
    -------
    matplotlib.collections.QuadMesh
        The mesh drawn.

    Examples
    --------
    >>> import xarray as xr
    >>> from matplotlib.figure import Figure
    >>> ds = xr.Dataset({"period": (("b", "a"), [[1, 2], [0, 1]]),
    ...                  "impacts_per_period": (("b", "a"), [[0, 1], [1, 1.0]])},
    ...                 coords={"b": [0.1, 0.2], "a": [0.4, 0.5]}, attrs={"params": "a,b"})
    >>> mesh = plot_period_map(Figure().add_subplot(), ds, colorbar=False)
    >>> mesh.get_array().reshape(2, 2).tolist()  # classes present: aperiodic, 1 no impacts, 1 impacting, 2
    [[1, 3], [0, 2]]
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap

    p1, p2 = str(ds.attrs.get("params", "x,y")).split(",")[:2]
    codes, labels, colors = period_classes(ds["period"].values, ds["impacts_per_period"].values, max_period)
    codes = np.asarray(codes)
    if ds["period"].dims != (p2, p1):
        codes = codes.T
    present = np.unique(codes)  # only the classes that occur get a colour and a colour-bar entry
    index = np.searchsorted(present, codes)
    par1, par2 = dataset_parameter(ds, p1), dataset_parameter(ds, p2)
    x = np.asarray(ds[p1].values, dtype=float) * param_scale(par1, degrees)
    y = np.asarray(ds[p2].values, dtype=float) * param_scale(par2, degrees)
    cmap = ListedColormap([colors[k] for k in present])
    norm = BoundaryNorm(np.arange(len(present) + 1) - 0.5, cmap.N)
    mesh = ax.pcolormesh(x, y, index, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
    ax.set_xlabel(param_label(par1, degrees))
    ax.set_ylabel(param_label(par2, degrees))
    if colorbar:
        cb = ax.figure.colorbar(mesh, ax=ax, ticks=np.arange(len(present)), fraction=0.04, pad=0.02)
        cb.ax.set_yticklabels([labels[k] for k in present], fontsize=8)
        cb.set_label("detected period", fontsize=9)
    return mesh
