"""The explorer on models with modes (issue 45): a click's motion with its modes, switches and sliding.

The soft-impact oscillator (free while ``x < gap``, in contact while ``x > gap``, no reset) and the
friction oscillator (slipping behind or ahead of the belt, ``v < v_belt`` or ``v > v_belt``, and
sticking to it, sliding on ``v = v_belt``): what the page shows of a clicked point is checked against
the library's :class:`~grazing.Solution` of the same run and against the regions of the modes
themselves (a stay in ``contact`` has ``x > gap`` throughout, a sliding interval ``v = v_belt``).
A model of one mode shows nothing of modes.
"""

from __future__ import annotations

import json
import runpy
import shlex
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import grazing
from grazing.cli import main
from grazing.explore import ModelSource, View, compute_diagram, continue_click, inspect_click, view_code
from grazing.explore.app import WHERE_IT_LIES, Explorer
from grazing.explore.figures import Figures, mode_span_columns, sliding_columns, switch_columns
from grazing.explore.point import INSPECT_SETTINGS

SOFT_STOPS = Path(__file__).resolve().parents[2] / "docs" / "examples" / "soft_stops.py"


def wait_until(cond, limit=120.0):
    end = time.monotonic() + limit
    while not cond():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.02)


def library_run(diagram, value):
    """The clicked point's shown motion as the library gives it: from the diagram's state there, in the
    mode that state lies in (``mode_at``), 200 periods of transient and 128 sampled, then one period."""
    model = diagram.view.at([value])
    x0 = diagram.start_state([value])
    s = INSPECT_SETTINGS
    sol = grazing.simulate(model, x0, transient=s.transient, periods=s.periods, impacts="none",
                           mode=model.mode_at(x0, 0.0))  # fmt: skip
    then = sol.mode_final if sol.mode_final not in model.sliding_names else model.mode_at(sol.x_final)
    run = grazing.simulate(model, sol.x_final, t0=sol.t_final, periods=max(sol.period(), 1),
                           trajectory=s.points_per_period, mode=then)  # fmt: skip
    return sol, run


@pytest.fixture(scope="module")
def soft():
    view = View.of(grazing.models.soft_impact_oscillator(), {"omega": (0.8, 1.6)}, num=9)
    diagram = compute_diagram(view, workers=1)
    return view, diagram, inspect_click(diagram, [1.2])


@pytest.fixture(scope="module")
def friction():
    view = View.of(grazing.models.friction_oscillator(), {"omega": (0.4, 0.8)}, num=9)
    diagram = compute_diagram(view, workers=1)
    return view, diagram, inspect_click(diagram, [0.6])


def test_a_soft_impact_point_shows_the_library_s_mode_spans_and_switches(soft):
    view, diagram, point = soft
    sol, run = library_run(diagram, 1.2)
    m = point.modes
    assert point.period == sol.period() == 1 and m is not None
    # the diagram's state there is in contact (x > gap): the run starts there, as mode_at says
    assert point.x0[0] > view.model.params["gap"] and m.start == "contact"
    expected = [(a - sol.t_final, b - sol.t_final, run.mode_names[k]) for a, b, k in run.mode_spans()]
    assert [name for *_, name in m.spans] == [name for *_, name in expected]
    assert np.array([s[:2] for s in m.spans]) == pytest.approx(np.array([s[:2] for s in expected]), abs=1e-9)
    assert m.switch_t == pytest.approx(run.switches.t - sol.t_final, abs=1e-9)
    assert m.switch_names == ("leave", "touch") and m.sliding == ()
    # each stay lies in its mode's region, each switch on the surface x = gap
    gap = view.model.params["gap"]
    for a, b, name in m.spans:
        inside = point.trajectory[(point.t > a + 1e-9) & (point.t < b - 1e-9), 0]
        assert inside.size and (np.all(inside > gap) if name == "contact" else np.all(inside < gap)), name
    assert point.modes.switch_states[:, 0] == pytest.approx(gap, abs=1e-9)
    # one period: the spans tile it
    assert m.spans[0][0] == 0 and m.spans[-1][1] == pytest.approx(view.at([1.2]).period, rel=1e-12)
    text = point.summary()
    assert "modes: started in contact; 2 switches per period; time in each mode: contact" in text
    assert "state at time 0: x = " in text and "(mode contact)" in text


