"""Global continuation of attractors: the attractors and their basin fractions along a parameter.

At each parameter value the grid's initial states, and seeds on the
attractors found at the value before (points of each, so that an attractor
whose basin falls between the grid's points is still followed), are run by
:func:`~grazing.attractors.basins.find_attractors`, as Attractors.jl's
``AttractorSeedContinueMatch`` does.  An attractor of the value before
continues as the attractor most of its seeds end on (when several end on one,
the nearest of them does); the attractors no seed reached are matched to the
ones left, nearest first, by the distance between their point sets (the
Hausdorff distance in cells, as ``MatchBySSSetDistance``), up to a threshold.
A matched attractor keeps its id, an unmatched one gets a new id.  Outcomes
(escaping, failed, invalid) match their own kind and reason.  The basin
fractions are those of the grid (seeds do not count).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from grazing.attractors.basins import AttractorSet, find_attractors
from grazing.attractors.classify import Attractor, set_distance
from grazing.attractors.grid import start_time, state_grid
from grazing.attractors.kinds import AttractorKind
from grazing.core.model import HybridModel, mode_of_states
from grazing.core.options import CELL_FRACTION, BasinSettings, refuse_unknown, with_shorthands
from grazing.errors import InvalidParameterError
from grazing.gpu.device import DEFAULT_DEVICE

MATCH_DISTANCE = 8.0
"""Largest distance (in cells) between an attractor at one parameter value and at the next for them
to be one attractor followed."""

SEEDS = 8
"""Most points of each attractor run again as initial states at the next parameter value."""

KEPT_POINTS = 256
"""Most points of each attractor at each value kept in the continuation's dataset."""


@dataclass(frozen=True, kw_only=True)
class ContinuationStep:
    """One parameter value of a continuation: what was found there, and the followed id of each attractor."""

    value: float
    found: AttractorSet
    grid_size: int
    ids: dict[int, int]  # the attractor's id at this value -> its followed id

    def fractions(self) -> dict[int, float]:
        """Followed id -> share of the grid's initial states (summing to 1)."""
        labels = self.found.labels[: self.grid_size]
        out = {
            self.ids[a.id]: float(np.count_nonzero(labels == a.id)) / self.grid_size
            for a in self.found.attractors
        }
        return out


def match(
    previous: Sequence[Attractor],
    current: Sequence[Attractor],
    cell: np.ndarray,
    threshold: float = MATCH_DISTANCE,
    seeded: Mapping[int, int] | None = None,
) -> dict[int, int]:
    """The attractors of ``current`` matched to those of ``previous``: ``{current id: previous id}``.

    ``seeded`` maps a previous id to the current id most of its seeds ended on:
    those pairs first (of several previous ones ending on one, the nearest).
    Then the other pairs are taken nearest first (Hausdorff distance between
    their points, in cells; on a model with modes, points in different modes
    are not near: :func:`_distance`), each attractor at most once, up to
    ``threshold``; outcomes match the outcome of the same kind and reason.

    Examples
    --------
    >>> def periodic(i, x, y):
    ...     return Attractor(id=i, kind="periodic", period=1, impacts_per_period=1.0, lyapunov=-0.1,
    ...                      points=np.array([[x, y]]))
    >>> a, b = periodic(1, 0.0, 0.0), periodic(2, 5.0, 5.0)
    >>> moved = [periodic(1, 5.5, 5.0), periodic(2, 0.5, 0.0)]
    >>> match([a, b], moved, np.ones(2))
    {1: 2, 2: 1}
    """
    out: dict[int, int] = {}
    taken: set[int] = set()
    by_id = {a.id: a for a in previous}
    now = {a.id: a for a in current}
    for p_id, c_id in sorted((seeded or {}).items()):
        rivals = [q for q, c in (seeded or {}).items() if c == c_id]
        best = min(rivals, key=lambda q: (_distance(by_id[q], now[c_id], cell), q))
        if best == p_id and c_id in now and not now[c_id].kind.outcome:
            out[c_id] = p_id
            taken.add(p_id)
    pairs = []
    for c in current:
        for p in previous:
            if c.kind.outcome != p.kind.outcome:
                continue
            if c.kind.outcome:
                if (c.kind, c.reason) == (p.kind, p.reason):
                    pairs.append((0.0, c.id, p.id))
                continue
            d = _distance(p, c, cell)
            if d <= threshold:
                pairs.append((d, c.id, p.id))
    for _, c_id, p_id in sorted(pairs):
        if c_id not in out and p_id not in taken:
            out[c_id] = p_id
            taken.add(p_id)
    return out


