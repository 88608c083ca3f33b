"""Attractors and their basins from many initial states: :func:`find_attractors`, :func:`basins`.

Every initial state is a point of a fresh sweep with its own start
(:class:`~grazing.sweeps.spec.SweepSpec` with ``starts``): the sweep engine
runs them on SIMD lanes, one lane per initial state, on the local cores or a
Dask cluster, and can keep them in a resumable Zarr store.  The results are
classified chunk by chunk, in order (:class:`~grazing.attractors.classify.Catalogue`),
so memory holds one label per initial state, not their samples.  An initial
state whose end state is aperiodic is run on from that end state for another
transient (``refine`` times) before it is classified: a chaotic transient, or
an orbit slow to settle, then ends on its attractor.  Initial states beyond a
stop are labelled ``invalid`` and not run.
"""

from __future__ import annotations

import itertools
import json
import math
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from grazing.attractors.classify import Attractor, Catalogue
from grazing.attractors.grid import StateGrid, as_states, beyond_stops, default_cell, start_time, state_grid
from grazing.core.model import HybridModel, mode_of_states
from grazing.core.options import (
    BASIN_ADAPTIVE_TOL,
    BASIN_CLOSING_ROUNDS,
    CELL_FRACTION,
    CELLS,
    ESCAPE_FACTOR,
    MATCH_TOL,
    BasinSettings,
    refuse_unknown,
    with_shorthands,
)
from grazing.errors import InvalidParameterError
from grazing.gpu.device import DEFAULT_DEVICE, check_device, spec_device
from grazing.sweeps.spec import ChunkResult, SweepSpec

BasinsProgress = Callable[[int, int], None]
"""Called as ``progress(initial_states_done, initial_states_total)``."""

SMALLEST_CELL = float(np.finfo(float).tiny) / MATCH_TOL
"""The smallest cell size: periodic orbits are matched to ``MATCH_TOL`` cells, a positive normal number."""


@dataclass(frozen=True)
class AttractorSet:
    """The attractors found from a set of initial states, and the attractor of each.

    Attributes
    ----------
    attractors
        Every attractor (and outcome: escaping, failed, invalid) with its basin
        fraction, in the order of its first initial state (``invalid`` first, id 0).
    labels
        The id of the attractor of each initial state.
    cell
        The cell size per state component (aperiodic attractors are sets of cells).
    phase
        The forcing phase of the initial states and of the samples (radians).
    transient, periods
        Forcing periods run before sampling, and sampled.
    seconds
        Wall time of the computation.
    cell_fraction
        The recurrence cell of an aperiodic attractor, as a fraction of its extent.
    polished
        Initial states whose end state was polished by Newton's method onto a stable orbit.

    Examples
    --------
    What :func:`find_attractors` returns:

    >>> import grazing
    >>> from grazing.attractors import find_attractors
    >>> ball = grazing.models.bouncing_ball(amplitude=0.8, r=0.8)
    >>> found = find_attractors(ball, [[0.0, 0.8], [3.6, -2.0], [-1.0, 0.0]], workers=1)
    >>> found.labels.tolist(), [round(f, 3) for f in found.fractions.values()]
    ([1, 2, 0], [0.333, 0.333, 0.333])
    >>> found.transient, found.periods  # the defaults of BasinSettings
    (300, 50)
    """

    attractors: tuple[Attractor, ...]
    labels: np.ndarray
    cell: np.ndarray
    phase: float
    transient: int
    periods: int
    seconds: float = 0.0
    cell_fraction: float = CELL_FRACTION
    polished: int = 0

    @property
    def fractions(self) -> dict[int, float]:
        """Each id's share of the initial states (summing to 1)."""
        return {a.id: a.fraction for a in self.attractors}

    def attractor(self, ident: int) -> Attractor:
        """The attractor with id ``ident``."""
        for a in self.attractors:
            if a.id == ident:
                return a
        raise KeyError(ident)


