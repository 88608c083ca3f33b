"""The discontinuity map of grazing a switching surface without a reset, against simulation.

The soft-impact oscillator ``x'' + 2 zeta x' + x = a cos(omega t) - k (x - gap)`` while ``x > gap``
(no reset: a spring engages) is continuous across ``x = gap`` and its derivative jumps there, so a
grazing trajectory is changed by ``-(4/3) sqrt(2 / acc) delta^(3/2) (0, k)`` (docs/normal-form.md,
section 5).  Its free periodic orbit is known in closed form, ``x = Re(X exp(i omega t))`` with
``X = a / (1 - omega^2 + 2 i zeta omega)``: it grazes when ``|X| = gap``.

The check is the one of ``test_map_error_shrinks_like_sqrt_of_penetration`` for impacts: the flow
through the contact minus the free flow, a quarter period after the contact, against the free flow of
the mapped state minus the free flow, over several decades of the penetration ``y``.  Theory (the same
derivation): the difference goes as ``y^(3/2)`` and the map's error as ``y^2`` in general; its ``y^2``
terms come from the offset ``-L_f h / a`` of the closest approach from the section and vanish when
the approach is centred on the section (the grazing orbit's own family), leaving ``y^(5/2)``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

import grazing
from grazing import (
    HybridModel,
    InvalidParameterError,
    InvalidStateError,
    Mode,
    Parameter,
    Surface,
    Transition,
)
from grazing.normalform import find_grazing_point, switching_map_at
from grazing.normalform.switching_check import compare_with_flow, loglog_slope, state_at
from tests.piecewise_exact import LinearMode, PiecewiseLinearModel

x, v, t = sp.symbols("x v t")
zeta, a, w, gap, k = sp.symbols("zeta a omega gap k")
VALUES = {"zeta": 0.05, "a": 0.3, "omega": 1.2, "gap": 0.5, "k": 4.0}
FREE = [v, -2 * zeta * v - x + a * sp.cos(w * t)]
SPRING = -k * (x - gap)
FAR = 100.0
"""A gap the motions here never reach: the model then runs its free flow."""


def soft_impact(contact_extra=0, leave_guard=x - gap, surface=False, name="soft-impact"):
    """The two-mode oscillator; ``contact_extra`` is added to the contact mode's acceleration."""
    modes = [Mode("free", FREE), Mode("contact", [v, FREE[1] + SPRING + contact_extra])]
    if surface:
        kw = {"surfaces": [Surface("wall", gap - x, "free", "contact", sliding=False)]}
    else:
        kw = {"transitions": [Transition("touch", "free", "contact", gap - x),
                              Transition("leave", "contact", "free", leave_guard)]}  # fmt: skip
    params = [Parameter(nm, val) for nm, val in VALUES.items()]
    return HybridModel(name, [x, v], t, params, modes=modes, period=2 * sp.pi / w, **kw)


def amplitude_factor(p):
    """``X / a``: the free periodic orbit per unit forcing."""
    return 1 / (1 - p["omega"] ** 2 + 2j * p["zeta"] * p["omega"])


def free_orbit(p, tt):
    """The free periodic orbit's state at ``tt`` (closed form)."""
    z = p["a"] * amplitude_factor(p) * np.exp(1j * p["omega"] * tt)
    return np.array([z.real, (1j * p["omega"] * z).real])


@pytest.fixture(scope="module")
def grazing_point():
    """The grazing of ``x = gap`` by the free orbit, located by the one-mode analysis with an impact
    stop at ``x = gap`` (the grazing orbit never enters the contact, so it is the free mode's)."""
    params = [Parameter(nm, val) for nm, val in VALUES.items()]
    one_mode = HybridModel("free-oscillator", [x, v], t, params, FREE, gap - x, [x, -v], 2 * sp.pi / w)
    return find_grazing_point(one_mode, "a", 0.1, 0.5)


