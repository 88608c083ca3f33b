"""A sweep that carries its state is one chain, whatever the chunking (grazing.sweeps.chain)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from grazing.core.cells import one_attractor
from grazing.core.options import CHAIN_CELLS, CHAIN_SHIFTS, CHAIN_TOL, PERIOD_TOL
from grazing.models import pendulum, two_sided_oscillator
from grazing.sweeps import run_sweep, run_sweeps, sweep
from grazing.sweeps.chain import ChainLine, from_start, orbit_advance, same_outcome, settle, shifted_start
from grazing.sweeps.executor import compute_parts
from grazing.sweeps.run import run_parts
from grazing.sweeps.spec import ChunkResult, sweep_spec
from grazing.sweeps.store import MemoryStore, ZarrStore
from tests.sweeps.dask_cluster import loopback_client

M40 = pendulum("B", theta_hat=math.radians(40))
# The paper's pendulum where its windows end in coexisting attractors (case B, 40 deg): the issue's
# example, where chunks of 50 started from rest differed from the chain at 3 points up, 2 down.
PENDULUM_ETAS = np.linspace(0.44, 0.56, 600)
# The oscillator between two stops, swept in omega: up and down differ over wide ranges (hysteresis).
TWO_STOPS = two_sided_oscillator(amp=0.5, gap_left=1.5)
OMEGAS = np.linspace(0.5, 1.6, 221)


def assert_same_chain(chain, chunked) -> None:
    """Every point the chain's: the same status; where both are aperiodic, one attractor (the chain check's
    rule: :func:`~grazing.core.cells.one_attractor`); where the chain is periodic, the same period and
    samples (to the chain's tolerance).  Except after the two went through an aperiodic point on one
    attractor, until they agree again: from there the chain's samples, and what it lands on after them,
    are an accident of rounding (test_a_chain_through_chaos_is_not_reproducible), its attractor is not.
    A point given its period by a Newton polish (grazing.sweeps.polish: its samples still approach the
    orbit, they do not repeat) is as an aperiodic one: its samples are those of its transient."""
    np.testing.assert_array_equal(chunked.status.values, chain.status.values)
    free = False  # (the two went through one aperiodic attractor since they last ended alike)
    for i in range(chain.period.size):
        p, q = int(chain.period.values[i]), int(chunked.period.values[i])
        a, b = chain.samples.values[i], chunked.samples.values[i]
        unsettled = not _repeats(a, p) and not _repeats(b, q)
        if chain.status.values[i] != 0:  # (both failed alike: the chain starts again from x0)
            free = False
        elif p == q and unsettled and one_attractor(a, b, CHAIN_CELLS):
            free = True
        elif p == q and p > 0 and np.abs(a - b).max() <= 10 * CHAIN_TOL:
            free = False
        else:
            assert free, f"point {i}: period {q}, the chain's {p}"


def _repeats(samples: np.ndarray, p: int) -> bool:
    """Whether ``samples`` repeat with period ``p > 0`` to the period detector's tolerance."""
    return p > 0 and bool(np.abs(samples[p:] - samples[:-p]).max() <= PERIOD_TOL)


def assert_a_chain(model, param, ds, direction, chunk_size) -> None:
    """``ds`` is a chain: the first point of each chunk ends as from the final state of the point visited
    before it (run again from there, alone: what the chain check decides on)."""
    values = ds.value.values
    order = np.arange(values.size) if direction == "up" else np.arange(values.size)[::-1]
    got = SimpleNamespace(**{k: ds[k].values for k in ("status", "period", "samples", "x_final")})
    for k in range(chunk_size, values.size, chunk_size):
        i, before = order[k], order[k - 1]
        again = sweep(model, param, [values[i]], x0=tuple(ds.x_final.values[before]), workers=1)
        ref = SimpleNamespace(**{k: again[k].values for k in ("status", "period", "samples", "x_final")})
        assert same_outcome(got, i, ref, 0), i


@pytest.fixture(scope="module")
def pendulum_chains():
    return {d: sweep(M40, "eta", PENDULUM_ETAS, direction=d, chunk_size=0, workers=2) for d in ("up", "down")}


@pytest.mark.parametrize("direction", ["up", "down"])
def test_the_pendulum_chunked_is_the_chain_at_every_point(pendulum_chains, direction):
    chain = pendulum_chains[direction]
    chunked = sweep(M40, "eta", PENDULUM_ETAS, direction=direction, workers=2)  # 12 chunks of 50
    assert_same_chain(chain, chunked)
    assert_a_chain(M40, "eta", chunked, direction, 50)
    # the chunks' guesses (from rest) differ from the chain somewhere: the check was needed
    guesses = sweep(M40, "eta", PENDULUM_ETAS, direction=direction, fresh=True, workers=2)
    assert (guesses.period.values != chain.period.values).any()


def test_the_pendulum_up_and_down_differ_where_attractors_coexist(pendulum_chains):
    up, down = pendulum_chains["up"], pendulum_chains["down"]
    assert (up.period.values != down.period.values).any()


@pytest.mark.parametrize("direction", ["up", "down"])
@pytest.mark.parametrize("chunk_size", [7, 30])
def test_a_hysteresis_loop_chunked_is_the_chain(direction, chunk_size):
    kw = {"transient": 300, "periods": 32, "direction": direction}
    chain = sweep(TWO_STOPS, "omega", OMEGAS, chunk_size=0, workers=2, **kw)
    chunked = sweep(TWO_STOPS, "omega", OMEGAS, chunk_size=chunk_size, workers=2, **kw)
    assert_same_chain(chain, chunked)


def test_the_hysteresis_loop_is_wide():
    both = sweep(
        TWO_STOPS, "omega", OMEGAS, direction="both", chunk_size=10, transient=300, periods=32, workers=2
    )
    assert both.period.dims == ("direction", "point")
    assert both.direction.values.tolist() == ["up", "down"]
    differ = (both.period.sel(direction="up") != both.period.sel(direction="down")).values
    assert differ.sum() > 20  # (about 60 of the 221 values)
    # each direction is the chain of that direction
    for d in ("up", "down"):
        chain = sweep(
            TWO_STOPS, "omega", OMEGAS, direction=d, chunk_size=0, transient=300, periods=32, workers=2
        )
        assert_same_chain(chain, both.sel(direction=d))


def two_stops_down():
    spec = sweep_spec(TWO_STOPS, "omega", OMEGAS[::3], direction="down")
    return type(spec)(**{**spec.__dict__, "chunk_size": 5, "transient": 200, "periods": 24})


def pendulum_through_chaos():
    # chaotic bands, chunks kept on the chain's attractor, periodic windows with chunks run again
    spec = sweep_spec(M40, "eta", PENDULUM_ETAS[40:200], direction="down")
    return type(spec)(**{**spec.__dict__, "chunk_size": 4, "transient": 300, "periods": 64})


@pytest.mark.parametrize("make", [two_stops_down, pendulum_through_chaos])
def test_the_result_does_not_depend_on_threads_window_or_store(tmp_path, make):
    spec = make()
    one = run_sweep(spec, workers=1)
    sink = MemoryStore(spec)
    # the smallest window: one chunk held at a time
    settle([ChainLine(spec, sink, list(range(spec.n_chunks)))], compute_parts(2, None),
           lambda _k, res: sink.write(res), window=1)  # fmt: skip
    small = sink.dataset()
    stored = run_sweep(spec, store=ZarrStore(tmp_path / "s.zarr", spec), workers=2)
    for other in (small, stored):
        np.testing.assert_array_equal(other.samples.values, one.samples.values)
        np.testing.assert_array_equal(other.period.values, one.period.values)


def two_stops_up():
    spec = sweep_spec(TWO_STOPS, "omega", OMEGAS[::2], direction="up")
    return type(spec)(**{**spec.__dict__, "chunk_size": 8, "transient": 200, "periods": 24})


@pytest.mark.parametrize("make", [two_stops_up, pendulum_through_chaos])
def test_a_store_resumes_from_the_end_stored_before(tmp_path, make):
    spec = make()
    whole = run_sweep(spec, workers=2)
    path = tmp_path / "r.zarr"
    with ZarrStore(path, spec) as store:  # the first chunks only, as a run stopped after them
        part = [0, 1, 2, 3, 4]
        settle([ChainLine(spec, store, part)], compute_parts(2, None), lambda _k, res: store.write(res), 64)
    with ZarrStore(path, spec) as store:
        assert store.n_done == 5
        resumed = run_sweep(spec, store=store, workers=2)
    np.testing.assert_array_equal(resumed.samples.values, whole.samples.values)


def test_several_sweeps_together_are_each_their_chain():
    specs = [sweep_spec(TWO_STOPS, "omega", OMEGAS[::4], direction=d, settings=None) for d in ("up", "down")]
    specs = [type(s)(**{**s.__dict__, "chunk_size": 6, "transient": 200, "periods": 24}) for s in specs]
    together = run_sweeps(specs, workers=2)
    for spec, ds in zip(specs, together):
        chain = run_sweep(type(spec)(**{**spec.__dict__, "chunk_size": 0}), workers=1)
        assert_same_chain(chain, ds)


def test_a_non_periodic_model_continues_from_the_final_time():
    # The ball on a fixed floor (amplitude 0) as a model that is not periodic in time: a chain goes on
    # from the final time of each point, which the store keeps per chunk.
    import sympy as sp

    from grazing import HybridModel, Parameter

    y, v, t, g, r = sp.symbols("y v t g r")
    ball = HybridModel("floor", [y, v], t, [Parameter("g", 1.0, lower=0, lower_open=True),
                       Parameter("r", 0.9, lower=0, upper=1)], vector_field=[v, -g + 0 * t], guard=y,
                       reset=[y, -r * v], period=1, periodic=False)  # fmt: skip
    x0 = (1.0, 0.0)
    values = np.linspace(0.5, 1.0, 12)
    spec = sweep_spec(ball, "g", values, x0=x0)
    spec = type(spec)(**{**spec.__dict__, "chunk_size": 3, "transient": 1, "periods": 2, "lyapunov": False})
    chunked = run_sweep(spec, workers=2)
    chain = run_sweep(type(spec)(**{**spec.__dict__, "chunk_size": 0}), workers=1)
    assert (chain.status.values == 0).sum() >= 8  # (one point fails: the chain starts again from x0 after it)
    np.testing.assert_array_equal(chunked.status.values, chain.status.values)
    np.testing.assert_allclose(chunked.samples.values, chain.samples.values, rtol=0, atol=1e-12)


def test_same_outcome_needs_the_same_orbit_at_the_same_point():
    spec = sweep_spec(M40, "eta", [0.455, 0.4555])  # period 3
    res = run_sweep(spec, workers=1)
    from grazing.sweeps.run import run_chunk

    a = run_chunk(spec, 0)
    assert same_outcome(a, 0, a, 0)
    shifted = type(a)(**{**a.__dict__, "samples": np.roll(a.samples, 1, axis=1)})
    assert int(res.period.values[0]) == 3
    assert not same_outcome(a, 0, shifted, 0)  # the same orbit, another point of it: not the chain


# issue 28 follow-up: a chunk whose first point is aperiodic is kept when it is on the chain's attractor.


def counted(parts_log: list) -> object:
    """``settle``'s compute on two local threads, recording every part it computes."""
    inner = compute_parts(2, None)

    def compute(parts):
        for part, res in inner(parts):
            parts_log.append((part, res))
            yield part, res

    return compute


def settled(spec, parts_log: list | None = None):
    """The dataset of ``spec`` settled, every chunk held at once (the parts computed into ``parts_log``)."""
    sink = MemoryStore(spec)
    log = [] if parts_log is None else parts_log
    settle([ChainLine(spec, sink, list(range(spec.n_chunks)))], counted(log), lambda _k, res: sink.write(res),
           window=1 << 40)  # fmt: skip
    return sink.dataset()


def chunked_spec(model, param, values, chunk_size, **settings):
    spec = sweep_spec(model, param, values)
    return type(spec)(**{**spec.__dict__, "chunk_size": chunk_size, **settings})


def runs_of(spec, parts_log):
    """The parts of ``parts_log`` by kind: guesses (chunks of ``spec`` from x0), checks (one point from a
    chain's start), shifts (a chunk from a point of its guess's orbit) and runs from a chain's start."""
    guesses = [(p, r) for p, r in parts_log if p[0] is spec]
    orbits = {tuple(map(float, x)) for _, r in guesses for x in r.samples[0]}
    checks = [(p, r) for p, r in parts_log if p[0] is not spec and len(p[0].points) == 1]
    longer = [(p, r) for p, r in parts_log if p[0] is not spec and len(p[0].points) > 1]
    shifts = [(p, r) for p, r in longer if p[0].resume[1] in orbits]
    runs = [(p, r) for p, r in longer if p[0].resume[1] not in orbits]
    return guesses, checks, shifts, runs


BANDS = {  # chaotic bands: every point of the chain aperiodic, with a positive Lyapunov exponent
    "pendulum": (M40, "eta", np.linspace(0.4591, 0.4625, 32), {}),
    "two stops": (two_sided_oscillator(amp=4.0, r=0.8, zeta=0.02), "omega", np.linspace(1.27, 1.43, 32),
                  {"transient": 300, "periods": 128}),
}  # fmt: skip


@pytest.mark.parametrize("name", sorted(BANDS))
def test_a_chaotic_band_chunked_is_on_the_chains_attractor_at_every_point(name):
    model, param, values, settings = BANDS[name]
    chain = sweep(model, param, values, chunk_size=0, workers=2, **settings)
    assert (chain.period.values <= 0).all() and (chain.lyapunov.values > 1e-3).all()
    spec = chunked_spec(model, param, values, 4, **settings)
    log: list = []
    chunked = settled(spec, log)
    for i in range(values.size):
        assert int(chunked.period.values[i]) <= 0
        assert one_attractor(chain.samples.values[i], chunked.samples.values[i], CHAIN_CELLS), i
    # not a chain run point after point: every chunk from its guess, checked once, none run again
    guesses, checks, shifts, runs = runs_of(spec, log)
    assert len(guesses) == spec.n_chunks and len(checks) == spec.n_chunks - 1 and shifts == runs == []
    # (and its samples are not the chain's: the chain check did not compare them)
    assert np.abs(chunked.samples.values[4:] - chain.samples.values[4:]).max() > 1e-2


def test_a_chaotic_guess_where_the_chain_is_periodic_is_run_again():
    # Case B, 40 deg: from rest the pendulum ends chaotic at these eta, the chain coming from below stays
    # on its period-3 orbit (coexisting attractors).
    values = PENDULUM_ETAS[80:100]
    fresh = sweep(M40, "eta", values, fresh=True, workers=2)
    chain = sweep(M40, "eta", values, chunk_size=0, workers=2)
    assert (chain.period.values[8:16] == 3).all()
    # the chunks (of 4) whose first point, from rest (the guess), ends chaotic (which of them do is a
    # matter of rounding: chaotic transients)
    starts = [i for i in range(8, 16, 4) if fresh.period.values[i] == 0]
    assert starts
    spec = chunked_spec(M40, "eta", values, 4)
    log: list = []
    chunked = settled(spec, log)
    assert_same_chain(chain, chunked)
    np.testing.assert_array_equal(chunked.period.values, chain.period.values)
    runs = runs_of(spec, log)[3]
    again = {point for p, _ in runs for point in p[0].points}
    for i in starts:  # (their checks ended periodic)
        assert set(spec.points[i : i + 4]) <= again


def _result(samples, period, status=0):
    samples = np.asarray(samples, dtype=float)[None]
    return ChunkResult(0, samples, np.array([period]), np.zeros(1), np.zeros(1), np.zeros(1),
                       samples[:, -1], np.array([status]))  # fmt: skip


def test_same_outcome_of_aperiodic_points_is_one_attractor():
    k = np.arange(200.0)
    ring = np.stack([np.cos(0.7 * k), np.sin(0.7 * k)], 1)  # points all around a circle
    on_ring = _result(ring[:100], 0)
    assert same_outcome(on_ring, 0, _result(ring[100:], 0), 0)  # other points of one set: one attractor
    assert not same_outcome(on_ring, 0, _result(ring[100:] + np.array([3.0, 0.0]), 0), 0)  # a set apart
    assert not same_outcome(on_ring, 0, _result(0.5 * ring[100:], 0), 0)  # inside it, sharing no cell
    point = _result(np.repeat(ring[:1], 100, axis=0), 1)  # a periodic orbit on the ring: another attractor
    assert not same_outcome(on_ring, 0, point, 0) and not same_outcome(point, 0, on_ring, 0)
    failed = _result(ring[:100] * np.nan, 0, status=1)
    assert not same_outcome(on_ring, 0, failed, 0) and same_outcome(failed, 0, failed, 0)


def test_the_default_sweep_through_chaos_computes_its_points_about_once():
    # The sweep (case B, 40 deg, eta 0.44-0.49) at 200 points in chunks of 20: chunks start in
    # chaos (before: each run again from the chain's end, one after the other)
    values = np.linspace(0.44, 0.49, 200)
    spec = chunked_spec(M40, "eta", values, 20)
    log: list = []
    ds = settled(spec, log)
    guesses, checks, shifts, runs = runs_of(spec, log)
    firsts = {spec.points[spec.chunk(i).start]: i for i in range(spec.n_chunks)}
    guess_of = {p[1]: r for p, r in guesses}
    aperiodic_firsts = [i for i in range(spec.n_chunks) if ds.period.values[spec.chunk(i).start] <= 0]
    assert len(aperiodic_firsts) >= 2  # (the chunks from eta[40] and eta[80])
    assert len(guesses) == spec.n_chunks
    for part, res in runs:  # run again only where a check found another attractor than the guess's
        guess = guess_of[firsts[part[0].points[0]]]
        assert int(guess.period[0]) != int(res.period[0]) or int(res.period[0]) > 0
    shifted = [firsts[part[0].points[0]] for part, _ in shifts]
    for i in set(shifted):  # from points of a periodic guess's orbit, each once
        starts = [part[0].resume for part, _ in shifts if firsts[part[0].points[0]] == i]
        assert len(set(starts)) == len(starts) <= int(guess_of[i].period[0]) in range(2, CHAIN_SHIFTS + 1)
    points = sum(len(p[0].points) if p[0] is not spec else 20 for p, _ in log)
    assert points == 200 + len(checks) + sum(len(p[0].points) for p, _ in shifts + runs)
    # none run again from its chain's start, one after the other: every round after the shifts is checks
    assert runs == [] and len(checks) <= 3 * spec.n_chunks


def test_a_chain_through_chaos_is_not_reproducible():
    # Why a chunk whose first point is aperiodic is kept on the chain's attractor, not on its samples: a
    # rounding-level change of the chain's state entering a chaotic band leaves it on the band's attractor,
    # but moves its samples by the band's size, and with them where it lands after the band.
    values = PENDULUM_ETAS[:200]
    chain = sweep(M40, "eta", values, chunk_size=0, workers=1)
    aperiodic = chain.period.values <= 0
    runs = np.split(np.arange(values.size), np.flatnonzero(np.diff(aperiodic.astype(int))) + 1)
    band = max((r for r in runs if aperiodic[r[0]]), key=len)  # (case B, 40 deg: the band from eta[96])
    assert band.size >= 8, band
    x = chain.x_final.values[band[0] - 1]
    specs = []
    for eps in (1e-15, 2e-15, 3e-15, 5e-15, 7e-15, 1e-14):
        spec = sweep_spec(M40, "eta", values[band[0] :], x0=tuple(x * (1 + eps)))
        specs.append(type(spec)(**{**spec.__dict__, "chunk_size": 0}))
    after = slice(band[0], None)
    moved_later = 0
    for ds in run_sweeps(specs, workers=2):
        for k, i in enumerate(band):
            assert one_attractor(ds.samples.values[k], chain.samples.values[i], CHAIN_CELLS)
        assert np.abs(ds.samples.values[: band.size] - chain.samples.values[band]).max() > 1e-2
        periodic = (chain.period.values[after] > 0) & (ds.period.values > 0)
        gap = np.abs(ds.samples.values - chain.samples.values[after]).max(axis=(1, 2))
        other_period = ds.period.values != chain.period.values[after]
        moved_later += bool((periodic & (gap > 1e-3)).any() or other_period.any())
    assert moved_later >= 1  # (measured: 4 of these 6 land at another point of the period-2 orbit after it)


@pytest.mark.parametrize(("window", "period"), [(slice(62, 86), 3), (slice(130, 170), 2)])
def test_a_guess_at_another_point_of_the_chains_orbit_is_kept_shifted(window, period):
    # In a periodic window the guesses from rest end at any point of the orbit, the chain's one time in p:
    # each such chunk is computed from every point of its guess's orbit (in parallel, from the guess alone)
    # and the one whose first point ends as the chain's is kept; none is run again after the one before.
    values = PENDULUM_ETAS[window]
    chain = sweep(M40, "eta", values, chunk_size=0, workers=2)
    assert (chain.period.values == period).all()
    spec = chunked_spec(M40, "eta", values, 4)
    log: list = []
    chunked = settled(spec, log)
    _guesses, _checks, shifts, runs = runs_of(spec, log)
    assert shifts and not runs
    np.testing.assert_array_equal(chunked.period.values, chain.period.values)
    assert np.abs(chunked.samples.values - chain.samples.values).max() <= 10 * CHAIN_TOL


def test_a_dask_cluster_settles_the_same_chain_through_chaos():
    spec = pendulum_through_chaos()
    local = run_sweep(spec, workers=2)
    with loopback_client(2) as client:
        remote = run_sweep(spec, client=client)
    np.testing.assert_array_equal(remote.samples.values, local.samples.values)
    np.testing.assert_array_equal(remote.period.values, local.period.values)


# issue 29: the rounds after the guesses, checks and shifts are few, the results the same.


def settled_by_rounds(spec, monkeypatch=None, **patches):
    """The dataset of ``spec`` settled (every chunk held at once) and the parts of each round (its calls of
    compute), with ``_Round``'s methods ``patches`` replaced for the run."""
    from grazing.sweeps import chain

    with pytest.MonkeyPatch.context() as mp:
        for name, method in patches.items():
            mp.setattr(chain._Round, name, method)
        inner, rounds = compute_parts(2, None), []

        def compute(parts):
            rounds.append(list(parts))
            yield from inner(parts)

        sink = MemoryStore(spec)
        settle([ChainLine(spec, sink, list(range(spec.n_chunks)))], compute, lambda _k, res: sink.write(res),
               window=1 << 40)  # fmt: skip
    return sink.dataset(), rounds


def assert_identical(a, b) -> None:
    for name in a.data_vars:
        assert np.array_equal(a[name].values, b[name].values, equal_nan=True), name


def test_a_ripple_through_a_periodic_window_is_decided_at_once():
    # A period-2 window in chunks of 4: each guess (from rest) ends at either point of the orbit, so a chunk
    # kept at the other point moves the start of the chunk after it, which is kept shifted too, and so on.
    # The chunk after a chunk with shifts is checked from the end of each of its candidates: the whole
    # ripple is decided in one round (it took a round a chunk: 13 rounds here).
    spec = chunked_spec(M40, "eta", PENDULUM_ETAS[120:200], 4)
    ds, rounds = settled_by_rounds(spec)
    one_by_one, before = settled_by_rounds(spec, check_after=lambda self, c: None)
    assert_identical(ds, one_by_one)
    assert len(before) >= 3 + spec.n_chunks // 3  # (guesses, checks, shifts, then a round a chunk)
    assert len(rounds) <= 4
    chain = sweep(M40, "eta", PENDULUM_ETAS[120:200], chunk_size=0, workers=2)
    np.testing.assert_array_equal(ds.period.values, chain.period.values)


def test_chunks_run_again_one_after_the_other_are_run_each_alone():
    # Through chaos down to a periodic window: chunks whose guesses miss the chain's attractor one after the
    # other.  Each is run again as a part of its own: run on over the next ones as one part (as it was), it
    # made its round as long as all of them while the other chains' chunks waited.
    spec = pendulum_through_chaos()
    log: list = []
    ds = settled(spec, log)
    runs = runs_of(spec, log)[3]
    firsts = {spec.points[spec.chunk(i).start]: i for i in range(spec.n_chunks)}
    run_again = {firsts[p[0].points[0]] for p, _ in runs}
    assert any(i + 1 in run_again for i in run_again)  # (a cascade: one run after the other)
    assert all(len(p[0].points) <= spec.chunk_size for p, _ in log if p[0] is not spec)
    assert_identical(ds, run_sweep(spec, workers=1))


def test_the_end_of_each_result_is_worked_out_once(monkeypatch):
    # (a chunk's end, asked for in every round and for each candidate whose end is checked, was worked out
    # each time: 17629 times for the default 16000-point sweep's 1000-odd results, a part of its serial time)
    from grazing.sweeps import chain

    calls: list = []
    inner = chain.next_start

    def counted_next_start(spec, res, index):
        calls.append(id(res))
        return inner(spec, res, index)

    monkeypatch.setattr(chain, "next_start", counted_next_start)
    spec = chunked_spec(M40, "eta", PENDULUM_ETAS[120:200], 4)
    log: list = []
    settled(spec, log)
    results = [r for p, r in log if p[0] is spec or len(p[0].points) > 1]  # (guesses, shifts and runs)
    assert len(calls) == len(set(calls)) <= len(results)


# Only the shifts a chunk keeps are computed (the default sweep computed 9700 shifts to keep 50 of them).


def test_orbit_advance_is_how_far_along_its_orbit_a_point_ends():
    orbit = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, -0.5]])
    samples = np.tile(orbit, (10, 1))  # (30 samples of a period-3 orbit, ending at its last point)
    guess = _result(samples, 3)
    for m in range(3):
        assert orbit_advance(guess, _result(np.roll(samples, -m, axis=0), 3), 3) == m
        nudged = np.roll(samples, -m, axis=0) + 1e-4  # (nearer to that turn of the orbit than to another)
        assert orbit_advance(guess, _result(nudged, 3), 3) == m
    assert orbit_advance(guess, _result(samples + 5.0, 3), 3) is None  # (on another orbit)
    # a period-4 orbit within rounding of a period-2 one: turned by 2 it is itself, which turn is not known
    twice = np.tile(np.array([[0.0, 1.0], [1.0, 0.0], [0.0, 1.0 + 1e-7], [1.0, 0.0]]), (10, 1))
    assert orbit_advance(_result(twice, 4), _result(np.roll(twice, -1, axis=0), 4), 4) is None
    assert orbit_advance(_result(twice, 4), _result(twice, 4), 4) is None


