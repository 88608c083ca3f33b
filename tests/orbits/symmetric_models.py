"""A pendulum forced between two walls: a model whose orbits come in mirror-image pairs.

::

    th'' + gamma th' + sin(th) = A cos(Om tau)      while -wall < th < wall
    th' <- -e th'                                    at th = wall (stop "east") and th = -wall ("west")

The equations are unchanged by ``(th, tau) -> (-th, tau + T/2)`` (``T = 2 pi / Om``, the forcing
period, which the parameter ``Om`` sets): the mirror image ``-th(tau - T/2)`` of a motion is a
motion, and a *symmetric* periodic orbit (one impact on each wall per period) is its own mirror
image.  As the forcing changes, a symmetric orbit can lose its symmetry in a pitchfork: a branch
point, where two mirror-image asymmetric orbits are born.  The built-in two-sided oscillator with
equal gaps has the same symmetry (:func:`mirror` applies to it too).  Names are unusual on purpose.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

import grazing
from grazing import HybridModel, Parameter, Stop


def walled_pendulum(**values: float) -> HybridModel:
    """The model, with parameter overrides (also the ``--model FILE.py:walled_pendulum`` object)."""
    th, dth, tau = sp.symbols("th dth tau")
    gamma, A, Om, wall, e = sp.symbols("gamma A Om wall e")
    model = HybridModel(
        "walled-pendulum",
        states=[th, dth],
        time=tau,
        parameters=[
            Parameter("gamma", 0.1, lower=0.0, description="damping"),
            Parameter("A", 0.6, description="forcing amplitude"),
            Parameter("Om", 1.2, lower=0.0, lower_open=True, description="forcing frequency"),
            Parameter("wall", 0.5, lower=0.0, lower_open=True, upper=3.0, description="wall angle (rad)"),
            Parameter("e", 0.8, lower=0.0, upper=1.0, description="coefficient of restitution"),
        ],
        vector_field=[dth, -gamma * dth - sp.sin(th) + A * sp.cos(Om * tau)],
        period=2 * sp.pi / Om,
        stops=[
            Stop("east", wall - th, [th, -e * dth], contact_direction=[0, 1]),
            Stop("west", th + wall, [th, -e * dth], contact_direction=[0, 1]),
        ],
    )
    return model.with_params(**values) if values else model


def mirror(model: HybridModel, state: np.ndarray, t0: float, period: int = 1) -> np.ndarray:
    """The mirror image's state on the section through ``t0``, of the period-``period`` orbit through
    ``state`` there: ``y(t0) = -x(t0 - T/2) = -x(t0 + (period - 1/2) T)``."""
    T = model.period
    phase = 2 * math.pi * (((t0 + 0.5 * T) / T) % 1.0)
    sol = grazing.simulate(model, state, t0=t0, periods=period, phase=phase)
    return -sol.samples[-1]
