"""The smooth bifurcations of a branch of periodic orbits between two of its points, and their account.

Test functions, each smooth along a branch of one impact signature, change sign
between two consecutive points ``a`` and ``b`` where a special point lies
between them:

* ``det(P_x - I)``: a multiplier passes through +1 (an odd number of times);
* the parameter component of the branch's unit tangent: the parameter turns
  (a fold);
* ``det([[P_x - I, P_p], [t^T]])``, the Jacobian of the pseudo-arclength
  system with the tangent ``t`` (oriented continuously along the branch):
  zero where the Jacobian ``[P_x - I, P_p]`` has a two-dimensional null space,
  a branch point where another branch crosses this one (symmetry breaking,
  transcritical); it does not change sign at a fold (Keller 1977; Kuznetsov,
  *Elements of Applied Bifurcation Theory*, sec. 10.2);
* ``det(P_x + I)``: a multiplier passes through -1 (period-doubling);
* ``det(P_x) - 1`` with a complex pair: a pair crosses the unit circle
  (Neimark-Sacker; 2-D maps).

A multiplier through +1 where the parameter turns is a fold; where the
pseudo-arclength determinant changes sign it is a branch point (the parameter
does not turn on a branch that crosses another transversally; it does on the
curved branch of a pitchfork, which crosses the straight one where its
multiplier touches +1).  Each is located by regula falsi along the secant
(:func:`~grazing.orbits.palc.locate`) to Newton tolerance and checked against
its defining condition.

The account: the number of multipliers outside the unit circle changes by one
at a fold, at a branch point where the parameter does not turn and at a
period-doubling, by none at a branch point where it turns, and by two at a
Neimark-Sacker point; a multiplier within ``core.options.UNIT_CIRCLE_TOL`` of the
circle is on it, not outside (an area-preserving map, of a conservative model,
keeps its complex pairs there, and ``det(P_x) - 1`` is then no test function:
:data:`AREA_PRESERVING_TOL`).  A change between two points that the located points do
not explain, or a test function that changed sign where no point could be
located, is an *unlocated* stability change, reported as such: never silent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from grazing.core.options import UNIT_CIRCLE_TOL
from grazing.orbits.branch_equations import BranchEquations
from grazing.orbits.palc import PalcPoint, PalcSettings, locate, locate_by_interpolation, sign_changed
from grazing.orbits.shooting import PeriodicOrbit

SMOOTH_KINDS = ("fold", "branch point", "period-doubling", "neimark-sacker")
"""The special points located between two points of a branch of one impact signature."""

CROSSINGS = {"fold": 1, "branch point": 1, "period-doubling": 1, "neimark-sacker": 2}
"""How many multipliers cross the unit circle at each kind (a branch point where the parameter
turns: none)."""

AREA_PRESERVING_TOL = 2 * UNIT_CIRCLE_TOL
"""Where ``|det(P_x) - 1|`` is below this the map preserves area (a conservative model) and the
Neimark-Sacker test function ``det(P_x) - 1`` says nothing (a pair on the unit circle stays on it)."""

VERIFY_TOL = 1e-5
"""A located point's multiplier must lie this close to its defining value (+1, -1, the unit circle)."""


def orbit_test(kind: str, orbit: PeriodicOrbit) -> float:
    """Test function of a special point (smooth along a branch of one impact signature)."""
    J = orbit.monodromy
    eye = np.eye(J.shape[0])
    if kind == "fold":
        return float(np.linalg.det(J - eye))
    if kind == "period-doubling":
        return float(np.linalg.det(J + eye))
    if kind == "neimark-sacker":
        complex_pair = bool(np.any(np.abs(orbit.multipliers.imag) > 1e-12))
        area = float(np.linalg.det(J) - 1.0)
        # (an area-preserving map keeps a complex pair on the circle: det - 1 is rounding, no test)
        return area if complex_pair and abs(area) > AREA_PRESERVING_TOL else math.nan
    raise ValueError(f"unknown special point kind {kind!r}")


def branch_test(pt: PalcPoint) -> float:
    """``det([[P_x - I, P_p], [t^T]])`` at a point with its oriented tangent: zero at a branch point."""
    assert pt.tangent is not None
    return float(np.linalg.det(np.vstack([pt.DF, pt.tangent])))


def verified(kind: str, orbit: PeriodicOrbit) -> bool:
    """Does a located point satisfy the defining condition of its kind?"""
    mu = orbit.multipliers
    if kind in ("fold", "branch point"):
        return bool(np.min(np.abs(mu - 1.0)) < VERIFY_TOL)
    if kind == "period-doubling":
        return bool(np.min(np.abs(mu + 1.0)) < VERIFY_TOL)
    if kind == "neimark-sacker":
        pair = mu[np.abs(mu.imag) > 1e-12]
        return bool(pair.size and np.min(np.abs(np.abs(pair) - 1.0)) < VERIFY_TOL)
    return True


