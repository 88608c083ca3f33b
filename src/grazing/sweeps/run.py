"""Computing chunks of a sweep: pure functions of the spec (what a worker runs).

At each point the model is run for a transient, then ``periods`` forcing
periods are sampled at the stroboscopic phase; the samples, their period, the
impacts and the largest Lyapunov exponent are recorded.  Within a chunk, each
point starts from the final state of the previous one, as an experimenter
sweeps (unless ``fresh``), at the sampling phase of its own forcing period;
every chunk starts from ``x0``.

Adaptive transients: the transient is run in blocks of 32 periods and stopped
as soon as the samples repeat with a period p <= 16 to 1e-9, at the point of
the cycle where the full transient would have ended (the periods run are
congruent to the full transient modulo p).  The samples, and in a continuation
sweep the next point's starting state, are then those of the full transient to
about 1e-9.  (In a continuation sweep through chaos with coexisting attractors,
such a 1e-9 difference can, like any rounding difference, lead the next points
to another attractor; fresh sweeps are unaffected.)  With Lyapunov exponents,
the last 16 periods of the transient align the tangent vectors, and the
exponent is taken over the sampled periods.

The points are computed by the compiled driver on SIMD lanes
(:mod:`grazing.engine.driver.lanes`): several points at once, each lane its
own point with its own steps and events; in a continuation sweep a lane
follows one chunk, in a fresh sweep it takes any point.  The results do not
depend on the lanes (each lane does the scalar path's arithmetic).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence

import numpy as np

from grazing.core.options import CHATTER_TOL
from grazing.core.period import DEFAULT_MAX_PERIOD, DEFAULT_PERIOD_TOL, detect_period
from grazing.engine.codegen import taylor_order
from grazing.engine.native import load_sweep_lanes
from grazing.engine.runner import step_safety
from grazing.sweeps.spec import ChunkResult, SweepSpec


def run_chunks(spec: SweepSpec, indices: Sequence[int]) -> list[ChunkResult]:
    """Compute the chunks ``indices`` of ``spec`` together (on SIMD lanes); their results in that order.

    Each chunk's result is a pure function of the spec and its index: the
    same whichever chunks are computed with it.
    """
    start = time.perf_counter()
    model = spec.model
    n, m, nstops = model.n_states, spec.periods, model.n_stops
    slices = [spec.chunk(i) for i in indices]
    pts = [pt for sl in slices for pt in spec.points[sl]]
    npts = len(pts)
    models = [spec.model_at(pt) for pt in pts]
    order = taylor_order(spec.tol)
    kern = model.kernels(0, order)
    pvs = np.array([mm.param_vector for mm in models], dtype=float).reshape(npts, -1)
    Ts = np.array([float(mm.period) for mm in models])
    phase = (spec.phase % (2 * math.pi)) / (2 * math.pi)
    sphase = phase * Ts
    tcarry = (spec.phase / (2 * math.pi)) % 1.0 * Ts
    z = spec.zdm
    zdms = np.array([float(z.phase) % T for T in Ts]) if z is not None else np.zeros(npts)
    # Jobs: runs of points in which each continues from the previous (a chunk; every point when fresh).
    jobs, first = [], 0
    for sl in slices:
        size = sl.stop - sl.start
        jobs += [(first + j, first + j + 1) for j in range(size)] if spec.fresh else [(first, first + size)]
        first += size
    samples = np.full((npts, m, n), np.nan)
    by_stop = np.zeros((npts, nstops), dtype=np.int64)
    lyap = np.full(npts, np.nan)
    used = np.zeros(npts, dtype=np.int64)
    x_final = np.full((npts, n), np.nan)
    t_final = np.zeros(npts)
    ok = np.zeros(npts, dtype=np.int64)
    load_sweep_lanes()(
        kern.table,
        1 if len(jobs) == 1 else max(1, kern.LANES),  # (the lane functions' width, or one lane)
        np.array(jobs, dtype=np.int64).reshape(-1, 2),
        bool(spec.fresh),
        bool(model.periodic),
        np.asarray(spec.x0, dtype=float),
        pvs,
        Ts,
        sphase,
        tcarry,
        zdms,
        int(spec.transient),
        int(m),
        bool(spec.adaptive),
        bool(spec.lyapunov),
        float(step_safety(spec.tol, order)),
        float(CHATTER_TOL),
        z is not None,
        float(z.accel) if z is not None else 1.0,
        np.asarray(z.direction if z is not None else np.zeros(n), dtype=float),
        float(z.window) if z is not None else 0.0,
        int(z.stop) if z is not None else 0,
        samples,
        by_stop,
        lyap,
        used,
        x_final,
        t_final,
        ok,
    )
    results, first = [], 0
    for index, sl in zip(indices, slices):
        size = sl.stop - sl.start
        part = slice(first, first + size)
        first += size
        good = ok[part] == 1
        res = ChunkResult(
            index=index,
            samples=np.where(good[:, None, None], samples[part], np.nan),
            period=np.array(
                [
                    detect_period(s, DEFAULT_PERIOD_TOL, DEFAULT_MAX_PERIOD) if g else -1
                    for s, g in zip(samples[part], good)
                ],
                dtype=np.int32,
            ),
            impacts=np.where(good, by_stop[part].sum(axis=1), 0).astype(np.int32),
            lyapunov=np.where(good, lyap[part], np.nan),
            transient_used=np.where(good, used[part], 0).astype(np.int32),
            x_final=np.where(good[:, None], x_final[part], np.nan),
            impacts_by_stop=np.where(good[:, None], by_stop[part], -1).astype(np.int32),
        )
        results.append(res)
    seconds = time.perf_counter() - start
    for res in results:  # (the chunks ran together: each is charged its share)
        res.seconds = seconds / len(results)
    return results


def run_chunk(spec: SweepSpec, index: int) -> ChunkResult:
    """Compute chunk ``index`` of ``spec`` (a pure function of its arguments)."""
    return run_chunks(spec, [index])[0]
