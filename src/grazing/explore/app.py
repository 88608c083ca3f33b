"""The explorer's page: one Panel component, served by ``grazing explore`` and shown in Jupyter.

:class:`Explorer` builds the page of one :class:`~grazing.explore.diagram.View`: the
diagram (computed in the background when the page opens, with a progress bar; refined
when zoomed in), the clicked point's orbit (a summary, the time series, the phase
portrait with the stops, the stroboscopic and impact points) and the actions on it
(continue the orbit, find the grazings in the range, copy as code).  Every request runs
in the background (:class:`~grazing.explore.jobs.Jobs`): the page stays responsive, a
newer click supersedes an older one, and anything that goes wrong (a point outside the
computed range, a parameter outside its interval, Newton's method failing) is a message
in the page, never a crash of the server.
"""

from __future__ import annotations

import traceback
from collections.abc import Callable
from typing import Any

from grazing.errors import GrazingError
from grazing.explore.basins import BasinView, basins_at
from grazing.explore.branch import (
    Continued,
    Curves,
    Grazings,
    continue_click,
    follow_click_curves,
    grazings_in_view,
)
from grazing.explore.code import view_code
from grazing.explore.diagram import Diagram, View, compute_diagram
from grazing.explore.figures import Figures
from grazing.explore.jobs import Jobs
from grazing.explore.point import PointReport, inspect_click

__all__ = ["NARROW", "PAGE_TEMPLATE", "REFINE_BELOW", "Explorer", "explorer"]

REFINE_BELOW = 0.5
"""Zoomed in to less than this fraction of the computed range, the diagram is computed again there."""

CLICK_HINT = "Click a point of the diagram (or type a value below) to see its orbit."

WHERE_IT_LIES = "where its state lies"
"""The start-mode choice of a model with modes that starts a click's simulation in the mode whose region
the diagram's state there lies in (:meth:`~grazing.HybridModel.mode_at`, the library's default)."""

NARROW = 560
"""The least width (CSS pixels) of the diagram's column and the orbit's beside it: on a narrower screen
(a phone) the page's columns stack, one above the other."""

PAGE_TEMPLATE = (
    '{% block postamble %}<meta name="viewport" content="width=device-width, initial-scale=1">{% endblock %}'
)
"""The served page's template (Panel's own, extended): a phone lays it out at its own width."""

MONOSPACE = (
    ":host textarea { font-family: ui-monospace, SFMono-Regular, Menlo, Consolas, 'DejaVu Sans Mono', "
    "'Liberation Mono', monospace; font-size: 13px; white-space: pre; overflow-x: auto; }"
)
"""The code boxes' style: code in a monospace font, its lines not wrapped (scrolled)."""


def flex(*children: Any, basis: int = NARROW) -> Any:
    """A row whose ``children`` share the width, each at least ``basis`` pixels wide, or wrap one under
    the other (the page's stacked layout on a narrow screen)."""
    import panel as pn

    for child in children:
        child.styles = {**child.styles, "flex": f"1 1 {basis}px", "min-width": "0"}
    return pn.FlexBox(*children, flex_wrap="wrap", sizing_mode="stretch_width")


def wrap(*children: Any) -> Any:
    """Widgets side by side, wrapping onto the next line where the screen is too narrow."""
    import panel as pn

    return pn.FlexBox(*children, flex_wrap="wrap", sizing_mode="stretch_width")


def message_of(exc: BaseException) -> str:
    """An error as the one line the page shows: the library's message, else its type and text."""
    if isinstance(exc, GrazingError):
        return str(exc)
    return f"unexpected error: {type(exc).__name__}: {exc}"


