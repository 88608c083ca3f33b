"""Where the chunks of a sweep run: in this process, on local worker processes, or on a Dask cluster.

Local processes come from :func:`grazing.parallel.map_unordered` (the one
process pool of the package: workers die with their parent, at most a few
chunks are queued ahead, Ctrl-C cancels what is queued and stops the workers
at once).  A Dask cluster gets the same bounded window of chunks; without any
worker for a while the caller is told, and given up on after a timeout.

Chunks travel in groups (:func:`chunk_groups`) that a worker computes
together on the SIMD lanes of :func:`grazing.sweeps.run.run_chunks`: a
continuation sweep needs one chunk per lane to fill them.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from grazing.errors import GrazingError
from grazing.parallel import in_flight, map_unordered
from grazing.sweeps.run import run_chunks
from grazing.sweeps.spec import ChunkResult, SweepSpec


class SweepTimeoutError(GrazingError):
    """A Dask cluster had no worker for longer than the timeout."""


DASK_NOTICE_AFTER = 5.0
"""Seconds without any Dask worker before :func:`run_sweep` says it is waiting for one."""

POLL_INTERVAL = 0.5
"""Seconds between two looks at a Dask cluster while no chunk finishes."""

_WORKER_SPEC: SweepSpec | None = None
"""The sweep of this pool worker (set once by its initializer, not sent with every chunk)."""


def _init_pool_worker(parent_pid: int, spec: SweepSpec) -> None:
    global _WORKER_SPEC
    from grazing.parallel import init_worker

    init_worker(parent_pid)
    _WORKER_SPEC = spec


def _run_group_in_worker(group: list[int]) -> list[ChunkResult]:
    assert _WORKER_SPEC is not None
    return run_chunks(_WORKER_SPEC, group)


def chunk_groups(spec: SweepSpec, todo: Sequence[int], workers: int) -> list[list[int]]:
    """``todo`` split into groups of consecutive chunks, each computed together on SIMD lanes.

    A continuation sweep fills the lanes with one chunk each (up to two
    chunks per lane: a lane whose chunk is done takes the next), a fresh one
    with points (about four per lane); no group is bigger than an even share
    of the chunks among the workers.

    Examples
    --------
    >>> import grazing
    >>> from grazing.sweeps.spec import sweep_spec
    >>> spec = sweep_spec(grazing.models.pendulum("B"), "eta", [0.4 + 0.001 * i for i in range(100)])
    >>> [len(g) for g in chunk_groups(spec, range(spec.n_chunks), workers=2)]
    [1, 1]
    """
    from grazing.engine.llvmgen import lane_width

    lanes = lane_width()
    per = math.ceil(4 * lanes / spec.size) if spec.fresh else 2 * lanes
    per = max(1, min(per, math.ceil(len(todo) / max(1, workers))))
    todo = list(todo)
    return [todo[i : i + per] for i in range(0, len(todo), per)]


def _local_results(
    spec: SweepSpec, todo: Sequence[int], workers: int, run: Callable[[int], Any] | None = None
) -> Iterator[Any]:
    """Chunk results from local worker processes (:func:`grazing.parallel.map_unordered`).

    Each worker receives the spec once, when it starts; ``run`` replaces
    the computation of one chunk (tests).
    """
    if run is not None:
        yield from map_unordered(run, list(todo), workers)
        return
    for results in map_unordered(
        _run_group_in_worker, chunk_groups(spec, todo, workers), workers, initializer=_init_pool_worker,
        initargs=(spec,),
    ):  # fmt: skip
        yield from results


def _dask_workers(client: Any) -> int:
    try:
        return len(client.scheduler_info(n_workers=-1).get("workers", {}))
    except TypeError:  # older distributed: no n_workers argument
        return len(client.scheduler_info().get("workers", {}))


def _dask_results(
    spec: SweepSpec,
    todo: Sequence[int],
    client: Any,
    timeout: float | None,
    notice: Callable[[str], None] | None,
) -> Iterator[ChunkResult]:
    """Chunk results from a Dask cluster, with a bounded number of chunks submitted ahead.

    Without any worker for :data:`DASK_NOTICE_AFTER` seconds, ``notice`` is
    told once; without any for ``timeout`` seconds, :class:`SweepTimeoutError`.
    """
    from distributed import wait

    address = getattr(getattr(client, "scheduler", None), "address", "the scheduler")
    queue = iter(chunk_groups(spec, todo, max(1, _dask_workers(client))))
    pending: set[Any] = set()
    idle_since: float | None = None
    noticed = False
    try:
        while True:
            window = max(64, in_flight(_dask_workers(client)))  # one look at the cluster per round
            for group in queue:
                pending.add(client.submit(run_chunks, spec, group, pure=False))
                if len(pending) >= window:
                    break
            if not pending:
                break
            try:
                res = wait(pending, timeout=POLL_INTERVAL, return_when="FIRST_COMPLETED")
                finished, pending = set(res.done), set(res.not_done)
            except TimeoutError:
                finished = set()
            if finished:
                idle_since = None
                for fut in finished:
                    yield from _dask_result(fut)
                continue
            if _dask_workers(client):
                idle_since = None
                continue
            now = time.monotonic()
            idle_since = idle_since if idle_since is not None else now
            if not noticed and notice is not None and now - idle_since >= DASK_NOTICE_AFTER:
                noticed = True
                give_up = f"giving up after {timeout:g} s" if timeout is not None else "--timeout to give up"
                notice(f"no Dask worker is connected to {address}: waiting for one ({give_up})")
            if timeout is not None and now - idle_since >= timeout:
                raise SweepTimeoutError(
                    f"no Dask worker connected to {address} within {timeout:g} s; start workers "
                    "(dask worker ADDRESS) or run without --scheduler"
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
    workers = workers or os.cpu_count() or 1
    if workers <= 1 or len(todo) <= 1:
        for group in chunk_groups(spec, todo, 1):
            yield from run_chunks(spec, group)
        return
    yield from _local_results(spec, todo, workers)
