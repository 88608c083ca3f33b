"""A clicked point: its motion simulated, its period and impacts, its orbit by Newton's method.

:func:`inspect_point` answers a click on a diagram: from the state the diagram's
chain reached nearest to the click, it simulates the model at the clicked
parameters (a transient, then samples), detects the period, records one period
of the motion densely (time series, phase portrait, impacts), and runs Newton's
method on the stroboscopic map (:func:`grazing.orbits.find_orbit`) from the
last sample for the orbit's Floquet multipliers.  Where there is no period or
Newton's method fails, :attr:`PointReport.message` says so; the simulation is
still shown.  On a model with modes the simulation starts in the mode asked for, else
in the mode whose region the state lies in (:meth:`~grazing.HybridModel.mode_at`, as
the library does), and :attr:`PointReport.modes` records the shown motion's stays in
each mode, its switches and its sliding intervals (:class:`ModeTrace`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.options import MAX_PERIOD
from grazing.core.solution import Solution
from grazing.engine.simulate import simulate
from grazing.errors import GrazingError
from grazing.explore.diagram import Diagram, IsCancelled, View, checkpoint
from grazing.orbits.periodic import multipliers_text
from grazing.orbits.shooting import PeriodicOrbit, find_orbit

__all__ = [
    "INSPECT_SETTINGS",
    "InspectSettings",
    "ModeTrace",
    "PointReport",
    "inspect_click",
    "inspect_point",
    "start_mode",
]


@dataclass(frozen=True)
class InspectSettings:
    """How a clicked point is simulated.

    Attributes
    ----------
    transient
        Forcing periods run first from the diagram's state (it is on the attractor
        already, but at a slightly different parameter).
    periods
        Forcing periods sampled to detect the period (twice the largest period detected).
    points_per_period
        Points per forcing period of the dense trajectory shown.
    shown_periods
        Forcing periods shown of a motion without a period.

    Examples
    --------
    >>> InspectSettings()
    InspectSettings(transient=200, periods=128, points_per_period=200, shown_periods=20)
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> inspect_point(m, {"eta": 0.446}, [0.0, 0.0], settings=InspectSettings(transient=500)).period
    5
    """

    transient: int = 200
    periods: int = 2 * MAX_PERIOD
    points_per_period: int = 200
    shown_periods: int = 20


INSPECT_SETTINGS = InspectSettings()
"""The defaults of :class:`InspectSettings`."""


@dataclass(frozen=True)
class ModeTrace:
    """The modes of a clicked point's shown motion (a model with modes), its times as :attr:`PointReport.t`.

    Attributes
    ----------
    start
        The mode the click's simulation started in (from :attr:`PointReport.x0`).
    shown_start
        The mode the shown motion starts in (where the detection run ended; a run ending on a
        sliding surface goes on in the mode :meth:`~grazing.HybridModel.mode_at` gives there).
    guess
        The mode Newton's method started in (where the shown motion ends, at time 0 mod the forcing
        period).
    spans
        Each stay in a mode: ``(start, end, mode name)`` (:meth:`~grazing.Solution.mode_spans`; a
        sliding pseudo-mode ``"sliding on 'belt'"`` is a stay of its own).
    switch_t, switch_states, switch_names
        The switches of mode: times, states (after any reset), transition names
        (:attr:`~grazing.Solution.switches`).
    sliding
        The sliding intervals: ``(start, end, surface name)`` (:attr:`~grazing.Solution.sliding`).
    """

    start: str
    shown_start: str
    guess: str
    spans: tuple[tuple[float, float, str], ...]
    switch_t: np.ndarray
    switch_states: np.ndarray
    switch_names: tuple[str, ...]
    sliding: tuple[tuple[float, float, str], ...]

    @classmethod
    def of(cls, start: str, shown_start: str, guess: str, run: Solution, t0: float) -> ModeTrace:
        """The trace of the shown run ``run``, its times less ``t0``."""
        sw, names = run.switches, run.mode_names
        assert sw is not None
        surfaces = run.model.surface_names
        sliding = () if run.sliding is None else run.sliding
        return cls(
            start=start,
            shown_start=shown_start,
            guess=guess,
            spans=tuple((a - t0, b - t0, names[k]) for a, b, k in run.mode_spans()),
            switch_t=sw.t - t0,
            switch_states=sw.state,
            switch_names=tuple(sw.name(i) for i in range(len(sw))),
            sliding=tuple((float(a) - t0, float(b) - t0, surfaces[int(j)]) for a, b, j in sliding),
        )

    def lines(self, scale: float) -> list[str]:
        """What the orbit panel says of the modes (counts per period: ``scale`` = 1 / shown periods
        without a period)."""
        total = sum(b - a for a, b, _ in self.spans) or 1.0
        share: dict[str, float] = {}
        for a, b, name in self.spans:
            share[name] = share.get(name, 0.0) + (b - a) / total
        n = len(self.switch_t) * scale
        lines = [
            f"modes: started in {self.start}; {_count(n)} switch{'es' * (n != 1)} per period; time in each "
            "mode: " + ", ".join(f"{k} {v:.1%}" for k, v in share.items())
        ]
        if self.sliding:
            slid = sum(b - a for a, b, _ in self.sliding)
            on = ", ".join(dict.fromkeys(s for _, _, s in self.sliding))
            lines.append(
                f"sliding on {on}: {_count(len(self.sliding) * scale)} interval(s) per period, "
                f"{slid / total:.1%} of the time"
            )
        return lines


@dataclass(frozen=True)
class PointReport:
    """What the explorer shows of a clicked point.

    Attributes
    ----------
    values
        The explored parameters at the point (model units), by name.
    model
        The model there.
    x0
        The state the simulation started from (at time 0).
    period
        The detected period in forcing periods (0: none <= 64).
    impacts_per_period
        Impacts in one period of the motion (per forcing period without a period),
        in all and by stop.
    samples
        The stroboscopic samples (phase 0) of the detection run.
    t, trajectory
        The dense trajectory of one period of the motion (:attr:`shown_periods` forcing periods).
    impact_t, impact_states, impact_stops
        Its impacts: times, states just before, stop index.
    orbit
        The periodic orbit from Newton's method, or None.
    orbit_guess
        Where Newton's method started (the state at the end of the shown period, at time 0 mod
        the forcing period), or None.
    message
        Why there is no orbit (no period, Newton's method failed), else "".
    impacts_by_stop
        Impacts per period on each stop, by name.
    shown_periods
        Forcing periods of the trajectory shown (the period, or
        :attr:`InspectSettings.shown_periods` without one).
    settings
        How the point was simulated.
    modes
        A model with modes: the shown motion's modes, switches and sliding (:class:`ModeTrace`);
        None for a model of one mode.

    Examples
    --------
    >>> import math, grazing
    >>> from grazing.explore import View, compute_diagram, inspect_click
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> view = View.of(m, {"eta": (0.44, 0.46)}, num=5)
    >>> point = inspect_click(compute_diagram(view, workers=1), [0.446])
    >>> point.period, point.impacts_per_period, point.impacts_by_stop, point.shown_periods
    (5, 1.0, {'stop': 1.0, 'back': 0.0}, 5)
    >>> point.orbit.period, point.message, point.trajectory.shape[1]
    (5, '', 2)
    """

    values: dict[str, float]
    model: HybridModel
    x0: np.ndarray
    period: int
    impacts_per_period: float
    impacts_by_stop: dict[str, float]
    samples: np.ndarray
    shown_periods: int
    t: np.ndarray
    trajectory: np.ndarray
    impact_t: np.ndarray
    impact_states: np.ndarray
    impact_stops: np.ndarray
    orbit: PeriodicOrbit | None
    message: str
    orbit_guess: np.ndarray | None = None
    settings: InspectSettings = INSPECT_SETTINGS
    modes: ModeTrace | None = None

    def summary(self) -> str:
        """The point in a few lines of text (what the orbit panel says).

        The first line is ``period 5 with 1 impact per period`` (by stop, for several stops).
        """
        shown = ", ".join(f"{self.model.parameter(n).show(v, '.6g')}" for n, v in self.values.items())
        by_stop = ""
        if len(self.impacts_by_stop) > 1:
            by_stop = " (" + ", ".join(f"{k}: {_count(v)}" for k, v in self.impacts_by_stop.items()) + ")"
        if self.period > 0:
            k = self.impacts_per_period
            first = f"period {self.period} with {_count(k)} impact{'s' * (k != 1)} per period{by_stop}"
        else:
            first = (
                f"no period <= {MAX_PERIOD} in {self.samples.shape[0]} sampled forcing periods (chaotic, "
                f"quasi-periodic or not settled); {_count(self.impacts_per_period)} impacts per forcing "
                f"period{by_stop}"
            )
        lines = [first, shown]
        if self.orbit is not None:
            o = self.orbit
            state = ", ".join(f"{n} = {x:.6g}" for n, x in zip(self.model.state_names, o.state))
            lines += [
                f"Newton: period-{o.period} orbit with {o.impacts} impact{'s' * (o.impacts != 1)}, "
                f"{'stable' if o.stable else 'unstable'}, max |multiplier| = {o.abs_lambda:.4f}",
                f"Floquet multipliers: {multipliers_text(o.multipliers)}",
                f"state at time 0: {state}" + (f" (mode {o.mode})" if o.mode is not None else ""),
            ]
        if self.modes is not None:
            lines[1:1] = self.modes.lines(1.0 if self.period > 0 else 1.0 / self.shown_periods)
        if self.message:
            lines.append(self.message)
        return "\n".join(lines)


def _count(v: float) -> str:
    return f"{v:g}" if float(v).is_integer() else f"{v:.3g}"


def start_mode(model: HybridModel, x: np.ndarray, t: float, mode: str | None = None) -> str | None:
    """The mode a run of ``model`` from ``x`` at time ``t`` starts in: ``mode`` where given, else the one
    whose region ``x`` lies in (:meth:`~grazing.HybridModel.mode_at`, the library's default for a given
    state); None for a model of one mode (its one mode).  A sliding pseudo-mode (a run that ended sliding)
    is not a mode a run starts in: it starts on the surface in the mode ``mode_at`` gives, and slides.

    Examples
    --------
    >>> import grazing
    >>> m = grazing.models.friction_oscillator()
    >>> on_belt, ahead = np.array([0.5, 0.2]), np.array([0.0, 1.0])  # (v_belt = 0.2)
    >>> start_mode(m, on_belt, 0.0, "sliding on 'belt'"), start_mode(m, ahead, 0.0)
    ('slip_behind', 'slip_ahead')
    """
    if not model.has_modes:
        return None if mode is None else model.mode_names[model.mode_index(mode)]
    if mode is None or mode in model.sliding_names:
        return model.mode_at(x, t)
    return mode


def inspect_point(
    model: HybridModel,
    values: dict[str, float],
    x0: Sequence[float] | np.ndarray,
    *,
    mode: str | None = None,
    settings: InspectSettings = INSPECT_SETTINGS,
    cancelled: IsCancelled | None = None,
) -> PointReport:
    """Simulate ``model`` at the parameters ``values`` from ``x0``; its period, impacts and orbit.

    Parameters
    ----------
    model
        The model.
    values
        The explored parameters' values at the point (model units), by name.
    x0
        The state the simulation starts from, at time 0.
    mode
        A model with modes: the mode ``x0`` is in (default: the one whose region it lies in,
        :func:`start_mode`).
    settings
        How the point is simulated.
    cancelled
        Looked at between the steps.

    Returns
    -------
    PointReport
        The point's period, impacts, trajectory and periodic orbit.

    Raises
    ------
    InvalidParameterError
        A parameter value outside its interval.
    SimulationError, InvalidStateError
        The simulation failed (see :func:`grazing.simulate`).
    SupersededError
        ``cancelled()`` became true (looked at between the steps).

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> rep = inspect_point(m, {"eta": 0.446}, [0.0, 0.0], settings=InspectSettings(transient=500))
    >>> print(rep.summary().splitlines()[0])
    period 5 with 1 impact per period (stop: 1, back: 0)
    """
    here = model.with_params(**values)
    x0 = np.array(x0, dtype=float)
    s = settings
    first = start_mode(here, x0, 0.0, mode)
    sol = simulate(here, x0, transient=s.transient, periods=s.periods, impacts="none", mode=first)
    period = sol.period()
    checkpoint(cancelled)
    shown = period if period > 0 else s.shown_periods
    then = start_mode(here, sol.x_final, sol.t_final, sol.mode_final)
    run = simulate(
        here, sol.x_final, t0=sol.t_final, periods=shown, trajectory=s.points_per_period, mode=then
    )
    per_stop = run.impacts.per_stop()
    scale = 1.0 if period > 0 else 1.0 / shown
    orbit, message = None, ""
    guess = start_mode(here, run.x_final, 0.0, run.mode_final)
    if period > 0:
        checkpoint(cancelled)
        try:
            orbit = find_orbit(here, run.x_final, period=period, t0=0.0, mode=guess)
        except GrazingError as exc:
            message = f"Newton's method on the period-{period} orbit failed: {exc}"
    else:
        message = "no periodic orbit to solve for: Newton's method not run"
    return PointReport(
        values={k: float(v) for k, v in values.items()},
        model=here,
        x0=x0,
        period=period,
        impacts_per_period=len(run.impacts) * scale,
        impacts_by_stop={k: v * scale for k, v in per_stop.items()},
        samples=sol.samples,
        shown_periods=shown,
        t=run.trajectory_t - sol.t_final,
        trajectory=run.trajectory,
        impact_t=run.impacts.t - sol.t_final,
        impact_states=run.impacts.state,
        impact_stops=run.impacts.stop,
        orbit=orbit,
        message=message,
        orbit_guess=run.x_final.copy() if period > 0 else None,
        settings=settings,
        modes=None
        if first is None or then is None or guess is None
        else ModeTrace.of(first, then, guess, run, sol.t_final),
    )


def inspect_click(
    diagram: Diagram,
    values: Sequence[float],
    *,
    mode: str | None = None,
    settings: InspectSettings = INSPECT_SETTINGS,
    cancelled: IsCancelled | None = None,
) -> PointReport:
    """:func:`inspect_point` at a point of a diagram (model units, one value per explored parameter).

    The simulation starts from the state the diagram reached at the nearest
    point, so it shows the attractor the diagram shows there.

    Parameters
    ----------
    diagram
        The computed diagram (:func:`~grazing.explore.compute_diagram`).
    values
        The point clicked, one value per explored parameter (model units).
    mode
        A model with modes: the mode the diagram's state there is in (default: the one whose
        region it lies in).
    settings
        How the point is simulated.
    cancelled
        Looked at between the steps.

    Returns
    -------
    PointReport
        As :func:`inspect_point`.

    Raises
    ------
    InvalidParameterError
        A point outside the computed range, or a value outside a parameter's interval.

    Examples
    --------
    >>> import math, grazing
    >>> from grazing.explore import View, compute_diagram
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> d = compute_diagram(View.of(m, {"eta": (0.44, 0.46)}, num=5), workers=1)
    >>> inspect_click(d, [0.446]).period
    5
    >>> inspect_click(d, [0.47])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: eta = 0.47 is outside the computed range ...
    """
    view: View = diagram.view
    if len(values) != len(view.axes):
        raise ValueError(f"one value per explored parameter ({len(view.axes)}), got {len(values)}")
    diagram.check_inside(values)
    named = dict(zip(view.names, (float(v) for v in values)))
    view.model.with_params(**named)  # (a value outside its interval: one line)
    x0 = diagram.start_state(values)
    return inspect_point(view.model, named, x0, mode=mode, settings=settings, cancelled=cancelled)
