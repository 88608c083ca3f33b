"""First-root isolation on [0, 1], including dips far below any step resolution."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.polynomial import polynomial as P  # noqa: N812

from grazing.engine.polyroots import (
    confirm_first_root,
    first_root,
    isolate_first_root,
    to_bernstein,
    work_shape,
)


def _first_root(coeffs):
    a = np.asarray(coeffs, dtype=float)
    return first_root(a, a.size - 1, np.zeros(work_shape(a.size - 1)))


@pytest.mark.parametrize("depth", [10.0**-k for k in range(2, 13)])
def test_shallow_dip_is_found(depth):
    """(u - 0.3)^2 - depth, times a positive factor, at degree 20."""
    base = P.polysub(P.polypow([-0.3, 1.0], 2), [depth])
    a = P.polymul(base, P.polypow([1.0, 0.2], 18))
    u = _first_root(a)
    # The root is conditioned by the slope 2 sqrt(depth): rounding ~1e-16 / slope.
    assert u == pytest.approx(0.3 - np.sqrt(depth), abs=1e-12 + 1e-16 / np.sqrt(depth))


def test_no_root_and_positive_minimum():
    a = P.polymul(P.polyadd(P.polypow([-0.5, 1.0], 2), [1e-12]), P.polypow([1.0, 0.1], 10))
    assert _first_root(a) == -1.0


def test_root_at_start_is_returned():
    assert _first_root([0.0, -1.0, 0.5]) == 0.0
    assert _first_root([-1e-20, 1.0]) == 0.0


def test_bernstein_conversion_exact_for_monomials():
    n = 6
    b = np.zeros(n + 1)
    a = np.zeros(n + 1)
    a[2] = 1.0  # u^2: Bernstein coefficients C(i,2)/C(n,2)
    to_bernstein(a, n, b)
    expected = [i * (i - 1) / (n * (n - 1)) for i in range(n + 1)]
    np.testing.assert_allclose(b, expected, rtol=1e-15, atol=1e-16)


@settings(max_examples=200, deadline=None)
@given(
    roots=st.lists(st.floats(0.01, 0.99), min_size=1, max_size=6),
    extra=st.lists(st.floats(-3.0, 3.0), min_size=0, max_size=6),
)
@example(roots=[0.5, 0.8125, 0.9080984134446282, 0.390625], extra=[])  # (a root at the halving point:
# Newton's method from the chord's root converged to it, not to the first)
@example(roots=[0.4765625, 0.484375, 0.5, 0.75], extra=[])  # (issue 42: two roots 0.008 apart, both on
# halving points; the interval [0.46875, 0.484375] ended at the second with -7e-18 for 0 and went to Newton)
def test_matches_smallest_simple_root(roots, extra):
    """Random polynomials with known simple roots in (0, 1) and complex/outside ones."""
    roots = sorted(roots)
    if np.min(np.diff(roots), initial=1.0) < 1e-3:
        return
    a = P.polyfromroots(roots)
    for e in extra:  # complex pairs, or real roots outside [0, 1] (a cluster at 1 would make those
        # inside ill-conditioned, as for any root finder: 1.1 keeps them apart)
        a = P.polymul(a, [1.0 + abs(e), 0.0, 1.0]) if e > 0 else P.polymul(a, [1.1 + abs(e), -1.0])
    if a[0] < 0:
        a = -a
    u = _first_root(a)
    assert u == pytest.approx(roots[0], abs=1e-9)


@settings(max_examples=300, deadline=None)
@given(coeffs=st.lists(st.floats(-2.0, 2.0), min_size=1, max_size=12))
def test_quadratic_lower_bound_is_a_lower_bound(coeffs):
    from grazing.engine.polyroots import quadratic_lower_bound

    a = np.asarray(coeffs, dtype=float)
    u = np.linspace(0.0, 1.0, 2001)
    assert quadratic_lower_bound(a, a.size - 1) <= P.polyval(u, a).min() + 1e-12


def _polish_cases(count: int, seed: int) -> np.ndarray:
    """Guard polynomials of a step: nearly straight, one root in (0.05, 0.95), decaying Taylor terms."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        c = rng.normal(size=14) * 0.4 ** np.arange(14)
        c[1] -= 1.0
        c[0] = 0.0
        c[0] = -P.polyval(rng.uniform(0.05, 0.95), c)
        if c[0] > 0.0:
            out.append(c)
    return np.array(out)


def test_the_root_is_certified_and_as_close_as_rounding_allows():
    # Newton's polishing stops once its step is below rounding; the root it returns is certified
    # (Horner's p <= 0 there) and within the rounding of p's evaluation (eps sum|a_k| / |p'|) of the
    # exact root (mpmath, 30 digits).
    import mpmath as mp

    from grazing.engine.polyroots import horner

    for a in _polish_cases(300, seed=3):
        u = _first_root(a)
        assert horner(a, a.size - 1, u) <= 0.0
        with mp.workdps(30):
            coeffs = [mp.mpf(float(c)) for c in a[::-1]]
            exact = mp.findroot(lambda v, c=coeffs: mp.polyval(c, v), mp.mpf(float(u)))
            slope = abs(float(mp.polyval([c * k for c, k in zip(coeffs, range(a.size - 1, 0, -1))], exact)))
        noise = 4 * np.finfo(float).eps * np.sum(np.abs(a)) / slope
        assert abs(u - float(exact)) <= 2 * np.spacing(u) + noise