@pytest.fixture(scope="module")
def zdm(grazing_point):
    model = soft_impact().with_params(a=grazing_point.model.params["a"])
    return switching_map_at(model, "touch", grazing_point.contact, grazing_point.t_graze)


def test_the_grazing_orbit_and_the_map_against_the_closed_form(grazing_point, zdm):
    p = dict(zdm.model.params)
    a_star = p["gap"] / abs(amplitude_factor(p))  # the amplitude equals the gap
    assert p["a"] == pytest.approx(a_star, rel=0, abs=1e-10)
    np.testing.assert_allclose(grazing_point.contact, [p["gap"], 0.0], rtol=0, atol=1e-10)
    np.testing.assert_allclose(free_orbit(p, zdm.t_graze), zdm.contact, rtol=0, atol=1e-10)
    # on the periodic orbit x'' = -omega^2 x, so the guard gap - x accelerates at omega^2 gap
    assert zdm.accel == pytest.approx(p["omega"] ** 2 * p["gap"], rel=1e-9)
    np.testing.assert_allclose(zdm.jump, [0.0, p["k"]], rtol=0, atol=1e-12)  # f+ - f- = k (gap - x) e_v
    assert zdm.transition_name == "touch"


def _one_sample(model, x0, t0, t1):
    """The state at ``t1`` (within a period after ``t0``) of a run from ``x0`` at ``t0``."""
    sol = state_at(model, x0, t0, t1)
    assert sol.t_final == pytest.approx(t1, abs=1e-9)
    return sol


def _compare(zdm, starts):
    """For each ``(model, x0, t0)``: the flow through the contact minus the free flow at
    ``t* + T/4``, and the map's prediction of it (free flow of ``D(x)`` minus free flow of ``x``,
    ``x`` the free flow's state on the section ``t*``): :func:`compare_with_flow`, which also checks
    that every run switches across ``touch`` and back once."""
    check = compare_with_flow(zdm, starts, zdm.model.with_params(gap=FAR))
    assert check.t_end == zdm.t_graze + zdm.model.period / 4
    return check.actual, check.predicted


def _same_constant(ratios, within=1.05):
    """The map's relative error is ``C y^p`` with one ``C`` over the decades (as for impacts), to
    ``within``: a leading coefficient off by a relative ``eps`` adds ``eps`` at every ``y`` and breaks
    this where ``C y^p < eps / (within - 1)``."""
    assert ratios.max() / ratios.min() < within, ratios


def test_the_map_predicts_the_contact_of_the_grazing_orbit_family(zdm):
    """Unfolding by the gap: the free periodic orbit reaches ``y`` past ``gap* - y``; the closest
    approach is on the section (``L_f h = 0`` there), so the map's error is ``O(y^(5/2))``.

    Tolerances: the fits use three decades where the error is >= 2e-12, far above the rounding of
    the differences (~1e-15), so rounding moves the slopes by < 1e-3; the next-order terms (relative
    ``y``) bend them by < 0.01.  The relative error ``C y`` (``C`` ~ 7 here) is 7e-5 at the smallest
    ``y``: a leading coefficient wrong by a relative 4e-6 changes the constant by 5% there.
    """
    p = dict(zdm.model.params)
    ts, T = zdm.t_graze, zdm.model.period
    ys = np.geomspace(1e-5, 1e-2, 7)
    starts = []
    for y in ys:
        model = zdm.model.with_params(gap=p["gap"] - y)
        t0 = ts - T / 4
        starts.append((model, free_orbit(p, t0), t0))
        assert zdm.penetration(free_orbit(p, ts), model=model) == pytest.approx(y, rel=1e-6)
    actual, predicted = _compare(zdm, starts)
    size = np.linalg.norm(actual, axis=1)
    error = np.linalg.norm(actual - predicted, axis=1)
    assert loglog_slope(ys, size) == pytest.approx(1.5, abs=0.01)
    assert loglog_slope(ys, error) == pytest.approx(2.5, abs=0.05)
    _same_constant(error / size / ys)
    assert np.all(actual[:, 1] < 0)  # the spring slows the motion out: the velocity drops


