"""Switches of vector field without a reset: the soft-impact oscillator against its exact solution.

x'' + 2 zeta x' + x = a cos(w t) - k (x - gap) - c x' while x > gap (no reset).  The contact damper
``c`` (a test-only term) makes the field jump at the surface, so that a missing or wrong saltation
matrix changes the Jacobian.  The reference (tests/piecewise_exact.py) is matrix exponentials per
mode, switch times by Brent's method and the Jacobian as a product of exponentials and saltation
matrices.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from scipy.optimize import brentq

import grazing
from grazing import HybridModel, InvalidParameterError, Mode, Parameter, Surface, Tangent, Transition
from tests.piecewise_exact import LinearMode, PiecewiseLinearModel

x, v, t = sp.symbols("x v t")
zeta, a, w, gap, k, c = sp.symbols("zeta a omega gap k c")
VALUES = {"zeta": 0.05, "a": 1.0, "omega": 1.2, "gap": 0.5, "k": 4.0, "c": 0.3}
FREE = [v, -2 * zeta * v - x + a * sp.cos(w * t)]
CONTACT = [v, -2 * zeta * v - x + a * sp.cos(w * t) - k * (x - gap) - c * v]


def soft_impact(surface=False, **values):
    params = [Parameter(name, value) for name, value in VALUES.items()]
    modes = [Mode("free", FREE), Mode("contact", CONTACT)]
    if surface:
        kw = {"surfaces": [Surface("wall", gap - x, "free", "contact", sliding=False)]}
    else:
        kw = {"transitions": [Transition("touch", "free", "contact", gap - x),
                              Transition("leave", "contact", "free", x - gap)]}  # fmt: skip
    model = HybridModel("soft-impact", [x, v], t, params, modes=modes, period=2 * sp.pi / w, **kw)
    return model.with_params(**values)


def reference(p):
    A0 = np.array([[0.0, 1.0], [-1.0, -2 * p["zeta"]]])
    A1 = np.array([[0.0, 1.0], [-1.0 - p["k"], -2 * p["zeta"] - p["c"]]])
    b = np.array([0.0, p["a"]])
    free = LinearMode(A0, b, np.zeros(2), ((np.array([-1.0, 0.0]), p["gap"], 1),))
    contact = LinearMode(A1, b, np.array([0.0, p["k"] * p["gap"]]), ((np.array([1.0, 0.0]), -p["gap"], 0),))
    return PiecewiseLinearModel([free, contact], p["omega"])


@pytest.mark.parametrize("surface", [False, True], ids=["transitions", "surface"])
def test_soft_impact_oscillator_against_the_exact_solution(surface):
    m = soft_impact(surface)
    periods = 6
    sol = grazing.simulate(m, [0.0, 0.0], periods=periods, impacts="all", tangent=Tangent(jacobian=True))
    ref = reference(dict(m.params))
    T = m.period
    x_ref, mode, t_prev, J, switches = np.zeros(2), 0, 0.0, np.eye(2), []
    for i, ts in enumerate(sol.t):
        x_ref, mode, Jstep, sw = ref.run(x_ref, mode, t_prev, ts)
        J, t_prev = Jstep @ J, ts
        switches += sw
        assert np.allclose(sol.samples[i], x_ref, rtol=0, atol=1e-10), (i, sol.samples[i] - x_ref)
    assert sol.t[-1] == pytest.approx(periods * T, abs=1e-12)
    assert len(sol.impacts) == 0 and sol.n_impacts == 0
    assert len(sol.switches) == len(switches) >= 6
    assert np.abs(sol.switches.t - [s[0] for s in switches]).max() < 1e-12
    names = [sol.switches.source(i) + ">" + sol.switches.target(i) for i in range(len(sol.switches))]
    assert names == [("free>contact", "contact>free")[s[2]] for s in switches]
    assert np.allclose(sol.switches.state[:, 0], m.params["gap"], rtol=0, atol=1e-12)
    assert sol.mode_final == m.mode_names[mode]
    assert sol.jacobian_valid
    assert np.allclose(sol.jacobian, J, rtol=0, atol=1e-9 * max(1.0, np.abs(J).max())), sol.jacobian - J


def test_the_saltation_matters_here():
    """Without the contact damper's jump the reference Jacobian would differ: the test above sees S."""
    p = dict(VALUES)
    ref = reference(p)
    _, _, J, sw = ref.run(np.zeros(2), 0, 0.0, 3 * 2 * math.pi / p["omega"])
    assert len(sw) >= 2
    no_jump = PiecewiseLinearModel(ref.modes, ref.w)
    no_jump.f = lambda k_, x_, t_: ref.f(0, x_, t_)  # S = I: the Jacobian a missing saltation gives
    _, _, J0, _ = no_jump.run(np.zeros(2), 0, 0.0, 3 * 2 * math.pi / p["omega"])
    assert np.abs(J - J0).max() > 1e-3


