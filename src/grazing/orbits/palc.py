"""Generic pseudo-arclength continuation of ``F(u) = 0``, ``F: R^(m+1) -> R^m``.

Continuation is an iterator over accepted points (as in BifurcationKit.jl):
predict along the unit tangent (the null vector of ``DF``), correct by
Newton's method on ``F = 0`` and ``t . (u - u_pred) = 0``, adapt the step.
The curve starts moving in the direction ``sign`` of one component and stops,
landing exactly on the bound, when a bounded component leaves its interval.

Step control does not jump over what it should see:

* a step whose corrector lands far from the predictor (more than
  ``max_correction * ds``) or whose tangent turns by more than
  ``acos(min_cos)`` is halved (unless the step is already tiny);
* the caller's ``check(previous, candidate)`` may ask for a shorter step
  (:data:`REFINE`: e.g. stability changed between the two points), or say that
  the candidate lies beyond a *boundary* of the curve's domain
  (:data:`BOUNDARY`: e.g. a periodic orbit that gains or loses an impact is
  another orbit).  A boundary is then bracketed along the step by bisection,
  with a secant on the caller's ``margin`` (positive before the boundary,
  tending to zero at it) when given, and the iteration ends at the last point
  before it, with :attr:`Palc.boundary` set.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from grazing.core.options import BOUNDARY_TOL, CORRECTOR_TOL, LOCATE_TOL, MAX_STEP
from grazing.errors import GrazingError

ACCEPT = "accept"
REFINE = "refine"
BOUNDARY = "boundary"
STOP = "stop"
"""Verdicts of a :data:`Check`: accept the candidate; halve the step; the candidate is
beyond a boundary; accept the candidate and end the iteration."""

ARCLENGTH_FLOOR = 1e-15
"""A boundary's bracket in the arclength is not narrowed below this (relative to ``max(1, its far
end)``): about five units in the last place (:data:`~grazing.core.options.MACHINE_EPSILON`), where its
midpoint is no longer a new step."""

INSIDE_BRACKET = 1e-3
"""A secant's or regula falsi's trial is kept at least this fraction of its bracket's width inside it
(:func:`locate`, a boundary's bracketing): a trial at an end would only compute that end again, and a
side where the secant stagnates still moves."""

MARGIN_REACHED = 1e-3
"""A boundary with a margin (a grazing: the distance to the stop) is reached continuously when the
margin at the last point before it has fallen to this fraction of its value where the bracketing began:
it tends to zero linearly at the boundary, where ten halvings of the bracket take it (2**-10); a margin
that stays larger means the corrector jumped across."""

JUMP_GAP = 1e-4
"""A boundary without a margin is reached continuously when the last points on either side of it are
within this of each other (relative to ``max(1, |u|)``): the points beyond tend to the last one before
it, and this is a million times the width to which the followed component is bracketed
(:data:`~grazing.core.options.BOUNDARY_TOL`); a larger gap is a jump of the corrector."""

LOCATE_WIDTH = 1e-12
""":func:`locate` ends when its bracket on the secant is narrower than this (in the secant's parameter,
0 to 1): with a secant at most ``ds_max`` long, the point is then within about 4e-14 of the zero, the
rounding of the corrected points, whatever the test function's value."""

REAL_ROOT_TOL = 1e-12
"""A root of :func:`locate_by_interpolation`'s cubic (in the secant's parameter, 0 to 1) is real when
its imaginary part is below this: a real root comes out of ``np.roots`` with an imaginary part of
rounding (zero or about 1e-16)."""


class PalcEnd(enum.Enum):
    """Why a :class:`Palc` iteration ended (:attr:`Palc.end`; :attr:`Palc.status` says it in words)."""

    MAX_POINTS = "maximum number of points reached"
    BOUND = "reached a bound"
    STUCK = "the step size fell below its minimum"
    BOUNDARY = "reached a boundary of the curve's domain"
    STOPPED = "the caller's check stopped it"


@dataclass(frozen=True)
class PalcSettings:
    """Step control and Newton options, with defaults.

    Attributes
    ----------
    ds, ds_min, ds_max
        Initial, smallest and largest arclength step.
    max_points
        Largest number of points (including the first).
    tol
        Newton tolerance on ``max |F|``.
    max_newton
        Newton iterations per corrector step.
    locate_tol
        Tolerance on a test function when locating a special point.
    min_cos
        Smallest cosine between consecutive tangents; a sharper turn halves the step.
    max_correction
        Largest distance from predictor to corrector, as a fraction of the step.
    ds_refine
        Steps on which the caller's check asks for refinement are halved down to
        this length (default ``ds_max / 16``).
    boundary_tol
        A boundary is bracketed until the followed component (:class:`Palc`'s ``index``) differs by
        at most this (relative to ``max(1, |value|)``) across it.

    Examples
    --------
    Smaller steps give a branch of more points, and the same grazing:

    >>> import math, grazing
    >>> from grazing.orbits import continue_orbit
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> coarse = continue_orbit(m, "eta", 0.40, 0.47)
    >>> fine = continue_orbit(m, "eta", 0.40, 0.47, settings=PalcSettings(ds_max=0.01))
    >>> len(coarse) < len(fine), round(coarse.special[0].param, 8) == round(fine.special[0].param, 8)
    (True, True)
    """

    ds: float = 0.01
    ds_min: float = 1e-6
    ds_max: float = MAX_STEP
    max_points: int = 2000
    tol: float = CORRECTOR_TOL
    max_newton: int = 8
    locate_tol: float = LOCATE_TOL
    min_cos: float = 0.9
    max_correction: float = 0.5
    ds_refine: float | None = None
    boundary_tol: float = BOUNDARY_TOL


@dataclass(frozen=True)
class Bracket:
    """Where the zero of a test function lies, as :func:`locate` leaves it.

    Attributes
    ----------
    lo, hi
        The points ``u`` of the curve (corrected) at the ends of the last bracket (the test function's
        signs differ there).
    step
        The located point's offset from the zero to first order: the test function's value there
        over its slope along the secant, times the secant (in ``u``).
    at
        The located point's ``u`` (None: only the ends are known).
    """

    lo: np.ndarray
    hi: np.ndarray
    step: np.ndarray
    at: np.ndarray | None = None

    def interval(self, i: int) -> tuple[float, float]:
        """Where component ``i`` of the zero lies, as ``(low, high)``: between its values at the bracket's
        ends, and within :meth:`precision` of the located point's.

        The located point's own value may lie outside the ends' (at a fold, where the parameter turns
        between them: both ends lie on the same side of the fold's value).

        Examples
        --------
        >>> ends, at = (np.array([0.0, 0.9]), np.array([1.0, 0.9])), np.array([0.5, 1.0])
        >>> fold = Bracket(*ends, np.array([0.0, 1e-9]), at)
        >>> fold.interval(1)[0] == 0.9 and 1.0 < fold.interval(1)[1] < 1.0 + 2e-9
        True
        """
        a, b = float(self.lo[i]), float(self.hi[i])
        lo, hi = min(a, b), max(a, b)
        if self.at is None:
            return (lo, hi)
        p, width = float(self.at[i]), self.precision(i)
        return (min(lo, p - width), max(hi, p + width))

    def precision(self, i: int) -> float:
        """How far component ``i`` of the located point may be from the zero: the first-order offset,
        at most the width of the bracket (its ends and the located point), plus the component's own
        rounding (4 eps of its size).

        Examples
        --------
        >>> p = Bracket(np.array([0.0, 1.0]), np.array([0.0, 1.5]), np.array([0.0, 2e-12])).precision(1)
        >>> bool(2e-12 < p < 2e-12 + 2e-15)
        True
        """
        values = [float(self.lo[i]), float(self.hi[i])] + ([] if self.at is None else [float(self.at[i])])
        lo, hi = min(values), max(values)
        rounding = 4 * float(np.finfo(float).eps) * max(abs(lo), abs(hi))
        return min(abs(float(self.step[i])), hi - lo) + rounding


@dataclass
class PalcPoint:
    """A point on the curve: ``u``, the residual and Jacobian there, the tangent, a payload, and for a
    located zero of a test function its :class:`Bracket`."""

    u: np.ndarray
    F: np.ndarray
    DF: np.ndarray
    payload: Any
    tangent: np.ndarray | None = None
    bracket: Bracket | None = None


Evaluate = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, Any]]
Check = Callable[[PalcPoint, PalcPoint], tuple[str, str]]
"""``check(previous, candidate) -> (verdict, reason)``."""


