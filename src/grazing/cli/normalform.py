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
@model_options(any_model=True, modes=True)
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
    from grazing.normalform import normal_form_at, observe, predict
    from grazing.normalform.discontinuity import no_contact_direction

    stop = stop_option_index(model, stop_name)
    if model.has_modes and not model.symbolic.resets[stop]:  # a switching surface: the switch's map
        _switching_form(model, case, which, eta_min, eta_max, gparam, prange, stop, initial, check, as_json)
        return
    if model.symbolic.stops[stop].contact_direction is None:  # (before the search, not after it)
        raise InputError(f"--model: {no_contact_direction(model, stop)}")
    par, pendulum, point, res = _located_grazing(
        model, case, which, eta_min, eta_max, gparam, prange, stop, initial
    )
    nf = normal_form_at(point, PENDULUM_UNFOLDING if pendulum else (par.name,))
    pred = predict(nf, par.name)
    res |= {
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


def _located_grazing(
    model: grazing.HybridModel, case: str, which: str, eta_min: float, eta_max: float, gparam: str | None,
    prange: str | None, stop: int, initial: str | None,
) -> tuple[Any, bool, Any, dict[str, Any]]:  # fmt: skip
    """The grazing of stop ``stop`` searched over ``--param``/``--range`` (the pendulum's eta by default):
    the parameter, whether it is the pendulum's search, the :class:`~grazing.normalform.GrazingPoint`, and
    the ``--json`` fields every normal form begins with."""
    from grazing.normalform import find_grazing_point

    par, lo, hi, pendulum = search_range(model, "normal-form", gparam, prange, eta_min, eta_max)
    x0 = range_start_state(initial, model, {par.name: lo})
    point = find_grazing_point(model, par.name, lo, hi, which, stop_name=stop, x0=x0)
    head: dict[str, Any] = {
        "params": model_params_json(point.model, case),
        "which": which,
        "param": par.name,
        "value": par.to_display(point.model.params[par.name]),
        "stop": point.stop_name,
        "t_graze": point.phase,
        "multipliers": complex_list(point.multipliers),
        "abs_lambda": point.abs_lambda,
    }
    return par, pendulum, point, head


def _switching_form(
    model: grazing.HybridModel, case: str, which: str, eta_min: float, eta_max: float, gparam: str | None,
    prange: str | None, stop: int, initial: str | None, check: bool, as_json: bool,
) -> None:  # fmt: skip
    """``normal-form`` at a grazing of a switching surface without a reset (a model with modes): the
    switch's discontinuity map ``D(x) = x - (4/3) sqrt(2 / a) delta^(3/2) w`` (no impact law, so no
    prediction of the scenario past grazing yet)."""
    from grazing.normalform.switching import switching_map_at

    name = model.stop_names[stop]
    if check:
        raise InputError(
            f"--check: the scenario past the grazing of switching surface {name!r} (no reset) is not "
            "predicted yet, so there is nothing to check; its discontinuity map is printed without --check"
        )
    par, _, point, res = _located_grazing(model, case, which, eta_min, eta_max, gparam, prange, stop, initial)
    try:
        zdm = switching_map_at(point.model, point.stop, point.contact, point.t_graze)
    except (grazing.InvalidParameterError, grazing.InvalidStateError) as exc:
        raise InputError(f"--stop-name {name}: {exc}") from None
    res |= {
        "mode": model.transition_source[stop],
        "switching_map": {
            "contact_state": zdm.contact,
            "accel": zdm.accel,
            "jump": zdm.jump,
            "coefficient": zdm.coefficient,
        },
    }
    if as_json:
        emit_json(res)
        return
    mu = multipliers_text(point.multipliers)
    click.echo(f"{which} grazing of switching surface {name!r} (from mode {res['mode']}) at "
               f"{par.show(point.model.params[par.name], '.6f')}, t_graze = {point.phase:.4f}")  # fmt: skip
    click.echo(f"  multipliers {mu}, |lambda| = {point.abs_lambda:.4f}")
    click.echo(
        f"  switch's discontinuity map: x -> x - {zdm.coefficient:.6f} delta^(3/2) w, a = {zdm.accel:.6f}, "
        f"w = {np.round(zdm.jump, 6).tolist()} (no reset: a 3/2-power correction)"
    )
    click.echo("  prediction: not available yet for a switching surface (an impact's rule does not apply)")
