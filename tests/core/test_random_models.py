"""Property tests over random models: no name a user chooses can change a result.

For random models (:mod:`tests.random_models`) whose states, time and
parameters are named like the code generator's own symbols, numpy or math
functions: the samples are the same with the Jacobian and the Lyapunov
exponents switched on and off, they agree with scipy's event loop
(:mod:`tests.engine.reference`), the Jacobian matches central finite differences,
and so do the parameter sensitivities, including the frequency, which sets the
forcing period.  Each model compiles its kernels (~15 s per variant), so the
default suite draws two models and the slow suite many.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings

import grazing
from tests.engine.reference import MAX_AMPLIFICATION, amplification, assert_agrees
from tests.random_models import ModelSpec, model_specs

PERIODS = 2


def _run(model: grazing.HybridModel, x0, t0: float, phase: float, **kw) -> grazing.Solution:
    return grazing.simulate(model, x0, t0=t0, phase=phase, periods=PERIODS, impacts="all", **kw)


def check_model(spec: ModelSpec) -> None:
    model = spec.model()
    x0 = np.array(spec.initial_state())
    t0 = 0.3 * model.period
    phase = 1.0
    plain = _run(model, x0, t0, phase)
    speeds = plain.impacts.speed
    assume(len(speeds) >= 1 and speeds.min() > 0.05 and not len(plain.sticking))
    # Every comparison below is between two computations of one trajectory (tangent dynamics on and
    # off, finite differences, scipy): well-conditioned only where the trajectory does not amplify
    # errors much; a random model may be chaotic even over two periods.
    assume(amplification(model, x0, t0=t0, phase=phase, periods=PERIODS) <= MAX_AMPLIFICATION)
    names = [p.name for p in model.parameters]
    # frequency (sets the period) and stop; restitution and amplitude: two runs share one kernel module
    pairs = [(names[3], names[4]), (names[5], names[2])]
    runs = [_run(model, x0, t0, phase, sensitivities=pair) for pair in pairs]
    jac = runs[0]
    lyap = _run(model, x0, t0, phase, lyapunov=True)

    # 1. The tangent dynamics never change the trajectory.
    scale = max(1.0, float(np.max(np.abs(plain.samples))))
    np.testing.assert_allclose(jac.samples, plain.samples, rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(lyap.samples, plain.samples, rtol=0, atol=1e-10 * scale)
    assert len(jac.impacts) == len(lyap.impacts) == len(plain.impacts)
    assert np.all(np.isfinite(lyap.lyapunov))

    # 2. The Jacobian with respect to the initial state, against central differences.
    n = model.n_states
    J = jac.jacobian[:, :n]
    fd = np.empty_like(J)
    for j in range(n):
        h = 1e-6 * max(1.0, abs(x0[j]))
        up, down = x0.copy(), x0.copy()
        up[j] += h
        down[j] -= h
        a, b = _run(model, up, t0, phase), _run(model, down, t0, phase)
        assume(len(a.impacts) == len(b.impacts) == len(plain.impacts))
        fd[:, j] = (a.x_final - b.x_final) / (2 * h)
    np.testing.assert_allclose(J, fd, rtol=0, atol=2e-5 * max(1.0, float(np.max(np.abs(fd)))))

    # 2b. The samples and impacts agree with scipy's event loop on the sympy expressions.
    assert_agrees(model, x0, t0=t0, phase=phase, periods=PERIODS)

    # 3. Parameter sensitivities, the period-setting frequency included.
    for pair, run in zip(pairs, runs):
        np.testing.assert_allclose(run.samples, plain.samples, rtol=0, atol=1e-10 * scale)
        for c, name in enumerate(pair):
            _check_sensitivity(model, spec, x0, t0, phase, plain, run.jacobian[:, n + c], name)


def _check_sensitivity(model, spec, x0, t0, phase, plain, column, name) -> None:
    """One sensitivity column against central differences of the final sample."""
    v = model.params[name]
    h = 1e-6 * max(1.0, abs(v))
    a = _run(model.with_params(**{name: v + h}), x0, t0, phase)
    b = _run(model.with_params(**{name: v - h}), x0, t0, phase)
    assume(len(a.impacts) == len(b.impacts) == len(plain.impacts))
    col = (a.x_final - b.x_final) / (2 * h)
    np.testing.assert_allclose(
        column, col, rtol=0, atol=2e-5 * max(1.0, float(np.max(np.abs(col)))),
        err_msg=f"d x / d {name} ({spec.names})",
    )  # fmt: skip


@settings(max_examples=1)
@given(spec=model_specs())
def test_random_models_names_jacobians_sensitivities(spec: ModelSpec) -> None:
    check_model(spec)


@pytest.mark.slow
@settings(max_examples=16)
@given(spec=model_specs())
def test_random_models_names_jacobians_sensitivities_many(spec: ModelSpec) -> None:
    check_model(spec)


def test_the_issue_case_x1_v1() -> None:
    """x'' + 0.05 x' + 2 x = 0.3 cos t with a stop at x = 1.5, states named x1, v1 (issue 11, case 1)."""
    import sympy as sp

    x1, v1, t = sp.symbols("x1 v1 t")
    model = grazing.HybridModel(
        "clash", [x1, v1], t, [grazing.Parameter("r", 0.8, lower=0, upper=1)],
        vector_field=[v1, -0.05 * v1 - 2 * x1 + 0.3 * sp.cos(t)], guard=1.5 - x1,
        reset=[x1, -sp.Symbol("r") * v1], period=2 * sp.pi, contact_direction=[0, 1],
    )  # fmt: skip
    x0 = [1.0, 2.0]
    plain = grazing.simulate(model, x0, periods=20)
    assert plain.n_impacts > 0
    with_jac = grazing.simulate(model, x0, periods=20, jacobian=True)
    with_lyap = grazing.simulate(model, x0, periods=20, lyapunov=True)
    np.testing.assert_allclose(with_jac.samples, plain.samples, rtol=0, atol=1e-12)
    np.testing.assert_allclose(with_lyap.samples, plain.samples, rtol=0, atol=1e-12)
    # Between impacts the flow contracts volume at the rate 0.05 (the trace of the vector field's
    # Jacobian); each impact multiplies it by r^2 (the saltation matrix of v <- -r v has determinant
    # r^2).  So over the span: sum of the exponents = -0.05 + 2 ln(r) n / span and
    # det(d x / d x0) = r^(2n) exp(-0.05 span), both identities of the algorithm up to a few ulps
    # per step (50 per step allowed; measured 7e-18 and 2e-14 relative).
    n, span, eps = with_lyap.n_impacts, with_lyap.t_final, np.finfo(float).eps
    assert n == with_jac.n_impacts == plain.n_impacts
    expected = -0.05 + 2 * math.log(0.8) * n / span
    assert with_lyap.lyapunov.sum() == pytest.approx(expected, abs=50 * with_lyap.n_steps * eps / span)
    det = 0.8 ** (2 * n) * math.exp(-0.05 * span)
    assert np.linalg.det(with_jac.jacobian) == pytest.approx(det, rel=50 * with_jac.n_steps * eps)


def test_period_parameter_named_pi_is_not_the_constant() -> None:
    """A parameter called ``pi`` must not replace the number pi in ``period = 2 pi / w``."""
    import sympy as sp

    x, v, t, w, mypi = sp.symbols("x v t w pi")
    params = [grazing.Parameter("w", 2.0, lower=0, lower_open=True), grazing.Parameter("pi", 7.0)]
    model = grazing.HybridModel(
        "named-pi", [x, v], t, params, vector_field=[v, -x + mypi * 0 + sp.cos(w * t)], guard=5 - x,
        reset=[x, -v], period=2 * sp.pi / w,
    )  # fmt: skip
    assert model.period == pytest.approx(math.pi)
    with pytest.raises(ValueError, match="used twice"):
        grazing.HybridModel(
            "dup", [x, v], t, [grazing.Parameter("x", 1.0)], vector_field=[v, -x], guard=1 - x,
            reset=[x, -v], period=2 * sp.pi,
        )  # fmt: skip
