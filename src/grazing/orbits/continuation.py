"""Pseudo-arclength continuation of periodic orbits in one parameter.

Unknowns ``u = (x, p)``: a point of the orbit on the stroboscopic section and
the parameter.  Equations ``F(u) = P^n(x; p) - x = 0`` with Jacobian
``[P_x - I, P_p]`` from the variational equations (saltation matrices at the
impacts, parameter sensitivities as extra columns, the moving return time
included for a parameter that sets the forcing period).  Each step predicts
along the tangent (the null vector of the Jacobian) and corrects by Newton's
method on ``F = 0`` plus the arclength condition (Keller 1977; Kuznetsov,
*Elements of Applied Bifurcation Theory*, ch. 10).

A branch is one orbit.  Every point carries its *impact signature* (impacts in
each of the ``n`` forcing periods); a corrected point with another signature
is another orbit, reached through a grazing (an impact speed, or the distance
of a near approach to the stop, passing through zero).  The branch therefore
ends at that grazing: it is bracketed along the step, located exactly by
solving the grazing equations (:mod:`grazing.orbits.contact`, Newton
tolerance) and reported as a special point, as COCO's hybrid toolbox does.
With ``switch=True`` the continuation goes on, deliberately, along the orbit
with the new impact sequence, as a new *segment* of the branch.  Steps are
halved where the corrector lands far from the predictor, where the tangent
turns sharply, and where stability changes between two points, so that no
special point is stepped over.

Special points are detected by sign changes of test functions between
consecutive points and located by regula falsi along the secant:

* fold: ``det(P_x - I)`` (a multiplier passes through +1);
* period-doubling: ``det(P_x + I)`` (a multiplier passes through -1);
* Neimark-Sacker: ``det(P_x) - 1`` with a complex pair (2-D maps; the
  bialternate-product test in general);
* grazing: the minimum of a stop's guard along a nonimpacting (virtual)
  orbit reaches zero, for every stop (then refined by the grazing
  equations), or the end of an impacting branch described above.

The stroboscopic map is not smooth where an impact falls on its section, so
the section is chosen away from impacts (``t0=None``, the default) and moved
when an impact comes within :data:`RESECTION_MARGIN` of a period of it; each
point records its section time.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.errors import ConvergenceError, GrazingError, InvalidParameterError
from grazing.maps import flow_map
from grazing.orbits.contact import GrazingPoint, refine_grazing
from grazing.orbits.palc import (
    ACCEPT,
    BOUNDARY,
    REFINE,
    STOP,
    Palc,
    PalcPoint,
    PalcSettings,
    locate,
    sign_changed,
)
from grazing.orbits.shooting import (
    SECTION_MARGIN,
    PeriodicOrbit,
    _orbit_from,
    find_orbit,
    move_section,
    quiet_section,
)

SPECIAL_KINDS = ("fold", "period-doubling", "neimark-sacker", "grazing")

RESECTION_MARGIN = 0.01
"""An impact closer than this fraction of a period to the section moves the section."""

_RESECTION = "an impact approaches the section"

ContinuationSettings = PalcSettings
"""Options of :func:`continue_orbit` (see :class:`~grazing.orbits.palc.PalcSettings`)."""


@dataclass(frozen=True)
class SpecialPoint:
    """A located special point on a branch (between points ``index`` and ``index + 1``).

    Attributes
    ----------
    kind
        One of :data:`SPECIAL_KINDS`.
    index
        The branch point just before it.
    param
        The parameter value where it occurs.
    orbit
        The periodic orbit there (for a grazing: the orbit where the branch
        ends, next to the grazing).
    grazing
        For a grazing: the grazing orbit itself, solved from the grazing
        equations (contact state and time, monodromy on the section through
        the contact with the grazing contact not an impact); None if those
        did not converge, in which case ``param`` is the end of the bracket.
    stop
        For a grazing: the index of the stop grazed.
    """

    kind: str
    index: int
    param: float
    orbit: PeriodicOrbit
    grazing: GrazingPoint | None = None
    stop: int = 0

    @property
    def multipliers(self) -> np.ndarray:
        """Floquet multipliers at the point (of the grazing orbit for a grazing)."""
        return self.grazing.multipliers if self.grazing is not None else self.orbit.multipliers


@dataclass
class Branch:
    """A computed branch of periodic orbits.

    Attributes
    ----------
    param
        Name of the continuation parameter.
    values
        Parameter value at each point.
    orbits
        The periodic orbit at each point (state on its section ``orbit.t0``,
        multipliers, impacts...).
    segments
        Segment index of each point: 0, then one more after each deliberate
        switch onto the orbit with a new impact sequence (``switch=True``).
    special
        Located special points, in order along the branch.
    status
        Why the continuation stopped.
    """

    model: HybridModel
    param: str
    period: int
    virtual: bool
    values: list[float] = field(default_factory=list)
    orbits: list[PeriodicOrbit] = field(default_factory=list)
    arclength: list[float] = field(default_factory=list)
    segments: list[int] = field(default_factory=list)
    special: list[SpecialPoint] = field(default_factory=list)
    status: str = ""

    def __len__(self) -> int:
        return len(self.values)

    @property
    def states(self) -> np.ndarray:
        return np.array([o.state for o in self.orbits])

    @property
    def multipliers(self) -> np.ndarray:
        return np.array([o.multipliers for o in self.orbits])

    @property
    def guard_min(self) -> np.ndarray:
        return np.array([o.guard_min for o in self.orbits])

    @property
    def sections(self) -> np.ndarray:
        """The section time of each point's orbit (see the module docstring)."""
        return np.array([o.t0 for o in self.orbits])

    def to_dataset(self) -> Any:
        """The branch as an :class:`xarray.Dataset` (one ``point`` per orbit)."""
        import xarray as xr

        import grazing

        mu = self.multipliers
        names = list(self.model.state_names)
        data = {
            "param": ("point", np.asarray(self.values)),
            "arclength": ("point", np.asarray(self.arclength)),
            "segment": ("point", np.asarray(self.segments, dtype=np.int32)),
            "section_time": ("point", self.sections),
            "state": (("point", "component"), self.states),
            "multiplier_re": (("point", "multiplier"), mu.real),
            "multiplier_im": (("point", "multiplier"), mu.imag),
            "abs_multiplier": (("point", "multiplier"), np.abs(mu)),
            "stable": ("point", np.array([o.stable for o in self.orbits], dtype=np.int8)),
            "impacts": ("point", np.array([o.impacts for o in self.orbits], dtype=np.int32)),
            "guard_min": ("point", self.guard_min),
            "min_impact_speed": ("point", np.array([o.min_impact_speed for o in self.orbits])),
            "special_kind": ("special", np.array([s.kind for s in self.special], dtype=str)),
            "special_index": ("special", np.array([s.index for s in self.special], dtype=np.int32)),
            "special_param": ("special", np.array([s.param for s in self.special], dtype=float)),
            "special_state": (
                ("special", "component"),
                np.array([s.orbit.state for s in self.special]).reshape(-1, len(names)),
            ),
            "special_abs_multiplier": (
                ("special", "multiplier"),
                np.array([np.abs(s.multipliers) for s in self.special]).reshape(-1, len(names)),
            ),
        }
        # Where each orbit comes closest to the stop (its largest angle, for the pendulum).
        nan = np.full(len(names), np.nan)
        closest = [o.x_guard_min if o.x_guard_min is not None else nan for o in self.orbits]
        data["closest_state"] = (("point", "component"), np.array(closest).reshape(-1, len(names)))
        ds = xr.Dataset(data, coords={"component": names, "multiplier": np.arange(len(names))})
        ds.param.attrs["long_name"] = self.param
        attrs: dict[str, Any] = {
            "model": self.model.name,
            "continuation_parameter": self.param,
            "period": self.period,
            "virtual": int(self.virtual),
            "status": self.status,
            "grazing_version": grazing.__version__,
        }
        for k, v in self.model.params.items():
            if k != self.param:
                attrs[f"param_{k}"] = v
        ds.attrs.update(attrs)
        return ds

    def to_netcdf(self, path: str | Path, overwrite: bool = False) -> None:
        """Save :meth:`to_dataset` to a NetCDF file (:func:`grazing.outputs.write_netcdf`: all at once,
        with grazing's mark; a file there that grazing did not write is refused unless ``overwrite``)."""
        from grazing.outputs import write_netcdf

        write_netcdf(path, self.to_dataset(), overwrite=overwrite)


