"""Shooting, continuation, grazing points and curves."""

from __future__ import annotations

import math

import numpy as np
import pytest

import grazing
from grazing import ConvergenceError
from grazing.models import pendulum
from grazing.orbits import (
    continue_orbit,
    find_grazings,
    find_orbit,
    flow_map,
    grazing_curve,
)

DEG = math.pi / 180


# --------------------------------------------------------------------------
# Shooting


def test_newton_converges_quadratically(pendulum_b, period5_orbit):
    x_star, t0 = period5_orbit
    orbit = find_orbit(pendulum_b, x_star + np.array([2e-3, -3e-3]), period=5, t0=t0)
    r = np.array(orbit.residuals)
    assert r[-1] <= 1e-11
    assert len(r) <= 6
    # quadratic: r_{k+1} <= C r_k^2 once in the basin (C ~ |second derivative|)
    big = r[:-1] > 1e-9
    ratios = r[1:][big] / r[:-1][big] ** 2
    assert np.all(ratios < 50.0)
    np.testing.assert_allclose(orbit.state, x_star, atol=1e-10)


def test_orbit_agrees_with_long_simulation(pendulum_b):
    """Shooting and a long simulation give the same orbit (two independent ways)."""
    orbit = find_orbit(pendulum_b, [0.0, 0.0], period=5, t0=0.0, max_iter=50)
    sim = grazing.simulate(pendulum_b, [0.0, 0.0], transient=1000, periods=5)
    dist = np.min(np.max(np.abs(sim.samples - orbit.state), axis=1))
    assert dist < 1e-10
    assert orbit.impacts == 1 and orbit.stable


