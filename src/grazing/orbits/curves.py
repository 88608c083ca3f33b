"""Curves of bifurcations of periodic orbits in two parameters, with their codimension-two points.

:func:`follow_curve` continues an orbit in one parameter (:func:`~grazing.orbits.continuation.continue_orbit`)
up to the first special point of the kind asked for (fold, period-doubling,
Neimark-Sacker, branch point or grazing) and follows that point in two
parameters by pseudo-arclength continuation of an extended system
(:mod:`grazing.orbits.extended`: the shooting equations with saltation
matrices and a minimally augmented defining condition, or the contact
equations of a grazing), in both directions from the start.

Along the curve a branch keeps its impact signature (impacts in each forcing
period): where the orbit gains or loses an impact, the curve meets a grazing
curve (a codimension-two point).  The step is bracketed there, as
:func:`~grazing.orbits.continuation.continue_orbit` brackets a grazing on a
branch (bisection with a secant on the grazing margin), the point is solved
from the grazing equations (the contact equations in both parameters with the
point on the curve's secant) and the curve ends.  A curve of an orbit computed
with the stops ignored (a nonimpacting orbit) reports its grazings and goes on.
Where the orbit's monodromy is large (at the start, or where single shooting
stalls along the curve) the fold, period-doubling, Neimark-Sacker and
branch-point curves are followed on the segmented equations instead
(:mod:`grazing.orbits.segmented_curves`: multiple shooting, one segment per impact).
The other codimension-two points are zeros of test functions
(:data:`~grazing.orbits.extended.CODIM2_TESTS`), located by regula falsi
along the curve; the 1:1 and 1:2 resonances end a Neimark-Sacker curve.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from grazing.core.model import HybridModel, Parameter
from grazing.errors import ConvergenceError, GrazingError, InvalidParameterError, NotFoundError
from grazing.orbits.contact import GrazingPoint
from grazing.orbits.continuation import (
    RESECTION,
    RESECTION_MARGIN,
    Branch,
    ImpactChange,
    SpecialPoint,
    continue_orbit,
    grazing_margin,
    switch_change,
    switch_change_reason,
)
from grazing.orbits.crossings import contact_guess, meeting_point, nearest_grazing
from grazing.orbits.curve_data import BifurcationCurve, CurveEnd, CurvePoint, CurveSpecial, bracket_between
from grazing.orbits.extended import CODIM2_TESTS, ENDING, Evaluation, GrazingSystem, OrbitSystem
from grazing.orbits.kinds import CurveKind
from grazing.orbits.palc import (
    ACCEPT,
    BOUNDARY,
    STOP,
    Palc,
    PalcEnd,
    PalcPoint,
    PalcSettings,
    correct,
    locate,
    sign_changed,
    tangent,
)
from grazing.orbits.segmented_curves import SegmentedOrbitSystem
from grazing.orbits.segments import MULTIPLE_SHOOTING_NORM, REORDER_REACH, reordered
from grazing.orbits.shooting import CROSSING_TOL, PeriodicOrbit, move_section, quiet_section

CURVE_KINDS = tuple(CurveKind)
"""The kinds of curves :func:`follow_curve` follows (each starts from the special point
:attr:`~grazing.orbits.kinds.CurveKind.start`)."""

SHIFT_TOL = 1e-7
"""Largest ``|shift|`` on a branch-point curve: beyond it the branch point does not persist in two
parameters (the model lacks the symmetry that makes it generic)."""

DOUBLE_GRAZING_MARGIN = 1e-6
"""Where a grazing curve gets stuck with its orbit this close to another contact with a stop
(:func:`_other_contact_margin`), it ends at a double grazing."""


CLOSURE_TOL = 0.25
"""A curve is closed where one of its steps passes its start within this fraction of the step's length
(in the orbit's state, its section time and the two parameters), once the curve has been farther from
its start than two such steps: it has come back to where it began, and stops there."""


CurveProgress = Callable[[str, int, float, float], None]
"""``progress(stage, points, value1, value2)``: stage ``"branch"`` (the one-parameter continuation
to the start) or ``"curve"``."""


# ----------------------------------------------------------------------------


def _interval(par: Parameter) -> tuple[float, float]:
    """Where a curve may go in ``par``: its interval, open ends moved inside by a hair."""

    def inside(bound: float, toward: float, is_open: bool) -> float:
        if math.isinf(bound) or not is_open:
            return bound
        return bound + toward * 1e-9 * max(1.0, abs(bound))

    return inside(par.lower, 1.0, par.lower_open), inside(par.upper, -1.0, par.upper_open)


def _with_events(point: GrazingPoint) -> bool:
    """Is a grazing orbit's flow computed with its impacts (else with the stops ignored)?

    Only if it has impacts besides the contact: an orbit that just touches the
    stop is the same orbit with the stops ignored, and Newton's method on the
    contact equations is then free of the impacts that its iterates make where
    they end slightly beyond the stop.
    """
    return point.impacts > 0


def _other_contact_margin(point: GrazingPoint) -> float:
    """How far a grazing orbit is from another contact with a stop (a double grazing).

    The smaller of ``v^2 / (2 |a|)`` over its other impacts (``v`` the impact
    speed, ``a = L_f^2 h``) and of every stop's closest approach in free flight
    other than the grazing contact itself (as
    :func:`~grazing.orbits.continuation.grazing_margin`): both tend to zero as
    another contact forms.
    """
    best = math.inf
    imp = point.other_impacts
    if imp is not None:
        for t, v, x, j in zip(imp.t, imp.speed, imp.state, imp.stop):
            a = abs(point.model.normal_accel(x, t, int(j)))
            best = min(best, v * v / (2 * a) if a > 0 else math.inf)
    T = point.model.period
    for j, approach in enumerate(point.approach_by_stop):
        if approach is None:
            continue
        h, t, _ = approach
        at_contact = min(abs(t - point.t_graze), abs(t - point.t_graze - point.period * T)) < 1e-6 * T
        if not (j == point.stop and at_contact):
            best = min(best, max(h, 0.0))
    return best


def _crossing(point: GrazingPoint) -> bool:
    """Does a grazing orbit computed with the stops ignored pass through a stop (other than touching)?"""
    return bool(point.guard_mins) and min(point.guard_mins) < -CROSSING_TOL


def _start_point(branch: Branch, kind: CurveKind, stop: int | None) -> SpecialPoint:
    """The first special point of ``kind`` on ``branch``, or :class:`NotFoundError` naming what was met."""
    wanted = kind.start
    for sp_ in branch.special:
        if sp_.kind == wanted and (kind != CurveKind.GRAZING or stop is None or sp_.stop == stop):
            return sp_
    par = branch.model.parameter(branch.param)
    lo, hi = branch.values[0], branch.values[-1]
    what = f"no {wanted}" + (f" with stop {branch.model.stop_names[stop]!r}" if kind == CurveKind.GRAZING and
                             stop is not None else "")  # fmt: skip
    met = ", ".join(f"{s.kind} at {par.show(s.param, '.8g')}" for s in branch.special)
    raise NotFoundError(
        f"{what} on the period-{branch.period} branch from {par.show(lo, '.8g')} to {par.show(hi, '.8g')}: "
        + (f"met {met} instead" if met else "met no special point")
        + f"; the branch {branch.status}"
    )


class _Direction:
    """The curve followed from its start in one direction (a sequence of PALC runs: the section moves)."""

    def __init__(self) -> None:
        self.points: list[CurvePoint] = []
        self.pal: list[PalcPoint] = []
        self.special: list[tuple[int, CurveSpecial]] = []  # (index of the point on the start's side, special)
        self.status = ""
        self.outcome: CurveEnd | None = None  # (what the status says)
        self.handover: tuple[float, float] | None = None  # where it went over to multiple shooting
        self.segmented_start: float | None = None  # the monodromy's norm where it started on the segments
        self.reorders: list[str] = []  # where two impacts changed order (on the segments)
        self.farthest = 0.0  # the largest distance of a point from the first (closure: _came_back)


class _Follower:
    """Follows one curve from a start point (see :func:`follow_curve`)."""

    def __init__(
        self, model: HybridModel, kind: str, params: tuple[str, str], range2: tuple[float, float],
        period: int, virtual: bool, stop: int, settings: PalcSettings,
        progress: Callable[[int, float, float], None] | None,
    ):  # fmt: skip
        self.model, self.kind, self.params, self.period = model, kind, params, period
        self.virtual, self.stop, self.s, self.progress = virtual, stop, settings, progress
        self.n = model.n_states
        self.pars = (model.parameter(params[0]), model.parameter(params[1]))
        lo1, hi1 = _interval(self.pars[0])
        lo2, hi2 = _interval(self.pars[1])
        self.bounds1 = (lo1, hi1)
        self.bounds2 = (max(range2[0], lo2), min(range2[1], hi2))
        self.count = 0
        self.segmented = False  # the system in hand is on the segmented equations (orbits.segmented_curves)
        self._offset = self.n + 1 if kind == "grazing" else self.n

    # -- the systems --------------------------------------------------------
    def offset(self) -> int:
        """Index of ``p1`` in the unknowns of the system in hand (``p2`` follows it)."""
        return self._offset

    @property
    def no_impacts(self) -> bool:
        """The model has no transition with a reset (only switches of mode): no impact's grazing margin."""
        return not any(self.model.transition_resets)

    def can_segment(self, orbit: PeriodicOrbit) -> bool:
        """Can the curve through ``orbit`` be followed on the segmented equations (it has impacts, it is
        not virtual, the model has a forcing period)?"""
        return (
            self.kind != "grazing" and not self.virtual and orbit.impacts > 0 and self.model.periodic
        )  # fmt: skip

    def system(
        self, start: PeriodicOrbit | GrazingPoint, segmented: bool = False
    ) -> OrbitSystem | GrazingSystem | SegmentedOrbitSystem:
        """The extended system through ``start``: on the segmented equations where asked (``segmented``)
        or where the monodromy exceeds :data:`~grazing.orbits.segments.MULTIPLE_SHOOTING_NORM`."""
        if self.kind == "grazing":
            assert isinstance(start, GrazingPoint)
            return GrazingSystem(self.model, self.params, self.period, _with_events(start), start.stop)
        assert isinstance(start, PeriodicOrbit)
        large = float(np.linalg.norm(start.monodromy, 2)) > MULTIPLE_SHOOTING_NORM
        self.segmented = self.can_segment(start) and (segmented or large)
        if self.segmented:
            system = SegmentedOrbitSystem(
                self.model, self.kind, self.params, self.period, start.t0, self.stop, start
            )
            self._offset = system.offset
            return system
        self._offset = self.n
        return OrbitSystem(
            self.model,
            self.kind,
            self.params,
            self.period,
            start.t0,
            self.virtual,
            self.stop,
            start.monodromy,
            start.mode,
        )

    def curve_point(self, pt: PalcPoint) -> CurvePoint:
        ev: Evaluation = pt.payload
        i = self.offset()
        values = (float(pt.u[i]), float(pt.u[i + 1]))
        if ev.grazing is not None:
            g = ev.grazing
            return CurvePoint(values, g.contact.copy(), g.phase, g.multipliers, g.impacts, self.period,
                              ev.condition, None, g)  # fmt: skip
        o = ev.orbit
        assert o is not None
        return CurvePoint(
            values, o.state.copy(), o.t0, o.multipliers, o.impacts, self.period, ev.condition, o,
            accuracy=ev.accuracy,
        )  # fmt: skip

    # -- checks -------------------------------------------------------------
    def check(self, prev: PalcPoint, cand: PalcPoint) -> tuple[str, str]:
        a, b = prev.payload, cand.payload
        if self.kind == "grazing":
            ga, gb = a.grazing, b.grazing
            if gb.impacts != ga.impacts or _crossing(gb) != _crossing(ga) or gb.accel <= 0:
                return BOUNDARY, "the grazing orbit meets another contact with a stop (a double grazing)"
            if gb.switches != ga.switches:
                return BOUNDARY, (
                    f"the grazing orbit's other switches of mode change ({ga.switches} -> {gb.switches} per "
                    "period): it meets another contact with a switching surface (a double grazing)"
                )
            return ACCEPT, ""
        if self.virtual:
            return ACCEPT, ""
        oa, ob = a.orbit, b.orbit
        if self.model.has_modes and ob.switch_signature != oa.switch_signature:
            return BOUNDARY, f"{switch_change_reason(oa, ob)}: the curve meets it"
        if ob.signature != oa.signature:
            what = "loses" if sum(ob.signature) < sum(oa.signature) else "gains"
            if sum(ob.signature) == sum(oa.signature):
                what = "changes"
            return BOUNDARY, (
                f"the orbit {what} an impact (impacts per forcing period {list(oa.signature)} -> "
                f"{list(ob.signature)}): the curve meets a grazing"
            )
        if self.segmented:  # (the segments ignore the stops: past a grazing they pass through one)
            if ob.impact_speeds.size and float(np.min(ob.impact_speeds)) <= 0.0:
                return BOUNDARY, (
                    "an impact speed reaches zero (the orbit loses an impact): the curve meets a grazing"
                )
            crossed = [name for name in ob.crossed_stops if name not in oa.crossed_stops]
            if crossed:
                return BOUNDARY, (
                    f"the orbit passes through stop {crossed[0]!r} between its impacts (it gains an impact "
                    "there): the curve meets a grazing"
                )
        if ob.section_clearance() < RESECTION_MARGIN:
            return STOP, RESECTION
        return ACCEPT, ""

    def margin(self, pt: PalcPoint) -> float:
        if self.kind == "grazing":
            return _other_contact_margin(pt.payload.grazing)
        return grazing_margin(pt.payload.orbit).delta

    # -- following ------------------------------------------------------------
    def first(self, system: OrbitSystem | GrazingSystem, u0: np.ndarray, index: int) -> PalcPoint:
        """The start, corrected onto the curve with component ``index`` fixed."""
        e = np.zeros(u0.size)
        e[index] = 1.0
        pt = correct(system, u0, e, self.s)
        if pt is None:
            raise ConvergenceError(
                f"the {self.kind} curve's equations did not converge at its start "
                f"({self.pars[0].show(u0[self.offset()])}, {self.pars[1].show(u0[self.offset() + 1])})"
            )
        return pt

    def run(self, start: PeriodicOrbit | GrazingPoint, sign: float, which: int) -> _Direction:
        """Follow the curve from ``start`` with parameter ``which`` (0: ``p1``, 1: ``p2``) moving in
        direction ``sign``.  Where single shooting stalls on an orbit with impacts, the curve goes on on
        the segmented equations from its last point."""
        d = _Direction()
        d.status = self._run(d, start, sign, which)
        if d.handover is not None:
            where = self.show(d.handover)
            d.status += f"; by multiple shooting from {where} on (single shooting stalled there)"
        elif d.segmented_start is not None:
            norm = f"{d.segmented_start:.1e}"
            d.status += f"; by multiple shooting (the monodromy's norm is {norm} at the start)"
        if d.reorders:
            d.status += "; " + "; ".join(d.reorders)
        return d

    def _run(self, d: _Direction, start: PeriodicOrbit | GrazingPoint, sign: float, which: int) -> str:
        """:meth:`run` itself: fills ``d``, returns its status."""
        current = start
        segmented = False
        # (past a change of impact order: the system in the new order, its unknowns, the note)
        prepared: tuple[SegmentedOrbitSystem, np.ndarray, str] | None = None
        across: PalcPoint | None = None  # (the last point before it)
        while True:
            if prepared is None:
                system = self.system(current, segmented)
                if self.segmented and not segmented and not d.pal:
                    d.segmented_start = float(np.linalg.norm(current.monodromy, 2))  # type: ignore[union-attr]
                u0 = system.start(current)
            else:
                (system, u0, note), prepared = prepared, None
                self._offset = system.offset
            i1 = self.offset()
            index = i1 + which
            bounds = {i1: self.bounds1, i1 + 1: self.bounds2}
            names = {i1: self.params[0], i1 + 1: self.params[1]}
            shows = {i1: self.pars[0].show, i1 + 1: self.pars[1].show}
            if across is not None:
                try:
                    first = self.first(system, u0, index)
                except ConvergenceError:
                    return d.status  # (the segments in the new order do not solve: it ends as it stalled)
                d.reorders.append(note)
            else:
                first = self.first(system, u0, i1 + 1 if not d.pal else index)
            palc = Palc(
                system, first, index=index, sign=sign, bounds=bounds,
                settings=dataclasses.replace(self.s, max_points=max(2, self.s.max_points - len(d.points))),
                names=names, shows=shows, check=self.check,
                margin=self.margin if self.kind == "grazing" or not (self.virtual or self.no_impacts)
                else None,
            )  # fmt: skip
            ended = False
            for k, pt in enumerate(palc):
                if k == 0 and across is not None:  # past the change of impact order: a new point
                    self.across_reordering(d, across, pt)
                    across = None
                    self.append(d, pt)
                    system.accept(pt.payload)
                    continue
                if k == 0 and d.pal:  # the same point on a moved section
                    d.pal[-1] = pt
                    system.accept(pt.payload)
                    continue
                if abs(pt.payload.shift) > SHIFT_TOL:
                    d.outcome = CurveEnd.NOT_PERSISTENT
                    return (
                        f"shift = {pt.payload.shift:.3g} at {self.show(self.curve_point(pt).values)}: the "
                        "branch point does not persist in two parameters (the model lacks the symmetry that "
                        "keeps it)"
                    )
                if d.pal and self.detect(system, d, d.pal[-1], pt):
                    ended = True
                    break
                self.append(d, pt)
                system.accept(pt.payload)
                along = _came_back(d)
                if along is not None:  # (the loop closed: its last point is its first, not one past it)
                    d.points[-1 if along < 1.0 else len(d.points) :] = [d.points[0]]
                    d.outcome = CurveEnd.CLOSED
                    return (
                        f"the curve came back to its start ({self.show(d.points[0].values)}) after "
                        f"{len(d.points) - 1} points: it is closed"
                    )
            if ended:
                return d.status
            d.status, d.outcome = palc.status, CurveEnd.of(palc.end)
            last = d.pal[-1]
            assert last.tangent is not None
            sign = math.copysign(1.0, last.tangent[index]) if last.tangent[index] != 0 else sign
            if palc.end is PalcEnd.STOPPED and len(d.points) < self.s.max_points:  # (check's STOP: RESECTION)
                try:
                    current = move_section(last.payload.orbit, quiet_section(last.payload.orbit))
                except GrazingError as exc:
                    d.outcome = CurveEnd.NO_SECTION
                    return f"{RESECTION} and the orbit could not be found on another section ({exc})"
                continue
            if palc.boundary is None:
                return d.status
            if self.end_at_grazing(d, palc):
                return d.status
            if not palc.boundary.reached and isinstance(system, SegmentedOrbitSystem):
                prepared = self.reorder(system, last)
                if prepared is not None and len(d.points) < self.s.max_points:
                    across = last
                    continue
            orbit = last.payload.orbit
            if (
                not palc.boundary.reached and not self.segmented and self.can_segment(orbit)
                and len(d.points) < self.s.max_points
            ):  # fmt: skip
                # Single shooting stalled (its residual's rounding, |M| eps |x|, above its tolerance where
                # the monodromy is large) with no grazing just ahead: the segmented equations from here.
                segmented, current = True, orbit
                d.handover = self.curve_point(last).values
                continue
            return d.status

    def reorder(
        self, system: SegmentedOrbitSystem, last: PalcPoint
    ) -> tuple[SegmentedOrbitSystem, np.ndarray, str] | None:
        """Where two of ``last``'s impacts on different stops change order just ahead: the system on the
        segments in the new order, the point past the change in its unknowns (for :meth:`first` to
        correct onto the curve) and a note saying so; None where no two impacts meet just ahead."""
        assert last.tangent is not None
        m = system.offset + 2
        ahead = reordered(
            self.model, system.layout, system.t0, last.u[:m], last.tangent[:m], self.params,
            REORDER_REACH * self.s.ds_max,
        )  # fmt: skip
        if ahead is None:
            return None
        new = SegmentedOrbitSystem(
            self.model, self.kind, self.params, self.period, system.t0, self.stop, layout=ahead.layout
        )
        names = self.model.stop_names
        a, b = system.layout.stops[ahead.first], system.layout.stops[ahead.first + 1]
        where = self.show(self.curve_point(last).values)
        note = f"the impacts on {names[a]!r} and {names[b]!r} change order after {where}"
        return new, np.concatenate([ahead.u, last.u[m:]]), note

    def across_reordering(self, d: _Direction, before: PalcPoint, after: PalcPoint) -> None:
        """Two points on either side of a change of impact order (two systems, so nothing is located
        between them): a codimension-two test that changes sign there is reported, bracketed only."""
        ta, tb = before.payload.tests, after.payload.tests
        for name in CODIM2_TESTS[self.kind]:
            if sign_changed(ta.get(name, math.nan), tb.get(name, math.nan)):
                d.special.append(
                    (len(d.points) - 1, self.special_at(name, len(d.points) - 1, before, located=False))
                )

    def append(self, d: _Direction, pt: PalcPoint) -> None:
        d.pal.append(pt)
        d.points.append(self.curve_point(pt))
        self.count += 1
        if self.progress is not None:
            v = d.points[-1].values
            self.progress(self.count, v[0], v[1])

    # -- codimension-two points ------------------------------------------------
    def detect(self, system: Any, d: _Direction, a: PalcPoint, b: PalcPoint) -> bool:
        """Locate the codimension-two points between ``a`` and ``b``; True if one ends the curve
        (then the curve ends at it: it is the last point)."""
        found: list[tuple[float, CurveSpecial, PalcPoint | None]] = []
        ta, tb = a.payload.tests, b.payload.tests
        for name in CODIM2_TESTS[self.kind]:
            if not sign_changed(ta.get(name, math.nan), tb.get(name, math.nan)):
                continue
            loc = locate(system, a, b, lambda p, name=name: p.payload.tests[name], self.s)
            ends = max(abs(ta[name]), abs(tb[name]))
            value = math.nan if loc is None else loc.payload.tests[name]
            if abs(value) > ends:
                continue  # a pole, not a zero (the cusp coefficient at a 1:1 resonance, say)
            if loc is None or not abs(value) <= max(self.s.locate_tol, 1e-6 * ends):
                special = self.special_at(name, len(d.points) - 1, a, located=False, beyond=b)
                found.append((0.0, special, None))
                continue  # bracketed only: said so (its values are those of the point before it)
            where = float(np.dot(loc.u - a.u, b.u - a.u) / np.dot(b.u - a.u, b.u - a.u))
            found.append((where, self.special_at(name, len(d.points) - 1, loc), loc))
        if self.virtual and self.kind != "grazing":
            for j in range(self.model.n_stops):
                hit = self.grazing_of_virtual(system, j, a, b, len(d.points) - 1)
                if hit is not None:
                    found.append(hit)
        found.sort(key=lambda item: item[0])
        for _, special, loc in found:
            if special.kind in ENDING.get(self.kind, ()):
                if loc is not None:
                    self.append(d, loc)  # the curve ends at it: its last point
                d.special.append((len(d.points) - 1, special))
                d.outcome = CurveEnd(special.kind)  # (a resonance: its kind's word)
                pair = "+1" if special.kind == "1:1 resonance" else "-1"
                where = self.show(special.values) + ("" if special.located else " (bracketed only)")
                d.status = (
                    f"ended at a {special.kind} at {where}: the pair of multipliers "
                    f"meets at {pair} and becomes real beyond it (a neutral saddle, not a Neimark-Sacker "
                    "bifurcation)"
                )
                return True
            d.special.append((special.index, special))
        return False

    def special_at(
        self, kind: str, index: int, pt: PalcPoint, located: bool = True, beyond: PalcPoint | None = None
    ) -> CurveSpecial:
        """The codimension-two point at ``pt`` (located: its bracket; else between ``pt`` and ``beyond``)."""
        cp = self.curve_point(pt)
        precision, interval = self.bracket(pt, beyond)
        return CurveSpecial(
            kind=kind, index=index, values=cp.values, multipliers=cp.multipliers, state=cp.state,
            located=located, precision=precision, interval=interval,
        )  # fmt: skip

    def bracket(self, pt: PalcPoint, beyond: PalcPoint | None = None) -> tuple[Any, Any]:
        """``(precision, interval)`` in the two parameters of a point located at ``pt`` (its bracket), or
        only bracketed between ``pt`` and ``beyond`` (:func:`~grazing.orbits.curve_data.bracket_between`)."""
        i = self.offset()
        if pt.bracket is not None and beyond is None:
            return (pt.bracket.precision(i), pt.bracket.precision(i + 1)), (
                pt.bracket.interval(i), pt.bracket.interval(i + 1)
            )  # fmt: skip
        return bracket_between(pt.u[i : i + 2], None if beyond is None else beyond.u[i : i + 2])

    def show(self, values: tuple[float, float]) -> str:
        return f"{self.pars[0].show(values[0])}, {self.pars[1].show(values[1])}"

    def grazing_of_virtual(
        self, system: Any, j: int, a: PalcPoint, b: PalcPoint, index: int
    ) -> tuple[float, CurveSpecial, None] | None:
        """A virtual orbit's grazing of stop ``j`` between ``a`` and ``b`` (it goes on: a virtual curve
        reports its grazings)."""

        def test(p: PalcPoint) -> float:
            return p.payload.orbit.guard_min_by_stop[j][0]

        if not sign_changed(test(a), test(b)):
            return None
        loc = locate(system, a, b, test, self.s)
        if loc is None:
            return None
        _, t, x = loc.payload.orbit.guard_min_by_stop[j]
        point, exact = self.solve_grazing(x, t, j, loc, None, 0, False)
        where = float(np.dot(loc.u - a.u, b.u - a.u) / np.dot(b.u - a.u, b.u - a.u))
        return where, self.grazing_special(index, loc, point, exact, self.bracket(loc)), None

    def grazing_special(
        self, index: int, before: PalcPoint, point: GrazingPoint | None, exact: bool, bracket: tuple[Any, Any]
    ) -> CurveSpecial:
        """The grazing where the curve meets the grazing curve: ``point`` (the meeting point if ``exact``),
        else only bracketed after ``before``; ``bracket``: ``(precision, interval)`` of that bracket."""
        precision, interval = bracket
        if point is None:
            cp = self.curve_point(before)
            return CurveSpecial(
                kind="grazing", index=index, values=cp.values, multipliers=cp.multipliers, state=cp.state,
                located=False, precision=precision, interval=interval,
            )  # fmt: skip
        values = (point.model.params[self.params[0]], point.model.params[self.params[1]])
        if interval is None:  # (found ahead of the last point, none beyond it: between the two)
            interval = bracket_between(before.u[self.offset() : self.offset() + 2], np.array(values))[1]
        if exact:
            precision = (point.precision, point.precision)
        return CurveSpecial(
            kind="grazing", index=index, values=values, multipliers=point.multipliers,
            state=point.contact.copy(), located=exact, grazing=point, precision=precision, interval=interval,
        )  # fmt: skip

    def solve_grazing(
        self, y: np.ndarray, t: float, stop: int, before: PalcPoint, after: PalcPoint | None, others: int,
        loses: bool,
    ) -> tuple[GrazingPoint | None, bool]:  # fmt: skip
        """The grazing orbit where the curve meets the grazing curve, after ``before`` (before ``after``).

        ``(y, t)``: a guess of the contact; ``others``: the grazing orbit's
        impacts besides it; ``loses``: the curve's orbit loses an impact there
        (else it gains one).  Returns the point and whether it was solved as
        the meeting point itself (:func:`~grazing.orbits.crossings.meeting_point`;
        else it is the grazing orbit nearest ``before``).  Without other impacts
        the grazing orbit is computed with the stops ignored (:func:`_with_events`),
        and then it must cross none.
        """
        i1 = self.offset()
        pb = before.u[i1 : i1 + 2]
        scale = max(1.0, float(np.max(np.abs(pb))))
        reach = 0.0 if after is None else float(np.linalg.norm(after.u[i1 : i1 + 2] - pb))
        first = not self.virtual and others > 0
        for events in (first,) if self.virtual else (first, not first):
            near = nearest_grazing(self.model, self.params, self.period, events, stop, y, t, pb)
            if near is None and self.kind == "fold":  # (the grazing curve turns back where it meets a fold)
                guess = contact_guess(self.model, self.params, self.period, events, stop, y, t, pb)
                near = None if guess is None else meeting_point(self.kind, self.params, events, guess, loses)
                if near is not None and near.impacts == others and not (not events and _crossing(near)):
                    return near, True
                continue
            if near is None or near.impacts != others or (not events and _crossing(near)):
                continue
            pn = np.array([near.model.params[q] for q in self.params])
            if float(np.linalg.norm(pn - pb)) > reach + 1e-4 * scale:
                continue  # another grazing, not this one
            exact = meeting_point(self.kind, self.params, events, near, loses)
            return (near, False) if exact is None else (exact, True)
        return None, False

    def end_at_grazing(self, d: _Direction, palc: Palc) -> bool:
        """The curve ends at a boundary: the orbit gains or loses an impact (a codimension-two grazing).

        False where the boundary is not confirmed and no grazing is just ahead (Newton's method fails
        beyond the last point): then nothing is recorded."""
        boundary = palc.boundary
        assert boundary is not None
        before = d.pal[-1]
        index = len(d.points) - 1
        if self.kind == "grazing":
            cp = self.curve_point(before)
            near = _other_contact_margin(before.payload.grazing)
            if boundary.reached or near <= DOUBLE_GRAZING_MARGIN:
                precision, interval = self.bracket(before, boundary.after)
                double = CurveSpecial(
                    kind="double grazing", index=index, values=cp.values, multipliers=cp.multipliers,
                    state=cp.state, located=False, precision=precision, interval=interval,
                )  # fmt: skip
                d.special.append((index, double))
                reason = boundary.reason
                if not boundary.reached:
                    reason = (
                        f"the grazing orbit comes within {near:.1e} of another contact with a stop (an "
                        "impact speed or a closest approach tends to zero: a double grazing, located from "
                        "this side)"
                    )
                d.status = f"ended at a double grazing at {self.show(cp.values)}: {reason}"
                d.outcome = CurveEnd.DOUBLE_GRAZING
                return True
            return False
        if self.model.has_modes:
            return self.end_at_switch_grazing(d, palc)
        orbit = before.payload.orbit
        margin = grazing_margin(orbit)
        y, t, what, stop = margin.contact, margin.time, margin.change or "", margin.stop
        loses = what is ImpactChange.LOSES
        point, exact = (None, False)
        if y is not None:
            point, exact = self.solve_grazing(
                y, t, stop, before, boundary.after, orbit.impacts - loses, loses
            )
        if point is None and not boundary.reached:
            return False  # stuck (Newton's method fails beyond the last point), no grazing just ahead
        special = self.grazing_special(index, before, point, exact, self.bracket(before, boundary.after))
        d.special.append((index, special))
        where = self.show(special.values)
        if self.model.n_stops > 1:
            where += f" with stop {self.model.stop_names[stop]!r}"
        reason = boundary.reason
        if not boundary.reached:
            reason = f"an impact speed reaches zero: the orbit {what}"
            if what is ImpactChange.GAINS:
                reason = f"the orbit touches the stop between its impacts: it {what}"
        if point is None:
            where += " (bracketed only: the grazing equations did not converge)"
        elif not exact:
            where += " (the grazing nearest the curve's last point: the meeting point did not converge)"
        d.status, d.outcome = f"ended at a grazing at {where}: {reason}", CurveEnd.GRAZING
        return True

    def end_at_switch_grazing(self, d: _Direction, palc: Palc) -> bool:
        """The curve ends where its orbit's switches of mode change (a model with modes): a grazing of a
        switching surface, bracketed between the last point and the first beyond it (False where no
        orbit beyond was found: nothing is recorded)."""
        boundary = palc.boundary
        assert boundary is not None
        if not boundary.reached or boundary.after is None:
            return False
        before = d.pal[-1]
        index = len(d.points) - 1
        found = switch_change(before.payload.orbit, boundary.after.payload.orbit)
        special = self.grazing_special(index, before, None, False, self.bracket(before, boundary.after))
        d.special.append((index, special))
        where = self.show(special.values)
        if found is not None:
            where += f" of transition {self.model.stop_names[found[1]]!r}"
        d.status = f"ended at a grazing at {where} (bracketed only): {boundary.reason}"
        d.outcome = CurveEnd.GRAZING
        return True


def follow_curve(
    model: HybridModel,
    kind: str,
    param: str,
    start: float,
    stop: float,
    param2: str,
    range2: tuple[float, float],
    *,
    x0: np.ndarray | None = None,
    orbit: PeriodicOrbit | None = None,
    period: int | None = None,
    stop_name: int | str | None = None,
    settings: PalcSettings | None = None,
    progress: CurveProgress | None = None,
) -> BifurcationCurve:
    """Follow a bifurcation of a periodic orbit in two parameters.

    The orbit at ``param = start`` is continued towards ``stop``
    (:func:`~grazing.orbits.continuation.continue_orbit`) up to its first
    special point of ``kind``; that point is followed in ``(param, param2)``
    in both directions, each until ``param2`` leaves ``range2``, a parameter
    leaves its own interval, or the curve ends at a codimension-two point that
    ends it (a grazing, where the orbit's impact sequence changes; a 1:1 or 1:2
    resonance on a Neimark-Sacker curve), or Newton's method fails.  A closed
    curve stops where it comes back to its start, once round (both ends
    :attr:`~grazing.orbits.curve_data.CurveEnd.CLOSED`, its last point its
    first, :attr:`~grazing.orbits.curve_data.BifurcationCurve.closed`).

    On a model with modes the orbits go through their switches of mode (single
    shooting only); a fold or period-doubling curve ends where its orbits'
    switches change (a grazing of a switching surface, bracketed), and the
    grazing curve of a transition is the orbit of its source mode tangent to
    its guard (:func:`~grazing.orbits.contact.contact_system`).

    Parameters
    ----------
    model
        The model with the other parameters set; its value of ``param2`` is where
        the curve starts.
    kind
        ``"fold"``, ``"period-doubling"``, ``"neimark-sacker"``, ``"branch-point"``
        or ``"grazing"`` (:data:`CURVE_KINDS`).
    param, start, stop
        The continuation parameter and the interval searched for the start.
    param2, range2
        The second parameter and its interval ``(lo, hi)`` (model units), which
        must hold its value in ``model``.
    x0, orbit, period
        The starting orbit or a guess for it (as for :func:`continue_orbit`).
    stop_name
        A stop (name or index): for ``"grazing"``, the first grazing with that
        stop (default: the first grazing); a nonimpacting orbit's branch looks for
        its grazings first (as for :func:`continue_orbit`).
    settings
        Step control (:class:`~grazing.orbits.palc.PalcSettings`; ``max_points``
        for each direction).
    progress
        Called as ``progress(stage, points, value1, value2)`` after each point
        (stage ``"branch"``, then ``"curve"``).

    Returns
    -------
    BifurcationCurve

    Raises
    ------
    NotFoundError
        When the branch meets no special point of ``kind``: the message names
        the special points met instead.
    InvalidParameterError
        An unknown kind or parameter, ``param2`` equal to ``param``, a
        ``range2`` without the value of ``param2``.


    Examples
    --------
    The fold of the period-1 orbit of the ball on a vibrating table (``g = omega = 1``) lies at
    ``amplitude = pi (1 - r) / (1 + r)``:

    >>> import math, grazing
    >>> m = grazing.models.bouncing_ball(amplitude=1.5, r=0.5)
    >>> curve = follow_curve(m, "fold", "amplitude", 1.5, 0.5, "r", (0.45, 0.55), x0=[3.26, -2.34], period=1)
    >>> a, r = curve.values("amplitude"), curve.values("r")
    >>> bool(np.allclose(a, np.pi * (1 - r) / (1 + r), atol=1e-8)), float(r.min()), float(r.max())
    (True, 0.45, 0.55)
    """
    if kind not in CURVE_KINDS:
        raise InvalidParameterError(f"unknown curve kind {kind!r} (known: {', '.join(CURVE_KINDS)})")
    kind = CurveKind(kind)
    for name in (param, param2):
        model.parameter(name)  # unknown names: one line naming the known ones
    if param2 == param:
        raise InvalidParameterError(f"the second parameter must differ from the first ({param!r})")
    lo, hi = (float(v) for v in range2)
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise InvalidParameterError(f"range2 must be two finite numbers lo < hi, got {range2!r}")
    par2 = model.parameter(param2)
    value2 = model.params[param2]
    if not lo <= value2 <= hi:
        raise InvalidParameterError(
            f"the range {par2.show_range(lo, hi)} excludes the start value {par2.show(value2)}"
        )
    s = settings or PalcSettings()

    def branch_progress(points: int, value: float) -> None:
        if progress is not None:
            progress("branch", points, value, value2)

    watch = None if stop_name is None else model.stop_index(stop_name)
    branch = continue_orbit(
        model, param, start, stop, x0=None if x0 is None else np.asarray(x0, dtype=float), orbit=orbit,
        period=period, settings=s, progress=branch_progress, stop_name=watch,
    )  # fmt: skip
    sp_ = _start_point(branch, kind, watch)
    if kind == "grazing":
        if sp_.grazing is None:
            raise ConvergenceError(
                f"the grazing at {model.parameter(param).show(sp_.param)} was bracketed but its equations "
                "did not converge: no grazing curve"
            )
        first: PeriodicOrbit | GrazingPoint = sp_.grazing
    else:
        first = sp_.orbit
    return _follow_from(
        model, kind, (param, param2), (lo, hi), first, branch.virtual, sp_.orbit.stop, s,
        None if progress is None else lambda k, v1, v2: progress("curve", k, v1, v2), sp_, branch,
    )  # fmt: skip


def _difference(a: CurvePoint, b: CurvePoint) -> np.ndarray:
    """``a - b`` for two points of a curve: in the orbit's state, its section time (modulo the forcing
    period) and the two parameters."""
    model = a.orbit.model if a.orbit is not None else a.grazing.model if a.grazing is not None else None
    dt = a.section_time - b.section_time
    if model is not None:
        dt = (dt + 0.5 * model.period) % model.period - 0.5 * model.period
    return np.concatenate([a.state - b.state, np.subtract(a.values, b.values), [dt]])


def _came_back(d: _Direction) -> float | None:
    """Where the curve's last step passed its start (within :data:`CLOSURE_TOL` of the step's length),
    after it had gone farther from it than two such steps: the fraction of the step at which it came
    nearest (1 where the start lies just beyond the step); None where it did not come back."""
    start, last = d.points[0], d.points[-1]
    if len(d.points) < 3 or start.state.shape != last.state.shape:
        return None
    away = d.farthest
    d.farthest = max(away, float(np.linalg.norm(_difference(last, start))))
    step = _difference(last, d.points[-2])
    size = float(np.linalg.norm(step))
    if not (size > 0.0 and away > 2.0 * size):
        return None
    to_start = _difference(start, d.points[-2])
    along = min(max(float(to_start @ step) / (size * size), 0.0), 1.0)
    return along if float(np.linalg.norm(to_start - along * step)) <= CLOSURE_TOL * size else None


def _follow_from(
    model: HybridModel, kind: str, params: tuple[str, str], range2: tuple[float, float],
    first: PeriodicOrbit | GrazingPoint, virtual: bool, stop: int, settings: PalcSettings,
    progress: Callable[[int, float, float], None] | None = None, sp_: SpecialPoint | None = None,
    branch: Branch | None = None,
) -> BifurcationCurve:  # fmt: skip
    """Follow the curve of ``kind`` through the orbit (or grazing orbit) ``first``, both ways from it,
    and join the two halves in order along the curve."""
    f = _Follower(model, kind, params, range2, first.period, virtual, stop, settings, progress)
    system = f.system(first)
    i1 = f.offset()
    u0 = system.start(first)
    t = tangent(f.first(system, u0, i1 + 1).DF)
    which = 0 if abs(t[i1]) >= abs(t[i1 + 1]) else 1  # the parameter that moves most
    back = f.run(first, -1.0, which)
    if back.outcome is CurveEnd.CLOSED:  # (the loop is whole: the other way would go round it again)
        ahead = _Direction()
        ahead.points, ahead.status, ahead.outcome = back.points[:1], back.status, back.outcome
    else:
        ahead = f.run(first, 1.0, which)
    curve = BifurcationCurve(
        model=f.model,
        kind=f.kind,
        params=f.params,
        period=f.period,
        virtual=f.virtual,
        start=sp_,
        branch=branch,
    )
    nb = len(back.points)
    curve.points = back.points[::-1] + ahead.points[1:]
    curve.start_index = nb - 1
    specials = [(nb - 1 - i, s) for i, s in reversed(back.special)]
    specials += [(nb - 1 + i, s) for i, s in ahead.special]
    curve.special = [dataclasses.replace(s, index=i) for i, s in specials]
    curve.status = f"at the first point: {back.status}; at the last point: {ahead.status}"
    assert back.outcome is not None and ahead.outcome is not None
    curve.outcomes = (back.outcome, ahead.outcome)
    return curve
