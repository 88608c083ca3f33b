"""``grazing normal-form``: the grazing normal form, its coefficients and the predicted scenario."""

from __future__ import annotations

from typing import Any

import click
import numpy as np

import grazing
from grazing.cli.common import (
    PENDULUM_UNFOLDING,
    check_eta_range,
    complex_list,
    emit_json,
    json_option,
    model_options,
    model_params_json,
)
from grazing.cli.validate import POSITIVE, refuse_unused


@click.command("normal-form")
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
@json_option
def normal_form_cmd(
    model: grazing.HybridModel, case: str,
    which: str, eta_min: float, eta_max: float, check: bool, as_json: bool,
) -> None:  # fmt: skip
    """Grazing normal form at a grazing of the period-1 orbit: multipliers, the
    discontinuity map's coefficients and the predicted scenario past grazing."""
    from grazing.normalform import find_grazing_point, normal_form_at, observe, predict

    refuse_unused(["eta"], True, "by normal-form: it searches eta in [--eta-min, --eta-max]")
    check_eta_range(eta_min, eta_max)
    point = find_grazing_point(model, "eta", eta_min, eta_max, which)
    nf = normal_form_at(point, PENDULUM_UNFOLDING)
    pred = predict(nf, "eta")
    b_eta, _, _ = nf.unfolding["eta"]
    res: dict[str, Any] = {
        "params": model_params_json(point.model, case),
        "which": which,
        "eta_graze": point.model.params["eta"],
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
            "unfolding_eta": b_eta,
            "unfolding_theta_hat": nf.unfolding["theta_hat"][0],
        },
    }
    if check:
        obs = observe(nf, "eta")
        res["observed"] = {"scenario": obs.scenario, "offsets": obs.offsets, "periods": obs.periods}
        res["agrees"] = obs.scenario == pred.scenario
    if as_json:
        emit_json(res)
        return
    mu = ", ".join(f"{z.real:+.4f}{z.imag:+.4f}i" for z in point.multipliers)
    click.echo(f"{which} grazing at eta = {res['eta_graze']:.6f}, t_graze = {point.phase:.4f}")
    click.echo(f"  multipliers {mu}, |lambda| = {point.abs_lambda:.4f}, kappa (M12) = {nf.kappa:+.4f}")
    click.echo(f"  discontinuity map: a = {nf.accel:.6f}, e = {np.round(nf.direction, 6).tolist()}")
    click.echo(f"  prediction: {pred.scenario} ({pred.rule})")
    if check:
        verdict = "agrees" if res["agrees"] else "differs"
        click.echo(f"  direct simulation just past grazing: {res['observed']['scenario']} ({verdict})")
