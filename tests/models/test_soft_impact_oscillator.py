"""The built-in soft-impact oscillator against its exact piecewise-linear solution.

x'' + 2 zeta x' + x = a cos(omega t) - k (x - gap) while x > gap, no reset.  Each mode is linear, so
the reference (tests/piecewise_exact.py) is matrix exponentials per mode with the switch times found by
Brent's method on the exact solution: samples to 1e-10, switch times to 1e-12, the mode of every sample,
and the Jacobian (the field is continuous at x = gap: S = I).
"""

from __future__ import annotations

import numpy as np
import pytest

import grazing
from grazing.models import soft_impact_oscillator
from tests.piecewise_exact import LinearMode, PiecewiseLinearModel


def reference(p):
    free = np.array([[0.0, 1.0], [-1.0, -2 * p["zeta"]]])
    contact = np.array([[0.0, 1.0], [-1.0 - p["k"], -2 * p["zeta"]]])
    b = np.array([0.0, p["a"]])
    modes = [
        LinearMode(free, b, np.zeros(2), ((np.array([-1.0, 0.0]), p["gap"], 1),)),
        LinearMode(contact, b, np.array([0.0, p["k"] * p["gap"]]), ((np.array([1.0, 0.0]), -p["gap"], 0),)),
    ]
    return PiecewiseLinearModel(modes, p["omega"])


@pytest.mark.parametrize(
    "values", [{}, {"k": 20.0, "omega": 1.7, "gap": 0.3}, {"zeta": 0.02, "a": 0.4, "gap": -0.1, "omega": 0.8}]
)
def test_against_the_exact_solution(values):
    m = soft_impact_oscillator(**values)
    x0 = [0.0, 0.0] if m.params["gap"] > 0 else [-0.5, 0.0]
    sol = grazing.simulate(m, x0, periods=8, impacts="all", tangent=grazing.Tangent(jacobian=True))
    ref = reference(dict(m.params))
    x, mode, t_prev, J, switches, modes = np.array(x0), 0, 0.0, np.eye(2), [], []
    for ts in sol.t:
        x, mode, step, sw = ref.run(x, mode, t_prev, ts)
        J, t_prev = step @ J, ts
        switches += sw
        modes.append(mode)
        assert np.abs(x - sol.samples[len(modes) - 1]).max() < 1e-10
    assert len(switches) >= 8 and len(sol.impacts) == 0
    assert len(sol.switches) == len(switches)
    assert np.abs(sol.switches.t - [s[0] for s in switches]).max() < 1e-12
    names = [("touch", "leave")[s[2]] for s in switches]
    assert [sol.switches.name(i) for i in range(len(switches))] == names
    assert np.abs(sol.switches.state[:, 0] - m.params["gap"]).max() < 1e-12
    assert sol.modes.tolist() == modes
    assert set(modes) == {0, 1} or values  # (the default's samples are in both modes)
    assert sol.mode_names == ("free", "contact") and sol.mode_final == sol.mode_names[mode]
    assert np.allclose(sol.jacobian, J, rtol=0, atol=1e-9 * max(1.0, np.abs(J).max()))


@pytest.mark.parametrize(
    "start", [(3, [0.0, 0.0], None), (0, [1.0, 0.0], "contact")], ids=["settled", "contact"]
)
def test_mode_spans_follow_the_switches(start):
    """Each stay's mode is the side of x = gap that the dense trajectory is on inside it (from a start in
    contact, too, where the first sample is in free flight)."""
    m = soft_impact_oscillator()
    transient, x0, mode = start
    sol = grazing.simulate(m, x0, transient=transient, periods=4, trajectory=400, mode=mode)
    spans = sol.mode_spans()
    assert len(spans) == len(sol.switches) + 1 >= 5
    assert transient or spans[0][2] == m.mode_index(mode)  # the mode it starts in
    assert spans[0][0] == sol.trajectory_t[0] and spans[-1][1] == sol.t_final
    assert next(k for _, end, k in spans if end > sol.t[0]) == sol.modes[0]  # the first sample's stay
    gap = m.params["gap"]
    for start, end, k in spans:
        inside = (sol.trajectory_t > start + 1e-9) & (sol.trajectory_t < end - 1e-9)
        assert inside.any()
        assert np.all((sol.trajectory[inside, 0] > gap) == (k == 1))


def test_one_mode_solutions_have_no_modes():
    sol = grazing.simulate(grazing.models.impact_oscillator(), [0.0, 0.0], periods=2)
    assert sol.modes is None and sol.switches is None and sol.mode_spans() == []
    assert sol.mode_names == ("free",)
