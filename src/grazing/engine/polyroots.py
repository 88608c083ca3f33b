"""Robust isolation of the first root of a polynomial on [0, 1].

The event functions of the engine (the guard during free flight, the contact
force during sticking) are available on every Taylor step as polynomials in the
normalised step time ``u`` in [0, 1].  An impact of depth 1e-12 makes the guard
polynomial dip below zero on a tiny sub-interval without any sign change at the
step ends, which is where sign-change event detection (MATLAB's hit-crossing,
``scipy.integrate.solve_ivp`` events) misses it.  Here the polynomial is
converted to the Bernstein basis, whose coefficients bound the polynomial on
the interval (convex-hull property), and subdivided by de Casteljau's algorithm
until every sub-interval either provably has no root or has exactly one sign
change (Descartes' rule of signs for the Bernstein basis).  The first root is
then polished by safeguarded Newton iteration.

All functions are numba-compiled and see only arrays.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_MAX_DEPTH = 60
_MAX_DEGREE = 64
"""Highest degree :func:`to_bernstein` takes (the Taylor order is at most 60)."""
_QUOTIENTS = np.array([[i / j if j else 0.0 for j in range(_MAX_DEGREE + 2)] for i in range(_MAX_DEGREE + 2)])
"""``_QUOTIENTS[i, j]`` = ``i / j``: :func:`to_bernstein`'s quotients of small integers, divided once here
(the same doubles as dividing on every call; a division costs several multiplications' time)."""


@njit(cache=True)
def horner(a, n, u):
    """Value of ``sum(a[k] * u**k for k <= n)``."""
    acc = a[n]
    for k in range(n - 1, -1, -1):
        acc = acc * u + a[k]
    return acc


@njit(cache=True)
def horner_with_derivative(a, n, u):
    """Value and derivative at ``u`` of the polynomial with coefficients ``a[:n+1]``."""
    p = a[n]
    dp = 0.0
    for k in range(n - 1, -1, -1):
        dp = dp * u + p
        p = p * u + a[k]
    return p, dp


@njit(cache=True)
def to_bernstein(a, n, b):
    """Bernstein coefficients on [0, 1] of the power-basis polynomial ``a[:n+1]`` (``n <= 64``)."""
    for i in range(n + 1):
        b[i] = 0.0
    # b_i = sum_{k<=i} C(i,k)/C(n,k) a_k; ratio(i,k) = ratio(i-1,k) * i/(i-k).
    inv_cnk = 1.0  # 1/C(n, k), updated with k
    for k in range(n + 1):
        if k > 0:
            inv_cnk *= _QUOTIENTS[k, n - k + 1]
        ratio = inv_cnk
        b[k] += ratio * a[k]
        for i in range(k + 1, n + 1):
            ratio *= _QUOTIENTS[i, i - k]
            b[i] += ratio * a[k]


@njit(cache=True)
def split_half(c, n, left, right, tmp):
    """de Casteljau subdivision at 1/2 of Bernstein coefficients ``c[:n+1]``."""
    for i in range(n + 1):
        tmp[i] = c[i]
    left[0] = tmp[0]
    right[n] = tmp[n]
    for r in range(1, n + 1):
        for i in range(n - r + 1):
            tmp[i] = 0.5 * (tmp[i] + tmp[i + 1])
        left[r] = tmp[0]
        right[n - r] = tmp[n - r]


@njit(cache=True)
def _polish(a, n, lo, hi, p_lo, p_hi):
    """The left-most point of [lo, hi] where the polynomial is <= 0, to about an ulp.

    Given value(lo) = p_lo > 0 >= value(hi) = p_hi and one root in between.
    Safeguarded Newton iteration from the chord's root (closer than the middle
    where the polynomial is nearly straight, as it is on a step; the middle where
    the value at ``hi`` is zero but for rounding), stopped once
    its step is below rounding; if the polynomial is still above zero there
    (rounding), the root is the next few doubles up.
    """
    x = lo + (hi - lo) * (p_lo / (p_lo - p_hi))
    if not (lo < x < hi) or -p_hi <= 1e-12 * p_lo:  # (the value at hi zero but for rounding: a root there,
        x = 0.5 * (lo + hi)  # the next one, would take the chord's root and then the bracket; the middle)
    p = p_lo
    for _ in range(200):
        p, dp = horner_with_derivative(a, n, x)
        if p > 0.0:
            lo = x
        else:
            hi = x
        if hi - lo <= 4e-16 * max(1.0, abs(hi)):
            break
        xn = x - p / dp if dp != 0.0 else 0.5 * (lo + hi)
        if xn == x:  # (a step below rounding: before the bracket's test, which would bisect)
            break
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        x = xn
    if p <= 0.0:
        return x
    for _ in range(8):  # p(x) > 0 by rounding: the root is a few doubles on
        x = np.nextafter(x, hi)
        if x >= hi:
            return hi
        if horner(a, n, x) <= 0.0:
            return x
    while hi - lo > 4e-16 * max(1.0, abs(hi)):  # (rare: a flat polynomial) bisection
        mid = 0.5 * (lo + hi)
        if horner(a, n, mid) > 0.0:
            lo = mid
        else:
            hi = mid
    return hi


@njit(cache=True, inline="always")
def quadratic_bound(a0, a1, a2, tail):
    """A lower bound on [0, 1] of ``a0 + a1 u + a2 u^2 + r(u)`` where ``|r| <= tail``.

    The exact minimum of the quadratic on [0, 1], minus ``tail``.  Scalars only,
    so that the integration driver can call it on every step without touching
    arrays (numba reference-counts arrays passed to functions it cannot prove
    do not keep them).
    """
    low = min(a0, a0 + a1 + a2)
    if a2 > 0.0:
        um = -a1 / (2.0 * a2)
        if 0.0 < um < 1.0:
            low = min(low, a0 - a1 * a1 / (4.0 * a2))
    return low - tail


@njit(cache=True)
def quadratic_lower_bound(a, n):
    """A lower bound of the polynomial ``a[:n+1]`` on [0, 1] in O(n).

    The exact minimum of ``a0 + a1 u + a2 u^2`` on [0, 1], minus the largest
    possible contribution of the higher terms, ``sum_{k>=3} |a_k|``.  Taylor
    coefficients scaled by the step decay geometrically, so this bound is
    tight except where the polynomial really comes close to zero.
    """
    tail = 0.0
    for k in range(3, n + 1):
        tail += abs(a[k])
    a1 = a[1] if n >= 1 else 0.0
    a2 = a[2] if n >= 2 else 0.0
    return quadratic_bound(a[0], a1, a2, tail)


@njit(cache=True)
def first_root(a, n, work):
    """First ``u`` in [0, 1] where the polynomial ``a[:n+1]`` becomes <= 0.

    The polynomial is expected to be positive at ``u = 0``; if it is not,
    0.0 is returned.  Returns -1.0 when the polynomial stays positive on the
    whole interval (to within rounding of its Bernstein coefficients).

    ``work`` must be a float array of at least the shape given by
    :func:`work_shape`.
    """
    if a[0] <= 0.0:
        return 0.0
    # Cheap certificate: on [0, 1], p(u) >= min(quadratic part) - sum_{k>=3} |a_k|.
    if quadratic_lower_bound(a, n) > 0.0:
        return -1.0
    return confirm_first_root(a, n, isolate_first_root(a, n, work), work)


ROUNDING_SLACK = 2.0
"""Bernstein coefficients within ``ROUNDING_SLACK * (n + 1) * eps`` of the largest of the whole step's are
of unknown sign: to_bernstein's sums and de Casteljau's halvings round them by about that much (a root on
a halving point, as 0.5 or 0.4765625, leaves ``-7e-18`` where 0 is exact)."""

_EPS = float(np.finfo(np.float64).eps)


@njit(cache=True)
def _most_sign_changes(c, n, tol):
    """The most sign changes ``c[:n+1]`` can have when each coefficient within ``tol`` of 0 takes either sign.

    ``c[0] > 0`` is taken as positive.  Dynamic programming over the two
    signs the sequence can end with (-1: impossible).
    """
    pos = 0  # most changes of a sequence ending positive
    neg = -1  # ... ending negative
    for i in range(1, n + 1):
        v = c[i]
        best_pos = max(pos, neg + 1 if neg >= 0 else -1)
        best_neg = max(neg, pos + 1 if pos >= 0 else -1)
        if abs(v) <= tol:  # (either sign)
            pos, neg = best_pos, best_neg
        elif v > 0.0:
            pos, neg = best_pos, -1
        else:
            pos, neg = -1, best_neg
    return max(pos, neg)


@njit(cache=True)
def isolate_first_root(a, n, work):
    """:func:`first_root` without its O(n) certificate, for callers that ran it already.

    Requires ``a[0] > 0``.  Bernstein subdivision and Newton polishing; a
    polynomial that certainly decreases on the whole of [0, 1] (the common
    event: a guard crossing zero) goes to Newton's method at once, its one
    root bracketed by the ends.  An interval goes to Newton's method only when
    its one root is certain whatever the rounding of its coefficients
    (:data:`ROUNDING_SLACK`): its end value clearly below zero and one sign
    change at most with each near-zero coefficient of either sign.  Otherwise
    it is halved, so that a root on a halving point (its end value zero but for
    rounding) with another just before it gives the first, not the second.
    """
    if n >= 2:
        # p'(u) <= a1 + max(0, 2 a2) + sum_{k>=3} k |a_k| on [0, 1]; below zero: p decreases, one root
        # at most, there iff p(1) <= 0
        slope = a[1] + max(0.0, 2.0 * a[2])
        end = a[0] + a[1] + a[2]
        for k in range(3, n + 1):
            slope += k * abs(a[k])
            end += a[k]
        if slope < 0.0:
            return -1.0 if end > 0.0 else _polish(a, n, 0.0, 1.0, a[0], end)
    # Bernstein coefficients all positive => no root (convex hull property).
    b = work[0]
    to_bernstein(a, n, b)
    allpos = True
    scale = 0.0
    for i in range(n + 1):
        if b[i] <= 0.0:
            allpos = False
        scale = max(scale, abs(b[i]))
    if allpos:
        return -1.0
    tol = ROUNDING_SLACK * (n + 1) * _EPS * scale
    # Depth-first search, left half first.  Stack rows hold Bernstein
    # coefficients; intervals are kept in parallel arrays.
    stack_lo = work[_MAX_DEPTH + 5]
    stack_hi = work[_MAX_DEPTH + 6]
    top = 0
    # row 1 + top stores the coefficients of the interval on the stack.
    for i in range(n + 1):
        work[1, i] = b[i]
    stack_lo[0] = 0.0
    stack_hi[0] = 1.0
    top = 1
    tmp_left = work[_MAX_DEPTH + 2]
    tmp_right = work[_MAX_DEPTH + 3]
    while top > 0:
        top -= 1
        lo = stack_lo[top]
        hi = stack_hi[top]
        c = work[1 + top]
        if c[0] <= 0.0:
            return lo
        # Sign variations and positivity.
        nvar = 0
        allpos = True
        inner_clear = True  # c[1..n-1] clearly positive
        last = 1.0
        for i in range(n + 1):
            v = c[i]
            if v <= 0.0:
                allpos = False
            if 0 < i < n and v <= tol:
                inner_clear = False
            if v != 0.0:
                if (v > 0.0) != (last > 0.0):
                    nvar += 1
                last = v
        if allpos:
            continue
        if c[n] < -tol and _most_sign_changes(c, n, tol) == 1:
            # (a Bernstein polynomial's end coefficients are its end values: one root, bracketed)
            return _polish(a, n, lo, hi, c[0], c[n])
        if c[n] <= 0.0 and inner_clear:  # positive up to hi, zero there but for rounding
            return hi
        if nvar == 0:
            # Coefficients >= 0 with zeros: the polynomial touches zero at most
            # at an endpoint; hi is checked by the next interval.
            if c[n] == 0.0:
                return hi
            continue
        mid = 0.5 * (lo + hi)
        if top >= _MAX_DEPTH or hi - lo < 1e-15:
            # Unresolvable tangency at double precision: a zero-depth graze.
            if horner(a, n, mid) <= 0.0:
                return mid
            continue
        # Split into halves; push right then left so that left is examined first.
        split_half(c, n, tmp_left, tmp_right, work[_MAX_DEPTH + 4])
        for i in range(n + 1):
            work[1 + top, i] = tmp_right[i]
        stack_lo[top] = mid
        stack_hi[top] = hi
        top += 1
        for i in range(n + 1):
            work[1 + top, i] = tmp_left[i]
        stack_lo[top] = lo
        stack_hi[top] = mid
        top += 1
    return -1.0


CONFIRM_GAP = 1e-12
""":func:`confirm_first_root` looks for an earlier root on ``[0, u (1 - CONFIRM_GAP)]``: one closer to the
root found than that is the same event to the engine's accuracy of event times."""


@njit(cache=True)
def confirm_first_root(a, n, u, work):
    """``u``, or the polynomial's first root before it: the check that a located root is the first.

    Given ``u``, the first root :func:`isolate_first_root` found of ``a[:n+1]``
    (``a[0] > 0``), the polynomial is rescaled to ``[0, u (1 - CONFIRM_GAP)]``
    and searched again.  A root there means the search returned a later one
    (a crossing and its return within one step located at the return); the
    earlier one is returned.  ``u < 0`` (no root) is returned as it is.  The
    rescaled copy lives in the last row of ``work``.
    """
    if u <= 0.0:
        return u
    for _ in range(4):  # (each pass either confirms or moves to an earlier root)
        s = u * (1.0 - CONFIRM_GAP)
        q = work[_MAX_DEPTH + 7]
        sk = 1.0
        for k in range(n + 1):
            q[k] = a[k] * sk
            sk *= s
        if quadratic_lower_bound(q, n) > 0.0:
            return u
        v = isolate_first_root(q, n, work)
        if v < 0.0 or v >= 1.0:
            return u
        u = s * v
    return u


def work_shape(n: int) -> tuple[int, int]:
    """Shape of the ``work`` array needed by :func:`first_root` for degree ``n``."""
    return (_MAX_DEPTH + 8, max(n + 1, _MAX_DEPTH + 2))
