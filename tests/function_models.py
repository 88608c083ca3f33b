"""Models written with the smooth functions beyond sin and cos (issue 26).

:data:`SMOOTH_FUNCTIONS` holds one function ``f(q)`` per supported function or
kind of power, defined for every real ``q`` (arguments of ``asin``, ``acos``,
``atanh`` are kept inside (-1, 1), of ``acosh`` above 1, of ``log`` and
non-integer powers positive); :func:`smooth_term` is ``f(q) - f(0)``, which
:mod:`tests.random_models` adds to its drawn models.  :func:`smooth_oscillator`
is a fixed model using several of them at once, with a parameter in an
exponent and a power whose base and exponent are both states, and
:func:`smooth_expressions` draws expressions that nest them.
"""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp
from hypothesis import strategies as st

import grazing


def _bounded(q: sp.Expr) -> sp.Expr:
    """``q / (2 + q^2)``, in ``[-0.36, 0.36]`` for every real ``q``."""
    return q / (2 + q**2)


SMOOTH_FUNCTIONS: dict[str, Callable[[sp.Expr], sp.Expr]] = {
    "tan": lambda q: sp.tan(_bounded(q)),
    "sinh": lambda q: sp.sinh(q / 2),
    "cosh": lambda q: sp.cosh(q / 2),
    "tanh": sp.tanh,
    "asin": lambda q: sp.asin(_bounded(q)),
    "acos": lambda q: sp.acos(_bounded(q)),
    "atan": sp.atan,
    "asinh": sp.asinh,
    "acosh": lambda q: sp.acosh(2 + q**2),
    "atanh": lambda q: sp.atanh(_bounded(q)),
    "erf": sp.erf,
    "erfc": sp.erfc,
    "log": lambda q: sp.log(1 + q**2 / 2),
    "exp": lambda q: sp.exp(-(q**2)),
    "sqrt": lambda q: sp.sqrt(1 + q**2),
    "rational power": lambda q: (1 + q**2) ** sp.Rational(3, 2),
    "real power": lambda q: (2 + q**2) ** sp.Float(0.37),
    "variable power": lambda q: (2 + q**2) ** (q / 4),
    "sec": lambda q: sp.sec(_bounded(q)),
    "coth": lambda q: sp.coth(2 + q**2),
}
"""``f(q)`` for each smooth function the Taylor kernels expand (beyond sin, cos), analytic for real ``q``
and within 1 of the real axis."""


def smooth_term(name: str, q: sp.Expr) -> sp.Expr:
    """``f(q) - f(0)`` for the function ``name`` of :data:`SMOOTH_FUNCTIONS`: a term that vanishes at 0."""
    f = SMOOTH_FUNCTIONS[name]
    return f(q) - f(sp.Integer(0))


def smooth_oscillator(**values: float) -> grazing.HybridModel:
    """A forced oscillator whose restoring force, damping and forcing use the new functions.

    ::

        x' = v
        v' = -k tanh(x) - c atan(v) + amp (2 + sin(w t))^p cos(w t) + (2 + x^2)^(v/4) / 10
        a stop where x + atan(x^2)/20 = gap, v <- -r v (1 + tanh(x)/10)

    The exponent ``p`` is a parameter (its sensitivity goes through ``log`` of the
    base), and ``(2 + x^2)^(v/4)`` a power with both base and exponent variable.  The guard and
    the reset use the new functions too (their derivatives, the saltation matrix and the sticking
    field are generated from them).
    """
    x, v, t = sp.symbols("x v t")
    k, c, amp, w, p, gap, r = sp.symbols("k c amp w p gap r")
    P = grazing.Parameter
    params = [
        P("k", 1.0, lower=0.0, lower_open=True),
        P("c", 0.1, lower=0.0),
        P("amp", 0.6),
        P("w", 1.3, lower=0.0, lower_open=True),
        P("p", 0.7),
        P("gap", 0.8, lower=0.0, lower_open=True),
        P("r", 0.7, lower=0.0, upper=1.0),
    ]
    accel = (
        -k * sp.tanh(x)
        - c * sp.atan(v)
        + amp * (2 + sp.sin(w * t)) ** p * sp.cos(w * t)
        + (2 + x**2) ** (v / 4) / 10
    )
    model = grazing.HybridModel(
        "smooth-oscillator", [x, v], t, params, vector_field=[v, accel], guard=gap - x - sp.atan(x**2) / 20,
        reset=[x, -r * v * (1 + sp.tanh(x) / 10)], period=2 * sp.pi / w, contact_direction=[0, 1],
    )  # fmt: skip
    return model.with_params(**values) if values else model


@st.composite
def smooth_expressions(draw: st.DrawFn, leaves: tuple[sp.Expr, ...], depth: int = 2) -> sp.Expr:
    """A random expression of ``leaves``: functions of :data:`SMOOTH_FUNCTIONS` nested in each
    other, sums, products and quotients ``a / (2 + b^2)``, defined for every real value of the leaves."""
    if depth == 0 or draw(st.integers(0, 3)) == 0:
        scale = draw(st.sampled_from([sp.Integer(1), sp.Integer(2), sp.Rational(1, 2), sp.Rational(-3, 4)]))
        return scale * draw(st.sampled_from(leaves))
    kind = draw(st.sampled_from(["function", "function", "sum", "product", "quotient"]))
    a = draw(smooth_expressions(leaves, depth - 1))
    if kind == "function":
        return SMOOTH_FUNCTIONS[draw(st.sampled_from(sorted(SMOOTH_FUNCTIONS)))](a)
    b = draw(smooth_expressions(leaves, depth - 1))
    return {"sum": a + b, "product": a * b, "quotient": a / (2 + b**2)}[kind]
