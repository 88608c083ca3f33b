"""Benchmark ``grazing.simulate`` against the loops a user would write with heyoka.py and scipy.

Problem: the impacting pendulum of Piiroinen, Virgin & Champneys (2004), case B
(alpha = 0.2254, beta = 0.048, r = 0.7675), eta = 0.446, stop at theta_hat = 40 deg,
started from (theta, theta') = (0, 0) at tau = 0.  It settles on a stable period-5
impacting orbit.  Every engine records a stroboscopic sample at every tau = 2 pi k.

Engines (each: a loop over forcing periods, a terminal event on theta - theta_hat in the
positive direction, the reset theta' <- -r theta' applied after each event):

* ``grazing``    -- ``grazing.simulate`` (default tolerance);
* ``heyoka-3d``  -- heyoka.py, the paper's 3-D autonomous form x = (theta - theta_hat, theta', tau)
  with tau' = 1 (tau is a state), ``hy.taylor_adaptive`` default tolerance,
  ``propagate_until(2 pi k)`` per period;
* ``heyoka-t``   -- heyoka.py as a user would write it: the non-autonomous 2-D system
  (theta, theta') with ``sin(hy.time)`` forcing, default tolerance, same loop;
* ``scipy``      -- ``solve_ivp(method="DOP853", rtol=1e-10, atol=1e-12)`` called once per
  forcing period, restarted after each reset.

Measured, in one run:

1. Time for 400 and 100,000 forcing periods, in-process (median of a few runs, after a
   warm-up / construction), and the whole-process time of a fresh interpreter doing the
   100,000-period run (imports, grazing kernel load / heyoka JIT compilation included;
   scipy's is extrapolated from a shorter fresh-process run, see ``SCIPY_PROCESS_PERIODS``).
   If scipy's in-process 100,000-period run would take over ~10 minutes, 10,000 periods
   are timed and the time is extrapolated linearly (marked in the output).
2. Accuracy: max |difference| of each engine's last 50 samples from a reference computed
   independently of grazing: the explicit-time heyoka system in long double
   (``fp_type=np.longdouble``, tolerance = its epsilon, 1.1e-19 on x86-64), with the time
   reset to 0 at the start of every period so that the forcing phase is exact.  Where
   long double is no wider than double, the reference falls back to the double
   explicit-time heyoka run (said so in the output).
3. Agreement with grazing: detected period and max |difference| of the last 50 samples,
   impact counts and the first impact times.  The script fails unless both heyoka loops
   (and the reference) match grazing sample by sample within 1e-6 with the same period,
   and scipy ends on the same orbit up to a phase shift (it misses an impact on the way).
4. Shallow impacts: from the period-1 non-impacting orbit at eta = 0.445 (stop out of
   reach), the stop is put at theta_max - d for d = 1e-2 ... 1e-12 and each engine
   integrates one forcing period; counted: how many of these impacts it misses.

Run (``make bench`` installs heyoka and runs the default)::

    python benchmarks/bench_simulate.py                 # full run (about 5-10 minutes)
    python benchmarks/bench_simulate.py --quick         # scipy on 400 periods only
    python benchmarks/bench_simulate.py --markdown --json bench.json
"""

from __future__ import annotations

import inspect
import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import heyoka as hy
import numpy as np
from scipy.integrate import solve_ivp

import grazing
from _common import (
    Spread,
    bench_parser,
    emit,
    loadavg,
    log,
    machine_info,
    process_seconds,
    process_spread,
    versions_line,
)

# ----------------------------------------------------------------------------- problem

CASE = "B"
ALPHA, BETA, R = 0.2254, 0.048, 0.7675
ETA = 0.446
THETA_HAT = math.radians(40.0)
X0 = (0.0, 0.0)
TWO_PI = 2.0 * math.pi
PI_DIGITS = "3.14159265358979323846264338327950288"  # for long double and exact time errors

SIZES = (400, 100_000)
LARGE = 100_000
SCIPY_CAP_S = 600.0  # time scipy's large run fully only if it is predicted to take less than this
SCIPY_FALLBACK = 10_000  # periods timed (and extrapolated) when it would take longer
SCIPY_PROCESS_PERIODS = 10_000  # scipy's fresh-process run (extrapolated to LARGE); 400 with --quick
SCIPY_OPTS: dict[str, Any] = {"method": "DOP853", "rtol": 1e-10, "atol": 1e-12}
PROCESS_REPEATS = 3

TAIL = 50  # samples compared after the transient
AGREE_TOL = 1e-6
N_FIRST_IMPACTS = 5

SHALLOW_ETA = 0.445
SHALLOW_DEPTHS = tuple(10.0**-e for e in range(2, 13))

ENGINES = ("grazing", "heyoka-3d", "heyoka-t", "scipy")
LABELS = {
    "grazing": "grazing.simulate",
    "heyoka-3d": "heyoka, paper's 3-D form (τ as a state)",
    "heyoka-t": "heyoka, explicit time",
    "scipy": "scipy solve_ivp (DOP853)",
    "reference": "reference (heyoka, explicit time, long double)",
}
STRICT = ("grazing", "heyoka-3d", "heyoka-t", "reference")  # must match grazing sample by sample


