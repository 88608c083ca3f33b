"""The explorer's computations without a browser: the diagram, a clicked point, its branch, the grazings.

Each is checked against what does not come from the explorer: the paper's period-5 window at
η = 0.446 (one impact per period), the exact determinant of a nonimpacting orbit's monodromy,
the closed-form grazing of the linear impact oscillator, the mirror symmetry of the pendulum
between two walls, and the library's own sweep at the same parameter values.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import grazing
from grazing.errors import ConvergenceError, InvalidParameterError
from grazing.explore import (
    InspectSettings,
    ModelSource,
    SupersededError,
    View,
    compute_diagram,
    continue_click,
    grazings_in_view,
    inspect_click,
    inspect_point,
)
from grazing.explore.figures import branch_columns, diagram_columns, mark_columns, period_label
from tests.orbits.symmetric_models import walled_pendulum

BETA = 0.048


@pytest.fixture(scope="module")
def pendulum_diagram():
    model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    return compute_diagram(View.of(model, {"eta": (0.44, 0.49)}, num=41))


def test_a_click_in_the_period_adding_window_finds_the_period_5_orbit(pendulum_diagram):
    rep = inspect_click(pendulum_diagram, [0.446])
    assert rep.period == 5
    assert rep.impacts_per_period == 1
    assert rep.impacts_by_stop == {"stop": 1, "back": 0}
    assert rep.orbit is not None and rep.orbit.period == 5 and rep.orbit.impacts == 1 and rep.orbit.stable
    assert rep.summary().splitlines()[0] == "period 5 with 1 impact per period (stop: 1, back: 0)"
    # one period of the motion is drawn: the trajectory spans 5 forcing periods with its one impact
    assert rep.t[0] == pytest.approx(0.0) and rep.t[-1] == pytest.approx(5 * rep.model.period)
    assert len(rep.impact_t) == 1 and 0.0 < rep.impact_t[0] < rep.t[-1]
    # the impact happens on the stop: theta = theta_hat there
    assert rep.impact_states[0, 0] == pytest.approx(math.radians(40), abs=1e-9)


def test_a_nonimpacting_orbit_has_the_exact_determinant(pendulum_diagram):
    """Without impacts det(monodromy) = exp(-4 pi beta / eta) per forcing period (SPEC)."""
    rep = inspect_click(pendulum_diagram, [0.441])
    assert rep.period == 1 and rep.impacts_per_period == 0
    det = math.exp(-4 * math.pi * BETA / 0.441)
    assert np.prod(rep.orbit.multipliers).real == pytest.approx(det, rel=1e-8)


def test_a_click_agrees_with_the_diagram_at_every_computed_value(pendulum_diagram):
    d = pendulum_diagram
    for i in range(0, d.period.size, 5):
        rep = inspect_click(d, [d.values[0][i]])
        assert rep.period == d.period[i], d.values[0][i]
        if rep.period > 0:  # (the orbit's, from the impacts of the sweep's 100 sampled periods)
            assert rep.impacts_per_period == d.impacts_per_period[i]


def test_a_click_outside_the_range_or_a_parameter_outside_its_interval_is_one_line(pendulum_diagram):
    with pytest.raises(
        InvalidParameterError,
        match=r"^eta = 0\.5 is outside the computed range eta in "
        r"\[0\.44, 0\.49\]: click inside the diagram$",
    ):
        inspect_click(pendulum_diagram, [0.5])
    model = pendulum_diagram.view.model
    with pytest.raises(InvalidParameterError, match=r"r = 1\.5 is outside"):
        View.of(model, {"r": (0.5, 1.5)})
    with pytest.raises(InvalidParameterError, match="finite and increasing"):
        View.of(model, {"eta": (0.49, 0.44)})
    with pytest.raises(InvalidParameterError, match="unknown parameter"):
        View.of(model, {"omega": (1, 2)})


def test_a_failed_newton_is_a_message_and_the_motion_is_still_shown(pendulum_diagram, monkeypatch):
    import grazing.explore.point as point

    def fails(*_a, **_k):
        raise ConvergenceError("Newton's method did not converge (residual 0.1 after 30 iterations)")

    monkeypatch.setattr(point, "find_orbit", fails)
    rep = inspect_click(pendulum_diagram, [0.446])
    assert rep.orbit is None and rep.period == 5
    assert rep.message.startswith("Newton's method on the period-5 orbit failed: Newton's method did not")
    assert rep.trajectory.shape[0] > 0
    with pytest.raises(InvalidParameterError, match="no orbit to continue"):
        continue_click(pendulum_diagram.view, rep)


def test_a_chaotic_point_says_there_is_no_period():
    model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    # eta = 0.4625 is chaotic in the diagram of the README (no period <= 64 between the windows)
    sweep = grazing.sweeps.sweep(model, "eta", [0.4625], periods=128, workers=1)
    assert sweep.period.values[0] == 0
    rep = inspect_point(model, {"eta": 0.4625}, sweep.x_final.values[0])
    assert rep.period == 0 and rep.orbit is None
    assert "no periodic orbit to solve for" in rep.message
    assert rep.summary().startswith("no period <= 64 in 128 sampled forcing periods")
    assert rep.t[-1] == pytest.approx(InspectSettings().shown_periods * model.period)


def test_the_branch_through_the_clicked_orbit_ends_at_the_grazings_of_the_window(pendulum_diagram):
    rep = inspect_click(pendulum_diagram, [0.446])
    c = continue_click(pendulum_diagram.view, rep)
    kinds = [m.kind for m in c.marks]
    assert "period-doubling" in kinds and kinds.count("grazing") == 2
    # the window's ends as the README's sweep sees them: [0.445455, 0.446306] lies between the grazings
    graze = sorted(m.value for m in c.marks if m.kind == "grazing")
    assert graze[0] < 0.445455 and 0.446306 < graze[1] < 0.4468
    # every branch point drawn has its period-5 orbit's 5 points at phase 0, stable or not; the clicked
    # orbit, where both directions start, once (a hover over it lists it once)
    cols = branch_columns(pendulum_diagram.view, c, 0)
    assert [p.values[0] for p in c.pieces] == [0.446, 0.446]
    assert len(cols["x"]) == 5 * (sum(len(p.values) for p in c.pieces) - 1)
    assert len(set(zip(cols["x"], cols["y"]))) == len(cols["x"])
    # in degrees, as the page's header gives angles: theta at phase 0 of the clicked orbit
    assert sorted(cols["y"][:5]) == pytest.approx(sorted(np.degrees(rep.samples[-5:, 0])), abs=1e-5)
    assert set(cols["stable"]) == {"stable", "unstable"}  # (unstable past the period-doubling)
    assert len(mark_columns(pendulum_diagram.view, c.marks, 0)["x"]) == 5 * len(c.marks)


def test_the_diagram_shows_each_point_s_distinct_samples(pendulum_diagram):
    d = pendulum_diagram
    cols = diagram_columns(d, 0)
    expected = sum(p if p > 0 else d.samples.shape[1] for p in d.period.tolist())
    assert len(cols["x"]) == expected
    assert set(cols["period"]) <= {period_label(p) for p in d.period.tolist()}


def test_a_newer_request_stops_a_diagram_between_chunks():
    model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    seen = []
    with pytest.raises(SupersededError):
        compute_diagram(
            View.of(model, {"eta": (0.44, 0.49)}, num=200),
            progress=lambda d, t: seen.append(d),
            cancelled=lambda: len(seen) >= 2,
            workers=1,
        )
    assert seen[-1] < 200  # (stopped before the end)


# -- another model: the linear impact oscillator ------------------------------------------------------


def test_the_impact_oscillator_grazes_where_its_amplitude_reaches_the_stop():
    """x'' + 2 zeta x' + x = cos(omega t): amplitude 1/sqrt((1 - w^2)^2 + (2 zeta w)^2) = sigma."""
    model = grazing.models.impact_oscillator()
    zeta, sigma = model.params["zeta"], model.params["sigma"]
    view = View.of(model, {"omega": (2.8, 3.6)}, num=12)
    found = grazings_in_view(view)
    c = 1 / sigma**2
    u = (2 - 4 * zeta**2 + math.sqrt((2 - 4 * zeta**2) ** 2 - 4 * (1 - c))) / 2
    assert [m.value for m in found.marks] == pytest.approx([math.sqrt(u)], rel=1e-8)
    assert found.lines[0].startswith("grazing at omega = 3.3157957")
    d = compute_diagram(view)
    periodic = [i for i in range(d.period.size) if d.period[i] > 0]
    assert periodic
    for i in periodic:
        rep = inspect_click(d, [d.values[0][i]])
        assert rep.period == d.period[i]
        assert rep.orbit is not None and rep.orbit.period == rep.period
        assert rep.orbit.impacts == rep.impacts_per_period


