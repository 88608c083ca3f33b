"""A linear oscillator between two stops: the model of gear rattle and loose joints.

::

    x'' + 2 zeta x' + x = amp cos(omega t)     while -gap_left < x < gap_right
    x' <- -r x'                                  when x reaches gap_right (stop "right")
    x' <- -r x'                                  when x reaches -gap_left (stop "left")

Below grazing the motion is the linear response, of amplitude
``amp / sqrt((1 - omega^2)^2 + (2 zeta omega)^2)``; it grazes the right stop
where that amplitude equals ``gap_right``.

References: S. W. Shaw and P. J. Holmes, "A periodically forced piecewise
linear oscillator", J. Sound Vib. 90 (1983) 129-155; M. di Bernardo,
C. J. Budd, A. R. Champneys, P. Kowalczyk, *Piecewise-smooth Dynamical
Systems*, Springer (2008), ch. 6.
"""

from __future__ import annotations

from functools import lru_cache

from grazing.core.model import HybridModel, Parameter
from grazing.core.symbolic import Stop


def _symbolic() -> dict:
    import sympy as sp

    x, v, t = sp.symbols("x v t")
    zeta, amp, omega, gap_left, gap_right, r = sp.symbols("zeta amp omega gap_left gap_right r")
    return {
        "states": [x, v],
        "time": t,
        "vector_field": [v, -2 * zeta * v - x + amp * sp.cos(omega * t)],
        "stops": [
            Stop("right", gap_right - x, [x, -r * v], [0, 1]),
            Stop("left", x + gap_left, [x, -r * v], [0, 1]),
        ],
    }


@lru_cache(maxsize=1)
def _base() -> HybridModel:
    params = [
        Parameter("zeta", 0.05, lower=0.0, description="damping ratio", symbol="ζ"),
        Parameter("amp", 1.0, description="forcing amplitude", symbol="A"),
        Parameter("omega", 0.8, lower=0.0, lower_open=True, description="forcing frequency", symbol="ω"),
        Parameter("gap_left", 1.0, lower=0.0, lower_open=True, description="distance to the left stop"),
        Parameter("gap_right", 1.0, lower=0.0, lower_open=True, description="distance to the right stop"),
        Parameter("r", 0.8, lower=0.0, upper=1.0, description="coefficient of restitution", symbol="r"),
    ]
    return HybridModel.lazy(
        "two-sided-oscillator",
        parameters=params,
        state_names=["x", "v"],
        period="2*pi/omega",
        builder=_symbolic,
        state_labels=["x", "x′"],
        stop_names=["right", "left"],
        description="harmonically forced linear oscillator between two rigid stops",
        reference="Shaw & Holmes, J. Sound Vib. 90 (1983) 129-155",
    )


def two_sided_oscillator(**values: float) -> HybridModel:
    """The two-sided impact oscillator with parameter overrides.

    Parameters
    ----------
    **values
        Parameter values by name, each replacing its default: ``zeta`` (damping ratio, default
        0.05), ``amp`` (forcing amplitude, default 1), ``omega`` (forcing frequency, default
        0.8), ``gap_left`` (distance to the left stop, default 1), ``gap_right`` (distance to
        the right stop, default 1), ``r`` (coefficient of restitution, default 0.8).

    Returns
    -------
    HybridModel
        The model with those values (its kernels are compiled once and
        cached, whatever the values).

    Examples
    --------
    >>> m = two_sided_oscillator(omega=0.5)
    >>> m.stop_names, m.params["gap_right"]
    (('right', 'left'), 1.0)
    """
    return _base().with_params(**values)
