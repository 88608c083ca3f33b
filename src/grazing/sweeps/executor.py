"""Where the chunks of a sweep run: on the local cores (threads of this process) or on a Dask cluster.

Locally, the chunks (of one sweep, or of several: :func:`local_results`)
are computed in batches (:func:`local_batches`) by one
thread per core sharing each batch's jobs
(:func:`grazing.sweeps.run.stream_batches`: the compiled driver runs without
the GIL), and handed to the caller as each one finishes.  No worker process
is started, so there is none to leave behind, and a small sweep costs little
more than its work; Ctrl-C (or an error while storing a result) stops the
threads at their next step.

A Dask cluster gets groups of chunks (:func:`chunk_groups`), each computed
together on the SIMD lanes of :func:`grazing.sweeps.run.run_chunks`, a
bounded window of them at a time; without any worker for a while the caller
is told, and given up on after a timeout.
"""

from __future__ import annotations

import functools
import math
import os
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from grazing.errors import GrazingError
from grazing.parallel import in_flight
from grazing.sweeps.run import LaneBatch, batch_key, run_parts, stream_batches
from grazing.sweeps.spec import ChunkResult, SweepSpec


class SweepTimeoutError(GrazingError):
    """A Dask cluster had no worker for longer than the timeout."""


DASK_NOTICE_AFTER = 5.0
"""Seconds without any Dask worker before :func:`run_sweep` says it is waiting for one."""

POLL_INTERVAL = 0.5
"""Seconds between two looks at a Dask cluster while no chunk finishes."""

TASK_POINTS = 256
"""Fewest points of a Dask task of a fresh sweep (where there are enough: see :data:`TASKS_PER_WORKER`)."""

TASKS_PER_WORKER = 8
"""Fewest Dask tasks per worker of a fresh sweep."""

BATCH_VALUES = 1 << 21
"""Most sample values (points x periods x states) of a local batch, beyond what filling the lanes takes."""

BATCH_GROWTH = 4
"""A fresh sweep's local batches grow by this factor up to :data:`BATCH_VALUES`, the first one filling the
lanes only: the threads start after building a small table, the next ones are built while they compute."""


def chunk_groups(spec: SweepSpec, todo: Sequence[int], workers: int) -> list[list[int]]:
    """``todo`` split into groups of consecutive chunks, each computed together on SIMD lanes.

    A continuation sweep fills the lanes with one chunk each (up to two
    chunks per lane: a lane whose chunk is done takes the next), no group
    bigger than an even share of the chunks among the workers.  A fresh one
    gives each task at least :data:`TASK_POINTS` points (a task costs the
    cluster a few milliseconds, and its lanes run idle at its end), yet at
    least :data:`TASKS_PER_WORKER` tasks to each worker (the last tasks
    finish at different times).

    Examples
    --------
    >>> import grazing
    >>> from grazing.sweeps.spec import sweep_spec
    >>> spec = sweep_spec(grazing.models.pendulum("B"), "eta", [0.4 + 0.001 * i for i in range(100)])
    >>> [len(g) for g in chunk_groups(spec, range(spec.n_chunks), workers=2)]
    [1, 1]
    >>> from grazing.core.options import SweepSettings
    >>> values = [0.4 + 1e-6 * i for i in range(32000)]
    >>> fresh = sweep_spec(grazing.models.pendulum("B"), "eta", values, settings=SweepSettings(fresh=True))
    >>> [len(chunk_groups(fresh, range(fresh.n_chunks), workers=w)) for w in (2, 16)]
    [107, 128]
    """
    from grazing.engine.llvmgen import lane_width

    workers = max(1, workers)
    if spec.fresh:
        per = min(math.ceil(TASK_POINTS / spec.size), math.ceil(len(todo) / (TASKS_PER_WORKER * workers)))
    else:
        per = min(2 * lane_width(), math.ceil(len(todo) / workers))
    per = max(1, per)
    todo = list(todo)
    return [todo[i : i + per] for i in range(0, len(todo), per)]


Part = tuple[SweepSpec, int]
"""A chunk of a sweep: the spec and the chunk's index."""


