"""The linear impact oscillator, the canonical example of grazing.

::

    x'' + 2 zeta x' + x = cos(omega t)      while x < sigma
    x' <- -r x'                              when x reaches sigma

References: A. B. Nordmark, "Non-periodic motion caused by grazing incidence
in an impact oscillator", J. Sound Vib. 145 (1991) 279-297; M. di Bernardo,
C. J. Budd, A. R. Champneys, P. Kowalczyk, *Piecewise-smooth Dynamical
Systems*, Springer (2008), ch. 6.
"""

from __future__ import annotations

from functools import lru_cache

from grazing.core.model import HybridModel, Parameter


def _symbolic() -> dict:
    import sympy as sp

    x, v, t = sp.symbols("x v t")
    zeta, omega, sigma, r = sp.symbols("zeta omega sigma r")
    return {
        "states": [x, v],
        "time": t,
        "vector_field": [v, -2 * zeta * v - x + sp.cos(omega * t)],
        "guard": sigma - x,
        "reset": [x, -r * v],
        "contact_direction": [0, 1],
    }


@lru_cache(maxsize=1)
def _base() -> HybridModel:
    params = [
        Parameter("zeta", 0.05, lower=0.0, description="damping ratio", symbol="ζ"),
        Parameter("omega", 2.8, lower=0.0, lower_open=True, description="forcing frequency", symbol="ω"),
        Parameter("sigma", 0.1, description="stop position", symbol="σ"),
        Parameter("r", 0.8, lower=0.0, upper=1.0, description="coefficient of restitution", symbol="r"),
    ]
    return HybridModel.lazy(
        "impact-oscillator",
        parameters=params,
        state_names=["x", "v"],
        period="2*pi/omega",
        builder=_symbolic,
        state_labels=["x", "x′"],
        description="harmonically forced linear oscillator with a rigid stop",
        reference="Nordmark, J. Sound Vib. 145 (1991) 279-297",
    )


def impact_oscillator(**values: float) -> HybridModel:
    """The linear impact oscillator with parameter overrides.

    Parameters
    ----------
    **values
        Parameter values by name, each replacing its default: ``zeta`` (damping ratio, default
        0.05), ``omega`` (forcing frequency, default 2.8), ``sigma`` (stop position, default
        0.1), ``r`` (coefficient of restitution, default 0.8).

    Returns
    -------
    HybridModel
        The model with those values (its kernels are compiled once and
        cached, whatever the values).

    Examples
    --------
    >>> impact_oscillator(sigma=0.0).params["sigma"]
    0.0
    """
    return _base().with_params(**values)