def _few(points: np.ndarray, most: int = 400) -> np.ndarray:
    """At most ``most`` of ``points``, evenly spread over the list."""
    if len(points) <= most:
        return points
    return points[np.linspace(0, len(points) - 1, most).astype(int)]


def _distance(a: Attractor, b: Attractor, cell: np.ndarray) -> float:
    """The distance between two attractors' points (at most 400 of each), in cells; where both know the
    mode at each point, two points in different modes are not near (one state in two modes: two orbits).

    Examples
    --------
    >>> def orbit(mode):
    ...     return Attractor(id=1, kind="periodic", period=1, impacts_per_period=0.0, lyapunov=-1.0,
    ...                      points=np.zeros((1, 2)), modes=(mode,) if mode else ())
    >>> _distance(orbit("ann"), orbit("ann"), np.ones(2)), _distance(orbit("ann"), orbit("bo"), np.ones(2))
    (0.0, inf)
    >>> _distance(orbit("ann"), orbit(""), np.ones(2))
    0.0
    """
    modes = len(a.modes) == len(a.points) and len(b.modes) == len(b.points)
    return set_distance(
        _few(a.points), _few(b.points), cell,
        _few(np.asarray(a.modes)) if modes else None, _few(np.asarray(b.modes)) if modes else None,
    )  # fmt: skip


