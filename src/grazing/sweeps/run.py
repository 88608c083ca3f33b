"""Computing chunks of a sweep: pure functions of the spec (what a worker runs).

At each point the model is run for a transient, then ``periods`` forcing
periods are sampled at the stroboscopic phase; the samples, their period, the
impacts and the largest Lyapunov exponent are recorded.  Within a chunk, each
point starts from the final state of the previous one, as an experimenter
sweeps (unless ``fresh``), at the sampling phase of its own forcing period;
every chunk starts from ``x0``.

Adaptive transients: the transient is run in blocks of
:data:`~grazing.core.options.ADAPTIVE_BLOCK` periods and stopped as soon
as the samples repeat with a period p <=
:data:`~grazing.core.options.ADAPTIVE_MAX_PERIOD` to
:data:`~grazing.core.options.ADAPTIVE_TOL`, at the point of
the cycle where the full transient would have ended (the periods run are
congruent to the full transient modulo p).  The samples, and in a continuation
sweep the next point's starting state, are then those of the full transient to
about that tolerance.  (In a continuation sweep through chaos with coexisting
attractors, such a difference can, like any rounding difference, lead the next points
to another attractor; fresh sweeps are unaffected.)  With Lyapunov exponents,
the last :data:`~grazing.core.options.LYAPUNOV_ALIGN` periods of the
transient align the tangent vectors, and the exponent is taken over the
sampled periods.

The points are computed by the compiled driver on SIMD lanes
(:mod:`grazing.engine.driver.lanes`): several points at once, each lane its
own point with its own steps and events; in a continuation sweep a lane
follows one chunk, in a fresh sweep it takes any point.  Several threads can
share one call's jobs (:func:`stream_chunks`): each takes the next job when
one of its lanes is free, so the cores stay busy until the last chains, and
the chunks are handed out as soon as they are finished; through several
batches (:func:`stream_batches`) a thread with no job left in one goes on to
the next.  The results do not
depend on the lanes or the threads (each lane does the scalar path's
arithmetic; a chain of points stays on one lane).
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import numpy as np

from grazing.core.period import DEFAULT_MAX_PERIOD, DEFAULT_PERIOD_TOL, detect_periods
from grazing.core.solution import Status
from grazing.engine.codegen import taylor_order
from grazing.engine.native import load_sweep_lanes
from grazing.engine.records import LaneJobs, LanePoints, LaneResults, LaneSettings
from grazing.engine.runner import step_safety
from grazing.sweeps.polish import polish, run_mode
from grazing.sweeps.spec import ChunkResult, SweepSpec
from grazing.sweeps.status import NOT_COMPUTED, STATUS_DTYPE

POLL_INTERVAL = 0.05
"""Seconds between two looks of :func:`stream_chunks` at the finished points."""


def batch_key(spec: SweepSpec) -> tuple[Any, ...]:
    """What the chunks of one driver call share (everything that is not per point or per job)."""
    z = spec.zdm
    zdm = None
    if z is not None:
        zdm = (float(z.accel), tuple(np.asarray(z.direction, dtype=float)), float(z.window), int(z.stop))
    return (
        id(spec.model._def), spec.model.periodic, taylor_order(spec.tol), spec.tol, spec.transient,
        spec.periods, spec.adaptive, spec.adaptive_tol, spec.lyapunov, zdm, spec.chatter_tol,
    )  # fmt: skip


class LaneBatch:
    """Chunks of sweeps computed by one call of the compiled driver, on one thread or several.

    ``parts`` are ``(spec, chunk index)`` pairs; their specs may differ in
    their points, start state, phase and in being fresh or not, but not in
    the model, tolerance, transient, periods, adaptive transients, Lyapunov
    exponents or discontinuity map (``ValueError``).

    Examples
    --------
    >>> import grazing
    >>> from grazing.sweeps.spec import sweep_spec
    >>> spec = sweep_spec(grazing.models.pendulum("B"), "eta", [0.44, 0.45, 0.46])
    >>> batch = LaneBatch([(spec, 0)])
    >>> batch.run()
    >>> batch.result(0).period.tolist() == batch.result(0).period.tolist()
    True
    """

    def __init__(self, parts: Sequence[tuple[SweepSpec, int]]) -> None:
        if not parts:
            raise ValueError("a batch needs at least one chunk")
        key = batch_key(parts[0][0])
        if any(batch_key(spec) != key for spec, _ in parts[1:]):
            raise ValueError("the chunks of a batch must share the model and the sweep settings")
        self.parts = list(parts)
        spec0 = parts[0][0]
        model = spec0.model
        n, m, nstops = model.n_states, spec0.periods, model.n_stops
        slices = [spec.chunk(i) for spec, i in parts]
        sizes = np.array([sl.stop - sl.start for sl in slices], dtype=np.int64)
        ends = np.cumsum(sizes)
        bounds = [(int(e - k), int(e)) for k, e in zip(sizes, ends)]
        npts = int(ends[-1])
        pvs, Ts = _point_table(parts, slices, npts)
        two_pi = 2 * math.pi
        sphase, tcarry, zdms = np.empty(npts), np.empty(npts), np.zeros(npts)
        jobs, x0s, firsts, first_vfs, x0_vfs = [], [], [], [], []
        for (spec, i), sl, (a, b) in zip(parts, slices, bounds):
            size, T = b - a, Ts[a:b]
            vf0 = model.mode_index(None) if spec.x0_mode is None else spec.x0_mode  # (x0's mode)
            sphase[a:b] = (spec.phase % two_pi) / two_pi * T
            carry = (spec.phase / two_pi) % 1.0 * T
            tcarry[a:b] = carry
            if spec.zdm is not None:
                zdms[a:b] = [float(spec.zdm.phase) % t for t in T]
            x0 = np.asarray(spec.x0, dtype=float)
            # Jobs: runs of points, each continuing from the previous (a chunk; every point when fresh).
            if spec.fresh:
                jobs.append(np.column_stack([np.arange(a, b), np.arange(a + 1, b + 1)]))
                x0_vfs.append([vf0] * size)
                first_vfs.append([vf0] * size if spec.start_modes is None else spec.start_modes[sl])
                x0s.append(np.broadcast_to(x0, (size, n)))
                if spec.starts is not None:  # (each from its own state, at its sampling phase)
                    firsts.append(np.column_stack([carry, spec.starts[sl]]))
                else:
                    firsts.append(np.broadcast_to(np.concatenate([[0.0], x0]), (size, n + 1)))
            else:
                jobs.append(np.array([[a, b]]))
                x0_vfs.append([vf0])
                x0s.append(x0[None])
                if i == 0 and spec.resume is not None:  # (continuing a chain: grazing.sweeps.chain)
                    t, x = spec.resume[:2]
                    firsts.append(np.array([[float(t), *x]]))
                    first_vfs.append([spec.resume[2] if len(spec.resume) > 2 else vf0])
                else:
                    firsts.append(np.concatenate([[0.0], x0])[None])
                    first_vfs.append([vf0])
        self._bounds = bounds
        order = taylor_order(spec0.tol)
        self._kern = model.kernels(0, order)
        self._driver = load_sweep_lanes()  # (loaded once, with the first table: not by each thread)
        self._order = order
        self._spec0 = spec0
        self.jobs = np.ascontiguousarray(np.concatenate(jobs), dtype=np.int64).reshape(-1, 2)
        self.x0 = np.ascontiguousarray(np.concatenate(x0s), dtype=float).reshape(-1, n)
        self.firsts = np.ascontiguousarray(np.concatenate(firsts), dtype=float).reshape(-1, n + 1)
        self.first_vf = np.ascontiguousarray(np.concatenate(first_vfs), dtype=np.int64)  # (their modes)
        self.x0_vf = np.ascontiguousarray(np.concatenate(x0_vfs), dtype=np.int64)
        self.pvs = pvs
        self.Ts = Ts
        self.sphase = sphase
        self.tcarry = tcarry
        self.zdms = zdms
        self.fresh = all(spec.fresh for spec, _ in parts)  # (a fresh spec's jobs are single points anyway)
        self.control = np.zeros(3, dtype=np.int64)  # [next job, stop, most jobs at a time per thread]
        self.samples = np.full((npts, m, n), np.nan)
        self.by_stop = np.zeros((npts, nstops), dtype=np.int64)
        self.lyap = np.full(npts, np.nan)
        self.used = np.zeros(npts, dtype=np.int64)
        self.x_final = np.full((npts, n), np.nan)
        self.t_final = np.zeros(npts)
        self.vf_final = np.zeros(npts, dtype=np.int64)
        self.status = np.full(npts, NOT_COMPUTED, dtype=np.int64)  # then each point's Status code
        self._starts = np.array([a for a, _ in bounds], dtype=np.int64)
        self._taken = np.zeros(len(parts), dtype=bool)

    def run(self) -> None:
        """Compute the batch's points (or, with other threads running it too, its share of them)."""
        work = LaneJobs(self.jobs, self.control, self.x0, self.firsts, self.first_vf, self.x0_vf)
        self.run_jobs(work)

    def settings(self, jobs: int) -> LaneSettings:
        """The driver's settings for a call over ``jobs`` jobs of this batch."""
        spec, kern, z = self._spec0, self._kern, self._spec0.zdm
        n = spec.model.n_states
        return LaneSettings(
            lanes=1 if jobs == 1 else max(1, kern.LANES),  # (the lane functions' width, or one lane)
            fresh=self.fresh,
            periodic=bool(spec.model.periodic),
            transient=int(spec.transient),
            periods=int(spec.periods),
            adaptive=bool(spec.adaptive),
            adaptive_tol=float(spec.adaptive_tol),
            lyapunov=bool(spec.lyapunov),
            safety=float(step_safety(spec.tol, self._order)),
            chatter_tol=float(spec.chatter_tol),
            zdm=z is not None,
            zdm_a=float(z.accel) if z is not None else 1.0,
            zdm_e=np.asarray(z.direction if z is not None else np.zeros(n), dtype=float),
            zdm_window=float(z.window) if z is not None else 0.0,
            stop=int(z.stop) if z is not None else 0,
        )

    def run_jobs(self, work: LaneJobs) -> None:
        """Compute the points of the jobs ``work`` (this batch's, or some of its points as jobs of their own)
        into the batch's results."""
        settings = self.settings(len(work.jobs))
        points = LanePoints(self.pvs, self.Ts, self.sphase, self.tcarry, self.zdms)
        out = LaneResults(
            self.samples,
            self.by_stop,
            self.lyap,
            self.used,
            self.x_final,
            self.t_final,
            self.status,
            self.vf_final,
        )
        self._driver(self._kern.table, tuple(settings), tuple(work), tuple(points), tuple(out))

    def stop(self) -> None:
        """Have the threads running the batch return at their next step (unfinished points stay so)."""
        self.control[1] = 1

    def finished(self) -> list[int]:
        """Positions in ``parts`` of the chunks finished since the last call (every point done or failed)."""
        complete = np.logical_and.reduceat(self.status != NOT_COMPUTED, self._starts)
        done = [int(k) for k in np.flatnonzero(complete & ~self._taken)]
        self._taken[done] = True
        return done

    def all_taken(self) -> bool:
        """Whether :meth:`finished` has given every chunk of the batch."""
        return bool(self._taken.all())

    def result(self, k: int) -> ChunkResult:
        """The result of chunk ``parts[k]`` (once finished)."""
        return self.results([k])[0]

    def results(self, ks: Sequence[int]) -> list[ChunkResult]:
        """:meth:`result` of each chunk ``parts[k]`` of ``ks`` (once finished), their periods found at once
        (one call per chunk was most of the Python work on a sweep's chunks)."""
        if not ks:
            return []
        rows = np.concatenate([np.arange(*self._bounds[k]) for k in ks])
        good = self.status[rows] == Status.OK
        periods = np.full(rows.size, -1, dtype=np.int32)
        periods[good] = detect_periods(self.samples[rows[good]], DEFAULT_PERIOD_TOL, DEFAULT_MAX_PERIOD)
        out, at = [], 0
        for k in ks:
            a, b = self._bounds[k]
            self._polish(k, periods[at : at + b - a])
            out.append(self._result(k, periods[at : at + b - a]))
            at += b - a
        return out

    def _polish(self, k: int, period: np.ndarray) -> None:
        """Give the points of chunk ``parts[k]`` with no period whose samples contract towards a stable
        orbit that orbit's period (:func:`grazing.sweeps.polish.polish`), in place."""
        spec, i = self.parts[k]
        if not spec.polish or spec.zdm is not None or not spec.model.periodic:
            return
        a, b = self._bounds[k]
        first = spec.chunk(i).start
        for j in np.flatnonzero((period == 0) & (self.status[a:b] == Status.OK)):
            model = spec.model_at(spec.points[first + j])
            t0 = float(self.sphase[a + j])
            mode = run_mode(model, int(self.vf_final[a + j]), self.samples[a + j, -1], t0)
            found = polish(model, self.samples[a + j], t0, max_period=DEFAULT_MAX_PERIOD, mode=mode)
            if found is not None:
                period[j] = found.period

    def _result(self, k: int, period: np.ndarray) -> ChunkResult:
        """The result of chunk ``parts[k]`` (once finished), its points' periods given."""
        a, b = self._bounds[k]
        part = slice(a, b)
        status = self.status[part]
        good = status == Status.OK
        samples = self.samples[part]
        return ChunkResult(
            index=self.parts[k][1],
            samples=np.where(good[:, None, None], samples, np.nan),
            period=period,
            impacts=np.where(good, self.by_stop[part].sum(axis=1), -1).astype(np.int32),
            lyapunov=np.where(good, self.lyap[part], np.nan),
            transient_used=np.where(good, self.used[part], -1).astype(np.int32),
            x_final=np.where(good[:, None], self.x_final[part], np.nan),
            impacts_by_stop=np.where(good[:, None], self.by_stop[part], -1).astype(np.int32),
            status=status.astype(STATUS_DTYPE),
            t_final=np.where(good, self.t_final[part], np.nan),
            mode_final=np.where(good, self.vf_final[part], -1),
        )


