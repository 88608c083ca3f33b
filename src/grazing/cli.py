"""The ``grazing`` command line.

Every analysis command takes the paper's parameter cases by name (``--case B``,
the default) and/or explicit parameters (``--alpha --beta --r --eta
--theta-hat``, the stop angle in degrees), prints a human-readable summary, or
one JSON object with ``--json``.  Bad input gets one line on stderr and a
non-zero exit status; nothing is written.
"""

from __future__ import annotations

import functools
import json
import math
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click
import numpy as np

import grazing
from grazing.atomic import atomic_path, write_text_atomic
from grazing.cli_validate import (
    ANGLE_DEG,
    FINITE,
    ORBIT_PERIOD,
    POSITIVE,
    TOLERANCE,
    WORKERS,
    InputError,
    count,
    path_type,
    refuse_unused,
)
from grazing.errors import GrazingError
from grazing.limits import MEMORY_ENV, POINT_OVERHEAD, check_memory, count_text, simulate_bytes, sweep_bytes
from grazing.models.pendulum import CASES, DEFAULT_CASE, case_values, max_angle

PENDULUM_UNFOLDING = ("eta", "theta_hat")
"""The parameters of the pendulum's normal-form unfolding vectors (the JSON reports both)."""

EXIT_USAGE = 2
EXIT_FAILURE = 1
EXIT_INTERRUPTED = 130


_ErrorInput = InputError
"""A usage error reported as one line (the name the command modules use)."""


# ----------------------------------------------------------------------------
# Shared options


_json_option = click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
_netcdf_out_option = click.option(
    "--out", type=path_type(dir_okay=False), metavar="FILE.nc", help="Save as NetCDF."
)


def model_options(func: Callable[..., Any]) -> Callable[..., Any]:
    """Options selecting the pendulum's parameters: a named case plus overrides.

    The decorated command receives the validated model as ``model`` and the
    case name as ``case`` (for its JSON output).
    """

    @functools.wraps(func)
    def wrapper(
        *args: Any, case: str, alpha: float | None, beta: float | None, r: float | None, eta: float,
        theta_hat: float, **kwargs: Any,
    ) -> Any:  # fmt: skip
        refuse_unused(["case"], None not in (alpha, beta, r), "when --alpha, --beta and --r are all given")
        model = build_pendulum(case, alpha, beta, r, eta, theta_hat)
        return func(*args, model=model, case=case, **kwargs)

    options = [
        click.option(
            "--case",
            default=DEFAULT_CASE,
            show_default=True,
            metavar="NAME",
            help=f"Paper parameter case: {', '.join(CASES)} (sets r, beta, alpha).",
        ),
        click.option("--alpha", type=float, help="Forcing amplitude A/L (overrides the case)."),
        click.option("--beta", type=float, help="Linear damping (overrides the case)."),
        click.option("--r", "r", type=float, help="Coefficient of restitution in [0, 1]."),
        click.option("--eta", type=float, default=0.446, show_default=True, help="Frequency ratio."),
        click.option(
            "--theta-hat",
            "theta_hat",
            type=ANGLE_DEG,
            default=40.0,
            show_default=True,
            metavar="DEG",
            help="Stop angle in degrees, in (-180, 180).",
        ),
    ]
    for opt in reversed(options):
        wrapper = opt(wrapper)
    return wrapper


def build_pendulum(
    case: str, alpha: float | None, beta: float | None, r: float | None, eta: float, theta_hat: float
) -> grazing.HybridModel:
    """The pendulum model from command-line values (theta_hat in degrees, checked by its option type)."""
    values = case_values(case)
    for name, val in (("alpha", alpha), ("beta", beta), ("r", r)):
        if val is not None:
            values[name] = val
    values["eta"] = eta
    values["theta_hat"] = math.radians(theta_hat)
    return grazing.models.pendulum(None, **values)


def model_params_json(model: grazing.HybridModel, case: str) -> dict[str, Any]:
    p = dict(model.params)
    p["theta_hat_deg"] = math.degrees(p["theta_hat"])
    p["case"] = case
    return p


def _parse_pair(text: str) -> tuple[float, float]:
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        a, b = (float(s) for s in parts)
    except ValueError:
        raise _ErrorInput(f"--initial must be THETA,THETADOT in radians, got {text!r}") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise _ErrorInput(f"--initial must be finite numbers, got {text!r}")
    return a, b


