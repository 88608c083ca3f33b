"""Periodic orbits and their continuation through modes: the soft-impact oscillator against its exact orbits.

The soft-impact oscillator with its test-only contact damper (tests/engine/test_mode_switches.py) is
piecewise linear, so its periodic orbits are exact: the fixed point of the exact period map of
tests/piecewise_exact.py (matrix exponentials per mode, switch times by Brent's method) by Newton's
method with the exact Jacobian, the product of the exponentials and the saltation matrices.  Its
determinant has a closed form, ``prod_k exp(tr A_k tau_k) prod_switches (h_x f+) / (h_x f-)``
(Liouville's formula in each mode, ``det S = 1 + h_x (f+ - f-) / (h_x f-)`` at each switch).  Where
the orbit stops touching the contact (a grazing of the switching surface) it is the linear free
response, whose amplitude ``a / |1 - w^2 + 2 i zeta w|`` equals the gap there: a closed form for the
grazing frequency.

The rocking block (tests/engine/test_rocking_modes.py: a reset onto the other corner that changes the
mode) has exact rocking orbits too, whose monodromy's determinant is ``r^2`` per impact (``det R = r``,
and ``(h_x R^-1 f+) / (h_x f-) = r``: the angular velocity after over before; ``tr A = 0``).
Nothing in the references uses grazing's engine.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve

import grazing
from grazing.errors import ConvergenceError, InvalidStateError
from grazing.maps import flow_map
from grazing.orbits import continue_orbit, find_orbit
from grazing.orbits.palc import PalcSettings
from grazing.orbits.segments import segmented_newton
from tests.engine.test_mode_switches import reference as reference_expm
from tests.engine.test_mode_switches import soft_impact
from tests.engine.test_rocking_modes import reference as rocking_reference
from tests.engine.test_rocking_modes import rocking_block
from tests.piecewise_exact import PiecewiseLinearModel


class Diagonalised(PiecewiseLinearModel):
    """The same exact solution with ``exp(A t) = V diag(exp(lambda t)) V^-1`` (the modes' matrices have
    distinct eigenvalues) and the particular solutions' amplitudes computed once: the dense search for
    switches, hundreds of flows per period, in a fraction of the time of ``expm``."""

    def __init__(self, base: PiecewiseLinearModel):
        super().__init__(base.modes, base.w)
        self.eig = [np.linalg.eig(md.A) for md in self.modes]
        self.inv = [np.linalg.inv(vec) for _, vec in self.eig]
        n = self.modes[0].A.shape[0]
        self.X = [np.linalg.solve(1j * self.w * np.eye(n) - md.A, md.b.astype(complex)) for md in self.modes]
        self.shift = [np.linalg.solve(md.A, md.d) for md in self.modes]

    def xp(self, k: int, t: float) -> np.ndarray:
        return (self.X[k] * np.exp(1j * self.w * t)).real - self.shift[k]

    def flow(self, k: int, x0: np.ndarray, t0: float, t: float) -> np.ndarray:
        lam, vec = self.eig[k]
        return (vec @ (np.exp(lam * (t - t0)) * (self.inv[k] @ (x0 - self.xp(k, t0))))).real + self.xp(k, t)


def reference(params: dict) -> Diagonalised:
    return Diagonalised(reference_expm(params))


def exact_orbit(params: dict | PiecewiseLinearModel, x: np.ndarray, mode: int, t0: float, periods: int = 1):
    """The exact period-``periods`` orbit near ``x`` (in ``mode`` at ``t0``) of the soft-impact oscillator
    with ``params`` (or of the piecewise-linear model given): ``(x, J, switches, residual)``, switches
    ``(t, exit, from, to)``."""
    ref = params if isinstance(params, PiecewiseLinearModel) else reference(params)
    t1 = t0 + periods * ref.period
    for _ in range(12):
        x_end, k_end, J, _ = ref.run(x, mode, t0, t1)
        assert k_end == mode
        step = np.linalg.solve(J - np.eye(x.size), x_end - x)
        x = x - step
        if np.abs(step).max() < 1e-15 * max(1.0, np.abs(x).max()):
            break
    x_end, _, J, switches = ref.run(x, mode, t0, t1)
    return x, J, switches, float(np.max(np.abs(x_end - x)))


def determinant_closed_form(params: dict, x: np.ndarray, mode: int, t0: float, t1: float) -> float:
    """``det`` of the exact flow map from ``x`` at ``t0`` to ``t1``: ``exp(tr A_k tau)`` for the time
    ``tau`` spent in each mode ``k`` (Liouville), times ``(h_x f+) / (h_x f-)`` at each switch."""
    ref = reference(params)
    det, t, k = 1.0, t0, mode
    while (ev := ref.first_exit(k, x, t, t1)) is not None:
        ts, i = ev
        c, _, target = ref.modes[k].exits[i][:3]
        xs = ref.flow(k, x, t, ts)
        det *= math.exp(np.trace(ref.modes[k].A) * (ts - t))
        det *= (c @ ref.f(target, xs, ts)) / (c @ ref.f(k, xs, ts))
        x, t, k = xs, ts, target
    return det * math.exp(np.trace(ref.modes[k].A) * (t1 - t))


def grazing_frequency(p: dict, lo: float, hi: float) -> float:
    """Where the free linear response's amplitude ``a / |1 - w^2 + 2 i zeta w|`` equals the gap."""
    return brentq(lambda w: abs(1 - w * w + 2j * p["zeta"] * w) - p["a"] / p["gap"], lo, hi, xtol=1e-15)