# ----------------------------------------------------------------------------


def _evaluator(model: HybridModel, param: str, period: int, t0: float, virtual: bool, stop: int = 0):
    """``u = (x, p) -> (F, DF, orbit)`` for the branch equations ``P^n(x; p) - x = 0``."""
    n = model.n_states
    eye = np.eye(n)

    def evaluate(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, PeriodicOrbit]:
        m = model.with_params(**{param: float(u[-1])})
        x = u[:-1]
        fm = flow_map(m, x, t0=t0, periods=period, sensitivities=[param], virtual=virtual, stop_name=stop)
        if not fm.solution.jacobian_valid:
            raise ConvergenceError("the orbit sticks to the stop: no Jacobian across sticking")
        F = fm.image - x
        orbit = _orbit_from(m, x, t0, period, fm, virtual, [float(np.max(np.abs(F)))], stop)
        return F, np.hstack([fm.jacobian - eye, fm.sensitivity]), orbit

    return evaluate


def _test_function(kind: str, orbit: PeriodicOrbit) -> float:
    """Test function of a special point (smooth along a branch of one impact signature)."""
    J = orbit.monodromy
    eye = np.eye(J.shape[0])
    if kind == "fold":
        return float(np.linalg.det(J - eye))
    if kind == "period-doubling":
        return float(np.linalg.det(J + eye))
    if kind == "neimark-sacker":
        complex_pair = bool(np.any(np.abs(orbit.multipliers.imag) > 1e-12))
        return float(np.linalg.det(J) - 1.0) if complex_pair else math.nan
    raise ValueError(f"unknown special point kind {kind!r}")