def _point_table(
    parts: Sequence[tuple[SweepSpec, int]], slices: Sequence[slice], npts: int
) -> tuple[np.ndarray, np.ndarray]:
    """The parameter vectors and forcing periods of the points of ``parts`` (chunks ``slices``), in order.

    Each spec's points at once (:meth:`~grazing.core.model.HybridModel.parameter_table`: the
    numbers of a model made per point, without making one).
    """
    by_spec: dict[int, tuple[SweepSpec, list[slice], list[np.ndarray]]] = {}
    at = 0
    for (spec, _), sl in zip(parts, slices):
        size = sl.stop - sl.start
        by_spec.setdefault(id(spec), (spec, [], []))
        by_spec[id(spec)][1].append(sl)
        by_spec[id(spec)][2].append(np.arange(at, at + size))
        at += size
    pvs = np.empty((npts, len(parts[0][0].model.parameters)))
    Ts = np.empty(npts)
    for spec, chunks, rows in by_spec.values():
        points = np.concatenate([np.asarray(spec.points[sl], dtype=float) for sl in chunks])
        table = spec.model.parameter_table(spec.params, points)
        where = np.concatenate(rows)
        pvs[where] = table.vectors
        Ts[where] = table.periods
    return pvs, Ts


def run_chunks(spec: SweepSpec, indices: Sequence[int]) -> list[ChunkResult]:
    """Compute the chunks ``indices`` of ``spec`` together (on SIMD lanes, in this thread); in that order.

    Each chunk's result is a pure function of the spec and its index: the
    same whichever chunks are computed with it.
    """
    return run_parts([(spec, i) for i in indices])


