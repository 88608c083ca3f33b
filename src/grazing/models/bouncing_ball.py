"""A ball bouncing on a sinusoidally vibrating table: the classic chattering example.

The table moves as ``s(t) = amplitude sin(omega t)``; the ball flies freely
under gravity and bounces with restitution ``r`` relative to the table::

    y'' = -gravity                      while y > s(t)
    y' <- (1 + r) s'(t) - r y'          when y reaches s(t)

Between bounces sequences of impacts can accumulate in finite time (complete
chattering); the ball then rides on the table until the table's downward
acceleration exceeds gravity.  With ``amplitude = 0`` it is a ball on a fixed
floor, whose impact times are known in closed form.

References: P. J. Holmes, J. Sound Vib. 84 (1982) 173-189; A. B. Nordmark and
P. T. Piiroinen, "Simulation and stability analysis of impacting systems with
complete chattering", Nonlinear Dyn. 58 (2009) 85-106.
"""

from __future__ import annotations

from functools import lru_cache

from grazing.core.model import HybridModel, Parameter


def _symbolic() -> dict:
    import sympy as sp

    y, v, t = sp.symbols("y v t")
    amplitude, omega, gravity, r = sp.symbols("amplitude omega gravity r")
    table = amplitude * sp.sin(omega * t)
    return {
        "states": [y, v],
        "time": t,
        "vector_field": [v, -gravity],
        "guard": y - table,
        "reset": [y, (1 + r) * sp.diff(table, t) - r * v],
        "contact_direction": [0, 1],
    }


@lru_cache(maxsize=1)
def _base() -> HybridModel:
    params = [
        Parameter("amplitude", 0.1, lower=0.0, description="table amplitude", symbol="A"),
        Parameter("omega", 1.0, lower=0.0, lower_open=True, description="table frequency", symbol="ω"),
        Parameter(
            "gravity", 1.0, lower=0.0, lower_open=True, description="gravitational acceleration", symbol="g"
        ),
        Parameter("r", 0.5, lower=0.0, upper=1.0, description="coefficient of restitution", symbol="r"),
    ]
    return HybridModel.lazy(
        "bouncing-ball",
        parameters=params,
        state_names=["y", "v"],
        period="2*pi/omega",
        builder=_symbolic,
        state_labels=["y", "y′"],
        description="ball on a vibrating table (chattering and sticking)",
        reference="Nordmark & Piiroinen, Nonlinear Dyn. 58 (2009) 85-106",
    )


def bouncing_ball(**values: float) -> HybridModel:
    """The bouncing ball with parameter overrides.

    Parameters
    ----------
    **values
        Parameter values by name, each replacing its default: ``amplitude`` (table amplitude,
        default 0.1), ``omega`` (table frequency, default 1), ``gravity`` (gravitational
        acceleration, default 1), ``r`` (coefficient of restitution, default 0.5).

    Returns
    -------
    HybridModel
        The model with those values (its kernels are compiled once and
        cached, whatever the values).

    Examples
    --------
    >>> bouncing_ball(amplitude=0.0).params["amplitude"]
    0.0
    """
    return _base().with_params(**values)
