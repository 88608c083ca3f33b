"""Bifurcation curves in two parameters on the segmented (multiple-shooting) equations.

Where an orbit's monodromy is large, single shooting's residual cannot fall below ``|M| eps |x|``
and a curve point cannot be solved; :mod:`grazing.orbits.segmented_curves` takes the defining
condition from the segmented Jacobian instead.  Checked here:

* every derivative of the four segmented extended systems against central differences;
* the fold and period-doubling curves of a strongly unstable orbit (``|M| = 3e7``: a ball beside an
  inverted pendulum, :mod:`tests.orbits.strongly_unstable`) against the bouncing ball's closed forms,
  where single shooting alone cannot even start;
* a curve that starts on single shooting and hands over where it stalls;
* the Neimark-Sacker curve of a 6-state model against its exact linear maps, and a branch-point curve
  of a symmetric model against single shooting's, both solved on the segments throughout.
"""

from __future__ import annotations

import numpy as np
import pytest

from grazing.errors import ConvergenceError
from grazing.maps import flow_map
from grazing.models import impact_damper, two_sided_oscillator
from grazing.orbits import continuation as continuation_module
from grazing.orbits import continue_orbit, find_orbit, follow_curve
from grazing.orbits import curves as curves_module
from grazing.orbits.curves import _Follower
from grazing.orbits.segmented_curves import CRITICAL_MULTIPLIER, SegmentedOrbitSystem, multiplier_slope
from tests.linear_exact import pair_closest_to_circle, six_state_matrices, six_state_model
from tests.orbits.strongly_unstable import (
    ball_alone,
    ball_fold,
    ball_period_doubling,
    strongly_unstable_orbit,
)
from tests.orbits.test_curves import (
    ACCURACY_RATIO,
    KINDS,
    SPEC_2,
    _condition_holds,
    _critical_distance,
    _differences,
    _random_orbit,
)

DRAWS = 64
"""Rounding-level draws of a point's unknowns that measure its critical multiplier's scatter."""


def _check_segmented_jacobian(orbit, params, kind):
    system = SegmentedOrbitSystem(orbit.model, kind, params, orbit.period, orbit.t0, orbit.stop, orbit)
    u = system.start(orbit)
    n = orbit.model.n_states
    u[:n] += 1e-5  # off the orbit and off the curve: the identities hold everywhere
    u[system.offset + 2 :] += 1e-3  # (theta off the pair's angle, shift off zero)
    _, DF, _ = system(u)
    fd = _differences(system, u)
    assert DF.shape == fd.shape == (u.size - 1, u.size)
    for i, (row, fd_row) in enumerate(zip(DF, fd)):
        assert np.max(np.abs(row - fd_row)) <= 2e-5 * max(1.0, float(np.max(np.abs(fd_row)))), (kind, i)


@pytest.fixture(scope="module")
def strongly_unstable():
    return strongly_unstable_orbit()


@pytest.mark.parametrize("kind", KINDS)
def test_segmented_extended_jacobians_of_a_four_state_model(kind):
    orbit = find_orbit(impact_damper(mu=0.3, r=0.8, omega=1.2), t0=None)
    _check_segmented_jacobian(orbit, ("omega", "mu"), kind)


@pytest.mark.parametrize("kind", ["fold", "period-doubling"])
def test_segmented_extended_jacobians_of_a_strongly_unstable_orbit(kind, strongly_unstable):
    _check_segmented_jacobian(strongly_unstable, ("A", "e"), kind)


@pytest.mark.parametrize("kind", ["neimark-sacker", "branch-point"])
def test_segmented_extended_jacobians_of_a_random_model_in_a_period_setting_parameter(kind):
    orbit = _random_orbit(SPEC_2)
    amplitude, frequency = SPEC_2.param_names[2], SPEC_2.param_names[3]
    _check_segmented_jacobian(orbit, (frequency, amplitude), kind)


