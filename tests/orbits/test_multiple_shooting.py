"""Multiple shooting: a segment per impact, impact times as unknowns (``grazing.orbits.segments``).

An inverted pendulum between two walls (:func:`tests.linear_exact.inverted_walls`)
has orbits whose multipliers grow past 1e7 as an impact speed falls to zero (a
saddle flow between impacts times a saltation matrix's ``1 / v``).  Single
shooting's residual cannot fall below ``|M| eps |x|`` there, and its branch
stalled at a = 5.9766 with "Newton's method did not converge"; the segmented
equations reach the grazing that ends the branch, checked against the exact
grazing of the linear flow (matrix exponentials).
"""

from __future__ import annotations

import numpy as np
import pytest

import grazing
from grazing.orbits import continue_orbit, find_orbit, follow_curve
from grazing.orbits.continuation import _Continuation
from grazing.orbits.palc import PalcSettings
from grazing.orbits.segments import layout_of, segmented_equations
from tests.linear_exact import damper, grazing_of_impact, inverted_walls, inverted_walls_matrices


def _ball_period_two():
    """The ball on its period-2 orbit with one impact (a flight of two forcing periods), and the orbit."""
    from tests.orbits.test_closed_forms import ball_orbit, ball_period_doubling

    return ball_orbit(2, 0.95 * ball_period_doubling(2))


def _start(make, guess, period):
    made = make()
    if guess == "ball":  # (the closed form's orbit)
        return made.model, made
    return made, find_orbit(made, guess, period=period)


def _central_differences(evaluate, u: np.ndarray) -> np.ndarray:
    F = evaluate(u)[0]
    J = np.zeros((F.size, u.size))
    for i in range(u.size):
        h = 1e-6 * max(1.0, abs(u[i]))
        e = np.zeros(u.size)
        e[i] = h
        J[:, i] = (evaluate(u + e)[0] - evaluate(u - e)[0]) / (2 * h)
    return J


CASES = [
    # (model, guess, period, parameters to differentiate by): the period-setting frequency, a guard's and
    # a reset's parameter, the damping of the flow; a flight longer than a forcing period (the ball)
    (lambda: grazing.models.impact_oscillator(omega=0.8), None, 1, ("omega", "sigma", "r", "zeta")),
    (lambda: _ball_period_two(), "ball", 2, ("amplitude", "r")),
    (lambda: damper(omega=1.2), None, 1, ("omega", "mu", "gap", "r")),
    (lambda: inverted_walls(), [-0.9294, 0.8725], 1, ("w", "a", "r", "k")),
]


@pytest.mark.parametrize(
    ("make", "guess", "period", "params"), CASES, ids=["oscillator", "ball", "damper", "inverted"]
)
def test_the_segmented_jacobian_is_the_derivative_of_its_equations(make, guess, period, params):
    model, orbit = _start(make, guess, period)
    assert orbit.impacts >= 1
    layout = layout_of(orbit)
    rng = np.random.default_rng(3)
    for param in params:
        evaluate = segmented_equations(model, param, period, orbit.t0, layout, 0)
        u = layout.pack(orbit, model.params[param])
        u = u + 1e-4 * rng.normal(size=u.size)  # (off the orbit: every term of the Jacobian counts)
        F, DF, _ = evaluate(u)
        assert DF.shape == (F.size, u.size) == (layout.size, layout.size + 1)
        np.testing.assert_allclose(
            DF, _central_differences(evaluate, u), atol=1e-6 * max(1.0, np.abs(DF).max())
        )


@pytest.mark.parametrize(
    ("make", "guess", "period", "params"), CASES, ids=["oscillator", "ball", "damper", "inverted"]
)
def test_the_segmented_orbit_is_the_single_shooting_orbit(make, guess, period, params):
    model, orbit = _start(make, guess, period)
    layout = layout_of(orbit)
    F, _, same = segmented_equations(model, params[0], period, orbit.t0, layout, 0)(
        layout.pack(orbit, model.params[params[0]])
    )
    assert np.max(np.abs(F)) < 1e-10
    np.testing.assert_allclose(same.impact_times, orbit.impact_times, atol=1e-12)
    np.testing.assert_allclose(same.impact_speeds, orbit.impact_speeds, rtol=1e-9)
    mu, ref = np.sort_complex(same.multipliers), np.sort_complex(orbit.multipliers)
    np.testing.assert_allclose(mu, ref, rtol=1e-8 * max(1.0, np.abs(ref).max()))
    assert same.impacts == orbit.impacts and same.signature == orbit.signature
    # Its guard minima: zero at the impacts, the free flight's closest approaches where there are any.
    assert same.guard_min == pytest.approx(orbit.guard_min, abs=1e-9)
    for ours, theirs in zip(same.approach_by_stop, orbit.approach_by_stop):
        assert (ours is None) == (theirs is None)
        if ours is not None:
            assert ours[0] == pytest.approx(theirs[0], abs=1e-9)


@pytest.fixture(scope="module")
def inverted_branch():
    model = inverted_walls()
    orbit = find_orbit(model, [-0.9294, 0.8725], period=1)
    return model, orbit, continue_orbit(model, "a", 3.0, 9.0, orbit=orbit)


