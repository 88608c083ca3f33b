"""The soft-impact oscillator: a forced linear oscillator against a compliant (spring) stop.

::

    x'' + 2 zeta x' + x = a cos(omega t)                    while x < gap   (mode "free")
    x'' + 2 zeta x' + x = a cos(omega t) - k (x - gap)      while x > gap   (mode "contact")

The stop is a spring of stiffness ``k`` (relative to the oscillator's) whose
end rests at ``x = gap``: the motion switches between two linear vector fields
at ``x = gap`` with no reset (transitions ``touch`` and ``leave``).  The
field is continuous across the switch (the spring's force is 0 there), so the
saltation matrix is the identity; each mode is linear, so its orbits are exact
from matrix exponentials.  As ``k`` grows it tends to the rigid impact
oscillator with ``r = 1``.

References: S. W. Shaw and P. J. Holmes, "A periodically forced piecewise
linear oscillator", J. Sound Vib. 90 (1983) 129-155; J. Ing, E. Pavlovskaia,
M. Wiercigroch and S. Banerjee, "Experimental study of impact oscillator with
one-sided elastic constraint", Phil. Trans. R. Soc. A 366 (2008) 679-705;
M. di Bernardo, C. J. Budd, A. R. Champneys, P. Kowalczyk, *Piecewise-smooth
Dynamical Systems*, Springer (2008), ch. 1 and 7.
"""

from __future__ import annotations

from functools import lru_cache

from grazing.core.model import HybridModel, Parameter
from grazing.core.symbolic import Mode, Transition

PARAMETERS = (
    Parameter("zeta", 0.05, lower=0.0, description="damping ratio", symbol="ζ"),
    Parameter("a", 1.0, description="forcing amplitude", symbol="a"),
    Parameter("omega", 1.2, lower=0.0, lower_open=True, description="forcing frequency", symbol="ω"),
    Parameter("gap", 0.5, description="position of the stop's spring", symbol="g"),
    Parameter("k", 4.0, lower=0.0, description="stiffness of the stop (relative)", symbol="k"),
)
"""The parameters and their defaults."""


@lru_cache(maxsize=1)
def _base() -> HybridModel:
    import sympy as sp

    x, v, t = sp.symbols("x v t")
    zeta, a, omega, gap, k = sp.symbols("zeta a omega gap k")
    free = [v, -2 * zeta * v - x + a * sp.cos(omega * t)]
    contact = [v, -2 * zeta * v - x + a * sp.cos(omega * t) - k * (x - gap)]
    return HybridModel(
        "soft-impact-oscillator",
        [x, v],
        t,
        PARAMETERS,
        modes=[Mode("free", free), Mode("contact", contact)],
        transitions=[
            Transition("touch", "free", "contact", gap - x),
            Transition("leave", "contact", "free", x - gap),
        ],
        period=2 * sp.pi / omega,
        state_labels=["x", "x′"],
        description="harmonically forced linear oscillator with a compliant (spring) stop: two modes",
        reference="Shaw & Holmes, J. Sound Vib. 90 (1983) 129-155",
    )


def soft_impact_oscillator(**values: float) -> HybridModel:
    """The soft-impact oscillator (two modes, ``free`` and ``contact``) with parameter overrides.

    Parameters
    ----------
    **values
        Parameter values by name, each replacing its default: ``zeta`` (damping ratio, default
        0.05), ``a`` (forcing amplitude, default 1), ``omega`` (forcing frequency, default 1.2),
        ``gap`` (where the stop's spring begins, default 0.5), ``k`` (its stiffness relative to
        the oscillator's, default 4).

    Returns
    -------
    HybridModel
        The model with those values (its kernels are compiled once and
        cached, whatever the values).

    Examples
    --------
    >>> m = soft_impact_oscillator(k=20.0)
    >>> m.mode_names, m.stop_names, m.params["k"]
    (('free', 'contact'), ('touch', 'leave'), 20.0)
    """
    return _base().with_params(**values)
