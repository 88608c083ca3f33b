"""Benchmark a basin of attraction of the pendulum (``grazing.attractors.basins``), issue 28's speed target.

Problem: the impacting pendulum of Piiroinen, Virgin & Champneys (2004), case B, theta_hat = 40
deg, eta = 0.446 (where the period-5 impacting orbit and the pendulum resting on the back of its
stop coexist); a grid of N x N initial states (theta, theta') over [-1.5, theta_hat] x [-2, 2] at
forcing phase 0; from each, 300 transient forcing periods (ended early once the samples repeat to
1e-7, in blocks of 32) and 50 sampled periods; aperiodic end states run on for another 300 + 50
(``refine = 1``) with Lyapunov exponents, each orbit's exponent from one of its points.  Both
cores (a thread each), SIMD lanes, tol 1e-10.

Reported: the wall time, the CPU time of the process (all its threads: what the computation cost
whatever else ran), the cores other processes kept busy meanwhile (from /proc/stat) and the load
average at the start and the end -- on a shared machine the wall time alone says little.  Also the
attractors found and their basin fractions.

Run::

    python benchmarks/bench_basins.py            # 500 x 500 (about a minute on 2 free cores)
    python benchmarks/bench_basins.py --n 100    # a quick look
    python benchmarks/bench_basins.py --json basins.json
"""

from __future__ import annotations

import math
import os
import time

import grazing
from _common import Meter, bench_parser, emit, loadavg, log, machine_info, versions_line, wait_quiet
from grazing.attractors import basins


def main() -> None:
    parser = bench_parser(__doc__, quiet_wait=30.0)
    parser.add_argument("--n", type=int, default=500, help="initial states along each side (default 500)")
    parser.add_argument("--workers", type=int, default=None, help="threads (default: all cores)")
    args = parser.parse_args()
    info = machine_info()
    model = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    log("warm-up (kernels loaded or compiled)")
    basins(model, (-1.5, math.radians(40)), (-2.0, 2.0), (8, 8), workers=args.workers)
    waited = wait_quiet(args.quiet_wait)
    cpu0 = time.process_time()
    with Meter() as m:
        ds = basins(model, (-1.5, math.radians(40)), (-2.0, 2.0), (args.n, args.n), workers=args.workers)
    cpu = time.process_time() - cpu0
    info["loadavg_end"] = loadavg()
    found = [
        (int(a), str(k), int(p), float(f))
        for a, k, p, f in zip(ds.attractor.values, ds.kind.values, ds.period.values, ds.fraction.values)
    ]
    result = {
        "grid": f"{args.n} x {args.n}",
        "initial_states": args.n * args.n,
        "wall_s": m.seconds,
        "cpu_s": cpu,
        "other_cores_busy": m.others,
        "waited_for_quiet_s": waited,
        "threads": args.workers or os.cpu_count(),
        "attractors": found,
        "machine": info,
    }

    def table() -> None:
        print(f"basin of the pendulum, {result['grid']} initial states, 300 + 50 periods each")
        print(
            f"  wall time {m.seconds:.1f} s, CPU time {cpu:.1f} s ({cpu / m.seconds:.2f} cores busy with it)"
        )
        print(f"  other processes kept {m.others:.2f} cores busy; {versions_line(info)}")
        for ident, kind, period, frac in found:
            print(f"  attractor {ident}: {kind}, period {period}, fraction {frac:.4f}")

    def markdown() -> str:
        return (
            "| grid | wall time | CPU time | other processes (cores busy) | load average start / end |\n"
            "|---|---:|---:|---:|---|\n"
            f"| {result['grid']} | {m.seconds:.1f} s | {cpu:.1f} s | {m.others:.2f} | "
            f"{info['loadavg_start']} / {info['loadavg_end']} |"
        )

    emit(args, table, markdown, lambda: result)


if __name__ == "__main__":
    main()
