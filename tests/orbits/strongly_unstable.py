"""A ball on a vibrating table beside an inverted pendulum between two walls: a strongly unstable orbit.

The two bodies do not interact: the orbit's monodromy is block-diagonal, the ball's block has the
closed forms of the bouncing ball (Holmes 1982; Luck & Mehta 1993) and the pendulum's block
(:func:`tests.linear_exact.inverted_walls`) a multiplier of ``1e4`` to ``1e7`` and more as the
pendulum's impact speed falls towards its grazing (``a = 6.003332408``).  The ball's fold and
period-doubling curves in ``(A, e)`` are then those of the bouncing ball, while single shooting of
the whole orbit is bounded below by ``|M| eps |x|`` (``3e-9`` at ``a = 5.99``): only the
segmented equations reach Newton's tolerance there.

States ``Hq, Hv`` (pendulum), ``Yb, Ub`` (ball); parameters ``k, c, a, w, r`` (pendulum), ``A, g, e``
(table amplitude, gravity, ball's restitution); stops ``right``, ``left`` (walls) and ``table``.
The table is ``A sin(w s - 1)``, a phase that keeps the ball's impacts away from the pendulum's.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from grazing import HybridModel, Parameter
from grazing.core.symbolic import Stop
from grazing.orbits import PeriodicOrbit, continue_orbit, find_orbit
from tests.linear_exact import inverted_walls

TABLE_PHASE = 1.0
"""The table is ``A sin(w s - TABLE_PHASE)``."""


def ball_beside_pendulum(table_phase: float = TABLE_PHASE, **values: float) -> HybridModel:
    """The model (see the module docstring) at ``values``, its table ``A sin(w s - table_phase)``."""
    Hq, Hv, Yb, Ub, s = sp.symbols("Hq Hv Yb Ub s")
    k, c, a, w, r, A, g, e = sp.symbols("k c a w r A g e")
    defaults = {"k": 2.0, "c": 0.1, "a": 5.99, "w": 2.0, "r": 0.8, "A": 0.3, "g": 1.0, "e": 0.5}
    defaults.update(values)
    table = A * sp.sin(w * s - table_phase)
    wall = [Hq, -r * Hv, Yb, Ub]
    bounce = [Hq, Hv, Yb, (1 + e) * sp.diff(table, s) - e * Ub]
    return HybridModel(
        "ball-beside-pendulum", [Hq, Hv, Yb, Ub], s, [Parameter(n, v) for n, v in defaults.items()],
        [Hv, k * Hq - c * Hv + a * sp.cos(w * s), Ub, -g], period=2 * sp.pi / w,
        stops=[Stop("right", 1 - Hq, wall, [0, 1, 0, 0]), Stop("left", 1 + Hq, wall, [0, 1, 0, 0]),
               Stop("table", Yb - table, bounce, [0, 0, 0, 1])],
    )  # fmt: skip


def ball_fold(e: np.ndarray | float, w: float = 2.0, g: float = 1.0) -> np.ndarray | float:
    """The table amplitude of the fold of the ball's one-impact period-1 orbit at restitution ``e``."""
    return g / w**2 * np.pi * (1 - e) / (1 + e)


def ball_period_doubling(e: np.ndarray | float, w: float = 2.0, g: float = 1.0) -> np.ndarray | float:
    """The table amplitude of that orbit's period-doubling."""
    return g / w**2 * np.sqrt(4 * (1 + e**2) ** 2 / (1 + e) ** 4 + (np.pi * (1 - e) / (1 + e)) ** 2)


def pendulum_orbit(a: float) -> PeriodicOrbit:
    """The pendulum's symmetric two-impact orbit at ``a`` (continued from ``a = 3``, where single shooting
    finds it)."""
    model = inverted_walls()
    start = find_orbit(model, [-0.9294, 0.8725], period=1)
    return continue_orbit(model, "a", 3.0, a, orbit=start).orbits[-1]


def strongly_unstable_orbit(
    a: float = 5.99, A: float = 0.3, e: float = 0.5, table_phase: float = TABLE_PHASE
) -> PeriodicOrbit:
    """The period-1 orbit of both bodies: the pendulum's orbit at ``a`` and the ball's stable one-impact
    orbit (its closed form: it leaves the table at phase ``phi``, ``cos phi = pi g (1 - e) / ((1 + e) A
    w^2)``, with speed ``g T / 2``)."""
    w, g = 2.0, 1.0
    T = 2 * math.pi / w
    pend = pendulum_orbit(a)
    phi = math.acos(math.pi * g * (1 - e) / ((1 + e) * A * w**2))
    t_imp = (phi + table_phase) / w
    dt = (pend.t0 - t_imp) % T
    ball = [A * math.sin(phi) + g * T / 2 * dt - g * dt * dt / 2, g * T / 2 - g * dt]
    model = ball_beside_pendulum(table_phase, a=a, A=A, e=e)
    return find_orbit(model, np.concatenate([pend.state, ball]), period=1, t0=pend.t0)


def ball_alone(**values: float) -> HybridModel:
    """The ball of :func:`ball_beside_pendulum` by itself (states ``Yb, Ub``): its block of the monodromy,
    computed without the pendulum's ``1e7``."""
    Yb, Ub, s = sp.symbols("Yb Ub s")
    w, A, g, e = sp.symbols("w A g e")
    defaults = {"w": 2.0, "A": 0.3, "g": 1.0, "e": 0.5}
    defaults.update(values)
    table = A * sp.sin(w * s - TABLE_PHASE)
    return HybridModel(
        "ball", [Yb, Ub], s, [Parameter(n, v) for n, v in defaults.items()], [Ub, -g], period=2 * sp.pi / w,
        stops=[Stop("table", Yb - table, [Yb, (1 + e) * sp.diff(table, s) - e * Ub], [0, 1])],
    )  # fmt: skip
