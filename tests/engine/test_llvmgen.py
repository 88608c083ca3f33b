"""The translation of generated straight-line code to machine code (grazing.engine.llvmgen).

The generated functions are plain Python: run by CPython they give the
reference, and the compiled code must give the same bits (same operations in
the same order, the same C library functions, and grazing's own ``sin`` and
``cos`` of :mod:`grazing.engine.sincos` in place of the C library's).
"""

from __future__ import annotations

import math
import types

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from grazing.engine import sincos
from grazing.engine.llvmgen import UntranslatableCodeError, compile_library
from grazing.engine.taylor import taylor_kernel

x, y, t = sp.symbols("x y t")
w, c = sp.symbols("w c")
RHS = (
    y * sp.cos(w * t) - sp.sin(x) + sp.exp(-(x**2)) / (2 + sp.cos(t)),
    -c * y - x**3 + sp.log(3 + x**2) + sp.sqrt(1 + y**2) + (1 + x**2) ** sp.Rational(1, 3),
)
OUTPUTS = (x - sp.sin(t) * sp.atan(w), x * y - c)
ORDER = 12


MATH = types.SimpleNamespace(**{**vars(math), "sin": sincos.sin, "cos": sincos.cos})
"""``math`` as the compiled code sees it: grazing's sin and cos, the C library's other functions."""


def _python(source: str, name: str):
    namespace: dict = {"math": MATH}
    exec(source, namespace)  # our own generated code
    return namespace[name]


@pytest.fixture(scope="module")
def taylor():
    k = taylor_kernel("tc", (x, y), t, (w, c), RHS, OUTPUTS, order=ORDER)
    lib = compile_library(k.source, "test_llvmgen_tc", columns={"tc": {"X": ORDER + 1, "O": ORDER + 1}})
    return _python(k.source, "tc"), lib.function("tc")


@settings(max_examples=40, deadline=None)
@given(
    st.floats(-2, 2), st.floats(-2, 2), st.floats(0, 7), st.floats(0.1, 3), st.floats(-1, 1)
)  # fmt: skip
def test_taylor_kernel_agrees_with_the_python_text(taylor, x0, y0, s0, w0, c0):
    """To rounding, at the scale of each series: LLVM (here as in numba) rewrites ``x ** 0.5``
    (``sqrt(1 + y**2)`` in RHS) as the correctly rounded ``sqrt(x)``, where CPython calls ``pow``,
    which can be one ulp off (found by hypothesis at x0 = s0 = c0 = 0, y0 = 1.3153:
    1.6522626223201962 against 1.652262622320196).  That ulp goes through the recurrence to the
    higher coefficients, where sums of terms larger than the coefficient make it several ulps of
    the coefficient (9 at y0 = 1.8352, also found by hypothesis): each coefficient must agree to
    :data:`SERIES_EPS` of its series' largest (measured: 2.4)."""
    py, compiled = taylor
    pv = np.array([w0, c0])
    Xp, Op = np.zeros((2, ORDER + 1)), np.zeros((2, ORDER + 1))
    Xc, Oc = np.zeros((2, ORDER + 1)), np.zeros((2, ORDER + 1))
    py(np.array([x0, y0]), s0, pv, Xp, Op)
    compiled(np.array([x0, y0]), s0, pv, Xc, Oc)
    for a, b in ((Xp, Xc), (Op, Oc)):
        scale = np.max(np.abs(a), axis=1, keepdims=True)
        assert np.all(np.abs(a - b) <= SERIES_EPS * np.finfo(float).eps * scale), (a, b)
        np.testing.assert_array_max_ulp(a[:, 0], b[:, 0], maxulp=1)  # (the values themselves)


SERIES_EPS = 16
"""Rounding units, of a series' largest coefficient, within which two evaluations of the same
Taylor recurrence agree when their inputs differ by an ulp."""


SCALAR = """
def f(x, s, pv, out, M):
    t_0 = x[0] * pv[1]
    out[0] = (t_0 if x[1] > 0.0 else -t_0) + abs(x[1]) * math.pi
    out[1] = min(x[0], x[1]) - max(x[0], 2.0) + math.tanh(s) + math.atan2(x[0], x[1]) + math.sin(s)
    out[2] = 1.0 / x[2]
    out[3] = 1.0 if (x[0] < x[1] and not x[1] == 3.0) or x[0] != x[0] else 0.0
    M[1, 2] = x[0] ** 2.5 + math.exp(s) - math.log(pv[0]) + math.sqrt(pv[0]) + math.erf(s) * math.cos(s)
    return x[0] * x[1] - s
"""


def test_scalar_constructs_match_python():
    lib = compile_library(SCALAR, "test_llvmgen_scalar", columns={"f": {"M": 3}})
    py, compiled = _python(SCALAR, "f"), lib.function("f")
    rng = np.random.default_rng(3)
    for _ in range(50):
        xv = np.concatenate([rng.uniform(0.1, 3, 2) * rng.choice([-1, 1], 2), [rng.uniform(0.5, 2)]])
        xv[0] = abs(xv[0])
        s, pv = float(rng.uniform(-2, 2)), rng.uniform(0.5, 2, 2)
        outs = [(np.zeros(4), np.zeros((2, 3))) for _ in range(2)]
        r_py = py(xv, s, pv, *outs[0])
        r_c = compiled(xv, s, pv, *outs[1])
        assert r_py == r_c
        assert np.array_equal(outs[0][0], outs[1][0]) and np.array_equal(outs[0][1], outs[1][1])


def test_division_by_zero_is_ieee():
    lib = compile_library(SCALAR, "test_llvmgen_div", columns={"f": {"M": 3}})
    out, M = np.zeros(4), np.zeros((2, 3))
    lib.function("f")(np.array([1.0, 1.0, 0.0]), 0.0, np.array([1.0, 1.0]), out, M)
    assert out[2] == math.inf


def test_dispatch_on_the_stop_index():
    src = "def g_s0(x, s, pv):\n    return x[0]\n\ndef g_s1(x, s, pv):\n    return -x[0] + 2.0\n"
    lib = compile_library(src, "test_llvmgen_dispatch", dispatch={"g": ["g_s0", "g_s1"]})
    g = lib.function("g")
    xv, pv = np.array([0.5]), np.zeros(1)
    assert (g(xv, 0.0, pv, 0), g(xv, 0.0, pv, 1), g(xv, 0.0, pv, 7)) == (0.5, 1.5, 1.5)


@pytest.mark.parametrize(
    "body", ["out[0] = x[i]", "out[0] = sorted(x)", "out[0] = math.frexp(x[0])", "for i in x:\n        pass"]
)
def test_untranslatable_code_is_refused(body):
    with pytest.raises(UntranslatableCodeError):
        compile_library(f"def f(x, s, pv, out):\n    {body}\n", "test_llvmgen_bad")


def test_arrays_must_be_contiguous_float64():
    lib = compile_library("def f(x, s, pv):\n    return x[0]\n", "test_llvmgen_arrays")
    with pytest.raises(TypeError, match="C-contiguous float64"):
        lib.function("f")(np.arange(3), 0.0, np.zeros(1))
