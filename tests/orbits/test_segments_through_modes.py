"""Multiple shooting through modes: segments that switch and slide, against exact piecewise-linear orbits.

Each segment of :mod:`grazing.orbits.segments` runs from one impact (a transition with a reset) to the
next without events, so that it follows the switches of vector field and the sliding in between; its
Jacobian carries their saltation matrices.  The references use nothing of grazing's engine:

* the soft-impact oscillator with a rigid wall inside its contact (tests/engine/test_events_off_modes.py:
  a switch into the contact, a reset at the wall, a switch out): its period-1 orbit solved exactly as a
  boundary-value problem in its event times (matrix exponentials, ``fsolve``), its monodromy the
  product of the exponentials and the saltation matrices.  Near the wall's grazing the orbit is
  strongly unstable (a multiplier ~5e5, an impact speed ~3e-6): single shooting from a guess 1e-7
  off falls onto the nonimpacting orbit next to it, multiple shooting finds the impacting one;
* the rocking block (resets that change the mode) against tests/orbits/test_orbits_through_modes.py's
  exact orbit;
* the friction oscillator's stick-slip orbit (one segment, sliding inside it) against
  tests/orbits/test_sliding_orbits.py's exact orbit.

The equations' Jacobian is checked against central differences (the contact damper makes the field
jump at the switching surface: a segment Jacobian without its saltation matrices would differ by
O(0.1)).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import fsolve

import grazing
from grazing.models import friction_oscillator
from grazing.orbits import continue_orbit, find_orbit
from grazing.orbits.segments import SegmentLayout, layout_of, segmented_equations, segmented_newton
from tests.engine.test_events_off_modes import reference, soft_hard
from tests.engine.test_rocking_modes import reference as rocking_reference
from tests.engine.test_rocking_modes import rocking_block
from tests.orbits.test_orbits_through_modes import Diagonalised, exact_orbit
from tests.orbits.test_segmented_curves import _check_segmented_jacobian
from tests.orbits.test_sliding_orbits import exact_orbit as exact_stick_slip

STRONGLY_UNSTABLE = 1.5926110182283104
"""A frequency on the unstable branch of soft_hard's period-1 orbit (after its fold near 1.815), just
short of the wall's grazing."""
GUESS = [-0.8698756, 0.1697573, 1.444077, 1.855036, 2.283691]
"""``(x, v, t_touch, t_wall, t_leave)`` of that orbit on the section t = 0, roughly: fsolve's start."""


def exact_wall_orbit(p: dict, guess) -> tuple[np.ndarray, np.ndarray]:
    """soft_hard's period-1 orbit through ``touch``, ``wall`` and ``leave`` from the section t = 0 in mode
    ``free``: ``(u, J)``, ``u = (x, v, t_touch, t_wall, t_leave)`` and the monodromy ``J``."""
    ref = reference(p)
    T, R = ref.period, np.diag([1.0, -p["r"]])

    def ends(u):
        x0, t1, t2, t3 = u[:2], u[2], u[3], u[4]
        y1 = ref.flow(0, x0, 0.0, t1)
        y2 = ref.flow(1, y1, t1, t2)
        y3 = ref.flow(1, R @ y2, t2, t3)
        return y1, y2, y3, ref.flow(0, y3, t3, T)

    def equations(u):
        y1, y2, y3, y4 = ends(u)
        return [y1[0] - p["gap"], y2[0] - p["wall"], y3[0] - p["gap"], *(y4 - u[:2])]

    u, _, _, msg = fsolve(equations, guess, xtol=1e-15, full_output=True)
    assert np.abs(equations(u)).max() < 1e-14, msg
    y1, y2, y3, _ = ends(u)
    hx = np.array([1.0, 0.0])
    A = [md.A for md in ref.modes]

    def salt(fm, fp, B=None):  # S = B + (f+ - B f-) h_x / (h_x f-), B the reset's Jacobian (I: none)
        B = np.eye(2) if B is None else B
        return B + np.outer(fp - B @ fm, hx) / (hx @ fm)

    t1, t2, t3 = u[2:]
    J = expm(A[1] * (t2 - t1)) @ salt(ref.f(0, y1, t1), ref.f(1, y1, t1)) @ expm(A[0] * t1)
    J = expm(A[1] * (t3 - t2)) @ salt(ref.f(1, y2, t2), ref.f(1, R @ y2, t2), R) @ J
    J = expm(A[0] * (T - t3)) @ salt(ref.f(1, y3, t3), ref.f(0, y3, t3)) @ J
    return u, J


