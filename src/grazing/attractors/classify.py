"""Which attractor each end state is on: classification, and end states recognised as one attractor.

Each initial state is run for a transient, then sampled at the forcing phase
(a sweep point of :mod:`grazing.sweeps`); its end state is

- **failed** (the run failed: step limit, accumulating impacts) or
  **escaping** (its samples leave a bound around the grid, or it overflowed);
- **periodic** (its samples repeat with a period ``p <= 64``, or they
  contract towards a cycle and Newton's method from its last sample
  converges to a stable orbit they approach: :mod:`grazing.sweeps.polish`):
  on the orbit made of its last ``p`` samples (or Newton's orbit).  Two end states are on one orbit when each
  point of one is within :data:`~grazing.core.options.MATCH_TOL` cells of a
  point of the other (whatever point of the cycle each ended at: a distance
  between point sets, as Attractors.jl matches attractors) and, on a model
  with modes, in the same mode there: an orbit is its points and the mode at
  each (a hysteretic switch puts one state in two modes' regions; each mode
  has its own future).  The modes of a new orbit come from one run of it
  from its end state (:meth:`Catalogue.cycle_modes`); its period is that of
  its states and modes together (samples that repeat every period, their
  modes every second one: period 2);  An orbit whose
  points all lie on a stop, without impacts, is **sticking** (riding on it);
  one whose multiplier 1 is double (a Jordan block: the impact damper's
  free particle at rest, periodic only because its velocity is exactly
  zero) is **neutral**: not an isolated attractor, a family of motions
  that a slice of state space can hit;
- aperiodic: its samples are recorded on a grid of cells (the cell grid of
  Attractors.jl's recurrences); end states whose samples share a cell, or
  come within one recurrence cell (:data:`~grazing.core.options.CELL_FRACTION`
  of the attractor's own extent per component, at least the grid's cell)
  are on one attractor, which is **chaotic** (the median largest Lyapunov
  exponent of its end states above
  :data:`~grazing.core.options.CHAOS_THRESHOLD`), **quasiperiodic** (within
  it of zero) or **aperiodic** (no exponent: the motion sticks, or it is
  still settling).

:class:`Catalogue` takes the results chunk by chunk, in order (so that the
attractors and their ids do not depend on which chunk finished first), and
keeps only one label per initial state and each attractor's summary: memory
does not grow with the samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from grazing.attractors.kinds import AttractorKind
from grazing.core.cells import group_by_cells
from grazing.core.model import ON_STOP_TOL, HybridModel
from grazing.core.options import (
    BASIN_ADAPTIVE_TOL,
    CELL_FRACTION,
    CHAOS_THRESHOLD,
    CLOSING_RATIO,
    MATCH_TOL,
    MAX_PERIOD,
    PERIOD_TOL,
    POLISH_TRIES,
)
from grazing.core.period import orbit_impacts, sample_scale
from grazing.core.solution import Status
from grazing.errors import GrazingError
from grazing.sweeps.polish import Polished, contracting_periods, is_neutral, polish, run_mode
from grazing.sweeps.spec import ChunkResult
from grazing.sweeps.status import reason

KINDS = tuple(AttractorKind)
"""What an initial state can end on (``invalid``: beyond a stop, not run): the
:class:`~grazing.attractors.kinds.AttractorKind` members, which are the words ``--json`` prints."""

MAX_POINTS = 2000
"""Most sampled points kept of an aperiodic attractor (the first end states' samples)."""

MAX_EXPONENTS = 4096
"""Most Lyapunov exponents of an aperiodic attractor's end states kept for its median."""

RIDING_TOL = 1e3 * ON_STOP_TOL
"""A motion without impacts rides on a stop when each of its sampled points is on one to this (relative
to ``max(1, |x|)``): a thousand times the rounding of a state put on the stop (``ON_STOP_TOL``), for a
sample taken while sticking is on the stop to the integrator's accuracy, not to rounding alone."""

INVALID = 0
"""The label of an initial state beyond a stop (not run); attractors are numbered from 1."""


@dataclass(kw_only=True)
class Attractor:
    """An attractor (or an outcome: escaping, failed, invalid) and the initial states that end on it.

    Attributes
    ----------
    id
        Its label (1, 2, ... in the order of the first initial state on it; 0: invalid).
    kind
        One of :data:`KINDS` (an :class:`~grazing.attractors.kinds.AttractorKind`: a string equal to the
        ``kind`` that ``--json`` and the datasets write).
    period
        Period in forcing periods (0: aperiodic; -1: an outcome without one).
    impacts_per_period
        Impacts per period of the orbit (per forcing period when aperiodic; nan for an outcome).
    lyapunov
        Largest Lyapunov exponent per unit time (the median over its end states; nan: not computed).
    points
        States on it at the sampling phase: the orbit's points, or sampled points of an aperiodic one.
    reason
        Why, for a failed or escaping outcome (``"step limit"``, ``"non-finite state"``, ``"left the
        bound"``, ``"beyond a stop"``); else ``""``.
    count
        Initial states ending on it.
    fraction
        ``count`` over all initial states.
    first
        The index of its first initial state.
    modes
        A model with modes: the mode of each of ``points`` (a periodic orbit's; empty where not known: an
        aperiodic attractor, an outcome, a model without modes).

    Examples
    --------
    The ball on a vibrating table: from three initial states, one beyond the
    table (``invalid``, id 0), one that comes to rest on it (``sticking``) and
    one on the period-1 orbit with one impact a period:

    >>> import grazing
    >>> from grazing.attractors import find_attractors
    >>> ball = grazing.models.bouncing_ball(amplitude=0.8, r=0.8)
    >>> found = find_attractors(ball, [[0.0, 0.8], [3.6, -2.0], [-1.0, 0.0]], workers=1)
    >>> [(a.id, a.kind, a.period, a.count, a.reason) for a in found.attractors]
    [(0, 'invalid', -1, 1, 'beyond a stop'), (1, 'sticking', 1, 1, ''), (2, 'periodic', 1, 1, '')]
    >>> a = found.attractor(2)
    >>> a.impacts_per_period, a.points.shape, a.first
    (1.0, (1, 2), 1)
    """

    id: int
    kind: AttractorKind
    period: int
    impacts_per_period: float
    lyapunov: float
    points: np.ndarray
    reason: str = ""
    count: int = 0
    fraction: float = 0.0
    first: int = 0
    modes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        self.kind = AttractorKind(self.kind)  # (given as its word: the member)

    @property
    def mode(self) -> str:
        """The one mode of all its points (an absorbing mode such as the rocking block's ``overturned``
        names the outcome); ``""`` where they are in several modes or not known."""
        return self.modes[0] if self.modes and len(set(self.modes)) == 1 else ""

    def to_json(self) -> dict[str, Any]:
        """The attractor as plain JSON data (``id``, ``kind``, ``period``, ``points``, ``lyapunov`` ...;
        ``modes``: the mode at each point, null where not known)."""
        return {
            "id": self.id,
            "kind": str(self.kind),
            "period": self.period if self.period >= 0 else None,
            "impacts_per_period": _finite(self.impacts_per_period),
            "points": self.points.tolist(),
            "lyapunov": _finite(self.lyapunov),
            "reason": self.reason or None,
            "count": self.count,
            "fraction": self.fraction,
            "modes": list(self.modes) or None,
        }


def _finite(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


@dataclass
class _Entry:
    """An attractor being collected (possibly merged into another: see :attr:`Catalogue.parent`)."""

    family: AttractorKind  # PERIODIC, APERIODIC, ESCAPING or FAILED (its kind: Catalogue._kind)
    first: int
    period: int = -1
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    impacts: float = math.nan
    exponents: list[float] = field(default_factory=list)  # (an orbit's: set by basins._orbit_exponents)
    count: int = 0
    reason: str = ""
    cells: set[bytes] = field(default_factory=set)
    failures: int = 0  # (failed Newton polishes of its end states)
    neutral: bool = False  # (a periodic orbit whose multiplier 1 is double)
    modes: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # (at each point; empty:
    # not known)

    def __post_init__(self) -> None:
        self.family = AttractorKind(self.family)


class Catalogue:
    """The attractors found so far, and the label of every initial state given to it.

    Parameters
    ----------
    model
        The model (its stops decide what is sticking).
    n_points
        Initial states in all (indices ``0 .. n_points - 1``).
    cell
        Size of a cell in each state component (aperiodic attractors are sets
        of cells; periodic orbits match to ``MATCH_TOL`` cells).
    origin
        A corner of the cell grid.
    escape
        A state farther than this (in every component's largest difference)
        from ``origin`` has escaped.
    periods
        Sampled periods of each end state (impacts per period from the counts).
    t_sample
        The time of the samples within a forcing period (for the stops' guards).
    cell_fraction
        Aperiodic end states whose samples come within one recurrence cell of
        an attractor's points are on it: the cell is this fraction of the
        extent of their joint points per component, at least ``cell`` (0:
        only shared cells of the grid count).
    polish
        Polish the aperiodic end states whose samples contract towards a
        cycle by Newton's method (:func:`grazing.sweeps.polish.polish`), at
        most :data:`~grazing.core.options.POLISH_TRIES` failed ones per
        attractor.
    """

    def __init__(
        self,
        model: HybridModel,
        n_points: int,
        cell: np.ndarray,
        origin: np.ndarray,
        escape: float,
        periods: int,
        t_sample: float,
        cell_fraction: float = CELL_FRACTION,
        polish: bool = True,
    ) -> None:
        self.model = model
        self.cell = np.asarray(cell, dtype=float)
        self.origin = np.asarray(origin, dtype=float)
        self.escape = float(escape)
        self.periods = int(periods)
        self.t_sample = float(t_sample)
        self.labels = np.full(
            n_points, -1, dtype=np.int64
        )  # entry of each initial state (-1: invalid/not yet)
        self.entries: list[_Entry] = []
        self.parent: list[int] = []
        self._by_period: dict[int, list[int]] = {}
        self._outcome: dict[tuple[AttractorKind, str], int] = {}
        self._owner: dict[bytes, int] = {}
        self.cell_fraction = float(cell_fraction)
        self.polish = bool(polish)
        self.polished = 0  # (end states labelled periodic by a Newton polish)
        self._trees: dict[int, tuple[int, np.ndarray, Any]] = {}
        self._aperiodic: list[int] = []

    # ------------------------------------------------------------------ entries

    def _new(self, entry: _Entry) -> int:
        self.entries.append(entry)
        self.parent.append(len(self.parent))
        return len(self.entries) - 1

    def root(self, k: int) -> int:
        """The entry ``k`` is merged into."""
        while self.parent[k] != k:
            self.parent[k] = self.parent[self.parent[k]]
            k = self.parent[k]
        return k

    def _union(self, a: int, b: int) -> int:
        a, b = self.root(a), self.root(b)
        if a == b:
            return a
        keep, gone = (a, b) if self.entries[a].first <= self.entries[b].first else (b, a)
        self.parent[gone] = keep
        e, g = self.entries[keep], self.entries[gone]
        e.count += g.count
        e.exponents = (e.exponents + g.exponents)[:MAX_EXPONENTS]
        e.failures += g.failures
        if len(e.points) < MAX_POINTS and len(g.points):
            e.points = np.concatenate([e.points, g.points[: MAX_POINTS - len(e.points)]])
        e.cells |= g.cells
        self._trees.pop(gone, None)
        for key in g.cells:
            self._owner[key] = keep
        g.cells = set()
        return keep

    # ------------------------------------------------------------------ adding end states

    def add(
        self,
        first: int,
        res: ChunkResult,
        which: np.ndarray | None = None,
        defer: bool = False,
        hold: bool = False,
    ) -> np.ndarray:
        """Classify the end states of ``res`` (initial states ``first + k``, or ``which[k]``) and label them.

        With ``defer``, the aperiodic ones are not labelled: their positions in
        ``res`` are returned, to be continued (:func:`grazing.attractors.basins`
        runs them further before deciding); else an empty array.  So are, with
        ``defer``, the periodic ones that have not settled (:func:`unsettled`):
        an orbit slow to converge, sampled on its way, repeats to the period
        detector's tolerance with a spurious period (a period-1 orbit whose
        samples spiral in looked like period 7, 2 or 9 after 200 periods).
        Without ``defer`` (the last look), an end state closing in on a shorter
        period (:func:`closing_period`) within a match of it has that period;
        beyond a match, with ``hold``, it is not labelled either but returned
        to be run on (else it keeps the period it repeats with).
        """
        index = first + np.arange(res.status.size) if which is None else np.asarray(which)
        status = np.asarray(res.status, dtype=int)
        ended = np.full(status.size, -1, dtype=np.int64)  # (the mode of each last sample; -1: not known)
        if self.model.has_modes and res.mode_final is not None:
            ended = np.asarray(res.mode_final, dtype=np.int64)
        samples = np.asarray(res.samples, dtype=float)
        period = np.array(res.period, dtype=int)
        ok = status == Status.OK
        far = np.zeros(status.size, dtype=bool)
        if ok.any():
            dist = np.max(np.abs(samples[ok] - self.origin), axis=(1, 2))
            far[ok] = ~(dist <= self.escape)
        for k in np.flatnonzero(~ok | far):
            if far[k]:
                self._outcome_label(int(index[k]), AttractorKind.ESCAPING, "left the bound")
            elif status[k] == Status.NONFINITE:
                self._outcome_label(int(index[k]), AttractorKind.ESCAPING, reason(int(status[k])))
            else:
                self._outcome_label(int(index[k]), AttractorKind.FAILED, reason(int(status[k])))
        settled = ok & ~far
        slow = unsettled(samples, period) & settled if defer else np.zeros(status.size, dtype=bool)
        if not defer:  # (the last look: an orbit closing in on a shorter period, within a match, has it)
            for k in np.flatnonzero(settled & (period > 0)):
                d, off = closing_period(samples[k], int(period[k]))
                if off <= MATCH_TOL * float(np.min(self.cell)):
                    period[k] = d
                elif hold:  # (beyond a match of it: run on)
                    slow[k] = True
        self._add_periodic(index, res, period, np.flatnonzero(settled & (period > 0) & ~slow), ended)
        aperiodic = np.flatnonzero(settled & (period <= 0))
        if defer:
            return np.union1d(aperiodic, np.flatnonzero(slow))
        self._add_aperiodic(index, res, aperiodic, ended)
        return np.flatnonzero(slow)

    def _outcome_label(self, i: int, family: AttractorKind, why: str) -> None:
        key = (family, why)
        if key not in self._outcome:
            self._outcome[key] = self._new(_Entry(family, i, reason=why))
        k = self._outcome[key]
        self.entries[k].count += 1
        self.labels[i] = k

    def _add_periodic(
        self, index: np.ndarray, res: ChunkResult, period: np.ndarray, rows: np.ndarray, ended: np.ndarray
    ) -> None:
        """Label the periodic end states ``rows`` of ``res`` (their last samples in modes ``ended``)."""
        if rows.size == 0:
            return
        tol = MATCH_TOL * self.cell
        for p in np.unique(period[rows]):
            sel = rows[period[rows] == p]
            cyc = np.asarray(res.samples, dtype=float)[sel, -p:, :]  # (states, p, n): the orbit's points
            start = np.argmin(cyc[:, :, 0], axis=1)  # (each cycle from its point of least first component)
            turn = (start[:, None] + np.arange(p)[None, :]) % p
            cyc = cyc[np.arange(sel.size)[:, None], turn]
            keys = np.floor((cyc[:, 0, :] - self.origin) / tol).astype(np.int64)
            last = (p - 1 - start) % p  # (where the last sample, whose mode is known, is in each cycle)
            if self.model.has_modes:  # (one state in two modes: two orbits)
                keys = np.column_stack([keys, last, ended[sel]])
            uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
            inverse = inverse.ravel()
            for g in range(uniq.shape[0]):
                members = np.flatnonzero(inverse == g)
                rep = members[0]
                row = int(sel[rep])
                impacts = float(orbit_impacts(np.array([res.impacts[row]]), np.array([p]), self.periods)[0])
                at = (int(last[rep]), int(ended[row]))
                k = self._periodic_entry(int(p), cyc[rep], int(index[row]), impacts, at)
                e = self.entries[k]
                e.count += members.size
                self.labels[index[sel[members]]] = k

    def _add_polished(self, i: int, found: Polished, mode: int = -1) -> None:
        """Label initial state ``i`` with the periodic orbit its end state (its last sample in mode
        ``mode``) was polished to."""
        start = int(np.argmin(found.cycle[:, 0]))
        cyc = np.roll(found.cycle, -start, axis=0)
        at = ((found.period - 1 - start) % found.period, int(mode))  # (the cycle's last: that sample's)
        k = self._periodic_entry(found.period, cyc, i, float(found.impacts), at)
        self.entries[k].count += 1
        self.labels[i] = k
        self.polished += 1

    def _periodic_entry(
        self, p: int, points: np.ndarray, first: int, impacts: float, at: tuple[int, int] = (0, -1)
    ) -> int:
        """The entry of the orbit whose samples repeat with period ``p`` through ``points``, in mode
        ``at[1]`` at ``points[at[0]]`` (a model with modes; -1: not known, any mode matches); a new one
        if none found so far is it."""
        for k in self._by_period.get(p, []):
            k = self.root(k)
            e = self.entries[k]
            near = set_distance(e.points, points, self.cell) <= MATCH_TOL or same_points(e.points, points)
            if near and self._in_mode(e, points[at[0]], at[1]):
                return k
        modes = self.cycle_modes(points, *at)
        times = max(1, modes.size // p)  # (its modes repeat every ``times`` periods of its states)
        entry = _Entry(AttractorKind.PERIODIC, first, period=p * times, points=np.tile(points, (times, 1)),
                       impacts=impacts * times, modes=modes)  # fmt: skip
        k = self._new(entry)
        self._by_period.setdefault(p, []).append(k)
        return k

    def _in_mode(self, e: _Entry, point: np.ndarray, mode: int) -> bool:
        """Is ``point`` in mode ``mode`` a point of the orbit ``e`` (its nearest points' modes; true where
        either mode is not known)?"""
        if mode < 0 or e.modes.size != len(e.points):
            return True
        d = np.max(np.abs(e.points - point) / self.cell, axis=1)
        return bool(np.any(e.modes[d <= d.min() + MATCH_TOL] == mode))

    def cycle_modes(self, points: np.ndarray, at: int, mode: int) -> np.ndarray:
        """The mode at each point of the orbit whose samples repeat with ``points`` (the cycle of a period
        ``p``), one run from ``points[at]`` in mode ``mode`` telling them; empty where not known (a model
        without modes, ``mode`` -1, or the run fails).

        The run goes on for up to as many cycles as the model has modes, until the mode at ``points[at]``
        comes back: its modes may repeat every ``q`` cycles only (the result then has ``q p`` entries, for
        the points repeated ``q`` times).

        Examples
        --------
        >>> import grazing
        >>> m = grazing.models.soft_impact_oscillator(gap=0.5, a=0.1, omega=1.2)
        >>> cat = Catalogue(m, 1, np.full(2, 0.01), np.zeros(2), 1e3, 50, 0.0)
        >>> run = grazing.simulate(m, [0.0, 0.0], transient=300, periods=1)
        >>> cat.cycle_modes(run.samples, 0, 0).tolist(), cat.cycle_modes(run.samples, 0, -1).tolist()
        ([0], [])
        """
        from grazing.engine.simulate import simulate

        none = np.zeros(0, dtype=np.int64)
        if not self.model.has_modes or mode < 0:
            return none
        p = len(points)
        n_modes = len(self.model.mode_names)
        phase = 2 * math.pi * (self.t_sample / float(self.model.period) % 1.0)
        start = run_mode(self.model, mode, points[at], self.t_sample)
        try:
            sol = simulate(self.model, points[at], t0=self.t_sample, transient=0, periods=p * n_modes,
                           phase=phase, mode=start)  # fmt: skip
        except (GrazingError, ArithmeticError):
            return none
        seen = np.concatenate([[mode], np.asarray(sol.modes, dtype=np.int64)])  # (at points[at + j])
        if seen.size < p * n_modes + 1:
            return none
        q = next((c for c in range(1, n_modes + 1) if seen[c * p] == mode), 1)
        out = np.empty(q * p, dtype=np.int64)
        out[(at + np.arange(q * p)) % (q * p)] = seen[: q * p]
        return out

    def _add_aperiodic(
        self, index: np.ndarray, res: ChunkResult, rows: np.ndarray, ended: np.ndarray
    ) -> None:
        """Aperiodic end states: those whose samples contract towards a stable orbit polished onto it; the
        others grouped when their samples share a cell, then merged with the attractors found before
        that share one or come within a recurrence cell of them."""
        if rows.size == 0:
            return
        samples = np.asarray(res.samples, dtype=float)[rows]  # (states, periods, n)
        m, P, n = samples.shape
        owner = np.repeat(np.arange(m), P)
        groups = group_by_cells(samples.reshape(-1, n), owner, m, self.origin, self.cell)
        lyap = np.asarray(res.lyapunov, dtype=float)[rows]
        impacts = np.asarray(res.impacts, dtype=float)[rows] / self.periods
        for c in np.unique(groups.group):
            members = np.flatnonzero(groups.group == c)
            fails = 0
            if self.polish:
                targets = self._targets(groups.cells_of(owner, members), samples[members].reshape(-1, n))
                left, fails = self._polish_members(index[rows], samples, members, targets, ended[rows])
                if left.size == 0:
                    continue
                members = left
            cells = groups.cells_of(owner, members)
            first = int(index[rows[members[0]]])
            pts = samples[members].reshape(-1, n)[:MAX_POINTS]
            owners = self._targets(cells, pts)
            mean_impacts = float(np.mean(impacts[members]))
            k = self._new(
                _Entry(AttractorKind.APERIODIC, first, period=0, points=pts.copy(), impacts=mean_impacts)
            )
            e = self.entries[k]
            e.count = members.size
            e.exponents = [float(v) for v in lyap[members][:MAX_EXPONENTS]]
            e.cells = cells
            e.failures = fails
            self._aperiodic.append(k)
            for key in cells:
                self._owner[key] = k
            for o in sorted(owners):
                k = self._union(k, o)
            self.labels[index[rows[members]]] = k

    def _targets(self, cells: set[bytes], points: np.ndarray) -> set[int]:
        """The aperiodic attractors found so far that end states with samples ``points`` (in ``cells``)
        are on: sharing a cell, or within a recurrence cell (:meth:`_recurrent`)."""
        owners = {self.root(self._owner[key]) for key in cells if key in self._owner}
        return owners | self._recurrent(points)

    def _polish_members(
        self,
        index: np.ndarray,
        samples: np.ndarray,
        members: np.ndarray,
        targets: set[int],
        ended: np.ndarray,
    ) -> tuple[np.ndarray, int]:
        """Polish the end states ``members`` (rows of ``samples``, initial states ``index``, ended in
        ``modes``: None, not known) that contract
        towards a cycle; label those on a stable orbit.  The others, and the failed attempts (at most
        :data:`~grazing.core.options.POLISH_TRIES` on the attractors ``targets`` they are on, more as
        long as attempts succeed), are returned."""
        budget = POLISH_TRIES - sum(self.entries[self.root(r)].failures for r in targets)
        left, fails = [], 0
        for j in members:
            if budget <= 0:
                left.append(j)
                continue
            candidates = contracting_periods(samples[j], MAX_PERIOD)
            if not candidates:
                left.append(j)
                continue
            mode = run_mode(self.model, int(ended[j]), samples[j, -1], self.t_sample)
            found = polish(self.model, samples[j], self.t_sample, candidates=candidates, mode=mode)
            if found is None:
                left.append(j)
                fails += 1
                budget -= 1
                continue
            budget += 1
            self._add_polished(int(index[j]), found, int(ended[j]))
        return np.asarray(left, dtype=np.int64), fails

    def _recurrent(self, points: np.ndarray) -> set[int]:
        """The aperiodic attractors found so far within one recurrence cell of ``points``: a point of one
        within a cell of the other's, the recurrence cell of a point set being ``cell_fraction`` of its
        extent per component (at least the grid's cell)."""
        from scipy.spatial import cKDTree

        if self.cell_fraction <= 0 or points.size == 0:
            return set()
        roots = sorted({self.root(k) for k in self._aperiodic})
        roots = [
            r
            for r in roots
            if self.entries[r].family is AttractorKind.APERIODIC and len(self.entries[r].points)
        ]
        if not roots:
            return set()
        pts = points[:MAX_POINTS]
        mine = self.recurrence_cell(pts)
        tree = cKDTree(pts / mine)
        out = set()

        def near(t: Any, q: np.ndarray) -> bool:
            return bool(np.isfinite(t.query(q, p=np.inf, distance_upper_bound=1.0)[0]).any())

        for r in roots:
            rtree, rcell = self._tree(r)
            if near(rtree, pts / rcell) or near(tree, self.entries[r].points / mine):
                out.add(r)
        return out

    def _tree(self, r: int) -> tuple[Any, np.ndarray]:
        """A k-d tree of attractor ``r``'s points in its recurrence cells, and that cell (kept while its
        points do not change)."""
        from scipy.spatial import cKDTree

        pts = self.entries[r].points
        kept = self._trees.get(r)
        if kept is None or kept[0] != len(pts):
            cell = self.recurrence_cell(pts)
            kept = (len(pts), cell, cKDTree(pts / cell))
            self._trees[r] = kept
        return kept[2], kept[1]

    def recurrence_cell(self, points: np.ndarray) -> np.ndarray:
        """The recurrence cell of a point set: ``cell_fraction`` of its extent per component, at least the
        grid's cell.

        Examples
        --------
        >>> import grazing
        >>> cat = Catalogue(grazing.models.bouncing_ball(), 1, np.full(2, 0.01), np.zeros(2), 1e3, 50, 0.0)
        >>> cat.recurrence_cell(np.array([[0.0, 0.0], [4.0, 0.1]])).tolist()
        [0.2, 0.01]
        """
        span = np.ptp(np.asarray(points, dtype=float), axis=0)
        return np.maximum(self.cell, self.cell_fraction * span)

    # ------------------------------------------------------------------ the result

    def orbits(self) -> list[int]:
        """The entries of the periodic orbits found (merged ones left out)."""
        return [
            k for k, e in enumerate(self.entries) if e.family is AttractorKind.PERIODIC and self.root(k) == k
        ]

    def attractors(self, invalid: int = 0) -> tuple[list[Attractor], np.ndarray]:
        """The attractors (ids 1, 2, ... by first initial state; ``invalid`` initial states as id 0) and
        each initial state's id."""
        roots = sorted({self.root(k) for k in range(len(self.entries))}, key=lambda k: self.entries[k].first)
        roots = [k for k in roots if self.entries[k].count > 0]
        total = self.labels.size
        ids = {k: i + 1 for i, k in enumerate(roots)}
        out = []
        if invalid:
            n = self.model.n_states
            out.append(
                Attractor(
                    id=INVALID,
                    kind=AttractorKind.INVALID,
                    period=-1,
                    impacts_per_period=math.nan,
                    lyapunov=math.nan,
                    points=np.zeros((0, n)),
                    reason="beyond a stop",
                    count=invalid,
                    fraction=invalid / total,
                    first=-1,
                )
            )
        for k in roots:
            e = self.entries[k]
            kind, exponent = self._kind(e)
            pts = e.points if e.points.size else np.zeros((0, self.model.n_states))
            names = self.model.mode_names
            modes = tuple(names[m] for m in e.modes) if e.modes.size == len(pts) and len(pts) else ()
            out.append(
                Attractor(
                    id=ids[k],
                    kind=kind,
                    period=e.period,
                    impacts_per_period=e.impacts,
                    lyapunov=exponent,
                    points=pts,
                    reason=e.reason,
                    count=e.count,
                    fraction=e.count / total,
                    first=e.first,
                    modes=modes,
                )
            )
        table = np.array(
            [
                ids[self.root(k)] if self.entries[self.root(k)].count else INVALID
                for k in range(len(self.entries))
            ],
            dtype=np.int64,
        )
        labels = np.full(total, INVALID, dtype=np.int64)
        done = self.labels >= 0
        labels[done] = table[self.labels[done]]
        return out, labels

    def _kind(self, e: _Entry) -> tuple[AttractorKind, float]:
        exps = np.array([v for v in e.exponents if not math.isnan(v)])  # (-inf: reached in finite time)
        exponent = float(np.median(exps)) if exps.size else math.nan
        if e.family.outcome:
            return e.family, math.nan
        if e.family is AttractorKind.PERIODIC:
            if self._sticks(e):
                return AttractorKind.STICKING, exponent
            return (AttractorKind.NEUTRAL if e.neutral else AttractorKind.PERIODIC), exponent
        if not math.isfinite(exponent):
            return AttractorKind.APERIODIC, exponent
        if exponent > CHAOS_THRESHOLD:
            return AttractorKind.CHAOTIC, exponent
        quasi = exponent >= -CHAOS_THRESHOLD
        return (AttractorKind.QUASIPERIODIC if quasi else AttractorKind.APERIODIC), exponent

    def examine_orbits(self) -> dict[int, float]:
        """Mark the periodic orbits found that are neutral (:func:`~grazing.sweeps.polish.is_neutral`: a
        double multiplier 1), from the monodromy at one of their points; return the largest Lyapunov
        exponent of each orbit whose monodromy was computed, ``ln |mu|_max / (p T)`` (by entry)."""
        from grazing.maps import flow_map

        out: dict[int, float] = {}
        for k in self.orbits():
            e = self.entries[k]
            if self._sticks(e):
                continue
            try:
                mode = run_mode(
                    self.model, int(e.modes[0]) if e.modes.size else -1, e.points[0], self.t_sample
                )
                fm = flow_map(self.model, e.points[0], t0=self.t_sample, periods=e.period, mode=mode)
            except (GrazingError, ArithmeticError):
                continue
            if not (fm.solution.jacobian_valid and np.all(np.isfinite(fm.jacobian))):
                continue
            mu = np.linalg.eigvals(fm.jacobian)
            e.neutral = is_neutral(fm.jacobian, mu)
            if e.neutral and mode is not None and landing_point(self.model, e.points[0], self.t_sample, mode):
                e.neutral = (
                    False  # (a rest every entering motion lands on: superstable, reached in finite time)
                )
                out[k] = -math.inf
                continue
            largest = float(np.max(np.abs(mu)))
            if largest > 0:
                out[k] = math.log(largest) / (e.period * float(self.model.period))
        return out

    def _sticks(self, e: _Entry) -> bool:
        """No impacts, and every point of the orbit on a stop: the motion rides on it."""
        if not e.impacts == 0 or not self.model.has_sticking:
            return False
        for x in e.points:
            tol = RIDING_TOL * max(1.0, float(np.max(np.abs(x))))
            if not any(abs(self.model.guard(x, self.t_sample, j)) <= tol for j in range(self.model.n_stops)):
                return False
        return True


def landing_point(model: HybridModel, point: np.ndarray, t: float, mode: str) -> bool:
    """Is ``point`` in ``mode`` a state of rest that every motion entering that mode lands on exactly: the
    mode absorbing (no transition leaves it), its field zero at ``point``, and a transition into it whose
    reset puts every state on ``point`` (``g_x = 0``, ``g = point``: the rocking block's ``overturned``,
    entered at ``(+-pi/2, 0)``)?

    Its monodromy in the mode is the identity (multipliers 1: within the mode every state is at rest), but
    no motion reaches the states around it: each perturbation of a motion that enters is erased by the
    reset (its saltation matrix is 0), so the point is an isolated attractor reached in finite time
    (multipliers 0, Lyapunov exponent ``-inf``), not a family of motions (``neutral``).  A state put in the
    mode elsewhere stays where it is: that one is neutral.

    Examples
    --------
    >>> import grazing
    >>> m = grazing.models.rocking_block()
    >>> side = np.array([np.pi / 2, 0.0])
    >>> landing_point(m, side, 0.0, "overturned"), landing_point(m, side + 0.1, 0.0, "overturned")
    (True, False)
    """
    from grazing.core.model import absorbing_modes

    if mode not in absorbing_modes(model) or np.any(model.vector_field(point, t, mode) != 0):
        return False
    scale = max(1.0, float(np.max(np.abs(point))))
    for j in range(model.n_stops):
        if model.transition_target[j] != mode or not model.transition_resets[j]:
            continue
        gx = model.jacobians(point, t, j)[2]
        if not np.any(gx) and np.max(np.abs(model.reset(point, t, j) - point)) <= ON_STOP_TOL * scale:
            return True
    return False


def unsettled(samples: np.ndarray, period: np.ndarray, tol: float = BASIN_ADAPTIVE_TOL) -> np.ndarray:
    """Which periodic end states have not settled: their samples repeat with their period only to more
    than ``tol`` of their scale (:func:`~grazing.core.period.sample_scale`; an orbit on its attractor
    repeats to rounding; the period detector accepts 1e-6), or
    they are closing in on a shorter period (a divisor's differences shrink over the samples).

    The second: an orbit slow to settle on a period-1 orbit with a multiplier near -1 (-0.94) repeats
    with period 2 to 7e-8 after 200 periods, with period 1 to only 1e-6 (found by hypothesis).

    Examples
    --------
    >>> k = np.arange(32.0)
    >>> spiral = 1e-6 * 0.98**k * np.cos(2 * np.pi * k / 7)     # converging to a point, slowly
    >>> flip = 1e-6 * (-0.94) ** k                                  # the same, alternating
    >>> two = np.where(k % 2 == 0, 1.0, -1.0)                       # a period-2 orbit
    >>> samples = np.stack([np.stack([v, 0 * k], 1) for v in (spiral, 0 * k + 1.0, flip, two)])
    >>> unsettled(samples, np.array([7, 1, 2, 2])).tolist()
    [True, False, True, False]
    """
    out = np.zeros(period.shape, dtype=bool)
    for i in np.flatnonzero(period > 0):
        p = int(period[i])
        repeats = np.max(np.abs(samples[i, p:] - samples[i, :-p]))
        out[i] = bool(repeats > tol * sample_scale(samples[i])) or closing_period(samples[i], p)[0] != p
    return out


def closing_period(samples: np.ndarray, p: int) -> tuple[int, float]:
    """The least divisor ``d`` of ``p`` that p-periodic ``samples`` are converging to, else ``p``; and
    how far their last samples are from period ``d`` (0 for ``p``).

    They converge to period ``d`` where the differences ``|x[k + d] - x[k]|`` of their last ``p``
    samples are under :data:`~grazing.core.options.CLOSING_RATIO` of those of their first ``p`` (on a
    p-periodic orbit they are the same).

    Examples
    --------
    >>> k = np.arange(32.0)[:, None]
    >>> d, off = closing_period(1e-5 * (-0.97) ** k, 2)
    >>> d, bool(off < 1e-5), closing_period(np.where(k % 2 == 0, 1.0, -1.0), 2)
    (1, True, (2, 0.0))
    """
    for d in (d for d in range(1, p) if p % d == 0):
        diff = np.max(np.abs(samples[d:] - samples[:-d]), axis=1)
        if diff.size >= 2 * p and np.max(diff[-p:]) < CLOSING_RATIO * np.max(diff[:p]):
            return d, float(np.max(diff[-p:]))
    return p, 0.0


def same_points(a: np.ndarray, b: np.ndarray) -> bool:
    """Are two periodic orbits' points the same to the period detector's tolerance (within
    :data:`~grazing.core.options.PERIOD_TOL` of their scale, :func:`~grazing.core.period.sample_scale`)?

    Two runs whose samples each repeat to that tolerance and whose points are that close are one orbit
    to the detector, whatever the cell: in small units (an orbit of size 1e-5, its cells 1e-8) the
    engine's error, ``tol`` times ``max(1, |x|)``, set two runs' points 5e-10 apart, more than a match's
    1e-3 cells, and one attractor was counted once per initial state.

    Examples
    --------
    >>> a = np.array([[1.3e-5, 8.7e-7]])
    >>> same_points(a, a + 5e-10), same_points(a, a + 1e-5), same_points(1e10 * a, 1e10 * a + 1e-2)
    (True, False, True)
    """
    scale = max(sample_scale(a), sample_scale(b))
    return set_distance(a, b, np.ones(np.shape(a)[-1])) <= PERIOD_TOL * scale


def set_distance(
    a: np.ndarray, b: np.ndarray, cell: np.ndarray, modes_a: Any = None, modes_b: Any = None
) -> float:
    """The Hausdorff distance between two point sets, in cells (each component over its cell size); given
    the mode at each point of both (``modes_a``, ``modes_b``), points in different modes are infinitely
    far apart.

    Examples
    --------
    >>> a = np.array([[0.0, 0.0], [1.0, 0.0]])
    >>> set_distance(a, a[::-1], np.ones(2)), set_distance(a, a + [0.0, 0.5], np.array([1.0, 0.25]))
    (0.0, 2.0)
    >>> one = np.ones(2)
    >>> set_distance(a, a, one, [0, 1], [0, 1]), set_distance(a, a, one, [0, 1], [1, 0])
    (0.0, 1.0)
    """
    a = np.asarray(a, dtype=float) / cell
    b = np.asarray(b, dtype=float) / cell
    if a.size == 0 or b.size == 0:
        return math.inf
    d = np.max(np.abs(a[:, None, :] - b[None, :, :]), axis=2)
    if modes_a is not None and modes_b is not None:
        d = np.where(np.asarray(modes_a)[:, None] == np.asarray(modes_b)[None, :], d, math.inf)
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))
