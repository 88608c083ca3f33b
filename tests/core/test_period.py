"""Period detection on stroboscopic samples."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from grazing import detect_period


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
