"""The pendulum's nonimpacting period-1 orbit computed the plain way, as an independent check.

Grazing points and their multipliers are found by the library with Newton's method on the
grazing equations and the variational equations (:func:`grazing.orbits.find_grazings`).  Here
the same facts come from direct simulation only: the stop is moved out of reach, the stable
nonimpacting orbit is reached by a long transient, its largest angle is the smallest guard
value over one period (the engine's guard search), and its multipliers are the eigenvalues of
the one-period map's Jacobian by central differences.  Tests compare the library's numbers
with these instead of with numbers pasted from the library's own output.

Example
-------
>>> free = free_orbit(eta=0.447)                          # case B
>>> round(math.degrees(free.theta_max), 2)               # fig 8: the grazing stop angle at eta = 0.447
41.33
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import grazing

OUT_OF_REACH = 3.0
"""A stop angle (rad) the nonimpacting orbits of the paper's cases never reach."""


@dataclass(frozen=True)
class FreeOrbit:
    """The stable nonimpacting period-1 orbit at one parameter point."""

    theta_max: float
    """Its largest angle (rad): the stop angle at which it grazes."""
    multipliers: np.ndarray
    """Eigenvalues of the one-period map's Jacobian (central differences), sorted by imaginary part."""


def free_orbit(case: str = "B", *, transient: int = 600, **params: float) -> FreeOrbit:
    """The nonimpacting orbit of the pendulum ``case`` with ``params``, the stop out of reach.

    The orbit must be stable (its multipliers are ~0.5 in modulus at the paper's grazings, so
    600 periods reach it to rounding).
    """
    model = grazing.models.pendulum(case, **{**params, "theta_hat": OUT_OF_REACH})
    settled = grazing.simulate(model, [0.0, 0.0], transient=transient, periods=1)
    x0, t0 = settled.x_final, settled.t_final
    one = grazing.simulate(model, x0, t0=t0, periods=1, guard_min=True)
    assert one.n_impacts == 0 and np.max(np.abs(one.x_final - x0)) < 1e-12, "not on a periodic orbit"
    h = 1e-6
    jac = np.empty((2, 2))
    for j in range(2):
        e = np.zeros(2)
        e[j] = h
        up = grazing.simulate(model, x0 + e, t0=t0, periods=1).x_final
        down = grazing.simulate(model, x0 - e, t0=t0, periods=1).x_final
        jac[:, j] = (up - down) / (2 * h)
    mus = np.linalg.eigvals(jac)
    return FreeOrbit(OUT_OF_REACH - one.guard_min[0], mus[np.argsort(mus.imag)])


def grazing_degrees(case: str = "B", **params: float) -> float:
    """The stop angle (degrees) at which the nonimpacting orbit at ``params`` grazes."""
    return math.degrees(free_orbit(case, **params).theta_max)
