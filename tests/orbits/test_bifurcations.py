"""No bifurcation passes silently, and branch switching (issue 27, items 1 and 2).

The symmetric orbits of a pendulum between two walls (:mod:`tests.orbits.symmetric_models`, a
model of our own) and of the two-sided oscillator with equal gaps lose their symmetry at a branch
point (a multiplier +1 where the parameter does not turn), which used to be reported as a fold;
the unstable symmetric branch then ends where its impact speeds vanish, where continuation used
to stop with "step size fell below 1e-06".  The branch point is checked against an independent
route (the half-period map's multiplier -1), the grazing against the grazing conditions and the
closed form, switching against the mirror symmetry and the period-doubling of the bouncing ball
against the squares of the period-1 multipliers.
"""

from __future__ import annotations

import math
from itertools import product

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

import grazing
from grazing.maps import flow_map
from grazing.models import two_sided_oscillator
from grazing.orbits import PalcSettings, continue_orbit, find_orbit
from grazing.orbits.bifurcations import CROSSINGS, Located, StepAccount
from grazing.orbits.continuation import _locate_grazing
from grazing.orbits.shooting import move_section
from tests.orbits.any_damping import any_damping
from tests.orbits.symmetric_models import mirror, symmetry_breaking, walled_pendulum
from tests.orbits.test_closed_forms import R, ball_fold, ball_orbit, ball_period_doubling

# (model, parameter, start, stop): a stable symmetric orbit followed down to below its branch point
SYMMETRIC = {
    "walled-pendulum": (walled_pendulum(A=0.3), "Om", 1.2, 0.6),
    "two-sided-oscillator": (two_sided_oscillator(amp=0.5), "omega", 1.0, 0.6),
}


@pytest.fixture(scope="module", params=list(SYMMETRIC))
def symmetric(request):
    model, param, start, stop = SYMMETRIC[request.param]
    orbit = find_orbit(model.with_params(**{param: start}), t0=None)
    assert orbit.impacts == 2 and orbit.stable
    np.testing.assert_allclose(mirror(orbit.model, orbit.state, orbit.t0), orbit.state, atol=1e-12)
    return request.param, continue_orbit(model, param, start, stop, orbit=orbit)


def test_the_branch_point_is_located_and_told_from_a_fold(symmetric):
    name, br = symmetric
    assert [s.kind for s in br.special] == ["branch point", "grazing"], br.status
    bp = br.special[0]
    # A multiplier +1 there: det(P_x - I) = 0 at the located point (the point's own monodromy) ...
    M = bp.orbit.monodromy
    assert abs(np.linalg.det(M - np.eye(2))) < 1e-9
    assert np.min(np.abs(bp.multipliers - 1)) < 1e-9
    assert bp.orbit.residual < 1e-10  # (a point of the branch, to Newton tolerance)
    # ... and the parameter does not turn: it moves the same way on both sides, the tangent too.
    i = bp.index
    values = np.array(br.values[i - 2 : i + 4])
    assert np.all(np.diff(values) < 0) and values[2] > bp.param > values[3]
    assert not bp.turns and abs(bp.tangent[-1]) > 0.1
    # The stable symmetric orbit becomes unstable there: one multiplier leaves the unit circle.
    assert all(o.stable for o in br.orbits[: i + 1]) and not any(o.stable for o in br.orbits[i + 1 :])
    # Independent route: the symmetric orbit is a fixed point of the half-period map G (P = G o G),
    # whose multiplier -1 breaks the symmetry.
    model, param, _, _ = SYMMETRIC[name]
    ref = symmetry_breaking(model, param, bp.orbit.state, bp.orbit.t0, bp.param - 3e-3, bp.param + 3e-3)
    assert bp.param == pytest.approx(ref, abs=1e-10)