def unstable_count(orbit: PeriodicOrbit) -> int:
    """The number of multipliers outside the unit circle (0: the orbit is stable; see ``UNIT_CIRCLE_TOL``)."""
    return orbit.unstable_count


@dataclass(frozen=True)
class Located:
    """A special point located between two consecutive points of a branch.

    Attributes
    ----------
    kind
        One of :data:`SMOOTH_KINDS`.
    point
        The located point of the branch (its ``u = (x, p)``, Jacobian, tangent, orbit).
    turns
        The parameter turns there (a fold; a branch point on the curved branch of a pitchfork).
    """

    kind: str
    point: PalcPoint
    turns: bool = False

    @property
    def crossings(self) -> int:
        """How many multipliers cross the unit circle there."""
        return 0 if self.kind == "branch point" and self.turns else CROSSINGS[self.kind]


@dataclass(frozen=True)
class Step:
    """What lies between two consecutive points ``a`` and ``b`` of a branch.

    Attributes
    ----------
    located
        The special points located between them, in order along the branch.
    missed
        The kinds whose test function changed sign where no point satisfying the kind's
        condition could be located.
    unstable
        The number of multipliers outside the unit circle at ``a`` and at ``b``.
    """

    located: tuple[Located, ...]
    missed: tuple[str, ...]
    unstable: tuple[int, int]

    @property
    def explained(self) -> bool:
        """Do the located points account for the change of the number of unstable multipliers?

        Each located point moves that number by its :attr:`Located.crossings`, up or down (a
        Neimark-Sacker pair by two, never by none): the change must be such a sum, and no test
        function may have changed sign without its point.
        """
        reachable = {0}
        for loc in self.located:
            reachable = {total + sign * loc.crossings for total in reachable for sign in (1, -1)}
        return not self.missed and self.unstable[1] - self.unstable[0] in reachable

    def describe(self) -> str:
        """What happened over the step, in words (for the ``unlocated`` special point)."""
        parts = [" -> ".join(_outside(n) for n in self.unstable)]
        if self.located:
            parts.append("located: " + ", ".join(loc.kind for loc in self.located))
        for kind in self.missed:
            parts.append(f"{_MISSED[kind]}, not located")
        return "; ".join(parts)


def _outside(n: int) -> str:
    return "stable" if n == 0 else f"{n} multiplier{'s' * (n > 1)} outside the unit circle"


_MISSED = {
    "fold": "the parameter turns (a fold)",
    "branch point": "the pseudo-arclength determinant changes sign (a branch point)",
    "fold or branch point": "a multiplier passes through +1 (det(P_x - I) changes sign) where the parameter "
    "does not turn and no branch point is detected",
    "period-doubling": "a multiplier passes through -1 (det(P_x + I) changes sign)",
    "neimark-sacker": "a complex pair crosses the unit circle (det(P_x) - 1 changes sign)",
}


def between(evaluate: BranchEquations, a: PalcPoint, b: PalcPoint, s: PalcSettings, index: int) -> Step:
    """Locate the smooth special points between consecutive points ``a`` and ``b`` of a branch.

    ``index`` is the parameter's component in ``u``.  Both points carry their orbit
    (``payload``) and their tangent, oriented continuously along the branch.
    """
    assert a.tangent is not None and b.tangent is not None
    oa, ob = a.payload, b.payload
    found: list[Located] = []
    missed: list[str] = []
    through_one = sign_changed(orbit_test("fold", oa), orbit_test("fold", ob))
    turns = sign_changed(float(a.tangent[index]), float(b.tangent[index]))
    if sign_changed(branch_test(a), branch_test(b)):
        loc = locate_by_interpolation(evaluate, a, b, branch_test, s)
        if loc is not None and verified("branch point", loc.payload):
            # The null space is two-dimensional there: the branch's tangent is the one on both sides.
            along = a.tangent + b.tangent
            loc.tangent = along / np.linalg.norm(along)
            found.append(Located("branch point", loc, turns))
        else:
            missed.append("branch point")
    elif turns:
        # (located by det(P_x - I) where it changes sign: the point where the multiplier is 1)
        if through_one:
            loc = locate(evaluate, a, b, lambda p: orbit_test("fold", p.payload), s)
        else:
            loc = locate(evaluate, a, b, lambda p: float(p.tangent[index]), s)  # type: ignore[index]
        if loc is not None and verified("fold", loc.payload):
            found.append(Located("fold", loc, True))
        else:
            missed.append("fold")
    elif through_one:
        missed.append("fold or branch point")
    for kind in ("period-doubling", "neimark-sacker"):
        if not sign_changed(orbit_test(kind, oa), orbit_test(kind, ob)):
            continue
        loc = locate(evaluate, a, b, lambda p, k=kind: orbit_test(k, p.payload), s)  # type: ignore[misc]
        if loc is not None and verified(kind, loc.payload):
            found.append(Located(kind, loc))
        else:
            missed.append(kind)
    found.sort(key=lambda loc: float(np.linalg.norm(loc.point.u - a.u)))
    return Step(tuple(found), tuple(missed), (unstable_count(oa), unstable_count(ob)))
