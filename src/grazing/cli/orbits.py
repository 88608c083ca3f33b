"""``grazing orbit``, ``graze``, ``graze-curve``, ``continue``: periodic orbits, grazings, branches."""

from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import Any

import click
import numpy as np

import grazing
from grazing.cli.common import (
    InputError,
    Progress,
    check_eta_range,
    check_mode,
    check_out,
    complex_list,
    emit_json,
    json_option,
    mode_option,
    model_options,
    model_parameter,
    model_params_json,
    netcdf_out_option,
    parse_pair,
    parse_state,
    refuse_varied,
    save_dataset,
    search_range,
    stop_name_option,
    stop_option_index,
)
from grazing.cli.hints import flag_hints
from grazing.cli.validate import ANGLE_DEG, FINITE, ORBIT_PERIOD, POSITIVE, count, refuse_unused
from grazing.core.options import DEFAULT_TRANSIENT, GRAZING_CURVE_MAX_STEP, MAX_STEP
from grazing.errors import GrazingWarning
from grazing.models.pendulum import max_angle
from grazing.orbits.periodic import multipliers_text


def not_isolated_note(orbit: Any) -> str:
    """One line on an orbit that is not isolated (``orbit.isolated`` false)."""
    from grazing.orbits.shooting import kept_directions

    what = "a plane of periodic states" if kept_directions(orbit.monodromy) >= 2 else "a Jordan block"
    return (
        f"the orbit is not isolated (its multiplier 1 is double: {what}), so it is neither stable nor "
        "unstable and no branch can be continued from it"
    )


def _orbit_json(orbit: Any) -> dict[str, Any]:
    out = {
        "period": orbit.period,
        "impacts": orbit.impacts,
        "state": orbit.state,
        "multipliers": complex_list(orbit.multipliers),
        "abs_multipliers": np.abs(orbit.multipliers),
        "stable": orbit.stable,
        "isolated": orbit.isolated,
        "residual": orbit.residual,
        "newton_iterations": len(orbit.residuals) - 1,
        "min_impact_speed": None if math.isnan(orbit.min_impact_speed) else orbit.min_impact_speed,
        "impacts_per_stop": {
            name: int(np.sum(orbit.impact_stops == j)) for j, name in enumerate(orbit.model.stop_names)
        },
    }
    if orbit.model.name == "pendulum":
        out["max_theta_deg"] = math.degrees(max_angle(orbit))
    if orbit.model.has_modes:  # (the JSON of a model of one mode stays as it was)
        out.update(orbit_modes_json(orbit))
    return out


def orbit_modes_json(orbit: Any) -> dict[str, Any]:
    """A model with modes: the orbit's mode on the section and its switches of mode over one period."""
    m = orbit.model
    return {
        "mode": orbit.mode,
        "switches": [
            {
                "t": float(t),
                "transition": m.switch_names[j],
                "from": m.switch_sources[j],
                "to": m.switch_targets[j],
            }
            for t, j in zip(orbit.switch_times, orbit.switch_transitions)
        ],
    }


def orbit_modes_text(orbit: Any) -> str:
    """One line on the mode and switches of an orbit of a model with modes."""
    m = orbit.model
    n = len(orbit.switch_times)
    switches = ", ".join(
        f"{m.switch_names[j]} at {m.time_label} = {t:.6f}"
        for t, j in zip(orbit.switch_times, orbit.switch_transitions)
    )
    return f"mode {orbit.mode} on the section; {n} switch{'es' * (n != 1)} per period" + (
        f": {switches}" if n else ""
    )


initial_option = click.option(
    "--initial",
    metavar="X1,X2,...",
    help="Guess of the nonimpacting orbit at time 0 (one number per state), with the parameters at the "
    "start of the search (default: simulated from rest with the stops ignored, which reaches only a "
    "stable orbit: give one where that orbit is unstable).",
)