def test_the_map_predicts_contacts_off_the_section(zdm):
    """States on the section ``t*`` at the surface's side, moving towards it: ``h = y``,
    ``L_f h = -sqrt(4 a y)``, so ``delta = 2y - y = y`` (the ``(L_f h)^2 / 2a`` term is half of it) and
    the closest approach comes ``sqrt(4 y / a)`` after the section: the map's error is ``O(y^2)``,
    relative ``C y^(1/2)`` with ``C`` ~ 2.5 (tolerances as above, errors >= 2e-11)."""
    p = dict(zdm.model.params)
    ys = np.geomspace(1e-6, 1e-3, 7)
    starts = []
    for y in ys:
        x0 = np.array([p["gap"] - y, math.sqrt(4 * zdm.accel * y)])
        starts.append((zdm.model, x0, zdm.t_graze))
        assert zdm.penetration(x0) == pytest.approx(y, rel=1e-9)
    actual, predicted = _compare(zdm, starts)
    size = np.linalg.norm(actual, axis=1)
    error = np.linalg.norm(actual - predicted, axis=1)
    assert loglog_slope(ys, size) == pytest.approx(1.5, abs=0.01)
    assert loglog_slope(ys, error) == pytest.approx(2.0, abs=0.05)
    _same_constant(error / size / np.sqrt(ys))


def test_the_simulated_contact_against_the_exact_solution(zdm):
    """The flow through the contact that the map is checked against, by matrix exponentials and
    Brent's method (tests/piecewise_exact.py, nothing of the engine)."""
    p = dict(zdm.model.params)
    A0 = np.array([[0.0, 1.0], [-1.0, -2 * p["zeta"]]])
    A1 = np.array([[0.0, 1.0], [-1.0 - p["k"], -2 * p["zeta"]]])
    b = np.array([0.0, p["a"]])
    y = 1e-4
    g = p["gap"] - y
    free = LinearMode(A0, b, np.zeros(2), ((np.array([-1.0, 0.0]), g, 1),))
    contact = LinearMode(A1, b, np.array([0.0, p["k"] * g]), ((np.array([1.0, 0.0]), -g, 0),))
    ref = PiecewiseLinearModel([free, contact], p["omega"])
    ts, T = zdm.t_graze, zdm.model.period
    x0 = free_orbit(p, ts - T / 4)
    exact, mode, _, switches = ref.run(x0, 0, ts - T / 4, ts + T / 4)
    sol = _one_sample(zdm.model.with_params(gap=g), x0, ts - T / 4, ts + T / 4)
    assert mode == 0 and len(switches) == 2 and len(sol.switches) == 2
    np.testing.assert_allclose(sol.x_final, exact, rtol=0, atol=1e-12)
    np.testing.assert_allclose(sol.switches.t, [s[0] for s in switches], rtol=0, atol=1e-12)


def test_the_map_is_the_identity_short_of_the_surface(zdm):
    p = dict(zdm.model.params)
    for x0 in ([p["gap"] - 1e-4, 0.0], [p["gap"] - 1e-3, -0.01], [p["gap"] - 1e-3, 0.02]):
        assert zdm.penetration(x0) < 0
        np.testing.assert_array_equal(zdm.zdm(x0), x0)


def test_a_surface_gives_the_same_map(grazing_point, zdm):
    model = soft_impact(surface=True, name="soft-impact-surface").with_params(a=zdm.model.params["a"])
    other = switching_map_at(model, "wall_to_contact", grazing_point.contact, grazing_point.t_graze)
    assert other.accel == zdm.accel
    np.testing.assert_array_equal(other.jump, zdm.jump)
    x0 = [zdm.model.params["gap"] + 1e-3, 1e-3]
    np.testing.assert_array_equal(other.zdm(x0), zdm.zdm(x0))