@dataclass
class Boundary:
    """Where the curve's domain ends: the last point before it, and the first beyond (if any)."""

    before: PalcPoint
    after: PalcPoint | None
    reason: str
    reached: bool = True
    """False when the points beyond did not approach the curve as the bracket shrank (the
    corrector jumped to another curve): then there is no boundary here."""
    ahead: float | None = None
    """For an unconfirmed boundary (``after`` None, not ``reached``): where the caller's margin,
    extrapolated from the last two points, reaches zero (the value of the component ``index``),
    by the farther of the two extrapolations of :func:`margin_zeros`; None without such a margin."""


def margin_zeros(margins: list[tuple[float, float]]) -> tuple[float, float] | None:
    """Where a margin tending to zero vanishes, from its last two values ``[(u0, m0), (u1, m1)]``.

    A boundary margin (an impact speed squared, say) vanishes linearly or quadratically in ``u``;
    returns the zeros of the linear and of the quadratic extrapolation (``sqrt(m)`` linear)
    through the two points, ``(linear, quadratic)``, or None when the margin is not decreasing
    towards zero.  For a margin ``~ d^k`` with ``1 <= k <= 2`` (``d`` the distance to its zero),
    the linear zero lies at most as far as the true one and the quadratic at least as far.

    Examples
    --------
    >>> margin_zeros([(0.0, 4.0), (1.0, 1.0)])  # m = (2 - u)^2: the quadratic zero is exact
    (1.3333333333333333, 2.0)
    """
    if len(margins) < 2:
        return None
    (p0, m0), (p1, m1) = margins[-2], margins[-1]
    if not (m0 > m1 > 0) or p1 == p0:
        return None
    linear = m1 / (m0 - m1)
    quadratic = math.sqrt(m1) / (math.sqrt(m0) - math.sqrt(m1))
    return p1 + linear * (p1 - p0), p1 + quadratic * (p1 - p0)


