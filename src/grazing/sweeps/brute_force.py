"""Brute-force bifurcation diagrams: sweeps in one or two parameters.

A sweep visits a list of parameter points.  At each point the model is run
for a transient, then ``periods`` forcing periods are sampled at the
stroboscopic phase; the samples, their period, the impacts and the largest
Lyapunov exponent are recorded.

Points are grouped in *chunks* of consecutive points (``chunk_size``).  Within
a chunk, each point starts from the final state of the previous one, as an
experimenter sweeps (unless ``fresh``); every chunk starts from ``x0``.  Chunks
are independent units of work: they run in parallel on the local cores or on
a Dask cluster, and each finished chunk is written to the result store, so
the chunking - not the machine - defines the result.  ``chunk_size = 0`` makes
the whole sweep one chunk (a strictly sequential experimenter sweep).

Adaptive transients: the transient is run in blocks of 32 periods and stopped
as soon as the samples repeat with a period p <= 16 to 1e-9, at the point of
the cycle where the full transient would have ended (the periods run are
congruent to the full transient modulo p).  The samples, and in a continuation
sweep the next point's starting state, are then those of the full transient to
about 1e-9.  (In a continuation sweep through chaos with coexisting attractors,
such a 1e-9 difference can, like any rounding difference, lead the next points
to another attractor; fresh sweeps are unaffected.)
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.period import DEFAULT_MAX_PERIOD, DEFAULT_PERIOD_TOL, detect_period
from grazing.engine.runner import DiscontinuityMap, Runner
from grazing.errors import GrazingError, InvalidParameterError, SimulationError

DEFAULT_SWEEP_TOL = 1e-10
"""Local error tolerance of sweeps: far below the 1e-6 of period detection."""

ADAPTIVE_BLOCK = 32
ADAPTIVE_MAX_PERIOD = 16
ADAPTIVE_TOL = 1e-9
LYAPUNOV_ALIGN = 16
"""Periods of the transient during which the tangent vectors are aligned (not counted)."""


class SweepTimeoutError(GrazingError):
    """A Dask cluster had no worker for longer than the timeout."""


@dataclass(frozen=True)
class SweepSpec:
    """Everything that defines a sweep's result.

    Attributes
    ----------
    model
        The model with its fixed parameter values.
    params
        Names of the swept parameters (one or two).
    points
        Parameter values, one tuple per point, in visiting order.
    x0
        Initial state of every chunk (and of every point with ``fresh``).
    transient, periods
        Forcing periods discarded and sampled at each point.
    phase
        Stroboscopic phase in radians.
    fresh
        Start every point from ``x0`` instead of the previous final state.
    chunk_size
        Points per chunk (0: one chunk).
    adaptive
        Stop transients early once the samples are periodic.
    lyapunov
        Compute the largest Lyapunov exponent (per unit time).
    tol
        Local error tolerance of the integrator.
    shape
        Grid shape for two-parameter maps (``(n2, n1)``), else ``(n,)``.
    zdm
        Iterate the discontinuity-map Poincare map instead of the flow: the
        stop is ignored and Nordmark's map applied once per period at the
        grazing phase (``--method map``).
    """

    model: HybridModel
    params: tuple[str, ...]
    points: tuple[tuple[float, ...], ...]
    x0: tuple[float, ...]
    transient: int = 500
    periods: int = 100
    phase: float = 0.0
    fresh: bool = False
    chunk_size: int = 50
    adaptive: bool = True
    lyapunov: bool = True
    tol: float = DEFAULT_SWEEP_TOL
    shape: tuple[int, ...] = field(default=())
    zdm: DiscontinuityMap | None = None

    def __post_init__(self) -> None:
        if not self.points:
            raise InvalidParameterError("a sweep needs at least one point")
        for p in self.params:
            if p not in self.model.params:
                raise InvalidParameterError(
                    f"unknown parameter {p!r} (known: {', '.join(self.model.params)})"
                )
        if self.transient < 0 or self.periods < 1:
            raise InvalidParameterError("need transient >= 0 and periods >= 1")
        if self.chunk_size < 0:
            raise InvalidParameterError(f"chunk size must be >= 0, got {self.chunk_size}")
        if not self.shape:
            object.__setattr__(self, "shape", (len(self.points),))
        # Validate every point's parameters now: one clear error before any work.
        for pt in (self.points[0], self.points[-1]):
            self.model_at(pt)

    @property
    def n_points(self) -> int:
        return len(self.points)

    @property
    def size(self) -> int:
        """Points per chunk."""
        return self.chunk_size or self.n_points

    @property
    def n_chunks(self) -> int:
        return math.ceil(self.n_points / self.size)

    def chunk(self, i: int) -> slice:
        return slice(i * self.size, min((i + 1) * self.size, self.n_points))

    def model_at(self, point: Sequence[float]) -> HybridModel:
        return self.model.with_params(**dict(zip(self.params, point)))

    def description(self) -> dict[str, Any]:
        """JSON-serialisable description of everything that determines the result."""
        import grazing

        d = {
            "model": self.model.name,
            "fixed_params": {k: v for k, v in self.model.params.items() if k not in self.params},
            "params": list(self.params),
            "points_sha256": hashlib.sha256(np.asarray(self.points, dtype=float).tobytes()).hexdigest(),
            "n_points": self.n_points,
            "first_point": list(self.points[0]),
            "last_point": list(self.points[-1]),
            "x0": list(self.x0),
            "transient": self.transient,
            "periods": self.periods,
            "phase": self.phase,
            "fresh": self.fresh,
            "chunk_size": self.size,
            "adaptive": self.adaptive,
            "lyapunov": self.lyapunov,
            "tol": self.tol,
            "shape": list(self.shape),
            "method": "map" if self.zdm is not None else "flow",
            "zdm": None if self.zdm is None else [self.zdm.phase, self.zdm.accel, list(self.zdm.direction)],
            "grazing_version": grazing.__version__,
        }
        return d

    def fingerprint(self) -> str:
        return hashlib.sha256(json.dumps(self.description(), sort_keys=True).encode()).hexdigest()[:16]


@dataclass
class ChunkResult:
    """The results of one chunk of points."""

    index: int
    samples: np.ndarray  # (points, periods, n_states)
    period: np.ndarray  # (points,) int
    impacts: np.ndarray  # (points,) impacts in the sampled span
    lyapunov: np.ndarray  # (points,) largest exponent per unit time (nan if sticking)
    transient_used: np.ndarray  # (points,) transient periods actually run
    x_final: np.ndarray  # (points, n_states)
    seconds: float = 0.0


def _run_point(spec: SweepSpec, model: HybridModel, x: np.ndarray, t0: float) -> tuple[Any, ...]:
    """Transient then sampled periods at one point; returns the point's results."""
    run = Runner(model, x, t0=t0, phase=spec.phase, tol=spec.tol, zdm=spec.zdm)
    align = min(LYAPUNOV_ALIGN, spec.transient) if spec.lyapunov else 0
    budget = spec.transient - align
    used = 0
    # The transient always runs in the same blocks (so the trajectory does not
    # depend on ``adaptive``); adaptive only decides whether to stop early.
    while used < budget:
        block = min(ADAPTIVE_BLOCK, budget - used)
        seg = run.advance(block, block if spec.adaptive else 0)
        used += block
        if spec.adaptive and block == ADAPTIVE_BLOCK:
            p = detect_period(seg.samples, tol=ADAPTIVE_TOL, max_period=ADAPTIVE_MAX_PERIOD)
            if p > 0:
                # Stop at the point of the cycle where the full transient would end,
                # so that the samples (and the next point's start) are the same.
                extra = (budget - used) % p
                if extra:
                    run.advance(extra, 0)
                    used += extra
                break
    if spec.lyapunov:
        var = Runner(model, run.x, t0=run.t, phase=spec.phase, tol=spec.tol, variational=True, zdm=spec.zdm)
        var.mode = run.mode
        seg = var.advance(align + spec.periods, spec.periods, lyapunov=True, impacts="sampled")
        lyap = (
            float(np.max(seg.log_sums / seg.lyap_span)) if seg.jacobian_valid and seg.lyap_span else math.nan
        )
        final = var
    else:
        seg = run.advance(spec.periods, spec.periods, impacts="sampled")
        lyap = math.nan
        final = run
    return seg.samples, len(seg.impacts), lyap, used + align, final.x, final.t