def range_start_state(
    initial: str | None, model: grazing.HybridModel, start: dict[str, float]
) -> np.ndarray | None:
    """``--initial`` of a grazing search: a state of ``model`` with the parameters ``start`` (or None)."""
    return None if initial is None else parse_state(initial, model.with_params(**start))


@click.command()
@model_options(any_model=True, modes=True)
@click.option("--period", type=ORBIT_PERIOD, help="Period in forcing periods (default: detected).")
@click.option(
    "--initial",
    metavar="X1,X2,...",
    help="Initial guess at time 0, one per state (default: simulated from rest; give one where that "
    "motion sticks, diverges or settles on another orbit).",
)
@click.option("--transient", type=count(0), default=DEFAULT_TRANSIENT, show_default=True,
              help="Forcing periods simulated for the initial guess (without --initial).")  # fmt: skip
@mode_option
@json_option
def orbit(
    model: grazing.HybridModel,
    case: str,
    period: int | None,
    initial: str | None,
    transient: int,
    mode: str | None,
    as_json: bool,
) -> None:
    """Find a periodic orbit by Newton shooting; print its multipliers and stability."""
    from grazing.orbits import find_orbit

    refuse_unused(["transient"], initial is not None, "with --initial (it runs the simulation that guesses)")
    check_mode(model, mode)
    x0 = parse_state(initial, model, mode) if initial is not None else None
    orb = find_orbit(model, x0, period=period, transient=transient, mode=mode)
    res = {"params": model_params_json(model, case), **_orbit_json(orb)}
    if as_json:
        emit_json(res)
        return
    kind = "stable" if orb.stable else ("unstable" if orb.isolated else "not isolated")
    extra = f"; max theta {res['max_theta_deg']:.6f} deg" if "max_theta_deg" in res else ""
    if model.n_stops > 1 and (orb.impacts or not model.has_modes):  # (not switches without a reset)
        extra += " (" + ", ".join(f"{k}: {v}" for k, v in res["impacts_per_stop"].items()) + ")"
    click.echo(f"period-{orb.period} orbit with {orb.impacts} impact(s) per period, {kind}{extra}")
    state = ", ".join(f"{nm} = {v:.12f}" for nm, v in zip(model.state_names, orb.state))
    click.echo(f"state at {model.time_label} = 0: {state}")
    if model.has_modes:
        click.echo(orbit_modes_text(orb))
    for z in orb.multipliers:
        click.echo(f"  multiplier {z.real:+.6f} {z.imag:+.6f}i   |mu| = {abs(z):.6f}")
    if not orb.isolated:
        click.echo(f"  note: {not_isolated_note(orb)}")


def _grazing_json(g: Any, param: str | None = None) -> dict[str, Any]:
    out: dict[str, Any] = {}
    if g.model.name == "pendulum":
        out["eta"] = g.model.params["eta"]
        out["theta_hat_deg"] = math.degrees(g.model.params["theta_hat"])
    if param is not None:
        out["value"] = g.model.parameter(param).to_display(g.model.params[param])
    out.update(
        {
            "stop": g.stop_name,
            "multipliers": complex_list(g.multipliers),
            "abs_lambda": g.abs_lambda,
            "t_graze": g.phase,
            "accel": g.accel,
            "crossed": list(g.crossed),
        }
    )
    if g.model.has_modes:  # the mode whose orbit touches the transition's guard (one mode: no key)
        out["mode"] = g.model.transition_source[g.model.stop_index(g.stop_name)]
    return out


