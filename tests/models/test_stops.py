"""Models with several stops and more degrees of freedom (issue 13).

Closed forms of the two-sided oscillator below grazing (amplitude, Floquet
multipliers, grazing frequencies of each stop), the determinant of the
monodromy of an orbit hitting both stops, agreement with scipy's event loop
with one terminal event per stop, the pendulum's back face, and a property
test: no trajectory of a model with one, two or three stops passes through a
stop, and no impact adds energy.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import grazing
from grazing.models import impact_damper, impact_oscillator, pendulum, two_sided_oscillator
from grazing.orbits import continue_orbit, find_grazings, find_orbit
from grazing.sweeps import sweep
from tests.engine.reference import assert_agrees


def linear_amplitude(m: grazing.HybridModel) -> float:
    p = m.params
    w, z = p["omega"], p["zeta"]
    return p["amp"] / math.hypot(1 - w * w, 2 * z * w)


def test_two_sided_nonimpacting_orbit_matches_the_linear_response() -> None:
    m = two_sided_oscillator(omega=0.5, amp=0.5)
    orbit = find_orbit(m, period=1, tol=1e-13)
    assert orbit.impacts == 0
    x, v = orbit.state  # x = A cos(phi), v = A omega sin(phi) at t = 0
    assert math.hypot(x, v / 0.5) == pytest.approx(linear_amplitude(m), abs=1e-10)
    T, z = m.period, m.params["zeta"]
    expected = np.exp(T * (-z + 1j * math.sqrt(1 - z * z) * np.array([1, -1])))
    np.testing.assert_allclose(np.sort_complex(orbit.multipliers), np.sort_complex(expected), atol=1e-10)


@pytest.mark.parametrize("stop, gap", [("right", 1.0), ("left", 1.5)])
def test_grazing_frequency_of_each_stop_is_the_closed_form(stop: str, gap: float) -> None:
    """The linear amplitude amp/|1 - w^2 + 2 i zeta w| reaches the stop's gap (below resonance)."""
    import warnings

    m = two_sided_oscillator(amp=0.5, gap_right=1.0, gap_left=1.5)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        points, _ = find_grazings(m, "omega", 0.5, 0.9, stop_name=stop)
    assert len(points) == 1 and points[0].stop_name == stop
    # the left grazing (amplitude 1.5) lies beyond the right one (1.0): that orbit passes through it
    assert points[0].crossed == (() if stop == "right" else ("right",))
    assert len(said) == (0 if stop == "right" else 1)
    z, a = m.params["zeta"], m.params["amp"]
    # (1 - u)^2 + 4 zeta^2 u = (a / gap)^2 with u = omega^2, the root below resonance
    b = 2 - 4 * z * z
    u = (b - math.sqrt(b * b - 4 * (1 - (a / gap) ** 2))) / 2
    assert points[0].model.params["omega"] == pytest.approx(math.sqrt(u), abs=1e-8)


def test_orbit_hitting_both_stops_monodromy() -> None:
    """det(monodromy) = r^(2k) exp(-2 zeta T) for k impacts; the monodromy against finite differences."""
    m = two_sided_oscillator()
    orbit = find_orbit(m, period=1)
    assert orbit.impacts == 2 and sorted(orbit.impact_stops.tolist()) == [0, 1]
    r, z, T = m.params["r"], m.params["zeta"], m.period
    assert np.linalg.det(orbit.monodromy) == pytest.approx(r**4 * math.exp(-2 * z * T), rel=1e-9)
    fd = np.zeros((2, 2))
    for j in range(2):
        e = np.zeros(2)
        e[j] = 1e-6
        up = grazing.simulate(m, orbit.state + e, t0=orbit.t0, periods=1, phase=0.0).x_final
        dn = grazing.simulate(m, orbit.state - e, t0=orbit.t0, periods=1, phase=0.0).x_final
        fd[:, j] = (up - dn) / 2e-6
    np.testing.assert_allclose(orbit.monodromy, fd, atol=1e-6)


def test_two_stops_agree_with_scipy() -> None:
    ref = assert_agrees(two_sided_oscillator(), [0.0, 0.0], periods=200)
    assert set(ref.impacts_stop.tolist()) == {0, 1}


def test_impact_damper_agrees_with_scipy_on_its_periodic_attractor() -> None:
    m = impact_damper()
    settled = grazing.simulate(m, [0.0, 0.0, 0.0, 0.0], transient=600, periods=1)
    ref = assert_agrees(m, settled.x_final, t0=settled.t_final, periods=100)
    assert set(ref.impacts_stop.tolist()) == {0, 1}


