"""Global continuation of attractors along a parameter (grazing.attractors.continue_attractors)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grazing.attractors import continue_attractors
from grazing.attractors.classify import Attractor
from grazing.attractors.continuation import match
from grazing.errors import InvalidParameterError
from grazing.models import bouncing_ball

R = 0.8
A_FOLD = math.pi * (1 - R) / (1 + R)  # the period-1 orbit is born in a fold ...
A_PD = math.sqrt(A_FOLD**2 + (2 * (1 + R**2) / (1 + R) ** 2) ** 2)  # ... and period-doubles here
BALL = bouncing_ball(r=R, omega=1.0, gravity=1.0)


def test_the_ball_along_its_amplitude_follows_the_closed_forms():
    values = [A_FOLD - 0.05, A_FOLD + 0.05, 0.8, 0.98, A_PD - 0.03, A_PD + 0.03]
    ds = continue_attractors(BALL, "amplitude", values, (0.0, 6.0), (-4.0, 4.0), (14, 14), workers=2)
    np.testing.assert_allclose(ds.value.values, values)
    np.testing.assert_allclose(ds.fraction.sum("attractor").values, 1.0)
    kinds = ds.kind.values
    riding = [j for j in range(ds.attractor.size) if kinds[0, j] == "sticking"]
    assert len(riding) == 1  # below the fold: the ball only rides on its table
    assert (kinds[0] != "periodic").all()
    orbit = [j for j in range(ds.attractor.size) if kinds[1, j] == "periodic" and ds.period.values[1, j] == 1]
    assert len(orbit) == 1  # past the fold, the period-1 orbit ...
    j = orbit[0]
    assert ds.present.values[1:, j].all()  # ... is followed as one attractor to the end
    assert ds.period.values[1:5, j].tolist() == [1, 1, 1, 1]
    assert ds.period.values[5, j] == 2  # past the period-doubling: the same attractor, period 2
    assert (ds.impacts_per_period.values[1:5, j] == 1).all()
    r = riding[0]
    assert ds.present.values[:4, r].all() and (kinds[:4, r] == "sticking").all()  # riding while A w^2 < g
    assert "sticking" not in kinds[5]  # the table's acceleration exceeds gravity: no riding for ever
    labels = ds.label.values
    for k in range(len(values)):
        ids, counts = np.unique(labels[k], return_counts=True)
        frac = dict(zip(ids.tolist(), (counts / labels[k].size).tolist()))
        assert {a: f for a, f in zip(ds.attractor.values.tolist(), ds.fraction.values[k]) if f > 0} == frac


def test_matching_prefers_the_seeds_then_the_nearest():
    a = Attractor(
        id=1, kind="periodic", period=1, impacts_per_period=1.0, lyapunov=-0.1, points=np.array([[0.0, 0.0]])
    )
    b = Attractor(
        id=2, kind="periodic", period=1, impacts_per_period=1.0, lyapunov=-0.1, points=np.array([[5.0, 5.0]])
    )
    far = Attractor(
        id=1,
        kind="periodic",
        period=1,
        impacts_per_period=1.0,
        lyapunov=-0.1,
        points=np.array([[50.0, 50.0]]),
    )
    near = Attractor(
        id=2, kind="periodic", period=1, impacts_per_period=1.0, lyapunov=-0.1, points=np.array([[0.5, 0.0]])
    )
    # by distance, a continues as the near one and b is too far from the far one (a new attractor)
    assert match([a, b], [far, near], np.ones(2), threshold=8.0) == {2: 1}
    # b's seeds all ended on the far one: that is b, however far it moved
    assert match([a, b], [far, near], np.ones(2), threshold=8.0, seeded={2: 1, 1: 2}) == {1: 2, 2: 1}
    # a and b both ended on the near one: it continues the nearer of them, a
    assert match([a, b], [far, near], np.ones(2), threshold=8.0, seeded={1: 2, 2: 2}) == {2: 1}


def test_bad_input():
    with pytest.raises(InvalidParameterError, match="unknown parameter"):
        continue_attractors(BALL, "nope", [0.5], (0.0, 1.0), (0.0, 1.0), (2, 2))
    with pytest.raises(InvalidParameterError, match="non-empty"):
        continue_attractors(BALL, "amplitude", [], (0.0, 1.0), (0.0, 1.0), (2, 2))
    with pytest.raises(InvalidParameterError, match="r = 2"):
        continue_attractors(BALL, "r", [0.5, 2.0], (0.0, 1.0), (0.0, 1.0), (2, 2))
