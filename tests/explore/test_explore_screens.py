"""The explorer on a phone (400 px) and on a desktop (1300 px), in headless Chromium (issue 44).

The default view (case B, θ̂ = 40°, η in [0.44, 0.49]), η = 0.446 clicked (the period-5 window,
~0.001 wide), its orbit continued, copy as code.  Then, as a person would see it: the page no
wider than the screen (a phone lays it out at its own width: the viewport tag), every button
inside it, no text smaller than 12 px, the diagram and the orbit side by side only where there is
room, a legend naming the period classes drawn, the diagram framed to the narrow branch with θ
in degrees (the header gives θ̂ in degrees), what the mouse is over read under the diagram, each
entry once, never in a tooltip over it, the code in a monospace font.  A screenshot of each is
left in the test's folder.
"""

from __future__ import annotations

import json
import re
import time

import pytest

from grazing.report.browser import find_chromium
from tests.explore.page import _CLICK_BUTTON, ExplorerPage

pytestmark = pytest.mark.skipif(find_chromium() is None, reason="no Chromium installed")

ARGS = ["--case", "B", "--theta-hat", "40", "--param", "eta", "--range", "0.44,0.49"]

_VIEWS = """  const views = [];
  const found = (v) => {
    if (v.model.name === 'diagram') views.push(v);
    for (const c of (v.child_views ?? [])) found(c);
  };
  for (const r of Bokeh.index.roots) found(r);
"""

_LAYOUT = """(() => {
  const all = [];
  const walk = (node) => {
    if (node.shadowRoot) walk(node.shadowRoot);
    for (const c of node.children ?? []) { all.push(c); walk(c); }
  };
  walk(document.body);
  const shown = (e) => {
    const r = e.getBoundingClientRect(), cs = getComputedStyle(e);
    return r.width > 0 && r.height > 0 && cs.visibility !== 'hidden' && cs.display !== 'none';
  };
  const box = (e) => { const r = e.getBoundingClientRect(); return {left: r.left, right: r.right,
                                                                    top: r.top, bottom: r.bottom}; };
  const buttons = all.filter(e => e.tagName === 'BUTTON' && shown(e))
                     .map(e => ({text: e.textContent.trim(), ...box(e)}));
  let smallest = {size: 1e9, text: ''};
  for (const e of all) {
    if (['STYLE', 'SCRIPT', 'TEMPLATE'].includes(e.tagName) || !shown(e)) continue;
    const own = [...e.childNodes].filter(n => n.nodeType === 3 && n.textContent.trim())
                                 .map(n => n.textContent.trim()).join(' ');
    const size = parseFloat(getComputedStyle(e).fontSize);
    if (own && size < smallest.size) smallest = {size, text: own.slice(0, 80)};
  }
  const code = all.find(e => e.tagName === 'TEXTAREA' && shown(e));
  const tips = all.filter(e => /tooltip/i.test(String(e.className?.baseVal ?? e.className)) && shown(e));
  const classed = (name) => {  // (a Bokeh Div's text is in its shadow root)
    const host = all.find(e => e.classList?.contains(name) && shown(e));
    const parts = host?.shadowRoot ? [...host.shadowRoot.children] : (host ? [host] : []);
    const shownParts = parts.filter(e => !['STYLE', 'LINK'].includes(e.tagName));
    return shownParts.map(e => e.innerText).join(String.fromCharCode(10));
  };
/*VIEWS*/  const pv = views[0], m = pv.model, canvas = pv.canvas_view.el;
  const orbit = all.find(e => /^H\\d$/.test(e.tagName) && e.textContent.trim() === 'Orbit');
  return JSON.stringify({
    scrollWidth: document.documentElement.scrollWidth, innerWidth: innerWidth, buttons, smallest,
    codeFont: code ? getComputedStyle(code).fontFamily : null,
    tooltips: tips.map(e => e.textContent.trim()),
    legend: classed('grazing-legend'), readout: classed('grazing-readout'),
    x: [m.x_range.start, m.x_range.end], y: [m.y_range.start, m.y_range.end],
    diagram: box(canvas), orbit: orbit ? box(orbit) : null,
  });
})()""".replace("/*VIEWS*/", _VIEWS)

_POINT_OF = """(() => {
/*VIEWS*/  const pv = views[0], rect = pv.canvas_view.el.getBoundingClientRect();
  const data = pv.model.renderers.map(r => r.data_source.data).find(d => d.%s !== undefined && d.x.length);
  if (!data) return null;
  let i = 0;
  data.x.forEach((x, k) => { if (Math.abs(x - %r) < Math.abs(data.x[i] - %r)) i = k; });
  return JSON.stringify({x: rect.left + pv.frame.x_scale.compute(data.x[i]),
                         y: rect.top + pv.frame.y_scale.compute(data.y[i]), text: data.text[i]});
})()""".replace("/*VIEWS*/", _VIEWS)
"""The page pixel of the point nearest to ``x`` of the first renderer with a column: ``% (column, x, x)``."""


