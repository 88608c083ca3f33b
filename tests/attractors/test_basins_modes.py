"""Attractors and basins of a model with modes: each initial state starts in the mode it lies in."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import grazing
from grazing.attractors import basins, find_attractors
from grazing.attractors.basins import basin_spec
from grazing.attractors.grid import start_time
from grazing.core.model import mode_of_states
from grazing.core.options import SWEEP_TOL, BasinSettings
from grazing.core.period import detect_period
from grazing.errors import InvalidStateError
from grazing.models import soft_impact_oscillator
from grazing.orbits import find_orbit
from grazing.sweeps.api import run_sweep

# Below the fold of the soft-impact oscillator's resonance (omega = 1.2, gap = 0.5, k = 4, zeta = 0.05),
# a small orbit that never reaches the spring (amplitude a / |1 - omega^2| ~ 0.34 < gap) coexists with a
# large one that goes into contact each period.
SOFT = soft_impact_oscillator(a=0.15, omega=1.2, gap=0.5, k=4.0, zeta=0.05)
RANGE, NUM = (-1.5, 1.5), (10, 10)


@pytest.fixture(scope="module")
def grid():
    return basins(SOFT, RANGE, RANGE, NUM, workers=1)


def switches(model, x0, mode):
    """The switches of mode of the period-1 orbit through ``x0`` (in ``mode``) over one period."""
    sol = grazing.simulate(model, x0, transient=0, periods=1, mode=mode, tol=SWEEP_TOL)
    return len(sol.switches.t)


def test_mode_at_picks_the_region_of_a_state():
    gap = SOFT.params["gap"]
    assert SOFT.mode_at([gap - 0.1, 3.0]) == "free" and SOFT.mode_at([gap + 0.1, -3.0]) == "contact"
    assert SOFT.mode_at([gap, 0.0]) == SOFT.initial_mode  # (on the switching surface: the initial mode)
    states = np.array([[gap - 1e-3, 0.0], [gap + 1e-3, 0.0]])
    assert mode_of_states(SOFT, states, 0.0).tolist() == [0, 1]
    with pytest.raises(InvalidStateError, match="finite"):
        SOFT.mode_at([np.nan, 0.0])


def test_the_two_coexisting_orbits_are_find_orbits(grid):
    kinds = grid.kind.values.tolist()
    assert kinds == ["periodic", "periodic"] and grid.period.values.tolist() == [1, 1]
    assert 0.0 not in grid.label.values  # (no state is invalid: each is in one mode's region)
    counts = []
    for k in range(2):
        point = grid.points.values[k, 0]
        mode = SOFT.mode_at(point)
        orbit = find_orbit(SOFT, point, period=1, mode=mode)
        assert orbit.stable and np.max(np.abs(orbit.state - point)) < 1e-8
        counts.append(switches(SOFT, orbit.state, mode))
    assert sorted(counts) == [0, 2]  # (one stays free, the other goes into contact and out each period)


def test_each_label_is_where_its_state_goes_in_its_own_mode(grid):
    x, y = grid.x.values, grid.y.values
    states = [(i, j) for j in range(y.size) for i in range(x.size)]
    gap = SOFT.params["gap"]
    contact = [(i, j) for i, j in states if x[i] > gap]
    sample = contact[::2] + states[::7]
    assert len(contact) > 10
    for i, j in sample:
        x0 = np.array([x[i], y[j]])
        sol = grazing.simulate(SOFT, x0, transient=600, periods=4, mode=SOFT.mode_at(x0), tol=SWEEP_TOL)
        assert detect_period(sol.samples) == 1
        label = int(grid.label.values[j, i])
        distances = np.abs(grid.points.values[:, 0] - sol.samples[-1]).max(axis=1)
        assert int(np.argmin(distances)) + 1 == label and distances[label - 1] < 1e-6, (x0, label, distances)


def test_find_attractors_of_states_in_either_mode():
    gap = SOFT.params["gap"]
    found = find_attractors(SOFT, [[gap + 0.5, 0.0], [0.0, 0.0], [gap + 0.2, -1.0]], workers=1)
    assert [a.kind for a in found.attractors] != [] and "invalid" not in [a.kind for a in found.attractors]
    assert found.labels.min() >= 1


def test_the_lanes_run_each_initial_state_in_its_mode():
    """The sweep of a grid's states (a few periods, unsettled) is each state's own run from its mode."""
    gap, phase = SOFT.params["gap"], 1.0
    states = np.array([[gap + 0.7, 0.5], [gap - 0.2, -1.0], [gap + 0.3, -1.2], [-1.0, 0.3]])
    spec = replace(basin_spec(SOFT, states, BasinSettings(transient=2, periods=3, phase=phase), False),
                   adaptive=False)  # fmt: skip
    ds = run_sweep(spec, workers=1)
    t0 = start_time(SOFT, phase)
    assert [SOFT.mode_at(x0, t0) for x0 in states] == ["contact", "free", "contact", "free"]
    for k, x0 in enumerate(states):
        mode = SOFT.mode_at(x0, t0)
        sol = grazing.simulate(SOFT, x0, t0=t0, transient=2, periods=3, phase=phase, mode=mode, tol=spec.tol)
        assert np.max(np.abs(ds.samples.values[k] - sol.samples)) < 1e-8, k


def test_each_attractor_names_the_mode_its_points_are_in(grid):
    """A periodic attractor of a model with modes names the mode of its point at the sampling phase: the
    region it lies in (``mode_at``); none on a model of one mode."""
    expected = [SOFT.mode_at(grid.points.values[k, 0]) for k in range(2)]
    assert grid["modes"].values[:, 0].tolist() == expected
    found = find_attractors(SOFT, grid.points.values[:, 0], workers=1)
    assert [a.mode for a in found.attractors] == expected
    assert [a.to_json()["modes"] for a in found.attractors] == [[m] for m in expected]
    ball = find_attractors(grazing.models.bouncing_ball(amplitude=0.8, r=0.8), [[0.0, 0.8]], workers=1)
    assert [a.mode for a in ball.attractors] == [""] and ball.attractors[0].to_json()["modes"] is None


def test_the_mode_of_an_attractor_is_that_of_its_own_end_states():
    """End states of a chunk, a failed one among them: each orbit takes the final mode of its own rows."""
    from grazing.attractors.classify import Catalogue
    from grazing.models import rocking_block
    from grazing.sweeps.spec import ChunkResult

    block = rocking_block()
    ends = np.array([[np.nan, np.nan], [np.pi / 2, 0.0], [0.05, -0.01]])
    res = ChunkResult(
        index=0, samples=np.repeat(ends[:, None, :], 4, axis=1), period=np.array([-1, 1, 1]),
        impacts=np.array([0, 0, 8]), lyapunov=np.full(3, np.nan), transient_used=np.full(3, 10),
        x_final=ends, status=np.array([3, 0, 0]), mode_final=np.array([-1, 2, 0]),
    )  # fmt: skip
    cat = Catalogue(block, 3, np.full(2, 0.01), np.zeros(2), 1e3, 4, 0.0)
    cat.add(0, res)
    atts, _ = cat.attractors()
    assert [(a.kind, a.mode) for a in atts] == [
        ("failed", ""),
        ("periodic", "overturned"),
        ("periodic", "right_corner"),
    ]