def central_differences(evaluate, u: np.ndarray, h: float = 1e-6) -> np.ndarray:
    columns = []
    for i in range(u.size):
        e = np.zeros(u.size)
        e[i] = h
        columns.append((evaluate(u + e)[0] - evaluate(u - e)[0]) / (2 * h))
    return np.array(columns).T


def assert_jacobian_is_the_differences(evaluate, u: np.ndarray) -> None:
    F, DF, _ = evaluate(u)
    fd = central_differences(evaluate, u)
    assert DF.shape == fd.shape == (F.size, u.size)
    scale = max(1.0, float(np.abs(fd).max()))
    assert np.abs(DF - fd).max() < 1e-7 * scale, np.abs(DF - fd).max()


def test_a_strongly_unstable_orbit_through_switches_and_a_wall_by_multiple_shooting(monkeypatch):
    m = soft_hard(omega=STRONGLY_UNSTABLE)
    u, J = exact_wall_orbit(dict(m.params), GUESS)
    x = u[:2]
    assert np.abs(np.linalg.eigvals(J)).max() > 1e5  # (strongly unstable)
    guess = x + np.array([-1e-7, 1e-7])
    orbit = segmented_newton(m, guess, 0.0, 1, tol=1e-11, max_iter=20, mode="free")
    assert np.abs(orbit.state - x).max() < 1e-10, orbit.state - x
    assert orbit.mode == "free" and orbit.impacts == 1 and m.stop_names[orbit.impact_stops[0]] == "wall"
    assert abs(orbit.impact_times[0] - u[3]) < 1e-10
    assert [m.stop_names[j] for j in orbit.switch_transitions] == ["touch", "leave"]
    assert np.abs(orbit.switch_times - u[[2, 4]]).max() < 1e-10
    assert np.abs(orbit.monodromy - J).max() < 1e-8 * np.abs(J).max(), orbit.monodromy - J
    assert orbit.passed_stops == () and orbit.residuals[-1] < 1e-11
    # single shooting from that guess falls onto the nonimpacting orbit next to it
    monkeypatch.setattr("grazing.orbits.shooting._Newton.segments_from_guess", lambda *args: False)
    single = find_orbit(m, guess, period=1, mode="free")
    assert single.impacts == 0 and np.abs(single.state - x).max() > 1e-7
    # from 1e-9 too; find_orbit hands that guess over to multiple shooting (its run's monodromy exceeds
    # MULTIPLE_SHOOTING_NORM: 2.6e4), which finds the impacting orbit
    near = x + np.array([-1e-9, 1e-9])
    assert find_orbit(m, near, period=1, mode="free").impacts == 0
    monkeypatch.undo()
    found = find_orbit(m, near, period=1, mode="free")
    assert np.abs(found.state - x).max() < 1e-10 and found.impacts == 1


def test_the_segmented_equations_through_switches_and_a_wall_against_differences():
    m = soft_hard()
    orbit = find_orbit(m, t0=None)
    assert orbit.impacts == 1 and len(orbit.switch_times) == 2  # (touch and leave inside the segments)
    layout = layout_of(orbit)
    assert layout.mode == orbit.mode and layout.start_mode(m, 1) == "contact"
    evaluate = segmented_equations(m, ("omega", "k"), 1, orbit.t0, layout, 0)
    u = np.append(layout.pack(orbit, m.params["omega"]), m.params["k"])
    F, _, same = evaluate(u)
    assert np.abs(F).max() < 1e-10
    assert np.abs(same.monodromy - orbit.monodromy).max() < 1e-9
    assert same.switch_signature == orbit.switch_signature
    u[:2] += 1e-4  # (off the orbit: the identities hold everywhere)
    assert_jacobian_is_the_differences(evaluate, u)


