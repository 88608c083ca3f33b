"""The explorer's page without a browser: its background requests, its answers to clicks, its two hosts."""

from __future__ import annotations

import math
import threading
import time

import numpy as np
import pytest

import grazing
from grazing.explore import View
from grazing.explore.app import CLICK_HINT, Explorer, explorer
from grazing.explore.jobs import Jobs


def wait_until(cond, limit=120.0):
    end = time.monotonic() + limit
    while not cond():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.02)


def test_a_newer_request_supersedes_a_running_one_and_only_its_result_arrives():
    delivered, started, release = [], threading.Event(), threading.Event()
    seen_cancelled = []
    jobs = Jobs(deliver=lambda fn: fn())

    def first(cancelled):
        started.set()
        release.wait(10)
        seen_cancelled.append(cancelled())
        return "first"

    jobs.submit("point", first, delivered.append, delivered.append)
    assert started.wait(10)
    jobs.submit("point", lambda c: "second", delivered.append, delivered.append)
    jobs.submit("point", lambda c: "third", delivered.append, delivered.append)  # replaces the waiting second
    release.set()
    wait_until(lambda: delivered)
    time.sleep(0.2)
    assert delivered == ["third"] and seen_cancelled == [True]
    jobs.close()


def test_an_error_in_a_request_is_delivered_as_an_error_and_the_lane_goes_on():
    got = []
    jobs = Jobs(deliver=lambda fn: fn())
    jobs.submit("point", lambda c: 1 / 0, got.append, lambda e: got.append(type(e).__name__))
    wait_until(lambda: got)
    jobs.submit("point", lambda c: "next", got.append, got.append)
    wait_until(lambda: len(got) == 2)
    assert got == ["ZeroDivisionError", "next"]
    jobs.close()


def test_a_long_diagram_does_not_hold_up_a_click():
    got, release = [], threading.Event()
    jobs = Jobs(deliver=lambda fn: fn())
    jobs.submit("diagram", lambda c: release.wait(10), got.append, got.append)
    jobs.submit("point", lambda c: "point", got.append, got.append)
    wait_until(lambda: got == ["point"])
    release.set()
    wait_until(lambda: len(got) == 2)
    jobs.close()


@pytest.fixture(scope="module")
def page():
    model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    shown = []

    def deliver(fn):  # (what the page says after each update: the progress of the diagram too)
        fn()
        shown.append((app.progress.value, app.status.object))

    app = Explorer(View.of(model, {"eta": (0.44, 0.49)}, num=21), deliver=deliver, compute=False)
    app.compute()
    wait_until(lambda: app.diagram is not None or "could not" in app.status.object)
    app.shown = shown
    yield app
    app.close()


def test_the_diagram_shows_its_progress(page):
    # chunks of 25 points: 21 points are one chunk, so the bar goes from 0 to 100 through "21 of 21"
    assert (0, "computing the diagram: 0 of 21 points") in page.shown
    assert (100, "computing the diagram: 21 of 21 points") in page.shown
    assert not page.progress.visible  # (done: hidden)


def test_the_page_answers_a_click_continues_and_copies(page):
    assert page.status.object.startswith("diagram: 21 points in")
    assert page.orbit.object == CLICK_HINT
    page.click_values([0.446])
    wait_until(lambda: page.point is not None)
    wait_until(lambda: "Floquet" in page.orbit.object)
    assert page.orbit.object.startswith("period 5 with 1 impact per period (stop: 1, back: 0)")
    assert not page.continue_button.disabled
    assert len(page.figures.series_sources[0].data["t"]) > 5 * 200
    page.continue_orbit()
    wait_until(lambda: page.continued is not None)
    assert "grazing at eta = 0.44512118" in page.actions_text.object
    assert len(page.figures.marks.data["x"]) == 5 * len(page.continued.marks)
    # the period-5 window is ~0.001 wide of the 0.05 computed: the diagram is framed to its branch,
    # the branch (grazing to grazing) in the middle third, and computed again there
    start, end = page.figures.diagram.x_range.start, page.figures.diagram.x_range.end
    graze = sorted(m.value for m in page.continued.marks if m.kind == "grazing")
    assert start < graze[0] < graze[1] < end and end - start == pytest.approx(
        3 * (graze[1] - graze[0]), rel=0.05
    )
    assert "the diagram is framed to the branch: eta in [0.44389" in page.actions_text.object
    wait_until(lambda: page.refined is not None)
    assert page.refined.view.axes[0].lo == pytest.approx(start)
    page.show_code()
    assert page.code_python.visible and "continue_orbit(point, 'eta', 0.446" in page.code_python.value
    # the diagram the click started from, not the one computed again over the frame since
    assert "np.linspace(0.44, 0.49, 21)" in page.code_python.value
    assert page.code_cli.value.startswith("grazing sweep --model pendulum")