class _Progress:
    """A progress bar on stderr that appears only if the work lasts over a second."""

    def __init__(self, label: str, enabled: bool, unit: str = "items"):
        self.label = label
        self.unit = unit
        self.enabled = enabled and sys.stderr.isatty()
        self.start = time.perf_counter()
        self._bar: Any = None
        self._task: Any = None

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        if self._bar is None:
            if time.perf_counter() - self.start < 1.0 or done >= total:
                return
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeRemainingColumn,
            )

            self._bar = Progress(
                TextColumn(self.label),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn("{task.fields[rate]}"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
                transient=True,
            )
            self._bar.start()
            self._task = self._bar.add_task(self.label, total=total, rate="")
        elapsed = time.perf_counter() - self.start
        rate = f"{done / elapsed:,.0f} {self.unit}/s" if elapsed > 0 else ""
        self._bar.update(self._task, completed=done, rate=rate)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.stop()


def _write_atomic(path: Path, write: Callable[[Any], None]) -> None:
    """Write a text file all at once (see :mod:`grazing.atomic`), into an existing folder."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise _ErrorInput(f"folder {str(folder)!r} does not exist")
    write_text_atomic(path, write)


def _emit_json(obj: dict[str, Any]) -> None:
    click.echo(json.dumps(obj, allow_nan=False, default=_json_default))


def _json_default(o: Any) -> Any:
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.generic):
        return o.item()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


# ----------------------------------------------------------------------------
# Commands


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(grazing.__version__, prog_name="grazing")
def cli() -> None:
    """Simulate and analyse impacting systems (the inclined impacting pendulum of
    Piiroinen, Virgin & Champneys 2004 by default)."""


@cli.command()
@model_options
@click.option("--initial", default="0,0", show_default=True, metavar="THETA,THETADOT",
              help="Initial state at tau = 0, radians.")  # fmt: skip
@click.option("--transient", type=count(0), default=500, show_default=True,
              help="Forcing periods run and discarded first.")  # fmt: skip
@click.option("--periods", type=count(1), default=100, show_default=True,
              help="Forcing periods sampled.")  # fmt: skip
@click.option("--phase", type=FINITE, default=0.0, show_default=True, metavar="PHI",
              help="Stroboscopic phase in radians: samples at tau = PHI mod 2 pi.")  # fmt: skip
@click.option("--trajectory", type=path_type(dir_okay=False), metavar="FILE.csv",
              help="Write the dense trajectory of the sampled span to a CSV file.")  # fmt: skip
@click.option("--points-per-period", type=count(4), default=100, show_default=True,
              help="Trajectory resolution (with --trajectory).")  # fmt: skip
@_json_option
def simulate(
    model: grazing.HybridModel,
    case: str,
    initial: str,
    transient: int,
    periods: int,
    phase: float,
    trajectory: Path | None,
    points_per_period: int,
    as_json: bool,
) -> None:
    """Simulate the impacting pendulum; print stroboscopic samples, impacts, period."""
    refuse_unused(["points_per_period"], trajectory is None, "without --trajectory")
    theta0, dtheta0 = _parse_pair(initial)
    if theta0 > model.params["theta_hat"]:
        raise _ErrorInput(
            f"initial angle {theta0:g} rad is beyond the stop at theta-hat = "
            f"{math.degrees(model.params['theta_hat']):g} deg ({model.params['theta_hat']:.6g} rad)"
        )
    _check_out(trajectory, ".csv", "--trajectory")
    points = periods * points_per_period + 1 if trajectory is not None else 0
    check_memory(
        simulate_bytes(periods, model.n_states, points, as_json),
        f"simulating {count_text(periods)} sampled periods"
        + (f" with a trajectory of {count_text(points)} points" if points else ""),
        "sample fewer periods (--periods; --transient runs without keeping anything)"
        + (" or fewer --points-per-period" if points else ""),
    )
    bar = _Progress("simulating", enabled=not as_json, unit="periods")
    t0 = time.perf_counter()
    try:
        sol = grazing.simulate(
            model,
            [theta0, dtheta0],
            transient=transient,
            periods=periods,
            phase=phase,
            trajectory=points_per_period if trajectory is not None else 0,
            progress=bar,
        )
    finally:
        bar.close()
    elapsed = time.perf_counter() - t0
    if trajectory is not None:
        _write_atomic(trajectory, functools.partial(_write_trajectory_csv, sol))
    period = sol.period()
    result = {
        "params": model_params_json(model, case),
        "initial": [theta0, dtheta0],
        "transient": transient,
        "periods": periods,
        "phase": phase,
        "samples": sol.samples,
        "impacts": sol.n_impacts,
        "impacts_sampled": len(sol.impacts),
        "impact_map": np.column_stack([sol.impacts.t, sol.impacts.phase, sol.impacts.speed]),
        "sticking_intervals": sol.sticking,
        "period": period,
        "t_final": sol.t_final,
        "x_final": sol.x_final,
        "steps": sol.n_steps,
        "elapsed_s": elapsed,
        "trajectory_file": str(trajectory) if trajectory is not None else None,
        "version": grazing.__version__,
    }
    if as_json:
        _emit_json(result)
        return
    _print_simulation(model, sol, period, elapsed, trajectory)


def _write_trajectory_csv(sol: grazing.Solution, fh: Any) -> None:
    fh.write("tau,theta,dtheta\n")
    assert sol.trajectory_t is not None and sol.trajectory is not None
    np.savetxt(fh, np.column_stack([sol.trajectory_t, sol.trajectory]), delimiter=",", fmt="%.17g")


def _print_simulation(
    model: grazing.HybridModel, sol: grazing.Solution, period: int, elapsed: float, trajectory: Path | None
) -> None:
    from rich.console import Console
    from rich.table import Table

    con = Console()
    p = model.params
    con.print(
        f"[bold]impacting pendulum[/bold]  alpha={p['alpha']:g} beta={p['beta']:g} r={p['r']:g} "
        f"eta={p['eta']:g} theta-hat={math.degrees(p['theta_hat']):g} deg"
    )
    n = sol.samples.shape[0]
    kind = f"period {period}" if period else "no period <= 64 (chaotic, quasi-periodic or not settled)"
    con.print(f"{n} sampled periods after {sol.info['transient']} transient: [bold]{kind}[/bold]")
    con.print(
        f"impacts: {sol.n_impacts} in the whole run, {len(sol.impacts)} in the sampled span; "
        f"sticking intervals: {len(sol.sticking)}; {sol.n_steps} steps in {elapsed:.3f} s"
    )
    table = Table("k", "tau", "theta [rad]", "theta' ", title="last stroboscopic samples")
    show = min(n, max(period, 5) if period else 8)
    for i in range(n - show, n):
        table.add_row(str(i), f"{sol.t[i]:.6f}", f"{sol.samples[i, 0]: .10f}", f"{sol.samples[i, 1]: .10f}")
    con.print(table)
    if trajectory is not None:
        con.print(f"trajectory written to {trajectory}")


def _check_eta_range(eta_min: float, eta_max: float) -> None:
    """``--eta-min < --eta-max`` (each is positive by its option type)."""
    if not eta_min < eta_max:
        raise _ErrorInput(f"need 0 < --eta-min < --eta-max, got {eta_min:g} and {eta_max:g}")


def _complex_list(mu: np.ndarray) -> list[list[float]]:
    return [[float(z.real), float(z.imag)] for z in np.asarray(mu, dtype=complex)]


def _check_out(out: Path | None, suffix: str, option: str = "--out") -> None:
    """An output path must have ``suffix`` and an existing folder (checked before any work)."""
    if out is None:
        return
    if out.suffix.lower() != suffix:
        raise _ErrorInput(f"{option} must name a {suffix} file, got {str(out)!r}")
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise _ErrorInput(f"folder {str(folder)!r} does not exist")


def _save_dataset(ds: Any, out: Path) -> None:
    """Write a dataset to NetCDF all at once, so a failure leaves nothing."""
    with atomic_path(out, suffix=".nc") as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")


def _orbit_json(orbit: Any) -> dict[str, Any]:
    out = {
        "period": orbit.period,
        "impacts": orbit.impacts,
        "state": orbit.state,
        "multipliers": _complex_list(orbit.multipliers),
        "abs_multipliers": np.abs(orbit.multipliers),
        "stable": orbit.stable,
        "residual": orbit.residual,
        "newton_iterations": len(orbit.residuals) - 1,
        "min_impact_speed": None if math.isnan(orbit.min_impact_speed) else orbit.min_impact_speed,
    }
    if "theta_hat" in orbit.model.params:
        out["max_theta_deg"] = math.degrees(max_angle(orbit))
    return out


@cli.command()
@model_options
@click.option("--period", type=ORBIT_PERIOD, help="Period in forcing periods (default: detected).")
@click.option(
    "--initial", metavar="THETA,THETADOT", help="Initial guess at tau = 0 (default: from simulation)."
)
@click.option("--transient", type=count(0), default=500, show_default=True,
              help="Forcing periods simulated for the initial guess (without --initial).")  # fmt: skip
@_json_option
def orbit(
    model: grazing.HybridModel,
    case: str,
    period: int | None,
    initial: str | None,
    transient: int,
    as_json: bool,
) -> None:
    """Find a periodic orbit by Newton shooting; print its multipliers and stability."""
    from grazing.orbits import find_orbit

    refuse_unused(["transient"], initial is not None, "with --initial (it runs the simulation that guesses)")
    x0 = None
    if initial is not None:
        x0 = _parse_pair(initial)
        if x0[0] > model.params["theta_hat"]:
            raise _ErrorInput(
                f"initial angle {x0[0]:g} rad is beyond the stop at theta-hat = "
                f"{math.degrees(model.params['theta_hat']):g} deg"
            )
    orb = find_orbit(model, x0, period=period, transient=transient)
    res = {"params": model_params_json(model, case), **_orbit_json(orb)}
    if as_json:
        _emit_json(res)
        return
    kind = "stable" if orb.stable else "unstable"
    click.echo(
        f"period-{orb.period} orbit with {orb.impacts} impact(s) per period, {kind}; "
        f"max theta {res['max_theta_deg']:.6f} deg"
    )
    click.echo(f"state at tau = 0: theta = {orb.state[0]:.12f}, theta' = {orb.state[1]:.12f}")
    for z in orb.multipliers:
        click.echo(f"  multiplier {z.real:+.6f} {z.imag:+.6f}i   |mu| = {abs(z):.6f}")


def _grazing_json(g: Any) -> dict[str, Any]:
    return {
        "eta": g.model.params["eta"],
        "theta_hat_deg": math.degrees(g.model.params["theta_hat"]),
        "multipliers": _complex_list(g.multipliers),
        "abs_lambda": g.abs_lambda,
        "t_graze": g.phase,
        "accel": g.accel,
    }


@cli.command()
@model_options
@click.option("--eta-min", type=POSITIVE, default=0.2, show_default=True, help="Lower end of the eta range.")
@click.option("--eta-max", type=POSITIVE, default=1.0, show_default=True, help="Upper end of the eta range.")
@_json_option
def graze(
    model: grazing.HybridModel,
    case: str,
    eta_min: float,
    eta_max: float,
    as_json: bool,
) -> None:
    """Every grazing of the period-1 nonimpacting orbit with the stop, for eta in a range."""
    from grazing.orbits import find_grazings

    refuse_unused(["eta"], True, "by graze: it searches eta in [--eta-min, --eta-max]")
    _check_eta_range(eta_min, eta_max)
    bar = _Progress("continuing", enabled=not as_json)
    try:
        points, branch = find_grazings(
            model,
            "eta",
            eta_min,
            eta_max,
            progress=lambda n, v: bar(int(1000 * (v - eta_min) / (eta_max - eta_min)), 1000),
        )
    finally:
        bar.close()
    res = {
        "params": model_params_json(model, case),
        "eta_range": [eta_min, eta_max],
        "grazings": [_grazing_json(g) for g in points],
        "folds": [s.param for s in branch.special if s.kind == "fold"],
    }
    if as_json:
        _emit_json(res)
        return
    if not points:
        th = math.degrees(model.params["theta_hat"])
        click.echo(f"no grazing for eta in [{eta_min:g}, {eta_max:g}] at theta-hat = {th:g} deg")
    for g in res["grazings"]:
        mu = ", ".join(f"{a:+.4f}{b:+.4f}i" for a, b in g["multipliers"])
        click.echo(f"eta = {g['eta']:.6f}: multipliers {mu}, |lambda| = {g['abs_lambda']:.4f}, "
                   f"t_graze = {g['t_graze']:.4f}")  # fmt: skip


@cli.command("graze-curve")
@model_options
@click.option(
    "--start-deg", type=ANGLE_DEG, default=5.0, show_default=True, help="theta-hat where the curve starts."
)
@click.option("--eta-min", type=POSITIVE, default=0.2, show_default=True, help="Lower end of the eta range.")
@click.option("--eta-max", type=POSITIVE, default=1.0, show_default=True, help="Upper end of the eta range.")
@click.option("--max-step", type=POSITIVE, default=0.05, show_default=True, help="Largest continuation step.")
@_netcdf_out_option
@_json_option
def graze_curve(
    model: grazing.HybridModel,
    case: str,
    start_deg: float,
    eta_min: float,
    eta_max: float,
    max_step: float,
    out: Path | None,
    as_json: bool,
) -> None:
    """Two-parameter continuation of grazing in (eta, theta-hat), with theta-hat_max."""
    from grazing.orbits import PalcSettings, grazing_curve

    refuse_unused(["eta"], True, "by graze-curve: it searches eta in [--eta-min, --eta-max]")
    refuse_unused(["theta_hat"], True, "by graze-curve: the curve starts at --start-deg")
    _check_eta_range(eta_min, eta_max)
    _check_out(out, ".nc")
    settings = PalcSettings(ds=min(0.02, max_step), ds_max=max_step)
    curve = grazing_curve(model, ("eta", "theta_hat"), math.radians(start_deg), search=(eta_min, eta_max),
                          settings=settings)  # fmt: skip
    if out is not None:
        _save_dataset(curve.to_dataset(), out)
    fold = curve.fold
    res = {
        "params": model_params_json(model, case),
        "theta_max_deg": math.degrees(fold.model.params["theta_hat"]) if fold else None,
        "eta_at_theta_max": fold.model.params["eta"] if fold else None,
        "multipliers_at_theta_max": _complex_list(fold.multipliers) if fold else None,
        "status": curve.status,
        "curve": [_grazing_json(g) for g in curve.points],
        "out": str(out) if out else None,
    }
    if as_json:
        _emit_json(res)
        return
    click.echo(f"{len(curve.points)} grazing orbits from theta-hat = {start_deg:g} deg ({curve.status})")
    if fold:
        click.echo(f"theta-hat_max = {res['theta_max_deg']:.4f} deg at eta = {res['eta_at_theta_max']:.6f}: "
                   "no grazing above it")  # fmt: skip


_CONTINUE_PARAMS = {"eta": "eta", "theta-hat": "theta_hat", "alpha": "alpha", "beta": "beta", "r": "r"}


@cli.command("continue")
@model_options
@click.option("--param", "cparam", required=True, type=click.Choice(list(_CONTINUE_PARAMS)),
              help="Parameter to vary (theta-hat in degrees).")  # fmt: skip
@click.option("--start", type=FINITE, required=True, help="Start value of the parameter.")
@click.option("--stop", type=FINITE, required=True, help="End value of the parameter.")
@click.option("--period", type=ORBIT_PERIOD, help="Period of the orbit (default: detected).")
@click.option("--initial", metavar="THETA,THETADOT", help="Initial guess at tau = 0.")
@click.option("--virtual/--physical", default=None,
              help="Ignore the stop (default: yes for a nonimpacting starting orbit).")  # fmt: skip
@click.option("--max-step", type=POSITIVE, default=0.04, show_default=True, help="Largest continuation step.")
@click.option("--switch", is_flag=True,
              help="At a grazing where the impact sequence changes, continue on the orbit with the new "
              "sequence (a new branch segment) instead of ending there.")  # fmt: skip
@_netcdf_out_option
@_json_option
def continue_(
    model: grazing.HybridModel,
    case: str,
    cparam: str,
    start: float,
    stop: float,
    period: int | None,
    initial: str | None,
    virtual: bool | None,
    max_step: float,
    switch: bool,
    out: Path | None,
    as_json: bool,
) -> None:
    """Pseudo-arclength continuation of a periodic orbit, with folds, period-doublings,
    Neimark-Sacker points and grazings located.  A branch of an impacting orbit ends at
    the grazing where its impact sequence changes (see --switch)."""
    from grazing.orbits import PalcSettings, continue_orbit

    name = _CONTINUE_PARAMS[cparam]
    refuse_unused([name], True, f"with --param {cparam}: the branch starts at --start")
    conv = math.radians if name == "theta_hat" else float
    if start == stop:
        raise _ErrorInput(f"--start and --stop must be finite and differ, got {start:g} and {stop:g}")
    if name == "theta_hat":
        for opt, v in (("--start", start), ("--stop", stop)):
            if not ANGLE_DEG.accepts(v):
                raise _ErrorInput(f"{opt} for theta-hat must be {ANGLE_DEG.describe()}, got {v:g}")
    _check_out(out, ".nc")
    x0 = _parse_pair(initial) if initial is not None else None
    a, b = conv(start), conv(stop)
    for v in (a, b):  # both ends within the parameter's bounds, before any work ("r = 2 is outside [0, 1]")
        model.with_params(**{name: v})
    bar = _Progress("continuing", enabled=not as_json)
    try:
        branch = continue_orbit(
            model, name, a, b, x0=None if x0 is None else np.array(x0), period=period, virtual=virtual,
            settings=PalcSettings(ds=min(0.01, max_step), ds_max=max_step), switch=switch,
            progress=lambda n, v: bar(int(1000 * abs(v - a) / abs(b - a)), 1000),
        )  # fmt: skip
    finally:
        bar.close()
    if out is not None:
        _save_dataset(branch.to_dataset(), out)
    back = math.degrees if name == "theta_hat" else float
    res = {
        "params": model_params_json(model, case),
        "param": cparam,
        "period": branch.period,
        "virtual": branch.virtual,
        "values": [back(v) for v in branch.values],
        "states": branch.states,
        "multipliers": [_complex_list(o.multipliers) for o in branch.orbits],
        "stable": [o.stable for o in branch.orbits],
        "impacts": [o.impacts for o in branch.orbits],
        "segments": branch.segments,
        "section_times": branch.sections,
        "switch": switch,
        "special": [
            {
                "kind": sp_.kind,
                "value": back(sp_.param),
                "index": sp_.index,
                "multipliers": _complex_list(sp_.multipliers),
                "state": sp_.orbit.state,
            }
            for sp_ in branch.special
        ],
        "status": branch.status,
        "out": str(out) if out else None,
    }
    res["max_theta_deg"] = [math.degrees(max_angle(o)) for o in branch.orbits]
    if as_json:
        _emit_json(res)
        return
    kind = "virtual (stop ignored)" if branch.virtual else "physical"
    segs = max(branch.segments) + 1 if branch.segments else 1
    more = f" in {segs} segments (impact sequence switched at grazings)" if segs > 1 else ""
    click.echo(f"{len(branch)} points of the period-{branch.period} orbit{more}, {kind}; {branch.status}")
    for sp_ in res["special"]:
        mu = ", ".join(f"{x:+.4f}{y:+.4f}i" for x, y in sp_["multipliers"])
        click.echo(f"  {sp_['kind']:16s} {cparam} = {sp_['value']:.8g}   multipliers {mu}")
    if out is not None:
        click.echo(f"branch saved to {out}")


_SWEEP_PARAMS = {"eta": "eta", "theta-hat": "theta_hat", "alpha": "alpha", "beta": "beta", "r": "r"}


def _sweep_options(func: Callable[..., Any]) -> Callable[..., Any]:
    options = [
        click.option("--transient", type=count(0), default=500, show_default=True,
                     help="Forcing periods discarded at each point.")
        ,
        click.option("--periods", type=count(1), default=100, show_default=True,
                     help="Forcing periods sampled at each point."),
        click.option("--initial", default="0,0", show_default=True, metavar="THETA,THETADOT",
                     help="Initial state (of every chunk; of every point with --fresh)."),
        click.option("--fresh", is_flag=True, help="Start every point from --initial."),
        click.option("--chunk-size", type=count(0), default=None,
                     help="Points per chunk: the unit of parallel work and of saving (0: one chunk)."),
        click.option("--workers", type=WORKERS, help="Local processes (default: all cores)."),
        click.option("--scheduler", metavar="tcp://HOST:PORT", help="Run the chunks on a Dask cluster."),
        click.option("--timeout", type=POSITIVE, metavar="SECONDS",
                     help="With --scheduler: give up after this long without any Dask worker "
                          "(default: wait; a message after 5 s)."),
        click.option("--no-lyapunov", is_flag=True, help="Skip the Lyapunov exponents."),
        click.option("--no-adaptive", is_flag=True, help="Always run the full transient."),
        click.option("--tol", type=TOLERANCE, default=1e-10, show_default=True,
                     help="Integrator tolerance, in (0, 0.01)."),
        click.option("--out", type=path_type(), metavar="FILE.zarr|FILE.nc",
                     help="Zarr store (resumable; one run at a time) or NetCDF file."),
        click.option("--wait", is_flag=True,
                     help="If another run is writing the --out store, wait for it instead of stopping."),
        _json_option,
    ]  # fmt: skip
    for opt in reversed(options):
        func = opt(func)
    return func


def _check_sweep_options(
    out: Path | None, scheduler: str | None, chunk_size: int | None, n_points: int, periods: int,
    n_states: int, workers: int | None, as_json: bool, what: str,
) -> None:  # fmt: skip
    """The checks shared by ``sweep`` and ``map``, before any work: output, options used together, memory."""
    if out is not None and out.suffix.lower() not in (".zarr", ".nc"):
        raise _ErrorInput(f"--out must end in .zarr or .nc, got {str(out)!r}")
    if out is not None:
        folder = out.parent if str(out.parent) else Path(".")
        if not folder.is_dir():
            raise _ErrorInput(f"folder {str(folder)!r} does not exist")
    zarr_out = out is not None and out.suffix.lower() == ".zarr"
    refuse_unused(["wait"], not zarr_out, "without a Zarr store (--out FILE.zarr)")
    refuse_unused(["timeout"], scheduler is None, "without --scheduler")
    refuse_unused(
        ["workers"], scheduler is not None, "with --scheduler (the cluster's workers run the chunks)"
    )
    if zarr_out and out is not None and out.exists():
        from grazing.sweeps.ownership import check_is_store

        check_is_store(out)  # refuse what grazing did not make before computing anything
    streamed = zarr_out and not as_json
    chunk = n_points if not chunk_size else min(chunk_size, n_points)
    n_workers = workers or os.cpu_count() or 1
    need = sweep_bytes(n_points, periods, n_states, streamed=streamed, as_json=as_json, chunk_points=chunk,
                       workers=n_workers)  # fmt: skip
    chunks_dominate = streamed and need > 2 * n_points * POINT_OVERHEAD  # the samples in flight, mostly
    check_memory(
        need,
        f"{what} of {count_text(n_points)} points x {count_text(periods)} periods",
        "use a smaller --chunk-size (or fewer --workers): the chunks in flight hold their samples"
        if chunks_dominate
        else "split it into several runs over parts of the range"
        + ("" if streamed else ", or stream the results to a Zarr store (--out FILE.zarr, without --json)"),
    )


class _SweepRun:
    """What a sweep run returns to its command: the dataset, or (streamed to a store) the periods only."""

    def __init__(self, ds: Any, period: np.ndarray | None):
        self.ds = ds
        self.period = period


def _run_sweep_spec(
    spec: Any, out: Path | None, scheduler: str | None, workers: int | None, as_json: bool,
    wait: bool = False, timeout: float | None = None,
) -> _SweepRun:  # fmt: skip
    """Run a sweep spec with the CLI's storage, cluster and progress options.

    With a Zarr store and no ``--json``, the results stream to the store and
    only the detected periods are read back (for the summary).
    """
    from grazing.sweeps.api import run_sweep

    zarr_out = out is not None and out.suffix.lower() == ".zarr"
    streamed = zarr_out and not as_json
    client = None
    if scheduler is not None:
        try:
            from distributed import Client

            client = Client(scheduler, timeout="5s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise _ErrorInput(f"cannot connect to the Dask scheduler at {scheduler}: {exc}") from None
    store: Any = None
    bar = _Progress("sweeping", enabled=not as_json, unit="points")
    try:
        if zarr_out:
            from grazing.sweeps.store import ZarrStore

            store = ZarrStore(
                out, spec, attrs={"command": " ".join(["grazing", *sys.argv[1:]])}, wait=wait,
                on_wait=lambda pid: click.echo(
                    f"grazing: {out} is being written by another grazing run"
                    + (f" (PID {pid})" if pid is not None else "") + "; waiting", err=True
                ),
            )  # fmt: skip
        ds = run_sweep(
            spec, store=store, workers=workers, client=client, progress=bar, timeout=timeout,
            notice=lambda msg: click.echo(f"grazing: {msg}", err=True), load=not streamed,
        )  # fmt: skip
        period = store.read("period") if streamed else None
    finally:
        bar.close()
        if store is not None:
            store.close()
        if client is not None:
            client.close()
    if out is not None and out.suffix.lower() == ".nc":
        _save_dataset(ds, out)
    return _SweepRun(ds, period)


def _sweep_json(ds: Any, param: str, values: np.ndarray) -> dict[str, Any]:
    return {
        "param": param,
        "values": values,
        "period": ds.period.values,
        "impacts_per_period": np.where(
            np.isfinite(ds.impacts_per_period.values), ds.impacts_per_period.values, None
        ),
        "lyapunov": [None if not math.isfinite(v) else float(v) for v in ds.lyapunov.values],
        "samples": ds.samples.values[..., 0],
        "transient_used": ds.transient_used.values,
    }


@cli.command("sweep")
@model_options
@click.option("--param", "sparam", required=True, type=click.Choice(list(_SWEEP_PARAMS)),
              help="Parameter to sweep (theta-hat in degrees).")  # fmt: skip
@click.option("--start", type=FINITE, required=True, help="First parameter value.")
@click.option("--stop", type=FINITE, required=True, help="Last parameter value.")
@click.option("--num", type=count(1), required=True, help="Number of parameter values.")
@click.option("--direction", type=click.Choice(["up", "down"]), default="up", show_default=True,
              help="Order in which the values are visited.")  # fmt: skip
@click.option(
    "--method",
    type=click.Choice(["flow", "map"]),
    default="flow",
    show_default=True,
    help="flow: direct simulation; map: the discontinuity-map Poincare map built at a grazing.",
)
@click.option("--which", type=click.Choice(["first", "second"]), default="first", show_default=True,
              help="With --method map: the grazing the map is built at.")  # fmt: skip
@_sweep_options
def sweep_cmd(
    model: grazing.HybridModel, case: str,
    sparam: str, start: float, stop: float, num: int, direction: str, method: str, which: str,
    transient: int, periods: int, initial: str, fresh: bool, chunk_size: int | None, workers: int | None,
    scheduler: str | None, timeout: float | None, no_lyapunov: bool, no_adaptive: bool, tol: float,
    out: Path | None, wait: bool, as_json: bool,
) -> None:  # fmt: skip
    """Brute-force bifurcation diagram: stroboscopic samples, periods, impacts and
    Lyapunov exponents along a parameter range."""
    from grazing.sweeps.spec import SweepSpec

    name = _SWEEP_PARAMS[sparam]
    refuse_unused([name], True, f"with --param {sparam}: the swept values replace it")
    refuse_unused(["which"], method != "map", "without --method map")
    chunk_size = 50 if chunk_size is None else chunk_size
    _check_sweep_options(
        out, scheduler, chunk_size, num, periods, model.n_states, workers, as_json, "a sweep"
    )
    shown = np.linspace(start, stop, num)
    vals = np.radians(shown) if name == "theta_hat" else shown
    order = np.sort(vals) if direction == "up" else np.sort(vals)[::-1]
    x0 = _parse_pair(initial)
    for v in (order[0], order[-1]):
        model.with_params(**{name: v})
    zdm, graze_info = None, None
    if method == "map":
        zdm, graze_info = _map_for_sweep(model, name, float(vals.min()), float(vals.max()), which)
    spec = SweepSpec(
        model=model, params=(name,), points=tuple((float(v),) for v in order),
        x0=tuple(float(v) for v in model.with_params(**{name: order[0]}).check_state(x0)),
        transient=transient, periods=periods, fresh=fresh, chunk_size=chunk_size,
        adaptive=not no_adaptive, lyapunov=not no_lyapunov, tol=tol, zdm=zdm,
    )  # fmt: skip
    t0 = time.perf_counter()
    run = _run_sweep_spec(spec, out, scheduler, workers, as_json, wait, timeout)
    elapsed = time.perf_counter() - t0
    if as_json:
        ds = run.ds.sortby("value")
        res = {"params": model_params_json(model, case), **_sweep_json(ds, sparam, np.sort(shown))}
        res.update({"direction": direction, "fresh": fresh, "transient": transient, "periods": periods,
                    "chunk_size": spec.size, "elapsed_s": elapsed, "out": str(out) if out else None,
                    "method": method, "grazing": graze_info})  # fmt: skip
        _emit_json(res)
        return
    if run.ds is not None:
        per = run.ds.sortby("value").period.values
    else:  # streamed to the store: the periods in visiting order, sorted like the values
        per = run.period[np.argsort(order, kind="stable")]
    click.echo(f"{num} values of {sparam} in {elapsed:.1f} s ({num / elapsed:.0f} points/s)")
    click.echo(f"periodic points: {(per > 0).sum()}, no period <= 64: {(per == 0).sum()}")
    for p in sorted(set(per[per > 0].tolist()))[:12]:
        sel = np.sort(shown)[per == p]
        click.echo(f"  period {p:2d}: {sel.size} points, {sparam} in [{sel.min():.6g}, {sel.max():.6g}]")
    if out is not None:
        click.echo(f"saved to {out}")


_GRAZE_SEARCH = {"eta": (0.2, 1.0), "theta_hat": (-3.1, 3.1)}


def _map_for_sweep(model: Any, name: str, lo: float, hi: float, which: str) -> tuple[Any, dict[str, Any]]:
    """The discontinuity map at the first/second grazing for a sweep in ``name`` over ``[lo, hi]``."""
    from grazing.normalform import find_grazing_point, normal_form_at

    a, b = _GRAZE_SEARCH.get(name, (lo - 0.5 * (hi - lo), hi + 0.5 * (hi - lo)))
    point = find_grazing_point(model, name, min(a, lo), max(b, hi), which)
    nf = normal_form_at(point, PENDULUM_UNFOLDING)
    back = math.degrees if name == "theta_hat" else float
    info = {
        "param": name,
        "value": back(point.model.params[name]),
        "t_graze": point.phase,
        "multipliers": _complex_list(point.multipliers),
        "accel": nf.accel,
        "direction": nf.direction,
    }
    return nf.discontinuity_map(), info


@cli.command("normal-form")
@model_options
@click.option(
    "--which",
    type=click.Choice(["first", "second"]),
    default="first",
    show_default=True,
    help="First or second grazing in eta at this theta-hat.",
)
@click.option("--eta-min", type=POSITIVE, default=0.2, show_default=True, help="Lower end of the eta search.")
@click.option("--eta-max", type=POSITIVE, default=1.0, show_default=True, help="Upper end of the eta search.")
@click.option(
    "--check", is_flag=True, help="Also simulate just past grazing and compare with the prediction."
)
@_json_option
def normal_form_cmd(
    model: grazing.HybridModel, case: str,
    which: str, eta_min: float, eta_max: float, check: bool, as_json: bool,
) -> None:  # fmt: skip
    """Grazing normal form at a grazing of the period-1 orbit: multipliers, the
    discontinuity map's coefficients and the predicted scenario past grazing."""
    from grazing.normalform import find_grazing_point, normal_form_at, observe, predict

    refuse_unused(["eta"], True, "by normal-form: it searches eta in [--eta-min, --eta-max]")
    _check_eta_range(eta_min, eta_max)
    point = find_grazing_point(model, "eta", eta_min, eta_max, which)
    nf = normal_form_at(point, PENDULUM_UNFOLDING)
    pred = predict(nf, "eta")
    b_eta, _, _ = nf.unfolding["eta"]
    res: dict[str, Any] = {
        "params": model_params_json(point.model, case),
        "which": which,
        "eta_graze": point.model.params["eta"],
        "t_graze": point.phase,
        "multipliers": _complex_list(point.multipliers),
        "abs_lambda": point.abs_lambda,
        "prediction": pred.to_json(),
        "coefficients": {
            "contact_state": nf.contact,
            "accel": nf.accel,
            "direction": nf.direction,
            "monodromy": nf.monodromy,
            "kappa": nf.kappa,
            "grad_h": nf.grad_h,
            "grad_rate": nf.grad_rate,
            "unfolding_eta": b_eta,
            "unfolding_theta_hat": nf.unfolding["theta_hat"][0],
        },
    }
    if check:
        obs = observe(nf, "eta")
        res["observed"] = {"scenario": obs.scenario, "offsets": obs.offsets, "periods": obs.periods}
        res["agrees"] = obs.scenario == pred.scenario
    if as_json:
        _emit_json(res)
        return
    mu = ", ".join(f"{z.real:+.4f}{z.imag:+.4f}i" for z in point.multipliers)
    click.echo(f"{which} grazing at eta = {res['eta_graze']:.6f}, t_graze = {point.phase:.4f}")
    click.echo(f"  multipliers {mu}, |lambda| = {point.abs_lambda:.4f}, kappa (M12) = {nf.kappa:+.4f}")
    click.echo(f"  discontinuity map: a = {nf.accel:.6f}, e = {np.round(nf.direction, 6).tolist()}")
    click.echo(f"  prediction: {pred.scenario} ({pred.rule})")
    if check:
        verdict = "agrees" if res["agrees"] else "differs"
        click.echo(f"  direct simulation just past grazing: {res['observed']['scenario']} ({verdict})")


@cli.command("map")
@model_options
@click.option("--param1", required=True, type=click.Choice(list(_SWEEP_PARAMS)), help="Horizontal parameter.")
@click.option("--start1", type=FINITE, required=True)
@click.option("--stop1", type=FINITE, required=True)
@click.option("--num1", type=count(1), required=True)
@click.option("--param2", required=True, type=click.Choice(list(_SWEEP_PARAMS)), help="Vertical parameter.")
@click.option("--start2", type=FINITE, required=True)
@click.option("--stop2", type=FINITE, required=True)
@click.option("--num2", type=count(1), required=True)
@_sweep_options
def map_cmd(
    model: grazing.HybridModel, case: str,
    param1: str, start1: float, stop1: float, num1: int, param2: str, start2: float, stop2: float, num2: int,
    transient: int, periods: int, initial: str, fresh: bool, chunk_size: int | None, workers: int | None,
    scheduler: str | None, timeout: float | None, no_lyapunov: bool, no_adaptive: bool, tol: float,
    out: Path | None, wait: bool, as_json: bool,
) -> None:  # fmt: skip
    """Two-parameter map of periods, impacts and Lyapunov exponents."""
    from grazing.sweeps.spec import SweepSpec

    if param1 == param2:
        raise _ErrorInput("--param1 and --param2 must differ")
    n1, n2 = _SWEEP_PARAMS[param1], _SWEEP_PARAMS[param2]
    refuse_unused([n1, n2], True, f"with --param1 {param1} --param2 {param2}: the mapped values replace it")
    chunk_size = num1 if chunk_size is None else chunk_size
    _check_sweep_options(out, scheduler, chunk_size, num1 * num2, periods, model.n_states, workers, as_json,
                         "a map")  # fmt: skip
    s1, s2 = np.linspace(start1, stop1, num1), np.linspace(start2, stop2, num2)
    v1 = np.radians(s1) if n1 == "theta_hat" else s1
    v2 = np.radians(s2) if n2 == "theta_hat" else s2
    v1, v2 = np.sort(v1), np.sort(v2)
    for a, b in ((v1[0], v2[0]), (v1[-1], v2[-1])):
        model.with_params(**{n1: a, n2: b})
    x0 = _parse_pair(initial)
    spec = SweepSpec(
        model=model, params=(n1, n2), points=tuple((float(a), float(b)) for b in v2 for a in v1),
        x0=tuple(float(v) for v in model.with_params(**{n1: v1[0], n2: v2[0]}).check_state(x0)),
        transient=transient, periods=periods, fresh=fresh, chunk_size=chunk_size,
        adaptive=not no_adaptive, lyapunov=not no_lyapunov, tol=tol, shape=(num2, num1),
    )  # fmt: skip
    t0 = time.perf_counter()
    run = _run_sweep_spec(spec, out, scheduler, workers, as_json, wait, timeout)
    elapsed = time.perf_counter() - t0
    if as_json:
        ds = run.ds
        res = {
            "params": model_params_json(model, case),
            "param1": param1, "values1": np.sort(s1), "param2": param2, "values2": np.sort(s2),
            "period": ds.period.values, "impacts_per_period": ds.impacts_per_period.values,
            "lyapunov": ds.lyapunov.values, "elapsed_s": elapsed, "out": str(out) if out else None,
        }  # fmt: skip
        res["impacts_per_period"] = [
            [None if not math.isfinite(x) else x for x in row] for row in res["impacts_per_period"]
        ]
        res["lyapunov"] = [[None if not math.isfinite(x) else x for x in row] for row in res["lyapunov"]]
        _emit_json(res)
        return
    per = run.ds.period.values if run.ds is not None else run.period
    click.echo(
        f"{num1} x {num2} map in {elapsed:.1f} s; periodic cells {(per > 0).sum()}, none {(per == 0).sum()}"
    )
    if out is not None:
        click.echo(f"saved to {out}")


@cli.command()
@click.option("--out", type=path_type(file_okay=False), default=Path("report"),
              show_default=True, help="Output folder for index.html and figures.")  # fmt: skip
@click.option("--only", "only", multiple=True, metavar="FIGURE",
              help="Rebuild only this figure (fig02, fig04, fig06 ... fig12, figmap, eq; repeatable) and "
                   "re-render the page with the other figures of earlier builds in --out.")  # fmt: skip
def report(out: Path, only: tuple[str, ...]) -> None:
    """Regenerate the paper's figures and tables into an HTML report."""
    from grazing.report import build_report, select

    if only:
        try:
            select(only)
        except ValueError as exc:
            raise click.BadParameter(str(exc), param_hint="--only") from None
    t0 = time.perf_counter()
    index = build_report(out, progress=lambda msg: click.echo(msg, err=True), only=only or None)
    click.echo(f"report written to {index} in {time.perf_counter() - t0:.1f} s")


# ----------------------------------------------------------------------------
# Entry point


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; every error becomes one line on stderr and an exit status."""
    try:
        cli.main(args=argv, prog_name="grazing", standalone_mode=False)
    except click.exceptions.Exit as exc:
        return int(exc.exit_code)
    except click.exceptions.Abort:
        click.echo("grazing: interrupted", err=True)
        return EXIT_INTERRUPTED
    except KeyboardInterrupt:
        click.echo("grazing: interrupted", err=True)
        return EXIT_INTERRUPTED
    except click.ClickException as exc:
        _error_line(exc.format_message())
        return EXIT_USAGE
    except GrazingError as exc:
        _error_line(str(exc))
        return EXIT_FAILURE
    except OSError as exc:
        _error_line(f"{exc.strerror or exc}: {exc.filename or ''}".rstrip(": "))
        return EXIT_FAILURE
    except MemoryError:
        _error_line(f"out of memory (the estimate before the run was too low; {MEMORY_ENV} lowers the bound)")
        return EXIT_FAILURE
    return 0


def _error_line(message: str) -> None:
    """``grazing: error: MESSAGE`` as one line on stderr (click's multi-line messages are joined)."""
    click.echo(f"grazing: error: {' '.join(message.split())}", err=True)


if __name__ == "__main__":  # pragma: no cover - `python -m grazing.cli`: use the importable module
    from grazing.cli import main as _main

    sys.exit(_main())
else:
    # The experiment commands import this module's helpers, so they register last.
    from grazing.cli_experiment import register as _register_experiment

    _register_experiment(cli)
