"""Options of the analyses, grouped into small frozen objects, and every default once.

As diffrax groups what to save in ``SaveAt`` and BifurcationKit groups
continuation settings in ``ContinuationPar``, a simulation takes three
objects: :class:`SaveAt` (what to record), :class:`Tangent` (which tangent
dynamics to integrate) and :class:`Solver` (integrator settings); a sweep takes
a :class:`SweepSettings`.  Each validates its fields when it is made, so an
invalid value is refused once, with one clear message, wherever it comes from.
The module-level constants are the defaults, named once for the whole package.

Examples
--------
>>> SaveAt(periods=20, transient=400).periods
20
>>> Solver(tol=0.5)
Traceback (most recent call last):
...
grazing.errors.InvalidParameterError: tol must be in (0, 0.01), got 0.5
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields, replace
from typing import Any, Literal, TypeVar

from grazing.errors import InvalidParameterError

MACHINE_EPSILON = 2.220446049250313e-16
"""Unit roundoff of a double, the integrator's default local error tolerance."""

SWEEP_TOL = 1e-10
"""Local error tolerance of sweeps: far below the 1e-6 of period detection."""

CHATTER_TOL = 1e-9
"""A chattering sequence whose remaining duration is below this fraction of the forcing
period is summed in closed form and continued as sticking."""

STEPS_PER_PERIOD = 20000
"""The integrator's default step limit grows by this many steps per forcing period (:func:`step_limit`)."""

STEPS_EXTRA = 100_000
"""The integrator's default step limit for no forcing period at all (:func:`step_limit`)."""

NEWTON_TOL = 1e-11
"""Periodic orbits: Newton's method stops when ``max |P^n(x) - x|`` is below this."""

CORRECTOR_TOL = 1e-10
"""Continuation (branches and curves): the corrector accepts a point when the largest of its
equations' residuals is below this (:class:`~grazing.orbits.palc.PalcSettings` ``tol``)."""

LOCATE_TOL = 1e-9
"""Continuation: a special point is located where its test function is below this (absolute;
:class:`~grazing.orbits.palc.PalcSettings` ``locate_tol``).  The test functions come from corrected
points, known to about :data:`CORRECTOR_TOL`: ten times that is as close to zero as their sign is sure."""

BOUNDARY_TOL = 1e-10
"""Continuation: a boundary of a branch (a grazing, an orbit sticking) is bracketed until the followed
component (the continued parameter) differs by at most this across it (relative to ``max(1, |value|)``;
:class:`~grazing.orbits.palc.PalcSettings` ``boundary_tol``): the corrector's :data:`CORRECTOR_TOL`,
below which the two corrected points are not told apart."""

MAX_STEP = 0.04
"""Continuation's largest step (:class:`~grazing.orbits.palc.PalcSettings` ``ds_max``; ``--max-step``)."""

GRAZING_CURVE_MAX_STEP = 0.05
"""The largest step of a grazing curve followed in two parameters from the nonimpacting orbits
(:func:`~grazing.orbits.grazing_curve`, ``grazing graze-curve --max-step``; its first step is 0.02): the
curve of the paper's figure 7, smooth at this scale up to its fold in the stop angle."""

DEFAULT_TRANSIENT = 500
"""Forcing periods run before sampling where none is given: a periodic orbit's guess simulated from rest
(:func:`~grazing.orbits.find_orbit`), a sweep's points (:class:`SweepSettings`), and the ``--transient``
of ``simulate``, ``orbit``, ``synthesize``, ``sweep`` and ``map``."""

UNIT_CIRCLE_TOL = 1e-9
"""A Floquet multiplier within this of the unit circle is on it (neither stable nor unstable): the
multipliers of an area-preserving map (a conservative model: no damping, elastic impacts) lie on the
circle up to rounding (measured: 2e-16), which would make such an orbit stable or unstable by chance."""

