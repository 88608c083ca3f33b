"""grazing's sin and cos (grazing.engine.sincos): accurate, and the same bits on a scalar and on lanes.

1. The reference (:func:`grazing.engine.sincos.sincos`, run by CPython) is
   within one ulp of mpmath's correctly rounded values: uniformly over the fast
   path's range, near multiples of pi/2 (the hardest arguments for the range
   reduction: the doubles closest to ``k pi/2`` found by an exact integer
   scan of every ``k``), tiny and subnormal arguments, signed zeros; beyond
   :data:`~grazing.engine.sincos.LIMIT` and for NaN and infinities it is the C
   library's.
2. The compiled code (:mod:`grazing.engine.llvmgen`) gives the reference's
   bits, on a scalar and on each of ``L`` lanes, whatever the other lanes hold
   (arguments of any size, NaN, infinities: lanes of the slow path mixed with
   fast ones).
3. A model with ``sin`` and ``cos`` of its states and of ``2 t`` (two stops,
   unusual names): its lane kernels equal its scalar kernels, and a sweep on
   lanes equals the scalar oracle of ``tests/engine/test_lanes.py``, bit for bit.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from grazing.engine import llvmgen
from grazing.engine.sincos import LIMIT, sincos

L = llvmgen.lane_width()
SOURCE = "def f(x, s, pv, out):\n    u = x[0]\n    out[0] = math.sin(u)\n    out[1] = math.cos(u)\n"
"""sin and cos of one value (as the Taylor kernels have them): computed together."""


@pytest.fixture(scope="module")
def compiled():
    """``(scalar, lanes)``: each maps an array of arguments to the arrays ``(sin, cos)``."""
    lib = llvmgen.compile_library(SOURCE, "test_sincos", lanes=L, lane_functions=("f",))
    scalar, lanes = lib.function("f"), llvmgen._CFUNC(lib.address("f_lanes"))
    pv, times = np.zeros(L), np.zeros(L)

    def run_scalar(xs: np.ndarray) -> np.ndarray:
        out = np.zeros((len(xs), 2))
        for i, x in enumerate(xs):
            scalar(np.array([x]), 0.0, pv, out[i])
        return out.T

    def run_lanes(xs: np.ndarray) -> np.ndarray:
        n = len(xs)
        padded = np.ascontiguousarray(np.concatenate([xs, np.zeros(-n % L)]))
        out = np.zeros((len(padded) // L, 2, L))
        for i in range(len(padded) // L):
            lanes(
                padded[i * L :].ctypes.data, 0.0, pv.ctypes.data, out[i].ctypes.data, 0, times.ctypes.data, 0
            )
        return out.transpose(1, 0, 2).reshape(2, -1)[:, :n]

    return run_scalar, run_lanes


def reference(xs) -> np.ndarray:
    return np.array([sincos(float(x)) for x in xs]).reshape(-1, 2).T


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal bit for bit (any NaN equals any NaN: the C library's NaN may carry a sign)."""
    nan = np.isnan(a) & np.isnan(b)
    return bool(np.array_equal(np.where(nan, 0.0, a).view(np.int64), np.where(nan, 0.0, b).view(np.int64)))


mpmath.mp.prec = 200


def ulp_errors(xs) -> np.ndarray:
    """Errors of the reference's sin and cos in ulps of the true values (mpmath, 200 bits)."""
    out = []
    for x in xs:
        s, c = sincos(float(x))
        row = []
        for got, f in ((s, mpmath.sin), (c, mpmath.cos)):
            true = f(mpmath.mpf(float(x)))
            row.append(float(abs(mpmath.mpf(got) - true) / math.ulp(float(true))))
        out.append(row)
    return np.array(out)