def run_chunk(spec: SweepSpec, index: int) -> ChunkResult:
    """Compute chunk ``index`` of ``spec`` (a pure function of its arguments)."""
    start = time.perf_counter()
    sl = spec.chunk(index)
    pts = spec.points[sl]
    n, m = spec.model.n_states, spec.periods
    res = ChunkResult(
        index=index,
        samples=np.full((len(pts), m, n), np.nan),
        period=np.zeros(len(pts), dtype=np.int32),
        impacts=np.zeros(len(pts), dtype=np.int32),
        lyapunov=np.full(len(pts), np.nan),
        transient_used=np.zeros(len(pts), dtype=np.int32),
        x_final=np.full((len(pts), n), np.nan),
    )
    x0 = np.asarray(spec.x0, dtype=float)
    x = x0.copy()
    t0 = 0.0
    carried = False
    for j, pt in enumerate(pts):
        model = spec.model_at(pt)
        if carried and model.periodic:
            # The state carried over is the last sample, at forcing phase ``spec.phase``:
            # start the next point at that phase of its own period (which may differ).
            t0 = (spec.phase / (2 * math.pi)) % 1.0 * model.period
        start_x, start_t = (x0, 0.0) if spec.fresh or not carried else (x, t0)
        try:
            samples, nimp, lyap, used, x, t0 = _run_point(spec, model, start_x, start_t)
        except SimulationError:
            # Recorded as missing (NaN samples, period -1); the next point restarts from x0.
            res.period[j] = -1
            carried = False
            continue
        res.samples[j] = samples
        res.period[j] = detect_period(samples, DEFAULT_PERIOD_TOL, DEFAULT_MAX_PERIOD)
        res.impacts[j] = nimp
        res.lyapunov[j] = lyap
        res.transient_used[j] = used
        res.x_final[j] = x
        carried = True
    res.seconds = time.perf_counter() - start
    return res


