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
* ``det(P_x (.) P_x - I)``, the bialternate product's (its eigenvalues are the
  products ``mu_i mu_j``, ``i < j``; for two states ``det(P_x) - 1``), as
  ``prod (mu_i mu_j - 1) / (1 + |mu_i mu_j|)``: a complex pair crosses the unit
  circle (Neimark-Sacker), in any dimension.  It also changes sign where two
  real multipliers' product passes through 1 (a *neutral saddle*, ``mu`` and
  ``1/mu``: no multiplier crosses the circle there); a point located where the
  pair is real is that, and neither reported nor missed (Kuznetsov, sec. 10.3;
  MatCont does the same).

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
keeps its complex pairs there, a pair's product is 1 all along, and the
Neimark-Sacker test function is then no test: :data:`AREA_PRESERVING_TOL`).
A change between two points that the located points do not explain, or a test
function that changed sign where no point could be located, is an *unlocated*
stability change, reported as such: never silent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from grazing.core.options import UNIT_CIRCLE_TOL
from grazing.orbits.branch_equations import BranchEquations
from grazing.orbits.kinds import SpecialKind
from grazing.orbits.palc import PalcPoint, PalcSettings, locate, locate_by_interpolation, sign_changed
from grazing.orbits.shooting import PeriodicOrbit

SMOOTH_KINDS = (
    SpecialKind.FOLD, SpecialKind.BRANCH_POINT, SpecialKind.PERIOD_DOUBLING, SpecialKind.NEIMARK_SACKER
)  # fmt: skip
"""The special points located between two points of a branch of one impact signature."""

CROSSINGS = {
    SpecialKind.FOLD: 1,
    SpecialKind.BRANCH_POINT: 1,
    SpecialKind.PERIOD_DOUBLING: 1,
    SpecialKind.NEIMARK_SACKER: 2,
}
"""How many multipliers cross the unit circle at each kind (a branch point where the parameter
turns: none)."""

AREA_PRESERVING_TOL = 2 * UNIT_CIRCLE_TOL
"""Where some product of two multipliers ``mu_i mu_j`` is within this of 1 at both ends of a step the
map preserves area there (a conservative model, or a conservative part of one: ``det(P_x) = 1`` for two
states) and the Neimark-Sacker test function says nothing (a pair on the unit circle stays on it)."""

UNRESOLVED_NORM = 1.0 / (64 * float(np.finfo(float).eps))
"""A monodromy of 2-norm beyond this (the orbit within about ``1e-13`` of a grazing, where a saltation
matrix holds ``1 / v``) resolves no multiplier of order one: its rounding (``64 eps |M|``, as
``orbits.extended.MONODROMY_ROUNDING``) exceeds 1, and the determinants the test functions take are
rounding's.  Between two points of which one is such, no test function is evaluated; the stability
account (the number of multipliers outside the circle) still holds, and a change there that nothing
explains is reported as unlocated."""

VERIFY_TOL = 1e-5
"""A located point's multiplier must lie this close to its defining value (+1, -1, the unit circle)."""


def pair_products(multipliers: np.ndarray) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """The products ``mu_i mu_j`` (``i < j``) of the multipliers, and their index pairs.

    They are the eigenvalues of the bialternate product ``P_x (.) P_x``.

    Examples
    --------
    >>> prods, pairs = pair_products(np.array([2.0, 0.5, 0.25]))
    >>> prods.real.tolist(), pairs
    ([1.0, 0.5, 0.125], [(0, 1), (0, 2), (1, 2)])
    """
    mu = np.asarray(multipliers, dtype=complex)
    pairs = [(i, j) for i in range(mu.size) for j in range(i + 1, mu.size)]
    prods = np.array([mu[i] * mu[j] for i, j in pairs], dtype=complex)
    return prods, pairs