@dataclass
class Run:
    """Output of one engine on one task: samples at t0 + 2 pi k (k = 1..n) and impact times."""

    samples: np.ndarray
    impact_t: np.ndarray
    seconds: float = math.nan
    spread: Spread | None = None  # of the repeated runs' times


@dataclass
class Timing:
    engine: str
    periods: int  # periods of work the time refers to
    seconds: float  # (possibly extrapolated) time for `periods`
    repeats: int
    measured_periods: int  # periods actually run
    impacts: int
    deviation: float = math.nan  # max |diff| of the last TAIL samples from the reference
    seconds_min: float = math.nan  # the spread of the repeated runs (scaled like `seconds`)
    seconds_max: float = math.nan

    @property
    def extrapolated(self) -> bool:
        return self.measured_periods != self.periods

    @property
    def us_per_period(self) -> float:
        return self.seconds / self.periods * 1e6


@dataclass
class ProcessTiming:
    engine: str
    periods: int  # periods the time refers to
    seconds: float  # median fresh-process wall time (extrapolated to `periods` if measured on fewer)
    measured_periods: int
    measured_seconds: float  # median fresh-process wall time for `measured_periods`
    seconds_min: float = math.nan  # the spread of the runs (extrapolated like `seconds`)
    seconds_max: float = math.nan

    @property
    def extrapolated(self) -> bool:
        return self.measured_periods != self.periods


@dataclass
class Agreement:
    engine: str
    periods: int
    period: int
    period_grazing: int
    max_diff_aligned: float
    max_diff_orbit: float
    shift: int
    impacts: int
    impacts_grazing: int
    first_impacts: list[float]
    first_impact_diff: float
    first_mismatch: str | None = None


@dataclass
class Results:
    machine: dict[str, Any]
    settings: dict[str, Any]
    timings: list[Timing] = field(default_factory=list)
    process: list[ProcessTiming] = field(default_factory=list)
    one_off: dict[str, float] = field(default_factory=dict)
    reference: dict[str, Any] = field(default_factory=dict)
    agreement: list[Agreement] = field(default_factory=list)
    shallow: dict[str, Any] = field(default_factory=dict)


# ----------------------------------------------------------------------------- engines


def grazing_model(eta: float, theta_hat: float) -> grazing.HybridModel:
    model = grazing.models.pendulum(CASE, eta=eta, theta_hat=theta_hat)
    expected = {"alpha": ALPHA, "beta": BETA, "r": R, "eta": eta, "theta_hat": theta_hat}
    assert all(model.params[k] == v for k, v in expected.items()), model.params
    return model


def grazing_run(model: grazing.HybridModel, n_periods: int) -> Run:
    sol = grazing.simulate(model, list(X0), periods=n_periods)
    assert sol.t[0] == TWO_PI, "grazing's first sample is expected at tau = 2 pi"
    return Run(sol.samples, sol.impacts.t)


def make_heyoka(alpha: float, beta: float, eta: float) -> hy.taylor_adaptive:
    """heyoka.py integrator for x = (theta - theta_hat, theta', tau); theta_hat is par[0].

    tau is a state, as in the paper's autonomous form.  heyoka's error norm mixes absolute
    and relative error over all states, tau included: as tau grows (6e5 after 100,000
    periods) the effective tolerance loosens and the steps get longer; tau's rounding
    (~1e-10 at 6e5) also perturbs the forcing.  tau reduced mod 2 pi would avoid both.
    """
    x1, x2, x3 = hy.make_vars("x1", "x2", "x3")
    theta = x1 + hy.par[0]
    ode = [
        (x1, x2),
        (x2, alpha * hy.cos(theta) * hy.sin(x3) - 2.0 * beta / eta * x2 - hy.sin(theta) / (4.0 * eta**2)),
        (x3, hy.expression(1.0)),
    ]
    stop = hy.t_event(x1, direction=hy.event_direction.positive)
    return hy.taylor_adaptive(ode, [0.0, 0.0, 0.0], pars=[0.0], t_events=[stop])


def heyoka_loop(
    ta: hy.taylor_adaptive, x0: tuple[float, float], t0: float, n_periods: int, theta_hat: float, r: float
) -> tuple[np.ndarray, np.ndarray]:
    """Samples (theta, theta') at t0 + 2 pi k, k = 1..n_periods, and the impact times.

    For either form: the paper's 3-D x = (theta - theta_hat, theta', tau) of :func:`make_heyoka`
    or explicit time (:func:`make_heyoka_time`), told apart by the size of the state.
    """
    shift = theta_hat if len(ta.state) == 3 else 0.0
    ta.pars[0] = theta_hat
    ta.time = t0
    ta.state[:] = [x0[0] - shift, x0[1], t0][: len(ta.state)]
    ta.reset_cooldowns()
    samples = np.empty((n_periods, 2))
    impacts = []
    for k in range(1, n_periods + 1):
        t_k = t0 + 2.0 * math.pi * k
        while True:
            outcome = ta.propagate_until(t_k)[0]
            if outcome == hy.taylor_outcome.time_limit:
                break
            if -1000 < int(outcome) < 0:  # the terminal event: the stop is reached
                impacts.append(ta.time)
                ta.state[1] *= -r
                continue
            raise RuntimeError(f"heyoka stopped with {outcome} at t = {ta.time}")
        samples[k - 1] = ta.state[:2]
    samples[:, 0] += shift
    return samples, np.array(impacts)


