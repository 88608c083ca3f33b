"""Equal work against the strongest heyoka.py peer we know: whole processes and in-process.

The work (issues 15 and 29): the impacting pendulum, case B, θ̂ = 40°, η =
``np.linspace(0.44, 0.49, N)``, every point from rest, 500 transient + 100 sampled forcing
periods, tolerance 1e-10, no Lyapunov exponents, the period of each point by grazing's rule.

* grazing: ``grazing sweep --param eta ... --fresh --no-lyapunov --no-adaptive --tol 1e-10
  --workers P --json`` (a thread per core), and in-process ``grazing.sweeps.sweep(...,
  fresh=True, lyapunov=False, adaptive=False, tol=1e-10, workers=P)``;
* heyoka.py: ``heyoka_batch_sweep.py`` (batch mode, one SIMD lane per η value; how it is
  written and tuned is in its docstring) with 4, 8 and 16 lanes, P processes; in-process,
  the same functions in a pool of P worker processes started, and their integrators
  compiled, before the timing.

Whole processes include the interpreter, the imports and loading grazing's kernels or
compiling heyoka's (heyoka compiles its integrator in every process).  In-process times
exclude them.  Every configuration runs ``--repeats`` times, interleaved (A B C ... A B C
...), after one warm-up run each; the record keeps every run, their median and their
min-max spread.  Also on one core (P = 1) in-process.  The periods of every heyoka
configuration are compared with grazing's, point by point.

Run::

    python benchmarks/bench_equal_work.py --json equal_work.json       # 1000 points (about 2 minutes)
    python benchmarks/bench_equal_work.py --quick                      # 200 points
"""

from __future__ import annotations

import json
import math
import multiprocessing
import os
import subprocess
import sys
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

import grazing
import heyoka_batch_sweep as peer
from _common import (
    EQUAL_WORK,
    EQUAL_WORK_TOL,
    Meter,
    Spread,
    bench_parser,
    emit,
    grazing_exe,
    loadavg,
    log,
    machine_info,
    versions_line,
    wait_quiet,
)
from grazing.sweeps import sweep

ETA_START, ETA_STOP = 0.44, 0.49
N_POINTS, QUICK_POINTS = 1000, 200
TRANSIENT, PERIODS, TOL = 500, 100, EQUAL_WORK_TOL
LANES = (4, 8, 16)
REPEATS = 5
QUIET_WAIT = 10.0
PEER = Path(__file__).with_name("heyoka_batch_sweep.py")


def grazing_command(n: int, processes: int) -> list[str]:
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
        "40",
        *EQUAL_WORK,
        "--workers",
        str(processes),
        "--json",
    ]


def peer_command(n: int, processes: int, lanes: int) -> list[str]:
    return [
        sys.executable,
        str(PEER),
        "--start",
        str(ETA_START),
        "--stop",
        str(ETA_STOP),
        "--num",
        str(n),
        "--transient",
        str(TRANSIENT),
        "--periods",
        str(PERIODS),
        "--tol",
        str(TOL),
        "--processes",
        str(processes),
        "--lanes",
        str(lanes),
        "--json",
    ]


def interleaved(
    runners: dict[str, Callable[[], Any]], repeats: int, quiet: float
) -> dict[str, dict[str, Any]]:
    """Each runner once (warm-up, its output kept), then ``repeats`` rounds of all of them in turn."""
    out: dict[str, Any] = {}
    for key, run in runners.items():
        log(f"  warm-up: {key}")
        out[key] = run()
    seconds: dict[str, list[float]] = {k: [] for k in runners}
    others: dict[str, list[float]] = {k: [] for k in runners}
    for r in range(repeats):
        log(f"  round {r + 1} of {repeats}")
        for key, run in runners.items():
            wait_quiet(quiet)
            with Meter() as m:
                run()
            seconds[key].append(m.seconds)
            others[key].append(m.others)
    return {
        k: {
            "seconds": Spread.of(seconds[k]).as_dict(),
            "others": Spread.of(others[k]).as_dict(),
            "output": out[k],
        }
        for k in runners
    }


def agreement(ours: list[int], theirs: list[int]) -> dict[str, Any]:
    """Points where the periods agree, and the first few that do not."""
    differ = [(j, a, b) for j, (a, b) in enumerate(zip(ours, theirs)) if a != b]
    return {"agree": len(ours) - len(differ), "points": len(ours), "first_differences": differ[:10]}


def whole_process(n: int, processes: int, repeats: int, quiet: float) -> dict[str, Any]:
    """grazing's command and the peer at every lane count, as fresh processes, interleaved."""
    log(f"whole processes: {n} points, {processes} processes, {repeats} rounds")
    commands = {"grazing": grazing_command(n, processes)}
    commands |= {f"heyoka-{lanes}": peer_command(n, processes, lanes) for lanes in LANES}

    def runner(cmd: list[str]) -> Callable[[], list[int]]:
        return lambda: json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)[
            "period"
        ]

    res = interleaved({k: runner(c) for k, c in commands.items()}, repeats, quiet)
    return finish(res, {k: shown(c) for k, c in commands.items()})


