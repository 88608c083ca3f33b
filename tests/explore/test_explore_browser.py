"""The explorer in headless Chromium: a click on the diagram shows that point's orbit (issue 31).

The pendulum of the paper, case B, θ̂ = 40°, η in [0.44, 0.49] (``grazing explore``'s default
view): past the grazing at η = 0.4451 the period-adding cascade begins, and η = 0.446 is in its
period-5 window, whose orbit has one impact per period (Piiroinen, Virgin & Champneys 2004,
figs 7 and 10; README).  A click outside the computed range is a message in the page.
"""

from __future__ import annotations

import re
import time

import pytest

from grazing.report.browser import find_chromium
from tests.explore.page import ExplorerPage

pytestmark = pytest.mark.skipif(find_chromium() is None, reason="no Chromium installed")

ARGS = ["--case", "B", "--theta-hat", "40", "--param", "eta", "--range", "0.44,0.49"]


def test_a_click_at_eta_0446_shows_the_period_5_orbit_with_one_impact(tmp_path):
    with ExplorerPage(ARGS, tmp_path) as page:
        page.wait_for(r"diagram: 200 points in [0-9.]+ s; failed: 0")
        where = page.diagram_pixel(0.446)
        assert where["left"] < where["x"] < where["right"]
        page.click(where["x"], where["y"])
        text = page.wait_for(r"Floquet multipliers|Newton's method .* failed")
        assert re.search(r"\bperiod 5 with 1 impact per period\b", text), text
        assert "period-5 orbit with 1 impact, stable" in text, text
        # the η of the click: within a pixel of 0.446 (the frame is ~600 px wide for 0.05)
        shown = float(re.search(r"(?<![a-z])eta = (0\.\d+)", text).group(1))
        assert abs(shown - 0.446) < 0.05 / 400, (shown, where)
    assert page.exit_code == 130
    assert page.stderr.strip() == "grazing: interrupted"


def test_a_click_outside_the_computed_range_is_a_message_in_the_page(tmp_path):
    with ExplorerPage(ARGS, tmp_path) as page:
        page.wait_for(r"diagram: 200 points")
        inside = page.diagram_pixel(0.445)
        page.click(inside["x"], inside["y"])  # a first point, then one past the range's end
        page.wait_for(r"Floquet multipliers")
        # zoom out so that the range's end is inside the frame: the reset tool is not enough, so
        # the mouse wheel over the plot (the diagram's active scroll tool)
        page.dt.send(
            "Input.dispatchMouseEvent",
            {"type": "mouseWheel", "x": inside["x"], "y": inside["y"], "deltaX": 0, "deltaY": 600},
            session=page.session,
        )
        outside = None
        for _ in range(50):
            where = page.diagram_pixel(0.495)
            if where["left"] < where["x"] < where["right"]:
                outside = where
                break
            time.sleep(0.1)
        assert outside is not None, "the diagram did not zoom out"
        page.click(outside["x"], outside["y"])
        text = page.wait_for(r"outside the computed range")
        assert re.search(r"eta = 0\.49\d* is outside the computed range eta in \[0\.44, 0\.49\]", text), text
        assert "Floquet multipliers" not in text
        # the server is still there: a click inside is answered again
        again = page.diagram_pixel(0.455)
        page.click(again["x"], again["y"])
        text = page.wait_for(r"Floquet multipliers")
        assert re.search(r"\bperiod 3 with 1 impact per period\b", text), text
    assert page.exit_code == 130
