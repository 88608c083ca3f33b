"""Multiple shooting cut at switches: models without resets, against exact piecewise-linear orbits.

A model with modes none of whose transitions resets the state (soft stops) has no impact to cut its
orbit at: :mod:`grazing.orbits.segments` cuts it at its switches instead, each segment one mode from
the previous switch's surface to the next switch's guard.  The model here has unusual names
(states ``yaw``/``spin``, time ``s``, modes ``middle``/``port``/``starboard``) and two soft stops
around an inverted (saddle) middle: its period-1 orbit through both stops is strongly unstable (a
multiplier ~2e7 at ``freq = 0.27``).  The reference uses nothing of grazing's engine: the orbit as a
boundary-value problem in its switch times and states with each mode's exact flow (matrix
exponentials, tests/piecewise_exact.py), solved by ``fsolve``, each switch time checked by Brent's
method on its segment, the monodromy the product of the exponentials and the saltation matrices.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from scipy.linalg import expm
from scipy.optimize import fsolve

import grazing
from grazing import HybridModel, Mode, Parameter, Transition
from grazing.errors import ConvergenceError
from grazing.orbits import continue_orbit, find_orbit
from grazing.orbits.segments import layout_of, segmented_equations, segmented_newton
from tests.orbits.test_segments_through_modes import assert_jacobian_is_the_differences
from tests.piecewise_exact import LinearMode, PiecewiseLinearModel

yaw, spin, s = sp.symbols("yaw spin s")
damp, amp, freq, edge, stiff, cc = sp.symbols("damp amp freq edge stiff cc")
VALUES = {"damp": 0.02, "amp": 1.0, "freq": 0.27, "edge": 0.4, "stiff": 0.5, "cc": 0.1}
SWITCHES = ("into_port", "out_port", "into_stbd", "out_stbd")
SEQUENCE = (0, 1, 0, 2)  # (the reference's mode of each segment: middle, port, middle, starboard)
GUARDS = ((-1.0, 1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, -1.0))  # (c, e / edge) of each switch's c x + e
GUESS = {
    0.27: [0.0257174, 0.2920425, 7.034245, 15.981612, 18.669773, 27.617141],
    0.33: [0.0313108, 0.3507688, 5.772384, 13.029646, 15.292362, 22.549623],
}
"""``(yaw, spin, t_1 ... t_4)`` of the orbit on the section ``s = T / 4`` in ``middle``, roughly (a
homotopy from the linear saddle's forced response, ``stiff = cc = damp = 0``): ``fsolve``'s start."""


def two_soft_stops(**values: float) -> HybridModel:
    base = -2 * damp * spin + yaw + amp * sp.cos(freq * s)
    modes = [
        Mode("middle", [spin, base]),
        Mode("port", [spin, base - stiff * (yaw - edge) - cc * spin]),
        Mode("starboard", [spin, base - stiff * (yaw + edge) - cc * spin]),
    ]
    transitions = [
        Transition("into_port", "middle", "port", edge - yaw),
        Transition("out_port", "port", "middle", yaw - edge),
        Transition("into_stbd", "middle", "starboard", yaw + edge),
        Transition("out_stbd", "starboard", "middle", -edge - yaw),
    ]
    params = [Parameter(k, v) for k, v in VALUES.items()]
    model = HybridModel(
        "two-soft-stops",
        [yaw, spin],
        s,
        params,
        modes=modes,
        transitions=transitions,
        period=2 * sp.pi / freq,
    )
    return model.with_params(**values)


def reference(p: dict) -> PiecewiseLinearModel:
    middle = np.array([[0.0, 1.0], [1.0, -2 * p["damp"]]])
    contact = np.array([[0.0, 1.0], [1.0 - p["stiff"], -2 * p["damp"] - p["cc"]]])
    b, e, k = np.array([0.0, p["amp"]]), p["edge"], p["stiff"]
    x1 = np.array([1.0, 0.0])
    return PiecewiseLinearModel(
        [
            LinearMode(middle, b, np.zeros(2), ((-x1, e, 1), (x1, e, 2))),
            LinearMode(contact, b, np.array([0.0, k * e]), ((x1, -e, 0),)),
            LinearMode(contact, b, np.array([0.0, -k * e]), ((-x1, -e, 0),)),
        ],
        p["freq"],
    )


def exact_orbit(
    p: dict, guess, t0: float | None = None, tol: float = 1e-13
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The orbit through the four switches from the section ``t0`` (``T / 4`` by default) in ``middle``:
    ``(x0, times, J)``; ``tol``: the largest residual (a segment's rounding, ``exp(T / 2) eps``: larger
    at lower frequencies), and the switch times' agreement with Brent's method."""
    ref = reference(p)
    T, e = ref.period, p["edge"]
    t0 = T / 4 if t0 is None else t0
    hx = np.array([1.0, 0.0])

    def equations(u):  # u = (x0, t1, s1, ..., t4, s4): one exact flow per segment
        out, x, ta = [], u[:2], t0
        for i, k in enumerate(SEQUENCE):
            tb = u[2 + 3 * i]
            y = ref.flow(k, x, ta, tb)
            c, d = GUARDS[i]
            out += [c * y[0] + d * e, *(u[3 + 3 * i : 5 + 3 * i] - y)]
            x, ta = u[3 + 3 * i : 5 + 3 * i], tb
        return [*out, *(ref.flow(0, x, ta, t0 + T) - u[:2])]

    u, x, ta = list(guess[:2]), np.array(guess[:2]), t0
    for k, tb in zip(SEQUENCE, guess[2:]):
        x = ref.flow(k, x, ta, tb)
        u, ta = [*u, tb, *x], tb
    u, _, _, msg = fsolve(equations, u, xtol=1e-15, full_output=True)
    assert np.abs(equations(u)).max() < tol, msg
    times = u[2::3]
    J, x, ta = np.eye(2), u[:2], t0
    for i, k in enumerate(SEQUENCE):  # each switch time again by Brent's method on its own segment
        tz, _ = ref.first_exit(k, x, ta, ta + 1.2 * (times[i] - ta))
        assert abs(tz - times[i]) < 10 * tol, (i, tz - times[i])
        y, nxt = ref.flow(k, x, ta, times[i]), (*SEQUENCE, 0)[i + 1]
        fm, fp = ref.f(k, y, times[i]), ref.f(nxt, y, times[i])
        J = (np.eye(2) + np.outer(fp - fm, hx) / (hx @ fm)) @ expm(ref.modes[k].A * (times[i] - ta)) @ J
        x, ta = u[3 + 3 * i : 5 + 3 * i], times[i]
    return u[:2], times, expm(ref.modes[0].A * (t0 + T - ta)) @ J


def test_a_strongly_unstable_orbit_between_two_soft_stops_by_multiple_shooting(monkeypatch):
    m = two_soft_stops()
    x, times, J = exact_orbit(dict(m.params), GUESS[0.27])
    t0 = m.period / 4
    assert np.abs(np.linalg.eigvals(J)).max() > 1e7  # (strongly unstable)
    guess = x + np.array([1e-7, -1e-7])
    orbit = segmented_newton(m, guess, t0, 1, tol=1e-11, max_iter=20, mode="middle")
    assert np.abs(orbit.state - x).max() < 1e-10, orbit.state - x
    assert orbit.impacts == 0 and orbit.mode == "middle"
    assert tuple(m.stop_names[j] for j in orbit.switch_transitions) == SWITCHES
    assert np.abs(orbit.switch_times - times).max() < 1e-10, orbit.switch_times - times
    assert np.abs(orbit.monodromy - J).max() < 1e-8 * np.abs(J).max(), orbit.monodromy - J
    # single shooting from that guess does not find it (its residual's rounding, |M| eps |x|, is above
    # the tolerance); find_orbit hands the guess over to multiple shooting, which does
    monkeypatch.setattr("grazing.orbits.shooting._Newton.segments_from_guess", lambda *args: False)
    with pytest.raises(ConvergenceError, match=r"^Newton did not converge to a period-1 orbit: residual"):
        find_orbit(m, guess, period=1, t0=t0, mode="middle")
    monkeypatch.undo()
    found = find_orbit(m, guess, period=1, t0=t0, mode="middle")
    assert np.abs(found.state - x).max() < 1e-10 and found.impacts == 0


def off_the_kinks(orbit, value: float, more: float, shift: float = 0.05) -> np.ndarray:
    """The unknowns of ``orbit``'s switch layout with each switch a little later along its start mode's
    flow and the section state moved: no segment starts or ends on a surface, nor near enough for the
    differences' steps to move a crossing past its end (where the field or its derivative jumps,
    central differences are first order only, or wrong)."""
    m = orbit.model
    layout = layout_of(orbit)
    u = np.append(layout.pack(orbit, value), more)
    for i in range(1, layout.impacts + 1):
        t = u[layout.time_index(i)]
        sol = grazing.simulate(
            m, layout.state(u, i), t0=t, periods=1, phase=2 * math.pi * ((t + shift) / m.period % 1.0),
            events=False, mode=layout.start_mode(m, i),
        )  # fmt: skip
        u[layout.time_index(i)] = t + shift
        u[layout.state_index(i) : layout.state_index(i) + 2] = sol.x_final
    u[:2] += 1e-4
    return u


def test_the_segmented_equations_at_switches_against_differences():
    m = two_soft_stops(freq=0.33)
    orbit = find_orbit(m, GUESS[0.33][:2], period=1, t0=m.period / 4, mode="middle")
    layout = layout_of(orbit)
    assert layout.switches and layout.impacts == 4 and layout.start_mode(m, 2) == "middle"
    # (the guards' parameter ``edge`` and a field's; ``freq``'s third derivative, ~1e5 here, would
    # need smaller steps: the period's parameter is the soft-impact oscillator's ``omega`` below)
    evaluate = segmented_equations(m, ("edge", "stiff"), 1, orbit.t0, layout, 0)
    u = np.append(layout.pack(orbit, m.params["edge"]), m.params["stiff"])
    F, _, same = evaluate(u)
    assert (
        np.abs(F).max() < 1e-9
        and np.abs(same.multipliers - orbit.multipliers).max() < 1e-6 * np.abs(orbit.multipliers).max()
    )
    assert_jacobian_is_the_differences(evaluate, off_the_kinks(orbit, m.params["edge"], m.params["stiff"]))
    # the built-in soft-impact oscillator (one stop, continuous field), by the same equations
    soft = grazing.models.soft_impact_oscillator()
    o = find_orbit(soft, t0=None)
    lay = layout_of(o)
    assert lay.switches and [soft.stop_names[j] for j in lay.stops] == ["leave", "touch"]
    ev = segmented_equations(soft, ("omega", "k"), 1, o.t0, lay, 0)
    assert_jacobian_is_the_differences(ev, off_the_kinks(o, soft.params["omega"], soft.params["k"]))


def test_continuation_hands_over_to_multiple_shooting_at_switches():
    """Down in frequency the multiplier grows past 1e6: single shooting stalls (no grazing ahead) and
    multiple shooting on the switches takes the branch on to its bound, each point the exact orbit.
    (Where single shooting stalls depends on rounding: near freq = 0.3024, or 0.2996 with OpenBLAS's
    SkylakeX kernels; the bound 0.29 lies beyond both.)"""
    m = two_soft_stops(freq=0.33)
    x, _, _ = exact_orbit(dict(m.params), GUESS[0.33])
    orbit = find_orbit(m, x, period=1, t0=m.period / 4, mode="middle")
    branch = continue_orbit(m, "freq", 0.33, 0.29, orbit=orbit)
    assert "by multiple shooting from freq = " in branch.status, branch.status
    assert branch.status.startswith("reached the bound freq = 0.29")
    handover = float(branch.status.split("by multiple shooting from freq = ")[1].split()[0])
    past = [o for o in branch.orbits if o.model.params["freq"] < handover]
    assert len(past) > 3 and past[-1].model.params["freq"] == 0.29
    for o in [*past[:: max(1, len(past) // 4)], past[-1]]:
        q = dict(o.model.params)
        guess = [*o.state, *o.switch_times]
        ux, times, _ = exact_orbit(q, guess, o.t0)
        assert np.abs(o.state - ux).max() < 1e-10, (q["freq"], o.state - ux)
        assert np.abs(o.switch_times - times).max() < 1e-9
    assert np.abs(past[-1].multipliers).max() > 1e6


def test_the_section_moves_along_a_segmented_branch_into_another_mode():
    """Further down in frequency (multipliers ~1e10 to 1e16) a switch approaches the section ``T / 4``
    and the section moves to the middle of the longest stretch between switches, inside ``port``.  The
    state there is one segment's flow from the switch before it: a run over the whole lag, or single
    shooting over a period, leaves the orbit by its rounding times the multiplier (it returned in
    ``starboard``, and the branch ended near ``freq = 0.135``).  On the moved section each point is the
    exact orbit, found from a section in ``middle`` (after ``out_stbd``) by the exact flows."""
    m = two_soft_stops(freq=0.33)
    x, _, _ = exact_orbit(dict(m.params), GUESS[0.33])
    orbit = find_orbit(m, x, period=1, t0=m.period / 4, mode="middle")
    branch = continue_orbit(m, "freq", 0.33, 0.13, orbit=orbit)
    assert branch.status.startswith("reached the bound freq = 0.13"), branch.status
    moved = [o for o in branch.orbits if o.mode == "port"]
    assert len(moved) > 3 and moved[-1].model.params["freq"] == 0.13 and not branch.special
    for o in [moved[0], moved[-1]]:
        q, T = dict(o.model.params), o.model.period
        names = [m.stop_names[j] for j in o.switch_transitions]
        assert names == ["out_port", "into_stbd", "out_stbd", "into_port"]
        ref, ts = reference(q), o.switch_times
        t0 = 0.5 * (ts[2] + ts[3])  # (in middle, between out_stbd and into_port)
        guess = [*ref.flow(0, o.switch_states[2], ts[2], t0), ts[3], ts[0] + T, ts[1] + T, ts[2] + T]
        x0, times, _ = exact_orbit(q, guess, t0, tol=1e-10)  # (exp(T / 2) eps: ~1e-11 here)
        assert np.abs(times - [ts[3], ts[0] + T, ts[1] + T, ts[2] + T]).max() < 1e-9, (q["freq"], times)
        y = ref.flow(1, ref.flow(0, x0, t0, times[0]), times[0], o.t0 + T)  # (in port to the section)
        assert np.abs(o.state - y).max() < 1e-9 * max(1.0, np.abs(y).max()), (q["freq"], o.state - y)
