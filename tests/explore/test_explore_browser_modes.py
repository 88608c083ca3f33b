"""``grazing explore`` of a model with modes in headless Chromium (issue 45): a click shows its modes.

The friction oscillator (a forced mass on a belt, Coulomb friction) over omega in [0.4, 0.8]; at
omega = 0.6 it sticks to the belt once a forcing period (sliding on ``v = v_belt``).  A real click
at 0.6; what the page's time series shades (its stays in each mode) and marks (its switches of mode)
is read from the page's own data and compared with the library's :class:`~grazing.Solution` of the
same run, as ``grazing simulate`` would give it.
"""

from __future__ import annotations

import json
import re
import time

import numpy as np
import pytest

import grazing
from grazing.explore import View, compute_diagram
from grazing.report.browser import find_chromium
from tests.explore.page import ExplorerPage
from tests.explore.test_explore_modes import library_run

pytestmark = pytest.mark.skipif(find_chromium() is None, reason="no Chromium installed")

ARGS = ["--model", "friction-oscillator", "--param", "omega", "--range", "0.4,0.8", "--num", "41"]

_SHOWN = """(() => {
  const all = [...Bokeh.documents[0].all_models];
  const columns = (m) => (m.data instanceof Map ? Object.fromEntries(m.data) : m.data);
  const sources = all.filter(m => m.data !== undefined && m.selected !== undefined).map(columns);
  const plain = (d) => d ? Object.fromEntries(Object.entries(d).map(([k, v]) => [k, Array.from(v)])) : null;
  const clicked = all.find(m => m.dimension === 'height' && m.line_color === 'red' && 'location' in m);
  return JSON.stringify({spans: plain(sources.find(d => 'x0' in d && 'mode' in d)),
                         switches: plain(sources.find(d => 'px' in d && 'name' in d)),
                         clicked: clicked ? clicked.location : null});
})()"""
"""What the page draws of the clicked point's modes: the time series' stays (``x0``, ``x1``, ``mode``), the
switches (``t``, ``name``), and where the click was (the red line's ``omega``)."""


def test_a_click_on_the_friction_oscillator_shows_the_library_s_modes_and_switches(tmp_path):
    with ExplorerPage(ARGS, tmp_path) as page:
        page.wait_for(r"diagram: 41 points in [0-9.]+ s; failed: 0")
        assert "modes: slip_behind, slip_ahead, sliding on 'belt'" in page.text()
        assert "Start mode" in page.text()
        where = page.diagram_pixel(0.6)
        page.click(where["x"], where["y"])
        text = page.wait_for(r"Floquet multipliers|Newton's method .* failed")
        assert re.search(r"modes: started in slip_ahead; 3 switches per period", text), text
        assert "sliding on belt: 1 interval(s) per period" in text, text
        shown = {}
        for _ in range(100):  # (the plots' data reach the page after the text)
            shown = json.loads(page.evaluate(_SHOWN))
            if shown["spans"] and shown["spans"]["x0"] and shown["clicked"] is not None:
                break
            time.sleep(0.1)
        assert shown["spans"] and shown["spans"]["x0"], shown
    assert page.exit_code == 130
    # the same run in the library, at the omega clicked (within a pixel of 0.6)
    omega = shown["clicked"]
    assert abs(omega - 0.6) < 0.4 / 400
    view = View.of(grazing.models.friction_oscillator(), {"omega": (0.4, 0.8)}, num=41)
    sol, run = library_run(compute_diagram(view), omega)
    spans = [(a - sol.t_final, b - sol.t_final, run.mode_names[k]) for a, b, k in run.mode_spans()]
    assert shown["spans"]["mode"] == [f"mode {name!r}" for *_, name in spans]
    assert "mode \"sliding on 'belt'\"" in shown["spans"]["mode"]
    assert np.array(shown["spans"]["x0"]) == pytest.approx([a for a, *_ in spans], abs=1e-9)
    assert np.array(shown["spans"]["x1"]) == pytest.approx([b for _, b, _ in spans], abs=1e-9)
    assert np.array(shown["switches"]["t"]) == pytest.approx(run.switches.t - sol.t_final, abs=1e-9)
    assert shown["switches"]["name"] == [run.switches.name(i) for i in range(len(run.switches))]
