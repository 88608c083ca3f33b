"""Periodic orbits through sliding and the sliding bifurcations: the friction oscillator against its exact
stick-slip orbits.

The reference is tests/engine/test_sliding.py's closed form (slips exact, a stick x = x0 + v_b (t - t0)
until |a cos(w t) - x| reaches mu, by Brent's method), whose period map's fixed point is solved here by
Newton's method with its exact Jacobian (the product of the slips' rotations, the entry saltation and
the stick's [[1, dt], [0, 1]]).  A stick collapses a direction (the entry's saltation projects onto the
belt), so the monodromy matrix has rank one: one multiplier is exactly zero.

The sliding bifurcations are located from their own equations on the closed form, independently of the
engine: a switching-sliding where the slip behind the belt reaches it exactly where the friction just
balances the force, a cos(w t) - x = mu, while that force is falling (the field ahead of the belt is
tangent there and its tangency invisible: past it the slip crosses the belt, slips ahead for a moment and
sticks; before it, it sticks at once); an adding-sliding where the force during the stick touches mu at
its maximum, d/dt (a cos(w t) - x) = -a w sin(w t) - v_b = 0 (the slip ahead that followed the stick
shrinks to nothing).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import fsolve

from grazing.errors import InvalidParameterError
from grazing.models import friction_oscillator
from grazing.orbits import continue_orbit, find_orbit
from grazing.orbits.kinds import SpecialKind
from grazing.orbits.sliding_bifurcations import kind_of_change
from grazing.orbits.sliding_curves import sliding_curve
from tests.engine.test_sliding import AHEAD, BEHIND, FrictionReference

VALUES = {"a": 1.0, "omega": 0.5, "mu": 0.5, "v_belt": 0.2}
BEHIND_IN, AHEAD_IN = "belt_slide_from_slip_behind", "belt_slide_from_slip_ahead"  # (entries into the stick)


def exact_orbit(p: dict, x: np.ndarray, mode: int, t0: float):
    """The exact period-1 orbit near ``x`` (in ``mode`` at ``t0``): ``(x, J, events, residual)``."""
    ref = FrictionReference(p)
    t1 = t0 + 2 * math.pi / p["omega"]
    for _ in range(20):
        x_end, k_end, J, _ = ref.run(x, mode, t0, t1)
        assert k_end == mode
        step = np.linalg.solve(J - np.eye(2), x_end - x)
        x = x - step
        if np.abs(step).max() < 1e-15 * max(1.0, np.abs(x).max()):
            break
    x_end, _, J, events = ref.run(x, mode, t0, t1)
    return x, J, events, float(np.abs(x_end - x).max())


def test_the_stick_slip_orbit_is_the_exact_one():
    m = friction_oscillator(**VALUES)
    o = find_orbit(m)
    assert o.mode in ("slip_ahead", "slip_behind") and o.period == 1
    x, J, events, res = exact_orbit(dict(m.params), o.state, m.mode_names.index(o.mode), o.t0)
    assert res < 1e-13
    assert np.abs(o.state - x).max() < 1e-10, o.state - x
    kinds = [k for _, k in events]
    assert kinds.count("stick") == 2 and kinds.count("slip") == 2  # (a stick on each side, no crossing)
    assert np.abs(o.switch_times - [t for t, _ in events]).max() < 1e-10
    ((*names,),) = o.switch_signature
    assert [n.startswith("belt_slide_from") for n in names] == [k == "stick" for k in kinds]
    assert sorted(names) == sorted(n for n in m.switch_names if "slide" in n or "exit" in n)
    assert np.abs(o.monodromy - J).max() < 1e-9 * max(1.0, np.abs(J).max()), o.monodromy - J
    # rank one: a zero multiplier (the entry saltation's projection), the other the trace
    mults = np.sort(np.abs(o.multipliers))
    assert mults[0] < 1e-12 and abs(abs(np.trace(J)) - mults[1]) < 1e-10
    assert abs(np.linalg.det(J)) < 1e-14


def test_continuation_in_omega_along_stick_slip_orbits():
    """Each orbit of the branch is the exact one (state, monodromy), with the same stick-slip switches."""
    m = friction_oscillator(**VALUES)
    br = continue_orbit(m, "omega", 0.5, 0.45)
    assert br.status.startswith("reached") and len(br) >= 3
    sig = br.orbits[0].switch_signature
    assert all(o.switch_signature == sig for o in br.orbits)
    for o in br.orbits[:: max(1, len(br) // 4)]:
        q = {**VALUES, "omega": o.model.params["omega"]}
        x, J, events, res = exact_orbit(q, o.state, m.mode_names.index(o.mode), o.t0)
        assert res < 1e-13 and np.abs(o.state - x).max() < 1e-10
        assert np.abs(o.monodromy - J).max() < 1e-9 * max(1.0, np.abs(J).max())
        assert np.abs(o.switch_times - [t for t, _ in events]).max() < 1e-10


def _slip(ref: FrictionReference, mode: int, x: float, t: float, tt: float) -> np.ndarray:
    return ref.flow(mode, np.array([x, ref.p["v_belt"]]), t, tt)


def exact_switching_sliding_residual(p: dict, u: np.ndarray) -> list[float]:
    """The equations of :func:`exact_switching_sliding` at ``u = (x_e, t_e, t_1, t_2, t_3)`` with the
    parameters ``p``."""
    T, vb, mu = 2 * math.pi / p["omega"], p["v_belt"], p["mu"]
    xe, te, t1, t2, t3 = u
    ref = FrictionReference(p)
    x1 = xe + vb * (t1 - te)
    x2, v2 = _slip(ref, AHEAD, x1, t1, t2)
    x3 = x2 + vb * (t3 - t2)
    xT, vT = _slip(ref, BEHIND, x3, t3, te + T)
    return [ref.force(xe, te) - mu, ref.force(x1, t1) - mu, v2 - vb, ref.force(x3, t3) + mu, vT - vb, xT - xe]


def exact_switching_sliding(p: dict, guess: np.ndarray) -> np.ndarray:
    """``(x_e, t_e, t_1, t_2, t_3, mu)``: behind the belt the slip reaches it at ``(x_e, t_e)`` where the
    force is exactly mu (the field ahead of the belt is tangent to it there), sticks until the force is mu
    again at ``t_1``, slips ahead back to the belt at ``t_2``, sticks until the force is -mu at ``t_3``
    and slips behind back to the belt at ``t_e + T``."""

    def equations(u):
        return exact_switching_sliding_residual({**p, "mu": u[-1]}, u[:-1])

    u, _, ier, msg = fsolve(equations, guess, xtol=1e-14, full_output=True)
    assert ier in (1, 3) and np.abs(equations(u)).max() < 1e-13, (msg, equations(u))  # (3: xtol too small)
    return u


def exact_adding_sliding(p: dict, guess: np.ndarray) -> np.ndarray:
    """``(x_e, t_e, t_x, mu)``: the slip behind the belt reaches it at ``(x_e, t_e)``, the stick's force
    reaches mu at its maximum (-a w sin(w t) = v_b) and -mu at ``t_x``, and the slip behind returns to
    the belt at ``t_e + T``."""
    T, w, a, vb = 2 * math.pi / p["omega"], p["omega"], p["a"], p["v_belt"]

    def equations(u):
        xe, te, tx, mu = u
        ref = FrictionReference({**p, "mu": mu})
        k = round((w * te - math.asin(-vb / (a * w))) / (2 * math.pi))  # the maximum just after the entry
        ts = (math.asin(-vb / (a * w)) + 2 * math.pi * k) / w
        while ts < te:
            ts += T
        xs, xx = xe + vb * (ts - te), xe + vb * (tx - te)
        xT, vT = _slip(ref, BEHIND, xx, tx, te + T)
        return [ref.force(xs, ts) - mu, ref.force(xx, tx) + mu, vT - vb, xT - xe]

    u, _, ier, msg = fsolve(equations, guess, xtol=1e-14, full_output=True)
    assert ier in (1, 3) and np.abs(equations(u)).max() < 1e-13, (msg, equations(u))  # (3: xtol too small)
    return u


def test_a_switching_sliding_located_at_the_exact_one():
    """Down in mu the slip behind reaches the belt where the force, falling, is just mu: past it the slip
    crosses the belt and sticks after a moment ahead of it (a real switching-sliding; it was named a
    crossing-sliding before)."""
    m = friction_oscillator(**VALUES)
    br = continue_orbit(m, "mu", 0.5, 0.3)
    [sp] = br.special
    assert sp.kind is SpecialKind.SWITCHING_SLIDING and sp.kind == "switching-sliding"
    assert "switching-sliding bifurcation" in br.status and "located" in br.status and "\n" not in br.status
    assert br.status.endswith("can be followed with switch (switch=True)")  # (the command line: --switch)
    assert f"(located to +-{sp.precision:.1g} by bisection on the switches)" in br.status  # (a width)
    assert m.switch_names[sp.stop] == "belt_to_slip_ahead"
    o = sp.orbit
    assert o.switch_signature == (
        (BEHIND_IN, "belt_exit_to_slip_ahead", AHEAD_IN, "belt_exit_to_slip_behind"),
    )
    te, t1, t2, t3 = o.switch_times
    ref = FrictionReference(dict(o.model.params))
    xe = ref.run(o.state, m.mode_names.index(o.mode), o.t0, te)[0][0]
    exact = exact_switching_sliding(dict(VALUES), np.array([xe, te, t1, t2, t3, sp.param]))
    lo, hi = sp.interval
    assert hi - lo <= 2.1e-10 and lo <= exact[-1] <= hi, (lo, exact[-1], hi)
    assert abs(sp.param - exact[-1]) < 1e-10 and sp.precision <= 1.1e-10
    # the name, from the closed form: the force is falling at the entry (the tangency ahead is invisible)
    # and the stick that starts there lasts (it is not a short one, as at a crossing-sliding)
    w, a, vb = VALUES["omega"], VALUES["a"], VALUES["v_belt"]
    assert -a * w * math.sin(w * exact[1]) - vb < -0.1 and exact[2] - exact[1] > 1.0


def test_an_adding_sliding_located_at_the_exact_one():
    """Up in mu the slip ahead between the two sticks shrinks to nothing: one stick remains."""
    m = friction_oscillator(**VALUES)
    br = continue_orbit(m, "mu", 0.5, 1.2)
    [sp] = br.special
    assert sp.kind is SpecialKind.ADDING_SLIDING and "ended at an adding-sliding bifurcation" in br.status
    o = sp.orbit
    names = o.switch_signature[0]
    [te] = [t for t, n in zip(o.switch_times, names) if n == "belt_slide_from_slip_behind"]
    [tx] = [t for t, n in zip(o.switch_times, names) if n == "belt_exit_to_slip_behind"]
    ref = FrictionReference(dict(o.model.params))
    xe = ref.run(o.state, m.mode_names.index(o.mode), o.t0, te)[0][0]
    exact = exact_adding_sliding(dict(VALUES), np.array([xe, te, tx, sp.param]))
    lo, hi = sp.interval
    assert hi - lo <= 2.1e-10 and lo <= exact[-1] <= hi, (lo, exact[-1], hi)
    assert abs(sp.param - exact[-1]) < 1e-10 and sp.precision <= 1.1e-10


TO_A, TO_B = "belt_to_slip_ahead", "belt_to_slip_behind"  # (crossings of the belt)
OUT = ("belt_exit_to_slip_ahead", "belt_exit_to_slip_behind")  # (exits from the stick)


@pytest.mark.parametrize(
    ("before", "after", "kind"),
    [
        # a crossing from behind the belt to ahead of it becomes a short stick (one, or both of a symmetric
        # orbit's crossings at once)
        ((TO_A, TO_B), (BEHIND_IN, OUT[0], TO_B), SpecialKind.CROSSING_SLIDING),
        ((TO_A, TO_B), (BEHIND_IN, OUT[0], AHEAD_IN, OUT[1]), SpecialKind.CROSSING_SLIDING),
        # an entry from behind becomes a crossing and a short slip ahead before the entry (or the other way)
        ((BEHIND_IN, OUT[0], AHEAD_IN, OUT[1]), (TO_A, AHEAD_IN, OUT[0], AHEAD_IN, OUT[1]),
         SpecialKind.SWITCHING_SLIDING),
        ((BEHIND_IN, OUT[0], AHEAD_IN, OUT[1]), (BEHIND_IN, OUT[0], TO_B, BEHIND_IN, OUT[1]),
         SpecialKind.SWITCHING_SLIDING),
        # a short stick inside the slip ahead
        ((TO_A, TO_B), (TO_A, AHEAD_IN, OUT[0], TO_B), SpecialKind.GRAZING_SLIDING),
        # a short slip ahead inside the stick entered from behind
        ((BEHIND_IN, OUT[1]), (BEHIND_IN, OUT[0], AHEAD_IN, OUT[1]), SpecialKind.ADDING_SLIDING),
        # an exit that changes side, with or without a crossing; a crossing alone; a short stick and a short
        # excursion at once (ambiguous without the times): none of the four
        ((AHEAD_IN, OUT[0]), (AHEAD_IN, OUT[1], TO_A), None),
        ((AHEAD_IN, OUT[0]), (AHEAD_IN, OUT[1]), None),
        ((AHEAD_IN, OUT[0], TO_B), (AHEAD_IN, OUT[0], TO_B, TO_A), None),
        ((TO_A, TO_B), (TO_A,), None),  # (no sliding)
        ((BEHIND_IN, OUT[0], AHEAD_IN, OUT[1]), (BEHIND_IN, OUT[0], AHEAD_IN, OUT[0], AHEAD_IN, OUT[1]),
         None),
    ],
)  # fmt: skip
def test_the_change_of_switches_names_the_sliding_bifurcation(before, after, kind):
    """The patterns of the module's docstring, both ways (a bifurcation is met from either side)."""
    m = friction_oscillator()
    assert kind_of_change(m, (before,), (after,)) is kind
    assert kind_of_change(m, (after,), (before,)) is kind