def _stop_guard_min(orbit: PeriodicOrbit, stop: int) -> float:
    """The smallest value of stop ``stop``'s guard along a virtual orbit: zero where it grazes that stop.

    (A physical branch ends at its grazings instead: nan.)
    """
    return orbit.guard_min_by_stop[stop][0] if orbit.virtual else math.nan


def _verified(kind: str, orbit: PeriodicOrbit) -> bool:
    """Does a located point satisfy the defining condition of its kind?"""
    mu = orbit.multipliers
    if kind == "fold":
        return bool(np.min(np.abs(mu - 1.0)) < 1e-5)
    if kind == "period-doubling":
        return bool(np.min(np.abs(mu + 1.0)) < 1e-5)
    if kind == "neimark-sacker":
        pair = mu[np.abs(mu.imag) > 1e-12]
        return bool(pair.size and np.min(np.abs(np.abs(pair) - 1.0)) < 1e-5)
    return True


def _detect(evaluate, kind: str, a: PalcPoint, b: PalcPoint, s: PalcSettings) -> PalcPoint | None:
    if not sign_changed(_test_function(kind, a.payload), _test_function(kind, b.payload)):
        return None
    loc = locate(evaluate, a, b, lambda p: _test_function(kind, p.payload), s)
    return loc if loc is not None and _verified(kind, loc.payload) else None


def _detect_grazing(
    evaluate, stop: int, a: PalcPoint, b: PalcPoint, param: str, n: int, s: PalcSettings
) -> SpecialPoint | None:
    """The grazing of stop ``stop`` between two points of a virtual branch, located and refined."""
    test = lambda p: _stop_guard_min(p.payload, stop)  # noqa: E731
    if not sign_changed(test(a), test(b)):
        return None
    loc = locate(evaluate, a, b, test, s)
    if loc is None:
        return None
    lo: PeriodicOrbit = loc.payload
    _, t, x = lo.guard_min_by_stop[stop]
    point = None
    try:
        point = refine_grazing(lo.model, x, t, param, period=n, stop_name=stop)
    except GrazingError:
        point = None
    value = float(loc.u[-1]) if point is None else point.model.params[param]
    return SpecialPoint("grazing", -1, value, lo, point, stop)


