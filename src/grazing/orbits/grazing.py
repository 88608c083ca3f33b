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
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.engine.simulate import simulate
from grazing.errors import ConvergenceError, InvalidParameterError
from grazing.orbits.continuation import Branch, continue_orbit
from grazing.orbits.palc import Palc, PalcPoint, PalcSettings, locate, newton, sign_changed
from grazing.orbits.shooting import sorted_multipliers


@dataclass(frozen=True)
class GrazingPoint:
    """A grazing periodic orbit.

    Attributes
    ----------
    model
        Model with the parameter values at grazing.
    contact
        State at the grazing contact (on the stop, zero normal velocity).
    t_graze
        Time of the contact (any representative; see :attr:`phase`).
    monodromy
        Jacobian of the period-n map on the section through the contact
        (``t = t_graze``), computed ignoring the stop.
    multipliers
        Its eigenvalues (the nontrivial Floquet multipliers), largest first.
    accel
        ``L_f^2 h`` at the contact (positive: the orbit turns back from the stop).
    period
        Period of the orbit in forcing periods.
    """

    model: HybridModel
    contact: np.ndarray
    t_graze: float
    monodromy: np.ndarray
    multipliers: np.ndarray
    accel: float
    period: int = 1

    @property
    def abs_lambda(self) -> float:
        """Largest multiplier modulus."""
        return float(np.max(np.abs(self.multipliers)))

    @property
    def phase(self) -> float:
        """Forcing phase of the contact, ``t_graze mod T`` in ``[0, T)``."""
        return float(np.mod(self.t_graze, self.model.period))

    def params(self) -> dict[str, float]:
        return dict(self.model.params)


def _contact_system(model: HybridModel, names: tuple[str, ...], period: int):
    """``u = (y, t_g, *params) -> (F, DF, GrazingPoint)`` for the grazing equations."""
    n = model.n_states
    eye = np.eye(n)
    pidx = [[p.name for p in model.parameters].index(name) for name in names]

    def evaluate(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, GrazingPoint]:
        y, tg = u[:n], float(u[n])
        m = model.with_params(**{name: float(v) for name, v in zip(names, u[n + 1 :])})
        T = m.period
        sol = simulate(
            m,
            y,
            t0=tg,
            periods=period,
            phase=2 * math.pi * (tg / T % 1.0),
            jacobian=True,
            sensitivities=names,
            events=False,
            impacts="none",
        )
        J, S = sol.jacobian[:, :n], sol.jacobian[:, n:]
        fy = m.vector_field(y, tg)
        fend = m.vector_field(sol.x_final, sol.t_final)
        cd = m.contact_derivatives(y, tg)
        F = np.concatenate([sol.x_final - y, [cd["h"], cd["rate"]]])
        DF = np.zeros((n + 2, n + 1 + len(names)))
        DF[:n, :n] = J - eye
        DF[:n, n] = fend - J @ fy  # moving the start time along the periodic forcing
        DF[:n, n + 1 :] = S
        DF[n, :n], DF[n, n], DF[n, n + 1 :] = cd["h_x"], cd["h_t"], cd["h_p"][pidx]
        DF[n + 1, :n], DF[n + 1, n], DF[n + 1, n + 1 :] = cd["rate_x"], cd["rate_t"], cd["rate_p"][pidx]
        point = GrazingPoint(
            model=m,
            contact=y.copy(),
            t_graze=tg,
            monodromy=J,
            multipliers=sorted_multipliers(J),
            accel=cd["accel"],
            period=period,
        )
        return F, DF, point

    return evaluate


