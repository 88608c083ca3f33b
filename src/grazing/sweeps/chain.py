"""Sweeps that carry their state are one chain, whatever the chunking.

A sweep that carries its state from point to point (not ``fresh``) is an
experimenter's sweep: one chain of points, each starting where the previous
one ended.  Its chunks are computed in parallel, so a chunk cannot wait for
the state the chunk before it ends in: :func:`settle` computes every chunk
from a guess (``x0`` at time 0, as the chain starts), then makes the result
the chain's, chunk by chunk:

- a chunk whose guess *is* the previous chunk's end (the first chunk of a
  chain; a chunk after a failed point, from where the chain starts again) is
  the chain's, bit for bit;
- otherwise its first point is run again from the previous chunk's final
  state (one point: a *check*); when both runs end alike (:func:`same_outcome`),
  the chunk is kept: from its first point on it is the chain's.  Alike is:
  on one periodic orbit at the same point of it (samples and final state
  equal to :data:`~grazing.core.options.CHAIN_TOL`); both aperiodic on one
  attractor (their samples share a cell of a grid of
  :data:`~grazing.core.options.CHAIN_CELLS` cells along their joint box, as
  the basins' classifier groups aperiodic end states:
  :func:`grazing.core.cells.one_attractor`); or failed alike;
- when both end periodic with one period (2 to
  :data:`~grazing.core.options.CHAIN_SHIFTS`) but not alike (mostly at
  another point of one orbit: a guess ends at the chain's point of a
  period-p orbit one time in p), the chunk is computed from the point of its
  guess's orbit from which its first point ends as far along the orbit as
  the check's (a *shift*: from the guess alone, so it stands for any start
  that leads there) and kept when its first point ends as the check does
  (when it does not, or the check is not that near one point of the orbit,
  from every point of the orbit: the one that agrees is kept);
- otherwise (another attractor: the hysteresis the guess misses, periodic
  against aperiodic, disjoint chaotic sets) the chunk is run again from that
  final state, so it is the chain's, and the chunks after it are checked
  against its new end.

Why the attractor, not the samples, at an aperiodic point: on a chaotic
attractor the chain's samples are not reproducible anyway.  Any rounding
difference (another processor, fused multiply-adds, another lane width)
moves them after a few periods, and with them what the chain lands on after
the chaos where attractors coexist (a relative change of 1e-15 in the
pendulum's state entering a chaotic band at 40 deg moves its samples by the
band's size and lands it on a period-6 orbit instead of a period-3 one a few
points later).  Only the attractor is reproducible, so "the chain's answer"
at an aperiodic point means the chain's attractor.  Periodic points keep
their guarantee: the same orbit, at the same point of it.

A chunk is *settled* once it and every chunk before it in its chain are the
chain's; then it is written to the store.  The checks, shifts and runs of a
round are computed together on the lanes, so a sweep whose chunks agree
costs one point per chunk more than the chunks; what is left of a chain's
time is the chunks run again, one after the other, where the guesses miss
the chain's attractor.  A store holds settled chunks only: resumed, a chunk
continues from the final state stored for the chunk before it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from grazing.core.cells import one_attractor
from grazing.core.options import CHAIN_CELLS, CHAIN_SHIFTS, CHAIN_TOL, PERIOD_TOL
from grazing.core.period import sample_scale
from grazing.core.solution import Status
from grazing.sweeps.spec import ChunkResult, SweepSpec

Part = tuple[SweepSpec, int]
"""A chunk of a sweep: the spec and the chunk's index."""

Compute = Callable[[list[Part]], Iterable[tuple[Part, ChunkResult]]]
"""Computes chunks (on the local cores, on a Dask cluster), each with its result, in any order."""

ChainStart = tuple[float, tuple[float, ...]] | tuple[float, tuple[float, ...], int] | None
"""Where a chunk starts: ``(t, x)`` (a model with modes: ``(t, x, mode)``, the index of the mode ``x`` is
in), or None: ``x0`` at time 0 (a chain's start; after a failed point)."""