def run_parts(parts: Sequence[tuple[SweepSpec, int]]) -> list[ChunkResult]:
    """Compute ``parts`` (``(spec, index)``, specs sharing a :func:`batch_key`) together; in order."""
    start = time.perf_counter()
    batch = LaneBatch(parts)
    batch.run()
    results = [batch.result(k) for k in range(len(parts))]
    seconds = time.perf_counter() - start
    for res in results:  # (the chunks ran together: each is charged its share)
        res.seconds = seconds / len(results)
    return results


def stream_chunks(
    parts: Sequence[tuple[SweepSpec, int]] | LaneBatch, threads: int
) -> Iterator[tuple[int, ChunkResult]]:
    """``(position in parts, result)`` of each chunk of ``parts`` as soon as it is finished.

    The chunks are computed as one :class:`LaneBatch` (``parts``, or a batch
    already built of them) by ``threads`` threads sharing its jobs (the
    compiled driver runs without the GIL): :func:`stream_batches` of one batch.
    """
    batch = parts if isinstance(parts, LaneBatch) else LaneBatch(parts)
    for _, k, res in stream_batches([lambda: batch], threads):
        yield k, res


def stream_batches(
    batches: Sequence[Callable[[], LaneBatch]], threads: int
) -> Iterator[tuple[int, int, ChunkResult]]:
    """``(batch, position in its parts, result)`` of each chunk of the batches, as soon as it is finished.

    ``batches[k]()`` builds batch ``k`` (a :class:`LaneBatch`): a thread of its
    own builds each batch while the cores compute the one before (a table of
    points, Python work: not a serial part of the sweep, issue 29).
    ``threads`` threads run the batches in order, sharing each batch's jobs
    (the compiled driver runs without the GIL); a thread with no job left in
    a batch goes on to the next one at once, so that no thread waits for the
    others' last points at a batch's end.  When the stream ends, or a
    thread's error (a batch that cannot be built, or fails to run) ends it,
    the threads are told to stop and have returned, at their next step, before
    this returns, the builder's thread too (no batch is begun after a batch
    that could not be built; one being built is waited for).  When the
    consumer stops it (Ctrl-C, ``close()``), a batch being built is not waited
    for: its builder thread (:class:`BatchBuilder`) goes on in the background,
    a daemon, and the first compile of the driver (half a minute) no longer
    holds up a Ctrl-C.
    """
    if not batches:
        return
    from concurrent.futures import Future

    errors: list[BaseException] = []
    finished = threading.Semaphore(0)
    stopping = threading.Event()
    lock = threading.Lock()
    built: dict[int, Future[LaneBatch]] = {}  # (batches built or being built, not yet all reported)
    reported: set[int] = set()  # (batches all reported: let go)
    builder = BatchBuilder()

    def build(k: int) -> LaneBatch:
        batch = batches[k]()
        batch.control[2] = math.ceil(len(batch.jobs) / threads)  # (a few chains: as many on each thread)
        return batch

    def batch_at(k: int) -> Future[LaneBatch] | None:
        """Batch ``k`` (built, or being built, once), or None if it is all reported."""
        with lock:
            if k in reported:
                return None
            if k not in built:
                built[k] = builder.submit(build, k)
            return built[k]

    def work() -> None:
        try:
            for k in range(len(batches)):
                future = batch_at(k)
                if k + 1 < len(batches):
                    batch_at(k + 1)  # (built while this one runs)
                if future is None:  # (the other threads ran it)
                    continue
                batch = _when_built(future, stopping)
                if batch is None or stopping.is_set():
                    break
                batch.run()
        except BaseException as exc:  # (reported by the consumer's thread)
            errors.append(exc)
            stop()
        finally:
            finished.release()

    def stop() -> None:
        stopping.set()
        with lock:
            futures = list(built.values())
        for future in futures:
            batch = _built(future)
            if batch is not None:
                batch.stop()

    def report() -> list[tuple[int, int, ChunkResult]]:
        """The chunks finished since the last look, in the batches built so far, with their results."""
        with lock:
            ready = sorted((k, b) for k, b in ((k, _built(f)) for k, f in built.items()) if b is not None)
        done = []
        for k, batch in ready:
            chunks = batch.finished()
            done += [(k, i, res) for i, res in zip(chunks, batch.results(chunks))]
            if batch.all_taken():
                with lock:
                    reported.add(k)
                    del built[k]
        return done

    workers = [threading.Thread(target=work, name=f"grazing-sweep-{i}", daemon=True) for i in range(threads)]
    for w in workers:
        w.start()
    running, last = len(workers), time.perf_counter()
    ended = False  # (by itself: all reported, or a thread's error; not stopped by the consumer)
    try:
        while running:
            if finished.acquire(timeout=POLL_INTERVAL):
                running -= 1
            if errors:
                ended = True
                raise errors[0]
            done = report()
            now = time.perf_counter()
            for k, i, res in done:
                res.seconds = (now - last) * threads / len(done)
                yield k, i, res
            last = now if done else last
        yield from report()
        ended = True
    finally:
        stop()
        builder.shutdown(wait=ended)  # (a batch not begun is cancelled; one being built waited for if ended)
        for w in workers:
            w.join()