def basin_spec(model: HybridModel, states: np.ndarray, settings: BasinSettings, lyapunov: bool,
               modes: np.ndarray | None = None) -> SweepSpec:  # fmt: skip
    """The fresh sweep whose points are the initial states ``states``, each from its own at the phase (a
    model with modes: in its mode, ``modes``, by default the one it lies in: :func:`start_modes`)."""
    return SweepSpec(
        model=model,
        params=(),
        points=((),) * states.shape[0],
        x0=tuple(float(v) for v in states[0]),
        transient=settings.transient,
        periods=settings.periods,
        phase=settings.phase,
        fresh=True,
        chunk_size=settings.chunk_size,
        adaptive=True,
        lyapunov=lyapunov,
        tol=settings.tol,
        starts=states,
        adaptive_tol=BASIN_ADAPTIVE_TOL,
        polish=False,  # (the catalogue polishes the end states, a few per attractor)
        start_modes=start_modes(model, states, start_time(model, settings.phase)) if modes is None else modes,
    )


def start_modes(model: HybridModel, states: np.ndarray, t: float) -> np.ndarray | None:
    """The index of the mode each initial state lies in at time ``t``
    (:func:`~grazing.core.model.mode_of_states`); None for a model without modes (its one mode)."""
    return mode_of_states(model, states, t) if model.has_modes else None


def outside(model: HybridModel, states: np.ndarray, t: float) -> np.ndarray:
    """Which initial states are ``invalid``: beyond a stop (:func:`~grazing.attractors.grid.beyond_stops`),
    or, in a model with modes, in no mode's region (:meth:`HybridModel.mode_at`)."""
    if model.has_modes:
        return mode_of_states(model, states, t) < 0
    return beyond_stops(model, states, t)


@dataclass(frozen=True)
class _Run:
    """Where the end states are computed and kept."""

    workers: int | None
    client: Any
    store: Any
    progress: BasinsProgress | None
    device: str = DEFAULT_DEVICE


