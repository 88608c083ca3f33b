"""The serial part of a sweep, measured on this machine, and what it allows at more cores (Amdahl's law).

Issue 29 item 3: local threads must keep at least 85 % of the cores busy at 16 cores.  A
machine with 2 cores cannot show that directly, but it can measure what does not run in
parallel: a sweep's time is ``S + P / c`` on ``c`` cores, with ``S`` the serial part (the
interpreter's start and imports, loading the kernels, building the points' table, the
result's assembly and its JSON text, and the threads' idle tail) and ``P`` the work the
threads share.  The cores kept busy on ``c`` cores are then ``(S + P) / (S + P / c)``, the
efficiency ``(S + P) / (c S + P)``.

Two ways to find ``S``, printed side by side:

- *measured*: one whole ``grazing sweep ... --json`` process, with the times of its phases
  taken in the process itself (the driver's calls on each thread, the JSON text) and the
  start-up measured as a process that stops right before the sweep; also printed, the main
  thread's CPU time while the threads compute (it takes each chunk's results, stores them and
  encodes their JSON: Python holding the GIL, which the threads' compiled driver does not need);
- *fitted*: the same command on 1 and on 2 threads, ``T1 = S + P``, ``T2 = S + P / 2``
  (each a median of several runs; noisy where other processes share the cores; the main
  thread's work while the threads compute counts as serial here: with one thread it has the
  other core to itself, with two it shares them).

A third projection leaves out the process's start and end (the interpreter, the imports, the
teardown): a sweep called from a running Python (a notebook) pays only the rest.

The sweep is the equal-work sweep of the heyoka comparison (every point from rest, no
Lyapunov exponents, no adaptive transients, tol 1e-10) and, with ``--default``, the default
sweep (one chain of points: chunks checked against the previous chunk's end and run again
where they differ; its rounds wait for their slowest chunk).

The processes import grazing from compiled bytecode, as an installed package does: where the
environment says not to write it (``PYTHONDONTWRITEBYTECODE``, set in some sandboxes and CI
jobs), every module was compiled from its source in every process, 0.06 s of the start-up; the
script then keeps the bytecode in a temporary directory of its own (``PYTHONPYCACHEPREFIX``)
unless ``--no-bytecode-cache`` is given.

Usage::

    python benchmarks/bench_scaling.py                 # 4000 points, 3 runs each (about 1-2 minutes)
    python benchmarks/bench_scaling.py --points 8000 32000 --default --default-points 8000 --json scaling.json
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

sys.path.insert(0, os.path.dirname(__file__))
from _common import EQUAL_WORK, EQUAL_WORK_TOL, bench_parser, emit, grazing_exe, loadavg, log, machine_info

CORES = (2, 4, 8, 16, 32, 64)
"""Core counts of the projection."""

HOWS = ("measured", "fitted", "in-process")
"""The serial parts projected: measured in the process, fitted from 1 and all threads, and the measured
one without the process's start and end (a sweep called from a running Python, the kernels loaded on
its first call counted)."""

_PROBE = r"""
import json, os, sys, threading, time
t_enter = time.perf_counter()
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # (as the grazing console script: _grazing_entry)
import grazing.cli
from grazing.cli import common
from grazing.sweeps import run as run_module
calls = []
original_run = run_module.LaneBatch.run
def timed_run(self):
    start = time.perf_counter()
    try:
        original_run(self)
    finally:
        calls.append((threading.get_ident(), start, time.perf_counter()))
run_module.LaneBatch.run = timed_run
encode = []
name = "json_pieces" if hasattr(common, "json_pieces") else "json_text"  # (the encoder emit_json calls)
original_text = getattr(common, name)
def timed_text(*args, **kwargs):
    start = time.perf_counter()
    out = original_text(*args, **kwargs)
    encode.append(time.perf_counter() - start)
    return out
setattr(common, name, timed_text)
from grazing.sweeps import executor
consumer = []
original_local = executor.local_results
def timed_local(*args, **kwargs):
    start = time.thread_time()  # (the main thread's CPU, while the threads compute the chunks it takes)
    try:
        yield from original_local(*args, **kwargs)
    finally:
        consumer.append(time.thread_time() - start)
executor.local_results = timed_local
t_main = time.perf_counter()
code = grazing.cli.main(sys.argv[2:])
t_end = time.perf_counter()
with open(sys.argv[1], "w") as fh:
    json.dump({"enter": t_enter, "main": t_main, "end": t_end, "calls": calls, "encode": encode,
               "consumer": consumer, "code": code}, fh)
