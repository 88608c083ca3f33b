"""The lanes' vector code (grazing.engine.lanevec) decides as the scalar path does, lane by lane."""

from __future__ import annotations

import numpy as np
from numba import njit

from grazing.engine.driver.events import event_certificate, event_polynomial
from grazing.engine.lanevec import LANE_WIDTH, advance_rows, certify_stop


@njit(cache=False)
def _vector(O, row, K, hs, plain):
    certify_stop(O, row, K, hs, plain)


@njit(cache=False)
def _scalar(O, row, order, h, a):
    """The scalar path's decision for one lane: event_polynomial, then event_certificate (-1: no event)."""
    _, tail = event_polynomial(O, row, h, 0, 0, False, a, order)
    return event_certificate(a, tail)


def test_every_lane_decides_as_the_scalar_path():
    rng = np.random.default_rng(5)
    order = 13
    K = order + 1
    decided = {True: 0, False: 0}
    for _ in range(400):
        # guard polynomials near a grazing: a0 small and positive or negative, a1 of either sign
        O = rng.normal(size=(2, K, LANE_WIDTH)) * (0.6 ** np.arange(K))[None, :, None]
        O[:, 0, :] = rng.uniform(-0.01, 0.05, size=(2, LANE_WIDTH))
        hs = rng.uniform(0.01, 1.5, LANE_WIDTH)
        a = np.zeros(K)
        for row in range(2):
            plain = rng.integers(0, 2, LANE_WIDTH).astype(np.int64)
            before = plain.copy()
            _vector(O, row, K, hs, plain)
            for lane in range(LANE_WIDTH):
                O_lane = np.ascontiguousarray(O[:, :, lane])
                none = _scalar(O_lane, row, order, hs[lane], a) < 0.0
                # a lane stays plain (skips the search) exactly where the scalar path's certificate
                # excludes an event without dividing out a root at the step's start (a0 > 0); elsewhere
                # it searches, as the scalar path does
                certain = none and O[row, 0, lane] > 0.0
                assert plain[lane] == (before[lane] if certain else 0)
                decided[bool(certain)] += 1
    assert min(decided.values()) > 100  # (both decisions are taken often)


@njit(cache=False)
def _advance(X, first, last, order, dt, mask, out):
    advance_rows(X, first, last, order, dt, mask, out)


def test_advancing_rows_is_the_scalar_evaluation_on_the_lanes_it_should():
    from grazing.engine.stepping import eval_rows

    rng = np.random.default_rng(6)
    order, rows = 13, 6
    X = rng.normal(size=(rows, order + 1, LANE_WIDTH))
    dt = rng.uniform(0.0, 2.0, LANE_WIDTH)
    mask = rng.integers(0, 2, LANE_WIDTH).astype(np.int64)
    out = rng.normal(size=(rows, LANE_WIDTH))
    before = out.copy()
    _advance(X, 1, 5, order, dt, mask, out)
    for lane in range(LANE_WIDTH):
        want = np.zeros(rows)
        eval_rows(np.ascontiguousarray(X[:, :, lane]), rows, order, dt[lane], want)
        for i in range(rows):
            expected = want[i] if (mask[lane] and 1 <= i < 5) else before[i, lane]
            assert out[i, lane] == expected  # (bit for bit)