def test_the_unstable_symmetric_branch_reaches_its_grazing(symmetric):
    """Its impact speeds vanish (both at once, by symmetry): the grazing is solved from the grazing
    equations, ahead of the last point where Newton's method still converges."""
    name, br = symmetric
    graze = br.special[-1]
    assert br.status.startswith("ended at a grazing at") and "step size" not in br.status
    assert not br.orbits[-1].stable and br.orbits[-1].min_impact_speed < 0.05
    g = graze.grazing
    assert g is not None and graze.param == g.model.params[br.param]
    assert graze.stop == g.stop == 0  # (both stops at once: the first is named, not rounding's pick)
    # The grazing conditions at the contact, to Newton tolerance: on the stop, zero normal speed,
    # turning back, and periodic from the contact.
    cd = g.model.contact_derivatives(g.contact, g.t_graze, g.stop)
    assert abs(cd["h"]) < 1e-12 and abs(cd["rate"]) < 1e-12 and cd["accel"] > 0
    fm = flow_map(g.model, g.contact, t0=g.t_graze, periods=1, virtual=True)
    np.testing.assert_allclose(fm.image, g.contact, atol=1e-10)
    # Ahead of the last point, in the direction of travel.
    assert graze.param < br.values[-1]
    if name == "two-sided-oscillator":  # the linear response's amplitude equals the gap there
        m = g.model
        zeta, amp = m.params["zeta"], m.params["amp"]
        expected = brentq(lambda w: amp / math.hypot(1 - w * w, 2 * zeta * w) - 1.0, 0.5, 0.9, xtol=1e-15)
        assert graze.param == pytest.approx(expected, abs=1e-11)
    else:  # the nonimpacting symmetric orbit there touches both walls
        free = find_orbit(g.model, g.contact, t0=g.t_graze, virtual=True)
        assert free.guard_mins == pytest.approx([0.0, 0.0], abs=1e-9)


@pytest.mark.parametrize("wall", [0.9, 1.1, 1.2])
def test_a_symmetric_orbit_losing_both_impacts_at_once_names_the_first_wall(wall):
    """Its impact speeds vanish on both walls at once (to rounding, which named "west" at these walls
    before): the first stop, "east", is named, and the grazing is the one of both."""
    m = walled_pendulum(A=0.9, wall=wall)
    orbit = find_orbit(m, grazing.simulate(m, [0.0, 0.0], transient=600, periods=4).x_final, period=1, t0=0.0)
    assert orbit.impacts == 2
    br = continue_orbit(m, "A", 0.9, 0.05, x0=orbit.state, period=1)
    graze = br.special[-1]
    assert graze.kind == "grazing" and graze.grazing.stop_name == "east" and "with stop 'east'" in br.status
    free = find_orbit(graze.grazing.model, graze.grazing.contact, t0=graze.grazing.t_graze, virtual=True)
    assert free.guard_mins == pytest.approx([0.0, 0.0], abs=1e-9)


def test_a_grazing_ahead_is_accepted_only_within_the_extrapolated_distance(symmetric):
    _, br = symmetric
    last, pg = br.orbits[-1], br.special[-1].param
    p = br.values[-1]
    d = pg - p  # (negative: the branch moves down)
    assert _locate_grazing(last, None, br.param, False, ahead=p + d) is not None
    assert _locate_grazing(last, None, br.param, False, ahead=p + 0.6 * d) is not None  # within twice
    assert _locate_grazing(last, None, br.param, False, ahead=p + 0.3 * d) is None  # beyond twice
    assert _locate_grazing(last, None, br.param, False, ahead=p - d) is None  # behind
    assert _locate_grazing(last, None, br.param, False) is None  # (the former window, 1e-4)


