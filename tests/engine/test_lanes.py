"""SIMD lanes: the lane functions and the sweep driver on lanes give the scalar path's numbers, bit for bit.

1. Each lane of a model's lane function (``tc_free_lanes``, ``tc_var_lanes``,
   :mod:`grazing.engine.llvmgen`) equals the scalar kernel at that lane's
   state, time and parameters, for the built-in models and random ones.
2. The sweep driver on lanes (:mod:`grazing.engine.driver.lanes`) equals an
   independent oracle written here over :class:`grazing.engine.runner.Runner`
   (the scalar driver called period block by period block, the protocol of a
   sweep point as :mod:`grazing.sweeps.run` describes it), and does not
   depend on the number of lanes or on how chunks are grouped: continuation
   and fresh sweeps, adaptive transients, Lyapunov exponents, chattering and
   sticking, the discontinuity map, and a point that fails.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import grazing
from grazing.core.options import SweepSettings
from grazing.core.period import DEFAULT_MAX_PERIOD, DEFAULT_PERIOD_TOL, detect_period
from grazing.core.solution import Status
from grazing.engine import llvmgen
from grazing.engine.abi import TC_FREE_LANES, TC_VAR_LANES
from grazing.engine.codegen import taylor_order
from grazing.engine.runner import Runner
from grazing.errors import SimulationError
from grazing.models import bouncing_ball, impact_oscillator, pendulum, two_sided_oscillator
from grazing.sweeps.run import LaneBatch, run_chunks, stream_chunks
from grazing.sweeps.spec import SweepSpec, sweep_spec
from tests.function_models import smooth_oscillator
from tests.random_models import ModelSpec, model_specs

CFUNC = llvmgen._CFUNC


# ----------------------------------------------------------------------------- lane functions


def check_lane_functions(model: grazing.HybridModel, rng: np.random.Generator, trials: int = 5) -> None:
    kern = model.kernels()
    L, n, K, nstops = kern.LANES, kern.NX, kern.ORDER + 1, kern.ROWS.shape[1]
    assert L == llvmgen.lane_width()
    fns = kern.table[0]
    p0 = model.param_vector
    slots = ((TC_FREE_LANES, kern.tc_free, n), (TC_VAR_LANES, kern.tc_var, n + n * n))
    for (slot, scalar, rows), mode in itertools.product(slots, range(kern.NMODES)):  # (each mode's kernels)
        lanes = CFUNC(int(fns[slot]))
        for _ in range(trials):
            x = np.ascontiguousarray(rng.normal(size=(rows, L)))
            s = rng.uniform(0.0, 2 * model.period, L)
            pv = np.ascontiguousarray(p0[:, None] * rng.uniform(0.8, 1.2, (len(p0), L)))
            XL, OL = np.full((rows, K, L), np.nan), np.full((nstops, K, L), np.nan)
            lanes(x.ctypes.data, 0.0, pv.ctypes.data, XL.ctypes.data, OL.ctypes.data, s.ctypes.data, mode)
            for lane in range(L):
                X, O = np.zeros((rows, K)), np.zeros((nstops, K))
                scalar(x[:, lane].copy(), s[lane], pv[:, lane].copy(), X, O, mode)
                assert np.array_equal(X, XL[:, :, lane], equal_nan=True), (model.name, slot, lane, mode)
                assert np.array_equal(O, OL[:, :, lane], equal_nan=True), (model.name, slot, lane, mode)


@pytest.mark.parametrize(
    "make",
    [
        lambda: pendulum("B", theta_hat=math.radians(40)),
        lambda: bouncing_ball(amplitude=1.2),
        lambda: impact_oscillator(sigma=0.1, omega=2.0),
        lambda: two_sided_oscillator(),
    ],
    ids=["pendulum", "bouncing-ball", "impact-oscillator", "two-sided"],
)
def test_lane_functions_equal_the_scalar_kernel(make) -> None:
    check_lane_functions(make(), np.random.default_rng(7))


@settings(max_examples=2)
@given(spec=model_specs())
def test_lane_functions_of_random_models(spec: ModelSpec) -> None:
    check_lane_functions(spec.model(), np.random.default_rng(3), trials=2)


def test_models_with_sensitivity_directions_have_no_lane_functions() -> None:
    kern = pendulum("B").kernels(1)
    assert kern.LANES == 0 and not kern.table[0][TC_FREE_LANES]


def test_lane_ir_is_vector_code() -> None:
    src = (
        "def tc(x, s, pv, X, O):\n"
        "    X[0, 0] = math.sin(s) * pv[0] + x[0] ** 2\n"
        "    O[0, 0] = math.tan(x[0])\n"
    )
    columns = {"tc": {"X": 1, "O": 1}}
    ir_text = str(llvmgen.translate(src, "v", columns=columns, lanes=4, lane_functions=("tc",)))
    # a vector intrinsic; sin on vectors is grazing's own arithmetic (tests/engine/test_sincos.py)
    assert "<4 x double>" in ir_text and "llvm.pow.v4f64" in ir_text and "llvm.sin" not in ir_text
    # no vector tan: the scalar function's call, then one per lane
    assert ir_text.count('call double @"tan"') == 1 + 4


# ----------------------------------------------------------------------------- the sweep driver

BLOCK, MAX_P, TOL, ALIGN = 32, 16, 1e-9, 16


def oracle_point(spec: SweepSpec, model, x, t0, mode=0):
    """A sweep point over Runner, period block by period block (the protocol of grazing.sweeps.run), from
    ``x`` at ``t0`` in mode ``mode``; its samples, impacts by stop, exponent, transient used and end (state,
    time, mode)."""
    run = Runner(model, x, t0=t0, phase=spec.phase, tol=spec.tol, zdm=spec.zdm, mode=mode)
    align = min(ALIGN, spec.transient) if spec.lyapunov else 0
    budget, used = spec.transient - align, 0
    while used < budget:
        block = min(BLOCK, budget - used)
        seg = run.advance(block, block if spec.adaptive else 0)
        used += block
        if spec.adaptive and block == BLOCK:
            p = detect_period(seg.samples, tol=TOL, max_period=MAX_P)
            if p > 0:
                extra = (budget - used) % p
                if extra:
                    run.advance(extra, 0)
                    used += extra
                break
    if spec.lyapunov:
        final = Runner(model, run.x, t0=run.t, phase=spec.phase, tol=spec.tol, variational=True, zdm=spec.zdm)
        final.mode, final.vf = run.mode, run.vf
        seg = final.advance(align + spec.periods, spec.periods, lyapunov=True, impacts="sampled")
        lyap = (
            float(np.max(seg.log_sums / seg.lyap_span)) if seg.jacobian_valid and seg.lyap_span else math.nan
        )
    else:
        final = run
        seg = run.advance(spec.periods, spec.periods, impacts="sampled")
        lyap = math.nan
    n = model.n_states
    by_stop = np.bincount(seg.impacts[:, 2 + n].astype(np.int64), minlength=model.n_stops)
    return seg.samples, by_stop, lyap, used + align, final.x, final.t, final.vf


def oracle_chunk(spec: SweepSpec, index: int) -> dict[str, np.ndarray]:
    pts = spec.points[spec.chunk(index)]
    keys = ("samples", "period", "by_stop", "lyapunov", "used", "x_final", "mode_final")
    out: dict[str, list] = {k: [] for k in keys}
    x0 = np.asarray(spec.x0, dtype=float)
    mode0 = spec.model.mode_index(None)
    x, t0, mode, carried = x0.copy(), 0.0, mode0, False
    if spec.resume is not None and index == 0 and not spec.fresh:  # (a chain continued: its start)
        t0, x, carried = spec.resume[0], np.asarray(spec.resume[1], dtype=float), True
        mode = spec.resume[2] if len(spec.resume) > 2 else mode0
    first = True
    for pt in pts:
        model = spec.model_at(pt)
        if carried and model.periodic and not first:
            t0 = (spec.phase / (2 * math.pi)) % 1.0 * model.period
        first = False
        start_x, start_t, start_mode = (x0, 0.0, mode0) if spec.fresh or not carried else (x, t0, mode)
        try:
            samples, by_stop, lyap, used, x, t0, mode = oracle_point(
                spec, model, start_x, start_t, start_mode
            )
        except SimulationError:
            n = model.n_states
            samples, by_stop, lyap, used = (
                np.full((spec.periods, n), np.nan),
                [-1] * model.n_stops,
                math.nan,
                -1,
            )
            out["x_final"].append(np.full(n, np.nan))
            out["mode_final"].append(-1)
            out["period"].append(-1)
            carried = False
        else:
            out["x_final"].append(x)
            out["mode_final"].append(mode)
            out["period"].append(detect_period(samples, DEFAULT_PERIOD_TOL, DEFAULT_MAX_PERIOD))
            carried = True
        out["samples"].append(samples)
        out["by_stop"].append(by_stop)
        out["lyapunov"].append(lyap)
        out["used"].append(used)
    return {k: np.asarray(v) for k, v in out.items()}


def assert_chunks_equal(spec: SweepSpec, results, lanes: str) -> None:
    for res in results:
        ref = oracle_chunk(spec, res.index)
        got = {
            "samples": res.samples,
            "period": res.period,
            "by_stop": res.impacts_by_stop,
            "lyapunov": res.lyapunov,
            "used": res.transient_used,
            "x_final": res.x_final,
            "mode_final": res.mode_final,
        }
        for key, value in ref.items():
            assert np.array_equal(np.asarray(got[key], dtype=float), value.astype(float), equal_nan=True), (
                f"{lanes}: chunk {res.index}, {key} differs from the Runner oracle"
            )


SWEEPS = {
    "pendulum continuation, adaptive, Lyapunov": (
        lambda: pendulum("B", theta_hat=math.radians(40)),
        "eta",
        np.linspace(0.44, 0.47, 12),
        SweepSettings(transient=200, periods=30, chunk_size=3),
    ),
    "pendulum fresh, no Lyapunov, fixed transient": (
        lambda: pendulum("B", theta_hat=math.radians(40)),
        "eta",
        np.linspace(0.44, 0.47, 10),
        SweepSettings(transient=100, periods=20, chunk_size=4, fresh=True, adaptive=False, lyapunov=False),
    ),
    "bouncing ball: chattering and sticking": (
        lambda: bouncing_ball(amplitude=1.2),
        "amplitude",
        np.linspace(1.0, 1.6, 8),
        SweepSettings(transient=20, periods=12, chunk_size=2),
    ),
    "two-sided oscillator, phase": (
        lambda: two_sided_oscillator(),
        "omega",
        np.linspace(0.7, 0.9, 8),
        SweepSettings(transient=60, periods=16, chunk_size=3, phase=1.3),
    ),
    # issue 26: models: tanh, atan, a power of a time function with the swept exponent p, x**(v/4)
    "smooth functions, exponent swept": (
        lambda: smooth_oscillator(),
        "p",
        np.linspace(0.5, 0.9, 8),
        SweepSettings(transient=40, periods=12, chunk_size=3),
    ),
}


def assert_lanes_equal_the_oracle(
    spec: SweepSpec, label: str = "", *, scalar: bool = True, regroup: bool = True
) -> list:
    """Every chunk of ``spec`` on the model's lanes equals the Runner oracle (:func:`assert_chunks_equal`),
    and with ``scalar`` lane by lane too (every Taylor kernel called scalar); with ``regroup`` also one
    chunk at a time and the jobs shared by three threads.  Returns the chunks run on the lanes."""
    kern = spec.model.kernels(0, taylor_order(spec.tol))
    saved = kern.LANES
    results = {}
    try:
        for lanes in dict.fromkeys((saved, 1) if scalar else (saved,)):  # (1: lane by lane, scalar)
            kern.LANES = lanes
            results[lanes] = run_chunks(spec, list(range(spec.n_chunks)))
            assert_chunks_equal(spec, results[lanes], f"{label}{lanes} lanes")
    finally:
        kern.LANES = saved
    if regroup:
        # grouped differently: one chunk at a time
        assert_chunks_equal(spec, [run_chunks(spec, [i])[0] for i in range(spec.n_chunks)], "one chunk")
        # the jobs shared by three threads (the chunks reported as they finish)
        streamed = list(stream_chunks([(spec, i) for i in range(spec.n_chunks)], 3))
        assert sorted(k for k, _ in streamed) == list(range(spec.n_chunks))
        assert_chunks_equal(spec, [res for _, res in streamed], "three threads")
    return results[saved]


@pytest.mark.parametrize("name", list(SWEEPS))
def test_sweep_on_lanes_equals_the_runner_oracle(name: str) -> None:
    make, param, values, settings_ = SWEEPS[name]
    # (the engine against its oracle: without the Newton polish of runs that have no period, a layer above)
    spec = dataclasses.replace(sweep_spec(make(), param, values, settings=settings_), polish=False)
    assert_lanes_equal_the_oracle(spec)


def test_chunks_of_several_sweeps_in_one_batch_equal_each_sweep_alone() -> None:
    # Specs that differ in their points, start state, phase and continuation share one driver call.
    model = pendulum("B", theta_hat=math.radians(40))
    base = dict(transient=120, periods=20, chunk_size=3)
    specs = [
        sweep_spec(model, "eta", np.linspace(0.44, 0.45, 6), settings=SweepSettings(**base)),
        sweep_spec(
            model,
            "eta",
            np.linspace(0.46, 0.47, 4),
            x0=(0.1, -0.2),
            direction="down",
            settings=SweepSettings(**base, phase=0.7),
        ),
        sweep_spec(
            model.with_params(theta_hat=math.radians(30)),
            "eta",
            np.linspace(0.45, 0.46, 5),
            x0=(0.05, 0.0),
            settings=SweepSettings(**base, fresh=True),
        ),
    ]
    parts = [(spec, i) for spec in specs for i in range(spec.n_chunks)]
    batch = LaneBatch(parts)
    batch.run()
    assert batch.finished() == list(range(len(parts)))
    for spec in specs:
        assert_chunks_equal(spec, [batch.result(k) for k, (s, _) in enumerate(parts) if s is spec], "batch")
    other = sweep_spec(model, "eta", [0.44, 0.45], settings=SweepSettings(**{**base, "periods": 10}))
    with pytest.raises(ValueError, match="share the model and the sweep settings"):
        LaneBatch([(specs[0], 0), (other, 0)])


def test_sweep_with_the_discontinuity_map_equals_the_oracle() -> None:
    from grazing.normalform import find_grazing_point, normal_form_at

    point = find_grazing_point(pendulum("B", theta_hat=math.radians(40)), "eta", 0.2, 1.0, "first")
    zdm = normal_form_at(point, ("eta", "theta_hat")).discontinuity_map()
    spec = sweep_spec(
        point.model,
        "eta",
        np.linspace(0.4452, 0.4462, 6),
        settings=SweepSettings(transient=100, periods=20, chunk_size=3),
        zdm=zdm,
    )
    assert_chunks_equal(spec, run_chunks(spec, list(range(spec.n_chunks))), "map method")


def runaway_model() -> grazing.HybridModel:
    """``x'' = k x + cos t`` with a stop at ``x = -1``: for ``k > 0`` the state runs away to infinity."""
    import sympy as sp

    x, v, t, k, c = sp.symbols("x v t k c")
    return grazing.HybridModel(
        "runaway",
        [x, v],
        t,
        [grazing.Parameter("k", -1.0), grazing.Parameter("c", 0.1, lower=0.0)],
        vector_field=[v, k * x - c * v + sp.cos(t)],
        guard=x + 1,
        reset=[x, -0.8 * v],
        period=2 * sp.pi,
        contact_direction=[0, 1],
    )


def test_failing_points_and_the_next_ones() -> None:
    # From x0, k = 25 overflows (a point that fails: NaN samples, period -1); the next point of
    # the chunk starts again from x0, and fails again or, with k < 0, succeeds.
    spec = sweep_spec(
        runaway_model(),
        "k",
        [30.0, 25.0, -1.0, -1.5, -2.0, -3.0],
        x0=(0.5, 0.0),
        direction="down",
        settings=SweepSettings(transient=40, periods=10, chunk_size=3),
    )
    results = run_chunks(spec, [0, 1])
    periods = np.concatenate([r.period for r in results])
    assert list(periods < 0) == [True, True, False, False, False, False]
    status = np.concatenate([r.status for r in results])
    assert [Status(s) for s in status] == [Status.NONFINITE] * 2 + [Status.OK] * 4
    for res in results:
        bad = res.period < 0
        assert np.isnan(res.samples[bad]).all() and (res.impacts_by_stop[bad] == -1).all()
    assert_chunks_equal(spec, results, "failing")


@pytest.mark.slow
@settings(max_examples=6)
@given(spec=model_specs(), fresh=st.booleans(), lyapunov=st.booleans())
def test_random_model_sweeps_on_lanes_equal_the_oracle(spec: ModelSpec, fresh: bool, lyapunov: bool) -> None:
    model = spec.model()
    w = [p.name for p in model.parameters][3]  # the frequency: it sets the period
    values = model.params[w] * np.linspace(0.9, 1.1, 9)
    sw = sweep_spec(
        model,
        w,
        values,
        x0=spec.initial_state(),
        settings=SweepSettings(
            transient=40,
            periods=10,
            chunk_size=3,
            fresh=fresh,
            lyapunov=lyapunov,
        ),
    )
    sw = dataclasses.replace(sw, polish=False)  # (the engine against its oracle: no Newton polish)
    assert_chunks_equal(sw, run_chunks(sw, list(range(sw.n_chunks))), "random model")
