"""Den Hartog's non-stop motion of the forced Coulomb oscillator (grazing.report.den_hartog).

The closed forms are checked against an independent integration (scipy's solve_ivp of
x'' + x = a cos(w t) - mu over one half-period: the motion from the reversal at x = -X with the
phase of the closed form must arrive at x = X with zero velocity), against Den Hartog's own printed
form (U = sin(pi / w) / (1 + cos(pi / w)); the limit pi / 4 at resonance), and grazing's orbits and
their stick boundary against the closed forms by the page's rules (docs/den-hartog.md).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from grazing.report import den_hartog as dh

OMEGAS = [0.6, 0.8, 0.9, 1.2, 1.5, 2.0, 3.0]
RATIOS = [0.1, 0.3, 0.5]


def _half_period(omega: float, ratio: float) -> np.ndarray:
    """The state (x, x') at s = pi / w after the reversal at (-X, 0), integrated by scipy (a = 1)."""
    k = 1.0 / (1.0 - omega**2)
    x = dh.amplitude(omega, ratio)
    # the phase from the printed relations: K cos(psi) = -X, K w sin(psi) = mu U
    u = math.sin(math.pi / omega) / (1.0 + math.cos(math.pi / omega))
    psi = math.atan2(ratio * u / (k * omega), -x / k)

    def rhs(s, y):
        return [y[1], -y[0] + math.cos(omega * s + psi) - ratio]

    sol = solve_ivp(rhs, (0.0, math.pi / omega), [-x, 0.0], method="DOP853", rtol=1e-13, atol=1e-13)
    return sol.y[:, -1]


@pytest.mark.parametrize("omega", OMEGAS)
@pytest.mark.parametrize("ratio", RATIOS)
def test_the_closed_form_motion_is_a_symmetric_half_period(omega, ratio):
    end = _half_period(omega, ratio)
    assert end == pytest.approx([dh.amplitude(omega, ratio), 0.0], abs=1e-9)


@pytest.mark.parametrize("omega", OMEGAS)
def test_the_amplitude_is_den_hartogs_printed_form(omega):
    beta, ratio = omega, 0.3
    u = math.sin(math.pi / beta) / (1.0 + math.cos(math.pi / beta))
    printed = math.sqrt(1.0 / (1.0 - beta**2) ** 2 - ratio**2 * (u / beta) ** 2)
    assert dh.amplitude(omega, ratio) == pytest.approx(printed, rel=1e-12)


@pytest.mark.parametrize("omega", OMEGAS)
def test_at_the_boundary_the_force_at_the_reversal_equals_the_friction(omega):
    # the mass leaves the reversal while the force there, a cos(psi) + X = w^2 X, is at least mu
    ratio = dh.boundary(omega)
    assert omega**2 * dh.amplitude(omega, ratio) == pytest.approx(ratio, rel=1e-10)
    below = 0.99 * ratio
    assert omega**2 * dh.amplitude(omega, below) > below


def test_the_boundary_tends_to_pi_over_4_at_resonance_and_to_zero_at_a_third():
    assert dh.boundary(1.0 + 1e-6) == pytest.approx(math.pi / 4, abs=1e-5)
    assert dh.boundary(1.0 - 1e-6) == pytest.approx(math.pi / 4, abs=1e-5)
    assert dh.boundary(1.0 / 3.0 + 1e-6) < 1e-4


def test_the_velocity_condition_lowers_the_boundary_only_at_low_frequency():
    for omega in (0.6, 0.8, 2.0):
        assert dh.nonstop_boundary(omega) == dh.boundary(omega)
    lowered = dh.nonstop_boundary(0.45)
    assert lowered < dh.boundary(0.45)
    assert abs(dh.min_velocity(0.45, lowered)) < 1e-12  # the velocity just touches zero inside


@pytest.mark.parametrize("ratio", RATIOS)
def test_grazings_orbits_have_den_hartogs_amplitude(ratio):
    points = dh.compare_amplitudes(OMEGAS, ratio)
    for p in points:
        assert not p.sticks, p
        assert abs(p.difference) <= dh.AMPLITUDE_RULE, p


@pytest.mark.parametrize("omega", [0.45, 0.8, 2.0])
def test_the_orbit_first_sticks_on_the_non_stop_boundary(omega):
    assert abs(dh.computed_boundary(omega) - dh.nonstop_boundary(omega)) <= dh.BOUNDARY_RULE


def test_above_the_boundary_the_orbit_sticks_and_below_it_does_not():
    b = dh.boundary(1.5)
    assert dh.reversals(dh.orbit_at(1.5, 0.98 * b)).margin > 0
    above = dh.reversals(dh.orbit_at(1.5, 1.02 * b))
    assert above.margin < 0 and above.sticks.all()


@pytest.mark.parametrize(("omega", "kind"), [(0.45, "grazing-sliding"), (2.0, "crossing-sliding")])
def test_the_sticking_starts_by_crossing_above_and_by_grazing_below_the_velocity_limit(omega, kind):
    # below omega ~ 0.5 the velocity touches zero inside a half-period first (min_velocity = 0 there)
    assert dh.transition_kind(omega, dh.computed_boundary(omega)) == kind


def test_at_resonance_exactly_the_boundary_is_pi_over_4():
    """At omega = 1 the closed form is 0 / 0 and its limit pi / 4 (the friction's work a period, 4 mu X,
    equals the resonant forcing's, pi a X): below it the motion never stops and its amplitude grows by
    pi a - 4 mu a period (no periodic orbit); above it the orbit sticks.  The located boundary is the
    limit (it raised ZeroDivisionError and ConvergenceError at omega = 1 exactly)."""
    assert dh.boundary(1.0) == math.pi / 4 and dh.nonstop_boundary(1.0) == math.pi / 4
    assert abs(dh.computed_boundary(1.0) - math.pi / 4) <= dh.BOUNDARY_RULE
    model = dh.friction_oscillator(a=1.0, omega=1.0, mu=0.5, v_belt=0.0)
    sol = dh.simulate(model, [0.0, 0.0], periods=200, impacts="all")
    late = sol.switches.t > 100 * 2 * math.pi
    x = np.abs(sol.switches.state[late, 0])
    growth = np.diff(x[::2])  # (a period apart: every other reversal)
    assert np.allclose(growth, math.pi - 4 * 0.5, atol=1e-6), growth
    above = dh.reversals(dh.orbit_at(1.0, 1.02 * math.pi / 4))
    assert above.margin < 0 and above.sticks.any()
