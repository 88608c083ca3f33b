"""The step size from the Taylor coefficients' norms, and the logarithm and exponential it uses."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from grazing.engine.stepping import fast_exp, fast_log, step_from_norms, steps_from_norms


def test_fast_log_against_the_c_library():
    rng = np.random.default_rng(0)
    xs = np.concatenate([
        np.exp(rng.uniform(-690, 690, 20000)),
        2.0 ** np.arange(-990, 990, 7.0),  # exact powers of two
        np.sqrt(2.0) * (1 + np.linspace(-1e-12, 1e-12, 101)),  # where the mantissa is halved
        [1e-300, 1e300, 1.0, 1.0 + 2**-52, 1.0 - 2**-53],
    ])  # fmt: skip
    err = max(abs(fast_log(x) - math.log(x)) / max(1.0, abs(math.log(x))) for x in xs)
    assert err < 2e-11


def test_fast_exp_against_the_c_library():
    ys = np.concatenate([np.random.default_rng(1).uniform(-700, 700, 20000), [0.0, -700.0, 700.0, 1e-300]])
    assert max(abs(fast_exp(y) / math.exp(y) - 1.0) for y in ys) < 2e-14


def _reference(nx, n1, n2, order, max_step, factor):
    """The Jorba-Zou step with the C library's functions (a zero norm says nothing)."""
    sc = max(1.0, nx)
    rho = min([(sc / n) ** (1.0 / p) for n, p in ((n1, order - 1), (n2, order)) if n > 0.0], default=math.inf)
    return min(rho * factor, max_step)


@settings(max_examples=300, deadline=None)
@given(
    nx=st.floats(0.0, 1e6),
    n1=st.floats(0.0, 1e30) | st.just(0.0),
    n2=st.floats(0.0, 1e30) | st.just(0.0),
    order=st.integers(6, 60),
)
def test_step_from_norms_is_jorba_zous(nx, n1, n2, order):
    got = step_from_norms(nx, n1, n2, order, 7.0, 0.2)
    want = _reference(nx, n1, n2, order, 7.0, 0.2)
    assert got == want or abs(got / want - 1.0) < 1e-9


def test_a_norm_that_says_nothing_leaves_the_other():
    assert step_from_norms(1.0, 0.0, 0.0, 13, 5.0, 0.1) == 5.0
    assert step_from_norms(1.0, math.nan, 1e-3, 13, 5.0, 0.1) == step_from_norms(1.0, 0.0, 1e-3, 13, 5.0, 0.1)
    assert step_from_norms(1.0, math.inf, 1e-3, 13, 5.0, 0.1) > 0.0


def test_lanes_take_the_scalar_step_bit_for_bit():
    rng = np.random.default_rng(2)
    L = 8
    for _ in range(50):
        nx, n1, n2 = rng.uniform(0, 3, L), 10 ** rng.uniform(-25, 3, L), 10 ** rng.uniform(-25, 3, L)
        n1[rng.integers(L)] = 0.0
        T = rng.uniform(1.0, 20.0, L)
        out = np.zeros(L)
        steps_from_norms(nx, n1, n2, 13, T, 0.3, out)
        scalar = [step_from_norms(a, b, c, 13, t, 0.3) for a, b, c, t in zip(nx, n1, n2, T)]
        assert out.tolist() == scalar