def neimark_sacker_test(multipliers: np.ndarray) -> float:
    """Zero where two multipliers' product is 1, of the sign of ``det(P_x (.) P_x - I)``.

    With the factors ``q_ij = (mu_i mu_j - 1) / (1 + |mu_i mu_j|)`` (``i < j``; the eigenvalues of
    ``P_x (.) P_x - I``, each scaled into the unit disc): the sign of ``prod q_ij`` (the
    determinant's), times ``min |q_ij|``.  Continuous (where the smallest factor changes, the
    product's sign does not), equal to ``+-q`` of the critical pair near a crossing, so that a
    tolerance on it is one on ``|mu|^2 - 1`` whatever the dimension (the product itself shrinks with
    every factor: 15 for six states).  Its sign changes where a complex pair crosses the unit circle
    (and where a real pair's product passes through 1, a neutral saddle).  For two states
    ``(det P_x - 1) / (1 + |det P_x|)``.  1 for a single multiplier.

    Examples
    --------
    >>> inside = np.array([0.9 * np.exp(0.5j), 0.9 * np.exp(-0.5j), 0.3, -0.2])
    >>> outside = np.array([1.1 * np.exp(0.5j), 1.1 * np.exp(-0.5j), 0.3, -0.2])
    >>> neimark_sacker_test(inside) * neimark_sacker_test(outside) < 0
    True
    >>> round(abs(neimark_sacker_test(np.array([np.exp(1j), np.exp(-1j), 0.5, 0.4]) * (1 + 1e-6))), 9)
    1e-06
    """
    prods, _ = pair_products(multipliers)
    if not prods.size:
        return 1.0
    q = (prods - 1.0) / (1.0 + np.abs(prods))
    return math.copysign(float(np.min(np.abs(q))), float(np.prod(q).real))


def critical_pair(multipliers: np.ndarray) -> tuple[int, int]:
    """The two multipliers whose product is closest to 1 (a Neimark-Sacker point's pair)."""
    prods, pairs = pair_products(multipliers)
    return pairs[int(np.argmin(np.abs(prods - 1.0)))]


def neimark_sacker_angle(multipliers: np.ndarray) -> float:
    """The angle ``arg mu`` in ``(0, pi)`` of the complex pair whose product is closest to 1 (nan: none).

    At a Neimark-Sacker point the pair is ``exp(+-i angle)``; the rotation number of the torus born
    there is near ``angle / (2 pi)`` (strong resonances at ``2 pi / k``, ``k <= 4``).

    Examples
    --------
    >>> round(neimark_sacker_angle(np.array([np.exp(0.7j), np.exp(-0.7j), 0.2])), 12)
    0.7
    """
    mu = np.asarray(multipliers, dtype=complex)
    i, j = critical_pair(mu)
    if not _conjugate_pair(mu[i], mu[j]):
        return math.nan
    return float(abs(np.angle(mu[i])))


def _conjugate_pair(a: complex, b: complex) -> bool:
    """``a`` and ``b`` are a complex-conjugate pair (not two real multipliers)."""
    return abs(a.imag) > COMPLEX_TOL * max(1.0, abs(a)) and abs(a - b.conjugate()) <= 1e-6 * max(1.0, abs(a))


COMPLEX_TOL = 1e-9
"""A multiplier whose imaginary part is below this (relative to ``max(1, |mu|)``) is real."""


def area_preserving(orbit: PeriodicOrbit) -> bool:
    """Some product of two multipliers is 1 to :data:`AREA_PRESERVING_TOL` (no Neimark-Sacker test there)."""
    prods, _ = pair_products(orbit.multipliers)
    return bool(prods.size and np.min(np.abs(prods - 1.0)) <= AREA_PRESERVING_TOL)


def neutral_saddle(orbit: PeriodicOrbit) -> bool:
    """The multipliers' product closest to 1 is of two real ones (``mu``, ``1/mu``): not a bifurcation."""
    mu = orbit.multipliers
    i, j = critical_pair(mu)
    return not _conjugate_pair(mu[i], mu[j]) and abs(mu[i] * mu[j] - 1.0) < VERIFY_TOL