# -- the impact damper (4 states, two walls) in the default suite: orbit, grazing, sweep, continue -------

TUNED = dict(omega2=0.8, amp=0.3, omega=0.6)
"""A spring on the secondary mass: the nonimpacting motion is the linear response, which grazes the walls."""


def damper_linear_response(m: grazing.HybridModel) -> tuple[complex, complex]:
    """Complex amplitudes (X1, X2) of the nonimpacting motion x = Re(X e^(i omega t)), in closed form.

    With s = i omega and k = 2 zeta2 omega2 s + omega2^2: (s^2 + 2 zeta s + 1 + mu k) X1 - mu k X2 = amp
    and (s^2 + k) X2 = k X1.
    """
    p = m.params
    s = 1j * p["omega"]
    k = 2 * p["zeta2"] * p["omega2"] * s + p["omega2"] ** 2
    x1 = p["amp"] / (s * s + 2 * p["zeta"] * s + 1 + p["mu"] * k - p["mu"] * k * k / (s * s + k))
    return x1, k * x1 / (s * s + k)


def test_impact_damper_orbit_hits_both_walls_with_the_closed_form_determinant() -> None:
    """det(monodromy) = r^(2k) exp(-2 zeta T) (a free secondary mass: trace -2 zeta; each impact's
    saltation matrix has determinant (-r) (-r): the reset's and the relative velocity's ratio)."""
    m = impact_damper()
    x0 = grazing.simulate(m, [0.0] * 4, transient=300, periods=1).x_final
    orbit = find_orbit(m, x0, period=1)
    assert orbit.impacts == 2 and sorted(orbit.impact_stops.tolist()) == [0, 1] and orbit.stable
    p = m.params
    assert np.linalg.det(orbit.monodromy) == pytest.approx(
        p["r"] ** 4 * math.exp(-2 * p["zeta"] * m.period), rel=1e-9
    )


def test_impact_damper_grazing_gap_is_the_linear_amplitude() -> None:
    """The right wall is grazed where the gap equals the amplitude |X2 - X1| of the relative motion."""
    m = impact_damper(**TUNED)
    x1, x2 = damper_linear_response(m)
    points, _ = find_grazings(m, "gap", 5.0, 0.05, stop_name="right")
    assert len(points) == 1 and points[0].stop_name == "right"
    assert points[0].model.params["gap"] == pytest.approx(abs(x2 - x1), abs=1e-9)
    g = points[0]
    assert abs(g.model.guard(g.contact, g.t_graze, "right")) < 1e-9


def test_impact_damper_sweep_in_the_gap() -> None:
    """Rattling (two impacts per period) in a narrow cavity; the linear response in a wide one."""
    m = impact_damper(**TUNED)
    gaps = [0.3, 0.5, 1.0, 2.0]  # the walls are grazed at 0.675
    ds = sweep(m, "gap", gaps, transient=200, periods=16, workers=1)
    assert ds.period.values.tolist() == [1, 1, 1, 1]
    assert ds.impacts_per_period.values.tolist() == [2.0, 2.0, 0.0, 0.0]
    x1, x2 = damper_linear_response(m)
    w = m.params["omega"]  # samples at t = k T: x = Re X, v = Re(i omega X)
    free = [x1.real, -w * x1.imag, x2.real, -w * x2.imag]
    np.testing.assert_allclose(ds.samples.values[2:], np.broadcast_to(free, (2, 16, 4)), atol=1e-9)
    for gap, samples in zip(gaps[:2], ds.samples.values[:2]):
        orbit = find_orbit(m.with_params(gap=gap), samples[-1], period=1)
        assert orbit.stable and orbit.impacts == 2
        np.testing.assert_allclose(samples[-1], orbit.state, atol=1e-8)


def test_impact_damper_nonimpacting_branch_ends_at_the_grazing() -> None:
    m = impact_damper(**TUNED)
    x1, x2 = damper_linear_response(m)
    free = find_orbit(m.with_params(gap=2.0), period=1)
    assert free.impacts == 0 and free.stable
    branch = continue_orbit(m, "gap", 2.0, 0.3, orbit=free)
    assert [s.kind for s in branch.special] == ["grazing"]
    # both walls at once: the relative motion is symmetric
    assert branch.special[0].param == pytest.approx(abs(x2 - x1), abs=1e-9)
    assert "grazing" in branch.status and all(o.impacts == 0 for o in branch.orbits)