class Explorer:
    """The page of one view (see the module docstring); :attr:`panel` is the component.

    Parameters
    ----------
    view
        What to explore.
    deliver
        How results computed in the background reach the page (default: the
        server session's next tick when there is a session, else a direct call).
    compute
        Start computing the diagram at once (default).
    mode
        A model with modes: the mode a click's simulation starts in, from the diagram's state there
        (default: the one whose region that state lies in); the page's "Start mode" choice.
    """

    def __init__(
        self,
        view: View,
        *,
        deliver: Callable[[Callable[[], None]], None] | None = None,
        compute: bool = True,
        mode: str | None = None,
    ) -> None:
        import panel as pn

        if mode is not None:
            view.model.mode_index(mode)  # (a mode a run can start in: one line)
        self.view = view
        self.doc = pn.state.curdoc
        self.jobs = Jobs(deliver or self._deliver)
        self.diagram: Diagram | None = None
        self.refined: Diagram | None = None
        self.point: PointReport | None = None
        self.point_diagram: Diagram | None = None  # (the diagram the clicked point started from)
        self.continued: Continued | None = None
        self.basins: BasinView | None = None  # (found at the clicked point, for copy as code)
        self.grazings: Grazings | None = None  # (sought over the range, for copy as code)
        self.curves: Curves | None = None  # (followed from the continued point, for copy as code)
        self.figures = Figures(view)
        model = view.model
        names = [view.parameter(i) for i in range(len(view.axes))]
        fixed = ", ".join(
            model.parameter(n).show(v, ".6g") for n, v in model.params.items() if n not in view.names
        )
        ranges = "; ".join(p.show_range(a.lo, a.hi, ".6g") for p, a in zip(names, view.axes))
        modes = f"; modes: {', '.join(model.mode_names)}" if model.has_modes else ""
        self.header = pn.pane.Markdown(
            f"### grazing explore: {model.name}\n{ranges} ({' x '.join(str(a.num) for a in view.axes)} "
            f"points); {fixed}{modes}",
            sizing_mode="stretch_width",
        )
        self.progress = pn.indicators.Progress(value=0, max=100, width=240, bar_color="primary")
        self.status = pn.pane.Markdown(
            "computing the diagram ...", sizing_mode="stretch_width", css_classes=["grazing-status"]
        )
        self.orbit = pn.pane.Markdown(CLICK_HINT, sizing_mode="stretch_width", css_classes=["grazing-orbit"])
        self.actions_text = pn.pane.Markdown("", sizing_mode="stretch_width", css_classes=["grazing-branch"])
        self.grazings_text = pn.pane.Markdown(
            "", sizing_mode="stretch_width", css_classes=["grazing-grazings"]
        )
        self.inputs = [
            pn.widgets.FloatInput(
                label=f"{p.label} ({p.display_unit})" if p.display_unit else p.label, value=None, width=150
            )
            for p in names
        ]
        real = [m for m in model.mode_names if m not in model.sliding_names]
        self.mode_select = pn.widgets.Select(
            label="Start mode", options=[WHERE_IT_LIES, *real], value=mode or WHERE_IT_LIES, width=180,
            visible=model.has_modes,
        )  # fmt: skip
        self.show_button = pn.widgets.Button(label="Show this point")
        self.continue_button = pn.widgets.Button(label="Continue this orbit", disabled=True)
        self.grazings_button = pn.widgets.Button(label="Find the grazings")
        self.code_button = pn.widgets.Button(label="Copy as code")
        self.basins_button = pn.widgets.Button(label="Basins of attraction", disabled=True)
        self.basins_text = pn.pane.Markdown("", sizing_mode="stretch_width", css_classes=["grazing-basins"])
        self.curves_button = pn.widgets.Button(
            label="Follow the bifurcation curves", disabled=True, visible=len(view.axes) == 2
        )
        self.curves_text = pn.pane.Markdown("", sizing_mode="stretch_width", css_classes=["grazing-curves"])
        self.code_python = pn.widgets.TextAreaInput(
            label="Python", height=260, sizing_mode="stretch_width", visible=False, stylesheets=[MONOSPACE]
        )
        self.code_cli = pn.widgets.TextAreaInput(
            label="Command line",
            height=160,
            sizing_mode="stretch_width",
            visible=False,
            stylesheets=[MONOSPACE],
        )
        self.show_button.on_click(lambda _e: self.click_values([w.value for w in self.inputs]))
        self.continue_button.on_click(lambda _e: self.continue_orbit())
        self.grazings_button.on_click(lambda _e: self.find_grazings())
        self.code_button.on_click(lambda _e: self.show_code())
        self.curves_button.on_click(lambda _e: self.follow_curves())
        self.basins_button.on_click(lambda _e: self.find_basins())
        from bokeh.events import DoubleTap, RangesUpdate, Tap

        self.figures.diagram.on_event(Tap, self._on_tap)
        self.figures.diagram.on_event(DoubleTap, self._on_tap)  # (two quick clicks: the second is not a Tap)
        self.figures.diagram.on_event(RangesUpdate, self._on_ranges)
        self.panel = pn.Column(
            self.header,
            wrap(self.progress, self.status),
            flex(
                pn.Column(
                    pn.pane.Bokeh(self.figures.diagram, sizing_mode="stretch_width"),
                    pn.pane.Bokeh(self.figures.readout, sizing_mode="stretch_width"),
                    pn.pane.Bokeh(self.figures.legend, sizing_mode="stretch_width"),
                    wrap(*self.inputs, self.mode_select, self.show_button),
                    sizing_mode="stretch_width",
                ),
                pn.Column(
                    pn.pane.Markdown("#### Orbit"),
                    self.orbit,
                    wrap(self.continue_button, self.grazings_button, self.code_button),
                    wrap(self.curves_button, self.basins_button),
                    self.actions_text,
                    self.grazings_text,
                    self.curves_text,
                    self.basins_text,
                    sizing_mode="stretch_width",
                ),
            ),
            flex(
                pn.pane.Bokeh(self.figures.series, sizing_mode="stretch_width"),
                pn.pane.Bokeh(self.figures.phase, sizing_mode="stretch_width"),
            ),
            pn.pane.Bokeh(self.figures.basins, sizing_mode="stretch_width"),
            self.code_python,
            self.code_cli,
            sizing_mode="stretch_width",
        )
        if compute:
            self.compute()

    # -- plumbing -------------------------------------------------------------------------

    def _deliver(self, fn: Callable[[], None]) -> None:
        doc = self.doc
        if doc is not None and getattr(doc, "session_context", None) is not None:
            doc.add_next_tick_callback(lambda: self._guarded(fn))
        else:
            self._guarded(fn)

    def _guarded(self, fn: Callable[[], None]) -> None:
        """Run a page update; an error in it is a message in the page, not a broken session."""
        try:
            fn()
        except Exception as exc:  # pragma: no cover - a bug of ours: shown, and on the server's stderr
            traceback.print_exc()
            self.status.object = f"**error:** {message_of(exc)}"

    def close(self) -> None:
        """Stop the background work of this page (its session ended)."""
        self.jobs.close(timeout=0.1)

    # -- the diagram ------------------------------------------------------------------------

    def compute(self) -> None:
        """Compute the diagram in the background, with progress."""
        self.progress.value = 0
        self.progress.visible = True

        def work(cancelled: Callable[[], bool]) -> Diagram:
            return compute_diagram(self.view, progress=self._progress_from_worker, cancelled=cancelled)

        self.jobs.submit("diagram", work, self._diagram_done, self._diagram_failed)

    def _progress_from_worker(self, done: int, total: int) -> None:
        def update() -> None:
            self.progress.value = int(100 * done / max(total, 1))
            self.status.object = f"computing the diagram: {done} of {total} points"

        self.jobs.deliver(update)

    def _diagram_done(self, diagram: Diagram) -> None:
        from grazing.sweeps.status import failure_text

        self.figures.show_diagram(diagram)
        self.progress.value = 100
        self.progress.visible = False
        failed = failure_text(diagram.status)
        self.status.object = f"diagram: {diagram.period.size} points in {diagram.elapsed:.1f} s; {failed}"
        self.diagram = diagram  # (last: clicks use it from now on)

    def _diagram_failed(self, exc: BaseException) -> None:
        self.progress.visible = False
        self.status.object = f"**the diagram could not be computed:** {message_of(exc)}"

    def _visible(self, i: int, a: float | None, b: float | None) -> tuple[float, float] | None:
        """The visible part ``[lo, hi]`` (model units) of explored parameter ``i``, or None."""
        if a is None or b is None:
            return None
        par, axis = self.view.parameter(i), self.view.axes[i]
        lo = max(axis.lo, par.from_display(min(a, b)))
        hi = min(axis.hi, par.from_display(max(a, b)))
        return (lo, hi) if lo < hi else None

    def _on_ranges(self, event: Any) -> None:
        """Zoomed in far enough: compute the diagram (or map) again over the visible range (as many
        points or cells).  On a map, far enough in either parameter."""
        self.refine(event.x0, event.x1, getattr(event, "y0", None), getattr(event, "y1", None))

    def refine(self, x0: float, x1: float, y0: float | None = None, y1: float | None = None) -> None:
        """The diagram shown over ``[x0, x1]`` (and a map's ``[y0, y1]``; display units): computed again
        there when that is far enough inside the computed range (:data:`REFINE_BELOW`)."""
        if self.diagram is None:
            return
        ranges = [self._visible(0, x0, x1)]
        if len(self.view.axes) == 2:
            ranges.append(self._visible(1, y0, y1))
        if any(r is None for r in ranges):
            return
        full = [a.hi - a.lo for a in self.view.axes]
        if all((hi - lo) > REFINE_BELOW * w for (lo, hi), w in zip(ranges, full)):  # type: ignore[misc]
            return
        current = self.refined.view.axes if self.refined is not None else None
        if current is not None and all(
            c.lo <= lo and hi <= c.hi and (hi - lo) > 0.5 * (c.hi - c.lo)
            for (lo, hi), c in zip(ranges, current)  # type: ignore[misc]
        ):
            return
        zoomed = self.view.zoomed(*[v for r in ranges for v in r])  # type: ignore[union-attr]
        shown = ", ".join(
            self.view.parameter(i).show_range(lo, hi, ".6g")
            for i, (lo, hi) in enumerate(ranges)  # type: ignore[misc]
        )
        self.status.object = f"refining the diagram over {shown} ..."

        def work(cancelled: Callable[[], bool]) -> Diagram:
            return compute_diagram(zoomed, cancelled=cancelled)

        self.jobs.submit("refine", work, self._refined_done, self._diagram_failed)

    def _refined_done(self, diagram: Diagram) -> None:
        self.figures.show_refined(diagram)
        axes = diagram.view.axes
        count = " x ".join(str(a.num) for a in axes) + (" points" if len(axes) == 1 else " cells")
        shown = ", ".join(self.view.parameter(i).show_range(a.lo, a.hi, ".6g") for i, a in enumerate(axes))
        self.status.object = f"refined: {count} over {shown} in {diagram.elapsed:.1f} s"
        self.refined = diagram  # (last: clicks use it from now on)

    # -- a click ------------------------------------------------------------------------------

    def _on_tap(self, event: Any) -> None:
        values = [event.x] if len(self.view.axes) == 1 else [event.x, event.y]
        self.click_values(values)

    def click_values(self, shown: list[float | None]) -> None:
        """Inspect the point at ``shown`` (display units, one per explored parameter), in the background."""
        if self.diagram is None:
            self.orbit.object = "the diagram is still being computed: click again when it is shown"
            return
        if any(v is None for v in shown):
            self.orbit.object = "give a value for every parameter"
            return
        values = [self.view.parameter(i).from_display(float(v)) for i, v in enumerate(shown)]  # type: ignore[arg-type]
        for w, v in zip(self.inputs, shown):
            w.value = float(f"{float(v):.6g}")  # (what a person would type)
        diagram = self._diagram_for(values)
        text = ", ".join(self.view.parameter(i).show(v, ".6g") for i, v in enumerate(values))
        self.orbit.object = f"computing the orbit at {text} ..."
        self.continue_button.disabled = True

        mode = self.start_mode

        def work(cancelled: Callable[[], bool]) -> PointReport:
            return inspect_click(diagram, values, mode=mode, cancelled=cancelled)

        def done(rep: PointReport) -> None:
            self.point_diagram = diagram  # (the one its simulation started from: copy as code sweeps it)
            self._point_done(rep)

        self.jobs.submit("point", work, done, self._point_failed)

    @property
    def start_mode(self) -> str | None:
        """The mode a click's simulation starts in (None: where the diagram's state lies; no modes)."""
        value = self.mode_select.value
        return None if value == WHERE_IT_LIES or not self.view.model.has_modes else str(value)

    def _diagram_for(self, values: list[float]) -> Diagram:
        """The finest computed diagram containing the point (the refined one when zoomed)."""
        assert self.diagram is not None
        r = self.refined
        if r is not None and all(a.contains(v) for a, v in zip(r.view.axes, values)):
            return r
        return self.diagram

    def _point_done(self, rep: PointReport) -> None:
        self.continued = None
        self.basins = self.curves = None
        self.curves_button.disabled = True
        self.basins_button.disabled = False
        self.figures.show_point(rep)
        self.orbit.object = "\n\n".join(rep.summary().splitlines())
        self.continue_button.disabled = rep.orbit is None
        self.point = rep
        if self.code_python.visible:
            self.show_code()

    def _point_failed(self, exc: BaseException) -> None:
        self.orbit.object = f"**{message_of(exc)}**"

    # -- actions on the clicked point -----------------------------------------------------------

    def continue_orbit(self) -> None:
        """Continue the clicked orbit both ways over the range, in the background."""
        point = self.point
        if point is None or point.orbit is None:
            self.actions_text.object = "click a point with a periodic orbit first"
            return
        self.actions_text.object = "continuing the orbit ..."

        def work(cancelled: Callable[[], bool]) -> Continued:
            return continue_click(self.view, point, cancelled=cancelled)

        def done(c: Continued) -> None:
            if self.point is not point:
                return  # another point was clicked meanwhile
            self.continued, self.curves = c, None  # (before the text that says it is done)
            frame = self.figures.show_branch(c, self._row(point))
            lines = list(c.lines)
            if frame is not None:
                par = self.view.parameter(0)
                shown = par.show_range(par.from_display(frame[0]), par.from_display(frame[1]), ".6g")
                lines.append(
                    f"the diagram is framed to the branch: {shown} (the toolbar's reset shows it all)"
                )
                self.refine(*frame)  # (computed again there, as a zoom there would)
            self.actions_text.object = "\n\n".join(lines)
            self.curves_button.disabled = False
            if self.code_python.visible:
                self.show_code()

        self.jobs.submit("branch", work, done, lambda e: setattr(self.actions_text, "object", message_of(e)))

    def follow_curves(self) -> None:
        """On a period map: follow the continued orbit's special points in the map's two parameters."""
        point, continued = self.point, self.continued
        if point is None or continued is None:
            self.curves_text.object = "continue a clicked orbit first: its special points are followed"
            return
        self.curves_text.object = "following the bifurcation curves ..."

        def work(cancelled: Callable[[], bool]) -> Curves:
            return follow_click_curves(self.view, point, continued, cancelled=cancelled)

        def done(found: Curves) -> None:
            current = self.point is point and self.continued is continued  # (else superseded meanwhile)
            if current:
                self.curves = found  # (before the text that says it is done)
            self.figures.show_curves(found)
            self.curves_text.object = "\n\n".join(found.lines)
            if current and self.code_python.visible:
                self.show_code()

        self.jobs.submit("curves", work, done, lambda e: setattr(self.curves_text, "object", message_of(e)))

    def find_basins(self) -> None:
        """The basins of attraction at the clicked parameters, around its motion."""
        point = self.point
        if point is None:
            self.basins_text.object = "click a point first"
            return
        self.basins_text.object = "finding the attractors and their basins ..."

        def done(found: BasinView) -> None:
            current = self.point is point  # (else another point was clicked meanwhile)
            if current:
                self.basins = found  # (before the text that says it is done)
            self.figures.show_basins(found)
            self.basins_text.object = "\n\n".join(found.lines)
            if current and self.code_python.visible:
                self.show_code()

        self.jobs.submit(
            "basins",
            lambda _c: basins_at(point),
            done,
            lambda e: setattr(self.basins_text, "object", message_of(e)),
        )

    def _row(self, point: PointReport) -> float | None:
        """The clicked row of a map (its second parameter's value), else None."""
        return point.values[self.view.axes[1].name] if len(self.view.axes) == 2 else None

    def find_grazings(self) -> None:
        """Find the grazings of the nonimpacting orbit over the range (at the clicked row of a map)."""
        fixed = {}
        if len(self.view.axes) == 2:
            if self.point is None:
                self.grazings_text.object = "click a row of the map first: the grazings are sought along it"
                return
            name = self.view.axes[1].name
            fixed = {name: self.point.values[name]}
        self.grazings_text.object = "finding the grazings ..."

        def work(cancelled: Callable[[], bool]) -> Grazings:
            return grazings_in_view(self.view, fixed, mode=self.start_mode, cancelled=cancelled)

        def done(g: Grazings) -> None:
            self.figures.show_grazings(g, fixed.get(self.view.axes[-1].name))
            self.grazings_text.object = "\n\n".join(g.lines)
            self.grazings = g
            if self.code_python.visible:
                self.show_code()

        self.jobs.submit(
            "grazings", work, done, lambda e: setattr(self.grazings_text, "object", message_of(e))
        )

    def show_code(self) -> None:
        """Show the Python and the command lines that reproduce the view."""
        view = self.view if self.point is None or self.point_diagram is None else self.point_diagram.view
        code = view_code(
            view,
            self.point,
            continued=self.continued is not None,
            basins=self.basins,
            grazings=self.grazings,
            curves=self.curves,
        )
        self.code_python.value = code.python
        self.code_cli.value = code.cli
        self.code_python.visible = self.code_cli.visible = True