# ----------------------------------------------------------------------------
# Execution

DASK_NOTICE_AFTER = 5.0
"""Seconds without any Dask worker before :func:`run_sweep` says it is waiting for one."""

POLL_INTERVAL = 0.5
"""Seconds between two looks at a Dask cluster while no chunk finishes."""

_WORKER_SPEC: SweepSpec | None = None
"""The sweep of this pool worker (set once by its initializer, not sent with every chunk)."""


def _init_pool_worker(parent_pid: int, spec: SweepSpec) -> None:
    global _WORKER_SPEC
    from grazing.workers import init_worker

    init_worker(parent_pid)
    _WORKER_SPEC = spec


def _run_chunk_in_worker(index: int) -> ChunkResult:
    assert _WORKER_SPEC is not None
    return run_chunk(_WORKER_SPEC, index)


def in_flight(workers: int) -> int:
    """Chunks submitted ahead of the results: enough to keep ``workers`` busy, few enough to hold."""
    return 2 * max(1, workers) + 2


def _local_results(
    spec: SweepSpec, todo: Sequence[int], workers: int, run: Callable[[int], Any] | None = None
) -> Iterator[Any]:
    """Chunk results from a pool of local processes, at most :func:`in_flight` submitted at a time.

    The workers die with this process (:mod:`grazing.workers`).  When the
    consumer stops (Ctrl-C, an error), queued chunks are cancelled and the
    workers killed at once: the chunks in flight are thrown away, not waited for.
    """
    import multiprocessing as mp
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    from grazing.workers import init_worker, stop_pool_processes

    ctx = mp.get_context("fork") if "fork" in mp.get_all_start_methods() else mp.get_context("spawn")
    n = min(workers, len(todo))
    if run is None:
        fn: Callable[[int], Any] = _run_chunk_in_worker
        init, initargs = _init_pool_worker, (os.getpid(), spec)
    else:  # a stand-in for run_chunk (tests)
        fn, init, initargs = run, init_worker, (os.getpid(),)
    ex = ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=init, initargs=initargs)
    queue = iter(todo)
    pending: set[Any] = set()
    try:
        while True:
            for i in queue:
                pending.add(ex.submit(fn, i))
                if len(pending) >= in_flight(n):
                    break
            if not pending:
                break
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in finished:
                yield fut.result()
    except BaseException as exc:
        stop_pool_processes(ex)  # first: shutdown() forgets the processes
        ex.shutdown(wait=False, cancel_futures=True)
        if isinstance(exc, BrokenProcessPool):
            raise SimulationError(
                "a worker process died (killed by the system: out of memory?); the finished chunks "
                "are kept in a --out store: run the same command again to resume"
            ) from None
        raise
    ex.shutdown(wait=True)


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
    queue = iter(todo)
    pending: set[Any] = set()
    idle_since: float | None = None
    noticed = False
    try:
        while True:
            window = max(64, in_flight(_dask_workers(client)))  # one look at the cluster per round
            for i in queue:
                pending.add(client.submit(run_chunk, spec, i, pure=False))
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
                    yield _dask_result(fut)
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


