"""The explorer's plots (Bokeh): the diagram or period map, the orbit's time series and phase portrait.

The data of each plot is built from the records of :mod:`grazing.explore` by a plain
function returning the columns of a Bokeh ``ColumnDataSource`` (testable without a
browser); :class:`Figures` holds the figures and their sources, and is changed only by
replacing those columns.  Labels come from the parameters' and states' metadata (symbol,
display unit: degrees for angles, states included, as in the page's header).  Periods are
coloured by the palette of the report and the docs (:mod:`grazing.plotting.palette`), named
in a legend under the diagram; what the mouse is over is read in a line under the diagram
(:data:`HOVER_JS`), never in a tooltip over the plot.  On a model with modes the time series
shades each stay in a mode as the static plots do (:func:`mode_span_columns`, the colours of
:data:`~grazing.plotting.palette.MODE_COLOURS`), and both plots mark the switches of mode and
the sliding intervals (:func:`switch_columns`, :func:`sliding_columns`).
"""

from __future__ import annotations

import html
import math
from typing import Any

import numpy as np

from grazing.attractors.kinds import AttractorKind
from grazing.core.model import HybridModel, Parameter
from grazing.explore.basins import BasinView
from grazing.explore.branch import Continued, Curves, Grazings, Mark
from grazing.explore.diagram import Diagram, View
from grazing.explore.point import PointReport
from grazing.plotting.labels import state_scale, state_unit
from grazing.plotting.palette import MAX_PERIOD, MODE_COLOURS, class_colours, class_labels, period_codes

__all__ = [
    "FRAME_BELOW",
    "PERIOD_COLOURS",
    "Figures",
    "branch_columns",
    "diagram_columns",
    "legend_html",
    "mark_columns",
    "mode_span_columns",
    "period_label",
    "sliding_columns",
    "switch_columns",
]

MODE_ALPHA = 0.15
"""The opacity of a mode's shading on the time series (the static plots' ``axvspan`` alpha)."""

SWITCH_COLOUR = "#7b3294"
"""The marks of the switches of mode (purple: not a period's colour, nor an impact's black)."""

PERIOD_COLOURS = tuple(class_colours(MAX_PERIOD)[3 : 3 + MAX_PERIOD])
"""The colours of periods 1 (with impacts) to 8, from the shared palette (:mod:`grazing.plotting.palette`:
nonimpacting period 1, no period, failed and longer periods have colours of their own there)."""

LINE_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf")
"""The colours of the time series' states (not periods)."""

CURVE_COLOURS = {
    "fold": "black",
    "period-doubling": "red",
    "neimark-sacker": "purple",
    "branch-point": "brown",
    "grazing": "orange",
}
"""The colours of the bifurcation curves on a period map."""

CURVE_DASHES = {
    "fold": "solid",
    "period-doubling": "dashed",
    "neimark-sacker": "dotdash",
    "branch-point": "dashdot",
    "grazing": "dotted",
}
"""The dash pattern of each kind of curve: a curve is told from a region of the period map in its own
colour (the period-doubling curve's red is period 1's, say) by its pattern and its white halo."""

FRAME_BELOW = 0.2
"""A continued branch narrower than this fraction of the diagram's range: the diagram is framed to it."""

HOVER_HINT = "Hover over the diagram to read a point here; click it to see its orbit."

HOVER_JS = """
const slots = (window.__grazing_hover ??= new Map());
const key = readout.id + ':' + cb_data.renderer.id;
const data = cb_data.renderer.data_source.data;
const g = cb_data.geometry;
let lines = [];
if (kind === 'image') {
  for (const d of [fine.data, data]) {
    if (!d.image.length) continue;
    const img = d.image[0], ny = img.shape[0], nx = img.shape[1];
    const i = Math.floor((g.x - d.x[0]) / d.dw[0] * nx), j = Math.floor((g.y - d.y[0]) / d.dh[0] * ny);
    if (i < 0 || j < 0 || i >= nx || j >= ny) continue;
    const code = img[j * nx + i];
    lines.push(xlabel + ' = ' + g.x.toPrecision(6) + ', ' + ylabel + ' = ' + g.y.toPrecision(6)
               + ': period ' + (labels[code] ?? '?'));
    break;
  }
} else {
  for (const i of cb_data.index.indices) lines.push(data.text[i]);
}
slots.set(key, [...new Set(lines)]);
const all = [...new Set([...slots.entries()].filter(([k]) => k.startsWith(readout.id + ':'))
                                            .flatMap(([, v]) => v))];
const shown = all.slice(0, 3).map(t => t.replace(/&/g, '&amp;').replace(/</g, '&lt;'));
if (all.length > 3) shown.push('and ' + (all.length - 3) + ' more here');
readout.text = shown.length ? shown.join('<br>') : hint;
"""
"""The hover tools' callback: the entries under the mouse, each once, in :attr:`Figures.readout`."""