def tangent(DF: np.ndarray, previous: np.ndarray | None = None) -> np.ndarray:
    """Unit null vector of ``DF``, oriented along ``previous`` if given."""
    _, _, vt = np.linalg.svd(DF)
    t = vt[-1]
    if previous is not None and t @ previous < 0:
        t = -t
    return t / np.linalg.norm(t)


def correct(
    evaluate: Evaluate, u_pred: np.ndarray, direction: np.ndarray, s: PalcSettings
) -> PalcPoint | None:
    """Newton's method on ``F(u) = 0`` and ``direction . (u - u_pred) = 0``."""
    u = u_pred.copy()
    for _ in range(s.max_newton + 1):
        try:
            F, DF, payload = evaluate(u)
        except (GrazingError, np.linalg.LinAlgError, FloatingPointError):
            return None
        if not np.all(np.isfinite(F)) or not np.all(np.isfinite(DF)):
            return None
        if np.max(np.abs(F)) <= s.tol:
            return PalcPoint(u.copy(), F, DF, payload)
        G = np.append(F, direction @ (u - u_pred))
        try:
            du = np.linalg.solve(np.vstack([DF, direction]), -G)
        except np.linalg.LinAlgError:
            return None
        u = u + du
    return None


def newton(evaluate: Evaluate, u0: np.ndarray, s: PalcSettings) -> PalcPoint | None:
    """Newton's method for a square system ``F(u) = 0``."""
    u = u0.copy()
    for _ in range(s.max_newton + 1):
        try:
            F, DF, payload = evaluate(u)
        except (GrazingError, np.linalg.LinAlgError, FloatingPointError):
            return None
        if not np.all(np.isfinite(F)):
            return None
        if np.max(np.abs(F)) <= s.tol:
            return PalcPoint(u.copy(), F, DF, payload)
        try:
            u = u - np.linalg.solve(DF, F)
        except np.linalg.LinAlgError:
            return None
    return None