def _built(future: Any) -> LaneBatch | None:
    """The batch of ``future`` if it is built; None while it is being built, if it failed or was cancelled."""
    if not future.done() or future.cancelled() or future.exception() is not None:
        return None
    return future.result()  # type: ignore[no-any-return]


def _when_built(future: Any, stopping: threading.Event) -> LaneBatch | None:
    """The batch of ``future`` once built, or None as soon as ``stopping`` is set (or it was cancelled)."""
    from concurrent.futures import CancelledError

    while True:
        try:
            return future.result(timeout=POLL_INTERVAL)  # type: ignore[no-any-return]
        except TimeoutError:
            if stopping.is_set():
                return None
        except CancelledError:
            return None


class BatchBuilder:
    """Builds batches one after the other in a thread of its own, a daemon.

    As a one-thread :class:`~concurrent.futures.ThreadPoolExecutor`, but the
    process's end does not wait for its thread: a batch being built when the
    sweep is stopped may be the first compile of the driver, which cannot be
    interrupted and takes half a minute (issue 43: Ctrl-C ended such a sweep
    35-40 s late).  What it builds then is thrown away.  A batch that cannot
    be built ends the stream on its error: the batches submitted after it are
    cancelled, not built.
    """

    def __init__(self) -> None:
        import queue

        self._jobs: Any = queue.SimpleQueue()
        self._thread: threading.Thread | None = None
        self._lock = threading.Lock()  # (whether a batch is begun, and whether one is being built)
        self._busy = False  # (a batch is being built)
        self._closed = False  # (shut down, or a batch could not be built: nothing more is begun)

    def submit(self, fn: Callable[..., Any], *args: Any) -> Any:
        """Build ``fn(*args)`` after the batches submitted before; a future of it (cancelled at once once
        a batch could not be built or the builder is shut down)."""
        from concurrent.futures import Future

        future: Future[Any] = Future()
        with self._lock:
            if self._closed:
                future.cancel()
                return future
            self._jobs.put((future, fn, args))
            if self._thread is None:
                self._thread = threading.Thread(target=self._work, name="grazing-batch", daemon=True)
                self._thread.start()
        return future

    def _work(self) -> None:
        while True:
            job = self._jobs.get()
            if job is None:
                return
            future, fn, args = job
            with self._lock:
                if self._closed:
                    future.cancel()
                    continue
                if not future.set_running_or_notify_cancel():
                    continue
                self._busy = True
            try:
                batch = fn(*args)
            except BaseException as exc:  # (the consumer's thread reports it)
                with self._lock:
                    self._busy, self._closed = False, True  # (before anyone hears of it: nothing more begun)
                future.set_exception(exc)
            else:
                with self._lock:
                    self._busy = False
                future.set_result(batch)

    def shutdown(self, wait: bool = False) -> None:
        """Cancel the batches not begun; the thread ends now if idle, else after the batch it builds (waited
        for if ``wait``)."""
        import queue

        with self._lock:
            self._closed = True
            busy = self._busy
        while True:
            try:
                job = self._jobs.get_nowait()
            except queue.Empty:
                break
            if job is not None:
                job[0].cancel()
        self._jobs.put(None)
        if self._thread is not None and (wait or not busy):
            self._thread.join()  # (idle, or begun nothing since `busy` was read: it ends at once)


def run_chunk(spec: SweepSpec, index: int) -> ChunkResult:
    """Compute chunk ``index`` of ``spec`` (a pure function of its arguments).

    Parameters
    ----------
    spec
        The sweep (:func:`~grazing.sweeps.sweep_spec`, :func:`~grazing.sweeps.map_spec`).
    index
        Which chunk, from 0 to ``spec.n_chunks - 1``.

    Returns
    -------
    ChunkResult
        The chunk's points: ``period``, ``samples``, ``impacts``,
        ``lyapunov``, ``status``, ``x_final`` ... one row per point, in the
        spec's order (what a store writes).

    Examples
    --------
    >>> import math, numpy as np, grazing
    >>> from grazing.sweeps import sweep_spec
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> spec = sweep_spec(m, "eta", np.linspace(0.44, 0.45, 5), settings=grazing.SweepSettings(
    ...     transient=300, periods=40, lyapunov=False))
    >>> res = run_chunk(spec, 0)
    >>> res.period.tolist(), res.samples.shape
    ([1, 1, 1, 4, 0], (5, 40, 2))
    """
    return run_chunks(spec, [index])[0]
