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
from dataclasses import dataclass

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.options import (
    DEFAULT_TRANSIENT,
    NEWTON_MAX_ITER,
    NEWTON_TOL,
)
from grazing.core.period import detect_period
from grazing.core.solution import Solution
from grazing.engine.simulate import simulate
from grazing.errors import (
    ConvergenceError,
    GrazingError,
    InvalidParameterError,
    InvalidStateError,
    SimulationError,
)
from grazing.maps import FlowMap, flow_map
from grazing.orbits.periodic import (  # noqa: F401 (the record and its tests, here as before)
    CROSSING_TOL,
    PeriodicOrbit,
    _orbit_from,
    is_isolated,
    kept_directions,
    multiplier_one_multiplicity,
    not_isolated_message,
    returning_mode_message,
    sorted_multipliers,
    unstable_count,
)
from grazing.orbits.segments import (
    GRAZING_SPEED_RATIO,
    MULTIPLE_SHOOTING_NORM,
    cut_speeds,
    resectioned,
    segmented_newton,
    solve_segments,
)

SECTION_MARGIN = 0.05
"""When an impact of the starting orbit lies within this fraction of a period of the
stroboscopic section, an automatic section (``t0=None``) moves to a quiet phase."""


def quiet_section(orbit: PeriodicOrbit) -> float:
    """A section time in ``[0, T)`` as far as possible (in phase) from every impact and switch of mode
    of ``orbit``."""
    T = orbit.model.period
    events = np.concatenate([orbit.impact_times, orbit.switch_times]) if orbit.mode else orbit.impact_times
    if not events.size:
        return orbit.t0 % T
    phases = np.sort(np.mod(events / T, 1.0))
    gaps = np.diff(np.append(phases, phases[0] + 1.0))
    i = int(np.argmax(gaps))
    return float((phases[i] + gaps[i] / 2) % 1.0 * T)


def move_section(orbit: PeriodicOrbit, t_new: float, *, tol: float = NEWTON_TOL) -> PeriodicOrbit:
    """The same orbit on the section through ``t_new`` (a time in ``[0, T)``).

    The orbit is followed from its section to the next time ``t_new (mod T)``
    and Newton's method is run again there (the monodromy and the point
    change with the section; the multipliers do not).  On a model with modes,
    in the mode the orbit is in at ``t_new``.
    """
    T = orbit.model.period
    if not orbit.virtual and float(np.linalg.norm(orbit.monodromy)) > MULTIPLE_SHOOTING_NORM:
        # A strongly unstable orbit: a run over the lag (and single shooting) would leave it by its
        # rounding times |M|, even land in another mode; its own segments are moved to the new section.
        moved = resectioned(orbit, t_new)
        if moved is not None:
            layout, u, t0 = moved
            try:
                return solve_segments(
                    orbit.model,
                    layout,
                    u,
                    t0,
                    orbit.period,
                    tol=tol,
                    max_iter=NEWTON_MAX_ITER,
                    stop=orbit.stop,
                )
            except (GrazingError, np.linalg.LinAlgError):
                pass  # (then as any orbit's)
    lag = (t_new - orbit.t0) % T
    x, mode = orbit.state, orbit.mode
    if lag > 0:
        phase = 2 * math.pi * ((orbit.t0 + lag) / T % 1.0)
        sol = simulate(
            orbit.model, orbit.state, t0=orbit.t0, periods=1, phase=phase, impacts="none",
            events=not orbit.virtual, mode=orbit.mode,
        )  # fmt: skip
        x, mode = sol.x_final, sol.mode_final
    return find_orbit(
        orbit.model, x, period=orbit.period, t0=t_new, virtual=orbit.virtual, tol=tol, stop_name=orbit.stop,
        mode=mode,
    )  # fmt: skip


GUESS = "an initial guess (x0=)"
"""What to give when the default guess, simulated from rest, cannot start Newton's method."""