def test_polishing_takes_few_newton_steps():
    # It used to bisect when Newton's last step was below rounding (the root ~50 times halved): count
    # the evaluations by a polynomial whose evaluations are counted.
    from grazing.engine import polyroots

    calls = []
    original = polyroots.horner_with_derivative.py_func

    def counted(a, n, u):
        calls.append(u)
        return original(a, n, u)

    polish = polyroots._polish.py_func
    polyroots_globals = polish.__globals__
    saved = polyroots_globals["horner_with_derivative"]
    polyroots_globals["horner_with_derivative"] = counted
    try:
        counts = []
        for a in _polish_cases(300, seed=4):
            calls.clear()
            b = np.zeros(a.size)
            to_bernstein(a, a.size - 1, b)
            polish(a, a.size - 1, 0.0, 1.0, b[0], b[-1])
            counts.append(len(calls))
    finally:
        polyroots_globals["horner_with_derivative"] = saved
    assert np.median(counts) <= 6 and max(counts) <= 12, (np.median(counts), max(counts))


@st.composite
def roots_hard_for_subdivision(draw):
    """Roots in (0, 1) placed where subdivision finds them hardest, with the first one known.

    One of: a pair whose second root is a halving point (``j / 2**L``) and whose first lies
    within the same halving interval before it (the interval's end coefficient is 0 but for
    rounding); roots all on halving points; a close pair (1e-4 to 1e-2 apart); plain random
    roots; each with up to three more roots on halving points or at random.
    """
    kind = draw(st.sampled_from(["halving-pair", "dyadic", "close-pair", "random"]))
    if kind == "halving-pair":
        level = draw(st.integers(1, 9))
        second = draw(st.integers(1, 2**level - 1)) / 2**level
        fraction = draw(st.one_of(st.integers(1, 63).map(lambda k: k / 64), st.floats(0.02, 0.98)))
        roots = [second - fraction / 2**level, second]
    elif kind == "dyadic":
        level = draw(st.integers(1, 10))
        roots = [k / 2**level for k in draw(st.lists(st.integers(1, 2**level - 1), min_size=1, max_size=4))]
    elif kind == "close-pair":
        first = draw(st.floats(0.01, 0.9))
        roots = [first, first + draw(st.floats(1e-4, 1e-2))]
    else:
        roots = draw(st.lists(st.floats(0.01, 0.99), min_size=1, max_size=4))
    more = draw(
        st.lists(st.one_of(st.integers(1, 255).map(lambda k: k / 256), st.floats(0.01, 0.99)), max_size=3)
    )
    roots = np.unique(np.array(roots + more, dtype=float))
    return roots[(roots > 0.0) & (roots < 1.0)]


def _check_first_root(roots):
    """The first root found is the smallest of ``roots`` to its conditioning (and never the second)."""
    if roots.size == 0 or np.min(np.diff(roots), initial=1.0) < 1e-4:
        return
    a = P.polyfromroots(roots)
    if a[0] < 0:
        a = -a
    u = _first_root(a)
    # A root's error from rounding the coefficients: eps sum|a_k| / |p'(root)| (times a margin).
    slope = abs(P.polyval(roots[0], P.polyder(a)))
    tol = max(1e-9, 1e4 * np.finfo(float).eps * np.abs(a).sum() / slope)
    assert abs(u - roots[0]) <= tol, (list(roots), u)
    if roots.size > 1:
        assert u < 0.5 * (roots[0] + roots[1])


@settings(max_examples=300, deadline=None)
@given(roots=roots_hard_for_subdivision())
@example(roots=np.array([0.6378135456416711, 0.640625, 0.734375, 0.9921875]))  # (found at random by the
# strategy against the code before issue 42's fix, as were the next two)
@example(roots=np.array([0.70458984375, 0.7109375, 0.75]))
@example(roots=np.array([0.47072647987476957, 0.4765625, 0.5, 0.75]))
def test_first_root_whatever_the_roots_positions(roots):
    _check_first_root(roots)


@pytest.mark.slow
@settings(max_examples=100_000, deadline=None)
@given(roots=roots_hard_for_subdivision())
def test_first_root_never_misses_in_100000_polynomials(roots):
    _check_first_root(roots)


def test_the_search_alone_finds_the_first_of_two_roots_on_halving_points():
    # Without the confirmation: the subdivision itself halves an interval whose end value is zero
    # but for rounding instead of polishing across two roots.
    a = P.polyfromroots([0.4765625, 0.484375, 0.5, 0.75])
    u = isolate_first_root(a, a.size - 1, np.zeros(work_shape(a.size - 1)))
    assert u == pytest.approx(0.4765625, abs=1e-12)


@pytest.mark.parametrize("later", [0.484375, 0.5, 0.75, 0.999])
def test_the_confirmation_returns_an_earlier_root(later):
    # The engine's check of a located event: handed a later root (as the search returned before the
    # fix), it finds the earlier sign change on the step and returns that.
    a = P.polyfromroots([0.4765625, 0.484375, 0.5, 0.75])
    work = np.zeros(work_shape(a.size - 1))
    assert confirm_first_root(a, a.size - 1, later, work) == pytest.approx(0.4765625, abs=1e-11)


def test_the_confirmation_keeps_a_first_root_and_no_root():
    a = P.polyfromroots([0.3, 0.7])
    work = np.zeros(work_shape(a.size - 1))
    assert confirm_first_root(a, a.size - 1, 0.3, work) == 0.3
    assert confirm_first_root(a, a.size - 1, -1.0, work) == -1.0
    assert confirm_first_root(a, a.size - 1, 0.0, work) == 0.0