@functools.cache
def hardest_multiples(count: int) -> list[float]:
    """The ``count`` doubles below LIMIT closest to a multiple ``k pi/2`` relative to their size
    (the most cancellation in the range reduction; every ``k``, exactly)."""
    bits = 240
    pio2 = int(mpmath.floor(mpmath.pi / 2 * mpmath.mpf(2) ** bits))  # pi/2 in fixed point, to 2^-240
    best: list[tuple[float, int, int]] = []
    for k in range(1, int(LIMIT * 2 / math.pi) + 1):
        q = k * pio2  # k pi/2 (to k 2^-240)
        shift = q.bit_length() - 53  # the double's grid, 2^(e - 52) for 2^e <= k pi/2, in units of 2^-240
        m = (q + (1 << (shift - 1))) >> shift
        rem = abs(q - (m << shift))  # |x - k pi/2| in units of 2^-240
        best.append((rem / q, m, shift - bits))
    best.sort()
    return [math.ldexp(m, e) for _, m, e in best[:count]]


# ----------------------------------------------------------------------------- accuracy


def test_hardest_multiples_are_found() -> None:
    """The scan's doubles are closer to ``k pi/2`` than ``2^-60 x`` (the nearest double to a random
    ``k pi/2`` is ~``2^-55 x`` away), for ``k`` up to ``2^20 2/pi``."""
    xs = hardest_multiples(20)
    assert all(math.pi / 2 < x < LIMIT for x in xs) and max(xs) > 1000
    for x in xs:
        k = round(x / (math.pi / 2))
        assert abs(mpmath.mpf(x) - k * mpmath.pi / 2) < 2.0**-60 * x


def test_within_one_ulp_of_mpmath() -> None:
    rng = np.random.default_rng(11)
    near = hardest_multiples(20)
    cases = {
        "uniform in [-LIMIT, LIMIT]": rng.uniform(-LIMIT, LIMIT, 3000),
        "uniform in [-4, 4]": rng.uniform(-4.0, 4.0, 3000),
        "log-uniform sizes": np.copysign(2.0 ** rng.uniform(-40, 20, 3000), rng.uniform(-1, 1, 3000)),
        "near multiples of pi/2": [y for x in near for y in (np.nextafter(x, 0), x, np.nextafter(x, np.inf))]
        + [(k * math.pi / 2) for k in range(1, 2000)],
        "tiny and subnormal": [1e-300, -(2.0**-1022), 5e-324, -5e-324, 2.0**-1074 * 12345, 2.0**-27, 1e-9],
        "the edge of the range": [
            np.nextafter(LIMIT, 0),
            -np.nextafter(LIMIT, 0),
            math.pi / 4,
            3 * math.pi / 4,
        ],
    }
    for name, xs in cases.items():
        err = ulp_errors(xs)
        assert err.max() < 1.0, (name, err.max(), xs[int(np.argmax(err.max(axis=1)))])


def test_special_values() -> None:
    assert sincos(0.0) == (0.0, 1.0) and math.copysign(1.0, sincos(-0.0)[0]) == -1.0
    assert sincos(-0.0)[1] == 1.0
    for x in (math.inf, -math.inf, math.nan):
        assert all(math.isnan(v) for v in sincos(x))
    for x in (LIMIT, -LIMIT, 1e22, -3.5e200, 1.7e308):  # beyond the fast path: the C library
        assert sincos(x) == (math.sin(x), math.cos(x))


@settings(max_examples=300, deadline=None)
@given(st.floats(-LIMIT, LIMIT))
def test_property_within_one_ulp(x: float) -> None:
    assert ulp_errors([x]).max() < 1.0


# ----------------------------------------------------------------------------- compiled = reference


def test_compiled_scalar_and_lanes_equal_the_reference(compiled) -> None:
    run_scalar, run_lanes = compiled
    rng = np.random.default_rng(5)
    xs = np.concatenate(
        [
            rng.uniform(-LIMIT, LIMIT, 2000),
            rng.uniform(-7, 7, 2000),
            hardest_multiples(20),
            [
                0.0,
                -0.0,
                5e-324,
                -5e-324,
                LIMIT,
                -LIMIT,
                np.nextafter(LIMIT, 0),
                1e300,
                np.inf,
                -np.inf,
                np.nan,
            ],
        ]
    )
    rng.shuffle(xs)  # the slow lanes among fast ones
    ref = reference(xs)
    assert same_bits(run_scalar(xs), ref)
    assert same_bits(run_lanes(xs), ref)


