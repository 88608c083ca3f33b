"""Period detection on stroboscopic samples."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from grazing import detect_period
from grazing.core.period import detect_periods, repeats_with_period


@given(p=st.integers(1, 64), reps=st.integers(2, 4), seed=st.integers(0, 2**31))
def test_detects_exact_periods(p, reps, seed):
    rng = np.random.default_rng(seed)
    cycle = rng.uniform(-1, 1, size=(p, 2))
    while p > 1 and detect_period(np.tile(cycle, (reps, 1))) not in (0, p):
        cycle = rng.uniform(-1, 1, size=(p, 2))
    assert detect_period(np.tile(cycle, (reps, 1))) == p


def test_tolerance_and_noise():
    base = np.tile([0.1, 0.4, 0.7], 20)
    assert detect_period(base + 1e-8) == 3
    noisy = base + np.random.default_rng(1).normal(0, 1e-5, base.size)
    assert detect_period(noisy) == 0
    assert detect_period(noisy, tol=1e-3) == 3


def test_too_few_samples_for_the_period():
    assert detect_period(np.array([0.0, 1.0, 2.0])) == 0
    assert detect_period(np.array([[0.0, 1.0]])) == 0


@given(
    p=st.integers(1, 8),
    n=st.integers(6, 40),
    cut=st.integers(0, 40),
    tol=st.sampled_from([0.0, 1e-9, 1e-3]),
    spoil=st.lists(st.tuples(st.integers(0, 39), st.integers(0, 1), st.sampled_from(
        [np.nan, np.inf, -np.inf, 1e-9, -1e-9, 2e-3, -0.0])), max_size=3),
    seed=st.integers(0, 2**31),
)  # fmt: skip
def test_the_lanes_loop_is_detect_periods_one_run_at_a_time(p, n, cut, tol, spoil, seed):
    """The compiled lanes' test of a repeating transient and the sweeps' give the same period (NaN, inf,
    a difference exactly at the tolerance, too few samples)."""
    rng = np.random.default_rng(seed)
    s = np.tile(rng.uniform(-1, 1, size=(p, 2)), (n // p + 1, 1))[:n]
    for i, c, v in spoil:
        if i < n:
            s[i, c] = v if not np.isfinite(v) or v == 0.0 else s[i, c] + v
    count = min(cut, n)
    for max_period in (3, 64):
        expected = int(detect_periods(s[None, :count], tol, max_period)[0])
        with np.errstate(invalid="ignore"):  # (inf - inf is NaN, as in the compiled lanes, which do not warn)
            assert repeats_with_period(s, count, tol, max_period) == expected