def explorer(
    model: Any,
    ranges: dict[str, tuple[float, float]] | None = None,
    *,
    num: int | None = None,
    component: int | str = 0,
    source: str | None = None,
    mode: str | None = None,
) -> Any:
    """The explorer of ``model`` over ``ranges`` as a Panel component: display it in a Jupyter notebook.

    Parameters
    ----------
    model
        A :class:`~grazing.HybridModel`, its other parameters set.
    ranges
        ``{name: (lo, hi)}`` in display units (degrees for angles): one parameter
        (a bifurcation diagram) or two (a period map).  Default for the pendulum:
        ``{"eta": (0.44, 0.49)}``.
    num
        Points per parameter (default :data:`~grazing.explore.diagram.DEFAULT_NUM`).
    component
        The state on the diagram's vertical axis (index or name).
    source
        How the model was made, as ``--model`` takes it (for "copy as code").
    mode
        A model with modes: the mode a click's simulation starts in (default: the one whose region
        the diagram's state there lies in).

    Examples
    --------
    In a notebook (``pip install grazing[explore]``)::

        import panel as pn, grazing
        pn.extension()
        grazing.explore.explorer(grazing.models.pendulum("B"), {"eta": (0.44, 0.49)})
    """
    from grazing.explore.source import ModelSource

    if ranges is None:
        if model.name != "pendulum":
            raise GrazingError("give the ranges explored: {name: (lo, hi)}")
        ranges = {"eta": (0.44, 0.49)}
    view = View.of(model, ranges, num=num, source=ModelSource.of(model, source), component=component)
    return Explorer(view, mode=mode).panel
