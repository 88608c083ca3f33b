"""Periodic orbits by Newton shooting on the stroboscopic map (paper eqs. 15-16).

For a T-periodically forced system the period of an n-periodic orbit is fixed
(nT), so the shooting equations reduce to ``P^n(x) - x = 0`` on the section
``t = t0 (mod T)``.  The Jacobian ``d P^n / d x`` comes from the variational
equations with the saltation matrix (eq. 14) applied at every impact, so
Newton converges quadratically; its eigenvalues are the nontrivial Floquet
multipliers (the paper's 3-D autonomous form adds a trivial multiplier 1).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.solution import Solution
from grazing.engine.simulate import simulate
from grazing.errors import ConvergenceError, InvalidParameterError, SimulationError
from grazing.sweeps.period import detect_period

DEFAULT_TOL = 1e-11
DEFAULT_MAX_ITER = 30


@dataclass(frozen=True)
class FlowMap:
    """``P^n`` at a point: the image, its Jacobians and what happened on the way."""

    image: np.ndarray
    jacobian: np.ndarray  # d P^n / d x
    sensitivity: np.ndarray  # d P^n / d p for the requested parameters (columns)
    solution: Solution

    @property
    def impacts(self) -> int:
        return self.solution.n_impacts


def flow_map(
    model: HybridModel,
    x: np.ndarray,
    *,
    t0: float = 0.0,
    periods: int = 1,
    sensitivities: Sequence[str] = (),
    virtual: bool = False,
) -> FlowMap:
    """Apply the stroboscopic map ``periods`` times from ``x`` at time ``t0``.

    The map goes from the section ``t = t0 (mod T)`` to itself, ending at
    ``t0 + periods T``.  With ``virtual`` the stop is ignored (the flow passes
    through it).
    """
    sol = simulate(
        model,
        x,
        t0=t0,
        periods=periods,
        phase=2 * math.pi * (t0 / model.period % 1.0),  # the section through t0
        jacobian=True,
        sensitivities=tuple(sensitivities),
        guard_min=True,
        events=not virtual,
    )
    n = model.n_states
    return FlowMap(sol.x_final, sol.jacobian[:, :n], sol.jacobian[:, n:], sol)


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit of the stroboscopic map.

    Attributes
    ----------
    model
        The model and parameters.
    state
        The point of the orbit at time ``t0`` (mod the forcing period).
    period
        Period in forcing periods (``n``).
    impacts
        Impacts per period ``n``.
    monodromy
        ``d P^n / d x`` at ``state``.
    multipliers
        Floquet multipliers (eigenvalues of the monodromy), largest modulus first.
    guard_min, t_guard_min, x_guard_min
        Smallest value of the guard along the orbit, when it occurs and the
        state there (``theta_hat - max theta`` for the pendulum; negative for a
        virtual orbit that passes through the stop).
    min_impact_speed
        Smallest impact speed along the orbit (``nan`` without impacts).
    virtual
        True if computed with the stop ignored.
    residuals
        ``|P^n(x_k) - x_k|`` at each Newton iterate.
    """

    model: HybridModel
    state: np.ndarray
    t0: float
    period: int
    impacts: int
    monodromy: np.ndarray
    multipliers: np.ndarray
    guard_min: float
    t_guard_min: float
    min_impact_speed: float
    virtual: bool
    residuals: tuple[float, ...] = field(default=())
    x_guard_min: np.ndarray | None = None

    @property
    def stable(self) -> bool:
        """Linearly stable: every multiplier inside the unit circle."""
        return bool(np.max(np.abs(self.multipliers)) < 1.0)

    @property
    def abs_lambda(self) -> float:
        """Largest multiplier modulus."""
        return float(np.max(np.abs(self.multipliers)))

    @property
    def residual(self) -> float:
        return self.residuals[-1] if self.residuals else math.nan

    def max_angle(self) -> float:
        """Largest angle along the orbit, for models with a ``theta_hat`` stop angle."""
        if "theta_hat" not in self.model.params:
            raise AttributeError("max_angle is defined for models with a theta_hat parameter")
        return self.model.params["theta_hat"] - self.guard_min


def sorted_multipliers(mono: np.ndarray) -> np.ndarray:
    """Eigenvalues of ``mono`` sorted by decreasing modulus (then by imaginary part)."""
    mu = np.linalg.eigvals(mono).astype(complex)
    order = np.lexsort((-mu.imag, -np.abs(mu)))
    return mu[order]


