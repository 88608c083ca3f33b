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

import warnings
from dataclasses import dataclass, field

import numpy as np

from grazing.cli.common import multipliers_text
from grazing.engine.simulate import simulate
from grazing.errors import GrazingError, GrazingWarning, InvalidParameterError
from grazing.explore.diagram import IsSupersededError, View, checkpoint
from grazing.explore.point import PointReport
from grazing.orbits.continuation import Branch, continue_orbit
from grazing.orbits.grazing import find_grazings
from grazing.orbits.shooting import PeriodicOrbit

__all__ = [
    "BranchPiece",
    "Continued",
    "Grazings",
    "Mark",
    "continue_click",
    "grazings_in_view",
    "section_states",
]


def section_states(orbit: PeriodicOrbit) -> np.ndarray:
    """The orbit's states at forcing phase 0, one per forcing period of its period: ``(period, n_states)``.

    A branch's orbits are solved on sections chosen away from their impacts; the
    diagram samples at phase 0, so each is simulated over one period from its section.
    """
    sol = simulate(
        orbit.model, orbit.state, t0=orbit.t0, periods=orbit.period, impacts="none", events=not orbit.virtual
    )
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


@dataclass(frozen=True)
class Continued:
    """The clicked orbit continued both ways: pieces (one per direction), special points, summary."""

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


def continue_click(
    view: View, point: PointReport, *, cancelled: IsSupersededError | None = None
) -> Continued:
    """Continue the orbit of ``point`` in the view's first parameter, both ways to the ends of its range.

    Raises
    ------
    InvalidParameterError
        The point has no orbit (:attr:`PointReport.message` says why).
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
        )
        states = []
        for o in branch.orbits:
            checkpoint(cancelled)
            states.append(section_states(o))
        crossing = np.array([o.virtual and bool(o.crossed_stops) for o in branch.orbits], dtype=bool)
        stable = np.array([o.stable for o in branch.orbits], dtype=bool)
        pieces.append(BranchPiece(branch, np.asarray(branch.values), states, stable, crossing))
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


@dataclass(frozen=True)
class Grazings:
    """The grazings of the nonimpacting orbit in the view's range: marks and one line each."""

    param: str
    marks: tuple[Mark, ...]
    lines: tuple[str, ...]

    def summary(self) -> str:
        return "\n".join(self.lines)


def grazings_in_view(
    view: View,
    fixed: dict[str, float] | None = None,
    *,
    period: int = 1,
    cancelled: IsSupersededError | None = None,
) -> Grazings:
    """Every stop's grazings of the nonimpacting period-``period`` orbit over the view's first range.

    ``fixed``: the other explored parameter's value (a period map: the clicked row).
    The orbit is followed with the stops ignored from the range's start (its guess:
    a simulation from rest with the stops ignored), through folds.
    """
    axis = view.axes[0]
    model = view.model.with_params(**(fixed or {}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GrazingWarning)  # (said in each grazing's text instead)
        _, branch = find_grazings(
            model, axis.name, axis.lo, axis.hi, period=period, progress=lambda _n, _v: checkpoint(cancelled)
        )
    marks, lines = [], []
    for sp in branch.special:
        if sp.kind != "grazing" or sp.grazing is None:
            continue
        checkpoint(cancelled)
        g = sp.grazing
        note = f"stop {g.stop_name}"
        if g.crossed:
            note += f"; passes through stop(s) {', '.join(g.crossed)}: not a motion of the system"
        try:
            states = section_states(sp.orbit)
        except GrazingError:
            states = np.empty((0, view.model.n_states))
        marks.append(
            Mark("grazing", sp.param, states, _special_text(view, "grazing", sp.param, g.multipliers, note))
        )
        lines.append(marks[-1].text)
    if not marks:
        lines.append(f"no grazing of the nonimpacting period-{period} orbit in the range ({branch.status})")
    return Grazings(axis.name, tuple(marks), tuple(lines))
