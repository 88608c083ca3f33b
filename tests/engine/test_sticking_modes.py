"""Sticking to a stop inside a model with modes: a mode's own impact stop chatters and sticks, its other
transitions still fire while it sticks, and the release returns to the mode.

Three models: the bouncing ball with a second mode it never enters (bit for bit the one-mode ball);
a forced mass on a rigid floor with a soft spring region above it (sticks, is released by the forcing,
then enters the spring); a forced mass on a rigid floor lifted by a time-switched pull (the switch
fires while it sticks).  Both forced masses are piecewise ``x'' = a cos(omega t) - g + c`` (the spring
linear), so their stick, release and switch times are roots of closed forms (brentq, 1e-10); the floor's
restitution is 0, so each impact sticks at once.  Sweeps on lanes equal the scalar runs bit for bit.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import sympy as sp
from scipy.optimize import brentq

import grazing
from grazing import HybridModel, Mode, Parameter, Stop, Transition
from grazing.core.options import SweepSettings
from grazing.engine.codegen import generate_source
from grazing.engine.runner import Runner
from grazing.models import bouncing_ball
from grazing.sweeps.run import run_chunks
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_lanes import assert_lanes_equal_the_oracle

x, v, t = sp.symbols("x v t")
a, w, g, k, d, r, pull, c0, phi = sp.symbols("a omega g k d r P c phi")
FORCE = a * sp.cos(w * t) - g
FORCED = [
    Parameter("a", 2.0), Parameter("omega", 1.0), Parameter("g", 1.0), Parameter("k", 4.0),
    Parameter("d", 1.5), Parameter("r", 0.0), Parameter("P", 3.2), Parameter("c", 0.825),
    Parameter("phi", 4.2),
]  # fmt: skip
FLOOR = Stop("floor", x, [x, -r * v], contact_direction=[0, 1])
START = dict(x0=[0.3, 0.0], t0=math.pi)


def ball_with_unused_mode() -> HybridModel:
    """The built-in bouncing ball, with a second mode behind a transition whose guard is never reached."""
    y, yv, tt = sp.symbols("y v t")
    amp, om, grav, rr = sp.symbols("amplitude omega gravity r")
    table = amp * sp.sin(om * tt)
    stop = Stop("stop", y - table, [y, (1 + rr) * sp.diff(table, tt) - rr * yv], contact_direction=[0, 1])
    params = [
        Parameter("amplitude", 0.1),
        Parameter("omega", 3.5),
        Parameter("gravity", 1.0),
        Parameter("r", 0.5),
    ]
    return HybridModel(
        "ball-modes", [y, yv], tt, params, period=2 * sp.pi / om,
        modes=[Mode("fly", [yv, -grav], stops=[stop]), Mode("away", [yv, -y])],
        transitions=[Transition("go", "fly", "away", 100 - y), Transition("back", "away", "fly", y - 100)],
    )  # fmt: skip


def stick_spring() -> HybridModel:
    """A forced mass on a rigid floor (``x >= 0``) with a soft spring region ``x > d`` above it."""
    return HybridModel(
        "stick-spring", [x, v], t, FORCED, period=2 * sp.pi / w,
        modes=[Mode("free", [v, FORCE], stops=[FLOOR]), Mode("spring", [v, FORCE - k * (x - d)])],
        transitions=[
            Transition("touch", "free", "spring", d - x), Transition("leave", "spring", "free", x - d),
        ],
    )  # fmt: skip


def stick_spring_floor_second() -> HybridModel:
    """:func:`stick_spring`, its modes the other way round: the floor is transition 1, row 0 of its mode."""
    return HybridModel(
        "stick-spring-2", [x, v], t, FORCED, period=2 * sp.pi / w, initial_mode="free",
        modes=[Mode("spring", [v, FORCE - k * (x - d)]), Mode("free", [v, FORCE], stops=[FLOOR])],
        transitions=[
            Transition("touch", "free", "spring", d - x), Transition("leave", "spring", "free", x - d),
        ],
    )  # fmt: skip


def stick_lift() -> HybridModel:
    """A forced mass on a rigid floor, pulled up by ``P`` while ``cos(omega t - phi) > c`` (switches in time
    only, which fire while the mass sticks; the pull lifts it, ``a cos + P - g > 0``, so it has no floor)."""
    return HybridModel(
        "stick-lift", [x, v], t, FORCED, period=2 * sp.pi / w,
        modes=[Mode("free", [v, FORCE], stops=[FLOOR]), Mode("pulled", [v, FORCE + pull])],
        transitions=[
            Transition("lift", "free", "pulled", c0 - sp.cos(w * t - phi)),
            Transition("drop", "pulled", "free", sp.cos(w * t - phi) - c0),
        ],
    )  # fmt: skip


# --- the exact reference ------------------------------------------------------------------------------

A, W, G, K, D, P, C, PHI = 2.0, 1.0, 1.0, 4.0, 1.5, 3.2, 0.825, 4.2


def flight(t0: float, x0: float, v0: float, c: float, tt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``x'' = A cos(W t) - G + c`` from ``(x0, v0)`` at ``t0``: position and velocity at ``tt``."""
    s = tt - t0
    vel = v0 + (c - G) * s + A / W * (np.sin(W * tt) - math.sin(W * t0))
    pos = (
        x0
        + (v0 - A / W * math.sin(W * t0)) * s
        + (c - G) * s**2 / 2
        - A / W**2 * (np.cos(W * tt) - math.cos(W * t0))
    )
    return pos, vel


