"""What the explorer shows (:class:`View`) and its brute-force diagram (:class:`Diagram`).

A view is a model with one or two parameters over ranges; its diagram is a sweep of
:mod:`grazing.sweeps` (one parameter: stroboscopic samples, period and impacts per
point; two: a period map), the same computation as ``grazing sweep`` and
``grazing map``.  A computation is stopped between chunks when its ``cancelled``
callable says so (:class:`SupersededError`): a newer request of the page replaced it.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from grazing.core.model import HybridModel, Parameter
from grazing.core.options import SweepSettings
from grazing.core.solution import Status
from grazing.errors import GrazingError, InvalidParameterError
from grazing.explore.source import ModelSource

__all__ = [
    "DEFAULT_NUM",
    "DIAGRAM_SETTINGS",
    "Axis",
    "Diagram",
    "SupersededError",
    "View",
    "compute_diagram",
]

DEFAULT_NUM = {1: 200, 2: 40}
"""Points per parameter of a diagram (a modest resolution: a second or a few on two cores)."""

DIAGRAM_SETTINGS = SweepSettings(lyapunov=False, chunk_size=25)
"""How the diagram's points are computed: ``grazing sweep``'s defaults (transient 500, 100 sampled
periods, one carried chain), without the Lyapunov exponents (not shown), in chunks of 25 points
(the steps of the progress bar; the chain's result does not depend on them)."""


class SupersededError(GrazingError):
    """A computation stopped because a newer request of the page replaced it.

    Examples
    --------
    A computation whose ``cancelled()`` says so stops at its next checkpoint:

    >>> import math, grazing
    >>> view = View.of(grazing.models.pendulum("B"), {"eta": (0.44, 0.46)}, num=5)
    >>> compute_diagram(view, workers=1, cancelled=lambda: True)
    Traceback (most recent call last):
    ...
    grazing.explore.diagram.SupersededError: replaced by a newer request
    """


DiagramProgress = Callable[[int, int], None]
"""Called as ``progress(points_done, points_total)``."""
IsCancelled = Callable[[], bool]


def checkpoint(cancelled: IsCancelled | None) -> None:
    """Raise :class:`SupersededError` when ``cancelled()`` says so."""
    if cancelled is not None and cancelled():
        raise SupersededError("replaced by a newer request")


def check_display(par: Parameter, value: float) -> None:
    """:meth:`Parameter.check` with the message in the display unit (degrees for an angle).

    Examples
    --------
    >>> stop = Parameter("theta_hat", 0.7, lower=-math.pi, upper=math.pi, lower_open=True, upper_open=True,
    ...                  description="stop angle", unit="rad", angle=True)
    >>> check_display(stop, math.radians(200))
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: theta_hat = 200 deg is outside (-180, 180) deg (stop angle)
    """
    try:
        par.check(value)
    except InvalidParameterError:
        if not par.angle:
            raise
        lo = "(" if par.lower_open or math.isinf(par.lower) else "["
        hi = ")" if par.upper_open or math.isinf(par.upper) else "]"
        what = f" ({par.description})" if par.description else ""
        interval = f"{lo}{par.to_display(par.lower):g}, {par.to_display(par.upper):g}{hi} {par.display_unit}"
        raise InvalidParameterError(f"{par.show(value, 'g')} is outside {interval}{what}") from None


@dataclass(frozen=True)
class Axis:
    """One explored parameter and the range of its diagram, in the model's units.

    Parameters
    ----------
    name
        The parameter's name.
    lo, hi
        Its range, in the model's units (radians for angles).
    num
        Values computed over the range.

    Examples
    --------
    >>> Axis("eta", 0.44, 0.49, 6).values().round(3).tolist()
    [0.44, 0.45, 0.46, 0.47, 0.48, 0.49]
    """

    name: str
    lo: float
    hi: float
    num: int

    def values(self) -> np.ndarray:
        return np.linspace(self.lo, self.hi, self.num)

    def contains(self, value: float) -> bool:
        """Inside the computed range (to a millionth of its width)."""
        slack = 1e-6 * (self.hi - self.lo)
        return self.lo - slack <= value <= self.hi + slack


@dataclass(frozen=True)
class View:
    """A model and the parameters explored, each over its range.

    Attributes
    ----------
    model
        The model, its other parameters set.
    axes
        One :class:`Axis` (a bifurcation diagram) or two (a period map: the first
        horizontal, the second vertical).
    source
        How the model is made (for "copy as code").
    settings
        How each point of the diagram is computed.
    component
        The state shown on a bifurcation diagram's vertical axis (index).

    Raises
    ------
    InvalidParameterError
        An unknown or repeated parameter, an empty range, a range end outside the
        parameter's interval, fewer than 2 points.

    Examples
    --------
    :meth:`View.of` takes the ranges in display units (degrees for angles):

    >>> import math, grazing
    >>> view = View.of(grazing.models.pendulum("B"), {"eta": (0.44, 0.46), "theta_hat": (38, 42)}, num=3)
    >>> view.names, [round(math.degrees(v), 6) for v in view.axes[1].values()]
    (('eta', 'theta_hat'), [38.0, 40.0, 42.0])
    >>> View.of(grazing.models.pendulum("B"), {"eta": (0.46, 0.44)})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: the range of eta must be finite and increasing, got ...
    """

    model: HybridModel
    axes: tuple[Axis, ...]
    source: ModelSource = field(default_factory=ModelSource)
    settings: SweepSettings = DIAGRAM_SETTINGS
    component: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "axes", tuple(self.axes))
        if len(self.axes) not in (1, 2):
            raise InvalidParameterError(f"a view has one or two parameters, got {len(self.axes)}")
        names = [a.name for a in self.axes]
        if len(set(names)) != len(names):
            raise InvalidParameterError(f"the two parameters must differ, got {names[0]} twice")
        for a in self.axes:
            par = self.model.parameter(a.name)
            if not (math.isfinite(a.lo) and math.isfinite(a.hi) and a.lo < a.hi):
                raise InvalidParameterError(
                    f"the range of {a.name} must be finite and increasing, got {par.show_range(a.lo, a.hi)}"
                )
            if int(a.num) != a.num or a.num < 2:
                raise InvalidParameterError(f"a diagram needs at least 2 values of {a.name}, got {a.num}")
            for v in (a.lo, a.hi):
                check_display(par, v)
                self.model.with_params(**{a.name: v})  # (and the forcing period there is positive)
        if not 0 <= self.component < self.model.n_states:
            raise InvalidParameterError(f"no state {self.component} in model {self.model.name}")

    @classmethod
    def of(
        cls,
        model: HybridModel,
        ranges: dict[str, tuple[float, float]],
        *,
        num: int | None = None,
        source: ModelSource | None = None,
        component: int | str = 0,
    ) -> View:
        """A view from ``{name: (lo, hi)}`` in display units (degrees for angles)."""
        axes = []
        for name, (lo, hi) in ranges.items():
            par = model.parameter(name)
            n = num or DEFAULT_NUM[len(ranges)]
            axes.append(Axis(name, par.from_display(lo), par.from_display(hi), n))
        index = model.state_names.index(component) if isinstance(component, str) else component
        return cls(model, tuple(axes), source or ModelSource.of(model), component=index)

    def parameter(self, i: int = 0) -> Parameter:
        return self.model.parameter(self.axes[i].name)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.axes)

    def zoomed(self, lo: float, hi: float, lo2: float | None = None, hi2: float | None = None) -> View:
        """The same view with the first parameter over ``[lo, hi]`` (model units), as many points;
        on a map also the second over ``[lo2, hi2]`` (given)."""
        a = self.axes[0]
        axes = [Axis(a.name, lo, hi, a.num), *self.axes[1:]]
        if lo2 is not None and hi2 is not None and len(axes) == 2:
            b = self.axes[1]
            axes[1] = Axis(b.name, lo2, hi2, b.num)
        return dataclasses.replace(self, axes=tuple(axes))

    def at(self, values: Sequence[float]) -> HybridModel:
        """The model at the explored parameters' ``values`` (model units), each checked."""
        return self.model.with_params(**dict(zip(self.names, (float(v) for v in values))))


