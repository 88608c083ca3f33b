"""Resets that change the mode: the linearised rocking block (Housner) against its exact solution.

theta'' = p^2 (theta - alpha) + a cos(w t) on the right corner (theta > 0), p^2 (theta + alpha) + a cos(w t)
on the left one (theta < 0); at theta = 0 the block lands on the other corner: the angular velocity is
multiplied by r and the mode changes.  The reference (tests/piecewise_exact.py) is matrix exponentials per
mode, impact times by Brent's method and the Jacobian as a product of exponentials and saltation matrices
``S = R + (f+ - R f-) h_x / (h_x f-)`` with ``f+`` the other corner's field.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

import grazing
from grazing import HybridModel, Mode, Parameter, Tangent, Transition
from tests.piecewise_exact import LinearMode, PiecewiseLinearModel

th, om, t = sp.symbols("theta omega_b t")
p, alpha, a, w, r = sp.symbols("p alpha a omega r")
# Sustained rocking below overturning (|theta| < 0.13 < alpha) for 6 periods, impacts 0.3 apart or more.
VALUES = {"p": 1.0, "alpha": 0.2, "a": 0.3, "omega": 3.0, "r": 0.9}


def rocking_block():
    params = [Parameter(name, value) for name, value in VALUES.items()]
    modes = [Mode("right_corner", [om, p**2 * (th - alpha) + a * sp.cos(w * t)]),
             Mode("left_corner", [om, p**2 * (th + alpha) + a * sp.cos(w * t)])]  # fmt: skip
    land = [th, r * om]  # (the same corner-change reset both ways)
    transitions = [Transition("onto_left", "right_corner", "left_corner", th, reset=land),
                   Transition("onto_right", "left_corner", "right_corner", -th, reset=land)]  # fmt: skip
    return HybridModel(
        "rocking", [th, om], t, params, modes=modes, transitions=transitions, period=2 * sp.pi / w
    )


def reference(q):
    A = np.array([[0.0, 1.0], [q["p"] ** 2, 0.0]])
    b = np.array([0.0, q["a"]])
    R = np.diag([1.0, q["r"]])
    d = np.array([0.0, q["p"] ** 2 * q["alpha"]])
    right = LinearMode(A, b, -d, ((np.array([1.0, 0.0]), 0.0, 1, R),))
    left = LinearMode(A, b, d, ((np.array([-1.0, 0.0]), 0.0, 0, R),))
    return PiecewiseLinearModel([right, left], q["omega"])


def run_reference(ref, times, x0):
    x, mode, t_prev, J, events = np.asarray(x0, dtype=float), 0, 0.0, np.eye(2), []
    samples = []
    for ts in times:
        x, mode, Jstep, ev = ref.run(x, mode, t_prev, ts)
        J, t_prev = Jstep @ J, ts
        events += ev
        samples.append(x)
    return np.array(samples), mode, J, events


def test_rocking_block_against_the_exact_solution():
    m = rocking_block()
    periods = 6
    x0 = [0.1, 0.0]
    sol = grazing.simulate(m, x0, periods=periods, impacts="all", tangent=Tangent(jacobian=True))
    samples, mode, J, events = run_reference(reference(dict(m.params)), sol.t, x0)
    assert np.abs(sol.samples - samples).max() < 1e-10, sol.samples - samples
    assert len(events) >= 8
    times = np.array([e[0] for e in events])
    # every corner change is an impact (state before it) and a switch (state after the reset)
    assert len(sol.impacts) == len(sol.switches) == len(events)
    assert np.abs(sol.impacts.t - times).max() < 1e-12
    assert np.abs(sol.switches.t - times).max() < 1e-12
    expected = [("onto_left", "onto_right")[e[2]] for e in events]
    assert [sol.switches.name(i) for i in range(len(events))] == expected
    assert [m.stop_names[j] for j in sol.impacts.stop] == expected
    assert [sol.switches.target(i) for i in range(len(events))] == [m.mode_names[e[3]] for e in events]
    assert np.allclose(sol.switches.state[:, 1], VALUES["r"] * sol.impacts.state[:, 1], rtol=1e-12, atol=0)
    assert np.abs(sol.impacts.state[:, 0]).max() < 1e-12
    assert sol.mode_final == m.mode_names[mode]
    assert sol.jacobian_valid
    assert np.allclose(sol.jacobian, J, rtol=0, atol=1e-9 * max(1.0, np.abs(J).max())), sol.jacobian - J


def test_the_target_field_matters_in_the_saltation():
    """With f+ the source corner's field (a wrong saltation) the reference Jacobian differs."""
    ref = reference(VALUES)
    T = 2 * np.pi / VALUES["omega"]
    _, _, J, events = run_reference(ref, [3 * T], [0.1, 0.0])
    assert len(events) >= 3
    source_field = PiecewiseLinearModel(ref.modes, ref.w)
    calls = []

    def f_source(k_, x_, t_):  # called as f(k, xz) for f- then f(target, R xz) for f+: give f+ the source's
        calls.append(k_)
        return ref.f(calls[-2] if len(calls) % 2 == 0 else k_, x_, t_)

    source_field.f = f_source
    _, _, J0, _ = run_reference(source_field, [3 * T], [0.1, 0.0])
    assert np.abs(J - J0).max() > 1e-3 * np.abs(J).max()
