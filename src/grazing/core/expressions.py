"""Which sympy functions a model may use, checked when the model is built.

The engine integrates a model with Taylor series (:mod:`grazing.engine.taylor`),
so every function of the vector field, guards, resets, contact directions and
period must have a Taylor-coefficient recurrence.  These are the
:data:`SMOOTH_FUNCTIONS` (with ``+``, ``-``, ``*``, ``/`` and powers, whose
exponent may be a number, a parameter or an expression of the state).  A
non-smooth function (:data:`NON_SMOOTH`: ``Abs``, ``sign``, ``Heaviside``,
``Max``, ``floor`` ...) has no Taylor series at its switch: it belongs in a
stop (a guard where it switches, a reset), so it is refused with one line
saying so; any other function is refused with one line naming it.

:func:`smooth_form` rewrites the reciprocal functions (``sec``, ``csc``,
``cot``, ``sech``, ``csch``, ``coth``) into the ones the kernels expand.

Examples
--------
>>> import sympy as sp
>>> x = sp.Symbol("x")
>>> check_expression(sp.tanh(x) + sp.sqrt(1 + x**2), "the vector field")
>>> print(unsupported(sp.Abs(x), "the vector field"))  # doctest: +NORMALIZE_WHITESPACE
Abs is not smooth (Abs(x) in the vector field): model it as a stop (a guard and a reset),
see docs/user-models.md
"""

from __future__ import annotations

from typing import Any

from grazing.errors import UnsupportedExpressionError

SMOOTH_FUNCTIONS = (
    "exp", "log", "sin", "cos", "tan", "sinh", "cosh", "tanh", "asin", "acos", "atan", "asinh", "acosh",
    "atanh", "erf", "erfc", "sec", "csc", "cot", "sech", "csch", "coth",
)  # fmt: skip
"""The sympy functions the Taylor kernels expand (besides ``+ - * /`` and powers; ``sqrt`` is a power)."""

RECIPROCALS = {"sec": "cos", "csc": "sin", "cot": "tan", "sech": "cosh", "csch": "sinh", "coth": "tanh"}
"""Functions expanded as ``1 / f``: ``sec(u) = 1 / cos(u)`` ..."""

NON_SMOOTH = (
    "Abs", "sign", "Heaviside", "Max", "Min", "floor", "ceiling", "frac", "Mod", "Piecewise", "DiracDelta",
    "SingularityFunction", "KroneckerDelta", "re", "im", "arg", "conjugate",
)  # fmt: skip
"""Functions with a switch (a kink, a jump): they belong in a stop, not in a smooth expression."""

ADVICE = "see docs/user-models.md"

_SHOWN = 60
"""Characters of an offending sub-expression shown in a message."""


def _shown(node: Any) -> str:
    text = " ".join(str(node).split())
    return text if len(text) <= _SHOWN else text[: _SHOWN - 3] + "..."


def supported_text() -> str:
    """The supported operations and functions, as a message lists them."""
    return "+, -, *, /, powers (sqrt, x**p, x**y), " + ", ".join(SMOOTH_FUNCTIONS)


def unsupported(expr: Any, where: str) -> str | None:
    """Why ``expr`` (in ``where``, for the message) cannot be expanded, or None if it can.

    Examples
    --------
    >>> import sympy as sp
    >>> x = sp.Symbol("x")
    >>> print(unsupported(sp.besselj(0, x), "the guard"))  # doctest: +NORMALIZE_WHITESPACE
    besselj is not supported by the Taylor kernels (besselj(0, x) in the guard): write it with
    +, -, *, /, powers (sqrt, x**p, x**y), exp, log, sin, cos, tan, sinh, cosh, tanh, asin, acos,
    atan, asinh, acosh, atanh, erf, erfc, sec, csc, cot, sech, csch, coth; see docs/user-models.md
    >>> unsupported(x ** sp.Symbol("y"), "the guard") is None
    True
    """
    import sympy as sp
    from sympy.core.function import AppliedUndef

    for node in sp.preorder_traversal(expr):
        if isinstance(node, (sp.Symbol, sp.Add, sp.Mul, sp.Pow)):
            continue
        if node is sp.I:
            return f"the imaginary unit I in {where}: a model's expressions are real"
        if node.is_Atom and node.is_number:  # numbers, pi, E, oo, nan, zoo
            if node.is_extended_real and node.is_finite:
                continue
            return f"{_shown(node)} in {where} is not a finite real number"
        if isinstance(node, AppliedUndef):
            return (
                f"{_shown(node)} in {where} is an undefined function: write it out with supported "
                f"functions; {ADVICE}"
            )
        name = type(node).__name__
        if name in SMOOTH_FUNCTIONS:
            continue
        if name in NON_SMOOTH:
            return (
                f"{name} is not smooth ({_shown(node)} in {where}): model it as a stop "
                f"(a guard and a reset), {ADVICE}"
            )
        return (
            f"{name} is not supported by the Taylor kernels ({_shown(node)} in {where}): write it with "
            f"{supported_text()}; {ADVICE}"
        )
    return None


def check_expression(expr: Any, where: str) -> None:
    """Raise :class:`~grazing.errors.UnsupportedExpressionError` (one line) if ``expr`` cannot be expanded."""
    reason = unsupported(expr, where)
    if reason is not None:
        raise UnsupportedExpressionError(reason)


def smooth_form(expr: Any) -> Any:
    """``expr`` with the reciprocal functions written as ``1 / f`` (``sec(u) -> 1/cos(u)``); else unchanged.

    Examples
    --------
    >>> import sympy as sp
    >>> x = sp.Symbol("x")
    >>> smooth_form(sp.sec(x) + sp.coth(x))
    1/tanh(x) + 1/cos(x)
    """
    import sympy as sp

    kinds = tuple(getattr(sp, name) for name in RECIPROCALS)
    if not expr.has(*kinds):
        return expr
    return expr.replace(
        lambda e: isinstance(e, kinds),
        lambda e: 1 / getattr(sp, RECIPROCALS[type(e).__name__])(e.args[0]),
    )
