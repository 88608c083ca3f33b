"""GPU against the CPU lanes on one machine: the equal-work map and a basin's initial states (issue 46).

The work:

* **map**: the impacting pendulum, case B, a grid of eta x theta_hat (``np.linspace(0.44, 0.49)``
  x 30-45 degrees), every point from rest, 500 transient + 100 sampled forcing periods, tol 1e-10,
  no adaptive transient, no Lyapunov exponents (the equal work of ``bench_equal_work.py``, on a
  grid of ``--points`` points, 10^6 by default: 1000 x 1000);
* **basin**: the pendulum at eta = 0.446, theta_hat = 40 degrees, a grid of initial states over
  [-1.5, theta_hat] x [-2, 2] at phase 0 (``--basin-points``, 1000 x 1000 by default), each run
  as ``grazing.attractors.basins`` runs its first look: 300 + 50 periods, adaptive transients (to
  1e-7), no Lyapunov exponents (the classification after it is the same code on either device
  and is not timed).

The GPU runs every point (``grazing.gpu``: one CUDA thread per point; ``--repeats`` timed runs
after one warm-up that compiles the kernel).  The CPU lanes (every core, a thread each) run a
subset of the same points (``--cpu-points``, whole rows of the grid: the full grid would take
minutes per run on the cores), and their time for the whole grid is their rate times its size.
The periods, impacts and statuses of the two are compared on the subset, point by point; the
samples' largest difference on the points where both found a period.

Reported, as medians with their min-max spread and every run: seconds and points per second for
each device, the CPU's extrapolated seconds for the full grid, the speed-up, the device and the
machine.  Run on a machine with an NVIDIA GPU and numba-cuda (the ``gpu`` extra)::

    python benchmarks/bench_gpu.py --json gpu.json
    NUMBA_ENABLE_CUDASIM=1 python benchmarks/bench_gpu.py --points 4 --basin-points 4 \
        --cpu-points 2 --transient 20 --periods 8 --repeats 1 --json smoke.json   # smoke test, no GPU
"""

from __future__ import annotations

import math
import os
import time
from typing import Any

import numpy as np

import grazing
from _common import EQUAL_WORK_TOL, Spread, bench_parser, emit, log, machine_info
from grazing.attractors.basins import basin_spec, outside
from grazing.attractors.grid import start_time, state_grid
from grazing.core.options import BasinSettings
from grazing.gpu.batch import gpu_results
from grazing.gpu.target import device_name, require_target
from grazing.sweeps.run import run_chunks
from grazing.sweeps.spec import SweepSpec, map_spec


def side(points: int) -> int:
    """Points along each side of a square grid of about ``points`` points."""
    return max(1, round(math.sqrt(points)))


def map_work(n: int, rows: int | None, transient: int, periods: int) -> SweepSpec:
    """The equal-work map on an ``n`` x ``n`` grid (its first ``rows`` rows of theta_hat only, evenly
    spread, when given)."""
    thetas = np.radians(np.linspace(30.0, 45.0, n))
    if rows is not None:
        thetas = thetas[np.linspace(0, n - 1, max(1, min(rows, n))).round().astype(int)]
    settings = grazing.SweepSettings(
        transient=transient, periods=periods, fresh=True, adaptive=False, lyapunov=False, tol=EQUAL_WORK_TOL,
        chunk_size=0,
    )  # fmt: skip
    model = grazing.models.pendulum("B")
    return map_spec(model, "eta", np.linspace(0.44, 0.49, n), "theta_hat", thetas, settings=settings)


def basin_work(n: int, rows: int, transient: int, periods: int) -> tuple[SweepSpec, SweepSpec, np.ndarray]:
    """The first look of the pendulum's basin on an ``n`` x ``n`` grid of initial states, as ``basins`` makes
    it (the states beyond the stop left out); the same for ``rows`` of its rows, evenly spread, and their
    points' positions in the whole grid's."""
    theta_hat = math.radians(40)
    model = grazing.models.pendulum("B", eta=0.446, theta_hat=theta_hat)
    states = state_grid(model, (-1.5, theta_hat), (-2.0, 2.0), (n, n)).states_array()
    valid = ~outside(model, states, start_time(model, 0.0))
    picked = subset_rows(n, rows)
    picked = picked[valid[picked]]
    settings = BasinSettings(transient=transient, periods=periods, lyapunov=False)
    full = basin_spec(model, states[valid], settings, False)
    part = basin_spec(model, states[picked], settings, False)
    return full, part, np.cumsum(valid)[picked] - 1


def results_of(results: Any) -> dict[str, np.ndarray]:
    """Periods, impacts, statuses and samples of a run's chunk results, in the order of the chunks."""
    chunks = sorted(results, key=lambda r: r.index)
    return {name: np.concatenate([getattr(r, name) for r in chunks]) for name in
            ("period", "impacts", "status", "samples")}  # fmt: skip


def timed(run: Any, repeats: int) -> tuple[Spread, dict[str, np.ndarray]]:
    """``repeats`` timed runs of ``run()``; their seconds and the last run's results."""
    seconds = []
    out: dict[str, np.ndarray] = {}
    for _ in range(repeats):
        start = time.perf_counter()
        out = results_of(run())
        seconds.append(time.perf_counter() - start)
    return Spread.of(seconds), out