@dataclass(frozen=True)
class Diagram:
    """A computed view: per point (one parameter) or cell (two), in increasing parameter order.

    Attributes
    ----------
    view
        What was computed.
    values
        Each parameter's values (model units).
    period, impacts_per_period, status
        Detected period (0: none <= 64, -1: failed), impacts per period of it, and
        the :class:`~grazing.core.solution.Status` code; shape ``(n,)`` or ``(n2, n1)``.
    x_final
        The state each point ended in (the start of a click's simulation there).
    samples
        One parameter: the stroboscopic samples, ``(n, periods, n_states)``; else None.
    elapsed
        Seconds it took.

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> d = compute_diagram(View.of(m, {"eta": (0.44, 0.45)}, num=5), workers=1)
    >>> d.values[0].tolist(), d.period.tolist(), d.samples.shape
    ([0.44, 0.4425, 0.445, 0.4475, 0.45], [1, 1, 1, 4, 0], (5, 100, 2))
    >>> d.nearest([0.4474])
    (3,)
    """

    view: View
    values: tuple[np.ndarray, ...]
    period: np.ndarray
    impacts_per_period: np.ndarray
    status: np.ndarray
    x_final: np.ndarray
    samples: np.ndarray | None
    elapsed: float

    def check_inside(self, values: Sequence[float]) -> None:
        """Raise :class:`InvalidParameterError` for a point outside the computed ranges (one line)."""
        for a, v in zip(self.view.axes, values):
            if not a.contains(v):
                par = self.view.model.parameter(a.name)
                raise InvalidParameterError(
                    f"{par.show(v, '.6g')} is outside the computed range {par.show_range(a.lo, a.hi)}: "
                    "click inside the diagram"
                )

    def nearest(self, values: Sequence[float]) -> tuple[int, ...]:
        """The index of the computed point nearest to ``values`` (in each parameter)."""
        index = tuple(int(np.argmin(np.abs(vals - v))) for vals, v in zip(self.values, values))
        return index if len(index) == 1 else index[::-1]  # (a map's arrays are (n2, n1))

    def start_state(self, values: Sequence[float]) -> np.ndarray:
        """Where a simulation at ``values`` starts: the final state of the nearest point that did not fail.

        The diagram's points are one chain, so this is the attractor the diagram shows
        there; zero (rest) when every point failed.
        """
        ok = self.status == Status.OK
        if not ok.any():
            return np.zeros(self.view.model.n_states)
        index = self.nearest(values)
        if ok[index]:
            return self.x_final[index].copy()
        grids = np.meshgrid(*self.values, indexing="xy") if len(self.values) == 2 else [self.values[0]]
        dist = sum(((g - v) / (a.hi - a.lo)) ** 2 for g, v, a in zip(grids, values, self.view.axes))
        dist = np.where(ok, dist, np.inf)
        return self.x_final[np.unravel_index(int(np.argmin(dist)), dist.shape)].copy()