def _look(page: ExplorerPage, phone: bool) -> tuple[dict, dict]:
    """Click eta = 0.446 (on the phone, continue its orbit too), copy as code, hover over the point:
    what the page then shows (:data:`_LAYOUT`), and the point hovered over."""
    page.wait_for(r"diagram: 100 points in [0-9.]+ s; failed: 0")
    where = page.diagram_pixel(0.446)
    page.click(where["x"], where["y"])
    page.wait_for(r"Floquet multipliers")
    if phone:
        page.evaluate(_CLICK_BUTTON % "Continue this orbit")
        page.wait_for(r"the diagram is framed to the branch")
    page.evaluate(_CLICK_BUTTON % "Copy as code")
    page.wait_for(r"Python Command line")
    point: dict = {}
    for k in range(150):  # (drawn: the branch, on the diagram framed to it; the code box; the point read)
        if k % 10 == 0:  # the mouse over the point (again: on a loaded machine the frame may still move)
            found = page.evaluate(_POINT_OF % ("stable" if phone else "code", 0.446, 0.446))
            point = json.loads(found) if found else {}
            if point:
                page.dt.send(
                    "Input.dispatchMouseEvent",
                    {"type": "mouseMoved", "x": point["x"], "y": point["y"]},
                    session=page.session,
                )
        shown = json.loads(page.evaluate(_LAYOUT))
        if point and shown["codeFont"] is not None and point["text"] in shown["readout"]:
            break
        time.sleep(0.1)
    assert point, "nothing drawn to hover over"
    assert shown["codeFont"] is not None, "no code shown"
    return shown, point


@pytest.mark.parametrize("width", [400, 1300])
def test_the_explorer_fits_the_screen_with_a_legend_degrees_and_no_tooltip_over_the_plot(tmp_path, width):
    """On the phone the clicked orbit is continued too (its branch framed and hovered over); on the
    desktop a point of the diagram is hovered over."""
    phone = width < 500
    page = ExplorerPage([*ARGS, "--num", "100"], tmp_path, width=width, height=900, mobile=phone)
    try:
        with page:
            shown, point = _look(page, phone)
            page.screenshot(tmp_path / f"explore-{width}.png")
    except AssertionError as exc:  # (with what the server said: a failure on a loaded machine is read)
        raise AssertionError(f"{exc}\nthe server's stderr: {page.stderr[-3000:]}") from None
    # the page at the screen's width (no viewport tag: a phone lays it out at 980 px), nothing past it
    assert shown["innerWidth"] == width
    assert shown["scrollWidth"] <= width, shown["scrollWidth"]
    labels = {b["text"] for b in shown["buttons"]}
    assert {"Show this point", "Continue this orbit", "Find the grazings", "Copy as code"} <= labels
    for b in shown["buttons"]:
        assert 0 <= b["left"] and b["right"] <= width, b
    assert shown["smallest"]["size"] >= 12, shown["smallest"]
    # the orbit beside the diagram on a desktop, under it on a phone
    diagram, orbit = shown["diagram"], shown["orbit"]
    if phone:
        assert orbit["top"] > diagram["bottom"] and diagram["right"] <= width
    else:
        assert orbit["left"] >= diagram["right"] and orbit["top"] < diagram["bottom"]
    # a legend of the shared palette's classes drawn: period 1 with and without impacts apart
    legend = shown["legend"]
    for entry in ("period:", "1, no impacts", "1, impacting", "aperiodic", "5", "stable", "unstable"):
        assert entry in legend, legend
    if phone:  # the period-5 branch (grazing to grazing, ~0.0012 of eta) in the diagram's middle third
        assert 0.4435 < shown["x"][0] < 0.4451 and 0.4464 < shown["x"][1] < 0.448, shown["x"]
        assert point["text"] == "η = 0.446000: continued branch, stable"
    else:
        assert shown["x"] == [0.44, 0.49]
        assert re.fullmatch(r"η = 0\.44\d+: period 5, 1 impacts per period", point["text"]), point
    # theta in degrees (as the header's theta_hat = 40 deg): the samples lie near -20 to -35 deg
    assert -45 < shown["y"][0] < -10 and -30 < shown["y"][1] < 0, shown["y"]
    # no tooltip over the plot: what is under the mouse is read under it, each entry once (the period-5
    # point's 5 samples, the clicked orbit where the branch's two directions start: one line)
    assert shown["tooltips"] == []
    lines = shown["readout"].splitlines()
    assert lines.count(point["text"]) == 1, lines
    assert len(lines) == len(set(lines))
    assert "monospace" in shown["codeFont"]
