"""A model written with tanh, atan, powers with parameter and variable exponents (issue 26), end to end.

The engine against scipy's event loop on the model's own sympy expressions
(:mod:`tests.engine.reference`) over a few periods; the flow's Jacobian and a
parameter sensitivity (through an exponent, and through the frequency that
sets the period) against central differences of the engine's own output; the
compiled vector field, guard and reset derivatives against central differences
of the compiled functions; and the SIMD lane kernels equal to the scalar ones,
bit for bit (a sweep on lanes is in :mod:`tests.engine.test_lanes`).
"""

from __future__ import annotations

import numpy as np
import pytest

import grazing
from tests.engine.reference import assert_agrees
from tests.engine.test_lanes import check_lane_functions
from tests.function_models import smooth_oscillator

X0 = [0.0, 0.5]
PERIODS = 4


@pytest.fixture(scope="module")
def model() -> grazing.HybridModel:
    return smooth_oscillator()


def test_agrees_with_scipy_on_a_short_horizon(model) -> None:
    ref = assert_agrees(model, X0, periods=PERIODS)
    # well-conditioned: every impact is a clear crossing, none a near-grazing one
    assert len(ref.impacts_t) >= 3 and ref.impacts_speed.min() > 0.1


def _final(model: grazing.HybridModel, x0) -> np.ndarray:
    return grazing.simulate(model, x0, periods=PERIODS).x_final


def test_jacobian_and_sensitivities_against_central_differences(model) -> None:
    """Through the impacts (saltation), the exponent p (d/dp of (2 + sin wt)^p) and w (the period)."""
    sol = grazing.simulate(model, X0, periods=PERIODS, sensitivities=["p", "w"])
    plain = grazing.simulate(model, X0, periods=PERIODS)
    # the tangent dynamics never move the orbit (their rows only shorten some steps: rounding)
    np.testing.assert_allclose(sol.samples, plain.samples, rtol=0, atol=1e-10)
    n = model.n_states
    # Central differences with h = 1e-6 of runs accurate to ~1e-14 carry errors ~1e-8 (measured 9e-9).
    h, atol = 1e-6, 1e-7
    for j in range(n):
        up, down = np.array(X0), np.array(X0)
        up[j] += h
        down[j] -= h
        fd = (_final(model, up) - _final(model, down)) / (2 * h)
        np.testing.assert_allclose(sol.jacobian[:, j], fd, rtol=0, atol=atol * max(1.0, np.abs(fd).max()))
    for c, name in enumerate(["p", "w"]):
        v = model.params[name]
        fd = (
            _final(model.with_params(**{name: v + h}), X0) - _final(model.with_params(**{name: v - h}), X0)
        ) / (2 * h)
        np.testing.assert_allclose(
            sol.jacobian[:, n + c], fd, rtol=0, atol=atol * max(1.0, np.abs(fd).max()), err_msg=name
        )


def test_compiled_derivatives_against_central_differences(model) -> None:
    """f_x, g_x (of the compiled vector field and reset), the guard's gradient and its normal rate."""
    rng = np.random.default_rng(5)
    kern = model.kernels()
    pv = model.param_vector
    h = 1e-6
    for _ in range(5):
        x, t = rng.normal(size=2), float(rng.uniform(0, model.period))
        fx, hx, gx_reset = model.jacobians(x, t)  # (sympy's derivatives, lambdified)
        gx = np.zeros(2)
        ht = kern.guard_grad(x, t, pv, gx, 0)
        for j in range(2):
            e = np.zeros(2)
            e[j] = h
            fd_f = (model.vector_field(x + e, t) - model.vector_field(x - e, t)) / (2 * h)
            np.testing.assert_allclose(fx[:, j], fd_f, rtol=1e-7, atol=1e-7)
            fd_g = (model.reset(x + e, t) - model.reset(x - e, t)) / (2 * h)
            np.testing.assert_allclose(gx_reset[:, j], fd_g, rtol=1e-7, atol=1e-7)
            fd_h = (model.guard(x + e, t) - model.guard(x - e, t)) / (2 * h)
            assert gx[j] == pytest.approx(fd_h, rel=1e-7, abs=1e-7) == hx[j]
        assert ht == 0.0
        rate = model.contact_derivatives(x, t)["rate"]
        assert rate == pytest.approx(float(gx @ model.vector_field(x, t)), rel=1e-12, abs=1e-12)


def test_lane_kernels_equal_the_scalar_ones(model) -> None:
    check_lane_functions(model, np.random.default_rng(11))
