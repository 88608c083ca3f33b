"""First-root isolation on [0, 1], including dips far below any step resolution."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.polynomial import polynomial as P  # noqa: N812

from grazing.engine.polyroots import first_root, to_bernstein, work_shape


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