def period_label(period: int) -> str:
    """How a period is shown: ``"5"``, ``"none <= 64"``, ``"failed"``."""
    if period > 0:
        return str(int(period))
    return "none <= 64" if period == 0 else "failed"


def state_display(model: HybridModel, i: int) -> tuple[float, str]:
    """State ``i``'s factor from its model unit to the page's unit, and that unit (deg for an angle)."""
    unit = model.state_units[i] if model.state_units else ""
    shown = state_unit(unit, True)
    return state_scale(unit, True), (shown.replace("degrees", "deg", 1) if shown != unit else unit)


def legend_html(codes: Any = (), *, map_view: bool = False) -> str:
    """The diagram's legend: the period classes ``codes`` (:func:`~grazing.plotting.palette.period_codes`)
    shown, in the shared palette, then the branch's, special points' and (on a map) curves' symbols.

    Examples
    --------
    >>> "1, impacting" in legend_html([3]) and "#9ecae1" in legend_html([3])
    True
    """
    colours, labels = class_colours(MAX_PERIOD), class_labels(MAX_PERIOD)

    def swatch(colour: str, text: str, shape: str = "square") -> str:
        radius = "50%" if shape == "circle" else "0"
        style = (
            f"display:inline-block;width:0.9em;height:0.9em;background:{colour};border:1px solid #666;"
            f"border-radius:{radius};vertical-align:-0.1em;margin-right:0.3em"
        )
        item = f'<span style="{style}"></span>{html.escape(text)}'
        return f'<span style="white-space:nowrap;margin-right:0.9em">{item}</span>'

    items = [swatch(colours[c], labels[c]) for c in sorted({int(c) for c in codes})]
    period = "<b>period:</b> " + (" ".join(items) if items else "(computing)")
    marks = [swatch("red", "special point (diamond)"), swatch("orange", "grazing (triangle)")]
    if map_view:
        marks += [
            swatch(colour, f"{kind} curve ({CURVE_DASHES[kind]})") for kind, colour in CURVE_COLOURS.items()
        ]
    else:
        marks = [
            swatch("black", "stable", "circle"),
            swatch("white", "unstable", "circle"),
            swatch("#dddddd", "through a stop (not a motion)", "circle"),
            *marks,
        ]
    what = "<b>continued branch:</b> " if not map_view else "<b>marks:</b> "
    return f'<div class="grazing-legend" style="line-height:1.6">{period}<br>{what}{" ".join(marks)}</div>'


def axis_label(par: Parameter) -> str:
    unit = par.display_unit
    return f"{par.label} ({unit})" if unit else par.label


def state_label(model: HybridModel, i: int) -> str:
    unit = state_display(model, i)[1]
    return f"{model.state_labels[i]} ({unit})" if unit else model.state_labels[i]


def diagram_columns(diagram: Diagram, component: int) -> dict[str, list[Any]]:
    """The stroboscopic points of a one-parameter diagram: one per distinct sample of each point.

    A point with period ``p`` contributes its last ``p`` samples, one without a
    period all of them, a failed point none (its samples are NaN).  The samples are in
    the state's display unit; ``code`` is each point's class in the shared palette
    (period 1 with and without impacts apart), ``text`` what the hover reads.
    """
    par = diagram.view.parameter(0)
    scale = state_display(diagram.view.model, component)[0]
    codes = period_codes(diagram.period, diagram.impacts_per_period, MAX_PERIOD)
    palette = class_colours(MAX_PERIOD)
    xs, ys, labels, colours, ipp, cs, texts = [], [], [], [], [], [], []
    assert diagram.samples is not None
    for i, value in enumerate(diagram.values[0]):
        p = int(diagram.period[i])
        s = diagram.samples[i, -p:, component] if p > 0 else diagram.samples[i, :, component]
        s = s[np.isfinite(s)] * scale
        impacts = float(diagram.impacts_per_period[i])
        shown = par.to_display(value)
        text = f"{par.label} = {shown:.6f}: period {period_label(p)}, {impacts:.4g} impacts per period"
        xs += [shown] * s.size
        ys += s.tolist()
        labels += [period_label(p)] * s.size
        colours += [palette[int(codes[i])]] * s.size
        ipp += [impacts] * s.size
        cs += [int(codes[i])] * s.size
        texts += [text] * s.size
    return {"x": xs, "y": ys, "period": labels, "colour": colours, "impacts": ipp, "code": cs, "text": texts}