class Palc:
    """Iterator over the points of a solution curve of ``F(u) = 0``.

    The curve starts in the direction where ``u[index]`` moves with ``sign``, or, given a
    ``direction`` vector, along it (leaving a branch point, where ``u[index]`` may not move).
    ``bounds`` maps component indices to ``(lo, hi)``: when a prediction
    leaves one of them, the last point is placed exactly on that bound and the
    iteration ends.  ``names`` gives the components' names for messages, and
    ``shows`` how to print a component's value in them (``index -> value ->
    "name = value unit"``, e.g. :meth:`~grazing.Parameter.show`: a parameter
    in its display unit); by default ``name = value``.
    ``check`` and ``margin`` are the caller's acceptance test and boundary
    margin (see the module docstring).  After iteration, :attr:`status` says
    why it stopped and :attr:`boundary` is set if it stopped at a boundary.
    """

    def __init__(
        self,
        evaluate: Evaluate,
        first: PalcPoint,
        *,
        index: int,
        sign: float,
        bounds: dict[int, tuple[float, float]],
        settings: PalcSettings | None = None,
        names: dict[int, str] | None = None,
        shows: dict[int, Callable[[float], str]] | None = None,
        check: Check | None = None,
        margin: Callable[[PalcPoint], float] | None = None,
        direction: np.ndarray | None = None,
    ):
        self.evaluate = evaluate
        self.first = first
        self.index = index
        self.bounds = bounds
        self.s = settings or PalcSettings()
        self.names = names or {}
        self.shows = shows or {}
        self.check = check
        self.margin = margin
        t = tangent(first.DF)
        if (t[index] * sign if direction is None else t @ direction) < 0:
            t = -t
        first.tangent = t
        self.status = ""
        self.end: PalcEnd | None = None
        self.boundary: Boundary | None = None
        self._margins: list[tuple[float, float]] = []  # (u[index], margin) of the last accepted points

    def _name(self, i: int) -> str:
        return self.names.get(i, f"u[{i}]")

    def _show(self, i: int, value: float) -> str:
        """Component ``i`` at ``value``, as messages print it."""
        show = self.shows.get(i)
        return show(float(value)) if show is not None else f"{self._name(i)} = {value:.10g}"

    def _where(self, pt: PalcPoint) -> str:
        return self._show(self.index, pt.u[self.index])

    def _outside(self, u: np.ndarray) -> tuple[int, float] | None:
        """The first violated bound along the step, as (index, bound value)."""
        for i, (lo, hi) in self.bounds.items():
            if u[i] > hi:
                return i, hi
            if u[i] < lo:
                return i, lo
        return None

    def _stuck(self, cur: PalcPoint, why: str) -> None:
        """End where no step beyond ``cur`` succeeds.

        With a ``margin``, a boundary may lie just ahead (Newton's method
        fails, or jumps to another curve, close to it): :attr:`boundary` is set,
        unconfirmed, for the caller to check.
        """
        if self.margin is not None:
            zeros = margin_zeros(self._margins)
            self.boundary = Boundary(cur, None, why, reached=False, ahead=None if zeros is None else zeros[1])
        self.status = f"step size fell below {self.s.ds_min:g} at {self._where(cur)}: {why}"
        self.end = PalcEnd.STUCK

    def _jumped(self, margins: list[tuple[float, float]], cand: PalcPoint) -> bool:
        """Is ``cand`` (beyond a boundary by the caller's check) short of where the margin predicts it?

        The margin of the accepted points tends to zero linearly or
        quadratically in ``u[index]`` as the boundary approaches (an impact
        speed ``v`` may vanish like the parameter distance or like its square
        root; the margin is ``v^2``); a candidate less than half-way from the
        last point to the nearer of the two extrapolated zeros cannot have
        crossed it.
        """
        if len(margins) < 2:
            return False
        (_, m0), (p1, m1) = margins[-2], margins[-1]
        pc = float(cand.u[self.index])
        zeros = margin_zeros(margins)
        if zeros is None:
            return m1 > 0 and not m0 > m1  # moving away from the boundary: a jump
        p_star = zeros[0]  # the nearer of the two
        return (pc - p1) / (p_star - p1) < 0.5

    def _step(self, cur: PalcPoint, sigma: float) -> PalcPoint | None:
        """The corrected point at arclength ``sigma`` along ``cur``'s tangent."""
        assert cur.tangent is not None
        pt = correct(self.evaluate, cur.u + sigma * cur.tangent, cur.tangent, self.s)
        if pt is not None:
            pt.tangent = tangent(pt.DF, cur.tangent)
        return pt

    def _locate_boundary(self, cur: PalcPoint, ds: float, beyond: PalcPoint, reason: str) -> Boundary:
        """Bracket the boundary between ``cur`` (before it) and the step ``ds`` (beyond it).

        Bisection on the arclength along ``cur``'s tangent; with a ``margin``, a
        secant through the last two points before the boundary (the margin
        tends to zero linearly at it) proposes the next trial, kept inside the
        bracket.
        """
        lo, hi = 0.0, ds
        best, after = cur, beyond
        history: list[tuple[float, float]] = []  # (sigma, margin) of points before the boundary
        if self.margin is not None:
            history.append((0.0, self.margin(cur)))
        i = self.index
        for _ in range(100):
            scale = max(1.0, abs(best.u[i]))
            if after is not None and abs(after.u[i] - best.u[i]) <= self.s.boundary_tol * scale:
                break
            if hi - lo <= ARCLENGTH_FLOOR * max(1.0, hi):
                break
            sig = 0.5 * (lo + hi)
            if len(history) >= 2:
                (sa, ma), (sb, mb) = history[-2], history[-1]
                if ma > mb > 0:
                    guess = sb + mb * (sb - sa) / (ma - mb)
                    width = hi - lo
                    if lo < guess < hi:  # else bisect
                        sig = min(max(guess, lo + INSIDE_BRACKET * width), hi - INSIDE_BRACKET * width)
            pt = self._step(cur, sig)
            verdict = BOUNDARY if pt is None or self.check is None else self.check(cur, pt)[0]
            if pt is not None and verdict != BOUNDARY:
                lo, best = sig, pt
                if self.margin is not None:
                    history.append((sig, self.margin(pt)))
            else:
                hi, after = sig, pt
        # A boundary of the curve is reached continuously: the margin tends to zero, the
        # points beyond tend to the last point before it.  Otherwise the corrector jumped.
        if history and history[0][1] > 0:
            reached = history[-1][1] <= MARGIN_REACHED * history[0][1]
        else:
            gap = math.inf if after is None else float(np.linalg.norm(after.u - best.u))
            reached = gap <= JUMP_GAP * max(1.0, float(np.linalg.norm(best.u)))
        return Boundary(best, after, reason, reached)

    def __iter__(self) -> Iterator[PalcPoint]:
        s = self.s
        ds_refine = s.ds_refine if s.ds_refine is not None else s.ds_max / 16
        cur = self.first
        yield cur
        ds = s.ds
        count = 1
        margins = self._margins  # (u[index], margin) of the accepted points
        if self.margin is not None:
            margins.append((float(cur.u[self.index]), self.margin(cur)))
        while count < s.max_points:
            assert cur.tangent is not None
            pred = cur.u + ds * cur.tangent
            out = self._outside(pred)
            if out is not None:
                i, bound = out
                frac = (bound - cur.u[i]) / (pred[i] - cur.u[i])
                pred = cur.u + frac * (pred - cur.u)
                pred[i] = bound
                e = np.zeros_like(pred)
                e[i] = 1.0
                nxt = correct(self.evaluate, pred, e, s)
            else:
                nxt = correct(self.evaluate, pred, cur.tangent, s)
            if nxt is None:
                ds *= 0.5
                if ds < s.ds_min:
                    self._stuck(
                        cur, "Newton's method did not converge beyond this point (a singular point, or "
                        "a step too large for the settings)",
                    )  # fmt: skip
                    return
                continue
            nxt.tangent = tangent(nxt.DF, cur.tangent)
            if out is None and ds > 4 * s.ds_min:
                turn = float(nxt.tangent @ cur.tangent)
                moved = float(np.linalg.norm(nxt.u - pred))
                if turn < s.min_cos or moved > s.max_correction * ds:
                    ds *= 0.5  # the step jumped: predictor and corrector disagree
                    continue
            verdict, reason = self.check(cur, nxt) if self.check is not None else (ACCEPT, "")
            if verdict == REFINE and ds > ds_refine and out is None:
                ds = max(0.5 * ds, ds_refine)
                continue
            if verdict == BOUNDARY and self._jumped(margins, nxt):
                # The margin says the boundary is still far: the corrector jumped to another curve.
                ds *= 0.5
                if ds < s.ds_min:
                    self._stuck(
                        cur, f"beyond this point Newton's method converges to another solution ({reason})"
                    )
                    return
                continue
            if verdict == BOUNDARY:
                found = self._locate_boundary(cur, ds, nxt, reason)
                if found.before is not cur:
                    count += 1
                    yield found.before
                if found.reached:
                    self.boundary = found
                    self.status = f"{reason} at {self._where(found.before)}"
                    self.end = PalcEnd.BOUNDARY
                    return
                # The corrector jumped to another curve: go on along this one with shorter steps.
                if found.before is not cur and self.margin is not None:
                    margins.append((float(found.before.u[self.index]), self.margin(found.before)))
                    del margins[:-2]
                cur = found.before
                ds *= 0.5
                if ds < s.ds_min:
                    self._stuck(
                        cur, f"beyond this point Newton's method converges to another solution ({reason})"
                    )
                    return
                continue
            count += 1
            yield nxt
            cur = nxt
            if self.margin is not None:
                margins.append((float(cur.u[self.index]), self.margin(cur)))
                del margins[:-2]
            if out is not None:
                self.status = f"reached the bound {self._show(out[0], out[1])}"
                self.end = PalcEnd.BOUND
                return
            if verdict == STOP:
                self.status = reason
                self.end = PalcEnd.STOPPED
                return
            ds = min(ds * 1.3, s.ds_max)
        self.status = PalcEnd.MAX_POINTS.value
        self.end = PalcEnd.MAX_POINTS


