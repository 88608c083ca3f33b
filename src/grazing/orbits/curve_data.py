"""The record of a bifurcation curve in two parameters: its points, its codimension-two points, its dataset.

:func:`~grazing.orbits.curves.follow_curve` computes a :class:`BifurcationCurve`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.orbits.contact import GrazingPoint
from grazing.orbits.continuation import Branch, SpecialPoint
from grazing.orbits.kinds import CurveKind, TextEnum
from grazing.orbits.palc import PalcEnd
from grazing.orbits.shooting import PeriodicOrbit, unstable_count

ACCURACY_NOTE = 1e-6
"""Points whose multipliers are known less well than this (:attr:`CurvePoint.accuracy`) are named
in the command's summary (:meth:`BifurcationCurve.imprecise`)."""


@dataclass(frozen=True)
class CurvePoint:
    """A point of a bifurcation curve.

    Attributes
    ----------
    values
        The two parameters' values (model units).
    state
        The orbit's point on its section (a grazing curve: the contact state).
    section_time
        The section's time (a grazing curve: the contact's forcing phase, in ``[0, T)``).
    multipliers
        The Floquet multipliers (a grazing curve: of the grazing orbit, the contact not an impact).
    impacts
        Impacts per period of the orbit (a grazing curve: besides the grazing contact).
    period
        Period of the orbit in forcing periods.
    condition
        The defining condition's value (zero on the curve, to Newton's tolerance).
    orbit, grazing
        The periodic orbit (fold, period-doubling, Neimark-Sacker, branch-point curves) or
        the grazing orbit (grazing curves).
    accuracy
        How far the critical multipliers may be from the curve's condition (``|mu - 1|`` on a
        fold or branch-point curve, ``|mu + 1|`` on a period-doubling curve, ``|mu_i mu_j - 1|``
        on a Neimark-Sacker curve), given ``condition`` and double precision: an estimate
        (:func:`~grazing.orbits.extended.multiplier_accuracy`) from Newton's residual, the
        rounding of the point's unknowns and of the integration through the gradient of the
        defining condition, and the rounding of the monodromy's entries, over ``|w^T v|``.  It is
        0.6 to 4.7 times what rounding-level changes of the point do to its multipliers (or their
        own distance from the condition, if larger) on the curves of the tests
        (docs/bifurcation-curves.md): ``1e-14`` to ``1e-10`` where the monodromy is close to
        normal, far worse within ``1e-5`` of a grazing (where it grows like ``1 / v^2``, ``v`` the
        impact speed).  nan on a grazing curve.

    Examples
    --------
    The first point of the fold curve of the impacting period-1 orbit of the
    pendulum (case B; the fold at θ̂ = 40° is near η = 0.654), at θ̂ = 30°:
    one multiplier is 1, to the point's accuracy:

    >>> import math, numpy as np, grazing
    >>> from grazing.orbits import follow_curve
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> curve = follow_curve(m, "fold", "eta", 0.55, 0.70, "theta_hat", (math.radians(30), math.radians(50)))
    >>> p = curve.points[0]
    >>> round(math.degrees(p.values[1]), 6), p.period, p.impacts, p.stable
    (30.0, 1, 1, True)
    >>> bool(abs(p.multipliers[0] - 1) < 1e-9), bool(p.accuracy < 1e-9)
    (True, True)
    """

    values: tuple[float, float]
    state: np.ndarray
    section_time: float
    multipliers: np.ndarray
    impacts: int
    period: int
    condition: float
    orbit: PeriodicOrbit | None = None
    grazing: GrazingPoint | None = None
    accuracy: float = math.nan

    @property
    def stable(self) -> bool:
        """No multiplier outside the unit circle (see ``core.options.UNIT_CIRCLE_TOL``)."""
        return unstable_count(self.multipliers) == 0