def next_start(spec: SweepSpec, res: ChunkResult, index: int) -> ChainStart:
    """Where the chain goes on after chunk ``index`` (result ``res``): its last point's final state.

    See :func:`start_after`.
    """
    t = math.nan if res.t_final is None else float(res.t_final[-1])
    mode = -1 if res.mode_final is None else int(res.mode_final[-1])
    return start_after(spec, index, int(res.status[-1]), res.x_final[-1], t, mode)


def start_after(spec: SweepSpec, index: int, status: int, x: Any, t: float, mode: int = -1) -> ChainStart:
    """Where the chain goes on after chunk ``index``, whose last point ended (``status``) in ``x`` at ``t``
    (a model with modes: in mode ``mode``).

    At the time the driver continues a chain with (the next point's sampling
    phase for a periodic model, else the final time ``t``); None after a failed
    point, from which the chain starts again from ``x0``.
    """
    if status != Status.OK:
        return None
    state = tuple(float(v) for v in x)
    if spec.model.periodic:
        T = float(spec.model_at(spec.points[spec.chunk(index).stop]).period)
        t = (spec.phase / (2 * math.pi)) % 1.0 * T  # (as grazing.sweeps.run.LaneBatch's tcarry)
    elif not math.isfinite(t):
        raise ValueError(f"the final time of chunk {index} is not known")
    if not spec.model.has_modes:
        return (t, state)
    if mode < 0:
        raise ValueError(f"the final mode of chunk {index} is not known")
    return (t, state, mode)


def from_start(spec: SweepSpec, index: int, start: ChainStart, points: int | None = None) -> Part:
    """Chunk ``index`` of ``spec`` (its first ``points`` points) from ``start``, as a part of its own."""
    if start is None and points is None:
        return (spec, index)
    sl = spec.chunk(index)
    stop = sl.stop if points is None else sl.start + points
    points_here = spec.points[sl.start : stop]
    derived = replace(spec, points=points_here, resume=start, chunk_size=0, segments=1, shape=(), starts=None)
    return (derived, 0)


def same_outcome(a: ChunkResult, i: int, b: ChunkResult, j: int, tol: float = CHAIN_TOL) -> bool:
    """Whether point ``i`` of ``a`` and point ``j`` of ``b`` end alike: the chain goes on the same from both.

    Both failed for the same reason; or both on one periodic orbit at one point of it: the same
    period, samples and final state equal to ``tol``; or both aperiodic on one attractor: their
    samples share a cell of the grid of :data:`~grazing.core.options.CHAIN_CELLS` cells along their
    joint box (:func:`~grazing.core.cells.one_attractor`, the basins' rule).  Two points given one
    period by a Newton polish (:mod:`grazing.sweeps.polish`: their samples approach the orbit, they
    do not repeat) are as aperiodic ones: on one attractor by that rule.
    """
    sa, sb = int(a.status[i]), int(b.status[j])
    if sa != Status.OK or sb != Status.OK:
        return sa == sb
    p = int(a.period[i])
    if p == int(b.period[j]) and not repeats(a.samples[i], p) and not repeats(b.samples[j], p):
        return one_attractor(a.samples[i], b.samples[j], CHAIN_CELLS)
    if p <= 0 or p != int(b.period[j]):
        return False
    close = np.max(np.abs(a.samples[i] - b.samples[j])) <= tol
    return bool(close and np.max(np.abs(a.x_final[i] - b.x_final[j])) <= tol)


def repeats(samples: np.ndarray, p: int) -> bool:
    """Whether ``samples`` repeat with period ``p > 0`` to :data:`~grazing.core.options.PERIOD_TOL` of
    their scale (:func:`~grazing.core.period.sample_scale`; a point whose period a Newton polish gave
    does not: its samples still approach the orbit).

    Examples
    --------
    >>> k = np.arange(20.0)[:, None]
    >>> repeats(np.cos(np.pi * k), 2), repeats(0.9**k * np.cos(np.pi * k), 2), repeats(np.ones((4, 1)), 0)
    (True, False, False)
    """
    s = np.asarray(samples, dtype=float)
    return p > 0 and bool(np.max(np.abs(s[p:] - s[:-p])) <= PERIOD_TOL * sample_scale(s))


_UNSET = object()


