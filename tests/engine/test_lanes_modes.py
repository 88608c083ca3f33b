"""Sweeps on SIMD lanes through modes: the lanes give the scalar Runner's numbers, bit for bit.

The two models with modes of the engine's tests: the soft-impact oscillator with its contact damper
(switches of vector field without a reset, the saltation matrix of a switch in the Lyapunov exponents)
and the linearised rocking block (resets that change the mode).  Each sweep is checked against the
independent Runner oracle of ``tests/engine/test_lanes.py`` (samples, impacts by transition, Lyapunov
exponent, transient used, final state and final mode of every point), on vectors of lanes and lane by
lane, chunk by chunk and shared by three threads; a chunk continued from a state in the other mode; and
a sweep against :func:`grazing.simulate` point by point.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import brentq

import grazing
from grazing.core.options import LYAPUNOV_ALIGN, SweepSettings
from grazing.engine.codegen import taylor_order
from grazing.sweeps.run import LaneBatch, run_chunks
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_lanes import assert_chunks_equal, assert_lanes_equal_the_oracle, check_lane_functions
from tests.engine.test_mode_switches import reference as mode_switches_reference
from tests.engine.test_mode_switches import soft_impact
from tests.engine.test_rocking_modes import rocking_block
from tests.piecewise_exact import SAMPLES_PER_PERIOD, PiecewiseLinearModel

SWEEPS = {
    "soft impact, continuation, Lyapunov": (
        soft_impact,
        "gap",
        np.linspace(0.5, 3.0, 20),
        SweepSettings(transient=40, periods=12, chunk_size=2),
    ),
    "soft impact, fresh, no Lyapunov": (
        soft_impact,
        "omega",
        np.linspace(0.8, 1.6, 20),
        SweepSettings(transient=30, periods=10, chunk_size=5, fresh=True, lyapunov=False, adaptive=False),
    ),
    "rocking block, continuation, Lyapunov": (
        rocking_block,
        "a",
        np.linspace(0.2, 0.32, 18),
        SweepSettings(transient=12, periods=6, chunk_size=2),
    ),
}


def test_lane_functions_of_each_mode_equal_the_scalar_kernels() -> None:
    for make in (soft_impact, rocking_block):
        check_lane_functions(make(), np.random.default_rng(3), trials=2)


@pytest.mark.parametrize("name", list(SWEEPS))
def test_sweep_through_modes_on_lanes_equals_the_runner_oracle(name: str) -> None:
    make, param, values, settings_ = SWEEPS[name]
    spec = dataclasses.replace(sweep_spec(make(), param, values, settings=settings_), polish=False)
    kern = spec.model.kernels(0, taylor_order(spec.tol))
    assert kern.NMODES == 2 and kern.LANES > 1
    res = assert_lanes_equal_the_oracle(spec)
    if name.startswith("soft"):
        modes = np.concatenate([r.mode_final for r in res])
        assert set(modes.tolist()) == {0, 1}, modes  # (points end in either mode)
    else:  # (the block lands on its other corner: resets that change the mode)
        assert sum(int(r.impacts.sum()) for r in res) > 0


def test_a_chunk_continued_in_the_other_mode() -> None:
    """A chain continued from a state in contact (mode 1): the lane starts in that mode, beside others."""
    m = soft_impact()
    settings_ = SweepSettings(transient=20, periods=8, chunk_size=3, lyapunov=True)
    base = dataclasses.replace(
        sweep_spec(m, "a", np.linspace(0.8, 1.2, 12), settings=settings_), polish=False
    )
    gap = m.params["gap"]
    resumed = dataclasses.replace(
        base, points=base.points[:3], resume=(0.3, (gap + 0.2, -0.5), 1), chunk_size=0
    )
    parts = [(resumed, 0)] + [(base, i) for i in range(base.n_chunks)]
    batch = LaneBatch(parts)
    batch.run()
    assert_chunks_equal(resumed, [batch.result(0)], "resumed in contact")
    assert_chunks_equal(base, [batch.result(k) for k in range(1, len(parts))], "beside it")
    # Its first point from the other mode differs from one from the initial mode (the mode is used).
    wrong = dataclasses.replace(resumed, resume=(0.3, (gap + 0.2, -0.5), 0))
    with pytest.raises(grazing.InvalidStateError):
        m.check_state((gap + 0.2, -0.5))
    assert not np.array_equal(run_chunks(wrong, [0])[0].samples[0], batch.result(0).samples[0])


def test_sweep_equals_simulate_point_by_point() -> None:
    """A fresh sweep over a parameter of the soft-impact oscillator: each point as grazing.simulate runs
    it."""
    m = soft_impact()
    values = np.linspace(0.9, 1.5, 10)
    settings_ = SweepSettings(
        transient=30, periods=8, chunk_size=5, fresh=True, adaptive=False, lyapunov=False
    )
    spec = dataclasses.replace(sweep_spec(m, "omega", values, settings=settings_), polish=False)
    res = run_chunks(spec, list(range(spec.n_chunks)))
    samples = np.concatenate([r.samples for r in res])
    modes = np.concatenate([r.mode_final for r in res])
    for i, w in enumerate(values):
        point = m.with_params(omega=float(w))
        sol = grazing.simulate(point, spec.x0, transient=30, periods=8)
        np.testing.assert_allclose(samples[i], sol.samples, rtol=0, atol=1e-8)  # (a run in blocks: rounding)
        assert point.mode_names[modes[i]] == sol.mode_final, i


def test_lyapunov_exponents_across_switches_against_the_exact_jacobian() -> None:
    """The largest exponent of a fresh sweep point from the exact Jacobians (the saltation of each switch).

    The point runs ``transient - align`` periods, then ``align`` periods aligning the tangent vectors from
    the identity (Gram-Schmidt: the first is ``J_align e1``), then the sampled span, over which the first
    vector grows by ``|J_span v1|`` and the second by ``|det J_span| / |J_span v1|``.
    """
    m = soft_impact()
    values = np.linspace(0.9, 1.5, 3)
    transient, periods = 24, 6
    settings_ = SweepSettings(transient=transient, periods=periods, chunk_size=3, fresh=True, adaptive=False)
    spec = dataclasses.replace(sweep_spec(m, "omega", values, settings=settings_), polish=False)
    res = run_chunks(spec, list(range(spec.n_chunks)))
    lyap = np.concatenate([r.lyapunov for r in res])
    align = min(LYAPUNOV_ALIGN, transient)
    switched = 0
    for i, w in enumerate(values):
        p = dict(m.with_params(omega=float(w)).params)
        exact = mode_switches_reference(p)
        ref, T = GridModel(exact.modes, exact.w), 2 * np.pi / w
        t1, t2, t3 = (transient - align) * T, transient * T, (transient + periods) * T
        x, mode, _, _ = by_periods(ref, np.zeros(2), 0, 0.0, t1, T)
        x, mode, J_align, _ = by_periods(ref, x, mode, t1, t2, T)
        _, _, J_span, sw = by_periods(ref, x, mode, t2, t3, T)
        switched += sw
        v1 = J_align[:, 0] / np.linalg.norm(J_align[:, 0])
        first = np.log(np.linalg.norm(J_span @ v1))
        second = np.log(abs(np.linalg.det(J_span))) - first
        assert lyap[i] == pytest.approx(max(first, second) / (t3 - t2), abs=1e-9), i
    assert switched > 0


class GridModel(PiecewiseLinearModel):
    """The exact reference, its search for a switch on the grid by powers of one exponential (the same
    grid and the same Brent refinement as :meth:`PiecewiseLinearModel.first_exit`, a few times faster)."""

    def first_exit(self, k, x0, t0, t1):
        n = max(8, math.ceil((t1 - t0) / self.period * SAMPLES_PER_PERIOD))
        ts = np.linspace(t0, t1, n + 1)
        md = self.modes[k]
        n_x = md.A.shape[0]
        P = np.linalg.solve(1j * self.w * np.eye(n_x) - md.A, md.b.astype(complex))
        xps = (P[None, :] * np.exp(1j * self.w * ts)[:, None]).real - np.linalg.solve(md.A, md.d)
        E = expm(md.A * (ts[1] - ts[0]))
        ys = np.empty((n + 1, n_x))
        ys[0] = x0 - xps[0]
        for i in range(n):
            ys[i + 1] = E @ ys[i]
        states = ys + xps
        best = None
        for i, (c, e, *_) in enumerate(md.exits):
            g = states @ c + e
            crossing = np.flatnonzero((g[1:] < 0.0) & (g[:-1] >= 0.0))
            crossing = crossing[~((crossing == 0) & (g[0] == 0.0))]
            if crossing.size:
                a = int(crossing[0]) + 1

                def guard(tt: float, c: np.ndarray = c, e: float = e) -> float:
                    return float(c @ self.flow(k, x0, t0, tt) + e)

                tz = brentq(guard, ts[a - 1], ts[a], xtol=1e-15, rtol=4 * np.finfo(float).eps)
                if best is None or tz < best[0]:
                    best = (tz, i)
        return best


def by_periods(ref, x, mode, t0, t1, T):
    """``ref.run`` from ``t0`` to ``t1`` one period at a time (its search for a switch scans to the end)."""
    J, switches = np.eye(len(x)), 0
    for k in range(round((t1 - t0) / T)):
        end = t1 if t0 + (k + 1) * T >= t1 - 1e-9 * T else t0 + (k + 1) * T
        x, mode, Jk, sw = ref.run(x, mode, t0 + k * T, end)
        J, switches = Jk @ J, switches + len(sw)
    return x, mode, J, switches


def test_continuation_sweep_in_chunks_equals_simulate_point_by_point(tmp_path) -> None:
    """A continuation sweep in chunks (a chain, grazing.sweeps.chain) of the soft-impact oscillator, into
    a store: each point as grazing.simulate continues it from the previous point's end and mode; the store
    keeps each chunk's end mode, from which the chain goes on."""
    from grazing.sweeps import sweep
    from grazing.sweeps.spec import sweep_spec as make_spec
    from grazing.sweeps.store import open_store

    m = soft_impact()
    values = np.linspace(0.6, 1.95, 10)  # (omega: the samples in contact, then free)
    kw = dict(transient=150, periods=6, chunk_size=3, adaptive=False, lyapunov=False)
    ds = sweep(m, "omega", values, store=tmp_path / "s.zarr", workers=1, **kw)
    x, t0, mode, modes = np.zeros(2), 0.0, None, []
    for i, g in enumerate(values):
        point = m.with_params(omega=float(g))
        sol = grazing.simulate(point, x, t0=t0, transient=150, periods=6, mode=mode)
        np.testing.assert_allclose(ds.samples.values[i], sol.samples, rtol=0, atol=1e-8)
        x, mode = sol.x_final, sol.mode_final
        modes.append(mode)
    assert set(modes) == {"free", "contact"}
    spec = make_spec(m, "omega", values, settings=SweepSettings(**kw))
    with open_store(tmp_path / "s.zarr", spec) as store:
        starts = [store.chain_start(i) for i in range(spec.n_chunks - 1)]
    last = [spec.chunk(i).stop - 1 for i in range(spec.n_chunks - 1)]
    assert [m.mode_names[s[2]] for s in starts] == [modes[k] for k in last]
