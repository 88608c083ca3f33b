"""``grazing curve``: a fold, period-doubling, Neimark-Sacker, branch-point or grazing curve in two
parameters."""

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
    stop_name_option,
    stop_option_index,
)
from grazing.cli.validate import ANGLE_DEG, FINITE, ORBIT_PERIOD, POSITIVE
from grazing.core.options import MAX_STEP
from grazing.errors import NotFoundError
from grazing.orbits.curves import CURVE_KINDS
from grazing.orbits.periodic import multipliers_text


def _point_modes(pt: Any) -> dict[str, Any]:
    """A point of a curve of a model with modes: its orbit's mode on the section and switches per period
    (a grazing curve: the grazed transition's source mode; its contact is not a switch)."""
    if pt.orbit is not None:
        m = pt.orbit.model
        return {"mode": pt.orbit.mode, "switches": [m.switch_names[j] for j in pt.orbit.switch_transitions]}
    g = pt.grazing
    m = g.model
    return {"mode": m.transition_source[m.stop_index(g.stop_name)], "switches": []}


def _range(text: str, par: grazing.Parameter, model: grazing.HybridModel) -> tuple[float, float]:
    """``--range LO,HI`` of the second parameter (display unit), which must hold its start value."""
    lo, hi = (par.from_display(v) for v in parse_pair(text, "--range", "LO,HI"))
    if not lo < hi:
        raise InputError(f"--range: LO must be below HI, got {text}")
    value = model.params[par.name]
    if not lo <= value <= hi:
        raise InputError(
            f"--range {text} excludes the start value of --param2 {par.name}: {par.show(value, 'g')} (the "
            f"curve starts there; set it with --set {par.name}=VALUE)"
        )
    return lo, hi


def _values(curve: Any, values: tuple[float, float]) -> dict[str, float]:
    """Both parameters by name, in their display units."""
    return {p.name: p.to_display(v) for p, v in zip(_parameters(curve), values)}


def _widths(curve: Any, widths: tuple[float, float]) -> dict[str, float | None]:
    """A special point's precision in each parameter, in its display unit (a width: the unit's scale
    alone); None where unknown."""
    return {p.name: None if math.isnan(w) else p.to_display(w) for p, w in zip(_parameters(curve), widths)}


def _intervals(curve: Any, interval: Any) -> dict[str, list[float]] | None:
    """A special point's bracket in each parameter, ``[low, high]`` in its display unit (None: none)."""
    if interval is None:
        return None
    return {p.name: sorted(p.to_display(v) for v in iv) for p, iv in zip(_parameters(curve), interval)}


def _parameters(curve: Any) -> tuple[grazing.Parameter, grazing.Parameter]:
    return curve.model.parameter(curve.params[0]), curve.model.parameter(curve.params[1])


@click.command("curve")
@model_options(any_model=True, modes=True)
@click.option(
    "--kind",
    type=click.Choice([str(k) for k in CURVE_KINDS]),  # (the words: click takes an enum by its names)
    required=True,
    help="The bifurcation to follow: the first one of this kind met from --start towards --stop.",
)
@click.option("--param", "cparam", required=True, metavar="NAME",
              help="The continuation parameter, searched from --start towards --stop for the bifurcation "
              "(angles in degrees).")  # fmt: skip
@click.option("--start", type=FINITE, required=True, help="Start value of --param (display unit).")
@click.option("--stop", type=FINITE, required=True, help="End value of --param (display unit).")
@click.option("--param2", "param2", required=True, metavar="NAME",
              help="The second parameter: the curve starts at its value in the model and follows the "
              "bifurcation in (--param, --param2).")  # fmt: skip
@click.option("--range", "prange", required=True, metavar="LO,HI",
              help="Interval of --param2 (display unit) in which the curve is followed, both ways from "
              "its start value.")  # fmt: skip