@dataclass
class _Chunk:
    """One chunk of a chain while it is being settled."""

    line: int
    index: int
    guess: ChunkResult | None = None  # computed from x0 at time 0
    result: ChunkResult | None = None  # what the chain goes on from, from ``start``
    start: Any = _UNSET  # the start ``result`` stands for (None: the guess's own, x0 at time 0)
    checks: dict[Any, ChunkResult] = field(default_factory=dict)  # its first point run from each start
    shifts: dict[int, ChunkResult] = field(default_factory=dict)  # advance -> its guess shifted so far along
    kept: dict[Any, ChunkResult | None] = field(default_factory=dict)  # start -> the candidate kept there
    heading: int | None = 0  # the advance of the candidate it goes on from once decided (None: not a shift)
    settled: bool = False
    ends: dict[int, tuple[ChunkResult, ChainStart]] = field(default_factory=dict)  # id -> (result, its end)

    def end(self, spec: SweepSpec, res: ChunkResult) -> ChainStart:
        """Where the chain goes on after it from ``res`` (:func:`next_start`), worked out once a result (a
        chunk's end is asked for in every round, its candidates' ends whenever the chunk after it is
        checked from them)."""
        known = self.ends.get(id(res))
        if known is None or known[0] is not res:  # (kept with its result: its id is not another's)
            known = self.ends[id(res)] = (res, next_start(spec, res, self.index))
        return known[1]

    def candidates(self) -> list[ChunkResult]:
        """The results it may keep where its check ends periodic with its guess's period: the guess, then
        the shifts computed, by advance."""
        assert self.guess is not None
        return [self.guess, *(self.shifts[m] for m in sorted(self.shifts))]

    def advance_of(self, res: ChunkResult | None) -> int | None:
        """How far along its guess's orbit ``res`` is (0: the guess; None: a run, not one of its shifts)."""
        if res is self.guess:
            return 0
        return next((m for m, r in self.shifts.items() if r is res), None)

    def verdict(self, start: Any, spec: SweepSpec) -> str:
        """From ``start``: ``"keep"`` (``kept[start]`` is the chain's), ``"check"`` (its first point from
        there is not known), ``"shift"`` (a shift of the guess, :meth:`shifts_wanted`, is needed to decide)
        or ``"run"``."""
        if start in self.kept:
            return "keep" if self.kept[start] is not None else "run"
        check = self.checks.get(start)
        if check is None:
            return "check"
        p = orbit_period(spec, self.guess)
        its_period = p > 0 and int(check.status[0]) == Status.OK and int(check.period[0]) == p
        if its_period and not same_outcome(self.guess, 0, check, 0) and self.shifts_wanted(check, p):
            return "shift"
        candidates = self.candidates() if its_period else [self.guess]  # (whatever was computed)
        self.kept[start] = next((r for r in candidates if same_outcome(r, 0, check, 0)), None)
        return self.verdict(start, spec)

    def shifts_wanted(self, check: ChunkResult, p: int) -> list[int]:
        """The shifts of its guess still to compute before ``check`` (its first point from a start, on the
        guess's period-``p`` orbit) decides which candidate it keeps: the one as far along the orbit as
        ``check`` (:func:`orbit_advance`), or, when that is not known or does not agree, every one (as many
        results as before: the first that agrees, the only one)."""
        assert self.guess is not None
        m = orbit_advance(self.guess, check, p)
        if m is not None and m not in self.shifts:
            return [m]
        if m is not None and same_outcome(self.shifts[m], 0, check, 0):
            return []
        return [k for k in range(p) if k not in self.shifts]

    def take_run(self, start: Any, res: ChunkResult) -> None:
        """``res``, computed from ``start``, is what the chain goes on from (it is the chain's from there)."""
        self.result, self.start = res, start
        self.kept[start] = None if start is not None else res
        if start is None:
            self.guess = res


def orbit_period(spec: SweepSpec, res: ChunkResult | None) -> int:
    """The period of the orbit the first point of ``res`` ends on when a chunk may keep it shifted along
    that orbit (:func:`shifted_starts`): 2 to :data:`~grazing.core.options.CHAIN_SHIFTS`, a periodic model;
    else 0."""
    if res is None or not spec.model.periodic or int(res.status[0]) != Status.OK:
        return 0
    if spec.model.has_modes:  # (the modes of the orbit's points are not known: no shifts along it)
        return 0
    p = int(res.period[0])
    return p if 2 <= p <= CHAIN_SHIFTS and repeats(res.samples[0], p) else 0