def shown(cmd: list[str]) -> str:
    """A command as the record shows it: programs and scripts by their names."""
    return " ".join(Path(a).name if os.sep in a else a for a in cmd)


def finish(res: dict[str, dict[str, Any]], commands: dict[str, str] | None = None) -> dict[str, Any]:
    """The record of one comparison: per configuration its times and period agreement; heyoka's best."""
    ours = res["grazing"]["output"]
    configs = {}
    for key, r in res.items():
        configs[key] = {"seconds": r["seconds"], "others": r["others"]}
        if commands:
            configs[key]["command"] = commands[key]
        if key != "grazing":
            configs[key]["periods"] = agreement(ours, r["output"])
    best = min((k for k in configs if k != "grazing"), key=lambda k: configs[k]["seconds"]["median"])
    return {
        "configs": configs,
        "heyoka_best": best,
        "speedup_median": configs[best]["seconds"]["median"] / configs["grazing"]["seconds"]["median"],
        "grazing_periods": ours,
    }


def in_process(n: int, processes: int, repeats: int, quiet: float) -> dict[str, Any]:
    """grazing's ``sweep`` and the peer's functions, kernels loaded and integrators compiled beforehand."""
    log(f"in-process: {n} points, {processes} worker(s), {repeats} rounds")
    etas = np.linspace(ETA_START, ETA_STOP, n)
    model = grazing.models.pendulum("B", theta_hat=math.radians(40.0))
    options = {
        "x0": [0.0, 0.0],
        "transient": TRANSIENT,
        "periods": PERIODS,
        "fresh": True,
        "lyapunov": False,
        "adaptive": False,
        "tol": TOL,
        "workers": processes,
    }
    runners: dict[str, Callable[[], Any]] = {
        "grazing": lambda: sweep(model, "eta", etas, **options).period.values.tolist()
    }
    pool = None
    if processes > 1:  # fresh interpreters (not forks of this one, whose sweep threads may be running)
        context = multiprocessing.get_context("spawn")
        pool = ProcessPoolExecutor(processes, mp_context=context, initializer=compile_all, initargs=(TOL,))
    try:
        if pool is None:
            compile_all(TOL)
        else:  # start every worker (each compiles its integrators) before the timing
            list(pool.map(peer.detect_period, [np.zeros((4, 2))] * processes * 2))
        for lanes in LANES:
            runners[f"heyoka-{lanes}"] = lambda lanes=lanes: peer.sweep(
                etas, TRANSIENT, PERIODS, TOL, lanes, pool, processes
            )
        return finish(interleaved(runners, repeats, quiet))
    finally:
        if pool is not None:
            pool.shutdown()


def compile_all(tol: float) -> None:
    """Compile this process's batch integrators for every lane count (a pool's initializer)."""
    for lanes in LANES:
        peer.integrator(lanes, tol)


def run(n: int, repeats: int, quiet: float) -> dict[str, Any]:
    processes = os.cpu_count() or 1
    return {
        "settings": {
            "points": n,
            "eta": [ETA_START, ETA_STOP],
            "transient": TRANSIENT,
            "periods": PERIODS,
            "tol": TOL,
            "lanes_tried": list(LANES),
            "processes": processes,
            "repeats": repeats,
            "quiet_wait_s": quiet,
        },
        "whole_process": whole_process(n, processes, repeats, quiet),
        "in_process": in_process(n, processes, repeats, quiet),
        "in_process_one_core": in_process(n, 1, repeats, quiet),
    }


def summary_lines(data: dict[str, Any]) -> list[str]:
    lines = []
    for part in ("whole_process", "in_process", "in_process_one_core"):
        d = data[part]
        best, speedup = d["heyoka_best"], d["speedup_median"]
        lines.append(f"{part}: heyoka's best {best}, grazing {speedup:.2f}x as fast (medians)")
        for key, c in d["configs"].items():
            s = c["seconds"]
            agree = c.get("periods")
            note = f"; periods agree at {agree['agree']}/{agree['points']}" if agree else ""
            lines.append(f"  {key:10} {s['median']:.3f} s ({s['min']:.3f}-{s['max']:.3f}){note}")
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = bench_parser(__doc__, quiet_wait=QUIET_WAIT)
    parser.add_argument("--quick", action="store_true", help=f"{QUICK_POINTS} points instead of {N_POINTS}")
    parser.add_argument("--repeats", type=int, default=REPEATS, help="timed rounds (after a warm-up)")
    args = parser.parse_args(argv)
    machine = machine_info()
    data = run(QUICK_POINTS if args.quick else N_POINTS, args.repeats, args.quiet_wait)
    machine["loadavg_end"] = loadavg()
    data["machine"] = machine
    emit(
        args,
        lambda: print("\n".join([f"Machine: {versions_line(machine)}", *summary_lines(data)])),
        lambda: "\n".join(summary_lines(data)),
        lambda: data,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