def mode_span_columns(rep: PointReport) -> dict[str, list[Any]]:
    """The shown motion's stays in each mode (a model with modes; empty without): ``x0``, ``x1`` (times as
    the time series'), ``mode`` (the legend's ``mode 'name'``, as the static plots label it), ``colour``
    (the mode's in :data:`~grazing.plotting.palette.MODE_COLOURS`, by its index in ``mode_names``).

    Examples
    --------
    >>> import grazing
    >>> from grazing.explore import inspect_point
    >>> rep = inspect_point(grazing.models.soft_impact_oscillator(), {"omega": 1.2}, [0.0, 0.0])
    >>> mode_span_columns(rep)["mode"]
    ["mode 'contact'", "mode 'free'", "mode 'contact'"]
    """
    out: dict[str, list[Any]] = {"x0": [], "x1": [], "mode": [], "colour": []}
    if rep.modes is None:
        return out
    names = rep.model.mode_names
    for a, b, name in rep.modes.spans:
        out["x0"].append(float(a))
        out["x1"].append(float(b))
        out["mode"].append(f"mode {name!r}")
        out["colour"].append(MODE_COLOURS[names.index(name) % len(MODE_COLOURS)])
    return out


def switch_columns(rep: PointReport, scales: np.ndarray, j: int) -> dict[str, list[Any]]:
    """The shown motion's switches of mode (empty without modes): ``t`` and ``x`` (the first state, display
    units) for the time series, ``px``, ``py`` (states 0 and ``j``) for the phase portrait, ``name`` (the
    transition)."""
    if rep.modes is None:
        return {"t": [], "x": [], "px": [], "py": [], "name": []}
    x = rep.modes.switch_states * scales
    return {
        "t": rep.modes.switch_t.tolist(),
        "x": x[:, 0].tolist(),
        "px": x[:, 0].tolist(),
        "py": x[:, j].tolist(),
        "name": list(rep.modes.switch_names),
    }


def sliding_columns(rep: PointReport, scales: np.ndarray, j: int) -> dict[str, list[Any]]:
    """The shown motion during each sliding interval (empty without): ``xs``, ``ys`` (states 0 and ``j``,
    display units) for the phase portrait, ``t0``, ``t1`` the interval, ``surface`` its surface, ``colour``
    its sliding pseudo-mode's (as the time series shades it)."""
    out: dict[str, list[Any]] = {"xs": [], "ys": [], "t0": [], "t1": [], "surface": [], "colour": []}
    if rep.modes is None:
        return out
    x = rep.trajectory * scales
    pseudo = {rep.model.surface_names[i]: k for k, i in rep.model.sliding_modes.items()}
    for a, b, surface in rep.modes.sliding:
        inside = (rep.t >= a) & (rep.t <= b)
        out["xs"].append(x[inside, 0].tolist())
        out["ys"].append(x[inside, j].tolist())
        out["t0"].append(float(a))
        out["t1"].append(float(b))
        out["surface"].append(surface)
        out["colour"].append(MODE_COLOURS[pseudo[surface] % len(MODE_COLOURS)])
    return out


def map_image(diagram: Diagram) -> dict[str, list[Any]]:
    """A period map as an image of the period classes of the shared palette (period 1 with and without
    impacts apart; :func:`~grazing.plotting.palette.period_codes`)."""
    a, b = diagram.view.axes
    pa, pb = diagram.view.parameter(0), diagram.view.parameter(1)
    lo1, hi1, lo2, hi2 = pa.to_display(a.lo), pa.to_display(a.hi), pb.to_display(b.lo), pb.to_display(b.hi)
    d1, d2 = (hi1 - lo1) / (a.num - 1), (hi2 - lo2) / (b.num - 1)
    image = period_codes(diagram.period, diagram.impacts_per_period, MAX_PERIOD).astype(float)
    return {
        "image": [image],
        "x": [lo1 - d1 / 2],
        "y": [lo2 - d2 / 2],
        "dw": [hi1 - lo1 + d1],
        "dh": [hi2 - lo2 + d2],
    }