def test_a_strongly_unstable_branch_reaches_the_grazing_that_ends_it(inverted_branch):
    model, _, branch = inverted_branch
    assert max(o.abs_lambda for o in branch.orbits) > 1e7
    kinds = [sp.kind for sp in branch.special]
    assert kinds == ["grazing"], [sp.note for sp in branch.special]  # (no unlocated change on the way)
    graze = branch.special[0]
    assert graze.grazing is not None and "loses an impact" in branch.status
    assert "by multiple shooting from a = " in branch.status
    # The exact grazing: the linear flow's orbit through the same impacts, one of them at zero speed.
    last = branch.orbits[-1]
    assert np.min(last.impact_speeds) < 1e-8
    guess = np.concatenate([last.state, last.impact_times, [graze.param]])
    exact = grazing_of_impact(
        lambda a: inverted_walls_matrices(model.with_params(a=a)), list(last.impact_stops), last.t0, guess,
        int(np.argmin(last.impact_speeds)),
    )  # fmt: skip
    assert graze.param == pytest.approx(exact[-1], abs=1e-9)
    lo, hi = graze.interval
    assert lo <= exact[-1] <= hi and hi - lo < 1e-9
    assert abs(graze.param - exact[-1]) <= 10 * graze.precision + 1e-13


def test_single_shooting_alone_stalls_short_of_it(inverted_branch, monkeypatch):
    # The same branch without the segments: Newton's method fails where |M| eps |x| exceeds its tolerance.
    model, orbit, segmented = inverted_branch
    monkeypatch.setattr(_Continuation, "_layout", lambda self, orbit: None)
    single = continue_orbit(model, "a", 3.0, 9.0, orbit=orbit)
    assert "step size fell below" in single.status
    assert max(single.values) < segmented.special[-1].param - 1e-3


def test_find_orbit_from_a_guess_solves_the_segments_where_the_monodromy_is_large(
    inverted_branch, monkeypatch
):
    # From within 1e-10 of a strongly unstable orbit (|M| from 1e6 to 1e8), single shooting's first step
    # (|M| times the guess's error) lands on another orbit; the segments of the guess's run do not.
    from grazing.orbits.shooting import _Newton

    model, _, branch = inverted_branch
    picked = [o for o in branch.orbits if 1e6 < o.abs_lambda < 1e8][::8]
    assert len(picked) >= 4

    def found(orbit):
        m = model.with_params(a=orbit.model.params["a"])
        return find_orbit(m, orbit.state * (1 + 1e-10), period=1, t0=orbit.t0)

    for orbit in picked:
        again = found(orbit)
        np.testing.assert_allclose(again.state, orbit.state, atol=1e-10)
        assert again.abs_lambda == pytest.approx(orbit.abs_lambda, rel=1e-6)
    monkeypatch.setattr(_Newton, "segments_from_guess", lambda self, fm, virtual: False)
    elsewhere = [np.max(np.abs(found(orbit).state - orbit.state)) for orbit in picked]
    assert max(elsewhere) > 1e-4  # (single shooting alone: another orbit, for some of them)


def test_the_grazing_equations_and_curve_need_no_segments(inverted_branch):
    # On the section through the contact the vanishing impact is not applied: its saltation matrix's 1 / v
    # never enters the grazing equations, whose monodromy is of moderate size (|M| ~ 1e2 where the
    # branch's reached 1e24).  The grazing's curve in (a, c) is followed by single shooting, and each of
    # its points is the exact linear flow's grazing at that damping to 1e-9.
    model, _, branch = inverted_branch
    graze = branch.special[0]
    assert graze.grazing.abs_lambda < 1e3 < 1e7 < max(o.abs_lambda for o in branch.orbits)
    near = min(branch.orbits, key=lambda o: abs(o.model.params["a"] - (graze.param - 0.1)))
    a0 = near.model.params["a"]
    curve = follow_curve(model.with_params(a=a0), "grazing", "a", a0, 9.0, "c", (0.05, 0.2), orbit=near,
                         settings=PalcSettings(ds=0.01, ds_max=0.02))  # fmt: skip
    cs, avals = curve.values("c"), curve.values("a")
    assert len(cs) >= 8 and cs.min() < 0.09 and cs.max() > 0.11
    last = branch.orbits[-1]
    stops, vanishing = list(last.impact_stops), int(np.argmin(last.impact_speeds))
    start = np.concatenate([last.state, last.impact_times, [graze.param]])
    for c, a in sorted(zip(cs, avals), key=lambda ca: abs(ca[0] - 0.1)):  # (from c = 0.1 out)
        z = grazing_of_impact(
            lambda v, c=c: inverted_walls_matrices(model.with_params(a=v, c=c)),
            stops,
            last.t0,
            start,
            vanishing,
        )
        assert a == pytest.approx(z[-1], abs=1e-9)


def test_a_multiplier_below_the_monodromys_rounding_makes_no_neimark_sacker_sign_change():
    # At w = 1.294 the branch in a ends at a grazing with |M| = 1e9 a few points before it: the small
    # multiplier (det M / |M| = 2e-10) came out as 1e-7, its product with the large one went from 0.25 to
    # 175, and the Neimark-Sacker test's sign change was reported as an unlocated stability change (the
    # count of unstable multipliers stays 1 all along).
    model = inverted_walls(w=1.2940109689978085)
    orbit = find_orbit(model, [-0.98392617, 0.30520675], period=1)  # (a point of it)
    assert orbit.impacts == 2
    branch = continue_orbit(model, "a", 3.0, 9.0, orbit=orbit)
    assert [s.kind for s in branch.special] == ["grazing"], [s.note for s in branch.special]
    assert max(o.abs_lambda for o in branch.orbits) > 1e9
    assert {o.unstable_count for o in branch.orbits} == {1}