def test_the_orbit_from_rest_is_the_exact_orbit():
    """State, mode, switch times and transitions, monodromy (saltations included), its determinant and the
    multipliers of the period-1 orbit that the default guess (simulated from rest) leads to."""
    m = soft_impact()
    orbit = find_orbit(m)
    p = dict(m.params)
    k = m.mode_names.index(orbit.mode)
    x, J, switches, res = exact_orbit(p, orbit.state, k, orbit.t0)
    assert res < 1e-13 and len(switches) == 2
    assert np.abs(orbit.state - x).max() < 1e-10, orbit.state - x
    assert orbit.period == 1 and orbit.impacts == 0 and orbit.residual < 1e-10
    assert np.abs(orbit.switch_times - [s[0] for s in switches]).max() < 1e-10
    names = [m.stop_names[j] for j in orbit.switch_transitions]
    assert names == [("touch", "leave")[s[2]] for s in switches]
    assert orbit.switch_signature == (tuple(names),)
    assert np.abs(orbit.monodromy - J).max() < 1e-9 * max(1.0, np.abs(J).max()), orbit.monodromy - J
    det = determinant_closed_form(p, x, k, orbit.t0, orbit.t0 + m.period)
    assert abs(np.linalg.det(orbit.monodromy) - det) < 1e-9 * abs(det)
    assert abs(np.linalg.det(J) - det) < 1e-11 * abs(det)  # (the reference agrees with its closed form)
    assert np.abs(np.sort_complex(orbit.multipliers) - np.sort_complex(np.linalg.eigvals(J))).max() < 1e-9
    assert orbit.stable


@pytest.mark.parametrize("section", ["free", "contact"])
def test_the_section_state_comes_with_its_mode(section):
    """The same orbit on sections where it is in either mode: found from a guess in that mode, with the
    exact state, switches and monodromy there."""
    m = soft_impact()
    p = dict(m.params)
    ref = reference(p)
    orbit = find_orbit(m)
    k0 = m.mode_names.index(orbit.mode)
    x_ref, _, switches, _ = exact_orbit(p, orbit.state, k0, orbit.t0)
    # a section time in the middle of the orbit's stay in the mode asked for
    (t1, _, _, to1), (t2, _, _, _) = switches
    t_in = 0.5 * (t1 + t2) if m.mode_names[to1] == section else 0.5 * (t2 + t1 + ref.period)
    x_in, k_in, _, _ = ref.run(x_ref, k0, orbit.t0, t_in)
    assert m.mode_names[k_in] == section
    guess = x_in + np.array([1e-3, -1e-3])
    found = find_orbit(m, guess, period=1, t0=t_in, mode=section)
    x, J, sw, res = exact_orbit(p, x_in, k_in, t_in)
    assert found.mode == section and res < 1e-13
    assert np.abs(found.state - x).max() < 1e-10
    assert np.abs(found.switch_times - [s[0] for s in sw]).max() < 1e-10
    assert np.abs(found.monodromy - J).max() < 1e-9 * max(1.0, np.abs(J).max())
    det = determinant_closed_form(p, x, k_in, t_in, t_in + m.period)
    assert abs(np.linalg.det(found.monodromy) - det) < 1e-9 * abs(det)