@dataclass(frozen=True)
class CurveSpecial:
    """A codimension-two point on a curve (between points ``index`` and ``index + 1``).

    Attributes
    ----------
    kind
        What the curve meets: ``"grazing"`` (the orbit gains or loses an impact: the
        curve ends), ``"double grazing"`` (on a grazing curve), ``"cusp"``,
        ``"fold-flip"``, ``"1:1 resonance"`` ... (see
        :data:`~grazing.orbits.extended.CODIM2_TESTS`).
    index
        The curve point next to it on the side of the curve's start (the point itself when it is
        one: a point that ends the curve).
    values
        Both parameters' values there.
    multipliers, state
        At the point (a grazing: of the grazing orbit).
    located
        False when it is only bracketed between two points (``values`` then
        those of the last point before it).
    grazing
        For a grazing: the grazing orbit, solved from the grazing equations.
    precision
        How far each parameter's value may be from the point's (as
        :attr:`~grazing.orbits.continuation.SpecialPoint.precision`, one per parameter): for a zero of a
        test function located along the curve, its value over its slope on the last bracket, at most the
        bracket's width; for a grazing solved as the meeting point of the two curves, the parameter part
        of the last Newton step; for a point only bracketed (not :attr:`located`, or a grazing whose
        meeting point did not converge: the grazing orbit nearest the curve's last point), the width of
        the bracket in each parameter; nan where there is no bracket (a curve stopped by Newton's method
        short of its grazing).
    interval
        The bracket in which the point lies, ``((low1, high1), (low2, high2))`` in the two parameters: the
        last bracket of the location along the curve, or the last point before the point and the first
        beyond; None where there is none.

    Examples
    --------
    The period-doubling curve of the period-5 orbit at θ̂ = 40° (case B) ends
    where the orbit loses its impact, at θ̂ = 35.9°:

    >>> import math, grazing
    >>> from grazing.orbits import follow_curve
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> curve = follow_curve(m, "period-doubling", "eta", 0.446, 0.44, "theta_hat",
    ...                      (math.radians(30), math.radians(41)))
    >>> (s,) = curve.special
    >>> s.kind, s.located, round(s.values[0], 6), round(math.degrees(s.values[1]), 4)
    ('grazing', True, 0.43866, 35.9051)
    """

    kind: str
    index: int
    values: tuple[float, float]
    multipliers: np.ndarray
    state: np.ndarray
    located: bool = True
    grazing: GrazingPoint | None = None
    precision: tuple[float, float] = (math.nan, math.nan)
    interval: tuple[tuple[float, float], tuple[float, float]] | None = None


def bracket_between(
    a: np.ndarray, b: np.ndarray | None
) -> tuple[tuple[float, float], tuple[tuple[float, float], tuple[float, float]] | None]:
    """``(precision, interval)`` of a point known only to lie between two points of a curve whose two
    parameters are ``a`` and ``b`` (``b`` None: no point beyond, nan and None).

    Examples
    --------
    >>> bracket_between(np.array([0.5, 2.0]), np.array([0.25, 2.5]))
    ((0.25, 0.5), ((0.25, 0.5), (2.0, 2.5)))
    """
    if b is None:
        return (math.nan, math.nan), None
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    interval = ((float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1])))
    return (interval[0][1] - interval[0][0], interval[1][1] - interval[1][0]), interval


class CurveEnd(TextEnum):
    """Why a bifurcation curve ends at one of its ends (:attr:`BifurcationCurve.outcomes`): a string equal
    to the word ``curve --json`` writes (``outcomes``), its :attr:`message` in a few words; the curve's
    :attr:`~BifurcationCurve.status` says it in full, with the values.

    Examples
    --------
    >>> CurveEnd.GRAZING.message, f"{CurveEnd.RESONANCE_1_2}", CurveEnd.of(PalcEnd.BOUND)
    ('ended at a grazing (a codimension-two point)', '1:2 resonance', 'bound')
    """

    BOUND = "bound"
    GRAZING = "grazing"
    """The orbit gains or loses an impact: the curve meets a grazing curve (a codimension-two point)."""
    DOUBLE_GRAZING = "double grazing"
    """A grazing curve's orbit meets another contact with a stop."""
    RESONANCE_1_1 = "1:1 resonance"
    """A Neimark-Sacker curve's pair of multipliers meets at +1 (beyond it: real, a neutral saddle)."""
    RESONANCE_1_2 = "1:2 resonance"
    """A Neimark-Sacker curve's pair of multipliers meets at -1."""
    NOT_PERSISTENT = "not persistent"
    """A branch point's shift leaves zero: the model lacks the symmetry that keeps it in two parameters."""
    STUCK = "stuck"
    """Newton's method failed beyond the last point: the step size fell below its minimum."""
    RESECTION = "resection"
    """The section had to move, with no points left to go on."""
    NO_SECTION = "no section"
    """The section had to move and the orbit could not be found on another one."""
    MAX_POINTS = "max points"
    CLOSED = "closed"
    """The curve came back to its start: it is closed (both ends are its start)."""

    @property
    def message(self) -> str:
        """The outcome in a few words."""
        return _CURVE_END_MESSAGES[self]

    @classmethod
    def of(cls, end: PalcEnd | None) -> CurveEnd:
        """The outcome of a direction whose last continuation ended with ``end`` (not at a
        codimension-two point)."""
        return {
            PalcEnd.BOUND: cls.BOUND,
            PalcEnd.STOPPED: cls.RESECTION,
            PalcEnd.MAX_POINTS: cls.MAX_POINTS,
        }.get(end, cls.STUCK)  # type: ignore[arg-type]