def find_attractors(
    model: HybridModel,
    states: Any,
    *,
    settings: BasinSettings | None = None,
    cell: Sequence[float] | None = None,
    cell_fraction: float = CELL_FRACTION,
    escape: float | None = None,
    workers: int | None = None,
    client: Any = None,
    store: Any = None,
    progress: BasinsProgress | None = None,
    device: str = DEFAULT_DEVICE,
    **shorthands: Any,
) -> AttractorSet:
    """The attractors reached from the initial states ``states`` (rows), and which one each reaches.

    Parameters
    ----------
    model
        The model with its parameter values.
    states
        Initial states, one row each (a grid: :func:`basins`; a random sample...).
    settings
        How each initial state is run (:class:`~grazing.core.options.BasinSettings`:
        ``transient``, ``periods``, ``phase``, ``refine``, ``lyapunov``, ``tol``,
        ``chunk_size``); those names are also accepted as keyword arguments.
    cell
        Size of a cell per state component (default: the initial states' box
        over :data:`~grazing.core.options.CELLS`): periodic orbits are one
        when their points match to :data:`~grazing.core.options.MATCH_TOL`
        cells, aperiodic end states are recorded on this grid of cells.
    cell_fraction
        Aperiodic end states are on one attractor when their samples share a
        cell, or come within one recurrence cell: this fraction of the extent
        of the attractor's points per component (at least ``cell``; default
        :data:`~grazing.core.options.CELL_FRACTION`; 0: shared cells only).
    escape
        Distance from the box (in each component) beyond which a state has
        escaped (default :data:`~grazing.core.options.ESCAPE_FACTOR` times the
        box's largest side or coordinate, at least 1).
    workers, client
        Local threads, or a Dask client (as for :func:`grazing.sweeps.run_sweep`).
    store
        A Zarr store (path, or an open :class:`~grazing.sweeps.store.ZarrStore`
        of the same computation) keeping every finished chunk of the first
        run: interrupted and run again, it computes only the chunks missing.
    progress
        Called as ``progress(done, total)``.
    device
        ``"cpu"`` (the default), ``"gpu"`` or ``"auto"`` (:mod:`grazing.gpu.device`): the runs on an
        NVIDIA GPU, one CUDA thread per initial state, those with Lyapunov exponents (the refined
        runs' last, each orbit's exponent) too.
    **shorthands
        Any field of :class:`~grazing.core.options.BasinSettings` by name
        (``transient=200``, ``lyapunov=False`` ...), replacing that field of
        ``settings``.

    Returns
    -------
    AttractorSet
        The attractors (and outcomes) with their basin fractions, and the
        attractor of each initial state.

    The first run of every initial state computes no Lyapunov exponent: the
    aperiodic end states get theirs when they are run on (``refine``), and each
    orbit from one of its points.  An end state with no period whose samples
    contract towards a cycle is polished by Newton's method
    (:mod:`grazing.sweeps.polish`): where that converges to a stable orbit the
    samples approach, it is on that periodic attractor (an orbit with a
    multiplier of modulus 0.997 is not "quasiperiodic" for want of a long
    transient).  A periodic orbit whose multiplier 1 is double (a free mass at
    rest, never impacting) is ``neutral``: a family of motions, not an
    isolated attractor (it keeps its share of the initial states that reach it).

    Examples
    --------
    >>> import numpy as np, grazing
    >>> ball = grazing.models.bouncing_ball(amplitude=0.8, r=0.8, omega=1.0, gravity=1.0)
    >>> found = find_attractors(ball, [[0.0, 0.8], [3.6, -2.0]], workers=1)
    >>> [(a.kind, a.period) for a in found.attractors], found.labels.tolist()
    ([('sticking', 1), ('periodic', 1)], [1, 2])
    """
    start = time.perf_counter()
    used: set[str] = set()
    s = with_shorthands(settings, BasinSettings, shorthands, used)
    refuse_unknown("find_attractors", shorthands, used)
    check_device(device, client)
    x = as_states(model, states)
    t0 = start_time(model, s.phase)
    invalid = outside(model, x, t0)
    valid = np.flatnonzero(~invalid)
    box = x[valid] if valid.size else x
    cells = default_cell(box) if cell is None else np.broadcast_to(np.asarray(cell, dtype=float), x.shape[1:])
    smallest = SMALLEST_CELL
    if cell is not None and not np.all(np.isfinite(cells) & (cells >= smallest)):
        raise InvalidParameterError(
            f"cell sizes must be positive numbers of at least {smallest:.3g}, got {cell!r}"
        )
    if cell is None and not np.all(cells >= smallest):
        raise InvalidParameterError(
            "the initial states' box is too narrow to tell attractors apart (cells of "
            f"{float(cells.min()):.3g}, its extent over {CELLS}): widen the box (or, in Python, give cell "
            f"sizes of at least {smallest:.3g}: cell=)"
        )
    try:
        fraction = float(cell_fraction)
    except (TypeError, ValueError):
        fraction = math.nan
    if not 0.0 <= fraction <= 1.0:
        raise InvalidParameterError(f"cell_fraction must be in [0, 1], got {cell_fraction!r}")
    side = float(np.ptp(box, axis=0).max())
    reach = ESCAPE_FACTOR * max(side, float(np.abs(box).max()), 1.0) if escape is None else float(escape)
    if not reach > 0:
        raise InvalidParameterError(f"escape must be a positive distance, got {escape!r}")
    catalogue = Catalogue(model, x.shape[0], cells, box.min(axis=0), reach + side, s.periods, t0, fraction)
    if valid.size:
        run = _Run(workers, client, store, progress, device)
        spec = basin_spec(model, x[valid], s, s.lyapunov and s.refine == 0)
        looks = _looks(s.refine)
        deferred = _run(spec, valid, catalogue, next(looks), run, x.shape[0] - valid.size, x.shape[0])
        for look in looks:
            if deferred.index.size == 0:  # (nothing left to run on: --refine 10**9 ends here too)
                break
            deferred = _refine(model, catalogue, deferred, s, look, replace(run, store=None, progress=None))
        exact = catalogue.examine_orbits()
        if s.lyapunov:
            _orbit_exponents(model, catalogue, s, run, exact)
    attractors, labels = catalogue.attractors(int(invalid.sum()))
    seconds = time.perf_counter() - start
    return AttractorSet(tuple(attractors), labels, np.array(cells), s.phase, s.transient, s.periods, seconds,
                        fraction, catalogue.polished)  # fmt: skip


def _orbit_exponents(model: HybridModel, catalogue: Catalogue, s: BasinSettings, run: _Run,
                     exact: dict[int, float]) -> None:  # fmt: skip
    """Each periodic orbit's largest Lyapunov exponent: ``exact`` (from its multipliers) where given, else
    from a run from one of its points (on ``run``'s device: :func:`~grazing.gpu.device.spec_device`)."""
    from grazing.sweeps.api import run_sweep

    for k, value in exact.items():
        catalogue.entries[k].exponents = [value]
    orbits = [k for k in catalogue.orbits() if k not in exact]
    if not orbits:
        return
    points = np.array([catalogue.entries[k].points[0] for k in orbits])
    one = replace(s, chunk_size=max(1, len(orbits)))  # (on the orbit: the adaptive transient ends at once)
    spec = basin_spec(model, points, one, True)
    device = spec_device(run.device, spec, run.client)
    ds = run_sweep(spec, workers=run.workers, client=run.client, device=device)
    for k, value in zip(orbits, ds.lyapunov.values):
        catalogue.entries[k].exponents = [float(value)]