def test_a_map_that_returns_in_another_mode_and_other_refusals_in_one_line():
    m = soft_impact()
    orbit = find_orbit(m)
    # The orbit is in contact at its section; from just short of the contact, moving as fast as the orbit
    # does there, the motion is in contact again one period later.
    assert orbit.mode == "contact"
    x = np.array([m.params["gap"] - 1e-3, orbit.state[1]])
    fm = flow_map(m, x, t0=orbit.t0, mode="free")
    assert fm.mode == "free" and fm.mode_final == "contact"
    with pytest.raises(ConvergenceError, match=r"returns in mode 'contact'") as info:
        find_orbit(m, x, period=1, t0=orbit.t0, mode="free")
    assert "\n" not in str(info.value)
    with pytest.raises(InvalidStateError, match="is not in mode 'free'"):
        find_orbit(m, [1.0, 0.0], period=1, mode="free")
    # a virtual orbit ignores the resets only (tests/orbits/test_virtual_through_modes.py): this model has
    # none, so it is the orbit itself
    virtual = find_orbit(m, orbit.state, period=1, t0=orbit.t0, mode=orbit.mode, virtual=True)
    assert virtual.virtual and np.abs(virtual.state - orbit.state).max() < 1e-10
    assert virtual.crossed_stops == () and np.isinf(virtual.guard_mins).all()
    # multiple shooting goes through modes (tests/orbits/test_segments_through_modes.py); this model has
    # no reset, so its segments end on its switches (tests/orbits/test_segments_at_switches.py)
    ms = segmented_newton(m, orbit.state, orbit.t0, 1, tol=1e-10, max_iter=5, mode=orbit.mode)
    assert ms.impacts == 0 and np.abs(ms.state - orbit.state).max() < 1e-10
    assert np.abs(ms.switch_times - orbit.switch_times).max() < 1e-10