from grazing.cli.quick_exit import quick_exit  # (as the console script ends)
quick_exit(code)
"""


def sweep_args(points: int, workers: int, default: bool) -> list[str]:
    """The ``grazing sweep`` arguments (pendulum, case B, θ̂ = 40°, η from 0.44 to 0.49)."""
    common = ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.49", "--num", str(points)]
    return [*common, *([] if default else EQUAL_WORK), "--workers", str(workers), "--json"]


def whole(args: list[str]) -> tuple[float, float]:
    """Wall and CPU seconds (user + system) of ``grazing ARGS > /dev/null`` (the console script) as a whole
    process."""
    before = os.times()
    start = time.perf_counter()
    subprocess.run([grazing_exe(), *args], stdout=subprocess.DEVNULL, check=True)
    wall = time.perf_counter() - start
    after = os.times()
    return wall, (after.children_user - before.children_user) + (
        after.children_system - before.children_system
    )


def phases(args: list[str], threads: int) -> dict[str, float]:
    """One whole process of a sweep on ``threads`` threads, its phases timed inside it (see the module).

    The threads' idle time is counted against ``threads``, not against the threads that ran the driver
    (a sweep that settles a chain in rounds starts new threads each round)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "phases.json"
        script = Path(tmp) / "probe.py"
        script.write_text(_PROBE)
        start = time.perf_counter()
        subprocess.run([sys.executable, str(script), str(out), *args], stdout=subprocess.DEVNULL, check=True)
        wall = time.perf_counter() - start
        rec = json.loads(out.read_text())
    calls = rec["calls"]
    first = min(c[1] for c in calls)
    last = max(c[2] for c in calls)
    busy = sum(c[2] - c[1] for c in calls)
    span = last - first
    return {
        "wall": wall,
        "startup": wall - (rec["end"] - rec["enter"]) + (rec["main"] - rec["enter"]),  # interpreter + imports
        "before_driver": first - rec["main"],  # parsing, kernels loaded, the points' table
        "driver_span": span,
        "idle_in_span": max(0.0, threads * span - busy)
        / max(threads, 1),  # (the threads' idle tail, per thread)
        "after_driver": rec["end"] - last,  # assembly, summary, JSON text and its writing
        "json": sum(rec["encode"]),
        "consumer_cpu": sum(rec["consumer"]),  # (the main thread's work on the chunks, overlapped)
        "threads": threads,
        "rounds": len(calls) / max(threads, 1),  # (driver calls per thread)
    }


def amdahl(serial: float, parallel: float, cores: int) -> dict[str, float]:
    """Time, cores kept busy and efficiency on ``cores`` cores of a job ``S + P``."""
    t = serial + parallel / cores
    return {
        "cores": cores,
        "seconds": t,
        "busy": (serial + parallel) / t,
        "efficiency": (serial + parallel) / (cores * t),
    }


def measure(points: int, runs: int, default: bool) -> dict[str, Any]:
    """Phases (median of ``runs``) on all cores, and the whole process on 1 and 2 threads; the projections."""
    ncores = os.cpu_count() or 1
    name = "default sweep" if default else "equal-work sweep"
    log(f"{name}, {points} points: {runs} runs with the phases timed, then 1 and {ncores} threads")
    runs_phases = [phases(sweep_args(points, ncores, default), ncores) for _ in range(runs)]
    med = {k: statistics.median(r[k] for r in runs_phases) for k in runs_phases[0]}
    t1 = [whole(sweep_args(points, 1, default)) for _ in range(runs)]
    tc = [whole(sweep_args(points, ncores, default)) for _ in range(runs)]
    T1, Tc = statistics.median(w for w, _ in t1), statistics.median(w for w, _ in tc)
    cpu_c = statistics.median(c for _, c in tc)
    # measured: everything but the threads' shared work is serial
    serial = med["startup"] + med["before_driver"] + med["after_driver"] + med["idle_in_span"]
    parallel = med["threads"] * (med["driver_span"] - med["idle_in_span"])
    # fitted from 1 and c threads: T1 = S + P, Tc = S + P / c
    p_fit = (T1 - Tc) * ncores / (ncores - 1) if ncores > 1 else float("nan")
    s_fit = T1 - p_fit
    return {
        "sweep": name,
        "points": points,
        "cores_here": ncores,
        "phases_median": med,
        "phases_runs": runs_phases,
        "whole_1_thread": {"median": T1, "min": min(w for w, _ in t1), "max": max(w for w, _ in t1)},
        "whole_all_threads": {"median": Tc, "min": min(w for w, _ in tc), "max": max(w for w, _ in tc)},
        "cores_busy_here": cpu_c / Tc,
        "measured": {
            "serial": serial,
            "parallel": parallel,
            "projection": [amdahl(serial, parallel, c) for c in CORES],
        },
        "fitted": {
            "serial": s_fit,
            "parallel": p_fit,
            "projection": [amdahl(s_fit, p_fit, c) for c in CORES],
        },
        "in-process": {  # (a sweep called from a running Python: the process's start and end are not its)
            "serial": serial - med["startup"],
            "parallel": parallel,
            "projection": [amdahl(serial - med["startup"], parallel, c) for c in CORES],
        },
    }


