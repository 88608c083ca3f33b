"""A model in other units has the same structure.

The engine sizes its steps by the state's scale ``max(1, |x|)``, so its error is relative to that scale;
the tolerances that say "these samples repeat" and "these two orbits are one" are relative to it too
(:func:`grazing.core.period.sample_scale`).  The forced, damped linear oscillator of
:mod:`tests.far_stop` has one attracting period-1 orbit, known in closed form and proportional to its
forcing: at a forcing of 1e5 (an orbit of size 1.3e5, whose samples repeat only to 5e-6, the adaptive
steps' error) it was called aperiodic, at 1e-5 (its points 5e-10 apart from run to run, 1e-2 of a
match's cells) it was counted once per initial state.
"""

from __future__ import annotations

import numpy as np
import pytest

import grazing
from grazing.attractors import find_attractors
from grazing.sweeps import sweep
from tests.far_stop import far_stop_swing, orbit_state

FORCES = [1e-5, 1.0, 1e5]


def _initial_states(force: float) -> np.ndarray:
    q, v = orbit_state(force)
    rng = np.random.default_rng(1)
    return np.column_stack([q + 2 * abs(q) * rng.standard_normal(8), v + 2 * abs(v) * rng.standard_normal(8)])


@pytest.mark.parametrize("force", FORCES)
def test_one_periodic_attractor_in_any_units(force):
    found = find_attractors(far_stop_swing(force=force), _initial_states(force))
    assert [(a.kind, a.period) for a in found.attractors] == [("periodic", 1)]
    (point,) = found.attractors[0].points
    # (the engine's error is 1e-10 of max(1, |x|): absolute below 1, so 1e-4 of an orbit of size 1e-5)
    np.testing.assert_allclose(point, orbit_state(force), rtol=1e-8, atol=1e-8)
    assert found.labels.tolist() == [found.attractors[0].id] * 8


@pytest.mark.parametrize("force", FORCES)
def test_a_run_and_a_sweep_see_period_one_in_any_units(force):
    model = far_stop_swing(force=force)
    run = grazing.simulate(model, _initial_states(force)[0], periods=64, transient=300)
    assert run.period() == 1
    ds = sweep(model, "force", [force, 1.5 * force], transient=300, periods=32)
    assert ds.period.values.tolist() == [1, 1]
