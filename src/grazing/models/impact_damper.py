"""An impact damper: a forced primary mass with a secondary mass rattling in a cavity (4 states).

With ``x1`` the primary mass (natural frequency 1, damping ratio ``zeta``,
forced by ``amp cos(omega t)``) and ``x2`` a secondary mass of mass ratio
``mu = m2 / m1`` in a cavity of half-width ``gap`` inside it, tied to the
primary by a spring and dashpot (natural frequency ``omega2``, damping ratio
``zeta2``; ``omega2 = 0`` is the free secondary mass of the classic impact
damper), with ``F = 2 zeta2 omega2 (v2 - v1) + omega2^2 (x2 - x1)``::

    x1'' + 2 zeta x1' + x1 = amp cos(omega t) + mu F,    x2'' = -F      while |x2 - x1| < gap
    v1 <- v1 + mu (1 + r) / (1 + mu) (v2 - v1)
    v2 <- v2 - (1 + r) / (1 + mu) (v2 - v1)       when x2 - x1 reaches gap (stop "right")
                                                  or -gap (stop "left")

The reset conserves momentum ``v1 + mu v2`` and reverses the relative velocity
times ``r``.  While the masses stick together the contact force acts on both
(direction ``(0, mu, 0, -1)``).

Reference: S. F. Masri and T. K. Caughey, "On the stability of the impact
damper", J. Appl. Mech. 33 (1966) 586-592 (the free secondary mass; the
spring makes the nonimpacting motion a unique, hyperbolic periodic orbit that
grazes the cavity's walls).
"""

from __future__ import annotations

from functools import lru_cache

from grazing.core.model import HybridModel, Parameter
from grazing.core.symbolic import Stop


def _symbolic() -> dict:
    import sympy as sp

    x1, v1, x2, v2, t = sp.symbols("x1 v1 x2 v2 t")
    zeta, amp, omega, mu, gap, r, omega2, zeta2 = sp.symbols("zeta amp omega mu gap r omega2 zeta2")
    dv = v2 - v1
    force = 2 * zeta2 * omega2 * dv + omega2**2 * (x2 - x1)
    reset = [x1, v1 + mu * (1 + r) / (1 + mu) * dv, x2, v2 - (1 + r) / (1 + mu) * dv]
    return {
        "states": [x1, v1, x2, v2],
        "time": t,
        "vector_field": [v1, -2 * zeta * v1 - x1 + amp * sp.cos(omega * t) + mu * force, v2, -force],
        "stops": [
            Stop("right", gap - (x2 - x1), reset, [0, mu, 0, -1]),
            Stop("left", gap + (x2 - x1), reset, [0, mu, 0, -1]),
        ],
    }


@lru_cache(maxsize=1)
def _base() -> HybridModel:
    params = [
        Parameter("zeta", 0.05, lower=0.0, description="damping ratio of the primary mass", symbol="ζ"),
        Parameter("amp", 1.0, description="forcing amplitude", symbol="A"),
        Parameter("omega", 1.2, lower=0.0, lower_open=True, description="forcing frequency", symbol="ω"),
        Parameter("mu", 0.1, lower=0.0, lower_open=True, description="mass ratio m2/m1", symbol="μ"),
        Parameter("gap", 2.0, lower=0.0, lower_open=True, description="half-width of the cavity", symbol="d"),
        Parameter("r", 0.6, lower=0.0, upper=1.0, description="coefficient of restitution", symbol="r"),
        Parameter(
            "omega2", 0.0, lower=0.0, description="natural frequency of the secondary mass", symbol="ω₂"
        ),
        Parameter("zeta2", 0.05, lower=0.0, description="damping ratio of the secondary mass", symbol="ζ₂"),
    ]
    return HybridModel.lazy(
        "impact-damper",
        parameters=params,
        state_names=["x1", "v1", "x2", "v2"],
        period="2*pi/omega",
        builder=_symbolic,
        state_labels=["x₁", "x₁′", "x₂", "x₂′"],
        stop_names=["right", "left"],
        description="forced primary mass with a secondary mass rattling in a cavity (impact damper)",
        reference="Masri & Caughey, J. Appl. Mech. 33 (1966) 586-592",
    )


def impact_damper(**values: float) -> HybridModel:
    """The impact damper with parameter overrides.

    Parameters
    ----------
    **values
        Parameter values by name, each replacing its default: ``zeta`` (damping ratio of the
        primary mass, default 0.05), ``amp`` (forcing amplitude, default 1), ``omega`` (forcing
        frequency, default 1.2), ``mu`` (mass ratio m2/m1, default 0.1), ``gap`` (half-width of
        the cavity, default 2), ``r`` (coefficient of restitution, default 0.6), ``omega2``
        (natural frequency of the secondary mass, default 0), ``zeta2`` (damping ratio of the
        secondary mass, default 0.05).

    Returns
    -------
    HybridModel
        The model with those values (its kernels are compiled once and
        cached, whatever the values).

    Examples
    --------
    >>> m = impact_damper(mu=0.2)
    >>> m.n_states, m.stop_names
    (4, ('right', 'left'))
    """
    return _base().with_params(**values)