def grazing_margin(orbit: PeriodicOrbit) -> tuple[float, np.ndarray | None, float, str, int]:
    """How far ``orbit`` is from grazing, and where: ``(delta, contact guess, time, what, stop)``.

    ``delta`` is the smaller of the closest approach to the stop away from the
    impacts (``h`` at a local minimum of the guard) and, over the impacts,
    ``v^2 / (2 a)`` (how deep the local parabola of a low-velocity impact
    reaches, ``v`` the impact speed and ``a = L_f^2 h``).  Both tend to zero
    linearly in the parameter as the orbit approaches a grazing from its side.
    ``stop`` is the index of the stop concerned (closest approaches and
    impacts on every stop are considered).
    """
    best: tuple[float, np.ndarray | None, float, str, int] = (math.inf, None, math.nan, "", orbit.stop)
    for j, ap in enumerate(orbit.approach_by_stop):  # a new impact on any stop
        if ap is not None and ap[0] < best[0]:
            best = (ap[0], ap[2], ap[1], "gains an impact", j)
    if orbit.impact_states is not None:
        stops = orbit.impact_stops if orbit.impact_stops.size == orbit.impact_times.size else None
        for i, (t, v, x) in enumerate(zip(orbit.impact_times, orbit.impact_speeds, orbit.impact_states)):
            j = int(stops[i]) if stops is not None else 0
            a = abs(orbit.model.normal_accel(x, t, j))
            delta = v * v / (2 * a) if a > 0 else math.inf
            if delta < best[0]:
                best = (delta, x, float(t), "loses an impact", j)
    return best


def _locate_grazing(
    last: PeriodicOrbit, beyond: PeriodicOrbit | None, param: str, virtual: bool
) -> GrazingPoint | None:
    """The grazing orbit at the end of a branch, from its last orbit (Newton on the contact equations)."""
    _, y, tg, _, stop = grazing_margin(last)
    if y is None:
        return None
    try:
        point = refine_grazing(
            last.model, y, tg, param, period=last.period, events=not virtual, stop_name=stop
        )
    except GrazingError:
        return None
    # It must be the grazing between the two sides, not some other solution of the equations.
    p, pg = last.model.params[param], point.model.params[param]
    scale = max(1.0, abs(p))
    if beyond is not None:
        q = beyond.model.params[param]
        ok = min(p, q) - 1e-8 * scale <= pg <= max(p, q) + 1e-8 * scale
    else:
        ok = abs(pg - p) <= 1e-4 * scale
    return point if ok else None


def _switch_orbit(
    last: PeriodicOrbit, param: str, value: float, direction: float, virtual: bool
) -> PeriodicOrbit | None:
    """An orbit with another impact signature than ``last``, just past the grazing at ``value``."""
    p = last.model.params[param]
    par = next(q for q in last.model.parameters if q.name == param)
    for sign in (direction, -direction):
        for eps in (1e-7, 1e-6, 1e-5, 1e-4):
            trial = value + sign * eps * max(1.0, abs(value))
            try:
                par.check(trial)
                orbit = find_orbit(
                    last.model.with_params(**{param: trial}), last.state, period=last.period, t0=last.t0,
                    virtual=virtual, stop_name=last.stop,
                )  # fmt: skip
            except GrazingError:
                continue
            if orbit.signature != last.signature and abs(trial - p) > 0:
                return orbit
    return None