def test_a_crossing_1e12_deep_is_found():
    """Unforced, from rest at x0: the free motion's first peak is 1e-12 beyond the surface."""
    p = {**VALUES, "a": 0.0}
    ref = reference({**p, "gap": 10.0})  # (no switch: the free flow alone)
    x0 = np.array([-1.0, 1.2])
    t_peak = brentq(lambda tt: ref.flow(0, x0, 0.0, tt)[1], 0.1, 3.0, xtol=1e-15)
    peak = ref.flow(0, x0, 0.0, t_peak)[0]
    m = soft_impact(**{**p, "gap": float(peak - 1e-12)})
    sol = grazing.simulate(m, x0, periods=1, impacts="all")
    assert len(sol.switches) == 2
    assert abs(sol.switches.t[0] - t_peak) < 1e-5 and sol.switches.name(0) == "touch"
    assert sol.switches.name(1) == "leave" and sol.mode_final == "free"


def test_start_in_another_mode_and_one_line_refusals():
    m = soft_impact()
    sol = grazing.simulate(m, [1.0, 0.0], periods=1, mode="contact", impacts="all")
    assert sol.switches.name(0) == "leave"
    # given no mode, it starts in the one it lies in (HybridModel.start_mode): the same run
    auto = grazing.simulate(m, [1.0, 0.0], periods=1, impacts="all")
    assert np.array_equal(auto.switches.t, sol.switches.t) and np.array_equal(auto.x_final, sol.x_final)
    with pytest.raises(InvalidParameterError, match=r"^unknown mode 'stuck' for model 'soft-impact'"):
        grazing.simulate(m, [0.0, 0.0], periods=1, mode="stuck")
    # the guard minima are the resets' only (tests/orbits/test_virtual_through_modes.py): this model has none
    sol = grazing.simulate(m, [0.0, 0.0], periods=1, guard_min=True)
    assert all(np.isinf(g[0]) for g in sol.guard_min_by_stop) and sol.approach_by_stop == (None, None)
    # a run from a grazing contact starts in the source mode of the transition touched
    with pytest.raises(InvalidParameterError, match=r"^a run from a grazing contact with transition 'leave' "
                       r"starts in its source mode 'contact', not in 'free'$"):  # fmt: skip
        grazing.simulate(m, [0.0, 0.0], periods=1, touching=True, stop_name="leave")


def test_parameter_sensitivities_across_switches_against_differences_of_the_exact_flow():
    """d x_final / d p for a guard's parameter (gap: the h_p term), a field's (c) and the period's (omega)."""
    m = soft_impact()
    periods = 3
    names = ("gap", "c", "omega")
    sol = grazing.simulate(m, [0.0, 0.0], periods=periods, tangent=Tangent(sensitivities=names))
    assert sol.jacobian.shape == (2, 5) and len(sol.switches) >= 4

    def final(**changes):
        p = {**dict(m.params), **changes}
        return reference(p).run(np.zeros(2), 0, 0.0, periods * 2 * math.pi / p["omega"])[0]

    for col, name in enumerate(names, start=2):
        eps = 1e-6
        value = m.params[name]
        fd = (final(**{name: value + eps}) - final(**{name: value - eps})) / (2 * eps)
        assert np.allclose(sol.jacobian[:, col], fd, rtol=0, atol=1e-7 * max(1.0, np.abs(fd).max())), (
            name,
            fd,
        )


def test_opposing_fields_end_in_one_line_not_a_hang():
    """Fields pushing into each other switch at zero time: a one-line error naming the modes."""
    model = HybridModel(
        "opposing", [x, v], t, [Parameter("omega", 1.0, lower=0, lower_open=True)], period=2 * sp.pi / w,
        modes=[Mode("up", [-1 + 0 * v, sp.cos(w * t)]), Mode("down", [1 + 0 * v, sp.cos(w * t)])],
        transitions=[Transition("touch", "up", "down", x), Transition("leave", "down", "up", -x)],
    )  # fmt: skip
    with pytest.raises(grazing.SimulationError) as info:
        grazing.simulate(model, [1.0, 0.0], periods=3)
    message = str(info.value)
    assert (
        "modes 'down', 'up' switch back and forth at zero time at t = 1 " in message and "\n" not in message
    )
    assert "declare their boundary as a Surface with sliding=True" in message
