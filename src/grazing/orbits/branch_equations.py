"""The equations of a branch of periodic orbits: ``F(x, p) = P^n(x; p) - x`` and their Jacobian.

A point of the branch is ``u = (x, p)``: the orbit's state on the stroboscopic
section ``t = t0 (mod T)`` and the continuation parameter.  The Jacobian
``[P_x - I, P_p]`` comes from the variational equations (saltation matrices at
the impacts, the parameter's sensitivity as an extra column, the moving return
time included for a parameter that sets the forcing period).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from grazing.core.model import HybridModel
from grazing.errors import ConvergenceError
from grazing.maps import flow_map
from grazing.orbits.shooting import PeriodicOrbit, _orbit_from

BranchEquations = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, PeriodicOrbit]]
"""``u -> (F, DF, orbit)``: the residual ``P^n(x; p) - x``, the Jacobian ``[P_x - I, P_p]`` and the
periodic orbit through ``x`` (its monodromy, multipliers, impacts...)."""


def branch_equations(
    model: HybridModel, param: str, period: int, t0: float, virtual: bool, stop: int = 0,
    mode: str | None = None,
) -> BranchEquations:  # fmt: skip
    """``u = (x, p) -> (F, DF, orbit)`` for the branch equations ``P^n(x; p) - x = 0``.

    On a model with modes ``x`` is in ``mode`` on the section; a map that returns in another mode
    raises :class:`~grazing.errors.ConvergenceError` (no orbit there).

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> o = grazing.orbits.find_orbit(m)
    >>> F, DF, orbit = branch_equations(m, "eta", o.period, o.t0, False)(np.append(o.state, 0.446))
    >>> bool(abs(F).max() < 1e-10), DF.shape, orbit.period
    (True, (2, 3), 5)
    """
    n = model.n_states
    eye = np.eye(n)

    def evaluate(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, PeriodicOrbit]:
        m = model.with_params(**{param: float(u[-1])})
        x = u[:-1]
        fm = flow_map(
            m, x, t0=t0, periods=period, sensitivities=[param], virtual=virtual, stop_name=stop, mode=mode
        )
        if not fm.solution.jacobian_valid:
            raise ConvergenceError("the orbit sticks to the stop: no Jacobian across sticking")
        F = fm.image - x
        orbit = _orbit_from(m, x, t0, period, fm, virtual, [float(np.max(np.abs(F)))], stop)
        return F, np.hstack([fm.jacobian - eye, fm.sensitivity]), orbit

    return evaluate