def continue_orbit(
    model: HybridModel,
    param: str,
    start: float,
    stop: float,
    *,
    orbit: PeriodicOrbit | None = None,
    x0: np.ndarray | None = None,
    period: int | None = None,
    t0: float | None = None,
    virtual: bool | None = None,
    settings: PalcSettings | None = None,
    detect: tuple[str, ...] = SPECIAL_KINDS,
    switch: bool = False,
    progress: Callable[[int, float], None] | None = None,
    stop_name: int | str | None = None,
) -> Branch:
    """Follow a periodic orbit as ``param`` goes from ``start`` towards ``stop``.

    Parameters
    ----------
    model
        Model with the other parameters set.
    param
        Name of the parameter to vary.
    start, stop
        The branch starts at ``param = start`` and ends when it reaches
        ``stop`` (it may turn back at folds before; the continuation follows
        the curve through them).  Both must lie in the parameter's interval.
    orbit, x0, period
        Starting orbit, or a guess for it (see :func:`find_orbit`).
    t0
        Section time for the starting orbit's guess ``x0``; ``None`` (default):
        0, moved away from impacts as described in the module docstring.
    virtual
        Ignore the stop (default: True when the starting orbit has no
        impacts, so nonimpacting orbits are followed through grazing, which is
        located and reported; False with ``switch``, which only a physical
        branch uses).
    settings
        Step control (:class:`~grazing.orbits.palc.PalcSettings`).
    detect
        Special points to detect and locate (any of ``SPECIAL_KINDS``).
    stop_name
        For models with several stops: the stop (name or index; default the
        starting orbit's, else the first) whose grazing a nonimpacting branch
        looks for first.  A nonimpacting branch reports the grazings of every
        stop; an impacting branch ends where it loses or gains an impact on
        any stop, at that stop's grazing.
    switch
        At a grazing where the impact sequence changes, continue onto the orbit
        with the new sequence (a new segment of the branch) instead of ending.
        A virtual branch has no such grazing: ``switch`` with ``virtual=True``
        (or a virtual starting ``orbit``) raises
        :class:`~grazing.errors.InvalidParameterError`.
    progress
        Called as ``progress(points, param_value)`` after each point.

    Returns
    -------
    Branch

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> br = continue_orbit(m, "eta", 0.40, 0.47)
    >>> [s.kind for s in br.special]
    ['grazing']
    >>> round(br.special[0].param, 6)
    0.445121
    """
    s = settings or PalcSettings()
    for kind in detect:
        if kind not in SPECIAL_KINDS:
            raise InvalidParameterError(f"unknown special point {kind!r} (known: {', '.join(SPECIAL_KINDS)})")
    if param not in model.params:
        raise InvalidParameterError(f"unknown parameter {param!r} (known: {', '.join(model.params)})")
    for name, val in (("start", start), ("stop", stop)):
        if not math.isfinite(val):
            raise InvalidParameterError(f"{name} must be finite, got {val}")
    if start == stop:
        raise InvalidParameterError("start and stop must differ")
    m0 = model.with_params(**{param: start})
    model.with_params(**{param: stop})  # the end of the range must be a valid value too
    par = model.parameter(param)
    if switch and (virtual or (virtual is None and orbit is not None and orbit.virtual)):
        raise InvalidParameterError(
            "switch has no effect on a virtual branch: it ignores the stops, so its impact sequence never "
            "changes (it is followed through its grazings, which are located); continue the physical "
            "orbit (virtual=False) to switch at a grazing"
        )
    if switch and virtual is None:
        virtual = False  # a nonimpacting orbit too: followed up to its grazing, then switched
    watch = model.stop_index(
        stop_name if stop_name is not None else (orbit.stop if orbit is not None else None)
    )
    if orbit is None:
        if virtual is None:
            probe = find_orbit(m0, x0, period=period, t0=0.0 if t0 is None else t0, stop_name=watch)
            virtual = probe.impacts == 0
            orbit = (
                probe
                if not virtual
                else find_orbit(
                    m0, probe.state, period=probe.period, t0=probe.t0, virtual=True, stop_name=watch
                )
            )
        else:
            orbit = find_orbit(
                m0, x0, period=period, t0=0.0 if t0 is None else t0, virtual=virtual, stop_name=watch
            )
        if t0 is None and orbit.section_clearance() < SECTION_MARGIN:
            orbit = move_section(orbit, quiet_section(orbit))
    elif virtual is None:
        virtual = orbit.virtual
    virtual = bool(virtual)
    n = orbit.period
    nx = model.n_states
    branch = Branch(model=model, param=param, period=n, virtual=virtual)
    bounds = {nx: (min(start, stop), max(start, stop))}

    def check(prev: PalcPoint, cand: PalcPoint) -> tuple[str, str]:
        a, b = prev.payload, cand.payload
        if not virtual and b.signature != a.signature:
            what = "loses" if sum(b.signature) < sum(a.signature) else "gains"
            if sum(b.signature) == sum(a.signature):
                what = "changes"
            return BOUNDARY, (
                f"the orbit {what} an impact (impacts per forcing period {list(a.signature)} -> "
                f"{list(b.signature)}): a grazing"
            )
        if not virtual and b.section_clearance() < RESECTION_MARGIN:
            return STOP, _RESECTION
        if a.stable != b.stable:
            return REFINE, "stability changes"
        return ACCEPT, ""

    def margin(pt: PalcPoint) -> float:
        return grazing_margin(pt.payload)[0]

    sign = math.copysign(1.0, stop - start)
    segment = 0
    prev: PalcPoint | None = None
    status = ""
    while True:
        evaluate = _evaluator(model, param, n, orbit.t0, virtual, orbit.stop)
        u0 = np.append(orbit.state, orbit.model.params[param])
        try:
            F, DF, orb = evaluate(u0)
        except GrazingError as exc:
            raise ConvergenceError(f"cannot start the continuation: {exc}") from None
        palc = Palc(
            evaluate, PalcPoint(u0, F, DF, orb), index=nx, sign=sign, bounds=bounds,
            settings=dataclasses.replace(s, max_points=max(2, s.max_points - len(branch) + 1)),
            names={nx: param}, shows={nx: par.show}, check=check, margin=None if virtual else margin,
        )  # fmt: skip
        restarted = prev is not None and segment == branch.segments[-1]  # the section moved
        for k, pt in enumerate(palc):
            if k == 0 and restarted:
                prev = pt  # the same orbit on a moved section: already on the branch
                continue
            if prev is not None and branch.segments and branch.segments[-1] == segment:
                for kind in detect:
                    if kind == "grazing":  # (virtual branches) the grazing of any stop
                        for j in range(model.n_stops):
                            found = _detect_grazing(evaluate, j, prev, pt, param, n, s)
                            if found is not None:
                                branch.special.append(dataclasses.replace(found, index=len(branch) - 1))
                        continue
                    loc = _detect(evaluate, kind, prev, pt, s)
                    if loc is None:
                        continue
                    value = float(loc.u[-1])
                    branch.special.append(SpecialPoint(kind, len(branch) - 1, value, loc.payload, None))
                branch.arclength.append(branch.arclength[-1] + float(np.linalg.norm(pt.u - prev.u)))
            else:
                branch.arclength.append(branch.arclength[-1] if branch.arclength else 0.0)
            branch.values.append(float(pt.u[-1]))
            branch.orbits.append(pt.payload)
            branch.segments.append(segment)
            prev = pt
            if progress is not None:
                progress(len(branch), float(pt.u[-1]))
        status = palc.status
        assert prev is not None and prev.tangent is not None
        sign = math.copysign(1.0, prev.tangent[nx]) if prev.tangent[nx] != 0 else sign
        last: PeriodicOrbit = prev.payload
        if status == _RESECTION and len(branch) < s.max_points:
            try:
                orbit = move_section(last, quiet_section(last))
            except GrazingError as exc:
                status = f"{_RESECTION} and the orbit could not be found on another section ({exc})"
                break
            continue
        if palc.boundary is None:
            break
        beyond = palc.boundary.after.payload if palc.boundary.after is not None else None
        point = _locate_grazing(last, beyond, param, virtual)
        if point is None and not palc.boundary.reached:
            break  # steps beyond jumped to another orbit, and no grazing is just ahead: say so
        value = point.model.params[param] if point is not None else float(prev.u[-1])
        where_stop = grazing_margin(last)[4] if point is None else point.stop
        branch.special.append(SpecialPoint("grazing", len(branch) - 1, value, last, point, where_stop))
        where = par.show(value)
        if model.n_stops > 1:
            where = f"{where} with stop {model.stop_names[where_stop]!r}"
        if point is None:
            where += (
                f" (bracketed only: the grazing equations did not converge; last orbit at "
                f"{par.show(prev.u[-1])})"
            )
        reason = palc.boundary.reason
        if not palc.boundary.reached:
            what = grazing_margin(last)[3]
            reason = f"an impact speed reaches zero: the orbit {what}"
            if what == "gains an impact":
                reason = f"the orbit touches the stop between its impacts: it {what}"
            reason += " (located from this side: the branch does not continue beyond it)"
        status = f"ended at a grazing at {where}: {reason}"
        if not switch:
            status += "; the orbit with the new impact sequence can be followed with switch (--switch)"
            break
        new = _switch_orbit(last, param, value, sign, virtual)
        if new is None:
            status += "; no orbit with another impact sequence was found just past it to switch to"
            break
        orbit = new
        sign = math.copysign(1.0, new.model.params[param] - value)
        segment += 1
        if new.section_clearance() < SECTION_MARGIN:
            orbit = move_section(new, quiet_section(new))
    branch.status = status
    return branch