def _orbit_from(model: HybridModel, x: np.ndarray, t0: float, n: int, fm: FlowMap, virtual: bool,
                residuals: list[float]) -> PeriodicOrbit:  # fmt: skip
    sol = fm.solution
    if not sol.jacobian_valid:
        raise ConvergenceError(
            f"the period-{n} orbit sticks to the stop; its Jacobian across sticking is not available"
        )
    gmin = sol.guard_min
    assert gmin is not None
    speeds = sol.impacts.speed
    return PeriodicOrbit(
        model=model,
        state=np.array(x, dtype=float),
        t0=float(t0),
        period=n,
        impacts=fm.impacts,
        monodromy=fm.jacobian,
        multipliers=sorted_multipliers(fm.jacobian),
        guard_min=gmin[0],
        t_guard_min=gmin[1],
        min_impact_speed=float(speeds.min()) if speeds.size else math.nan,
        virtual=virtual,
        residuals=tuple(residuals),
        x_guard_min=gmin[2],
    )


def initial_guess(
    model: HybridModel, *, t0: float = 0.0, transient: int = 500, samples: int = 128, virtual: bool = False
) -> tuple[np.ndarray, int]:
    """A point near an attractor and its period, from simulation starting at rest.

    Returns the last stroboscopic sample and the detected period (0 if none).
    """
    sol = simulate(
        model,
        np.zeros(model.n_states),
        t0=t0,
        transient=transient,
        periods=samples,
        phase=2 * math.pi * (t0 / model.period % 1.0),
        impacts="none",
        events=not virtual,
    )
    return sol.samples[-1].copy(), detect_period(sol.samples, tol=1e-6)


def find_orbit(
    model: HybridModel,
    x0: Sequence[float] | np.ndarray | None = None,
    *,
    period: int | None = None,
    t0: float = 0.0,
    virtual: bool = False,
    tol: float = DEFAULT_TOL,
    max_iter: int = DEFAULT_MAX_ITER,
    transient: int = 500,
) -> PeriodicOrbit:
    """Find a periodic orbit by Newton's method on the stroboscopic map.

    Parameters
    ----------
    model
        Model and parameters.
    x0
        Initial guess at time ``t0``.  Default: the state after ``transient``
        forcing periods from rest (and its detected period, if ``period`` is
        not given).
    period
        Period in forcing periods (default: detected by simulation, else 1).
    t0
        Time of the section (sets the forcing phase of ``state``).
    virtual
        Ignore the stop (for nonimpacting orbits continued past grazing).
    tol
        Convergence when ``max |P^n(x) - x| <= tol``.
    max_iter
        Newton iteration limit.

    Raises
    ------
    ConvergenceError
        With the residual, the iteration count and what to try.

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> orbit = find_orbit(m)
    >>> orbit.period, orbit.impacts, orbit.stable
    (5, 1, True)
    """
    if period is not None and (not isinstance(period, (int, np.integer)) or period < 1):
        raise InvalidParameterError(f"period must be a positive integer, got {period!r}")
    if x0 is None:
        x, detected = initial_guess(model, t0=t0, transient=transient, virtual=virtual)
        n = int(period or detected or 1)
    else:
        x = model.check_state(x0, t0, allowed=not virtual)
        n = int(period or 1)
    residuals: list[float] = []
    step_note = ""
    for it in range(max_iter + 1):
        try:
            fm = flow_map(model, x, t0=t0, periods=n, virtual=virtual)
        except SimulationError as exc:
            raise ConvergenceError(f"Newton iterate {it} could not be integrated: {exc}") from None
        F = fm.image - x
        res = float(np.max(np.abs(F)))
        residuals.append(res)
        if not np.isfinite(res):
            break
        if res <= tol:
            return _orbit_from(model, x, t0, n, fm, virtual, residuals)
        if it == max_iter:
            break
        A = fm.jacobian - np.eye(model.n_states)
        try:
            dx = np.linalg.solve(A, -F)
        except np.linalg.LinAlgError:
            step_note = "; the Jacobian P_x - I is singular (a fold or multiplier 1?)"
            break
        # Backtrack so that the iterate stays in the allowed region.
        lam = 1.0
        for _ in range(30):
            trial = x + lam * dx
            if virtual or model.guard(trial, t0) >= 0:
                break
            lam *= 0.5
        x = trial
    raise ConvergenceError(
        f"Newton did not converge to a period-{n} orbit: residual {residuals[-1]:.3g} after "
        f"{len(residuals) - 1} iterations{step_note}; try another initial guess, another period, "
        "or a longer transient"
    )
