"""Orbits, folds, period-doublings and grazings of the classic systems against closed forms.

* The bouncing ball (Holmes 1982; Luck & Mehta 1993): the orbit with one impact
  every n periods leaves the table with speed ``g n T / 2`` at a phase with
  ``cos(phi) = n (1 - r) pi g / ((1 + r) A w^2)``.  It is born in a fold (the
  impact at the table's zero phase) at ``A w^2 / g = n pi (1 - r) / (1 + r)``
  and period-doubles where ``sin(phi) = 2 (1 + r^2) g / ((1 + r)^2 A w^2)``.
* The linear impact oscillator (Nordmark 1991): the nonimpacting orbit has the
  amplitude ``1 / sqrt((1 - w^2)^2 + (2 zeta w)^2)`` and the multipliers
  ``exp(T (-zeta +- i sqrt(1 - zeta^2)))``; it grazes where that amplitude is
  the stop distance; its impacting period-one orbit solves a 2x2 linear
  problem (matrix exponential of the free flow), whose turning point in ``w``
  is the fold.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import brentq, minimize_scalar, root

import grazing
from grazing.models import bouncing_ball, impact_oscillator
from grazing.orbits import continue_orbit, find_grazings, find_orbit, grazing_curve

R, G, W = 0.5, 1.0, 1.0


def ball_fold(n: int) -> float:
    return n * math.pi * (1 - R) * G / ((1 + R) * W**2)


def ball_period_doubling(n: int) -> float:
    return G / W**2 * math.sqrt(4 * (1 + R**2) ** 2 / (1 + R) ** 4 + (n * math.pi * (1 - R) / (1 + R)) ** 2)


def ball_orbit(n: int, amplitude: float) -> grazing.orbits.PeriodicOrbit:
    """The stable one-impact period-n orbit from its closed form, polished by Newton."""
    m = bouncing_ball(amplitude=amplitude, r=R, gravity=G, omega=W)
    T = 2 * math.pi / W
    phi = math.acos(n * math.pi * (1 - R) * G / ((1 + R) * amplitude * W**2))  # sin(phi) > 0: stable
    t_imp = phi / W
    after = [amplitude * math.sin(W * t_imp) + 1e-12, G * n * T / 2]
    x0 = grazing.simulate(m, after, t0=t_imp, periods=1, phase=0.0).x_final  # at the next t = 0 (mod T)
    return find_orbit(m, x0, period=n, t0=None)


@pytest.mark.parametrize("n", [1, 2])
def test_bouncing_ball_fold_and_period_doubling(n):
    a_fold, a_pd = ball_fold(n), ball_period_doubling(n)
    mid = 0.5 * (a_fold + a_pd)
    orbit = ball_orbit(n, mid)
    assert orbit.impacts == 1 and orbit.stable
    np.testing.assert_allclose(abs(np.prod(orbit.multipliers)), R**2, rtol=1e-10)  # det = r^2
    m = orbit.model
    down = continue_orbit(m, "amplitude", mid, a_fold - 0.3, orbit=orbit)
    folds = [s for s in down.special if s.kind == "fold"]
    assert folds, down.status
    assert folds[0].param == pytest.approx(a_fold, abs=1e-9)
    assert abs(folds[0].param - a_fold) <= 2 * folds[0].precision  # (its precision is an honest estimate)
    np.testing.assert_allclose(sorted(folds[0].multipliers.real), [R**2, 1.0], atol=1e-7)
    # Past the fold the branch is the unstable orbit (sin(phi) < 0): it comes back up.
    assert not down.orbits[-1].stable and down.values[-1] > a_fold
    up = continue_orbit(m, "amplitude", mid, a_pd + 0.3, orbit=orbit)
    pds = [s for s in up.special if s.kind == "period-doubling"]
    assert pds, up.status
    assert pds[0].param == pytest.approx(a_pd, abs=1e-8)
    assert abs(pds[0].param - a_pd) <= 2 * pds[0].precision
    np.testing.assert_allclose(sorted(pds[0].multipliers.real), [-1.0, -(R**2)], atol=1e-7)
    # One orbit all along: one impact per n periods (the section moves away from the impact
    # near the fold, so the period in which it falls may change).
    assert {o.impacts for o in down.orbits + up.orbits} == {1}


ZETA, REST = 0.05, 0.8


def oscillator_amplitude(w: float) -> float:
    return 1.0 / math.sqrt((1 - w * w) ** 2 + (2 * ZETA * w) ** 2)


def test_impact_oscillator_nonimpacting_orbit_and_multipliers():
    w = 2.8
    m = impact_oscillator(zeta=ZETA, omega=w, sigma=2.0, r=REST)
    orbit = find_orbit(m)
    assert orbit.impacts == 0 and orbit.period == 1
    assert m.params["sigma"] - orbit.guard_min == pytest.approx(oscillator_amplitude(w), abs=1e-10)
    T = 2 * math.pi / w
    expected = np.exp(T * (-ZETA + 1j * math.sqrt(1 - ZETA**2) * np.array([1, -1])))
    np.testing.assert_allclose(np.sort_complex(orbit.multipliers), np.sort_complex(expected), atol=1e-10)


def test_impact_oscillator_grazing_in_omega_and_in_sigma():
    sigma = 0.1
    points, _ = find_grazings(impact_oscillator(zeta=ZETA, sigma=sigma, r=REST), "omega", 2.5, 4.0)
    expected = brentq(lambda w: oscillator_amplitude(w) - sigma, 2.5, 4.0, xtol=1e-15)
    assert [p.model.params["omega"] for p in points] == pytest.approx([expected], abs=1e-10)
    w = 2.8
    points, _ = find_grazings(impact_oscillator(zeta=ZETA, omega=w, sigma=1.0, r=REST), "sigma", 1.0, 0.01)
    assert [p.model.params["sigma"] for p in points] == pytest.approx([oscillator_amplitude(w)], abs=1e-10)


def test_a_grazing_curve_in_restitution_ends_exactly_at_r_equal_to_one():
    # r does not change the nonimpacting orbit: the curve is omega = const (the closed-form grazing
    # frequency) from r = 0.5 up to r's own upper bound, 1, where it ends (it stopped on a step size
    # that fell below its minimum just short of 1).
    sigma = 0.1
    curve = grazing_curve(impact_oscillator(zeta=ZETA, sigma=sigma, r=REST), ("omega", "r"), 0.5,
                          search=(2.5, 4.0))  # fmt: skip
    expected = brentq(lambda w: oscillator_amplitude(w) - sigma, 2.5, 4.0, xtol=1e-15)
    assert curve.status == "reached the bound r = 1"
    r_values = [p.model.params["r"] for p in curve.points]
    assert r_values[0] == 0.5 and r_values[-1] == 1.0
    assert [p.model.params["omega"] for p in curve.points] == pytest.approx(
        [expected] * len(r_values), abs=1e-9
    )


def _impacting_orbit_closed_form(sigma: float):
    """``residual(v, w, phase) = 0``: a period-one orbit with one impact at forcing phase ``phase``."""
    A = np.array([[0.0, 1.0], [-1.0, -2 * ZETA]])

    def particular(t: float, w: float) -> np.ndarray:
        H = 1 / (1 - w * w + 2j * ZETA * w)
        e = np.exp(1j * w * t)
        return np.array([(H * e).real, (1j * w * H * e).real])

    def residual(v: float, w: float, phase: float) -> np.ndarray:
        Phi = expm(A * 2 * math.pi / w)
        start = np.array([sigma, -REST * v])  # just after the impact
        return (np.eye(2) - Phi) @ particular(phase / w, w) + Phi @ start - np.array([sigma, v])

    return residual


def test_impact_oscillator_continuation_in_omega_through_the_fold():
    """sigma = 0.5: the impacting orbit outlives grazing (hysteresis) up to a fold, then comes back."""
    sigma = 0.5
    m = impact_oscillator(zeta=ZETA, sigma=sigma, r=REST)
    orbit = find_orbit(m.with_params(omega=1.5), period=1, t0=None)
    assert orbit.impacts == 1
    branch = continue_orbit(m, "omega", 1.5, 2.5, orbit=orbit)
    kinds = [s.kind for s in branch.special]
    assert kinds == ["fold", "grazing"], branch.status
    fold, graze = branch.special
    # The fold: the largest frequency of the closed-form branch, parametrised by the impact phase.
    residual = _impacting_orbit_closed_form(sigma)
    T = 2 * math.pi / fold.param
    phase0 = (fold.orbit.impact_times[0] % T) * fold.param
    guess = [fold.orbit.impact_speeds[0], fold.param]

    def omega(phase: float) -> float:
        sol = root(lambda u: residual(u[0], u[1], phase), guess, tol=1e-15)
        return float(sol.x[1])

    best = minimize_scalar(lambda p: -omega(p), bracket=(phase0 - 0.05, phase0, phase0 + 0.05), tol=1e-12)
    assert fold.param == pytest.approx(-best.fun, abs=1e-9)
    # The branch ends where it loses its impact: the nonimpacting orbit's grazing.
    expected = brentq(lambda w: oscillator_amplitude(w) - sigma, 1.2, 2.5, xtol=1e-15)
    assert graze.param == pytest.approx(expected, abs=1e-10)
    assert graze.grazing is not None and graze.grazing.impacts == 0
    # Every point of the branch is a solution of the closed form.
    for value, o in zip(branch.values[::20], branch.orbits[::20]):
        t_imp = o.impact_times[0] % (2 * math.pi / value)
        np.testing.assert_allclose(residual(o.impact_speeds[0], value, t_imp * value), 0.0, atol=1e-10)


def test_an_orbit_that_is_not_isolated_is_refused_and_one_that_is_continues():
    """The undamped oscillator forced at omega = 2.8 = 14/5: 14 forcing periods are 5 of its own
    (14 T = 10 pi), so its period-14 map is the identity (every state is periodic) and no branch
    goes through such an orbit: refused in one line (it stalled at 5 points among hundreds of
    branch points before).  Its period-1 orbit (M: a rotation by T = 2 pi / 2.8, not the identity)
    is isolated and is followed through omega = 2.8 with the closed-form multipliers."""
    m = impact_oscillator(zeta=0.0, omega=2.8, sigma=2.0, r=REST)
    every = find_orbit(m, period=14, virtual=True)
    np.testing.assert_allclose(every.monodromy, np.eye(2), atol=1e-9)  # (P^14 = I: the closed form)
    with pytest.raises(grazing.ConvergenceError, match="period-14 orbit is not isolated"):
        continue_orbit(m, "omega", 2.8, 2.9, orbit=every)
    branch = continue_orbit(m, "omega", 2.7, 2.9, period=1, virtual=True)
    assert branch.status.startswith("reached") and branch.period == 1
    assert min(branch.values) <= 2.7 + 1e-12 and max(branch.values) >= 2.9 - 1e-12
    assert not [s for s in branch.special if s.kind != "grazing"]
    for w, orbit in zip(branch.values, branch.orbits):
        T = 2 * math.pi / w
        expected = np.exp(1j * T * np.array([1, -1]))
        np.testing.assert_allclose(np.sort_complex(orbit.multipliers), np.sort_complex(expected), atol=1e-9)
