"""The grazing of a switching surface located, and curves in two parameters, through modes.

The soft-impact oscillator with its test-only contact damper (tests/engine/test_mode_switches.py) is
piecewise linear.  Where its orbit just touches the contact it is the free linear response
``x = Re(X e^{i w t})``, ``X = a / (1 - w^2 + 2 i zeta w)``, whose amplitude equals the gap: the grazing
frequency at a given ``a`` and the grazing curve ``a = gap |1 - w^2 + 2 i zeta w|`` in ``(omega, a)``
are closed forms, the contact is ``(gap, 0)`` at ``w t = -arg X`` and the monodromy there is
``exp(A_free T)``.  A grazing with other switches (the orbit with one contact per period touching the
surface a second time) is checked against the exact period map (tests/piecewise_exact.py), and a
period-doubling curve against the exact period-doublings (multiplier -1 of the exact monodromy, by
fsolve) at a fixed ``a``.  Nothing in the references uses grazing's engine.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import fsolve

from grazing.errors import ConvergenceError
from grazing.normalform.discontinuity import find_grazing_point
from grazing.normalform.switching import switching_map_at
from grazing.orbits import continue_orbit, find_orbit, follow_curve
from grazing.orbits.grazing import find_grazings, grazing_curve
from grazing.orbits.shooting import move_section
from tests.engine.test_mode_switches import soft_impact
from tests.orbits.test_orbits_through_modes import exact_fold, grazing_frequency, reference


def free_matrix(p: dict) -> np.ndarray:
    return np.array([[0.0, 1.0], [-1.0, -2 * p["zeta"]]])


def free_response(p: dict, w: float, t: float) -> np.ndarray:
    X = p["a"] / (1 - w * w + 2j * p["zeta"] * w)
    return np.array([(X * np.exp(1j * w * t)).real, (1j * w * X * np.exp(1j * w * t)).real])


def test_the_grazing_of_the_switching_surface_is_located_at_the_closed_form():
    """Up in frequency the orbit loses its contact: the branch's grazing is located (not only bracketed)
    at the closed-form frequency, with the contact, its time and the monodromy of the free response."""
    m = soft_impact()
    p = dict(m.params)
    w = grazing_frequency(p, 1.3, 3.0)
    br = continue_orbit(m, "omega", 1.2, 2.0)
    [sp] = br.special
    g = sp.grazing
    assert sp.kind == "grazing" and g is not None and g.stop_name == "touch" and g.mode == "free"
    assert abs(sp.param - w) < 1e-10 and abs(g.model.params["omega"] - w) < 1e-10, sp.param - w
    assert "of transition 'touch'" in br.status and "bracketed only" not in br.status
    assert g.precision < 1e-10 and abs(sp.precision) < 1e-10
    assert np.abs(g.contact - [p["gap"], 0.0]).max() < 1e-10, g.contact
    assert np.abs(g.contact - free_response(p, w, g.t_graze)).max() < 1e-10
    assert g.switches == 0 and g.impacts == 0
    assert abs(g.accel - w * w * p["gap"]) < 1e-10  # (L_f^2 h = -x'' = w^2 x on the free response)
    J = expm(free_matrix(p) * 2 * math.pi / w)
    assert np.abs(g.monodromy - J).max() < 1e-9, g.monodromy - J


def test_a_grazing_with_another_contact_against_the_exact_period_map():
    """Down in frequency at a = 2 the orbit with one contact per period touches the surface a second
    time: the grazing orbit located there is a fixed point of the exact period map from its contact,
    which lies on the guard with zero normal velocity, and its other contact is the exact one."""
    m = soft_impact(a=2.0)
    br = continue_orbit(m, "omega", 1.2, 0.6)
    [sp] = br.special
    g = sp.grazing
    assert sp.kind == "grazing" and g is not None and g.stop_name == "touch" and g.mode == "free"
    assert "gains a switch ('touch'" in br.status and "bracketed only" not in br.status
    lo, hi = sp.interval
    assert lo - 1e-12 <= sp.param <= hi + 1e-12
    p = dict(g.model.params)
    ref = reference(p)
    assert abs(g.contact[0] - p["gap"]) < 1e-12 and abs(g.contact[1]) < 1e-12
    # the exact map from the contact over one period, less a sliver at its end (where the orbit touches
    # the guard again, tangentially), then the free flow over the sliver
    t1 = g.t_graze + ref.period
    x, k, J, switches = ref.run(g.contact, 0, g.t_graze, t1 - 1e-3)
    assert k == 0 and len(switches) == 2 == g.switches
    x = ref.flow(0, x, t1 - 1e-3, t1)
    assert np.abs(x - g.contact).max() < 1e-10, x - g.contact
    J = expm(free_matrix(p) * 1e-3) @ J
    assert np.abs(g.monodromy - J).max() < 1e-8 * max(1.0, np.abs(J).max()), g.monodromy - J


def test_the_grazing_curve_of_the_switching_surface_is_the_closed_form():
    m = soft_impact()
    p = dict(m.params)
    curve = follow_curve(m, "grazing", "omega", 1.2, 2.0, "a", (0.8, 1.3))
    w, a = curve.values("omega"), curve.values("a")
    assert len(curve.points) > 10 and a.min() == pytest.approx(0.8) and a.max() == pytest.approx(1.3)
    assert np.abs(a - p["gap"] * np.abs(1 - w * w + 2j * p["zeta"] * w)).max() < 1e-10
    for pt in curve.points:
        g = pt.grazing
        assert g.mode == "free" and g.stop_name == "touch" and g.accel > 0
        assert np.abs(g.contact - [p["gap"], 0.0]).max() < 1e-10
        assert (
            np.abs(g.contact - free_response(dict(g.model.params), g.model.params["omega"], g.t_graze)).max()
            < 1e-10
        )


@pytest.mark.parametrize("section", ["free", "contact"])
def test_a_period_doubling_curve_against_the_exact_period_doublings(section):
    """The stiff soft-impact oscillator's period-doubling in (omega, a), with the section where the orbit
    is in either mode: at a few points of the curve, the exact period-doubling at that ``a`` (the exact
    period-1 orbit with a multiplier -1, by fsolve)."""
    m = soft_impact(k=50.0, zeta=0.02)
    orbit = find_orbit(m)
    if orbit.mode != section:  # (the section in the middle of the orbit's stay in the other mode)
        t1, t2 = orbit.switch_times[:2]
        orbit = move_section(orbit, (0.5 * (t1 + t2)) % m.period)
    assert orbit.mode == section
    curve = follow_curve(m, "period-doubling", "omega", 1.2, 1.0, "a", (0.9, 1.1), orbit=orbit)
    assert (
        curve.status
        == "at the first point: reached the bound a = 0.9; at the last point: reached the bound a = 1.1"
    )
    assert len(curve.points) > 6 and all(pt.orbit.mode == section for pt in curve.points)
    for pt in curve.points[:: max(1, len(curve.points) // 4)]:
        o = pt.orbit
        k = m.mode_names.index(o.mode)
        q = dict(o.model.params)

        def equations(u, q=q, o=o, k=k):
            ref = reference({**q, "omega": u[2]})
            x_end, k_end, J, _ = ref.run(u[:2], k, o.t0, o.t0 + ref.period)
            assert k_end == k
            return np.append(x_end - u[:2], np.linalg.det(J + np.eye(2)))

        u, _, ok, msg = fsolve(equations, np.append(o.state, q["omega"]), xtol=1e-14, full_output=True)
        assert ok in (1, 3) and np.abs(equations(u)).max() < 1e-11, msg  # (3: xtol below rounding)
        assert abs(q["omega"] - u[2]) < 1e-9, (q["omega"], u[2])
        assert np.abs(o.state - u[:2]).max() < 1e-9
        assert np.min(np.abs(o.multipliers + 1.0)) < 1e-8, o.multipliers


def test_the_grazing_analysis_and_the_grazing_curve_through_modes():
    """find_grazing_point and grazing_curve on the soft-impact oscillator: the branch followed through
    its switches of mode (switched across the grazing), the grazing at the closed-form frequency, and the
    grazing curve in (omega, a) the closed form."""
    m = soft_impact()
    p = dict(m.params)
    w = grazing_frequency(p, 1.3, 3.0)
    g = find_grazing_point(m, "omega", 1.2, 2.0, stop_name="touch")
    assert abs(g.model.params["omega"] - w) < 1e-10 and g.mode == "free" and g.stop_name == "touch"
    points, branch = find_grazings(m, "omega", 1.2, 2.0)
    assert [q.model.params["omega"] for q in points] == [g.model.params["omega"]]
    assert branch.values[-1] == pytest.approx(2.0) and branch.orbits[-1].switch_signature == ((),)
    with pytest.raises(ConvergenceError, match="no second grazing"):
        find_grazing_point(m, "omega", 1.2, 2.0, "second")
    curve = grazing_curve(m, ("omega", "a"), 1.0, search=(1.2, 2.0))
    wc, a = curve.values("omega"), curve.values("a")
    assert len(curve.points) > 5 and a.min() == pytest.approx(1.0) and curve.fold is None
    assert np.abs(a - p["gap"] * np.abs(1 - wc * wc + 2j * p["zeta"] * wc)).max() < 1e-10


def test_a_fold_curve_after_a_gained_switch_against_the_exact_folds():
    """At a = 2 the orbit with two contacts per period (past the grazing where it gains the second) folds;
    its fold curve in (omega, a), at a few points, is the exact fold at that ``a``."""
    m = soft_impact(a=2.0)
    br = continue_orbit(m, "omega", 1.2, 0.6, switch=True)
    start = next(o for o, s in zip(br.orbits, br.segments) if s == 1)
    assert len(sum(start.switch_signature, ())) == 4
    curve = follow_curve(m, "fold", "omega", start.model.params["omega"], 0.6, "a", (1.8, 2.2), orbit=start)
    assert len(curve.points) > 6 and curve.values("a").min() == pytest.approx(1.8)
    for pt in curve.points[:: max(1, len(curve.points) // 4)]:
        o = pt.orbit
        q = dict(o.model.params)
        x, w = exact_fold(q, o.state, q["omega"], m.mode_names.index(o.mode), o.t0)
        assert abs(q["omega"] - w) < 1e-9, (q["omega"], w)
        assert np.abs(o.state - x).max() < 1e-9, o.state - x
        assert np.min(np.abs(o.multipliers - 1.0)) < 1e-8, o.multipliers


def test_the_located_grazing_feeds_the_discontinuity_map_of_the_switch():
    """Without the contact damper the field is continuous across the surface: the grazing located by
    find_grazing_point is a contact the switch's discontinuity map accepts, with ``a = w^2 gap`` and the
    jump of the field per unit guard ``(0, k)``."""
    m = soft_impact(c=0.0)
    p = dict(m.params)
    w = grazing_frequency(p, 1.3, 3.0)
    g = find_grazing_point(m, "omega", 1.2, 2.0, stop_name="touch")
    assert abs(g.model.params["omega"] - w) < 1e-10
    zdm = switching_map_at(g.model, g.stop, g.contact, g.t_graze)
    assert zdm.transition_name == "touch" and abs(zdm.accel - w * w * p["gap"]) < 1e-10
    assert np.abs(zdm.jump - [0.0, p["k"]]).max() < 1e-12