def locate(
    evaluate: Evaluate,
    a: PalcPoint,
    b: PalcPoint,
    test: Callable[[PalcPoint], float],
    s: PalcSettings,
) -> PalcPoint | None:
    """Zero of ``test`` between consecutive points ``a`` and ``b`` (signs differ).

    Corrected points along the secant ``a + sigma (b - a)`` are found by Newton
    with the constraint orthogonal to the secant; ``sigma`` is updated by the
    Illinois variant of regula falsi.
    """
    d = b.u - a.u
    dn = d / np.linalg.norm(d)
    lo, hi = 0.0, 1.0
    flo, fhi = test(a), test(b)
    true_lo, true_hi = flo, fhi  # (the test's values at the bracket's ends, before Illinois halves them)
    u_lo, u_hi = a.u, b.u  # (the corrected points at the bracket's ends)
    best: PalcPoint | None = None
    side = 0
    for _ in range(60):
        sig = (lo * fhi - hi * flo) / (fhi - flo)  # (fhi and flo differ in sign: never equal)
        sig = min(max(sig, lo + INSIDE_BRACKET * (hi - lo)), hi - INSIDE_BRACKET * (hi - lo))
        pt = correct(evaluate, a.u + sig * d, dn, s)
        if pt is None:
            return best
        pt.tangent = tangent(pt.DF, a.tangent)
        f = test(pt)
        slope = (true_hi - true_lo) / (hi - lo)
        offset = f / slope if slope != 0 and math.isfinite(f) else math.inf
        pt.bracket = Bracket(u_lo, u_hi, offset * d, pt.u)
        best = pt
        if abs(f) <= s.locate_tol or (hi - lo) < LOCATE_WIDTH:
            return pt
        if (f > 0) == (flo > 0):
            lo, flo, true_lo, u_lo = sig, f, f, pt.u
            if side == -1:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi, true_hi, u_hi = sig, f, f, pt.u
            if side == 1:
                flo *= 0.5
            side = 1
    return best


