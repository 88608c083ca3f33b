"""``grazing simulate``: simulate a model; stroboscopic samples, impacts, the period, a dense trajectory."""

from __future__ import annotations

import functools
import time
from pathlib import Path
from typing import Any

import click
import numpy as np

import grazing
from grazing.cli.common import (
    Progress,
    check_mode,
    check_out,
    emit_json,
    json_option,
    mode_option,
    model_options,
    model_params_json,
    overwrite_option,
    parse_state,
    stdout_console,
    write_table,
)
from grazing.cli.limits import check_memory, count_text, simulate_bytes
from grazing.cli.validate import FINITE, count, path_type, refuse_unused
from grazing.core.options import DEFAULT_TRANSIENT


@click.command()
@model_options(any_model=True, modes=True)
@click.option("--initial", default=None, metavar="X1,X2,...",
              help="Initial state at time 0, one per state (default: zero; pendulum: rad).")  # fmt: skip
@mode_option
@click.option("--transient", type=count(0), default=DEFAULT_TRANSIENT, show_default=True,
              help="Forcing periods run and discarded first.")  # fmt: skip
@click.option("--periods", type=count(1), default=100, show_default=True,
              help="Forcing periods sampled.")  # fmt: skip
@click.option("--phase", type=FINITE, default=0.0, show_default=True, metavar="PHI",
              help="Stroboscopic phase in radians: samples at tau = PHI mod 2 pi.")  # fmt: skip
@click.option("--trajectory", type=path_type(dir_okay=False), metavar="FILE.csv",
              help="Write the dense trajectory of the sampled span to a CSV file.")  # fmt: skip
@click.option("--points-per-period", type=count(4), default=100, show_default=True,
              help="Trajectory resolution (with --trajectory).")  # fmt: skip
@overwrite_option
@json_option
def simulate(
    model: grazing.HybridModel,
    case: str,
    initial: str,
    mode: str | None,
    transient: int,
    periods: int,
    phase: float,
    trajectory: Path | None,
    points_per_period: int,
    overwrite: bool,
    as_json: bool,
) -> None:
    """Simulate a model (the pendulum by default); print stroboscopic samples, impacts, period."""
    refuse_unused(["points_per_period"], trajectory is None, "without --trajectory")
    check_mode(model, mode)
    x0 = parse_state(initial, model, mode)
    check_out(trajectory, ".csv", "--trajectory", overwrite)
    points = periods * points_per_period + 1 if trajectory is not None else 0
    check_memory(
        simulate_bytes(periods, model.n_states, points, as_json),
        f"simulating {count_text(periods)} sampled periods"
        + (f" with a trajectory of {count_text(points)} points" if points else ""),
        "sample fewer periods (--periods; --transient runs without keeping anything)"
        + (" or fewer --points-per-period" if points else ""),
    )
    bar = Progress("simulating", enabled=not as_json, unit="periods")
    t0 = time.perf_counter()
    try:
        sol = grazing.simulate(
            model,
            x0,
            transient=transient,
            periods=periods,
            phase=phase,
            trajectory=points_per_period if trajectory is not None else 0,
            progress=bar,
            mode=mode,
        )
    finally:
        bar.close()
    elapsed = time.perf_counter() - t0
    if trajectory is not None:
        write_table(trajectory, functools.partial(_write_trajectory_csv, sol), overwrite)
    period = sol.period()
    result = {
        "params": model_params_json(model, case),
        "initial": x0,
        "transient": transient,
        "periods": periods,
        "phase": phase,
        "samples": sol.samples,
        "impacts": sol.n_impacts,
        "impacts_sampled": len(sol.impacts),
        "impact_map": np.column_stack([sol.impacts.t, sol.impacts.phase, sol.impacts.speed]),
        "impact_stops": [sol.impacts.stop_name(i) for i in range(len(sol.impacts))],
        "impacts_per_stop": sol.impacts.per_stop(),
        "sticking_intervals": sol.sticking,
        "period": period,
        "t_final": sol.t_final,
        "x_final": sol.x_final,
        "steps": sol.n_steps,
        "elapsed_s": elapsed,
        "trajectory_file": str(trajectory) if trajectory is not None else None,
        "version": grazing.__version__,
    }
    if model.has_modes:  # (the JSON of a model of one mode stays as it was)
        result.update(_modes_json(sol))
    if as_json:
        emit_json(result)
        return
    _print_simulation(model, sol, period, elapsed, trajectory)