TWO_STOPS_3 = (two_sided_oscillator(amp=4.0, r=0.8, zeta=0.02), "omega", np.linspace(1.450, 1.458, 3))
PENDULUM_3 = (M40, "eta", PENDULUM_ETAS[62:65])
PENDULUM_2 = (M40, "eta", PENDULUM_ETAS[140:143])


@pytest.mark.parametrize(("case", "period"), [(TWO_STOPS_3, 3), (PENDULUM_3, 3), (PENDULUM_2, 2)])
@pytest.mark.parametrize("settings", [
    {"transient": 300, "periods": 100}, {"transient": 301, "periods": 100},
    {"transient": 302, "periods": 64}, {"transient": 301, "periods": 100, "adaptive": False},
    {"transient": 302, "periods": 100, "lyapunov": True},
])  # fmt: skip
def test_a_shift_ends_its_first_point_as_far_along_the_orbit_as_asked(case, period, settings):
    # A point runs transient + periods periods (an adaptive transient: a number congruent to it modulo the
    # period; with Lyapunov exponents, the last of them aligning the tangent vectors): from the orbit's
    # point j its samples are j + transient + periods + 1 points along the orbit from the guess's.
    model, param, values = case
    spec = chunked_spec(model, param, values, 3, **settings)
    guess = run_parts([(spec, 0)])[0]
    assert int(guess.period[0]) == period
    for m in range(period):
        shifted = run_parts([from_start(spec, 0, shifted_start(spec, 0, guess, m))])[0]
        assert orbit_advance(guess, shifted, period) == m
        ahead = guess.samples[0][m:]  # (the guess's samples m periods on)
        assert np.abs(shifted.samples[0][: len(ahead)] - ahead).max() <= 10 * CHAIN_TOL


