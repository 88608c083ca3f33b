"""A forced linear oscillator with negative damping between two stops: its free periodic orbit is unstable.

::

    q'' + 2 zeta q' + q = cos(w s)         zeta < 0: the damping pumps energy in
    stops "ceiling" (q = upper) and "floor" (q = -lower), restitution e; upper and lower in m

Everything about its nonimpacting periodic orbit (the stops ignored) is known in closed form,
so the orbit, its multipliers and its grazings can be checked exactly (:class:`ClosedForm`):

* the response ``q(s) = A cos(w s - phi)`` with ``A = 1 / sqrt((1 - w^2)^2 + (2 zeta w)^2)``
  and ``phi = atan2(2 zeta w, 1 - w^2)``;
* the Floquet multipliers ``exp(T (-zeta +- i sqrt(1 - zeta^2)))``, ``T = 2 pi / w``: of
  modulus ``exp(-zeta T) > 1``, so a simulation diverges from the orbit;
* it grazes the ceiling where ``A = upper`` (at ``w s - phi = 0 mod 2 pi``) and the floor where
  ``A = lower`` (at ``w s - phi = pi``): with ``u = w^2``, ``u^2 + (4 zeta^2 - 2) u + 1 - 1/A^2
  = 0``;
* the grazing curve ``upper = A(w)`` has its fold (largest ``upper``) at the resonance
  ``w^2 = 1 - 2 zeta^2``, ``A = 1 / (2 |zeta| sqrt(1 - zeta^2))``.

With the defaults (``zeta = -0.2``, ``upper = 2``, ``lower = 2.5``) the simulation from rest with
the stops ignored overflows within 500 forcing periods; the ceiling is grazed at
``w^2 = 0.92 -+ sqrt(0.0964)`` and the floor at ``w = sqrt(0.84)`` and ``w = 1``.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from grazing import HybridModel, Parameter, Stop

ZETA = -0.2
UPPER = 2.0
LOWER = 2.5


def negative_damping(**values: float) -> HybridModel:
    """The model, with parameter overrides (also the ``--model FILE.py:negative_damping`` object)."""
    q, qdot, s = sp.symbols("q qdot s")
    zeta, w, upper, lower, e = sp.symbols("zeta w upper lower e")
    model = HybridModel(
        "negative-damping",
        states=[q, qdot],
        time=s,
        parameters=[
            Parameter("zeta", ZETA, lower=-0.5, upper=0.5, description="damping ratio (negative: unstable)"),
            Parameter("w", 0.5, lower=0.0, lower_open=True, description="forcing frequency"),
            Parameter(
                "upper", UPPER, lower=0.0, lower_open=True, description="height of the ceiling", unit="m"
            ),
            Parameter("lower", LOWER, lower=0.0, lower_open=True, description="depth of the floor", unit="m"),
            Parameter("e", 0.8, lower=0.0, upper=1.0, description="coefficient of restitution"),
        ],
        vector_field=[qdot, -2 * zeta * qdot - q + sp.cos(w * s)],
        period=2 * sp.pi / w,
        stops=[
            Stop("ceiling", upper - q, [q, -e * qdot], contact_direction=[0, 1]),
            Stop("floor", q + lower, [q, -e * qdot], contact_direction=[0, 1]),
        ],
    )
    return model.with_params(**values) if values else model


class ClosedForm:
    """The nonimpacting periodic orbit at damping ratio ``zeta`` (see the module docstring).

    (A plain class: ``--model FILE.py:OBJECT`` loads this file as a module that is not in
    ``sys.modules``, where ``dataclasses`` cannot resolve its annotations.)
    """

    def __init__(self, zeta: float = ZETA):
        self.zeta = zeta

    def amplitude(self, w: float) -> float:
        return 1.0 / math.hypot(1.0 - w * w, 2.0 * self.zeta * w)

    def phase_lag(self, w: float) -> float:
        return math.atan2(2.0 * self.zeta * w, 1.0 - w * w)

    def state(self, w: float, s: float = 0.0) -> np.ndarray:
        """``(q, q')`` of the orbit at time ``s``."""
        a, arg = self.amplitude(w), w * s - self.phase_lag(w)
        return np.array([a * math.cos(arg), -a * w * math.sin(arg)])

    def multipliers(self, w: float) -> np.ndarray:
        T = 2.0 * math.pi / w
        z = np.exp(T * complex(-self.zeta, math.sqrt(1.0 - self.zeta**2)))
        return np.array([z, z.conjugate()])

    def grazing_frequencies(self, amplitude: float) -> list[float]:
        """The frequencies ``w`` where the response amplitude is ``amplitude``, increasing."""
        b = 1.0 - 2.0 * self.zeta**2
        disc = b * b - 1.0 + 1.0 / amplitude**2
        roots = [b - math.sqrt(disc), b + math.sqrt(disc)] if disc >= 0 else []
        return [math.sqrt(u) for u in roots if u > 0]

    def contact_time(self, w: float, floor: bool = False) -> float:
        """The forcing phase (time in ``[0, T)``) where the orbit reaches its top (its bottom: ``floor``)."""
        T = 2.0 * math.pi / w
        return ((self.phase_lag(w) + (math.pi if floor else 0.0)) / w) % T

    def fold(self) -> tuple[float, float]:
        """``(w, A)`` at the top of the resonance curve: the fold of the grazing curve in ``(w, upper)``."""
        return math.sqrt(1.0 - 2.0 * self.zeta**2), 1.0 / (
            2.0 * abs(self.zeta) * math.sqrt(1.0 - self.zeta**2)
        )


BYSTANDER_DAMPING, BYSTANDER_STIFFNESS = 0.5, 3.0


def negative_damping_with_bystander(**values: float) -> HybridModel:
    """The same oscillator beside a second one that never meets a stop and does not act on it (4 states).

    States in the order ``(b, q, b_t, qdot)``: the bystander ``b'' + 0.5 b' + 3 b = 0.4 sin(w s)`` comes
    first, so that an index into the states, the tangent or the contact that is right only for two
    states (or only where the contact coordinate is the first one) shows.  Its periodic response is
    stable; the impacting oscillator's orbit, multipliers, grazings and grazing curve are those of
    :class:`ClosedForm`, and the bystander adds the multipliers ``exp(T (-0.25 +- i sqrt(2.9375)))``.
    """
    b, q, b_t, qdot, s = sp.symbols("b q b_t qdot s")
    zeta, w, upper, lower, e = sp.symbols("zeta w upper lower e")
    base = negative_damping()
    model = HybridModel(
        "negative-damping-with-bystander",
        states=[b, q, b_t, qdot],
        time=s,
        parameters=list(base.parameters),
        vector_field=[
            b_t,
            qdot,
            -BYSTANDER_DAMPING * b_t - BYSTANDER_STIFFNESS * b + sp.Rational(2, 5) * sp.sin(w * s),
            -2 * zeta * qdot - q + sp.cos(w * s),
        ],
        period=2 * sp.pi / w,
        stops=[
            Stop("ceiling", upper - q, [b, q, b_t, -e * qdot], contact_direction=[0, 0, 0, 1]),
            Stop("floor", q + lower, [b, q, b_t, -e * qdot], contact_direction=[0, 0, 0, 1]),
        ],
    )
    return model.with_params(**values) if values else model


def bystander_multipliers(w: float) -> np.ndarray:
    """The bystander's two Floquet multipliers over one forcing period ``2 pi / w``."""
    c = BYSTANDER_DAMPING / 2.0
    z = np.exp((2.0 * math.pi / w) * complex(-c, math.sqrt(BYSTANDER_STIFFNESS - c * c)))
    return np.array([z, z.conjugate()])
