"""Pseudo-arclength continuation of periodic orbits in one parameter.

Unknowns ``u = (x, p)``: a point of the orbit on the stroboscopic section and
the parameter.  Equations ``F(u) = P^n(x; p) - x = 0`` with Jacobian
``[P_x - I, P_p]`` from the variational equations (saltation matrices at the
impacts, parameter sensitivities as extra columns).  Each step predicts along
the tangent (the null vector of the Jacobian) and corrects by Newton's method
on ``F = 0`` plus the arclength condition (Keller 1977; Kuznetsov,
*Elements of Applied Bifurcation Theory*, ch. 10).

Special points are detected by sign changes of test functions between
consecutive points and located by regula falsi along the secant:

* fold: ``det(P_x - I)`` (a multiplier passes through +1);
* period-doubling: ``det(P_x + I)`` (a multiplier passes through -1);
* Neimark-Sacker: ``det(P_x) - 1`` with a complex pair (2-D maps; the
  bialternate-product test in general);
* grazing: the minimum of the guard along a nonimpacting (virtual) orbit
  reaches zero, or the number of impacts per period of an impacting orbit
  changes (an impact velocity reaches zero).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.errors import ConvergenceError, GrazingError, InvalidParameterError
from grazing.orbits.palc import Palc, PalcPoint, PalcSettings, locate, sign_changed
from grazing.orbits.shooting import PeriodicOrbit, _orbit_from, find_orbit, flow_map

SPECIAL_KINDS = ("fold", "period-doubling", "neimark-sacker", "grazing")


ContinuationSettings = PalcSettings
"""Options of :func:`continue_orbit` (see :class:`~grazing.orbits.palc.PalcSettings`)."""


@dataclass(frozen=True)
class SpecialPoint:
    """A located special point on a branch (between points ``index`` and ``index + 1``)."""

    kind: str
    index: int
    param: float
    orbit: PeriodicOrbit

    @property
    def multipliers(self) -> np.ndarray:
        return self.orbit.multipliers


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
        The periodic orbit at each point (state, multipliers, impacts...).
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

    def to_dataset(self) -> Any:
        """The branch as an :class:`xarray.Dataset` (one ``point`` per orbit)."""
        import xarray as xr

        import grazing

        mu = self.multipliers
        names = list(self.model.state_names)
        data = {
            "param": ("point", np.asarray(self.values)),
            "arclength": ("point", np.asarray(self.arclength)),
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
        if "theta_hat" in self.model.params:
            theta_hat = np.array([o.model.params["theta_hat"] for o in self.orbits])
            data["max_theta"] = ("point", theta_hat - self.guard_min)
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

    def to_netcdf(self, path: str | Path) -> None:
        """Save :meth:`to_dataset` to a NetCDF file."""
        self.to_dataset().to_netcdf(path, engine="h5netcdf")


# ----------------------------------------------------------------------------


def _evaluator(model: HybridModel, param: str, period: int, t0: float, virtual: bool):
    """``u = (x, p) -> (F, DF, orbit)`` for the branch equations ``P^n(x; p) - x = 0``."""
    n = model.n_states
    eye = np.eye(n)

    def evaluate(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, PeriodicOrbit]:
        m = model.with_params(**{param: float(u[-1])})
        x = u[:-1]
        fm = flow_map(m, x, t0=t0, periods=period, sensitivities=[param], virtual=virtual)
        F = fm.image - x
        orbit = _orbit_from(m, x, t0, period, fm, virtual, [float(np.max(np.abs(F)))])
        return F, np.hstack([fm.jacobian - eye, fm.sensitivity]), orbit

    return evaluate


def _test_function(kind: str, orbit: PeriodicOrbit) -> float:
    """Test function of a special point; for impacting grazing, the impact count."""
    J = orbit.monodromy
    eye = np.eye(J.shape[0])
    if kind == "fold":
        return float(np.linalg.det(J - eye))
    if kind == "period-doubling":
        return float(np.linalg.det(J + eye))
    if kind == "neimark-sacker":
        complex_pair = bool(np.any(np.abs(orbit.multipliers.imag) > 1e-12))
        return float(np.linalg.det(J) - 1.0) if complex_pair else math.nan
    if kind == "grazing":
        return orbit.guard_min if (orbit.virtual or orbit.impacts == 0) else float(orbit.impacts)
    raise ValueError(f"unknown special point kind {kind!r}")


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
    oa, ob = a.payload, b.payload
    if kind == "grazing" and not (oa.virtual or (oa.impacts == 0 and ob.impacts == 0)):
        # Impacting orbits: an impact appears or disappears (its speed reaches 0).
        if oa.impacts == ob.impacts:
            return None
        return locate(
            evaluate, a, b, lambda p: 1.0 if p.payload.impacts == oa.impacts else -1.0, s, bisect=True
        )
    if kind != "grazing" and oa.impacts != ob.impacts:
        return None  # the monodromy jumps at a grazing: smooth test functions do not apply
    if not sign_changed(_test_function(kind, oa), _test_function(kind, ob)):
        return None
    loc = locate(evaluate, a, b, lambda p: _test_function(kind, p.payload), s)
    return loc if loc is not None and _verified(kind, loc.payload) else None


def continue_orbit(
    model: HybridModel,
    param: str,
    start: float,
    stop: float,
    *,
    orbit: PeriodicOrbit | None = None,
    x0: np.ndarray | None = None,
    period: int | None = None,
    t0: float = 0.0,
    virtual: bool | None = None,
    settings: PalcSettings | None = None,
    detect: tuple[str, ...] = SPECIAL_KINDS,
    progress: Callable[[int, float], None] | None = None,
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
        the curve through them).
    orbit, x0, period
        Starting orbit, or a guess for it (see :func:`find_orbit`).
    virtual
        Ignore the stop (default: True when the starting orbit has no
        impacts, so nonimpacting orbits are followed through grazing, which is
        located and reported).
    settings
        Step control (:class:`~grazing.orbits.palc.PalcSettings`).
    detect
        Special points to detect and locate (any of ``SPECIAL_KINDS``).
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
    >>> round(br.special[0].param, 4)
    0.4451
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
    if orbit is None:
        if virtual is None:
            probe = find_orbit(m0, x0, period=period, t0=t0)
            virtual = probe.impacts == 0
            orbit = (
                probe
                if not virtual
                else find_orbit(m0, probe.state, period=probe.period, t0=t0, virtual=True)
            )
        else:
            orbit = find_orbit(m0, x0, period=period, t0=t0, virtual=virtual)
    elif virtual is None:
        virtual = orbit.virtual
    n = orbit.period
    evaluate = _evaluator(model, param, n, t0, bool(virtual))
    branch = Branch(model=model, param=param, period=n, virtual=bool(virtual))
    try:
        F, DF, orb = evaluate(np.append(orbit.state, start))
    except GrazingError as exc:
        raise ConvergenceError(f"cannot start the continuation: {exc}") from None
    first = PalcPoint(np.append(orbit.state, start), F, DF, orb)
    palc = Palc(
        evaluate,
        first,
        index=model.n_states,
        sign=math.copysign(1.0, stop - start),
        bounds={model.n_states: (min(start, stop), max(start, stop))},
        settings=s,
    )
    prev: PalcPoint | None = None
    for pt in palc:
        if prev is not None:
            for kind in detect:
                loc = _detect(evaluate, kind, prev, pt, s)
                if loc is not None:
                    branch.special.append(SpecialPoint(kind, len(branch) - 1, float(loc.u[-1]), loc.payload))
            branch.arclength.append(branch.arclength[-1] + float(np.linalg.norm(pt.u - prev.u)))
        else:
            branch.arclength.append(0.0)
        branch.values.append(float(pt.u[-1]))
        branch.orbits.append(pt.payload)
        prev = pt
        if progress is not None:
            progress(len(branch), float(pt.u[-1]))
    branch.status = palc.status
    return branch