NON_ISOLATED_TOL = 1e-6
"""A periodic orbit is not isolated where its multiplier 1 is double (or more): two multipliers within
this of 1, or two kept directions (:data:`NOT_ISOLATED_TOL`).  That is a Jordan block
(``M = [[1, T], [0, 1]]`` on a free mass at rest: a line of periodic states, and states off it drift),
computed to a split of about ``sqrt(eps T)`` (3e-8 for T = 5), or an eigenspace (``M = I``).  An
absolute tolerance: near a grazing, where the monodromy is far from normal (``|M| = 4e5``), any
tolerance that grows with ``|M|`` (as the singular values of ``(M - I)^2`` do, ``1e-3`` there with no
multiplier within 0.1 of 1) calls folds there not isolated."""

NOT_ISOLATED_TOL = 1e-8
"""A periodic orbit is not isolated where its monodromy matrix ``M`` keeps two or more directions:
``M - I`` has two or more singular values below this (relative to ``1 + |M|``).  Every state near it
is then periodic too (the undamped linear oscillator forced at a rational multiple of its own
frequency: ``M = I``), and no curve of orbits through it can be followed."""

NEWTON_MAX_ITER = 30
"""Periodic orbits: the largest number of Newton iterations."""

PERIOD_TOL = 1e-6
"""Stroboscopic samples are p-periodic when they repeat to this tolerance, relative to their scale
``max(1, max |s|)`` (:func:`grazing.core.period.sample_scale`): the engine's error is relative to that
scale (its steps are sized by it), so a model in other units has the same periods.  An orbit of
amplitude 1.3e5 repeated only to 5e-6 (the error of the adaptive steps, 1e-10 of its size, changes
from one forcing period to the next) and was called aperiodic against an absolute 1e-6."""

MAX_PERIOD = 64
"""The largest period detected on computed samples."""

MAX_PERIOD_NOISY = 32
"""The largest period detected on recorded (noisy) samples: a recording of ~100 forcing
cycles shows a longer period fewer than three times."""

CHUNK_SIZE = 50
"""Points per chunk of a one-parameter sweep: the unit of parallel work and of saving."""

ADAPTIVE_TOL = 1e-9
"""A sweep's adaptive transient ends once the samples repeat to this (with a period of at most
:data:`ADAPTIVE_MAX_PERIOD`)."""

ADAPTIVE_BLOCK = 32
"""An adaptive transient is run in blocks of this many forcing periods, checked after each."""

ADAPTIVE_MAX_PERIOD = 16
"""The longest period with which an adaptive transient's samples may repeat to end it."""

LYAPUNOV_ALIGN = 16
"""With Lyapunov exponents, the last forcing periods of the transient (at most this many) align the
tangent vectors before the exponent is taken over the sampled periods."""

BASIN_ADAPTIVE_TOL = 1e-7
"""The same for the initial states of a basin: their orbits are told apart to 1e-3 cells, and recognised
periodic to 1e-6."""

CELLS = 64
"""Cells along each side of the grid box on which the points of aperiodic attractors are recorded
(the size of a cell is the box's extent over this)."""

CHAIN_TOL = PERIOD_TOL
"""A chunk of a sweep computed from a guess is kept when its first point ends on the periodic orbit,
at the same point of it, as from the chain's state: samples and final state equal to this."""

CHAIN_CELLS = CELLS
"""A chunk of a sweep computed from a guess is kept when its first point ends aperiodic, on the attractor
it ends on from the chain's state: both runs' samples share a cell of a grid of this many cells along
each side of their joint box (:func:`grazing.core.cells.one_attractor`).  On a chaotic attractor only
the attractor is reproducible, not the samples (any rounding difference moves them after a few periods),
so the basins' rule decides, on their default grid: two sets farther apart than 1/64 of their joint
extent are told apart.  Two runs on one chaotic attractor share tens of cells (the pendulum's band at
40 deg, 100 samples each: 14 or more); too few samples to share one make the check fail, and the chunk
is run again: a slower answer, not another one."""

