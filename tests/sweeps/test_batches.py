"""Local batches run one after the other by threads that do not wait at a batch's end (grazing.sweeps.run)."""

from __future__ import annotations

import dataclasses
import functools
import threading

import numpy as np
import pytest

from grazing.core.options import SweepSettings
from grazing.engine.llvmgen import lane_width
from grazing.models import impact_oscillator, pendulum
from grazing.sweeps import executor
from grazing.sweeps.run import LaneBatch, run_chunks, stream_batches
from grazing.sweeps.spec import sweep_spec

FIELDS = [f.name for f in dataclasses.fields(executor.ChunkResult) if f.name not in ("index", "seconds")]


def _same(a, b) -> bool:
    return all(np.array_equal(getattr(a, f), getattr(b, f), equal_nan=True) for f in FIELDS)


@pytest.mark.parametrize("fresh", [True, False])
def test_batches_give_each_chunk_once_as_computed_alone(fresh):
    """Chunks in batches of several sizes, three threads: every chunk once, with the results of the chunk
    computed alone (a chunk's result does not depend on the chunks computed with it)."""
    model = impact_oscillator(sigma=0.1)
    spec = sweep_spec(model, "omega", np.linspace(1.5, 3.0, 41), settings=SweepSettings(
        fresh=fresh, chunk_size=3, transient=40, periods=12))  # fmt: skip
    groups = [[0], [1, 2, 3], [4], list(range(5, 12)), [12, 13]]
    assert sorted(i for g in groups for i in g) == list(range(spec.n_chunks))
    makers = [functools.partial(LaneBatch, [(spec, i) for i in g]) for g in groups]
    got = {}
    for k, i, res in stream_batches(makers, 3):
        assert (k, i) not in got
        got[k, i] = res
        assert res.index == groups[k][i]
    assert sorted(got) == [(k, i) for k, g in enumerate(groups) for i in range(len(g))]
    alone = {res.index: res for res in run_chunks(spec, range(spec.n_chunks))}
    for res in got.values():
        assert _same(res, alone[res.index]), res.index


