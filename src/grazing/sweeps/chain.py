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
  state (one point: a *check*); when both end on the same periodic orbit, at
  the same point of it (samples and final state equal to
  :data:`~grazing.core.options.CHAIN_TOL`), or fail alike, the chunk is
  kept: from its first point on it is the chain's to that tolerance;
- otherwise (another attractor: the hysteresis the guess misses; an
  aperiodic point, which no tolerance makes equal) the chunk is run again
  from that final state, so it is the chain's, and the chunks after it are
  checked against its new end.

A chunk is *settled* once it and every chunk before it in its chain are the
chain's; then it is written to the store.  The checks and the runs of a
round are computed together on the lanes, so a sweep whose chunks agree
costs one point per chunk more than the chunks; a sweep through chaos, where
no chunk can be kept, costs a chain's time.  A store holds settled chunks
only: resumed, a chunk continues from the final state stored for the chunk
before it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from grazing.core.options import CHAIN_TOL
from grazing.core.solution import Status
from grazing.sweeps.spec import ChunkResult, SweepSpec

Part = tuple[SweepSpec, int]
"""A chunk of a sweep: the spec and the chunk's index."""

Compute = Callable[[list[Part]], Iterable[tuple[Part, ChunkResult]]]
"""Computes chunks (on the local cores, on a Dask cluster), each with its result, in any order."""

ChainStart = tuple[float, tuple[float, ...]] | None
"""Where a chunk starts: ``(t, x)``, or None: ``x0`` at time 0 (a chain's start; after a failed point)."""


def next_start(spec: SweepSpec, res: ChunkResult, index: int) -> ChainStart:
    """Where the chain goes on after chunk ``index`` (result ``res``): its last point's final state.

    See :func:`start_after`.
    """
    t = math.nan if res.t_final is None else float(res.t_final[-1])
    return start_after(spec, index, int(res.status[-1]), res.x_final[-1], t)


def start_after(spec: SweepSpec, index: int, status: int, x: Any, t: float) -> ChainStart:
    """Where the chain goes on after chunk ``index``, whose last point ended (``status``) in ``x`` at ``t``.

    At the time the driver continues a chain with (the next point's sampling
    phase for a periodic model, else the final time ``t``); None after a failed
    point, from which the chain starts again from ``x0``.
    """
    if status != Status.OK:
        return None
    state = tuple(float(v) for v in x)
    if spec.model.periodic:
        T = float(spec.model_at(spec.points[spec.chunk(index).stop]).period)
        return ((spec.phase / (2 * math.pi)) % 1.0 * T, state)  # (as grazing.sweeps.run.LaneBatch's tcarry)
    if not math.isfinite(t):
        raise ValueError(f"the final time of chunk {index} is not known")
    return (t, state)


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

    Both failed for the same reason, or both on one periodic orbit at one point of it: the same
    period, samples and final state equal to ``tol``.
    """
    sa, sb = int(a.status[i]), int(b.status[j])
    if sa != Status.OK or sb != Status.OK:
        return sa == sb
    p = int(a.period[i])
    if p <= 0 or p != int(b.period[j]):
        return False
    close = np.max(np.abs(a.samples[i] - b.samples[j])) <= tol
    return bool(close and np.max(np.abs(a.x_final[i] - b.x_final[j])) <= tol)


def split_result(spec: SweepSpec, res: ChunkResult, indices: Sequence[int]) -> list[ChunkResult]:
    """The result of one run over the consecutive chunks ``indices`` of ``spec``, as each chunk's result."""
    out, a = [], 0
    total = max(1, sum(spec.chunk(i).stop - spec.chunk(i).start for i in indices))
    for i in indices:
        sl = spec.chunk(i)
        b = a + sl.stop - sl.start
        cut = {
            name: None if getattr(res, name) is None else getattr(res, name)[a:b]
            for name in ("samples", "period", "impacts", "lyapunov", "transient_used", "x_final", "status",
                         "impacts_by_stop", "t_final")
        }  # fmt: skip
        out.append(replace(res, index=i, seconds=res.seconds * (b - a) / total, **cut))
        a = b
    return out


_UNSET = object()