@pytest.mark.parametrize("kind", ["fold", "period-doubling"])
def test_the_segmented_curve_systems_through_modes_against_differences(kind):
    _check_segmented_jacobian(find_orbit(soft_hard(), t0=None), ("omega", "k"), kind)


def test_the_rocking_orbit_by_multiple_shooting():
    """Both impacts change the mode: the second segment starts on the other corner."""
    m = rocking_block()
    run = grazing.simulate(m, [0.1, 0.0], periods=1, transient=40)
    orbit = find_orbit(m, run.x_final, period=1, mode=run.mode_final)
    ms = segmented_newton(m, orbit.state + 1e-6, orbit.t0, 1, tol=1e-11, max_iter=20, mode=orbit.mode)
    ref = Diagonalised(rocking_reference(dict(m.params)))
    x, J, switches, res = exact_orbit(ref, orbit.state, m.mode_names.index(orbit.mode), orbit.t0)
    assert res < 1e-13 and len(switches) == 2
    assert np.abs(ms.state - x).max() < 1e-10 and ms.mode == orbit.mode
    assert np.abs(ms.impact_times - [s[0] for s in switches]).max() < 1e-10
    assert np.abs(ms.switch_times - ms.impact_times).max() == 0.0  # (each impact is a switch)
    assert np.abs(ms.monodromy - J).max() < 1e-9 * max(1.0, np.abs(J).max())
    layout = layout_of(ms)
    assert layout.start_mode(m, 1) != layout.start_mode(m, 0)
    u = layout.pack(ms, m.params["omega"])
    u[:2] += 1e-4
    assert_jacobian_is_the_differences(segmented_equations(m, "omega", 1, ms.t0, layout, 0), u)


def test_the_stick_slip_orbit_on_a_segment_that_slides():
    """No reset: one segment, whose run sticks twice (slides on the belt) and slips twice."""
    m = friction_oscillator(a=1.0, omega=0.5, mu=0.5, v_belt=0.2)
    orbit = find_orbit(m)
    layout = SegmentLayout(2, (), orbit.mode)
    evaluate = segmented_equations(m, "mu", 1, orbit.t0, layout, 0)
    u = np.append(orbit.state + 1e-3, m.params["mu"])
    for _ in range(12):
        F, DF, ms = evaluate(u)
        if np.abs(F).max() < 1e-12:
            break
        u[:-1] -= np.linalg.solve(DF[:, :-1], F)
    x, J, events, res = exact_stick_slip(
        dict(m.params), orbit.state, m.mode_names.index(orbit.mode), orbit.t0
    )
    assert res < 1e-13 and [k for _, k in events].count("stick") == 2
    assert np.abs(ms.state - x).max() < 1e-10, ms.state - x
    assert np.abs(ms.switch_times - [tt for tt, _ in events]).max() < 1e-10
    assert any("slide" in m.switch_names[j] for j in ms.switch_transitions)
    assert np.abs(ms.monodromy - J).max() < 1e-9 * max(1.0, np.abs(J).max())
    u[:2] += 1e-4
    assert_jacobian_is_the_differences(evaluate, u)
    assert math.isnan(ms.guard_min) and ms.impacts == 0


