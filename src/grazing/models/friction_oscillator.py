"""The forced dry-friction oscillator on a moving belt: stick-slip, the stick phase as Filippov sliding.

::

    x'' + x = a cos(omega t) - mu sgn(x' - v_belt)

A unit mass on a unit spring rests on a belt moving at the constant speed
``v_belt``; Coulomb friction of magnitude ``mu`` opposes the slip velocity
``x' - v_belt`` and a harmonic force ``a cos(omega t)`` drives the mass.  Two
modes, one per sign of the slip: ``slip_ahead`` (``x' > v_belt``, friction
``-mu``) and ``slip_behind`` (``x' < v_belt``, friction ``+mu``), on either side
of the surface ``belt``: ``h = x' - v_belt = 0``.  Where both modes' fields push
into it, ``|a cos(omega t) - x| < mu``, the mass sticks to the belt: it slides
on the surface (Filippov's convex combination, the pseudo-mode ``"sliding on
'belt'"``), ``x' = v_belt`` and ``x = x0 + v_belt (t - t0)`` exactly, until
``|a cos(omega t) - x|`` reaches ``mu``.  Piecewise linear: every phase has a
closed form (matrix exponentials while slipping).

References: K. Popp, P. Stelter, "Stick-slip vibrations and chaos",
Phil. Trans. R. Soc. Lond. A 332 (1990) 89-105; M. di Bernardo, C. J. Budd,
A. R. Champneys, P. Kowalczyk, *Piecewise-smooth Dynamical Systems*, Springer
(2008), the dry-friction oscillator.
"""

from __future__ import annotations

from functools import lru_cache

from grazing.core.model import HybridModel, Parameter


@lru_cache(maxsize=1)
def _base() -> HybridModel:
    import sympy as sp

    from grazing.core.symbolic import Mode, Surface

    x, v, t = sp.symbols("x v t")
    a, omega, mu, v_belt = sp.symbols("a omega mu v_belt")
    spring_and_forcing = -x + a * sp.cos(omega * t)
    params = [
        Parameter("a", 1.0, lower=0.0, description="forcing amplitude", symbol="a"),
        Parameter("omega", 0.5, lower=0.0, lower_open=True, description="forcing frequency", symbol="ω"),
        Parameter("mu", 0.5, lower=0.0, lower_open=True, description="friction force (Coulomb)", symbol="μ"),
        Parameter("v_belt", 0.2, description="belt speed", symbol="v_b"),
    ]
    return HybridModel(
        "friction-oscillator",
        [x, v],
        t,
        params,
        modes=[
            Mode("slip_behind", [v, spring_and_forcing + mu]),
            Mode("slip_ahead", [v, spring_and_forcing - mu]),
        ],
        surfaces=[Surface("belt", v - v_belt, "slip_ahead", "slip_behind", sliding=True)],
        period=2 * sp.pi / omega,
        state_labels=["x", "x′"],
        description="harmonically forced mass on a moving belt with Coulomb friction (stick-slip)",
        reference="Popp & Stelter, Phil. Trans. R. Soc. Lond. A 332 (1990) 89-105",
    )


def friction_oscillator(**values: float) -> HybridModel:
    """The forced dry-friction oscillator on a moving belt with parameter overrides.

    Parameters
    ----------
    **values
        Parameter values by name, each replacing its default: ``a`` (forcing
        amplitude, default 1), ``omega`` (forcing frequency, default 0.5),
        ``mu`` (Coulomb friction force, default 0.5), ``v_belt`` (belt speed,
        default 0.2): stick-slip, sticking entered and left on both sides.

    Returns
    -------
    HybridModel
        The model with those values: modes ``slip_behind`` (the initial one),
        ``slip_ahead`` and the sliding pseudo-mode ``"sliding on 'belt'"`` (sticking).

    Examples
    --------
    >>> m = friction_oscillator(mu=0.4)
    >>> m.params["mu"], m.mode_names
    (0.4, ('slip_behind', 'slip_ahead', "sliding on 'belt'"))
    """
    return _base().with_params(**values)