@pytest.mark.parametrize(("stick", "slip", "kind"), [(1e-6, 9.0, SpecialKind.GRAZING_SLIDING),
                                                      (9.0, 1e-6, SpecialKind.ADDING_SLIDING)])  # fmt: skip
def test_the_window_that_vanishes_tells_grazing_from_adding_sliding(stick, slip, kind):
    """No switches against one stick (or one slip) a period: a short stick appeared inside a slip
    (grazing-sliding) or a short slip inside a stick (adding-sliding); the names cannot tell, the times
    between the switches do."""
    m = friction_oscillator()
    one = ((BEHIND_IN, OUT[1]),)
    assert kind_of_change(m, ((),), one) is None
    gaps = (np.empty(0), np.array([stick, slip]))
    assert kind_of_change(m, ((),), one, gaps=gaps) is kind
    assert kind_of_change(m, one, ((),), gaps=gaps[::-1]) is kind


def _guess_adding(o, m) -> np.ndarray:
    names = o.switch_signature[0]
    [te] = [t for t, n in zip(o.switch_times, names) if n == BEHIND_IN]
    [tx] = [t for t, n in zip(o.switch_times, names) if n == OUT[1]]
    xe = FrictionReference(dict(o.model.params)).run(o.state, m.mode_names.index(o.mode), o.t0, te)[0][0]
    return np.array([xe, te, tx, o.model.params["mu"]])