@dataclass(frozen=True)
class _Look:
    """How the end states of one run are classified (:meth:`Catalogue.add`): ``defer`` the aperiodic and
    unsettled ones (to run them on), or label them; at a last look, ``hold`` those still closing in on a
    shorter period beyond a match of it (to run them on)."""

    defer: bool
    hold: bool = False


def _looks(refine: int) -> Iterator[_Look]:
    """The runs of an initial state, at most: the first, ``refine`` runs on, then up to
    :data:`~grazing.core.options.BASIN_CLOSING_ROUNDS` for the end states closing in on a shorter
    period (none without ``refine``: a run on was not asked for).  An iterator: ``refine`` may be
    huge (a list of 10**9 looks took 8 GB before the first run).

    Examples
    --------
    >>> [(look.defer, look.hold) for look in _looks(1)][:3], len(list(_looks(1))), list(_looks(0))
    ([(True, False), (False, True), (False, True)], 6, [_Look(defer=False, hold=False)])
    """
    if refine == 0:
        return iter([_Look(defer=False)])
    held = [_Look(defer=False, hold=True)] * BASIN_CLOSING_ROUNDS  # (the last run on, then all but one)
    return itertools.chain(itertools.repeat(_Look(defer=True), refine), held, [_Look(defer=False)])


@dataclass
class _Deferred:
    """Initial states (their indices) whose end state was aperiodic, and those end states."""

    index: np.ndarray
    states: np.ndarray
    modes: np.ndarray | None = None  # (a model with modes: the mode each end state is in)


class _InOrder:
    """Classifies the chunks of a spec in their order, as they arrive (or are read from the store)."""

    def __init__(self, spec: SweepSpec, which: np.ndarray, catalogue: Catalogue, look: _Look, store: Any,
                 done: set[int]) -> None:  # fmt: skip
        self.spec, self.which, self.catalogue, self.look = spec, which, catalogue, look
        self.store, self.done = store, done
        self.pending: dict[int, ChunkResult] = {}
        self.next = 0
        self.counted = 0
        self.index: list[np.ndarray] = []
        self.states: list[np.ndarray] = []
        self.modes: list[np.ndarray] = []

    def take(self, res: ChunkResult | None = None) -> None:
        """Keep ``res``; classify every chunk now ready in order (computed, or in the store)."""
        if res is not None:
            self.pending[res.index] = res
        while self.next < self.spec.n_chunks and (self.next in self.pending or self.next in self.done):
            i = self.next
            part = self.pending.pop(i) if i in self.pending else self.store.read_chunk(i)
            sl = self.spec.chunk(i)
            look = self.look
            later = self.catalogue.add(0, part, which=self.which[sl], defer=look.defer, hold=look.hold)
            if later.size:
                self.index.append(self.which[sl][later])
                self.states.append(np.asarray(part.x_final, dtype=float)[later])
                ended = part.mode_final if part.mode_final is not None else np.full(sl.stop - sl.start, -1)
                self.modes.append(np.asarray(ended, dtype=np.int64)[later])
            self.counted += sl.stop - sl.start
            self.next += 1

    def deferred(self) -> _Deferred:
        n = self.spec.model.n_states
        return _Deferred(
            np.concatenate(self.index) if self.index else np.zeros(0, dtype=np.int64),
            np.concatenate(self.states) if self.states else np.zeros((0, n)),
            np.concatenate(self.modes) if self.spec.model.has_modes and self.modes else None,
        )


