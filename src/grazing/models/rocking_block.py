"""Housner's rocking block on a base with a harmonic horizontal acceleration.

A rigid rectangular block of half-width ``b`` and half-height ``h`` rocks on
one bottom corner or the other; ``theta`` is its rotation (positive: on the
corner of mode ``right_corner``, negative: on that of ``left_corner``),
``alpha = atan(b/h)`` its slenderness and ``p = sqrt(3 g / (4 R))`` its
frequency parameter (``R`` the half-diagonal).  With the base acceleration
``u_g''(t) = a g cos(omega t)``::

    theta'' = -p^2 (sin(alpha - theta) + a cos(omega t) cos(alpha - theta))   while theta > 0
    theta'' =  p^2 (sin(alpha + theta) - a cos(omega t) cos(alpha + theta))   while theta < 0

(``theta'' = -p^2 (sin(alpha sgn(theta) - theta) + u_g''/g cos(alpha sgn(theta) - theta))``).
At ``theta = 0`` the block lands on its other corner: an impact that changes
the mode and multiplies the angular velocity by the coefficient of
restitution ``rho``, Housner's from the conservation of angular momentum
about the new corner, ``1 - 3/2 sin^2(alpha)``, or a given ``r``::

    theta' <- rho theta',   rho = housner (1 - 3/2 sin^2 alpha) + (1 - housner) r

(``housner = 1``, the default, is Housner's; ``housner = 0`` uses ``r``).
Between impacts ``theta'^2 / 2 + p^2 cos(alpha - |theta|)`` is conserved when
``a = 0``.  The model is of a block already rocking: it has no mode at rest
on its base (a block at rest starts to rock once ``|u_g''| > g tan(alpha)``);
a decaying motion whose landings accumulate (the block coming to rest) ends
the run with the status ``accumulating impacts``, which the engine does not
continue across modes yet.
Past ``|theta| = alpha`` gravity tips it further over; when ``|theta|`` reaches
``pi/2`` its side face meets the base: it has overturned.  The transitions
``overturn_right`` / ``overturn_left`` then enter the absorbing mode
``overturned`` (field 0) with the state reset to ``(+-pi/2, 0)``, so every
overturned block ends on one of two fixed states (the equations would
otherwise carry it on through the base).  For small angles it is the
piecewise-linear ``theta'' = p^2 (theta -+ alpha) - p^2 a cos(omega t)``.

References: G. W. Housner, "The behavior of inverted pendulum structures
during earthquakes", Bull. Seismol. Soc. Am. 53 (1963) 403-417; P. D. Spanos
and A.-S. Koh, "Rocking of rigid blocks due to harmonic shaking", J. Eng.
Mech. 110 (1984) 1627-1642; N. Makris and D. Konstantinidis, "The rocking
spectrum and the limitations of practical design methodologies", Earthquake
Eng. Struct. Dyn. 32 (2003) 265-289 (eq. 1).
"""

from __future__ import annotations

import math
from functools import lru_cache

from grazing.core.model import HybridModel, Parameter
from grazing.core.symbolic import Mode, Transition

PARAMETERS = (
    Parameter("p", 1.0, lower=0.0, lower_open=True, description="frequency parameter sqrt(3g/4R)",
              symbol="p"),
    Parameter("alpha", 0.2, lower=0.0, upper=math.pi / 2, lower_open=True, upper_open=True,
              description="slenderness atan(b/h)", unit="rad", symbol="α", angle=True),
    Parameter("a", 0.3, description="base acceleration amplitude (in g)", symbol="a"),
    Parameter("omega", 3.0, lower=0.0, lower_open=True, description="forcing frequency", symbol="ω"),
    Parameter("r", 0.9, lower=0.0, upper=1.0, description="coefficient of restitution (housner = 0)",
              symbol="r"),
    Parameter("housner", 1.0, lower=0.0, upper=1.0,
              description="1: Housner's restitution 1 - 3/2 sin^2 alpha; 0: r", symbol="H"),
)  # fmt: skip
"""The parameters and their defaults."""


def housner_restitution(alpha: float) -> float:
    """Housner's coefficient of restitution of a rectangular block of slenderness ``alpha``.

    The ratio of the angular velocities after and before an impact that
    conserves the angular momentum about the new corner.

    Examples
    --------
    >>> round(housner_restitution(0.2), 6)
    0.940796
    """
    return 1.0 - 1.5 * math.sin(alpha) ** 2


OVERTURN_ANGLE = math.pi / 2
"""``|theta|`` at which the block lies on its side: overturned."""


@lru_cache(maxsize=1)
def _base() -> HybridModel:
    import sympy as sp

    th, om, t = sp.symbols("theta omega_b t")
    p, alpha, a, omega, r, housner = sp.symbols("p alpha a omega r housner")
    base = a * sp.cos(omega * t)  # the base acceleration over g
    right = [om, -(p**2) * (sp.sin(alpha - th) + base * sp.cos(alpha - th))]
    left = [om, p**2 * (sp.sin(alpha + th) - base * sp.cos(alpha + th))]
    rho = housner * (1 - sp.Rational(3, 2) * sp.sin(alpha) ** 2) + (1 - housner) * r
    land = [th, rho * om]
    side = sp.pi / 2  # OVERTURN_ANGLE
    return HybridModel(
        "rocking-block",
        [th, om],
        t,
        PARAMETERS,
        modes=[Mode("right_corner", right), Mode("left_corner", left), Mode("overturned", [0, 0])],
        transitions=[
            Transition("onto_left", "right_corner", "left_corner", th, reset=land),
            Transition("onto_right", "left_corner", "right_corner", -th, reset=land),
            Transition("overturn_right", "right_corner", "overturned", side - th, reset=[side, 0]),
            Transition("overturn_left", "left_corner", "overturned", side + th, reset=[-side, 0]),
        ],
        period=2 * sp.pi / omega,
        state_labels=["θ", "θ′"],
        state_units=["rad", "rad/s"],
        description="Housner's rocking block on a harmonically shaken base: two corners, impacts between",
        reference="Housner, Bull. Seismol. Soc. Am. 53 (1963) 403-417",
    )


def rocking_block(**values: float) -> HybridModel:
    """Housner's rocking block (modes ``right_corner``, ``left_corner`` and ``overturned``) with overrides.

    Parameters
    ----------
    **values
        Parameter values by name, each replacing its default: ``p`` (frequency parameter, default
        1), ``alpha`` (slenderness in radians, default 0.2), ``a`` (base acceleration amplitude in
        units of g, default 0.3), ``omega`` (forcing frequency, default 3), ``r`` (coefficient of
        restitution used when ``housner = 0``, default 0.9), ``housner`` (1, the default:
        Housner's restitution ``1 - 3/2 sin^2 alpha``; 0: ``r``).

    Returns
    -------
    HybridModel
        The model with those values (its kernels are compiled once and
        cached, whatever the values).

    Examples
    --------
    >>> m = rocking_block(housner=0.0, r=0.8)
    >>> m.mode_names
    ('right_corner', 'left_corner', 'overturned')
    >>> m.stop_names  # (the transitions, by their source mode)
    ('onto_left', 'overturn_right', 'onto_right', 'overturn_left')
    """
    return _base().with_params(**values)