def _refused(error, match, *args):
    with pytest.raises(error, match=match) as info:
        switching_map_at(*args)
    assert "\n" not in str(info.value)


def test_one_line_refusals(grazing_point, zdm):
    contact, ts = grazing_point.contact, grazing_point.t_graze
    a_star = zdm.model.params["a"]
    # a reset: an impact's grazing, the square-root map's
    _refused(InvalidParameterError, r"^stop 'stop' has a reset: grazing it is an impact", grazing_point.model,
             "stop", contact, ts)  # fmt: skip
    c = sp.Symbol("c")
    with_reset = HybridModel(
        "soft-impact-reset", [x, v], t, [Parameter(nm, val) for nm, val in VALUES.items()],
        modes=[Mode("free", FREE), Mode("contact", [v, FREE[1] + SPRING])], period=2 * sp.pi / w,
        transitions=[Transition("touch", "free", "contact", gap - x, reset=[x, -v / 2]),
                     Transition("leave", "contact", "free", x - gap)],
    )  # fmt: skip
    _refused(InvalidParameterError, r"^transition 'touch' has a reset", with_reset, "touch", contact, ts)
    # the field itself jumps (a constant contact force): degree one
    jumps = soft_impact(contact_extra=-0.2, name="soft-impact-force").with_params(a=a_star)
    _refused(InvalidParameterError, r"^the field jumps across transition 'touch' at the contact", jumps,
             "touch", contact, ts)  # fmt: skip
    # a contact damper: the jump -c x' vanishes at the contact but not along the surface
    damped = HybridModel(
        "soft-impact-damper", [x, v], t, [Parameter(nm, val) for nm, val in {**VALUES, "c": 0.3}.items()],
        modes=[Mode("free", FREE), Mode("contact", [v, FREE[1] + SPRING - c * v])], period=2 * sp.pi / w,
        transitions=[Transition("touch", "free", "contact", gap - x),
                     Transition("leave", "contact", "free", x - gap)],
    ).with_params(a=a_star)  # fmt: skip
    _refused(InvalidParameterError, r"does not vanish along the surface near the contact", damped, "touch",
             contact, ts)  # fmt: skip
    # the contact mode is left elsewhere (hysteresis): the map's return is not there
    hysteresis = soft_impact(leave_guard=x - gap - 0.1, name="soft-impact-hysteresis")
    _refused(InvalidParameterError, r"^transition 'touch' has no way back across its surface", hysteresis,
             "touch", contact, ts)  # fmt: skip
    # not a contact; a contact the flow does not turn back from
    _refused(InvalidStateError, r"is not a grazing contact of transition 'touch' \(h = ", zdm.model, "touch",
             contact + np.array([0.0, 0.1]), ts)  # fmt: skip
    strong = zdm.model.with_params(a=1.0)  # at t = 0 the forcing pushes x = gap, x' = 0 on: a = gap - 1 < 0
    _refused(InvalidStateError, r"does not turn back from the surface of transition 'touch' at", strong,
             "touch", [VALUES["gap"], 0.0], 0.0)  # fmt: skip


