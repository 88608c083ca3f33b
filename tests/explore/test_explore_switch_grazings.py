""" "Find the grazings" on a model with modes: the transition grazed, an unlocated bracket, the start mode.

The soft-impact oscillator (free while ``x < gap``, in contact while ``x > gap``) followed in ``omega``
over (0.3, 0.8) loses and gains pairs of switches where an orbit in contact briefly leaves the spring
(a grazing of ``leave`` from the contact side) and where a free orbit briefly touches it (``touch``).
Each grazing found is checked against an exact reference that does not use grazing's engine
(tests/piecewise_exact.py: matrix exponentials per mode): the contact state, run one forcing period,
comes back to itself in the mode it started in, having stayed on the side of the guard it touched.
"""

from __future__ import annotations

import json
import time
import warnings

import numpy as np
import pytest

import grazing
import grazing.orbits.continuation as continuation
from grazing.cli import main
from grazing.errors import GrazingWarning
from grazing.explore import View, grazings_in_view, view_code
from grazing.explore.app import Explorer
from grazing.orbits import find_grazings
from tests.piecewise_exact import LinearMode, PiecewiseLinearModel

RANGE = (0.3, 0.8)


def exact_soft_impact(p: dict[str, float]) -> PiecewiseLinearModel:
    """The soft-impact oscillator as two linear modes: 0 free, 1 in contact (``k (x - gap)`` on it)."""
    zeta, a, w, gap, k = (p[n] for n in ("zeta", "a", "omega", "gap", "k"))
    b = np.array([0.0, a])
    free = LinearMode(
        np.array([[0.0, 1.0], [-1.0, -2 * zeta]]), b, np.zeros(2), ((np.array([-1.0, 0.0]), gap, 1),)
    )
    contact = LinearMode(
        np.array([[0.0, 1.0], [-(1.0 + k), -2 * zeta]]),
        b,
        np.array([0.0, k * gap]),
        ((np.array([1.0, 0.0]), -gap, 0),),
    )
    return PiecewiseLinearModel([free, contact], w)


@pytest.fixture(scope="module")
def found():
    model = grazing.models.soft_impact_oscillator()
    return model, grazings_in_view(View.of(model, {"omega": RANGE}))


def test_every_grazing_in_the_range_is_located_with_the_transition_it_grazes(found):
    """Near omega = 0.3752 and 0.4337 the orbit in contact briefly leaves the spring: those grazings are
    of ``leave`` (the search crashed there, solving them as grazings of ``touch``)."""
    model, g = found
    assert g.unlocated == () and len(g.marks) == 4, g.lines
    words = [line.rsplit("(", 1)[1] for line in g.lines]
    assert words == ["transition touch)", "transition leave)", "transition leave)", "transition touch)"]
    assert [round(m.value, 4) for m in g.marks] == [0.3219, 0.3752, 0.4337, 0.6263]
    _, branch = find_grazings(model, "omega", *RANGE, stop_name="leave")
    points = [s.grazing for s in branch.special if s.kind == "grazing"]
    assert all(p is not None for p in points)
    gap = model.params["gap"]
    for point, mark in zip(points, g.marks):
        assert point.model.params["omega"] == mark.value
        ref = exact_soft_impact(point.model.params)
        source = model.mode_names.index(point.mode)
        assert np.allclose(point.contact, [gap, 0.0], atol=1e-12)
        # the exact flow from the contact: back to it one period later, in the mode it touched from (the
        # last thousandth of the period in that mode alone: the reference would see the tangency as a switch)
        t1 = point.t_graze + ref.period
        x, k, _, switches = ref.run(point.contact, source, point.t_graze, t1 - 1e-3 * ref.period)
        x = ref.flow(source, x, t1 - 1e-3 * ref.period, t1)
        assert k == source and np.max(np.abs(x - point.contact)) < 1e-8, (x, point.contact)
        # just after the contact it moves back into its mode (the guard touched, not crossed)
        later = ref.flow(source, point.contact, point.t_graze, point.t_graze + 1e-3)
        inside = later[0] - gap if point.mode == "contact" else gap - later[0]
        assert inside > 0.0 and point.accel > 0.0
        assert len(switches) == point.switches


def test_a_bracket_whose_equations_do_not_converge_is_one_unlocated_point(monkeypatch):
    """Where the grazing equations fail, the search reports that grazing, unlocated, and goes on."""
    monkeypatch.setattr(continuation, "locate_switch_grazing", lambda *args: None)
    model = grazing.models.soft_impact_oscillator()
    g = grazings_in_view(View.of(model, {"omega": RANGE}))
    assert len(g.unlocated) == 4 and len(g.marks) == 4
    assert all("was bracketed but its equations did not converge: unlocated" in line for line in g.lines)
    assert [round(v, 4) for v in g.unlocated] == [0.3219, 0.3752, 0.4337, 0.6263]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        points, _ = find_grazings(model, "omega", *RANGE)
    said = [str(w.message) for w in caught if issubclass(w.category, GrazingWarning)]
    assert points == [] and len(said) == 2 and all("'touch' near omega = 0." in s for s in said), said


def test_the_search_starts_in_the_start_mode():
    """From rest (x = 0 < gap) the soft stop's orbit cannot start in contact: asked to, the search says so
    in one line; started free it finds what the default (its initial mode, free) finds."""
    model = grazing.models.soft_impact_oscillator()
    view = View.of(model, {"omega": (0.3, 0.34)})
    with pytest.raises(grazing.GrazingError) as info:
        grazings_in_view(view, mode="contact")
    assert "not in mode 'contact'" in str(info.value) and "\n" not in str(info.value)
    free = grazings_in_view(view, mode="free")
    assert free.lines == grazings_in_view(view).lines and free.mode == "free"
    code = view_code(view, grazings=free)
    assert "find_grazings(model, 'omega', 0.3, 0.34, period=1, mode='free')" in code.python


def test_the_page_finds_the_grazings_from_its_start_mode():
    view = View.of(grazing.models.soft_impact_oscillator(), {"omega": (0.3, 0.34)}, num=3)
    page = Explorer(view, deliver=lambda fn: fn(), compute=False)
    try:
        page.mode_select.value = "contact"
        page.find_grazings()
        end = 120.0
        while "not in mode 'contact'" not in page.grazings_text.object:
            assert end > 0, page.grazings_text.object
            end -= 0.05
            time.sleep(0.05)
        assert page.grazings is None
    finally:
        page.close()


def test_graze_takes_the_mode_and_names_unlocated_grazings(capsys, monkeypatch):
    line = ["graze", "--model", "soft-impact-oscillator", "--param", "omega", "--range", "0.3,0.8"]
    assert main([*line, "--stop-name", "leave", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert [round(g["value"], 4) for g in res["grazings"]] == [0.3752, 0.4337] and res["unlocated"] == []
    assert main([*line, "--mode", "contact", "--json"]) != 0
    assert "not in mode 'contact'" in capsys.readouterr().err
    monkeypatch.setattr(continuation, "locate_switch_grazing", lambda *args: None)
    assert main(line) == 0
    out = capsys.readouterr().out
    assert out.count("was bracketed but its equations did not converge") == 2 and "no grazing" not in out