def compute_diagram(
    view: View,
    *,
    progress: DiagramProgress | None = None,
    cancelled: IsCancelled | None = None,
    workers: int | None = None,
) -> Diagram:
    """Compute a view's diagram with :func:`grazing.sweeps.sweep` or :func:`~grazing.sweeps.parameter_map`.

    Parameters
    ----------
    view
        What to compute.
    progress
        Called as ``progress(points_done, points_total)`` after each chunk.
    cancelled
        Looked at after each chunk: when it returns True the sweep stops and
        :class:`SupersededError` is raised.
    workers
        Local threads (default: all cores).

    Returns
    -------
    Diagram
        Each point's period, impacts per period, status and final state.

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> d = compute_diagram(View.of(m, {"eta": (0.4455, 0.4462)}, num=3), workers=1)
    >>> d.period.tolist()  # the period-5 window (grazing sweep finds it at 0.445455-0.446306)
    [5, 5, 5]
    """
    from grazing.sweeps import parameter_map, sweep

    def step(done: int, total: int) -> None:
        checkpoint(cancelled)
        if progress is not None:
            progress(done, total)

    t0 = time.perf_counter()
    model, axes = view.model, view.axes
    if len(axes) == 1:
        a = axes[0]
        ds = sweep(model, a.name, a.values(), settings=view.settings, workers=workers, progress=step)
        per = ("point",)
        samples = ds.samples.transpose("point", "sample", "component").values
    else:
        a, b = axes
        settings = dataclasses.replace(view.settings, chunk_size=a.num)  # (one row a chunk, as grazing map)
        ds = parameter_map(
            model, a.name, a.values(), b.name, b.values(), settings=settings, workers=workers, progress=step
        )
        per = (b.name, a.name)
        samples = None
    checkpoint(cancelled)
    return Diagram(
        view=view,
        values=tuple(np.asarray(ds[a.name].values, dtype=float) for a in axes),
        period=ds.period.transpose(*per).values,
        impacts_per_period=ds.impacts_per_period.transpose(*per).values,
        status=ds.status.transpose(*per).values,
        x_final=ds.x_final.transpose(*per, "component").values,
        samples=samples,
        elapsed=time.perf_counter() - t0,
    )