CHAIN_SHIFTS = 8
"""A chunk of a sweep whose guess's first point ends on a periodic orbit of period 2 to this, and from
the chain's state on that orbit at another point of it, is computed from the point of the orbit from
which its first point ends where the chain's state does (from the guess alone: it stands for any start
that leads there), and kept (a guess ends at the chain's point of a period-p orbit only one time in p)."""

CHAOS_THRESHOLD = 1e-3
"""Largest Lyapunov exponent (per unit time) above which an aperiodic run counts as chaotic; within
it of zero, quasi-periodic."""

BASIN_TRANSIENT = 300
"""Forcing periods run from each initial state of a basin before its attractor is sampled."""

BASIN_PERIODS = 50
"""Forcing periods sampled on the attractor each initial state of a basin ends on."""

BASIN_CHUNK = 512
"""Initial states per chunk of a basin computation: the unit of parallel work and of saving."""

MATCH_TOL = 1e-3
"""Two periodic orbits are one attractor when each point of one is within this many cells of a point
of the other (a periodic orbit's samples repeat to 1e-6)."""

BASIN_REFINE = 1
"""Times an initial state whose end state is aperiodic is run on for another transient before it is
classified (a chaotic transient, or one slow to settle, then ends on its attractor)."""

BASIN_CLOSING_ROUNDS = 4
"""Times, after the ``refine`` runs, an end state still closing in on a shorter period than the one it
repeats with (a period-1 orbit with a multiplier near -1 looks period-2 long before it is period 1),
yet beyond a match of it, is run on for another transient before it is classified (then, still so,
it keeps the period it repeats with)."""

CLOSING_RATIO = 0.8
"""Samples repeating with period p are closing in on a divisor d of it where the differences
``|x[k + d] - x[k]|`` of their last p samples are under this fraction of those of their first p (on a
p-periodic orbit they are the same, to rounding).  0.5 missed a period-2 orbit with complex
multipliers of modulus 0.975, whose samples repeated with period 4 to the detector's tolerance after
200 periods (the differences shrank by 0.49 to 0.51 over 32 samples; found by hypothesis)."""

ESCAPE_FACTOR = 1e6
"""A state farther than this many times the grid box's extent from the box has escaped."""

CELL_FRACTION = 0.05
"""The recurrence cell of an aperiodic attractor (chaotic, quasi-periodic), per state component: this
fraction of the attractor's own extent (as Attractors.jl sizes its recurrence cells from the
attractor), never less than the grid's cell.  Two aperiodic end states are one attractor when their
samples come within one such cell.  Sized from the grid box instead (``box / CELLS``), one chaotic
attractor of the impact damper larger than a small box was split into 65 "attractors"."""

POLISH_RATIO = 0.99
"""A run's samples contract towards a period-p cycle where the largest difference ``|x[k + p] - x[k]|``
falls from quarter to quarter of its samples and over the last quarter is under this fraction of that
over the first (an orbit with a multiplier of modulus 0.9968 shrinks them by 0.88 over 38 samples)."""

POLISH_CANDIDATES = 2
"""Periods (the shortest whose differences contract) tried by Newton's method per run."""

POLISH_MAX_ITER = 6
"""Newton iterations of a run's polish: from a run contracting towards a cycle it converges in a few;
one that does not is not that cycle's."""

POLISH_TRIES = 3
"""Failed Newton polishes per aperiodic attractor of a basin computation: past them its other end states
(on a chaotic set or a torus) are not tried."""

IMPACTS = ("none", "sampled", "all")
"""What :class:`SaveAt` can record of the impacts."""

_Opt = TypeVar("_Opt")


def _count(name: str, value: Any, minimum: int) -> int:
    if isinstance(value, bool) or (not isinstance(value, int) and not hasattr(value, "__index__")):
        raise InvalidParameterError(f"{name} must be an integer, got {value!r}")
    value = int(value)
    if value < minimum:
        raise InvalidParameterError(f"{name} must be >= {minimum}, got {value}")
    return value