def orbit_test(kind: SpecialKind, orbit: PeriodicOrbit) -> float:
    """Test function of a special point (smooth along a branch of one impact signature)."""
    J = orbit.monodromy
    eye = np.eye(J.shape[0])
    if kind == SpecialKind.FOLD:
        return float(np.linalg.det(J - eye))
    if kind == SpecialKind.PERIOD_DOUBLING:
        return float(np.linalg.det(J + eye))
    if kind == SpecialKind.NEIMARK_SACKER:
        return neimark_sacker_test(resolved_multipliers(orbit))
    raise ValueError(f"unknown special point kind {kind!r}")


def resolved_multipliers(orbit: PeriodicOrbit) -> np.ndarray:
    """The multipliers, those within the monodromy's rounding of zero (``64 eps |M|``) set to zero.

    A multiplier that small is rounding's (the eigenvalues of ``M`` are known to ``eps |M|``): beside
    one of ``1e9`` a multiplier of ``2e-10`` came out as ``1e-7``, and its product with the large one,
    which the Neimark-Sacker test takes, went from ``0.25`` (``det M``) to ``175``: a sign change of the
    test where nothing happened.  Such a multiplier is in no complex pair on the unit circle (its
    conjugate would be as small), so zero loses no Neimark-Sacker point.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> near_grazing = SimpleNamespace(monodromy=np.diag([1.5e9, 1e-7]), multipliers=np.array([1.5e9, 1e-7]))
    >>> resolved_multipliers(near_grazing).real.tolist()
    [1500000000.0, 0.0]
    """
    mu = np.array(orbit.multipliers, dtype=complex)
    mu[np.abs(mu) <= multiplier_floor(orbit.monodromy)] = 0.0
    return mu


def multiplier_floor(monodromy: np.ndarray) -> float:
    """The monodromy's rounding, ``64 eps |M|`` (``|M| / UNRESOLVED_NORM``): a multiplier below it is
    rounding's."""
    return float(np.linalg.norm(monodromy, 2)) / UNRESOLVED_NORM


def branch_test(pt: PalcPoint) -> float:
    """``det([[P_x - I, P_p], [t^T]])`` at a point with its oriented tangent: zero at a branch point."""
    assert pt.tangent is not None
    return float(np.linalg.det(np.vstack([pt.DF, pt.tangent])))


def verified(kind: SpecialKind, orbit: PeriodicOrbit) -> bool:
    """Does a located point satisfy the defining condition of its kind?"""
    mu = orbit.multipliers
    if kind in (SpecialKind.FOLD, SpecialKind.BRANCH_POINT):
        return bool(np.min(np.abs(mu - 1.0)) < VERIFY_TOL)
    if kind == SpecialKind.PERIOD_DOUBLING:
        return bool(np.min(np.abs(mu + 1.0)) < VERIFY_TOL)
    if kind == SpecialKind.NEIMARK_SACKER:
        if mu.size < 2:
            return False
        i, j = critical_pair(mu)
        return _conjugate_pair(mu[i], mu[j]) and abs(abs(mu[i]) - 1.0) < VERIFY_TOL
    return True


def resolved_unstable_count(orbit: PeriodicOrbit) -> int:
    """The multipliers outside the unit circle that the monodromy resolves: those larger than its rounding,
    ``64 eps |M|`` (:data:`UNRESOLVED_NORM`); the others are rounding's, inside the circle or out (at
    ``|M| = 1e24`` the second multiplier of an inverted pendulum came out as 1e8 or 0 depending on the
    BLAS kernel).  Where ``|M|`` is below ``UNRESOLVED_NORM`` it is :func:`unstable_count`.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> at_grazing = SimpleNamespace(monodromy=np.diag([1e24, 3e7]), multipliers=np.array([1e24, 3e7]))
    >>> resolved_unstable_count(at_grazing)
    1
    """
    floor = multiplier_floor(orbit.monodromy)
    mu = np.abs(orbit.multipliers)
    return int(np.sum((mu > 1.0 + UNIT_CIRCLE_TOL) & (mu > floor)))


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

    kind: SpecialKind
    point: PalcPoint
    turns: bool = False

    @property
    def crossings(self) -> int:
        """How many multipliers cross the unit circle there."""
        return 0 if self.kind == SpecialKind.BRANCH_POINT and self.turns else CROSSINGS[self.kind]