@click.command()
@model_options(any_model=True, modes=True)
@click.option("--eta-min", type=POSITIVE, default=0.2, show_default=True, help="Lower end of the eta range.")
@click.option("--eta-max", type=POSITIVE, default=1.0, show_default=True, help="Upper end of the eta range.")
@click.option(
    "--param",
    "gparam",
    default=None,
    metavar="NAME",
    help="Any parameter of the model to search (default for the pendulum: eta, over --eta-min/--eta-max).",
)
@click.option(
    "--range",
    "prange",
    default=None,
    metavar="LO,HI",
    help="The interval of --param to search (in its display unit: degrees for angles).",
)
@stop_name_option
@initial_option
@mode_option
@json_option
def graze(
    model: grazing.HybridModel,
    case: str,
    eta_min: float,
    eta_max: float,
    gparam: str | None,
    prange: str | None,
    stop_name: str | None,
    initial: str | None,
    mode: str | None,
    as_json: bool,
) -> None:
    """Every grazing of the period-1 nonimpacting orbit with a stop, for a parameter in a range."""
    from grazing.orbits import find_grazings
    from grazing.orbits.grazing import unlocated_grazing_text

    stop = stop_option_index(model, stop_name)
    check_mode(model, mode)
    par, lo, hi, _ = search_range(model, "graze", gparam, prange, eta_min, eta_max)
    x0 = range_start_state(initial, model, {par.name: lo})
    bar = Progress("continuing", enabled=not as_json)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", GrazingWarning)  # (said below, with each grazing)
            points, branch = find_grazings(
                model, par.name, lo, hi, x0=x0, stop_name=stop, mode=mode,
                progress=lambda n, v: bar(int(1000 * (v - lo) / (hi - lo)), 1000),
            )  # fmt: skip
    finally:
        bar.close()
    unlocated = [s for s in branch.special if s.kind == "grazing" and s.grazing is None and s.stop == stop]
    res = {
        "params": model_params_json(model, case),
        "param": par.name,
        "range": [par.to_display(lo), par.to_display(hi)],
        "stop": model.stop_names[stop],
        "grazings": [_grazing_json(g, par.name) for g in points],
        "folds": [par.to_display(s.param) for s in branch.special if s.kind == "fold"],
        "unlocated": [par.to_display(s.param) for s in unlocated],  # (bracketed, equations not converged)
    }
    if par.name == "eta":
        res["eta_range"] = [lo, hi]
    if as_json:
        emit_json(res)
        return
    if not points and not unlocated:
        click.echo(f"no grazing with stop {model.stop_names[stop]!r} for {par.show_range(lo, hi)}")
    for sp_ in unlocated:
        click.echo(f"note: {unlocated_grazing_text(model, par.name, sp_)}")
    for point, g in zip(points, res["grazings"]):
        mu = multipliers_text(g["multipliers"])
        where = (
            ""
            if g["stop"] == "stop"
            else f" (stop {g['stop']}{', from mode ' + g['mode'] if 'mode' in g else ''})"
        )
        click.echo(f"{par.show(point.model.params[par.name], '.6f')}{where}: multipliers {mu}, "
                   f"|lambda| = {g['abs_lambda']:.4f}, t_graze = {g['t_graze']:.4f}")  # fmt: skip
        if g["crossed"]:
            click.echo(f"  note: this orbit passes through stop {', '.join(g['crossed'])}, which the system "
                       "hits first: not a motion of the system")  # fmt: skip


@click.command("graze-curve")
@model_options(any_model=True, modes=True)
@click.option(
    "--start-deg", type=ANGLE_DEG, default=5.0, show_default=True, help="theta-hat where the curve starts."
)
@click.option("--params", "gparams", default=None, metavar="P1,P2",
              help="Any two parameters (pendulum default: eta,theta_hat): P1 is searched over --range, "
              "P2 starts at --start-value and moves along the curve.")  # fmt: skip
@click.option("--range", "prange", default=None, metavar="LO,HI", help="Interval of P1 (display unit).")
@click.option(
    "--start-value", type=FINITE, default=None, help="Value of P2 where the curve starts (display unit)."
)
@stop_name_option
@click.option("--eta-min", type=POSITIVE, default=0.2, show_default=True, help="Lower end of the eta range.")
@click.option("--eta-max", type=POSITIVE, default=1.0, show_default=True, help="Upper end of the eta range.")
@click.option("--max-step", type=POSITIVE, default=GRAZING_CURVE_MAX_STEP, show_default=True,
              help="Largest continuation step.")  # fmt: skip
