"""Orbits a simulation never settles on, and the default guess's failures (issue 26).

An unstable nonimpacting orbit is found from a guess ``x0`` by Newton's method on the flow through
the stops and followed to its grazings, checked against the closed form of a negatively damped
linear oscillator (:mod:`tests.orbits.negative_damping`) and against the pendulum's own largest
angle; where the default guess (a simulation from rest) cannot start Newton's method — it
diverges, sticks to a stop or starts beyond one — the error says what happened and to give
``x0`` (``--initial``).
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import replace

import numpy as np
import pytest

import grazing
from grazing.core.options import NEWTON_TOL
from grazing.errors import GrazingWarning
from grazing.models import bouncing_ball, impact_oscillator, pendulum, two_sided_oscillator
from grazing.models.pendulum import max_angle
from grazing.normalform import find_grazing_point, normal_form_at
from grazing.orbits import continue_orbit, find_grazings, find_orbit, grazing_curve, shooting
from grazing.orbits.shooting import move_section
from tests.orbits.negative_damping import (
    LOWER,
    UPPER,
    ZETA,
    ClosedForm,
    bystander_multipliers,
    negative_damping,
    negative_damping_with_bystander,
)

CF = ClosedForm()
GUESS = r"give an initial guess \(x0=\)"
DIVERGES = (
    r"cannot guess the orbit by simulating from rest with the stops ignored: the state became non-finite"
)


def sorted_mu(mu) -> np.ndarray:
    return np.sort_complex(np.asarray(mu, dtype=complex))


def test_the_free_orbit_is_unstable_and_newton_finds_it_from_a_guess():
    orbit = find_orbit(negative_damping(w=0.7), [0.0, 0.0], period=1, virtual=True)
    np.testing.assert_allclose(orbit.state, CF.state(0.7), rtol=0, atol=1e-12)
    np.testing.assert_allclose(sorted_mu(orbit.multipliers), sorted_mu(CF.multipliers(0.7)), rtol=1e-10)
    assert not orbit.stable and orbit.abs_lambda == pytest.approx(math.exp(-ZETA * 2 * math.pi / 0.7))


def test_a_physical_search_finds_the_unstable_orbit_where_it_touches_no_stop():
    """From a guess whose flow hits a stop, Newton's method on the physical map fails; on the flow
    through the stops it converges, and an orbit clear of every stop is a physical orbit.  At w = 0.9
    the free orbit (amplitude 2.46) passes through the ceiling (2): no such orbit, and the error stays."""
    for w in (0.5, 0.7):
        orbit = find_orbit(negative_damping(w=w), [0.0, 0.0], period=1)
        assert not orbit.virtual and orbit.impacts == 0 and not orbit.stable
        np.testing.assert_allclose(orbit.state, CF.state(w), rtol=0, atol=1e-12)
        assert min(orbit.guard_mins) == pytest.approx(UPPER - CF.amplitude(w), abs=1e-9)
    assert CF.amplitude(0.9) > UPPER
    with pytest.raises(grazing.ConvergenceError, match=r"try another initial guess or another period$"):
        find_orbit(negative_damping(w=0.9), [0.0, 0.0], period=1)


@pytest.mark.parametrize(
    "call",
    [
        lambda m: find_orbit(m, virtual=True),
        lambda m: find_grazings(m, "w", 0.5, 1.5),
        lambda m: find_grazing_point(m, "w", 0.5, 1.5),
        lambda m: grazing_curve(m, ("w", "upper"), UPPER, search=(0.5, 1.5)),
        lambda m: continue_orbit(m, "w", 0.5, 1.5, virtual=True),
    ],
    ids=["find_orbit", "find_grazings", "find_grazing_point", "grazing_curve", "continue_orbit"],
)
def test_without_a_guess_the_error_says_what_happened_and_to_give_one(call):
    with pytest.raises(grazing.SimulationError, match=f"{DIVERGES}.*{GUESS}"):
        call(negative_damping())


@pytest.mark.parametrize(("stop", "level"), [("ceiling", UPPER), ("floor", LOWER)])
def test_grazings_of_the_unstable_orbit_agree_with_the_closed_form(stop, level):
    floor = stop == "floor"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", GrazingWarning)
        points, branch = find_grazings(negative_damping(), "w", 0.5, 1.5, x0=[0.0, 0.0], stop_name=stop)
    expected = CF.grazing_frequencies(level)
    assert len(expected) == 2
    assert [p.model.params["w"] for p in points] == pytest.approx(expected, rel=1e-10)
    for p in points:
        w = p.model.params["w"]
        assert p.stop_name == stop and not np.isnan(p.accel)
        np.testing.assert_allclose(p.contact, [-level if floor else level, 0.0], rtol=0, atol=1e-10)
        assert p.phase == pytest.approx(CF.contact_time(w, floor=floor), abs=1e-9)
        np.testing.assert_allclose(sorted_mu(p.multipliers), sorted_mu(CF.multipliers(w)), rtol=1e-9)
        assert p.abs_lambda > 1
        # L_f^2 h at the contact: -q'' = q - cos(w t) = A - A (1 - w^2) = A w^2 at the top (and the floor)
        assert p.accel == pytest.approx(level * w * w, rel=1e-9)
    # The floor is grazed with amplitude 2.5 > 2: those orbits pass through the ceiling, and say so.
    assert [p.crossed for p in points] == [("ceiling",) if floor else ()] * 2
    assert len(caught) == (2 if floor else 0)
    assert not any(o.stable for o in branch.orbits)
    # The branch reports the grazings of both stops, in the order met.
    graze = [(s.stop, s.param) for s in branch.special if s.kind == "grazing"]
    ceiling, bottom = CF.grazing_frequencies(UPPER), CF.grazing_frequencies(LOWER)
    assert [j for j, _ in graze] == [0, 1, 1, 0]
    assert [v for _, v in graze] == pytest.approx([ceiling[0], *bottom, ceiling[1]], rel=1e-10)


def test_the_grazing_curve_of_the_unstable_orbit_is_its_resonance_curve():
    curve = grazing_curve(negative_damping(), ("w", "upper"), UPPER, search=(0.5, 1.5), x0=[0.0, 0.0])
    assert len(curve.points) > 20
    w, upper = curve.values("w"), curve.values("upper")
    np.testing.assert_allclose(upper, [CF.amplitude(v) for v in w], rtol=1e-12)
    assert curve.fold is not None
    fold_w, fold_a = CF.fold()
    assert curve.fold.model.params["w"] == pytest.approx(fold_w, rel=1e-8)
    assert curve.fold.model.params["upper"] == pytest.approx(fold_a, rel=1e-12)
    assert curve.status == "reached the bound upper = 2 m"  # in its unit, as every message prints it


def test_the_normal_form_at_the_unstable_grazing():
    point = find_grazing_point(negative_damping(), "w", 0.5, 1.5, "second", x0=[0.0, 0.0])
    w = CF.grazing_frequencies(UPPER)[1]
    assert point.model.params["w"] == pytest.approx(w, rel=1e-10)
    nf = normal_form_at(point, ("w",))
    assert nf.accel == pytest.approx(UPPER * w * w, rel=1e-9)
    np.testing.assert_allclose(
        sorted_mu(np.linalg.eigvals(nf.monodromy)), sorted_mu(CF.multipliers(w)), rtol=1e-9
    )


def test_the_pendulums_unstable_nonimpacting_orbit_grazes_at_its_largest_angle():
    """With α = 0.6 the pendulum's resonance curve folds over in η: at η = 0.4148 a saddle orbit lies
    between two stable ones.  θ̂ does not enter the flow, so the nonimpacting orbit found from a guess
    grazes the stop placed at its own largest angle; the default guess finds a stable orbit instead."""
    m = pendulum("B", alpha=0.6, eta=0.4148, theta_hat=math.radians(170))
    unstable = find_orbit(m, [-1.39, 0.73], period=1, virtual=True)  # a guess near the saddle
    stable = find_orbit(m, period=1, virtual=True)
    assert not unstable.stable and stable.stable and unstable.impacts == 0
    lo, hi = math.radians(60), math.radians(120)
    (from_guess,), _ = find_grazings(m, "theta_hat", lo, hi, x0=unstable.state)
    (default,), _ = find_grazings(m, "theta_hat", lo, hi)
    assert from_guess.model.params["theta_hat"] == pytest.approx(max_angle(unstable), abs=1e-10)
    assert default.model.params["theta_hat"] == pytest.approx(max_angle(stable), abs=1e-10)
    assert abs(from_guess.model.params["theta_hat"] - default.model.params["theta_hat"]) > 0.3
    np.testing.assert_allclose(sorted_mu(from_guess.multipliers), sorted_mu(unstable.multipliers), atol=1e-8)


# --------------------------------------------------------------------------
# The default guess sticks, or starts beyond a stop


@pytest.mark.parametrize(
    ("model", "how"),
    [
        (
            pendulum("B", r=0.0, theta_hat=math.radians(10)),
            r"sticks to the stop 128 times in 128 forcing periods",
        ),
        (bouncing_ball(), r"ends riding on the stop"),  # the table's acceleration never exceeds gravity
        (
            two_sided_oscillator(r=0.0, amp=3.0),
            r"sticks to (?=.*stop 'right' 12\d times)(?=.*stop 'left' 12\d times).* in 128 forcing periods",
        ),
    ],
    ids=["pendulum", "bouncing-ball", "two-sided-oscillator"],
)
def test_a_default_guess_that_sticks_says_so_and_to_give_one(model, how):
    with pytest.raises(grazing.ConvergenceError) as err:
        find_orbit(model)
    msg = str(err.value)
    assert msg.startswith("the default initial guess sticks: simulated from rest for 500 forcing periods")
    assert re.search(how, msg) and re.search(f"{GUESS} near an orbit that does not stick", msg), msg


@pytest.mark.parametrize(
    "model",
    [pendulum("B", theta_hat=math.radians(-10)), impact_oscillator(sigma=-0.1)],
    ids=["pendulum", "io"],
)
def test_a_default_guess_from_rest_beyond_the_stop_says_to_give_one(model):
    with pytest.raises(
        grazing.InvalidStateError,
        match=rf"simulating from rest: initial state \[0.0, 0.0\] is beyond the stop.*{GUESS}",
    ):
        find_orbit(model)


# --------------------------------------------------------------------------
# switch and virtual


def test_switch_is_refused_on_a_virtual_branch():
    for model, param, a, b in [(pendulum("B"), "eta", 0.40, 0.47), (impact_oscillator(), "omega", 4.0, 3.0)]:
        with pytest.raises(grazing.InvalidParameterError, match="switch has no effect on a virtual branch"):
            continue_orbit(model, param, a, b, virtual=True, switch=True)
        virtual = find_orbit(model.with_params(**{param: a}), period=1, virtual=True)
        with pytest.raises(grazing.InvalidParameterError, match="switch has no effect on a virtual branch"):
            continue_orbit(model, param, a, b, orbit=virtual, switch=True)


@pytest.mark.parametrize(
    ("model", "param", "a", "b"),
    [(pendulum("B"), "eta", 0.40, 0.47), (impact_oscillator(sigma=0.1), "omega", 4.0, 3.0)],
    ids=["pendulum", "impact-oscillator"],
)
def test_switch_follows_a_nonimpacting_orbit_physically_to_its_grazing(model, param, a, b):
    """Without ``virtual`` a nonimpacting start is followed with the stops ignored, through its
    grazings; with ``switch`` it is followed physically, so that the branch ends (or switches) at
    the grazing: the same grazing as the virtual branch locates."""
    ignored = continue_orbit(model, param, a, b)
    physical = continue_orbit(model, param, a, b, switch=True)
    assert ignored.virtual and not physical.virtual
    first = next(s for s in ignored.special if s.kind == "grazing")
    end = next(s for s in physical.special if s.kind == "grazing")
    assert end.param == pytest.approx(first.param, abs=1e-9)
    assert "switch" in physical.status and "followed with switch (switch=True)" not in physical.status


def test_moving_the_section_starts_newton_on_the_orbit():
    """move_section follows the orbit to the new section: Newton's method starts there on the orbit
    (its first residual is the integration's), at the closed form's state."""
    orbit = find_orbit(negative_damping(w=0.7), [0.0, 0.0], period=1)
    T = orbit.model.period
    for t_new in (0.3 * T, 0.77 * T):
        moved = move_section(orbit, t_new)
        assert moved.t0 == t_new and moved.residuals[0] < 1e-9
        np.testing.assert_allclose(moved.state, CF.state(0.7, t_new), rtol=0, atol=1e-11)
        np.testing.assert_allclose(sorted_mu(moved.multipliers), sorted_mu(orbit.multipliers), rtol=1e-9)


def test_an_orbit_clear_of_the_stops_whose_physical_map_does_not_close_is_refused(monkeypatch):
    """The orbit found on the flow through the stops is a physical orbit only if the physical map
    closes on it to the tolerance: one whose physical image is off by 1e-6 is not returned."""
    model = negative_damping(w=0.7)
    orbit = find_orbit(model, [0.0, 0.0], period=1)  # (the check passes on the true map)
    assert not orbit.virtual and orbit.residual <= NEWTON_TOL
    true_map = shooting.flow_map

    def off(*args, **kwargs):  # (the physical map only: the flow through the stops stays true)
        fm = true_map(*args, **kwargs)
        return fm if kwargs.get("virtual") else replace(fm, image=fm.image + 1e-6)

    monkeypatch.setattr(shooting, "flow_map", off)
    newton = shooting._Newton(model, 0.0, 1, 0, NEWTON_TOL, 20)
    assert newton.nonimpacting(np.array([0.0, 0.0])) is None


def test_a_grazing_curve_with_two_more_states_first_is_the_resonance_curve():
    """The same grazing curve and fold with a 4-state model whose impacting coordinate is the second state
    (a bystander oscillator first): every index into the states and the tangent must be the model's."""
    model = negative_damping_with_bystander()
    orbit = find_orbit(model.with_params(w=0.7), np.zeros(4), period=1)
    np.testing.assert_allclose(orbit.state[[1, 3]], CF.state(0.7), rtol=0, atol=1e-11)
    expected = np.concatenate([CF.multipliers(0.7), bystander_multipliers(0.7)])
    np.testing.assert_allclose(sorted_mu(orbit.multipliers), sorted_mu(expected), rtol=1e-9)
    fold_w, fold_a = CF.fold()
    # From the grazing below the resonance (w grows along the curve) and from the one above it (w falls)
    for search, direction in (((0.5, 1.0), 1.0), ((0.9, 1.5), -1.0)):  # (search: also the bounds on w)
        curve = grazing_curve(model, ("w", "upper"), UPPER, search=search, x0=np.zeros(4))
        assert len(curve.points) > 20
        w, upper = curve.values("w"), curve.values("upper")
        assert np.sign(w[1] - w[0]) == direction
        np.testing.assert_allclose(upper, [CF.amplitude(v) for v in w], rtol=1e-11)
        assert curve.fold is not None
        assert curve.fold.model.params["w"] == pytest.approx(fold_w, rel=1e-8)
        assert curve.fold.model.params["upper"] == pytest.approx(fold_a, rel=1e-12)
        # (the fold lies between the point before it and the next, in the order the curve was followed)
        i = curve.fold_index
        assert min(upper[i], upper[i + 1]) <= fold_a and max(w[i], w[i + 1]) >= fold_w >= min(w[i], w[i + 1])
