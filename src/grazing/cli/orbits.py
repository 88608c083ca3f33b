"""``grazing orbit``, ``graze``, ``graze-curve``, ``continue``: periodic orbits, grazings, branches."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click
import numpy as np

import grazing
from grazing.cli.common import (
    InputError,
    Progress,
    check_eta_range,
    check_out,
    complex_list,
    emit_json,
    json_option,
    model_options,
    model_params_json,
    netcdf_out_option,
    parse_pair,
    save_dataset,
)
from grazing.cli.validate import ANGLE_DEG, FINITE, ORBIT_PERIOD, POSITIVE, count, refuse_unused
from grazing.models.pendulum import max_angle


def _orbit_json(orbit: Any) -> dict[str, Any]:
    out = {
        "period": orbit.period,
        "impacts": orbit.impacts,
        "state": orbit.state,
        "multipliers": complex_list(orbit.multipliers),
        "abs_multipliers": np.abs(orbit.multipliers),
        "stable": orbit.stable,
        "residual": orbit.residual,
        "newton_iterations": len(orbit.residuals) - 1,
        "min_impact_speed": None if math.isnan(orbit.min_impact_speed) else orbit.min_impact_speed,
    }
    if "theta_hat" in orbit.model.params:
        out["max_theta_deg"] = math.degrees(max_angle(orbit))
    return out


@click.command()
@model_options
@click.option("--period", type=ORBIT_PERIOD, help="Period in forcing periods (default: detected).")
@click.option(
    "--initial", metavar="THETA,THETADOT", help="Initial guess at tau = 0 (default: from simulation)."
)
@click.option("--transient", type=count(0), default=500, show_default=True,
              help="Forcing periods simulated for the initial guess (without --initial).")  # fmt: skip
@json_option
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
        x0 = parse_pair(initial)
        if x0[0] > model.params["theta_hat"]:
            raise InputError(
                f"initial angle {x0[0]:g} rad is beyond the stop at theta-hat = "
                f"{math.degrees(model.params['theta_hat']):g} deg"
            )
    orb = find_orbit(model, x0, period=period, transient=transient)
    res = {"params": model_params_json(model, case), **_orbit_json(orb)}
    if as_json:
        emit_json(res)
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
        "multipliers": complex_list(g.multipliers),
        "abs_lambda": g.abs_lambda,
        "t_graze": g.phase,
        "accel": g.accel,
    }


@click.command()
@model_options
@click.option("--eta-min", type=POSITIVE, default=0.2, show_default=True, help="Lower end of the eta range.")
@click.option("--eta-max", type=POSITIVE, default=1.0, show_default=True, help="Upper end of the eta range.")
@json_option
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
    check_eta_range(eta_min, eta_max)
    bar = Progress("continuing", enabled=not as_json)
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
        emit_json(res)
        return
    if not points:
        th = math.degrees(model.params["theta_hat"])
        click.echo(f"no grazing for eta in [{eta_min:g}, {eta_max:g}] at theta-hat = {th:g} deg")
    for g in res["grazings"]:
        mu = ", ".join(f"{a:+.4f}{b:+.4f}i" for a, b in g["multipliers"])
        click.echo(f"eta = {g['eta']:.6f}: multipliers {mu}, |lambda| = {g['abs_lambda']:.4f}, "
                   f"t_graze = {g['t_graze']:.4f}")  # fmt: skip


@click.command("graze-curve")
@model_options
@click.option(
    "--start-deg", type=ANGLE_DEG, default=5.0, show_default=True, help="theta-hat where the curve starts."
)
@click.option("--eta-min", type=POSITIVE, default=0.2, show_default=True, help="Lower end of the eta range.")
@click.option("--eta-max", type=POSITIVE, default=1.0, show_default=True, help="Upper end of the eta range.")
@click.option("--max-step", type=POSITIVE, default=0.05, show_default=True, help="Largest continuation step.")
@netcdf_out_option
@json_option
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
    check_eta_range(eta_min, eta_max)
    check_out(out, ".nc")
    settings = PalcSettings(ds=min(0.02, max_step), ds_max=max_step)
    curve = grazing_curve(model, ("eta", "theta_hat"), math.radians(start_deg), search=(eta_min, eta_max),
                          settings=settings)  # fmt: skip
    if out is not None:
        save_dataset(curve.to_dataset(), out)
    fold = curve.fold
    res = {
        "params": model_params_json(model, case),
        "theta_max_deg": math.degrees(fold.model.params["theta_hat"]) if fold else None,
        "eta_at_theta_max": fold.model.params["eta"] if fold else None,
        "multipliers_at_theta_max": complex_list(fold.multipliers) if fold else None,
        "status": curve.status,
        "curve": [_grazing_json(g) for g in curve.points],
        "out": str(out) if out else None,
    }
    if as_json:
        emit_json(res)
        return
    click.echo(f"{len(curve.points)} grazing orbits from theta-hat = {start_deg:g} deg ({curve.status})")
    if fold:
        click.echo(f"theta-hat_max = {res['theta_max_deg']:.4f} deg at eta = {res['eta_at_theta_max']:.6f}: "
                   "no grazing above it")  # fmt: skip


_CONTINUE_PARAMS = {"eta": "eta", "theta-hat": "theta_hat", "alpha": "alpha", "beta": "beta", "r": "r"}


@click.command("continue")
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
@netcdf_out_option
@json_option
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
        raise InputError(f"--start and --stop must be finite and differ, got {start:g} and {stop:g}")
    if name == "theta_hat":
        for opt, v in (("--start", start), ("--stop", stop)):
            if not ANGLE_DEG.accepts(v):
                raise InputError(f"{opt} for theta-hat must be {ANGLE_DEG.describe()}, got {v:g}")
    check_out(out, ".nc")
    x0 = parse_pair(initial) if initial is not None else None
    a, b = conv(start), conv(stop)
    for v in (a, b):  # both ends within the parameter's bounds, before any work ("r = 2 is outside [0, 1]")
        model.with_params(**{name: v})
    bar = Progress("continuing", enabled=not as_json)
    try:
        branch = continue_orbit(
            model, name, a, b, x0=None if x0 is None else np.array(x0), period=period, virtual=virtual,
            settings=PalcSettings(ds=min(0.01, max_step), ds_max=max_step), switch=switch,
            progress=lambda n, v: bar(int(1000 * abs(v - a) / abs(b - a)), 1000),
        )  # fmt: skip
    finally:
        bar.close()
    if out is not None:
        save_dataset(branch.to_dataset(), out)
    back = math.degrees if name == "theta_hat" else float
    res = {
        "params": model_params_json(model, case),
        "param": cparam,
        "period": branch.period,
        "virtual": branch.virtual,
        "values": [back(v) for v in branch.values],
        "states": branch.states,
        "multipliers": [complex_list(o.multipliers) for o in branch.orbits],
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
                "multipliers": complex_list(sp_.multipliers),
                "state": sp_.orbit.state,
            }
            for sp_ in branch.special
        ],
        "status": branch.status,
        "out": str(out) if out else None,
    }
    res["max_theta_deg"] = [math.degrees(max_angle(o)) for o in branch.orbits]
    if as_json:
        emit_json(res)
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