@initial_option
@netcdf_out_option
@json_option
def graze_curve(
    model: grazing.HybridModel,
    case: str,
    start_deg: float,
    eta_min: float,
    eta_max: float,
    max_step: float,
    gparams: str | None,
    prange: str | None,
    start_value: float | None,
    stop_name: str | None,
    initial: str | None,
    out: Path | None,
    overwrite: bool,
    as_json: bool,
) -> None:
    """Two-parameter continuation of grazing (the pendulum: in (eta, theta-hat), with theta-hat_max)."""
    from grazing.orbits import PalcSettings, grazing_curve

    stop = stop_option_index(model, stop_name)
    generic = gparams is not None or prange is not None or start_value is not None or model.name != "pendulum"
    if not generic:
        refuse_varied(["eta"], "by graze-curve: it searches eta in [--eta-min, --eta-max]")
        refuse_varied(["theta_hat"], "by graze-curve: the curve starts at --start-deg")
        check_eta_range(eta_min, eta_max)
        p1, p2 = model.parameter("eta"), model.parameter("theta_hat")
        lo, hi, start = eta_min, eta_max, math.radians(start_deg)
    else:
        refuse_unused(["eta_min", "eta_max", "start_deg"], True, "with --params/--range/--start-value")
        if gparams is None or prange is None or start_value is None:
            raise InputError(
                "graze-curve needs --params P1,P2, --range LO,HI and --start-value (for this model)"
            )
        names = [t for t in gparams.split(",") if t.strip()]
        if len(names) != 2:
            raise InputError(f"--params {gparams!r}: expected two parameter names P1,P2")
        p1, p2 = (model_parameter(model, t, "--params") for t in names)
        if p1.name == p2.name:
            raise InputError("--params: the two parameters must differ")
        refuse_varied([p1.name, p2.name], "by graze-curve: it moves both --params")
        lo, hi = (p1.from_display(v) for v in parse_pair(prange, "--range", "LO,HI"))
        if not lo < hi:
            raise InputError(f"--range: LO must be below HI, got {prange}")
        start = p2.from_display(start_value)
        model.with_params(**{p2.name: start})
    x0 = range_start_state(initial, model, {p1.name: lo, p2.name: start})
    check_out(out, ".nc", overwrite=overwrite)
    settings = PalcSettings(ds=min(0.02, max_step), ds_max=max_step)
    curve = grazing_curve(
        model, (p1.name, p2.name), start, search=(lo, hi), x0=x0, settings=settings, stop_name=stop
    )
    if out is not None:
        save_dataset(curve.to_dataset(), out, overwrite)
    fold = curve.fold
    res: dict[str, Any] = {
        "params": model_params_json(model, case),
        "curve_params": [p1.name, p2.name],
        "stop": model.stop_names[stop],
        "fold": {p.name: p.to_display(fold.model.params[p.name]) for p in (p1, p2)} if fold else None,
        "multipliers_at_fold": complex_list(fold.multipliers) if fold else None,
        "status": curve.status,
        "curve": [{**_grazing_json(g), p1.name: p1.to_display(g.model.params[p1.name]),
                   p2.name: p2.to_display(g.model.params[p2.name])} for g in curve.points],
        "out": str(out) if out else None,
    }  # fmt: skip
    if not generic:  # the pendulum's keys
        res["theta_max_deg"] = math.degrees(fold.model.params["theta_hat"]) if fold else None
        res["eta_at_theta_max"] = fold.model.params["eta"] if fold else None
        res["multipliers_at_theta_max"] = complex_list(fold.multipliers) if fold else None
    if as_json:
        emit_json(res)
        return
    if not generic:
        click.echo(f"{len(curve.points)} grazing orbits from theta-hat = {start_deg:g} deg ({curve.status})")
        if fold:
            tmax, eta_at = res["theta_max_deg"], res["eta_at_theta_max"]
            click.echo(f"theta-hat_max = {tmax:.4f} deg at eta = {eta_at:.6f}: no grazing above it")
        return
    click.echo(f"{len(curve.points)} grazing orbits from {p2.show(start, 'g')} ({curve.status})")
    if fold:
        where = ", ".join(p.show(fold.model.params[p.name], ".6g") for p in (p1, p2))
        click.echo(f"fold of the grazing curve (largest {p2.name}) at {where}: no grazing beyond it")