def local_batches(parts: Sequence[Part], threads: int) -> list[list[Part]]:
    """``parts`` split into the batches that ``threads`` threads compute in turn (one driver call each).

    The chunks of a batch share the model and the sweep settings
    (:func:`grazing.sweeps.run.batch_key`).  A batch fills every thread's
    lanes twice over (two chains of a continuation sweep per lane, four
    points per lane) and holds at least :data:`BATCH_VALUES` sample values
    (points x periods x states) when there are that many: a batch's chunks
    reach the caller as they finish, but its lanes run idle at its end.  A
    fresh sweep's first batch only fills the lanes, and the next ones grow by
    :data:`BATCH_GROWTH` up to that size: the threads wait only for the first
    batch's table of points (:func:`local_results` builds the next ones while
    they compute), and a fresh sweep's lanes are idle at a batch's end for
    less than a point's time (a chain's, for its slowest chain: not so grown).

    Examples
    --------
    >>> import grazing
    >>> from grazing.core.options import SweepSettings
    >>> from grazing.engine.llvmgen import lane_width
    >>> from grazing.sweeps.spec import sweep_spec
    >>> spec = sweep_spec(grazing.models.pendulum("B"), "eta", [0.4 + 0.001 * i for i in range(1000)])
    >>> [len(b) for b in local_batches([(spec, i) for i in range(spec.n_chunks)], threads=2)]
    [20]
    >>> values = [0.4 + 1e-6 * i for i in range(32000)]
    >>> fresh = sweep_spec(grazing.models.pendulum("B"), "eta", values, settings=SweepSettings(fresh=True))
    >>> batches = local_batches([(fresh, i) for i in range(fresh.n_chunks)], threads=2)
    >>> points = [sum(fresh.chunk(i).stop - fresh.chunk(i).start for _, i in b) for b in batches]
    >>> points[0] >= 4 * 2 * lane_width(), points[1] >= 4 * points[0], max(points) * 200 < 2 * 2**21
    (True, True, True)
    """
    from grazing.engine.llvmgen import lane_width

    lanes = max(1, lane_width()) * max(1, threads)
    groups: dict[tuple[Any, ...], list[Part]] = {}
    for part in parts:
        groups.setdefault(batch_key(part[0]), []).append(part)
    out: list[list[Part]] = []
    for group in groups.values():
        batch: list[Part] = []
        jobs = points = values = 0
        fresh = all(spec.fresh for spec, _ in group)
        least = 0 if fresh else BATCH_VALUES  # (the sample values the next batch needs)
        for part in group:
            spec, i = part
            sl = spec.chunk(i)
            size = sl.stop - sl.start
            batch.append(part)  # (the caller's own tuple: it finds its results by it)
            jobs += size if spec.fresh else 1
            points += size
            values += size * spec.periods * spec.model.n_states
            if jobs >= 2 * lanes and points >= 4 * lanes and values >= least:
                out.append(batch)
                least = min(BATCH_VALUES, BATCH_GROWTH * values) if fresh else BATCH_VALUES
                batch, jobs, points, values = [], 0, 0, 0
        if batch:
            out.append(batch)
    return out


def local_results(parts: Sequence[Part], threads: int | None) -> Iterator[tuple[Part, ChunkResult]]:
    """Each chunk of ``parts`` with its result as it finishes, by ``threads`` threads (None: one per core).

    The batches (:func:`local_batches`) run one after the other, a thread
    going on to the next batch as soon as it has no job left in its batch;
    the next batch's table of points (:class:`~grazing.sweeps.run.LaneBatch`)
    is built by a thread of its own while the cores compute the one before
    (:func:`~grazing.sweeps.run.stream_batches`), so that they do not wait for
    it (a serial part of the sweep, issue 29).
    """
    threads = max(1, threads or os.cpu_count() or 1)
    batches = local_batches(parts, threads)
    makers = [functools.partial(LaneBatch, group) for group in batches]
    for k, i, result in stream_batches(makers, threads):
        yield batches[k][i], result


def _same(value: Any) -> Any:
    """``value`` (a Dask task that keeps an argument on the cluster for the tasks that need it)."""
    return value


def run_indexed(specs: Sequence[SweepSpec], indices: Sequence[int]) -> list[ChunkResult]:
    """:func:`~grazing.sweeps.run.run_parts` of the chunks ``indices[k]`` of ``specs[k]`` (a Dask task)."""
    return run_parts(list(zip(specs, indices)))


def _dask_workers(client: Any) -> int:
    try:
        return len(client.scheduler_info(n_workers=-1).get("workers", {}))
    except TypeError:  # older distributed: no n_workers argument
        return len(client.scheduler_info().get("workers", {}))


def part_groups(parts: Sequence[Part], workers: int) -> list[list[Part]]:
    """``parts`` (specs sharing a batch key) in groups of consecutive parts, as :func:`chunk_groups` makes."""
    if not parts:
        return []
    return [[parts[k] for k in group] for group in chunk_groups(parts[0][0], range(len(parts)), workers)]


def _dask_results(
    spec: SweepSpec,
    todo: Sequence[int],
    client: Any,
    timeout: float | None,
    notice: Callable[[str], None] | None,
) -> Iterator[ChunkResult]:
    """Chunk results from a Dask cluster (see :func:`dask_parts`)."""
    for _, res in dask_parts([(spec, i) for i in todo], client, timeout, notice):
        yield res