def test_bad_clicks_are_messages_in_the_page(page):
    page.click_values([0.5])
    wait_until(lambda: "outside" in page.orbit.object)
    assert page.orbit.object == (
        "**eta = 0.5 is outside the computed range eta in [0.44, 0.49]: click inside the diagram**"
    )
    page.click_values([None])
    assert page.orbit.object == "give a value for every parameter"
    page.find_grazings()
    wait_until(lambda: "grazing at" in page.grazings_text.object)
    assert page.grazings_text.object.startswith("grazing at eta = 0.44512118")
    wait_until(lambda: page.grazings is not None)
    page.show_code()
    assert "_, branch = find_grazings(model, 'eta', 0.44, 0.49, period=1)" in page.code_python.value
    assert "\ngrazing graze --model pendulum" in page.code_cli.value


def test_the_same_component_renders_without_a_server_as_in_a_notebook():
    """Jupyter displays a Panel component by asking for its MIME bundle (the Bokeh document, rendered
    through the notebook's comms, no server): the same call here."""
    import panel as pn
    from bokeh.models import LayoutDOM

    component = explorer(grazing.models.pendulum("B"), {"eta": (0.44, 0.45)}, num=3)
    assert isinstance(component, pn.viewable.Viewable)
    root = component.get_root()
    assert isinstance(root, LayoutDOM)
    assert any(getattr(m, "name", None) == "diagram" for m in root.references())
    pn.extension()  # (a notebook's first cell)
    bundle = component._repr_mimebundle_()
    data = bundle[0] if isinstance(bundle, tuple) else bundle
    assert "application/vnd.holoviews_exec.v0+json" in data
    assert '"name":"diagram"' in data["text/html"].replace(" ", "")
    with pytest.raises(grazing.GrazingError, match="give the ranges"):
        explorer(grazing.models.impact_oscillator())


def test_a_period_map_marks_the_special_points_on_the_clicked_row():
    model = grazing.models.pendulum("B")
    app = Explorer(
        View.of(model, {"eta": (0.44, 0.46), "theta_hat": (35, 45)}, num=5), deliver=lambda fn: fn()
    )
    try:
        wait_until(lambda: app.diagram is not None)
        assert app.diagram.period.shape == (5, 5)
        assert len(app.figures.image.data["image"][0]) == 5
        app.click_values([0.446, 40])
        wait_until(lambda: app.point is not None)
        assert app.orbit.object.startswith("period 5 with 1 impact per period")
        assert app.figures.clicked_cell.data == {"x": [0.446], "y": [pytest.approx(40.0)]}
        app.continue_orbit()
        wait_until(lambda: app.continued is not None)
        marks = app.figures.marks.data
        assert marks["kind"] == [m.kind for m in app.continued.marks]
        assert marks["y"] == pytest.approx([40.0] * len(marks["x"]))
        app.find_grazings()
        wait_until(lambda: app.figures.grazings.data["x"] != [])
        assert app.figures.grazings.data["x"] == [pytest.approx(0.4451211835, abs=1e-9)]
    finally:
        app.close()


class _Zoom:
    def __init__(self, x0, x1):
        self.x0, self.x1 = x0, x1


def test_zoomed_in_the_diagram_is_computed_again_there_and_clicks_use_it(page):
    before = page.refined  # (a continued orbit's narrow branch may have framed and refined it already)
    page._on_ranges(_Zoom(0.4480, 0.4460))  # (either order)
    wait_until(lambda: page.refined is not None and page.refined is not before)
    axis = page.refined.view.axes[0]
    assert (axis.lo, axis.hi, axis.num) == (pytest.approx(0.446), pytest.approx(0.448), 21)
    assert page.status.object.startswith("refined: 21 points over eta in [0.446, 0.448]")
    assert sum(0.446 <= x <= 0.448 for x in page.figures.points.data["x"]) >= 21  # the fine points drawn
    assert page._diagram_for([0.447]) is page.refined and page._diagram_for([0.47]) is page.diagram
    page._on_ranges(_Zoom(0.44, 0.47))  # wider than half the range: nothing computed
    assert page.refined.view.axes[0].lo == pytest.approx(0.446)


class _MapZoom(_Zoom):
    def __init__(self, x0, x1, y0, y1):
        super().__init__(x0, x1)
        self.y0, self.y1 = y0, y1


