"""Event-driven simulation: closed forms, invariants, finite differences, references."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import grazing
from grazing import InvalidParameterError, InvalidStateError, SimulationError
from grazing.engine import simulate as simulate_module
from grazing.models import bouncing_ball, impact_oscillator, pendulum, two_sided_oscillator
from tests.far_stop import far_stop_swing, orbit_state

# --------------------------------------------------------------------------
# Closed forms: a ball on a fixed floor, released from rest at height 1.


def test_ball_on_fixed_floor_impact_times_and_accumulation():
    g, r, y0 = 1.0, 0.5, 1.0
    m = bouncing_ball(amplitude=0.0, gravity=g, r=r, omega=1.0)
    sol = grazing.simulate(m, [y0, 0.0], periods=2)
    t1 = math.sqrt(2 * y0 / g)
    v1 = g * t1
    n = len(sol.impacts)
    expected_t = t1 + np.concatenate([[0.0], np.cumsum([2 * r**k * v1 / g for k in range(1, n)])])
    expected_v = v1 * r ** np.arange(n)
    assert n >= 25  # bounces until the remaining chatter is shorter than 1e-9 periods
    np.testing.assert_allclose(sol.impacts.t, expected_t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(sol.impacts.speed, expected_v, rtol=1e-12, atol=1e-15)
    # Complete chattering: summed in closed form, then sticking to the floor.
    t_acc = t1 + 2 * r * v1 / (g * (1 - r))
    assert sol.sticking.shape == (1, 2)
    assert sol.sticking[0, 0] == pytest.approx(t_acc, abs=1e-12)
    assert sol.sticking[0, 1] == pytest.approx(4 * math.pi, abs=1e-12)
    np.testing.assert_allclose(sol.samples, 0.0, atol=1e-15)


def test_ball_released_when_table_acceleration_exceeds_gravity():
    """Sticking ends when A w^2 sin(w t) = g, i.e. at w t = asin(g / (A w^2)) mod 2 pi."""
    amplitude = 1.2
    m = bouncing_ball(amplitude=amplitude, omega=1.0, gravity=1.0, r=0.5)
    sol = grazing.simulate(m, [0.0, 0.0], transient=3, periods=10)
    # The recorded span (from the last transient sample, t = 3T) starts while the ball
    # rides on the table: that interval is reported from the span's start, then one
    # chatter-stick-release cycle per period.
    assert len(sol.sticking) == 11
    assert sol.sticking[0, 0] == pytest.approx(3 * 2 * math.pi, abs=1e-12)
    releases = sol.sticking[:, 1][sol.sticking[:, 1] < sol.t_final - 1e-9]  # the last is cut by the end
    assert len(releases) == 10
    phase = np.mod(releases, 2 * math.pi)
    np.testing.assert_allclose(phase, math.asin(1 / amplitude), atol=1e-10)


def test_no_impact_redetected_after_reset(pendulum_b):
    """Every impact is followed by a finite flight: no zero-time re-detection."""
    sol = grazing.simulate(pendulum_b, [0.0, 0.0], transient=100, periods=200)
    gaps = np.diff(sol.impacts.t)
    assert len(sol.impacts) > 10
    assert gaps.min() > 1.0


# --------------------------------------------------------------------------
# Shallow impacts: the stop d below the maximum of a nonimpacting orbit.


@pytest.fixture(scope="module")
def period1_orbit():
    """Period-1 nonimpacting orbit of case B at eta = 0.445 and its maximum angle."""
    free = pendulum("B", eta=0.445, theta_hat=3.0)  # the stop out of reach
    sol = grazing.simulate(free, [0.0, 0.0], transient=200, periods=1, guard_min=True)
    x0, t0 = sol.samples[-1], sol.t[-1]
    again = grazing.simulate(free, x0, t0=t0, periods=1, guard_min=True)
    theta_max = 3.0 - again.guard_min[0]
    return x0, t0, theta_max, again.guard_min[1]


@pytest.mark.parametrize("d", [10.0**-k for k in range(2, 13)])
def test_shallow_impact_is_never_missed(period1_orbit, d):
    x0, t0, theta_max, t_max = period1_orbit
    m = pendulum("B", eta=0.445, theta_hat=theta_max - d)
    sol = grazing.simulate(m, x0, t0=t0, periods=1, impacts="all")
    assert sol.n_impacts >= 1
    first = sol.impacts.t[0]
    assert t0 < first < t0 + 2 * math.pi
    # Leading order: the impact speed is sqrt(2 |a| d), a = theta'' at the apex;
    # relative error O(sqrt(d)) from the parabola, plus half the relative error of
    # d itself, which is a difference of two angles near 0.7 each a few ulps off.
    a = pendulum("B", eta=0.445).vector_field([theta_max, 0.0], t_max)[1]
    rel = 3 * math.sqrt(d) + 0.5 * 8 * math.ulp(theta_max) / d
    assert sol.impacts.speed[0] == pytest.approx(math.sqrt(2 * abs(a) * d), rel=rel)


# --------------------------------------------------------------------------
# Chattering and sticking on the pendulum: stop below the equilibrium.


def test_pendulum_chatters_every_period_and_never_hangs():
    m = pendulum("B", eta=0.45, theta_hat=math.radians(-10))
    sol = grazing.simulate(m, [math.radians(-30), 0.0], transient=5, periods=20)
    starts, ends = sol.sticking[:, 0], sol.sticking[:, 1]
    assert np.all(ends > starts)
    for k in range(20):  # a sticking interval in every sampled forcing period
        lo, hi = sol.t[k] - 2 * math.pi, sol.t[k]
        assert np.any((ends > lo) & (starts < hi))
    # Release when the forcing overcomes gravity: alpha cos(th) sin(tau) = sin(th)/(4 eta^2).
    p = m.params
    q = math.sin(p["theta_hat"]) / (4 * p["eta"] ** 2 * p["alpha"] * math.cos(p["theta_hat"]))
    tau_release = math.pi - math.asin(q)
    released = ends[ends < sol.t_final - 1e-9]
    np.testing.assert_allclose(np.mod(released, 2 * math.pi), tau_release, atol=1e-9)
    assert sol.n_impacts > 20 * 20


# --------------------------------------------------------------------------
# Jacobians across impacts: invariants and finite differences.


def test_jacobian_matches_finite_differences_across_impacts(pendulum_b, period5_orbit):
    x0, t0 = period5_orbit
    sol = grazing.simulate(pendulum_b, x0, t0=t0, periods=5, jacobian=True, sensitivities=["eta", "r"])
    assert sol.n_impacts == 1 and sol.jacobian_valid
    J = sol.jacobian
    eps = 1e-7
    for j in range(2):
        dx = np.zeros(2)
        dx[j] = eps
        plus = grazing.simulate(pendulum_b, x0 + dx, t0=t0, periods=5).x_final
        minus = grazing.simulate(pendulum_b, x0 - dx, t0=t0, periods=5).x_final
        np.testing.assert_allclose(J[:, j], (plus - minus) / (2 * eps), rtol=1e-6, atol=1e-8)
    for c, name in enumerate(["eta", "r"], start=2):
        p = pendulum_b.params[name]
        plus = grazing.simulate(pendulum_b.with_params(**{name: p + eps}), x0, t0=t0, periods=5).x_final
        minus = grazing.simulate(pendulum_b.with_params(**{name: p - eps}), x0, t0=t0, periods=5).x_final
        np.testing.assert_allclose(J[:, c], (plus - minus) / (2 * eps), rtol=1e-6, atol=1e-7)


def test_monodromy_determinant_period5(pendulum_b, period5_orbit):
    x0, t0 = period5_orbit
    sol = grazing.simulate(pendulum_b, x0, t0=t0, periods=5, jacobian=True)
    np.testing.assert_allclose(sol.x_final, x0, atol=1e-12)  # it is a periodic orbit
    p = pendulum_b.params
    expected = p["r"] ** 2 * math.exp(-4 * math.pi * p["beta"] * 5 / p["eta"])
    assert np.linalg.det(sol.jacobian) == pytest.approx(expected, rel=1e-10)


def test_monodromy_determinant_period1_nonimpacting(period1_orbit):
    x0, t0, _, _ = period1_orbit
    m = pendulum("B", eta=0.445, theta_hat=3.0)
    sol = grazing.simulate(m, x0, t0=t0, periods=1, jacobian=True)
    assert sol.n_impacts == 0
    assert np.linalg.det(sol.jacobian) == pytest.approx(math.exp(-4 * math.pi * 0.048 / 0.445), rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(
    alpha=st.floats(0.0, 0.5),
    beta=st.floats(0.0, 0.1),
    eta=st.floats(0.3, 1.0),
    r=st.floats(0.3, 1.0),
    theta_hat=st.floats(-0.3, 1.0),
    theta0=st.floats(-1.0, 1.0),
    dtheta0=st.floats(-0.5, 0.5),
    n=st.integers(1, 3),
)
def test_determinant_identity_on_any_segment(alpha, beta, eta, r, theta_hat, theta0, dtheta0, n):
    """det(d x(nT)/d x0) = r^(2k) exp(-4 pi beta n / eta) for k impacts, any start."""
    assume(theta0 < theta_hat - 1e-3)
    m = pendulum(None, alpha=alpha, beta=beta, eta=eta, r=r, theta_hat=theta_hat)
    sol = grazing.simulate(m, [theta0, dtheta0], periods=n, jacobian=True)
    assume(sol.jacobian_valid)
    assume(np.all(sol.impacts.speed > 1e-3))  # saltation ~ 1/speed: keep it well conditioned
    expected = r ** (2 * sol.n_impacts) * math.exp(-4 * math.pi * beta * n / eta)
    assert np.linalg.det(sol.jacobian) == pytest.approx(expected, rel=1e-7)


def test_impact_oscillator_determinant_identity():
    m = impact_oscillator(zeta=0.05, omega=2.8, sigma=0.1, r=0.8)
    sol = grazing.simulate(m, [0.0, 0.0], transient=10, periods=3)
    run = grazing.simulate(m, sol.x_final, t0=sol.t_final, periods=4, jacobian=True)
    assert run.n_impacts > 0
    expected = 0.8 ** (2 * run.n_impacts) * math.exp(-2 * 0.05 * 4 * m.period)
    assert np.linalg.det(run.jacobian) == pytest.approx(expected, rel=1e-9)


# --------------------------------------------------------------------------
# Lyapunov exponents.


def test_lyapunov_of_periodic_orbit_matches_floquet_multipliers(pendulum_b, period5_orbit):
    x0, t0 = period5_orbit
    mono = grazing.simulate(pendulum_b, x0, t0=t0, periods=5, jacobian=True).jacobian
    mu = np.sort(np.abs(np.linalg.eigvals(mono)))[::-1]
    sol = grazing.simulate(pendulum_b, x0, t0=t0, periods=2000, lyapunov=True)
    expected = np.log(mu) / (2 * math.pi * 5)
    span = sol.t_final - t0
    # Finite-time exponents converge like log(c) / span, c the initial tangent frame's O(1)
    # misalignment with the Floquet directions (measured: 4e-6 over this span of 12566).
    np.testing.assert_allclose(np.sort(sol.lyapunov)[::-1], expected, atol=1 / span)
    # The sum is the mean divergence, impacts included: -2 beta/eta + 2 ln r per impact.  An
    # identity of the algorithm: the Gram-Schmidt log norms of each step add up to log|det| of
    # that step's flow, which the integrator (tolerance one ulp per step) keeps to a few ulps;
    # 50 ulps per step is ten times what is measured (2.5e-15 = 4.5 n_steps eps / span).  A
    # wrong saltation determinant would be off by 2 |ln r| impacts / span = 0.017.
    p = pendulum_b.params
    div = -2 * p["beta"] / p["eta"] + 2 * math.log(p["r"]) * len(sol.impacts) / span
    assert sol.lyapunov.sum() == pytest.approx(div, abs=50 * sol.n_steps * np.finfo(float).eps / span)


def test_lyapunov_sums_start_at_the_sample_before_the_span(pendulum_b):
    """issue 29: the span starts at the transient's last sample, inside a step; the sums start there too.

    The sum of the exponents is the mean divergence over the span (see above):
    ``-2 beta/eta + 2 ln r`` per impact in it.  The span runs from the
    transient's last sample, ``t[0] - T``, to the end.  Sums that started at
    the end of the step holding that sample, or counted the whole step, would
    be off by the divergence over part of a step, ``~0.2 * 0.5 / span = 4e-4``.
    """
    T = pendulum_b.period
    sol = grazing.simulate(pendulum_b, [0.0, 0.0], transient=7, periods=30, lyapunov=True, impacts="all")
    start = sol.t[0] - T
    span = sol.t_final - start
    impacts = np.count_nonzero(sol.impacts.t > start)
    assert 0 < impacts < len(sol.impacts)  # (impacts before and in the span)
    p = pendulum_b.params
    div = -2 * p["beta"] / p["eta"] + 2 * math.log(p["r"]) * impacts / span
    assert sol.lyapunov.sum() == pytest.approx(div, abs=50 * sol.n_steps * np.finfo(float).eps / span)


# --------------------------------------------------------------------------
# Sampling, chunking, errors.


def test_samples_lie_on_the_trajectory_at_the_sampling_phase(pendulum_b):
    sol = grazing.simulate(pendulum_b, [0.0, 0.0], transient=3, periods=6, phase=math.pi / 2, trajectory=4)
    assert sol.t[0] == pytest.approx((3 + 0.25) * 2 * math.pi)
    for t, s in zip(sol.t, sol.samples):
        i = np.argmin(np.abs(sol.trajectory_t - t))
        assert sol.trajectory_t[i] == pytest.approx(t, abs=1e-12)
        np.testing.assert_allclose(sol.trajectory[i], s, atol=1e-13)


def test_results_do_not_depend_on_chunking(pendulum_b, monkeypatch):
    ref = grazing.simulate(pendulum_b, [0.0, 0.0], transient=10, periods=40, trajectory=5, lyapunov=True)
    monkeypatch.setattr(simulate_module, "CHUNK_PERIODS", 7)
    seen = []
    sol = grazing.simulate(
        pendulum_b,
        [0.0, 0.0],
        transient=10,
        periods=40,
        trajectory=5,
        lyapunov=True,
        progress=lambda d, tot: seen.append((d, tot)),
    )
    assert seen[-1] == (50, 50) and len(seen) == 8
    # Not bit for bit: every chunk ends with a step cut short at its last period, so the two runs
    # round differently; on this transient to a stable orbit that amplifies errors ~30 times
    # (tests/engine/reference.amplification) the samples differ by ~5e-13.
    np.testing.assert_allclose(sol.samples, ref.samples, atol=1e-11)
    np.testing.assert_allclose(sol.impacts.t, ref.impacts.t, atol=1e-11)
    assert sol.trajectory.shape == ref.trajectory.shape
    # The exponents are (sum of the log norms over the span) / span, the sum a function of the
    # trajectory and the final tangent frame, both the same to ~1e-12: measured 9e-15.  A change
    # of the span or of the tangent frame at a chunk boundary moves them by ~1e-5 (see below).
    np.testing.assert_allclose(sol.lyapunov, ref.lyapunov, rtol=0, atol=1e-12)


def test_lyapunov_span_does_not_depend_on_where_chunks_end(pendulum_b, monkeypatch):
    ref = grazing.simulate(pendulum_b, [0.0, 0.0], transient=10, periods=40, lyapunov=True)
    monkeypatch.setattr(simulate_module, "CHUNK_PERIODS", 5)  # a chunk ends where the transient does
    sol = grazing.simulate(pendulum_b, [0.0, 0.0], transient=10, periods=40, lyapunov=True)
    np.testing.assert_allclose(sol.lyapunov, ref.lyapunov, rtol=0, atol=1e-12)


def test_sticking_continues_across_chunks(monkeypatch):
    m = bouncing_ball(amplitude=0.0, r=0.5)
    monkeypatch.setattr(simulate_module, "CHUNK_PERIODS", 1)
    sol = grazing.simulate(m, [1.0, 0.0], periods=4)
    assert sol.sticking.shape == (1, 2)
    assert sol.n_impacts < 60


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"periods": 0}, InvalidParameterError, "periods must be >= 1"),
        ({"transient": -1}, InvalidParameterError, "transient must be >= 0"),
        ({"periods": 2.5}, InvalidParameterError, "periods must be an integer"),
        ({"x0": [1.0, 0.0]}, InvalidStateError, "beyond the stop"),
        ({"x0": [float("nan"), 0.0]}, InvalidStateError, "finite"),
        ({"phase": float("inf")}, InvalidParameterError, "phase must be a finite number"),
        ({"max_steps": 5, "periods": 10}, SimulationError, "step limit"),
        ({"lyapunov": True, "jacobian": True}, InvalidParameterError, "cannot be combined"),
    ],
)
def test_bad_arguments(pendulum_b, kwargs, error, message):
    kwargs = {"x0": [0.0, 0.0], **kwargs}
    with pytest.raises(error, match=message):
        grazing.simulate(pendulum_b, **kwargs)


# --------------------------------------------------------------------------
# Sticking that begins before the recorded span (issue 11, case 6).


def test_sticking_in_progress_when_recording_starts_is_reported(monkeypatch):
    """The ball rides the table throughout: the recorded span is one sticking interval."""
    m = bouncing_ball(amplitude=0.1)
    T = m.period
    sol = grazing.simulate(m, [0.0, 0.0], transient=50, periods=3)
    assert len(sol.impacts) == 0
    np.testing.assert_allclose(sol.sticking, [[50 * T, 53 * T]], atol=1e-9)
    # From rest: a chattering sequence, then one interval to the end of the run...
    first = grazing.simulate(m, [0.0, 0.0], periods=3)
    assert len(first.impacts) > 10 and first.sticking.shape == (1, 2)
    assert 0 < first.sticking[0, 0] < 0.25 and first.sticking[0, 1] == pytest.approx(3 * T, abs=1e-9)
    # ... reported once, not cut or lost, across the engine's chunks of periods.
    monkeypatch.setattr(simulate_module, "CHUNK_PERIODS", 2)
    for transient, expected in ((50, sol.sticking), (0, first.sticking)):
        chunked = grazing.simulate(m, [0.0, 0.0], transient=transient, periods=3)
        np.testing.assert_allclose(chunked.sticking, expected, atol=1e-9)


@pytest.mark.parametrize("x0", [[0.0, 0.0], [-0.30952407456611286, 0.4508808109843482]])
def test_a_dense_trajectory_covers_the_recorded_span_in_order(x0):
    """Every row of a dense trajectory was written: its times rise from the span's start to its end,
    each point where the flow from the last sample puts it (a refactoring once left rows unwritten)."""
    m = pendulum("B", eta=0.446, theta_hat=math.radians(40))
    sol = grazing.simulate(m, x0, transient=600, periods=37, trajectory=400)
    t = sol.trajectory_t
    T = 2 * math.pi
    assert t[0] == pytest.approx(600 * T) and t[-1] == pytest.approx((600 + 37) * T)
    assert np.all(np.diff(t) >= 0.0)  # (an impact is two rows at one time: before and after)
    spacing = T / 400
    # rows: every spacing, plus two at each impact of the span
    assert len(t) == pytest.approx(37 * 400 + 1 + 2 * sol.impacts.t.size, abs=2)
    assert np.all(np.isfinite(sol.trajectory))
    assert np.all(sol.trajectory[:, 0] <= m.params["theta_hat"] + 1e-9)
    assert np.max(np.diff(t)) <= spacing * (1 + 1e-9)


@pytest.mark.parametrize(
    ("make", "x0"),
    [
        (lambda: impact_oscillator(sigma=0.1, omega=2.0), [0.0, 0.5]),  # one stop
        (lambda: two_sided_oscillator(), [0.0, 0.0]),  # two stops
        (lambda: bouncing_ball(amplitude=1.2), [0.0, 0.0]),  # chattering and sticking
    ],
    ids=["impact-oscillator", "two-sided-oscillator", "bouncing-ball"],
)
def test_a_dense_trajectory_of_other_models_has_every_row(make, x0):
    """Rows every T/100 over the recorded span plus two at each impact, in time order and finite (issue 29:
    the run's state record once pointed into freed memory and the count of rows came back wrong)."""
    m = make()
    transient, periods, per_period = 50, 20, 100
    sol = grazing.simulate(m, x0, transient=transient, periods=periods, trajectory=per_period)
    t = sol.trajectory_t
    T = m.period
    assert t[0] == pytest.approx(transient * T) and t[-1] == pytest.approx((transient + periods) * T)
    assert np.all(np.diff(t) >= 0.0) and np.all(np.isfinite(sol.trajectory))
    assert len(t) == pytest.approx(periods * per_period + 1 + 2 * sol.impacts.t.size, abs=2)
    assert np.max(np.diff(t)) <= T / per_period * (1 + 1e-9)
    np.testing.assert_allclose(sol.trajectory[-1], sol.samples[-1], atol=1e-12)  # (the span ends at a sample)


@pytest.mark.parametrize("distance", [10.0, 1e6, 1e12])
def test_a_stop_far_away_leaves_the_orbit_as_accurate(distance):
    # The closed-form orbit of a damped linear oscillator to rounding, wherever its (unreached) stop is: the
    # guard's value, offset by the stop's distance, once set the step's scale (1e12: samples off by 1e-4).
    m = far_stop_swing(force=1.0, distance=distance)
    for x0 in ([0.3, 0.0], [-0.2, 0.1]):  # (the sweeps' lanes: tests/attractors/test_dynamics.py)
        run = grazing.simulate(m, x0, transient=400, periods=8)
        np.testing.assert_allclose(run.samples, np.tile(orbit_state(1.0), (8, 1)), rtol=0, atol=1e-12)