@dataclass(frozen=True)
class StepAccount:
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
    SpecialKind.FOLD: "the parameter turns (a fold)",
    SpecialKind.BRANCH_POINT: "the pseudo-arclength determinant changes sign (a branch point)",
    "fold or branch point": "a multiplier passes through +1 (det(P_x - I) changes sign) where the parameter "
    "does not turn and no branch point is detected",
    SpecialKind.PERIOD_DOUBLING: "a multiplier passes through -1 (det(P_x + I) changes sign)",
    SpecialKind.NEIMARK_SACKER: "a complex pair crosses the unit circle (det(P_x (.) P_x - I) changes sign)",
}


def between(
    evaluate: BranchEquations, a: PalcPoint, b: PalcPoint, s: PalcSettings, index: int
) -> StepAccount:
    """Locate the smooth special points between consecutive points ``a`` and ``b`` of a branch.

    ``index`` is the parameter's component in ``u``.  Both points carry their orbit
    (``payload``) and their tangent, oriented continuously along the branch.
    """
    assert a.tangent is not None and b.tangent is not None
    oa, ob = a.payload, b.payload
    found: list[Located] = []
    missed: list[str] = []
    if max(np.linalg.norm(oa.monodromy, 2), np.linalg.norm(ob.monodromy, 2)) > UNRESOLVED_NORM:
        return StepAccount((), (), (resolved_unstable_count(oa), resolved_unstable_count(ob)))
    through_one = sign_changed(orbit_test(SpecialKind.FOLD, oa), orbit_test(SpecialKind.FOLD, ob))
    turns = sign_changed(float(a.tangent[index]), float(b.tangent[index]))
    if sign_changed(branch_test(a), branch_test(b)):
        loc = locate_by_interpolation(evaluate, a, b, branch_test, s)
        if loc is not None and verified(SpecialKind.BRANCH_POINT, loc.payload):
            # The null space is two-dimensional there: the branch's tangent is the one on both sides.
            along = a.tangent + b.tangent
            loc.tangent = along / np.linalg.norm(along)
            found.append(Located(SpecialKind.BRANCH_POINT, loc, turns))
        else:
            missed.append(SpecialKind.BRANCH_POINT)
    elif turns:
        # (located by det(P_x - I) where it changes sign: the point where the multiplier is 1)
        if through_one:
            loc = locate(evaluate, a, b, lambda p: orbit_test(SpecialKind.FOLD, p.payload), s)
        else:
            loc = locate(evaluate, a, b, lambda p: float(p.tangent[index]), s)  # type: ignore[index]
        if loc is not None and verified(SpecialKind.FOLD, loc.payload):
            found.append(Located(SpecialKind.FOLD, loc, True))
        else:
            missed.append(SpecialKind.FOLD)
    elif through_one:
        missed.append("fold or branch point")
    for kind in (SpecialKind.PERIOD_DOUBLING, SpecialKind.NEIMARK_SACKER):
        if not sign_changed(orbit_test(kind, oa), orbit_test(kind, ob)):
            continue
        if kind == SpecialKind.NEIMARK_SACKER and area_preserving(oa) and area_preserving(ob):
            continue  # (a pair's product is 1 all along: the sign is rounding's)
        loc = locate(evaluate, a, b, lambda p, k=kind: orbit_test(k, p.payload), s)  # type: ignore[misc]
        if loc is not None and verified(kind, loc.payload):
            found.append(Located(kind, loc))
        elif kind == SpecialKind.NEIMARK_SACKER and loc is not None and neutral_saddle(loc.payload):
            continue  # (two real multipliers mu, 1/mu: none crosses the circle)
        else:
            missed.append(kind)
    found.sort(key=lambda loc: float(np.linalg.norm(loc.point.u - a.u)))
    return StepAccount(tuple(found), tuple(missed), (unstable_count(oa), unstable_count(ob)))
