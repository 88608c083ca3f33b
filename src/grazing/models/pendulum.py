"""The inclined impacting pendulum of Piiroinen, Virgin & Champneys (2004).

Nondimensional equations (paper eqs. 4-5), with ``tau = omega t`` as time::

    theta'' + (2 beta/eta) theta' + sin(theta)/(4 eta^2) = alpha cos(theta) sin(tau)
    theta' <- -r theta'            when theta reaches theta_hat (from below): stop "stop"
    theta' <- -r theta'            when theta reaches theta_hat - 2 pi (from above): stop "back"

The second stop is the back face of the same stop: a pendulum rotating over
the top (backwards) reaches it at ``theta_hat - 2 pi``; no orbit of the paper
does.

The state is ``(theta, theta')``.  The paper writes the state as
``x1 = theta - theta_hat``; the shift changes no Jacobian or multiplier, and
with ``theta`` as the state the flow does not depend on ``theta_hat`` at all
(only the guard does).  ``theta_hat`` is in radians here; the command line
takes degrees.

The paper's named parameter sets (docs/equations.md; errata: case D has beta = 0.068,
not 0.68, and the numerics use alpha = 0.2254):

=========  ======  =====  ==============  =========================
case       r       beta   alpha           used in
=========  ======  =====  ==============  =========================
A          0.4707  0.010  0.2254          fig 8b
B          0.7675  0.048  0.2254          figs 6, 7, 8a, 9, 10, 11
C          0.8778  0.058  0.2254          figs 4b, 6
D          1.0     0.068  0.2254          figs 4b, 6
A-reduced  0.4707  0.010  0.71 * 0.2254   fig 12
=========  ======  =====  ==============  =========================

Reference: P. T. Piiroinen, L. N. Virgin, A. R. Champneys, "Chaos and
period-adding: experimental and numerical verification of the grazing
bifurcation", J. Nonlinear Sci. 14 (2004) 383-404.
"""

from __future__ import annotations

import math
from functools import lru_cache
from types import MappingProxyType
from typing import Any

from grazing.core.model import HybridModel, Parameter
from grazing.core.symbolic import Stop
from grazing.errors import InvalidParameterError

ALPHA = 0.2254

CASES = MappingProxyType(
    {
        "A": MappingProxyType({"r": 0.4707, "beta": 0.010, "alpha": ALPHA}),
        "B": MappingProxyType({"r": 0.7675, "beta": 0.048, "alpha": ALPHA}),
        "C": MappingProxyType({"r": 0.8778, "beta": 0.058, "alpha": ALPHA}),
        "D": MappingProxyType({"r": 1.0, "beta": 0.068, "alpha": ALPHA}),
        "A-reduced": MappingProxyType({"r": 0.4707, "beta": 0.010, "alpha": 0.71 * ALPHA}),
    }
)
"""The paper's parameter cases (r, beta, alpha) by name."""

DEFAULT_CASE = "B"


def case_values(name: str) -> dict[str, float]:
    """Parameter values ``{r, beta, alpha}`` of a named case (case-insensitive).

    Parameters
    ----------
    name
        One of the paper's cases: ``A``, ``B``, ``C``, ``D``, ``A-reduced``
        (:data:`CASES`).

    Returns
    -------
    dict of str to float
        The case's restitution ``r``, damping ``beta`` and forcing amplitude ``alpha``.

    Examples
    --------
    >>> case_values("b")
    {'r': 0.7675, 'beta': 0.048, 'alpha': 0.2254}
    """
    for key, vals in CASES.items():
        if key.lower() == str(name).strip().lower():
            return dict(vals)
    raise InvalidParameterError(f"unknown case {name!r} (known: {', '.join(CASES)})")


def _symbolic() -> dict:
    """The pendulum's equations (paper eqs. 4-5), built only when kernels must be generated."""
    import sympy as sp

    theta, dtheta, tau = sp.symbols("theta dtheta tau")
    alpha, beta, eta, r, theta_hat = sp.symbols("alpha beta eta r theta_hat")
    return {
        "states": [theta, dtheta],
        "time": tau,
        "vector_field": [
            dtheta,
            alpha * sp.cos(theta) * sp.sin(tau) - 2 * beta / eta * dtheta - sp.sin(theta) / (4 * eta**2),
        ],
        "stops": [
            Stop("stop", theta_hat - theta, [theta, -r * dtheta], [0, 1]),
            # The back of the stop: a rotation over the top reaches it at theta_hat - 2 pi.
            Stop("back", theta - theta_hat + 2 * sp.pi, [theta, -r * dtheta], [0, 1]),
        ],
    }


@lru_cache(maxsize=1)
def _base() -> HybridModel:
    params = [
        Parameter("alpha", ALPHA, lower=0.0, description="forcing amplitude A/L", symbol="α"),
        Parameter("beta", 0.048, lower=0.0, description="linear damping", symbol="β"),
        Parameter(
            "eta", 0.446, lower=0.0, lower_open=True, description="forcing frequency ratio", symbol="η"
        ),
        Parameter("r", 0.7675, lower=0.0, upper=1.0, description="coefficient of restitution", symbol="r"),
        Parameter(
            "theta_hat",
            math.radians(40.0),
            lower=-math.pi,
            upper=math.pi,
            lower_open=True,
            upper_open=True,
            description="stop angle in radians",
            unit="rad",
            symbol="θ̂",
            angle=True,
        ),
    ]
    return HybridModel.lazy(
        "pendulum",
        parameters=params,
        state_names=["theta", "dtheta"],
        period="2*pi",
        builder=_symbolic,
        state_labels=["θ", "θ′"],
        state_units=["rad", "rad per unit time"],
        time_label="τ",
        stop_names=["stop", "back"],
        description="horizontally forced inclined pendulum with a rigid stop (paper eqs. 4-5)",
        reference="Piiroinen, Virgin & Champneys, J. Nonlinear Sci. 14 (2004) 383-404",
    )


def pendulum(case: str | None = DEFAULT_CASE, **values: float) -> HybridModel:
    """The impacting pendulum with a named parameter case and overrides.

    Parameters
    ----------
    case
        One of ``A``, ``B`` (default), ``C``, ``D``, ``A-reduced`` (sets r,
        beta, alpha), or ``None`` for the defaults.
    **values
        Any of ``alpha``, ``beta``, ``eta``, ``r``, ``theta_hat`` (radians),
        replacing the case's value.

    Returns
    -------
    HybridModel
        The pendulum of the paper's eqs. 4-5, with its stop at ``theta_hat``
        and the stop's back face at ``theta_hat - 2 pi``.

    Examples
    --------
    >>> import math
    >>> m = pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> round(m.params["r"], 4), m.period == 2 * math.pi
    (0.7675, True)
    >>> m.stop_names
    ('stop', 'back')
    >>> pendulum("B", r=2.0)
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: r = 2 is outside [0, 1] (coefficient of restitution)
    """
    vals = case_values(case) if case is not None else {}
    vals.update(values)
    return _base().with_params(**vals)


def max_angle(orbit: Any) -> float:
    """The largest angle of a pendulum orbit (a :class:`~grazing.orbits.PeriodicOrbit`), in radians.

    The guard ``theta_hat - theta`` is smallest where ``theta`` is largest, so
    this is the stop angle minus the orbit's smallest guard value (the stop
    angle itself for an impacting orbit).
    """
    return float(orbit.model.params["theta_hat"] - orbit.guard_min)