def test_a_friction_point_shows_its_stick_phase_as_sliding(friction):
    view, diagram, point = friction
    sol, run = library_run(diagram, 0.6)
    m = point.modes
    assert point.period == 1 and m is not None
    expected = [run.mode_names[k] for *_, k in run.mode_spans()]
    assert [name for *_, name in m.spans] == expected
    assert "sliding on 'belt'" in expected
    # the sliding intervals: the library's, and the motion on the belt (v = v_belt) throughout
    assert len(m.sliding) == len(run.sliding) == 1
    assert np.array([s[:2] for s in m.sliding]) == pytest.approx(run.sliding[:, :2] - sol.t_final, abs=1e-9)
    v_belt = view.model.params["v_belt"]
    a, b, surface = m.sliding[0]
    assert surface == "belt" and b > a
    on = point.trajectory[(point.t >= a) & (point.t <= b), 1]
    assert on.size > 2 and on == pytest.approx(v_belt, abs=1e-9)
    for a, b, name in m.spans:  # slipping ahead of the belt: v > v_belt; behind it: v < v_belt
        inside = point.trajectory[(point.t > a + 1e-9) & (point.t < b - 1e-9), 1]
        if name == "slip_ahead":
            assert np.all(inside > v_belt)
        elif name == "slip_behind":
            assert np.all(inside < v_belt)
    assert "sliding on belt: 1 interval(s) per period" in point.summary()


def test_the_plots_columns_are_the_point_s_modes_in_the_static_plots_colours(friction):
    from grazing.plotting.palette import MODE_COLOURS

    view, _, point = friction
    names = view.model.mode_names
    spans = mode_span_columns(point)
    assert spans["x0"] == [s[0] for s in point.modes.spans] and spans["x1"] == [
        s[1] for s in point.modes.spans
    ]
    assert spans["mode"] == [f"mode {s[2]!r}" for s in point.modes.spans]  # (as the static plots label them)
    assert spans["colour"] == [MODE_COLOURS[names.index(s[2])] for s in point.modes.spans]
    scales = np.ones(2)
    sw = switch_columns(point, scales, 1)
    assert sw["t"] == point.modes.switch_t.tolist() and sw["py"] == point.modes.switch_states[:, 1].tolist()
    slid = sliding_columns(point, scales, 1)
    assert slid["surface"] == ["belt"] and slid["colour"] == [MODE_COLOURS[names.index("sliding on 'belt'")]]
    assert np.array(slid["ys"][0]) == pytest.approx(view.model.params["v_belt"], abs=1e-9)
    # the figures show them: the stays shaded under the time series, the switches on both plots
    figures = Figures(view)
    figures.show_point(point)
    assert figures.series_modes.data == spans and figures.series_switches.data["t"] == sw["t"]
    kinds = [type(r.glyph).__name__ for r in figures.series.renderers]
    assert "VStrip" in kinds and figures.phase_sliding.data["t0"] == slid["t0"]


def test_a_model_of_one_mode_shows_nothing_of_modes():
    import math

    view = View.of(grazing.models.pendulum("B", theta_hat=math.radians(40)), {"eta": (0.445, 0.447)}, num=3)
    point = inspect_click(compute_diagram(view, workers=1), [0.446])
    assert point.modes is None and "mode" not in point.summary()
    assert mode_span_columns(point)["x0"] == [] and switch_columns(point, np.ones(2), 1)["t"] == []
    figures = Figures(view)
    assert [type(r.glyph).__name__ for r in figures.series.renderers].count("VStrip") == 0
    assert len(figures.phase.renderers) == 3  # (the motion, the stroboscopic points, the impacts)
    page = Explorer(view, deliver=lambda fn: fn(), compute=False)
    assert not page.mode_select.visible and page.start_mode is None and "modes:" not in page.header.object
    code = view_code(view, point)
    assert ", mode=" not in code.python and "--mode " not in code.cli
    page.close()


def test_the_page_starts_a_click_in_the_mode_chosen_and_continues_through_modes():
    view = View.of(grazing.models.friction_oscillator(), {"omega": (0.4, 0.8)}, num=9)
    page = Explorer(view, deliver=lambda fn: fn(), compute=False)
    assert page.mode_select.visible and page.mode_select.options == [
        WHERE_IT_LIES,
        "slip_behind",
        "slip_ahead",
    ]
    assert "modes: slip_behind, slip_ahead, sliding on 'belt'" in page.header.object
    page.compute()
    wait_until(lambda: page.diagram is not None)
    page.click_values([0.6])
    wait_until(lambda: page.point is not None or page.orbit.object.startswith("**"))
    assert page.point is not None, page.orbit.object
    assert page.point.modes.start == "slip_ahead"  # (where the diagram's state lies: v > v_belt)
    assert len(page.figures.series_modes.data["x0"]) == len(page.point.modes.spans) >= 3
    # the other mode asked for: the state is not in it, one line in the page
    page.mode_select.value = "slip_behind"
    page.click_values([0.61])
    wait_until(lambda: "not in mode" in page.orbit.object)
    assert page.orbit.object.startswith("**initial state [") and "\n" not in page.orbit.object
    assert "is not in mode 'slip_behind'" in page.orbit.object
    page.mode_select.value = WHERE_IT_LIES
    page.click_values([0.6])
    wait_until(lambda: "Floquet" in page.orbit.object)
    # continued through its switches: the stick phase is lost at a crossing-sliding bifurcation
    page.continue_orbit()
    wait_until(
        lambda: page.continued is not None or not page.actions_text.object.startswith("continuing"), 300
    )
    kinds = [m.kind for m in page.continued.marks]
    assert "crossing-sliding" in kinds, page.actions_text.object
    branch = grazing.orbits.continue_orbit(
        page.point.model, "omega", 0.6, 0.8, x0=page.point.orbit.state, period=1, mode=page.point.orbit.mode
    )
    assert [(s.kind, s.param) for s in branch.special] == [
        (m.kind, m.value) for m in page.continued.marks if m.value > 0.6
    ]
    page.show_code()
    assert "mode='slip_ahead'" in page.code_python.value and "--mode slip_ahead" in page.code_cli.value
    page.close()