def test_a_segment_through_the_wall_is_told():
    """The orbit's run without its impact (one segment, no reset) passes through the wall: the physical
    run of that segment hits it, and the orbit says so; with its impact it passes through nothing."""
    m = soft_hard()
    orbit = find_orbit(m, t0=None)
    through = segmented_equations(m, None, 1, orbit.t0, SegmentLayout(2, (), orbit.mode), 0)
    _, _, passing = through(np.append(orbit.state, 0.0))
    assert passing.passed_stops == ("wall",) and passing.crossed_stops == ("wall",)
    layout = layout_of(orbit)
    _, _, same = segmented_equations(m, None, 1, orbit.t0, layout, 0)(layout.pack(orbit, 0.0))
    assert same.crossed_stops == ()


def exact_wall_grazing(p: dict, guess) -> np.ndarray:
    """``(x, v, t_touch, t_wall, t_leave, omega)`` where soft_hard's orbit meets the wall at zero speed."""

    def equations(u):
        q = {**p, "omega": u[5]}
        ref = reference(q)
        x0, t1, t2, t3 = u[:2], u[2], u[3], u[4]
        y1 = ref.flow(0, x0, 0.0, t1)
        y2 = ref.flow(1, y1, t1, t2)
        y3 = ref.flow(1, np.diag([1.0, -q["r"]]) @ y2, t2, t3)
        y4 = ref.flow(0, y3, t3, ref.period)
        return [y1[0] - q["gap"], y2[0] - q["wall"], y2[1], y3[0] - q["gap"], *(y4 - x0)]

    u, _, _, msg = fsolve(equations, guess, xtol=1e-15, full_output=True)
    assert np.abs(equations(u)).max() < 1e-13, msg
    return u


def test_continuation_hands_over_to_multiple_shooting_and_ends_at_the_exact_grazing_of_the_wall():
    """Down the unstable branch towards the wall's grazing the multiplier grows past 1e5: single shooting
    stalls, multiple shooting takes over (as on a model of one mode) and the branch ends where the wall
    impact's speed vanishes, at the exact grazing frequency."""
    start = 1.5926184272441661
    m = soft_hard(omega=start)
    u, _ = exact_wall_orbit(dict(m.params), GUESS)
    orbit = find_orbit(m, u[:2], period=1, mode="free")
    assert orbit.impacts == 1 and np.abs(orbit.state - u[:2]).max() < 1e-10
    branch = continue_orbit(m, "omega", start, 1.59, orbit=orbit)
    assert "by multiple shooting from omega = " in branch.status, branch.status
    # (the wall is an impact: its grazing changes the impacts, not the switches of mode)
    assert (
        "; the orbit with the new impact sequence can be followed with switch (switch=True)" in branch.status
    )
    assert "switches of mode" not in branch.status
    [graze] = branch.special
    exact = exact_wall_grazing(dict(m.params), [*GUESS, start])
    assert graze.kind == "grazing" and abs(graze.param - exact[5]) < 1e-9, (graze.param, exact[5])
    for o in branch.orbits[1:]:
        q = o.model.params["omega"]
        if q > exact[5] + 1e-7:  # (the exact boundary-value problem is well posed off the grazing)
            ux, _ = exact_wall_orbit(dict(o.model.params), [*o.state, *u[2:]])
            assert np.abs(o.state - ux[:2]).max() < 1e-10, (q, o.state - ux[:2])


def test_past_the_wall_s_grazing_the_branch_switches_to_the_orbit_without_the_impact():
    """With switch, the branch goes on past the wall's grazing along the orbit that misses the wall (no
    impact, its switches into and out of the contact kept), and says that its impacts changed."""
    start = 1.5926184272441661
    m = soft_hard(omega=start)
    u, _ = exact_wall_orbit(dict(m.params), GUESS)
    orbit = find_orbit(m, u[:2], period=1, mode="free")
    branch = continue_orbit(m, "omega", start, 1.59, orbit=orbit, switch=True)
    first = branch.segment_status[0]
    assert (
        "(the orbit loses an impact)" in first
        and "; switched to the orbit with the new impact sequence" in first
    )
    assert "switches of mode" not in first
    assert branch.orbits[0].impacts == 1 and branch.orbits[-1].impacts == 0