@pytest.mark.slow
def test_impact_damper_jacobian_orbit_and_grazing() -> None:
    """4 states: the Jacobian across impacts, a periodic orbit with its multipliers, a grazing point."""
    m = impact_damper()
    x0 = grazing.simulate(m, [0.0, 0.0, 0.0, 0.0], transient=300, periods=1).x_final
    sol = grazing.simulate(m, x0, periods=3, jacobian=True)
    assert sol.n_impacts >= 4
    fd = np.zeros((4, 4))
    for j in range(4):
        e = np.zeros(4)
        e[j] = 1e-6
        fd[:, j] = (
            grazing.simulate(m, x0 + e, periods=3).x_final - grazing.simulate(m, x0 - e, periods=3).x_final
        ) / 2e-6
    np.testing.assert_allclose(sol.jacobian, fd, atol=1e-5 * max(1.0, np.abs(fd).max()))
    orbit = find_orbit(m, x0, period=1)
    assert orbit.impacts == 2 and orbit.stable
    assert np.linalg.det(orbit.monodromy) != 0
    # With a spring on the secondary mass the nonimpacting orbit is hyperbolic and grazes the walls.
    tuned = impact_damper(omega2=0.8, amp=0.3, omega=0.6)
    points, _ = find_grazings(tuned, "gap", 5.0, 0.05, stop_name="right")
    assert points, "no grazing of the right wall found"
    g = points[0]
    assert abs(g.model.guard(g.contact, g.t_graze, "right")) < 1e-9 and g.stop_name == "right"


def test_pendulum_rotating_over_the_top_hits_the_back_face() -> None:
    m = pendulum("B", eta=0.446, theta_hat=math.radians(40))
    sol = grazing.simulate(m, [0.0, -8.0], periods=3, impacts="all", trajectory=200)
    per = sol.impacts.per_stop()
    assert per["back"] >= 1
    assert np.all(sol.trajectory[:, 0] >= m.params["theta_hat"] - 2 * math.pi - 1e-9)
    assert_agrees(m, [0.0, -8.0], periods=2)  # (it chatters onto the front face in the third period)


# -- nothing passes through a stop, no impact adds energy: one, two and three stops --------------


def _three_stops() -> grazing.HybridModel:
    """The impact damper with a third stop: a rigid wall for the primary mass at x1 = wall."""
    x1, v1, x2, v2, t = sp.symbols("x1 v1 x2 v2 t")
    zeta, amp, omega, mu, gap, r, wall = sp.symbols("zeta amp omega mu gap r wall")
    dv = v2 - v1
    rattle = [x1, v1 + mu * (1 + r) / (1 + mu) * dv, x2, v2 - (1 + r) / (1 + mu) * dv]
    P = grazing.Parameter
    return grazing.HybridModel(
        "three-stops", [x1, v1, x2, v2], t,
        [P("zeta", 0.05, lower=0), P("amp", 1.0), P("omega", 1.2, lower=0, lower_open=True),
         P("mu", 0.1, lower=0, lower_open=True), P("gap", 2.0, lower=0, lower_open=True),
         P("r", 0.6, lower=0, upper=1), P("wall", 1.5, lower=0, lower_open=True)],
        vector_field=[v1, -2 * zeta * v1 - x1 + amp * sp.cos(omega * t), v2, 0],
        period=2 * sp.pi / omega,
        stops=[grazing.Stop("right", gap - (x2 - x1), rattle, [0, mu, 0, -1]),
               grazing.Stop("left", gap + (x2 - x1), rattle, [0, mu, 0, -1]),
               grazing.Stop("wall", wall - x1, [x1, -r * v1, x2, v2], [0, 1, 0, 0])],
    )  # fmt: skip


MODELS = {"one": impact_oscillator, "two": two_sided_oscillator, "three": _three_stops}


def _energy(model: grazing.HybridModel, x: np.ndarray) -> float:
    """Kinetic energy (the resets change velocities only)."""
    if model.n_states == 2:
        return 0.5 * x[1] ** 2
    return 0.5 * (x[1] ** 2 + model.params["mu"] * x[3] ** 2)