def _finite(name: str, value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"{name} must be a finite number, got {value!r}") from None
    if isinstance(value, bool) or not math.isfinite(v):
        raise InvalidParameterError(f"{name} must be a finite number, got {value!r}")
    return v


def _tolerance(name: str, value: Any) -> float:
    v = _finite(name, value)
    if not 0 < v < 1e-2:
        raise InvalidParameterError(f"{name} must be in (0, 0.01), got {v:g}")
    return v


def _set(obj: Any, name: str, value: Any) -> None:
    object.__setattr__(obj, name, value)


@dataclass(frozen=True)
class SaveAt:
    """What a simulation records.

    Attributes
    ----------
    periods
        Forcing periods sampled (stroboscopic samples kept), at least 1.
    transient
        Forcing periods run first and discarded.
    phase
        Stroboscopic phase ``phi`` in radians: samples at ``t = (phi/2pi + k) T``.
    trajectory
        If positive, the dense trajectory over the sampled span with this many
        points per forcing period (plus both states at each impact).
    impacts
        Which impacts to record: the ``"sampled"`` span, ``"all"`` or ``"none"``.
    guard_min
        Track the smallest guard value over the sampled span and the closest
        approach to the stop away from contacts.

    Examples
    --------
    Ten stroboscopic samples after 400 periods, and the dense trajectory over
    them at 50 points per period (505 rows: both states at each impact added):

    >>> import math, grazing
    >>> model = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> save = SaveAt(periods=10, transient=400, trajectory=50)
    >>> sol = grazing.simulate(model, [0.0, 0.0], save=save)
    >>> sol.samples.shape, sol.trajectory.shape, sol.period()
    ((10, 2), (505, 2), 5)

    The same fields are keywords of :func:`grazing.simulate`
    (``simulate(model, x0, periods=10, transient=400)``); a bad value is
    refused when the object is made:

    >>> SaveAt(periods=0)
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: periods must be >= 1, got 0
    """

    periods: int = 100
    transient: int = 0
    phase: float = 0.0
    trajectory: int = 0
    impacts: Literal["none", "sampled", "all"] = "sampled"
    guard_min: bool = False

    def __post_init__(self) -> None:
        _set(self, "periods", _count("periods", self.periods, 1))
        _set(self, "transient", _count("transient", self.transient, 0))
        _set(self, "trajectory", _count("trajectory", self.trajectory, 0))
        _set(self, "phase", _finite("phase", self.phase))
        if self.impacts not in IMPACTS:
            raise InvalidParameterError(f"impacts must be one of {sorted(IMPACTS)}, got {self.impacts!r}")
        _set(self, "guard_min", bool(self.guard_min))


@dataclass(frozen=True)
class Tangent:
    """Which tangent dynamics a simulation integrates alongside the state.

    Attributes
    ----------
    jacobian
        The variational equations (saltation matrices at impacts): ``d x_final / d x0``.
    sensitivities
        Parameter names whose derivatives ``d x_final / d p`` are appended as
        extra Jacobian columns (implies ``jacobian``).
    lyapunov
        The Lyapunov exponents over the sampled span (cannot be combined with
        the Jacobian in one run).

    Examples
    --------
    The Jacobian of the final state with respect to the initial one, with a
    column for the derivative with respect to ``eta`` appended:

    >>> import math, grazing
    >>> model = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> sol = grazing.simulate(model, [0.0, 0.0], transient=400, periods=10,
    ...                        tangent=Tangent(sensitivities=("eta",)))
    >>> sol.jacobian.shape, sol.jacobian_valid
    ((2, 3), True)

    On the stable period-5 orbit both Lyapunov exponents are negative:

    >>> sol = grazing.simulate(model, [0.0, 0.0], transient=400, periods=50, tangent=Tangent(lyapunov=True))
    >>> bool((sol.lyapunov < 0).all())
    True
    >>> Tangent(jacobian=True, lyapunov=True)
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: lyapunov and jacobian/sensitivities cannot be combined in one run
    """

    jacobian: bool = False
    sensitivities: tuple[str, ...] = ()
    lyapunov: bool = False

    def __post_init__(self) -> None:
        sens = (self.sensitivities,) if isinstance(self.sensitivities, str) else tuple(self.sensitivities)
        _set(self, "sensitivities", sens)
        _set(self, "jacobian", bool(self.jacobian or sens))
        if self.lyapunov and self.jacobian:
            raise InvalidParameterError("lyapunov and jacobian/sensitivities cannot be combined in one run")

    @property
    def variational(self) -> bool:
        """True when the variational equations are integrated."""
        return self.jacobian or self.lyapunov


