"""The sweep a heyoka.py expert would write: batch mode, one SIMD lane per parameter value.

The peer of ``grazing sweep --param eta --fresh --no-lyapunov --no-adaptive`` at equal work
(issue 15): the impacting pendulum, case B, θ̂ = 40°, η values in ``[start, stop]``, every
point from (θ, θ') = (0, 0) at τ = 0, ``transient`` + ``periods`` forcing periods, tolerance
1e-10.  One ``taylor_adaptive_batch`` per process with as many lanes as heyoka's recommended
SIMD width for doubles; α, β, η, r, θ̂ are runtime parameters (one value per lane); the
impact is a terminal batch event on θ − θ̂ (upwards) whose callback applies the reset
θ' ← −rθ' to its lane and returns True (integration goes on); the stroboscopic samples come
from one ``propagate_grid`` call per batch.  The values are split over ``--processes``
processes.  Prints the detected period of every point as JSON (``--json``) or a summary.

Run as a whole process to time it (``bench_sweep.py`` does, side by side with grazing)::

    python benchmarks/heyoka_batch_sweep.py --num 1000 --processes 2
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

CASE_B = {"alpha": 0.2254, "beta": 0.048, "r": 0.7675}
THETA_HAT = math.radians(40.0)
PERIOD_TOL = 1e-6
MAX_PERIOD = 64


def detect_period(samples: np.ndarray, tol: float = PERIOD_TOL, max_period: int = MAX_PERIOD) -> int:
    """Smallest p with the samples p-periodic to ``tol`` (0: none), as grazing's sweeps define it."""
    n = len(samples)
    for p in range(1, min(max_period, n // 2) + 1):
        if np.max(np.abs(samples[p:] - samples[:-p])) <= tol:
            return p
    return 0


def make_integrator(lanes: int, tol: float):
    """The batch integrator: (θ, θ') in explicit time, runtime parameters, the impact event and its reset."""
    import heyoka as hy

    th, dth = hy.make_vars("th", "dth")
    alpha, beta, eta, _, theta_hat = (hy.par[i] for i in range(5))  # (r, par[3], is used by the reset)
    sys_ = [
        (th, dth),
        (dth, alpha * hy.cos(th) * hy.sin(hy.time) - 2.0 * beta / eta * dth - hy.sin(th) / (4 * eta**2)),
    ]

    def reset(ta, d_sgn, lane):  # the impact: θ' <- -r θ' in this lane only
        ta.state[1, lane] = -ta.pars[3, lane] * ta.state[1, lane]
        return True

    event = hy.t_event_batch(th - theta_hat, callback=reset, direction=hy.event_direction.positive)
    return hy.taylor_adaptive_batch(
        sys_, np.zeros((2, lanes)), pars=np.zeros((5, lanes)), tol=tol, t_events=[event]
    )


def run_values(etas: np.ndarray, transient: int, periods: int, tol: float) -> list[int]:
    """The detected period at each η (one process): batches of ``lanes`` values."""
    import heyoka as hy

    lanes = hy.recommended_simd_size()
    ta = make_integrator(lanes, tol)
    total = transient + periods
    grid = np.repeat((2.0 * math.pi * np.arange(total + 1))[:, None], lanes, axis=1)  # from τ = 0
    out: list[int] = []
    for start in range(0, len(etas), lanes):
        batch = etas[start : start + lanes]
        vals = np.concatenate([batch, np.full(lanes - len(batch), batch[-1])])  # pad the last batch
        ta.set_time(0.0)
        ta.state[:] = 0.0
        ta.pars[0, :] = CASE_B["alpha"]
        ta.pars[1, :] = CASE_B["beta"]
        ta.pars[2, :] = vals
        ta.pars[3, :] = CASE_B["r"]
        ta.pars[4, :] = THETA_HAT
        ta.reset_cooldowns()
        res = ta.propagate_grid(grid)
        states = res[-1]  # (times, 2, lanes): the samples at τ = 2πk, k = 0 .. total
        for lane in range(len(batch)):
            out.append(detect_period(states[transient + 1 :, :, lane]))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--start", type=float, default=0.44)
    ap.add_argument("--stop", type=float, default=0.49)
    ap.add_argument("--num", type=int, default=1000)
    ap.add_argument("--transient", type=int, default=500)
    ap.add_argument("--periods", type=int, default=100)
    ap.add_argument("--tol", type=float, default=1e-10)
    ap.add_argument("--processes", type=int, default=2)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    etas = np.linspace(a.start, a.stop, a.num)
    parts = np.array_split(etas, a.processes)
    if a.processes == 1:
        periods = run_values(etas, a.transient, a.periods, a.tol)
    else:
        with ProcessPoolExecutor(a.processes) as pool:
            futures = [pool.submit(run_values, p, a.transient, a.periods, a.tol) for p in parts]
            periods = [v for f in futures for v in f.result()]
    elapsed = time.perf_counter() - t0
    import heyoka as hy

    result = {"values": etas.tolist(), "period": periods, "lanes": hy.recommended_simd_size(),
              "processes": a.processes, "elapsed_s": elapsed}  # fmt: skip
    if a.json:
        json.dump(result, sys.stdout)
    else:
        print(f"{a.num} points on {a.processes} processes x {result['lanes']} lanes in {elapsed:.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