def branch_columns(view: View, continued: Continued, component: int) -> dict[str, list[Any]]:
    """The continued branch's points at phase 0 (one per forcing period of each orbit), in display units.

    Each is ``stable``, ``unstable`` or, for a virtual orbit that passes through a stop (a
    nonimpacting branch followed past its grazing), ``through a stop``: drawn apart, it is not
    a motion of the system.  The clicked orbit, where both directions start, is drawn once.
    """
    par = view.parameter(0)
    scale = state_display(view.model, component)[0]
    xs, ys, kinds, texts = [], [], [], []
    seen: set[float] = set()
    for piece in continued.pieces:
        for value, states, st, cross in zip(piece.values, piece.states, piece.stable, piece.crossing):
            if float(value) in seen:
                continue  # (each direction starts at the clicked orbit)
            seen.add(float(value))
            kind = "through a stop (not a motion)" if cross else ("stable" if st else "unstable")
            shown = par.to_display(value)
            xs += [shown] * len(states)
            ys += [float(v) * scale for v in states[:, component]]
            kinds += [kind] * len(states)
            texts += [f"{par.label} = {shown:.6f}: continued branch, {kind}"] * len(states)
    fill = {"stable": "black", "unstable": "white"}
    line = {"stable": "black", "unstable": "black"}
    return {
        "x": xs,
        "y": ys,
        "stable": kinds,
        "fill": [fill.get(k, "#dddddd") for k in kinds],
        "line": [line.get(k, "#aaaaaa") for k in kinds],
        "text": texts,
    }


def mark_columns(view: View, marks: tuple[Mark, ...], component: int) -> dict[str, list[Any]]:
    """Special points (and grazings) at phase 0 (display units), with their text for the hover."""
    par = view.parameter(0)
    scale = state_display(view.model, component)[0]
    xs, ys, kinds, texts = [], [], [], []
    for m in marks:
        for s in m.states:
            xs.append(par.to_display(m.value))
            ys.append(float(s[component]) * scale)
            kinds.append(m.kind)
            texts.append(m.text)
    return {"x": xs, "y": ys, "kind": kinds, "text": texts}


def row_columns(view: View, marks: tuple[Mark, ...], row: float | None) -> dict[str, list[Any]]:
    """Special points on a map's row ``row`` (the second parameter's value, model units)."""
    p1, p2 = view.parameter(0), view.parameter(1)
    y = p2.to_display(row) if row is not None else math.nan
    return {
        "x": [p1.to_display(m.value) for m in marks],
        "y": [y] * len(marks),
        "kind": [m.kind for m in marks],
        "text": [m.text for m in marks],
    }


def branch_frame(view: View, continued: Continued) -> tuple[float, float] | None:
    """The range (display units) the diagram is framed to after a continuation: the branch in the
    middle third; None when the branch is wider than :data:`FRAME_BELOW` of the range (shown as is).

    Examples
    --------
    >>> import grazing
    >>> from grazing.explore.branch import BranchPiece
    >>> view = View.of(grazing.models.pendulum("B"), {"eta": (0.44, 0.49)})
    >>> values = np.array([0.446, 0.445, 0.4451])
    >>> piece = BranchPiece(None, values, [], np.ones(3, bool), np.zeros(3, bool), 0.44)
    >>> [round(v, 6) for v in branch_frame(view, Continued("eta", (piece,), ()))]
    [0.444, 0.447]
    """
    par, axis = view.parameter(0), view.axes[0]
    values = [par.to_display(v) for p in continued.pieces for v in p.values]
    values += [par.to_display(m.value) for m in continued.marks]
    if not values:
        return None
    lo, hi = min(values), max(values)
    full_lo, full_hi = sorted((par.to_display(axis.lo), par.to_display(axis.hi)))
    width = hi - lo
    if width >= FRAME_BELOW * (full_hi - full_lo):
        return None
    pad = max(width, 0.01 * (full_hi - full_lo))  # (a branch of one point: 2 % of the range)
    return max(full_lo, lo - pad), min(full_hi, hi + pad)