def test_find_the_grazings_words_the_orbit_through_its_modes():
    """On a model with modes "Find the grazings" follows the orbit itself through its modes (there is no
    nonimpacting orbit): its lines and its copied code say so and name the transition grazed.  The soft
    stop's orbit at omega = 0.5 clears the contact while the gap exceeds the free orbit's amplitude
    a / sqrt((1 - w^2)^2 + (2 zeta w)^2) and grazes it where they are equal."""
    model = grazing.models.soft_impact_oscillator(omega=0.5)
    p = model.params
    amplitude = p["a"] / np.hypot(1 - p["omega"] ** 2, 2 * p["zeta"] * p["omega"])
    page = Explorer(View.of(model, {"gap": (1.6, 2.0)}, num=3), deliver=lambda fn: fn(), compute=False)
    try:
        page.find_grazings()
        wait_until(lambda: page.grazings is not None)
        text = page.grazings_text.object
        assert text.startswith("no grazing of the period-1 orbit followed through its modes in the range (")
        assert "nonimpacting" not in text
    finally:
        page.close()
    page = Explorer(View.of(model, {"gap": (1.0, 1.6)}, num=3), deliver=lambda fn: fn(), compute=False)
    try:
        page.find_grazings()
        wait_until(lambda: page.grazings is not None)
        [mark] = page.grazings.marks
        assert abs(mark.value - amplitude) < 1e-6, (mark.value, amplitude)
        assert page.grazings_text.object.endswith("(transition touch)")
        page.show_code()
        assert "# the grazings of the period-1 orbit followed through its modes over the range (every " \
            "transition's)" in page.code_python.value  # fmt: skip
        assert "nonimpacting" not in page.code_python.value
    finally:
        page.close()


def test_an_unknown_start_mode_is_one_line():
    view = View.of(grazing.models.soft_impact_oscillator(), {"omega": (0.8, 1.6)}, num=3)
    with pytest.raises(grazing.InvalidParameterError) as info:
        Explorer(view, deliver=lambda fn: fn(), compute=False, mode="stuck")
    assert "\n" not in str(info.value) and "stuck" in str(info.value)


def run_cli(line: str, capsys) -> dict:
    argv = shlex.split(line)
    capsys.readouterr()
    assert main([*argv[1:], "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_copy_as_code_gives_the_modes_in_python_and_on_the_command_line(tmp_path, capsys):
    """The soft stops' three modes from the docs' model file: the command lines start every run in the
    mode the page did, and give the page's switches."""
    model = runpy.run_path(str(SOFT_STOPS))["soft_stops"]
    view = View.of(
        model, {"omega": (1.0, 1.2)}, num=3, source=ModelSource.of(model, f"{SOFT_STOPS}:soft_stops")
    )
    point = inspect_click(compute_diagram(view, workers=1), [1.1])
    assert point.modes is not None and point.orbit is not None
    continued = continue_click(view, point)
    code = view_code(view, point, continued=True)
    lines = code.cli.strip().splitlines()
    assert [shlex.split(line)[1] for line in lines] == ["sweep", "simulate", "orbit", "continue", "continue"]
    assert all(f"--mode {m}" in line for line, m in zip(
        lines[1:], [point.modes.start, point.modes.guess, point.orbit.mode, point.orbit.mode]))  # fmt: skip
    sim = run_cli(lines[1], capsys)
    assert sim["period"] == point.period and sim["mode_final"] == point.modes.shown_start
    orbit = run_cli(lines[2], capsys)
    assert orbit["mode"] == point.orbit.mode
    assert orbit["state"] == pytest.approx(point.orbit.state.tolist(), abs=1e-9)
    names = [name for *_, name in point.modes.spans]
    assert {"free", "left", "right"} <= set(names)  # (the motion touches both soft stops)
    for line, piece in zip(lines[3:], continued.pieces):
        branch = run_cli(line, capsys)
        assert [s["kind"] for s in branch["special"]] == [s.kind for s in piece.branch.special]
    # the Python script prints the page's period and orbit
    path = tmp_path / "view.py"
    path.write_text(code.python)
    done = subprocess.run(
        [sys.executable, str(path)], capture_output=True, text=True, timeout=600, cwd=tmp_path
    )
    assert done.returncode == 0, done.stderr
    out = done.stdout.splitlines()
    assert out[0] == f"period {point.period} impacts {float(point.impacts_per_period)}"
    assert out[1].startswith(f"orbit {point.orbit.period} {point.orbit.impacts} [")
