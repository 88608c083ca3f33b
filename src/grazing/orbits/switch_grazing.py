"""The grazing of a switching surface, located between two orbits whose switches of mode differ.

On a model with modes a branch ends where its orbits gain or lose a pair of
switches (into a mode through a transition's guard and back out): the orbit
there touches the guard of that transition tangentially, in the transition's
source mode (:func:`~grazing.orbits.contact.contact_system`).  Of the two
orbits on either side, the one with the extra pair passes briefly through the
other mode; where it crosses the guard is the guess for the contact, and
Newton's method on the grazing equations locates it exactly.
"""

from __future__ import annotations

import numpy as np

from grazing.errors import GrazingError
from grazing.maps import flow_map
from grazing.orbits.contact import GrazingPoint, refine_grazing
from grazing.orbits.periodic import PeriodicOrbit


def brief_crossing(orbit: PeriodicOrbit, transition: int) -> tuple[np.ndarray, float, float] | None:
    """``(state, time, stay)`` where ``orbit`` crosses the guard of ``transition`` for its shortest stay on
    the other side (``stay``: until its next switch of mode, over the orbit's period); None without a
    crossing."""
    sw = flow_map(
        orbit.model, orbit.state, t0=orbit.t0, periods=orbit.period, mode=orbit.mode
    ).solution.switches
    if sw is None or not len(sw):
        return None
    t_end = orbit.t0 + orbit.period * orbit.model.period
    stays = [
        ((sw.t[i + 1] if i + 1 < len(sw) else sw.t[0] + (t_end - orbit.t0)) - sw.t[i], i)
        for i in range(len(sw))
        if sw.transition[i] == transition
    ]
    if not stays:
        return None
    stay, i = min(stays)
    return sw.state[i].copy(), float(sw.t[i]), float(stay)


def grazed_transition(last: PeriodicOrbit, beyond: PeriodicOrbit) -> int | None:
    """The transition whose guard is grazed between ``last`` and ``beyond`` (orbits at two values of a
    parameter whose switches of mode differ): of the transitions whose counts of switches differ, the one
    crossed for the briefest stay on the other side by the orbit that has more of them (that stay shrinks
    to zero at the grazing).  A brief excursion out of a mode and back crosses two transitions' guards,
    the grazed one first (into the excursion: a ``leave`` when an orbit in contact briefly leaves it), so
    the first whose count differs in the model's order is not always the one grazed.  None where no
    transition's count differs."""
    best: tuple[float, int] | None = None
    for j in range(last.model.n_stops):
        counts = [int(np.count_nonzero(o.switch_transitions == j)) for o in (last, beyond)]
        if counts[0] == counts[1]:
            continue
        found = brief_crossing(last if counts[0] > counts[1] else beyond, j)
        if found is not None and (best is None or found[2] < best[0]):
            best = (found[2], j)
    return None if best is None else best[1]


def locate_switch_grazing(
    last: PeriodicOrbit, beyond: PeriodicOrbit, param: str, transition: int, slack: float
) -> GrazingPoint | None:
    """The grazing of ``transition``'s guard between ``last`` and ``beyond`` (orbits at two values of
    ``param`` whose counts of ``transition``'s switches differ), solved from the brief crossing of the
    orbit that has more; None where Newton's method fails or the grazing found lies outside the two
    values (by more than ``slack`` times ``max(1, |value|)``) or turns into the guard (``L_f^2 h <= 0``)."""
    counts = [int(np.count_nonzero(o.switch_transitions == transition)) for o in (last, beyond)]
    if counts[0] == counts[1]:
        return None
    crossing_orbit = last if counts[0] > counts[1] else beyond
    found = brief_crossing(crossing_orbit, transition)
    if found is None:
        return None
    y, tg, _ = found
    try:
        point = refine_grazing(
            crossing_orbit.model,
            y,
            tg,
            param,
            period=crossing_orbit.period,
            events=True,
            stop_name=transition,
        )
    except GrazingError:
        return None
    p, q, pg = last.model.params[param], beyond.model.params[param], point.model.params[param]
    scale = max(1.0, abs(p))
    if not (min(p, q) - slack * scale <= pg <= max(p, q) + slack * scale) or not point.accel > 0:
        return None
    return point
