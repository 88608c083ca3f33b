"""Runs without events (``events=False``) on models with modes: the resets are ignored, the switches are not.

The soft-impact oscillator with a rigid wall inside its contact (``soft_hard``): a spring-damper contact
beyond ``gap`` (a switch of vector field, no reset) and a wall at ``wall > gap`` inside the contact mode
that reverses the velocity (``v <- -r v``, a reset).  Without events the run must pass through the wall
and still switch in and out of the contact: the exact solution (tests/piecewise_exact.py) of the model
without the wall.  The rocking block (tests/engine/test_rocking_modes.py), whose only transitions are
resets that change the mode, then stays in its first mode: the exact flow of that mode alone.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

import grazing
from grazing import HybridModel, Mode, Parameter, Stop, Tangent, Transition
from tests.engine.test_rocking_modes import reference as rocking_reference
from tests.engine.test_rocking_modes import rocking_block
from tests.piecewise_exact import LinearMode, PiecewiseLinearModel

x, v, t = sp.symbols("x v t")
zeta, a, w, gap, k, c, wall, r = sp.symbols("zeta a omega gap k c wall r")
VALUES = {"zeta": 0.05, "a": 1.0, "omega": 1.2, "gap": 0.5, "k": 4.0, "c": 0.3, "wall": 0.7, "r": 0.8}
FREE = [v, -2 * zeta * v - x + a * sp.cos(w * t)]
CONTACT = [v, -2 * zeta * v - x + a * sp.cos(w * t) - k * (x - gap) - c * v]


def soft_hard(**values: float) -> HybridModel:
    """A soft contact beyond ``gap`` (switches ``touch``/``leave``) and a rigid wall at ``wall`` inside it
    (the contact mode's stop ``wall``, ``v <- -r v``); the contact damper ``c`` makes the field jump at the
    switching surface, so that a missing saltation matrix shows."""
    params = [Parameter(name, value) for name, value in VALUES.items()]
    model = HybridModel(
        "soft-hard", [x, v], t, params,
        modes=[Mode("free", FREE), Mode("contact", CONTACT, stops=[Stop("wall", wall - x, [x, -r * v])])],
        transitions=[Transition("touch", "free", "contact", gap - x),
                     Transition("leave", "contact", "free", x - gap)],
        period=2 * sp.pi / w,
    )  # fmt: skip
    return model.with_params(**values)


def reference(p: dict, walls: bool = True) -> PiecewiseLinearModel:
    """The exact solution of :func:`soft_hard` with parameters ``p`` (without its wall: ``walls=False``)."""
    A0 = np.array([[0.0, 1.0], [-1.0, -2 * p["zeta"]]])
    A1 = np.array([[0.0, 1.0], [-1.0 - p["k"], -2 * p["zeta"] - p["c"]]])
    b = np.array([0.0, p["a"]])
    leave = (np.array([1.0, 0.0]), -p["gap"], 0)
    hit = (np.array([-1.0, 0.0]), p["wall"], 1, np.diag([1.0, -p["r"]]))
    free = LinearMode(A0, b, np.zeros(2), ((np.array([-1.0, 0.0]), p["gap"], 1),))
    contact = LinearMode(A1, b, np.array([0.0, p["k"] * p["gap"]]), (leave, hit) if walls else (leave,))
    return PiecewiseLinearModel([free, contact], p["omega"])


def test_the_model_has_a_reset_and_two_switches():
    m = soft_hard()
    assert m.stop_names == ("touch", "wall", "leave")
    assert m.transition_resets == (False, True, False)


def test_without_events_the_wall_is_passed_and_the_contact_still_switches():
    m = soft_hard()
    periods = 5
    x0 = np.zeros(2)
    sol = grazing.simulate(
        m, x0, periods=periods, events=False, impacts="all", tangent=Tangent(jacobian=True), trajectory=50
    )  # fmt: skip
    walls = grazing.simulate(m, x0, periods=periods, impacts="all")
    assert len(walls.impacts) >= 3  # (with events the wall is hit: the run below must pass it)
    ref = reference(dict(m.params), walls=False)
    state, mode, t_prev, J, switches = x0, 0, 0.0, np.eye(2), []
    for i, ts in enumerate(sol.t):
        state, mode, step, sw = ref.run(state, mode, t_prev, ts)
        J, t_prev = step @ J, ts
        switches += sw
        assert np.abs(sol.samples[i] - state).max() < 1e-10, (i, sol.samples[i] - state)
    assert len(sol.impacts) == 0 and sol.n_impacts == 0
    assert np.max(sol.trajectory[:, 0]) > m.params["wall"] + 0.05  # (the flow goes well beyond the wall)
    assert len(sol.switches) == len(switches) >= 6
    assert np.abs(sol.switches.t - [s[0] for s in switches]).max() < 1e-12
    assert [sol.switches.name(i) for i in range(len(sol.switches))] == [
        ("touch", "leave")[s[2]] for s in switches
    ]
    assert sol.mode_final == m.mode_names[mode] and sol.jacobian_valid
    assert np.abs(sol.jacobian - J).max() < 1e-9 * max(1.0, np.abs(J).max()), sol.jacobian - J


def test_without_events_a_start_beyond_the_wall_is_allowed_but_not_one_outside_its_mode():
    m = soft_hard()
    beyond = [m.params["wall"] + 0.1, 0.0]
    sol = grazing.simulate(m, beyond, periods=1, events=False, mode="contact", impacts="all")
    assert len(sol.impacts) == 0 and len(sol.switches) >= 1
    try:
        grazing.simulate(m, [0.0, 0.0], periods=1, events=False, mode="contact")
    except grazing.InvalidStateError as exc:
        assert "is not in mode 'contact'" in str(exc) and "\n" not in str(exc)
    else:
        raise AssertionError("a state outside the contact was accepted in mode 'contact'")


def test_without_events_the_rocking_block_keeps_its_corner():
    """Its transitions are resets that change the mode: without events none happens."""
    m = rocking_block()
    x0 = np.array([0.1, 0.0])
    sol = grazing.simulate(m, x0, periods=2, events=False, impacts="all")
    with_events = grazing.simulate(m, x0, periods=2, impacts="all")
    assert len(with_events.switches) >= 2
    ref = rocking_reference(dict(m.params))
    expected = np.array([ref.flow(0, x0, 0.0, ts) for ts in sol.t])
    assert np.abs(sol.samples - expected).max() < 1e-9 * max(1.0, np.abs(expected).max())
    assert np.min(expected[:, 0]) < 0.0  # (the exact corner's flow crosses theta = 0: the resets' guard)
    assert len(sol.switches) == 0 and len(sol.impacts) == 0 and sol.mode_final == m.mode_names[0]