@pytest.mark.parametrize("name", list(SYMMETRIC))
def test_switching_at_the_branch_point_gives_the_mirror_image_pair(name):
    model, param, start, stop = SYMMETRIC[name]
    orbit = find_orbit(model.with_params(**{param: start}), t0=None)
    br = continue_orbit(model, param, start, stop, orbit=orbit, switch=True)
    i = next(k for k, s in enumerate(br.special) if s.kind == "branch point")
    assert br.special[i].switched and br.segment_status[0].startswith("switched at the branch point")
    halves = [seg for seg, origin in enumerate(br.segment_origin) if origin == i]
    assert len(halves) == 2
    points = [[k for k, seg in enumerate(br.segments) if seg == h] for h in halves]
    a, b = ([br.orbits[k] for k in pts] for pts in points)
    # Both halves leave the branch point and are asymmetric: the two walls are hit at different speeds.
    for half in (a, b):
        assert half[0].model.params[param] == pytest.approx(br.special[i].param, abs=1e-5)
        far = [
            o
            for o in half
            if o.min_impact_speed > 0.05 and abs(o.model.params[param] - half[0].model.params[param]) > 1e-4
        ]
        assert far
        for o in far:
            assert abs(o.impact_speeds[0] - o.impact_speeds[1]) > 1e-3
            assert np.max(np.abs(mirror(o.model, o.state, o.t0) - o.state)) > 1e-3
    # Mirror images: the mirror image of each clearly asymmetric orbit of one half is the orbit of the
    # other half at the same value (Newton's method from the nearest point of that half, on the same
    # section).
    values_a = np.array([o.model.params[param] for o in a])
    checked = 0
    for o in b:
        image = mirror(o.model, o.state, o.t0)
        if o.min_impact_speed < 0.05 or np.max(np.abs(image - o.state)) < 0.05:
            continue
        near = a[int(np.argmin(np.abs(values_a - o.model.params[param])))]
        other = find_orbit(o.model, move_section(near, o.t0).state, period=1, t0=o.t0)
        # Near the branch point a multiplier is near 1: Newton's residual leaves the state uncertain by
        # about residual / |1 - mu| (1.7e-11 / 3e-4 at 5e-6 from it: measured differences 1.5e-7)
        conditioning = min(abs(1 - o.multipliers))
        atol = 1e-9 + 10 * (o.residual + other.residual) / conditioning
        np.testing.assert_allclose(image, other.state, rtol=0, atol=atol)
        np.testing.assert_allclose(np.sort(o.impact_speeds), np.sort(other.impact_speeds), rtol=0, atol=atol)
        checked += 1
    assert checked >= 3
    # Each half ends at the grazing of one wall at the same value: the other's, mirrored.
    ends = [next(s for s in br.special if s.kind == "grazing" and s.index == pts[-1]) for pts in points]
    assert ends[0].param == pytest.approx(ends[1].param, abs=1e-10)
    assert {ends[0].stop, ends[1].stop} == {0, 1}


def test_the_curved_branch_of_the_pitchfork_passes_the_branch_point_where_the_parameter_turns():
    """The two-sided oscillator at omega = 1.4, amp from 2 down: the attractor is asymmetric; its branch
    turns back at the pitchfork, through the branch point, onto its mirror image (no multiplier
    crosses the unit circle: +1 is touched).  Switching there gives the symmetric branch, both ways."""
    m = two_sided_oscillator(omega=1.4)
    orbit = find_orbit(m.with_params(amp=2.0), t0=None)
    assert np.max(np.abs(mirror(orbit.model, orbit.state, orbit.t0) - orbit.state)) > 0.1  # asymmetric
    br = continue_orbit(m, "amp", 2.0, 0.5, orbit=orbit, switch=True)
    (bp,) = br.special
    assert bp.kind == "branch point" and bp.turns and bp.switched
    assert np.min(np.abs(bp.multipliers - 1)) < 1e-9
    assert br.segment_origin == [-1, 0, 0] and br.status == "reached the bound amp = 2"
    assert br.segment_status[1] == "reached the bound amp = 0.5"
    for k in (1, 2):
        for o in [o for o, seg in zip(br.orbits, br.segments) if seg == k]:
            np.testing.assert_allclose(mirror(o.model, o.state, o.t0), o.state, atol=1e-9)  # symmetric
    sym = next(o for o, seg in zip(br.orbits, br.segments) if seg == 1)
    ref = symmetry_breaking(m, "amp", sym.state, sym.t0, bp.param - 0.01, bp.param + 0.01)
    assert bp.param == pytest.approx(ref, abs=1e-10)


# --------------------------------------------------------------------------
# folds, period-doubling, switching at a period-doubling


def test_a_fold_is_still_a_fold():
    """The bouncing ball's fold (the parameter turns there), against its closed form."""
    a_fold, a_pd = ball_fold(1), ball_period_doubling(1)
    mid = 0.5 * (a_fold + a_pd)
    orbit = ball_orbit(1, mid)
    br = continue_orbit(orbit.model, "amplitude", mid, a_fold - 0.3, orbit=orbit)
    assert [s.kind for s in br.special] == ["fold"]
    fold = br.special[0]
    assert fold.param == pytest.approx(math.pi * (1 - R) / (1 + R), abs=1e-9) and fold.turns
    i = fold.index
    assert br.values[i - 1] > br.values[i] and br.values[i + 2] > br.values[i + 1]  # it turns back