SHIFTED = {  # sweeps whose chunks keep shifts: the pendulum's windows, the two-stop oscillator's period 3
    "pendulum 62-86": (M40, "eta", PENDULUM_ETAS[62:86], {}),
    "pendulum 120-200": (M40, "eta", PENDULUM_ETAS[120:200], {}),
    "pendulum 40-120": (M40, "eta", PENDULUM_ETAS[40:120], {}),
    "two stops": (TWO_STOPS_3[0], "omega", np.linspace(1.445, 1.462, 36), {"transient": 301, "periods": 97}),
}


@pytest.mark.parametrize("name", sorted(SHIFTED))
def test_the_shifts_computed_are_those_kept_with_the_same_results(name):
    # The result a chunk keeps is the one candidate whose first point ends as its check does: computing
    # only the shift as far along the orbit as the check (and, where the chunk before it moves, as far as
    # it will be) gives the results of computing every shift, with fewer points.
    from grazing.sweeps import chain

    model, param, values, settings = SHIFTED[name]
    spec = chunked_spec(model, param, values, 4, **settings)
    lazy, rounds = settled_by_rounds(spec)
    every = lambda self, check, p: [k for k in range(p) if k not in self.shifts]  # noqa: E731
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(chain._Chunk, "shifts_wanted", every)
        eager, eager_rounds = settled_by_rounds(spec)
    assert_identical(lazy, eager)
    assert computed(spec, rounds) < computed(spec, eager_rounds)


def computed(spec, rounds) -> int:
    """The points computed in ``rounds`` besides the guesses (of ``spec``'s chunks)."""
    return sum(len(part[0].points) for parts in rounds for part in parts if part[0] is not spec)