def dask_against_threads(points: int, runs: int) -> dict[str, Any]:
    """The equal-work sweep in one process on a local Dask cluster (a one-thread worker process per
    core, started and warmed up first) against the same process's threads, interleaved."""
    import numpy as np
    from distributed import Client, LocalCluster

    import grazing
    from grazing.core.options import SweepSettings
    from grazing.sweeps import sweep

    ncores = os.cpu_count() or 1
    model = grazing.models.pendulum("B")
    values = np.linspace(0.44, 0.49, points)
    settings = SweepSettings(fresh=True, lyapunov=False, adaptive=False, tol=EQUAL_WORK_TOL)  # (EQUAL_WORK)
    log(f"Dask against threads, {points} points: {ncores} one-thread workers, {runs} interleaved runs")
    with LocalCluster(n_workers=ncores, threads_per_worker=1, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            sweep(model, "eta", values[: min(points, 200)], settings=settings, client=client)
            sweep(model, "eta", values[: min(points, 200)], settings=settings)
            threads, dask = [], []
            for _ in range(runs):
                start = time.perf_counter()
                a = sweep(model, "eta", values, settings=settings)
                threads.append(time.perf_counter() - start)
                start = time.perf_counter()
                b = sweep(model, "eta", values, settings=settings, client=client)
                dask.append(time.perf_counter() - start)
    same = bool(np.array_equal(np.asarray(a["period"]), np.asarray(b["period"])))
    return {
        "points": points,
        "workers": ncores,
        "threads_s": {"median": statistics.median(threads), "min": min(threads), "max": max(threads)},
        "dask_s": {"median": statistics.median(dask), "min": min(dask), "max": max(dask)},
        "ratio": statistics.median(dask) / statistics.median(threads),
        "same_periods": same,
    }


def report(results: list[dict[str, Any]], dask: dict[str, Any] | None = None) -> None:
    if dask is not None:
        t, d = dask["threads_s"], dask["dask_s"]
        print(
            f"\nDask against threads, equal-work sweep of {dask['points']} points, {dask['workers']} cores: "
            f"threads {t['median']:.2f} s ({t['min']:.2f}–{t['max']:.2f}), local Dask cluster "
            f"{d['median']:.2f} s ({d['min']:.2f}–{d['max']:.2f}): {dask['ratio']:.2f}× as long; "
            f"periods {'the same' if dask['same_periods'] else 'DIFFER'}"
        )
    for r in results:
        m = r["phases_median"]
        print(
            f"\n{r['sweep']}, {r['points']} points, {r['cores_here']} cores here "
            f"(whole process: 1 thread {r['whole_1_thread']['median']:.2f} s, "
            f"{r['cores_here']} threads {r['whole_all_threads']['median']:.2f} s, "
            f"{r['cores_busy_here']:.2f} cores busy)"
        )
        print(
            f"  phases (median of {len(r['phases_runs'])}): start-up {m['startup']:.3f} s, before the driver "
            f"{m['before_driver']:.3f} s, driver {m['driver_span']:.3f} s on {m['threads']:.0f} threads "
            f"({m['rounds']:.0f} rounds, idle {m['idle_in_span']:.3f} s per thread), after it "
            f"{m['after_driver']:.3f} s (JSON text {m['json']:.3f} s); the main thread's CPU while the "
            f"threads compute {m['consumer_cpu']:.3f} s (each chunk's results, storing, JSON: work shared "
            "with the threads' cores, not serial)"
        )
        for how in HOWS:
            a = r[how]
            share = a["serial"] / (a["serial"] + a["parallel"])
            print(
                f"  {how}: serial {a['serial']:.3f} s, parallel {a['parallel']:.2f} CPU-s "
                f"(serial fraction {100 * share:.2f} %)"
            )
            print("    cores:      " + "".join(f"{p['cores']:>8d}" for p in a["projection"]))
            print("    busy:       " + "".join(f"{p['busy']:>8.1f}" for p in a["projection"]))
            print("    efficiency: " + "".join(f"{100 * p['efficiency']:>7.0f}%" for p in a["projection"]))


def markdown(results: list[dict[str, Any]], dask: dict[str, Any] | None = None) -> str:
    rows = [
        "| sweep | serial (s) | parallel (CPU-s) | " + " | ".join(f"{c} cores" for c in CORES) + " |",
        "|---|---:|---:|" + "---:|" * len(CORES),
    ]
    for r in results:
        for how in HOWS:
            a = r[how]
            eff = " | ".join(f"{100 * p['efficiency']:.0f} %" for p in a["projection"])
            rows.append(
                f"| {r['sweep']}, {r['points']} points ({how}) "
                f"| {a['serial']:.2f} | {a['parallel']:.1f} | {eff} |"
            )
    if dask is not None:
        t, d = dask["threads_s"], dask["dask_s"]
        rows += [
            "",
            f"Equal-work sweep of {dask['points']} points on {dask['workers']} cores, in one process: "
            f"threads {t['median']:.2f} s ({t['min']:.2f}–{t['max']:.2f}), a local Dask cluster of "
            f"{dask['workers']} one-thread workers {d['median']:.2f} s ({d['min']:.2f}–{d['max']:.2f}), "
            f"{dask['ratio']:.2f}× as long (issue 29: within 1.15×); periods "
            f"{'the same' if dask['same_periods'] else 'differ'}.",
        ]
    return "\n".join(rows)


@contextlib.contextmanager
def bytecode_cache(enabled: bool) -> Iterator[str]:
    """The measured processes import compiled bytecode (see the module); yields what they do."""
    if not (enabled and sys.flags.dont_write_bytecode):
        written = "" if not sys.flags.dont_write_bytecode else " (from source: no bytecode written)"
        yield f"as the environment has it{written}"
        return
    saved = {k: os.environ.get(k) for k in ("PYTHONDONTWRITEBYTECODE", "PYTHONPYCACHEPREFIX")}
    with tempfile.TemporaryDirectory(prefix="bench-scaling-pyc-") as cache:
        os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
        os.environ["PYTHONPYCACHEPREFIX"] = cache
        try:
            yield "compiled bytecode, kept in a temporary directory (PYTHONDONTWRITEBYTECODE was set)"
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v


def main() -> None:
    parser = bench_parser(__doc__)
    parser.add_argument(
        "--points",
        type=int,
        nargs="+",
        default=[4000],
        help="points of the sweep, one or more (default 4000)",
    )
    parser.add_argument(
        "--default-points", type=int, default=None, help="points of the default sweep (default: the first)"
    )
    parser.add_argument("--runs", type=int, default=3, help="runs of each measurement (default 3)")
    parser.add_argument("--default", action="store_true", help="also the default sweep (one chain)")
    parser.add_argument("--dask", action="store_true", help="also a local Dask cluster against threads")
    parser.add_argument(
        "--no-bytecode-cache",
        action="store_true",
        help="import grazing as the environment says (with PYTHONDONTWRITEBYTECODE: from source)",
    )
    args = parser.parse_args()
    with bytecode_cache(not args.no_bytecode_cache) as imports:
        log(f"the processes import grazing: {imports}")
        measured(args, imports)


def measured(args: argparse.Namespace, imports: str) -> None:
    """Everything :func:`main` measures and prints."""
    load_start = loadavg()
    subprocess.run(
        [sys.executable, "-m", "grazing", *sweep_args(8, 1, False)], stdout=subprocess.DEVNULL, check=True
    )
    results = [measure(points, args.runs, default=False) for points in args.points]
    if args.default:
        results.append(measure(args.default_points or args.points[0], args.runs, default=True))
    dask = dask_against_threads(args.points[0], args.runs) if args.dask else None
    machine = machine_info()
    machine["load_average"] = [load_start, loadavg()]
    machine["imports"] = imports
    emit(
        args,
        lambda: report(results, dask),
        lambda: markdown(results, dask),
        lambda: {"machine": machine, "results": results, "dask": dask},
    )
    print(f"\nload average {load_start} (start), {loadavg()} (end); the processes imported {imports}")


if __name__ == "__main__":
    main()
