"""An exact reference for piecewise-linear forced models with modes, with or without linear resets.

In mode ``k`` the state obeys ``x' = A_k x + b cos(w t) + d_k``; its solution is
``x(t) = exp(A_k (t - t0)) (x0 - xp_k(t0)) + xp_k(t)`` with the particular
solution ``xp_k(t) = Re(X_k exp(i w t)) - A_k^-1 d_k``, ``X_k = (i w I - A_k)^-1 b``.
A mode is left when a linear guard ``c . x + e`` of one of its transitions
reaches 0: the guard is sampled densely on the exact solution and each sign
change refined by Brent's method (to 1e-15).  A transition may reset the state
linearly, ``x+ = R x`` (the identity without a reset).  The Jacobian of the flow
map is the product of the exponentials and the saltation matrices of the
transitions, ``S = R + (f+ - R f-) c^T / (c^T f-)`` with ``f-`` the source
mode's field at ``x`` and ``f+`` the target's at ``R x`` (no reset:
``S = I + (f+ - f-) c^T / (c^T f-)``).  Nothing here uses grazing's engine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

SAMPLES_PER_PERIOD = 800


@dataclass(frozen=True)
class LinearMode:
    """``x' = A x + b cos(w t) + d``, left through ``exits``: ``(c, e, target)`` with guard ``c . x + e``,
    or ``(c, e, target, R)`` with the reset ``x+ = R x``."""

    A: np.ndarray
    b: np.ndarray
    d: np.ndarray
    exits: tuple[tuple[np.ndarray, float, int], ...]


@dataclass
class PiecewiseLinearModel:
    modes: list[LinearMode]
    w: float

    @property
    def period(self) -> float:
        return 2 * math.pi / self.w

    def xp(self, k: int, t: float) -> np.ndarray:
        md = self.modes[k]
        n = md.A.shape[0]
        X = np.linalg.solve(1j * self.w * np.eye(n) - md.A, md.b.astype(complex))
        return (X * np.exp(1j * self.w * t)).real - np.linalg.solve(md.A, md.d)

    def f(self, k: int, x: np.ndarray, t: float) -> np.ndarray:
        md = self.modes[k]
        return md.A @ x + md.b * math.cos(self.w * t) + md.d

    def flow(self, k: int, x0: np.ndarray, t0: float, t: float) -> np.ndarray:
        return expm(self.modes[k].A * (t - t0)) @ (x0 - self.xp(k, t0)) + self.xp(k, t)

    def first_exit(self, k: int, x0: np.ndarray, t0: float, t1: float) -> tuple[float, int] | None:
        """The first switch out of mode ``k`` in ``(t0, t1]``: (time, index of the exit)."""
        n = max(8, math.ceil((t1 - t0) / self.period * SAMPLES_PER_PERIOD))
        ts = np.linspace(t0, t1, n + 1)
        best = None
        for i, (c, e, *_) in enumerate(self.modes[k].exits):

            def guard(tt: float, c: np.ndarray = c, e: float = e) -> float:
                return float(c @ self.flow(k, x0, t0, tt) + e)

            g = [guard(tt) for tt in ts]
            for a in range(1, n + 1):
                if g[a] < 0.0 <= g[a - 1] and not (a == 1 and g[0] == 0.0 and g[1] > 0.0):
                    tz = brentq(guard, ts[a - 1], ts[a], xtol=1e-15, rtol=4 * np.finfo(float).eps)
                    if best is None or tz < best[0]:
                        best = (tz, i)
                    break
        return best

    def run(self, x0, k0: int, t0: float, t1: float):
        """From ``x0`` in mode ``k0`` at ``t0`` to ``t1``: ``(x, mode, J, switches)``; switches are
        ``(t, exit index, from, to)``."""
        x, k, t = np.asarray(x0, dtype=float), k0, t0
        J = np.eye(len(x))
        switches = []
        while True:
            ev = self.first_exit(k, x, t, t1)
            if ev is None:
                J = expm(self.modes[k].A * (t1 - t)) @ J
                return self.flow(k, x, t, t1), k, J, switches
            tz, i = ev
            c, _, target, *reset = self.modes[k].exits[i]
            R = reset[0] if reset else np.eye(len(x))
            xz = self.flow(k, x, t, tz)
            J = expm(self.modes[k].A * (tz - t)) @ J
            fm, fp = self.f(k, xz, tz), self.f(target, R @ xz, tz)
            S = R + np.outer(fp - R @ fm, c) / (c @ fm)
            J = S @ J
            switches.append((tz, i, k, target))
            x, k, t = R @ xz, target, tz