def test_a_model_file_with_two_walls_counts_the_impacts_on_each(tmp_path):
    """The pendulum between two walls (tests/orbits/symmetric_models.py): a symmetric orbit hits each once."""
    model = walled_pendulum(A=0.3)
    view = View.of(model, {"Om": (1.0, 1.2)}, num=6, source=ModelSource.of(model, "m.py:walled_pendulum"))
    d = compute_diagram(view)
    rep = inspect_click(d, [1.1])
    assert rep.period == 1 and rep.impacts_by_stop == {"east": 1, "west": 1}
    assert rep.summary().splitlines()[0] == "period 1 with 2 impacts per period (east: 1, west: 1)"
    assert sorted(np.bincount(rep.orbit.impact_stops, minlength=2).tolist()) == [1, 1]
    # mirror symmetry: the orbit's state half a period later is minus itself
    half = grazing.simulate(rep.model, rep.orbit.state, t0=0.0, periods=1, phase=math.pi).samples[0]
    assert half == pytest.approx(-rep.orbit.state, abs=1e-8)


def test_a_click_on_a_map_that_is_not_square_starts_from_the_cell_clicked():
    # A map's arrays are (n2, n1): the nearest cell's index is (i2, i1), for a map of 3 x 5 cells too
    # (on a square map the transposed index is a cell as well, only the wrong one).
    from grazing.core.solution import Status
    from grazing.explore.diagram import Diagram

    p1, p2 = np.linspace(0.0, 1.0, 3), np.linspace(10.0, 14.0, 5)
    i2, i1 = np.meshgrid(np.arange(5), np.arange(3), indexing="ij")
    x_final = np.stack([i1, i2], axis=-1).astype(float)  # (5, 3, 2): each cell's own (i1, i2)
    ok = np.full((5, 3), int(Status.OK))
    diagram = Diagram(None, (p1, p2), np.ones((5, 3)), np.ones((5, 3)), ok, x_final, None, 0.0)  # type: ignore[arg-type]
    for v1, v2, cell in [(0.5, 13.0, (1, 3)), (1.0, 10.2, (2, 0)), (0.1, 14.0, (0, 4))]:
        assert diagram.nearest((v1, v2)) == (cell[1], cell[0])
        assert tuple(diagram.start_state((v1, v2))) == cell
