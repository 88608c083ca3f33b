"""Actions on a clicked orbit: continue it over the diagram's range; find the grazings there.

:func:`continue_click` follows the clicked point's orbit both ways to the ends of the
diagram's first parameter with :func:`grazing.orbits.continue_orbit` (special points
located: folds, branch points, period-doublings, Neimark-Sacker points, grazings, where
an impacting branch ends).  :func:`grazings_in_view` follows the nonimpacting period-1
orbit over that range with the stops ignored (:func:`grazing.orbits.find_grazings`)
and returns every stop's grazings.  Both give what the diagram draws: each orbit by its
points at forcing phase 0, the diagram's stroboscopic section.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from grazing.core.model import HybridModel
from grazing.engine.simulate import simulate
from grazing.errors import GrazingError, GrazingWarning, InvalidParameterError
from grazing.explore.diagram import IsCancelled, SupersededError, View, checkpoint
from grazing.explore.point import PointReport
from grazing.orbits.continuation import Branch, continue_orbit
from grazing.orbits.grazing import find_grazings, unlocated_grazing_text
from grazing.orbits.kinds import SpecialKind
from grazing.orbits.periodic import multipliers_text
from grazing.orbits.shooting import PeriodicOrbit

__all__ = [
    "BranchPiece",
    "Continued",
    "CurveView",
    "Curves",
    "Grazings",
    "Mark",
    "continue_click",
    "follow_click_curves",
    "grazings_in_view",
    "section_states",
]


def section_states(orbit: PeriodicOrbit) -> np.ndarray:
    """The orbit's states at forcing phase 0, one per forcing period of its period: ``(period, n_states)``.

    A branch's orbits are solved on sections chosen away from their impacts; the
    diagram samples at phase 0, so each is simulated over one period from its section
    (on a model with modes, in the orbit's mode there).
    """
    sol = simulate(
        orbit.model, orbit.state, t0=orbit.t0, periods=orbit.period, impacts="none", events=not orbit.virtual,
        mode=orbit.mode,
    )  # fmt: skip
    return sol.samples


@dataclass(frozen=True)
class Mark:
    """A special point drawn on the diagram: its kind, parameter value (model units), states at phase 0."""

    kind: str
    value: float
    states: np.ndarray
    text: str


@dataclass(frozen=True)
class BranchPiece:
    """One direction of a continuation: the branch and each point's states at phase 0.

    ``crossing``: the point's orbit is a virtual one (followed with the stops ignored, as a
    nonimpacting branch is) that passes through a stop: not a motion of the system.
    """

    branch: Branch
    values: np.ndarray
    states: list[np.ndarray]
    stable: np.ndarray
    crossing: np.ndarray
    end: float


@dataclass(frozen=True)
class Continued:
    """The clicked orbit continued both ways: pieces (one per direction), special points, summary.

    Parameters
    ----------
    param
        The parameter continued (the view's first).
    pieces
        The branch towards each end of the range.
    marks
        The special points met, for the diagram.
    lines
        The summary, one line per direction and per special point.

    Examples
    --------
    The paper's period-5 orbit at θ̂ = 40°, η = 0.446, continued over the
    view's range (:func:`continue_click`):

    >>> import math, grazing
    >>> from grazing.explore import View, compute_diagram, inspect_click
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> view = View.of(m, {"eta": (0.44, 0.46)}, num=5)
    >>> point = inspect_click(compute_diagram(view, workers=1), [0.446])
    >>> c = continue_click(view, point)
    >>> c.param, len(c.pieces), [mark.kind for mark in c.marks]
    ('eta', 2, ['period-doubling', 'grazing', 'grazing'])
    """

    param: str
    pieces: tuple[BranchPiece, ...]
    marks: tuple[Mark, ...]
    lines: tuple[str, ...] = field(default=())

    def summary(self) -> str:
        return "\n".join(self.lines)


def _special_text(view: View, kind: str, value: float, mu: np.ndarray, note: str = "") -> str:
    par = view.model.parameter(view.axes[0].name)
    text = f"{kind} at {par.show(value, '.8g')}, multipliers {multipliers_text(mu)}"
    return f"{text} ({note})" if note else text


def continue_click(view: View, point: PointReport, *, cancelled: IsCancelled | None = None) -> Continued:
    """Continue the orbit of ``point`` in the view's first parameter, both ways to the ends of its range.

    Parameters
    ----------
    view
        The view (its first parameter and range).
    point
        The clicked point (:func:`~grazing.explore.inspect_click`), with its orbit.
    cancelled
        Looked at between the steps: when it returns True, :class:`SupersededError` is raised.

    Returns
    -------
    Continued
        The branch both ways, its special points and a summary.

    Raises
    ------
    InvalidParameterError
        The point has no orbit (:attr:`PointReport.message` says why).

    Examples
    --------
    >>> import math, grazing
    >>> from grazing.explore import View, compute_diagram, inspect_click
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> view = View.of(m, {"eta": (0.44, 0.46)}, num=5)
    >>> point = inspect_click(compute_diagram(view, workers=1), [0.446])
    >>> c = continue_click(view, point)
    >>> [round(mark.value, 6) for mark in c.marks]  # period-doubling, and a grazing each way
    [0.445393, 0.445121, 0.44635]
    """
    if point.orbit is None:
        raise InvalidParameterError(f"no orbit to continue: {point.message}")
    axis = view.axes[0]
    par = view.model.parameter(axis.name)
    start = point.values[axis.name]
    pieces, marks, lines = [], [], []
    for end in (axis.lo, axis.hi):
        if abs(end - start) <= 1e-12 * max(1.0, abs(start)):
            continue
        checkpoint(cancelled)
        branch = continue_orbit(
            point.model,
            axis.name,
            start,
            end,
            x0=point.orbit.state,
            period=point.orbit.period,
            progress=lambda _n, _v: checkpoint(cancelled),
            mode=point.orbit.mode,
        )
        states = []
        for o in branch.orbits:
            checkpoint(cancelled)
            states.append(section_states(o))
        crossing = np.array([o.virtual and bool(o.crossed_stops) for o in branch.orbits], dtype=bool)
        stable = np.array([o.stable for o in branch.orbits], dtype=bool)
        pieces.append(BranchPiece(branch, np.asarray(branch.values), states, stable, crossing, end))
        lines.append(
            f"towards {par.show(end, '.6g')}: {len(branch)} points, {branch.status or 'reached the end'}"
        )
        for sp in branch.special:
            marks.append(
                Mark(
                    sp.kind,
                    sp.param,
                    section_states(sp.orbit),
                    _special_text(view, sp.kind, sp.param, sp.multipliers, sp.note),
                )
            )
            lines.append("  " + marks[-1].text)
    return Continued(axis.name, tuple(pieces), tuple(marks), tuple(lines))


def grazed_orbit(model: HybridModel, period: int = 1) -> str:
    """The orbit whose grazings :func:`grazings_in_view` seeks, in words: the nonimpacting one (the stops
    ignored), or on a model with modes the orbit itself followed through its modes
    (:func:`~grazing.orbits.find_grazings`)."""
    if model.has_modes:
        return f"the period-{period} orbit followed through its modes"
    return f"the nonimpacting period-{period} orbit"


@dataclass(frozen=True)
class Grazings:
    """The grazings of the nonimpacting orbit (on a model with modes: the orbit through its modes) in the
    view's range: marks and one line each; where they were sought (the parameter, its range, the other
    explored parameter's value held: ``fixed``).

    Parameters
    ----------
    param
        The parameter of the range.
    marks
        The grazings, for the diagram.
    lines
        One line per grazing.
    range
        Where they were sought.
    fixed
        The other explored parameter's value held (a period map), else empty.
    mode
        A model with modes: the mode the orbit's search started in (the page's "Start mode"; None:
        the model's initial mode).
    unlocated
        The grazings bracketed whose equations did not converge: where (their marks and lines say so).

    Examples
    --------
    >>> import math, grazing
    >>> from grazing.explore import View, grazings_in_view
    >>> view = View.of(grazing.models.pendulum("B", theta_hat=math.radians(40)), {"eta": (0.44, 0.46)})
    >>> g = grazings_in_view(view)
    >>> g.param, g.range, [round(mark.value, 6) for mark in g.marks]
    ('eta', (0.44, 0.46), [0.445121])
    """

    param: str
    marks: tuple[Mark, ...]
    lines: tuple[str, ...]
    range: tuple[float, float] = (math.nan, math.nan)
    fixed: dict[str, float] = field(default_factory=dict)
    mode: str | None = None
    unlocated: tuple[float, ...] = ()

    def summary(self) -> str:
        return "\n".join(self.lines)


def grazings_in_view(
    view: View,
    fixed: dict[str, float] | None = None,
    *,
    period: int = 1,
    mode: str | None = None,
    cancelled: IsCancelled | None = None,
) -> Grazings:
    """Every stop's grazings of the nonimpacting period-``period`` orbit over the view's first range.

    ``fixed``: the other explored parameter's value (a period map: the clicked row).
    The orbit is followed with the stops ignored from the range's start (its guess:
    a simulation from rest with the stops ignored), through folds.  On a model with
    modes, every transition's grazings of the period-``period`` orbit followed through
    its modes (:func:`~grazing.orbits.find_grazings`), from ``mode``.  A grazing bracketed whose
    equations do not converge is one unlocated mark and line; the search goes on.

    Parameters
    ----------
    view
        The view (its first parameter and range).
    fixed
        The other explored parameter's value, by name (a period map).
    period
        Period of the nonimpacting orbit, in forcing periods.
    mode
        A model with modes: the mode the search starts in (the page's "Start mode"; default: the
        model's initial mode).
    cancelled
        Looked at between the steps: when it returns True, :class:`SupersededError` is raised.

    Returns
    -------
    Grazings
        Every stop's grazings in the range, with one line each.

    Examples
    --------
    The paper's first grazing at θ̂ = 40° is the only one in η in [0.44, 0.46]:

    >>> import math, grazing
    >>> from grazing.explore import View
    >>> view = View.of(grazing.models.pendulum("B", theta_hat=math.radians(40)), {"eta": (0.44, 0.46)})
    >>> print(grazings_in_view(view).summary())
    grazing at eta = 0.44512118, multipliers +0.4612+0.2127i, +0.4612-0.2127i (stop stop)
    """
    axis = view.axes[0]
    model = view.model.with_params(**(fixed or {}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GrazingWarning)  # (said in each grazing's text instead)
        _, branch = find_grazings(
            model, axis.name, axis.lo, axis.hi, period=period, mode=mode,
            progress=lambda _n, _v: checkpoint(cancelled),
        )  # fmt: skip
    stop_word = "transition" if model.has_modes else "stop"
    marks, lines, unlocated = [], [], []
    for sp in branch.special:
        if sp.kind != SpecialKind.GRAZING:
            continue
        checkpoint(cancelled)
        if sp.grazing is None:  # (bracketed only: one unlocated point, said)
            unlocated.append(sp.param)
            text = unlocated_grazing_text(model, axis.name, sp)
            marks.append(Mark("grazing", sp.param, np.empty((0, view.model.n_states)), text))
            lines.append(text)
            continue
        g = sp.grazing
        note = f"{stop_word} {g.stop_name}"
        if g.crossed:
            note += f"; passes through {stop_word}(s) {', '.join(g.crossed)}: not a motion of the system"
        try:
            states = section_states(sp.orbit)
        except GrazingError:
            states = np.empty((0, view.model.n_states))
        marks.append(
            Mark("grazing", sp.param, states, _special_text(view, "grazing", sp.param, g.multipliers, note))
        )
        lines.append(marks[-1].text)
    if not marks:
        lines.append(f"no grazing of {grazed_orbit(model, period)} in the range ({branch.status})")
    return Grazings(
        axis.name, tuple(marks), tuple(lines), (axis.lo, axis.hi), dict(fixed or {}), mode, tuple(unlocated)
    )


@dataclass(frozen=True)
class CurveView:
    """A bifurcation curve drawn on a period map: its kind, its two parameters' values (model units);
    the continuation it was found on (from the clicked value towards ``stop``), for copy as code."""

    kind: str
    first: np.ndarray
    second: np.ndarray
    text: str
    stop: float = math.nan


@dataclass(frozen=True)
class Curves:
    """The bifurcation curves through the special points of a continued orbit, and one line each.

    Parameters
    ----------
    curves
        The curves followed (their kind, both parameters' values, the stop of a grazing curve).
    lines
        One line per curve.
    view
        The map they were followed over (for "copy as code").

    Examples
    --------
    On a period map, the curves through the special points of the period-5
    orbit's branch (:func:`follow_click_curves`):

    >>> import math, grazing
    >>> from grazing.explore import View, compute_diagram, continue_click, inspect_click
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> view = View.of(m, {"eta": (0.44, 0.46), "theta_hat": (38, 42)}, num=3)
    >>> point = inspect_click(compute_diagram(view, workers=1), [0.446, math.radians(40)])
    >>> curves = follow_click_curves(view, point, continue_click(view, point))
    >>> [c.kind for c in curves.curves]
    ['period-doubling', 'grazing', 'grazing']
    """

    curves: tuple[CurveView, ...]
    lines: tuple[str, ...]
    view: View | None = None  # (the map they were followed over, for copy as code)


def follow_click_curves(
    view: View, point: PointReport, continued: Continued, *, cancelled: IsCancelled | None = None
) -> Curves:
    """Follow each special point of the clicked orbit's branch (the first of each kind, each way) in
    the map's two parameters over the map's range (:func:`grazing.orbits.follow_curve`).

    Parameters
    ----------
    view
        A period map (two parameters).
    point
        The clicked point, with its orbit.
    continued
        Its branch (:func:`continue_click`).
    cancelled
        Looked at between the curves: when it returns True, :class:`SupersededError` is raised.

    Returns
    -------
    Curves
        The curves followed and one line each.

    Raises
    ------
    InvalidParameterError
        A view with one parameter (a curve needs two), or a point without an orbit.

    Examples
    --------
    >>> import math, grazing
    >>> from grazing.explore import View, compute_diagram, continue_click, inspect_click
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> view = View.of(m, {"eta": (0.44, 0.46), "theta_hat": (38, 42)}, num=3)
    >>> point = inspect_click(compute_diagram(view, workers=1), [0.446, math.radians(40)])
    >>> curves = follow_click_curves(view, point, continue_click(view, point))
    >>> print(curves.lines[0])  # doctest: +NORMALIZE_WHITESPACE
    period-doubling curve from eta = 0.44539259: 10 points; at the first point: reached the bound
    theta_hat = 38 deg; at the last point: reached the bound theta_hat = 42 deg
    """
    from grazing.orbits.curves import follow_curve

    if len(view.axes) != 2:
        raise InvalidParameterError(
            "a bifurcation curve needs two parameters: explore a period map (two parameters)"
        )
    if point.orbit is None:
        raise InvalidParameterError(f"no orbit to follow: {point.message}")
    a, b = view.axes
    par = view.model.parameter(a.name)
    start = point.values[a.name]
    modes = point.model.has_modes
    curves, lines = [], []
    for piece in continued.pieces:
        done = set()
        for sp in piece.branch.special:
            kind = SpecialKind(sp.kind).curve  # (the curve that follows it; None: an unlocated change)
            if kind is None or kind in done:
                continue
            done.add(kind)
            checkpoint(cancelled)
            try:
                curve = follow_curve(
                    point.model,
                    kind,
                    a.name,
                    start,
                    piece.end,
                    b.name,
                    (b.lo, b.hi),
                    x0=None if modes else point.orbit.state,
                    orbit=point.orbit if modes else None,  # (in its mode: follow_curve starts from it)
                    period=point.orbit.period,
                    progress=lambda *_: checkpoint(cancelled),
                )
            except GrazingError as exc:
                if isinstance(exc, SupersededError):
                    raise
                lines.append(f"{kind} curve from {par.show(sp.param, '.8g')}: {exc}")
                continue
            text = (
                f"{kind} curve from {par.show(sp.param, '.8g')}: {len(curve.points)} points; {curve.status}"
            )
            curves.append(CurveView(kind, curve.values(a.name), curve.values(b.name), text, piece.end))
            lines.append(text)
    if not lines:
        lines.append("no special point on the branch to follow")
    return Curves(tuple(curves), tuple(lines), view)