@pytest.mark.parametrize(
    ("kind", "stop", "closed_form"),
    [("fold", 0.1, ball_fold), ("period-doubling", 0.5, ball_period_doubling)],
)
def test_curves_of_a_strongly_unstable_orbit_are_the_closed_forms(kind, stop, closed_form, strongly_unstable):
    model = strongly_unstable.model
    assert np.linalg.norm(strongly_unstable.monodromy, 2) > 1e7
    curve = follow_curve(model, kind, "A", 0.3, stop, "e", (0.4, 0.6), orbit=strongly_unstable)
    A, e = curve.values("A"), curve.values("e")
    assert e.min() == 0.4 and e.max() == 0.6, curve.status
    np.testing.assert_allclose(A, closed_form(e), rtol=0, atol=1e-12)
    assert curve.status.count("by multiple shooting (the monodromy's norm is 2.8e+07 at the start)") == 2
    assert not curve.special  # (no codimension-two point: the pendulum's tiny multiplier is rounding's)
    for point in curve.points:
        assert point.accuracy < 1e-12  # (a segment's rounding: single shooting's would be |M| eps ~ 1e-8)
        assert abs(point.condition) < 1e-10


def _ball_accuracy(kind: str, point) -> float:
    """The measured accuracy of a curve point's critical multiplier: the ball's block of the monodromy
    computed by the ball alone (no 1e7 beside it), at the point and at ``DRAWS`` rounding-level changes
    (``2 eps`` relative) of its state and parameters; the larger of the scatter and the distance from
    the condition."""
    A, e = point.values
    x = np.asarray(point.state)[2:]
    rng = np.random.default_rng(27)

    def distance(state, values) -> float:
        fm = flow_map(ball_alone(A=values[0], e=values[1]), state, t0=point.section_time, periods=1)
        return _critical_distance(kind, np.linalg.eigvals(fm.jacobian))

    base = distance(x, (A, e))
    eps = np.finfo(float).eps
    scatter = max(
        abs(
            distance(
                x * (1 + 2 * eps * rng.standard_normal(2)), (A, e) * (1 + 2 * eps * rng.standard_normal(2))
            )
            - base
        )
        for _ in range(DRAWS)
    )
    return max(base, scatter)


@pytest.mark.parametrize(("kind", "stop"), [("fold", 0.1), ("period-doubling", 0.5)])
def test_the_accuracy_of_a_segmented_point_is_an_estimate(kind, stop, strongly_unstable):
    # The pendulum's block does not move the ball's multipliers: measured by the ball alone, the
    # segmented point's critical multiplier is as accurate as its reported accuracy says, within
    # ACCURACY_RATIO (single shooting's would say 1e-8: |M| eps).
    curve = follow_curve(
        strongly_unstable.model, kind, "A", 0.3, stop, "e", (0.4, 0.6), orbit=strongly_unstable
    )
    low, high = ACCURACY_RATIO
    for point in curve.points[::3]:
        assert low <= point.accuracy / _ball_accuracy(kind, point) <= high, point.values


def test_single_shooting_alone_cannot_start_those_curves(strongly_unstable, monkeypatch):
    monkeypatch.setattr(_Follower, "can_segment", lambda self, orbit: False)
    with pytest.raises(ConvergenceError, match="did not converge at its start"):
        follow_curve(strongly_unstable.model, "fold", "A", 0.3, 0.1, "e", (0.4, 0.6), orbit=strongly_unstable)


def test_a_curve_hands_over_to_the_segments_where_single_shooting_stalls():
    # From a = 5 (|M| = 4e3: single shooting) up in a, towards the pendulum's grazing: single shooting
    # stalls near a = 5.977 (|M| ~ 5e6), the segments go on to the bound.
    orbit = strongly_unstable_orbit(a=5.0)
    assert np.linalg.norm(orbit.monodromy, 2) < 1e4
    curve = follow_curve(orbit.model, "fold", "A", 0.3, 0.1, "a", (4.9, 5.995), orbit=orbit)
    a = curve.values("a")
    assert a.min() == 4.9 and a.max() == 5.995, curve.status
    assert "at the last point: reached the bound a = 5.995; by multiple shooting from A = " in curve.status
    np.testing.assert_allclose(curve.values("A"), ball_fold(0.5), rtol=0, atol=1e-12)
    assert not curve.special
    late = [p for p in curve.points if p.values[1] > 5.99]
    assert late and all(p.accuracy < 1e-12 for p in late)


