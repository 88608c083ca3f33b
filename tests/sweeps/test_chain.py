"""A sweep that carries its state is one chain, whatever the chunking (grazing.sweeps.chain)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grazing.core.options import CHAIN_TOL
from grazing.models import pendulum, two_sided_oscillator
from grazing.sweeps import run_sweep, run_sweeps, sweep
from grazing.sweeps.chain import ChainLine, same_outcome, settle
from grazing.sweeps.executor import compute_parts
from grazing.sweeps.spec import sweep_spec
from grazing.sweeps.store import MemoryStore, ZarrStore

M40 = pendulum("B", theta_hat=math.radians(40))
# The paper's pendulum where its windows end in coexisting attractors (case B, 40 deg): the issue's
# example, where chunks of 50 started from rest differed from the chain at 3 points up, 2 down.
PENDULUM_ETAS = np.linspace(0.44, 0.56, 600)
# The oscillator between two stops, swept in omega: up and down differ over wide ranges (hysteresis).
TWO_STOPS = two_sided_oscillator(amp=0.5, gap_left=1.5)
OMEGAS = np.linspace(0.5, 1.6, 221)


def assert_same_chain(chain, chunked) -> None:
    """Every point alike: status, period, and on a periodic orbit the samples (to the chain's tolerance)."""
    np.testing.assert_array_equal(chunked.status.values, chain.status.values)
    np.testing.assert_array_equal(chunked.period.values, chain.period.values)
    periodic = chain.period.values > 0
    diff = np.abs(chunked.samples.values[periodic] - chain.samples.values[periodic])
    assert diff.max() <= 10 * CHAIN_TOL


@pytest.fixture(scope="module")
def pendulum_chains():
    return {d: sweep(M40, "eta", PENDULUM_ETAS, direction=d, chunk_size=0, workers=2) for d in ("up", "down")}


@pytest.mark.parametrize("direction", ["up", "down"])
def test_the_pendulum_chunked_is_the_chain_at_every_point(pendulum_chains, direction):
    chain = pendulum_chains[direction]
    chunked = sweep(M40, "eta", PENDULUM_ETAS, direction=direction, workers=2)  # 12 chunks of 50
    assert_same_chain(chain, chunked)
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


def test_the_result_does_not_depend_on_threads_window_or_store(tmp_path):
    spec = sweep_spec(TWO_STOPS, "omega", OMEGAS[::3], direction="down")
    spec = type(spec)(**{**spec.__dict__, "chunk_size": 5, "transient": 200, "periods": 24})
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


def test_a_store_resumes_from_the_end_stored_before(tmp_path):
    spec = sweep_spec(TWO_STOPS, "omega", OMEGAS[::2], direction="up")
    spec = type(spec)(**{**spec.__dict__, "chunk_size": 8, "transient": 200, "periods": 24})
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