def test_the_adding_sliding_curve_in_mu_and_omega_is_the_exact_one():
    m = friction_oscillator(**VALUES)
    br = continue_orbit(m, "mu", 0.5, 1.2)
    curve = sliding_curve(br, "omega", 0.55, steps=4)
    assert curve.kind is SpecialKind.ADDING_SLIDING and curve.status == "reached omega = 0.55"
    assert len(curve) == 5 and [w for _, w in curve.values] == pytest.approx(
        [0.5, 0.5125, 0.525, 0.5375, 0.55]
    )
    for (mu, w), (lo, hi), o in zip(curve.values, curve.intervals, curve.orbits):
        exact = exact_adding_sliding({**VALUES, "omega": w}, _guess_adding(o, m))[-1]
        assert abs(mu - exact) < 1e-10 and hi - lo <= 2.1e-10, (w, mu - exact)
    mus = [mu for mu, _ in curve.values]
    assert mus[-1] - mus[0] > 0.02  # (it moves: not the start repeated)


def test_the_switching_sliding_curve_in_omega_and_mu_is_the_exact_one():
    """Followed from a branch in omega, as mu goes down (the curve is steep the other way round)."""
    m = friction_oscillator(**VALUES)
    br = continue_orbit(m, "omega", 0.5, 0.9)
    [sp] = br.special
    assert sp.kind is SpecialKind.SWITCHING_SLIDING
    curve = sliding_curve(br, "mu", 0.45, steps=2)
    assert curve.kind is SpecialKind.SWITCHING_SLIDING and curve.status == "reached mu = 0.45"
    assert len(curve) >= 3 and curve.values[-1][1] == 0.45
    for (w, mu), o in zip(curve.values, curve.orbits):
        assert o.switch_signature == ((BEHIND_IN, OUT[0], AHEAD_IN, OUT[1]),)
        te, t1, t2, t3 = o.switch_times
        p = {**VALUES, "omega": w, "mu": mu}
        xe = FrictionReference(p).run(o.state, m.mode_names.index(o.mode), o.t0, te)[0][0]

        def equations(u, mu=mu, o=o):
            q = {**VALUES, "mu": mu, "omega": u[-1]}
            return exact_switching_sliding_residual(q, u[:-1])

        u, _, ier, msg = fsolve(equations, np.array([xe, te, t1, t2, t3, w]), xtol=1e-14, full_output=True)
        assert ier in (1, 3) and np.abs(equations(u)).max() < 1e-13, msg
        assert abs(w - u[-1]) < 1e-10, (mu, w - u[-1])


