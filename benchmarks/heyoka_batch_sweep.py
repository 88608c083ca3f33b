"""The sweep a heyoka.py expert would write: batch mode, one SIMD lane per parameter value.

The peer of ``grazing sweep --param eta --fresh --no-lyapunov --no-adaptive --tol 1e-10`` at
equal work (issues 15 and 29): the impacting pendulum, case B, θ̂ = 40°, η values in
``[start, stop]``, every point from (θ, θ') = (0, 0) at τ = 0, ``transient`` + ``periods``
forcing periods, tolerance 1e-10, the period of each point by grazing's rule.

How it is written (tuned as heyoka.py's documentation advises; measured choices in
benchmarks/README.md):

* one ``taylor_adaptive_batch`` per process, ``--lanes`` SIMD lanes (default heyoka's
  ``recommended_simd_size()``; ``run_all.py`` tries 4, 8 and 16 and keeps the fastest), the
  default compilation options (``compact_mode=False``, ``opt_level=3``, no fast-math: the same
  floating-point rules as grazing); α, β, η, r, θ̂ runtime parameters (one value per lane);
* the impact a terminal batch event on θ − θ̂ (upwards) whose callback applies θ' ← −rθ' to
  its lane and returns True, so that the propagation goes on.  The callback is an object
  that keeps a view of the integrator's state (``__deepcopy__`` returns itself, as the event
  tutorial suggests for stateful callbacks), so a callback costs one multiplication in numpy
  and no attribute look-up on the integrator;
* the transient by ``propagate_until(2π·transient)``, then ``propagate_grid`` over the
  ``periods + 1`` sample times only (not a grid over the transient's times too);
* no ``reset_cooldowns()`` between batches: a cooldown is the integration time elapsed since
  its event, at most ten times the event's tolerance over its time derivative (about 1e-9
  here), and from rest the first impact of a new batch comes a whole swing later, so a
  cooldown left from the previous batch has expired long before (heyoka resets nothing
  when the state is set by hand; here nothing needs resetting);
* the values split over ``--processes`` processes (a process pool: heyoka's Python
  callbacks need the interpreter, so threads would serialise on it);
* one OpenBLAS thread (``OPENBLAS_NUM_THREADS=1`` unless set, before numpy is imported), as
  ``grazing``'s command line has: the BLAS threads numpy starts spin for about 0.1 s of a
  core each, beside the processes' work, and nothing here is BLAS.

Prints a JSON record (``--json``: the periods, the lanes, heyoka's recommended SIMD width,
the elapsed time) or a summary.  Run as a whole process to time it (``run_all.py`` does,
interleaved with grazing)::

    python benchmarks/heyoka_batch_sweep.py --num 1000 --processes 2 --lanes 8
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # (before numpy: see above)

import numpy as np

CASE_B = {"alpha": 0.2254, "beta": 0.048, "r": 0.7675}
THETA_HAT = math.radians(40.0)
PERIOD_TOL = 1e-6
MAX_PERIOD = 64
PARS = ("alpha", "beta", "eta", "r", "theta_hat")  # the runtime parameters, in hy.par order


def detect_period(samples: np.ndarray, tol: float = PERIOD_TOL, max_period: int = MAX_PERIOD) -> int:
    """Smallest p with the samples p-periodic to ``tol`` (0: none), as grazing's sweeps define it."""
    n = len(samples)
    for p in range(1, min(max_period, n // 2) + 1):
        if np.max(np.abs(samples[p:] - samples[:-p])) <= tol:
            return p
    return 0


class LaneReset:
    """The impact's callback: θ' ← −rθ' in the lane whose event fired; integration goes on.

    Holds a view of the integrator's state (set once the integrator exists) and of its
    parameters; heyoka deep-copies callbacks, so ``__deepcopy__`` returns this very object.
    """

    def __init__(self) -> None:
        self.state: np.ndarray | None = None
        self.r: np.ndarray | None = None

    def __deepcopy__(self, memo: dict[int, Any]) -> LaneReset:
        return self

    def __call__(self, ta: Any, d_sgn: Any, lane: int) -> bool:
        state = self.state
        state[1, lane] = -self.r[lane] * state[1, lane]  # type: ignore[index]
        return True


def make_integrator(lanes: int, tol: float) -> Any:
    """The batch integrator: (θ, θ') in explicit time, runtime parameters, the impact event and its reset."""
    import heyoka as hy

    th, dth = hy.make_vars("th", "dth")
    alpha, beta, eta, _, theta_hat = (hy.par[i] for i in range(len(PARS)))  # r (par[3]) is the reset's
    sys_ = [
        (th, dth),
        (dth, alpha * hy.cos(th) * hy.sin(hy.time) - 2.0 * beta / eta * dth - hy.sin(th) / (4 * eta**2)),
    ]
    reset = LaneReset()
    event = hy.t_event_batch(th - theta_hat, callback=reset, direction=hy.event_direction.positive)
    ta = hy.taylor_adaptive_batch(
        sys_, np.zeros((2, lanes)), pars=np.zeros((len(PARS), lanes)), tol=tol, t_events=[event]
    )
    reset.state, reset.r = ta.state, ta.pars[PARS.index("r")]
    return ta


_INTEGRATORS: dict[tuple[int, float], Any] = {}


def integrator(lanes: int, tol: float) -> Any:
    """This process's integrator for ``lanes`` and ``tol`` (JIT-compiled once per process)."""
    key = (lanes, tol)
    if key not in _INTEGRATORS:
        _INTEGRATORS[key] = make_integrator(lanes, tol)
    return _INTEGRATORS[key]


def run_values(etas: np.ndarray, transient: int, periods: int, tol: float, lanes: int) -> list[int]:
    """The detected period at each η (one process): batches of ``lanes`` values."""
    ta = integrator(lanes, tol)
    t_transient = 2.0 * math.pi * transient
    grid = np.repeat((2.0 * math.pi * np.arange(transient, transient + periods + 1))[:, None], lanes, axis=1)
    fixed = {"alpha": CASE_B["alpha"], "beta": CASE_B["beta"], "r": CASE_B["r"], "theta_hat": THETA_HAT}
    out: list[int] = []
    for start in range(0, len(etas), lanes):
        batch = etas[start : start + lanes]
        ta.set_time(0.0)
        ta.state[:] = 0.0
        for name, value in fixed.items():
            ta.pars[PARS.index(name), :] = value
        ta.pars[PARS.index("eta"), :] = np.concatenate([batch, np.full(lanes - len(batch), batch[-1])])
        ta.propagate_until(t_transient)
        _, states = ta.propagate_grid(grid)  # (periods + 1, 2, lanes): τ = 2πk, k = transient .. total
        check_outcomes(ta, len(batch))
        for lane in range(len(batch)):
            out.append(detect_period(states[1:, :, lane]))
    return out


def check_outcomes(ta: Any, used: int) -> None:
    """Every used lane reached the last sample time (a failed lane is never silent)."""
    import heyoka as hy

    for lane, res in enumerate(ta.propagate_res[:used]):
        if res[0] != hy.taylor_outcome.time_limit:
            raise RuntimeError(f"heyoka lane {lane} ended with {res[0]}")


def sweep(
    etas: np.ndarray,
    transient: int,
    periods: int,
    tol: float,
    lanes: int,
    pool: Any = None,
    processes: int = 1,
) -> list[int]:
    """The periods at ``etas``: in this process, or split over ``processes`` processes of ``pool``."""
    if pool is None:
        return run_values(etas, transient, periods, tol, lanes)
    parts = np.array_split(etas, processes)
    futures = [pool.submit(run_values, p, transient, periods, tol, lanes) for p in parts if len(p)]
    return [v for f in futures for v in f.result()]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--start", type=float, default=0.44)
    ap.add_argument("--stop", type=float, default=0.49)
    ap.add_argument("--num", type=int, default=1000)
    ap.add_argument("--transient", type=int, default=500)
    ap.add_argument("--periods", type=int, default=100)
    ap.add_argument("--tol", type=float, default=1e-10)
    ap.add_argument("--processes", type=int, default=2)
    ap.add_argument("--lanes", type=int, default=0, help="SIMD lanes (0: heyoka's recommended_simd_size())")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    import heyoka as hy

    lanes = a.lanes or hy.recommended_simd_size()
    etas = np.linspace(a.start, a.stop, a.num)
    if a.processes == 1:
        periods = sweep(etas, a.transient, a.periods, a.tol, lanes)
    else:
        with ProcessPoolExecutor(a.processes) as pool:
            periods = sweep(etas, a.transient, a.periods, a.tol, lanes, pool, a.processes)
    elapsed = time.perf_counter() - t0
    result = {"values": etas.tolist(), "period": periods, "lanes": lanes,
              "recommended_simd_size": hy.recommended_simd_size(), "processes": a.processes,
              "elapsed_s": elapsed}  # fmt: skip
    if a.json:
        json.dump(result, sys.stdout)
    else:
        print(f"{a.num} points on {a.processes} processes x {lanes} lanes in {elapsed:.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
