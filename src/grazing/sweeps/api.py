"""The public sweeps: :func:`sweep` (one parameter), :func:`parameter_map` (two), :func:`run_sweep`.

Chunks are independent units of work: they run in parallel on the local cores
or on a Dask cluster, and each finished chunk is written to the result store,
so the chunking - not the machine - defines the result.  ``chunk_size = 0``
makes the whole sweep one chunk (a strictly sequential experimenter sweep).
A store given by its path (``*.zarr``) is created or resumed: re-running the
same sweep computes only the chunks that are missing.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any, TypeVar

from grazing.core.model import HybridModel
from grazing.core.options import SweepSettings, refuse_unknown, with_shorthands
from grazing.errors import InvalidParameterError
from grazing.gpu.device import DEFAULT_DEVICE, resolve_device
from grazing.sweeps.chain import ChainLine, settle
from grazing.sweeps.executor import (
    DASK_NOTICE_AFTER,
    chain_window,
    chunk_results,
    compute_parts,
    local_results,
)
from grazing.sweeps.spec import DiscontinuityMapLike, SweepSpec, map_spec, sweep_spec

__all__ = ["DASK_NOTICE_AFTER", "parameter_map", "run_sweep", "run_sweeps", "sweep"]

T = TypeVar("T")


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
    device: str = DEFAULT_DEVICE,
) -> Any:
    """Run a sweep; return its :class:`xarray.Dataset` (:func:`sweep` and :func:`parameter_map` call it).

    Parameters
    ----------
    spec
        The sweep (:func:`~grazing.sweeps.spec.sweep_spec`, :func:`~grazing.sweeps.spec.map_spec`).
    store
        A result store (:class:`~grazing.sweeps.store.ZarrStore`, or the path
        of one): results written chunk by chunk, chunks already in it not
        recomputed; None keeps them in memory.
    workers
        Local threads computing the chunks (default: all cores).
    client
        A :class:`dask.distributed.Client`: run the chunks on its cluster.
    progress
        Called as ``progress(points_done, points_total)``.
    timeout
        With ``client``: give up (:class:`~grazing.sweeps.executor.SweepTimeoutError`)
        after this many seconds without any worker in the cluster (default: wait).
    notice
        Called with a one-line message when the cluster has had no worker
        for :data:`DASK_NOTICE_AFTER` seconds.
    load
        Return the dataset; with False, return None and keep nothing of the
        results in memory (they are in ``store``: a huge sweep streams to it).
    device
        ``"cpu"`` (the default): the CPU lanes; ``"gpu"``: an NVIDIA GPU, one
        CUDA thread per point (:mod:`grazing.gpu`, Lyapunov exponents, models
        with modes and chains of several chunks included, the latter settled
        as on the CPU: :mod:`grazing.sweeps.chain`; not yet the discontinuity
        map; sticking is finished on the CPU); ``"auto"``: the GPU
        when one is present and the sweep is large (:mod:`grazing.gpu.device`).

    Returns
    -------
    xarray.Dataset or None
        The results, in the order of the spec's points (:func:`sweep` sorts
        them by value); None with ``load=False``.

    Interrupted (Ctrl-C) or failing, the chunks not yet started are cancelled
    and the local workers stopped at once; the finished chunks are in ``store``.

    Examples
    --------
    A spec made once and run into a Zarr store; run again, nothing is
    recomputed (the store says every chunk is done):

    >>> import math, tempfile, numpy as np, grazing
    >>> from pathlib import Path
    >>> from grazing.sweeps import sweep_spec
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> spec = sweep_spec(m, "eta", np.linspace(0.44, 0.45, 5), settings=grazing.SweepSettings(
    ...     transient=300, periods=40, lyapunov=False, chunk_size=2))
    >>> path = Path(tempfile.mkdtemp()) / "eta.zarr"
    >>> run_sweep(spec, store=path, workers=1).period.values.tolist()
    [1, 1, 1, 4, 0]
    >>> calls = []
    >>> ds = run_sweep(spec, store=path, workers=1, progress=lambda done, total: calls.append(done))
    >>> calls, ds.period.values.tolist()
    ([5], [1, 1, 1, 4, 0])
    """
    from grazing.sweeps.store import MemoryStore

    where = resolve_device(device, spec, client)  # (before a store is opened: nothing written on an error)
    if isinstance(store, (str, Path)):
        from grazing.sweeps.store import open_store

        with open_store(store, spec) as opened:
            return run_sweep(
                spec, store=opened, workers=workers, client=client, progress=progress, timeout=timeout,
                notice=notice, load=load, device=where,
            )  # fmt: skip
    if store is None and not load:
        raise InvalidParameterError("load=False needs a store to keep the results")
    sink = store if store is not None else MemoryStore(spec)
    todo = [i for i in range(spec.n_chunks) if not sink.is_done(i)]
    done_points = spec.n_points - sum(spec.chunk(i).stop - spec.chunk(i).start for i in todo)
    if progress is not None:
        progress(done_points, spec.n_points)
    # (what the dataset needs besides the results, done while the cores compute: MemoryStore.prepare)
    prepare = sink.prepare if load and isinstance(sink, MemoryStore) else None
    memory = isinstance(sink, MemoryStore) and client is None
    if is_chained(spec):  # (the chunks of a chain: settled into the one chain's results)
        counted = [done_points]

        def write(_line: int, res: Any) -> None:
            sink.write(res)
            counted[0] += res.period.size
            if progress is not None:
                progress(counted[0], spec.n_points)

        if where == "gpu":
            from grazing.gpu.batch import gpu_chain_window, gpu_parts

            compute, window = gpu_parts, gpu_chain_window(spec, memory)
        else:
            compute, window = compute_parts(workers, client, timeout, notice), chain_window(workers, memory)
        settle([ChainLine(spec, sink, todo)], lambda parts: then(compute(parts), prepare), write, window)
        return sink.dataset() if load else None
    if where == "gpu":  # (chunks of whole chains or single points)
        from grazing.gpu.batch import gpu_results

        for res in then(gpu_results(spec, todo), prepare):
            sink.write(res)
            done_points += res.period.size
            if progress is not None:
                progress(done_points, spec.n_points)
        return sink.dataset() if load else None
    results = chunk_results(spec, todo, workers, client, timeout, notice)
    try:
        for res in then(results, prepare):
            sink.write(res)
            done_points += res.period.size
            if progress is not None:
                progress(done_points, spec.n_points)
    finally:
        results.close()  # cancels what is queued and stops the workers if we leave early
    return sink.dataset() if load else None


def run_sweeps(
    specs: Sequence[SweepSpec], *, workers: int | None = None, device: str = DEFAULT_DEVICE
) -> list[Any]:
    """Run several sweeps together on the local cores or a GPU; their datasets (as :func:`run_sweep`), in
    order.

    The chunks of sweeps that share the model and the sweep settings (they
    may differ in their points, start state, phase and ``fresh``) fill the
    same SIMD lanes (on the GPU: the same launches, :func:`grazing.gpu.batch.gpu_parts`):
    a dozen one-chunk experimenter sweeps run as fast as one sweep of a dozen
    chunks.  Each result is the one :func:`run_sweep` gives for that spec.

    Parameters
    ----------
    specs
        The sweeps (:func:`~grazing.sweeps.spec.sweep_spec`, :func:`~grazing.sweeps.spec.map_spec`).
    workers
        Local threads computing the chunks on the CPU (default: all cores).
    device
        ``"cpu"`` (the default), ``"gpu"`` or ``"auto"``, decided for each sweep as :func:`run_sweep`
        decides (:func:`~grazing.gpu.device.resolve_device`: ``"gpu"`` refuses, in one line and before
        anything runs, a sweep the GPU does not do; ``"auto"`` puts a large sweep on a GPU present).

    Returns
    -------
    list of xarray.Dataset
        One dataset per spec, in the order of ``specs``.

    Examples
    --------
    >>> import math, numpy as np, grazing
    >>> from grazing.sweeps.spec import sweep_spec
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> specs = [sweep_spec(m.with_params(theta_hat=math.radians(a)), "eta", np.linspace(0.40, 0.42, 3))
    ...          for a in (30, 40)]
    >>> [ds.period.values.tolist() for ds in run_sweeps(specs, workers=1)]
    [[1, 1, 1], [1, 1, 1]]
    """
    from grazing.sweeps.store import MemoryStore

    unique = {id(spec): spec for spec in specs}  # (a spec given twice is computed once)
    where = {key: resolve_device(device, spec) for key, spec in unique.items()}  # (refused before any run)
    sinks = {key: MemoryStore(spec) for key, spec in unique.items()}
    for on in ("cpu", "gpu"):
        mine = [spec for key, spec in unique.items() if where[key] == on]
        parts = [(spec, i) for spec in mine if not is_chained(spec) for i in range(spec.n_chunks)]
        if parts:
            if on == "gpu":
                from grazing.gpu.batch import gpu_parts

                computed = gpu_parts(parts)
            else:
                computed = local_results(parts, workers)
            for (spec, _), res in computed:
                sinks[id(spec)].write(res)
        lines = [
            ChainLine(spec, sinks[id(spec)], list(range(spec.n_chunks))) for spec in mine if is_chained(spec)
        ]
        if lines:
            write = lambda k, res, lines=lines: lines[k].sink.write(res)  # noqa: E731
            compute = parts_on(on, workers)
            settle(lines, compute, write, chain_window(0, True))  # (in memory: every chunk at a time)
    return [sinks[id(spec)].dataset() for spec in specs]


def parts_on(device: str, workers: int | None) -> Any:
    """What computes a round of chained parts on ``device`` (``"cpu"``: the local cores; ``"gpu"``:
    :func:`grazing.gpu.batch.gpu_parts`) for :func:`grazing.sweeps.chain.settle`."""
    if device == "gpu":
        from grazing.gpu.batch import gpu_parts

        return gpu_parts
    return compute_parts(workers, None)


def then(items: Iterable[T], action: Callable[[], None] | None) -> Iterator[T]:
    """``items``, with ``action`` done once, when the first has been dealt with (before the second is asked
    for): a sweep's dataset is prepared once its first chunk is in, while the cores compute the others
    (a chain's first round: every chunk from its guess).

    Examples
    --------
    >>> done = []
    >>> [(k, list(done)) for k in then(range(3), lambda: done.append("prepared"))]
    [(0, []), (1, ['prepared']), (2, ['prepared'])]
    """
    for k, item in enumerate(items):
        yield item
        if k == 0 and action is not None:
            action()


def is_chained(spec: SweepSpec) -> bool:
    """Whether the chunks of ``spec`` are parts of chains (carried, and some chain has several chunks)."""
    return spec.carried and spec.n_chunks > spec.segments


def sweep(
    model: HybridModel,
    param: str,
    values: Sequence[float],
    *,
    x0: Sequence[float] | None = None,
    direction: str = "up",
    settings: SweepSettings | None = None,
    zdm: DiscontinuityMapLike = None,
    store: Any = None,
    workers: int | None = None,
    client: Any = None,
    progress: Callable[[int, int], None] | None = None,
    device: str = DEFAULT_DEVICE,
    **shorthands: Any,
) -> Any:
    """One-parameter brute-force bifurcation diagram.

    Parameters
    ----------
    model, param, values
        The model and the parameter swept over ``values``.
    x0
        Initial state (of every chunk; of every point with ``fresh``).
    direction
        ``"up"`` or ``"down"``: the order the values are visited in; ``"both"``:
        up, then down from ``x0`` again, kept apart (hysteresis): the dataset's
        variables gain a first dimension ``direction`` (``"up"``, ``"down"``).
    settings
        How each point is computed (:class:`~grazing.core.options.SweepSettings`:
        ``transient``, ``periods``, ``phase``, ``fresh``, ``chunk_size``,
        ``adaptive``, ``lyapunov``, ``tol``); those names are also accepted as
        keyword arguments.
    zdm
        Iterate the discontinuity-map Poincare map instead of the flow.
    store, workers, client, progress, device
        See :func:`run_sweep` (``store`` may be the path of a Zarr store).
    **shorthands
        Any field of :class:`~grazing.core.options.SweepSettings` by name
        (``periods=20``, ``lyapunov=False`` ...), replacing that field of
        ``settings``.

    Returns
    -------
    xarray.Dataset
        The diagram, described below.

    The dataset has, per point (in increasing parameter
    order whatever the direction): ``samples`` (periods x states), ``period``
    (0: none <= 64; -1: the point failed), ``impacts_per_period``, ``lyapunov``
    (largest exponent per unit time), ``transient_used``, and ``status``: 0
    (ok) or why the point failed, a :class:`~grazing.core.solution.Status`
    code (1 step limit, 2 non-finite state, 3 accumulating impacts, 5 outside
    its mode; its attributes ``flag_values`` and ``flag_meanings`` say so too).  A failed
    point has NaN samples and Lyapunov exponent and -1 impacts; the sweep
    goes on, its next point starting afresh from ``x0``.

    Unless ``fresh``, the sweep is one chain: each point starts from the
    previous one's final state, and the result at every point is that of one
    continuous chain (``chunk_size = 0``) whatever the chunking, the threads
    or the cluster (:mod:`grazing.sweeps.chain`).

    Examples
    --------
    >>> import math, numpy as np, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> ds = sweep(m, "eta", np.linspace(0.40, 0.42, 3), periods=20, workers=1)
    >>> ds.period.values.tolist(), ds.status.values.tolist()
    ([1, 1, 1], [0, 0, 0])
    >>> ds = sweep(m.with_params(eta=0.4), "alpha", [0.2254, 1e300], periods=20, workers=1)
    >>> ds.period.values.tolist(), ds.status.values.tolist()  # forcing of 1e300 overflows the state
    ([1, -1], [0, 2])
    >>> from grazing.sweeps.status import failure_text
    >>> failure_text(ds.status.values)
    'failed: 1 (non-finite state: 1)'
    """
    used: set[str] = set()
    settings = with_shorthands(settings, SweepSettings, shorthands, used)
    refuse_unknown("sweep", shorthands, used)
    spec = sweep_spec(model, param, values, x0=x0, direction=direction, settings=settings, zdm=zdm)
    ds = run_sweep(spec, store=store, workers=workers, client=client, progress=progress, device=device)
    return ds.sortby("value")


def parameter_map(
    model: HybridModel,
    param1: str,
    values1: Sequence[float],
    param2: str,
    values2: Sequence[float],
    *,
    x0: Sequence[float] | None = None,
    settings: SweepSettings | None = None,
    store: Any = None,
    workers: int | None = None,
    client: Any = None,
    progress: Callable[[int, int], None] | None = None,
    device: str = DEFAULT_DEVICE,
    **shorthands: Any,
) -> Any:
    """Two-parameter period / impact / Lyapunov map.

    Each row (fixed ``param2``) is swept in increasing ``param1``, each point
    starting from the previous one's final state (unless ``fresh``); with the
    default ``chunk_size = 0`` one row is one chunk, and the rows run in
    parallel.

    Parameters
    ----------
    model
        The model, with the values of the parameters not swept.
    param1, values1
        The parameter along each row (the map's x axis, the dataset's last
        dimension) and its values, in the model's units (radians for angles).
    param2, values2
        The parameter across the rows (y axis, first dimension) and its values.
    x0
        Initial state of every row (default: zeros); of every point with
        ``fresh``.
    settings
        How each point is computed (:class:`~grazing.core.options.SweepSettings`;
        default: its defaults with ``chunk_size=0``, one chunk a row).
    store
        A result store, or the path of a Zarr store (``*.zarr``) created or
        resumed: each finished chunk is written to it, and a rerun computes
        only the chunks that are missing (:func:`run_sweep`).  None: in memory.
    workers
        Local threads computing the chunks (default: all cores).
    client
        A :class:`dask.distributed.Client`: run the chunks on its cluster.
    progress
        Called as ``progress(points_done, points_total)``.
    device
        ``"cpu"`` (the default), ``"gpu"`` or ``"auto"``: see :func:`run_sweep`.
    **shorthands
        Any field of :class:`~grazing.core.options.SweepSettings` by name
        (``transient=300``, ``periods=40``, ``lyapunov=False`` ...), replacing
        that field of ``settings``.

    Returns
    -------
    xarray.Dataset
        Dimensions ``(param2, param1)`` (named after the parameters, with their
        values as coordinates) and the variables of :func:`sweep`: ``samples``,
        ``period`` (0: aperiodic up to 64; -1: the point failed), ``impacts``,
        ``impacts_per_period``, ``lyapunov``, ``transient_used``, ``x_final``,
        the impacts per stop, ``status`` (0, or why each point failed: a
        :class:`~grazing.core.solution.Status` code) and ``stop_level``.

    Examples
    --------
    The pendulum (case B) at two stop angles: at 30° a period-4 and a
    period-2 motion past the grazing, at 40° period 1 longer, then chaos:

    >>> import numpy as np, grazing
    >>> m = grazing.models.pendulum("B")
    >>> ds = parameter_map(m, "eta", np.linspace(0.40, 0.46, 4), "theta_hat", np.radians([30, 40]),
    ...                    transient=300, periods=40, lyapunov=False, workers=1)
    >>> ds.period.dims, ds.period.values.tolist()
    (('theta_hat', 'eta'), [[1, 1, 4, 2], [1, 1, 1, 0]])
    >>> ds.impacts_per_period.values.round(2).tolist()
    [[0.0, 0.0, 2.0, 1.0], [0.0, 0.0, 0.0, 0.52]]

    :func:`grazing.plotting.plot_period_map` draws it.
    """
    used: set[str] = set()
    settings = with_shorthands(settings or SweepSettings(chunk_size=0), SweepSettings, shorthands, used)
    refuse_unknown("parameter_map", shorthands, used)
    spec = map_spec(model, param1, values1, param2, values2, x0=x0, settings=settings)
    return run_sweep(spec, store=store, workers=workers, client=client, progress=progress, device=device)
