"""A periodic orbit of the stroboscopic map as a record, and what its monodromy says.

:class:`PeriodicOrbit` is what shooting (:mod:`grazing.orbits.shooting`, single) and the segmented
equations (:mod:`grazing.orbits.segments`, multiple) both find; here too are the tests of its
monodromy (how many multipliers lie outside the unit circle, whether its multiplier 1 is double: an
orbit that is not isolated) and :func:`_orbit_from`, the record of a converged flow map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.options import NON_ISOLATED_TOL, NOT_ISOLATED_TOL, UNIT_CIRCLE_TOL
from grazing.errors import ConvergenceError
from grazing.maps import FlowMap

CROSSING_TOL = 1e-9
"""A virtual orbit whose guard goes below ``-CROSSING_TOL`` passes through that stop."""


def unstable_count(multipliers: np.ndarray) -> int:
    """The number of ``multipliers`` outside the unit circle by more than ``core.options.UNIT_CIRCLE_TOL``.

    Examples
    --------
    >>> unstable_count(np.array([1.5, 0.2])), unstable_count(np.exp(1j * np.array([0.3, -0.3]) + 1e-15))
    (1, 0)
    """
    return int(np.sum(np.abs(multipliers) > 1.0 + UNIT_CIRCLE_TOL))


def multipliers_text(pairs: Any, digits: int = 4) -> str:
    """Multipliers (complex numbers or ``[re, im]`` pairs) as ``+a+bi, ...`` to ``digits`` decimals.

    A part that rounds to zero is printed ``+0.0000``, whatever its sign: the sign of a
    rounding-level imaginary part (a double real multiplier) depends on the processor's linear
    algebra.

    Examples
    --------
    >>> multipliers_text([complex(-0.03214, 1e-17), complex(-0.03214, -1e-17)])
    '-0.0321+0.0000i, -0.0321+0.0000i'
    >>> multipliers_text([[0.5, 0.25]], digits=2)
    '+0.50+0.25i'
    """

    def part(v: float) -> str:
        r = round(float(v), digits)
        return f"{(r if r != 0.0 else 0.0):+.{digits}f}"

    out = []
    for z in pairs:
        re_, im = (z.real, z.imag) if isinstance(z, complex | np.complexfloating) else z
        out.append(f"{part(re_)}{part(im)}i")
    return ", ".join(out)


def kept_directions(monodromy: np.ndarray) -> int:
    """How many directions the monodromy matrix ``M`` keeps: the singular values of ``M - I`` below
    ``core.options.NOT_ISOLATED_TOL`` (relative to ``1 + |M|``).  Two or more: the orbit is not isolated.

    Examples
    --------
    >>> kept_directions(np.eye(2)), kept_directions(np.diag([1.0, 0.5])), kept_directions(np.diag([0.3, 0.5]))
    (2, 1, 0)
    """
    m = np.asarray(monodromy, dtype=float)
    sv = np.linalg.svd(m - np.eye(m.shape[0]), compute_uv=False)
    return int(np.sum(sv <= NOT_ISOLATED_TOL * (1.0 + np.linalg.norm(m, 2))))


def multiplier_one_multiplicity(monodromy: np.ndarray) -> int:
    """The multiplicity of the multiplier 1 of ``M``, up to 2: the multipliers within
    ``core.options.NON_ISOLATED_TOL`` of 1, or the directions ``M`` keeps (:func:`kept_directions`) if
    more.  0: ``M - I`` is regular; 1: one multiplier 1 (a fold, a branch
    point); 2: a double one (a Jordan block or an eigenspace: the orbit is not isolated,
    :func:`is_isolated`).

    Examples
    --------
    >>> jordan = np.array([[1.0, 5.2], [0.0, 1.0]])  # a free mass at rest over one period T = 5.2
    >>> cases = (np.diag([0.3, 0.5]), np.diag([1.0, 0.5]), jordan, np.eye(2))
    >>> [multiplier_one_multiplicity(m) for m in cases]
    [0, 1, 2, 2]
    """
    m = np.asarray(monodromy, dtype=float)
    mu = np.linalg.eigvals(m)
    near = int(np.sum(np.abs(mu - 1.0) <= NON_ISOLATED_TOL))
    return min(2, max(near, kept_directions(m)))


def is_isolated(monodromy: np.ndarray) -> bool:
    """Is the periodic orbit of monodromy ``M`` isolated: is its multiplier 1, if any, simple?

    A double multiplier 1 (a Jordan block: ``M = [[1, T], [0, 1]]`` on a free mass at rest; or an
    eigenspace: ``M = I``) means a family of periodic states through the orbit or a drift away from
    it: the orbit is neither stable nor unstable, and no branch of orbits can be followed through it.
    (The stroboscopic map of a forced model has no multiplier 1 of its own, as the autonomous flow's
    trivial one: every multiplier 1 is the orbit's.)

    Examples
    --------
    >>> is_isolated(np.array([[1.0, 5.2], [0.0, 1.0]])), is_isolated(np.diag([1.0, 0.5]))
    (False, True)
    """
    return multiplier_one_multiplicity(monodromy) < 2


def not_isolated_message(monodromy: np.ndarray, period: int) -> str:
    """Why a branch cannot go through an orbit that is not isolated (:func:`is_isolated`), in one line."""
    kept = kept_directions(monodromy)
    if kept >= 2:
        why = f"its monodromy keeps {kept} directions: every state near it is periodic too"
    else:
        why = "its multiplier 1 is double, a Jordan block: a neutral direction where nearby states drift"
    return f"the period-{period} orbit is not isolated ({why}), so no branch of orbits goes through it"


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
        state there (negative for a virtual orbit that passes through the stop;
        zero at an impact).
    min_impact_speed
        Smallest impact speed along the orbit (``nan`` without impacts).
    virtual
        True if computed with the stop ignored.
    residuals
        ``|P^n(x_k) - x_k|`` at each Newton iterate.
    impact_times, impact_speeds, impact_states
        The orbit's impacts over one period ``[t0, t0 + n T)``: times, approach
        speeds and the states on the stop just before the reset.
    approach
        ``(h, t, x)``: the orbit's closest approach to the stop away from its
        impacts (a local minimum of the guard in free flight), or None.
    stop
        Index of the stop that ``guard_min`` and ``approach`` refer to (models
        with several stops); ``impact_stops`` gives the stop of each impact.
    guard_min_by_stop, approach_by_stop
        ``(h, t, x)`` of the smallest guard value and of the closest approach
        for every stop, in the order of the model's ``stop_names`` (see
        :attr:`guard_mins` and :attr:`crossed_stops`).
    t0
        The time of the section the orbit is taken on (:attr:`state` is its
        point there).
    impact_stops
        The stop of each of the orbit's impacts (index into the model's ``stop_names``).
    mode
        A model with modes: the mode of :attr:`state` on the section (the same
        at both ends of the period); None for a model without modes.
    switch_times, switch_transitions
        A model with modes: the orbit's changes of mode over one period
        ``[t0, t0 + n T)``, their times and transitions (indices into the model's
        ``stop_names``; a reset that changes the mode is both an impact and a
        switch); see :attr:`switch_signature`.
    switch_states
        The state at each switch (after the reset, if any), shape ``(n_switches, n_states)``; None
        where not recorded.
    passed_stops
        A segmented orbit on a model with modes (multiple shooting, which keeps no guard minima
        there): the transitions with a reset its segments pass through between its impacts, found
        by running them with the resets watched (see :attr:`crossed_stops`).

    Examples
    --------
    The paper's stable period-5 orbit at θ̂ = 40°, η = 0.446, with one
    impact in its third forcing period:

    >>> import math, numpy as np, grazing
    >>> from grazing.orbits import find_orbit
    >>> orbit = find_orbit(grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40)))
    >>> orbit.period, orbit.impacts, orbit.signature, orbit.stable, orbit.impact_stops.tolist()
    (5, 1, (0, 0, 1, 0, 0), True, [0])
    >>> np.abs(orbit.multipliers).round(4).tolist(), bool(orbit.residuals[-1] < 1e-11)
    ([0.3464, 0.002], True)
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
    impact_times: np.ndarray = field(default_factory=lambda: np.empty(0))
    impact_speeds: np.ndarray = field(default_factory=lambda: np.empty(0))
    impact_states: np.ndarray | None = None
    approach: tuple[float, float, np.ndarray] | None = None
    stop: int = 0
    impact_stops: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    guard_min_by_stop: tuple[tuple[float, float, np.ndarray], ...] = ()
    approach_by_stop: tuple[tuple[float, float, np.ndarray] | None, ...] = ()
    mode: str | None = None
    switch_times: np.ndarray = field(default_factory=lambda: np.empty(0))
    switch_transitions: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    passed_stops: tuple[str, ...] = ()
    switch_states: np.ndarray | None = None

    @property
    def guard_mins(self) -> np.ndarray:
        """The smallest value of every stop's guard along the orbit."""
        return np.array([g[0] for g in self.guard_min_by_stop])

    @property
    def crossed_stops(self) -> tuple[str, ...]:
        """The stops a virtual orbit passes through (where any are, it is not a physical motion): those
        whose guard minimum is below ``-CROSSING_TOL``, and :attr:`passed_stops`."""
        below = [name for name, g in zip(self.model.stop_names, self.guard_mins) if g < -CROSSING_TOL]
        return tuple(dict.fromkeys([*below, *self.passed_stops]))

    @property
    def signature(self) -> tuple[int, ...]:
        """Impacts in each of the orbit's ``period`` forcing periods after ``t0``.

        Two orbits with different signatures are different orbits: a branch of
        periodic orbits keeps its signature up to a grazing.
        """
        T = self.model.period
        counts = [0] * self.period
        for t in self.impact_times:
            counts[min(self.period - 1, max(0, math.floor((t - self.t0) / T)))] += 1
        return tuple(counts)

    @property
    def switch_signature(self) -> tuple[tuple[str, ...], ...]:
        """The transitions of the orbit's switches in each of its ``period`` forcing periods after ``t0``,
        in order (a model with modes; empty tuples without switches).

        As :attr:`signature` for impacts: a branch of periodic orbits keeps its switches, in number and
        order, up to a grazing of a switching surface.
        """
        T = self.model.period
        per: list[list[str]] = [[] for _ in range(self.period)]
        names = self.model.switch_names  # (a sliding pseudo-mode's entries and exits after the transitions)
        for t, j in zip(self.switch_times, self.switch_transitions):
            per[min(self.period - 1, max(0, math.floor((t - self.t0) / T)))].append(names[int(j)])
        return tuple(tuple(p) for p in per)

    def section_clearance(self) -> float:
        """Distance, in periods, from the section ``t0 (mod T)`` to the nearest impact or switch of mode
        (0.5 if none)."""
        events = np.concatenate([self.impact_times, self.switch_times])
        if not events.size:
            return 0.5
        d = np.mod((events - self.t0) / self.model.period, 1.0)
        return float(np.min(np.minimum(d, 1.0 - d)))

    @property
    def unstable_count(self) -> int:
        """How many multipliers lie outside the unit circle (by more than ``options.UNIT_CIRCLE_TOL``)."""
        return unstable_count(self.multipliers)

    @property
    def isolated(self) -> bool:
        """No double multiplier 1 (:func:`is_isolated`): ``False`` for an orbit in a family of periodic
        states or with a drift along one (a Jordan block), which is then neither stable nor unstable."""
        return is_isolated(self.monodromy)

    @property
    def stable(self) -> bool:
        """Linearly stable: isolated, no multiplier outside the unit circle (one on it, to rounding, is
        not outside)."""
        return self.unstable_count == 0 and self.isolated

    @property
    def abs_lambda(self) -> float:
        """Largest multiplier modulus."""
        return float(np.max(np.abs(self.multipliers)))

    @property
    def residual(self) -> float:
        return self.residuals[-1] if self.residuals else math.nan


def sorted_multipliers(mono: np.ndarray) -> np.ndarray:
    """Eigenvalues of ``mono`` sorted by decreasing modulus (then by imaginary part)."""
    mu = np.linalg.eigvals(mono).astype(complex)
    order = np.lexsort((-mu.imag, -np.abs(mu)))
    return mu[order]


def returning_mode_message(fm: FlowMap, n: int, t0: float) -> str:
    """Why the period-``n`` map ``fm`` of a model with modes has no fixed point there: it returns in
    another mode than it started in (empty where it returns in the same mode)."""
    if fm.mode == fm.mode_final:
        return ""
    return (
        f"the period-{n} map from mode {fm.mode!r} at t0 = {t0:.10g} returns in mode {fm.mode_final!r}: "
        "a periodic orbit is in the same mode at both ends of its period; give another section time, "
        "starting mode or period"
    )


def _orbit_from(model: HybridModel, x: np.ndarray, t0: float, n: int, fm: FlowMap, virtual: bool,
                residuals: list[float], stop: int = 0) -> PeriodicOrbit:  # fmt: skip
    sol = fm.solution
    if not sol.jacobian_valid:
        raise ConvergenceError(
            f"the period-{n} orbit sticks to the stop; its Jacobian across sticking is not available"
        )
    returns_elsewhere = returning_mode_message(fm, n, t0)
    if returns_elsewhere:
        raise ConvergenceError(returns_elsewhere)
    gmin = sol.guard_min
    if gmin is None:  # (a model with modes: not computed yet)
        gmin = (math.nan, math.nan, None)
    sw = sol.switches
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
        impact_times=sol.impacts.t.copy(),
        impact_speeds=speeds.copy(),
        impact_states=sol.impacts.state.copy(),
        approach=sol.approach_min,
        stop=stop,
        impact_stops=sol.impacts.stop.copy(),
        guard_min_by_stop=sol.guard_min_by_stop or (),
        approach_by_stop=sol.approach_by_stop or (),
        mode=fm.mode,
        switch_times=sw.t.copy() if sw is not None else np.empty(0),
        switch_transitions=sw.transition.copy() if sw is not None else np.zeros(0, dtype=int),
        switch_states=sw.state.copy() if sw is not None else None,
    )