@click.option("--period", type=ORBIT_PERIOD, help="Period of the orbit (default: detected).")
@click.option("--initial", metavar="X1,X2,...", help="Initial guess at time 0, one number per state.")
@stop_name_option
@click.option(
    "--max-step",
    type=POSITIVE,
    default=MAX_STEP,
    show_default=True,
    help="Largest continuation step.",
)
@mode_option
@netcdf_out_option
@json_option
def curve(
    model: grazing.HybridModel,
    case: str,
    kind: str,
    cparam: str,
    start: float,
    stop: float,
    param2: str,
    prange: str,
    period: int | None,
    initial: str | None,
    stop_name: str | None,
    max_step: float,
    mode: str | None,
    out: Path | None,
    overwrite: bool,
    as_json: bool,
) -> None:
    """Follow a fold, period-doubling, Neimark-Sacker, branch point or grazing of a periodic orbit in two
    parameters, with its codimension-two points (cusps, fold-flips, resonances, where it meets a grazing).

    The orbit is continued in --param from --start towards --stop up to its first bifurcation of
    --kind, which is then followed in (--param, --param2) while --param2 stays in --range."""
    from grazing.orbits import PalcSettings, follow_curve

    p1 = model_parameter(model, cparam, "--param")
    p2 = model_parameter(model, param2, "--param2")
    if p1.name == p2.name:
        raise InputError(f"--param2 must differ from --param (both are {p1.name})")
    refuse_varied([p1.name], f"with --param {cparam}: the branch starts at --start")
    watch = stop_option_index(model, stop_name)
    check_mode(model, mode)
    if start == stop:
        raise InputError(f"--start and --stop must differ, got {start:g} and {stop:g}")
    if p1.name == "theta_hat" and model.name == "pendulum":
        for opt, v in (("--start", start), ("--stop", stop)):
            if not ANGLE_DEG.accepts(v):
                raise InputError(f"{opt} for theta-hat must be {ANGLE_DEG.describe()}, got {v:g}")
    a, b = p1.from_display(start), p1.from_display(stop)
    for v in (a, b):  # both ends within the parameter's bounds, before any work
        model.with_params(**{p1.name: v})
    lo, hi = _range(prange, p2, model)
    check_out(out, ".nc", overwrite=overwrite)
    x0 = parse_state(initial, model.with_params(**{p1.name: a}), mode) if initial is not None else None
    bars = {"branch": Progress("continuing", enabled=not as_json),
            "curve": Progress("following the curve", enabled=not as_json)}  # fmt: skip
    seen = [model.params[p2.name]] * 2

    def progress(stage: str, points: int, v1: float, v2: float) -> None:
        if stage == "branch":
            bars[stage](int(1000 * abs(v1 - a) / abs(b - a)), 1000)
        else:
            bars["branch"].close()
            seen[:] = [min(seen[0], v2), max(seen[1], v2)]
            bars[stage](int(1000 * (seen[1] - seen[0]) / (hi - lo)), 1000)

    try:
        orbit = None
        if mode is not None:  # (follow_curve starts from an orbit in the mode asked for)
            from grazing.orbits import find_orbit

            orbit = find_orbit(model.with_params(**{p1.name: a}), x0, period=period, mode=mode)
        result = follow_curve(
            model, kind, p1.name, a, b, p2.name, (lo, hi), x0=None if x0 is None or orbit else np.array(x0),
            orbit=orbit, period=period, stop_name=watch if stop_name is not None else None,
            settings=PalcSettings(ds=min(0.01, max_step), ds_max=max_step), progress=progress,
        )  # fmt: skip
    except NotFoundError as exc:
        raise InputError(f"--kind {kind}: {exc}") from None
    finally:
        for bar in bars.values():
            bar.close()
    if out is not None:
        save_dataset(result.to_dataset(), out, overwrite)
    res = {
        "kind": kind,
        "params": [p1.name, p2.name],
        "points": [
            {**_values(result, pt.values), "multipliers": complex_list(pt.multipliers), "state": pt.state,
             "period": pt.period, "impacts": pt.impacts, "section_time": pt.section_time,
             "stable": pt.stable, "accuracy": pt.accuracy}
            for pt in result.points
        ],
        "special": [
            {"kind": sp_.kind, **_values(result, sp_.values), "located": sp_.located,
             "multipliers": complex_list(sp_.multipliers), "index": sp_.index,
             "precision": _widths(result, sp_.precision), "interval": _intervals(result, sp_.interval)}
            for sp_ in result.special
        ],
        "status": result.status,
        "outcomes": None if result.outcomes is None else [str(o) for o in result.outcomes],
        "start": {**_values(result, result.points[result.start_index].values), "index": result.start_index},
        "model": model.name,
        "model_params": model_params_json(model, case),
        "virtual": result.virtual,
        "out": str(out) if out else None,
    }  # fmt: skip
    if model.has_modes:  # (the JSON of a model of one mode stays as it was)
        for row, pt in zip(res["points"], result.points):
            row.update(_point_modes(pt))
    if as_json:
        emit_json(res)
        return
    where = ", ".join(p.show(v, ".8g") for p, v in zip((p1, p2), result.points[result.start_index].values))
    click.echo(
        f"{len(result)} points of the {kind} curve of the period-{result.period} orbit in ({p1.name}, "
        f"{p2.name}) from {where}; {result.status}"
    )
    if model.has_modes and len(result):
        first = _point_modes(result.points[result.start_index])
        switches = ", ".join(first["switches"]) or "none"
        click.echo(f"  at the start: mode {first['mode']}, switches per period: {switches}")
    for sp_ in result.special:
        at = ", ".join(p.show(v, ".8g") for p, v in zip((p1, p2), sp_.values))
        mu = multipliers_text(sp_.multipliers)
        note = "" if sp_.located else " (not located exactly)"
        click.echo(f"  {sp_.kind:22s} {at}   multipliers {mu}{note}")
    imprecise = result.imprecise()
    if imprecise:
        worst = max(result.points[i].accuracy for i in imprecise)
        click.echo(
            f"note: the multipliers of {len(imprecise)} points are known only to {worst:.1g}: their "
            "monodromy is far from normal (as next to a grazing, where the saltation matrix holds 1/v, "
            "v the impact speed) and double precision does no better"
        )
    if out is not None:
        click.echo(f"curve saved to {out}")
