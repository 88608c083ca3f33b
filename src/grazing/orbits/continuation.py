"""Pseudo-arclength continuation of periodic orbits in one parameter.

Unknowns ``u = (x, p)``: a point of the orbit on the stroboscopic section and
the parameter.  Equations ``F(u) = P^n(x; p) - x = 0`` with Jacobian
``[P_x - I, P_p]`` (:mod:`grazing.orbits.branch_equations`).  Each step predicts
along the tangent (the null vector of the Jacobian) and corrects by Newton's
method on ``F = 0`` plus the arclength condition (Keller 1977; Kuznetsov,
*Elements of Applied Bifurcation Theory*, ch. 10).

A branch is one orbit.  Every point carries its *impact signature* (impacts in
each of the ``n`` forcing periods); a corrected point with another signature
is another orbit, reached through a grazing (an impact speed, or the distance
of a near approach to the stop, passing through zero).  The branch therefore
ends at that grazing: it is bracketed along the step, located exactly by
solving the grazing equations (:mod:`grazing.orbits.contact`, Newton
tolerance) and reported as a special point, as COCO's hybrid toolbox does.
Where Newton's method fails before the grazing (an impact speed tending to
zero makes the saltation matrix, hence the map, singular), the grazing is
located from the last point, if it lies ahead within the distance at which
``v^2 / (2a)`` extrapolates to zero and its contact lies next to the
vanishing impact.  Steps are halved where the corrector lands far from the
predictor, where the tangent turns sharply, and where the number of
multipliers outside the unit circle changes, so that no special point is
stepped over.

Between consecutive points the smooth special points are detected by sign
changes of test functions and located to Newton tolerance
(:mod:`grazing.orbits.bifurcations`): fold (the parameter turns, a multiplier
+1), branch point (the pseudo-arclength determinant changes sign, a multiplier
+1: symmetry breaking, transcritical), period-doubling (-1), Neimark-Sacker (a
complex pair on the unit circle); and on virtual branches the grazing of every
stop (the minimum of its guard reaches zero, refined by the grazing
equations).  Every change of the number of multipliers outside the unit circle
between two points must be explained by the points located there; where it is
not, the branch reports an ``unlocated`` special point ("unlocated stability
change between p1 and p2"): no change of stability passes silently.

With ``switch=True`` the continuation switches branches, each branch switched
to being a new *segment* (:mod:`grazing.orbits.switching`): at every grazing
where the impact sequence changes, onto the orbit with the new sequence (the
old orbit ends there); and at the first period-doubling or branch point met,
onto the branch born there instead of going on along this one: the
period-``2n`` orbit (up to period :data:`~grazing.core.options.MAX_PERIOD`),
or the other branch through the branch point, both ways (one segment each,
the second after the first and everything it switched to).  Later
period-doublings and branch points are reported, not switched at: one switch
of that kind per run keeps the branch a chain, not a tree.

The stroboscopic map is not smooth where an impact falls on its section, so
the section is chosen away from impacts (``t0=None``, the default) and moved
when an impact comes within :data:`RESECTION_MARGIN` of a period of it; each
point records its section time.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.options import BOUNDARY_TOL, MAX_PERIOD
from grazing.errors import ConvergenceError, GrazingError, InvalidParameterError
from grazing.orbits.bifurcations import Located, between, neimark_sacker_angle
from grazing.orbits.branch_equations import branch_equations
from grazing.orbits.contact import GrazingPoint, refine_grazing
from grazing.orbits.kinds import SpecialKind, TextEnum
from grazing.orbits.palc import (
    ACCEPT,
    BOUNDARY,
    REFINE,
    STOP,
    Boundary,
    Palc,
    PalcEnd,
    PalcPoint,
    PalcSettings,
    correct,
    locate,
    sign_changed,
)
from grazing.orbits.segmented_grazing import (
    brief_excursion,
    excursions,
    extrapolated_grazing,
    locate_segmented_grazing,
)
from grazing.orbits.segments import (
    MULTIPLE_SHOOTING_NORM,
    REORDER_REACH,
    SegmentLayout,
    cuts_at_switches,
    layout_of,
    reordered,
    segmented_equations,
    switch_rates,
)
from grazing.orbits.shooting import (
    SECTION_MARGIN,
    PeriodicOrbit,
    find_orbit,
    is_isolated,
    move_section,
    not_isolated_message,
    quiet_section,
)
from grazing.orbits.sliding_bifurcations import bisect_switches, sliding_kind
from grazing.orbits.switch_grazing import grazed_transition, locate_switch_grazing
from grazing.orbits.switching import SegmentStart, crossing_starts, doubled_start, new_sequence_orbit

SPECIAL_KINDS = tuple(k for k in SpecialKind if k is not SpecialKind.UNLOCATED)
"""The special points that :func:`continue_orbit` detects and locates (its ``detect``)."""

UNLOCATED = SpecialKind.UNLOCATED
"""The kind of a special point that stands for a stability change no located point explains."""

SWITCH_KINDS = (SpecialKind.PERIOD_DOUBLING, SpecialKind.BRANCH_POINT, SpecialKind.GRAZING)
"""The special points where another branch starts: ``switch`` continues onto it."""

RESECTION_MARGIN = 0.01
"""An impact closer than this fraction of a period to the section moves the section."""

RESECTION = "an impact approaches the section"
"""Why a branch or a curve stops to move its section (:data:`RESECTION_MARGIN`): the ``STOP`` reason of
their checks, and the start of their status where the orbit is not found on another section."""


class BranchEnd(enum.Enum):
    """Why a segment of a branch ended (:attr:`Branch.outcome`, :attr:`Branch.segment_outcome`): its
    :attr:`message` in a few words; the branch's :attr:`Branch.status` says it in full, with the values.

    Examples
    --------
    >>> BranchEnd.GRAZING.message
    'ended at a grazing'
    """

    BOUND = "reached the end of the range"
    MAX_POINTS = "maximum number of points reached"
    STUCK = "Newton's method failed beyond the last point"
    RESECTION = RESECTION
    """The section had to move, with no points left to go on."""
    NO_SECTION = "the orbit could not be found on another section"
    CANNOT_CONTINUE = "the orbit could not be computed where the segment starts"
    GRAZING = "ended at a grazing"
    DOUBLE_GRAZING = "ended at a double grazing"
    SWITCHED = "switched to another branch"

    @property
    def message(self) -> str:
        """The outcome in a few words."""
        return str(self.value)

    @classmethod
    def of(cls, end: PalcEnd | None) -> BranchEnd:
        """The outcome of a segment whose continuation ended with ``end`` (not at a grazing)."""
        return {
            PalcEnd.BOUND: cls.BOUND,
            PalcEnd.STOPPED: cls.RESECTION,
            PalcEnd.MAX_POINTS: cls.MAX_POINTS,
        }.get(end, cls.STUCK)  # type: ignore[arg-type]


ContinuationSettings = PalcSettings
"""Options of :func:`continue_orbit` (see :class:`~grazing.orbits.palc.PalcSettings`)."""


@dataclass(frozen=True, kw_only=True)
class SpecialPoint:
    """A located special point on a branch (between points ``index`` and ``index + 1``).

    Attributes
    ----------
    kind
        One of :data:`SPECIAL_KINDS`, or :data:`UNLOCATED` (a :class:`~grazing.orbits.kinds.SpecialKind`: a
        string equal to the ``kind`` that ``--json`` and the branch's dataset write).
    index
        The branch point just before it.
    param
        The parameter value where it occurs (for an unlocated stability change: the middle of
        the two points' values, :attr:`between`).
    orbit
        The periodic orbit there (for a grazing: the orbit where the branch
        ends, next to the grazing; for an unlocated stability change: the orbit at point
        ``index``).
    grazing
        For a grazing: the grazing orbit itself, solved from the grazing
        equations (contact state and time, monodromy on the section through
        the contact with the grazing contact not an impact); None if those
        did not converge, in which case ``param`` is the end of the bracket.
    stop
        For a grazing: the index of the stop grazed.
    note
        For an unlocated stability change: what was seen, in words ("unlocated stability
        change between omega = 0.9 and omega = 0.95: ...", the values in display units); for
        a period-doubling or branch point where ``switch`` found no branch to follow: why.
    between
        For an unlocated stability change: the parameter values of the two points.
    tangent
        For a fold, branch point, period-doubling or Neimark-Sacker point: the branch's unit
        tangent there, in ``u = (x, p)`` (a branch point: the tangent of the branch followed).
    turns
        For a branch point: the parameter turns there (the curved branch of a pitchfork); for a
        fold, always.
    switched
        The continuation switched there onto another branch (``switch``).
    precision
        How far :attr:`param` may be from the special point's parameter (as BifurcationKit's
        ``SpecialPoint.precision``): for a point located between two points of the branch, its test
        function's value there over the test's slope, at most the final bracket's width; for a grazing,
        the parameter part of the grazing equations' next Newton step (or the bracket's width where
        they did not converge); nan for an unlocated change.
    interval
        The parameter values between which the special point lies (``(low, high)``, as
        BifurcationKit's ``interval``): the parameter at the two points of the branch that end the last
        bracket of the location, widened to hold ``param +- precision`` (where the branch bends between
        them, as it does at a fold, both ends may lie on one side of the point:
        :meth:`~grazing.orbits.palc.Bracket.interval`); of a grazing: the last point before it and the
        first beyond, where there is one; of an unlocated change: its two points; None where unknown.

    Examples
    --------
    The first grazing of the period-1 orbit at θ̂ = 40° (case B), met by
    :func:`continue_orbit`: where, how precisely, and its multipliers:

    >>> import math, numpy as np, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> sp = continue_orbit(m, "eta", 0.40, 0.47).special[0]
    >>> round(sp.param, 6), bool(sp.precision < 1e-10), sp.interval[0] < sp.param < sp.interval[1]
    (0.445121, True, True)
    >>> np.abs(sp.multipliers).round(4).tolist(), sp.orbit.impacts
    ([0.5079, 0.5079], 0)
    """

    kind: SpecialKind
    index: int
    param: float
    orbit: PeriodicOrbit
    grazing: GrazingPoint | None = None
    stop: int = 0
    note: str = ""
    between: tuple[float, float] | None = None
    tangent: np.ndarray | None = None
    turns: bool = False
    switched: bool = False
    precision: float = math.nan
    interval: tuple[float, float] | None = None

    @property
    def multipliers(self) -> np.ndarray:
        """Floquet multipliers at the point (of the grazing orbit for a grazing)."""
        return self.grazing.multipliers if self.grazing is not None else self.orbit.multipliers

    @property
    def angle(self) -> float:
        """For a Neimark-Sacker point: the angle ``theta`` in ``(0, pi)`` of its pair ``exp(+-i theta)`` on
        the unit circle, in radians (:func:`~grazing.orbits.bifurcations.neimark_sacker_angle`); else nan."""
        return neimark_sacker_angle(self.multipliers) if self.kind == SpecialKind.NEIMARK_SACKER else math.nan


@dataclass
class Branch:
    """A computed branch of periodic orbits.

    Attributes
    ----------
    param
        Name of the continuation parameter.
    period
        The starting orbit's period (see :attr:`periods` for each point's).
    values
        Parameter value at each point.
    orbits
        The periodic orbit at each point (state on its section ``orbit.t0``,
        multipliers, impacts...).
    segments
        Segment index of each point: 0, then one more for each branch followed after a
        switch (``switch=True``).
    special
        Located special points, in order along the branch (segment after segment).
    status
        Why the continuation stopped, in words (its last segment; :attr:`segment_status` has each
        segment's); :attr:`outcome` the same as a :class:`BranchEnd`.
    segment_status
        Why each segment ended.
    outcome
        Why the continuation stopped (its last segment's :attr:`segment_outcome`).
    segment_outcome
        Why each segment ended, as a :class:`BranchEnd` (beside :attr:`segment_status`).
    segment_origin
        For each segment, the index in :attr:`special` of the point it was switched to from
        (-1 for the first).
    model
        The model (with the values of the other parameters).
    virtual
        The orbits are computed with the stops ignored (a nonimpacting orbit
        followed past its grazing).
    arclength
        The pseudo-arclength of each point from the first.

    Examples
    --------
    The nonimpacting period-1 orbit of the pendulum at θ̂ = 40° (case B),
    from η = 0.40 up to its grazing:

    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> br = continue_orbit(m, "eta", 0.40, 0.47)
    >>> br.period, br.virtual, br.values[0], br.status
    (1, True, 0.4, 'reached the bound eta = 0.47')
    >>> ds = br.to_dataset()
    >>> ds.param.size == len(br), bool((ds.arclength.diff("point") > 0).all())
    (True, True)
    """

    model: HybridModel
    param: str
    period: int
    virtual: bool
    values: list[float] = field(default_factory=list)
    orbits: list[PeriodicOrbit] = field(default_factory=list)
    arclength: list[float] = field(default_factory=list)
    segments: list[int] = field(default_factory=list)
    special: list[SpecialPoint] = field(default_factory=list)
    status: str = ""
    segment_status: list[str] = field(default_factory=list)
    segment_origin: list[int] = field(default_factory=list)
    outcome: BranchEnd | None = None
    segment_outcome: list[BranchEnd] = field(default_factory=list)

    def end_segment(self, outcome: BranchEnd, status: str) -> None:
        """Record why a segment ended: its outcome and the sentence that says it."""
        self.segment_outcome.append(outcome)
        self.segment_status.append(status)

    def __len__(self) -> int:
        return len(self.values)

    @property
    def states(self) -> np.ndarray:
        return np.array([o.state for o in self.orbits])

    @property
    def multipliers(self) -> np.ndarray:
        return np.array([o.multipliers for o in self.orbits])

    @property
    def periods(self) -> np.ndarray:
        """The period of each point's orbit, in forcing periods (it doubles after a switch at a
        period-doubling)."""
        return np.array([o.period for o in self.orbits], dtype=int)

    @property
    def guard_min(self) -> np.ndarray:
        return np.array([o.guard_min for o in self.orbits])

    @property
    def sections(self) -> np.ndarray:
        """The section time of each point's orbit (see the module docstring)."""
        return np.array([o.t0 for o in self.orbits])

    def to_dataset(self) -> Any:
        """The branch as an :class:`xarray.Dataset` (one ``point`` per orbit)."""
        import xarray as xr

        import grazing

        mu = self.multipliers
        names = list(self.model.state_names)
        data = {
            "param": ("point", np.asarray(self.values)),
            "arclength": ("point", np.asarray(self.arclength)),
            "segment": ("point", np.asarray(self.segments, dtype=np.int32)),
            "period": ("point", self.periods.astype(np.int32)),
            "section_time": ("point", self.sections),
            "state": (("point", "component"), self.states),
            "multiplier_re": (("point", "multiplier"), mu.real),
            "multiplier_im": (("point", "multiplier"), mu.imag),
            "abs_multiplier": (("point", "multiplier"), np.abs(mu)),
            "stable": ("point", np.array([o.stable for o in self.orbits], dtype=np.int8)),
            "impacts": ("point", np.array([o.impacts for o in self.orbits], dtype=np.int32)),
            "guard_min": ("point", self.guard_min),
            "min_impact_speed": ("point", np.array([o.min_impact_speed for o in self.orbits])),
            "special_kind": ("special", np.array([s.kind for s in self.special], dtype=str)),
            "special_index": ("special", np.array([s.index for s in self.special], dtype=np.int32)),
            "special_param": ("special", np.array([s.param for s in self.special], dtype=float)),
            "special_state": (
                ("special", "component"),
                np.array([s.orbit.state for s in self.special]).reshape(-1, len(names)),
            ),
            "special_abs_multiplier": (
                ("special", "multiplier"),
                np.array([np.abs(s.multipliers) for s in self.special]).reshape(-1, len(names)),
            ),
            "special_note": ("special", np.array([s.note for s in self.special], dtype=str)),
            "special_switched": ("special", np.array([s.switched for s in self.special], dtype=np.int8)),
            "special_precision": ("special", np.array([s.precision for s in self.special], dtype=float)),
            "special_interval": (
                ("special", "bound"),
                np.array([s.interval or (np.nan, np.nan) for s in self.special], dtype=float).reshape(-1, 2),
            ),
        }
        # Where each orbit comes closest to the stop (its largest angle, for the pendulum).
        nan = np.full(len(names), np.nan)
        closest = [o.x_guard_min if o.x_guard_min is not None else nan for o in self.orbits]
        data["closest_state"] = (("point", "component"), np.array(closest).reshape(-1, len(names)))
        if self.model.has_modes:  # (the mode on the section and the switches of mode per period)
            data["mode"] = ("point", np.array([o.mode for o in self.orbits], dtype=str))
            data["switches"] = ("point", np.array([o.switch_times.size for o in self.orbits], dtype=np.int32))
        ds = xr.Dataset(data, coords={"component": names, "multiplier": np.arange(len(names))})
        ds.param.attrs["long_name"] = self.param
        ds.period.attrs["long_name"] = "period of the orbit in forcing periods"
        attrs: dict[str, Any] = {
            "model": self.model.name,
            "continuation_parameter": self.param,
            "period": self.period,
            "virtual": int(self.virtual),
            "status": self.status,
            "grazing_version": grazing.__version__,
        }
        for k, v in self.model.params.items():
            if k != self.param:
                attrs[f"param_{k}"] = v
        ds.attrs.update(attrs)
        return ds

    def to_netcdf(self, path: str | Path, overwrite: bool = False) -> None:
        """Save :meth:`to_dataset` to a NetCDF file (:func:`grazing.outputs.write_netcdf`: all at once,
        with grazing's mark; a file there that grazing did not write is refused unless ``overwrite``)."""
        from grazing.outputs import write_netcdf

        write_netcdf(path, self.to_dataset(), overwrite=overwrite)


# ----------------------------------------------------------------------------


def _reduced(u: np.ndarray, nx: int) -> np.ndarray:
    """``(x, p)`` of a point or tangent ``u`` of either formulation: single shooting's ``(x, p)`` as it is,
    multiple shooting's ``(s_0, t_1, s_1, ..., p)`` without its impacts' unknowns."""
    return u if u.size == nx + 1 else np.append(u[:nx], u[-1])


def _sign_of(direction: np.ndarray) -> float:
    """The direction in which the parameter (the last component of ``direction``) moves first (+1 where
    it does not move)."""
    return math.copysign(1.0, direction[-1] or 1.0)


def _stop_guard_min(orbit: PeriodicOrbit, stop: int) -> float:
    """The smallest value of stop ``stop``'s guard along a virtual orbit: zero where it grazes that stop.

    (A physical branch ends at its grazings instead: nan.)
    """
    return orbit.guard_min_by_stop[stop][0] if orbit.virtual else math.nan


def _detect_grazing(
    evaluate, stop: int, a: PalcPoint, b: PalcPoint, param: str, n: int, s: PalcSettings
) -> SpecialPoint | None:
    """The grazing of stop ``stop`` between two points of a virtual branch, located and refined."""
    test = lambda p: _stop_guard_min(p.payload, stop)  # noqa: E731
    if not sign_changed(test(a), test(b)):
        return None
    loc = locate(evaluate, a, b, test, s)
    if loc is None:
        return None
    lo: PeriodicOrbit = loc.payload
    _, t, x = lo.guard_min_by_stop[stop]
    point = None
    try:
        point = refine_grazing(lo.model, x, t, param, period=n, stop_name=stop)
    except GrazingError:
        point = None
    value = float(loc.u[-1]) if point is None else point.model.params[param]
    last, bracket = loc.u.size - 1, loc.bracket
    if point is not None:  # (its own precision; between the two points, which the guard's minimum brackets)
        precision = point.precision
        interval = (min(float(a.u[-1]), float(b.u[-1])), max(float(a.u[-1]), float(b.u[-1])))
    else:
        precision = bracket.precision(last) if bracket is not None else math.nan
        interval = bracket.interval(last) if bracket is not None else None
    return SpecialPoint(
        kind=SpecialKind.GRAZING, index=-1, param=value, orbit=lo, grazing=point, stop=stop,
        precision=precision, interval=interval,
    )  # fmt: skip


GRAZING_TIE = 1e-6
"""Margins (:func:`grazing_margin`) of two stops within this relative difference are one simultaneous
grazing (a symmetric orbit touching both walls at once): the stop with the lower index is named, not
whichever rounding makes the smaller."""


class ImpactChange(TextEnum):
    """What a grazing does to an orbit's impacts (:attr:`GrazingMargin.change`), in the words of the
    branch's status."""

    GAINS = "gains an impact"
    """A closest approach to the stop between the impacts reaches it."""
    LOSES = "loses an impact"
    """An impact's speed reaches zero."""


@dataclass(frozen=True, kw_only=True)
class GrazingMargin:
    """How far an orbit is from grazing, and where (:func:`grazing_margin`).

    Attributes
    ----------
    delta
        The margin: zero at the grazing (``inf`` for an orbit that neither impacts nor approaches a stop).
    contact
        A guess of the contact state (the closest approach, or the weakest impact); None with ``delta``
        infinite.
    time
        The time of that contact (nan without one).
    change
        Whether the orbit gains an impact or loses one there (None without a contact).
    stop
        The index of the stop concerned.
    """

    delta: float
    contact: np.ndarray | None
    time: float
    change: ImpactChange | None
    stop: int


def grazing_margin(orbit: PeriodicOrbit) -> GrazingMargin:
    """How far ``orbit`` is from grazing, and where (:class:`GrazingMargin`).

    ``delta`` is the smaller of the closest approach to the stop away from the
    impacts (``h`` at a local minimum of the guard) and, over the impacts,
    ``v^2 / (2 a)`` (how deep the local parabola of a low-velocity impact
    reaches, ``v`` the impact speed and ``a = L_f^2 h``).  Both tend to zero
    linearly in the parameter as the orbit approaches a grazing from its side
    (``v^2 / (2 a)`` may also tend to zero quadratically, where ``v`` does linearly).
    ``stop`` is the index of the stop concerned (closest approaches and
    impacts on every stop are considered; of stops whose margins are equal to
    :data:`GRAZING_TIE`, the first, then the earliest contact).
    """
    found: list[tuple[float, np.ndarray | None, float, ImpactChange, int]] = []
    for j, ap in enumerate(orbit.approach_by_stop):  # a new impact on any stop
        if ap is not None:
            found.append((ap[0], ap[2], ap[1], ImpactChange.GAINS, j))
    if orbit.impact_states is not None:
        stops = orbit.impact_stops if orbit.impact_stops.size == orbit.impact_times.size else None
        for i, (t, v, x) in enumerate(zip(orbit.impact_times, orbit.impact_speeds, orbit.impact_states)):
            j = int(stops[i]) if stops is not None else 0
            a = abs(orbit.model.normal_accel(x, t, j))
            found.append((v * v / (2 * a) if a > 0 else math.inf, x, float(t), ImpactChange.LOSES, j))
    least = min((f[0] for f in found), default=math.inf)
    if not math.isfinite(least):
        return GrazingMargin(delta=math.inf, contact=None, time=math.nan, change=None, stop=orbit.stop)
    _, x, t, change, stop = min(
        (f for f in found if f[0] <= least + abs(least) * GRAZING_TIE), key=lambda f: (f[4], f[2])
    )  # (a margin below zero: the orbit of a multiple-shooting segment passes through the stop)
    return GrazingMargin(delta=least, contact=x, time=t, change=change, stop=stop)


AHEAD_FACTOR = 2.0
"""A grazing located from the last point of a branch whose Newton steps failed before it is accepted
up to this many times the distance at which the margin (:func:`grazing_margin`) extrapolates to zero."""

NEAR_CONTACT = 0.05
"""A grazing located that way must touch the stop within this fraction of a forcing period of the
vanishing impact (or closest approach), and within this fraction of ``max(1, |x|)`` of its state."""

BETWEEN_SLACK = 1e-8
"""A grazing located between the last orbit of a branch and the first beyond it may lie outside their
values by this (relative to ``max(1, |value|)``): a hundred times the width to which the boundary is
bracketed (:data:`~grazing.core.options.BOUNDARY_TOL`), for the grazing equations' own error."""

NEAR_LAST = 1e-4
"""A grazing located from a branch's last orbit alone (its Newton steps failed beyond) within this of
its value (relative to ``max(1, |value|)``) is that orbit's, with no other check: far below the steps
near a boundary (halved down to ``ds_max / 16``), so no other grazing is that close."""


def _locate_grazing(
    last: PeriodicOrbit,
    beyond: PeriodicOrbit | None,
    param: str,
    virtual: bool,
    ahead: float | None = None,
) -> GrazingPoint | None:
    """The grazing orbit at the end of a branch, from its last orbit (Newton on the contact equations).

    With ``beyond`` (the first orbit past the boundary) the grazing must lie between the two.
    Without it, within :data:`NEAR_LAST` ``max(1, |p|)`` of the last value ``p``, or, given ``ahead`` (where
    the margin extrapolates to zero), ahead of ``p`` in the direction of travel up to
    :data:`AHEAD_FACTOR` times that distance, with its contact next to the vanishing impact
    (:data:`NEAR_CONTACT`): the same orbit's grazing.
    """
    margin = grazing_margin(last)
    y, tg = margin.contact, margin.time
    if y is None:
        return None
    try:
        point = refine_grazing(
            last.model, y, tg, param, period=last.period, events=not virtual, stop_name=margin.stop
        )
    except GrazingError:
        return None
    # It must be the grazing between the two sides, not some other solution of the equations.
    p, pg = last.model.params[param], point.model.params[param]
    scale = max(1.0, abs(p))
    if beyond is not None:
        q = beyond.model.params[param]
        return point if min(p, q) - BETWEEN_SLACK * scale <= pg <= max(p, q) + BETWEEN_SLACK * scale else None
    if abs(pg - p) <= NEAR_LAST * scale:
        return point
    if ahead is None or not (pg - p) * (ahead - p) > 0 or abs(pg - p) > AHEAD_FACTOR * abs(ahead - p):
        return None
    T = last.model.period
    lag = (point.t_graze - tg) / T
    near_time = abs(lag - round(lag)) <= NEAR_CONTACT
    near_state = float(np.max(np.abs(point.contact - y))) <= NEAR_CONTACT * max(1.0, float(np.max(np.abs(y))))
    return point if near_time and near_state else None


DOUBLE_GRAZING_AGREE = 1e-9
"""Two excursions of a stalled branch that shrink to nothing at values of its parameter this close
(relative to ``max(1, |p|)``, their extrapolations' precisions included) end it at a double grazing."""

STALLED_EXCURSION = 1e-3
"""Multiple shooting on a branch's switches that stalls with an excursion through another mode shorter
than this many forcing periods stalled at its grazing (the excursion's two switches meet there, and the
equations are singular: it stalls with the excursion far shorter, 1e-8 periods and less)."""


class SwitchChange(TextEnum):
    """What a grazing of a switching surface does to an orbit's switches of mode (a model with modes)."""

    GAINS = "gains a switch"
    LOSES = "loses a switch"
    CHANGES = "changes the order of its switches"


def switch_change(a: PeriodicOrbit, b: PeriodicOrbit) -> tuple[SwitchChange, int] | None:
    """How the switches of mode of ``b`` differ from ``a``'s (their number or order in a forcing period,
    :attr:`~grazing.orbits.periodic.PeriodicOrbit.switch_signature`), and the first transition whose
    count differs (or, same counts, the first out of order); None where they do not differ."""
    sa, sb = a.switch_signature, b.switch_signature
    if sa == sb:
        return None
    na, nb = sum(map(len, sa)), sum(map(len, sb))
    what = SwitchChange.GAINS if nb > na else SwitchChange.LOSES if nb < na else SwitchChange.CHANGES
    names = a.model.switch_names
    flat_a, flat_b = [n for p in sa for n in p], [n for p in sb for n in p]
    counts = [j for j, nm in enumerate(names) if flat_a.count(nm) != flat_b.count(nm)]
    if counts:
        return what, counts[0]
    first = next(
        (i for i, (x, y) in enumerate(zip(flat_a, flat_b)) if x != y), min(len(flat_a), len(flat_b)) - 1
    )
    return what, names.index(flat_a[max(first, 0)]) if flat_a else 0


def switch_change_reason(a: PeriodicOrbit, b: PeriodicOrbit) -> str:
    """The boundary between two orbits of a branch whose switches of mode differ, in words."""
    found = switch_change(a, b)
    assert found is not None
    what, j = found
    before = [list(p) for p in a.switch_signature]
    after = [list(p) for p in b.switch_signature]
    return (
        f"the orbit {what} ({a.model.switch_names[j]!r}; switches per forcing period {before} -> {after}): a "
        "grazing of a switching surface"
    )


class _Continuation:
    """One run of :func:`continue_orbit`: its settings, the branch it fills, one segment at a time."""

    def __init__(self, model: HybridModel, param: str, branch: Branch, s: PalcSettings,
                 bounds: tuple[float, float], detect: tuple[SpecialKind, ...], switch: bool,
                 progress: Callable[[int, float], None] | None):  # fmt: skip
        self.model, self.param, self.branch, self.s = model, param, branch, s
        self.par = model.parameter(param)
        self.nx = model.n_states
        self.bounds = {self.nx: bounds}
        self.detect, self.switch, self.progress = detect, switch, progress
        self.virtual = branch.virtual
        self.switched_smooth = False  # switched at a period-doubling or branch point (done once)
        self.segmented = False  # the segment in hand is solved by multiple shooting (orbits.segments)
        self.toward = 1.0  # the parameter's direction from the request's start to its stop

    # -- acceptance of a step -------------------------------------------------------------

    def check(self, prev: PalcPoint, cand: PalcPoint) -> tuple[str, str]:
        a, b = prev.payload, cand.payload
        if self.model.has_modes and b.switch_signature != a.switch_signature:
            return BOUNDARY, switch_change_reason(a, b)
        if not self.virtual and b.signature != a.signature:
            what = "loses" if sum(b.signature) < sum(a.signature) else "gains"
            if sum(b.signature) == sum(a.signature):
                what = "changes"
            return BOUNDARY, (
                f"the orbit {what} an impact (impacts per forcing period {list(a.signature)} -> "
                f"{list(b.signature)}): a grazing"
            )
        if self.segmented:  # (the segments ignore the stops: past a grazing they pass through one)
            if (
                b.impacts == 0
                and b.switch_states is not None
                and len(b.switch_times)
                and cuts_at_switches(self.model)
            ):  # (segments cut at switches: a crossing that slows to zero is a grazing of the surface)
                rates = switch_rates(b.model, b.switch_times, b.switch_states, b.switch_transitions)
                if min(rates) <= 0.0:
                    return BOUNDARY, "a switch's crossing speed reaches zero: a grazing of its surface"
            if b.impact_speeds.size and float(np.min(b.impact_speeds)) <= 0.0:
                return BOUNDARY, "an impact speed reaches zero (the orbit loses an impact): a grazing"
            crossed = [name for name in b.crossed_stops if name not in a.crossed_stops]
            if crossed:
                return BOUNDARY, (
                    f"the orbit passes through stop {crossed[0]!r} between its impacts (it gains an impact "
                    "there): a grazing"
                )
        if not self.virtual and b.section_clearance() < RESECTION_MARGIN:
            return STOP, RESECTION
        if a.unstable_count != b.unstable_count:
            return REFINE, "stability changes"
        return ACCEPT, ""

    def _layout(self, orbit: PeriodicOrbit) -> SegmentLayout | None:
        """The segments of ``orbit`` for multiple shooting, or None where it does not apply (a virtual
        branch, an orbit without impacts, a model without a forcing period)."""
        if self.virtual or not self.model.periodic:
            return None
        layout = layout_of(orbit)  # (its switches, on a model without resets: segments.cuts_at_switches)
        return layout if layout.impacts else None

    def _stalled_at_switches(self, palc: Palc, last: PeriodicOrbit) -> bool:
        """Did single shooting stall (its step fell below the minimum) on a model whose segments end on
        its switches, with a monodromy above ``MULTIPLE_SHOOTING_NORM``, where multiple shooting applies?"""
        return (
            palc.end is PalcEnd.STUCK
            and not self.segmented
            and cuts_at_switches(self.model)
            and float(np.linalg.norm(last.monodromy, 2)) > MULTIPLE_SHOOTING_NORM
            and self._layout(last) is not None
        )

    @staticmethod
    def margin(pt: PalcPoint) -> float:
        return grazing_margin(pt.payload).delta

    # -- special points between two points --------------------------------------------------

    def _special_between(
        self, evaluate, prev: PalcPoint, pt: PalcPoint, n: int, ip: int
    ) -> SpecialPoint | None:
        """Record the special points between ``prev`` and ``pt`` (``ip``: the parameter's index in their
        ``u``); the first where ``switch`` acts."""
        branch, index = self.branch, len(self.branch) - 1
        step = between(evaluate, prev, pt, self.s, ip)
        first: SpecialPoint | None = None
        for loc in step.located:
            if loc.kind not in self.detect:
                continue
            sp_ = self._special(loc, index)
            branch.special.append(sp_)
            if first is None and self.switch and not self.switched_smooth and loc.kind in SWITCH_KINDS:
                first = sp_
        if not step.explained:
            self._unlocated(prev, pt, step.describe())
        if SpecialKind.GRAZING in self.detect and self.virtual:  # the grazing of any stop
            for j in range(self.model.n_stops):
                found = _detect_grazing(evaluate, j, prev, pt, self.param, n, self.s)
                if found is not None:
                    branch.special.append(dataclasses.replace(found, index=index))
        return first

    def _special(self, loc: Located, index: int) -> SpecialPoint:
        tangent = loc.point.tangent
        if tangent is not None and tangent.size != self.nx + 1:
            tangent = _reduced(tangent, self.nx)
            tangent = tangent / np.linalg.norm(tangent)
        bracket, last = loc.point.bracket, loc.point.u.size - 1
        return SpecialPoint(
            kind=loc.kind, index=index, param=float(loc.point.u[-1]), orbit=loc.point.payload,
            tangent=tangent, turns=loc.turns,
            precision=bracket.precision(last) if bracket is not None else math.nan,
            interval=bracket.interval(last) if bracket is not None else None,
        )  # fmt: skip

    # -- one segment ------------------------------------------------------------------------

    def segment(self, start: SegmentStart) -> list[SegmentStart]:
        """Follow one segment from ``start``; the starts of the branches it switches to.

        Its status says where it went over to multiple shooting, if it did."""
        self.handover: float | None = None
        self.reorders: list[str] = []  # where two impacts changed order (multiple shooting)
        told = len(self.branch.segment_status)
        starts = self._segment(start)
        if len(self.branch.segment_status) > told:
            if self.handover is not None:
                self.branch.segment_status[told] += (
                    f"; by multiple shooting from {self.par.show(self.handover)} on "
                    "(single shooting stalled there)"
                )
            if self.reorders:
                self.branch.segment_status[told] += "; " + "; ".join(self.reorders)
        return starts

    def _segment(self, start: SegmentStart) -> list[SegmentStart]:
        """:meth:`segment` itself."""
        branch, s, nx = self.branch, self.s, self.nx
        seg = len(branch.segment_origin)
        branch.segment_origin.append(start.origin)
        orbit, sign, direction = start.orbit, start.sign, start.direction
        prev: PalcPoint | None = None
        segmented = False  # (multiple shooting, once single shooting has stalled short of a grazing)
        across: PalcPoint | None = None  # (the last point before two impacts changed order)
        while True:
            n = orbit.period
            layout = self._layout(orbit) if segmented else None
            self.segmented = layout is not None
            if layout is not None:  # (multiple shooting: a large monodromy, orbits.segments)
                evaluate = segmented_equations(self.model, self.param, n, orbit.t0, layout, orbit.stop)
                u0 = layout.pack(orbit, orbit.model.params[self.param])
            else:
                evaluate = branch_equations(
                    self.model, self.param, n, orbit.t0, self.virtual, orbit.stop, orbit.mode
                )
                u0 = np.append(orbit.state, orbit.model.params[self.param])
            ip = u0.size - 1  # (the parameter's index in u)
            try:
                F, DF, orb = evaluate(u0)
                if not is_isolated(orb.monodromy):
                    raise ConvergenceError(not_isolated_message(orb.monodromy, n))
            except GrazingError as exc:
                if seg == 0 and prev is None:
                    raise ConvergenceError(f"cannot start the continuation: {exc}") from None
                branch.end_segment(
                    BranchEnd.CANNOT_CONTINUE, f"cannot continue from {self.par.show(u0[-1])}: {exc}"
                )
                return []
            palc = Palc(
                evaluate, PalcPoint(u0, F, DF, orb), index=ip, sign=sign, bounds={ip: self.bounds[nx]},
                settings=dataclasses.replace(s, max_points=max(2, s.max_points - len(branch) + 1)),
                names={ip: self.param}, shows={ip: self.par.show}, check=self.check,
                margin=None if self.virtual or not any(self.model.transition_resets) else self.margin,
                direction=direction,
            )  # fmt: skip
            direction = None
            restarted = prev is not None and across is None  # the section moved: the same orbit
            for k, pt in enumerate(palc):
                if k == 0 and restarted:
                    prev = pt
                    continue
                switch_at = None
                if prev is not None and k == 0 and across is not None:
                    self._across_reordering(prev, pt)  # (another layout: the stability account alone)
                    across = None
                elif prev is not None:
                    switch_at = self._special_between(evaluate, prev, pt, n, ip)
                if prev is not None:
                    step = _reduced(pt.u, nx) - _reduced(prev.u, nx)
                    branch.arclength.append(branch.arclength[-1] + float(np.linalg.norm(step)))
                else:
                    branch.arclength.append(branch.arclength[-1] if branch.arclength else 0.0)
                branch.values.append(float(pt.u[-1]))
                branch.orbits.append(pt.payload)
                branch.segments.append(seg)
                prev = pt
                if self.progress is not None:
                    self.progress(len(branch), float(pt.u[-1]))
                if switch_at is not None:
                    starts = self._switch_smooth(switch_at, evaluate)
                    if starts:
                        return starts  # (else the point says why, and the branch goes on)
            status = palc.status
            assert prev is not None and prev.tangent is not None
            sign = math.copysign(1.0, prev.tangent[ip]) if prev.tangent[ip] != 0 else sign
            last: PeriodicOrbit = prev.payload
            if palc.end is PalcEnd.STOPPED and len(branch) < s.max_points:  # (check's STOP: RESECTION)
                try:
                    orbit = move_section(last, quiet_section(last))
                except GrazingError as exc:
                    status = f"{RESECTION} and the orbit could not be found on another section ({exc})"
                    branch.end_segment(BranchEnd.NO_SECTION, status)
                    return []
                continue
            if palc.boundary is None and self._stalled_at_switches(palc, last) and len(branch) < s.max_points:
                # A model without resets stalled by its monodromy alone (no grazing ahead): its segments
                # end on its switches (orbits.segments.cuts_at_switches), multiple shooting from here.
                segmented, orbit = True, last
                self.handover = float(prev.u[-1])
                continue
            if palc.boundary is None and self.segmented and palc.end is PalcEnd.STUCK:
                ended = self._stalled_at_contact(palc, prev, sign)
                if ended is not None:
                    return ended
            if palc.boundary is None:
                branch.end_segment(BranchEnd.of(palc.end), status)
                return []
            point = self._end_grazing(palc, prev)
            if (
                point is None
                and not palc.boundary.reached
                and layout is not None
                and len(branch) < s.max_points
            ):
                past = self._reorder(layout, orbit, prev, n)
                if past is not None:  # (two impacts changed order: the segments in the other order)
                    across, orbit = prev, past
                    continue
            if point is None and not palc.boundary.reached and not self.segmented:
                if self._layout(last) is not None and len(branch) < s.max_points:
                    # Single shooting stalled short of the grazing (its residual's rounding, |M| eps |x|,
                    # above its tolerance where the monodromy is large): multiple shooting from here.
                    segmented, orbit = True, last
                    self.handover = float(prev.u[-1])
                    continue
            return self._grazing_end(palc, prev, sign, point)

    def _reorder(
        self, layout: SegmentLayout, orbit: PeriodicOrbit, prev: PalcPoint, n: int
    ) -> PeriodicOrbit | None:
        """The orbit just past where two of ``prev``'s impacts on different stops change order, solved on
        the segments in the new order at a fixed parameter (None where no two impacts meet just ahead, or
        Newton's method fails there: then the branch ends as it stalled)."""
        assert prev.tangent is not None
        ahead = reordered(
            self.model, layout, orbit.t0, prev.u, prev.tangent, (self.param,), REORDER_REACH * self.s.ds_max
        )
        if ahead is None:
            return None
        evaluate = segmented_equations(self.model, self.param, n, orbit.t0, ahead.layout, orbit.stop)
        fixed = np.zeros(ahead.u.size)
        fixed[-1] = 1.0
        pt = correct(evaluate, ahead.u, fixed, self.s)
        if pt is None:
            return None
        past: PeriodicOrbit = pt.payload
        if past.crossed_stops or float(np.min(past.impact_speeds)) <= 0.0:
            return None
        names = self.model.stop_names
        a, b = layout.stops[ahead.first], layout.stops[ahead.first + 1]
        self.reorders.append(
            f"the impacts on {names[a]!r} and {names[b]!r} change order between "
            f"{self.par.show(float(prev.u[-1]))} and {self.par.show(float(pt.u[-1]))}"
        )
        return past

    def _across_reordering(self, before: PalcPoint, after: PalcPoint) -> None:
        """Two points on either side of a change of impact order (another layout, so no test function
        is compared across it): a change of stability between them is reported, unlocated."""
        if before.payload.unstable_count == after.payload.unstable_count:
            return
        self._unlocated(
            before, after, f"{before.payload.unstable_count} -> {after.payload.unstable_count} unstable "
            "multipliers, where two impacts change order",
        )  # fmt: skip

    def _unlocated(self, before: PalcPoint, after: PalcPoint, why: str) -> None:
        """Record an unlocated change of stability between two points of the branch, saying ``why``."""
        p1, p2 = float(before.u[-1]), float(after.u[-1])
        note = f"unlocated stability change between {self.par.show(p1)} and {self.par.show(p2)}: {why}"
        self.branch.special.append(
            SpecialPoint(
                kind=UNLOCATED, index=len(self.branch) - 1, param=0.5 * (p1 + p2), orbit=before.payload,
                note=note, between=(p1, p2), interval=(min(p1, p2), max(p1, p2)),
            )
        )  # fmt: skip

    # -- how a segment ends -----------------------------------------------------------------

    def _end_grazing(self, palc: Palc, prev: PalcPoint) -> GrazingPoint | None:
        """The grazing orbit at the boundary where ``palc`` stopped (None where none is located)."""
        boundary = palc.boundary
        assert boundary is not None
        beyond = boundary.after.payload if boundary.after is not None else None
        if self.segmented and cuts_at_switches(self.model):  # (segments cut at switches: the same switches)
            return self._segmented_grazing(prev.payload, beyond)
        if self.model.has_modes:  # (a grazing of a switching surface: the switches of mode differ)
            found = switch_change(prev.payload, beyond) if beyond is not None else None
            if found is None or found[1] >= self.model.n_stops or sliding_kind(prev.payload, beyond):
                return None  # (a sliding bifurcation: bisected in _grazing_end)
            grazed = grazed_transition(prev.payload, beyond)
            if grazed is None:
                return None
            return locate_switch_grazing(prev.payload, beyond, self.param, grazed, BETWEEN_SLACK)
        return _locate_grazing(prev.payload, beyond, self.param, self.virtual, boundary.ahead)

    def _segmented_grazing(self, last: PeriodicOrbit, beyond: PeriodicOrbit | None) -> GrazingPoint | None:
        """The grazing of a switching surface where ``last``'s briefest excursion shrinks to a contact,
        solved by multiple shooting (:func:`locate_segmented_grazing`): between ``last`` and ``beyond``
        (up to :data:`BETWEEN_SLACK`), or without ``beyond`` within :data:`NEAR_LAST` of ``last``."""
        p = last.model.params[self.param]
        scale = max(1.0, abs(p))
        q = beyond.model.params[self.param] if beyond is not None else p
        reach = abs(q - p) + (BETWEEN_SLACK if beyond is not None else NEAR_LAST) * scale
        point = locate_segmented_grazing(last, self.param, reach)
        if point is None or beyond is None:
            return point
        pg = point.model.params[self.param]
        return point if min(p, q) - BETWEEN_SLACK * scale <= pg <= max(p, q) + BETWEEN_SLACK * scale else None

    def _stalled_at_contact(self, palc: Palc, prev: PalcPoint, sign: float) -> list[SegmentStart] | None:
        """Multiple shooting on the switches stalled (``palc`` STUCK) where the orbit's briefest excursion
        through another mode shrinks to nothing (its two switches meet: the segmented equations are
        singular there): the segment ends at the grazing of that switching surface, located
        (:meth:`_segmented_grazing`), or, where it is not, with that grazing reported unlocated.  None
        where the last orbit has no excursion shorter than :data:`STALLED_EXCURSION` forcing periods (the
        branch ends as it stalled)."""
        last: PeriodicOrbit = prev.payload
        found = brief_excursion(last) if cuts_at_switches(self.model) else None
        if found is None or found[1] > STALLED_EXCURSION * last.model.period:
            return None
        i, stay = found
        names = self.model.stop_names
        into, back = (int(j) for j in last.switch_transitions[i : i + 2])
        reason = (
            f"the orbit's excursion through {names[into]!r} and back through {names[back]!r} shrinks to "
            "nothing (its two switches meet; multiple shooting stalls there): a grazing of a switching "
            "surface"
        )
        point = self._segmented_grazing(last, None)
        if point is not None:
            palc.boundary = Boundary(prev, None, reason)
            return self._grazing_end(palc, prev, sign, point)
        if self._double_grazing(last, i, reason):
            return []
        value = float(prev.u[-1])
        note = (
            f"grazing of transition {names[into]!r} not located: the grazing equations on the segments did "
            f"not converge from the last orbit, at {self.par.show(value)} (its excursion lasts {stay:.3g})"
        )
        self.branch.special.append(
            SpecialPoint(
                kind=SpecialKind.GRAZING, index=len(self.branch) - 1, param=value, orbit=last, stop=into,
                note=note,
            )
        )  # fmt: skip
        self.branch.end_segment(BranchEnd.GRAZING, f"ended at an unlocated grazing ({note}): {reason}")
        return []

    def _double_grazing(self, last: PeriodicOrbit, i: int, reason: str) -> bool:
        """Where ``last`` has a second excursion as brief as its briefest (switches ``i``, ``i + 1``),
        both shrinking to nothing at the same value of the parameter (:func:`extrapolated_grazing`, each
        to within :data:`DOUBLE_GRAZING_AGREE`): end the segment at that double grazing, located, and say
        True.  (One contact's equations on the segments cannot be solved with the other excursion
        shrinking to nothing as well: its segments are singular there too.)"""
        T = last.model.period
        others = [k for k, stay in excursions(last) if abs(k - i) >= 2 and stay <= STALLED_EXCURSION * T]
        if not others:
            return False
        branch, j = self.branch, others[0]
        values = [v for v, sg in zip(branch.values, branch.segments) if sg == branch.segments[-1]]
        orbits = branch.orbits[-len(values) :]
        a, b = extrapolated_grazing(orbits, values, i), extrapolated_grazing(orbits, values, j)
        if a is None or b is None:
            return False
        scale = max(1.0, abs(a[0]))
        precision = max(a[1], b[1], abs(a[0] - b[0]))
        if precision > DOUBLE_GRAZING_AGREE * scale:
            return False
        names = self.model.stop_names
        first, second = int(last.switch_transitions[i]), int(last.switch_transitions[j])
        value = 0.5 * (a[0] + b[0])
        note = (
            f"double grazing of transitions {names[first]!r} and {names[second]!r}, located by extrapolating "
            f"each excursion's time to zero over the branch's last points ({self.par.show(a[0])} and "
            f"{self.par.show(b[0])}, to +-{precision:.1g})"
        )
        branch.special.append(
            SpecialPoint(
                kind=SpecialKind.DOUBLE_GRAZING, index=len(branch) - 1, param=value, orbit=last, stop=first,
                precision=precision, note=note,
            )
        )  # fmt: skip
        branch.end_segment(
            BranchEnd.DOUBLE_GRAZING,
            f"ended at a double grazing at {self.par.show(value)} of transitions {names[first]!r} and "
            f"{names[second]!r}: {reason}; both excursions shrink to nothing together",
        )
        return True

    def _grazing_end(
        self, palc: Palc, prev: PalcPoint, sign: float, point: GrazingPoint | None
    ) -> list[SegmentStart]:
        """The segment ends at a grazing (bracketed, or ahead of a point beyond which Newton fails), with
        the grazing orbit ``point`` located there (:meth:`_end_grazing`; None: not located)."""
        branch, par = self.branch, self.par
        boundary = palc.boundary
        assert boundary is not None
        last: PeriodicOrbit = prev.payload
        if point is None and not boundary.reached:
            branch.end_segment(
                BranchEnd.of(palc.end), palc.status
            )  # the steps beyond jumped to another orbit
            return []
        value = point.model.params[self.param] if point is not None else float(prev.u[-1])
        after = boundary.after.payload if boundary.after is not None else None
        switched = switch_change(last, after) if after is not None and self.model.has_modes else None
        kind = sliding_kind(last, after) if switched is not None else None
        if kind is not None:
            assert after is not None and switched is not None
            return self._sliding_end(kind, last, after, switched[1], sign)
        if point is not None:
            where_stop = point.stop
        elif switched is not None:
            assert after is not None
            grazed = grazed_transition(last, after) if switched[1] < self.model.n_stops else None
            where_stop = switched[1] if grazed is None else grazed
        else:
            where_stop = grazing_margin(last).stop if point is None else point.stop
        p0 = float(prev.u[-1])
        p1 = float(boundary.after.u[-1]) if boundary.after is not None else value
        interval = (min(p0, p1), max(p0, p1)) if p1 != p0 else None
        precision = point.precision if point is not None else (p1 - p0 if interval else math.nan)
        graze = SpecialPoint(
            kind=SpecialKind.GRAZING, index=len(branch) - 1, param=value, orbit=last, grazing=point,
            stop=where_stop, precision=abs(precision), interval=interval,
        )  # fmt: skip
        where = par.show(value)
        if self.model.has_modes:
            where = f"{where} of transition {self.model.stop_names[where_stop]!r}"
        elif self.model.n_stops > 1:
            where = f"{where} with stop {self.model.stop_names[where_stop]!r}"
        if point is None and self.model.has_modes:
            where += (
                f" (bracketed only, between {par.show(prev.u[-1])} and the first orbit beyond it: the "
                "grazing equations did not converge)"
            )
        elif point is None:
            where += (
                f" (bracketed only: the grazing equations did not converge; last orbit at "
                f"{par.show(prev.u[-1])})"
            )
        reason = boundary.reason
        if not boundary.reached:
            what = grazing_margin(last).change or ""
            reason = f"an impact speed reaches zero: the orbit {what}"
            if what is ImpactChange.GAINS:
                reason = f"the orbit touches the stop between its impacts: it {what}"
            reason += " (located from this side: the branch does not continue beyond it)"
        status = f"ended at a grazing at {where}: {reason}"
        model = self.model  # (an impact: a transition with a reset; without modes every stop is one)
        impact = where_stop < model.n_stops and model.transition_resets[where_stop]
        sequence = "impact sequence" if impact else "switches of mode"
        other = "another impact sequence" if impact else "other switches of mode"
        if not self.switch:
            branch.special.append(graze)
            branch.end_segment(
                BranchEnd.GRAZING,
                status + f"; the orbit with the new {sequence} can be followed with switch (switch=True)",
            )
            return []
        new = new_sequence_orbit(last, self.param, value, sign, self.virtual)
        if new is None:
            branch.special.append(graze)
            branch.end_segment(
                BranchEnd.GRAZING,
                status + f"; no orbit with {other} was found just past it to switch to",
            )
            return []
        branch.special.append(dataclasses.replace(graze, switched=True))
        branch.end_segment(BranchEnd.SWITCHED, status + f"; switched to the orbit with the new {sequence}")
        if new.section_clearance() < SECTION_MARGIN:
            new = move_section(new, quiet_section(new))
        sign = math.copysign(1.0, new.model.params[self.param] - value)
        return [SegmentStart(orbit=new, sign=sign, origin=len(branch.special) - 1)]

    def _sliding_end(
        self, kind: SpecialKind, last: PeriodicOrbit, after: PeriodicOrbit, switch: int, sign: float
    ) -> list[SegmentStart]:
        """The segment ends at a sliding bifurcation of ``kind`` between ``last`` and ``after`` (the first
        orbit beyond), narrowed by bisection on the switches (:func:`bisect_switches`) and reported."""
        branch, par, name = self.branch, self.par, self.model.switch_names[switch]
        bracket = bisect_switches(last, after, self.param)
        kind = sliding_kind(bracket.before, bracket.after) or kind  # (the narrowest bracket tells best)
        lo, hi = bracket.interval(self.param)
        value = 0.5 * (lo + hi)
        # (whether an orbit sticks is decided from the far field's sign, to rounding: the boundary that the
        # bisection brackets lies within BOUNDARY_TOL of the exact one, not within its bracket)
        precision = max(0.5 * (hi - lo), BOUNDARY_TOL * max(1.0, abs(value)))
        point = SpecialPoint(
            kind=kind, index=len(branch) - 1, param=value, orbit=bracket.before, stop=switch,
            precision=precision, interval=(min(lo, value - precision), max(hi, value + precision)),
        )  # fmt: skip
        how = "located" if bracket.complete else "bracketed only"
        where = f"{par.show(value)} of {name!r} ({how} to +-{precision:.1g} by bisection on the switches)"
        article = "an" if str(kind)[0] in "aeiou" else "a"
        status = f"ended at {article} {kind} bifurcation at {where}: {switch_change_reason(last, after)}"
        status = status.replace(": a grazing of a switching surface", f": {article} {kind} bifurcation")
        if not self.switch:
            branch.special.append(point)
            branch.end_segment(
                BranchEnd.GRAZING,
                status + "; the orbit with the new switches of mode can be followed with switch "
                "(switch=True)",
            )
            return []
        new = new_sequence_orbit(bracket.before, self.param, value, sign, self.virtual)
        if new is None:
            branch.special.append(point)
            branch.end_segment(
                BranchEnd.GRAZING,
                status + "; no orbit with other switches of mode was found just past it to switch to",
            )
            return []
        branch.special.append(dataclasses.replace(point, switched=True))
        branch.end_segment(
            BranchEnd.SWITCHED, status + "; switched to the orbit with the new switches of mode"
        )
        if new.section_clearance() < SECTION_MARGIN:
            new = move_section(new, quiet_section(new))
        sign = math.copysign(1.0, new.model.params[self.param] - value)
        return [SegmentStart(orbit=new, sign=sign, origin=len(branch.special) - 1)]

    def _switch_smooth(self, at: SpecialPoint, evaluate) -> list[SegmentStart]:
        """The starts of the branches born at a period-doubling or branch point just passed; none (the
        point's note says why) if there is none to follow.  Only the first such point is tried."""
        branch, par = self.branch, self.par
        self.switched_smooth = True
        i = next(j for j in range(len(branch.special) - 1, -1, -1) if branch.special[j] is at)
        starts: list[SegmentStart] = []
        if at.kind == SpecialKind.PERIOD_DOUBLING:
            n2 = 2 * at.orbit.period
            found = doubled_start(at.orbit, self.param, self.s) if n2 <= MAX_PERIOD else None
            if found is not None:
                orbit, direction = found
                starts = [SegmentStart(orbit=orbit, sign=_sign_of(direction), direction=direction, origin=i)]
            why = f"periods above {MAX_PERIOD} are not switched to" if n2 > MAX_PERIOD else "none was found"
            missing = f"not switched to the period-{n2} orbit born here: {why}"
            what = f"the period-{n2} orbit born there"
        else:
            assert at.tangent is not None
            u_star = np.append(at.orbit.state, at.param)
            if self.segmented:  # (the branches through it are followed by single shooting first)
                o = at.orbit
                evaluate = branch_equations(
                    self.model, self.param, o.period, o.t0, self.virtual, o.stop, o.mode
                )
            for orbit, direction in crossing_starts(evaluate, u_star, at.tangent, self.s):
                starts.append(
                    SegmentStart(orbit=orbit, sign=_sign_of(direction), direction=direction, origin=i)
                )
            # first the direction of the request (the null vector's sign, and so their order, is arbitrary)
            starts.sort(key=lambda st: st.sign != self.toward)
            missing = "not switched: no other branch was found through it"
            what = "the other branch through it" + (" (both directions)" if len(starts) == 2 else "")
        if not starts:
            branch.special[i] = dataclasses.replace(at, note=missing)
            return []
        branch.special[i] = dataclasses.replace(at, switched=True)
        branch.end_segment(BranchEnd.SWITCHED, f"switched at the {at.kind} at {par.show(at.param)} to {what}")
        return starts


def continue_orbit(
    model: HybridModel,
    param: str,
    start: float,
    stop: float,
    *,
    orbit: PeriodicOrbit | None = None,
    x0: np.ndarray | None = None,
    period: int | None = None,
    t0: float | None = None,
    virtual: bool | None = None,
    settings: PalcSettings | None = None,
    detect: tuple[SpecialKind | str, ...] = SPECIAL_KINDS,
    switch: bool = False,
    progress: Callable[[int, float], None] | None = None,
    stop_name: int | str | None = None,
    mode: str | None = None,
) -> Branch:
    """Follow a periodic orbit as ``param`` goes from ``start`` towards ``stop``.

    Parameters
    ----------
    model
        Model with the other parameters set.
    param
        Name of the parameter to vary.
    start, stop
        The branch starts at ``param = start`` and ends when it reaches
        ``stop`` (it may turn back at folds before; the continuation follows
        the curve through them).  Both must lie in the parameter's interval.
    orbit, x0, period
        Starting orbit, or a guess for it (see :func:`find_orbit`).
    t0
        Section time for the starting orbit's guess ``x0``; ``None`` (default):
        0, moved away from impacts as described in the module docstring.
    virtual
        Ignore the stop (default: True when the starting orbit has no
        impacts, so nonimpacting orbits are followed through grazing, which is
        located and reported; False with ``switch``, which only a physical
        branch uses).
    settings
        Step control (:class:`~grazing.orbits.palc.PalcSettings`).
    detect
        Special points to report (any of ``SPECIAL_KINDS``).  Every kind is
        located wherever it explains a stability change; a change that no
        located point explains is always reported, as :data:`UNLOCATED`.
    stop_name
        For models with several stops: the stop (name or index; default the
        starting orbit's, else the first) whose grazing a nonimpacting branch
        looks for first.  A nonimpacting branch reports the grazings of every
        stop; an impacting branch ends where it loses or gains an impact on
        any stop, at that stop's grazing.
    switch
        Switch branches, each switch starting a new segment: at every grazing
        where the impact sequence changes, onto the orbit with the new
        sequence; at the first period-doubling or branch point met (of the
        kinds in ``detect``), onto the period-``2n`` orbit born there or along
        the other branch through it, both ways.  Segments are followed while
        points remain (``settings.max_points`` in all).  A virtual branch has
        no grazing where its impact sequence changes: ``switch`` with
        ``virtual=True`` (or a virtual starting ``orbit``) raises
        :class:`~grazing.errors.InvalidParameterError`.
    progress
        Called as ``progress(points, param_value)`` after each point.
    mode
        A model with modes: the mode of ``x0`` (see :func:`find_orbit`).  Each
        point's orbit records its mode on the section and its switches of mode;
        where their number or order changes along the branch (a grazing of a
        switching surface), the segment ends there as at a change of impacts,
        the grazing located, and with ``switch`` goes on along the orbit with
        the new switches.  Branches of models with modes are physical
        (``virtual=True`` is refused); on a model without resets a strongly
        unstable branch goes on by multiple shooting cut at its switches, and
        ends where an excursion through another mode shrinks to nothing, at
        that grazing solved on the segments
        (:mod:`grazing.orbits.segmented_grazing`).

    Returns
    -------
    Branch

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> br = continue_orbit(m, "eta", 0.40, 0.47)
    >>> [s.kind for s in br.special]
    ['grazing']
    >>> round(br.special[0].param, 6)
    0.445121
    """
    s = settings or PalcSettings()
    for kind in detect:
        if kind not in SPECIAL_KINDS:
            raise InvalidParameterError(f"unknown special point {kind!r} (known: {', '.join(SPECIAL_KINDS)})")
    if param not in model.params:
        raise InvalidParameterError(f"unknown parameter {param!r} (known: {', '.join(model.params)})")
    for name, val in (("start", start), ("stop", stop)):
        if not math.isfinite(val):
            raise InvalidParameterError(f"{name} must be finite, got {val}")
    if start == stop:
        raise InvalidParameterError("start and stop must differ")
    m0 = model.with_params(**{param: start})
    model.with_params(**{param: stop})  # the end of the range must be a valid value too
    if switch and (virtual or (virtual is None and orbit is not None and orbit.virtual)):
        raise InvalidParameterError(
            "switch has no effect on a virtual branch: it ignores the stops, so its impact sequence never "
            "changes (it is followed through its grazings, which are located); continue the physical "
            "orbit (virtual=False) to switch at its grazings, period-doublings and branch points"
        )
    if switch and virtual is None:
        virtual = False  # a nonimpacting orbit too: followed up to its grazing, then switched
    if model.has_modes and not (virtual or (orbit is not None and orbit.virtual)):
        virtual = False  # (its switches of mode end it where they change, as impacts do)
    watch = model.stop_index(
        stop_name if stop_name is not None else (orbit.stop if orbit is not None else None)
    )
    if orbit is None:
        if virtual is None:
            probe = find_orbit(
                m0, x0, period=period, t0=0.0 if t0 is None else t0, stop_name=watch, mode=mode
            )
            virtual = probe.impacts == 0
            orbit = (
                probe
                if not virtual
                else find_orbit(
                    m0, probe.state, period=probe.period, t0=probe.t0, virtual=True, stop_name=watch
                )
            )
        else:
            orbit = find_orbit(
                m0, x0, period=period, t0=0.0 if t0 is None else t0, virtual=virtual, stop_name=watch,
                mode=mode,
            )  # fmt: skip
        if t0 is None and orbit.section_clearance() < SECTION_MARGIN:
            orbit = move_section(orbit, quiet_section(orbit))
    elif virtual is None:
        virtual = orbit.virtual
    branch = Branch(model=model, param=param, period=orbit.period, virtual=bool(virtual))
    run = _Continuation(
        model,
        param,
        branch,
        s,
        (min(start, stop), max(start, stop)),
        tuple(SpecialKind(k) for k in detect),
        switch,
        progress,
    )
    run.toward = math.copysign(1.0, stop - start)
    pending = [SegmentStart(orbit=orbit, sign=run.toward)]  # (a stack: each chain to its end first)
    while pending:
        if len(branch) >= s.max_points:
            left = len(pending)
            branch.segment_status[-1] += (
                f"; {left} branch{'es' * (left > 1)} switched to not followed: maximum number of points "
                "reached"
            )
            break
        pending.extend(reversed(run.segment(pending.pop())))
    branch.status = branch.segment_status[-1]
    branch.outcome = branch.segment_outcome[-1]
    return branch
