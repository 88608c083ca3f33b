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


def half_map(model: HybridModel, state: np.ndarray, t0: float) -> tuple[np.ndarray, np.ndarray]:
    """``G(x) = -x(t0 + T/2)`` from ``x(t0) = x``, and its Jacobian: the stroboscopic map is ``P = G o G``.

    By the symmetry, the motion from ``-x(t0 + T/2)`` at ``t0 + T/2`` is the mirror image of the
    motion from ``x`` at ``t0``, so ``P(x) = G(G(x))``.  A symmetric period-1 orbit is a fixed
    point of ``G`` (:func:`mirror` is ``G`` for period 1), and it breaks its symmetry where ``G``
    has the multiplier -1: there ``P`` has the multiplier ``(-1)^2 = 1`` with an antisymmetric
    eigenvector.  Impacts on the way are applied, with their saltation matrices.
    """
    T = model.period
    phase = 2 * math.pi * (((t0 + 0.5 * T) / T) % 1.0)
    sol = grazing.simulate(model, state, t0=t0, periods=1, phase=phase, jacobian=True)
    return -sol.samples[-1], -sol.jacobian


def symmetry_breaking(
    model: HybridModel, param: str, state: np.ndarray, t0: float, lo: float, hi: float
) -> float:
    """Where the symmetric period-1 orbit through ``state`` (at ``t0``) breaks its symmetry, for
    ``param`` in ``[lo, hi]``: the zero of ``det(G_x + I)`` on the fixed points of :func:`half_map`,
    each found by Newton's method (an independent route to the branch point of ``P``)."""
    from scipy.optimize import brentq

    guess = [np.array(state, dtype=float)]
    eye = np.eye(len(state))

    def test(value: float) -> float:
        m = model.with_params(**{param: value})
        x = guess[0].copy()
        for _ in range(40):
            g, J = half_map(m, x, t0)
            step = np.linalg.solve(J - eye, x - g)
            x = x + step
            if np.max(np.abs(step)) < 1e-14:
                break
        g, J = half_map(m, x, t0)
        assert np.max(np.abs(g - x)) < 1e-11, "no symmetric orbit"
        guess[0] = x
        return float(np.linalg.det(J + eye))

    return float(brentq(test, lo, hi, xtol=1e-15, rtol=1e-15))