def test_switching_at_the_period_doubling_follows_the_period_two_orbit():
    a_fold, a_pd = ball_fold(1), ball_period_doubling(1)
    assert a_pd == pytest.approx(
        math.sqrt((math.pi * (1 - R) / (1 + R)) ** 2 + (2 * (1 + R * R) / (1 + R) ** 2) ** 2), abs=1e-15
    )
    mid = 0.5 * (a_fold + a_pd)
    orbit = ball_orbit(1, mid)
    br = continue_orbit(orbit.model, "amplitude", mid, a_pd + 0.1, orbit=orbit, switch=True)
    pd = br.special[0]
    assert pd.kind == "period-doubling" and pd.switched and pd.param == pytest.approx(a_pd, abs=1e-8)
    assert set(br.segments) == {0, 1} and br.segment_origin == [-1, 0]
    periods, segments = br.periods, np.array(br.segments)
    assert set(periods[segments == 0]) == {1} and set(periods[segments == 1]) == {2}
    doubled = [o for o, seg in zip(br.orbits, br.segments) if seg == 1]
    for o in doubled:
        assert o.period == 2 and o.impacts == 2 and o.signature == (1, 1)
        assert abs(np.prod(o.multipliers)) == pytest.approx(R**4, rel=1e-9)  # det: r^2 per impact
        once = flow_map(o.model, o.state, t0=o.t0, periods=1).image
        assert np.max(np.abs(once - o.state)) > 1e-4  # not the period-1 orbit
    # The period-2 orbits' multipliers at the period-doubling are the squares of the period-1 orbit's:
    # extrapolated (linearly in the parameter) from the first points of the new segment.
    values = np.array([o.model.params["amplitude"] for o in doubled[:4]])
    mu = np.array([np.sort(o.multipliers.real) for o in doubled[:4]])
    at_pd = [np.polyval(np.polyfit(values - a_pd, mu[:, j], 1), 0.0) for j in range(2)]
    np.testing.assert_allclose(at_pd, np.sort((pd.multipliers**2).real), atol=1e-6)
    np.testing.assert_allclose(at_pd, [R**4, 1.0], atol=1e-6)
    assert br.status == f"reached the bound amplitude = {a_pd + 0.1:.10g}"
    ds = br.to_dataset()
    assert list(ds.period.values) == list(periods) and int(ds.special_switched[0]) == 1


def test_no_switch_beyond_the_largest_period(monkeypatch):
    import grazing.orbits.continuation as continuation

    monkeypatch.setattr(continuation, "MAX_PERIOD", 1)
    a_pd = ball_period_doubling(1)
    orbit = ball_orbit(1, 1.3)
    br = continue_orbit(orbit.model, "amplitude", 1.3, a_pd + 0.1, orbit=orbit, switch=True)
    (pd,) = br.special
    assert set(br.segments) == {0} and pd.kind == "period-doubling" and not pd.switched
    assert pd.note == "not switched to the period-2 orbit born here: periods above 1 are not switched to"
    assert br.status == f"reached the bound amplitude = {a_pd + 0.1:.10g}"  # along the period-1 orbit


# --------------------------------------------------------------------------
# the account: an unlocated stability change is reported


def test_a_stability_change_that_cannot_be_located_is_reported():
    """From c = 1.2 (two real multipliers inside the unit circle) to c = -0.5 (a complex pair outside)
    in one step, no test function changes sign: the pair crossed the circle as a complex pair (the
    Neimark-Sacker test needs one at both ends).  With steps that see it, it is located at c = 0."""
    m = any_damping()
    coarse = PalcSettings(ds=2.0, ds_max=2.0, ds_refine=2.0)
    br = continue_orbit(m, "c", 1.2, -0.5, period=1, virtual=True, settings=coarse)
    assert br.values == [1.2, -0.5]
    (sp_,) = br.special
    assert sp_.kind == "unlocated" and sp_.between == (1.2, -0.5) and sp_.index == 0
    assert sp_.note.startswith(
        "unlocated stability change between c = 1.2 and c = -0.5: stable -> 2 multipliers"
    )
    fine = continue_orbit(m, "c", 1.2, -0.5, period=1, virtual=True)
    (ns,) = fine.special
    assert ns.kind == "neimark-sacker" and ns.param == pytest.approx(0.0, abs=1e-9)
    T = 2 * math.pi / 1.3
    np.testing.assert_allclose(np.abs(ns.multipliers), 1.0, atol=1e-8)
    assert ns.multipliers[0] == pytest.approx(np.exp(1j * T), abs=1e-8) or ns.multipliers[1] == pytest.approx(
        np.exp(1j * T), abs=1e-8
    )