@dataclass(frozen=True)
class InitialGuess:
    """A point near an attractor, from simulation starting at rest (:func:`initial_guess`).

    Attributes
    ----------
    state
        The last stroboscopic sample.
    period
        The period detected over the sampled periods (0 if none).
    transient
        Forcing periods simulated before sampling.
    sticking
        How the motion sticks to a stop over the sampled periods: ``""`` (it
        does not), or a phrase such as ``"ends riding on the stop"`` (see
        :func:`sticking_phrase`).
    mode
        A model with modes: the mode of :attr:`state` (None without modes).
    """

    state: np.ndarray
    period: int
    transient: int
    sticking: str = ""
    mode: str | None = None


def _stop_phrase(name: str) -> str:
    """A stop as messages name it: ``the stop`` (a model's only, unnamed stop) or ``stop 'left'``."""
    return "the stop" if name == "stop" else f"stop {name!r}"


def _sticking_stops(sol: Solution, riding: bool) -> list[str]:
    """The stop of each sticking interval of ``sol``: that of the last recorded impact before it (the
    chattering that ends in it), else the stop the run ends on (last interval), else ``""``."""
    model = sol.model
    if model.n_stops == 1:
        return [model.stop_names[0]] * len(sol.sticking)
    names = []
    for start in sol.sticking[:, 0]:
        before = np.flatnonzero(sol.impacts.t <= start + 1e-9 * max(1.0, abs(start)))
        names.append(sol.impacts.stop_name(int(before[-1])) if before.size else "")
    if riding and not names[-1]:
        names[-1] = model.stop_names[int(np.argmin(np.abs(model.guards(sol.x_final, sol.t_final))))]
    return names


def sticking_phrase(sol: Solution, periods: int) -> str:
    """How the run ``sol``, sampled over ``periods`` forcing periods, sticks to its stops, in words.

    ``""`` without sticking; ``"ends riding on the stop"`` when one interval
    lasts to the end of the run; else ``"sticks to stop 'right' 3 times and
    to stop 'left' 2 times in 2 forcing periods"`` (each interval's stop as
    :func:`_sticking_stops` finds it; intervals whose stop it does not find
    are left out unless it finds none).
    """
    if not len(sol.sticking):
        return ""
    riding = sol.sticking[-1, 1] >= sol.t_final - 1e-9 * max(1.0, abs(sol.t_final))
    names = _sticking_stops(sol, riding)
    if riding and len(names) == 1:
        return f"ends riding on {_stop_phrase(names[0]) if names[0] else 'a stop'}"
    known = [n for n in names if n] or names  # (one begun before the sampled span has no impact before it)
    counts = {name: known.count(name) for name in dict.fromkeys(known)}
    parts = [f"{_stop_phrase(n) if n else 'a stop'} {k} time{'s' * (k > 1)}" for n, k in counts.items()]
    return f"sticks to {' and to '.join(parts)} in {periods} forcing period{'s' * (periods > 1)}"


def initial_guess(
    model: HybridModel,
    *,
    t0: float = 0.0,
    transient: int = DEFAULT_TRANSIENT,
    samples: int = 128,
    virtual: bool = False,
    mode: str | None = None,
) -> InitialGuess:
    """A point near an attractor and its period, from simulation starting at rest (on a model with
    modes, in ``mode``, its initial mode by default; the guess is then in the mode the run ends in,
    :attr:`InitialGuess.mode`).

    Raises
    ------
    SimulationError, InvalidStateError
        When the simulation fails (it diverges from an unstable orbit, say) or
        rest is beyond a stop, saying what to do: give an initial guess.
    """
    try:
        sol = simulate(
            model,
            np.zeros(model.n_states),
            t0=t0,
            transient=transient,
            periods=samples,
            phase=2 * math.pi * (t0 / model.period % 1.0),
            impacts="sampled",  # (they name the stop of each sticking interval)
            events=not virtual,
            mode=mode,
        )
    except (SimulationError, InvalidStateError) as exc:
        flow = " with the stops ignored" if virtual else ""
        raise type(exc)(
            f"cannot guess the orbit by simulating from rest{flow}: {exc}; give {GUESS} near the orbit, "
            "from which Newton's method finds it without simulating it (unstable orbits too, which a "
            "simulation never settles on)"
        ) from None
    return InitialGuess(
        state=sol.samples[-1].copy(),
        period=detect_period(sol.samples, tol=1e-6),
        transient=transient,
        sticking=sticking_phrase(sol, samples),
        mode=sol.mode_final,
    )


