"""The generated Taylor kernels against symbolic differentiation."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from grazing.engine.llvmgen import compile_library
from grazing.engine.taylor import UnsupportedExpressionError, taylor_kernel

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