KINDS = ["fold", "period-doubling", "neimark-sacker", "branch point", "branch point (turns)"]


@given(
    kinds=st.lists(st.sampled_from(KINDS), max_size=4),
    before=st.integers(0, 3),
    change=st.integers(-3, 3),
    missed=st.booleans(),
)
@settings(max_examples=300, deadline=None)
def test_the_account_of_a_step(kinds, before, change, missed):
    """A step is explained iff its change of the number of unstable multipliers is a sum of each located
    point's crossings taken up or down (a branch point where the parameter turns crosses none)."""
    located = tuple(
        Located(k.split(" (")[0], None, turns=k.endswith("(turns)"))
        for k in kinds  # type: ignore[arg-type]
    )
    after = max(0, before + change)
    step = StepAccount(located, ("fold",) if missed else (), (before, after))
    crossings = [0 if k == "branch point (turns)" else CROSSINGS[k] for k in kinds]
    reachable = {
        sum(sign * c for sign, c in zip(signs, crossings)) for signs in product((-1, 1), repeat=len(kinds))
    }
    assert step.explained == (not missed and (after - before) in reachable)


# --------------------------------------------------------------------------
# random parameters: every stability change between two points is accounted for


def check_branch_account(amp: float, omega: float, r: float, zeta: float, down: bool) -> None:
    """The two-sided oscillator (equal gaps) with random parameters, continued from its attractor over
    0.3 in omega: between any two points of a segment whose numbers of unstable multipliers differ
    lies a special point (located, or reported as unlocated), and every located point satisfies
    its defining condition."""
    from hypothesis import assume

    m = two_sided_oscillator(amp=amp, omega=omega, r=r, zeta=zeta)
    try:
        orbit = find_orbit(m, t0=None, transient=300)
    except grazing.GrazingError:
        assume(False)
    assume(orbit.period <= 2)
    end = omega - 0.3 if down else omega + 0.3
    try:
        br = continue_orbit(m, "omega", omega, end, orbit=orbit)
    except grazing.GrazingError:
        assume(False)
    unstable = [o.unstable_count for o in br.orbits]
    at = {s.index for s in br.special}
    for k in range(len(br) - 1):
        if br.segments[k] == br.segments[k + 1] and unstable[k] != unstable[k + 1]:
            assert k in at, (k, br.values[k : k + 2], [s.kind for s in br.special])
    for s in br.special:
        mu = s.multipliers
        if s.kind in ("fold", "branch point"):
            assert np.min(np.abs(mu - 1)) < 1e-5
        elif s.kind == "period-doubling":
            assert np.min(np.abs(mu + 1)) < 1e-5
        elif s.kind == "neimark-sacker":
            assert np.min(np.abs(np.abs(mu) - 1)) < 1e-5


RANDOM = {
    "amp": st.floats(0.2, 2.0),
    "omega": st.floats(0.7, 1.8),
    "r": st.floats(0.6, 0.95),
    "zeta": st.floats(0.02, 0.1),
    "down": st.booleans(),
}


@given(**RANDOM)
@settings(max_examples=3, deadline=None)
def test_every_stability_change_on_a_branch_is_accounted_for(amp, omega, r, zeta, down):
    check_branch_account(amp, omega, r, zeta, down)


@pytest.mark.slow
@given(**RANDOM)
@settings(max_examples=60, deadline=None)
def test_every_stability_change_on_a_branch_is_accounted_for_many(amp, omega, r, zeta, down):
    check_branch_account(amp, omega, r, zeta, down)