def _run(spec: SweepSpec, which: np.ndarray, catalogue: Catalogue, look: _Look, run: _Run, offset: int,
         total: int) -> _Deferred:  # fmt: skip
    """Run (or read from the store) every chunk of ``spec`` and classify them (initial states ``which``)."""
    from grazing.sweeps.executor import chunk_results

    if isinstance(run.store, (str, Path)):
        from grazing.sweeps.store import open_store

        with open_store(run.store, spec) as opened:
            return _run(spec, which, catalogue, look, replace(run, store=opened), offset, total)
    store = run.store
    done = {i for i in range(spec.n_chunks) if store is not None and store.is_done(i)}
    todo = [i for i in range(spec.n_chunks) if i not in done]
    order = _InOrder(spec, which, catalogue, look, store, done)
    order.take()
    if run.progress is not None:
        run.progress(offset + order.counted, total)
    if todo:
        if spec_device(run.device, spec, run.client) == "gpu":
            from grazing.gpu.batch import gpu_results

            results = gpu_results(spec, todo)
        else:
            results = chunk_results(spec, todo, run.workers, run.client)
        try:
            for res in results:
                if store is not None:
                    store.write(res)
                order.take(res)
                if run.progress is not None:
                    run.progress(offset + order.counted, total)
        finally:
            results.close()
    return order.deferred()


def _refine(model: HybridModel, catalogue: Catalogue, deferred: _Deferred, s: BasinSettings, look: _Look,
            run: _Run) -> _Deferred:  # fmt: skip
    """Run the deferred end states on for another transient, from where they ended; classify them."""
    if deferred.index.size == 0:
        return deferred
    modes = None if deferred.modes is None else _end_modes(model, deferred, start_time(model, s.phase))
    spec = basin_spec(model, deferred.states, s, s.lyapunov and not look.defer, modes)
    return _run(spec, deferred.index, catalogue, look, run, 0, 0)


def _end_modes(model: HybridModel, deferred: _Deferred, t: float) -> np.ndarray:
    """The mode each deferred end state is run on in: the mode its run ended in, where known and not a
    sliding pseudo-mode (a chunk read back from a store keeps only its last point's), else the one it
    lies in (:func:`start_modes`; it slides on from a surface), else the initial mode (its run then
    says what it does there)."""
    assert deferred.modes is not None
    real = len(model.mode_names) - len(model.sliding_modes)
    ended = np.asarray(deferred.modes, dtype=np.int64)
    known = (ended >= 0) & (ended < real)
    there = mode_of_states(model, deferred.states, t)
    return np.where(known, ended, np.where(there >= 0, there, model.mode_index(None)))


def basins(
    model: HybridModel,
    x_range: Sequence[float],
    y_range: Sequence[float],
    num: Sequence[int],
    *,
    states: Sequence[str | int] = (0, 1),
    fixed: Mapping[str | int, float] | None = None,
    phase: float = 0.0,
    **options: Any,
) -> Any:
    """Basins of attraction on a grid of initial states: an :class:`xarray.Dataset`.

    The grid (:func:`~grazing.attractors.grid.state_grid`) is ``num[0] x
    num[1]`` initial states over ``x_range`` x ``y_range`` in the state
    components ``states`` (indices or names), the others at their ``fixed``
    values (default 0), at forcing phase ``phase``; ``options`` are those of
    :func:`find_attractors`.

    Parameters
    ----------
    model
        The model with its parameter values.
    x_range, y_range
        ``(lo, hi)`` of the two state components varied.
    num
        Initial states along each.
    states
        The two state components varied (indices or names).
    fixed
        Values of the other state components (default 0).
    phase
        Forcing phase of the initial states and of the samples (radians).
    **options
        Those of :func:`find_attractors` (``settings``, ``workers``,
        ``store``, the :class:`~grazing.core.options.BasinSettings` fields ...).

    Returns
    -------
    xarray.Dataset
        ``label`` (``y``, ``x``: the attractor id of each initial state; 0
        beyond a stop), and along ``attractor`` (the ids): ``kind``,
        ``period``, ``impacts_per_period``, ``lyapunov``, ``fraction``,
        ``count``, ``reason``, ``points`` (``attractor``, ``point``,
        ``component``; NaN-padded) and ``n_points``.

    Examples
    --------
    >>> import grazing
    >>> ball = grazing.models.bouncing_ball(amplitude=0.8, r=0.8)
    >>> ds = basins(ball, (-1.0, 6.0), (-4.0, 4.0), (8, 8), workers=1)  # (below the table at y < 0)
    >>> ds.kind.values.tolist(), float(ds.fraction.sum()), ds.label.values[0].tolist()
    (['invalid', 'periodic', 'sticking'], 1.0, [0, 1, 2, 2, 2, 1, 1, 1])
    """
    grid = state_grid(model, x_range, y_range, num, states=states, fixed=fixed, phase=phase)
    found = find_attractors(model, grid.states_array(), phase=grid.phase, **options)
    return to_dataset(model, grid, found)