def test_a_segmented_neimark_sacker_curve_is_the_exact_maps(monkeypatch):
    monkeypatch.setattr(curves_module, "MULTIPLE_SHOOTING_NORM", 0.0)  # the segments throughout
    model = six_state_model(Om=1.2)
    curve = follow_curve(model, "neimark-sacker", "Om", 1.2, 1.45, "rr", (0.75, 0.85))
    assert len(curve.points) >= 3 and curve.status.count("by multiple shooting") == 2
    for point in curve.points[:: max(1, len(curve.points) // 3)]:
        om, rr = point.values
        ref = six_state_matrices(model.with_params(Om=om, rr=rr))
        _, J = ref.periodic_orbit(np.asarray(point.state), point.section_time)
        assert abs(abs(pair_closest_to_circle(J)) - 1.0) < 1e-8
        assert point.accuracy < 1e-9
    _condition_holds(curve, "neimark-sacker", tol=1e-8)


def test_a_segmented_branch_point_curve_is_single_shootings(monkeypatch):
    m = two_sided_oscillator(amp=2.0, omega=1.0, zeta=0.05, r=0.8)
    single = follow_curve(m, "branch-point", "omega", 1.0, 1.2, "amp", (1.8, 2.2), period=1)
    monkeypatch.setattr(curves_module, "MULTIPLE_SHOOTING_NORM", 0.0)
    segmented = follow_curve(m, "branch-point", "omega", 1.0, 1.2, "amp", (1.8, 2.2), period=1)
    assert segmented.status.count("by multiple shooting") == 2
    _condition_holds(segmented, "fold", tol=1e-8)
    for curve in (single, segmented):  # (both end on the bounds of amp, where they can be compared)
        assert curve.points[0].values[1] in (1.8, 2.2) and curve.points[-1].values[1] in (1.8, 2.2)
    ends = {p.values[1]: p.values[0] for p in (single.points[0], single.points[-1])}
    for p in (segmented.points[0], segmented.points[-1]):
        assert p.values[0] == pytest.approx(ends[p.values[1]], abs=1e-9)
    assert max(abs(p.orbit.model.params["amp"] - p.values[1]) for p in segmented.points) == 0.0


def test_the_segments_reach_the_grazing_with_no_codimension_two_point_of_rounding():
    # On to the pendulum's grazing (a = 6.003332408, where the exact linear flow's impact speed is zero:
    # docs/shooting.md, tests/orbits/test_multiple_shooting.py): |M| reaches 1e29 and the pendulum's
    # small multiplier, below the monodromy's rounding, came out as -1.8e13: it must change no sign of
    # the codimension-two tests (a "fold-flip" there is rounding's).
    orbit = strongly_unstable_orbit(a=5.0)
    curve = follow_curve(orbit.model, "fold", "A", 0.3, 0.1, "a", (4.9, 6.1), orbit=orbit)
    assert [s.kind for s in curve.special] == ["grazing"], [(s.kind, s.values) for s in curve.special]
    assert max(np.linalg.norm(p.orbit.monodromy, 2) for p in curve.points) > 1e20
    assert curve.special[0].values[1] == pytest.approx(6.003332408, abs=1e-9)
    np.testing.assert_allclose(curve.values("A"), ball_fold(0.5), rtol=0, atol=1e-12)


@pytest.mark.parametrize(("kind", "delta"), [("fold", 1e-8), ("period-doubling", -1e-5)])
def test_the_condition_moves_with_the_multiplier_as_its_slope_says(kind, delta):
    # Just off the curve (the ball's amplitude delta inside the orbit's side) the critical multiplier is
    # mu - g / (dg/dmu): against the ball alone's multiplier (the pendulum's 1e7 is in the same orbit).
    A = float((ball_fold if kind == "fold" else ball_period_doubling)(0.5)) + delta
    orbit = strongly_unstable_orbit(A=A)
    system = SegmentedOrbitSystem(orbit.model, kind, ("A", "e"), 1, orbit.t0, orbit.stop, orbit)
    _, _, ev = system(system.start(orbit))
    predicted = CRITICAL_MULTIPLIER[kind] - ev.condition / multiplier_slope(ev.solution, 4).real
    fm = flow_map(ball_alone(A=A), np.asarray(orbit.state)[2:], t0=orbit.t0, periods=1)
    mu = np.linalg.eigvals(fm.jacobian)
    exact = mu[np.argmin(np.abs(mu - CRITICAL_MULTIPLIER[kind]))].real
    assert 1e-5 < abs(exact - CRITICAL_MULTIPLIER[kind]) < 1e-3  # (off the curve, to first order)
    assert predicted == pytest.approx(exact, abs=1e-2 * abs(exact - CRITICAL_MULTIPLIER[kind]))


# --------------------------------------------------------------------------
# Impacts that change order on the segments


CROSSING_PHASE = 2.3812
"""A table phase that puts the ball's impact on the pendulum's at the right wall near ``A = 0.35``."""


def _crossing_amplitude(orbit) -> float:
    """The ``A`` where the ball's impact (at ``w t = phi + phase``, ``cos phi = pi (1 - e) / ((1 + e) A
    w^2)``: the closed form) coincides with the pendulum's at the right wall."""
    right = float(orbit.impact_times[list(orbit.impact_stops).index(0)])
    phi = (2.0 * right - CROSSING_PHASE) % (2 * np.pi)
    return float(np.pi * 0.5 / (1.5 * 4.0 * np.cos(phi)))


def test_a_branch_on_the_segments_goes_on_where_two_impacts_change_order():
    orbit = strongly_unstable_orbit(table_phase=CROSSING_PHASE)
    branch = continue_orbit(orbit.model, "A", 0.3, 0.37, orbit=orbit)
    assert branch.values[-1] == 0.37, branch.status
    assert "by multiple shooting from A = 0.3 on" in branch.status
    assert list(branch.orbits[0].impact_stops) == [1, 2, 0] and list(branch.orbits[-1].impact_stops) == [
        1,
        0,
        2,
    ]
    where = branch.status.split("the impacts on 'table' and 'right' change order between A = ")[1]
    low, high = (float(v.split()[0]) for v in where.split(" and A = "))
    assert low <= _crossing_amplitude(branch.orbits[-1]) <= high and high - low < 1e-6
    for end in (low, high):  # (both points are on the branch; the status prints them to 10 digits)
        assert np.min(np.abs(np.array(branch.values) - end)) < 1e-9
    assert not branch.special
    # The ball's orbit all along is its closed form: it leaves the table at speed g T / 2 = pi / 2.
    for o in branch.orbits:
        j = list(o.impact_stops).index(2)
        u_after = float(o.model.reset(o.impact_states[j], o.impact_times[j], 2)[3])
        assert u_after == pytest.approx(np.pi / 2, abs=1e-9)


def test_without_the_reordering_the_segments_stall_at_the_change(monkeypatch):
    monkeypatch.setattr(continuation_module, "reordered", lambda *args, **kwargs: None)
    orbit = strongly_unstable_orbit(table_phase=CROSSING_PHASE)
    branch = continue_orbit(orbit.model, "A", 0.3, 0.37, orbit=orbit)
    assert (
        branch.values[-1] < _crossing_amplitude(branch.orbits[-1]) and "step size fell below" in branch.status
    )


def test_a_curve_on_the_segments_goes_on_where_two_impacts_change_order():
    # The ball's period-doubling curve in (A, e) with its impact reaching the pendulum's at the right
    # wall near e = 0.5 (a table phase chosen for it): the closed form on both sides of the change.
    orbit = strongly_unstable_orbit(table_phase=2.2924)
    curve = follow_curve(orbit.model, "period-doubling", "A", 0.3, 0.5, "e", (0.4, 0.6), orbit=orbit)
    e = curve.values("e")
    assert e.min() == 0.4 and e.max() == 0.6, curve.status
    assert "the impacts on 'table' and 'right' change order after A = " in curve.status
    orders = {tuple(p.orbit.impact_stops) for p in curve.points}
    assert orders == {(1, 2, 0), (1, 0, 2)}
    error = np.abs(curve.values("A") - ball_period_doubling(e))
    accuracy = np.array([p.accuracy for p in curve.points])
    # (where the two impacts are 1e-8 apart in time the segment between them is that short, and the
    # point is known only to 6e-10: it says so)
    assert np.all(error <= np.maximum(1e-12, accuracy)), (error.max(), accuracy.max())
    assert np.sum(accuracy > 1e-12) <= 4 and not curve.special