def _seeds(attractors: Sequence[Attractor], most: int) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Points of each attractor (not the outcomes), at most ``most`` each, as initial states; the id of
    the attractor of each; and the mode at each (``""``: not known)."""
    chosen = [
        (a.id, _few(a.points, most), _few(np.asarray(a.modes if len(a.modes) == len(a.points) else
                                                     [""] * len(a.points)), most))
        for a in attractors if not a.kind.outcome and len(a.points)
    ]  # fmt: skip
    if not chosen:
        return np.zeros((0, 0)), np.zeros(0, dtype=np.int64), []
    points = np.concatenate([p for _, p, _ in chosen])
    ids = np.concatenate([[i] * len(p) for i, p, _ in chosen])
    return points, ids, [str(m) for _, _, ms in chosen for m in ms]


def _start_modes(model: HybridModel, states: np.ndarray, seeded: list[str], t: float) -> list[int] | None:
    """A model with modes: the mode each of ``states`` starts in: its seed's (the last ``len(seeded)``
    states), where known and not a sliding pseudo-mode, else the one it lies in
    (:func:`~grazing.attractors.basins.start_modes`)."""
    if not model.has_modes:
        return None
    there = mode_of_states(model, states, t)
    out = [model.mode_index(None) if k < 0 else int(k) for k in there]  # (-1: invalid, whichever)
    first = len(out) - len(seeded)
    real = model.mode_names[: len(model.mode_names) - len(model.sliding_modes)]
    for i, name in enumerate(seeded):
        if name in real:  # (not known, or sliding on a surface, where no run starts: the one it lies in)
            out[first + i] = real.index(name)
    return out


def _votes(origin: np.ndarray, labels: np.ndarray) -> dict[int, int]:
    """Previous id -> the current id most of its seeds ended on (ties: the smallest)."""
    out = {}
    for p_id in np.unique(origin):
        ended = labels[origin == p_id]
        ids, counts = np.unique(ended, return_counts=True)
        out[int(p_id)] = int(ids[np.argmax(counts)])
    return out


def continue_attractors(
    model: HybridModel,
    param: str,
    values: Sequence[float],
    x_range: Sequence[float],
    y_range: Sequence[float],
    num: Sequence[int],
    *,
    states: Sequence[str | int] = (0, 1),
    fixed: Mapping[str | int, float] | None = None,
    settings: BasinSettings | None = None,
    seeds: int = SEEDS,
    threshold: float = MATCH_DISTANCE,
    cell_fraction: float = CELL_FRACTION,
    workers: int | None = None,
    client: Any = None,
    progress: Callable[[int, int], None] | None = None,
    device: str = DEFAULT_DEVICE,
    **shorthands: Any,
) -> Any:
    """Attractors and their basin fractions followed along ``param`` over ``values`` (an xarray Dataset).

    Parameters
    ----------
    model, param, values
        The model and the parameter taking ``values`` (in this order).
    x_range, y_range, num, states, fixed
        The grid of initial states, as for :func:`~grazing.attractors.basins.basins`
        (its phase is the settings' ``phase``).
    settings
        :class:`~grazing.core.options.BasinSettings` (also as keyword arguments).
    seeds
        Points of each attractor run again as initial states at the next value.
    threshold
        Largest distance (cells) between an attractor at one value and at the next to be followed.
    cell_fraction
        The recurrence cell of an aperiodic attractor, a fraction of its extent (as for
        :func:`~grazing.attractors.basins.find_attractors`).
    workers, client
        Local threads, or a Dask client.
    progress
        Called as ``progress(values_done, values_total)``.
    device
        Where each value's runs go, as for :func:`~grazing.attractors.basins.find_attractors`.
    **shorthands
        Any field of :class:`~grazing.core.options.BasinSettings` by name.

    Returns
    -------
    xarray.Dataset
        Along ``value`` and ``attractor`` (the followed ids, 1, 2, ... in
        order of appearance; 0 is ``invalid``): ``fraction`` (0 where the
        attractor is not found; an attractor found only from the seeds has 0),
        ``present``, ``kind``, ``period``, ``impacts_per_period``,
        ``lyapunov``, ``points`` (NaN-padded), and ``label`` (``value``, ``y``,
        ``x``: the followed id of each initial state).

    Examples
    --------
    >>> import grazing
    >>> ball = grazing.models.bouncing_ball(r=0.8)
    >>> ds = continue_attractors(ball, "amplitude", [0.7, 0.8], (0.0, 6.0), (-4.0, 4.0), (6, 6), workers=1)
    >>> ds.kind.values.tolist()
    [['periodic', 'sticking'], ['periodic', 'sticking']]
    """
    start = time.perf_counter()
    used: set[str] = set()
    s = with_shorthands(settings, BasinSettings, shorthands, used)
    refuse_unknown("continue_attractors", shorthands, used)
    par = model.parameter(param)
    vals = np.asarray(values, dtype=float).ravel()
    if vals.size == 0 or not np.all(np.isfinite(vals)):
        raise InvalidParameterError("values must be a non-empty list of finite numbers")
    for v in (vals[0], vals[-1]):
        model.with_params(**{par.name: float(v)})
    grid = state_grid(model, x_range, y_range, num, states=states, fixed=fixed, phase=s.phase)
    x = grid.states_array()
    steps: list[ContinuationStep] = []
    next_id = 1
    previous: list[Attractor] = []
    for k, v in enumerate(vals):
        here = model.with_params(**{par.name: float(v)})
        extra, origin, seeded = _seeds(previous, seeds)
        states_here = np.concatenate([x, extra]) if extra.size else x
        modes = _start_modes(here, states_here, seeded, start_time(here, s.phase))
        found = find_attractors(
            here,
            states_here,
            settings=s,
            cell_fraction=cell_fraction,
            workers=workers,
            client=client,
            device=device,
            modes=modes,
        )
        # (the cell grid of the first value throughout: distances in the same units)
        cell = steps[0].found.cell if steps else found.cell
        seeded = _votes(origin, found.labels[x.shape[0] :])
        matched = match(previous, found.attractors, cell, threshold, seeded) if previous else {}
        prev_ids = steps[-1].ids if steps else {}
        ids: dict[int, int] = {}
        for a in found.attractors:
            if a.kind is AttractorKind.INVALID:
                ids[a.id] = 0
            elif a.id in matched:
                ids[a.id] = prev_ids[matched[a.id]]
            else:
                ids[a.id] = next_id
                next_id += 1
        steps.append(ContinuationStep(value=float(v), found=found, grid_size=x.shape[0], ids=ids))
        previous = list(found.attractors)
        if progress is not None:
            progress(k + 1, vals.size)
    return to_dataset(model, par.name, grid, steps, time.perf_counter() - start)


def to_dataset(
    model: HybridModel, param: str, grid: Any, steps: Sequence[ContinuationStep], seconds: float
) -> Any:
    """The dataset of :func:`continue_attractors`."""
    import xarray as xr

    shown = [
        [a for a in st.found.attractors if not a.kind.outcome or st.fractions()[st.ids[a.id]] > 0]
        for st in steps
    ]  # (an outcome of seeds alone, off the grid, is no attractor: left out)
    followed = sorted({st.ids[a.id] for st, atts in zip(steps, shown) for a in atts})
    col = {g: j for j, g in enumerate(followed)}
    nv, na, n = len(steps), len(followed), model.n_states
    fraction = np.zeros((nv, na))
    present = np.zeros((nv, na), dtype=bool)
    kind = np.full((nv, na), "", dtype=object)
    period = np.full((nv, na), -1, dtype=np.int32)
    impacts = np.full((nv, na), np.nan)
    lyap = np.full((nv, na), np.nan)
    longest = max([min(len(a.points), KEPT_POINTS) for atts in shown for a in atts] + [1])
    points = np.full((nv, na, longest, n), np.nan)
    modes = np.full((nv, na, longest), "", dtype=object)
    labels = np.zeros((nv, *grid.shape), dtype=np.int32)
    for i, st in enumerate(steps):
        fr = st.fractions()
        for a in shown[i]:
            j = col[st.ids[a.id]]
            present[i, j] = True
            fraction[i, j] = fr[st.ids[a.id]]
            kind[i, j] = str(a.kind)
            period[i, j] = a.period
            impacts[i, j] = a.impacts_per_period
            lyap[i, j] = a.lyapunov
            pts = _few(a.points, KEPT_POINTS)
            points[i, j, : len(pts)] = pts
            if len(a.modes) == len(a.points):
                kept = _few(np.asarray(a.modes), KEPT_POINTS)
                modes[i, j, : len(kept)] = kept
        table = np.zeros(max(st.ids) + 1, dtype=np.int32)
        for local, g in st.ids.items():
            table[local] = g
        labels[i] = table[st.found.labels[: st.grid_size]].reshape(grid.shape)
    names = model.state_names
    i0, j0 = grid.states
    ds = xr.Dataset(
        {
            "fraction": (("value", "attractor"), fraction),
            "present": (("value", "attractor"), present),
            "kind": (("value", "attractor"), kind.astype(str)),
            "period": (("value", "attractor"), period),
            "impacts_per_period": (("value", "attractor"), impacts),
            "lyapunov": (("value", "attractor"), lyap),
            "points": (("value", "attractor", "point", "component"), points),
            "label": (("value", "y", "x"), labels),
        },
        coords={
            "value": ("value", np.array([st.value for st in steps])),
            "attractor": ("attractor", np.array(followed, dtype=np.int32)),
            "x": ("x", grid.x),
            "y": ("y", grid.y),
            "component": ("component", list(names)),
        },
    )
    if model.has_modes:
        ds["modes"] = (("value", "attractor", "point"), modes.astype(str))
        ds["modes"].attrs["description"] = "the mode at each of the points ('': not known, or padding)"
    p = model.parameter(param)
    ds["value"].attrs.update({"long_name": p.description or param, "symbol": p.label, "units": p.unit,
                              "angle": int(p.angle)})  # fmt: skip
    labels_, units = model.state_labels, model.state_units
    ds["x"].attrs.update({"long_name": names[i0], "symbol": labels_[i0], "units": units[i0] if units else ""})
    ds["y"].attrs.update({"long_name": names[j0], "symbol": labels_[j0], "units": units[j0] if units else ""})
    first = steps[0].found
    ds.attrs.update(
        {
            "model": model.name,
            "param": param,
            "params": json.dumps({k: v for k, v in model.params.items() if k != param}),
            "states": f"{names[i0]},{names[j0]}",
            "initial_state": json.dumps(list(grid.base)),
            "phase": grid.phase,
            "transient": first.transient,
            "periods": first.periods,
            "cell": json.dumps(first.cell.tolist()),
            "state_labels": json.dumps(list(labels_)),
            "state_units": json.dumps(list(units)),
            "seconds": seconds,
        }
    )
    return ds