def make_heyoka_time(alpha: float, beta: float, eta: float, fp_type: type = float) -> hy.taylor_adaptive:
    """heyoka.py integrator for (theta, theta') with explicit time (``hy.time``); theta_hat is par[0]."""
    c = fp_type  # the coefficients are computed in fp_type from the (double) parameter values
    theta, omega = hy.make_vars("theta", "omega")
    ode = [
        (theta, omega),
        (
            omega,
            c(alpha) * hy.cos(theta) * hy.sin(hy.time)
            - c(2.0) * c(beta) / c(eta) * omega
            - hy.sin(theta) / (c(4.0) * c(eta) ** 2),
        ),
    ]
    stop = hy.t_event(theta - hy.par[0], direction=hy.event_direction.positive, fp_type=fp_type)
    zero = c(0.0)
    return hy.taylor_adaptive(ode, [zero, zero], pars=[zero], t_events=[stop], fp_type=fp_type)


def make_reference() -> hy.taylor_adaptive:
    """The explicit-time integrator in long double if that is wider than double and heyoka has it."""
    if np.finfo(np.longdouble).eps < np.finfo(float).eps:
        try:
            return make_heyoka_time(ALPHA, BETA, ETA, np.longdouble)
        except (TypeError, ValueError, RuntimeError) as exc:
            log(f"heyoka has no long double integrator ({exc!r}); the reference is in double")
    return make_heyoka_time(ALPHA, BETA, ETA)


def reference_loop(ta: hy.taylor_adaptive, n_periods: int, theta_hat: float, r: float) -> Run:
    """Explicit-time loop from X0 at t = 0, in ta's precision, with the time reset to 0 every period.

    The reset keeps the forcing phase exact to the precision of 2 pi: propagating until
    2 pi k instead would put the samples at the rounded 2 pi k (an error ~ k * ulp(2 pi)).
    """
    fp = type(ta.time)
    two_pi = fp(2) * fp(PI_DIGITS) if fp is not float else TWO_PI
    ta.pars[0] = fp(theta_hat)
    ta.state[:] = [fp(X0[0]), fp(X0[1])]
    ta.reset_cooldowns()
    samples = np.empty((n_periods, 2), dtype=fp)
    impacts = []
    for k in range(n_periods):
        ta.time = fp(0)
        while True:
            outcome = ta.propagate_until(two_pi)[0]
            if outcome == hy.taylor_outcome.time_limit:
                break
            if -1000 < int(outcome) < 0:
                impacts.append(float(k * two_pi + ta.time))
                ta.state[1] *= -fp(r)
                continue
            raise RuntimeError(f"reference stopped with {outcome} at t = {k * two_pi + ta.time}")
        samples[k] = ta.state
    return Run(samples, np.array(impacts))


def scipy_rhs(alpha: float, beta: float, eta: float) -> Callable[[float, np.ndarray], np.ndarray]:
    c_damp, c_grav = 2.0 * beta / eta, 1.0 / (4.0 * eta**2)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        return np.array([y[1], alpha * np.cos(y[0]) * np.sin(t) - c_damp * y[1] - c_grav * np.sin(y[0])])

    return rhs


