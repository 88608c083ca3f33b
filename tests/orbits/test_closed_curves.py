"""A closed curve of folds ends where it comes back to its start, reported as closed.

The model's period-1 orbits are the equilibria of ``x' = -(x^3 - 3 x + a^2 + b^2 + 7/4)`` (``y' = -y``,
a stop far away): the cubic has a double root, a fold, at ``x = 1`` exactly where ``a^2 + b^2 = 1/4``
(and at ``x = -1`` where ``a^2 + b^2 = -15/4``: nowhere).  Its fold curve in ``(a, b)`` is the circle of
radius 1/2, a closed curve with no codimension-two point on it: followed once round, it ends at its start.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

import grazing
from grazing.orbits import follow_curve
from grazing.orbits.curve_data import CurveEnd
from grazing.orbits.palc import PalcSettings
from tests.orbits.curve_outcomes import ends

RADIUS = 0.5
LIMIT = 400  # (points per direction: without closure the curve goes round until it has them all)


def ring_of_folds() -> grazing.HybridModel:
    x, y, t = sp.symbols("x y t")
    a, b = sp.symbols("a b")
    return grazing.HybridModel(
        "ring-of-folds",
        states=[x, y],
        time=t,
        parameters=[grazing.Parameter("a", 0.0), grazing.Parameter("b", 0.0)],
        vector_field=[-(x**3 - 3 * x + a**2 + b**2 + 2 - sp.Rational(1, 4)), -y],
        period=2 * sp.pi,
        stops=[grazing.Stop("far", 10 - x, [x, y])],
    )


def test_a_closed_fold_curve_stops_where_it_comes_back_to_its_start():
    curve = follow_curve(
        ring_of_folds(), "fold", "a", 0.0, 1.0, "b", (-1.0, 1.0), x0=[1.3, 0.0], period=1,
        settings=PalcSettings(max_points=LIMIT),
    )  # fmt: skip
    assert curve.closed and curve.outcomes == (CurveEnd.CLOSED, CurveEnd.CLOSED), curve.status
    first, last = ends(curve.status)
    assert first == last and first.startswith("the curve came back to its start (a = 0.5, b = 0) after ")
    assert first.endswith(f"after {len(curve) - 1} points: it is closed")
    a, b = curve.values("a"), curve.values("b")
    assert np.allclose(np.hypot(a, b), RADIUS, atol=1e-10) and np.allclose(curve.states[:, 0], 1.0, atol=1e-9)
    assert curve.points[0] is curve.points[-1] and np.allclose(
        curve.points[curve.start_index].values, (0.5, 0.0)
    )
    # once round, no more: its angle turns through 2 pi, one way, and its length is the circle's
    turn = np.diff(np.unwrap(np.arctan2(b, a)))
    assert np.all(np.sign(turn) == np.sign(turn[0])) and abs(abs(np.sum(turn)) - 2 * math.pi) < 1e-12
    length = float(np.sum(np.hypot(np.diff(a), np.diff(b))))
    assert 0.99 < length / (2 * math.pi * RADIUS) <= 1.0 and len(curve) < LIMIT
