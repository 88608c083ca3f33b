"""The explorer's plots (Bokeh): the diagram or period map, the orbit's time series and phase portrait.

The data of each plot is built from the records of :mod:`grazing.explore` by a plain
function returning the columns of a Bokeh ``ColumnDataSource`` (testable without a
browser); :class:`Figures` holds the figures and their sources, and is changed only by
replacing those columns.  Labels come from the parameters' and states' metadata (symbol,
display unit: degrees for angles).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from grazing.core.model import HybridModel, Parameter
from grazing.explore.basins import BasinView
from grazing.explore.branch import Continued, Curves, Grazings, Mark
from grazing.explore.diagram import Diagram, View
from grazing.explore.point import PointReport

__all__ = ["PERIOD_COLOURS", "Figures", "branch_columns", "diagram_columns", "mark_columns", "period_label"]

PERIOD_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf")
"""The colours of periods 1 to 8 (longer periods, no period and failed points are grey)."""

OTHER_COLOUR, NONE_COLOUR, FAILED_COLOUR = "#7f7f7f", "#444444", "#ff00ff"


def period_label(period: int) -> str:
    """How a period is shown: ``"5"``, ``"none <= 64"``, ``"failed"``."""
    if period > 0:
        return str(int(period))
    return "none <= 64" if period == 0 else "failed"


def period_colour(period: int) -> str:
    if 0 < period <= len(PERIOD_COLOURS):
        return PERIOD_COLOURS[period - 1]
    return OTHER_COLOUR if period > 0 else (NONE_COLOUR if period == 0 else FAILED_COLOUR)


def axis_label(par: Parameter) -> str:
    unit = par.display_unit
    return f"{par.label} ({unit})" if unit else par.label


def state_label(model: HybridModel, i: int) -> str:
    unit = model.state_units[i] if model.state_units else ""
    return f"{model.state_labels[i]} ({unit})" if unit else model.state_labels[i]


def diagram_columns(diagram: Diagram, component: int) -> dict[str, list[Any]]:
    """The stroboscopic points of a one-parameter diagram: one per distinct sample of each point.

    A point with period ``p`` contributes its last ``p`` samples, one without a
    period all of them, a failed point none (its samples are NaN).
    """
    par = diagram.view.parameter(0)
    xs, ys, labels, colours, ipp = [], [], [], [], []
    assert diagram.samples is not None
    for i, value in enumerate(diagram.values[0]):
        p = int(diagram.period[i])
        s = diagram.samples[i, -p:, component] if p > 0 else diagram.samples[i, :, component]
        s = s[np.isfinite(s)]
        xs += [par.to_display(value)] * s.size
        ys += s.tolist()
        labels += [period_label(p)] * s.size
        colours += [period_colour(p)] * s.size
        ipp += [float(diagram.impacts_per_period[i])] * s.size
    return {"x": xs, "y": ys, "period": labels, "colour": colours, "impacts": ipp}


def map_image(diagram: Diagram) -> dict[str, list[Any]]:
    """A period map as an image: the period of each cell (NaN where there is none; -1 where it failed)."""
    a, b = diagram.view.axes
    pa, pb = diagram.view.parameter(0), diagram.view.parameter(1)
    lo1, hi1, lo2, hi2 = pa.to_display(a.lo), pa.to_display(a.hi), pb.to_display(b.lo), pb.to_display(b.hi)
    d1, d2 = (hi1 - lo1) / (a.num - 1), (hi2 - lo2) / (b.num - 1)
    image = np.where(diagram.period == 0, np.nan, diagram.period).astype(float)
    return {
        "image": [image],
        "x": [lo1 - d1 / 2],
        "y": [lo2 - d2 / 2],
        "dw": [hi1 - lo1 + d1],
        "dh": [hi2 - lo2 + d2],
    }


def branch_columns(view: View, continued: Continued, component: int) -> dict[str, list[Any]]:
    """The continued branch's points at phase 0 (one per forcing period of each orbit).

    Each is ``stable``, ``unstable`` or, for a virtual orbit that passes through a stop (a
    nonimpacting branch followed past its grazing), ``through a stop``: drawn apart, it is not
    a motion of the system.
    """
    par = view.parameter(0)
    xs, ys, kinds = [], [], []
    for piece in continued.pieces:
        for value, states, st, cross in zip(piece.values, piece.states, piece.stable, piece.crossing):
            kind = "through a stop (not a motion)" if cross else ("stable" if st else "unstable")
            xs += [par.to_display(value)] * len(states)
            ys += [float(v) for v in states[:, component]]
            kinds += [kind] * len(states)
    fill = {"stable": "black", "unstable": "white"}
    line = {"stable": "black", "unstable": "black"}
    return {
        "x": xs,
        "y": ys,
        "stable": kinds,
        "fill": [fill.get(k, "#dddddd") for k in kinds],
        "line": [line.get(k, "#aaaaaa") for k in kinds],
    }


def mark_columns(view: View, marks: tuple[Mark, ...], component: int) -> dict[str, list[Any]]:
    """Special points (and grazings) at phase 0, with their text for the hover."""
    par = view.parameter(0)
    xs, ys, kinds, texts = [], [], [], []
    for m in marks:
        for s in m.states:
            xs.append(par.to_display(m.value))
            ys.append(float(s[component]))
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


class Figures:
    """The explorer's Bokeh figures and their data sources."""

    def __init__(self, view: View) -> None:
        from bokeh.models import ColumnDataSource, HoverTool, Span
        from bokeh.plotting import figure

        self.view = view
        model = view.model
        par = view.parameter(0)
        tools = "pan,wheel_zoom,box_zoom,reset,tap,save"
        self.diagram = figure(
            height=460,
            sizing_mode="stretch_width",
            tools=tools,
            active_scroll="wheel_zoom",
            x_axis_label=axis_label(par),
            name="diagram",
            output_backend="canvas",
        )
        lo, hi = par.to_display(view.axes[0].lo), par.to_display(view.axes[0].hi)
        self.diagram.x_range.start, self.diagram.x_range.end = lo, hi
        if len(view.axes) == 1:
            self.diagram.title.text = (
                f"bifurcation diagram: stroboscopic {model.state_labels[view.component]}"
            )
            self.diagram.yaxis.axis_label = state_label(model, view.component)
            self.points = ColumnDataSource({"x": [], "y": [], "period": [], "colour": [], "impacts": []})
            r = self.diagram.scatter("x", "y", source=self.points, size=2, color="colour", alpha=0.8)
            self.diagram.add_tools(
                HoverTool(
                    renderers=[r],
                    tooltips=[
                        (par.label, "@x{0.000000}"),
                        ("period", "@period"),
                        ("impacts per period", "@impacts{0.[00]}"),
                    ],
                )
            )
        else:
            from bokeh.models import LinearColorMapper

            pb = view.parameter(1)
            self.diagram.title.text = (
                "period map (colours as periods 1 to 8; grey: longer; white: none <= 64)"
            )
            self.diagram.yaxis.axis_label = axis_label(pb)
            self.diagram.y_range.start = pb.to_display(view.axes[1].lo)
            self.diagram.y_range.end = pb.to_display(view.axes[1].hi)
            self.image = ColumnDataSource({"image": [], "x": [], "y": [], "dw": [], "dh": []})
            n = len(PERIOD_COLOURS)  # (periods 1 to 8 in the diagram's colours, longer grey, failed magenta)
            mapper = LinearColorMapper(
                palette=list(PERIOD_COLOURS),
                low=0.5,
                high=n + 0.5,
                nan_color="white",
                high_color=OTHER_COLOUR,
                low_color=FAILED_COLOUR,
            )
            r = self.diagram.image(
                "image", x="x", y="y", dw="dw", dh="dh", source=self.image, color_mapper=mapper
            )
            self.fine_image = ColumnDataSource({"image": [], "x": [], "y": [], "dw": [], "dh": []})
            fine = self.diagram.image(  # (a zoomed-in map, drawn over the coarse one where it is)
                "image", x="x", y="y", dw="dw", dh="dh", source=self.fine_image, color_mapper=mapper
            )
            self.diagram.add_tools(
                HoverTool(
                    renderers=[r, fine],
                    tooltips=[
                        (par.label, "$x{0.000000}"),
                        (pb.label, "$y{0.000000}"),
                        ("period", "@image"),
                    ],
                )
            )
        self.branch = ColumnDataSource({"x": [], "y": [], "stable": [], "fill": [], "line": []})
        self.marks = ColumnDataSource({"x": [], "y": [], "kind": [], "text": []})
        self.grazings = ColumnDataSource({"x": [], "y": [], "kind": [], "text": []})
        self.curves = ColumnDataSource({"xs": [], "ys": [], "kind": [], "text": [], "colour": []})
        if len(view.axes) == 2:
            rc = self.diagram.multi_line("xs", "ys", source=self.curves, line_color="colour", line_width=3)
            self.diagram.add_tools(HoverTool(renderers=[rc], tooltips=[("", "@text")]))
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
        self.diagram.add_tools(HoverTool(renderers=[rm, rg], tooltips=[("", "@text")]))
        if len(view.axes) == 1:
            rb = self.diagram.scatter(
                "x", "y", source=self.branch, size=4, line_color="line", fill_color="fill"
            )
            self.diagram.add_tools(
                HoverTool(renderers=[rb], tooltips=[(par.label, "@x{0.000000}"), ("branch", "@stable")])
            )
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
        self.series_sources = []
        for i, colour in zip(range(model.n_states), PERIOD_COLOURS):
            src = ColumnDataSource({"t": [], "x": []})
            self.series.line("t", "x", source=src, color=colour, legend_label=model.state_labels[i])
            self.series_sources.append(src)
        self.series_impacts = ColumnDataSource({"t": [], "x": []})
        self.series.scatter(
            "t", "x", source=self.series_impacts, marker="x", size=9, color="black", legend_label="impact"
        )
        self.series.legend.click_policy = "hide"
        self.series.add_layout(self.series.legend[0], "right")  # (beside the plot: it hides no data)
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
        self.phase.legend.click_policy = "hide"
        self.phase.add_layout(self.phase.legend[0], "right")
        self._basins_figure(model)
        self.stop_spans = []
        for k, name in enumerate(model.stop_names):
            level = model.stop_level(0, 0.0, k)
            if level is not None and np.isfinite(level):
                span = Span(location=level, dimension="height", line_color="grey", line_width=3)
                self.phase.add_layout(span)
                self.stop_spans.append((name, span))

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

    def show_basins(self, found: BasinView) -> None:
        """The basins: each initial state coloured by its attractor, the attractors' points on top."""
        (x0, x1), (y0, y1) = found.x_range, found.y_range
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
            if found.kinds[k] == "invalid" or not len(pts):
                continue
            xs += pts[:, 0].tolist()
            ys += pts[:, 1].tolist()
            texts += [found.lines[k]] * len(pts)
        self.basin_points.data = {"x": xs, "y": ys, "text": texts}
        self.basins.visible = True

    def show_refined(self, refined: Diagram) -> None:
        """A zoomed-in diagram: its points replace the coarse ones over its range; a zoomed-in map
        is drawn over the coarse one."""
        if len(refined.view.axes) == 2:
            self.fine_image.data = map_image(refined)
            return
        coarse = self.points.data
        a = refined.view.axes[0]
        par = self.view.parameter(0)
        lo, hi = par.to_display(a.lo), par.to_display(a.hi)
        keep = [i for i, x in enumerate(coarse["x"]) if not lo <= x <= hi]
        fine = diagram_columns(refined, self.view.component)
        self.points.data = {k: [coarse[k][i] for i in keep] + fine[k] for k in fine}

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
        x = rep.trajectory
        for i, src in enumerate(self.series_sources):
            src.data = {"t": rep.t.tolist(), "x": x[:, i].tolist()}
        self.series_impacts.data = {"t": rep.impact_t.tolist(), "x": rep.impact_states[:, 0].tolist()}
        j = 1 if x.shape[1] > 1 else 0
        self.phase_line.data = {"x": x[:, 0].tolist(), "y": x[:, j].tolist()}
        strobe = rep.samples[-rep.period :] if rep.period > 0 else rep.samples
        self.phase_strobe.data = {"x": strobe[:, 0].tolist(), "y": strobe[:, j].tolist()}
        self.phase_impacts.data = {
            "x": rep.impact_states[:, 0].tolist(),
            "y": rep.impact_states[:, j].tolist(),
        }
        for k, (_, span) in enumerate(self.stop_spans):
            level = rep.model.stop_level(0, 0.0, k)
            if level is not None:
                span.location = level

    def show_branch(self, continued: Continued, row: float | None = None) -> None:
        """A continued branch: on a diagram its points and special points; on a map (at the clicked
        ``row``, model units) its special points."""
        if len(self.view.axes) == 1:
            self.branch.data = branch_columns(self.view, continued, self.view.component)
            self.marks.data = mark_columns(self.view, continued.marks, self.view.component)
        else:
            self.marks.data = row_columns(self.view, continued.marks, row)

    def show_curves(self, found: Curves) -> None:
        """Bifurcation curves on a period map, in display units."""
        p1, p2 = self.view.parameter(0), self.view.parameter(1)
        colours = {
            "fold": "black",
            "period-doubling": "red",
            "neimark-sacker": "purple",
            "branch-point": "brown",
            "grazing": "orange",
        }
        self.curves.data = {
            "xs": [[p1.to_display(v) for v in c.first] for c in found.curves],
            "ys": [[p2.to_display(v) for v in c.second] for c in found.curves],
            "kind": [c.kind for c in found.curves],
            "text": [c.text for c in found.curves],
            "colour": [colours.get(c.kind, "black") for c in found.curves],
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
