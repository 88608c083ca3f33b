"""Plots of attractors: basins of attraction, basin fractions along a parameter.

For the datasets of :func:`grazing.attractors.basins` (:func:`plot_basins`:
each initial state coloured by its attractor, the attractors' points drawn on
top) and :func:`grazing.attractors.continue_attractors`
(:func:`plot_fractions`: each attractor's share of the initial states against
the parameter).  The same attractor id has the same colour in both
(:func:`attractor_color`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from grazing.attractors.kinds import AttractorKind
from grazing.plotting.labels import (
    dataset_parameter,
    param_label,
    param_scale,
    state_scale,
    state_unit,
    with_unit,
)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22",
           "#aec7e8", "#ffbb78", "#98df8a", "#c5b0d5")  # fmt: skip
"""Colours of the attractors 1, 2, ... (then again)."""

OUTCOME_COLORS = {AttractorKind.INVALID: "#ffffff", AttractorKind.FAILED: "#d62728",
                  AttractorKind.ESCAPING: "#000000"}  # fmt: skip
"""Colours of the outcomes that are not attractors."""


def attractor_color(ident: int, kind: str) -> str:
    """The colour of attractor ``ident`` of ``kind`` (outcomes: white invalid, red failed, black escaping).

    Examples
    --------
    >>> attractor_color(1, "periodic"), attractor_color(0, "invalid"), attractor_color(13, "chaotic")
    ('#1f77b4', '#ffffff', '#1f77b4')
    """
    if kind in OUTCOME_COLORS:
        return OUTCOME_COLORS[kind]
    return PALETTE[(int(ident) - 1) % len(PALETTE)]


def describe(kind: str, period: int, impacts: float) -> str:
    """A few words for an attractor: ``"period 5, 1 impact"``, ``"chaotic"``, ``"sticking"``.

    Examples
    --------
    >>> describe("periodic", 5, 1.0), describe("periodic", 1, 0.0), describe("chaotic", 0, 0.8)
    ('period 5, 1 impact', 'period 1, no impacts', 'chaotic')
    >>> describe("neutral", 1, 0.0)
    'neutral, period 1, no impacts'
    """
    if kind in (AttractorKind.PERIODIC, AttractorKind.NEUTRAL):
        n = round(float(impacts)) if np.isfinite(impacts) else -1
        imp = "no impacts" if n == 0 else ("1 impact" if n == 1 else f"{n} impacts" if n > 0 else "")
        neutral = "neutral, " if kind == AttractorKind.NEUTRAL else ""
        return neutral + f"period {period}" + (f", {imp}" if imp else "")
    return str(kind)


def _state_axes(ds: Any, degrees: bool) -> tuple[str, str, float, float]:
    """The labels of the grid's two states and their scale factors (radians shown in degrees)."""
    labels = []
    scales = []
    for axis in ("x", "y"):
        attrs = ds[axis].attrs
        unit = str(attrs.get("units", ""))
        labels.append(
            with_unit(str(attrs.get("symbol", attrs.get("long_name", axis))), state_unit(unit, degrees))
        )
        scales.append(state_scale(unit, degrees))
    return labels[0], labels[1], scales[0], scales[1]


