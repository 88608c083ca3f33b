"""Benchmark a bifurcation curve of the impacting pendulum (``grazing.orbits.follow_curve``, issue 27).

Problem: case B of Piiroinen, Virgin & Champneys (2004) (alpha = 0.2254, beta = 0.048,
r = 0.7675), the stable period-5 orbit with one impact (eta = 0.446, theta_hat = 40 deg).  It is
continued in eta from 0.446 towards 0.44 up to its period-doubling (eta = 0.44539259), which is
followed in (eta, theta_hat) for theta_hat in [30, 55] deg, with the Floquet multipliers at every
point.  Towards low theta_hat the curve ends where it meets the grazing curve (the orbit's impact
speed falls to zero, near theta_hat = 35.905 deg): a codimension-two point, located from the
grazing equations.  The largest step ``ds_max = 0.01`` gives about 100 points.  Target (issue 27):
a 100-point curve in a few seconds.

Measured: the in-process time of ``follow_curve`` (first call, kernel load included; the median of a
few further calls), split into the one-parameter continuation to the start and the curve itself,
and the whole-process time of ``grazing curve ... --json``.  Before each timed run the script waits
(up to ``--quiet-wait`` seconds) for other processes to go quiet, and it reports the cores they
kept busy meanwhile (the machine may be shared).

Run::

    python benchmarks/bench_curves.py
    python benchmarks/bench_curves.py --markdown --json curves.json
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import time
from typing import Any

import grazing
from _common import (
    Meter,
    Spread,
    bench_parser,
    emit,
    grazing_exe,
    log,
    machine_info,
    metered_command,
    versions_line,
    wait_quiet,
)
from grazing.orbits import BifurcationCurve, PalcSettings, follow_curve

CASE = "B"
START, STOP = 0.446, 0.44  # eta: the period-doubling lies between
THETA_HAT_DEG = 40.0
RANGE_DEG = (30.0, 55.0)
DS_MAX = 0.01
REPEATS = 3
PROCESS_REPEATS = 3
TARGET_SECONDS = 5.0  # "a few seconds"
QUIET_WAIT = 20.0
PACKAGES = ("numpy", "scipy", "numba", "grazing")


def run_curve(stages: dict[str, float] | None = None) -> BifurcationCurve:
    """The curve; ``stages`` receives the time at which the curve stage began."""
    model = grazing.models.pendulum(CASE, eta=START, theta_hat=math.radians(THETA_HAT_DEG))

    def progress(stage: str, points: int, v1: float, v2: float) -> None:
        if stages is not None and stage == "curve" and "curve" not in stages:
            stages["curve"] = time.perf_counter()

    return follow_curve(
        model, "period-doubling", "eta", START, STOP, "theta_hat", tuple(map(math.radians, RANGE_DEG)),
        settings=PalcSettings(ds=DS_MAX, ds_max=DS_MAX), progress=progress,
    )  # fmt: skip


def cli_command() -> list[str]:
    return [
        grazing_exe(),
        *f"curve --case {CASE} --theta-hat {THETA_HAT_DEG:g} --kind period-doubling --param eta "
        f"--start {START} --stop {STOP} --param2 theta-hat --range {RANGE_DEG[0]:g},{RANGE_DEG[1]:g} "
        f"--max-step {DS_MAX} --json".split(),
    ]


def measure(res: dict[str, Any], quiet: float) -> BifurcationCurve:
    log("follow_curve: first call ...")
    wait_quiet(quiet)
    with Meter() as m:
        curve = run_curve()
    res["first_call_s"], res["first_call_others"] = m.seconds, m.others
    runs = []
    log(f"follow_curve: median of {REPEATS} ...")
    for _ in range(REPEATS):
        wait_quiet(quiet)
        stages: dict[str, float] = {}
        with Meter() as m:
            start = time.perf_counter()
            again = run_curve(stages)
        assert len(again) == len(curve)
        runs.append((m.seconds, m.others, stages["curve"] - start))
    spread = Spread.of([r[0] for r in runs])
    middle = sorted(runs)[len(runs) // 2]  # the run of the median time (REPEATS is odd)
    res["median_s"], res["median_others"], res["branch_s"] = spread.median, middle[1], middle[2]
    res["min_max_s"] = [spread.min, spread.max]
    res["curve_s"] = middle[0] - res["branch_s"]
    cmd = cli_command()
    log(f"whole process: {' '.join(cmd[1:])}, median of {PROCESS_REPEATS} ...")
    proc, proc_others = metered_command(cmd, PROCESS_REPEATS, quiet, stdout=subprocess.DEVNULL)
    res["process_s"], res["process_others"] = proc.median, proc_others.median
    res["process_min_max_s"] = [proc.min, proc.max]
    cli = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    res["cli_points"] = len(cli["points"])
    return curve


def describe(curve: BifurcationCurve, res: dict[str, Any]) -> None:
    th = [math.degrees(v) for v in curve.values("theta_hat")]
    res.update(
        {
            "points": len(curve),
            "status": curve.status,
            "theta_hat_deg": [min(th), max(th)],
            "special": [
                {
                    "kind": s.kind,
                    "eta": s.values[0],
                    "theta_hat_deg": math.degrees(s.values[1]),
                    "located": s.located,
                }
                for s in curve.special
            ],
            "max_condition": max(abs(p.condition) for p in curve.points),
            "max_distance_from_minus_one": max(float(min(abs(p.multipliers + 1))) for p in curve.points),
        }
    )
    res["ms_per_point"] = 1000 * res["curve_s"] / res["points"]


def target_line(res: dict[str, Any]) -> str:
    worst = max(res["median_s"], res["process_s"])
    verdict = "met" if worst < TARGET_SECONDS else f"MISSED (by a factor {worst / TARGET_SECONDS:.2f})"
    return (
        f"a {res['points']}-point curve in {res['median_s']:.2f} s in-process (first call "
        f"{res['first_call_s']:.2f} s), {res['process_s']:.2f} s whole process; under {TARGET_SECONDS:g} s: "
        f"{verdict}"
    )


def print_report(res: dict[str, Any]) -> None:
    print(f"Machine: {versions_line(res['machine'], PACKAGES)}")
    print(
        f"Problem: pendulum case {CASE}, period-5 orbit at theta_hat = {THETA_HAT_DEG:g} deg; its "
        f"period-doubling from eta = {START} towards {STOP}, followed in (eta, theta_hat) for theta_hat in "
        f"{list(RANGE_DEG)} deg, PalcSettings(ds={DS_MAX}, ds_max={DS_MAX})"
    )
    print(
        f"\n{res['points']} points, theta_hat from {res['theta_hat_deg'][0]:.5f} to "
        f"{res['theta_hat_deg'][1]:.5f} deg"
    )
    print(f"  status: {res['status']}")
    for s in res["special"]:
        print(
            f"  {s['kind']} at eta = {s['eta']:.9f}, theta_hat = {s['theta_hat_deg']:.6f} deg "
            f"(located: {s['located']})"
        )
    print(
        f"  defining condition at most {res['max_condition']:.1e}; a multiplier within "
        f"{res['max_distance_from_minus_one']:.1e} of -1 at every point"
    )
    print(
        f"\nTime: first call {res['first_call_s']:.3f} s (kernel load included); median of {REPEATS} further "
        f"calls {res['median_s']:.3f} s = {res['branch_s']:.3f} s continuation to the start + "
        f"{res['curve_s']:.3f} s curve ({res['ms_per_point']:.1f} ms per point); whole process "
        f"{res['process_s']:.3f} s (median of "
        f"{PROCESS_REPEATS}, {res['cli_points']} points); cores kept busy by other processes meanwhile: "
        f"{res['first_call_others']:.2f}, {res['median_others']:.2f}, {res['process_others']:.2f}"
    )
    print(f"Target (issue 27): {target_line(res)}")


def markdown(res: dict[str, Any]) -> str:
    rows = [
        "| quantity | value |",
        "|---|---:|",
        f"| points | {res['points']} |",
        f"| in-process, first call (kernel load included) | {res['first_call_s']:.2f} s |",
        f"| in-process, median of {REPEATS}: continuation to the start + curve | {res['median_s']:.2f} s "
        f"({res['branch_s']:.2f} + {res['curve_s']:.2f}) |",
        f"| per point of the curve | {res['ms_per_point']:.1f} ms |",
        f"| whole process, `grazing curve ... --json` | {res['process_s']:.2f} s |",
        *(
            f"| {s['kind']} (codimension two) | η = {s['eta']:.8f}, θ̂ = {s['theta_hat_deg']:.5f}° |"
            for s in res["special"]
        ),
    ]
    notes = [
        "",
        f"- Target (issue 27, not asserted): {target_line(res)}.",
        f"- Machine: {versions_line(res['machine'], PACKAGES)}; cores kept busy by other processes: "
        f"{res['first_call_others']:.2f}, {res['median_others']:.2f}, {res['process_others']:.2f}.",
    ]
    return "\n".join(rows + notes)


def main(argv: list[str] | None = None) -> int:
    parser = bench_parser(__doc__, quiet_wait=QUIET_WAIT)
    args = parser.parse_args(argv)
    res: dict[str, Any] = {"machine": machine_info(PACKAGES), "quiet_wait_s": args.quiet_wait}
    curve = measure(res, args.quiet_wait)
    describe(curve, res)
    emit(args, lambda: print_report(res), lambda: markdown(res), lambda: res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
