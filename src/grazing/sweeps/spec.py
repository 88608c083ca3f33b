"""What defines a sweep: :class:`SweepSpec` (the points and how each is computed), :class:`ChunkResult`.

A sweep visits a list of parameter points, grouped in *chunks* of consecutive
points; the spec's description (and its fingerprint) says everything that
determines the result, so that a store can tell whether it holds this sweep.
The builders :func:`sweep_spec` and :func:`map_spec` make the specs of a
one-parameter sweep and of a two-parameter map from parameter values and a
:class:`~grazing.core.options.SweepSettings`; the public functions of
:mod:`grazing.sweeps.api` and the command line both use them.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.options import ADAPTIVE_TOL, CHATTER_TOL, SweepSettings
from grazing.errors import InvalidParameterError

_SETTINGS = SweepSettings()
"""The defaults of a sweep's settings (:class:`~grazing.core.options.SweepSettings`)."""

DiscontinuityMapLike = Any
"""A :class:`grazing.engine.runner.DiscontinuityMap` (typed loosely: the spec does not run anything)."""


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
    segments
        The points are this many chains of equal length, one after the other
        (a two-parameter map: its rows; a sweep up and down: two), each
        starting from ``x0``; no chunk holds points of two chains.
    starts
        With ``fresh``: each point's own initial state (an array of
        ``n_points`` rows), at the sampling phase of its forcing period (a
        grid of initial states, :mod:`grazing.attractors`); None: ``x0`` at
        time 0.
    start_modes
        With ``starts`` on a model with modes: the index of the mode each
        point's initial state is in (:func:`grazing.core.model.mode_of_states`);
        None: the model's initial mode.
    adaptive_tol
        The tolerance to which the samples must repeat for an adaptive transient to end.
    resume
        ``(t, x)``: the first point continues a chain from state ``x`` at time
        ``t`` instead of starting from ``x0`` at time 0 (a chunk run again from
        the final state of the chunk before it, :mod:`grazing.sweeps.chain`);
        after a failed point the chain still starts again from ``x0``.  A
        model with modes: ``(t, x, mode)``, the index of the mode ``x`` is in
        (``x0`` is in :attr:`x0_mode`).
    chatter_tol
        Chattering shorter than this fraction of the forcing period is summed
        to its accumulation point and continued as sticking (as
        :class:`~grazing.core.options.Solver`'s).
    polish
        A point with no period whose samples contract towards a cycle is
        polished by Newton's method (:mod:`grazing.sweeps.polish`): where it
        converges to a stable orbit the samples approach, the point has that
        orbit's period.  (The basins polish their end states themselves.)
    x0_mode
        A model with modes: the index of the mode ``x0`` starts in, the one it
        lies in at the first point (:meth:`~grazing.HybridModel.start_mode`);
        None: the model's initial mode (where ``x0`` lies in its region).

    Examples
    --------
    Made by :func:`sweep_spec` or :func:`map_spec`; a spec is a value (equal
    specs are the same sweep, and a store keeps the one it was made for):

    >>> import math, numpy as np, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> spec = sweep_spec(m, "eta", np.linspace(0.44, 0.45, 5), settings=grazing.SweepSettings(chunk_size=2))
    >>> spec.params, spec.n_points, spec.n_chunks, spec.points[:2]
    (('eta',), 5, 3, ((0.44,), (0.4425,)))
    >>> spec == sweep_spec(m, "eta", np.linspace(0.44, 0.45, 5), settings=grazing.SweepSettings(chunk_size=2))
    True
    """

    model: HybridModel
    params: tuple[str, ...]
    points: tuple[tuple[float, ...], ...]
    x0: tuple[float, ...]
    transient: int = _SETTINGS.transient
    periods: int = _SETTINGS.periods
    phase: float = _SETTINGS.phase
    fresh: bool = _SETTINGS.fresh
    chunk_size: int = _SETTINGS.chunk_size
    adaptive: bool = _SETTINGS.adaptive
    lyapunov: bool = _SETTINGS.lyapunov
    tol: float = _SETTINGS.tol
    shape: tuple[int, ...] = field(default=())
    zdm: DiscontinuityMapLike = None
    segments: int = 1
    starts: Any = field(default=None, compare=False, repr=False)
    start_modes: Any = field(default=None, compare=False, repr=False)
    adaptive_tol: float = ADAPTIVE_TOL
    resume: tuple[float, tuple[float, ...]] | tuple[float, tuple[float, ...], int] | None = None
    chatter_tol: float = CHATTER_TOL
    polish: bool = True
    x0_mode: int | None = None

    def __post_init__(self) -> None:
        if not self.points:
            raise InvalidParameterError("a sweep needs at least one point")
        if self.segments < 1 or len(self.points) % self.segments:
            raise InvalidParameterError(
                f"{len(self.points)} points cannot be {self.segments} chains of equal length"
            )
        if self.starts is not None:
            starts = np.ascontiguousarray(self.starts, dtype=float)
            if not self.fresh or starts.shape != (len(self.points), self.model.n_states):
                raise InvalidParameterError("starts needs a fresh sweep and one initial state per point")
            object.__setattr__(self, "starts", starts)
        if self.start_modes is not None:
            modes = np.ascontiguousarray(self.start_modes, dtype=np.int64)
            real = len(self.model.mode_names) - len(self.model.sliding_modes)
            if (
                self.starts is None
                or modes.shape != (len(self.points),)
                or np.any((modes < 0) | (modes >= real))
            ):
                raise InvalidParameterError(
                    "start_modes needs starts and one mode index of the model per point"
                )
            object.__setattr__(self, "start_modes", modes)
        if self.x0_mode is not None and not 0 <= self.x0_mode < len(self.model.mode_names) - len(
            self.model.sliding_modes
        ):
            raise InvalidParameterError(
                f"x0_mode must be the index of a mode of the model, got {self.x0_mode!r}"
            )
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
    def segment_points(self) -> int:
        """Points per chain (the whole sweep unless it has several ``segments``)."""
        return self.n_points // self.segments

    @property
    def size(self) -> int:
        """Points per chunk."""
        return self.chunk_size or self.segment_points

    @property
    def chunks_per_segment(self) -> int:
        return math.ceil(self.segment_points / self.size)

    @property
    def n_chunks(self) -> int:
        return self.segments * self.chunks_per_segment

    def chunk(self, i: int) -> slice:
        per, n = self.chunks_per_segment, self.segment_points
        seg, j = divmod(i, per)
        return slice(seg * n + j * self.size, seg * n + min((j + 1) * self.size, n))

    def chain_first(self, i: int) -> bool:
        """Whether chunk ``i`` starts a chain (from ``x0``): the first chunk of its segment."""
        return i % self.chunks_per_segment == 0

    @property
    def carried(self) -> bool:
        """Whether each point continues from the previous one (chunks are parts of one chain)."""
        return not self.fresh

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
            "zdm": None
            if self.zdm is None
            else [self.zdm.phase, self.zdm.accel, list(self.zdm.direction), self.zdm.stop],
            "stops": list(self.model.stop_names),
            "store_layout": STORE_LAYOUT,
            "grazing_version": grazing.__version__,
        }
        if not self.fresh:  # (the chunks are one chain, whatever the chunking: grazing.sweeps.chain)
            d["chain"] = True
            d["segments"] = self.segments
        if self.starts is not None:
            d["starts_sha256"] = hashlib.sha256(self.starts.tobytes()).hexdigest()
        if self.start_modes is not None:
            d["start_modes_sha256"] = hashlib.sha256(self.start_modes.tobytes()).hexdigest()
        if self.resume is not None:
            d["resume"] = [self.resume[0], list(self.resume[1]), *self.resume[2:]]
        if self.adaptive_tol != ADAPTIVE_TOL:
            d["adaptive_tol"] = self.adaptive_tol
        if self.chatter_tol != CHATTER_TOL:
            d["chatter_tol"] = self.chatter_tol
        if not self.polish:
            d["polish"] = False
        if self.x0_mode is not None:
            d["x0_mode"] = self.model.mode_names[self.x0_mode]
        return d

    def fingerprint(self) -> str:
        return hashlib.sha256(json.dumps(self.description(), sort_keys=True).encode()).hexdigest()[:16]


DIRECTIONS = ("up", "down", "both")
"""The orders a one-parameter sweep visits its values in (``both``: up, then down, two chains)."""

STORE_LAYOUT = 3
"""The version of what a store holds (2: impacts on each stop, 3: each point's status); a store of
another layout is another sweep."""


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
    status: np.ndarray  # (points,) each point's Status code (grazing.sweeps.status): 0 ok, else why it failed
    impacts_by_stop: np.ndarray | None = None  # (points, n_stops) impacts on each stop in the sampled span
    seconds: float = 0.0
    t_final: np.ndarray | None = None  # (points,) time of x_final (not stored: a chain continues from it)
    mode_final: np.ndarray | None = None  # (points,) the index of the mode x_final is in (-1: failed)


def spec_summary(spec: SweepSpec) -> dict[str, Any]:
    """The spec description plus a fingerprint, for dataset attributes."""
    d = spec.description()
    d["fingerprint"] = spec.fingerprint()
    return d


def _checked_start(
    first: HybridModel, x0: Sequence[float] | None, tol: float
) -> tuple[tuple[float, ...], int | None]:
    """The sweep's start (zeros by default), checked against ``first``'s stops, and on a model with modes
    the index of the mode it starts in where that is not the initial one (the one it lies in:
    :meth:`~grazing.HybridModel.start_mode`; else None).

    The kernels the sweep runs are loaded first: the check evaluates the guards with them
    (``scalar_kernels``) instead of loading a module of the default order as well (about 15 ms of
    every sweep's serial part).
    """
    from grazing.engine.codegen import taylor_order

    first.kernels(0, taylor_order(tol))
    x = np.zeros(first.n_states) if x0 is None else np.asarray(x0, dtype=float)
    mode = first.start_mode(x) if first.has_modes else None
    checked = tuple(float(v) for v in first.check_state(x, mode=mode))
    return checked, (None if mode is None or mode == first.initial_mode else first.mode_index(mode))


def sweep_spec(
    model: HybridModel,
    param: str,
    values: Sequence[float],
    *,
    x0: Sequence[float] | None = None,
    direction: str = "up",
    settings: SweepSettings | None = None,
    zdm: DiscontinuityMapLike = None,
) -> SweepSpec:
    """The spec of a one-parameter sweep of ``param`` over ``values``, visited in ``direction``.

    Parameters
    ----------
    model
        The model, with the values of the parameters not swept.
    param
        The parameter swept.
    values
        Its values (any order: they are visited in ``direction``), finite.
    x0
        Initial state (default: zeros), checked against the guard at the
        first value; on a model with modes it starts in the mode it lies in
        there (:meth:`~grazing.HybridModel.start_mode`).
    direction
        ``"up"``, ``"down"`` or ``"both"``: up, then down from ``x0`` again,
        as two chains (``segments = 2``) of one sweep.
    settings
        How each point is computed (default: :class:`~grazing.core.options.SweepSettings`'s defaults).
    zdm
        Iterate Nordmark's discontinuity map instead of the flow (see :class:`SweepSpec`).

    Returns
    -------
    SweepSpec
        The sweep, to run with :func:`~grazing.sweeps.run_sweep` (or chunk by
        chunk with :func:`~grazing.sweeps.run_chunk`).

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> spec = sweep_spec(m, "eta", [0.45, 0.44, 0.46], direction="both")
    >>> [p[0] for p in spec.points], spec.segments
    ([0.44, 0.45, 0.46, 0.46, 0.45, 0.44], 2)
    >>> sweep_spec(m, "eta", [0.44], direction="sideways")
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: direction must be 'up', 'down' or 'both', got 'sideways'
    """
    s = settings or SweepSettings()
    vals = np.asarray(values, dtype=float)
    if vals.ndim != 1 or vals.size == 0 or not np.all(np.isfinite(vals)):
        raise InvalidParameterError("values must be a non-empty list of finite numbers")
    if direction not in DIRECTIONS:
        raise InvalidParameterError(f"direction must be 'up', 'down' or 'both', got {direction!r}")
    if direction == "both" and s.fresh:
        raise InvalidParameterError(
            "direction 'both' needs a sweep that carries its state (with fresh, every point starts from "
            "x0: both directions are the same)"
        )
    if zdm is not None:
        from grazing.engine.runner import check_map_stop

        check_map_stop(model, int(zdm.stop))
    up = np.sort(vals)
    order = {"up": up, "down": up[::-1], "both": np.concatenate([up, up[::-1]])}[direction]
    first = model.with_params(**{param: float(order[0])}) if param in model.params else model
    start, start_mode = _checked_start(first, x0, s.tol)
    return SweepSpec(
        model=model,
        params=(param,),
        points=tuple((float(v),) for v in order),
        segments=2 if direction == "both" else 1,
        x0=start,
        x0_mode=start_mode,
        transient=s.transient,
        periods=s.periods,
        phase=s.phase,
        fresh=s.fresh,
        chunk_size=s.chunk_size,
        adaptive=s.adaptive,
        lyapunov=s.lyapunov,
        tol=s.tol,
        zdm=zdm,
    )


def map_spec(
    model: HybridModel,
    param1: str,
    values1: Sequence[float],
    param2: str,
    values2: Sequence[float],
    *,
    x0: Sequence[float] | None = None,
    settings: SweepSettings | None = None,
) -> SweepSpec:
    """The spec of a two-parameter map: each row (fixed ``param2``) swept in increasing ``param1``.

    Each row is a chain of its own from ``x0`` (``segments``, unless fresh);
    with ``settings.chunk_size = 0`` (``parameter_map``'s default) one row is one chunk.

    Parameters
    ----------
    model
        The model, with the values of the parameters not swept.
    param1, values1
        The parameter along each row and its values (sorted increasing).
    param2, values2
        The parameter across the rows and its values (sorted increasing).
    x0
        Initial state of every row (default: zeros).
    settings
        How each point is computed (default: ``SweepSettings(chunk_size=0)``).

    Returns
    -------
    SweepSpec
        The map, ``shape = (len(values2), len(values1))``, to run with
        :func:`~grazing.sweeps.run_sweep`.

    Examples
    --------
    >>> import numpy as np, grazing
    >>> m = grazing.models.pendulum("B")
    >>> spec = map_spec(m, "eta", np.linspace(0.40, 0.46, 4), "theta_hat", np.radians([30, 40]))
    >>> spec.shape, spec.n_points, spec.n_chunks, spec.segments
    ((2, 4), 8, 2, 2)
    """
    s = settings or SweepSettings(chunk_size=0)
    v1 = np.sort(np.asarray(values1, dtype=float))
    v2 = np.sort(np.asarray(values2, dtype=float))
    if v1.size == 0 or v2.size == 0:
        raise InvalidParameterError("both parameter lists must be non-empty")
    if not (np.all(np.isfinite(v1)) and np.all(np.isfinite(v2))):
        raise InvalidParameterError("parameter values must be finite numbers")
    known = param1 in model.params and param2 in model.params
    first = model.with_params(**{param1: float(v1[0]), param2: float(v2[0])}) if known else model
    start, start_mode = _checked_start(first, x0, s.tol)
    return SweepSpec(
        model=model,
        params=(param1, param2),
        points=tuple((float(a), float(b)) for b in v2 for a in v1),
        x0=start,
        x0_mode=start_mode,
        transient=s.transient,
        periods=s.periods,
        phase=s.phase,
        fresh=s.fresh,
        chunk_size=s.chunk_size or v1.size,
        adaptive=s.adaptive,
        lyapunov=s.lyapunov,
        tol=s.tol,
        shape=(v2.size, v1.size),
        segments=1 if s.fresh else v2.size,
    )