def step_limit(periods: int) -> int:
    """The default step limit of a run over ``periods`` forcing periods.

    Examples
    --------
    >>> step_limit(10)
    300000
    """
    return STEPS_PER_PERIOD * periods + STEPS_EXTRA


@dataclass(frozen=True)
class Solver:
    """Settings of the Taylor integrator.

    Attributes
    ----------
    tol
        Local error tolerance in (0, 0.01); sets the Taylor order (20 at the
        default, machine epsilon) and the step.
    max_steps
        Abort after this many steps (default: :func:`step_limit` of the periods run,
        transient included: ``20000 * periods + 100000``).
    chatter_tol
        A chattering sequence whose remaining duration is below this fraction
        of the period is summed to its accumulation point and continued as
        sticking.

    Examples
    --------
    A looser tolerance takes a lower Taylor order (:attr:`Solution.info`
    says which); the samples agree to about that tolerance:

    >>> import math, numpy as np, grazing
    >>> model = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> exact = grazing.simulate(model, [0.0, 0.0], transient=400, periods=10)
    >>> loose = grazing.simulate(model, [0.0, 0.0], transient=400, periods=10, solver=Solver(tol=1e-12))
    >>> exact.info["order"], loose.info["order"], bool(np.abs(loose.samples - exact.samples).max() < 1e-9)
    (20, 15, True)

    A run that needs more steps than ``max_steps`` stops with one line:

    >>> grazing.simulate(model, [0.0, 0.0], periods=10, solver=Solver(max_steps=100))
    Traceback (most recent call last):
    ...
    grazing.errors.SimulationError: step limit of 100 steps reached at t = 46.1425
    """

    tol: float = MACHINE_EPSILON
    max_steps: int | None = None
    chatter_tol: float = CHATTER_TOL

    def __post_init__(self) -> None:
        _set(self, "tol", _tolerance("tol", self.tol))
        if self.max_steps is not None:
            _set(self, "max_steps", _count("max_steps", self.max_steps, 1))
        chatter = _finite("chatter_tol", self.chatter_tol)
        if chatter < 0:
            raise InvalidParameterError(f"chatter_tol must be >= 0, got {chatter:g}")
        _set(self, "chatter_tol", chatter)


