"""Virtual orbits of a model with modes: the impacts' guard minima, each over its source mode only.

The soft-hard oscillator (tests/engine/test_events_off_modes.py: a soft contact beyond ``gap``, a rigid
wall at ``wall`` inside it) with its wall ignored is piecewise linear: its period-1 orbit is solved
exactly as a boundary-value problem in its switch times (matrix exponentials, ``fsolve``), and the
wall's guard minimum is ``wall`` less the largest ``x`` of the contact segment, where ``v = 0``.  A wall
declared in the free mode beyond the gap is never reached there: its guard minimum is its value where
the free mode is left or entered (``wall - gap``, at the switches), although the contact segment goes far
past it.
"""

from __future__ import annotations

import numpy as np
import sympy as sp
from scipy.optimize import brentq, fsolve

import grazing
from grazing import HybridModel, Mode, Parameter, Stop, Transition
from grazing.orbits import find_orbit
from grazing.orbits.grazing import find_grazings, grazing_curve
from tests.engine.test_events_off_modes import (
    CONTACT,
    FREE,
    VALUES,
    gap,
    r,
    reference,
    soft_hard,
    t,
    v,
    w,
    wall,
    x,
)


def exact_virtual_orbit(p: dict, t0: float, guess) -> tuple[np.ndarray, float, float, float]:
    """The wall-less period-1 orbit of soft_hard from ``t0`` in mode ``free``: ``(x0, t_touch, t_peak,
    x_peak)``, its largest ``x`` at ``t_peak`` in the contact (``v = 0``)."""
    ref = reference(p, walls=False)
    T = ref.period

    def equations(u):
        x0, t1, t2 = u[:2], u[2], u[3]
        y1 = ref.flow(0, x0, t0, t1)
        y2 = ref.flow(1, y1, t1, t2)
        return [y1[0] - p["gap"], y2[0] - p["gap"], *(ref.flow(0, y2, t2, t0 + T) - x0)]

    u, _, _, msg = fsolve(equations, guess, xtol=1e-15, full_output=True)
    assert np.abs(equations(u)).max() < 1e-13, msg
    x0, t1, t2 = u[:2], u[2], u[3]
    y1 = ref.flow(0, x0, t0, t1)
    t_peak = brentq(lambda s: ref.flow(1, y1, t1, s)[1], t1 + 1e-9, t2 - 1e-9, xtol=1e-15)
    return x0, t1, t_peak, ref.flow(1, y1, t1, t_peak)[0]


def _virtual(m: HybridModel):
    """The virtual period-1 orbit from a section in the free mode, well before the contact."""
    sol = grazing.simulate(m, [0.0, 0.0], periods=1, transient=300, events=False, trajectory=400)
    i = int(np.argmin(sol.trajectory[:, 0]))
    t0 = float(sol.trajectory_t[i] % m.period)
    return find_orbit(m, sol.trajectory[i], period=1, t0=t0, virtual=True, stop_name="wall", mode="free")


def test_the_virtual_orbit_reports_the_walls_guard_minimum_exactly():
    m = soft_hard()
    orbit = _virtual(m)
    p = dict(m.params)
    sw = orbit.switch_times
    t0 = orbit.t0
    first = sw[sw >= t0]
    x0, _, t_peak, x_peak = exact_virtual_orbit(p, t0, [*orbit.state, first[0], first[1]])
    assert np.abs(orbit.state - x0).max() < 1e-10
    assert orbit.virtual and orbit.impacts == 0
    assert x_peak > p["wall"] + 1.0  # (far past the wall: the orbit is virtual)
    assert abs(orbit.guard_min - (p["wall"] - x_peak)) < 1e-10, orbit.guard_min - (p["wall"] - x_peak)
    assert abs(orbit.t_guard_min - t_peak) < 1e-7
    assert abs(orbit.x_guard_min[0] - x_peak) < 1e-10
    assert orbit.crossed_stops == ("wall",)
    mins = orbit.guard_mins  # the switches (no reset) report no minimum
    assert np.isinf(mins[0]) and np.isinf(mins[2])


def free_wall(**values: float) -> HybridModel:
    """soft_hard with its wall declared in the free mode (beyond the gap: never reached there)."""
    params = [Parameter(name, value) for name, value in VALUES.items()]
    model = HybridModel(
        "free-wall", [x, v], t, params,
        modes=[Mode("free", FREE, stops=[Stop("wall", wall - x, [x, -r * v])]), Mode("contact", CONTACT)],
        transitions=[Transition("touch", "free", "contact", gap - x),
                     Transition("leave", "contact", "free", x - gap)],
        period=2 * sp.pi / w,
    )  # fmt: skip
    return model.with_params(**values)