@pytest.mark.parametrize(
    ("eta", "to", "virtual"),
    [(0.6, 0.5, True), (0.46, 0.44, False)],
    ids=["elliptic-nonimpacting", "hyperbolic-impacting"],
)
def test_a_conservative_branch_has_no_spurious_stability_change(eta, to, virtual):
    """No damping and elastic impacts (beta = 0, r = 1): the map preserves area, det(P_x) = 1
    (the invariant r^(2k) exp(-4 pi beta n / eta)), and a complex pair stays on the unit circle.
    Rounding put it inside or outside, a Neimark-Sacker test function of rounding changed sign:
    'neimark-sacker' and 'unlocated' points came and went along the branch."""
    m = grazing.models.pendulum("B", theta_hat=math.radians(40), eta=eta, beta=0.0, r=1.0)
    br = continue_orbit(m, "eta", eta, to, virtual=virtual)
    assert len(br) > 5
    dets = np.array([np.linalg.det(o.monodromy) for o in br.orbits])
    assert np.allclose(dets, 1.0, rtol=0, atol=1e-9), np.max(np.abs(dets - 1))
    assert not [s.kind for s in br.special if s.kind in ("neimark-sacker", "unlocated")]
    if virtual:  # (an elliptic orbit: on the circle, neither stable nor unstable by chance)
        pairs = [o.multipliers for o in br.orbits]
        assert all(np.all(np.abs(np.abs(mu) - 1) < 1e-12) and o.stable for mu, o in zip(pairs, br.orbits))


# --------------------------------------------------------------------------
# a test function that jumps is not a bifurcation: the located point fails its condition


def _jumping_system(before: complex, after: complex, at: float = 0.5):
    """A one-state 'branch' ``x = 0`` whose multiplier jumps from ``before`` to ``after`` at ``p = at``."""
    from types import SimpleNamespace

    from grazing.orbits.shooting import unstable_count as count

    def orbit(p: float):
        mu = np.array([before if p < at else after], dtype=complex)
        return SimpleNamespace(monodromy=np.diag(mu.real), multipliers=mu, unstable_count=count(mu))

    def evaluate(u):
        return np.array([u[0]]), np.array([[1.0, 0.0]]), orbit(float(u[1]))

    return evaluate


@pytest.mark.parametrize(
    ("kind", "before", "after"),
    [("period-doubling", -0.97, -1.03), ("period-doubling", -0.995, -1.005), ("fold", 0.98, 1.02)],
)
def test_a_multiplier_that_jumps_across_the_circle_is_unlocated_not_a_bifurcation(kind, before, after):
    # The test function changes sign, and regula falsi closes in on the jump; the point there has a
    # multiplier 0.005 to 0.03 from -1 (or +1), which no tolerance of located points may accept.
    from grazing.orbits.bifurcations import between
    from grazing.orbits.palc import PalcPoint, PalcSettings

    evaluate = _jumping_system(before, after)
    tangent = np.array([0.0, 1.0])
    a, b = (PalcPoint(np.array([0.0, p]), *evaluate(np.array([0.0, p])), tangent=tangent) for p in (0.3, 0.7))
    step = between(evaluate, a, b, PalcSettings(), 1)
    assert step.located == () and not step.explained, step
    assert step.unstable == (0, 1)
    assert any(kind in m for m in step.missed), step.missed


def test_an_unexplained_step_with_located_points_names_them():
    step = StepAccount((Located("fold", None, turns=True),), ("period-doubling",), (0, 2))
    assert not step.explained
    text = step.describe()
    assert text.startswith("stable -> 2 multipliers outside the unit circle")
    assert "located: fold" in text and "a multiplier passes through -1" in text


def test_a_candidate_short_of_the_extrapolated_boundary_is_a_jump():
    # The margin (an impact speed squared) falls 4 -> 1 from p = 0 to 1: it vanishes between p = 4/3
    # (linearly) and 2 (quadratically); a candidate beyond the boundary at p = 1.1 is less than half-way
    # to the nearer zero from the last point (p = 1): the corrector jumped to another curve.
    from grazing.orbits.palc import Palc, PalcPoint

    palc = object.__new__(Palc)
    palc.index = 0
    margins = [(0.0, 4.0), (1.0, 1.0)]

    def at(p):
        return PalcPoint(np.array([p]), np.zeros(1), np.zeros((1, 1)), None)

    assert palc._jumped(margins, at(1.1))
    assert not palc._jumped(margins, at(1.3))
    assert palc._jumped([(0.0, 1.0), (1.0, 2.0)], at(1.5))  # (moving away from the boundary)
