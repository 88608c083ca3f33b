"""Benchmark a brute-force bifurcation diagram (``grazing.sweeps.sweep``) against user-written loops.

Problem (issue 4's speed targets): the impacting pendulum of Piiroinen, Virgin & Champneys
(2004), case B (alpha = 0.2254, beta = 0.048, r = 0.7675), theta_hat = 40 deg, 1000 values of
eta = np.linspace(0.44, 0.49, 1000); at each point 500 transient + 100 sampled forcing periods,
samples at tau = 2 pi k, each point started from the previous point's final state (an
experimenter's sweep); the first point starts from (theta, theta') = (0, 0).  The period of each
point is the smallest p <= min(64, M // 2) with max |s[i+p] - s[i]| <= 1e-6 over the M = 100
samples (grazing's rule; 0: none).

Sweeps timed:

* ``grazing`` -- ``sweep(model, "eta", etas)``: all cores, chunks of 50 points computed in
  parallel and made one chain (issue 28: each chunk checked against the chain's end, run again
  where it lands on another attractor), adaptive transients, Lyapunov exponents, tol 1e-10;
* the same with ``lyapunov=False``; with ``workers=1``; with ``adaptive=False``; and with all
  four switched off (``workers=1, chunk_size=0, adaptive=False, lyapunov=False``: one strictly
  sequential sweep doing exactly the work of the loops below);
* ``heyoka-t`` -- heyoka.py as a user would write it: one ``taylor_adaptive`` for (theta, theta')
  with ``sin(hy.time)`` forcing and alpha, beta, eta, theta_hat as runtime parameters
  (``hy.par``, ``ta.pars[2] = eta`` per point), terminal ``t_event`` on theta - theta_hat
  (positive direction), ``propagate_until(2 pi k)`` per period, theta' <- -r theta' in Python
  after each event; at each point ``ta.time = 0`` and the state is kept.  At heyoka's default
  tolerance (2.2e-16) and at tol = 1e-10 (grazing's sweep tolerance);
* ``heyoka-3d`` -- the paper's 3-D autonomous form (theta - theta_hat, theta', tau), tau' = 1,
  default tolerance, tau and the time reset to 0 at each point;
* ``scipy`` -- ``solve_ivp(method="DOP853", rtol=1e-10, atol=1e-12)`` per forcing period with a
  terminal event, restarted after each reset, on every 50th point only (indices 25, 75, ...,
  mid-chunk), each started from grazing's final state of the previous point, full 500 + 100
  periods; its time is EXTRAPOLATED to all points (mean time per point x points).

In-process times are the median of 3 interleaved runs (their spread is recorded too)
after a warm-up (grazing kernel load, heyoka
JIT compilation excluded and reported separately).  The machine may be shared: before each timed
run the script waits (up to ``--quiet-wait`` seconds) for other processes to go quiet, and it
reports the cores other processes kept busy during each run (from /proc/stat) and the load
average at the start and end.  Whole process: the ``grazing sweep ... --json``
command in a fresh process, output to /dev/null.  Period agreement: the number of points where
a sweep's period equals the default grazing sweep's, over all points and over the points whose
period in the default sweep is the same at both neighbours (away from window edges).

Run::

    python benchmarks/bench_sweep.py                  # full run (a few minutes)
    python benchmarks/bench_sweep.py --quick          # 200 points
    python benchmarks/bench_sweep.py --markdown --json sweep.json
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import heyoka as hy
import numpy as np
from scipy.integrate import solve_ivp

import grazing
from _common import (
    Meter,
    Spread,
    bench_parser,
    command_seconds,
    emit,
    grazing_exe,
    loadavg,
    log,
    machine_info,
    metered_command,
    versions_line,
    wait_quiet,
)
from grazing.sweeps import sweep

# ----------------------------------------------------------------------------- problem

CASE = "B"
ALPHA, BETA, R = 0.2254, 0.048, 0.7675
THETA_HAT_DEG = 40.0
THETA_HAT = math.radians(THETA_HAT_DEG)
ETA_START, ETA_STOP = 0.44, 0.49
N_POINTS, QUICK_POINTS = 1000, 200
TRANSIENT, PERIODS = 500, 100
X0 = (0.0, 0.0)
TWO_PI = 2.0 * math.pi

PERIOD_TOL, MAX_PERIOD = 1e-6, 64  # grazing's period rule
SWEEP_TOL = 1e-10  # grazing's sweep tolerance
CHUNK = 50  # grazing's default chunk size
SCIPY_STRIDE, SCIPY_OFFSET = 50, 25  # scipy runs points 25, 75, ... (mid-chunk)
SCIPY_OPTS: dict[str, Any] = {"method": "DOP853", "rtol": 1e-10, "atol": 1e-12}
REPEATS = 3  # in-process runs per sweep (interleaved, the median taken)
QUIET_WAIT = 20.0  # s: the most to wait before each timed run for other processes to go quiet
PROCESS_REPEATS = 3

TARGET_SECONDS = 10.0
TARGET_HEYOKA = 3.0
TARGET_SCIPY = 500.0

GRAZING_VARIANTS: dict[str, dict[str, Any]] = {
    "grazing": {},
    "grazing-nolyap": {"lyapunov": False},
    "grazing-w1": {"workers": 1},
    "grazing-noadapt": {"adaptive": False},
    "grazing-plain": {"workers": 1, "chunk_size": 0, "adaptive": False, "lyapunov": False},
}
LABELS = {
    "grazing": "grazing `sweep` (default: all cores, chunks of 50, adaptive, Lyapunov)",
    "grazing-nolyap": "grazing, `lyapunov=False`",
    "grazing-w1": "grazing, `workers=1`",
    "grazing-noadapt": "grazing, `adaptive=False`",
    "grazing-plain": "grazing, sequential plain (`workers=1, chunk_size=0, adaptive=False, lyapunov=False`)",
    "heyoka-t": "heyoka loop, explicit time, default tol (2.2e-16)",
    "heyoka-t-1e-10": "heyoka loop, explicit time, tol 1e-10",
    "heyoka-3d": "heyoka loop, paper's 3-D form (τ as a state), default tol",
    "scipy": "scipy `solve_ivp` loop (DOP853, rtol 1e-10, atol 1e-12)",
}


@dataclass
class Timing:
    key: str
    points: int  # points the time refers to
    seconds: float  # (possibly extrapolated) median time for `points`
    others: float  # cores kept busy by other processes during the runs (median)
    repeats: int
    measured_points: int
    indices: list[int]  # points whose period was computed
    periods: list[int]  # their periods
    agree: int = 0  # points of `indices` where the period equals the default sweep's
    stable: int = 0  # of those, points whose period is the same at both neighbours in the default sweep
    agree_stable: int = 0
    seconds_min: float = math.nan  # the spread of the repeated runs (extrapolated like `seconds`)
    seconds_max: float = math.nan

    @classmethod
    def of_runs(cls, key: str, spread: Spread, others: float, repeats: int, periods: list[int]) -> Timing:
        """The timing of ``repeats`` runs over every point (``len(periods)``), their spread ``spread``."""
        n = len(periods)
        return cls(
            key, n, spread.median, others, repeats, n, list(range(n)), periods,
            seconds_min=spread.min, seconds_max=spread.max,
        )  # fmt: skip

    @property
    def extrapolated(self) -> bool:
        return self.measured_points != self.points

    @property
    def points_per_s(self) -> float:
        return self.points / self.seconds


@dataclass
class Results:
    machine: dict[str, Any]
    settings: dict[str, Any]
    timings: list[Timing] = field(default_factory=list)
    process_seconds: float = math.nan  # median
    process_spread: tuple[float, float] = (math.nan, math.nan)  # (min, max)
    process_others: float = math.nan
    one_off: dict[str, float] = field(default_factory=dict)
    grazing_periods: list[int] = field(default_factory=list)


def detect_period(samples: np.ndarray, tol: float = PERIOD_TOL, max_period: int = MAX_PERIOD) -> int:
    """Smallest p <= min(max_period, M // 2) with max |s[i+p] - s[i]| <= tol (all components); else 0."""
    m = samples.shape[0]
    for p in range(1, min(max_period, m // 2) + 1):
        if np.max(np.abs(samples[p:] - samples[:-p])) <= tol:
            return p
    return 0


# ----------------------------------------------------------------------------- engines


def grazing_model() -> grazing.HybridModel:
    model = grazing.models.pendulum(CASE, theta_hat=THETA_HAT)
    expected = {"alpha": ALPHA, "beta": BETA, "r": R, "theta_hat": THETA_HAT}
    assert all(model.params[k] == v for k, v in expected.items()), model.params
    return model


def grazing_sweep(etas: np.ndarray, **options: Any) -> Any:
    options = {"x0": list(X0), "transient": TRANSIENT, "periods": PERIODS, **options}
    return sweep(grazing_model(), "eta", etas, **options)


def make_heyoka_t(tol: float | None = None) -> hy.taylor_adaptive:
    """(theta, theta') with explicit time; pars = (alpha, beta, eta, theta_hat)."""
    theta, omega = hy.make_vars("theta", "omega")
    alpha, beta, eta, theta_hat = hy.par[0], hy.par[1], hy.par[2], hy.par[3]
    ode = [
        (theta, omega),
        (
            omega,
            alpha * hy.cos(theta) * hy.sin(hy.time)
            - 2.0 * beta / eta * omega
            - hy.sin(theta) / (4.0 * eta**2),
        ),
    ]
    stop = hy.t_event(theta - theta_hat, direction=hy.event_direction.positive)
    opts = {} if tol is None else {"tol": tol}
    return hy.taylor_adaptive(
        ode, [0.0, 0.0], pars=[ALPHA, BETA, ETA_START, THETA_HAT], t_events=[stop], **opts
    )


def make_heyoka_3d(tol: float | None = None) -> hy.taylor_adaptive:
    """The paper's x = (theta - theta_hat, theta', tau), tau' = 1; pars = (alpha, beta, eta, theta_hat)."""
    x1, x2, x3 = hy.make_vars("x1", "x2", "x3")
    alpha, beta, eta, theta_hat = hy.par[0], hy.par[1], hy.par[2], hy.par[3]
    theta = x1 + theta_hat
    ode = [
        (x1, x2),
        (x2, alpha * hy.cos(theta) * hy.sin(x3) - 2.0 * beta / eta * x2 - hy.sin(theta) / (4.0 * eta**2)),
        (x3, hy.expression(1.0)),
    ]
    stop = hy.t_event(x1, direction=hy.event_direction.positive)
    opts = {} if tol is None else {"tol": tol}
    return hy.taylor_adaptive(
        ode, [0.0, 0.0, 0.0], pars=[ALPHA, BETA, ETA_START, THETA_HAT], t_events=[stop], **opts
    )


def heyoka_sweep(ta: hy.taylor_adaptive, etas: np.ndarray, three_d: bool) -> np.ndarray:
    """Samples (points, PERIODS, 2) of a continuation sweep; each point continues from the last state."""
    samples = np.empty((len(etas), PERIODS, 2))
    ta.state[:] = [X0[0] - THETA_HAT, X0[1], 0.0] if three_d else list(X0)
    shift = THETA_HAT if three_d else 0.0
    for j, eta in enumerate(etas):
        ta.pars[2] = eta
        ta.time = 0.0
        if three_d:
            ta.state[2] = 0.0
        ta.reset_cooldowns()
        for k in range(1, TRANSIENT + PERIODS + 1):
            t_k = 2.0 * math.pi * k
            while True:
                outcome = ta.propagate_until(t_k)[0]
                if outcome == hy.taylor_outcome.time_limit:
                    break
                if -1000 < int(outcome) < 0:  # the terminal event: the stop is reached
                    ta.state[1] *= -R
                    continue
                raise RuntimeError(f"heyoka stopped with {outcome} at eta = {eta}, t = {ta.time}")
            if k > TRANSIENT:
                samples[j, k - TRANSIENT - 1] = ta.state[0] + shift, ta.state[1]
    return samples


def scipy_rhs(eta: float) -> Callable[[float, np.ndarray], np.ndarray]:
    c_damp, c_grav = 2.0 * BETA / eta, 1.0 / (4.0 * eta**2)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        return np.array([y[1], ALPHA * np.cos(y[0]) * np.sin(t) - c_damp * y[1] - c_grav * np.sin(y[0])])

    return rhs


def scipy_point(eta: float, x0: np.ndarray) -> np.ndarray:
    """One point: TRANSIENT + PERIODS periods from x0 at t = 0; the last PERIODS samples."""

    def hit(t: float, y: np.ndarray) -> float:
        return y[0] - THETA_HAT

    hit.terminal = True  # type: ignore[attr-defined]
    hit.direction = 1  # type: ignore[attr-defined]
    rhs = scipy_rhs(eta)
    t, y = 0.0, np.array(x0, dtype=float)
    samples = np.empty((PERIODS, 2))
    for k in range(1, TRANSIENT + PERIODS + 1):
        t_k = 2.0 * math.pi * k
        while True:
            sol = solve_ivp(rhs, (t, t_k), y, events=hit, **SCIPY_OPTS)
            if sol.status == 1:  # the stop is reached: restart after the reset
                t, y = float(sol.t_events[0][-1]), sol.y_events[0][-1].copy()
                y[1] *= -R
                continue
            if sol.status != 0:
                raise RuntimeError(f"solve_ivp failed at eta = {eta}, t = {t}: {sol.message}")
            t, y = t_k, sol.y[:, -1]
            break
        if k > TRANSIENT:
            samples[k - TRANSIENT - 1] = y
    return samples


# ----------------------------------------------------------------------------- timing


def round_robin(
    runners: dict[str, Callable[[], Any]], repeats: int, quiet: float
) -> dict[str, tuple[Spread, float, int, Any]]:
    """Run every runner `repeats` times, interleaved; per runner (seconds, others, runs, output).

    ``seconds`` is the spread of the runs' wall times (the tables show its median); before
    each run, waits up to `quiet` seconds for other processes to go quiet; ``others`` is the
    median number of cores other processes kept busy during the runs.
    """
    seconds: dict[str, list[float]] = {k: [] for k in runners}
    others: dict[str, list[float]] = {k: [] for k in runners}
    outputs: dict[str, Any] = {}
    for r in range(repeats):
        for key, run in runners.items():
            log(f"  {key}: run {r + 1} ...")
            wait_quiet(quiet)
            with Meter() as m:
                outputs[key] = run()
            seconds[key].append(m.seconds)
            others[key].append(m.others)
    return {k: (Spread.of(seconds[k]), Spread.of(others[k]).median, repeats, outputs[k]) for k in runners}


def time_grazing(res: Results, etas: np.ndarray, quiet: float) -> np.ndarray:
    """Time the grazing variants; returns the default sweep's final states (for scipy's starts)."""
    start = time.perf_counter()
    grazing_sweep(etas[:2], periods=4, transient=4, workers=1)  # kernel load (also the variational one)
    res.one_off["grazing kernel load (first call)"] = time.perf_counter() - start
    n = len(etas)
    log(f"grazing variants: {n} points, median of {REPEATS} ...")
    runners = {key: (lambda o=opts: grazing_sweep(etas, **o)) for key, opts in GRAZING_VARIANTS.items()}
    x_final = None
    for key, (sec, others, runs, ds) in round_robin(runners, REPEATS, quiet).items():
        per = ds.period.values.astype(int)
        assert [detect_period(s) for s in ds.samples.values] == per.tolist(), "period rules differ"
        res.timings.append(Timing.of_runs(key, sec, others, runs, per.tolist()))
        if key == "grazing":
            res.grazing_periods = per.tolist()
            x_final = ds.x_final.values
    assert x_final is not None
    return x_final


def time_heyoka(res: Results, etas: np.ndarray, quiet: float) -> None:
    n = len(etas)
    runners = {}
    for key, make, tol, three_d in (
        ("heyoka-t", make_heyoka_t, None, False),
        ("heyoka-t-1e-10", make_heyoka_t, SWEEP_TOL, False),
        ("heyoka-3d", make_heyoka_3d, None, True),
    ):
        start = time.perf_counter()
        ta = make(tol)
        res.one_off[f"{key} JIT (taylor_adaptive construction)"] = time.perf_counter() - start
        runners[key] = lambda t=ta, d=three_d: heyoka_sweep(t, etas, d)
    log(f"heyoka loops: {n} points, median of {REPEATS} ...")
    for key, (sec, others, runs, samples) in round_robin(runners, REPEATS, quiet).items():
        res.timings.append(Timing.of_runs(key, sec, others, runs, [detect_period(s) for s in samples]))


def time_scipy(res: Results, etas: np.ndarray, x_final: np.ndarray, quiet: float) -> None:
    idx = list(range(SCIPY_OFFSET, len(etas), SCIPY_STRIDE))
    log(f"scipy: {len(idx)} points (every {SCIPY_STRIDE}th), {TRANSIENT + PERIODS} periods each ...")
    periods, total, other = [], 0.0, 0.0
    for j in idx:
        wait_quiet(quiet)
        with Meter() as m:
            samples = scipy_point(float(etas[j]), x_final[j - 1])
        total += m.seconds
        other += m.others * m.seconds
        periods.append(detect_period(samples))
    n = len(etas)
    res.timings.append(Timing("scipy", n, total / len(idx) * n, other / total, 1, len(idx), idx, periods))


def cli_command(n: int) -> list[str]:
    return [
        grazing_exe(),
        "sweep",
        "--param",
        "eta",
        "--start",
        str(ETA_START),
        "--stop",
        str(ETA_STOP),
        "--num",
        str(n),
        "--theta-hat",
        str(THETA_HAT_DEG),
        "--json",
    ]


def time_process(res: Results, n: int, quiet: float) -> None:
    cmd = cli_command(n)
    log(f"whole process: {' '.join(cmd[1:])} > /dev/null, median of {PROCESS_REPEATS} ...")
    spread, others = metered_command(cmd, PROCESS_REPEATS, quiet, stdout=subprocess.DEVNULL)
    res.process_seconds, res.process_others = spread.median, others.median
    res.process_spread = (spread.min, spread.max)
    res.one_off["python -c pass (fresh interpreter)"] = command_seconds(
        [sys.executable, "-c", "pass"], PROCESS_REPEATS
    )


# ----------------------------------------------------------------------------- agreement


def stable_points(periods: list[int]) -> set[int]:
    """Interior points whose period equals both neighbours' (in the default sweep)."""
    return {j for j in range(1, len(periods) - 1) if periods[j - 1] == periods[j] == periods[j + 1]}


def fill_agreement(res: Results) -> None:
    ours = res.grazing_periods
    stable = stable_points(ours)
    for t in res.timings:
        t.agree = sum(ours[j] == p for j, p in zip(t.indices, t.periods))
        t.stable = sum(j in stable for j in t.indices)
        t.agree_stable = sum(ours[j] == p for j, p in zip(t.indices, t.periods) if j in stable)


def disagreements(res: Results, key: str) -> list[tuple[int, int, int]]:
    """(index, our period, its period) where they differ."""
    t = next(t for t in res.timings if t.key == key)
    ours = res.grazing_periods
    return [(j, ours[j], p) for j, p in zip(t.indices, t.periods) if ours[j] != p]


# ----------------------------------------------------------------------------- report


def ours(res: Results) -> Timing:
    return next(t for t in res.timings if t.key == "grazing")


def ratio(res: Results, key: str) -> float:
    return next(t for t in res.timings if t.key == key).seconds / ours(res).seconds


def verdict(ok: bool, short_by: float) -> str:
    return "met" if ok else f"MISSED (short by a factor {short_by:.2f})"


def targets(res: Results) -> list[str]:
    """One line per target of issue 4 (not asserted)."""
    sec, n, proc = ours(res).seconds, ours(res).points, res.process_seconds
    scale = "" if n == N_POINTS else f" (for {n} points, not {N_POINTS})"
    worst = max(sec, proc)
    lines = [
        f"ours < {TARGET_SECONDS:g} s{scale}: {sec:.2f} s in-process, {proc:.2f} s whole process: "
        + verdict(worst < TARGET_SECONDS, worst / TARGET_SECONDS)
    ]
    for key in ("heyoka-t", "heyoka-t-1e-10", "heyoka-3d"):
        x = ratio(res, key)
        lines.append(
            f"≥ {TARGET_HEYOKA:g}× faster than the {LABELS[key]}: {x:.2f}×: "
            + verdict(x >= TARGET_HEYOKA, TARGET_HEYOKA / x)
        )
    x = ratio(res, "scipy")
    lines.append(
        f"≥ {TARGET_SCIPY:g}× faster than the {LABELS['scipy']}: {x:.0f}× (extrapolated): "
        + verdict(x >= TARGET_SCIPY, TARGET_SCIPY / x)
    )
    return lines


def row_note(t: Timing) -> str:
    if t.extrapolated:
        return f"EXTRAPOLATED from {t.measured_points} points (every {SCIPY_STRIDE}th)"
    return ""


def print_table(res: Results) -> None:
    m, s = res.machine, res.settings
    print(f"Machine: {versions_line(m)}")
    print(f"Problem: {s['problem']}")
    print(
        "\nTime, in-process (median of `runs`; kernel load / JIT excluded); x ours = time / ours; "
        "periods = ours: points where the detected period equals the default grazing sweep's "
        "(all; and at points whose period is the same at both neighbours in ours); "
        "others = cores kept busy by other processes during the run"
    )
    print(
        f"{'sweep':16} {'time [s]':>9} {'points/s':>9} {'x ours':>8} {'= ours':>11} {'= ours, stable':>15} "
        f"{'runs':>4} {'others':>6}  note"
    )
    for t in res.timings:
        print(
            f"{t.key:16} {t.seconds:>9.3f} {t.points_per_s:>9.1f} {t.seconds / ours(res).seconds:>8.2f} "
            f"{f'{t.agree}/{len(t.indices)}':>11} {f'{t.agree_stable}/{t.stable}':>15} {t.repeats:>4} "
            f"{t.others:>6.2f}  {row_note(t)}"
        )
    for t in res.timings:
        print(f"  {t.key:16} {LABELS[t.key]}")
    print(
        f"\nWhole process (fresh `grazing sweep ... --json > /dev/null`, {ours(res).points} points, "
        f"median of {PROCESS_REPEATS}): {res.process_seconds:.2f} s (others {res.process_others:.2f})"
    )
    for name, sec in res.one_off.items():
        print(f"  {name}: {sec:.3f} s")
    per = np.array(res.grazing_periods)
    vals, counts = np.unique(per, return_counts=True)
    print("\nPeriods in the default sweep: " + ", ".join(f"{v}: {c}" for v, c in zip(vals, counts)))
    for key in ("grazing-plain", "heyoka-t", "heyoka-t-1e-10", "heyoka-3d", "scipy"):
        d = disagreements(res, key)
        at_chunk = sum(j % CHUNK == 0 for j, _, _ in d)
        shown = ", ".join(f"#{j} {a}->{b}" for j, a, b in d[:8]) + (" ..." if len(d) > 8 else "")
        print(f"  {key}: {len(d)} disagreements ({at_chunk} at chunk starts of ours): {shown}")
    print("\nTargets (issue 4):")
    for line in targets(res):
        print(f"  {line}")


def markdown(res: Results) -> str:
    n = ours(res).points
    head = [
        f"| sweep ({n} points) | wall time | points/s | time ÷ ours | periods = ours "
        "| periods = ours, where ours is locally constant | other load |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    rows = []
    for t in res.timings:
        mark = "*" if t.extrapolated else ""
        rows.append(
            f"| {LABELS[t.key]} | {t.seconds:.2f} s{mark} | {t.points_per_s:.1f}{mark} "
            f"| {t.seconds / ours(res).seconds:.2f}{mark} | {t.agree}/{len(t.indices)} "
            f"| {t.agree_stable}/{t.stable} | {t.others:.2f} |"
        )
    rows.append(
        f"| grazing default, whole process (`grazing sweep ... --json > /dev/null`) "
        f"| {res.process_seconds:.2f} s | {n / res.process_seconds:.1f} | "
        f"{res.process_seconds / ours(res).seconds:.2f} | – | – | {res.process_others:.2f} |"
    )
    sc = next(t for t in res.timings if t.key == "scipy")
    notes = [
        "",
        f"- Problem: impacting pendulum, case {CASE} (α = {ALPHA}, β = {BETA}, r = {R}), "
        f"θ̂ = {THETA_HAT_DEG:g}°, η = `np.linspace({ETA_START}, {ETA_STOP}, {n})`; {TRANSIENT} transient + "
        f"{PERIODS} sampled forcing periods per point, samples at τ = 2πk; each point starts from the "
        "previous point's final state "
        f"(grazing: chunks of {CHUNK} points computed in parallel and made one chain — each checked "
        "against the chain's end and run again where it lands on another attractor; the sequential plain "
        "variant and the loops: one chain point after point).",
        "- Period: smallest p ≤ min(64, M/2) with max |s[i+p] − s[i]| ≤ 1e-6 over the M = 100 samples "
        '(grazing\'s rule, reimplemented for the loops). "Locally constant": interior points whose period '
        f"in the default sweep equals both neighbours' ({sc.stable} of the scipy points).",
        "- heyoka loops: one `taylor_adaptive` reused for all points, α, β, η, θ̂ as runtime parameters "
        "(`hy.par`, `ta.pars[2] = η` per point), terminal `t_event` on θ − θ̂ (positive direction), "
        "`propagate_until(2πk)` per period, θ′ ← −rθ′ in Python after each event, `ta.time = 0` at each "
        "point (state kept). Explicit time: state (θ, θ′), `sin(hy.time)` forcing; 3-D form: state "
        "(θ − θ̂, θ′, τ) with τ′ = 1, τ also reset to 0 at each point.",
        f"- \\* scipy: EXTRAPOLATED: {sc.measured_points} points (indices {SCIPY_OFFSET}, "
        f"{SCIPY_OFFSET + SCIPY_STRIDE}, …, mid-chunk) each run for the full {TRANSIENT} + {PERIODS} periods "
        "from grazing's final state of the previous point; time = mean per point × "
        f"{n}; period agreement over those {sc.measured_points} points.",
        f"- In-process: median of {REPEATS} interleaved runs after a warm-up; excluded: "
        + ", ".join(f"{k} {v:.2f} s" for k, v in res.one_off.items() if "python -c" not in k)
        + f". Whole process: median of {PROCESS_REPEATS}, imports and kernel load included. Before each "
        f"run, up to {res.settings['quiet_wait_s']:g} s of waiting for other processes to go quiet. "
        "Other load: cores kept busy by other processes during the runs (median), from /proc/stat.",
        "- Targets (issue 4, not asserted):",
        *(f"  - {line}" for line in targets(res)),
        f"- Machine: {versions_line(res.machine)}.",
    ]
    return "\n".join(head + rows + notes)


def settings(n: int) -> dict[str, Any]:
    return {
        "problem": f"pendulum case {CASE}: alpha={ALPHA}, beta={BETA}, r={R}, theta_hat={THETA_HAT_DEG} deg, "
        f"eta=linspace({ETA_START}, {ETA_STOP}, {n}), transient={TRANSIENT}, periods={PERIODS}, "
        f"x0={X0}, continuation",
        "points": n,
        "period_rule": f"smallest p <= min({MAX_PERIOD}, M//2) with max|s[i+p]-s[i]| <= {PERIOD_TOL}",
        "grazing_variants": GRAZING_VARIANTS,
        "scipy": {**SCIPY_OPTS, "stride": SCIPY_STRIDE, "offset": SCIPY_OFFSET},
        "sweep_tol": SWEEP_TOL,
        "cpu_count": os.cpu_count(),
    }


def to_json(res: Results) -> dict[str, Any]:
    return {
        "machine": res.machine,
        "settings": res.settings,
        "labels": LABELS,
        "timings": [
            {
                **vars(t),
                "points_per_s": t.points_per_s,
                "extrapolated": t.extrapolated,
                "ratio_to_ours": t.seconds / ours(res).seconds,
            }
            for t in res.timings
        ],
        "process_seconds": res.process_seconds,
        "process_seconds_min_max": list(res.process_spread),
        "process_others": res.process_others,
        "one_off_seconds": res.one_off,
        "targets": targets(res),
    }


def main(argv: list[str] | None = None) -> int:
    parser = bench_parser(__doc__, quiet_wait=QUIET_WAIT)
    parser.add_argument("--quick", action="store_true", help=f"{QUICK_POINTS} points instead of {N_POINTS}")
    args = parser.parse_args(argv)
    n = QUICK_POINTS if args.quick else N_POINTS
    etas = np.linspace(ETA_START, ETA_STOP, n)
    res = Results(machine=machine_info(), settings={**settings(n), "quiet_wait_s": args.quiet_wait})
    x_final = time_grazing(res, etas, args.quiet_wait)
    time_heyoka(res, etas, args.quiet_wait)
    time_scipy(res, etas, x_final, args.quiet_wait)
    time_process(res, n, args.quiet_wait)
    fill_agreement(res)
    res.machine["loadavg_end"] = loadavg()
    emit(args, lambda: print_table(res), lambda: markdown(res), lambda: to_json(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