class Figures:
    """The explorer's Bokeh figures and their data sources; :attr:`readout` (what the mouse is over)
    and :attr:`legend` are shown under the diagram."""

    def __init__(self, view: View) -> None:
        from bokeh.models import ColumnDataSource, CustomJS, Div, LinearColorMapper, Range1d, Span
        from bokeh.plotting import figure

        self.view = view
        model = view.model
        self.scales = np.array([state_display(model, i)[0] for i in range(model.n_states)])
        par = view.parameter(0)
        lo, hi = par.to_display(view.axes[0].lo), par.to_display(view.axes[0].hi)
        tools = "pan,wheel_zoom,box_zoom,reset,tap,save"
        self.diagram = figure(
            x_range=Range1d(lo, hi),  # (the computed range; the toolbar's reset comes back to it)
            height=460,
            sizing_mode="stretch_width",
            min_width=280,
            tools=tools,
            active_scroll="wheel_zoom",
            x_axis_label=axis_label(par),
            name="diagram",
            output_backend="canvas",
        )
        self.readout = Div(
            text=HOVER_HINT, sizing_mode="stretch_width", min_height=40, css_classes=["grazing-readout"]
        )
        self.legend = Div(
            text=legend_html(map_view=len(view.axes) == 2),
            sizing_mode="stretch_width",
            css_classes=["grazing-legend"],
        )
        self._hover = {"readout": self.readout, "hint": HOVER_HINT, "kind": "points"}
        self.fine_image = ColumnDataSource({"image": [], "x": [], "y": [], "dw": [], "dh": []})
        if len(view.axes) == 1:
            self.diagram.title.text = (
                f"bifurcation diagram: stroboscopic {model.state_labels[view.component]}"
            )
            self.diagram.yaxis.axis_label = state_label(model, view.component)
            self.points = ColumnDataSource(
                {"x": [], "y": [], "period": [], "colour": [], "impacts": [], "code": [], "text": []}
            )
            r = self.diagram.scatter("x", "y", source=self.points, size=3, color="colour", alpha=0.8)
            self._hover_over([r])
        else:
            pb = view.parameter(1)
            self.diagram.title.text = "period map (colours: the legend below)"
            self.diagram.yaxis.axis_label = axis_label(pb)
            self.diagram.y_range.start = pb.to_display(view.axes[1].lo)
            self.diagram.y_range.end = pb.to_display(view.axes[1].hi)
            self.image = ColumnDataSource({"image": [], "x": [], "y": [], "dw": [], "dh": []})
            colours = class_colours(MAX_PERIOD)  # (the classes of the shared palette, by their codes)
            mapper = LinearColorMapper(palette=colours, low=-0.5, high=len(colours) - 0.5)
            r = self.diagram.image(
                "image", x="x", y="y", dw="dw", dh="dh", source=self.image, color_mapper=mapper
            )
            self.diagram.image(  # (a zoomed-in map, drawn over the coarse one where it is)
                "image", x="x", y="y", dw="dw", dh="dh", source=self.fine_image, color_mapper=mapper
            )
            code = CustomJS(
                args={
                    **self._hover,
                    "kind": "image",
                    "fine": self.fine_image,
                    "labels": class_labels(MAX_PERIOD),
                    "xlabel": par.label,
                    "ylabel": pb.label,
                },
                code=HOVER_JS,
            )
            self._hover_over([r], code)
        self.branch = ColumnDataSource({"x": [], "y": [], "stable": [], "fill": [], "line": [], "text": []})
        self.marks = ColumnDataSource({"x": [], "y": [], "kind": [], "text": []})
        self.grazings = ColumnDataSource({"x": [], "y": [], "kind": [], "text": []})
        self.curves = ColumnDataSource({"xs": [], "ys": [], "kind": [], "text": [], "colour": [], "dash": []})
        if len(view.axes) == 2:
            halo = {"line_color": "white", "line_width": 6}
            self.diagram.multi_line("xs", "ys", source=self.curves, **halo)
            rc = self.diagram.multi_line(
                "xs", "ys", source=self.curves, line_color="colour", line_dash="dash", line_width=3
            )
            self._hover_over([rc])
        rm = self.diagram.scatter(
            "x", "y", source=self.marks, size=12, marker="diamond", fill_color="red", line_color="black"
        )
        rg = self.diagram.scatter(
            "x",
            "y",
            source=self.grazings,
            size=12,
            marker="triangle",
            fill_color="orange",
            line_color="black",
        )
        self._hover_over([rm, rg])
        if len(view.axes) == 1:
            rb = self.diagram.scatter(
                "x", "y", source=self.branch, size=6, line_color="line", fill_color="fill"
            )
            self._hover_over([rb])
        self.clicked = Span(
            location=lo, dimension="height", line_color="red", line_dash="dashed", visible=False
        )
        self.diagram.add_layout(self.clicked)
        self.clicked_cell = ColumnDataSource({"x": [], "y": []})  # (a map's clicked point)
        self.diagram.scatter(
            "x",
            "y",
            source=self.clicked_cell,
            marker="circle_cross",
            size=14,
            fill_alpha=0,
            line_color="red",
            line_width=2,
        )
        self.grazing_spans: list[Any] = []
        # The clicked point: time series and phase portrait.
        self.series = figure(
            height=260,
            sizing_mode="stretch_width",
            x_axis_label=f"time {model.time_label}",
            tools="pan,wheel_zoom,box_zoom,reset,save",
            title="time series",
        )
        self.series_modes = ColumnDataSource({"x0": [], "x1": [], "mode": [], "colour": []})
        self.series_switches = ColumnDataSource({"t": [], "x": [], "px": [], "py": [], "name": []})
        self.phase_sliding = ColumnDataSource(
            {"xs": [], "ys": [], "t0": [], "t1": [], "surface": [], "colour": []}
        )
        if model.has_modes:  # (the stays in each mode shaded under the lines, as the static plots do)
            self.series.vstrip(
                x0="x0", x1="x1", source=self.series_modes, fill_color="colour", fill_alpha=MODE_ALPHA,
                line_alpha=0, legend_field="mode", level="underlay",
            )  # fmt: skip
        self.series_sources = []
        for i, colour in zip(range(model.n_states), LINE_COLOURS):
            src = ColumnDataSource({"t": [], "x": []})
            self.series.line("t", "x", source=src, color=colour, legend_label=state_label(model, i))
            self.series_sources.append(src)
        self.series_impacts = ColumnDataSource({"t": [], "x": []})
        self.series.scatter(
            "t", "x", source=self.series_impacts, marker="x", size=9, color="black", legend_label="impact"
        )
        if model.has_modes:
            self.series.scatter(
                "t", "x", source=self.series_switches, marker="triangle", size=9, color=SWITCH_COLOUR,
                legend_label="switch of mode",
            )  # fmt: skip
        self.series.legend.click_policy = "hide"
        self.series.legend.orientation = "horizontal"
        self.series.add_layout(self.series.legend[0], "above")  # (outside the plot: it hides no data)
        j = 1 if model.n_states > 1 else 0
        self.phase = figure(
            height=300,
            sizing_mode="stretch_width",
            x_axis_label=state_label(model, 0),
            y_axis_label=state_label(model, j),
            tools="pan,wheel_zoom,box_zoom,reset,save",
            title="phase portrait",
        )
        self.phase_line = ColumnDataSource({"x": [], "y": []})
        self.phase.line("x", "y", source=self.phase_line, color="#1f77b4", legend_label="motion")
        self.phase_strobe = ColumnDataSource({"x": [], "y": []})
        self.phase.scatter(
            "x", "y", source=self.phase_strobe, size=8, color="red", legend_label="stroboscopic (phase 0)"
        )
        self.phase_impacts = ColumnDataSource({"x": [], "y": []})
        self.phase.scatter(
            "x", "y", source=self.phase_impacts, marker="x", size=10, color="black", legend_label="impacts"
        )
        if model.has_modes:
            if model.sliding_modes:
                self.phase.multi_line(
                    "xs", "ys", source=self.phase_sliding, line_width=6, line_alpha=0.5, line_color="colour",
                    legend_label="sliding",
                )  # fmt: skip
            self.phase.scatter(
                "px", "py", source=self.series_switches, marker="triangle", size=10, color=SWITCH_COLOUR,
                legend_label="switches of mode",
            )  # fmt: skip
        self.phase.legend.click_policy = "hide"
        self.phase.legend.orientation = "horizontal"
        self.phase.add_layout(self.phase.legend[0], "above")
        self._basins_figure(model)
        self.stop_spans = []
        for k, name in enumerate(model.stop_names):
            level = model.stop_level(0, 0.0, k)
            if level is not None and np.isfinite(level):
                span = Span(
                    location=level * self.scales[0], dimension="height", line_color="grey", line_width=3
                )
                self.phase.add_layout(span)
                self.stop_spans.append((name, span))

    def _hover_over(self, renderers: list[Any], code: Any = None) -> None:
        """A hover tool over ``renderers`` that writes their ``text`` under the mouse into :attr:`readout`."""
        from bokeh.models import CustomJS, HoverTool

        code = code or CustomJS(args={**self._hover, "fine": self.fine_image, "labels": [], "xlabel": "",
                                      "ylabel": ""}, code=HOVER_JS)  # fmt: skip
        self.diagram.add_tools(HoverTool(renderers=renderers, tooltips=None, callback=code))

    def _basins_figure(self, model: HybridModel) -> None:
        from bokeh.models import ColumnDataSource, HoverTool, LinearColorMapper
        from bokeh.plotting import figure

        self.basins = figure(
            height=300,
            sizing_mode="stretch_width",
            x_axis_label=state_label(model, 0),
            y_axis_label=state_label(model, 1),
            tools="pan,wheel_zoom,box_zoom,reset,save",
            title="basins of attraction (initial states at phase 0; white: beyond a stop)",
            visible=False,
        )
        self.basin_image = ColumnDataSource({"image": [], "x": [], "y": [], "dw": [], "dh": []})
        palette = ["#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5", "#c49c94", "#f7b6d2", "#dbdb8d"]
        mapper = LinearColorMapper(
            palette=palette, low=0.5, high=len(palette) + 0.5, low_color="white", high_color="#cccccc"
        )
        self.basins.image(
            "image", x="x", y="y", dw="dw", dh="dh", source=self.basin_image, color_mapper=mapper
        )
        self.basin_points = ColumnDataSource({"x": [], "y": [], "text": []})
        r = self.basins.scatter("x", "y", source=self.basin_points, size=7, color="black")
        self.basins.add_tools(HoverTool(renderers=[r], tooltips=[("", "@text")]))

    def show_diagram(self, diagram: Diagram) -> None:
        if len(diagram.view.axes) == 1:
            self.points.data = diagram_columns(diagram, self.view.component)
        else:
            self.image.data = map_image(diagram)
        self._show_legend()

    def _show_legend(self) -> None:
        """The legend of the period classes drawn (the coarse and the zoomed-in diagram's)."""
        if len(self.view.axes) == 1:
            codes = set(self.points.data["code"])
        else:
            codes = {
                int(c) for d in (self.image.data, self.fine_image.data) for c in np.unique(d["image"][:1])
            }
        self.legend.text = legend_html(sorted(codes), map_view=len(self.view.axes) == 2)

    def show_basins(self, found: BasinView) -> None:
        """The basins: each initial state coloured by its attractor, the attractors' points on top (the
        states in display units)."""
        sx, sy = self.scales[0], self.scales[1]
        (x0, x1), (y0, y1) = found.x_range, found.y_range
        x0, x1, y0, y1 = x0 * sx, x1 * sx, y0 * sy, y1 * sy
        nx, ny = found.label.shape[1], found.label.shape[0]
        dx, dy = (x1 - x0) / max(nx - 1, 1), (y1 - y0) / max(ny - 1, 1)
        self.basin_image.data = {
            "image": [found.label.astype(float)],
            "x": [x0 - dx / 2],
            "y": [y0 - dy / 2],
            "dw": [x1 - x0 + dx],
            "dh": [y1 - y0 + dy],
        }
        xs, ys, texts = [], [], []
        for k, pts in enumerate(found.points):
            if found.kinds[k] == AttractorKind.INVALID or not len(pts):
                continue
            xs += (pts[:, 0] * sx).tolist()
            ys += (pts[:, 1] * sy).tolist()
            texts += [found.lines[k]] * len(pts)
        self.basin_points.data = {"x": xs, "y": ys, "text": texts}
        self.basins.visible = True

    def show_refined(self, refined: Diagram) -> None:
        """A zoomed-in diagram: its points replace the coarse ones over its range; a zoomed-in map
        is drawn over the coarse one."""
        if len(refined.view.axes) == 2:
            self.fine_image.data = map_image(refined)
            self._show_legend()
            return
        coarse = self.points.data
        a = refined.view.axes[0]
        par = self.view.parameter(0)
        lo, hi = par.to_display(a.lo), par.to_display(a.hi)
        keep = [i for i, x in enumerate(coarse["x"]) if not lo <= x <= hi]
        fine = diagram_columns(refined, self.view.component)
        self.points.data = {k: [coarse[k][i] for i in keep] + fine[k] for k in fine}
        self._show_legend()

    def show_point(self, rep: PointReport) -> None:
        par = self.view.parameter(0)
        self.clicked.location = par.to_display(rep.values[self.view.axes[0].name])
        self.clicked.visible = len(self.view.axes) == 1
        if len(self.view.axes) == 2:
            second = self.view.parameter(1)
            self.clicked_cell.data = {
                "x": [self.clicked.location],
                "y": [second.to_display(rep.values[self.view.axes[1].name])],
            }
        x = rep.trajectory * self.scales
        for i, src in enumerate(self.series_sources):
            src.data = {"t": rep.t.tolist(), "x": x[:, i].tolist()}
        impacts = rep.impact_states * self.scales
        self.series_impacts.data = {"t": rep.impact_t.tolist(), "x": impacts[:, 0].tolist()}
        j = 1 if x.shape[1] > 1 else 0
        self.phase_line.data = {"x": x[:, 0].tolist(), "y": x[:, j].tolist()}
        strobe = (rep.samples[-rep.period :] if rep.period > 0 else rep.samples) * self.scales
        self.phase_strobe.data = {"x": strobe[:, 0].tolist(), "y": strobe[:, j].tolist()}
        self.phase_impacts.data = {"x": impacts[:, 0].tolist(), "y": impacts[:, j].tolist()}
        self.series_modes.data = mode_span_columns(rep)
        self.series_switches.data = switch_columns(rep, self.scales, j)
        self.phase_sliding.data = sliding_columns(rep, self.scales, j)
        for k, (_, span) in enumerate(self.stop_spans):
            level = rep.model.stop_level(0, 0.0, k)
            if level is not None:
                span.location = level * self.scales[0]

    def show_branch(self, continued: Continued, row: float | None = None) -> tuple[float, float] | None:
        """A continued branch: on a diagram its points and special points, the diagram framed to a
        narrow branch (:func:`branch_frame`; the range framed, else None); on a map (at the clicked
        ``row``, model units) its special points."""
        if len(self.view.axes) == 2:
            self.marks.data = row_columns(self.view, continued.marks, row)
            return None
        self.branch.data = branch_columns(self.view, continued, self.view.component)
        self.marks.data = mark_columns(self.view, continued.marks, self.view.component)
        frame = branch_frame(self.view, continued)
        if frame is not None:
            self.diagram.x_range.update(start=frame[0], end=frame[1])
        return frame

    def show_curves(self, found: Curves) -> None:
        """Bifurcation curves on a period map, in display units."""
        p1, p2 = self.view.parameter(0), self.view.parameter(1)
        colours = CURVE_COLOURS
        self.curves.data = {
            "xs": [[p1.to_display(v) for v in c.first] for c in found.curves],
            "ys": [[p2.to_display(v) for v in c.second] for c in found.curves],
            "kind": [c.kind for c in found.curves],
            "text": [c.text for c in found.curves],
            "colour": [colours.get(c.kind, "black") for c in found.curves],
            "dash": [CURVE_DASHES.get(c.kind, "solid") for c in found.curves],
        }

    def show_grazings(self, found: Grazings, row: float | None = None) -> None:
        """Grazings: on a diagram a dotted line and the grazing orbit's points; on a map a mark on the row."""
        from bokeh.models import Span

        par = self.view.parameter(0)
        for span in self.grazing_spans:
            span.visible = False
        if len(self.view.axes) == 2:
            self.grazings.data = row_columns(self.view, found.marks, row)
            return
        for m in found.marks:
            span = Span(
                location=par.to_display(m.value),
                dimension="height",
                line_color="orange",
                line_dash="dotted",
                line_width=2,
            )
            self.diagram.add_layout(span)
            self.grazing_spans.append(span)
        if len(self.view.axes) == 1:
            self.grazings.data = mark_columns(self.view, found.marks, self.view.component)
