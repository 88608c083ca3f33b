"""Grazing of periodic orbits: one-parameter location and two-parameter curves.

A periodic orbit grazes when it touches the stop with zero normal velocity:
``h = 0`` and ``L_f h = 0`` (with ``L_f^2 h > 0``) at some time ``t_g``.

* :func:`find_grazings` follows the period-n *nonimpacting* orbit in one
  parameter (ignoring the stop, so that it can be followed through grazing)
  and locates every parameter value where its minimum guard value is zero.
* :func:`grazing_curve` follows the grazing condition in two parameters.  The
  unknowns are the state ``y`` at the contact, the contact time ``t_g`` and the
  two parameters; the equations are periodicity from the contact,
  ``Phi(y, t_g -> t_g + nT) = y``, and the two contact conditions.  Taking the
  Poincare section through the contact point itself keeps the problem smooth
  and gives the monodromy matrix at the grazing point, which the normal form
  needs.  The curve's turning point in the second parameter is where grazing
  ceases to exist (``theta_hat_max`` for the pendulum).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from grazing.core.model import HybridModel, Parameter
from grazing.core.options import GRAZING_CURVE_MAX_STEP
from grazing.errors import ConvergenceError, GrazingWarning, InvalidParameterError
from grazing.orbits.contact import GrazingPoint, contact_system
from grazing.orbits.continuation import Branch, SpecialPoint, continue_orbit
from grazing.orbits.kinds import SpecialKind
from grazing.orbits.palc import Palc, PalcPoint, PalcSettings, locate, sign_changed


def find_grazings(
    model: HybridModel,
    param: str,
    start: float,
    stop: float,
    *,
    x0: Sequence[float] | np.ndarray | None = None,
    period: int = 1,
    settings: PalcSettings | None = None,
    progress: Callable[[int, float], None] | None = None,
    stop_name: int | str | None = None,
    mode: str | None = None,
) -> tuple[list[GrazingPoint], Branch]:
    """Every grazing of the period-n nonimpacting orbit for ``param`` in ``[start, stop]``.

    The orbit is followed with the stop ignored, through folds, and every zero
    of its minimum guard value is located and refined.  ``x0``: a guess of the
    orbit's state at time 0 with ``param = start``; Newton's method on the
    flow through the stops finds the orbit from it, stable or unstable
    (default: the state after a simulation from rest with the stops ignored,
    which reaches only a stable orbit).  ``stop_name``: for
    models with several stops, the stop whose grazings are sought (name or
    index; the first by default; the branch's special points hold every
    stop's).  A grazing orbit that passes through another stop
    (:attr:`GrazingPoint.crossed`) is not a motion of the system: it is
    returned, with a :class:`~grazing.errors.GrazingWarning`.  A grazing
    bracketed between two points of the branch whose grazing equations do not
    converge is not returned: a :class:`~grazing.errors.GrazingWarning` says
    where (the branch's special points hold it, its ``grazing`` None), and the
    search goes on.

    On a model with modes, for a transition without a reset (a switch of vector
    field), the branch is the orbit itself, followed through its switches of
    mode (no virtual orbit): each grazing of the transition's guard where its
    switches change is located (the orbit of the transition's source mode
    tangent to the guard) and the branch goes on along the orbit with the new
    switches (``switch``); ``stop_name`` names the transition.  For an impact
    (a transition with a reset) the branch is virtual, as for a model of one
    mode: it switches and slides, the impacts are ignored, and the impact's
    guard counts only while the orbit is in its source mode.

    Parameters
    ----------
    model
        The model, with the values of the other parameters.
    param
        The parameter followed.
    start, stop
        The interval of ``param`` searched, from ``start``.
    x0
        A guess of the orbit's state at time 0 with ``param = start``.
    period
        Period of the nonimpacting orbit, in forcing periods.
    settings
        The continuation's settings (:class:`~grazing.orbits.PalcSettings`).
    progress
        Called as ``progress(step, value)`` after each continuation step.
    stop_name
        The stop whose grazings are sought (name or index; the first by default).
    mode
        A model with modes: the mode of ``x0`` (without ``x0``: the mode its simulation from rest
        starts in; see :func:`~grazing.orbits.find_orbit`); the model's initial mode by default.

    Returns
    -------
    grazings, branch
        The grazing points in the order met along the branch, and the branch.

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> points, _ = find_grazings(m, "eta", 0.4, 0.6)
    >>> [round(p.model.params["eta"], 4) for p in points]
    [0.4451, 0.5473]
    """
    watch = model.stop_index(stop_name)
    switching = model.has_modes and not model.transition_resets[watch]  # (an impact's: a virtual orbit)
    branch = continue_orbit(
        model,
        param,
        start,
        stop,
        x0=None if x0 is None else np.asarray(x0, dtype=float),
        period=period,
        virtual=not switching,
        settings=settings,
        detect=(SpecialKind.FOLD, SpecialKind.GRAZING),
        progress=progress,
        stop_name=None if switching else stop_name,
        switch=switching,  # (through modes: the orbit with the new switches past each grazing)
        mode=mode,
    )
    par = model.parameter(param)
    points = []
    for sp_ in branch.special:
        if sp_.kind != SpecialKind.GRAZING:
            continue
        if sp_.stop != watch:
            continue
        if sp_.grazing is None:  # (one unlocated point, said: the search goes on)
            warnings.warn(unlocated_grazing_text(model, param, sp_), GrazingWarning, stacklevel=2)
            continue
        if sp_.grazing.crossed:
            warnings.warn(
                f"the nonimpacting orbit grazing stop {sp_.grazing.stop_name!r} at {par.show(sp_.param)} "
                f"passes through stop(s) {', '.join(map(repr, sp_.grazing.crossed))}: "
                "the system hits those first, so this grazing is not a motion of the system",
                GrazingWarning,
                stacklevel=2,
            )
        points.append(sp_.grazing)
    return points, branch


def unlocated_grazing_text(model: HybridModel, param: str, special: SpecialPoint) -> str:
    """A grazing of ``special`` (a :class:`~grazing.orbits.continuation.SpecialPoint`) bracketed on a branch
    whose grazing equations did not converge, in one line: where, and between which values."""
    par = model.parameter(param)
    where = f"near {par.show(special.param, '.8g')}"
    if special.interval is not None:
        where += (
            f" (between {par.show(special.interval[0], '.10g')} and {par.show(special.interval[1], '.10g')})"
        )
    word = "transition" if model.has_modes else "stop"
    return (
        f"a grazing of {word} {model.stop_names[special.stop]!r} {where} was bracketed but its equations did "
        "not converge: unlocated, not among the grazings found"
    )


@dataclass
class GrazingCurve:
    """A curve of grazing orbits in two parameters.

    Attributes
    ----------
    params
        The two parameter names (the first varies along the search interval,
        the second is the one whose largest value on the curve is the fold).
    points
        Grazing orbits along the curve.
    fold
        The turning point in the second parameter (its largest value on the
        curve, beyond which no grazing occurs), if the curve has one.
    fold_index
        The fold lies between ``points[fold_index]`` and the point after it
        (-1 without a fold).
    status
        Why the continuation stopped.

    Examples
    --------
    The paper's grazing curve of fig. 6 (case B): no grazing of the period-1
    orbit above θ̂ = 55.9° (:func:`grazing_curve` makes it):

    >>> import math, grazing
    >>> curve = grazing_curve(grazing.models.pendulum("B"), ("eta", "theta_hat"), math.radians(5),
    ...                       search=(0.2, 1.0))
    >>> curve.params, round(math.degrees(curve.fold.model.params["theta_hat"]), 1)
    (('eta', 'theta_hat'), 55.9)
    >>> theta = [p.model.params["theta_hat"] for p in curve.points]
    >>> max(theta[curve.fold_index : curve.fold_index + 2]) < curve.fold.model.params["theta_hat"]
    True
    >>> curve.to_dataset().abs_lambda.dims
    ('point',)
    """

    params: tuple[str, str]
    points: list[GrazingPoint] = field(default_factory=list)
    fold: GrazingPoint | None = None
    fold_index: int = -1
    status: str = ""

    def values(self, name: str) -> np.ndarray:
        return np.array([p.model.params[name] for p in self.points])

    def to_dataset(self) -> Any:
        import xarray as xr

        import grazing

        mu = np.array([p.multipliers for p in self.points])
        data: dict[str, Any] = {name: ("point", self.values(name)) for name in self.params}
        data.update(
            {
                "t_graze": ("point", np.array([p.phase for p in self.points])),
                "multiplier_re": (("point", "multiplier"), mu.real),
                "multiplier_im": (("point", "multiplier"), mu.imag),
                "abs_lambda": ("point", np.abs(mu).max(axis=1)),
                "accel": ("point", np.array([p.accel for p in self.points])),
            }
        )
        ds = xr.Dataset(data)
        ds.attrs.update(
            {"params": ",".join(self.params), "status": self.status, "grazing_version": grazing.__version__}
        )
        if self.fold is not None:
            for name in self.params:
                ds.attrs[f"fold_{name}"] = self.fold.model.params[name]
        return ds


def grazing_curve(
    model: HybridModel,
    params: tuple[str, str],
    start: float,
    *,
    search: tuple[float, float],
    x0: Sequence[float] | np.ndarray | None = None,
    period: int = 1,
    settings: PalcSettings | None = None,
    progress: Callable[[int, float], None] | None = None,
    stop_name: int | str | None = None,
) -> GrazingCurve:
    """Follow the grazing condition in two parameters, over the top and back down.

    The curve starts at the first grazing (smallest value of ``params[0]`` in
    ``search``) at ``params[1] = start``, moves with ``params[1]`` increasing,
    turns at the fold (located), and ends when ``params[1]`` is back at
    ``start`` on the other branch or ``params[0]`` leaves ``search``.
    ``x0``: a guess of the nonimpacting orbit at time 0 with ``params[0] =
    search[0]`` and ``params[1] = start`` (see :func:`find_grazings`).
    On a model with modes the curve is that of a transition's guard
    (``stop_name``) touched by an orbit of its source mode, found on the orbit's
    own branch (see :func:`find_grazings`).

    Parameters
    ----------
    model
        The model, with the values of the other parameters.
    params
        The two parameters: the one searched for the first grazing, and the
        one whose largest value on the curve is the fold.
    start
        The second parameter's value where the curve starts and ends.
    search
        The interval of the first parameter searched for the first grazing.
    x0
        A guess of the nonimpacting orbit's state (see above).
    period
        Period of the nonimpacting orbit, in forcing periods.
    settings
        The continuation's settings (default: steps of 0.02, at most 0.05).
    progress
        Called as ``progress(step, value)`` after each continuation step.
    stop_name
        The stop grazed (name or index; the first by default).

    Returns
    -------
    GrazingCurve
        The grazing orbits along the curve, its fold, and why it ended.

    Examples
    --------
    >>> import grazing
    >>> curve = grazing_curve(grazing.models.pendulum("B"), ("eta", "theta_hat"), math.radians(5),
    ...                       search=(0.2, 1.0))
    >>> round(math.degrees(curve.fold.model.params["theta_hat"]), 1)
    55.9
    """
    p1, p2 = params
    for p in params:
        if p not in model.params:
            raise InvalidParameterError(f"unknown parameter {p!r}")
    s = settings or PalcSettings(ds=0.02, ds_max=GRAZING_CURVE_MAX_STEP)
    base = model.with_params(**{p2: start})
    first, _ = find_grazings(base, p1, search[0], search[1], x0=x0, period=period, stop_name=stop_name)
    if not first:
        raise ConvergenceError(
            f"no grazing of the period-{period} orbit for {model.parameter(p1).show_range(*search)} at "
            f"{model.parameter(p2).show(start, 'g')}"
        )
    g0 = first[0]
    n = model.n_states
    evaluate = contact_system(model, params, period, stop=g0.stop)
    u0 = np.concatenate([g0.contact, [g0.t_graze, g0.model.params[p1], g0.model.params[p2]]])
    F, DF, pay = evaluate(u0)
    palc = Palc(
        evaluate,
        PalcPoint(u0, F, DF, pay),
        index=n + 2,
        sign=1.0,
        bounds={n + 1: search, n + 2: (start, _closed_upper(model.parameter(p2)))},
        settings=s,
        names={n: "t_graze", n + 1: p1, n + 2: p2},
        shows={n + 1: model.parameter(p1).show, n + 2: model.parameter(p2).show},
    )
    curve = GrazingCurve(params=params)
    prev: PalcPoint | None = None
    for pt in palc:
        if prev is not None and prev.tangent is not None and pt.tangent is not None:
            if sign_changed(prev.tangent[n + 2], pt.tangent[n + 2]) and curve.fold is None:
                loc = locate(evaluate, prev, pt, lambda q: float(q.tangent[n + 2]), s)
                if loc is not None:
                    curve.fold = loc.payload
                    curve.fold_index = len(curve.points) - 1
        curve.points.append(pt.payload)
        prev = pt
        if progress is not None:
            progress(len(curve.points), float(pt.u[n + 2]))
    curve.status = palc.status
    return curve


def _closed_upper(par: Parameter) -> float:
    """Where a curve moving up in ``par`` ends: its upper bound if the parameter may take it (r = 1)."""
    return par.upper if not par.upper_open else math.inf