def test_local_results_of_a_fresh_sweep_in_growing_batches(monkeypatch):
    """A fresh sweep's batches grow from one that fills the lanes; the results are those of one batch."""
    n = 4 * 2 * lane_width() * 6  # (the first batch fills two threads' lanes: 4 points each)
    spec = sweep_spec(pendulum("B"), "eta", np.linspace(0.44, 0.49, n), settings=SweepSettings(
        fresh=True, chunk_size=2, transient=20, periods=6))  # fmt: skip
    monkeypatch.setattr(executor, "BATCH_VALUES", 4 * 4 * (n // 6) * 6 * 2)  # (so that they grow)
    parts = [(spec, i) for i in range(spec.n_chunks)]
    sizes = [len(b) for b in executor.local_batches(parts, 2)]
    assert len(sizes) > 2 and sizes[1] > sizes[0]
    got = {part[1]: res for part, res in executor.local_results(parts, 2)}
    alone = {res.index: res for res in run_chunks(spec, range(spec.n_chunks))}
    assert sorted(got) == sorted(alone)
    assert all(_same(got[i], alone[i]) for i in alone)


def _thread_errors(monkeypatch) -> list[str]:
    """The exceptions that end a thread from now on, as "thread: exception" (none may go unhandled)."""
    errors: list[str] = []
    monkeypatch.setattr(
        threading, "excepthook", lambda a: errors.append(f"{a.thread.name}: {a.exc_type.__name__}")
    )
    return errors


def _alive() -> list[str]:
    return [t.name for t in threading.enumerate() if t.name.startswith(("grazing-sweep", "grazing-batch"))]


def test_a_batch_that_cannot_be_built_stops_the_threads(monkeypatch):
    """An error building a later batch reaches the consumer; no batch after it is begun (the next one was
    begun while the error travelled, and left building); every thread has returned, none with an exception
    (a thread stopping the stream met the next batch's cancelled future: CancelledError)."""
    spec = sweep_spec(pendulum("B"), "eta", np.linspace(0.44, 0.49, 8), settings=SweepSettings(
        fresh=True, chunk_size=2, transient=20, periods=6))  # fmt: skip
    errors = _thread_errors(monkeypatch)
    begun: list[int] = []

    def broken() -> LaneBatch:
        raise ValueError("no table")

    def after() -> LaneBatch:
        begun.append(2)
        return LaneBatch([(spec, 2)])

    makers = [functools.partial(LaneBatch, [(spec, 0), (spec, 1)]), broken, after]
    with pytest.raises(ValueError, match="no table"):
        list(stream_batches(makers, 2))
    assert (begun, _alive(), errors) == ([], [], [])


class _FailingBatch:
    """A batch whose run fails once ``begin`` is set (the next batch being built)."""

    def __init__(self, begin: threading.Event) -> None:
        self.control, self.jobs, self._begin = np.zeros(3, dtype=np.int64), [0], begin

    def run(self) -> None:
        assert self._begin.wait(30)
        raise RuntimeError("lane failed")

    def stop(self) -> None:
        pass

    def finished(self) -> list[int]:
        return []

    def all_taken(self) -> bool:
        return False

    def results(self, ks):
        return []


def test_a_failed_batch_waits_for_the_batch_being_built(monkeypatch):
    """A batch whose run fails while the next one is being built: the error reaches the consumer once the
    builder's thread has finished it and returned (it was left alive); no thread ends with an exception."""
    import time

    errors = _thread_errors(monkeypatch)
    building, built = threading.Event(), threading.Event()

    def slow() -> _FailingBatch:
        building.set()
        time.sleep(0.3)
        built.set()
        return _FailingBatch(building)

    with pytest.raises(RuntimeError, match="lane failed"):
        list(stream_batches([lambda: _FailingBatch(building), slow], 2))
    assert (built.is_set(), _alive(), errors) == (True, [], [])


def test_a_stopped_stream_does_not_wait_for_a_batch_being_built():
    """issue 43: a batch being built when the consumer stops (Ctrl-C during the driver's first compile,
    which nothing interrupts: half a minute) is not waited for; its daemon thread finishes it alone."""
    import time

    spec = sweep_spec(pendulum("B"), "eta", np.linspace(0.44, 0.49, 4), settings=SweepSettings(
        fresh=True, chunk_size=2, transient=20, periods=6))  # fmt: skip
    building, release = threading.Event(), threading.Event()

    def long_compile() -> LaneBatch:
        building.set()
        release.wait(60)
        return LaneBatch([(spec, 1)])

    stream = stream_batches([functools.partial(LaneBatch, [(spec, 0)]), long_compile], 2)
    try:
        assert next(stream)[:2] == (0, 0)
        assert building.wait(30)
        start = time.monotonic()
        stream.close()  # (as a KeyboardInterrupt in the consumer's loop)
        assert time.monotonic() - start < 1.0
        alive = [t for t in threading.enumerate() if t.name.startswith(("grazing-sweep", "grazing-batch"))]
        assert [(t.name, t.daemon) for t in alive] == [("grazing-batch", True)]  # (the one building)
    finally:
        release.set()
    for t in alive:
        t.join(60)


@pytest.mark.parametrize("fresh", [True, False])
def test_the_dataset_is_prepared_while_the_cores_compute(fresh, monkeypatch):
    """issue 29: what a sweep's dataset needs besides its results (xarray, the dask it asks about, the
    stops' levels: about 1 s of a process's first sweep) is done once the first chunk is in, while the
    other chunks compute (a fresh sweep: after its first chunk is written; a chain: in its first
    round, before any chunk is settled), not after the last one; the dataset is the same."""
    from grazing.sweeps.api import run_sweep
    from grazing.sweeps.store import MemoryStore, _stop_levels

    settings = SweepSettings(fresh=fresh, chunk_size=8, transient=50, periods=16)
    spec = sweep_spec(impact_oscillator(), "omega", np.linspace(2.5, 3.0, 240), settings=settings)
    written: list[int] = []
    prepared_after: list[int] = []
    write, prepare = MemoryStore.write, MemoryStore.prepare

    def counted_write(store, res):
        written.append(res.index)
        write(store, res)

    def counted_prepare(store):
        prepared_after.append(len(written))
        prepare(store)

    monkeypatch.setattr(MemoryStore, "write", counted_write)
    monkeypatch.setattr(MemoryStore, "prepare", counted_prepare)
    ds = run_sweep(spec, workers=2)
    assert prepared_after[0] == (1 if fresh else 0) and len(written) == spec.n_chunks
    np.testing.assert_array_equal(ds.stop_level.values, _stop_levels(spec))  # (as built without preparing)
    assert np.all(ds.stop_level.values[:, 0] == impact_oscillator().stop_level(0))
    if fresh:
        alone = run_chunks(spec, range(spec.n_chunks))
        np.testing.assert_array_equal(ds.period.values, np.concatenate([r.period for r in alone]))