@settings(max_examples=150, deadline=None)
@given(
    st.lists(
        st.one_of(
            st.floats(), st.floats(-10.0, 10.0), st.floats(-LIMIT, LIMIT), st.sampled_from([-0.0, 0.0])
        ),
        min_size=L,
        max_size=L,
    )
)
def test_property_each_lane_is_the_scalar(compiled, xs: list[float]) -> None:
    run_scalar, run_lanes = compiled
    xs_ = np.array(xs)
    assert same_bits(run_lanes(xs_), run_scalar(xs_))
    assert same_bits(run_scalar(xs_), reference(xs_))


def test_ir_calls_the_c_library_only_on_the_slow_path() -> None:
    module = str(llvmgen.translate(SOURCE, "t", lanes=L, lane_functions=("f",)))
    assert "llvm.sin" not in module and "llvm.cos" not in module
    calls, block = [], ""
    for line in module.splitlines():
        if line.endswith(":") and not line.startswith(" "):  # a block's label
            block = line.strip('":')
        elif 'call double @"sin"' in line or 'call double @"cos"' in line:
            calls.append(block)
    # sin and cos: once in the scalar function, once per lane in the lane function, all on the slow path
    assert len(calls) == 2 * (1 + L) and all(b.startswith("sincos_slow") for b in calls), calls


# ----------------------------------------------------------------------------- a model with sin of its states

MODEL_FILE = """
import sympy as sp
from grazing import HybridModel, Parameter, Stop

phi, w_dot, t = sp.symbols("phi_1 w_dot t")
k, c, a, gap, r = sp.symbols("k c a_2t gap r")
MODEL = HybridModel(
    "trig rotor",
    [phi, w_dot],
    t,
    [Parameter("k", 1.0), Parameter("c", 0.1, lower=0), Parameter("a_2t", 0.9),
     Parameter("gap", 0.3), Parameter("r", 0.8, lower=0, upper=1)],
    vector_field=[w_dot, -k * sp.sin(phi) - c * w_dot + a * sp.cos(2 * t) + sp.sin(phi) * sp.cos(3 * phi)],
    stops=[
        Stop("Upper_Wall2", gap - sp.sin(phi), [phi, -r * w_dot], [0, 1]),
        Stop("lower_wall", phi + 1.2 + sp.cos(phi) / 10, [phi, -r * w_dot], [0, 1]),
    ],
    period=sp.pi,
)
"""
"""``sin`` and ``cos`` of the state (in the field and in a guard) and of ``2 t``; two stops, unusual names."""


@pytest.fixture(scope="module")
def trig_model(tmp_path_factory):
    from grazing.cli.common import load_model

    path = tmp_path_factory.mktemp("models") / "trig_rotor.py"
    path.write_text(MODEL_FILE)
    return load_model(f"{path}:MODEL")


def test_a_model_with_sin_of_its_states_on_lanes_equals_the_scalar_path(trig_model) -> None:
    from grazing.core.options import SweepSettings
    from grazing.sweeps.run import run_chunks
    from grazing.sweeps.spec import sweep_spec
    from tests.engine.test_lanes import assert_chunks_equal, check_lane_functions

    check_lane_functions(trig_model, np.random.default_rng(17))
    settings_ = SweepSettings(transient=40, periods=16, chunk_size=3, lyapunov=False)
    spec = dataclasses.replace(  # (the engine against its oracle: without the Newton polish, a layer above)
        sweep_spec(trig_model, "a_2t", np.linspace(0.8, 2.0, 9), settings=settings_), polish=False
    )
    results = run_chunks(spec, list(range(spec.n_chunks)))
    by_stop = sum(np.asarray(res.impacts_by_stop).sum(axis=0) for res in results)
    assert by_stop.min() > 0  # both stops are hit (their guards and resets run)
    assert_chunks_equal(spec, results, "trig rotor")
