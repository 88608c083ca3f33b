"""Attractors classified from the dynamics, not the window (issue 42, part 5).

On the impact damper (states x1, v1, x2, v2): a stable orbit slow to attract is periodic (Newton's
method from the last samples), not quasiperiodic; one chaotic attractor larger than a small grid box
is one attractor (recurrence cells sized from the attractor); the free particle at rest is neutral;
the torus past the Neimark-Sacker point (omega = 1.40918 at mu = 0.3, r = 0.8) is quasiperiodic.
Every expected value is a property (multipliers, find_orbit's period), none a number of our output.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import grazing
from grazing.attractors import find_attractors, state_grid
from grazing.attractors.grid import start_time
from grazing.core.options import CHAOS_THRESHOLD, ESCAPE_FACTOR, MATCH_TOL, SweepSettings
from grazing.core.period import detect_period
from grazing.maps import flow_map
from grazing.models import impact_damper
from grazing.orbits import find_orbit
from grazing.orbits.shooting import is_isolated
from grazing.sweeps import run_sweep
from grazing.sweeps.polish import approaches, contracting_periods, polish
from grazing.sweeps.spec import sweep_spec
from tests.far_stop import RESPONSE, far_stop_swing

SLOW = impact_damper(mu=0.3, r=0.8, omega=1.408)  # the period-1 two-impact orbit, just before its NS point
TORUS = impact_damper(mu=0.3, r=0.8, omega=1.412)  # just past it
CHAOS = impact_damper(omega=0.825)  # the default damper is chaotic there


def grid(model, num=(5, 5), **fixed):
    return state_grid(model, (-1.0, 1.0), (-1.0, 1.0), num, states=("x1", "v1"), fixed=fixed)


def orbit_through(model, attractor, found):
    """find_orbit from the attractor's first point, at the samples' time, with its period."""
    t0 = start_time(model, found.phase)
    return find_orbit(model, attractor.points[0], period=int(attractor.period), t0=t0)


def test_a_slowly_contracting_orbit_is_periodic_not_quasiperiodic():
    x = grid(SLOW, v2=0.3).states_array()
    found = find_attractors(SLOW, x, workers=2, transient=100, refine=0)  # (a short transient)
    (a,) = found.attractors
    assert (a.kind, a.count) == ("periodic", x.shape[0])
    orbit = orbit_through(SLOW, a, found)
    mu = float(np.abs(orbit.multipliers).max())
    assert orbit.stable and orbit.isolated and 0.98 < mu < 1.0  # (slow: what the issue is about)
    assert orbit.period == a.period and orbit.impacts == a.impacts_per_period
    assert math.isclose(a.lyapunov, math.log(mu) / (a.period * SLOW.period), rel_tol=1e-6)
    assert abs(a.lyapunov) < CHAOS_THRESHOLD  # (its exponent alone would say quasiperiodic)
    # the window alone shows no period: Newton's method decided it
    run = grazing.simulate(SLOW, x[0], transient=100, periods=found.periods, tol=1e-10)
    assert detect_period(run.samples) == 0 and found.polished > 0
    assert contracting_periods(run.samples)[0] == orbit.period


def test_the_sweep_gives_a_slow_orbit_its_period():
    settings = SweepSettings(transient=100, periods=50, fresh=True)
    spec = sweep_spec(SLOW, "omega", [1.404, 1.408], x0=(0.0, 0.0, 0.5, 0.0), settings=settings)
    ds = run_sweep(spec, workers=1)
    raw = run_sweep(replace(spec, polish=False), workers=1)
    assert raw.period.values.tolist() == [0, 0]  # (the samples do not repeat to 1e-6 yet)
    for omega, p, samples in zip(ds.value.values, ds.period.values, ds.samples.values):
        orbit = find_orbit(SLOW.with_params(omega=float(omega)), samples[-1], period=1)
        assert orbit.stable and np.abs(orbit.multipliers).max() > 0.98
        assert p == orbit.period


def test_the_particle_at_rest_is_neutral_not_an_attractor():
    x = grid(SLOW, x2=0.5).states_array()  # (v2 = 0: the particle starts at rest)
    found = find_attractors(SLOW, x, workers=2, transient=100, refine=0)
    kinds = {a.kind: a for a in found.attractors}
    assert set(kinds) == {"periodic", "neutral"}
    rest = kinds["neutral"]
    assert rest.impacts_per_period == 0 and rest.points[0][3] == 0.0  # (never impacts, at rest)
    fm = flow_map(SLOW, rest.points[0], t0=start_time(SLOW, found.phase), periods=rest.period)
    assert np.abs(fm.image - rest.points[0]).max() < 1e-9 and fm.impacts == 0  # (a periodic motion)
    assert not is_isolated(fm.jacobian)  # (a double multiplier 1: a Jordan block)
    assert np.sum(np.abs(np.linalg.eigvals(fm.jacobian) - 1) < 1e-6) >= 2
    moving = kinds["periodic"]
    assert orbit_through(SLOW, moving, found).stable and moving.impacts_per_period > 0
    assert math.isclose(sum(found.fractions.values()), 1.0)  # (it keeps the states that reach it)


def test_one_chaotic_attractor_larger_than_the_box_is_one_attractor():
    g = state_grid(CHAOS, (-0.1, 0.1), (-0.1, 0.1), (10, 10), states=("x1", "v1"), fixed={"x2": 0.5})
    found = find_attractors(CHAOS, g.states_array(), workers=2)
    (a,) = found.attractors
    assert a.kind == "chaotic" and a.lyapunov > CHAOS_THRESHOLD and a.count == g.size
    extent = np.ptp(a.points, axis=0)
    box = np.ptp(g.states_array(), axis=0)
    assert (extent[:2] > box[:2]).all()  # (the attractor is larger than the grid's box)
    # with cells of the box (1/64 of it), its end states' samples rarely share one: it falls apart
    split = find_attractors(CHAOS, g.states_array(), workers=2, cell_fraction=0.0)
    assert len(split.attractors) > 1 and {b.kind for b in split.attractors} == {"chaotic"}


def test_the_torus_past_neimark_sacker_is_quasiperiodic():
    x = grid(TORUS, (4, 4), v2=0.3).states_array()
    found = find_attractors(TORUS, x, workers=2)
    (a,) = found.attractors
    assert (a.kind, a.period, a.count) == ("quasiperiodic", 0, x.shape[0])
    assert abs(a.lyapunov) <= CHAOS_THRESHOLD
    # inside it, the period-1 orbit lost its stability to a complex pair
    orbit = find_orbit(TORUS, a.points.mean(axis=0), period=1, t0=start_time(TORUS, found.phase))
    mu = orbit.multipliers[0]
    assert abs(mu) > 1 and abs(mu.imag) > 0 and orbit.unstable_count == 2
    # the samples fill a closed curve around it: every angle, never near it
    d = (a.points - orbit.state)[:, :2] / np.ptp(a.points[:, :2], axis=0)
    angle, radius = np.arctan2(d[:, 1], d[:, 0]), np.hypot(d[:, 0], d[:, 1])
    assert np.unique(np.floor((angle + np.pi) / (np.pi / 8))).size == 16
    assert radius.min() > 0.2 * radius.max()
    # and no Newton polish made it an orbit: from its samples, it is none
    assert polish(TORUS, a.points[:50], start_time(TORUS, found.phase)) is None


def test_a_failed_polish_leaves_the_label_and_is_bounded(monkeypatch):
    """Newton failing everywhere (raising inside find_orbit) changes no label and costs at most a few
    attempts per attractor."""
    import grazing.orbits.shooting as shooting

    calls = []

    def failing(*args, **kwargs):
        calls.append(1)
        raise grazing.ConvergenceError("no")

    monkeypatch.setattr(shooting, "find_orbit", failing)
    x = grid(SLOW, v2=0.3).states_array()
    found = find_attractors(SLOW, x, workers=2, transient=100, refine=0)
    assert [a.kind for a in found.attractors] in (["quasiperiodic"], ["aperiodic"])  # (what the samples say)
    assert 0 < len(calls) <= 2 * 3  # (POLISH_TRIES failures, each at most POLISH_CANDIDATES periods)


@pytest.mark.parametrize("bad", [-0.1, 1.5, math.nan, "x"])
def test_bad_cell_fractions_are_refused(bad):
    with pytest.raises(grazing.InvalidParameterError, match="cell_fraction"):
        find_attractors(SLOW, [[0.0, 0.0, 0.5, 0.3]], cell_fraction=bad)


def test_approaches_needs_the_contraction_the_multipliers_allow():
    k = np.arange(50.0)[:, None]
    fast = 0.3 * np.cos(1.7 * k) * (1.0 - 0.002 * k)  # (shrinking, but far slower than 0.5 a period)
    assert approaches(fast, np.zeros((1, 1)), 0.999) and not approaches(fast, np.zeros((1, 1)), 0.5)


def test_a_large_chaotic_set_takes_in_a_small_one_within_its_own_recurrence_cell():
    # Recurrence works both ways: a new set whose points are far from a small attractor in that
    # attractor's cells (1e-3 here) but within one of its own (0.1: 5 % of its extent of 2) is the same
    # attractor.
    from grazing.attractors.classify import Catalogue, _Entry

    cat = Catalogue(grazing.models.bouncing_ball(), 1, np.full(2, 1e-3), np.zeros(2), 1e3, 50, 0.0)
    small = cat._new(_Entry("aperiodic", 0, points=np.array([[0.0, 0.0], [0.01, 0.01]])))
    cat._aperiodic.append(small)
    large = np.array([[0.05, 0.0], [2.0, 2.0], [1.0, 0.5]])
    assert cat._recurrent(large) == {small}
    assert cat._recurrent(large + 1.0) == set()  # (0.95 from it: 9.5 of its own cells)


def test_failed_polishes_stop_at_their_budget_per_attractor(monkeypatch):
    # On a chaotic attractor every run may look like it contracts; Newton's method is tried on at most
    # POLISH_TRIES of them that fail (then the attractor's other end states are not tried).
    import grazing.attractors.classify as classify
    from grazing.core.options import POLISH_TRIES

    calls = []
    monkeypatch.setattr(classify, "contracting_periods", lambda samples, most: [1])
    monkeypatch.setattr(classify, "polish", lambda *a, **k: calls.append(1))
    g = state_grid(CHAOS, (-0.1, 0.1), (-0.1, 0.1), (4, 4), states=("x1", "v1"), fixed={"x2": 0.5})
    found = find_attractors(CHAOS, g.states_array(), workers=1, chunk_size=4)
    assert [a.kind for a in found.attractors] == ["chaotic"]
    assert 1 <= len(calls) <= POLISH_TRIES


def test_progress_counts_every_initial_state_once_invalid_ones_first():
    # A grid half beyond the stop: the invalid states count at once, then each run as it is labelled.
    m = grazing.models.pendulum("B", eta=0.40, theta_hat=math.radians(40))
    x = np.column_stack([np.linspace(0.3, 1.0, 8), np.zeros(8)])  # (theta beyond 40 deg: invalid)
    valid = int(np.sum(x[:, 0] < math.radians(40)))
    assert 0 < valid < 8
    seen = []
    found = find_attractors(
        m, x, transient=50, periods=16, chunk_size=2, progress=lambda d, t: seen.append((d, t))
    )
    kinds = {a.id: a.kind for a in found.attractors}
    assert sum(1 for label in found.labels if kinds[int(label)] == "invalid") == 8 - valid
    done = [d for d, _ in seen]
    assert {t for _, t in seen} == {8} and done == sorted(done)
    assert done[0] >= 8 - valid and done[-1] == 8


def test_resuming_a_finished_store_reports_every_state_done_at_once(tmp_path):
    # The second run reads every chunk from the store: its first report counts them all.
    m = grazing.models.pendulum("B", eta=0.40, theta_hat=math.radians(40))
    x = np.column_stack([np.linspace(0.0, 0.5, 6), np.zeros(6)])
    store = tmp_path / "runs.zarr"
    first = find_attractors(m, x, transient=50, periods=16, chunk_size=2, store=store)
    seen = []
    again = find_attractors(
        m, x, transient=50, periods=16, chunk_size=2, store=store, progress=lambda d, t: seen.append((d, t))
    )
    assert seen[0] == (6, 6)
    assert again.labels.tolist() == first.labels.tolist()


def test_an_attractor_far_larger_than_a_box_wider_than_one_is_not_escaping():
    # The escape distance is ESCAPE_FACTOR times the box's size, or 1 if less (here 2000, and 1): a periodic
    # orbit of amplitude 6.5e3 reached from it is an attractor.
    m = far_stop_swing(5e3, distance=1e7)
    amplitude = 5e3 * abs(RESPONSE)
    for half in (0.5, 1000.0):
        x = state_grid(m, (-half, half), (-half, half), (2, 2)).states_array()
        found = find_attractors(m, x, transient=200, periods=8, workers=1)
        (a,) = found.attractors
        assert (a.kind, a.period, a.count) == ("periodic", 1, 4)
        assert float(np.max(np.abs(a.points[:, 0]))) < amplitude < ESCAPE_FACTOR * max(2 * half, 1.0)


@pytest.mark.parametrize(("amplitude", "period"), [(1e-6, 1), (0.2, 2)])
def test_a_run_closing_in_on_a_shorter_period_has_it_only_within_a_match(amplitude, period):
    # Samples repeating with period 2 whose two points close in on one (x = 0.5 + a (-0.8)^k): on the last
    # look they are period 1 where their last difference is within a match (MATCH_TOL cells: 1e-5 here),
    # and keep period 2 where it is not (5e-4 for a = 0.2).
    from grazing.attractors.classify import Catalogue, closing_period
    from grazing.sweeps.spec import ChunkResult

    k = np.arange(32.0)
    x = 0.5 + amplitude * (-0.8) ** k
    samples = np.stack([x, np.full_like(x, 0.1)], axis=1)[None]
    cell = np.full(2, 0.01)
    d, off = closing_period(samples[0], 2)
    assert d == 1 and (off <= MATCH_TOL * cell[0]) == (period == 1)
    cat = Catalogue(grazing.models.bouncing_ball(), 1, cell, np.zeros(2), 1e3, 32, 0.0, polish=False)
    one = np.ones(1)
    res = ChunkResult(
        0, samples, np.array([2]), 2 * one, -one, 100 * one, samples[:, -1], np.zeros(1, dtype=int)
    )
    cat.add(0, res)
    (a,), labels = cat.attractors()
    assert (a.kind, a.period, labels.tolist()) == ("periodic", period, [1])


def test_a_box_too_narrow_for_its_cells_is_refused():
    # A box 1e-320 wide: its cells (1.6e-322) times the match tolerance underflow to zero (numpy's
    # warnings, then every orbit in one cell); cells given smaller than that are refused the same way.
    ball = grazing.models.bouncing_ball()
    x = np.array([[0.0, -1.0], [1e-320, 1.0]])
    with pytest.raises(grazing.InvalidParameterError, match="too narrow to tell attractors apart"):
        find_attractors(ball, x, workers=1)
    with pytest.raises(
        grazing.InvalidParameterError, match="cell sizes must be positive numbers of at least"
    ):
        find_attractors(ball, np.array([[0.0, -1.0], [1.0, 1.0]]), cell=[1e-310, 0.1], workers=1)