def test_a_moving_wall_off_the_section():
    """A spring on a wall that moves, ``s(t) = gap + e sin(omega t)``: the guard ``s(t) - x`` depends on
    time (``h_t`` enters the rate, the acceleration and the jump's derivative, ``w`` from ``(D_x, D_t)``).
    At ``t* = 0`` the motion ``x = gap``, ``x' = e omega`` touches the wall with
    ``a = s'' - x'' = gap - a + 2 zeta e omega > 0``; states ``h = y``, ``L_f h = -sqrt(4 a y)`` on the
    section give the 3/2 law with an ``O(y^2)`` error, as on a fixed wall.  Its constant (~4.8) drifts by
    8% over the decades (the next order, relative ``y^(1/2)``), hence 10% here."""
    e = sp.Symbol("e")
    wall = gap + e * sp.sin(w * t)
    params = [Parameter(nm, val) for nm, val in {**VALUES, "e": 0.2}.items()]
    model = HybridModel(
        "soft-impact-moving-wall", [x, v], t, params, period=2 * sp.pi / w,
        modes=[Mode("free", FREE), Mode("contact", [v, FREE[1] - k * (x - wall)])],
        transitions=[Transition("touch", "free", "contact", wall - x),
                     Transition("leave", "contact", "free", x - wall)],
    )  # fmt: skip
    p = dict(model.params)
    speed = p["e"] * p["omega"]
    zdm = switching_map_at(model, "touch", [p["gap"], speed], 0.0)
    assert zdm.accel == pytest.approx(p["gap"] - p["a"] + 2 * p["zeta"] * speed, rel=1e-12)
    np.testing.assert_allclose(zdm.jump, [0.0, p["k"]], rtol=0, atol=1e-12)
    ys = np.geomspace(1e-6, 1e-3, 7)
    starts = []
    for y in ys:
        x0 = np.array([p["gap"] - y, speed + math.sqrt(4 * zdm.accel * y)])
        starts.append((model, x0, 0.0))
        assert zdm.penetration(x0) == pytest.approx(y, rel=1e-9)
    actual, predicted = _compare(zdm, starts)
    size = np.linalg.norm(actual, axis=1)
    error = np.linalg.norm(actual - predicted, axis=1)
    assert loglog_slope(ys, size) == pytest.approx(1.5, abs=0.01)
    assert loglog_slope(ys, error) == pytest.approx(2.0, abs=0.05)
    _same_constant(error / size / np.sqrt(ys), within=1.1)


def test_the_periodic_orbit_past_grazing_from_the_map(grazing_point, zdm):
    """The stroboscopic map on the contact section, free flow then the map, is to leading order
    ``u -> M (u + c(x* + u))`` with ``M`` the grazing orbit's monodromy matrix (from the one-mode
    analysis) and ``c`` the map's correction: its fixed point, carried half a period on by the free
    flow, is the simulated periodic orbit past grazing (``gap* - y``), away from the contact.  The
    orbit moves from the grazing one by ``O(y^(3/2))`` and the prediction's relative error is ``O(y)``
    (the map's, on the grazing orbit's family; ``M``'s linearisation adds ``O(y^(3/2))``).  The shift
    feeds back into the orbit's penetration (``h`` moves by ``grad(h) . u ~ y^(3/2)``): a relative
    ``C y^(1/2)`` with ``C`` ~ 15 here, which bends the fitted slopes by up to ~0.03 over these decades;
    hence 0.05 and 0.1."""
    p = dict(zdm.model.params)
    ts, T = zdm.t_graze, zdm.model.period
    M = grazing_point.monodromy
    half = ts + T / 2
    free_model = zdm.model.with_params(gap=FAR)
    ys = np.geomspace(1e-6, 1e-4, 5)
    moved, errors = [], []
    for y in ys:
        model = zdm.model.with_params(gap=p["gap"] - y)
        settled = grazing.simulate(model, free_orbit(p, ts - T / 4), t0=ts - T / 4, transient=300, periods=2,
                                   phase=2 * math.pi * (half / T % 1), impacts="none")  # fmt: skip
        assert np.abs(settled.samples[-1] - settled.samples[-2]).max() < 1e-14  # a period-one orbit
        u = np.zeros(2)
        for _ in range(400):
            u = M @ (u + zdm.correction(zdm.contact + u, model=model))
        kicked = zdm.contact + u + zdm.correction(zdm.contact + u, model=model)
        predicted = _one_sample(free_model, kicked, ts, half).x_final
        moved.append(np.linalg.norm(settled.x_final - free_orbit(p, half)))
        errors.append(np.linalg.norm(settled.x_final - predicted))
    moved, errors = np.array(moved), np.array(errors)
    assert loglog_slope(ys, moved) == pytest.approx(1.5, abs=0.05)
    assert loglog_slope(ys, errors / moved) == pytest.approx(1.0, abs=0.1)
