"""The sliding bifurcations of a periodic orbit, named from the change of its switches along a branch.

On a model with a sliding surface (a Filippov system) a branch of periodic orbits keeps its switches of
mode (:attr:`~grazing.orbits.periodic.PeriodicOrbit.switch_signature`: the transitions, then each sliding
pseudo-mode's entries and exits) up to a boundary where the orbit meets the boundary of the sliding
region, a point where the field of one side, ``A``, is tangent to the surface (di Bernardo, Kowalczyk &
Nordmark, *Physica D* 170, 2002; di Bernardo, Budd, Champneys & Kowalczyk, *Piecewise-smooth Dynamical
Systems*, 2008, ch. 8; Kuznetsov, Rinaldi & Gragnani, *Int. J. Bifurcation Chaos* 13, 2003).  Across it
the switches change by a local move, a window of two consecutive switches (cyclically) that shrinks to
nothing at the bifurcation; which move names the bifurcation (:func:`kind_of_change`):

* **crossing-sliding**: the orbit arrives from the other side, ``B``, at the boundary point, where ``A``'s
  tangency is visible (the sliding flow leaves there): on one side it crosses into ``A``, on the other
  it slides for a short time first: a crossing ``B -> A`` against an entry from ``B`` and an exit to
  ``A`` (a short stick);
* **switching-sliding**: the same arrival at a boundary point where ``A``'s tangency is invisible (the
  sliding flow moves away from it): on one side the orbit slides at once, on the other it crosses into
  ``A``, makes a short excursion there and comes back to slide: an entry from ``B`` against a crossing
  ``B -> A`` and an entry from ``A`` (a short excursion);
* **grazing-sliding**: the orbit touches the surface from inside ``A`` at the boundary point: a short
  sliding segment (an entry from ``A`` and an exit to ``A``) appears inside a phase in ``A``;
* **adding-sliding**: the sliding orbit reaches the boundary point where the trajectory that leaves
  is tangent to the surface to higher order: a short excursion into ``A`` (an exit to ``A`` and an
  entry from ``A``) appears inside a sliding phase.

The window that vanishes tells the moves apart where the names alone do not (an orbit with a single
stick and none: a short stick inside a slip, grazing-sliding, or a short slip inside a stick,
adding-sliding): :func:`sliding_kind` takes the window with the shortest duration.

The boundary itself is bracketed by the continuation (its parameter to
:data:`~grazing.core.options.BOUNDARY_TOL`) and narrowed by bisection on the switches of the orbits found
between (:func:`bisect_switches`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grazing.core.model import HybridModel
from grazing.errors import GrazingError
from grazing.orbits.kinds import SpecialKind
from grazing.orbits.periodic import PeriodicOrbit
from grazing.orbits.shooting import find_orbit

BISECTION_TOL = 1e-12
"""The sliding bifurcation's parameter is bisected until its bracket is at most this wide (relative to
``max(1, |value|)``), or until an orbit between does not have the switches of either side."""

BISECTION_STEPS = 60
"""At most this many bisection steps (each a :func:`~grazing.orbits.shooting.find_orbit`)."""

MAX_MOVES = 4
"""At most this many simultaneous moves (a symmetric orbit meets the boundary twice a period)."""

Signature = tuple[tuple[str, ...], ...]
Item = tuple[int | None, str]  # (the switch's index in the longer sequence, or None if put in; its name)


def _roles(m: HybridModel) -> dict[str, tuple[str, str, str]]:
    """Each switch name's ``(role, source, target)``: role ``"entry"`` (into a sliding pseudo-mode),
    ``"exit"`` (out of one) or ``"cross"`` (between two modes)."""
    sliding = set(m.sliding_names)
    roles = {}
    for name, src, tgt in zip(m.switch_names, m.switch_sources, m.switch_targets):
        role = "entry" if tgt in sliding else "exit" if src in sliding else "cross"
        roles[name] = (role, src, tgt)
    return roles


def _moves(m: HybridModel) -> dict[tuple[str, str], tuple[SpecialKind, tuple[str, ...]]]:
    """The local moves of the module's docstring: each window of two switches that shrinks to nothing,
    with the bifurcation it names and what is left of it on the other side."""
    roles = _roles(m)
    by_ends = {(src, tgt): name for name, (role, src, tgt) in roles.items()}
    entries = [(n, src, tgt) for n, (r, src, tgt) in roles.items() if r == "entry"]
    exits = [(n, src, tgt) for n, (r, src, tgt) in roles.items() if r == "exit"]
    crossings = [(n, src, tgt) for n, (r, src, tgt) in roles.items() if r == "cross"]
    moves: dict[tuple[str, str], tuple[SpecialKind, tuple[str, ...]]] = {}
    for entry, side_b, slide in entries:
        for exit_, slide2, side_a in exits:
            if slide2 != slide:
                continue
            if side_a == side_b:  # a short stick inside a phase in A, or a short slip inside a stick
                moves[(entry, exit_)] = (SpecialKind.GRAZING_SLIDING, ())
                moves[(exit_, entry)] = (SpecialKind.ADDING_SLIDING, ())
            elif (side_b, side_a) in by_ends:  # a short stick between B and A, or the crossing
                moves[(entry, exit_)] = (SpecialKind.CROSSING_SLIDING, (by_ends[(side_b, side_a)],))
    for cross, side_b, side_a in crossings:
        for entry, side, slide in entries:
            if side == side_a and (side_b, slide) in by_ends:  # a short excursion into A, or the entry
                moves[(cross, entry)] = (SpecialKind.SWITCHING_SLIDING, (by_ends[(side_b, slide)],))
    return moves


def _same_cycle(x: tuple[str, ...], y: tuple[str, ...]) -> bool:
    """Whether ``x`` and ``y`` are the same cyclic sequence (one a rotation of the other)."""
    return len(x) == len(y) and (not x or any(x[i:] + x[:i] == y for i in range(len(x))))


def _reductions(
    moves: dict[tuple[str, str], tuple[SpecialKind, tuple[str, ...]]],
    less: tuple[str, ...],
    more: tuple[str, ...],
) -> list[tuple[SpecialKind, list[tuple[int, int]]]]:
    """Every way of reducing the cyclic sequence ``more`` to ``less`` by at most :data:`MAX_MOVES` moves
    of one kind: ``(kind, windows)``, each window the indices in ``more`` of its two switches (where it
    holds switches of ``more``)."""
    found: list[tuple[SpecialKind, list[tuple[int, int]]]] = []

    def walk(seq: list[Item], kind: SpecialKind | None, windows: list[tuple[int, int]], depth: int) -> None:
        if kind is not None and _same_cycle(tuple(n for _, n in seq), less):
            found.append((kind, windows))
            return
        if depth == MAX_MOVES or len(seq) <= len(less) or len(seq) < 2:
            return
        for i in range(len(seq)):
            j = (i + 1) % len(seq)
            move = moves.get((seq[i][1], seq[j][1]))
            if move is None or (kind is not None and move[0] is not kind):
                continue
            rest = [seq[k] for k in range(len(seq)) if k not in (i, j)]
            at = i if j > i else i - 1  # (where the window was, in ``rest``)
            left = rest[:at] + [(None, n) for n in move[1]] + rest[at:]
            first, second = seq[i][0], seq[j][0]
            window = [(first, second)] if first is not None and second is not None else []
            walk(left, move[0], windows + window, depth + 1)

    walk(list(enumerate(more)), None, [], 0)
    return found


def kind_of_change(
    model: HybridModel, a: Signature, b: Signature, *, gaps: tuple[np.ndarray, np.ndarray] | None = None
) -> SpecialKind | None:
    """The sliding bifurcation where the switches per period of ``model``'s orbits change from ``a`` to
    ``b`` (see the module's docstring), or None where the change involves no sliding, fits none of the
    four moves, or fits moves of several kinds that ``gaps`` do not tell apart.

    Parameters
    ----------
    model
        The model.
    a, b
        The switches of the two orbits (:attr:`~grazing.orbits.periodic.PeriodicOrbit.switch_signature`).
    gaps
        The time from each switch to the next (cyclically over the orbit's period), of ``a`` and of
        ``b``, in their order: where the names fit moves of several kinds, the kind whose windows last
        shortest (the window that vanishes at the bifurcation).

    Returns
    -------
    SpecialKind or None
        The bifurcation's kind.
    """
    moves = _moves(model)
    flat = [tuple(n for p in sig for n in p) for sig in (a, b)]
    best: tuple[float, SpecialKind] | None = None
    kinds = set()
    for less, more in ((0, 1), (1, 0)):
        for kind, windows in _reductions(moves, flat[less], flat[more]):
            kinds.add(kind)
            if gaps is not None and windows:
                width = max(float(gaps[more][i]) for i, _ in windows)
                if best is None or width < best[0]:
                    best = (width, kind)
    if len(kinds) == 1:
        return kinds.pop()
    return best[1] if best is not None and len(kinds) > 1 else None


def switch_gaps(orbit: PeriodicOrbit) -> np.ndarray:
    """The time from each of ``orbit``'s switches to the next, cyclically over its period."""
    t = np.asarray(orbit.switch_times, dtype=float)
    if not t.size:
        return t
    return np.diff(np.append(t, t[0] + orbit.period * orbit.model.period))


def sliding_kind(a: PeriodicOrbit, b: PeriodicOrbit) -> SpecialKind | None:
    """The sliding bifurcation between two orbits of a branch whose switches differ: :func:`kind_of_change`
    of their :attr:`~grazing.orbits.periodic.PeriodicOrbit.switch_signature`, told apart by the duration
    of the windows where the names fit several kinds (:func:`switch_gaps`)."""
    return kind_of_change(
        a.model, a.switch_signature, b.switch_signature, gaps=(switch_gaps(a), switch_gaps(b))
    )


@dataclass(frozen=True, kw_only=True)
class SwitchBracket:
    """The narrowest bracket of a change of switches found by :func:`bisect_switches`.

    Attributes
    ----------
    before, after
        The orbits on either side (``before`` with the switches of the branch's side).
    steps
        The bisection steps taken.
    complete
        True where the bracket reached :data:`BISECTION_TOL`; False where an orbit between had neither
        side's switches (or was not found), which ends the bisection.
    """

    before: PeriodicOrbit
    after: PeriodicOrbit
    steps: int
    complete: bool

    def interval(self, param: str) -> tuple[float, float]:
        """The parameter's bracket, lowest first."""
        p, q = self.before.model.params[param], self.after.model.params[param]
        return (min(p, q), max(p, q))


def bisect_switches(before: PeriodicOrbit, after: PeriodicOrbit, param: str) -> SwitchBracket:
    """Narrow the change of switches between ``before`` and ``after`` (orbits at two values of ``param``)
    by bisection: the orbit at the midpoint (:func:`~grazing.orbits.shooting.find_orbit` from the nearer
    side's state) replaces the side whose switches it has."""
    steps = 0
    while steps < BISECTION_STEPS:
        p, q = before.model.params[param], after.model.params[param]
        if abs(q - p) <= BISECTION_TOL * max(1.0, abs(p)):
            return SwitchBracket(before=before, after=after, steps=steps, complete=True)
        mid = 0.5 * (p + q)
        if mid in (p, q):
            return SwitchBracket(before=before, after=after, steps=steps, complete=True)
        steps += 1
        found = None
        for side in (before, after):
            try:
                o = find_orbit(
                    side.model.with_params(**{param: mid}), side.state, period=side.period, t0=side.t0,
                    mode=side.mode,
                )  # fmt: skip
            except GrazingError:
                continue
            if (
                o.switch_signature in (before.switch_signature, after.switch_signature)
                and o.mode == side.mode
            ):
                found = o
                break
        if found is None:
            break
        if found.switch_signature == before.switch_signature:
            before = found
        else:
            after = found
    return SwitchBracket(before=before, after=after, steps=steps, complete=False)
