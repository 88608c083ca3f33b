"""Branch switching: the first orbit of each branch that starts at a special point of a branch.

* At a period-doubling of a period-``n`` orbit ``x*`` (multiplier -1, eigenvector
  ``v``) the period-``2n`` orbit is born: ``x*`` is a branch point of the doubled
  map ``P^(2n)(x) - x`` (its multiplier ``(-1)^2 = 1``), whose other branch
  leaves ``x*`` along ``v``.  Its first point solves ``P^(2n)(x; p) = x`` with
  ``v . (x - x*) = eps`` (Newton's method for ``x`` and ``p``), and is not the
  period-``n`` orbit (``P^n(x) != x``).
* At a branch point ``u*`` the Jacobian ``[P_x - I, P_p]`` has a two-dimensional
  null space, spanned by the tangent ``t`` of the branch followed and the null
  vector ``w`` orthogonal to it; the other branch leaves along a combination
  ``a t + b w`` with ``b != 0``.  Its first points are corrected from
  ``u* +- eps w`` on the hyperplanes orthogonal to ``w``, which it crosses
  (the branch followed, tangent to them, does not nearby): both directions,
  for a symmetry-breaking pitchfork the two mirror images.
* At a grazing where the impact sequence changes, the orbit with the new
  sequence just past it (:func:`new_sequence_orbit`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grazing.errors import GrazingError
from grazing.orbits.branch_equations import BranchEquations, branch_equations
from grazing.orbits.palc import PalcSettings, correct, newton
from grazing.orbits.shooting import PeriodicOrbit, find_orbit

SWITCH_STEPS = (1e-3, 1e-2, 1e-4)
"""Distances from a period-doubling or branch point (relative to ``max(1, |u|)``) at which the new
branch's first point is sought, in this order."""

IN_NULL_SPACE = 1e-3
"""At a branch point the tangent of the branch followed lies in the two-dimensional null space of the
equations' Jacobian: its component there is at least this fraction of it, or the point is not a branch
point (the null space computed is of a nearly singular Jacobian elsewhere)."""

PAST_GRAZING = (1e-7, 1e-6, 1e-5, 1e-4)
"""Distances past a grazing (relative to ``max(1, |value|)``) at which an orbit with the new impact
sequence is sought, nearest first: beyond the grazing's own error (the boundary is bracketed to
:data:`~grazing.core.options.BOUNDARY_TOL`), and close enough that the orbit past it is the grazing
orbit's continuation."""


CROSSING_SLOPE = 10.0
"""A branch crossing at a branch point is followed if it leaves it at an angle whose cotangent to the
direction ``w`` (orthogonal to the branch followed) is at most this (about 6 degrees from it or more)."""


@dataclass(frozen=True, kw_only=True)
class SegmentStart:
    """Where a segment of a branch starts.

    Attributes
    ----------
    orbit
        Its first orbit.
    sign
        The direction in which the parameter moves first (used without ``direction``).
    direction
        The direction in ``u = (x, p)`` in which the segment leaves its origin (a switch at a
        period-doubling or branch point: away from it), or None.
    origin
        The special point it starts from (its index in the branch's ``special``; -1: the
        continuation's start).
    """

    orbit: PeriodicOrbit
    sign: float
    direction: np.ndarray | None = None
    origin: int = -1


def doubled_start(
    orbit: PeriodicOrbit, param: str, s: PalcSettings
) -> tuple[PeriodicOrbit, np.ndarray] | None:
    """The period-``2n`` orbit next to the period-doubling ``orbit`` (period ``n``), and the direction
    ``u - u*`` in which it lies from it; None if Newton's method does not find one.

    The model of ``orbit`` carries the parameter's value at the period-doubling.
    """
    n = orbit.period
    mu, vectors = np.linalg.eig(orbit.monodromy)
    v = np.real(vectors[:, int(np.argmin(np.abs(mu + 1.0)))])
    v /= np.linalg.norm(v)
    row = np.append(v, 0.0)
    u_star = np.append(orbit.state, orbit.model.params[param])
    doubled = branch_equations(orbit.model, param, 2 * n, orbit.t0, orbit.virtual, orbit.stop, orbit.mode)
    single = branch_equations(orbit.model, param, n, orbit.t0, orbit.virtual, orbit.stop, orbit.mode)
    scale = max(1.0, float(np.linalg.norm(u_star)))
    for step in SWITCH_STEPS:
        eps = step * scale
        for sign in (1.0, -1.0):
            u0 = u_star + sign * eps * row

            def pinned(u: np.ndarray, u0: np.ndarray = u0) -> tuple[np.ndarray, np.ndarray, PeriodicOrbit]:
                F, DF, o = doubled(u)
                return np.append(F, row @ (u - u0)), np.vstack([DF, row]), o

            pt = newton(pinned, u0, s)
            if pt is None:
                continue
            try:
                F1 = single(pt.u)[0]
            except GrazingError:
                continue
            if float(np.max(np.abs(F1))) < 0.5 * eps:
                continue  # the period-n orbit itself (P^n(x) = x)
            return pt.payload, pt.u - u_star
    return None


def crossing_starts(
    evaluate: BranchEquations, u_star: np.ndarray, along: np.ndarray, s: PalcSettings
) -> list[tuple[PeriodicOrbit, np.ndarray]]:
    """The first orbits of the branch that crosses, at the branch point ``u_star``, the branch
    followed along ``along``, in both directions: ``(orbit, direction)`` pairs (none found: empty).
    """
    try:
        _, DF, _ = evaluate(u_star)
    except GrazingError:
        return []
    _, _, vt = np.linalg.svd(DF)
    null = vt[-2:]  # the two right singular vectors of the smallest singular values (one is zero)
    c = null @ along
    if float(np.linalg.norm(c)) < IN_NULL_SPACE * float(np.linalg.norm(along)):
        return []  # the branch followed does not lie in the null space: not a branch point
    w = null.T @ np.array([-c[1], c[0]])
    w /= np.linalg.norm(w)
    scale = max(1.0, float(np.linalg.norm(u_star)))
    starts = []
    for sign in (1.0, -1.0):
        for step in SWITCH_STEPS:
            eps = step * scale
            u_pred = u_star + sign * eps * w
            pt = correct(evaluate, u_pred, w, s)
            # The other branch leaves along a null vector a t + b w (b != 0): the hyperplane meets it
            # a distance eps |a / b| from the prediction; the branch followed, only ~sqrt(eps) away.
            if pt is not None and float(np.linalg.norm(pt.u - u_pred)) < CROSSING_SLOPE * eps:
                starts.append((pt.payload, pt.u - u_star))
                break
    return starts


def new_sequence_orbit(
    last: PeriodicOrbit, param: str, value: float, direction: float, virtual: bool
) -> PeriodicOrbit | None:
    """An orbit with another impact signature than ``last`` (or, on a model with modes, other switches:
    :attr:`~grazing.orbits.periodic.PeriodicOrbit.switch_signature`), just past the grazing at ``value``."""
    p = last.model.params[param]
    par = next(q for q in last.model.parameters if q.name == param)
    for sign in (direction, -direction):
        for eps in PAST_GRAZING:
            trial = value + sign * eps * max(1.0, abs(value))
            try:
                par.check(trial)
                orbit = find_orbit(
                    last.model.with_params(**{param: trial}), last.state, period=last.period, t0=last.t0,
                    virtual=virtual, stop_name=last.stop, mode=last.mode,
                )  # fmt: skip
            except GrazingError:
                continue
            other = orbit.signature != last.signature or orbit.switch_signature != last.switch_signature
            if other and abs(trial - p) > 0:
                return orbit
    return None