def test_a_change_of_switches_along_a_branch_ends_it_at_the_exact_grazing():
    """Up in frequency the orbit leaves the contact: the branch ends where its switches change, bracketed
    around the closed-form grazing; with ``switch`` it goes on along the free linear response."""
    m = soft_impact()
    p = dict(m.params)
    w_graze = grazing_frequency(p, 1.3, 3.0)
    br = continue_orbit(m, "omega", 1.2, 2.0)
    [sp] = br.special
    assert sp.kind == "grazing" and m.stop_names[sp.stop] == "touch" and sp.grazing is not None
    assert "loses a switch ('touch'" in br.status and "\n" not in br.status
    assert "bracketed only" not in br.status
    lo, hi = sp.interval
    assert lo - 1e-12 <= w_graze <= hi + 1e-12 and hi - lo < 1e-8, (lo, w_graze, hi)
    assert abs(sp.param - w_graze) < 1e-10  # (located: tests/orbits/test_curves_through_modes.py)
    ds = br.to_dataset()
    assert set(ds.mode.values) <= {"free", "contact"} and (ds.switches.values == 2).all()
    assert all(o.switch_signature == (("touch", "leave"),) for o in br.orbits) or all(
        o.switch_signature == (("leave", "touch"),) for o in br.orbits
    )
    # every orbit on the branch is the exact one
    for o in br.orbits[:: max(1, len(br) // 6)]:
        q = {**p, "omega": o.model.params["omega"]}
        x, J, _, res = exact_orbit(q, o.state, m.mode_names.index(o.mode), o.t0)
        assert res < 1e-12 and np.abs(o.state - x).max() < 1e-9
        assert np.abs(o.monodromy - J).max() < 1e-8 * max(1.0, np.abs(J).max())
    switched = continue_orbit(m, "omega", 1.2, 2.0, switch=True)
    assert (
        switched.special[0].switched
        and "switched to the orbit with the new switches of mode" in (switched.segment_status[0])
    )
    after = [o for o, s in zip(switched.orbits, switched.segments) if s == 1]
    assert after and all(o.switch_signature == ((),) and o.mode == "free" for o in after)
    for o in after[:: max(1, len(after) // 4)]:  # the free linear response, exactly
        w, t0 = o.model.params["omega"], o.t0
        X = p["a"] / (1 - w * w + 2j * p["zeta"] * w)
        exact = np.array([(X * np.exp(1j * w * t0)).real, (1j * w * X * np.exp(1j * w * t0)).real])
        assert np.abs(o.state - exact).max() < 1e-10 and w > w_graze


def exact_fold(params: dict, x: np.ndarray, w: float, mode: int, t0: float) -> tuple[np.ndarray, float]:
    """The exact fold near ``(x, w)``: the period-1 orbit with ``det(J - I) = 0``, by fsolve on the exact
    period map (section at ``t0``, a fixed time)."""

    def equations(u):
        q = {**params, "omega": u[2]}
        ref = reference(q)
        x_end, k_end, J, _ = ref.run(u[:2], mode, t0, t0 + ref.period)
        assert k_end == mode
        return np.append(x_end - u[:2], np.linalg.det(J - np.eye(2)))

    u, _, ok, msg = fsolve(equations, np.append(x, w), xtol=1e-14, full_output=True)
    assert ok in (1, 3), msg  # (3: no further improvement at xtol, below rounding; the residual decides)
    assert np.abs(equations(u)).max() < 1e-11
    return u[:2], float(u[2])


def test_folds_after_a_gained_switch_against_the_exact_folds():
    """Down in frequency (a = 2) the orbit gains a second contact per period (reported, then switched to)
    and that orbit's branch folds twice: each fold located where the exact fold is, with a multiplier 1."""
    m = soft_impact(a=2.0)
    p = dict(m.params)
    br = continue_orbit(m, "omega", 1.2, 0.6, switch=True)
    kinds = [s.kind for s in br.special]
    assert kinds == ["grazing", "fold", "fold"], kinds
    graze = br.special[0]
    assert graze.switched and "gains a switch ('touch'" in br.segment_status[0]
    assert [len(sum(o.switch_signature, ())) for o in br.orbits] == [2 if s == 0 else 4 for s in br.segments]
    for fold in br.special[1:]:
        o = fold.orbit
        k = m.mode_names.index(o.mode)
        x, w = exact_fold(p, o.state, fold.param, k, o.t0)
        assert abs(fold.param - w) < 1e-10, (fold.param, w)
        assert np.abs(o.state - x).max() < 1e-9, o.state - x
        J = reference({**p, "omega": w}).run(x, k, o.t0, o.t0 + 2 * math.pi / w)[2]
        assert np.min(np.abs(np.linalg.eigvals(J) - 1.0)) < 1e-10  # (the reference's own fold)
        assert np.min(np.abs(o.multipliers - 1.0)) < 1e-8, o.multipliers
        assert np.abs(o.monodromy - J).max() < 1e-8 * max(1.0, np.abs(J).max())
        det = determinant_closed_form(p | {"omega": w}, x, k, o.t0, o.t0 + 2 * math.pi / w)
        assert abs(np.linalg.det(o.monodromy) - det) < 1e-9 * abs(det)


def test_a_rocking_orbit_through_impacts_that_change_the_mode():
    """The period-1 rocking orbit (one landing on each corner per forcing period) from a guess after a
    transient: state, mode, impacts and switches, monodromy and its determinant ``r^4`` exactly."""
    m = rocking_block()
    run = grazing.simulate(m, [0.1, 0.0], periods=1, transient=40)
    orbit = find_orbit(m, run.x_final, period=1, mode=run.mode_final)
    k = m.mode_names.index(orbit.mode)
    ref = Diagonalised(rocking_reference(dict(m.params)))
    x, J, switches, res = exact_orbit(ref, orbit.state, k, orbit.t0)
    assert res < 1e-13 and len(switches) == 2 and orbit.mode == run.mode_final
    assert np.abs(orbit.state - x).max() < 1e-10, orbit.state - x
    times = [s[0] for s in switches]
    assert orbit.impacts == 2 and np.abs(orbit.impact_times - times).max() < 1e-10
    assert np.abs(orbit.switch_times - times).max() < 1e-10
    names = [("onto_left", "onto_right")[s[2]] for s in switches]
    assert [m.stop_names[j] for j in orbit.switch_transitions] == names
    assert [m.stop_names[j] for j in orbit.impact_stops] == names
    assert np.abs(orbit.monodromy - J).max() < 1e-9 * max(1.0, np.abs(J).max()), orbit.monodromy - J
    r = m.params["r"]
    assert abs(np.linalg.det(orbit.monodromy) - r**4) < 1e-10 and abs(np.linalg.det(J) - r**4) < 1e-12
    assert orbit.stable and np.allclose(np.abs(orbit.multipliers), r**2, rtol=1e-9)


def test_a_period_doubling_against_the_exact_one():
    """A stiff contact (k = 50, zeta = 0.02): the period-1 orbit's branch down in frequency has a
    period-doubling, located where the exact orbit has a multiplier -1; ``switch`` goes on along the
    period-2 orbit born there, as exact as the period-1 one."""
    m = soft_impact(k=50.0, zeta=0.02)
    p = dict(m.params)
    br = continue_orbit(m, "omega", 1.2, 1.0)
    [pd] = br.special
    assert pd.kind == "period-doubling" and br.status == "reached the bound omega = 1"
    o = pd.orbit
    k = m.mode_names.index(o.mode)

    def equations(u):
        ref = reference({**p, "omega": u[2]})
        x_end, k_end, J, _ = ref.run(u[:2], k, o.t0, o.t0 + ref.period)
        assert k_end == k
        return np.append(x_end - u[:2], np.linalg.det(J + np.eye(2)))

    u, _, ok, msg = fsolve(equations, np.append(o.state, pd.param), xtol=1e-14, full_output=True)
    assert ok == 1 and np.abs(equations(u)).max() < 1e-11, msg
    assert abs(pd.param - u[2]) < 1e-10, (pd.param, u[2])
    assert np.abs(o.state - u[:2]).max() < 1e-9
    assert np.min(np.abs(o.multipliers + 1.0)) < 1e-8, o.multipliers
    J = reference({**p, "omega": u[2]}).run(u[:2], k, o.t0, o.t0 + 2 * math.pi / u[2])[2]
    assert np.abs(o.monodromy - J).max() < 1e-8 * max(1.0, np.abs(J).max())
    doubled = continue_orbit(m, "omega", 1.2, 1.0, switch=True, settings=PalcSettings(max_points=24))
    assert doubled.special[0].switched and "period-2 orbit born there" in doubled.segment_status[0]
    twice = [orb for orb, s in zip(doubled.orbits, doubled.segments) if s == 1]
    assert twice and all(orb.period == 2 for orb in twice)
    checked = 0
    for orb in twice:
        q = {**p, "omega": orb.model.params["omega"]}
        ref, k = reference(q), m.mode_names.index(orb.mode)
        x_end, k_end, J, _ = ref.run(orb.state, k, orb.t0, orb.t0 + 2 * ref.period)
        assert k_end == k and np.abs(x_end - orb.state).max() < 1e-11  # (a fixed point of the exact map)
        assert np.abs(orb.monodromy - J).max() < 1e-7 * max(1.0, np.abs(J).max())
        if np.min(np.abs(orb.multipliers - 1.0)) < 1e-3:
            continue  # (next to the period-doubling the period-2 orbit's state is ill-conditioned)
        x, J, sw, res = exact_orbit(q, orb.state, k, orb.t0, periods=2)
        assert res < 1e-12 and np.abs(orb.state - x).max() < 1e-9
        assert np.abs(orb.switch_times - [s[0] for s in sw]).max() < 1e-9 and len(sw) == 4
        assert np.abs(orb.monodromy - J).max() < 1e-9 * max(1.0, np.abs(J).max())
        checked += 1
    assert checked >= 3