def orbit_advance(guess: ChunkResult, res: ChunkResult, p: int) -> int | None:
    """How many points of the period-``p`` orbit that the first point of ``guess`` ends on the first point of
    ``res`` ends ahead of it: the ``m`` with the last ``p`` samples of ``res`` those of ``guess`` ``m`` on
    along the orbit, nearer to them than half the least distance between the orbit turned by ``m`` and by
    another number (so there is one such ``m``; and none when that distance is within rounding:
    ``4 * CHAIN_TOL``)."""
    orbit, other = guess.samples[0][-p:], res.samples[0][-p:]
    if orbit.shape != other.shape or orbit.shape[0] < p:
        return None
    turned = [np.roll(orbit, -m, axis=0) for m in range(p)]  # (turned[m][i]: the orbit's point i + m)
    apart = min(float(np.max(np.abs(turned[m] - orbit))) for m in range(1, p))
    distance = [float(np.max(np.abs(t - other))) for t in turned]
    m = int(np.argmin(distance))
    return m if apart > 4 * CHAIN_TOL and distance[m] < apart / 2 else None


def shifted_start(spec: SweepSpec, index: int, res: ChunkResult, advance: int) -> ChainStart:
    """The start of chunk ``index`` on the orbit that the first point of its guess ``res`` ends on, from which
    its first point ends ``advance`` points of that orbit ahead of the guess's (at the sampling phase).

    A point run from the orbit's point ``j`` ends ``transient + periods`` periods on (an adaptive transient
    runs a number of periods congruent to ``transient`` modulo the period), sampling the ends of the last
    ``periods``; the guess's samples end at the orbit's last point: its samples are as far ahead as
    ``j + transient + periods + 1`` points of the orbit.
    """
    p = orbit_period(spec, res)
    T = float(spec.model_at(spec.points[spec.chunk(index).start]).period)
    t = (spec.phase / (2 * math.pi)) % 1.0 * T
    j = (advance - spec.transient - spec.periods - 1) % p
    return (t, tuple(float(v) for v in res.samples[0][-p + j]))


def in_phase_through(spec: SweepSpec, res: ChunkResult, p: int) -> bool:
    """Whether every point of ``res`` ends on a period-``p`` orbit: a chunk's shift is then as far ahead at
    its end as at its first point (the chunk after it starts that far along its orbit)."""
    if not (spec.model.periodic and np.all(res.status == Status.OK) and np.all(res.period == p)):
        return False
    return all(repeats(s, p) for s in res.samples)


