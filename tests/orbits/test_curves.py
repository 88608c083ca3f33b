"""Curves of folds, period-doublings, Neimark-Sacker points, branch points and grazings in two parameters.

Every curve is checked against something computed independently of it: a closed form (the ball on
a vibrating table, the linear impact oscillator), the one-parameter special points of
:func:`continue_orbit` at the curve's ends, or a one-parameter root search on the multipliers.
Every derivative of the extended systems is checked against central differences of their
equations, on two-state and four-state models and on random models whose frequency sets the
forcing period.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, assume, example, given, settings
from scipy.optimize import brentq, minimize_scalar, root

import grazing
from grazing.errors import InvalidParameterError, NotFoundError
from grazing.maps import flow_map
from grazing.models import bouncing_ball, impact_damper, impact_oscillator, two_sided_oscillator
from grazing.orbits import PalcSettings, continue_orbit, find_grazings, find_orbit, follow_curve
from grazing.orbits.bordered import Borders, bialternate, bordered
from grazing.orbits.continuation import SPECIAL_KINDS
from grazing.orbits.crossings import limit_condition
from grazing.orbits.curve_data import CurveEnd
from grazing.orbits.curves import BifurcationCurve, _follow_from
from grazing.orbits.extended import OrbitSystem
from tests.orbits.test_closed_forms import REST, ZETA, _impacting_orbit_closed_form, oscillator_amplitude
from tests.random_models import NAMES, ModelSpec, model_specs

DEG = math.pi / 180


# --------------------------------------------------------------------------
# The minimally augmented test functions


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_bialternate_product_has_the_products_of_eigenvalues_and_its_derivative(n):
    rng = np.random.default_rng(n)
    M = rng.standard_normal((n, n))
    mu = np.linalg.eigvals(M)
    products = [mu[i] * mu[j] for i in range(n) for j in range(i + 1, n)]
    np.testing.assert_allclose(
        np.sort_complex(np.linalg.eigvals(bialternate(M, M))), np.sort_complex(np.array(products)), atol=1e-10
    )
    # d(M (.) M) = 2 dM (.) M, against a central difference
    dM = rng.standard_normal((n, n))
    h = 1e-6
    fd = (bialternate(M + h * dM, M + h * dM) - bialternate(M - h * dM, M - h * dM)) / (2 * h)
    np.testing.assert_allclose(2 * bialternate(dM, M), fd, atol=1e-8)


def test_bordered_test_function_vanishes_at_singular_matrices_and_its_derivative():
    rng = np.random.default_rng(7)
    A = rng.standard_normal((4, 4))
    borders = Borders.of(A)
    sol = bordered(A, borders)
    dA = rng.standard_normal((4, 4))
    h = 1e-6
    fd = (bordered(A + h * dA, borders).g - bordered(A - h * dA, borders).g) / (2 * h)
    assert sol.derivative(dA) == pytest.approx(fd, rel=1e-7)
    u, s, vt = np.linalg.svd(A)
    singular = A - s[-1] * np.outer(u[:, -1], vt[-1])
    one = bordered(singular, borders)
    assert abs(one.g) < 1e-13
    np.testing.assert_allclose(singular @ one.v, 0, atol=1e-13)
    np.testing.assert_allclose(one.w @ singular, 0, atol=1e-13)


# --------------------------------------------------------------------------
# Every derivative of the extended systems against central differences


def _differences(system, u: np.ndarray) -> np.ndarray:
    cols = []
    for k in range(u.size):
        h = 1e-6 * max(1.0, abs(u[k]))
        e = np.zeros(u.size)
        e[k] = h
        cols.append((system(u + e)[0] - system(u - e)[0]) / (2 * h))
    return np.array(cols).T


def _check_jacobian(model, orbit, params, kind):
    system = OrbitSystem(
        model, kind, params, orbit.period, orbit.t0, orbit.virtual, orbit.stop, orbit.monodromy
    )
    u = system.start(orbit)
    u[: model.n_states] += 1e-5  # off the orbit and off the curve: the identities hold everywhere
    _, DF, _ = system(u)
    fd = _differences(system, u)
    for row, fd_row in zip(DF, fd):
        assert np.max(np.abs(row - fd_row)) <= 2e-5 * max(1.0, float(np.max(np.abs(fd_row)))), (
            kind,
            row,
            fd_row,
        )


KINDS = ("fold", "period-doubling", "neimark-sacker", "branch-point")


@pytest.fixture(scope="module")
def pendulum_period5():
    m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    return find_orbit(m, t0=None)


@pytest.mark.parametrize("kind", KINDS)
def test_extended_jacobians_of_the_pendulum(kind, pendulum_period5):
    _check_jacobian(pendulum_period5.model, pendulum_period5, ("eta", "theta_hat"), kind)


@pytest.fixture(scope="module")
def damper_orbit():
    """The impact damper (4 states, two stops) on an impacting period-1 orbit; omega sets the period."""
    m = impact_damper(mu=0.3, r=0.8, omega=1.2)
    orbit = find_orbit(m, t0=None)
    assert orbit.impacts == 2 and orbit.period == 1
    return orbit


@pytest.mark.parametrize("kind", KINDS)
def test_extended_jacobians_of_a_four_state_model(kind, damper_orbit):
    _check_jacobian(damper_orbit.model, damper_orbit, ("omega", "mu"), kind)


# Random models (tests/random_models.py): names chosen to collide with the generated code's, the
# frequency a parameter that sets the forcing period.
SPEC_1 = ModelSpec(
    names=("v0", "sqrt", "k", "math", "X", "sin", "w0", "x1", "cos", "v1"), dof=1, damping=0.079,
    stiffness=1.517, amplitude=0.755, omega=0.833, stop_fraction=0.6, restitution=0.927, coupling=0.707,
    cubic=0.0,
)  # fmt: skip
SPEC_2 = ModelSpec(
    names=("N", "X", "t_", "np", "c0", "pi", "x1", "k", "x", "Dummy", "O", "sin"), dof=2, damping=0.151,
    stiffness=1.365, amplitude=0.975, omega=0.922, stop_fraction=0.483, restitution=0.516, coupling=0.545,
    cubic=0.2,
)  # fmt: skip


def _random_orbit(spec: ModelSpec):
    m = spec.model()
    return find_orbit(m, spec.initial_state(), period=1, t0=None)


@pytest.mark.parametrize("kind", KINDS)
def test_extended_jacobians_of_a_random_model_in_a_period_setting_parameter(kind):
    orbit = _random_orbit(SPEC_2)
    amplitude, frequency = SPEC_2.param_names[2], SPEC_2.param_names[3]
    _check_jacobian(orbit.model, orbit, (frequency, amplitude), kind)


# --------------------------------------------------------------------------
# The ball on a vibrating table (g = omega = 1): closed forms in (amplitude, r)


def _ball(amplitude: float = 1.5, r: float = 0.5):
    """The model and a guess of its period-1 orbit at t = 0 from the closed form (take-off speed pi)."""
    m = bouncing_ball(amplitude=amplitude, r=r, gravity=1.0, omega=1.0)
    phi = math.acos(math.pi * (1 - r) / ((1 + r) * amplitude))
    flight = 2 * math.pi - phi  # from the take-off at phi - 2 pi to t = 0
    return m, [amplitude * math.sin(phi) + math.pi * flight - flight**2 / 2, math.pi - flight]


def _critical_distance(kind: str, mu: np.ndarray) -> float:
    """How far the multipliers ``mu`` are from the condition of a ``kind`` curve."""
    if kind in ("fold", "branch-point"):
        return float(np.min(np.abs(mu - 1)))
    if kind == "period-doubling":
        return float(np.min(np.abs(mu + 1)))
    n = len(mu)
    return min(abs(mu[i] * mu[j] - 1) for i in range(n) for j in range(i + 1, n))


ACCURACY_RATIO = (0.1, 10.0)
"""A curve point's reported accuracy must lie within these factors of the measured one
(:func:`_accuracy_ratio`): an estimate, not a bound off by orders of magnitude either way."""


def _rounding_scatter(curve: BifurcationCurve, kind: str, p) -> float:
    """The largest change of the critical multipliers' distance from the condition when the point's
    state and parameters change at the rounding level (by ``2 eps`` relative, 32 draws): what
    double precision can say about the multipliers there.  A draw that changes the number of impacts
    (a point within rounding of a grazing, where the curve ends) is another map, and left out.

    (Eight draws found up to 1.5 times less than 64 on a fold curve 8e-6 from a grazing.)"""
    o = p.orbit
    base = _critical_distance(kind, p.multipliers)
    rng = np.random.default_rng(27)
    scatter = 0.0
    for _ in range(32):
        x = o.state * (1 + 2 * np.finfo(float).eps * rng.standard_normal(o.state.size))
        values = np.array(p.values) * (1 + 2 * np.finfo(float).eps * rng.standard_normal(2))
        m = o.model.with_params(**dict(zip(curve.params, values.tolist())))
        fm = flow_map(m, x, t0=o.t0, periods=o.period, virtual=o.virtual, stop_name=o.stop)
        if fm.impacts != o.impacts:
            continue
        scatter = max(scatter, abs(_critical_distance(kind, np.linalg.eigvals(fm.jacobian)) - base))
    return scatter


def _accuracy_ratio(curve: BifurcationCurve, kind: str, p) -> float:
    """The point's reported accuracy over the measured one: the larger of the rounding scatter of its
    critical multipliers (:func:`_rounding_scatter`) and their own distance from the condition (where
    Newton's residual leaves them further from it than rounding moves them)."""
    measured = max(_rounding_scatter(curve, kind, p), _critical_distance(kind, p.multipliers))
    return p.accuracy / measured


def _accuracy_is_an_estimate(curve: BifurcationCurve, kind: str, points=None) -> list[float]:
    """Each point's accuracy is within :data:`ACCURACY_RATIO` of the measured one; the ratios."""
    ratios = [_accuracy_ratio(curve, kind, p) for p in (curve.points if points is None else points)]
    low, high = ACCURACY_RATIO
    assert all(low <= r <= high for r in ratios), (min(ratios), max(ratios))
    return ratios


def _condition_holds(
    curve: BifurcationCurve, kind: str, tol: float = 1e-7, every_point: bool = False
) -> None:
    """Every point satisfies the curve's condition: ``|g|`` within Newton's tolerance, and its critical
    multipliers within ``tol`` of it (relative to the largest multiplier for a fold and a
    period-doubling) or within the accuracy the curve reports.

    That accuracy exceeds ``tol`` only where double precision cannot do better: within about
    ``1e-5`` of a grazing, where the monodromy holds the saltation matrix's ``1 / v`` (``v`` the
    impact speed), the gradient of the defining condition grows like ``1 / v^2`` and ``w^T v`` falls
    like ``v``: a rounding-level change of the point then moves the multiplier by ~1e-5, and
    ``|g| <= 1e-10`` bounds it only to ~1e-6 (``|g| / |w^T v|``, the accuracy's first term).  There
    the point must be close to a grazing, and the reported accuracy an estimate, within
    :data:`ACCURACY_RATIO` of the measured one (:func:`_accuracy_ratio`); with ``every_point``, at
    every point."""
    checked = []
    for p in curve.points:
        mu = p.multipliers
        assert abs(p.condition) <= 1e-9
        if kind == "grazing":
            continue
        allowed = tol * max(1.0, np.max(np.abs(mu))) if kind != "neimark-sacker" else tol
        distance = _critical_distance(kind, mu)
        assert distance <= max(allowed, p.accuracy), p
        if p.accuracy > allowed:  # the limit of double precision, reported: near a grazing, and real
            assert p.orbit.impacts > 0 and p.orbit.min_impact_speed < 1e-3, p
        if every_point or p.accuracy > allowed:
            checked.append(p)
    if checked:
        _accuracy_is_an_estimate(curve, kind, checked)


def test_bouncing_ball_fold_curve_is_the_closed_form():
    m, x0 = _ball()
    curve = follow_curve(m, "fold", "amplitude", 1.5, 0.5, "r", (0.3, 0.7), x0=x0, period=1)
    a, r = curve.values("amplitude"), curve.values("r")
    assert r.min() == 0.3 and r.max() == 0.7 and len(curve) > 10
    np.testing.assert_allclose(a, math.pi * (1 - r) / (1 + r), atol=1e-7)
    assert np.all(np.diff(r) > 0) or np.all(np.diff(r) < 0)  # in order along the curve
    _condition_holds(curve, "fold")
    assert {p.impacts for p in curve.points} == {1} and curve.special == []
    assert curve.status.count("reached the bound r = ") == 2
    assert curve.outcomes == (CurveEnd.BOUND, CurveEnd.BOUND)


def test_bouncing_ball_period_doubling_curve_is_the_closed_form():
    m, x0 = _ball()
    curve = follow_curve(m, "period-doubling", "amplitude", 1.5, 3.0, "r", (0.3, 0.7), x0=x0, period=1)
    a, r = curve.values("amplitude"), curve.values("r")
    assert r.min() == 0.3 and r.max() == 0.7
    expected = np.sqrt((math.pi * (1 - r) / (1 + r)) ** 2 + (2 * (1 + r**2) / (1 + r) ** 2) ** 2)
    np.testing.assert_allclose(a, expected, atol=1e-7)
    _condition_holds(curve, "period-doubling")
    # the other multiplier: det = r^2
    np.testing.assert_allclose([np.prod(p.multipliers).real for p in curve.points], r**2, atol=1e-9)


def test_a_curve_in_the_parameter_that_sets_the_period():
    """The ball's fold in (amplitude, omega): A omega^2 / g = pi (1 - r) / (1 + r)."""
    m, x0 = _ball()
    curve = follow_curve(m, "fold", "amplitude", 1.5, 0.5, "omega", (0.8, 1.25), x0=x0, period=1)
    a, w = curve.values("amplitude"), curve.values("omega")
    assert w.min() == 0.8 and w.max() == 1.25
    np.testing.assert_allclose(a * w**2, math.pi / 3, atol=1e-7)


# --------------------------------------------------------------------------
# The pendulum's period-5 orbit (case B): its period-doubling curve in (eta, theta_hat)


def _one_parameter(model, param, start, stop, orbit, kind):
    branch = continue_orbit(model, param, start, stop, orbit=orbit)
    return [s.param for s in branch.special if s.kind == kind]


def test_pendulum_period_doubling_curve_passes_through_the_one_parameter_points(pendulum_period5):
    m = pendulum_period5.model
    curve = follow_curve(
        m,
        "period-doubling",
        "eta",
        0.446,
        0.44,
        "theta_hat",
        (39.8 * DEG, 40.2 * DEG),
        orbit=pendulum_period5,
    )
    assert curve.status.count("reached the bound theta_hat = ") == 2
    assert curve.outcomes == (CurveEnd.BOUND, CurveEnd.BOUND)
    th = curve.values("theta_hat")
    _condition_holds(curve, "period-doubling", tol=1e-6)
    for end in (0, -1):  # the curve lands exactly on the bounds: compare with continue_orbit there
        assert th[end] in (39.8 * DEG, 40.2 * DEG)
        p = curve.points[end]
        there = m.with_params(theta_hat=th[end])
        orbit = find_orbit(there.with_params(eta=0.446), p.state, period=5, t0=p.section_time)
        pds = _one_parameter(there, "eta", 0.446, 0.44, orbit, "period-doubling")
        assert pds and p.values[0] == pytest.approx(pds[0], abs=1e-7)
    # the start is the one-parameter point at 40 degrees
    assert curve.start is not None and curve.start.kind == "period-doubling"
    assert curve.points[curve.start_index].values[0] == pytest.approx(curve.start.param, abs=1e-8)


def test_pendulum_period_doubling_curve_ends_where_it_meets_the_grazing(pendulum_period5):
    """Below theta_hat ~ 35.905 deg the period-5 orbit loses its impact before it period-doubles.

    The curve ends at the grazing; there it is tangent to the grazing curve (the multipliers
    vary as the square root of the distance to it), so the gap between the one-parameter
    period-doubling and grazing values of eta vanishes quadratically: its square root is linear
    in theta_hat and its root is the codimension-two point."""
    m = pendulum_period5.model
    curve = follow_curve(
        m, "period-doubling", "eta", 0.446, 0.44, "theta_hat", (35.5 * DEG, 40 * DEG), orbit=pendulum_period5
    )
    assert curve.status.startswith("at the first point: ended at a grazing at eta = ")
    assert curve.outcomes[0] is CurveEnd.GRAZING
    (meet,) = curve.special
    assert meet.kind == "grazing" and meet.located and meet.index == 0
    assert meet.grazing is not None and meet.grazing.impacts == 0
    th = curve.values("theta_hat")
    gaps = []
    for deg in (35.95, 35.92):
        k = int(np.argmin(np.abs(th - deg * DEG)))
        p = curve.points[k]
        there = m.with_params(theta_hat=deg * DEG)
        orbit = find_orbit(there.with_params(eta=p.values[0] + 2e-4), p.state, period=5, t0=p.section_time)
        branch = continue_orbit(there, "eta", p.values[0] + 2e-4, 0.43, orbit=orbit)
        kinds = {s.kind: s.param for s in branch.special}
        gaps.append(kinds["period-doubling"] - kinds["grazing"])
    root_deg = 35.95 - math.sqrt(gaps[0]) * (35.95 - 35.92) / (math.sqrt(gaps[0]) - math.sqrt(gaps[1]))
    assert math.degrees(meet.values[1]) == pytest.approx(root_deg, abs=2e-3)
    # the limit of the condition vanishes there; the curve's last point is next to it
    assert abs(limit_condition("period-doubling", meet.grazing, loses=True)) < 1e-8
    assert abs(curve.points[0].values[1] - meet.values[1]) < 1e-4


# --------------------------------------------------------------------------
# The linear impact oscillator: folds of the impacting period-1 orbit, and its grazing curve


def _closed_form_fold(sigma: float, v: float, w: float, phase: float) -> float:
    """The fold frequency of the closed-form orbit at ``sigma``: the extreme frequency of its branch of
    impacting orbits, parametrised by the impact phase (as in ``test_closed_forms``), near ``phase``."""
    residual = _impacting_orbit_closed_form(sigma)
    guess = [v, w]

    def omega(ph: float) -> float:
        sol = root(lambda z: residual(z[0], z[1], ph), guess, tol=1e-15)
        return float(sol.x[1])

    side = 1.0 if omega(phase + 0.01) + omega(phase - 0.01) < 2 * omega(phase) else -1.0  # a maximum?
    best = minimize_scalar(
        lambda ph: -side * omega(ph), bracket=(phase - 0.05, phase, phase + 0.05), tol=1e-12
    )
    return -side * float(best.fun)


def test_impact_oscillator_fold_curve_is_the_closed_form():
    m = impact_oscillator(zeta=ZETA, sigma=0.5, r=REST)
    orbit = find_orbit(m.with_params(omega=1.5), period=1, t0=None)
    curve = follow_curve(m, "fold", "omega", 1.5, 2.5, "sigma", (0.4, 0.8), orbit=orbit)
    sig = curve.values("sigma")
    assert sig.min() == pytest.approx(0.4, abs=1e-12) and sig.max() == pytest.approx(0.8, abs=1e-12)
    _condition_holds(curve, "fold", tol=1e-6)
    for p in curve.points[:: max(1, len(curve) // 6)]:
        o = p.orbit
        w, s = p.values
        t_imp = o.impact_times[0] % (2 * math.pi / w)
        assert w == pytest.approx(_closed_form_fold(s, o.impact_speeds[0], w, t_imp * w), abs=1e-7)


def test_impact_oscillator_grazing_curve_of_the_impacting_orbit_is_the_closed_form():
    """The impacting orbit loses its impact where the nonimpacting response grazes: sigma = A(omega)."""
    m = impact_oscillator(zeta=ZETA, sigma=0.5, r=REST)
    orbit = find_orbit(m.with_params(omega=1.5), period=1, t0=None)
    curve = follow_curve(m, "grazing", "omega", 1.5, 2.5, "sigma", (0.4, 0.6), orbit=orbit)
    w, s = curve.values("omega"), curve.values("sigma")
    assert s.min() == pytest.approx(0.4) and s.max() == pytest.approx(0.6)
    np.testing.assert_allclose(s, [oscillator_amplitude(x) for x in w], atol=1e-9)
    for p in curve.points:  # the contact: on the stop, at zero normal speed
        assert abs(p.grazing.model.guard(p.state, p.grazing.t_graze)) < 1e-10 and abs(p.state[1]) < 1e-9
        assert p.grazing.accel > 0


# --------------------------------------------------------------------------
# Neimark-Sacker curves: the forced van der Pol oscillator (2 states) and the impact damper (4 states)


def _van_der_pol():
    x, v, t = sp.symbols("x v t")
    eps, F, w = sp.symbols("eps F w")
    return grazing.HybridModel(
        "van-der-pol", [x, v], t,
        [grazing.Parameter("eps", 0.2), grazing.Parameter("F", 1.0),
         grazing.Parameter("w", 1.15, lower=0, lower_open=True)],
        vector_field=[v, eps * (1 - x**2) * v - x + F * sp.cos(w * t)],
        guard=10 - x, reset=[x, -v], period=2 * sp.pi / w,
    )  # fmt: skip


def test_neimark_sacker_curve_its_resonances_and_its_end():
    vdp = _van_der_pol()
    curve = follow_curve(vdp, "neimark-sacker", "F", 1.0, 0.1, "w", (0.8, 1.5), period=1)
    assert curve.virtual
    _condition_holds(curve, "neimark-sacker", tol=1e-8)
    kinds = [s.kind for s in curve.special]
    assert kinds[0] == "1:1 resonance" and "1:4 resonance" in kinds
    r11 = curve.special[0]
    assert r11.index == 0 and curve.points[0].values == r11.values  # the curve ends there
    np.testing.assert_allclose(r11.multipliers, [1, 1], atol=1e-4)  # a double multiplier: ~sqrt(tol)
    assert curve.status.startswith("at the first point: ended at a 1:1 resonance")
    assert curve.outcomes == (CurveEnd.RESONANCE_1_1, CurveEnd.BOUND)  # (the other end on w's bound)
    r14 = next(s for s in curve.special if s.kind == "1:4 resonance")
    np.testing.assert_allclose(np.sort_complex(r14.multipliers), [-1j, 1j], atol=1e-8)
    # at the other end (w = 1.5, on the bound) the one-parameter continuation finds it too
    end = curve.points[-1]
    assert end.values[1] == 1.5
    there = vdp.with_params(w=1.5)
    orbit = find_orbit(there.with_params(F=end.values[0] + 0.05), end.state, period=1, virtual=True)
    ns = _one_parameter(there, "F", end.values[0] + 0.05, 0.1, orbit, "neimark-sacker")
    assert ns and end.values[0] == pytest.approx(ns[0], abs=1e-7)


def _pair_modulus(model, state, t0):
    orbit = find_orbit(model, state, period=1, t0=t0)
    mu = orbit.multipliers
    return float(np.max(np.abs(mu[np.abs(mu.imag) > 1e-9]))) - 1.0, orbit


def test_neimark_sacker_curve_of_an_impacting_four_state_orbit(damper_orbit):
    """The bialternate product on four states: the impact damper's impacting orbit near omega = 1.408."""
    m = damper_orbit.model
    branch = continue_orbit(m, "omega", 1.2, 1.45, orbit=damper_orbit)
    modulus = [_pair_modulus(o.model, o.state, o.t0)[0] for o in branch.orbits]
    k = next(i for i in range(len(modulus) - 1) if modulus[i] < 0 < modulus[i + 1])
    start = branch.orbits[k]  # next to the Neimark-Sacker point: the curve's first Newton solve finds it
    curve = _follow_from(m, "neimark-sacker", ("omega", "mu"), (0.28, 0.32), start, False, 0, PalcSettings())
    _condition_holds(curve, "neimark-sacker", tol=1e-8)
    mus = curve.values("mu")
    assert mus.min() == pytest.approx(0.28) and mus.max() == pytest.approx(0.32)
    assert {p.impacts for p in curve.points} == {2}
    # independent check at both ends: the pair's modulus is 1 at the curve's omega (root in omega)
    for p in (curve.points[0], curve.points[-1]):
        w, mu_ = p.values
        there = m.with_params(mu=mu_)

        def modulus(x, there=there, p=p):
            return _pair_modulus(there.with_params(omega=x), p.state, p.section_time)[0]

        found = brentq(modulus, w - 2e-3, w + 2e-3, xtol=1e-13)
        assert w == pytest.approx(found, abs=1e-7)


# --------------------------------------------------------------------------
# Branch points: the symmetric orbit of the oscillator between two equal stops


def test_branch_point_curve_of_a_symmetric_orbit():
    """x -> -x, t -> t + T/2 maps the two-sided oscillator to itself; its symmetric period-1 orbit (one
    impact on each stop) loses its symmetry where a multiplier passes +1 while omega keeps increasing:
    a branch point, which persists in (omega, amp).  The one-parameter continuation locates it at the
    curve's ends (reported as a fold until it tells branch points apart)."""
    m = two_sided_oscillator(amp=2.0, omega=1.0, zeta=0.05, r=0.8)
    orbit = find_orbit(m, period=1, t0=None)
    branch = continue_orbit(m, "omega", 1.0, 1.2, orbit=orbit)
    (bp,) = [s for s in branch.special if s.kind in ("fold", "branch point")]
    k = bp.index
    assert branch.values[k - 1] < branch.values[k] < branch.values[k + 1] < branch.values[k + 2]  # no turn
    curve = _follow_from(m, "branch-point", ("omega", "amp"), (1.5, 3.0), bp.orbit, False, 0, PalcSettings())
    amp = curve.values("amp")
    assert amp.min() == 1.5 and amp.max() == 3.0
    _condition_holds(curve, "fold", tol=1e-8)
    for p in (curve.points[0], curve.points[-1]):
        w, a = p.values
        there = m.with_params(amp=a)
        o = find_orbit(there.with_params(omega=w - 0.01), p.state, period=1, t0=p.section_time)
        b = continue_orbit(there, "omega", w - 0.01, w + 0.01, orbit=o)
        found = [s.param for s in b.special if s.kind in ("fold", "branch point")]
        assert found and w == pytest.approx(found[0], abs=1e-7)
        assert np.all(np.diff(b.values) > 0)  # omega does not turn: a branch point, not a fold
        # the orbit is symmetric: half a period later its state is reflected
        T = 2 * math.pi / w
        phase = 2 * math.pi * ((p.section_time + T / 2) / T % 1.0)
        half = grazing.simulate(p.orbit.model, p.state, t0=p.section_time, periods=1, phase=phase)
        np.testing.assert_allclose(half.samples[0], -p.state, atol=1e-9)


@pytest.mark.skipif(
    "branch point" not in SPECIAL_KINDS, reason="continue_orbit does not report branch points"
)
def test_branch_point_curve_from_the_command_of_one_parameter():
    m = two_sided_oscillator(amp=2.0, omega=1.0, zeta=0.05, r=0.8)
    curve = follow_curve(m, "branch-point", "omega", 1.0, 1.2, "amp", (1.8, 2.2), period=1)
    assert curve.start is not None and curve.start.kind == "branch point"
    _condition_holds(curve, "fold", tol=1e-8)


# --------------------------------------------------------------------------
# Random models: names, stops, a frequency that sets the period


def _first_curve(spec: ModelSpec, kind: str, width: float = 0.02):
    """The first ``kind`` met continuing the amplitude down or up, followed in (amplitude, frequency)."""
    orbit = _random_orbit(spec)
    m = orbit.model
    amplitude, frequency = spec.param_names[2], spec.param_names[3]
    a0, w0 = m.params[amplitude], m.params[frequency]
    for end in (0.3 * a0, 2.5 * a0):
        try:
            return follow_curve(
                m, kind, amplitude, a0, end, frequency, (w0 * (1 - width), w0 * (1 + width)), orbit=orbit
            )
        except NotFoundError:
            continue
    return None


def _ends_agree(curve: BifurcationCurve, kind: str, step: float = 1e-3) -> None:
    """At the curve's start and at its ends on a bound the one-parameter continuation finds the point
    (to 1e-7): the orbit there is continued a little away in the first parameter, then back across
    it.  (An end at a grazing is left out: near it the point and the grazing are closer than a
    continuation step.)"""
    m = curve.model
    p1, p2 = curve.params
    first, last = curve.status.split("; at the last point: ")
    points = [curve.points[curve.start_index]]
    points += [curve.points[0]] if "reached the bound" in first else []
    points += [curve.points[-1]] if "reached the bound" in last else []
    for p in points:
        assert _found_by_one_parameter(m.with_params(**{p2: p.values[1]}), p1, p, kind, step), p.values


def _found_by_one_parameter(there, p1: str, p, kind: str, step: float) -> bool:
    """Is the point ``p`` of a curve found (to 1e-7) by continuing its orbit a step away in ``p1`` and back
    across it?  Steps shrink where a grazing is closer than the step."""
    v = p.values[0]
    for size in (step, step / 10, step / 100, step / 1000):
        for side in (1, -1):
            away = continue_orbit(there, p1, v, v + side * size, orbit=p.orbit)
            if abs(away.values[-1] - v) < 0.5 * size:
                continue  # (it turned at a fold, or ended at a grazing)
            back = continue_orbit(there, p1, away.values[-1], v - side * size, orbit=away.orbits[-1])
            found = [s.param for s in back.special if s.kind == kind]
            if found:
                assert v == pytest.approx(found[0], abs=1e-7)
                return True
    return False


NEAR_GRAZING_FOLD = ModelSpec(
    names=NAMES, dof=1, damping=0.17155447956349493, stiffness=0.8536677151504607, amplitude=1.0,
    omega=0.765625, stop_fraction=0.6875, restitution=0.5, coupling=1.0, cubic=0.2,
)  # fmt: skip
"""A random model whose fold curve in (amplitude, frequency) ends at a grazing (found by hypothesis)."""


def test_a_curve_near_a_grazing_reports_how_well_its_multipliers_are_known():
    """The fold curve ends at a grazing, where the impact speed v tends to zero: the monodromy is far
    from normal there (its norm and the condition number of its multiplier 1 grow like 1 / v), so a
    Newton tolerance of 1e-10 on the bordered condition bounds the multiplier only to ~1e-6, and a
    rounding-level change of the point moves it by ~1e-5.  The points say so (``accuracy``); away
    from the grazing it is ~1e-10 or better.  The condition number against the eigenvectors of numpy."""
    curve = _first_curve(NEAR_GRAZING_FOLD, "fold")
    assert curve.status.startswith("at the first point: ended at a grazing")
    _condition_holds(curve, "fold", tol=1e-6)
    speeds = np.array([p.orbit.min_impact_speed for p in curve.points])
    accuracy = np.array([p.accuracy for p in curve.points])
    assert accuracy[0] > 1e-6 and speeds[0] < 1e-4  # the last point before the grazing
    assert np.all(accuracy[speeds > 1e-2] < 1e-9)
    for p in (curve.points[0], curve.points[-1]):
        M = p.orbit.monodromy
        mu, right = np.linalg.eig(M)
        k = int(np.argmin(np.abs(mu - 1)))
        left = np.linalg.inv(right)[k]  # the left eigenvector (a row of V^-1)
        kappa = np.linalg.norm(left) * np.linalg.norm(right[:, k]) / abs(left @ right[:, k])
        sol = bordered(M - np.eye(2), Borders.of(M - np.eye(2)))
        assert sol.eigenvalue_condition == pytest.approx(kappa, rel=1e-3)
    assert curve.to_dataset().accuracy.values[0] == accuracy[0]


NEAR_GRAZING_PD = dataclasses.replace(NEAR_GRAZING_FOLD, amplitude=0.9999999999999999, omega=0.78125)
"""The same model elsewhere: its period-doubling curve in (amplitude, frequency) ends at a grazing."""


def _damper_neimark_sacker_curve() -> BifurcationCurve:
    """The impact damper's Neimark-Sacker curve in (omega, r) (4 states, two impacts a period)."""
    m = impact_damper(mu=0.3, r=0.8)
    return follow_curve(m, "neimark-sacker", "omega", 1.2, 1.45, "r", (0.7, 0.9))


@pytest.mark.parametrize(
    ("curve_of", "kind"),
    [
        (lambda: _first_curve(NEAR_GRAZING_FOLD, "fold"), "fold"),
        (lambda: _first_curve(NEAR_GRAZING_PD, "period-doubling"), "period-doubling"),
        (_damper_neimark_sacker_curve, "neimark-sacker"),
    ],
    ids=["fold to a grazing", "period-doubling to a grazing", "neimark-sacker on 4 states"],
)
def test_curve_accuracy_is_an_estimate_of_the_rounding_scatter(curve_of, kind):
    """At every point, from 1e-3 of the condition's scale down to 1e-14, the reported accuracy is within
    ten times, either way, of what rounding-level changes of the point do to its critical multipliers
    (or of their own distance from the condition, where Newton's residual is larger): near a grazing,
    where both grow like ``1 / v``, and away from it, on a fold and a period-doubling curve that end at
    a grazing and on a 4-state Neimark-Sacker curve (the bialternate product)."""
    curve = curve_of()
    assert curve is not None and len(curve) > 5
    accuracy = np.array([p.accuracy for p in curve.points])
    if kind != "neimark-sacker":
        assert curve.status.count("ended at a grazing") == 1
        assert accuracy.max() > 1e3 * accuracy.min()  # the curve spans orders of magnitude of it
    _condition_holds(curve, kind, tol=1e-6, every_point=True)


@pytest.mark.parametrize(("spec", "kind"), [(SPEC_1, "fold"), (SPEC_2, "period-doubling")])
def test_random_model_curves_in_amplitude_and_the_period_setting_frequency(spec, kind):
    curve = _first_curve(spec, kind)
    assert curve is not None
    _condition_holds(curve, kind, tol=1e-6)
    assert len({p.impacts for p in curve.points}) == 1
    _ends_agree(curve, kind)


@pytest.mark.slow
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(spec=model_specs())
@example(  # a fold curve that ends on its range's bound 1e-4 from a grazing (the check's steps shrink there)
    spec=ModelSpec(
        names=NAMES, dof=2, damping=0.046875, stiffness=1.984375, amplitude=1.0, omega=0.75,
        stop_fraction=0.375, restitution=0.5, coupling=1.0, cubic=0.0,
    )
)  # fmt: skip
@example(  # a fold curve that ends on its range's bound 5e-6 from a grazing (the check's steps go to 1e-6)
    spec=ModelSpec(
        names=NAMES, dof=1, damping=0.17811286503998547, stiffness=1.0631102851401786, amplitude=0.5,
        omega=2.00001, stop_fraction=0.5, restitution=0.5, coupling=0.5047989912168046, cubic=0.0,
        smooth="log",
    )
)  # fmt: skip
@example(spec=NEAR_GRAZING_FOLD)  # fold points 4e-6 from a grazing: multipliers known only to ~1e-5
@example(  # a fold curve to a grazing (the old accuracy, kappa 64 eps |M|, was 346 times the scatter)
    spec=ModelSpec(
        names=NAMES, dof=1, damping=0.16667393152116802, stiffness=1.4465846495510322,
        amplitude=0.5809758631410941, omega=2.4375, stop_fraction=0.35563660016569304, restitution=0.75,
        coupling=1.0, cubic=0.0, smooth="variable power",
    )
)  # fmt: skip
@example(  # a period-doubling curve to a grazing whose multipliers the monodromy's own rounding moves most
    spec=ModelSpec(
        names=NAMES, dof=2, damping=0.14052204306941454, stiffness=1.7138884929527194,
        amplitude=0.49376899991608614, omega=1.4317670648653116, stop_fraction=0.446,
        restitution=0.9005274503875389, coupling=0.13542694335164107, cubic=0.2, smooth="atan",
    )
)  # fmt: skip
@example(  # a period-doubling curve whose last point is within rounding of a grazing (draws gain an impact)
    spec=ModelSpec(
        names=NAMES, dof=2, damping=0.031523306207345156, stiffness=1.6531696955905637,
        amplitude=0.878864430955997, omega=0.878864430955997, stop_fraction=0.3, restitution=0.5,
        coupling=0.8068822871676186, cubic=0.0, smooth="real power",
    )
)  # fmt: skip
@example(spec=NEAR_GRAZING_PD)  # a PD's
def test_random_models_fold_and_period_doubling_curves(spec):
    try:
        _random_orbit(spec)
    except grazing.GrazingError:
        assume(False)
    done = 0
    for kind in ("fold", "period-doubling"):
        try:
            curve = _first_curve(spec, kind)
        except grazing.GrazingError:
            continue  # (a continuation that fails on the way: another test's business)
        if curve is None or len(curve) < 3:
            continue
        _condition_holds(curve, kind, tol=1e-6, every_point=True)
        _ends_agree(curve, kind)
        done += 1
    assume(done)


# --------------------------------------------------------------------------
# The record, the dataset, bad input


def test_curve_dataset_and_netcdf(tmp_path):
    import xarray as xr

    m, x0 = _ball()
    curve = follow_curve(m, "fold", "amplitude", 1.5, 0.5, "r", (0.45, 0.55), x0=x0, period=1)
    ds = curve.to_dataset()
    assert ds.attrs["kind"] == "fold" and ds.attrs["params"] == "amplitude,r"
    assert ds.param1.attrs["long_name"] == "amplitude" and ds.sizes["point"] == len(curve)
    np.testing.assert_array_equal(ds.param2.values, curve.values("r"))
    assert ds.attrs["param_gravity"] == 1.0 and "param_r" not in ds.attrs
    path = tmp_path / "c.nc"
    curve.to_netcdf(path)
    with xr.open_dataset(path) as back:
        np.testing.assert_array_equal(back.param1.values, curve.values("amplitude"))
        assert back.attrs["status"] == curve.status
        assert back.attrs["outcomes"] == "bound,bound" and type(ds.attrs["outcomes"]) is str


def test_bad_input_is_refused_before_any_work():
    m, x0 = _ball()
    with pytest.raises(InvalidParameterError, match="unknown curve kind 'flip'"):
        follow_curve(m, "flip", "amplitude", 1.5, 0.5, "r", (0.4, 0.6))
    with pytest.raises(InvalidParameterError, match="must differ"):
        follow_curve(m, "fold", "amplitude", 1.5, 0.5, "amplitude", (0.4, 0.6))
    with pytest.raises(
        InvalidParameterError, match=r"the range r in \[0.6, 0.7\] excludes the start value r = 0.5"
    ):
        follow_curve(m, "fold", "amplitude", 1.5, 0.5, "r", (0.6, 0.7))
    with pytest.raises(NotFoundError, match=r"no period-doubling .* met fold at amplitude = 1.0471976"):
        follow_curve(m, "period-doubling", "amplitude", 1.5, 0.5, "r", (0.4, 0.6), x0=x0, period=1)


# --------------------------------------------------------------------------
# A cusp, and the grazing of a nonimpacting orbit along its fold curve


def _duffing(stop: float):
    x, v, t = sp.symbols("x v t")
    c, k, A, w, s = sp.symbols("c k A w s")
    return grazing.HybridModel(
        "duffing", [x, v], t,
        [grazing.Parameter("c", 0.1), grazing.Parameter("k", 0.5), grazing.Parameter("A", 0.5),
         grazing.Parameter("w", 1.0, lower=0, lower_open=True), grazing.Parameter("s", stop)],
        vector_field=[v, -c * v - x - k * x**3 + A * sp.cos(w * t)], guard=s - x, reset=[x, -0.8 * v],
        period=2 * sp.pi / w,
    )  # fmt: skip


def test_fold_curve_through_its_cusp_and_a_grazing_of_the_nonimpacting_orbit():
    """The hardening Duffing oscillator's two folds of its response curve meet in a cusp; the orbit
    (followed with the stop ignored) touches the stop at x = 1.8 somewhere along the curve."""
    m = _duffing(1.8)
    curve = follow_curve(m, "fold", "w", 0.8, 2.5, "A", (0.05, 0.8), period=1)
    assert curve.virtual and curve.status.count("reached the bound A = 0.8") == 2  # over the cusp and back
    _condition_holds(curve, "fold", tol=1e-7)
    kinds = [s.kind for s in curve.special]
    assert kinds == ["cusp", "grazing"] or kinds == ["grazing", "cusp"]
    cusp = curve.special[kinds.index("cusp")]
    a_c = cusp.values[1]
    for factor, folds in ((1.02, 2), (0.98, 0)):  # two folds just above the cusp, none below
        b = continue_orbit(m.with_params(A=a_c * factor), "w", 0.8, 2.5, period=1, virtual=True)
        assert [s.kind for s in b.special if s.kind != "grazing"] == ["fold"] * folds
    touch = curve.special[kinds.index("grazing")]
    assert touch.located and touch.grazing is not None
    np.testing.assert_allclose(touch.state, [1.8, 0.0], atol=1e-10)  # on the stop, at zero speed
    assert np.min(np.abs(touch.multipliers - 1)) < 1e-7  # a fold orbit: the curves meet there


# --------------------------------------------------------------------------
# Grazing curves from a nonimpacting orbit and from an impacting one


@pytest.mark.parametrize("start", ["nonimpacting", "impacting"])
def test_pendulum_grazing_curves_agree_with_the_one_parameter_grazings(start, pendulum_period5):
    """The period-1 nonimpacting orbit grazes where the period-5 orbit loses its one impact (eta ~ 0.4451 at
    40 deg): both grazing curves are the grazing of the nonimpacting orbit (find_grazings)."""
    m = pendulum_period5.model
    if start == "nonimpacting":
        curve = follow_curve(m, "grazing", "eta", 0.40, 0.5, "theta_hat", (39 * DEG, 41 * DEG), period=1)
        assert curve.virtual and curve.period == 1
    else:
        curve = follow_curve(m, "grazing", "eta", 0.446, 0.44, "theta_hat", (39 * DEG, 41 * DEG),
                             orbit=pendulum_period5)  # fmt: skip
        assert not curve.virtual and curve.period == 5 and curve.start.grazing.impacts == 0
    th = curve.values("theta_hat")
    assert th.min() == 39 * DEG and th.max() == 41 * DEG
    for p in (curve.points[0], curve.points[-1]):
        points, _ = find_grazings(m.with_params(theta_hat=p.values[1]), "eta", 0.40, 0.5)
        assert p.values[0] == pytest.approx(points[0].model.params["eta"], abs=1e-9)
        assert abs(p.condition) < 1e-10 and p.grazing.accel > 0


@pytest.mark.parametrize(
    ("kind", "before", "after", "changed"),
    [
        ("fold", [1.0, 0.9], [1.0, 1.1], "1:1 resonance"),
        ("fold", [1.0, -0.9], [1.0, -1.1], "fold-flip"),
        (
            "fold",
            [1.0, 0.2, 0.5 + 0.8j, 0.5 - 0.8j],
            [1.0, 0.2, 0.6 + 0.85j, 0.6 - 0.85j],
            "fold-neimark-sacker",
        ),
        ("period-doubling", [-1.0, 0.9], [-1.0, 1.1], "fold-flip"),
        ("period-doubling", [-1.0, -0.9], [-1.0, -1.1], "1:2 resonance"),
        ("neimark-sacker", [0.9 + 0.43589j, 0.9 - 0.43589j], [1.1, 1 / 1.1], "1:1 resonance"),
        ("neimark-sacker", [-0.9 + 0.43589j, -0.9 - 0.43589j], [-1.1, -1 / 1.1], "1:2 resonance"),
        (
            "neimark-sacker",
            [0.1 + 0.99499j, 0.1 - 0.99499j],
            [-0.1 + 0.99499j, -0.1 - 0.99499j],
            "1:4 resonance",
        ),
        ("neimark-sacker", [-0.4 + 0.91652j, -0.4 - 0.91652j], [-0.6 + 0.8j, -0.6 - 0.8j], "1:3 resonance"),
        (
            "neimark-sacker",
            [0.6 + 0.8j, 0.6 - 0.8j, 0.9, 0.1],
            [0.6 + 0.8j, 0.6 - 0.8j, 1.1, 0.1],
            "fold-neimark-sacker",
        ),
        (
            "neimark-sacker",
            [0.6 + 0.8j, 0.6 - 0.8j, -0.9, 0.1],
            [0.6 + 0.8j, 0.6 - 0.8j, -1.1, 0.1],
            "flip-neimark-sacker",
        ),
        ("grazing", [0.5, 0.9], [0.5, 1.1], "fold"),
        ("grazing", [0.5, -0.9], [0.5, -1.1], "period-doubling"),
    ],
)
def test_each_codimension_two_test_function_changes_sign_at_its_own_point_only(kind, before, after, changed):
    from grazing.orbits.extended import CODIM2_TESTS, codim2_tests

    a = codim2_tests(kind, np.array(before, dtype=complex), cusp=1.0)
    b = codim2_tests(kind, np.array(after, dtype=complex), cusp=1.0)
    assert set(a) == set(CODIM2_TESTS[kind])
    flipped = {
        name
        for name in a
        if not (math.isnan(a[name]) or math.isnan(b[name])) and (a[name] > 0) != (b[name] > 0)
    }
    assert flipped == {changed}


def _one_sided_where_needed(system, u: np.ndarray) -> np.ndarray:
    """Central differences of ``system``'s equations, one-sided where a step leaves its domain (a contact
    state moved beyond its stop)."""
    F0 = system(u)[0]
    cols = []
    for k in range(u.size):
        h = 1e-6 * max(1.0, abs(u[k]))
        e = np.zeros(u.size)
        e[k] = h
        try:
            plus = system(u + e)[0]
        except grazing.GrazingError:
            plus = None
        try:
            minus = system(u - e)[0]
        except grazing.GrazingError:
            minus = None
        if plus is not None and minus is not None:
            cols.append((plus - minus) / (2 * h))
        else:
            cols.append((plus - F0) / h if plus is not None else (F0 - minus) / h)
    return np.array(cols).T


@pytest.mark.parametrize("case", ["nonimpacting pendulum", "impacting two-sided oscillator"])
def test_grazing_system_jacobian_in_two_parameters(case):
    """The contact equations in two parameters, for a grazing orbit without other impacts (the flow with
    the stops ignored) and for one with an impact on the other stop (the flow with its impacts; omega
    sets the period)."""
    from grazing.orbits.extended import GrazingSystem

    if case == "nonimpacting pendulum":
        m = grazing.models.pendulum("B", theta_hat=math.radians(40))
        points, _ = find_grazings(m, "eta", 0.4, 0.5)
        point, params = points[0], ("eta", "theta_hat")
    else:
        m = two_sided_oscillator(amp=0.5, gap_left=1.5)
        branch = continue_orbit(m, "omega", 1.1, 1.35, period=1)
        (sp_,) = [s for s in branch.special if s.kind == "grazing"]
        point, params = sp_.grazing, ("omega", "amp")
        assert point.impacts == 1 and point.stop_name == "left"
    system = GrazingSystem(m, params, point.period, point.impacts > 0, point.stop)
    u = system.start(point)
    F, DF, _ = system(u)
    assert np.max(np.abs(F)) < 1e-10
    fd = _one_sided_where_needed(system, u)
    for row, fd_row in zip(DF, fd):
        assert np.max(np.abs(row - fd_row)) <= 1e-5 * max(1.0, float(np.max(np.abs(fd_row)))), (row, fd_row)


def test_grazing_curve_meets_a_fold_and_ends_at_a_double_grazing():
    """The oscillator between two stops, on its orbit with one impact on the right stop that grazes the
    left one: along the grazing curve in (omega, amp) the grazing orbit passes a fold (a multiplier +1),
    and at low omega it comes to touch the right stop in free flight as well: a double grazing, where
    the curve ends (the contact equations fail past it)."""
    from grazing.orbits.curves import DOUBLE_GRAZING_MARGIN

    m = two_sided_oscillator(amp=0.5, gap_left=1.5)
    curve = follow_curve(m, "grazing", "omega", 1.1, 1.35, "amp", (0.1, 2.0), period=1)
    assert [s.kind for s in curve.special] == ["fold", "double grazing"]
    fold, double = curve.special
    assert fold.located and np.min(np.abs(fold.multipliers - 1)) < 1e-7
    assert not double.located and double.index == len(curve) - 1
    assert curve.status.endswith("a double grazing, located from this side)")
    assert curve.outcomes[1] is CurveEnd.DOUBLE_GRAZING
    last = curve.points[-1].grazing
    h_right = last.approach_by_stop[0][0]  # the right stop's closest approach in free flight
    assert 0 <= h_right < DOUBLE_GRAZING_MARGIN and last.impacts == 1 and last.stop_name == "left"
    _condition_holds(curve, "grazing")


def test_the_gradient_is_one_sided_where_a_step_leaves_the_domain():
    from grazing.errors import GrazingError
    from grazing.orbits.crossings import _gradient

    for side in (1.0, -1.0):  # (the domain ends at u0 = 1 above, then below)

        def f(u, side=side):
            if side * (u[0] - 1.0) > 0:  # (beyond the stop)
                raise GrazingError("beyond the stop")
            return float(u[0] ** 2 + 3 * u[1])

        u = np.array([1.0, 2.0])
        np.testing.assert_allclose(_gradient(f, u, f(u)), [2.0, 3.0], rtol=1e-5)


def test_a_branch_point_curve_ends_at_once_where_the_second_parameter_breaks_the_symmetry():
    # The two-sided oscillator is symmetric only with equal gaps: in (omega, gap_right) its branch point
    # does not persist, and the regularising shift grows like the asymmetry (7.6e-3 where gap_right is
    # 0.004 from the other gap) — far above SHIFT_TOL, far below anything the curve could go on with.
    from grazing.orbits.curves import SHIFT_TOL

    m = two_sided_oscillator(amp=2.0, omega=1.0, zeta=0.05, r=0.8)
    curve = follow_curve(m, "branch-point", "omega", 1.0, 1.2, "gap_right", (0.95, 1.05), period=1)
    assert len(curve.points) == 1 and curve.points[0].values[1] == 1.0
    first, last = curve.status.split("; at the last point: ")
    assert curve.outcomes == (CurveEnd.NOT_PERSISTENT, CurveEnd.NOT_PERSISTENT)
    for end in (first, last):
        assert "does not persist in two parameters" in end
        shift = float(end.split("shift = ")[1].split(" ")[0])
        assert SHIFT_TOL < abs(shift) < 0.1


def test_the_margin_to_another_contact_leaves_out_the_grazing_contact_itself():
    # A grazing orbit's own contact is a closest approach at h = 0 on the stop it grazes: not another
    # contact. The margin is the other stop's approach (0.3), not zero.
    from types import SimpleNamespace

    from grazing.orbits.curves import _other_contact_margin

    model = grazing.models.two_sided_oscillator()
    for stop in (0, 1):
        for lag in (0.0, 1e-9, -1e-9):  # (the contact's own approach, found to rounding of its time)
            point = SimpleNamespace(
                model=model, other_impacts=None, stop=stop, t_graze=1.0, period=1,
                approach_by_stop=tuple(
                    (0.0, 1.0 + lag, np.zeros(2)) if j == stop else (0.3, 2.0, np.zeros(2)) for j in range(2)
                ),
            )  # fmt: skip
            assert _other_contact_margin(point) == pytest.approx(0.3)


def test_a_difference_step_that_changes_the_impact_count_is_refused_either_way():
    # The monodromy's derivatives are differences of the map's Jacobian: a step across a grazing (an impact
    # more or fewer than the point's) is no derivative, and is refused.
    from grazing.errors import ConvergenceError
    from grazing.models import impact_oscillator
    from grazing.orbits.extended import OrbitSystem

    m = impact_oscillator(omega=0.8)
    orbit = find_orbit(m)
    system = OrbitSystem(m, "fold", ("omega", "r"), 1, orbit.t0, False, 0, orbit.monodromy)
    p = np.array([0.8, m.params["r"]])
    assert system.jacobian(orbit.state, p, orbit.impacts).shape == (2, 4)
    for other in (orbit.impacts - 1, orbit.impacts + 1):
        with pytest.raises(ConvergenceError, match="crosses a grazing"):
            system.jacobian(orbit.state, p, other)
