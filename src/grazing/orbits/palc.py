"""Generic pseudo-arclength continuation of ``F(u) = 0``, ``F: R^(m+1) -> R^m``.

Continuation is an iterator over accepted points (as in BifurcationKit.jl):
predict along the unit tangent (the null vector of ``DF``), correct by
Newton's method on ``F = 0`` and ``t . (u - u_pred) = 0``, adapt the step.
The curve starts moving in the direction ``sign`` of one component and stops,
landing exactly on the bound, when a bounded component leaves its interval.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from grazing.errors import GrazingError


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
    """

    ds: float = 0.01
    ds_min: float = 1e-6
    ds_max: float = 0.04
    max_points: int = 2000
    tol: float = 1e-10
    max_newton: int = 8
    locate_tol: float = 1e-9


@dataclass
class PalcPoint:
    """A point on the curve: ``u``, the residual and Jacobian there, the tangent, a payload."""

    u: np.ndarray
    F: np.ndarray
    DF: np.ndarray
    payload: Any
    tangent: np.ndarray | None = None


Evaluate = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, Any]]


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

    The curve starts in the direction where ``u[index]`` moves with ``sign``.
    ``bounds`` maps component indices to ``(lo, hi)``: when a prediction
    leaves one of them, the last point is placed exactly on that bound and the
    iteration ends.  After iteration, :attr:`status` says why it stopped.
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
    ):
        self.evaluate = evaluate
        self.first = first
        self.bounds = bounds
        self.s = settings or PalcSettings()
        t = tangent(first.DF)
        if t[index] * sign < 0:
            t = -t
        first.tangent = t
        self.status = ""

    def _outside(self, u: np.ndarray) -> tuple[int, float] | None:
        """The first violated bound along the step, as (index, bound value)."""
        for i, (lo, hi) in self.bounds.items():
            if u[i] > hi:
                return i, hi
            if u[i] < lo:
                return i, lo
        return None

    def __iter__(self) -> Iterator[PalcPoint]:
        s = self.s
        cur = self.first
        yield cur
        ds = s.ds
        count = 1
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
                    self.status = f"step size fell below {s.ds_min:g}"
                    return
                continue
            nxt.tangent = tangent(nxt.DF, cur.tangent)
            if out is None and nxt.tangent @ cur.tangent < 0.5 and ds > 4 * s.ds_min:
                ds *= 0.5  # sharp turn: refine
                continue
            count += 1
            yield nxt
            cur = nxt
            if out is not None:
                self.status = f"reached the bound u[{out[0]}] = {out[1]:.8g}"
                return
            ds = min(ds * 1.3, s.ds_max)
        self.status = "maximum number of points reached"


def locate(
    evaluate: Evaluate,
    a: PalcPoint,
    b: PalcPoint,
    test: Callable[[PalcPoint], float],
    s: PalcSettings,
    *,
    bisect: bool = False,
) -> PalcPoint | None:
    """Zero of ``test`` between consecutive points ``a`` and ``b`` (signs differ).

    Corrected points along the secant ``a + sigma (b - a)`` are found by Newton
    with the constraint orthogonal to the secant; ``sigma`` is updated by the
    Illinois variant of regula falsi (or by bisection for a discrete test).
    """
    d = b.u - a.u
    dn = d / np.linalg.norm(d)
    lo, hi = 0.0, 1.0
    flo, fhi = test(a), test(b)
    best: PalcPoint | None = None
    side = 0
    for _ in range(60):
        if bisect or fhi == flo:
            sig = 0.5 * (lo + hi)
        else:
            sig = (lo * fhi - hi * flo) / (fhi - flo)
            sig = min(max(sig, lo + 1e-3 * (hi - lo)), hi - 1e-3 * (hi - lo))
        pt = correct(evaluate, a.u + sig * d, dn, s)
        if pt is None:
            return best
        pt.tangent = tangent(pt.DF, a.tangent)
        f = test(pt)
        best = pt
        if (not bisect and abs(f) <= s.locate_tol) or (hi - lo) < 1e-12:
            return pt
        if (f > 0) == (flo > 0):
            lo, flo = sig, f
            if side == -1 and not bisect:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi = sig, f
            if side == 1 and not bisect:
                flo *= 0.5
            side = 1
    return best


def sign_changed(fa: float, fb: float) -> bool:
    """True when two finite test-function values have strictly different signs."""
    if math.isnan(fa) or math.isnan(fb):
        return False
    return (fa > 0) != (fb > 0)