def test_a_guard_is_ignored_while_the_run_is_in_another_mode():
    m = free_wall()
    orbit = _virtual(m)
    p = dict(m.params)
    i = m.stop_names.index("wall")
    h, t_min, x_min = orbit.guard_min_by_stop[i]
    # In the contact the orbit reaches x ~ 2, where the wall's guard is ~ -1.3; in the free mode it is
    # smallest where the free mode is left or entered again (x = gap).
    assert abs(h - (p["wall"] - p["gap"])) < 1e-10, h - (p["wall"] - p["gap"])
    at_gap = orbit.switch_times  # (into and out of the contact: x = gap at both)
    assert np.abs(at_gap - t_min).min() < 1e-9 and abs(x_min[0] - p["gap"]) < 1e-10
    assert orbit.crossed_stops == ()


def exact_wall_grazing(p: dict, guess: tuple[float, float]) -> tuple[float, float]:
    """``(a, t_graze)`` of soft_hard's wall-less period-1 orbit touching the wall: from ``(wall, 0)`` in
    the contact at ``t_graze`` back to it a period later (the exact flow and its switch times)."""

    def back(u):
        q = {**p, "a": u[0]}
        ref = reference(q, walls=False)
        y, mode, _, _ = ref.run([q["wall"], 0.0], 1, u[1], u[1] + ref.period)
        assert mode == 1
        return y - [q["wall"], 0.0]

    u, _, _, msg = fsolve(back, guess, xtol=1e-15, full_output=True)
    assert np.abs(back(u)).max() < 1e-13, msg
    return float(u[0]), float(u[1])


def test_an_impacts_grazing_is_located_on_the_virtual_branch_through_modes():
    m = soft_hard(wall=1.5)
    points, branch = find_grazings(m, "a", 0.5, 1.0, stop_name="wall")
    assert len(points) == 1 and points[0].stop == m.stop_names.index("wall")
    g = points[0]
    a, t_graze = exact_wall_grazing(dict(m.params), (g.model.params["a"], g.t_graze))
    assert abs(g.model.params["a"] - a) < 1e-10, g.model.params["a"] - a
    assert abs((g.t_graze - t_graze) % m.period) < 1e-8 or abs((t_graze - g.t_graze) % m.period) < 1e-8
    assert np.abs(g.contact - [1.5, 0.0]).max() < 1e-10 and g.mode == "contact"
    assert all(o.virtual for o in branch.orbits)


def test_the_walls_grazing_curve_through_modes_against_the_exact_orbit():
    m = soft_hard(wall=1.5)
    curve = grazing_curve(m, ("a", "zeta"), 0.05, search=(0.5, 1.0), stop_name="wall")
    assert len(curve.points) >= 5
    zetas = [g.model.params["zeta"] for g in curve.points]
    assert max(zetas) > 0.12  # (the curve goes well beyond its start)
    for g in curve.points:
        p = dict(g.model.params)
        a, _ = exact_wall_grazing(p, (p["a"], g.t_graze))
        assert abs(p["a"] - a) < 1e-10, (p["zeta"], p["a"] - a)
        assert np.abs(g.contact - [1.5, 0.0]).max() < 1e-10


def test_a_guard_smallest_where_its_mode_is_left_counts_there():
    """A guard ``3 - x - v`` of the free mode decreases up to the switch into the contact: its minimum over
    the free mode is at that switch, the end of the last step in the free mode (no later step sees it)."""
    params = [Parameter(name, value) for name, value in VALUES.items()]
    m = HybridModel(
        "tilted-wall", [x, v], t, params,
        modes=[Mode("free", FREE, stops=[Stop("wall", 3 - x - v, [x, -r * v])]), Mode("contact", CONTACT)],
        transitions=[Transition("touch", "free", "contact", gap - x),
                     Transition("leave", "contact", "free", x - gap)],
        period=2 * sp.pi / w,
    )  # fmt: skip
    orbit = _virtual(m)
    p = dict(m.params)
    sw, T = orbit.switch_times, m.period
    x0, t_touch, _, _ = exact_virtual_orbit(p, orbit.t0, [*orbit.state, sw[0], sw[1]])
    ref = reference(p, walls=False)
    y = ref.flow(0, x0, orbit.t0, t_touch)
    h_touch = 3 - y[0] - y[1]
    # the exact guard over the free mode (before the touch, after the leave) is nowhere smaller
    free = [ref.flow(0, x0, orbit.t0, s) for s in np.linspace(orbit.t0, t_touch, 2001)]
    free += [ref.flow(0, x0, orbit.t0 + T, s) for s in np.linspace(sw[1], orbit.t0 + T, 2001)]  # (backwards)
    assert min(3 - z[0] - z[1] for z in free) >= h_touch - 1e-15
    h, t_min, _ = orbit.guard_min_by_stop[m.stop_names.index("wall")]
    assert abs(h - h_touch) < 1e-10, h - h_touch
    assert abs(t_min - t_touch) < 1e-9 and orbit.crossed_stops == ("wall",)