def plot_basins(ax: Axes, ds: Any, *, points: bool = True, legend: bool = True, degrees: bool = True) -> Any:
    """Colour each initial state of a basin dataset by its attractor; draw the attractors' points on top.

    Parameters
    ----------
    ax
        Axes to draw on.
    ds
        A dataset of :func:`grazing.attractors.basins` (``label`` on ``(y, x)``, the attractors along
        ``attractor``).
    points
        Draw each attractor's points (its states at the sampling phase, in the grid's two states) as
        markers outlined in black.
    legend
        A legend naming every attractor with its kind and basin fraction.
    degrees
        Show states in radians in degrees.

    Returns
    -------
    matplotlib.collections.QuadMesh
        The mesh drawn.

    Examples
    --------
    >>> import grazing
    >>> from matplotlib.figure import Figure
    >>> from grazing.attractors import basins
    >>> ds = basins(grazing.models.bouncing_ball(amplitude=0.8, r=0.8), (-1, 6), (-4, 4), (8, 8), workers=1)
    >>> ax = Figure().add_subplot()
    >>> mesh = plot_basins(ax, ds)
    >>> ax.get_xlabel(), [t.get_text().rsplit(", ", 1)[0] for t in ax.get_legend().get_texts()]
    ('y', ['0: invalid (beyond a stop)', '1: period 1, 1 impact', '2: sticking'])
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.lines import Line2D

    ids = [int(a) for a in ds.attractor.values]
    kinds = [str(k) for k in ds.kind.values]
    colors = [attractor_color(i, k) for i, k in zip(ids, kinds)]
    index = np.searchsorted(np.array(ids), ds.label.values)
    xlabel, ylabel, xs, ys = _state_axes(ds, degrees)
    cmap = ListedColormap(colors)
    norm = BoundaryNorm(np.arange(len(ids) + 1) - 0.5, cmap.N)
    mesh = ax.pcolormesh(ds.x.values * xs, ds.y.values * ys, index, cmap=cmap, norm=norm, shading="nearest",
                         rasterized=True)  # fmt: skip
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    names = list(ds.component.values)
    i, j = (names.index(s) for s in str(ds.attrs.get("states", f"{names[0]},{names[1]}")).split(","))
    box = _extent(ds.x.values * xs, ds.y.values * ys)
    handles = []
    for k, (ident, kind) in enumerate(zip(ids, kinds)):
        n = int(ds.n_points.values[k])
        pts = ds.points.values[k, :n]
        if points and n:
            size = 7 if n <= 64 else 1.5
            ax.plot(pts[:, i] * xs, pts[:, j] * ys, "o" if n <= 64 else ".", ms=size, mfc=colors[k],
                    mec="k", mew=0.7 if n <= 64 else 0.0, ls="none", zorder=3)  # fmt: skip
        words = describe(kind, int(ds.period.values[k]), float(ds.impacts_per_period.values[k]))
        why = str(ds.reason.values[k])
        if why and kind != AttractorKind.PERIODIC:
            words += f" ({why})"
        if n and not _inside(pts[:, i] * xs, pts[:, j] * ys, box):
            words += " (outside the grid)"
        text = f"{ident}: {words}, {100 * float(ds.fraction.values[k]):.1f}%"
        handles.append(
            Line2D([], [], marker="s", ls="none", ms=9, mfc=colors[k], mec="k", mew=0.5, label=text)
        )
    ax.set_xlim(box[0], box[1])
    ax.set_ylim(box[2], box[3])
    if legend:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    return mesh


def _extent(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float, float]:
    """The grid's extent with half a cell around it (as the mesh draws it)."""

    def side(v: np.ndarray) -> tuple[float, float]:
        half = 0.5 * (v[-1] - v[0]) / max(v.size - 1, 1) if v.size > 1 else 0.5
        return float(v[0] - half), float(v[-1] + half)

    return (*side(x), *side(y))


def _inside(x: np.ndarray, y: np.ndarray, box: tuple[float, float, float, float]) -> bool:
    """Whether any of the points is inside ``box``."""
    return bool(np.any((x >= box[0]) & (x <= box[1]) & (y >= box[2]) & (y <= box[3])))


def plot_fractions(ax: Axes, ds: Any, *, degrees: bool = True, legend: bool = True) -> list[Any]:
    """Each followed attractor's basin fraction against the parameter (a dataset of ``continue_attractors``).

    The fractions are stacked (they sum to 1 at every value), coloured as in :func:`plot_basins`;
    an attractor found only from the seeds (fraction 0) is marked at the bottom.

    Parameters
    ----------
    ax
        Axes to draw on.
    ds
        A dataset of :func:`grazing.attractors.continue_attractors`.
    degrees
        Show an angle parameter in degrees.
    legend
        Add a legend (``id: kind`` for each attractor).

    Returns
    -------
    list
        The artists drawn, one per attractor present.

    Examples
    --------
    >>> import grazing
    >>> from matplotlib.figure import Figure
    >>> from grazing.attractors import continue_attractors
    >>> ball = grazing.models.bouncing_ball(r=0.8)
    >>> ds = continue_attractors(ball, "amplitude", [0.3, 0.5, 0.8], (-1, 6), (-4, 4), (8, 6), workers=1)
    >>> ax = Figure().add_subplot()
    >>> len(plot_fractions(ax, ds)), ax.get_xlabel()  # heights below the table are invalid starts
    (3, 'A')
    >>> [t.get_text() for t in ax.get_legend().get_texts()]
    ['0: invalid', '1: sticking', '2: periodic']
    """
    par = dataset_parameter(ds, "value")
    scale = param_scale(par, degrees)
    v = ds.value.values * scale
    fr = ds.fraction.values
    bottom = np.zeros(v.size)
    drawn = []
    for k, ident in enumerate(ds.attractor.values):
        kinds = [str(x) for x in ds.kind.values[:, k] if str(x)]
        kind = max(set(kinds), key=kinds.count) if kinds else AttractorKind.PERIODIC
        if not ds.present.values[:, k].any():
            continue
        color = attractor_color(int(ident), kind)
        top = bottom + fr[:, k]
        words = sorted(set(kinds), key=kinds.index)
        label = f"{int(ident)}: {', '.join(words)}"
        drawn.append(ax.fill_between(v, bottom, top, color=color, lw=0, label=label, step=None,
                                     edgecolor="k" if kind == AttractorKind.INVALID else None))  # fmt: skip
        only_seeds = ds.present.values[:, k] & (fr[:, k] == 0)
        if only_seeds.any():
            ax.plot(v[only_seeds], np.zeros(only_seeds.sum()), "^", color=color, mec="k", ms=6, clip_on=False)
        bottom = top
    if v.size > 1:
        ax.set_xlim(v.min(), v.max())
    ax.set_ylim(0, 1)
    ax.set_xlabel(param_label(par, degrees))
    ax.set_ylabel("basin fraction")
    if legend:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    return drawn