@click.command("continue")
@model_options(any_model=True, modes=True)
@click.option("--param", "cparam", required=True, metavar="NAME",
              help="Parameter to vary: any of the model's (the pendulum's eta, theta-hat, alpha, beta, r); "
              "angles in degrees.")  # fmt: skip
@click.option("--start", type=FINITE, required=True, help="Start value of the parameter (display unit).")
@click.option("--stop", type=FINITE, required=True, help="End value of the parameter (display unit).")
@click.option("--period", type=ORBIT_PERIOD, help="Period of the orbit (default: detected).")
@click.option("--initial", metavar="X1,X2,...", help="Initial guess at time 0, one number per state.")
@stop_name_option
@click.option("--virtual/--physical", default=None,
              help="Ignore the stops (default: for a nonimpacting starting orbit, without "
              "--switch).")  # fmt: skip
@click.option(
    "--max-step",
    type=POSITIVE,
    default=MAX_STEP,
    show_default=True,
    help="Largest continuation step.",
)
@click.option("--switch", is_flag=True,
              help="Switch branches, each switch starting a new branch segment: at the first "
              "period-doubling or branch point met, onto the period-2n orbit born there or the other "
              "branch through it (both ways); at every grazing where the impact sequence changes, onto "
              "the orbit with the new sequence instead of ending there (a physical branch only: not "
              "with --virtual).")  # fmt: skip
