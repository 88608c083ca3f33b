"""Computing a chunk of a sweep: pure functions of the spec (what a worker runs).

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
to another attractor; fresh sweeps are unaffected.)
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.period import DEFAULT_MAX_PERIOD, DEFAULT_PERIOD_TOL, detect_period
from grazing.engine.runner import Runner
from grazing.errors import SimulationError
from grazing.sweeps.spec import ChunkResult, SweepSpec

ADAPTIVE_BLOCK = 32
"""Periods of the transient run between two looks at the samples (adaptive transients)."""

ADAPTIVE_MAX_PERIOD = 16
"""The largest period an adaptive transient recognises."""

ADAPTIVE_TOL = 1e-9
"""Samples repeating to this tolerance end an adaptive transient."""

LYAPUNOV_ALIGN = 16
"""Periods of the transient during which the tangent vectors are aligned (not counted)."""


def run_point(spec: SweepSpec, model: HybridModel, x: np.ndarray, t0: float) -> tuple[Any, ...]:
    """Transient then sampled periods at one point; returns the point's results."""
    run = Runner(model, x, t0=t0, phase=spec.phase, tol=spec.tol, zdm=spec.zdm)
    align = min(LYAPUNOV_ALIGN, spec.transient) if spec.lyapunov else 0
    budget = spec.transient - align
    used = 0
    # The transient always runs in the same blocks (so the trajectory does not
    # depend on ``adaptive``); adaptive only decides whether to stop early.
    while used < budget:
        block = min(ADAPTIVE_BLOCK, budget - used)
        seg = run.advance(block, block if spec.adaptive else 0)
        used += block
        if spec.adaptive and block == ADAPTIVE_BLOCK:
            p = detect_period(seg.samples, tol=ADAPTIVE_TOL, max_period=ADAPTIVE_MAX_PERIOD)
            if p > 0:
                # Stop at the point of the cycle where the full transient would end,
                # so that the samples (and the next point's start) are the same.
                extra = (budget - used) % p
                if extra:
                    run.advance(extra, 0)
                    used += extra
                break
    if spec.lyapunov:
        var = Runner(model, run.x, t0=run.t, phase=spec.phase, tol=spec.tol, variational=True, zdm=spec.zdm)
        var.mode = run.mode
        seg = var.advance(align + spec.periods, spec.periods, lyapunov=True, impacts="sampled")
        lyap = (
            float(np.max(seg.log_sums / seg.lyap_span)) if seg.jacobian_valid and seg.lyap_span else math.nan
        )
        final = var
    else:
        seg = run.advance(spec.periods, spec.periods, impacts="sampled")
        lyap = math.nan
        final = run
    n = model.n_states
    by_stop = np.bincount(seg.impacts[:, 2 + n].astype(np.int64), minlength=model.n_stops)
    return seg.samples, by_stop, lyap, used + align, final.x, final.t


def run_chunk(spec: SweepSpec, index: int) -> ChunkResult:
    """Compute chunk ``index`` of ``spec`` (a pure function of its arguments)."""
    start = time.perf_counter()
    sl = spec.chunk(index)
    pts = spec.points[sl]
    n, m = spec.model.n_states, spec.periods
    res = ChunkResult(
        index=index,
        samples=np.full((len(pts), m, n), np.nan),
        period=np.zeros(len(pts), dtype=np.int32),
        impacts=np.zeros(len(pts), dtype=np.int32),
        lyapunov=np.full(len(pts), np.nan),
        transient_used=np.zeros(len(pts), dtype=np.int32),
        x_final=np.full((len(pts), n), np.nan),
        impacts_by_stop=np.zeros((len(pts), spec.model.n_stops), dtype=np.int32),
    )
    x0 = np.asarray(spec.x0, dtype=float)
    x = x0.copy()
    t0 = 0.0
    carried = False
    for j, pt in enumerate(pts):
        model = spec.model_at(pt)
        if carried and model.periodic:
            # The state carried over is the last sample, at forcing phase ``spec.phase``:
            # start the next point at that phase of its own period (which may differ).
            t0 = (spec.phase / (2 * math.pi)) % 1.0 * model.period
        start_x, start_t = (x0, 0.0) if spec.fresh or not carried else (x, t0)
        try:
            samples, by_stop, lyap, used, x, t0 = run_point(spec, model, start_x, start_t)
        except SimulationError:
            # Recorded as missing (NaN samples, period -1); the next point restarts from x0.
            res.period[j] = -1
            res.impacts_by_stop[j] = -1
            carried = False
            continue
        res.samples[j] = samples
        res.period[j] = detect_period(samples, DEFAULT_PERIOD_TOL, DEFAULT_MAX_PERIOD)
        res.impacts[j] = int(by_stop.sum())
        res.impacts_by_stop[j] = by_stop
        res.lyapunov[j] = lyap
        res.transient_used[j] = used
        res.x_final[j] = x
        carried = True
    res.seconds = time.perf_counter() - start
    return res
