"""The sliding bifurcations of a periodic orbit, named from the change of its switches along a branch.

On a model with a sliding surface (a Filippov system) a branch of periodic orbits keeps its switches of
mode (:attr:`~grazing.orbits.periodic.PeriodicOrbit.switch_signature`: the transitions, then each sliding
pseudo-mode's entries and exits) up to a boundary where the orbit meets the boundary of the sliding
region, where the far side's field is tangent to the surface (di Bernardo, Budd, Champneys & Kowalczyk,
*Piecewise-smooth Dynamical Systems*, 2008, ch. 8; Kuznetsov, Rinaldi & Gragnani, *Int. J. Bifurcation
Chaos* 13, 2003).  How the switches differ across it names the bifurcation (:func:`sliding_kind`):

* **crossing-sliding**: the orbit reaches the surface at the tangency point; on one side it enters
  sliding there, on the other it crosses (and comes back to the surface further on): an entry into
  sliding from a mode is replaced by a crossing out of that mode;
* **grazing-sliding**: the orbit touches the surface from outside at the tangency point: a sliding
  segment (an entry from a mode and an exit) appears where there was none;
* **adding-sliding**: the same, on the segment that leaves a sliding segment: the orbit leaving sliding
  comes back to the surface, a second sliding segment is added right after an exit to that mode;
* **switching-sliding**: the orbit leaves sliding at the boundary of the sliding region: on one side
  it leaves into the far side at once, on the other into the near side and crosses the surface soon
  after (an exit to ``Y`` replaced by an exit to ``X`` and a crossing from ``X`` to ``Y``).

The boundary itself is bracketed by the continuation (its parameter to
:data:`~grazing.core.options.BOUNDARY_TOL`) and narrowed by bisection on the switches of the orbits found
between (:func:`bisect_switches`).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

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


def _roles(m: HybridModel) -> dict[str, tuple[str, str, str]]:
    """Each switch name's ``(role, source, target)``: role ``"entry"`` (into a sliding pseudo-mode),
    ``"exit"`` (out of one) or ``"cross"`` (between two modes)."""
    sliding = set(m.sliding_names)
    roles = {}
    for name, src, tgt in zip(m.switch_names, m.switch_sources, m.switch_targets):
        role = "entry" if tgt in sliding else "exit" if src in sliding else "cross"
        roles[name] = (role, src, tgt)
    return roles


def sliding_kind(a: PeriodicOrbit, b: PeriodicOrbit) -> SpecialKind | None:
    """The sliding bifurcation between two orbits of a branch whose switches differ: :func:`kind_of_change`
    of their :attr:`~grazing.orbits.periodic.PeriodicOrbit.switch_signature`."""
    return kind_of_change(a.model, a.switch_signature, b.switch_signature)


def kind_of_change(
    model: HybridModel, a: tuple[tuple[str, ...], ...], b: tuple[tuple[str, ...], ...]
) -> SpecialKind | None:
    """The sliding bifurcation where the switches per period of ``model``'s orbits change from ``a`` to
    ``b`` (see the module's docstring), or None where the change involves no entry into or exit from
    sliding, or fits none of the four patterns.

    The rules are tried in this order on the switches per period, ``a``'s and ``b``'s, in either order:
    an entry from a mode replaced by a crossing out of it (crossing-sliding); one sequence is the other
    with an entry and an exit more (adding-sliding where the entry follows an exit to its mode,
    grazing-sliding otherwise); an exit to a mode ``Y`` replaced by an exit to ``X`` followed by a
    crossing from ``X`` to ``Y``, or such a crossing gained right after an exit (switching-sliding).
    """
    roles = _roles(model)
    flat = [[n for p in sig for n in p] for sig in (a, b)]
    count = [Counter(f) for f in flat]
    diff = (count[0] - count[1], count[1] - count[0])
    for less, more in ((0, 1), (1, 0)):
        lost, gained = diff[less], diff[more]  # (what ``more`` lacks of ``less``; what it has more)
        lost_entries = {roles[n][1] for n in lost if roles[n][0] == "entry"}
        gained_crossings = {roles[n][1] for n in gained if roles[n][0] == "cross"}
        if lost_entries & gained_crossings:
            return SpecialKind.CROSSING_SLIDING
    for less, more in ((0, 1), (1, 0)):
        lost, gained, seq = diff[less], diff[more], flat[more]
        after = {n: [seq[i - 1] for i, m in enumerate(seq) if m == n] for n in gained}  # (cyclically)
        if not lost and sorted(roles[n][0] for n in gained.elements()) == ["entry", "exit"]:
            (entry,) = [n for n in gained if roles[n][0] == "entry"]
            source = roles[entry][1]
            after_exit = any(roles[p][0] == "exit" and roles[p][2] == source for p in after[entry])
            return SpecialKind.ADDING_SLIDING if after_exit else SpecialKind.GRAZING_SLIDING
        crossings = [n for n in gained if roles[n][0] == "cross"]
        if len(crossings) != 1 or sum(gained.values()) > 2 or sum(lost.values()) > 1:
            continue
        (cross,) = crossings
        _, source, target = roles[cross]
        exits = [p for p in after[cross] if roles[p][0] == "exit" and roles[p][2] == source]
        others = [n for n in gained if n != cross]
        # exit_to_Y replaced by exit_to_X then a crossing X -> Y (or that crossing alone gained)
        replaced = all(roles[n][0] == "exit" and roles[n][2] == target for n in lost) and all(
            n in exits for n in others
        )
        if exits and replaced and len(others) == len(lost):
            return SpecialKind.SWITCHING_SLIDING
    return None


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