@settings(max_examples=12, deadline=None)
@given(
    which=st.sampled_from(sorted(MODELS)),
    omega=st.floats(0.5, 2.0),
    r=st.floats(0.3, 0.95),
    start=st.floats(-0.9, 0.9),
    speed=st.floats(-3.0, 3.0),
)
def test_nothing_passes_through_a_stop(which, omega, r, start, speed) -> None:
    base = MODELS[which]()
    m = base.with_params(omega=omega, r=r)
    n = m.n_states
    x0 = np.zeros(n)
    x0[0], x0[1] = start * 0.09 if which == "one" else start, speed
    sol = grazing.simulate(m, x0, periods=20, impacts="all", trajectory=40)
    for j in range(m.n_stops):
        h = np.array([m.guard(x, t, j) for x, t in zip(sol.trajectory, sol.trajectory_t)])
        assert h.min() >= -1e-9, f"{m.name}: through stop {m.stop_names[j]} (h = {h.min():.3g})"
    for x, t, j in zip(sol.impacts.state, sol.impacts.t, sol.impacts.stop):
        assert _energy(m, m.reset(x, t, j)) <= _energy(m, x) * (1 + 1e-12) + 1e-15


def test_sticks_on_either_stop_and_releases_where_the_force_vanishes() -> None:
    """Slow strong forcing: the mass chatters onto one stop, sticks, is released, crosses to the other.

    On the right stop (x = 1, v = 0) the contact force vanishes when amp cos(omega t) = 1, on
    the left (x = -1) when amp cos(omega t) = -1: every sticking interval ends at one of those
    phases, and the motion sticks on both stops.
    """
    amp, w = 3.0, 0.2
    m = two_sided_oscillator(amp=amp, omega=w, r=0.3)
    sol = grazing.simulate(m, [0.0, 0.0], transient=2, periods=3, impacts="sampled")
    assert len(sol.sticking) >= 4
    per = sol.impacts.per_stop()
    assert per["right"] > 0 and per["left"] > 0
    T = m.period
    release = {"right": math.acos(1 / amp) / w, "left": (2 * math.pi - math.acos(-1 / amp)) / w}
    for _, end in sol.sticking:
        if abs(end - sol.t_final) < 1e-9:
            continue  # still sticking when the run ends
        phase = end % T
        dist = min(min(abs(phase - r), T - abs(phase - r)) for r in release.values())
        assert dist < 1e-9, f"a sticking interval ends at phase {phase}, not where the force vanishes"


def test_nonimpacting_branch_reports_every_stops_grazing_and_what_it_passes_through() -> None:
    """Right gap 1, left gap 1.5: the linear orbit touches the right stop first, then the left one.

    The left grazing of the virtual (stops ignored) orbit lies beyond the right one, so that orbit
    passes through the right stop: it is not a motion of the system, and find_grazings says so.
    """
    from grazing.errors import GrazingWarning
    from grazing.orbits import continue_orbit

    m = two_sided_oscillator(amp=0.5, gap_right=1.0, gap_left=1.5, omega=0.5)
    branch = continue_orbit(m, "omega", 0.5, 0.9, period=1, virtual=True, detect=("grazing",))
    found = [(m.stop_names[sp_.stop], sp_.grazing.stop_name, sp_.grazing.crossed) for sp_ in branch.special]
    assert found == [("right", "right", ()), ("left", "left", ("right",))]
    with pytest.warns(GrazingWarning, match="passes through stop.*'right'"):
        points, _ = find_grazings(m, "omega", 0.5, 0.9, stop_name="left")
    assert [p.stop_name for p in points] == ["left"]


def test_impacting_branch_ends_where_it_gains_an_impact_on_another_stop() -> None:
    """A period-1 orbit impacting only the right stop, continued in omega until it touches the left one.

    The branch ends at a grazing with the left stop, located by the grazing equations; an independent
    simulation of the orbit there comes within 1e-9 of the left stop with zero speed.
    """
    from grazing.orbits import continue_orbit

    m = two_sided_oscillator(amp=0.5, gap_right=1.0, gap_left=1.5, omega=1.1)
    orbit = find_orbit(m, period=1, t0=None)
    assert orbit.impacts == 1 and orbit.impact_stops.tolist() == [0]
    branch = continue_orbit(m, "omega", 1.1, 1.35, orbit=orbit)
    end = branch.special[-1]
    assert end.kind == "grazing" and end.grazing is not None and end.grazing.stop_name == "left"
    assert "with stop 'left'" in branch.status and "gains an impact" in branch.status
    assert branch.values[-1] < end.param < 1.35
    at = m.with_params(omega=end.param)
    there = find_orbit(at, end.orbit.state, period=1, t0=end.orbit.t0)
    phase = 2 * math.pi * (there.t0 / at.period % 1.0)
    sol = grazing.simulate(at, there.state, t0=there.t0, periods=1, phase=phase, guard_min=True)
    h_left, _, x_left = sol.guard_min_by_stop[1]
    assert abs(h_left) < 1e-9 and abs(x_left[1]) < 1e-6
    assert sol.impacts.per_stop() == {"right": 1, "left": 0}