@mode_option
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
    stop_name: str | None,
    virtual: bool | None,
    max_step: float,
    switch: bool,
    mode: str | None,
    out: Path | None,
    overwrite: bool,
    as_json: bool,
) -> None:
    """Pseudo-arclength continuation of a periodic orbit, with folds, branch points,
    period-doublings, Neimark-Sacker points and grazings located; a stability change that none
    explains is reported as unlocated.  A branch of an impacting orbit ends at the grazing where
    its impact sequence changes (see --switch)."""
    from grazing.orbits import PalcSettings, continue_orbit

    par = model_parameter(model, cparam)
    name = par.name
    refuse_varied([name], f"with --param {cparam}: the branch starts at --start")
    refuse_unused(
        ["switch"], virtual is True, "with --virtual: a virtual branch ignores the stops, so its impact "
        "sequence never changes (it is followed through its grazings); branches are switched on the "
        "physical orbit",
    )  # fmt: skip
    watch = stop_option_index(model, stop_name)
    check_mode(model, mode)
    if start == stop:
        raise InputError(f"--start and --stop must be finite and differ, got {start:g} and {stop:g}")
    if name == "theta_hat" and model.name == "pendulum":
        for opt, v in (("--start", start), ("--stop", stop)):
            if not ANGLE_DEG.accepts(v):
                raise InputError(f"{opt} for theta-hat must be {ANGLE_DEG.describe()}, got {v:g}")
    check_out(out, ".nc", overwrite=overwrite)
    x0 = (
        parse_state(initial, model.with_params(**{name: par.from_display(start)}), mode)
        if initial is not None
        else None
    )
    a, b = par.from_display(start), par.from_display(stop)
    for v in (a, b):  # both ends within the parameter's bounds, before any work ("r = 2 is outside [0, 1]")
        model.with_params(**{name: v})
    bar = Progress("continuing", enabled=not as_json)
    try:
        branch = continue_orbit(
            model, name, a, b, x0=None if x0 is None else np.array(x0), period=period, virtual=virtual,
            settings=PalcSettings(ds=min(0.01, max_step), ds_max=max_step), switch=switch, stop_name=watch,
            mode=mode, progress=lambda n, v: bar(int(1000 * abs(v - a) / abs(b - a)), 1000),
        )  # fmt: skip
    finally:
        bar.close()
    if out is not None:
        save_dataset(branch.to_dataset(), out, overwrite)
    back = par.to_display
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
        "periods": branch.periods,
        "section_times": branch.sections,
        "switch": switch,
        "special": [
            {
                "kind": sp_.kind,
                "value": back(sp_.param),
                **({"stop": model.stop_names[sp_.stop]} if sp_.kind in ("grazing", "double grazing") else {}),
                **({"between": [back(v) for v in sp_.between]} if sp_.between is not None else {}),
                **({"note": sp_.note} if sp_.note else {}),
                **({"angle": sp_.angle} if sp_.kind == "neimark-sacker" else {}),
                "precision": None if math.isnan(sp_.precision) else back(sp_.precision),  # (a width: linear)
                "interval": None if sp_.interval is None else sorted(back(v) for v in sp_.interval),
                "index": sp_.index,
                "multipliers": complex_list(sp_.multipliers),
                "state": sp_.orbit.state,
                "switched": sp_.switched,
            }
            for sp_ in branch.special
        ],
        "segment_status": [flag_hints(s) for s in branch.segment_status],
        "status": flag_hints(branch.status),
        "out": str(out) if out else None,
    }
    if model.name == "pendulum":
        res["max_theta_deg"] = [math.degrees(max_angle(o)) for o in branch.orbits]
    if model.has_modes:  # (the JSON of a model of one mode stays as it was)
        res["modes"] = [o.mode for o in branch.orbits]
        res["switches"] = [[model.switch_names[j] for j in o.switch_transitions] for o in branch.orbits]
    if as_json:
        emit_json(res)
        return
    kind = "virtual (stop ignored)" if branch.virtual else "physical"
    segs = len(branch.segment_status)
    more = ""
    if segs > 1:
        kinds = dict.fromkeys(sp_.kind for sp_ in branch.special if sp_.switched)
        periods = sorted(set(branch.periods.tolist()))
        listed = f"period{'s' * (len(periods) > 1)} {', '.join(map(str, periods))}"
        more = f" in {segs} segments (switched at: {', '.join(kinds)}; {listed})"
    click.echo(f"{len(branch)} points of the period-{branch.period} orbit{more}, {kind}; {res['status']}")
    if model.has_modes and len(branch):
        ends = (("first", 0), ("last", -1)) if len(branch) > 1 else (("first", 0),)
        shown = [f"{w} point: mode {res['modes'][i]}, switches per period: "
                 f"{', '.join(res['switches'][i]) or 'none'}" for w, i in ends]  # fmt: skip
        click.echo("  " + "; ".join(shown))
    for point, sp_ in zip(branch.special, res["special"]):
        if point.between is not None:  # an unlocated stability change: what was seen, in words
            click.echo(f"  {sp_['kind']:16s} {point.note}")
            continue
        mu = multipliers_text(sp_["multipliers"])
        on = f" (stop {sp_['stop']})" if sp_.get("stop", "stop") != "stop" else ""  # as graze prints it
        switched = "   (switched here)" if point.switched else (f"   ({point.note})" if point.note else "")
        angle = f"   angle {point.angle:.6g} rad" if "angle" in sp_ else ""
        click.echo(
            f"  {sp_['kind']:16s} {par.show(point.param, '.8g')}   multipliers {mu}{angle}{on}{switched}"
        )
    if segs > 1:
        for i, (origin, status) in enumerate(zip(branch.segment_origin, res["segment_status"])):
            at = branch.special[origin] if origin >= 0 else None
            start = f" (from the {at.kind} at {par.show(at.param, '.8g')})" if at is not None else ""
            period = branch.periods[branch.segments.index(i)] if i in branch.segments else branch.period
            click.echo(f"  segment {i}, period {period}{start}: {status}")
    if out is not None:
        click.echo(f"branch saved to {out}")
