"""The grazing of a switching surface, located by multiple shooting (segments cut at switches).

A strongly unstable orbit of a model without resets is followed by multiple shooting on its switches
(:mod:`grazing.orbits.segments`).  Where such an orbit is about to lose a brief excursion through
another mode (into it through one transition's guard and straight back), the segmented equations
become singular: the excursion's segment shrinks to nothing and its two switches meet, so the
continuation stalls there.  The single-shooting grazing equations
(:func:`~grazing.orbits.contact.refine_grazing`) cannot be solved on such an orbit either (their
residual's rounding is ``|M| eps |x|``).  Here the grazing orbit is solved on segments: the excursion's
two switches are replaced by one cut, a *contact* (:attr:`~grazing.orbits.segments.SegmentLayout.contact`)
where the orbit touches the guard of the transition into the excursion, tangent to it in the
transition's source mode (``h = 0``, ``L_f h = 0``), with the parameter an unknown: a square system,
each of its entries one segment's, rounded as a segment is.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from grazing.orbits.contact import CONTACT_MAX_NEWTON, CONTACT_TOL, GrazingPoint
from grazing.orbits.palc import PalcSettings, newton
from grazing.orbits.periodic import PeriodicOrbit, sorted_multipliers
from grazing.orbits.segments import ContactRun, cuts_at_switches, layout_of, segmented_equations, switch_rates

EXTRAPOLATION_POINTS = 4
"""The last points of a stalled branch whose excursion times :func:`extrapolated_grazing` fits (the
briefest excursions, where the series in the excursion time converges fastest)."""


def excursions(orbit: PeriodicOrbit) -> list[tuple[int, float]]:
    """``(i, stay)`` for each of the orbit's excursions out of a mode and straight back, between its
    switches ``i`` and ``i + 1`` (over one period from its section; ``stay`` the time between them), in
    order (an excursion across the section is not looked at)."""
    m, times, js = orbit.model, orbit.switch_times, orbit.switch_transitions
    found: list[tuple[int, float]] = []
    for i in range(len(js) - 1):
        a, b = int(js[i]), int(js[i + 1])
        if b >= m.n_stops or a >= m.n_stops:
            continue
        back = (
            m.transition_source[b] == m.transition_target[a]
            and m.transition_target[b] == m.transition_source[a]
        )
        if back:
            found.append((i, float(times[i + 1] - times[i])))
    return found


def brief_excursion(orbit: PeriodicOrbit) -> tuple[int, float] | None:
    """``(i, stay)``: the orbit's briefest excursion (:func:`excursions`); None without one."""
    found = excursions(orbit)
    return min(found, key=lambda e: e[1]) if found else None


def extrapolated_grazing(
    orbits: list[PeriodicOrbit], values: list[float], i: int
) -> tuple[float, float] | None:
    """``(p, precision)``: the parameter where the excursion between switches ``i`` and ``i + 1`` of the last
    of ``orbits`` (a branch's points, at ``values`` of its parameter) shrinks to nothing, extrapolated from
    the last :data:`EXTRAPOLATION_POINTS` points' excursion times through the same two transitions.

    An excursion of depth ``d`` past a surface that the field turns back from lasts ``s = 2 sqrt(2 d / a)``
    (``a = L_f^2 h``) and ``d`` is linear in the parameter near the grazing ``p*``, so
    ``p = p* + k s^2 + O(s^4)``: fitted in ``(1, s^2, s^4)`` by least squares.  ``precision``: the
    largest of the fit's residuals and its difference from the fit in ``(1, s^2)`` of the last three
    points.  None with fewer points through that excursion."""
    last = orbits[-1]
    pair = tuple(int(j) for j in last.switch_transitions[i : i + 2])
    rows: list[tuple[float, float]] = []
    for o, v in zip(orbits[-EXTRAPOLATION_POINTS:], values[-EXTRAPOLATION_POINTS:]):
        stays = [
            st for k, st in excursions(o) if tuple(int(j) for j in o.switch_transitions[k : k + 2]) == pair
        ]
        if len(stays) == 1:
            rows.append((stays[0] ** 2, v))
    if len(rows) < 4:
        return None
    s2, p = np.array(rows).T
    scale = float(np.max(s2))
    A = np.stack([np.ones_like(s2), s2 / scale, (s2 / scale) ** 2], axis=1)
    coef, *_ = np.linalg.lstsq(A, p, rcond=None)
    lin, *_ = np.linalg.lstsq(A[-3:, :2], p[-3:], rcond=None)
    precision = max(float(np.max(np.abs(A @ coef - p))), abs(float(coef[0] - lin[0])))
    return float(coef[0]), precision