def test_monodromy_matches_finite_differences_of_the_map(pendulum_b, period5_orbit):
    x, t0 = period5_orbit
    orbit = find_orbit(pendulum_b, x, period=5, t0=t0)
    eps = 1e-7
    fd = np.empty((2, 2))
    for j in range(2):
        dx = np.zeros(2)
        dx[j] = eps
        plus = flow_map(pendulum_b, x + dx, t0=t0, periods=5).image
        minus = flow_map(pendulum_b, x - dx, t0=t0, periods=5).image
        fd[:, j] = (plus - minus) / (2 * eps)
    np.testing.assert_allclose(orbit.monodromy, fd, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize(("eta", "theta_hat"), [(0.446, 40), (0.50, 30), (0.40, 10), (0.60, 20)])
def test_determinant_identity_for_periodic_orbits(eta, theta_hat):
    m = pendulum("B", eta=eta, theta_hat=theta_hat * DEG)
    orbit = find_orbit(m, max_iter=60)
    n, k = orbit.period, orbit.impacts
    expected = m.params["r"] ** (2 * k) * math.exp(-4 * math.pi * m.params["beta"] * n / eta)
    assert np.prod(orbit.multipliers).real == pytest.approx(expected, rel=1e-9)


def test_no_orbit_of_that_period_is_a_clear_error():
    m = pendulum("B", eta=0.4458, theta_hat=40 * DEG)  # fig 11's η: the period-5 window, no period-3 orbit
    with pytest.raises(ConvergenceError, match=r"Newton did not converge to a period-3 orbit: residual"):
        find_orbit(m, [0.1, 0.1], period=3, max_iter=8)


# --------------------------------------------------------------------------
# Continuation and special points


def test_grazings_at_40_degrees_match_the_paper():
    """Fig 6 insets (b), (c): eta = 0.4450 with 0.4606 +- 0.2137i; 0.5475 with 0.2534 +- 0.5178i."""
    points, _branch = find_grazings(pendulum("B", theta_hat=40 * DEG), "eta", 0.2, 1.0)
    assert len(points) == 2
    g1, g2 = points
    assert g1.model.params["eta"] == pytest.approx(0.4450, abs=5e-4)
    assert g2.model.params["eta"] == pytest.approx(0.5475, abs=5e-4)
    np.testing.assert_allclose(g1.multipliers[0], 0.4606 + 0.2137j, atol=3e-3)
    np.testing.assert_allclose(g2.multipliers[0], 0.2534 + 0.5178j, atol=3e-3)
    for g in points:
        # the contact is on the stop with zero velocity, turning back
        np.testing.assert_allclose(g.contact, [40 * DEG, 0.0], atol=1e-11)
        assert g.accel > 0
        det = math.exp(-4 * math.pi * 0.048 / g.model.params["eta"])
        assert np.linalg.det(g.monodromy) == pytest.approx(det, rel=1e-10)


def test_grazing_at_10_degrees_and_no_second_grazing():
    """Fig 6 inset (a): the grazing is at eta ~ 0.333 (erratum: printed 0.3229), |lambda| = 0.404."""
    points, _ = find_grazings(pendulum("B", theta_hat=10 * DEG), "eta", 0.2, 1.0)
    assert len(points) == 1  # the paper: no second grazing at 10 degrees
    g = points[0]
    assert g.model.params["eta"] == pytest.approx(0.333, abs=1e-3)
    assert g.abs_lambda == pytest.approx(0.4040, abs=2e-3)


def test_grazing_from_continuation_agrees_with_maximum_of_simulated_orbit():
    points, _ = find_grazings(pendulum("B", theta_hat=40 * DEG), "eta", 0.40, 0.47)
    eta_g = points[0].model.params["eta"]
    for eta, sign in ((eta_g - 1e-4, 1), (eta_g + 1e-4, -1)):
        free = pendulum("B", eta=eta, theta_hat=3.0)
        sol = grazing.simulate(free, [0, 0], transient=300, periods=1, guard_min=True)
        theta_max = 3.0 - sol.guard_min[0]
        assert np.sign(40 * DEG - theta_max) == sign


def test_response_curve_folds_are_located():
    """beta = 0.010 (case A): the resonance peak leans over with two folds; det(P_x - I) = 0 there."""
    m = pendulum(None, alpha=0.2254, beta=0.010, theta_hat=3.0)
    br = continue_orbit(m, "eta", 0.2, 1.0, virtual=True)
    folds = [s for s in br.special if s.kind == "fold"]
    assert len(folds) == 2
    for f in folds:
        mu = np.sort(np.abs(f.multipliers))
        assert mu[-1] == pytest.approx(1.0, abs=1e-6)
    # between the folds, the branch is the unstable middle one
    i, j = sorted(f.index for f in folds)
    assert not br.orbits[(i + j) // 2 + 1].stable
    assert br.status.startswith("reached")


def test_period_doubling_is_located_on_an_impacting_branch():
    """Case B, theta_hat = 20 deg: the period-1 impacting orbit (multiplier -0.89 at eta = 0.45)
    period-doubles as eta decreases; below it the attractor is period 2 (the fig 7b window)."""
    m = pendulum("B", theta_hat=20 * DEG)
    br = continue_orbit(m, "eta", 0.50, 0.43, period=1, detect=("period-doubling",))
    pds = [s for s in br.special if s.kind == "period-doubling"]
    assert len(pds) == 1
    pd = pds[0]
    assert 0.44 < pd.param < 0.45
    assert np.min(np.abs(pd.multipliers + 1)) < 1e-6
    assert pd.orbit.impacts == 1
    below = find_orbit(m.with_params(eta=pd.param - 2e-3), max_iter=60)
    assert below.period == 2 and below.stable


def test_branch_to_netcdf(tmp_path):
    import xarray as xr

    br = continue_orbit(pendulum("B", theta_hat=40 * DEG), "eta", 0.43, 0.46)
    path = tmp_path / "branch.nc"
    br.to_netcdf(path)
    ds = xr.open_dataset(path, engine="h5netcdf")
    assert ds.sizes["point"] == len(br)
    assert list(ds.special_kind.values) == ["grazing"]
    assert float(ds.special_param[0]) == pytest.approx(0.44512, abs=1e-4)
    assert ds.attrs["continuation_parameter"] == "eta"
    assert "closest_state" in ds


# --------------------------------------------------------------------------
# Two-parameter grazing curve


def test_grazing_curve_fold_and_agreement_with_response_curve():
    curve = grazing_curve(pendulum("B"), ("eta", "theta_hat"), 5 * DEG, search=(0.2, 1.0))
    assert curve.fold is not None
    theta_max = math.degrees(curve.fold.model.params["theta_hat"])
    assert 54.0 < theta_max < 57.0  # the paper: "about 55 degrees for case B"
    # The same maximum from the response curve of the free pendulum (independent route).
    br = continue_orbit(pendulum("B", theta_hat=3.0), "eta", 0.2, 1.0, virtual=True)
    peak = math.degrees(3.0 - br.guard_min.min())
    assert theta_max == pytest.approx(peak, abs=1e-3)
    # every point satisfies grazing: contact on the stop, det identity
    for p in curve.points[::10]:
        assert p.contact[0] == pytest.approx(p.model.params["theta_hat"], abs=1e-10)
        det = math.exp(-4 * math.pi * 0.048 / p.model.params["eta"])
        assert np.linalg.det(p.monodromy) == pytest.approx(det, rel=1e-9)
    thetas = curve.values("theta_hat")
    assert thetas[0] == pytest.approx(5 * DEG)
    fold = curve.fold.model.params["theta_hat"]
    assert thetas.max() <= fold + 1e-12 and fold - thetas.max() < 1e-3  # the fold is the true top
    # fold_index is the point just before the fold: the fold's eta lies between it and the next
    i, etas = curve.fold_index, curve.values("eta")
    eta_fold = curve.fold.model.params["eta"]
    assert 0 <= i < len(curve.points) - 1
    assert min(etas[i], etas[i + 1]) <= eta_fold <= max(etas[i], etas[i + 1])


def test_flow_map_on_a_section_at_any_phase(pendulum_b):
    """The map from t0 ends at t0 + n T whatever the phase of t0 (regression)."""
    x0 = np.array([-0.3, 0.2])
    fm = flow_map(pendulum_b, x0, t0=2.3, periods=2)
    assert fm.solution.t_final == pytest.approx(2.3 + 4 * math.pi, abs=1e-12)
    ref = grazing.simulate(pendulum_b, x0, t0=2.3, periods=2, phase=2.3)
    np.testing.assert_allclose(fm.image, ref.x_final, atol=1e-14)


def test_neimark_sacker_is_located_for_the_forced_van_der_pol_oscillator():
    """The impacting pendulum is uniformly dissipative (det < 1: no NS); the forced van der Pol
    oscillator is not: its entrained orbit loses stability to a torus as the forcing weakens."""
    import sympy as sp

    from grazing import HybridModel, Parameter

    x, v, t = sp.symbols("x v t")
    eps, F, w = sp.symbols("eps F w")
    vdp = HybridModel(
        "van-der-pol", [x, v], t,
        [Parameter("eps", 0.2), Parameter("F", 1.0), Parameter("w", 1.15, lower=0, lower_open=True)],
        vector_field=[v, eps * (1 - x**2) * v - x + F * sp.cos(w * t)],
        guard=10 - x, reset=[x, -v], period=2 * sp.pi / w,
    )  # fmt: skip
    br = continue_orbit(vdp, "F", 1.0, 0.1, period=1, virtual=True)
    ns = [s for s in br.special if s.kind == "neimark-sacker"]
    assert len(ns) == 1
    mu = ns[0].multipliers
    np.testing.assert_allclose(np.abs(mu), 1.0, atol=1e-6)
    assert abs(mu[0].imag) > 0.1  # a complex pair, not +-1
    f_ns = ns[0].param
    above = grazing.simulate(vdp.with_params(F=f_ns + 0.05), [0, 0], transient=1500, periods=100)
    below = grazing.simulate(vdp.with_params(F=f_ns - 0.05), [0, 0], transient=1500, periods=100)
    assert above.period() == 1 and below.period() == 0  # entrained vs quasi-periodic


def test_an_impact_at_zero_speed_gives_no_jacobian_and_one_clear_error():
    """The ball on a table moving 1.3 (ω = 0.9) meets the table at exactly zero speed: the saltation
    matrix is unbounded there, so the Jacobian is marked invalid (it used to raise ZeroDivisionError
    inside the compiled driver) and Newton's method says why it stops."""
    from grazing.errors import ConvergenceError
    from grazing.models import bouncing_ball
    from grazing.orbits.shooting import initial_guess

    m = bouncing_ball(amplitude=1.3, omega=0.9)
    x = initial_guess(m).state
    sol = grazing.simulate(m, x, periods=1, jacobian=True)
    assert not sol.jacobian_valid
    with pytest.raises(ConvergenceError, match="sticks to the stop"):
        find_orbit(m, period=1)
