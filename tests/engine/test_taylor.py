"""The generated Taylor kernels against symbolic differentiation."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from grazing.engine.llvmgen import compile_library
from grazing.engine.taylor import UnsupportedExpressionError, taylor_kernel
from tests.function_models import SMOOTH_FUNCTIONS, smooth_expressions

x, y, t = sp.symbols("x y t")
w, c = sp.symbols("w c")

# Exercises every recurrence: products general x general, affine x general and
# affine x affine, quotients by general and affine denominators, integer,
# negative and fractional powers, sin/cos of general and affine arguments, exp
# of general and affine arguments, log.
RHS = (
    sp.sin(x) * sp.cos(w * t) + sp.exp(-y) / (1 + x**2) + c * t * t,
    sp.log(2 + x**2)
    + sp.sqrt(1 + y**2)
    - x**3
    + t * y
    + sp.cos(x + t)
    + 1 / (2 + t) * y
    + sp.exp(c * t) * x
    + y**-2,
)
OUTPUTS = (x - y * sp.sin(t), x * y)


def _symbolic_coefficients(rhs, outputs, x0, t0, params, order):
    """Taylor coefficients by repeated total differentiation (slow, obviously right)."""
    states = (x, y)

    def total(e):
        return sum(sp.diff(e, s) * f for s, f in zip(states, rhs)) + sp.diff(e, t)

    subs = {x: x0[0], y: x0[1], t: t0, w: params[0], c: params[1]}
    X = np.zeros((2, order + 1))
    O = np.zeros((len(outputs), order + 1))
    for i, s in enumerate(states):
        e = s
        for k in range(order + 1):
            X[i, k] = float(e.subs(subs)) / math.factorial(k)
            e = total(e)
    for m, o in enumerate(outputs):
        e = o
        for k in range(order + 1):
            O[m, k] = float(e.subs(subs)) / math.factorial(k)
            e = total(e)
    return X, O


def _compiled(order):
    k = taylor_kernel("tc", (x, y), t, (w, c), RHS, OUTPUTS, order=order)
    lib = compile_library(k.source, f"test_taylor_{order}", columns={"tc": {"X": order + 1, "O": order + 1}})
    return k, lib.function("tc")


@pytest.fixture(scope="module")
def kernel4():
    return _compiled(4)


@pytest.fixture(scope="module")
def kernel20():
    return _compiled(20)


def test_coefficients_match_symbolic_differentiation(kernel4):
    k, tc = kernel4
    order = k.order  # symbolic differentiation swells quickly; test_high_order_* covers order 20
    x0, t0, params = np.array([0.3, -0.7]), 0.4, np.array([1.3, 0.25])
    X = np.zeros((2, order + 1))
    O = np.zeros((2, order + 1))
    tc(x0, t0, params, X, O)
    Xs, Os = _symbolic_coefficients(RHS, OUTPUTS, x0, t0, params, order)
    np.testing.assert_allclose(X, Xs, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(O, Os, rtol=1e-12, atol=1e-13)


def test_high_order_polynomial_agrees_with_solve_ivp(kernel20):
    """At order 20 the Taylor polynomial reproduces the flow to ~1e-14."""
    from scipy.integrate import solve_ivp

    k, tc = kernel20
    order = k.order
    x0, t0, params = np.array([0.3, -0.7]), 0.4, (1.3, 0.25)
    X = np.zeros((2, order + 1))
    O = np.zeros((2, order + 1))
    tc(x0, t0, np.array(params), X, O)
    f = sp.lambdify((t, (x, y), w, c), RHS)
    h = 0.01  # the coefficients grow like 13.5^k here: radius of convergence ~0.074
    ref = solve_ivp(
        lambda tt, z: f(tt, z, *params), (t0, t0 + h), x0, method="DOP853", rtol=1e-13, atol=1e-15
    )
    poly = [np.polynomial.polynomial.polyval(h, X[i]) for i in range(2)]
    np.testing.assert_allclose(poly, ref.y[:, -1], rtol=1e-12, atol=1e-13)


def test_unsupported_function_is_reported():
    with pytest.raises(UnsupportedExpressionError, match="Abs"):
        taylor_kernel("tc", (x,), t, (), (sp.Abs(x),))


# ----------------------------------------------------------------------------
# issue 26: every smooth function of a model, coefficient by coefficient

q, s, pa, pb = sp.symbols("q s a b")
ARGUMENTS = (pa + pb * q + q**2 / 4, pa + pb * s)
"""The argument ``u`` of each function: general (a state ``q`` with ``q' = 1``) and affine in time."""
FUNCTION_ORDER = 20
"""The engine's default order (machine-epsilon tolerance)."""
CAUCHY_RADIUS, CAUCHY_POINTS, CAUCHY_DIGITS = 0.1, 64, 40


@functools.cache
def _function_kernel(name: str):
    """The kernel of ``q' = 1`` whose outputs are the function of each argument, and mpmath references."""
    outputs = [SMOOTH_FUNCTIONS[name](u) for u in ARGUMENTS]
    k = taylor_kernel("tc", (q,), s, (pa, pb), (sp.Integer(1),), outputs, order=FUNCTION_ORDER)
    columns = {"tc": {"X": FUNCTION_ORDER + 1, "O": FUNCTION_ORDER + 1}}
    lib = compile_library(k.source, f"test_taylor_fn_{abs(hash(name))}", columns=columns)
    return lib.function("tc"), [sp.lambdify((q, s, pa, pb), e, modules="mpmath") for e in outputs]


def _cauchy_coefficients(f, q0: float, s0: float, a: float, b: float) -> np.ndarray:
    """Taylor coefficients of ``tau -> f(q0 + tau, s0 + tau, a, b)`` at 0, to ~1e-20 of the largest.

    The Cauchy integral on the circle ``|tau| = 0.1`` by the trapezoidal rule on 64 points at 40
    digits: the rule's error is the aliasing ``c_(k+64) 0.1^64``, negligible for functions analytic
    on the disk of radius 1 (every argument moves by at most 0.13 on the circle, and every
    function of SMOOTH_FUNCTIONS is analytic within 1 of the real axis), and the rounding of 1e-40
    is divided by ``0.1^k <= 1e-20``.  (Checked against ``mpmath.taylor``'s high-precision
    differences, which are ~50 times slower.)
    """
    import mpmath as mp

    n = CAUCHY_POINTS
    with mp.workdps(CAUCHY_DIGITS):
        q0m, s0m, am, bm = (mp.mpf(v) for v in (q0, s0, a, b))
        taus = [CAUCHY_RADIUS * mp.expjpi(2 * mp.mpf(j) / n) for j in range(n)]
        vals = [f(q0m + tau, s0m + tau, am, bm) for tau in taus]
        return np.array([
            float(mp.re(mp.fsum(v * mp.expjpi(-2 * mp.mpf(j * k) / n) for j, v in enumerate(vals)) / n)
                  / mp.mpf(CAUCHY_RADIUS) ** k)
            for k in range(FUNCTION_ORDER + 1)
        ])  # fmt: skip


def _weighted_error(got: np.ndarray, ref: np.ndarray) -> float:
    """``max_k |got_k - ref_k| rho^k / max(max_k |ref_k| rho^k, ERROR_FLOOR)``, ``rho`` the reference's
    radius (at most 1).

    The engine sums ``c_k h^k`` with steps ``h`` below the radius of convergence, so an error in
    ``c_k`` matters as much as its ``rho^k`` multiple does beside the polynomial's largest term.
    """
    k = np.arange(ref.size)
    nonzero = np.abs(ref[1:]) > 0
    rho = (
        min(1.0, float(np.min(np.abs(ref[1:][nonzero]) ** (-1.0 / k[1:][nonzero])))) if nonzero.any() else 1.0
    )
    w = rho**k
    return float(np.max(np.abs(got - ref) * w) / max(np.max(np.abs(ref) * w), ERROR_FLOOR))


ERROR_FLOOR = 1e-2
"""Errors are relative to the polynomial's largest term, or to this where it is smaller: the functions'
own arithmetic is of size 1 (``log(1 + u^2/2)`` with ``u = 5e-4`` is ``1.25e-7``, computed from
``1 + 1.25e-7``, whose rounding, 1e-16, is 1e-9 of the result); a wrong recurrence still errs by
the function's size.  At 1e-3, a log of size 2e-3 erred by 5e-14 of it in 300 random draws and
hypothesis found one at 1.04e-13, over :data:`FUNCTION_TOL`: rounding of arithmetic of size 1, of
size 1e-16, which 1e-2 counts as 1e-14."""
FUNCTION_TOL = 1e-13
"""Each coefficient is a sum of at most k + 1 products of earlier ones, so the rounding of the
recurrences grows at most like k^2 eps (~1e-13 at order 20); measured: below 2e-15 (9 eps) for
every function.  A wrong term of a recurrence gives an error of order 1."""


def _grid(bound: float) -> st.SearchStrategy[float]:
    """Points of ``[-bound, bound]`` in steps of ``bound / 1000`` (values of the size a model has;
    the reference's 40 digits are absolute, not enough for a function of size 1e-230)."""
    return st.integers(-1000, 1000).map(lambda i: i * bound / 1000)


@pytest.mark.parametrize("name", list(SMOOTH_FUNCTIONS))
@settings(max_examples=8, deadline=None)
@given(q0=_grid(0.5), s0=_grid(1.0), a=_grid(0.5), b=_grid(1.0))
@example(q0=0.0, s0=0.0, a=0.0005, b=0.0)  # (a small function of arithmetic of size 1: ERROR_FLOOR)
def test_each_function_against_high_precision_series(name, q0, s0, a, b):
    """The coefficients of f(u(tau)) against the Cauchy integral at 40 digits, u general and affine."""
    tc, refs = _function_kernel(name)
    X = np.zeros((1, FUNCTION_ORDER + 1))
    O = np.zeros((len(ARGUMENTS), FUNCTION_ORDER + 1))
    tc(np.array([q0]), s0, np.array([a, b]), X, O)
    for m, ref in enumerate(refs):
        err = _weighted_error(O[m], _cauchy_coefficients(ref, q0, s0, a, b))
        assert err < FUNCTION_TOL, (name, ["general", "affine"][m], err)


# Every new recurrence inside a system: a power whose base and exponent are states, a parameter as
# an exponent, tanh, atan, asinh, acos, erf, sinh/cosh of general and affine arguments.
RHS_FUNCTIONS = (
    sp.tanh(x) * (2 + y**2) ** (x / 3) - sp.atan(y) + sp.cosh(w * t) / 4 + sp.erf(x * y),
    sp.asinh(x - y) + (1 + x**2) ** c * sp.sinh(x) - sp.acos(x / (2 + x**2)) + sp.tan(y / 3),
)


def test_new_functions_in_a_system_match_symbolic_differentiation():
    order = 4  # (symbolic differentiation of these swells quickly)
    k = taylor_kernel("tc", (x, y), t, (w, c), RHS_FUNCTIONS, OUTPUTS, order=order)
    lib = compile_library(k.source, "test_taylor_fns_4", columns={"tc": {"X": order + 1, "O": order + 1}})
    x0, t0, params = np.array([0.3, -0.7]), 0.4, np.array([1.3, 0.25])
    X = np.zeros((2, order + 1))
    O = np.zeros((2, order + 1))
    lib.function("tc")(x0, t0, params, X, O)
    Xs, Os = _symbolic_coefficients(RHS_FUNCTIONS, OUTPUTS, x0, t0, params, order)
    np.testing.assert_allclose(X, Xs, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(O, Os, rtol=1e-12, atol=1e-13)


def test_reciprocal_functions_are_expanded_as_quotients():
    k = taylor_kernel("tc", (x,), t, (), (sp.sec(x) + sp.coth(2 + x),), order=3)
    assert "math.cos(" in k.source and "math.tanh(" in k.source


@settings(max_examples=10, deadline=None)
@given(
    expr=smooth_expressions((q, s, pa, pb)), q0=_grid(0.5), s0=_grid(1.0), a=_grid(0.5), b=_grid(1.0)
)  # fmt: skip
def test_random_nested_expressions_against_high_precision_series(expr, q0, s0, a, b):
    """Functions nested in each other, with sums, products and quotients (drawn by hypothesis)."""
    k = taylor_kernel("tc", (q,), s, (pa, pb), (sp.Integer(1),), (expr,), order=FUNCTION_ORDER)
    columns = {"tc": {"X": FUNCTION_ORDER + 1, "O": FUNCTION_ORDER + 1}}
    tc = compile_library(k.source, f"test_taylor_random_{abs(hash(expr))}", columns=columns).function("tc")
    X = np.zeros((1, FUNCTION_ORDER + 1))
    O = np.zeros((1, FUNCTION_ORDER + 1))
    tc(np.array([q0]), s0, np.array([a, b]), X, O)
    ref = _cauchy_coefficients(sp.lambdify((q, s, pa, pb), expr, modules="mpmath"), q0, s0, a, b)
    # Where the expression itself cannot be evaluated in double precision to the tolerance (log(1 +
    # a**2/2) at a = 5e-4 loses 9 digits in 1 + a**2/2), no kernel can be that accurate: only
    # expressions that numpy's double-precision evaluation gets right are compared.
    in_double = float(sp.lambdify((q, s, pa, pb), expr, modules="numpy")(q0, s0, a, b))
    assume(_weighted_error(np.concatenate([[in_double], ref[1:]]), ref) < FUNCTION_TOL)
    assert _weighted_error(O[0], ref) < FUNCTION_TOL, expr