def scipy_loop(
    rhs: Callable[[float, np.ndarray], np.ndarray],
    x0: tuple[float, float],
    t0: float,
    n_periods: int,
    theta_hat: float,
    r: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Samples (theta, theta') at t0 + 2 pi k, k = 1..n_periods, and the impact times."""

    def hit(t: float, y: np.ndarray) -> float:
        return y[0] - theta_hat

    hit.terminal = True  # type: ignore[attr-defined]
    hit.direction = 1  # type: ignore[attr-defined]
    t, y = t0, np.array(x0, dtype=float)
    samples = np.empty((n_periods, 2))
    impacts = []
    for k in range(1, n_periods + 1):
        t_k = t0 + 2.0 * math.pi * k
        while True:
            sol = solve_ivp(rhs, (t, t_k), y, events=hit, **SCIPY_OPTS)
            if sol.status == 1:  # the stop is reached: restart after the reset
                t, y = float(sol.t_events[0][-1]), sol.y_events[0][-1].copy()
                y[1] *= -r
                impacts.append(t)
                continue
            if sol.status != 0:
                raise RuntimeError(f"solve_ivp failed at t = {t}: {sol.message}")
            t, y = t_k, sol.y[:, -1]
            break
        samples[k - 1] = y
    return samples, np.array(impacts)


# ----------------------------------------------------------------------------- timing


def median_of(fn: Callable[[], Run], repeats: int) -> Run:
    """``fn`` run ``repeats`` times: the middle run (by time), with the median time and the spread."""
    runs = []
    for _ in range(repeats):
        start = time.perf_counter()
        run = fn()
        run.seconds = time.perf_counter() - start
        runs.append(run)
    spread = Spread.of([r.seconds for r in runs])
    middle = sorted(runs, key=lambda r: r.seconds)[len(runs) // 2]
    middle.seconds, middle.spread = spread.median, spread
    return middle


def process_code(engine: str, n_periods: int) -> str:
    """A stand-alone script running `engine` for n_periods: the very same functions as in-process."""
    if engine == "grazing":
        return (
            "import math, grazing; "
            f"m = grazing.models.pendulum({CASE!r}, eta={ETA!r}, theta_hat=math.radians(40)); "
            f"grazing.simulate(m, [0.0, 0.0], periods={n_periods})"
        )
    args = f"{X0!r}, 0.0, {n_periods}, {THETA_HAT!r}, {R!r}"
    setup, body = {
        "heyoka-3d": (
            ["import heyoka as hy", inspect.getsource(make_heyoka), inspect.getsource(heyoka_loop)],
            [f"ta = make_heyoka({ALPHA!r}, {BETA!r}, {ETA!r})", f"heyoka_loop(ta, {args})"],
        ),
        "heyoka-t": (
            ["import heyoka as hy", inspect.getsource(make_heyoka_time), inspect.getsource(heyoka_loop)],
            [f"ta = make_heyoka_time({ALPHA!r}, {BETA!r}, {ETA!r})", f"heyoka_loop(ta, {args})"],
        ),
        "scipy": (
            [
                "from scipy.integrate import solve_ivp",
                f"SCIPY_OPTS = {SCIPY_OPTS!r}",
                inspect.getsource(scipy_rhs),
                inspect.getsource(scipy_loop),
            ],
            [f"rhs = scipy_rhs({ALPHA!r}, {BETA!r}, {ETA!r})", f"scipy_loop(rhs, {args})"],
        ),
    }[engine]
    return "\n".join(
        ["from __future__ import annotations", "import math", "import numpy as np", *setup, *body]
    )


def timing(engine: str, periods: int, run: Run, repeats: int) -> Timing:
    measured = run.samples.shape[0]
    scale = periods / measured
    spread = run.spread or Spread.of([run.seconds])
    return Timing(
        engine, periods, run.seconds * scale, repeats, measured, run.impact_t.size,
        seconds_min=spread.min * scale, seconds_max=spread.max * scale,
    )  # fmt: skip


def time_engines(res: Results, quick: bool) -> dict[tuple[str, int], Run]:
    """Time the engines on both sizes; returns the runs (for the accuracy and agreement checks)."""
    model = grazing_model(ETA, THETA_HAT)
    start = time.perf_counter()
    grazing.simulate(model, list(X0), periods=1)
    res.one_off["grazing first call (kernel load) [s]"] = time.perf_counter() - start
    start = time.perf_counter()
    ta3 = make_heyoka(ALPHA, BETA, ETA)
    res.one_off["heyoka-3d taylor_adaptive construction (JIT) [s]"] = time.perf_counter() - start
    start = time.perf_counter()
    tat = make_heyoka_time(ALPHA, BETA, ETA)
    res.one_off["heyoka-t taylor_adaptive construction (JIT) [s]"] = time.perf_counter() - start
    rhs = scipy_rhs(ALPHA, BETA, ETA)

    runners: dict[str, Callable[[int], Run]] = {
        "grazing": lambda n: grazing_run(model, n),
        "heyoka-3d": lambda n: Run(*heyoka_loop(ta3, X0, 0.0, n, THETA_HAT, R)),
        "heyoka-t": lambda n: Run(*heyoka_loop(tat, X0, 0.0, n, THETA_HAT, R)),
        "scipy": lambda n: Run(*scipy_loop(rhs, X0, 0.0, n, THETA_HAT, R)),
    }
    runs: dict[tuple[str, int], Run] = {}
    for n in SIZES:
        for engine in ENGINES:
            measured, repeats = n, (5 if n < LARGE else 3)
            if engine == "scipy" and n == LARGE:
                if quick:
                    continue
                predicted = runs["scipy", SIZES[0]].seconds / SIZES[0] * n
                measured = n if predicted <= SCIPY_CAP_S else SCIPY_FALLBACK
                repeats = 1
                log(f"scipy: {n:,} periods predicted to take {predicted:.0f} s")
            elif engine == "scipy":
                repeats = 3
            log(f"{engine}: {measured:,} periods, median of {repeats} ...")
            run = median_of(lambda e=engine, m=measured: runners[e](m), repeats)
            runs[engine, n] = run
            res.timings.append(timing(engine, n, run, repeats))
    return runs


def time_processes(res: Results, quick: bool) -> None:
    """Fresh-interpreter wall time of every engine's LARGE-period run (scipy's extrapolated)."""
    log("whole-process runs ...")
    res.one_off["python -c pass (fresh interpreter) [s]"] = process_seconds("pass", PROCESS_REPEATS)
    for engine in ENGINES:
        measured = LARGE
        if engine == "scipy":
            measured = SIZES[0] if quick else SCIPY_PROCESS_PERIODS
        log(f"  {engine}: {measured:,} periods, median of {PROCESS_REPEATS} ...")
        spread = process_spread(process_code(engine, measured), PROCESS_REPEATS)
        rest = 0.0
        if measured != LARGE:  # add the in-process time of the periods not run
            t = max((t for t in res.timings if t.engine == engine), key=lambda t: t.periods)
            rest = t.seconds / t.periods * (LARGE - measured)
        res.process.append(
            ProcessTiming(
                engine,
                LARGE,
                spread.median + rest,
                measured,
                spread.median,
                seconds_min=spread.min + rest,
                seconds_max=spread.max + rest,
            )
        )


# ----------------------------------------------------------------------------- accuracy


def deviation(ref: np.ndarray, samples: np.ndarray) -> float:
    """Max |diff| of the last TAIL samples from the reference's samples at the same times."""
    n = samples.shape[0]
    return float(np.max(np.abs(samples[-TAIL:] - ref[n - TAIL : n])))


def run_reference(res: Results, runs: dict[tuple[str, int], Run]) -> Run:
    """Compute the reference and fill in every timing's deviation from it."""
    ta = make_reference()
    fp = type(ta.time)
    log(f"reference ({np.dtype(fp).name}): {LARGE:,} periods ...")
    ref = median_of(lambda: reference_loop(ta, LARGE, THETA_HAT, R), 1)
    res.reference = {
        "fp_type": np.dtype(fp).name,
        "mantissa_bits": int(np.finfo(fp).nmant) + 1,
        "tol": float(ta.tol),
        "periods": LARGE,
        "seconds": ref.seconds,
        "impacts": int(ref.impact_t.size),
        "description": (
            "heyoka explicit-time system, "
            + (
                "fp_type=np.longdouble, tol = its epsilon"
                if fp is not float
                else "double precision (long double unavailable), default tol"
            )
            + ", time reset to 0 every period"
        ),
    }
    for t in res.timings:
        t.deviation = deviation(ref.samples, runs[t.engine, t.periods].samples)
    # Diagnostic: heyoka-t samples at the doubles 2.0 * math.pi * k, not at 2 pi k; the same
    # double integrator with the time reset every period shows what is left without that.
    log(f"heyoka-t with the time reset every period (diagnostic, not timed): {LARGE:,} periods ...")
    reset = reference_loop(make_heyoka_time(ALPHA, BETA, ETA), LARGE, THETA_HAT, R)
    res.reference[RESET_DEV] = deviation(ref.samples, reset.samples)
    two_pi = 2 * Fraction(PI_DIGITS)
    res.reference[TIME_ERR] = max(
        abs(float(Fraction(2.0 * math.pi * k) - two_pi * k)) for k in range(LARGE - TAIL + 1, LARGE + 1)
    )
    return ref


# ----------------------------------------------------------------------------- agreement


def orbit_diff(ref: np.ndarray, other: np.ndarray, period: int) -> tuple[float, int]:
    """Smallest max |diff| of other's last TAIL samples to ref's, over phase shifts of the orbit."""
    n = other.shape[0]
    best = (math.inf, 0)
    for shift in range(max(period, 1)):
        lo, hi = n - TAIL - shift, n - shift
        if lo < 0:
            break
        diff = float(np.max(np.abs(other[-TAIL:] - ref[lo:hi])))
        best = min(best, (diff, shift))
    return best


def first_mismatch(ref: np.ndarray, other: np.ndarray) -> str | None:
    for i in range(min(ref.size, other.size)):
        if abs(ref[i] - other[i]) > AGREE_TOL:
            return f"impact #{i + 1}: grazing t = {ref[i]:.6f}, engine t = {other[i]:.6f}"
    if ref.size != other.size:
        return f"impact counts differ after {min(ref.size, other.size)} matching impacts"
    return None


def agreement(engine: str, periods: int, ref: Run, run: Run) -> Agreement:
    n = run.samples.shape[0]
    samples = run.samples.astype(float)
    ref_samples, ref_impacts = ref.samples[:n], ref.impact_t[ref.impact_t < TWO_PI * n + 1e-9]
    run_impacts = run.impact_t[run.impact_t < TWO_PI * n + 1e-9]
    ref_period = grazing.detect_period(ref_samples[-TAIL:])
    aligned = float(np.max(np.abs(samples[-TAIL:] - ref_samples[-TAIL:])))
    orbit, shift = orbit_diff(ref_samples, samples, ref_period)
    k = min(N_FIRST_IMPACTS, run_impacts.size, ref_impacts.size)
    return Agreement(
        engine=engine,
        periods=n,
        period=grazing.detect_period(samples[-TAIL:]),
        period_grazing=ref_period,
        max_diff_aligned=aligned,
        max_diff_orbit=orbit,
        shift=shift,
        impacts=int(run_impacts.size),
        impacts_grazing=int(ref_impacts.size),
        first_impacts=[float(t) for t in run_impacts[:N_FIRST_IMPACTS]],
        first_impact_diff=float(np.max(np.abs(run_impacts[:k] - ref_impacts[:k]))) if k else math.nan,
        first_mismatch=first_mismatch(ref_impacts, run_impacts),
    )


def compare_engines(res: Results, runs: dict[tuple[str, int], Run], reference: Run) -> None:
    for n in SIZES:
        ref = runs["grazing", n]
        res.agreement.append(agreement("grazing", n, ref, ref))
        for engine in ENGINES[1:]:
            if (engine, n) in runs:
                res.agreement.append(agreement(engine, n, ref, runs[engine, n]))
    big = runs["grazing", LARGE]
    res.agreement.append(agreement("reference", LARGE, big, reference))


def check_agreement(res: Results) -> None:
    """Fail loudly unless every engine ends on grazing's orbit with the same period.

    grazing, both heyoka loops and the reference must match grazing's samples index by index
    within AGREE_TOL; scipy (which misses an impact and ends out of phase) up to a phase shift.
    """
    for a in res.agreement:
        assert a.period_grazing > 0, f"grazing found no period over the last {TAIL} samples"
        strict = a.engine in STRICT
        diff = a.max_diff_aligned if strict else a.max_diff_orbit
        if a.period != a.period_grazing or not diff <= AGREE_TOL:
            how = "sample by sample" if strict else "up to a phase shift of the orbit"
            raise AssertionError(
                f"{a.engine} disagrees with grazing after {a.periods} periods: period {a.period}, "
                f"max |diff| {diff:.3g} ({how})"
            )


# ----------------------------------------------------------------------------- shallow impacts


def shallow_impacts(res: Results) -> None:
    """Count impacts recorded in one period with the stop just below a non-impacting orbit's maximum."""
    free = grazing.simulate(
        grazing_model(SHALLOW_ETA, 3.0), list(X0), transient=200, periods=1, guard_min=True
    )
    assert free.n_impacts == 0 and free.guard_min is not None
    theta_max = 3.0 - free.guard_min[0]
    x0 = (float(free.samples[-1, 0]), float(free.samples[-1, 1]))
    t0 = float(free.t[-1])
    ta3 = make_heyoka(ALPHA, BETA, SHALLOW_ETA)
    tat = make_heyoka_time(ALPHA, BETA, SHALLOW_ETA)
    rhs = scipy_rhs(ALPHA, BETA, SHALLOW_ETA)
    counts: dict[str, list[int]] = {e: [] for e in ENGINES}
    for d in SHALLOW_DEPTHS:
        stop = theta_max - d
        sol = grazing.simulate(grazing_model(SHALLOW_ETA, stop), list(x0), t0=t0, periods=1, impacts="all")
        counts["grazing"].append(sol.n_impacts)
        counts["heyoka-3d"].append(heyoka_loop(ta3, x0, t0, 1, stop, R)[1].size)
        counts["heyoka-t"].append(heyoka_loop(tat, x0, t0, 1, stop, R)[1].size)
        counts["scipy"].append(scipy_loop(rhs, x0, t0, 1, stop, R)[1].size)
    res.shallow = {
        "eta": SHALLOW_ETA,
        "theta_max": theta_max,
        "x0": list(x0),
        "t0": t0,
        "depths": list(SHALLOW_DEPTHS),
        "impacts": counts,
        "missed": {e: sum(c == 0 for c in counts[e]) for e in ENGINES},
    }


# ----------------------------------------------------------------------------- report


RESET_DEV = "heyoka-t with the time reset every period: deviation"
TIME_ERR = "max |2.0 * math.pi * k - 2 pi k| over the last samples"


def time_err(rf: dict[str, Any]) -> float:
    return float(rf[TIME_ERR])


def settings() -> dict[str, Any]:
    return {
        "problem": f"pendulum case {CASE}: alpha={ALPHA}, beta={BETA}, r={R}",
        "eta": ETA,
        "theta_hat_deg": 40.0,
        "x0": list(X0),
        "sizes": list(SIZES),
        "grazing": "default tol (2.2e-16)",
        "heyoka-3d": "taylor_adaptive, default tol (2.2e-16), state (theta - theta_hat, theta', tau) "
        "with tau' = 1, terminal t_event on theta - theta_hat (positive), propagate_until(2 pi k) per period",
        "heyoka-t": "taylor_adaptive, default tol (2.2e-16), state (theta, theta'), sin(hy.time) forcing, "
        "terminal t_event on theta - theta_hat (positive), propagate_until(2 pi k) per period",
        "scipy": "solve_ivp per period, "
        + ", ".join(f"{k}={v}" for k, v in SCIPY_OPTS.items())
        + ", terminal event theta - theta_hat (direction +1), restarted after each reset",
    }


def ratio(res: Results, t: Timing) -> float:
    ref = next(g for g in res.timings if g.engine == "grazing" and g.periods == t.periods)
    return t.seconds / ref.seconds


def fmt_depth(d: float) -> str:
    return f"1e-{round(-math.log10(d))}"


def print_table(res: Results) -> None:
    m, s, rf = res.machine, res.settings, res.reference
    print(f"Machine: {versions_line(m)}")
    print(f"Problem: {s['problem']}, eta={ETA}, theta_hat=40 deg, x0=(0,0) at tau=0; a sample every period")
    for engine in ENGINES:
        print(f"  {engine:10s} {LABELS[engine]}: {s[engine]}")
    print(
        f"  reference  {rf['description']} ({rf['fp_type']}, {rf['mantissa_bits']}-bit mantissa, "
        f"tol {rf['tol']:.2g}): {rf['periods']:,} periods in {rf['seconds']:.1f} s, {rf['impacts']} impacts"
    )
    print(
        f"  heyoka-t   samples at the doubles 2.0 * math.pi * k: off 2 pi k by up to {time_err(rf):.2g} "
        f"at the end; with the time reset every period (diagnostic) it deviates from the reference "
        f"by {rf[RESET_DEV]:.2g}"
    )
    print(
        "\nTime, in-process (median of `runs`; first-call / JIT costs excluded, see below); "
        f"max|d| ref = max |diff| of the last {TAIL} samples from the reference"
    )
    print(
        f"{'periods':>8} {'engine':10} {'time [s]':>10} {'us/period':>10} {'x grazing':>10} "
        f"{'max|d| ref':>11} {'impacts':>8} {'runs':>5}  note"
    )
    for t in res.timings:
        note = (
            f"EXTRAPOLATED from {t.measured_periods:,} periods (impacts, max|d|: in those)"
            if t.extrapolated
            else ""
        )
        print(
            f"{t.periods:>8} {t.engine:10} {t.seconds:>10.4g} {t.us_per_period:>10.2f} "
            f"{ratio(res, t):>10.2f} {t.deviation:>11.2e} {t.impacts:>8} {t.repeats:>5}  {note}"
        )
    if not any(t.engine == "scipy" and t.periods == LARGE for t in res.timings):
        print(f"{LARGE:>8} {'scipy':10} {'skipped (--quick)':>10}")
    print(
        f"\nWhole process, fresh interpreter, {LARGE:,} periods (imports, kernel load/JIT incl.), "
        f"median of {PROCESS_REPEATS}"
    )
    for p in res.process:
        note = (
            f"  EXTRAPOLATED: {p.measured_seconds:.2f} s for {p.measured_periods:,} periods "
            f"+ in-process time of the other {LARGE - p.measured_periods:,}"
            if p.extrapolated
            else ""
        )
        print(f"  {p.engine:10s} {p.seconds:9.3f} s{note}")
    for name, sec in res.one_off.items():
        print(f"  {name}: {sec:.3f}")
    print(f"\nAgreement with grazing over the last {TAIL} samples (tolerance {AGREE_TOL:g})")
    print(
        f"{'periods':>8} {'engine':10} {'period':>6} {'max|d| aligned':>15} {'max|d| orbit':>13} "
        f"{'shift':>5} {'impacts':>8} {'grazing':>8} {'first-5 impact |dt|':>20}"
    )
    for a in res.agreement:
        print(
            f"{a.periods:>8} {a.engine:10} {a.period:>6} {a.max_diff_aligned:>15.2e} "
            f"{a.max_diff_orbit:>13.2e} {a.shift:>5} {a.impacts:>8} {a.impacts_grazing:>8} "
            f"{a.first_impact_diff:>20.2e}"
        )
    for a in res.agreement:
        if a.first_mismatch:
            print(
                f"  NOTE {a.engine} ({a.periods} periods) first differs from grazing at "
                f"{a.first_mismatch}; its samples are {a.shift} period(s) out of phase with grazing's"
            )
    print("  first impact times:")
    for a in res.agreement:
        if a.periods == SIZES[0] or a.engine == "reference":
            print(f"    {a.engine:10} " + "  ".join(f"{t:.10f}" for t in a.first_impacts))
    sh = res.shallow
    print(
        f"\nShallow impacts: one period from the period-1 orbit at eta={sh['eta']} "
        f"(theta_max = {sh['theta_max']:.15f}), stop at theta_max - d; impacts recorded"
    )
    print(f"{'d':>8} " + " ".join(f"{e:>10}" for e in ENGINES))
    for i, d in enumerate(sh["depths"]):
        print(f"{fmt_depth(d):>8} " + " ".join(f"{sh['impacts'][e][i]:>10}" for e in ENGINES))
    n = len(sh["depths"])
    print(f"{'missed':>8} " + " ".join(f"{sh['missed'][e]:>7}/{n:<2}" for e in ENGINES))


def markdown(res: Results) -> str:
    n_depths = len(res.shallow["depths"])
    head = [
        "| engine | µs/period (400) | µs/period (100,000) | × grazing (100,000) "
        "| whole process, 100,000 periods | max deviation from reference "
        f"| shallow impacts missed (of {n_depths}) |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    rows = []
    marks: set[str] = set()
    for engine in ENGINES:
        cells = [LABELS[engine]]
        ts = {n: next((t for t in res.timings if t.engine == engine and t.periods == n), None) for n in SIZES}
        for n in SIZES:
            t = ts[n]
            cells.append("–" if t is None else f"{t.us_per_period:.1f}{'*' if t.extrapolated else ''}")
            marks |= {"*"} if t is not None and t.extrapolated else set()
        big = ts[LARGE]
        cells.append("–" if big is None else f"{ratio(res, big):.2f}{'*' if big.extrapolated else ''}")
        p = next((p for p in res.process if p.engine == engine), None)
        cells.append("–" if p is None else f"{p.seconds:.2f} s{'†' if p.extrapolated else ''}")
        marks |= {"†"} if p is not None and p.extrapolated else set()
        last = big or ts[SIZES[0]]
        assert last is not None
        dev = f"{last.deviation:.1e}"
        if last.measured_periods != LARGE:
            dev += f" (after {last.measured_periods:,} periods)"
        orbit = next(a for a in res.agreement if a.engine == engine and a.periods == last.measured_periods)
        if orbit.shift or orbit.impacts != orbit.impacts_grazing:
            dev += "‡"
            marks.add("‡")
        cells.append(dev)
        cells.append(str(res.shallow["missed"][engine]))
        rows.append("| " + " | ".join(cells) + " |")
    rf, m = res.reference, res.machine
    notes = [
        "",
        f"- Problem: impacting pendulum, case {CASE} (α = {ALPHA}, β = {BETA}, r = {R}), η = {ETA}, "
        "θ̂ = 40°, from (θ, θ′) = (0, 0) at τ = 0; a stroboscopic sample every forcing period.",
        "- grazing: `grazing.simulate`, default tolerance (2.2e-16).",
        "- heyoka, paper's 3-D form: `taylor_adaptive`, default tol (2.2e-16); state (θ − θ̂, θ′, τ) "
        "with τ′ = 1; terminal `t_event` on θ − θ̂ (positive direction); `propagate_until(2πk)` per period; "
        "θ′ ← −rθ′ after each event. τ enters heyoka's mixed absolute/relative error norm, so the "
        "effective tolerance loosens as τ grows.",
        "- heyoka, explicit time: as above, but state (θ, θ′) only and `sin(hy.time)` forcing. Its "
        "deviation comes from the sample times: the doubles `2.0 * math.pi * k` are off 2πk by up to "
        f"{time_err(rf):.1e} at the end; the same integrator with the time reset to 0 every period "
        f"deviates by {rf[RESET_DEV]:.1e} (diagnostic run, not timed).",
        f"- scipy: `solve_ivp`, {', '.join(f'{k}={v}' for k, v in SCIPY_OPTS.items())}, terminal event "
        "on θ − θ̂ (direction +1), one call per period, restarted after each reset.",
        "- Reference: the explicit-time heyoka system in "
        + ("long double (`fp_type=np.longdouble`" if rf["mantissa_bits"] > 53 else "double (no long double")
        + f", {rf['mantissa_bits']}-bit mantissa, tol {rf['tol']:.2g}), "
        "time reset to 0 every period so the forcing phase is exact; "
        f"independent of grazing. Deviation = max |Δ| over both components of the last {TAIL} samples, "
        "at the same sample index.",
        f"- Whole process: fresh interpreter, imports + kernel load / JIT compilation + run, median of "
        f"{PROCESS_REPEATS}.",
    ]
    if "*" in marks:
        ext = next(t for t in res.timings if t.extrapolated)
        notes.append(f"- \\* extrapolated linearly from {ext.measured_periods:,} periods.")
    if "†" in marks:
        p = next(p for p in res.process if p.extrapolated)
        notes.append(
            f"- † {p.measured_seconds:.2f} s measured for {p.measured_periods:,} periods in a fresh process, "
            f"plus the in-process time of the remaining {LARGE - p.measured_periods:,} periods."
        )
    for a in res.agreement:
        if a.engine in ENGINES and a.engine != "grazing":
            if a.periods == max(b.periods for b in res.agreement if b.engine == a.engine):
                if a.shift or a.impacts != a.impacts_grazing:
                    notes.append(agreement_note(a))
    notes.append(f"- Machine: {versions_line(m)}.")
    return "\n".join(head + rows + notes)


def agreement_note(a: Agreement) -> str:
    return (
        f"- ‡ {LABELS[a.engine]} ({a.periods:,} periods) ends on grazing's period-{a.period_grazing} orbit "
        f"(last {TAIL} samples within {a.max_diff_orbit:.1e} up to a phase shift), but records "
        f"{a.impacts:,} impacts to grazing's {a.impacts_grazing:,} (first difference at "
        f"{a.first_mismatch}) and ends {a.shift} period(s) out of phase."
    )


def to_json(res: Results) -> dict[str, Any]:
    return {
        "machine": res.machine,
        "settings": res.settings,
        "labels": LABELS,
        "timings": [
            {
                **vars(t),
                "us_per_period": t.us_per_period,
                "extrapolated": t.extrapolated,
                "ratio_to_grazing": ratio(res, t),
            }
            for t in res.timings
        ],
        "process_seconds": [{**vars(p), "extrapolated": p.extrapolated} for p in res.process],
        "one_off_seconds": res.one_off,
        "reference": res.reference,
        "agreement": [vars(a) for a in res.agreement],
        "shallow_impacts": res.shallow,
    }


def main(argv: list[str] | None = None) -> int:
    parser = bench_parser(__doc__)
    parser.add_argument("--quick", action="store_true", help="skip scipy's 100,000-period run")
    args = parser.parse_args(argv)
    res = Results(machine=machine_info(), settings=settings())
    runs = time_engines(res, args.quick)
    time_processes(res, args.quick)
    reference = run_reference(res, runs)
    compare_engines(res, runs, reference)
    log("shallow impacts ...")
    shallow_impacts(res)
    res.machine["loadavg_end"] = loadavg()
    emit(args, lambda: print_table(res), lambda: markdown(res), lambda: to_json(res))
    check_agreement(res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