def to_dataset(model: HybridModel, grid: StateGrid, found: AttractorSet) -> Any:
    """The dataset of :func:`basins` from the grid and what :func:`find_attractors` found on it.

    Parameters
    ----------
    model
        The model.
    grid
        The grid of initial states (:func:`~grazing.attractors.state_grid`).
    found
        What :func:`find_attractors` found from the grid's states.

    Returns
    -------
    xarray.Dataset
        As :func:`basins` returns.

    Examples
    --------
    >>> import grazing
    >>> from grazing.attractors import state_grid
    >>> ball = grazing.models.bouncing_ball(amplitude=0.8, r=0.8)
    >>> grid = state_grid(ball, (-1.0, 6.0), (-4.0, 4.0), (3, 2))
    >>> ds = to_dataset(ball, grid, find_attractors(ball, grid.states_array(), workers=1))
    >>> ds.label.values.tolist(), ds.kind.values.tolist()
    ([[0, 1, 2], [0, 2, 1]], ['invalid', 'sticking', 'periodic'])
    """
    import xarray as xr

    i, j = grid.states
    names = model.state_names
    atts = found.attractors
    longest = max([len(a.points) for a in atts] + [1])
    points = np.full((len(atts), longest, model.n_states), np.nan)
    for k, a in enumerate(atts):
        points[k, : len(a.points)] = a.points
    ds = xr.Dataset(
        {
            "label": (("y", "x"), found.labels.reshape(grid.shape).astype(np.int32)),
            "kind": ("attractor", np.array([str(a.kind) for a in atts], dtype=str)),
            "period": ("attractor", np.array([a.period for a in atts], dtype=np.int32)),
            "impacts_per_period": ("attractor", np.array([a.impacts_per_period for a in atts], dtype=float)),
            "lyapunov": ("attractor", np.array([a.lyapunov for a in atts], dtype=float)),
            "fraction": ("attractor", np.array([a.fraction for a in atts], dtype=float)),
            "count": ("attractor", np.array([a.count for a in atts], dtype=np.int64)),
            "reason": ("attractor", np.array([a.reason for a in atts], dtype=str)),
            "mode": ("attractor", np.array([a.mode for a in atts], dtype=str)),
            "points": (("attractor", "point", "component"), points),
            "n_points": ("attractor", np.array([len(a.points) for a in atts], dtype=np.int32)),
        },
        coords={
            "x": ("x", grid.x),
            "y": ("y", grid.y),
            "attractor": ("attractor", np.array([a.id for a in atts], dtype=np.int32)),
            "component": ("component", list(names)),
        },
    )
    labels, units = model.state_labels, model.state_units
    ds["x"].attrs.update({"long_name": names[i], "symbol": labels[i], "units": units[i] if units else ""})
    ds["y"].attrs.update({"long_name": names[j], "symbol": labels[j], "units": units[j] if units else ""})
    ds["label"].attrs["description"] = "the id of the attractor each initial state ends on (0: beyond a stop)"
    ds["kind"].attrs["description"] = (
        "periodic, sticking, neutral, chaotic, quasiperiodic, aperiodic, escaping, failed, invalid"
    )
    ds["points"].attrs["description"] = "states on the attractor at the sampling phase (NaN-padded)"
    ds["mode"].attrs["description"] = "the mode its end states ended in ('': in different ones, or not known)"
    ds.attrs.update(
        {
            "model": model.name,
            "params": json.dumps(dict(model.params)),
            "states": f"{names[i]},{names[j]}",
            "initial_state": json.dumps(list(grid.base)),
            "phase": grid.phase,
            "transient": found.transient,
            "periods": found.periods,
            "cell": json.dumps(found.cell.tolist()),
            "cell_fraction": found.cell_fraction,
            "polished": found.polished,
            "state_labels": json.dumps(list(labels)),
            "state_units": json.dumps(list(units)),
            "time_label": model.time_label,
            "forcing_period": float(model.period),
            "seconds": found.seconds,
        }
    )
    return ds