_CURVE_END_MESSAGES = {
    CurveEnd.BOUND: "reached a bound",
    CurveEnd.GRAZING: "ended at a grazing (a codimension-two point)",
    CurveEnd.DOUBLE_GRAZING: "ended at a double grazing",
    CurveEnd.RESONANCE_1_1: "ended at a 1:1 resonance",
    CurveEnd.RESONANCE_1_2: "ended at a 1:2 resonance",
    CurveEnd.NOT_PERSISTENT: "the branch point does not persist in two parameters",
    CurveEnd.STUCK: "Newton's method failed: the step size fell below its minimum",
    CurveEnd.RESECTION: "the section had to move, with no points left",
    CurveEnd.NO_SECTION: "the section could not be moved",
    CurveEnd.MAX_POINTS: "maximum number of points reached",
    CurveEnd.CLOSED: "the curve is closed: it came back to its start",
}


@dataclass
class BifurcationCurve:
    """A curve of bifurcations of a periodic orbit in two parameters (:func:`follow_curve`).

    Attributes
    ----------
    model
        The model (the values of other parameters).
    kind
        One of :data:`CURVE_KINDS`.
    params
        The two parameters' names: the continuation parameter and the second one.
    period
        Period of the orbit in forcing periods.
    virtual
        The orbit is computed with the stops ignored (a nonimpacting orbit).
    points
        The points, in order along the curve.
    special
        Codimension-two points, in order along the curve.
    status
        Why the curve ends at its first and at its last point.
    start
        The one-parameter special point the curve starts from (on ``branch``).
    start_index
        Its index among :attr:`points`.
    branch
        The one-parameter branch on which the start was found.
    outcomes
        What :attr:`status` says as two :class:`CurveEnd` (at the first point, at the last point); None
        for a curve not followed by :func:`~grazing.orbits.curves.follow_curve`.

    Examples
    --------
    The fold of the impacting period-1 orbit of the pendulum (case B) in
    (η, θ̂), from the fold near η = 0.654 at θ̂ = 40° to both ends of
    θ̂'s range:

    >>> import math, grazing
    >>> from grazing.orbits import follow_curve
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> curve = follow_curve(m, "fold", "eta", 0.55, 0.70, "theta_hat", (math.radians(30), math.radians(50)))
    >>> curve.kind, curve.params, curve.period, round(curve.start.param, 4)
    ('fold', ('eta', 'theta_hat'), 1, 0.6543)
    >>> theta = curve.values("theta_hat")
    >>> round(math.degrees(theta.min()), 6), round(math.degrees(theta.max()), 6), curve.special
    (30.0, 50.0, [])
    """

    model: HybridModel
    kind: CurveKind
    params: tuple[str, str]
    period: int
    virtual: bool
    points: list[CurvePoint] = field(default_factory=list)
    special: list[CurveSpecial] = field(default_factory=list)
    status: str = ""
    start: SpecialPoint | None = None
    start_index: int = 0
    branch: Branch | None = None
    outcomes: tuple[CurveEnd, CurveEnd] | None = None

    def __len__(self) -> int:
        return len(self.points)

    @property
    def closed(self) -> bool:
        """The curve came back to its start (:attr:`CurveEnd.CLOSED`): its last point is its first."""
        return self.outcomes == (CurveEnd.CLOSED, CurveEnd.CLOSED)

    def values(self, name: str) -> np.ndarray:
        """One parameter's values along the curve."""
        return np.array([p.values[self.params.index(name)] for p in self.points])

    def imprecise(self, tol: float = ACCURACY_NOTE) -> list[int]:
        """The indices of the points whose multipliers are known only to worse than ``tol``
        (:attr:`CurvePoint.accuracy`: in double precision, near a grazing)."""
        return [i for i, p in enumerate(self.points) if p.accuracy > tol]

    @property
    def states(self) -> np.ndarray:
        return np.array([p.state for p in self.points]).reshape(-1, self.model.n_states)

    @property
    def multipliers(self) -> np.ndarray:
        return np.array([p.multipliers for p in self.points]).reshape(-1, self.model.n_states)

    def to_dataset(self) -> Any:
        """The curve as an :class:`xarray.Dataset` (one ``point`` per curve point, one ``special`` per
        codimension-two point); the parameters are ``param1`` and ``param2`` (named in their
        ``long_name`` and in the ``params`` attribute)."""
        import xarray as xr

        import grazing

        names = list(self.model.state_names)
        k = len(names)
        mu = self.multipliers
        sp_mu = np.array([s.multipliers for s in self.special]).reshape(-1, k)
        sp_state = np.array([s.state for s in self.special]).reshape(-1, k)
        data: dict[str, Any] = {
            "param1": ("point", self.values(self.params[0])),
            "param2": ("point", self.values(self.params[1])),
            "state": (("point", "component"), self.states),
            "section_time": ("point", np.array([p.section_time for p in self.points])),
            "multiplier_re": (("point", "multiplier"), mu.real),
            "multiplier_im": (("point", "multiplier"), mu.imag),
            "abs_multiplier": (("point", "multiplier"), np.abs(mu)),
            "stable": ("point", np.array([p.stable for p in self.points], dtype=np.int8)),
            "impacts": ("point", np.array([p.impacts for p in self.points], dtype=np.int32)),
            "condition": ("point", np.array([p.condition for p in self.points])),
            "accuracy": ("point", np.array([p.accuracy for p in self.points])),
            "special_kind": ("special", np.array([s.kind for s in self.special], dtype=str)),
            "special_index": ("special", np.array([s.index for s in self.special], dtype=np.int32)),
            "special_param1": ("special", np.array([s.values[0] for s in self.special], dtype=float)),
            "special_param2": ("special", np.array([s.values[1] for s in self.special], dtype=float)),
            "special_located": ("special", np.array([s.located for s in self.special], dtype=np.int8)),
            "special_precision": (
                ("special", "param"),
                np.array([s.precision for s in self.special], dtype=float).reshape(-1, 2),
            ),
            "special_interval": (
                ("special", "param", "bound"),
                np.array(
                    [s.interval or ((np.nan, np.nan), (np.nan, np.nan)) for s in self.special], dtype=float
                ).reshape(-1, 2, 2),
            ),
            "special_state": (("special", "component"), sp_state),
            "special_multiplier_re": (("special", "multiplier"), sp_mu.real),
            "special_multiplier_im": (("special", "multiplier"), sp_mu.imag),
        }  # fmt: skip
        ds = xr.Dataset(data, coords={"component": names, "multiplier": np.arange(k)})
        for var, name in (("param1", self.params[0]), ("param2", self.params[1])):
            ds[var].attrs["long_name"] = name
            ds["special_" + var].attrs["long_name"] = name
        ds.section_time.attrs["long_name"] = "contact phase" if self.kind == "grazing" else "section time"
        attrs: dict[str, Any] = {
            "model": self.model.name,
            "kind": str(self.kind),
            "params": ",".join(self.params),
            "period": self.period,
            "virtual": int(self.virtual),
            "status": self.status,
            "start_index": self.start_index,
            "grazing_version": grazing.__version__,
        }
        if self.outcomes is not None:  # (their words, comma-separated as the params)
            attrs["outcomes"] = ",".join(str(o) for o in self.outcomes)
        for name, v in self.model.params.items():
            if name not in self.params:
                attrs[f"param_{name}"] = v
        ds.attrs.update(attrs)
        return ds

    def to_netcdf(self, path: str | Path, overwrite: bool = False) -> None:
        """Save :meth:`to_dataset` to a NetCDF file (:func:`grazing.outputs.write_netcdf`: all at once,
        with grazing's mark; a file there that grazing did not write is refused unless ``overwrite``)."""
        from grazing.outputs import write_netcdf

        write_netcdf(path, self.to_dataset(), overwrite=overwrite)