def test_zoomed_in_a_period_map_is_computed_again_there_and_clicks_use_it():
    model = grazing.models.pendulum("B")
    view = View.of(model, {"eta": (0.43, 0.47), "theta_hat": (30, 50)}, num=4)
    app = Explorer(view, deliver=lambda fn: fn())
    try:
        wait_until(lambda: app.diagram is not None)
        app._on_ranges(_MapZoom(0.44, 0.47, 30, 50))  # (not zoomed in far enough: nothing computed)
        assert app.refined is None and app.status.object.startswith("diagram:")
        app._on_ranges(_MapZoom(0.44, 0.455, 30, 50))  # (eta narrower than half its range: refined)
        wait_until(lambda: app.refined is not None)
        a, b = app.refined.view.axes
        assert (a.lo, a.hi, a.num) == (pytest.approx(0.44), pytest.approx(0.455), 4)
        assert (b.lo, b.hi, b.num) == (pytest.approx(math.radians(30)), pytest.approx(math.radians(50)), 4)
        assert app.status.object.startswith("refined: 4 x 4 cells over eta in [0.44, 0.455], ")
        fine = app.figures.fine_image.data
        assert fine["x"][0] < 0.44 < fine["x"][0] + fine["dw"][0] and fine["image"][0].shape == (4, 4)
        assert app._diagram_for([0.446, math.radians(40)]) is app.refined
        assert app._diagram_for([0.46, math.radians(40)]) is app.diagram
        assert app.refined.period.shape == (4, 4) and (app.refined.period > 0).any()
        app.click_values([0.446, 40])
        wait_until(lambda: app.point is not None)
        assert app.orbit.object.startswith("period 5 with 1 impact per period")
    finally:
        app.close()


def test_on_a_period_map_the_clicked_orbit_s_bifurcation_curves_are_followed():
    """The period-5 window's period-doubling and grazings, followed in (eta, theta_hat)."""
    model = grazing.models.pendulum("B")
    app = Explorer(
        View.of(model, {"eta": (0.43, 0.46), "theta_hat": (35, 45)}, num=4), deliver=lambda fn: fn()
    )
    try:
        wait_until(lambda: app.diagram is not None)
        app.click_values([0.446, 40])
        wait_until(lambda: app.point is not None)
        app.continue_orbit()
        wait_until(lambda: app.continued is not None)
        assert not app.curves_button.disabled
        app.follow_curves()
        wait_until(lambda: app.figures.curves.data["kind"] != [] or "curve from" in app.curves_text.object)
        kinds = app.figures.curves.data["kind"]
        assert "period-doubling" in kinds and "grazing" in kinds, app.curves_text.object
        pd = kinds.index("period-doubling")
        xs, ys = app.figures.curves.data["xs"][pd], app.figures.curves.data["ys"][pd]
        # it passes through the period-doubling the branch found at theta_hat = 40 deg
        at = [x for x, y in zip(xs, ys) if abs(y - 40) < 1e-6]
        assert at == [pytest.approx(0.44539259, abs=1e-8)]
        assert 35 - 1e-9 <= min(ys) and max(ys) <= 45 + 1e-9  # (inside the map's range)
        # copy as code follows them too (tests/explore/test_explore_code.py runs such code)
        wait_until(lambda: app.curves is not None)
        app.show_code()
        assert "curve = follow_curve(point, kind, 'eta', 0.446, stop, 'theta_hat'" in app.code_python.value
        assert "\ngrazing curve --model pendulum" in app.code_cli.value
    finally:
        app.close()


def test_the_basins_at_the_clicked_point_hold_its_attractor(page):
    """At eta = 0.446 the period-5 orbit attracts most of the plane (the diagram's chain found it too)."""
    before = page.point  # (another test's click may have left one at 0.446 too)
    page.click_values([0.446])
    wait_until(lambda: page.point is not before and page.point.values["eta"] == 0.446)
    assert not page.basins_button.disabled
    page.find_basins()
    wait_until(lambda: "of the grid" in page.basins_text.object or "error" in page.basins_text.object)
    text = page.basins_text.object
    assert "periodic, period 5 with 1 impacts per period" in text, text
    assert page.figures.basins.visible
    label = page.figures.basin_image.data["image"][0]
    assert label.shape == (40, 40) and set(np.unique(label)) <= {0.0, 1.0, 2.0, 3.0, 4.0, 5.0}
    # the attractor's points drawn are those of the clicked orbit (the same 5 points at phase 0)
    pts = np.column_stack([page.figures.basin_points.data["x"], page.figures.basin_points.data["y"]])
    orbit = np.degrees(page.point.samples[-5:])  # (drawn in degrees, as the page's header gives angles)
    assert all(np.min(np.abs(pts - p).sum(axis=1)) < 1e-5 for p in orbit)
    # copy as code gives the basins shown (tests/explore/test_explore_code.py runs such code)
    wait_until(lambda: page.basins is not None)
    page.show_code()
    assert "found = basins(point, " in page.code_python.value and "(40, 40)" in page.code_python.value
    assert "\ngrazing basins --model pendulum" in page.code_cli.value
