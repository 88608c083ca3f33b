"""How ``heyoka_batch_sweep.py`` was tuned: its variants side by side, in one process, on one core.

Each variant integrates the same equal-work sweep (case B, θ̂ = 40°, η in [0.44, 0.49], from
rest, 500 + 100 periods, tol 1e-10) with one ``taylor_adaptive_batch``; they differ in one
choice each from the peer as it is:

* ``grid-601``: the peer of issue 15 -- the transient inside one ``propagate_grid`` over all
  601 sample times, ``reset_cooldowns()`` before each batch, a callback that reads
  ``ta.state`` and ``ta.pars`` through the integrator;
* ``until+grid``: the transient by ``propagate_until``, the grid over the 101 sample times,
  the same callback;
* ``peer``: as ``until+grid`` with the callback on a view of the state (the peer as it is);
* ``peer+reset_cooldowns``: the peer with ``reset_cooldowns()`` before each batch;
* ``peer+slp``: the peer compiled with LLVM's SLP vectoriser (``slp_vectorize=True``);
* ``peer, L lanes``: the peer with 4 and 16 lanes (8 is this machine's recommended width on
  AVX-512; the rows say which).

Integrators are compiled before the timing; every variant runs ``--repeats`` times,
interleaved; the table gives medians and min-max.  Also checked: every variant finds the
same period at every point as the peer.

    python benchmarks/heyoka_peer_tuning.py --num 1000 --repeats 5
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from typing import Any

import heyoka as hy
import numpy as np

import heyoka_batch_sweep as peer
from _common import Meter, Spread, log, machine_info, versions_line

TRANSIENT, PERIODS, TOL = 500, 100, 1e-10


def plain_integrator(lanes: int, **options: Any) -> Any:
    """The peer's system with the callback of issue 15 (through the integrator's attributes)."""
    th, dth = hy.make_vars("th", "dth")
    alpha, beta, eta, _, theta_hat = (hy.par[i] for i in range(len(peer.PARS)))
    sys_ = [
        (th, dth),
        (dth, alpha * hy.cos(th) * hy.sin(hy.time) - 2.0 * beta / eta * dth - hy.sin(th) / (4 * eta**2)),
    ]

    def reset(ta: Any, d_sgn: Any, lane: int) -> bool:
        ta.state[1, lane] = -ta.pars[3, lane] * ta.state[1, lane]
        return True

    event = hy.t_event_batch(th - theta_hat, callback=reset, direction=hy.event_direction.positive)
    return hy.taylor_adaptive_batch(
        sys_,
        np.zeros((2, lanes)),
        pars=np.zeros((len(peer.PARS), lanes)),
        tol=TOL,
        t_events=[event],
        **options,
    )


def view_integrator(lanes: int, **options: Any) -> Any:
    """The peer's integrator (callback on a view of the state), with compilation ``options``."""
    if not options:
        return peer.make_integrator(lanes, TOL)
    th, dth = hy.make_vars("th", "dth")
    alpha, beta, eta, _, theta_hat = (hy.par[i] for i in range(len(peer.PARS)))
    sys_ = [
        (th, dth),
        (dth, alpha * hy.cos(th) * hy.sin(hy.time) - 2.0 * beta / eta * dth - hy.sin(th) / (4 * eta**2)),
    ]
    reset = peer.LaneReset()
    event = hy.t_event_batch(th - theta_hat, callback=reset, direction=hy.event_direction.positive)
    ta = hy.taylor_adaptive_batch(
        sys_,
        np.zeros((2, lanes)),
        pars=np.zeros((len(peer.PARS), lanes)),
        tol=TOL,
        t_events=[event],
        **options,
    )
    reset.state, reset.r = ta.state, ta.pars[peer.PARS.index("r")]
    return ta


def sweep(ta: Any, lanes: int, etas: np.ndarray, *, whole_grid: bool, reset_cooldowns: bool) -> list[int]:
    """The periods at ``etas`` with integrator ``ta`` (the peer's loop, or issue 15's with ``whole_grid``)."""
    first = 0 if whole_grid else TRANSIENT
    grid = np.repeat((2.0 * math.pi * np.arange(first, TRANSIENT + PERIODS + 1))[:, None], lanes, axis=1)
    fixed = {"alpha": peer.CASE_B["alpha"], "beta": peer.CASE_B["beta"], "r": peer.CASE_B["r"],
             "theta_hat": peer.THETA_HAT}  # fmt: skip
    out = []
    for start in range(0, len(etas), lanes):
        batch = etas[start : start + lanes]
        ta.set_time(0.0)
        ta.state[:] = 0.0
        for name, value in fixed.items():
            ta.pars[peer.PARS.index(name), :] = value
        ta.pars[peer.PARS.index("eta"), :] = np.concatenate([batch, np.full(lanes - len(batch), batch[-1])])
        if reset_cooldowns:
            ta.reset_cooldowns()
        if not whole_grid:
            ta.propagate_until(2.0 * math.pi * TRANSIENT)
        states = ta.propagate_grid(grid)[-1][-PERIODS:]
        peer.check_outcomes(ta, len(batch))
        out += [peer.detect_period(states[:, :, lane]) for lane in range(len(batch))]
    return out


def variants(etas: np.ndarray) -> dict[str, Callable[[], list[int]]]:
    width = hy.recommended_simd_size()
    made: dict[str, Callable[[], list[int]]] = {}

    def add(name: str, ta: Any, lanes: int, whole_grid: bool = False, reset_cooldowns: bool = False) -> None:
        made[name] = lambda: sweep(ta, lanes, etas, whole_grid=whole_grid, reset_cooldowns=reset_cooldowns)

    add("grid-601", plain_integrator(width), width, whole_grid=True, reset_cooldowns=True)
    add("until+grid", plain_integrator(width), width)
    add(f"peer ({width} lanes)", view_integrator(width), width)
    add("peer+reset_cooldowns", view_integrator(width), width, reset_cooldowns=True)
    add("peer+slp", view_integrator(width, slp_vectorize=True), width)
    for lanes in (4, 8, 16):
        if lanes != width:
            add(f"peer, {lanes} lanes", view_integrator(lanes), lanes)
    return made


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--num", type=int, default=1000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    etas = np.linspace(0.44, 0.49, args.num)
    runs = variants(etas)
    outputs = {name: run() for name, run in runs.items()}  # warm-up, and the periods
    reference = outputs[f"peer ({hy.recommended_simd_size()} lanes)"]
    seconds: dict[str, list[float]] = {name: [] for name in runs}
    for r in range(args.repeats):
        log(f"round {r + 1} of {args.repeats}")
        for name, run in runs.items():
            with Meter() as m:
                run()
            seconds[name].append(m.seconds)
    print(f"Machine: {versions_line(machine_info())}")
    print(f"{args.num} points, one process, median (min-max) of {args.repeats} interleaved runs:")
    base = Spread.of(seconds[f"peer ({hy.recommended_simd_size()} lanes)"]).median
    for name in runs:
        s = Spread.of(seconds[name])
        agree = sum(a == b for a, b in zip(outputs[name], reference))
        print(f"  {name:22} {s.median:.3f} s ({s.min:.3f}-{s.max:.3f})  x peer {s.median / base:.2f}  "
              f"periods = peer's at {agree}/{args.num}")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
