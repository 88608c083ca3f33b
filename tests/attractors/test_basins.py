"""Attractors and basins from grids of initial states (grazing.attractors)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

import grazing
from grazing.attractors import basins, find_attractors, state_grid
from grazing.attractors.classify import closing_period, set_distance
from grazing.attractors.grid import start_time
from grazing.core.options import SWEEP_TOL
from grazing.core.period import detect_period
from grazing.errors import InvalidParameterError
from grazing.models import bouncing_ball, impact_damper, pendulum, two_sided_oscillator
from grazing.sweeps import sweep
from tests.random_models import ModelSpec, model_specs

# The bouncing ball on a table whose acceleration (A w^2 = 0.8) is below gravity (g = 1): the ball can
# ride on the table for ever, and the period-1 orbit (one impact a period) is stable between its fold
# and its period-doubling (closed forms, Holmes 1982; Nordmark & Piiroinen 2009):
R, AMP = 0.8, 0.8
A_FOLD = math.pi * (1 - R) / (1 + R)
A_PD = math.sqrt(A_FOLD**2 + (2 * (1 + R**2) / (1 + R) ** 2) ** 2)
BALL = bouncing_ball(amplitude=AMP, r=R, omega=1.0, gravity=1.0)


def ends_on(model, found, label, x0, transient=1000):
    """Simulate ``x0`` on its own (at the grid's phase) and check it ends on attractor ``label``:
    the nearest attractor to its samples (Hausdorff distance in cells) is that one.

    A periodic attractor is run for at least as long as its Lyapunov exponent says its orbits take to
    come within 1e-8 of it (a period-3 orbit of a random model with exponent -0.0028, found by
    hypothesis, repeated only to 8e-5 after 800 periods: 2,800 more brought it to 1e-12)."""
    a = found.attractor(label)
    if a.kind == "periodic" and a.lyapunov < 0:
        settle = math.log(1e-8) / (a.lyapunov * model.period)
        transient = max(transient, min(20_000, math.ceil(settle)))
    sol = grazing.simulate(model, x0, t0=start_time(model, found.phase), transient=transient,
                           periods=found.periods, phase=found.phase, tol=SWEEP_TOL)  # fmt: skip
    if a.kind in ("periodic", "sticking"):
        p = detect_period(sol.samples)
        assert p == a.period, (x0, p, a.period)
        return set_distance(sol.samples[-p:], a.points, found.cell) <= 0.01
    others = [b for b in found.attractors if len(b.points) and b.id != label]
    mine = set_distance(sol.samples, a.points, found.cell)
    return all(mine < set_distance(sol.samples, b.points, found.cell) for b in others)


def ends_on_one_of_them(model, found, label, x0, transient=1000) -> bool:
    """:func:`ends_on` where no attractor is chaotic; beside a chaotic one, ``x0``'s own run ends on
    *some* attractor of the catalogue (the nearest to its samples is one whose points its samples
    repeat, or a chaotic one when they do not).  Near a chaotic attractor a state may lie on a fractal
    basin boundary: the grid's run and this one differ by rounding, and transient chaos sends them to
    different attractors (a random model's state labelled with its period-2 orbit ran on the chaotic
    one, found by hypothesis)."""
    if not any(a.kind == "chaotic" for a in found.attractors):
        return ends_on(model, found, label, x0, transient)
    try:
        return ends_on(model, found, label, x0, transient)
    except AssertionError:
        pass
    sol = grazing.simulate(model, x0, t0=start_time(model, found.phase), transient=transient,
                           periods=found.periods, phase=found.phase, tol=SWEEP_TOL)  # fmt: skip
    p = detect_period(sol.samples)
    candidates = [a for a in found.attractors if len(a.points)]
    nearest = min(candidates, key=lambda a: set_distance(sol.samples, a.points, found.cell))
    if p > 0:
        return nearest.period == p and set_distance(sol.samples[-p:], nearest.points, found.cell) <= 0.01
    return nearest.kind == "chaotic"


def test_the_ball_rides_on_its_table_beside_its_period_one_orbit():
    assert A_FOLD < AMP < A_PD  # (0.349 < 0.8 < 1.071): the period-1 orbit is stable
    assert AMP * 1.0**2 < 1.0  # the table's acceleration stays below gravity: riding never ends
    grid = state_grid(BALL, (0.0, 6.0), (-4.0, 4.0), (12, 12))
    found = find_attractors(BALL, grid.states_array(), workers=2)
    kinds = sorted((a.kind, a.period) for a in found.attractors)
    assert kinds == [("periodic", 1), ("sticking", 1)]
    orbit = next(a for a in found.attractors if a.kind == "periodic")
    assert orbit.impacts_per_period == 1
    assert orbit.lyapunov < 0
    riding = next(a for a in found.attractors if a.kind == "sticking")
    # on the table at phase 0: y = A sin 0 = 0, moving with it, y' = A w cos 0 = A
    np.testing.assert_allclose(riding.points[0], [0.0, AMP], atol=1e-6)
    assert math.isclose(sum(found.fractions.values()), 1.0)
    assert all(a.count > 0 for a in found.attractors)
    for x0, label in zip(grid.states_array(), found.labels):
        assert ends_on(BALL, found, int(label), x0), (x0, label)


def test_the_orbit_points_are_the_closed_form_period_one_orbit():
    # The period-1 orbit's impact: relative velocity 2 pi g / ((1 + r) w) ... checked through its
    # flight: between impacts the ball flies one forcing period, so its samples repeat.
    found = find_attractors(BALL, [[3.6, -2.0]], workers=1)
    (orbit,) = found.attractors
    sol = grazing.simulate(BALL, orbit.points[0], periods=3, tol=SWEEP_TOL)
    np.testing.assert_allclose(sol.samples[-1], orbit.points[0], atol=1e-8)


def test_the_basins_dataset():
    ds = basins(BALL, (-1.0, 6.0), (-4.0, 4.0), (9, 7), workers=2)
    assert ds.label.shape == (7, 9)
    assert ds.label.dims == ("y", "x")
    np.testing.assert_allclose(ds.x.values, np.linspace(-1, 6, 9))
    assert (ds.label.values[:, ds.x.values < 0] == 0).all()  # below the table: invalid, not run
    assert ds.kind.values[0] == "invalid" and ds.attractor.values[0] == 0
    assert math.isclose(float(ds.fraction.sum()), 1.0)
    counts = {int(a): int((ds.label.values == a).sum()) for a in ds.attractor.values}
    assert counts == dict(zip(ds.attractor.values.tolist(), ds["count"].values.tolist()))
    assert ds.x.attrs["long_name"] == "y" and ds.y.attrs["long_name"] == "v"


def test_labels_do_not_depend_on_threads_or_chunks():
    grid = state_grid(BALL, (0.0, 6.0), (-4.0, 4.0), (10, 10))
    a = find_attractors(BALL, grid.states_array(), workers=1, chunk_size=7)
    b = find_attractors(BALL, grid.states_array(), workers=2, chunk_size=64)
    np.testing.assert_array_equal(a.labels, b.labels)
    assert [x.kind for x in a.attractors] == [x.kind for x in b.attractors]


def test_a_store_keeps_the_end_states_and_is_resumed(tmp_path, monkeypatch):
    grid = state_grid(BALL, (0.0, 6.0), (-4.0, 4.0), (8, 8))
    path = tmp_path / "b.zarr"
    first = find_attractors(BALL, grid.states_array(), workers=2, chunk_size=16, store=path)
    import grazing.sweeps.executor as executor

    def nothing_to_compute(*args, **kwargs):
        raise AssertionError("a chunk was computed again")

    monkeypatch.setattr(executor, "chunk_results", nothing_to_compute)
    again = find_attractors(BALL, grid.states_array(), workers=2, chunk_size=16, store=path)
    np.testing.assert_array_equal(first.labels, again.labels)


def test_a_grid_all_beyond_the_stop_is_all_invalid():
    found = find_attractors(BALL, [[-1.0, 0.0], [-2.0, 1.0]], workers=1)
    assert [a.kind for a in found.attractors] == ["invalid"]
    assert found.labels.tolist() == [0, 0] and found.fractions == {0: 1.0}


def test_the_pendulum_chaos_is_chaotic():
    m = pendulum("B", eta=0.4505, theta_hat=math.radians(40))  # in a wide chaotic band (fig 7d)
    found = find_attractors(m, [[-0.5, 0.5], [-0.4, 0.45], [0.0, 0.0]], workers=2)
    chaotic = [a for a in found.attractors if a.kind == "chaotic"]
    assert len(chaotic) == 1 and chaotic[0].lyapunov > 0.001 and chaotic[0].period == 0
    assert len(chaotic[0].points) > 50


def test_the_pendulum_resting_on_the_back_of_its_stop():
    # Thrown over the top, the pendulum lands on the back face of its stop (theta = theta_hat - 2 pi),
    # gravity holds it there: it rides on that stop, beside the period-5 impacting orbit.
    m = pendulum("B", eta=0.446, theta_hat=math.radians(40))
    found = find_attractors(m, [[-1.5, -2.0], [0.0, 0.0]], workers=1)
    kinds = {a.kind: a for a in found.attractors}
    assert set(kinds) == {"sticking", "periodic"}
    np.testing.assert_allclose(kinds["sticking"].points[0][0], math.radians(40) - 2 * math.pi, atol=1e-8)
    assert kinds["periodic"].period == 5


def test_four_states_a_slice_of_two():
    m = impact_damper(amp=1.0, omega=1.2)
    grid = state_grid(m, (-1.5, 1.5), (-2.0, 2.0), (6, 5), states=("x2", "v2"), fixed={"x1": 0.2, "v1": -0.1})
    x = grid.states_array()
    assert x.shape == (30, 4) and np.all(x[:, 0] == 0.2) and np.all(x[:, 1] == -0.1)
    found = find_attractors(m, x, workers=2)
    assert math.isclose(sum(found.fractions.values()), 1.0)
    for k in range(0, 30, 7):
        assert ends_on(m, found, int(found.labels[k]), x[k]), k


def test_two_stops_coexisting_orbits():
    # Where the sweeps up and down in omega differ (the hysteresis loop of the oscillator between two
    # stops: impacting up to omega = 1.6 going up, free of the stops from 1.6 down to 1.23), a grid of
    # initial states finds both orbits.
    m = two_sided_oscillator(amp=0.5, gap_left=1.5)
    omegas = np.linspace(1.2, 1.6, 41)
    both = sweep(m, "omega", omegas, direction="both", chunk_size=10, transient=300, periods=32)
    at = both.sel(point=30)  # omega = 1.5
    assert at.impacts_per_period.sel(direction="up") > 0 and at.impacts_per_period.sel(direction="down") == 0
    x_up, x_down = (at.samples.sel(direction=d).values[-1] for d in ("up", "down"))
    m15 = m.with_params(omega=float(omegas[30]))
    found = find_attractors(m15, [x_up, x_down], workers=1)
    assert [(a.kind, a.period) for a in found.attractors] == [("periodic", 2), ("periodic", 1)]
    assert found.labels.tolist() == [1, 2]
    assert [a.impacts_per_period for a in found.attractors] == [3, 0]  # (up: 3 impacts in 2 periods)
    grid = state_grid(m15, (-1.4, 0.9), (-1.5, 1.5), (12, 12))
    x = grid.states_array()
    on_grid = find_attractors(m15, x, workers=2)
    orbits = [a for a in on_grid.attractors if a.kind == "periodic"]
    assert len(orbits) == 2 and sorted(a.impacts_per_period > 0 for a in orbits) == [False, True]
    for k in range(0, x.shape[0], 11):
        assert ends_on(m15, on_grid, int(on_grid.labels[k]), x[k]), k


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"num": (0, 5)}, "at least one value"),
        ({"states": (0, 4)}, "state index 4 is out of range"),
        ({"states": ("y", "w")}, "unknown state 'w'"),
        ({"states": (1, 1)}, "must differ"),
        ({"fixed": {"z": 1.0}}, "unknown fixed state 'z'"),
        ({"fixed": {"y": 1.0}}, "varied by the grid"),
        ({"x_range": (1.0, 0.0)}, "LO < HI"),
        ({"x_range": (0.0, math.inf)}, "finite"),
    ],
)
def test_bad_grids_are_refused(kwargs, message):
    args = {"x_range": (0.0, 1.0), "y_range": (-1.0, 1.0), "num": (3, 3)}
    args.update(kwargs)
    with pytest.raises(InvalidParameterError, match=message):
        state_grid(BALL, **args)


def test_bad_initial_states_are_refused():
    with pytest.raises(InvalidParameterError, match="rows of 2"):
        find_attractors(BALL, [[0.0, 1.0, 2.0]])
    with pytest.raises(InvalidParameterError, match="empty"):
        find_attractors(BALL, np.zeros((0, 2)))
    with pytest.raises(TypeError, match="unexpected keyword"):
        find_attractors(BALL, [[0.0, 1.0]], transients=3)


CLASHING_NAMES = ("x1", "v1", "t_0", "v0", "pi", "T", "J", "t", "t_", "x2", "v2", "E", "I", "e", "S", "N",
                  "lambda", "sin", "cos", "exp", "log", "sqrt", "math", "np", "pv", "s", "x", "out", "h", "k",
                  "c0", "w0", "p0", "xs0_0", "X", "O", "tau", "Dummy")  # fmt: skip
"""The names of the two-mass models hypothesis found (tests.random_models draws such clashes)."""


def test_a_period_two_orbit_closing_in_slowly_is_not_period_four():
    """Hypothesis's example: a two-mass model whose period-2 orbit has complex multipliers of modulus
    about 0.975. After 200 periods its samples repeated with period 4 to the detector's tolerance and
    closed in on period 2 by only half over 32 samples: 23 of the grid's states were a period-4
    attractor beside the period-2 one (CLOSING_RATIO)."""
    spec = ModelSpec(names=CLASHING_NAMES, dof=2, damping=0.15625, stiffness=1.5, amplitude=0.375,
                     omega=2.875, stop_fraction=0.75, restitution=0.625, coupling=1.0, cubic=0.0,
                     smooth="erfc")  # fmt: skip
    model = spec.model()
    grid = state_grid(model, (-1.5 * spec.stop, 1.2 * spec.stop), (-2.0, 2.0), (6, 6))
    found = find_attractors(model, grid.states_array(), workers=2, transient=200, periods=32)
    assert sorted((a.kind, a.period) for a in found.attractors) == [("invalid", -1), ("periodic", 2)]
    orbit = next(a for a in found.attractors if a.kind == "periodic")
    x0 = grid.states_array()[int(np.flatnonzero(found.labels == orbit.id)[0])]
    assert ends_on(model, found, orbit.id, x0, transient=800)


def test_closing_period_sees_a_slow_rotation_in_on_a_shorter_period():
    k = np.arange(32.0)[:, None]
    two = np.where(k % 2 == 0, 1.0, -1.0)
    rotating = two + 1e-7 * 0.98**k * np.cos(np.pi * k / 2)  # (repeats with period 4, closes in on 2)
    assert closing_period(rotating, 4)[0] == 2
    assert closing_period(two, 2) == (2, 0.0)  # (a period-2 orbit is not closing in on period 1)


@settings(max_examples=3, deadline=None, suppress_health_check=list(HealthCheck))
@given(spec=model_specs())
def test_random_models(spec: ModelSpec):
    # Models whose names clash with everything the code generator uses, one or two degrees of freedom.
    model = spec.model()
    stop = spec.stop
    grid = state_grid(model, (-1.5 * stop, 1.2 * stop), (-2.0, 2.0), (6, 6))
    x = grid.states_array()
    found = find_attractors(model, x, workers=2, transient=200, periods=32)
    ids = {a.id for a in found.attractors}
    assert set(found.labels.tolist()) == ids
    assert math.isclose(sum(found.fractions.values()), 1.0)
    beyond = x[:, 0] > stop  # (the stop is at q = stop: those initial states are invalid)
    assert (found.labels[beyond] == 0).all() and (found.labels[~beyond] > 0).all()
    for k in range(0, x.shape[0], 5):
        if found.labels[k] > 0 and found.attractor(int(found.labels[k])).kind in ("periodic", "sticking"):
            assert ends_on_one_of_them(model, found, int(found.labels[k]), x[k], transient=800), k


def only_period_one(every: int, transient: int, **values: float) -> None:
    """A lightly damped two-mass model with clashing names whose only attractor is a period-1 orbit:
    so the basins of a 6 x 6 grid find, and every ``every``-th state run on its own ends there."""
    spec = ModelSpec(names=CLASHING_NAMES, dof=2, amplitude=1.0, stop_fraction=0.5, coupling=0.25,
                     cubic=0.0, smooth="none", **values)  # type: ignore[arg-type]  # fmt: skip
    model = spec.model()
    grid = state_grid(model, (-1.5 * spec.stop, 1.2 * spec.stop), (-2.0, 2.0), (6, 6))
    x = grid.states_array()
    found = find_attractors(model, x, workers=2, transient=200, periods=32)
    assert [(a.kind, a.period) for a in found.attractors if a.kind != "invalid"] == [("periodic", 1)]
    for k in np.flatnonzero(found.labels > 0)[::every]:
        assert ends_on(model, found, int(found.labels[k]), x[k], transient=transient), k


def test_an_orbit_closing_in_on_a_shorter_period_is_not_an_attractor_of_its_own():
    """Found by hypothesis: the period-1 orbit of this model has a multiplier near -1 (-0.94), and
    initial states on their way to it repeated with period 2 to 7e-8 (settled, by the 1e-7 of the
    check for an orbit slow to settle) and with period 1 to 1e-6 only: a period-2 "attractor".
    Their period-1 differences shrink over the samples: they are run on, and at the last look they
    are given the period they close in on where they are within a match of it.  With damping
    0.03125 (a multiplier near -0.97) some were still 3e-5 from it after 400 periods, beyond a match,
    and a period-2 attractor was reported: such end states are run on (BASIN_CLOSING_ROUNDS)."""
    only_period_one(5, 1600, damping=0.0625, stiffness=1.1875, omega=2.375, restitution=0.5)
    only_period_one(5, 3200, damping=0.03125, stiffness=1.1875, omega=2.375, restitution=0.5)


def test_an_orbit_slow_to_settle_is_not_split_into_spurious_periods():
    """Found by hypothesis (a lightly damped two-mass model, random names): after 200 periods some
    initial states still spiralled into the period-1 orbit and their samples repeated to the period
    detector's 1e-6 with periods 2, 7 and 9, each reported as an attractor of its own (the same
    Lyapunov exponent to 1e-11). Such end states are run on before they are classified."""
    only_period_one(1, 800, damping=0.03125, stiffness=1.0, omega=2.0, restitution=0.75)


def test_refine_may_be_huge_the_looks_are_made_as_they_are_used():
    """``--refine 1000000000`` (issue 43's fuzz): a list of its looks took 8 GB before the first run."""
    from grazing.attractors.basins import _Look, _looks

    looks = _looks(10**12)
    assert [next(looks) for _ in range(3)] == [_Look(defer=True)] * 3