def dask_parts(
    parts: Sequence[Part],
    client: Any,
    timeout: float | None,
    notice: Callable[[str], None] | None,
) -> Iterator[tuple[Part, ChunkResult]]:
    """Each of ``parts`` with its result from a Dask cluster, with a bounded number of groups submitted ahead.

    Without any worker for :data:`DASK_NOTICE_AFTER` seconds, ``notice`` is
    told once; without any for ``timeout`` seconds, :class:`SweepTimeoutError`.
    """
    from distributed import wait

    address = getattr(getattr(client, "scheduler", None), "address", "the scheduler")
    groups: list[list[Part]] = []
    by_key: dict[tuple[Any, ...], list[Part]] = {}
    for part in parts:
        by_key.setdefault(batch_key(part[0]), []).append(part)
    for same in by_key.values():
        groups += part_groups(same, max(1, _dask_workers(client)))
    queue = iter(groups)
    shipped: dict[int, Any] = {}  # id(spec) -> the spec on the cluster

    def on_cluster(spec: SweepSpec) -> Any:
        """The spec sent to the cluster once, as the result of a task of its own (its points are in
        it: sent with every task, they made the client's work grow as the square of the points, 8 ms
        per task at 32000 points).  Not ``scatter``: that waits for a worker, this is queued."""
        if id(spec) not in shipped:
            shipped[id(spec)] = client.submit(_same, spec, pure=False)
        return shipped[id(spec)]

    pending: dict[Any, list[Part]] = {}
    idle_since: float | None = None
    noticed = False
    try:
        while True:
            window = max(64, in_flight(_dask_workers(client)))  # one look at the cluster per round
            for group in queue:
                specs = [on_cluster(spec) for spec, _ in group]
                pending[client.submit(run_indexed, specs, [i for _, i in group], pure=False)] = group
                if len(pending) >= window:
                    break
            if not pending:
                break
            try:
                res = wait(list(pending), timeout=POLL_INTERVAL, return_when="FIRST_COMPLETED")
                finished = set(res.done)
            except TimeoutError:
                finished = set()
            if finished:
                idle_since = None
                for fut in finished:
                    group = pending.pop(fut)
                    yield from zip(group, _dask_result(fut))
                continue
            if _dask_workers(client):
                idle_since = None
                continue
            now = time.monotonic()
            idle_since = idle_since if idle_since is not None else now
            if not noticed and notice is not None and now - idle_since >= DASK_NOTICE_AFTER:
                noticed = True
                give_up = f"giving up after {timeout:g} s" if timeout is not None else "timeout= to give up"
                notice(f"no Dask worker is connected to {address}: waiting for one ({give_up})")
            if timeout is not None and now - idle_since >= timeout:
                raise SweepTimeoutError(
                    f"no Dask worker connected to {address} within {timeout:g} s; start workers "
                    "(dask worker ADDRESS) or run without a scheduler (client=)"
                )
    except BaseException:
        if pending:
            client.cancel(list(pending))
        raise


def _dask_result(fut: Any) -> list[ChunkResult]:
    """A finished group's chunk results; a failure of the cluster (a worker killed...) as one line."""
    try:
        return fut.result()
    except GrazingError:
        raise
    except Exception as exc:
        text = " ".join(str(exc).split())[:200]
        raise GrazingError(f"a chunk failed on the Dask cluster: {type(exc).__name__}: {text}") from None


def chain_window(threads: int | None, memory: bool) -> int:
    """Most chunks of carried sweeps held at a time while they are settled (:mod:`grazing.sweeps.chain`).

    All of them when the results are kept in memory anyway; else enough to
    fill every thread's lanes twice over (two chains per lane).
    """
    from grazing.engine.llvmgen import lane_width

    if memory:
        return 1 << 62
    return 2 * max(1, lane_width()) * max(1, threads or os.cpu_count() or 1)


def compute_parts(
    workers: int | None,
    client: Any,
    timeout: float | None = None,
    notice: Callable[[str], None] | None = None,
) -> Callable[[list[Part]], Iterator[tuple[Part, ChunkResult]]]:
    """How chunks are computed: on the local cores (``workers`` threads) or on a Dask ``client``'s cluster."""
    if client is not None:
        return lambda parts: dask_parts(parts, client, timeout, notice)
    return lambda parts: local_results(parts, workers)


def chunk_results(
    spec: SweepSpec,
    todo: Sequence[int],
    workers: int | None,
    client: Any,
    timeout: float | None = None,
    notice: Callable[[str], None] | None = None,
) -> Iterator[ChunkResult]:
    """Yield chunk results as they finish (Dask client, process pool, or in-process)."""
    if client is not None:
        yield from _dask_results(spec, todo, client, timeout, notice)
        return
    for _, result in local_results([(spec, i) for i in todo], workers):
        yield result
