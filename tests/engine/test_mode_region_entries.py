"""The two other ways into a mode are region-checked too: the exit from sliding and a reset within a mode.

A switch and a reset into another mode already end the run (status OUTSIDE_MODE) where they land outside
the target mode's region (``test_mode_region.py``).  Here the two models are built so that the
entry is by the exit from a sliding surface, or by a reset that keeps the mode, and lands where a guard
of the mode is already negative; the independent reference is the time of that entry, from the
closed form (the sliding model) or from the well-posed model whose motion is the same up to it (the
reset).  Without the check the runs went on as if the guard were not there.
"""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
import sympy as sp

import grazing
from grazing import HybridModel, Mode, Parameter, Surface, Transition
from grazing.core.options import SweepSettings
from grazing.core.solution import Status
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_lanes import assert_lanes_equal_the_oracle
from tests.engine.test_mode_region import CONTACT, FREE, VALUES, gap, t, v, x

MESSAGE = (
    r"a transition entered mode '{mode}' at t = (\S+) outside its region: there the guard of its "
    r"transition '{guard}' is already h = (\S+) < 0 \(the guards of the model's modes do not fit "
    r"together there\)"
)


def slide_then_leave(trap: bool, level: float = 3.0) -> HybridModel:
    """``y' = 1``; above ``x = 0``, ``x' = -1``; below, ``x' = 2 - y``.  From ``(1, 0)`` the motion reaches
    the surface at ``t = 1``, where the field below pushes back: it slides until ``t = 2``, where the
    field below vanishes, and leaves downwards into ``below`` at ``(0, 2)``.  With ``trap`` ``below``
    has one more transition, guard ``y - level``: ``2 - level`` where the motion enters it."""
    xs, ys, ts, c = sp.symbols("x y t c")
    transitions = [Transition("trap", "below", "above", ys - c)] if trap else []
    return HybridModel(
        "slide-then-leave", [xs, ys], ts, [Parameter("c", level)], period=10,
        modes=[Mode("above", [-1, 1]), Mode("below", [2 - ys, 1])],
        surfaces=[Surface("floor", xs, "above", "below")], transitions=transitions,
    )  # fmt: skip


def wall(restitution: float, **values: float) -> HybridModel:
    """The soft-impact oscillator whose ``free`` mode has a wall at ``x = -0.3`` (a reset within the mode,
    ``v <- -restitution v``) and a transition ``overspeed``, guard ``5 - v``, into ``fast`` (the free
    field, no way out: a run that enters it goes on in it for good).  From ``x = 0`` at speed 1 the
    first bounce (at speed 0.53) lands past that guard for a restitution above about 9.5."""
    params = [Parameter(name, value) for name, value in {**VALUES, "e": restitution}.items()]
    e = sp.Symbol("e")
    transitions = [Transition("touch", "free", "contact", gap - x),
                   Transition("leave", "contact", "free", x - gap),
                   Transition("wall", "free", "free", x + sp.Rational(3, 10), reset=[x, -e * v]),
                   Transition("overspeed", "free", "fast", 5 - v)]  # fmt: skip
    model = HybridModel(
        "walled", [x, v], t, params, modes=[Mode("free", FREE), Mode("contact", CONTACT), Mode("fast", FREE)],
        transitions=transitions, period=2 * sp.pi / sp.Symbol("omega"),
    )  # fmt: skip
    return model.with_params(**values)


def test_leaving_sliding_into_a_mode_outside_its_region_ends_the_run_saying_so():
    well_posed = grazing.simulate(slide_then_leave(False), [1.0, 0.0], transient=0, periods=1)
    assert well_posed.mode_final == "below"  # (the reference: it slid, then left downwards)
    with pytest.raises(grazing.SimulationError) as caught:
        grazing.simulate(slide_then_leave(True), [1.0, 0.0], transient=0, periods=1)
    found = re.fullmatch(MESSAGE.format(mode="below", guard="trap"), str(caught.value))
    assert found, str(caught.value)
    assert float(found.group(1)) == pytest.approx(2.0, rel=1e-5)  # (the exit: y = 2, the field below 0)
    assert float(found.group(2)) == pytest.approx(-1.0, rel=1e-2)  # (y - 3 there)


def test_a_reset_within_a_mode_landing_outside_its_region_ends_the_run_saying_so():
    well_posed = grazing.simulate(wall(0.8), [0.0, -1.0], transient=0, periods=1)
    first_wall = float(well_posed.impacts.t[0])  # (the motion is the same up to the first bounce)
    speed = -float(well_posed.impacts.state[0, 1])
    assert 0.0 < first_wall < 1.0 and 0.5 < speed < 0.55  # (the wall at -0.3 is reached early)
    with pytest.raises(grazing.SimulationError) as caught:
        grazing.simulate(wall(12.0), [0.0, -1.0], transient=0, periods=1)
    found = re.fullmatch(MESSAGE.format(mode="free", guard="overspeed"), str(caught.value))
    assert found, str(caught.value)
    assert float(found.group(1)) == pytest.approx(first_wall, rel=1e-5)
    assert float(found.group(2)) == pytest.approx(5.0 - 12.0 * speed, rel=1e-2)  # (5 - v after it)


def test_a_reset_within_a_mode_that_stays_inside_it_is_unchanged():
    inside = grazing.simulate(wall(0.8), [0.0, -1.0], transient=4, periods=2, impacts="all")
    assert len(inside.impacts.t) > 2  # (it bounces, and ends without an error)


@pytest.mark.parametrize("which", ["sliding", "reset"])
def test_a_sweep_fails_those_points_on_lanes_as_in_the_runner(which):
    """The lanes (each point from the start) fail the points that enter outside and no other, as the
    runner (the oracle) does."""
    settings = SweepSettings(transient=4, periods=2, chunk_size=2, fresh=True, lyapunov=False, adaptive=False)
    if which == "sliding":
        spec = sweep_spec(slide_then_leave(True), "c", [3.0, 1.5, 2.5], x0=[1.0, 0.0], settings=settings)
    else:
        spec = sweep_spec(wall(0.8), "e", [12.0, 0.8, 11.0], x0=[0.0, -1.0], settings=settings)
    spec = dataclasses.replace(spec, polish=False)
    results = assert_lanes_equal_the_oracle(spec, regroup=False)
    status = np.concatenate([res.status for res in sorted(results, key=lambda r: r.index)])
    points = np.asarray(spec.points, dtype=float).reshape(-1)  # (in the order the sweep visits them)
    outside = points > 2.0  # (the trap's level above 2; a restitution above about 9.5)
    np.testing.assert_array_equal(status, np.where(outside, int(Status.OUTSIDE_MODE), int(Status.OK)))
