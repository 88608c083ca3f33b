"""``grazing normal-form``: the grazing normal form, its coefficients and the predicted scenario."""

from __future__ import annotations

from typing import Any

import click
import numpy as np

import grazing
from grazing.cli.common import (
    PENDULUM_UNFOLDING,
    InputError,
    complex_list,
    emit_json,
    json_option,
    model_options,
    model_params_json,
    search_range,
    stop_name_option,
    stop_option_index,
)
from grazing.cli.orbits import initial_option, range_start_state
from grazing.cli.validate import POSITIVE
from grazing.orbits.periodic import multipliers_text


@click.command("normal-form")
@model_options(any_model=True)
@click.option(
    "--which",
    type=click.Choice(["first", "second"]),
    default="first",
    show_default=True,
    help="First or second grazing in increasing --param (the pendulum: in eta at this theta-hat).",
)
@click.option("--eta-min", type=POSITIVE, default=0.2, show_default=True, help="Lower end of the eta search.")
@click.option("--eta-max", type=POSITIVE, default=1.0, show_default=True, help="Upper end of the eta search.")
@click.option(
    "--param",
    "gparam",
    default=None,
    metavar="NAME",
    help="Any parameter of the model to search (pendulum default: eta over --eta-min/--eta-max).",
)
@click.option(
    "--range", "prange", default=None, metavar="LO,HI", help="The interval of --param (display unit)."
)
@stop_name_option
@initial_option
@click.option(
    "--check", is_flag=True, help="Also simulate just past grazing and compare with the prediction."
)
@json_option
def normal_form_cmd(
    model: grazing.HybridModel, case: str, which: str, eta_min: float, eta_max: float, gparam: str | None,
    prange: str | None, stop_name: str | None, initial: str | None, check: bool, as_json: bool,
) -> None:  # fmt: skip
    """Grazing normal form at a grazing of the period-1 orbit: multipliers, the
    discontinuity map's coefficients and the predicted scenario past grazing."""
    from grazing.normalform import find_grazing_point, normal_form_at, observe, predict
    from grazing.normalform.discontinuity import no_contact_direction

    stop = stop_option_index(model, stop_name)
    if model.symbolic.stops[stop].contact_direction is None:  # (before the search, not after it)
        raise InputError(f"--model: {no_contact_direction(model, stop)}")
    par, lo, hi, pendulum = search_range(model, "normal-form", gparam, prange, eta_min, eta_max)
    x0 = range_start_state(initial, model, {par.name: lo})
    point = find_grazing_point(model, par.name, lo, hi, which, stop_name=stop, x0=x0)
    nf = normal_form_at(point, PENDULUM_UNFOLDING if pendulum else (par.name,))
    pred = predict(nf, par.name)
    res: dict[str, Any] = {
        "params": model_params_json(point.model, case),
        "which": which,
        "param": par.name,
        "value": par.to_display(point.model.params[par.name]),
        "stop": point.stop_name,
        "t_graze": point.phase,
        "multipliers": complex_list(point.multipliers),
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
            f"unfolding_{par.name}": nf.unfolding[par.name][0],
        },
    }
    if pendulum:
        res["eta_graze"] = point.model.params["eta"]
        res["coefficients"]["unfolding_theta_hat"] = nf.unfolding["theta_hat"][0]
    if check:
        obs = observe(nf, par.name)
        res["observed"] = {"scenario": obs.scenario, "offsets": obs.offsets, "periods": obs.periods}
        res["agrees"] = obs.scenario == pred.scenario
    if as_json:
        emit_json(res)
        return
    mu = multipliers_text(point.multipliers)
    where = "" if point.stop_name == "stop" else f" (stop {point.stop_name})"
    click.echo(f"{which} grazing at {par.show(point.model.params[par.name], '.6f')}{where}, "
               f"t_graze = {point.phase:.4f}")  # fmt: skip
    click.echo(f"  multipliers {mu}, |lambda| = {point.abs_lambda:.4f}, kappa (M12) = {nf.kappa:+.4f}")
    click.echo(f"  discontinuity map: a = {nf.accel:.6f}, e = {np.round(nf.direction, 6).tolist()}")
    click.echo(f"  prediction: {pred.scenario} ({pred.rule})")
    if check:
        verdict = "agrees" if res["agrees"] else "differs"
        click.echo(f"  direct simulation just past grazing: {res['observed']['scenario']} ({verdict})")
