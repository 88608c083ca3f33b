"""A branch is one orbit: it ends at its grazing, or switches deliberately (issue 11, cases 4, 5, 7).

Regression of the run that used to step from the period-5 orbit onto the
nonimpacting period-1 orbit and back, all points marked stable; the automatic
section away from impacts; errors that name the quantity and say what to do.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import grazing
from grazing.cli import main
from grazing.models import bouncing_ball, impact_oscillator, pendulum
from grazing.orbits import continue_orbit, find_grazings, find_orbit

# The first grazing of the period-1 orbit at 40 deg, case B (to the Newton tolerance).
THETA_40 = math.radians(40)


@pytest.fixture(scope="module")
def period5_branch():
    return continue_orbit(pendulum("B", theta_hat=THETA_40), "eta", 0.446, 0.44)


@pytest.fixture(scope="module")
def first_grazing_40():
    points, _ = find_grazings(pendulum("B", theta_hat=THETA_40), "eta", 0.40, 0.47)
    return points[0]


def test_period5_branch_finds_the_period_doubling_and_ends_at_its_grazing(period5_branch, first_grazing_40):
    br = period5_branch
    assert br.period == 5 and not br.virtual
    assert {o.signature for o in br.orbits} == {br.orbits[0].signature}  # never another orbit
    assert all(o.impacts == 1 for o in br.orbits)
    assert [s.kind for s in br.special] == ["period-doubling", "grazing"]
    pd, graze = br.special
    # the independent check of the location: a multiplier is -1 there (from the orbit's own monodromy)
    np.testing.assert_allclose(np.min(np.abs(pd.multipliers + 1)), 0, atol=1e-6)
    # regression pin: where issue 11's finer run put it (0.445393), and issue 27's value (0.44539259)
    assert pd.param == pytest.approx(0.445393, abs=2e-6)
    assert pd.param == pytest.approx(0.44539259, abs=5e-9)
    assert not pd.switched and not pd.turns
    # Stable before the period-doubling, unstable after it, each from its own monodromy.
    values = np.array(br.values)
    stable = np.array([o.stable for o in br.orbits])
    assert stable[values > pd.param + 1e-6].all() and not stable[values < pd.param - 1e-6].any()
    for o in br.orbits:
        assert o.stable == bool(np.max(np.abs(np.linalg.eigvals(o.monodromy))) < 1)
    # The period-5 orbit shrinks onto the grazing period-1 orbit: its grazing is that grazing,
    # located by the grazing equations to their tolerance (not by bisection to 1e-6).
    assert graze.grazing is not None
    assert graze.param == pytest.approx(first_grazing_40.model.params["eta"], abs=1e-10)
    # ... and its monodromy is the period-1 one to the fifth power.
    np.testing.assert_allclose(
        np.sort_complex(graze.multipliers), np.sort_complex(first_grazing_40.multipliers**5), atol=1e-8
    )
    assert "grazing" in br.status and "switch" in br.status
    assert br.values[-1] > graze.param


def test_switch_continues_on_the_new_impact_sequence_as_a_new_segment():
    """Impact oscillator: the unstable period-2 orbit ends where the period-1 orbit grazes."""
    m = impact_oscillator(sigma=0.1)
    start = find_orbit(m.with_params(omega=3.2), t0=None)
    assert (start.period, start.impacts) == (2, 1)
    ended = continue_orbit(m, "omega", 3.2, 4.0, orbit=start)
    switched = continue_orbit(m, "omega", 3.2, 4.0, orbit=start, switch=True)
    expected = brentq_grazing(sigma=0.1)
    for br in (ended, switched):
        kinds = [s.kind for s in br.special]
        assert kinds == ["fold", "grazing"]
        assert br.special[1].param == pytest.approx(expected, abs=1e-10)
    assert set(ended.segments) == {0} and "switch" in ended.status
    assert set(switched.segments) == {0, 1}
    after = [o for o, seg in zip(switched.orbits, switched.segments) if seg == 1]
    assert all(o.impacts == 0 for o in after) and switched.status.startswith("reached the bound omega = 4")


def brentq_grazing(sigma: float) -> float:
    from scipy.optimize import brentq

    zeta = 0.05
    return brentq(lambda w: 1 / math.hypot(1 - w * w, 2 * zeta * w) - sigma, 2.5, 4.0, xtol=1e-15)


def test_fold_with_the_impact_on_the_section_is_found():
    """Bouncing ball period-1 orbit in the table amplitude: at the fold the impact is at t = 0."""
    from tests.orbits.test_closed_forms import ball_fold, ball_orbit

    orbit = ball_orbit(1, 1.3)
    assert orbit.section_clearance() > 0.01
    branch = continue_orbit(orbit.model, "amplitude", 1.3, 0.5, orbit=orbit)
    folds = [s for s in branch.special if s.kind == "fold"]
    assert folds and folds[0].param == pytest.approx(ball_fold(1), abs=1e-9)
    assert len(set(np.round(branch.sections, 9))) > 1  # the section moved away from the impact


def test_find_orbit_errors_are_about_the_orbit_not_an_internal_iterate():
    with pytest.raises(grazing.ConvergenceError) as err:
        find_orbit(impact_oscillator())
    msg = str(err.value)
    assert "initial state" not in msg and "no period" in msg and "initial guess" in msg
    with pytest.raises(grazing.ConvergenceError, match=r"default initial guess sticks.*riding on the stop"):
        find_orbit(bouncing_ball())


def test_messages_name_the_parameter_not_a_vector_slot(capsys):
    assert main(["graze-curve", "--start-deg", "50", "--max-step", "0.05"]) == 0
    out = capsys.readouterr().out
    assert "u[" not in out and "eta" in out


def test_continue_stop_outside_the_parameter_interval_is_refused():
    with pytest.raises(grazing.InvalidParameterError, match=r"r = 2 is outside \[0, 1\]"):
        continue_orbit(pendulum("B"), "r", 0.5, 2.0)