# issue 26: models: "impacts accumulate" names the stop and the reason


def _corner(contact: bool, r: float = 0.5) -> grazing.HybridModel:
    """A mass pushed into the corner of a wall (x = 1) and a floor (y = 1), both with restitution r."""
    x, vx, y, vy, t, w, rr = sp.symbols("x vx y vy t w r")
    P = grazing.Parameter
    return grazing.HybridModel(
        "corner", [x, vx, y, vy], t, [P("w", 1.0, lower=0, lower_open=True), P("r", r, lower=0, upper=1)],
        vector_field=[vx, 2 + sp.cos(w * t) / 2 - vx / 10, vy, 2 + sp.sin(w * t) / 3 - vy / 10],
        period=2 * sp.pi / w,
        stops=[grazing.Stop("wall", 1 - x, [x, -rr * vx, y, vy], [0, 1, 0, 0] if contact else None),
               grazing.Stop("floor", 1 - y, [x, vx, y, -rr * vy], [0, 0, 0, 1] if contact else None)],
    )  # fmt: skip


def test_accumulation_in_a_corner_of_two_sticking_stops_says_so() -> None:
    """Contact directions on both stops: the run ends where the mass is on both at once, and the
    message says so (it used to say that the model defines no contact_direction)."""
    with pytest.raises(grazing.SimulationError) as err:
        grazing.simulate(_corner(contact=True), [0.0, 0.0, 0.0, 0.0], periods=5)
    msg = str(err.value)
    assert "in the corner where stops 'wall' and 'floor' meet (the state is on both)" in msg
    assert "contact_direction" not in msg


def test_accumulation_on_a_stop_without_contact_direction_names_it() -> None:
    with pytest.raises(grazing.SimulationError) as err:
        grazing.simulate(_corner(contact=False, r=0.0), [0.0, 0.0, 0.0, 0.0], periods=5)
    expected = "on stop 'wall' and cannot be continued (stop 'wall' has no contact_direction for sticking)"
    assert expected in str(err.value)


STICKING = {  # a motion that sticks to a stop for a part of every period (and the state it starts from)
    "ball on a table": (grazing.models.bouncing_ball(amplitude=0.8, r=0.8), [0.0, 0.8]),
    "ball thrown off the table": (grazing.models.bouncing_ball(amplitude=1.2), [0.0, 0.0]),
    "either stop": (two_sided_oscillator(amp=3.0, omega=0.2, r=0.3), [0.0, 0.0]),
}


@pytest.mark.parametrize("name", sorted(STICKING))
def test_a_sticking_state_lies_on_its_stop(name):
    # While it sticks the state is on the stop's contact manifold (h = 0, L_f h = 0): the step's end and
    # its samples are put back on it (the integration drifted off it by its error, by 3.6e-11 after 300
    # periods of the ball on the table; 3.7e-9 at the basins' tolerance).
    m, x0 = STICKING[name]
    sol = grazing.simulate(m, x0, transient=300, periods=20)
    stuck = [(t, x) for t, x in zip(sol.t, sol.samples) if any(a < t < b for a, b in sol.sticking)]
    assert stuck, "(the case is about sticking samples)"
    for t, x in stuck:  # (at the sampling phase 0: time 0 of the forcing period, as the engine has it)
        h = min(abs(m.guard(x, 0.0, j)) for j in range(m.n_stops))
        assert h <= 1e-15 * max(1.0, float(np.abs(x).max())), (t, h)
    # the lanes of a sweep do the same (each point from x0 at the same parameters: the same motion)
    param = next(iter(m.params))
    ds = sweep(m, param, [m.params[param]] * 3, x0=x0, fresh=True, transient=300, periods=20, lyapunov=False)
    np.testing.assert_array_equal(ds.samples.values[0], sol.samples)