def _modes_json(sol: grazing.Solution) -> dict[str, Any]:
    """The modes of a run of a model with modes: each sample's, the switches and the final mode."""
    sw = sol.switches
    assert sol.modes is not None and sw is not None
    return {
        "modes": [sol.mode_names[k] for k in sol.modes],
        "switches": [
            {
                "t": float(sw.t[i]),
                "transition": sw.name(i),
                "from": sw.source(i),
                "to": sw.target(i),
                "state": sw.state[i],
            }
            for i in range(len(sw))
        ],
        "mode_final": sol.mode_final,
        "sliding_intervals": [
            {"t_start": float(a), "t_end": float(b), "surface": sol.model.surface_names[int(k)]}
            for a, b, k in (sol.sliding if sol.sliding is not None else np.empty((0, 3)))
        ],
    }


def _switch_lines(sol: grazing.Solution) -> list[str]:
    """A run of a model with modes: its switches per transition, and its time sliding on each surface."""
    sw = sol.switches
    assert sw is not None
    per = {name: 0 for name in dict.fromkeys(sw.name(i) for i in range(len(sw)))}
    for i in range(len(sw)):
        per[sw.name(i)] += 1
    lines = ["switches per transition: " + ", ".join(f"{k} {v}" for k, v in per.items())] if per else []
    if sol.sliding is not None and len(sol.sliding):
        for k, surface in enumerate(sol.model.surface_names):
            rows = sol.sliding[sol.sliding[:, 2] == k]
            if len(rows):
                total = float(np.sum(rows[:, 1] - rows[:, 0]))
                lines.append(
                    f"sliding on {surface!r}: {len(rows)} intervals, {total:.6g} "
                    f"time units in all (the first from t = {rows[0, 0]:.6f} to {rows[0, 1]:.6f})"
                )
    return lines


def _write_trajectory_csv(sol: grazing.Solution, fh: Any) -> None:
    time = "tau" if sol.model.name == "pendulum" else "t"
    fh.write(",".join([time, *sol.model.state_names]) + "\n")
    assert sol.trajectory_t is not None and sol.trajectory is not None
    np.savetxt(fh, np.column_stack([sol.trajectory_t, sol.trajectory]), delimiter=",", fmt="%.17g")


def _print_simulation(
    model: grazing.HybridModel, sol: grazing.Solution, period: int, elapsed: float, trajectory: Path | None
) -> None:
    from rich.table import Table

    con = stdout_console(soft_wrap=True)  # (no line cut at the terminal's width; a table keeps its own)
    values = "  ".join(
        f"{p.name}={p.to_display(model.params[p.name]):g}{' deg' if p.angle else ''}"
        for p in model.parameters
    )
    con.print(f"[bold]{model.name}[/bold]  {values}")
    n = sol.samples.shape[0]
    kind = f"period {period}" if period else "no period <= 64 (chaotic, quasi-periodic or not settled)"
    con.print(f"{n} sampled periods after {sol.info['transient']} transient: [bold]{kind}[/bold]")
    sliding = f"; sliding intervals: {len(sol.sliding)}" if sol.sliding is not None else ""
    con.print(
        f"impacts: {sol.n_impacts} in the whole run, {len(sol.impacts)} in the sampled span; "
        f"sticking intervals: {len(sol.sticking)}{sliding}"
    )
    if sol.modes is not None and sol.switches is not None:
        counts = np.bincount(sol.modes, minlength=model.n_modes)
        con.print(
            f"modes: {len(sol.switches)} switches in the sampled span, ending in {sol.mode_final}; "
            "samples per mode: " + ", ".join(f"{name} {c}" for name, c in zip(model.mode_names, counts))
        )
        for line in _switch_lines(sol):
            con.print(line)
    con.print(f"{sol.n_steps} steps in {elapsed:.3f} s")
    if model.n_stops > 1 and (sol.n_impacts or not model.has_modes):  # (not switches without a reset)
        con.print(
            "impacts per stop in the sampled span: "
            + ", ".join(f"{k} {v}" for k, v in sol.impacts.per_stop().items())
        )
    mode = ("mode",) if sol.modes is not None else ()
    table = Table("k", model.time_label, *model.state_labels, *mode, title="last stroboscopic samples")
    show = min(n, max(period, 5) if period else 8)
    for i in range(n - show, n):
        shown = (sol.mode_names[sol.modes[i]],) if sol.modes is not None else ()
        table.add_row(str(i), f"{sol.t[i]:.6f}", *(f"{v: .10f}" for v in sol.samples[i]), *shown)
    con.print(table)
    if trajectory is not None:
        con.print(f"trajectory written to {trajectory}")