def locate_segmented_grazing(orbit: PeriodicOrbit, param: str, reach: float) -> GrazingPoint | None:
    """The grazing orbit where ``orbit``'s briefest excursion (:func:`brief_excursion`) shrinks to a
    contact, solved for ``param`` by multiple shooting on its other switches, from ``orbit`` with the
    excursion's two switches merged into one cut half-way between them.  That start must be near the
    grazing already (the end of a branch, where the excursion has shrunk until the segmented equations
    stalled): from an orbit whose excursion is long, the segment to the contact crosses the surface
    before it (the contact's guard has moved with ``param``) and Newton's method fails.  None where the
    model's segments are not cut at switches, the orbit has no such excursion, Newton's method fails, or
    the grazing found is farther than ``reach`` from ``orbit``'s value of ``param``, turns into the guard
    (``L_f^2 h <= 0``) or is not a motion of the system (a switch crossed at no rate or backwards).

    Its :attr:`~grazing.orbits.contact.GrazingPoint.precision` is the parameter component of the Newton
    step that would follow the last.
    """
    m = orbit.model
    if not cuts_at_switches(m) or orbit.switch_states is None or orbit.impacts:
        return None
    found = brief_excursion(orbit)
    if found is None:
        return None
    i, _ = found
    layout = layout_of(orbit)
    if not layout.switches:
        return None
    stops = (*layout.stops[: i + 1], *layout.stops[i + 2 :])
    contact = dataclasses.replace(layout, stops=stops, contact=i)
    states, times = orbit.switch_states, orbit.switch_times
    parts = [orbit.state]
    for k in range(len(times)):
        if k == i:  # (the contact: half-way through the excursion)
            parts += [np.array([0.5 * (times[i] + times[i + 1])]), 0.5 * (states[i] + states[i + 1])]
        elif k != i + 1:
            parts += [np.array([times[k]]), np.asarray(states[k], dtype=float)]
    p0 = m.params[param]
    u0 = np.concatenate([*parts, [p0]])
    evaluate = segmented_equations(m, param, orbit.period, orbit.t0, contact, orbit.stop)
    pt = newton(evaluate, u0, PalcSettings(tol=CONTACT_TOL, max_newton=CONTACT_MAX_NEWTON))
    if pt is None:
        return None
    run: ContactRun = pt.payload
    pg = float(pt.u[-1])
    if not abs(pg - p0) <= reach or not run.accel > 0:
        return None
    crossings = [k for k in range(len(stops)) if k != i]
    rates = switch_rates(
        run.model,
        [pt.u[contact.time_index(k + 1)] for k in crossings],
        [contact.state(pt.u, k + 1) for k in crossings],
        [stops[k] for k in crossings],
    )
    if crossings and min(rates) <= 0.0:
        return None
    try:
        precision = abs(float(np.linalg.solve(pt.DF, pt.F)[-1]))
    except np.linalg.LinAlgError:
        precision = float("nan")
    return GrazingPoint(
        model=run.model, contact=run.contact, t_graze=run.t_contact, monodromy=run.monodromy,
        multipliers=sorted_multipliers(run.monodromy), accel=run.accel, period=orbit.period, impacts=0,
        stop=run.transition, precision=precision, mode=m.transition_source[run.transition],
        switches=run.switches,
    )  # fmt: skip