@dataclass(frozen=True)
class SweepSettings:
    """How every point of a sweep is computed.

    Attributes
    ----------
    transient, periods
        Forcing periods discarded and sampled at each point.
    phase
        Stroboscopic phase in radians.
    fresh
        Start every point from the initial state instead of the previous
        point's final state (the experimenter's sweep).
    chunk_size
        Points per chunk, the unit of parallel work and of saving (0: one chunk).
    adaptive
        Stop transients early once the samples are periodic.
    lyapunov
        Compute the largest Lyapunov exponent (per unit time).
    tol
        Local error tolerance of the integrator.

    Examples
    --------
    The defaults, and a short sweep across the paper's first grazing at
    θ̂ = 40°: period 1 free of the stop, then period 4 and chaos past it:

    >>> SweepSettings()  # doctest: +NORMALIZE_WHITESPACE
    SweepSettings(transient=500, periods=100, phase=0.0, fresh=False, chunk_size=50,
                  adaptive=True, lyapunov=True, tol=1e-10)
    >>> import math, numpy as np, grazing
    >>> from grazing.sweeps import sweep
    >>> model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> settings = SweepSettings(transient=300, periods=40, lyapunov=False)
    >>> ds = sweep(model, "eta", np.linspace(0.44, 0.45, 5), settings=settings, workers=1)
    >>> ds.period.values.tolist(), ds.impacts_per_period.values[:3].tolist()
    ([1, 1, 1, 4, 0], [0.0, 0.0, 0.0])
    """

    transient: int = DEFAULT_TRANSIENT
    periods: int = 100
    phase: float = 0.0
    fresh: bool = False
    chunk_size: int = CHUNK_SIZE
    adaptive: bool = True
    lyapunov: bool = True
    tol: float = SWEEP_TOL

    def __post_init__(self) -> None:
        _set(self, "transient", _count("transient", self.transient, 0))
        _set(self, "periods", _count("periods", self.periods, 1))
        _set(self, "chunk_size", _count("chunk size", self.chunk_size, 0))
        _set(self, "phase", _finite("phase", self.phase))
        _set(self, "tol", _tolerance("tol", self.tol))


@dataclass(frozen=True)
class BasinSettings:
    """How every initial state of a basin computation is run (:mod:`grazing.attractors`).

    Attributes
    ----------
    transient, periods
        Forcing periods run before sampling, and sampled (at least 2: a period
        is recognised when it repeats twice).
    phase
        Forcing phase of the initial states and of the samples, in radians.
    refine
        Times an initial state whose end state is aperiodic is run on for
        another ``transient`` before it is classified.
    lyapunov
        Compute largest Lyapunov exponents (of the aperiodic end states, which
        they tell chaotic from quasi-periodic, and of one point of each orbit).
    tol
        Local error tolerance of the integrator.
    chunk_size
        Initial states per chunk: the unit of parallel work and of saving.
    """

    transient: int = BASIN_TRANSIENT
    periods: int = BASIN_PERIODS
    phase: float = 0.0
    refine: int = BASIN_REFINE
    lyapunov: bool = True
    tol: float = SWEEP_TOL
    chunk_size: int = BASIN_CHUNK

    def __post_init__(self) -> None:
        _set(self, "transient", _count("transient", self.transient, 0))
        _set(self, "periods", _count("periods", self.periods, 2))
        _set(self, "refine", _count("refine", self.refine, 0))
        _set(self, "chunk_size", _count("chunk size", self.chunk_size, 1))
        _set(self, "phase", _finite("phase", self.phase))
        _set(self, "tol", _tolerance("tol", self.tol))
        _set(self, "lyapunov", bool(self.lyapunov))


def with_shorthands(
    options: _Opt | None, cls: type[_Opt], shorthands: Mapping[str, Any], used: set[str] | None = None
) -> _Opt:
    """``options`` (or the defaults of ``cls``) with the fields named in ``shorthands`` replaced.

    Lets ``simulate(model, periods=20)`` stand for
    ``simulate(model, save=SaveAt(periods=20))``.  The keys taken are added to
    ``used``, so the caller can refuse the ones no option object knows.
    """
    names = {f.name for f in fields(cls)}  # type: ignore[arg-type]
    changes = {k: v for k, v in shorthands.items() if k in names}
    if used is not None:
        used.update(changes)
    base = options if options is not None else cls()
    return replace(base, **changes) if changes else base  # type: ignore[type-var]


def refuse_unknown(function: str, shorthands: Mapping[str, Any], used: Sequence[str] | set[str]) -> None:
    """Raise ``TypeError`` for keyword arguments that no option object took."""
    unknown = sorted(set(shorthands) - set(used))
    if unknown:
        raise TypeError(f"{function}() got unexpected keyword argument(s): {', '.join(unknown)}")
