"""A mode entered outside its region: the run ends with status OUTSIDE_MODE and says which mode and guard.

The soft-impact oscillator's ``contact`` mode is given one more transition, ``rebound`` (guard ``-v``:
the mode's region asks ``v <= 0``), which the oscillator's motion contradicts: it enters ``contact`` at
``x = gap`` moving on, ``v > 0``.  Before, the run took the ``rebound`` event at once, off its surface,
and went on as if nothing had happened.  Up to that first entry the model is the well-posed soft-impact
oscillator, so the run must end at that oscillator's first switch (the independent reference), on the
scalar driver and on the sweep's lanes alike; a small amplitude that never reaches the gap is unaffected.
"""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
import sympy as sp

import grazing
from grazing import HybridModel, Mode, Parameter, Transition
from grazing.core.options import SweepSettings
from grazing.core.solution import Status
from grazing.sweeps.run import run_chunks
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_lanes import assert_lanes_equal_the_oracle

x, v, t = sp.symbols("x v t")
zeta, a, w, gap, k = sp.symbols("zeta a omega gap k")
VALUES = {"zeta": 0.05, "a": 1.0, "omega": 1.2, "gap": 0.5, "k": 4.0}
FREE = [v, -2 * zeta * v - x + a * sp.cos(w * t)]
CONTACT = [v, -2 * zeta * v - x + a * sp.cos(w * t) - k * (x - gap)]

SMALL = 0.1
"""An amplitude that never reaches the gap: |x| <= 2 a / |1 - omega^2| = 0.45 < 0.5 from rest."""


def oscillator(rebound: bool, touch_reset: bool = False, **values: float) -> HybridModel:
    """The soft-impact oscillator, with ``rebound`` the transition whose guard is negative where the motion
    enters ``contact``; with ``touch_reset`` it enters ``contact`` through a reset (``v <- v / 2``)."""
    params = [Parameter(name, value) for name, value in VALUES.items()]
    reset = [x, v / 2] if touch_reset else None
    transitions = [Transition("touch", "free", "contact", gap - x, reset=reset),
                   Transition("leave", "contact", "free", x - gap)]  # fmt: skip
    if rebound:
        transitions.append(Transition("rebound", "contact", "free", -v, reset=[x - gap / 2, v]))
    model = HybridModel(
        "ill-posed" if rebound else "soft-impact", [x, v], t, params,
        modes=[Mode("free", FREE), Mode("contact", CONTACT)], transitions=transitions, period=2 * sp.pi / w,
    )  # fmt: skip
    return model.with_params(**values)


@pytest.mark.parametrize("touch_reset", [False, True], ids=["switch", "reset"])
def test_a_mode_entered_outside_its_region_ends_the_run_saying_so(touch_reset):
    well_posed = grazing.simulate(oscillator(False, touch_reset), [0.0, 0.0], transient=0, periods=3)
    first_entry = float(well_posed.switches.t[0])  # (well_posed.switches: "touch" first)
    assert well_posed.switches.transition[0] == 0
    with pytest.raises(grazing.SimulationError) as caught:
        grazing.simulate(oscillator(True, touch_reset), [0.0, 0.0], transient=0, periods=3)
    message = str(caught.value)
    assert re.fullmatch(
        r"a transition entered mode 'contact' at t = \S+ outside its region: there the guard of its "
        r"transition 'rebound' is already h = -\S+ < 0 \(the guards of the model's modes do not fit "
        r"together there\)",
        message,
    ), message
    t_end = float(re.search(r"t = (\S+) ", message).group(1))
    assert t_end == pytest.approx(first_entry, rel=1e-5)  # (the message's 6 digits)
    h = float(re.search(r"h = (\S+) <", message).group(1))
    assert h < 0


def test_a_run_that_never_enters_the_mode_is_unchanged():
    ill = grazing.simulate(oscillator(True, a=SMALL), [0.0, 0.0], transient=20, periods=10)
    well = grazing.simulate(oscillator(False, a=SMALL), [0.0, 0.0], transient=20, periods=10)
    np.testing.assert_array_equal(ill.samples, well.samples)


def test_a_sweep_fails_the_points_that_enter_the_mode_on_lanes_as_in_the_runner():
    settings = SweepSettings(transient=30, periods=8, chunk_size=2)
    amplitudes = np.array([SMALL, 1.0, 0.08, 1.5, SMALL, 0.09])
    spec = dataclasses.replace(sweep_spec(oscillator(True), "a", amplitudes, settings=settings), polish=False)
    results = assert_lanes_equal_the_oracle(spec)  # (failed points alike: NaN samples, period -1)
    status = np.concatenate([res.status for res in sorted(results, key=lambda r: r.index)])
    outside = int(Status.OUTSIDE_MODE)
    points = np.asarray(spec.points, dtype=float).reshape(-1)  # (in the order the sweep visits them)
    assert sorted(points) == sorted(amplitudes)
    np.testing.assert_array_equal(status, np.where(points > 0.5, outside, int(Status.OK)))
    fresh = run_chunks(dataclasses.replace(spec, fresh=True), list(range(spec.n_chunks)))
    np.testing.assert_array_equal(np.concatenate([r.status for r in fresh]), status)
