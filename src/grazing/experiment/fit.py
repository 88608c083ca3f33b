"""The paper's fit of the restitution ``r`` and the damping ``beta`` (section 3).

The measured damping ``D`` fixes a curve in the ``(r, beta)`` plane (fig 4b);
the paper removed the remaining freedom by choosing the point of that curve
whose primary grazing bifurcation at ``theta_hat = 40 deg`` happens at the
observed ``eta ~ 0.445``.

The primary grazing is that of the nonimpacting period-one orbit, which never
touches the stop before grazing: its ``eta`` depends on ``alpha``, ``beta`` and
``theta_hat`` only, not on ``r``.  So the fit separates: ``beta`` is the root
of ``eta_graze(beta) = eta_observed`` (a one-dimensional root-finding, each
evaluation one :func:`grazing.orbits.find_grazings`), and ``r`` is then the
point of the equal-damping curve at that ``beta``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from grazing.errors import InvalidParameterError
from grazing.experiment.damping import PAPER_DAMPING, Relation, beta_for_damping, r_for_damping
from grazing.models.pendulum import ALPHA

PRIMARY_ETA_RANGE = (0.2, 0.5)
"""Where the primary grazing is searched (below the primary resonance at eta = 1/2)."""


def grazing_eta(
    theta_hat_deg: float,
    beta: float,
    *,
    alpha: float = ALPHA,
    eta_range: tuple[float, float] = PRIMARY_ETA_RANGE,
) -> float | None:
    """``eta`` of the primary grazing of the nonimpacting period-one orbit, or None if it does not graze.

    Parameters
    ----------
    theta_hat_deg
        Stop angle in degrees.
    beta
        Linear damping.
    alpha
        Forcing amplitude ``A / L``.
    eta_range
        Where to search.

    Returns
    -------
    float or None
        The grazing's ``eta``, or None when the orbit does not reach the stop in the range.

    Examples
    --------
    >>> round(grazing_eta(40.0, 0.048), 5)
    0.44512
    >>> grazing_eta(40.0, 0.2) is None
    True
    """
    from grazing.models.pendulum import pendulum
    from grazing.orbits import find_grazings

    model = pendulum(
        None, alpha=alpha, beta=beta, r=1.0, eta=eta_range[0], theta_hat=math.radians(theta_hat_deg)
    )
    points, _ = find_grazings(model, "eta", eta_range[0], eta_range[1])
    if not points:
        return None
    return float(min(p.model.params["eta"] for p in points))


@dataclass(frozen=True)
class FitResult:
    """The fitted parameters.

    Attributes
    ----------
    beta, r
        The fitted damping and restitution.
    eta_graze
        ``eta`` of the primary grazing at the fitted ``beta`` (equal to the
        observed value to the root-finding's tolerance).
    theta_hat_deg, damping, alpha, relation
        The inputs: stop angle, target ``D``, forcing amplitude, and
        ``"model"``, ``"paper"`` or ``"protocol"`` (which damping relation
        defines the curve; see :func:`~grazing.experiment.iso_damping`).
    beta_max, r_min
        Ends of the equal-damping curve (``beta`` at ``r = 1``, ``r`` at ``beta = 0``).
    evaluations
        Number of grazing computations the root-finding needed.

    Examples
    --------
    What :func:`fit_parameters` finds for the paper's rig (θ̂ = 40°, the
    grazing observed near η = 0.445, D = 0.07): close to its case B
    (beta = 0.048, r = 0.7675):

    >>> from grazing.experiment import fit_parameters
    >>> fit = fit_parameters(40.0, 0.445, 0.07, relation="paper")
    >>> round(fit.beta, 4), round(fit.r, 4), round(fit.eta_graze, 5), fit.relation
    (0.0478, 0.7568, 0.445, 'paper')
    """

    beta: float
    r: float
    eta_graze: float
    theta_hat_deg: float
    damping: float
    alpha: float
    relation: str
    beta_max: float
    r_min: float
    evaluations: int


def fit_parameters(
    theta_hat_deg: float,
    eta_graze: float,
    damping: float = PAPER_DAMPING,
    *,
    alpha: float = ALPHA,
    relation: Relation = "model",
    eta_range: tuple[float, float] | None = None,
    **protocol: object,
) -> FitResult:
    """The point of the equal-damping curve whose primary grazing is at ``eta_graze``.

    Parameters
    ----------
    theta_hat_deg
        Stop angle in degrees (the paper used 40).
    eta_graze
        Observed ``eta`` of the primary grazing (the paper: about 0.445).
    damping
        Measured damping ``D`` (the paper: 0.07).
    alpha
        Forcing amplitude ``A / L``.
    relation
        ``"model"``: the equal-damping curve measured on the model with the
        eq. 6 normalisation (:func:`~grazing.experiment.iso_damping`);
        ``"paper"``: the relation ``D = beta - ln(r) / (4 pi)`` of the paper's points;
        ``"protocol"``: :func:`~grazing.experiment.damping.paper_protocol_damping`.
    eta_range
        Where to search for the primary grazing (default ``(0.2, 0.5)``,
        widened to include ``eta_graze``).
    **protocol
        Free-decay settings for the model's damping (``amplitude``, ``peaks``,
        ``k_hat``, ``normalisation``).

    Returns
    -------
    FitResult
        The fitted ``beta`` and ``r`` with the inputs and the curve's ends.

    Raises
    ------
    InvalidParameterError
        When no point of the curve grazes at ``eta_graze`` (it would need
        ``beta < 0`` or ``r > 1``, or the orbit never reaches the stop).

    Examples
    --------
    >>> fit = fit_parameters(40.0, 0.445, 0.07, relation="paper")
    >>> round(fit.beta, 4), round(fit.r, 4)
    (0.0478, 0.7568)
    """
    from scipy.optimize import brentq

    eta_obs = float(eta_graze)
    if not (math.isfinite(eta_obs) and eta_obs > 0):
        raise InvalidParameterError(f"the grazing eta must be positive, got {eta_graze!r}")
    if not -180.0 < float(theta_hat_deg) < 180.0:
        raise InvalidParameterError(f"theta_hat must be in (-180, 180) degrees, got {theta_hat_deg:g}")
    lo_eta, hi_eta = eta_range or (PRIMARY_ETA_RANGE[0], max(PRIMARY_ETA_RANGE[1], eta_obs + 0.05))
    if not lo_eta < eta_obs < hi_eta:
        raise InvalidParameterError(
            f"eta_graze = {eta_obs:g} is outside the search range ({lo_eta:g}, {hi_eta:g})"
        )
    beta_max = beta_for_damping(1.0, damping, relation=relation, **protocol)
    calls = 0

    def g(beta: float) -> float:
        nonlocal calls
        calls += 1
        e = grazing_eta(theta_hat_deg, beta, alpha=alpha, eta_range=(lo_eta, hi_eta))
        return 1.0 if e is None else e - eta_obs  # no grazing: damped below the stop

    g0 = g(0.0)
    if g0 == 1.0:
        raise InvalidParameterError(
            f"even with beta = 0 the period-one orbit does not reach the stop at theta_hat = "
            f"{theta_hat_deg:g} deg for eta in ({lo_eta:g}, {hi_eta:g}): no grazing to fit"
        )
    if g0 > 0:
        raise InvalidParameterError(
            f"even with beta = 0 the primary grazing at theta_hat = {theta_hat_deg:g} deg is at "
            f"eta = {g0 + eta_obs:.6g} > {eta_obs:g}: no point of the curve grazes there"
        )
    g1 = g(beta_max)
    if g1 < 0:
        raise InvalidParameterError(
            f"grazing at eta = {eta_obs:g} needs beta above {beta_max:.4g}, i.e. r > 1 at D = {damping:g} "
            f"(at beta = {beta_max:.4g} it grazes at eta = {g1 + eta_obs:.6g})"
        )
    beta = float(brentq(g, 0.0, beta_max, xtol=1e-10, rtol=1e-12))
    e = g(beta) + eta_obs
    if not abs(e - eta_obs) < 1e-6:
        raise InvalidParameterError(
            f"no beta in [0, {beta_max:.4g}] grazes at eta = {eta_obs:g} (the grazing disappears at "
            f"beta = {beta:.4g})"
        )
    r = r_for_damping(beta, damping, relation=relation, **protocol)
    r_min = _r_min(damping, relation, protocol)
    return FitResult(
        beta=beta,
        r=r,
        eta_graze=e,
        theta_hat_deg=float(theta_hat_deg),
        damping=float(damping),
        alpha=float(alpha),
        relation=relation,
        beta_max=beta_max,
        r_min=r_min,
        evaluations=calls,
    )


def _r_min(damping: float, relation: Relation, protocol: dict) -> float:
    try:
        return r_for_damping(0.0, damping, relation=relation, **protocol)
    except InvalidParameterError:  # pragma: no cover - beta = 0 always gives D <= target here
        return math.nan