def _dask_result(fut: Any) -> ChunkResult:
    """A finished chunk's result; a failure of the cluster (a worker killed too often...) as one line."""
    try:
        return fut.result()
    except GrazingError:
        raise
    except Exception as exc:
        text = " ".join(str(exc).split())[:200]
        raise GrazingError(f"a chunk failed on the Dask cluster: {type(exc).__name__}: {text}") from None


def _executor_results(
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
        for i in todo:
            yield run_chunk(spec, i)
        return
    yield from _local_results(spec, todo, workers)


def run_sweep(
    spec: SweepSpec,
    *,
    store: Any = None,
    workers: int | None = None,
    client: Any = None,
    progress: Callable[[int, int], None] | None = None,
    timeout: float | None = None,
    notice: Callable[[str], None] | None = None,
    load: bool = True,
) -> Any:
    """Run a sweep; return its :class:`xarray.Dataset`.

    Parameters
    ----------
    spec
        The sweep.
    store
        A :class:`~grazing.sweeps.store.SweepStore` (results written chunk by
        chunk; chunks already in it are not recomputed), or None.
    workers
        Local processes (default: all cores).
    client
        A :class:`dask.distributed.Client`: run the chunks on its cluster.
    progress
        Called as ``progress(points_done, points_total)``.
    timeout
        With ``client``: give up (:class:`SweepTimeoutError`) after this many
        seconds without any worker in the cluster (default: wait).
    notice
        Called with a one-line message when the cluster has had no worker
        for :data:`DASK_NOTICE_AFTER` seconds.
    load
        Return the dataset; with False, return None and keep nothing of the
        results in memory (they are in ``store``: a huge sweep streams to it).

    Interrupted (Ctrl-C) or failing, the chunks not yet started are cancelled
    and the local workers stopped at once; the finished chunks are in ``store``.
    """
    from grazing.sweeps.store import MemoryStore

    if store is None and not load:
        raise InvalidParameterError("load=False needs a store to keep the results")
    sink = store if store is not None else MemoryStore(spec)
    todo = [i for i in range(spec.n_chunks) if not sink.is_done(i)]
    done_points = spec.n_points - sum(spec.chunk(i).stop - spec.chunk(i).start for i in todo)
    if progress is not None:
        progress(done_points, spec.n_points)
    results = _executor_results(spec, todo, workers, client, timeout, notice)
    try:
        for res in results:
            sink.write(res)
            done_points += res.period.size
            if progress is not None:
                progress(done_points, spec.n_points)
    finally:
        results.close()  # cancels what is queued and stops the workers if we leave early
    return sink.dataset() if load else None


def sweep(
    model: HybridModel,
    param: str,
    values: Sequence[float],
    *,
    x0: Sequence[float] | None = None,
    transient: int = 500,
    periods: int = 100,
    phase: float = 0.0,
    direction: str = "up",
    fresh: bool = False,
    chunk_size: int = 50,
    adaptive: bool = True,
    lyapunov: bool = True,
    tol: float = DEFAULT_SWEEP_TOL,
    zdm: DiscontinuityMap | None = None,
    store: Any = None,
    workers: int | None = None,
    client: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> Any:
    """One-parameter brute-force bifurcation diagram.

    Returns an :class:`xarray.Dataset` with, per point (in increasing parameter
    order whatever the direction): ``samples`` (periods x states), ``period``
    (0: none <= 64), ``impacts_per_period``, ``lyapunov`` (largest exponent
    per unit time), ``transient_used``.

    Examples
    --------
    >>> import math, numpy as np, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> ds = sweep(m, "eta", np.linspace(0.40, 0.42, 3), periods=20, workers=1)
    >>> ds.period.values.tolist()
    [1, 1, 1]
    """
    vals = np.asarray(values, dtype=float)
    if vals.ndim != 1 or vals.size == 0 or not np.all(np.isfinite(vals)):
        raise InvalidParameterError("values must be a non-empty list of finite numbers")
    if direction not in ("up", "down"):
        raise InvalidParameterError(f"direction must be 'up' or 'down', got {direction!r}")
    order = np.sort(vals) if direction == "up" else np.sort(vals)[::-1]
    x = np.zeros(model.n_states) if x0 is None else np.asarray(x0, dtype=float)
    spec = SweepSpec(
        model=model,
        params=(param,),
        points=tuple((float(v),) for v in order),
        x0=tuple(float(v) for v in model.check_state(x)),
        transient=transient,
        periods=periods,
        phase=phase,
        fresh=fresh,
        chunk_size=chunk_size,
        adaptive=adaptive,
        lyapunov=lyapunov,
        tol=tol,
        zdm=zdm,
    )
    ds = run_sweep(spec, store=store, workers=workers, client=client, progress=progress)
    return ds.sortby("value")


def parameter_map(
    model: HybridModel,
    param1: str,
    values1: Sequence[float],
    param2: str,
    values2: Sequence[float],
    *,
    x0: Sequence[float] | None = None,
    transient: int = 500,
    periods: int = 100,
    phase: float = 0.0,
    fresh: bool = False,
    chunk_size: int = 0,
    adaptive: bool = True,
    lyapunov: bool = True,
    tol: float = DEFAULT_SWEEP_TOL,
    store: Any = None,
    workers: int | None = None,
    client: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> Any:
    """Two-parameter period / impact / Lyapunov map.

    Each row (fixed ``param2``) is swept in increasing ``param1``; with the
    default ``chunk_size = 0`` one row is one chunk.  Returns a dataset with
    dimensions ``(param2, param1)``.
    """
    v1 = np.sort(np.asarray(values1, dtype=float))
    v2 = np.sort(np.asarray(values2, dtype=float))
    if v1.size == 0 or v2.size == 0:
        raise InvalidParameterError("both parameter lists must be non-empty")
    x = np.zeros(model.n_states) if x0 is None else np.asarray(x0, dtype=float)
    points = tuple((float(a), float(b)) for b in v2 for a in v1)
    spec = SweepSpec(
        model=model,
        params=(param1, param2),
        points=points,
        x0=tuple(float(v) for v in model.check_state(x)),
        transient=transient,
        periods=periods,
        phase=phase,
        fresh=fresh,
        chunk_size=chunk_size or v1.size,
        adaptive=adaptive,
        lyapunov=lyapunov,
        tol=tol,
        shape=(v2.size, v1.size),
    )
    return run_sweep(spec, store=store, workers=workers, client=client, progress=progress)


def spec_summary(spec: SweepSpec) -> dict[str, Any]:
    """The spec description plus a fingerprint, for dataset attributes."""
    d = spec.description()
    d["fingerprint"] = spec.fingerprint()
    return d


__all__ = [
    "ChunkResult",
    "SweepSpec",
    "SweepTimeoutError",
    "parameter_map",
    "run_chunk",
    "run_sweep",
    "spec_summary",
    "sweep",
]