@dataclass
class _Chunk:
    """One chunk of a chain while it is being settled."""

    line: int
    index: int
    result: ChunkResult | None = None
    start: Any = _UNSET  # the start its result was computed from
    passed: list[Any] = field(default_factory=list)  # starts its first point was checked against and agreed
    failed: dict[Any, bool] = field(default_factory=dict)  # ... disagreed: start -> the check ended periodic
    settled: bool = False

    @property
    def aperiodic(self) -> bool:
        """Whether its first point ended on no periodic orbit (no check can agree with it)."""
        res = self.result
        return res is not None and int(res.status[0]) == Status.OK and int(res.period[0]) <= 0


@dataclass
class _Round:
    """What one round of :func:`settle` computes: checks of first points, and runs of chunks."""

    lines: Sequence[Any]
    active: dict[tuple[int, int], _Chunk]
    parts: list[Part] = field(default_factory=list)
    jobs: list[tuple[list[_Chunk], str, Any]] = field(default_factory=list)
    claimed: set[tuple[int, int]] = field(default_factory=set)

    def ask(self, c: _Chunk, what: str, start: Any, extend: bool = False) -> None:
        """Check ``c``'s first point from ``start``, or run ``c`` from there; ``extend``-ed, with the chunks
        after it that only a run from the chain's start can settle (their first point aperiodic), as one
        job (the same numbers as runs of each from the end of the one before)."""
        group = [c]
        while extend:
            nxt = self.active.get((c.line, group[-1].index + 1))
            if nxt is None or nxt.result is None or nxt.settled or not nxt.aperiodic:
                break
            group.append(nxt)
        self.claimed.update((g.line, g.index) for g in group)
        spec = self.lines[c.line].spec
        if what == "check":
            self.parts.append(from_start(spec, c.index, start, 1))
        else:
            points = spec.chunk(group[-1].index).stop - spec.chunk(c.index).start
            self.parts.append(from_start(spec, c.index, start, points if len(group) > 1 else None))
        self.jobs.append((group, what, start))


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
    settled) is settled when its result started there or its check there
    agreed; else it is checked there, or run again there when its first point
    is aperiodic or its check disagreed.  A chunk whose chain's start may still
    change is checked there, and run again there only when the check ended on
    another periodic orbit (hysteresis: likely to stay so); an aperiodic one
    waits for the start to be final.

    Every chunk is computed first from ``x0`` at time 0 (the guess), whatever
    is known of its chain's start: its result is then a function of that
    guess and the final start alone (the guess's when it started there or its
    check there agrees, else the run from there), so the results are the same
    whatever the window, the rounds, the threads or an interruption.
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
        return prev.settled, next_start(line.spec, prev.result, prev.index)

    while pending:
        work = _Round(lines, active)
        for key in sorted(active):
            c = active[key]
            if c.result is None or key in work.claimed:
                continue
            final, start = chain_start(c)
            if start is _UNSET or c.start == start or start in c.passed:
                continue
            if final:
                if c.aperiodic or start in c.failed:
                    work.ask(c, "run", start, extend=True)
                else:
                    work.ask(c, "check", start)
            elif c.failed.get(start, False):
                work.ask(c, "run", start)
            elif not c.aperiodic and start not in c.failed:
                work.ask(c, "check", start)
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
            for k, (group, what, start) in enumerate(work.jobs):
                res, c = results[k], group[0]
                if what == "run":  # (a part of its own, of index 0: its result is the chunks')
                    spec = lines[c.line].spec
                    pieces = split_result(spec, res, [g.index for g in group])
                    for n, (g, piece) in enumerate(zip(group, pieces)):
                        g.result, g.start, g.passed, g.failed = piece, start, [], {}
                        if n + 1 < len(group):  # (the next one started where this one ended)
                            start = next_start(spec, piece, g.index)
                elif c.result is not None and same_outcome(c.result, 0, res, 0):
                    c.passed.append(start)
                else:
                    c.failed[start] = int(res.status[0]) == Status.OK and int(res.period[0]) > 0
        progressed = False
        for key in sorted(active):
            c = active[key]
            if c.result is None:
                continue
            final, start = chain_start(c)
            if final and (c.start == start or start in c.passed):
                c.settled = True
                on_settled(c.line, c.result)
                del active[key]
                pending -= 1
                progressed = True
        if not work.parts and not progressed:  # pragma: no cover - every round computes or settles something
            raise RuntimeError("settling a sweep's chain made no progress")