def spring(t0: float, x0: float, v0: float, tt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``y'' + K y = A cos(W t) - G`` with ``y = x - D``: position and velocity at ``tt``."""
    kap = math.sqrt(K)
    yp = -G / K + A * np.cos(W * tt) / (K - W**2)
    ypd = -A * W * np.sin(W * tt) / (K - W**2)
    c0 = x0 - D - (-G / K + A * math.cos(W * t0) / (K - W**2))
    s0 = (v0 - (-A * W * math.sin(W * t0) / (K - W**2))) / kap
    s = tt - t0
    pos = D + yp + c0 * np.cos(kap * s) + s0 * np.sin(kap * s)
    vel = ypd - c0 * kap * np.sin(kap * s) + s0 * kap * np.cos(kap * s)
    return pos, vel


def first_root(fun, start: float, end: float, *args: float, dt: float = 1e-3) -> float:
    """The first time in ``(start, end]`` where ``fun(t, *args)`` (positive just after ``start``) reaches 0,
    or inf."""
    tt = np.arange(start + 1e-6, end + dt, dt)
    vals = fun(tt, *args)
    lifted = np.nonzero(vals > 1e-12)[0][0]  # (a guard that starts at 0: rounding first)
    assert lifted <= 2
    below = np.nonzero(vals[lifted:] <= 0.0)[0]
    if not below.size:
        return math.inf
    i = lifted + below[0]
    return brentq(lambda s: float(fun(np.array([s]), *args)[0]), tt[i - 1], tt[i], xtol=1e-15)


def height(tt, t0, x0, v0, c):
    return flight(t0, x0, v0, c, tt)[0]


def below_spring(tt, t0, x0, v0, c):
    return D - flight(t0, x0, v0, c, tt)[0]


def in_spring(tt, t0, x0, v0):
    return spring(t0, x0, v0, tt)[0] - D


def clock(tt, sign):
    """The time switches' guards: ``C - cos(W t - PHI)`` in free flight (``sign`` 1), its negative pulled."""
    return sign * (C - np.cos(W * tt - PHI))


def contact_force(tt):
    """The floor's force on the mass at rest on it, ``-(A cos(W t) - G)`` (the release at its zero)."""
    return G - A * np.cos(W * tt)


def reference(model: str, t_end: float) -> dict[str, list]:
    """Stick intervals, impacts and switches ``(t, transition)`` of ``model`` from ``START`` to ``t_end``."""
    t0, (x0, v0) = START["t0"], START["x0"]
    mode, out = "free", {"stick": [], "impacts": [], "switches": []}
    end = t_end + 10
    while t0 < t_end:
        if mode == "stuck":  # released by the force (stick-spring) or lifted by the switch (stick-lift)
            force = first_root(contact_force, t0, end)
            lift = first_root(clock, t0, end, 1.0) if model == "lift" else math.inf
            t1 = min(force, lift)
            out["stick"].append((t0, t1))
            t0, x0, v0, mode = t1, 0.0, 0.0, "free" if t1 == force else "pulled"
            if mode == "pulled":
                out["switches"].append((t1, 1))
            continue
        if mode in ("free", "pulled"):
            c = P if mode == "pulled" else 0.0
            events = {"floor": first_root(height, t0, end, t0, x0, v0, c)}
            if model == "spring":
                events["touch"] = first_root(below_spring, t0, end, t0, x0, v0, c)
            else:  # (the switches in time)
                events["time"] = first_root(clock, t0, end, 1.0 if mode == "free" else -1.0)
            name = min(events, key=events.__getitem__)
            t1 = events[name]
            (x1,), (v1,) = flight(t0, x0, v0, c, np.array([t1]))
            if name == "floor":
                assert mode == "free" and A * math.cos(W * t1) - G < 0.0  # (r = 0: it sticks at once)
                out["impacts"].append(t1)
                t0, x0, v0, mode = t1, 0.0, 0.0, "stuck"
            elif name == "touch":
                out["switches"].append((t1, 1))
                t0, x0, v0, mode = t1, x1, v1, "spring"
            else:
                out["switches"].append((t1, 1 if mode == "free" else 2))
                t0, x0, v0, mode = t1, x1, v1, "pulled" if mode == "free" else "free"
        else:  # the spring, until it leaves at x = D
            t1 = first_root(in_spring, t0, end, t0, x0, v0)
            (x1,), (v1,) = spring(t0, x0, v0, np.array([t1]))
            out["switches"].append((t1, 2))
            t0, x0, v0, mode = t1, x1, v1, "free"
    return {
        key: [e for e in val if (e[0] if isinstance(e, tuple) else e) < t_end] for key, val in out.items()
    }


# --- the tests ----------------------------------------------------------------------------------------


def test_an_unentered_mode_changes_no_bit_of_chattering_and_sticking() -> None:
    """(a) The ball on its table chatters, sticks and is released 40 times: with a second mode it never
    enters, the samples, impacts and sticking intervals are the one-mode ball's, bit for bit."""
    one = grazing.simulate(
        bouncing_ball(omega=3.5, r=0.5), [0.5, 0.0], transient=0, periods=40, impacts="all"
    )
    two = grazing.simulate(ball_with_unused_mode(), [0.5, 0.0], transient=0, periods=40, impacts="all")
    assert len(one.sticking) == 40 and len(one.impacts) > 1000  # (it chatters and sticks every period)
    assert np.array_equal(one.samples, two.samples)
    assert np.array_equal(one.sticking, two.sticking)
    assert np.array_equal(one.impacts.t, two.impacts.t) and np.array_equal(
        one.impacts.state, two.impacts.state
    )
    assert np.array_equal(one.x_final, two.x_final) and len(two.switches) == 0
    assert two.mode_final == "fly" and set(two.modes.tolist()) == {0}


@pytest.mark.parametrize(("make", "name"), [(stick_spring, "spring"), (stick_lift, "lift")])
def test_sticking_and_switches_against_the_closed_form(make, name) -> None:
    """(b) Stick start (an impact at restitution 0) and end (the force's zero, or a switch while it sticks),
    the switches, to 1e-10; the modes of the samples."""
    periods = 6
    sol = grazing.simulate(make(), START["x0"], t0=START["t0"], transient=0, periods=periods, impacts="all")
    ref = reference(name, sol.t_final)
    assert len(ref["stick"]) >= periods // 2 and len(ref["switches"]) >= 2 * periods - 2  # (the scenario)
    np.testing.assert_allclose(sol.sticking, np.array(ref["stick"]), rtol=0, atol=1e-10)
    np.testing.assert_allclose(sol.impacts.t, ref["impacts"], rtol=0, atol=1e-10)
    assert sol.switches.transition.tolist() == [j for _, j in ref["switches"]]
    np.testing.assert_allclose(sol.switches.t, [s for s, _ in ref["switches"]], rtol=0, atol=1e-10)
    if name == "lift":  # each stick ends at the switch, which fires while it sticks
        assert set(sol.sticking[:, 1].tolist()) <= set(sol.switches.t[sol.switches.transition == 1].tolist())
    else:  # each stick ends at the force's zero (a cos(omega t) = g, rising)
        np.testing.assert_allclose(
            np.mod(sol.sticking[:, 1], 2 * math.pi), 5 * math.pi / 3, rtol=0, atol=1e-10
        )
    assert np.all(sol.samples[:, 0] >= -1e-12)  # (never below the floor)


def test_the_order_of_the_modes_changes_no_bit() -> None:
    """The floor in the second mode (transition 1, its mode's event row 0): the same run, bit for bit (the
    contact force's row, not the stop's index, sets the sticking step's scale)."""
    runs = [
        grazing.simulate(make(), START["x0"], t0=START["t0"], transient=0, periods=6, impacts="all")
        for make in (stick_spring, stick_spring_floor_second)
    ]
    assert stick_spring_floor_second().stop_names == ("leave", "floor", "touch")
    assert len(runs[0].sticking) == 6
    assert np.array_equal(runs[0].samples, runs[1].samples)
    assert np.array_equal(runs[0].sticking, runs[1].sticking)
    assert np.array_equal(runs[0].switches.t, runs[1].switches.t)
    assert np.array_equal(runs[0].impacts.t, runs[1].impacts.t)


def test_sticking_marks_the_jacobian_invalid_and_a_smooth_run_keeps_it() -> None:
    """Sticking (through modes as in one) has no variational equations: the Jacobian is marked invalid."""
    stuck = Runner(stick_lift(), START["x0"], t0=START["t0"], variational=True)
    assert not stuck.advance(3, 3).jacobian_valid
    free = Runner(stick_lift(), [30.0, 0.0], t0=0.1, variational=True)
    seg = free.advance(1, 1, impacts="all")
    assert seg.jacobian_valid and len(seg.switches) == 2  # (high above the floor: switches only)
    sol = grazing.simulate(stick_spring(), START["x0"], t0=START["t0"], transient=0, periods=3, jacobian=True)
    assert not sol.jacobian_valid


@pytest.mark.parametrize(("make", "top"), [(stick_spring, 2.4), (stick_lift, 1.95)])
def test_sweep_with_sticking_on_lanes_equals_the_runner_oracle(make, top) -> None:
    """(c) Sweeps through sticking and switches: lanes bit-identical to the scalar Runner oracle.

    (The lift has no floor while it pulls: above a = 2 a mass still falling when the pull begins goes
    through the floor, and the drop back then enters ``free`` beyond its floor, which ends the run:
    :func:`test_the_lift_above_a_2_ends_outside_its_mode`.)"""
    values = np.linspace(1.6, top, 8)
    settings_ = SweepSettings(transient=12, periods=6, chunk_size=4, adaptive=False, lyapunov=False)
    spec = dataclasses.replace(
        sweep_spec(make(), "a", values, x0=(0.3, 0.0), settings=settings_), polish=False
    )
    assert_lanes_equal_the_oracle(spec)
    for value in values[::3]:  # (the points stick)
        sol = grazing.simulate(make().with_params(a=float(value)), [0.3, 0.0], transient=12, periods=6)
        assert len(sol.sticking) > 0


def test_the_lift_above_a_2_ends_outside_its_mode() -> None:
    """The lift at a = 2.4 is ill-posed (no floor while it pulls): the run ends where the drop enters
    ``free`` below its floor, said in one line, on the scalar driver and on lanes alike."""
    model = stick_lift().with_params(a=2.4)
    with pytest.raises(grazing.SimulationError, match=r"entered mode 'free' .* outside its region"):
        grazing.simulate(model, [0.3, 0.0], transient=12, periods=6)
    settings_ = SweepSettings(
        transient=12, periods=6, chunk_size=4, adaptive=False, lyapunov=False, fresh=True
    )
    spec = sweep_spec(stick_lift(), "a", [1.6, 2.4], x0=(0.3, 0.0), settings=settings_)
    statuses = np.concatenate([r.status for r in run_chunks(spec, range(spec.n_chunks))])
    assert statuses.tolist() == [0, 5]


def test_a_sweep_through_sticking_has_no_lyapunov_exponent() -> None:
    """Sticking has no variational equations: a sweep point that sticks in its sampled span reports NaN
    (as in a model of one mode), on lanes as in the scalar oracle."""
    settings_ = SweepSettings(transient=12, periods=6, chunk_size=4, adaptive=False, lyapunov=True)
    values = [1.8, 2.0, 2.2, 2.4]
    spec = sweep_spec(stick_spring(), "a", values, x0=(0.3, 0.0), settings=settings_)
    res = assert_lanes_equal_the_oracle(dataclasses.replace(spec, polish=False), scalar=False, regroup=False)
    assert np.all(np.isnan(np.concatenate([r.lyapunov for r in res])))


def test_sticking_kernels_per_mode_and_by_stop() -> None:
    """A sticking kernel per sticking stop, with its mode's event rows, dispatched by the stop's index:
    with a stop that does not stick first, the floor (stop 1) sticks by its own kernel, not the roof's
    (the dispatch's cases are positions in its list), as the same mass with its floor alone does."""
    src = generate_source(stick_spring().symbolic)
    assert src.sizes["sticks"] == [True, False, False]
    assert src.dispatch["tc_stick"] == ["tc_stick_s0"] * 3
    y, yv, tt = sp.symbols("y v t")
    wall = Stop("wall", 5 - y, [y, -yv])
    floor = Stop("floor", y, [y, -0.5 * yv], contact_direction=[0, 1])
    roof = Stop("roof", 4 - y, [y, -0.5 * yv], contact_direction=[0, 1])
    field = [yv, 2 * sp.cos(tt) - 1]
    runs = []
    for stops in ([wall, floor, roof], [floor]):
        model = HybridModel("three", [y, yv], tt, [], field, period=2 * sp.pi, stops=stops)
        runs.append(grazing.simulate(model, [0.3, 0.0], t0=math.pi, transient=0, periods=4, impacts="all"))
    assert len(runs[1].sticking) >= 1 and len(runs[1].impacts) > 20  # (it chatters, sticks and is released)
    np.testing.assert_allclose(runs[0].sticking, runs[1].sticking, rtol=0, atol=1e-12)
    np.testing.assert_allclose(runs[0].impacts.t, runs[1].impacts.t, rtol=0, atol=1e-12)
    three = HybridModel("three", [y, yv], tt, [], field, period=2 * sp.pi, stops=[wall, floor, roof])
    assert generate_source(three.symbolic).dispatch["tc_stick"] == [
        "tc_stick_s1",
        "tc_stick_s1",
        "tc_stick_s2",
    ]


def test_a_contact_direction_on_a_switch_is_refused_in_one_line() -> None:
    with pytest.raises(
        ValueError, match="is for sticking to a stop: it needs a reset back to its own mode"
    ) as info:
        HybridModel(
            "bad", [x, v], t, FORCED, period=2 * sp.pi / w,
            modes=[Mode("free", [v, FORCE], stops=[FLOOR]), Mode("spring", [v, FORCE - k * (x - d)])],
            transitions=[
                Transition("touch", "free", "spring", d - x, contact_direction=[0, 1]),
                Transition("leave", "spring", "free", x - d),
            ],
        )  # fmt: skip
    assert "\n" not in str(info.value)