def refine_grazing(
    model: HybridModel,
    contact: np.ndarray,
    t_graze: float,
    free: str,
    *,
    period: int = 1,
    tol: float = 1e-12,
) -> GrazingPoint:
    """Solve the grazing equations for the contact state, time and parameter ``free``."""
    evaluate = _contact_system(model, (free,), period)
    u0 = np.concatenate([contact, [t_graze, model.params[free]]])
    pt = newton(evaluate, u0, PalcSettings(tol=tol, max_newton=12))  # n + 2 equations, n + 2 unknowns
    if pt is None:
        raise ConvergenceError(
            f"grazing point did not converge near {free} = {model.params[free]:.6g}; "
            "try a finer continuation step"
        )
    return pt.payload


def find_grazings(
    model: HybridModel,
    param: str = "eta",
    start: float = 0.2,
    stop: float = 1.0,
    *,
    period: int = 1,
    settings: PalcSettings | None = None,
    progress: Callable[[int, float], None] | None = None,
) -> tuple[list[GrazingPoint], Branch]:
    """Every grazing of the period-n nonimpacting orbit for ``param`` in ``[start, stop]``.

    The orbit is followed with the stop ignored, through folds, and every zero
    of its minimum guard value is located and refined.

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
    branch = continue_orbit(
        model,
        param,
        start,
        stop,
        period=period,
        virtual=True,
        settings=settings,
        detect=("fold", "grazing"),
        progress=progress,
    )
    points = []
    for sp_ in branch.special:
        if sp_.kind != "grazing":
            continue
        orbit = sp_.orbit
        assert orbit.x_guard_min is not None
        points.append(refine_grazing(orbit.model, orbit.x_guard_min, orbit.t_guard_min, param, period=period))
    return points, branch


@dataclass
class GrazingCurve:
    """A curve of grazing orbits in two parameters.

    Attributes
    ----------
    params
        The two parameter names, e.g. ``("eta", "theta_hat")``.
    points
        Grazing orbits along the curve.
    fold
        The turning point in the second parameter (its largest value on the
        curve, beyond which no grazing occurs), if the curve has one.
    status
        Why the continuation stopped.
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
    params: tuple[str, str] = ("eta", "theta_hat"),
    start: float = math.radians(5.0),
    *,
    search: tuple[float, float] = (0.2, 1.0),
    period: int = 1,
    settings: PalcSettings | None = None,
    progress: Callable[[int, float], None] | None = None,
) -> GrazingCurve:
    """Follow the grazing condition in two parameters, over the top and back down.

    The curve starts at the first grazing (smallest value of ``params[0]`` in
    ``search``) at ``params[1] = start``, moves with ``params[1]`` increasing,
    turns at the fold (located), and ends when ``params[1]`` is back at
    ``start`` on the other branch or ``params[0]`` leaves ``search``.

    Examples
    --------
    >>> import grazing
    >>> curve = grazing_curve(grazing.models.pendulum("B"))
    >>> round(math.degrees(curve.fold.model.params["theta_hat"]), 1)
    55.9
    """
    p1, p2 = params
    for p in params:
        if p not in model.params:
            raise InvalidParameterError(f"unknown parameter {p!r}")
    s = settings or PalcSettings(ds=0.02, ds_max=0.05)
    base = model.with_params(**{p2: start})
    first, _ = find_grazings(base, p1, search[0], search[1], period=period)
    if not first:
        raise ConvergenceError(
            f"no grazing of the period-{period} orbit for {p1} in {search} at {p2} = {start:g}"
        )
    g0 = first[0]
    n = model.n_states
    evaluate = _contact_system(model, params, period)
    u0 = np.concatenate([g0.contact, [g0.t_graze, g0.model.params[p1], g0.model.params[p2]]])
    F, DF, pay = evaluate(u0)
    palc = Palc(
        evaluate,
        PalcPoint(u0, F, DF, pay),
        index=n + 2,
        sign=1.0,
        bounds={n + 1: search, n + 2: (start, math.inf)},
        settings=s,
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


def save_dataset(ds: Any, path: str | Path) -> None:
    """Write an xarray dataset to NetCDF (h5netcdf engine)."""
    ds.to_netcdf(path, engine="h5netcdf")