def agreement(gpu: dict[str, np.ndarray], cpu: dict[str, np.ndarray], rows: np.ndarray) -> dict[str, Any]:
    """How the GPU's points ``rows`` compare with the CPU's (the same points, in order)."""
    g = {k: v[rows] for k, v in gpu.items()}
    both = (g["period"] > 0) & (cpu["period"] > 0)
    diff = np.abs(g["samples"][both] - cpu["samples"][both])
    return {
        "points": int(rows.size),
        "periods_equal": int((g["period"] == cpu["period"]).sum()),
        "impacts_equal": int((g["impacts"] == cpu["impacts"]).sum()),
        "statuses_equal": int((g["status"] == cpu["status"]).sum()),
        "max_sample_difference_periodic": float(diff.max()) if diff.size else 0.0,
        "failed_gpu": int((g["status"] != 0).sum()),
    }


def compare(name: str, full: SweepSpec, part: SweepSpec, part_rows: np.ndarray, args: Any) -> dict[str, Any]:
    """Time ``full`` on the GPU and ``part`` (its points ``part_rows``) on the CPU lanes."""
    from grazing.sweeps.executor import chunk_results

    log(f"{name}: GPU, {full.n_points} points (warm-up, then {args.repeats} runs)")
    timed(lambda: gpu_results(part, range(min(1, part.n_chunks))), 1)  # (compiles the kernel)
    gpu_s, gpu = timed(lambda: gpu_results(full, range(full.n_chunks)), args.repeats)
    workers = args.workers or os.cpu_count() or 1
    log(f"{name}: CPU lanes, {part.n_points} points on {workers} threads")
    run_chunks(part, [0])  # (warm-up: the driver and the model's kernels loaded)
    cpu_s, cpu = timed(
        lambda: chunk_results(part, range(part.n_chunks), workers, None, None, None), args.repeats
    )
    cpu_full = cpu_s.scaled(full.n_points / part.n_points)
    return {
        "points": full.n_points,
        "transient": full.transient,
        "periods": full.periods,
        "gpu_s": gpu_s.as_dict(),
        "gpu_points_per_s": full.n_points / gpu_s.median,
        "cpu_points": part.n_points,
        "cpu_threads": workers,
        "cpu_s": cpu_s.as_dict(),
        "cpu_points_per_s": part.n_points / cpu_s.median,
        "cpu_s_full_extrapolated": cpu_full.as_dict(),
        "speedup": cpu_full.median / gpu_s.median,
        "agreement": agreement(gpu, cpu, part_rows),
    }


def subset_rows(n: int, rows: int) -> np.ndarray:
    """The indices in the full ``n`` x ``n`` grid of the points of its ``rows`` evenly spread rows."""
    picked = np.linspace(0, n - 1, max(1, min(rows, n))).round().astype(int)
    return (picked[:, None] * n + np.arange(n)[None, :]).ravel()


def main() -> None:
    parser = bench_parser(__doc__)
    parser.add_argument("--points", type=int, default=10**6, help="points of the map (default 10^6)")
    parser.add_argument("--basin-points", type=int, default=10**6, help="initial states (default 10^6)")
    parser.add_argument("--cpu-points", type=int, default=20_000, help="points the CPU lanes run (rows)")
    parser.add_argument("--transient", type=int, default=500, help="map transient periods (default 500)")
    parser.add_argument("--periods", type=int, default=100, help="map sampled periods (default 100)")
    parser.add_argument("--repeats", type=int, default=3, help="timed runs of each (default 3)")
    parser.add_argument("--workers", type=int, default=None, help="CPU threads (default: all cores)")
    parser.add_argument("--skip-basin", action="store_true", help="time the map only")
    args = parser.parse_args()
    require_target()
    info = machine_info()
    info["device"] = device_name()
    found: dict[str, Any] = {"device": info["device"], "machine": info, "date": time.strftime("%Y-%m-%d")}
    n = side(args.points)
    rows = max(1, args.cpu_points // n)
    full, part = (map_work(n, r, args.transient, args.periods) for r in (None, rows))
    found["map"] = compare("map", full, part, subset_rows(n, rows), args)
    if not args.skip_basin:
        nb = side(args.basin_points)
        rows_b = max(1, args.cpu_points // nb)
        t, p = (300, 50) if args.transient == 500 else (args.transient, args.periods)  # (smoke: scaled)
        found["basin"] = compare("basin", *basin_work(nb, rows_b, t, p), args)

    def table() -> None:
        print(f"GPU against the CPU lanes on {found['device']}; CPU {info['cpu']} ({info['cores']} cores)")
        for name in ("map", "basin"):
            if name not in found:
                continue
            r = found[name]
            g, c, a = r["gpu_s"], r["cpu_s_full_extrapolated"], r["agreement"]
            print(
                f"  {name}: {r['points']} points, {r['transient']} + {r['periods']} periods: GPU "
                f"{g['median']:.2f} s ({g['min']:.2f}-{g['max']:.2f}), CPU lanes {c['median']:.1f} s "
                f"(from {r['cpu_points']} points), x{r['speedup']:.1f}; periods equal at "
                f"{a['periods_equal']}/{a['points']}, statuses {a['statuses_equal']}/{a['points']}"
            )

    def markdown() -> str:
        lines = [
            "| work | points | GPU s (median, min-max) | CPU lanes s (extrapolated) | speed-up "
            "| periods equal |",
            "|---|---:|---:|---:|---:|---:|",
        ]
        for name in ("map", "basin"):
            if name in found:
                r = found[name]
                g, c, a = r["gpu_s"], r["cpu_s_full_extrapolated"], r["agreement"]
                lines.append(
                    f"| {name} | {r['points']} | {g['median']:.2f} ({g['min']:.2f}-{g['max']:.2f}) | "
                    f"{c['median']:.1f} | {r['speedup']:.1f} | {a['periods_equal']}/{a['points']} |"
                )
        return "\n".join(lines)

    emit(args, table, markdown, lambda: found)


if __name__ == "__main__":
    main()