@dataclass
class _Round:
    """What one round of :func:`settle` computes: checks of first points, and runs of chunks."""

    lines: Sequence[Any]
    active: dict[tuple[int, int], _Chunk]
    parts: list[Part] = field(default_factory=list)
    jobs: list[tuple[_Chunk, str, Any]] = field(default_factory=list)
    claimed: set[tuple[int, int]] = field(default_factory=set)
    checking: set[tuple[int, int, Any]] = field(default_factory=set)  # (line, index, start) of its checks
    shifting: set[tuple[int, int, int]] = field(default_factory=set)  # (line, index, advance) of its shifts

    def check(self, c: _Chunk, start: Any) -> None:
        """Check ``c``'s first point from ``start`` (once a round; unlike :meth:`ask`, ``c`` is not claimed:
        its own verdict is still asked for in this round)."""
        if start in c.checks or (c.line, c.index, start) in self.checking:
            return
        self.checking.add((c.line, c.index, start))
        self.parts.append(from_start(self.lines[c.line].spec, c.index, start, 1))
        self.jobs.append((c, "check", start))

    def check_after(self, c: _Chunk) -> None:
        """Check the first point of the chunk after ``c`` from the end of each of ``c``'s candidates (the
        ends it may go on from, its guess's orbit computed from each of its points): however ``c`` is
        decided, the chunk after it is decided in the same pass, not a round later (a ripple through a
        periodic window, each chunk kept at another point of its orbit, took a round a chunk)."""
        nxt = self.active.get((c.line, c.index + 1))
        if nxt is None or nxt.guess is None or nxt.settled or not c.shifts:
            return
        spec = self.lines[c.line].spec
        for r in c.candidates():
            self.check(nxt, c.end(spec, r))

    def ask(self, c: _Chunk, what: str, start: Any) -> None:
        """Check ``c``'s first point from ``start``, or run ``c`` from there (:meth:`shift`: from a point of
        its guess's orbit).

        A run is one chunk's: run on over the chunks after it (which a run from its chain's start is likely
        to be needed for too), it made its round as long as all of them, and every other chain's chunks
        waited for it (the default 16000-point sweep's longest part in its rounds after the shifts, summed:
        560 points with such runs, 460 without)."""
        self.claimed.add((c.line, c.index))
        spec = self.lines[c.line].spec
        if what == "check":
            self.check(c, start)
            return
        self.parts.append(from_start(spec, c.index, start))
        self.jobs.append((c, what, start))

    def shift(self, c: _Chunk, advances: Iterable[int]) -> None:
        """Run ``c`` from the points of its guess's orbit from which its first point ends ``advances`` points
        of that orbit ahead of the guess's (:func:`shifted_start`), those not known or asked yet."""
        self.claimed.add((c.line, c.index))
        spec = self.lines[c.line].spec
        for m in advances:
            if m in c.shifts or (c.line, c.index, m) in self.shifting:
                continue
            self.shifting.add((c.line, c.index, m))
            self.parts.append(from_start(spec, c.index, shifted_start(spec, c.index, c.guess, m)))
            self.jobs.append((c, "shift", m))

    def take(self, results: Sequence[ChunkResult]) -> None:
        """Record the results of the round's jobs (``results[k]`` of ``jobs[k]``) in their chunks."""
        for (c, what, start), res in zip(self.jobs, results):
            if what == "check":
                c.checks[start] = res
            elif what == "shift":  # (``start``: its advance)
                c.shifts[start] = replace(res, index=c.index)
            else:  # (a run: a part of its own, of index 0)
                c.take_run(start, replace(res, index=c.index))


def heading_lead(prev: _Chunk | None, spec: SweepSpec, p: int) -> int | None:
    """How many points of its period-``p`` orbit the start of the chunk after ``prev`` moves on once ``prev``
    keeps the shift of its guess it heads for (:attr:`_Chunk.heading`); None when that is not known: ``prev``
    heads for a run, or its guess is not on a period-``p`` orbit at every point (:func:`in_phase_through`)."""
    if prev is None or prev.heading is None or orbit_period(spec, prev.guess) != p:
        return None
    now = prev.advance_of(prev.result)
    if now is None or not in_phase_through(spec, prev.guess, p):
        return None
    return (prev.heading - now) % p


@dataclass
class ChainLine:
    """A sweep being settled: its spec, its store (``write``, ``chain_start``) and the chunks to compute."""

    spec: SweepSpec
    sink: Any
    todo: list[int]