INTERPOLATION_WIDTH = 2e-4
""":func:`locate_by_interpolation` narrows its bracket to this width (relative to ``max(1, |u|)``):
a cubic's error there is of the order of its fourth power, its nodes stay a quarter of it from
the zero."""


def locate_by_interpolation(
    evaluate: Evaluate,
    a: PalcPoint,
    b: PalcPoint,
    test: Callable[[PalcPoint], float],
    s: PalcSettings,
    *,
    rounds: int = 8,
) -> PalcPoint | None:
    """Zero of ``test`` between consecutive points ``a`` and ``b`` (signs differ), where the corrector
    is ill-conditioned near the zero (a branch point, where another curve crosses this one).

    There the residual grows only quadratically off the curves, so a corrected point close to
    the zero is known only to the square root of the Newton tolerance, and may lie on the
    other curve.  Instead, ``test`` and ``u`` are interpolated by cubics in the secant
    parameter ``sigma`` through ``a``, ``b`` and two points corrected (as in :func:`locate`)
    at ``sigma`` in (0.25, 0.5, 0.75), the two farthest from the linear estimate of the zero:
    regular points of this curve.  The cubic's zero gives ``u``, evaluated there.  Until the
    bracket is narrower than :data:`INTERPOLATION_WIDTH` and the residual there within the
    tolerance ``s.tol``, the same is done between the two points around the zero (up to
    ``rounds`` times).  None if no point is found.
    """
    fa, fb = test(a), test(b)
    for _ in range(rounds):
        d = b.u - a.u
        dn = d / np.linalg.norm(d)
        guess = fa / (fa - fb)
        inner = sorted(sorted((0.25, 0.5, 0.75), key=lambda c: -abs(c - guess))[:2])
        nodes = [(0.0, a, fa)]
        for sig in inner:
            pt = correct(evaluate, a.u + sig * d, dn, s)
            if pt is None:
                return None
            pt.tangent = tangent(pt.DF, a.tangent)
            nodes.append((sig, pt, test(pt)))
        nodes.append((1.0, b, fb))
        sigmas = np.array([node[0] for node in nodes])
        values = np.array([node[2] for node in nodes])
        if not np.all(np.isfinite(values)):
            return None
        roots = np.roots(np.polyfit(sigmas, values, 3))
        real = roots[(np.abs(roots.imag) < REAL_ROOT_TOL) & (roots.real >= 0.0) & (roots.real <= 1.0)].real
        if not real.size:
            return None
        root = float(real[np.argmin(np.abs(real - guess))])
        weights = [np.prod([(root - sj) / (si - sj) for sj in sigmas if sj != si]) for si in sigmas]
        u = sum(w * node[1].u for w, node in zip(weights, nodes))  # Lagrange's interpolation at the root
        found = None
        try:
            F, DF, payload = evaluate(u)
            if np.all(np.isfinite(F)) and np.max(np.abs(F)) <= s.tol:
                found = PalcPoint(u, F, DF, payload, tangent(DF, a.tangent))
                slope = float(np.polyval(np.polyder(np.polyfit(sigmas, values, 3)), root))
                f = test(found)
                offset = f / slope if slope != 0 and math.isfinite(f) else math.inf
                found.bracket = Bracket(a.u.copy(), b.u.copy(), offset * d, u)
        except (GrazingError, np.linalg.LinAlgError, FloatingPointError):
            pass
        narrow = float(np.linalg.norm(d)) <= INTERPOLATION_WIDTH * max(1.0, float(np.linalg.norm(a.u)))
        k = next((i for i in range(3) if (values[i] > 0) != (values[i + 1] > 0)), None)
        if (found is not None and narrow) or k is None:
            return found
        (_, a, fa), (_, b, fb) = nodes[k], nodes[k + 1]
    return found


def sign_changed(fa: float, fb: float) -> bool:
    """True when two finite test-function values have strictly different signs."""
    if math.isnan(fa) or math.isnan(fb):
        return False
    return (fa > 0) != (fb > 0)