def test_a_sliding_curve_needs_a_sliding_bifurcation():
    m = friction_oscillator(**VALUES)
    br = continue_orbit(m, "omega", 0.5, 0.45)
    with pytest.raises(InvalidParameterError, match="no sliding bifurcation"):
        sliding_curve(br, "mu", 0.4)


def test_switched_past_the_switching_sliding_onto_the_exact_orbits():
    """With ``switch`` the branch goes on with the new switches (the slip crosses the belt, sticks ahead of
    it, slips ahead and sticks again), each orbit the exact one."""
    m = friction_oscillator(**VALUES)
    br = continue_orbit(m, "mu", 0.5, 0.4, switch=True)
    first = br.special[0]
    assert first.kind is SpecialKind.SWITCHING_SLIDING and first.switched
    after = [o for o, s in zip(br.orbits, br.segments) if s == 1]
    assert len(after) >= 3
    assert all(o.switch_signature == ((TO_A, AHEAD_IN, OUT[0], AHEAD_IN, OUT[1]),) for o in after)
    # (the first, 1e-7 past the bifurcation, slips ahead for 1e-6: too short for the reference's sampled
    # search of the return to the belt)
    for o in after[1:][:: max(1, len(after) // 4)]:
        q = {**VALUES, "mu": o.model.params["mu"]}
        x, J, events, res = exact_orbit(q, o.state, m.mode_names.index(o.mode), o.t0)
        assert res < 1e-13 and np.abs(o.state - x).max() < 1e-10 and o.model.params["mu"] < first.param
        assert [k for _, k in events] == ["cross", "stick", "slip", "stick", "slip"]
        assert np.abs(o.monodromy - J).max() < 1e-9 * max(1.0, np.abs(J).max())


def test_where_sticking_begins_with_the_belt_at_rest_is_den_hartogs_boundary():
    """From the public API: the non-stop orbit's crossing-sliding, followed in omega across resonance,
    on Den Hartog's closed form mu / a = omega^2 / (|1 - omega^2| sqrt(1 + omega^2 tan^2(pi / 2 omega)))."""
    from grazing.orbits import SlidingCurve
    from grazing.orbits import sliding_curve as public_sliding_curve
    from grazing.report.den_hartog import boundary

    br = continue_orbit(friction_oscillator(omega=1.2, mu=0.1, v_belt=0.0), "mu", 0.1, 0.9)
    [sp] = br.special
    assert sp.kind is SpecialKind.CROSSING_SLIDING and sorted(sp.orbit.switch_signature[0]) == [TO_A, TO_B]
    curve = public_sliding_curve(br, "omega", 0.9, steps=6)
    assert isinstance(curve, SlidingCurve) and curve.status == "reached omega = 0.9"
    assert curve.params == ("mu", "omega") and curve.kind is SpecialKind.CROSSING_SLIDING
    assert len(curve) >= 7 and min(w for _, w in curve.values) < 1.0 < max(w for _, w in curve.values)
    for (mu, w), (lo, hi) in zip(curve.values, curve.intervals):
        exact = boundary(w) if abs(w - 1.0) > 1e-9 else math.pi / 4
        assert hi - lo <= 2.1e-10 and abs(mu - exact) < 1e-9, (w, mu - exact)


@pytest.mark.parametrize("stop, steps", [(0.6, 28), (2.5, 10)])
def test_the_sliding_curve_goes_on_where_a_switch_reaches_the_section(stop, steps):
    """From omega = 2 down past resonance and up to 2.5 a switch of the orbits comes to the section on
    the way (the period map from it returned in another mode, and the curve ended at omega = 0.875 and
    2.25): both curves reach their end, on Den Hartog's boundary."""
    from grazing.report.den_hartog import boundary

    br = continue_orbit(friction_oscillator(omega=2.0, mu=0.05, v_belt=0.0), "mu", 0.05, 0.95)
    curve = sliding_curve(br, "omega", stop, steps=steps)
    assert curve.status == f"reached omega = {stop:g}" and len(curve) >= steps + 1
    for mu, w in curve.values:
        exact = boundary(w) if abs(w - 1.0) > 1e-9 else math.pi / 4
        assert abs(mu - exact) < 1e-9, (w, mu - exact)
