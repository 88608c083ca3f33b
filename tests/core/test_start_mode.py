"""A run of a model with modes given no mode starts in the mode its initial state lies in
(:meth:`HybridModel.start_mode`, as the basins do): the initial mode where the state is in its region,
else the one other mode whose region it is in; one line where that is ambiguous or where it is in none.

The rocking block from ``theta < 0`` (the region of ``left_corner`` only: ``right_corner`` is the initial
mode) was refused unless ``mode="left_corner"`` was given, by simulate, find_orbit, the sweeps and the
command line alike.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import grazing
from grazing.core.model import mode_of_states
from grazing.orbits import find_orbit
from grazing.sweeps.api import run_sweep
from grazing.sweeps.spec import sweep_spec
from tests.attractors.test_attractor_modes import QUAD
from tests.cli.test_cli_models import run, run_json

LEFT = [-0.05, 0.02]
"""A rocking block on its left corner (``theta < 0``): outside the initial mode ``right_corner``'s region."""

QUAD_FILE = f"{Path(__file__).parents[1] / 'attractors' / 'test_attractor_modes.py'}:QUAD"
"""The hysteretic four-mode model as a model file of the command line."""


def block() -> grazing.HybridModel:
    return grazing.models.rocking_block(a=0.15)


def same_run(a: grazing.Solution, b: grazing.Solution) -> bool:
    return (
        np.array_equal(a.samples, b.samples)
        and np.array_equal(a.impacts.t, b.impacts.t)
        and np.array_equal(a.modes, b.modes)
        and np.array_equal(a.x_final, b.x_final)
        and a.mode_final == b.mode_final
    )


def test_simulate_starts_in_the_mode_the_state_lies_in():
    m = block()
    sol = grazing.simulate(m, LEFT, transient=3, periods=6)
    assert same_run(sol, grazing.simulate(m, LEFT, transient=3, periods=6, mode="left_corner"))
    first = grazing.simulate(m, LEFT, transient=0, periods=1).impacts
    assert first.stop.size and m.stop_names[first.stop[0]] == "onto_right"  # (it lands from its left corner)
    # an explicit mode is kept: the state is not in right_corner's region
    with pytest.raises(grazing.InvalidStateError, match="not in mode 'right_corner'"):
        grazing.simulate(m, LEFT, periods=2, mode="right_corner")


@pytest.mark.parametrize("x0", [[0.1, 0.0], [0.0, -0.3], [0.0, 0.2]])
def test_a_state_in_the_initial_modes_region_starts_there(x0):
    """On the edge of the initial mode's region too (``theta = 0``, either way: also in
    ``left_corner``'s), as before: the runs that started in the initial mode are unchanged."""
    m = block()
    assert m.start_mode(x0) == "right_corner"
    sol = grazing.simulate(m, x0, transient=2, periods=4)
    assert same_run(sol, grazing.simulate(m, x0, transient=2, periods=4, mode="right_corner"))


def test_an_absorbing_mode_only_where_no_other_is():
    """``overturned`` (no transition out, its region everywhere) is where a state in no other mode's
    region starts; a state on a corner is not in it, and ``mode_of_states`` (the basins') agrees."""
    m = block()
    states = np.array([LEFT, [2.0, 0.0], [-2.0, 0.1], [0.3, 0.0]])
    assert [m.start_mode(x) for x in states] == ["left_corner", "overturned", "overturned", "right_corner"]
    assert [m.mode_names[k] for k in mode_of_states(m, states, 0.0)] == [m.start_mode(x) for x in states]
    sol = grazing.simulate(m, [2.0, 0.0], periods=2)
    assert sol.mode_final == "overturned" and np.array_equal(sol.x_final, [2.0, 0.0])


def test_an_ambiguous_state_is_refused_in_one_line():
    """Outside the initial mode ``ann`` (``q > ell``) the hysteretic model's state lies in the regions of
    ``bo`` and ``dee``: which it starts in changes its future, so the run asks; in the band ``|q| < ell``
    (every mode's region) it starts in ``ann`` as before."""
    x = [2.0, 0.0]
    with pytest.raises(grazing.InvalidStateError, match="regions of modes 'bo', 'dee'") as err:
        grazing.simulate(QUAD, x, periods=2)
    assert "\n" not in str(err.value) and "say which mode" in str(err.value)
    assert grazing.simulate(QUAD, x, periods=2, mode="dee").mode_final == "dee"
    assert QUAD.start_mode([0.0, 0.3]) == "ann"
    with pytest.raises(grazing.InvalidStateError, match="regions of modes"):
        find_orbit(QUAD, x, period=1)


def test_find_orbit_from_a_guess_in_another_mode():
    """The block's symmetric rocking orbit: half a period after its point ``(theta, omega)`` on its right
    corner it is at ``(-theta, -omega)`` on its left one (the model is symmetric under ``theta -> -theta``
    with the forcing shifted by half a period); Newton's method from there, given no mode, finds it."""
    m = block()
    right = find_orbit(m, [0.039, -0.012], period=1)
    assert right.mode == "right_corner" and right.impacts == 2
    half = m.period / 2
    left = find_orbit(m, -right.state, period=1, t0=half)
    assert left.mode == "left_corner" and np.abs(left.state + right.state).max() < 1e-9
    given = find_orbit(m, -right.state, period=1, t0=half, mode="left_corner")
    assert np.array_equal(left.state, given.state) and np.array_equal(left.multipliers, given.multipliers)


def test_a_sweep_starts_its_x0_in_its_mode():
    m = block()
    spec = sweep_spec(m, "a", [0.15, 0.16], x0=LEFT, settings=grazing.SweepSettings(transient=3, periods=4))
    assert spec.x0_mode == m.mode_index("left_corner")
    assert spec.description()["x0_mode"] == "left_corner"
    assert sweep_spec(m, "a", [0.15], x0=[0.1, 0.0]).x0_mode is None  # (the initial mode: as before)
    ds = run_sweep(spec, workers=1)
    first = grazing.simulate(m, LEFT, transient=3, periods=4, mode="left_corner")
    assert np.allclose(ds.samples.values[0], first.samples, rtol=0, atol=1e-9)


def test_the_command_line_starts_in_the_mode_of_initial(capsys):
    base = ["simulate", "--model", "rocking-block", "--set", "a=0.15", "--transient", "3", "--periods", "5"]
    auto = run_json([*base, "--initial=-0.05,0.02"], capsys)
    given = run_json([*base, "--initial=-0.05,0.02", "--mode", "left_corner"], capsys)
    auto.pop("elapsed_s"), given.pop("elapsed_s")
    assert auto == given and auto["modes"][0] in ("left_corner", "right_corner", "overturned")
    code, out, err = run(["simulate", "--model", QUAD_FILE, "--initial", "2,0", "--periods", "2"], capsys)
    assert code != 0 and out == "" and len(err.strip().splitlines()) == 1
    assert "--initial:" in err and "regions of modes 'bo', 'dee'" in err