def find_orbit(
    model: HybridModel,
    x0: Sequence[float] | np.ndarray | None = None,
    *,
    period: int | None = None,
    t0: float | None = 0.0,
    virtual: bool = False,
    tol: float = NEWTON_TOL,
    max_iter: int = NEWTON_MAX_ITER,
    transient: int = DEFAULT_TRANSIENT,
    stop_name: int | str | None = None,
    through_stops: bool = True,
    mode: str | None = None,
) -> PeriodicOrbit:
    """Find a periodic orbit by Newton's method on the stroboscopic map.

    Parameters
    ----------
    model
        Model and parameters.
    x0
        Initial guess at time ``t0``.  Default: the state after ``transient``
        forcing periods from rest (and its detected period, if ``period`` is
        not given).  A simulation settles only on a stable orbit: where the
        motion from rest diverges (an unstable orbit), sticks to a stop or
        settles on another orbit, give ``x0`` (the error says which happened).
    period
        Period in forcing periods (default: detected by simulation, else 1).
    t0
        Time of the section (sets the forcing phase of ``state``).  ``None``:
        chosen automatically, at 0 unless an impact of the orbit lies within
        :data:`SECTION_MARGIN` of a period of it, else half-way between the
        impacts furthest apart in phase (the stroboscopic map is not smooth
        where an impact falls on the section).
    virtual
        Ignore the stop (for nonimpacting orbits continued past grazing).
        Without it, where Newton's method on the physical map fails, it is
        run from the same guess on the flow through the stops too: an orbit
        found there that keeps clear of every stop is a physical orbit (an
        unstable orbit whose neighbours hit a stop, say) and is returned.
    tol
        Convergence when ``max |P^n(x) - x| <= tol``.
    max_iter
        Newton iteration limit.
    stop_name
        The stop (name or index; the first by default) whose closest approach
        the orbit reports (``guard_min``, ``approach``), for grazing analysis.
    through_stops
        Where Newton's method on the physical map fails, try it on the flow
        through the stops too (see ``virtual``); False: do not (a caller that
        only wants the orbit a run approaches, at the cost of one try).
    transient
        Forcing periods simulated from rest for the default guess.
    mode
        A model with modes: the mode of ``x0`` on the section (by default the
        one it lies in, :meth:`~grazing.HybridModel.start_mode`: the initial
        mode where it is in its region), which the orbit must be in again one
        period later.
        Without ``x0``, the guess is simulated from rest in ``mode`` and the
        orbit is sought in the mode that run ends in.  The monodromy carries
        the saltation matrices of the switches (a switch of mode without a
        reset too); multiple shooting splits the orbit at its transitions
        with a reset (:mod:`grazing.orbits.segments`); ``virtual`` orbits
        and the guard minimum are not available on models with modes yet.

    Returns
    -------
    PeriodicOrbit
        The orbit: its state on the section, period, impacts, monodromy and
        Floquet multipliers.

    Raises
    ------
    ConvergenceError
        With the residual, the iteration count and what to try; also where
        the motion sticks to a stop (no Jacobian across sticking).
    SimulationError, InvalidStateError
        Without ``x0``, when the simulation from rest fails or rest is beyond
        a stop (see :func:`initial_guess`).

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
    if t0 is None:
        orbit = find_orbit(
            model, x0, period=period, t0=0.0, virtual=virtual, tol=tol, max_iter=max_iter,
            transient=transient, stop_name=stop_name, through_stops=through_stops, mode=mode,
        )  # fmt: skip
        if orbit.section_clearance() >= SECTION_MARGIN:
            return orbit
        return move_section(orbit, quiet_section(orbit), tol=tol)
    stop = model.stop_index(stop_name)
    guess: InitialGuess | None = None
    note = ""  # why the default guess's period was not used, if it was not
    if x0 is None:
        advice = "try another period (period=), an initial guess (x0=) or a longer transient"
        guess = initial_guess(model, t0=t0, transient=transient, virtual=virtual, mode=mode)
        x, detected, mode = guess.state, guess.period, guess.mode
        n = int(period or detected or 1)
        if not (period or detected):
            note = (
                f"simulation from rest showed no period <= 64 after {transient} periods (chaos, or a "
                "transient not yet settled), so a period-1 orbit was tried"
            )
            advice = (
                f"{note}; give the period (period=) or an initial guess (x0=), or a longer transient "
                "(transient=)"
            )
    else:
        advice = "try another initial guess or another period"
        if model.has_modes and not virtual:  # (by default the mode x0 lies in: HybridModel.start_mode)
            mode = model.start_mode(x0, t0, mode)
        x = model.check_state(x0, t0, allowed=not virtual, mode=mode)
        n = int(period or 1)
    mode = model.mode_names[model.mode_index(mode)] if model.has_modes else None
    newton = _Newton(model, t0, n, stop, tol, max_iter, mode)
    try:
        return newton.solve(x, virtual, advice, guess, note)
    except ConvergenceError:
        nonimpacting = not (virtual or not through_stops or model.has_modes)
        inside = newton.nonimpacting(x) if nonimpacting else None
        if inside is None:
            raise
        return inside


@dataclass(frozen=True)
class _Newton:
    """Newton's method on the period-``n`` stroboscopic map from the section through ``t0``."""

    model: HybridModel
    t0: float
    n: int
    stop: int
    tol: float
    max_iter: int
    mode: str | None = None
    """A model with modes: the mode on the section (None without modes)."""

    def solve(
        self, x: np.ndarray, virtual: bool, advice: str, guess: InitialGuess | None, note: str = ""
    ) -> PeriodicOrbit:
        """The orbit from ``x``, or :class:`ConvergenceError` saying why not and ``advice`` (with
        ``note``, how the guess was made, where the motion sticks)."""
        model, t0, n, stop, tol = self.model, self.t0, self.n, self.stop, self.tol
        residuals: list[float] = []
        why = ""
        for it in range(self.max_iter + 1):
            try:
                fm = flow_map(model, x, t0=t0, periods=n, virtual=virtual, stop_name=stop, mode=self.mode)
            except SimulationError as exc:
                raise ConvergenceError(
                    f"Newton's method for a period-{n} orbit failed at iterate {it} ({exc}); {advice}"
                ) from None
            except InvalidStateError:
                where = f"is not in mode {self.mode!r}" if self.mode else "is beyond the stop"
                raise ConvergenceError(
                    f"Newton's method for a period-{n} orbit left the allowed region (iterate {it} "
                    f"{where}); {advice}"
                ) from None
            if not fm.solution.jacobian_valid:
                raise ConvergenceError(
                    _sticking_message(model, n, it, fm, guess) + (f"; {note}" if note else "")
                )
            returns_elsewhere = returning_mode_message(fm, n, t0)
            if returns_elsewhere:
                raise ConvergenceError(f"{returns_elsewhere} (Newton iterate {it})")
            F = fm.image - x
            res = float(np.max(np.abs(F)))
            residuals.append(res)
            if not np.isfinite(res):
                break
            if it == 0 and self.segments_from_guess(fm, virtual):
                # A large monodromy: single shooting's residual cannot fall below |M| eps |x|, and its
                # steps may land on another orbit; the segments of the guess's own run are solved.
                try:
                    return segmented_newton(
                        model, x, t0, n, tol=tol, max_iter=self.max_iter, stop=stop, mode=self.mode
                    )
                except (GrazingError, np.linalg.LinAlgError):
                    pass  # (then single shooting, as for any other guess)
            if res <= tol:
                return _orbit_from(model, x, t0, n, fm, virtual, residuals, stop)
            if it == self.max_iter:
                break
            A = fm.jacobian - np.eye(model.n_states)
            try:
                dx = np.linalg.solve(A, -F)
            except np.linalg.LinAlgError:
                why = " (the Jacobian P_x - I is singular: a fold or a multiplier 1?)"
                break
            # Backtrack so that the iterate stays in the allowed region.
            lam = 1.0
            for _ in range(30):
                trial = x + lam * dx
                if virtual or self._allowed(trial):
                    break
                lam *= 0.5
            x = trial
        raise ConvergenceError(
            f"Newton did not converge to a period-{n} orbit: residual {residuals[-1]:.3g} after "
            f"{len(residuals) - 1} iterations{why}; {advice}"
        )

    def _allowed(self, x: np.ndarray) -> bool:
        """Does ``x`` satisfy the guards (on a model with modes, those of the transitions that leave the
        section's mode)?"""
        if self.mode is None:
            return bool(np.min(self.model.guards(x, self.t0)) >= 0)
        try:
            self.model.check_state(x, self.t0, mode=self.mode)
        except InvalidStateError:
            return False
        return True

    def segments_from_guess(self, fm: FlowMap, virtual: bool) -> bool:
        """Is the guess's run to be solved by multiple shooting (:mod:`grazing.orbits.segments`): a
        physical run with impacts of a periodic model whose monodromy exceeds
        :data:`~grazing.orbits.segments.MULTIPLE_SHOOTING_NORM`, none of them at a grazing
        (:data:`~grazing.orbits.segments.GRAZING_SPEED_RATIO`)?"""
        if virtual or not self.model.periodic or not fm.solution.jacobian_valid:
            return False
        speeds = cut_speeds(self.model, fm.solution)
        if speeds is None:
            return False
        if float(speeds.min()) < GRAZING_SPEED_RATIO * float(speeds.max()):
            return False  # (an impact of the guess's run at a grazing: single shooting's orbit, without it)
        return float(np.linalg.norm(fm.jacobian, 2)) > MULTIPLE_SHOOTING_NORM

    def nonimpacting(self, x: np.ndarray) -> PeriodicOrbit | None:
        """A physical orbit that touches no stop, found from ``x`` on the flow through the stops, or None.

        Newton's method on the physical map fails from a guess whose flow hits a stop although the
        orbit itself does not (an unstable orbit, from a guess off it, say); on the flow through the
        stops it converges, and an orbit that keeps clear of every stop is also a physical orbit
        (checked on the physical map).
        """
        try:
            free = self.solve(x, True, "", None)
        except GrazingError:
            return None
        if np.min(free.guard_mins) <= CROSSING_TOL:
            return None
        fm = flow_map(self.model, free.state, t0=self.t0, periods=self.n, stop_name=self.stop)
        res = float(np.max(np.abs(fm.image - free.state)))
        if fm.impacts or not fm.solution.jacobian_valid or not res <= self.tol:
            return None
        residuals = [*free.residuals, res]
        return _orbit_from(self.model, free.state, self.t0, self.n, fm, False, residuals, self.stop)


def _sticking_message(model: HybridModel, n: int, it: int, fm: FlowMap, guess: InitialGuess | None) -> str:
    """Why Newton's method stops where the period-``n`` map has no Jacobian (sticking), and what to do."""
    how = sticking_phrase(fm.solution, n)
    what = (
        f"the motion {how}" if how else "the motion sticks to the stop (or meets it at zero speed)"
    ) + f" during the period-{n} map (iterate {it})"
    no_jacobian = (
        "the Jacobian across sticking is not computed, so Newton's method and Floquet multipliers are "
        "not available for it"
    )
    if guess is not None and guess.sticking and it == 0:
        return (
            f"the default initial guess sticks: simulated from rest for {guess.transient} forcing periods, "
            f"the motion {guess.sticking}, and {no_jacobian}; give {GUESS} near an orbit that does not "
            "stick, or simulate this motion instead"
        )
    return f"{what}; {no_jacobian}: give {GUESS} near an orbit that does not stick, or simulate this motion"