def settle(
    lines: Sequence[ChainLine],
    compute: Compute,
    on_settled: Callable[[int, ChunkResult], None],
    window: int,
) -> None:
    """Compute the chunks ``todo`` of each line so that every point is its chain's (see the module).

    ``on_settled(line, result)`` receives each chunk once it is settled (in
    each chain's order), to write it.  At most ``window`` chunks are held at a
    time, besides the checks.  ``compute`` runs a round's parts together; an
    exception (Ctrl-C) leaves the chunks settled before it written.

    In each round, a chunk whose chain's start is final (the chunk before it
    settled) is settled when its result stands for that start; else it is
    checked there, computed from its shifts when the check ended periodic with
    its guess's period but not alike, or run again there.  A chunk whose
    chain's start may still change is treated alike, but run again only when
    its check ended on an attractor (hysteresis: likely to stay so); and when
    the chunk before it moves (its result is not its guess), the shift it will
    keep is computed at once: its start moves along the orbit as far as the
    chunk before it heads for (:func:`heading_lead`; as it is, where that is
    not known).  The chunk after one not decided yet whose shifts are known is
    checked from the end of each of its candidates in the same round: however
    that one is decided, the chunk after it is decided in the same pass
    (:meth:`_Round.check_after`).

    Only the shifts a chunk keeps are computed, as a rule: where every shift of
    a chunk whose start moves was computed ahead (as before), the default
    sweep of 8000 points computed 9700 points of shifts to keep 2350 of them,
    half its work.  Computing them when known costs a round where a guess of
    where a start goes is wrong (measured: 15 rounds instead of 12 for that
    sweep, 22 for 16000 points as before); on 2 cores the whole 8000-point
    sweep took 0.82 times as long.

    Every chunk is computed first from ``x0`` at time 0 (the guess), whatever
    is known of its chain's start: its result is then a function of that
    guess and the final start alone (the guess when its check from there
    agrees; else, when the check ended with the guess's period, the shift
    that agrees; else the run from there), so the results are the same
    whatever the window, the rounds, the threads or an interruption.  (One
    shift at most agrees: two would be the orbit turned into itself, which
    :func:`orbit_advance` refuses, and then every shift is computed.)
    """
    waiting = iter([_Chunk(k, i) for k, line in enumerate(lines) for i in line.todo])
    pending = sum(len(line.todo) for line in lines)
    active: dict[tuple[int, int], _Chunk] = {}

    def chain_start(c: _Chunk) -> tuple[bool, Any]:
        """``(final, start)``: where the chain is at chunk ``c``'s first point, from the chunk before it."""
        line = lines[c.line]
        if line.spec.chain_first(c.index):
            return True, None
        prev = active.get((c.line, c.index - 1))
        if prev is None:  # settled and written (in this run or an earlier one)
            return True, line.sink.chain_start(c.index - 1)
        if prev.result is None:
            return False, _UNSET
        return prev.settled, prev.end(line.spec, prev.result)

    while pending:
        work = _Round(lines, active)
        moving: set[tuple[int, int]] = set()  # (chunks whose result is not, or will not be, their guess)
        for key in sorted(active):
            c = active[key]
            if c.result is None or key in work.claimed:
                continue
            final, start = chain_start(c)
            if start is _UNSET:
                continue
            spec = lines[c.line].spec
            what = "keep" if c.start == start else c.verdict(start, spec)
            if c.start == start:
                pass
            elif what == "keep":  # (the chunks after it see its new end in this same loop)
                c.result, c.start = c.kept[start], start
            elif what == "check":
                work.ask(c, what, start)
            elif what == "run" and (final or int(c.checks[start].status[0]) == Status.OK):  # (hysteresis)
                work.ask(c, "run", start)
            if not final or what not in ("keep", "run"):  # (undecided: which of its candidates it keeps)
                work.check_after(c)
            p = orbit_period(spec, c.guess)
            wanted = c.shifts_wanted(c.checks[start], p) if what == "shift" else []
            c.heading = c.advance_of(c.result) if what == "keep" else wanted[0] if len(wanted) == 1 else None
            follows = (c.line, c.index - 1) in moving and p > 0
            if follows:  # (the chunk before it moves: its start will too, by its lead, or else as it is)
                lead = heading_lead(active.get((c.line, c.index - 1)), spec, p) or 0
                c.heading = None if c.heading is None else (c.heading + lead) % p
                wanted = [c.heading] if c.heading else []
            work.shift(c, wanted)
            if follows or what in ("shift", "run") or c.result is not c.guess:
                moving.add(key)
        while len(active) < window:  # new chunks, from x0 (see above: whatever the window, the same results)
            c = next(waiting, None)
            if c is None:
                break
            active[c.line, c.index] = c
            work.ask(c, "run", None)
        if work.parts:
            position = {id(part): k for k, part in enumerate(work.parts)}  # (compute hands back these parts)
            results: dict[int, ChunkResult] = {}
            for part, res in compute(work.parts):
                results[position[id(part)]] = res
            work.take([results[k] for k in range(len(work.parts))])
        progressed = False
        for key in sorted(active):
            c = active[key]
            if c.result is None:
                continue
            final, start = chain_start(c)
            if final and c.start == start:
                c.settled = True
                on_settled(c.line, c.result)
                del active[key]
                pending -= 1
                progressed = True
        if not work.parts and not progressed:  # pragma: no cover - every round computes or settles something
            raise RuntimeError("settling a sweep's chain made no progress")
