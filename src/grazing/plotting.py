"""Matplotlib helpers for simulation results.

matplotlib is imported lazily inside the functions that draw, so ``import
grazing`` never loads it and never selects a backend.  The helpers draw on an
``Axes`` the caller supplies, so they work with pyplot figures, with
``matplotlib.figure.Figure`` objects (no pyplot state, as the report uses) and
inside notebooks alike.

Two array helpers come with them: :func:`uniform_resample` puts a dense
trajectory (whose impact times appear twice, once per side of the impact) on a
uniform time grid, and :func:`delay_embedding` builds the Takens delay
coordinates ``(x(t - delay), x(t))`` from it.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from grazing.core.solution import Solution

__all__ = [
    "delay_embedding",
    "plot_delay",
    "plot_time_series",
    "uniform_resample",
]


def uniform_resample(
    t: np.ndarray, x: np.ndarray, dt: float, *, start: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Linearly interpolate samples ``x(t)`` on the uniform grid ``start + k dt``.

    Repeated times (a dense trajectory holds both states at every impact) are
    dropped, keeping the first occurrence; for a position-like component that
    is continuous across impacts, the two states agree anyway.

    Parameters
    ----------
    t
        Nondecreasing sample times, shape ``(n,)``.
    x
        Samples, shape ``(n,)`` or ``(n, m)``.
    dt
        Grid step (> 0).
    start
        First grid time (default ``t[0]``); the grid runs while it stays
        within ``t[-1]`` (up to a rounding tolerance of ``1e-9 dt``).

    Returns
    -------
    t_grid, x_grid
        The grid and the interpolated samples (same trailing shape as ``x``).

    Examples
    --------
    >>> t = np.array([0.0, 0.5, 0.5, 2.0])
    >>> tg, xg = uniform_resample(t, 2 * t, 0.5)
    >>> tg.tolist(), xg.tolist()
    ([0.0, 0.5, 1.0, 1.5, 2.0], [0.0, 1.0, 2.0, 3.0, 4.0])
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if t.ndim != 1 or t.size < 2 or x.shape[0] != t.size:
        raise ValueError("t must be 1-d with at least 2 points and x must have len(t) rows")
    if not (dt > 0 and math.isfinite(dt)):
        raise ValueError(f"dt must be a positive finite number, got {dt!r}")
    if np.any(np.diff(t) < 0):
        raise ValueError("t must be nondecreasing")
    keep = np.concatenate(([True], np.diff(t) > 0))
    t, x = t[keep], x[keep]
    t0 = float(t[0]) if start is None else float(start)
    n = math.floor((t[-1] - t0) / dt + 1e-9) + 1
    if n < 1 or t0 < t[0] - 1e-9 * dt:
        raise ValueError("the grid start lies outside the sampled times")
    tg = t0 + dt * np.arange(n)
    tg = np.clip(tg, t[0], t[-1])  # the last point may exceed t[-1] by rounding
    if x.ndim == 1:
        return tg, np.interp(tg, t, x)
    return tg, np.column_stack([np.interp(tg, t, x[:, j]) for j in range(x.shape[1])])


def delay_embedding(
    t: np.ndarray, x: np.ndarray, delay: float, *, dt: float | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Takens delay coordinates of a scalar signal: ``x(t - delay)`` and ``x(t)``.

    The signal is first resampled on a uniform grid (see
    :func:`uniform_resample`) whose step divides ``delay`` exactly, so the
    delayed copy is a shift by a whole number of grid steps and involves no
    further interpolation.

    Parameters
    ----------
    t, x
        Times and scalar samples (1-d, same length; repeated times allowed).
    delay
        The delay (> 0), in the units of ``t``.  The paper uses a quarter of a
        forcing period, ``pi/2`` in ``tau``.
    dt
        Grid step wanted; it is shrunk to ``delay / ceil(delay / dt)``.
        Default: the median positive spacing of ``t``.

    Returns
    -------
    t_now, x_delayed, x_now
        Grid times ``t`` (from ``t[0] + delay``), ``x(t - delay)`` and ``x(t)``.

    Examples
    --------
    A sine wave delayed by a quarter of its period gives the unit circle:

    >>> t = np.linspace(0.0, 4 * np.pi, 401)
    >>> _, xd, xn = delay_embedding(t, np.sin(t), np.pi / 2)
    >>> bool(np.allclose(xd**2 + xn**2, 1.0, atol=1e-3))
    True
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if x.ndim != 1:
        raise ValueError("delay_embedding takes a scalar signal (1-d x)")
    if not (delay > 0 and math.isfinite(delay)):
        raise ValueError(f"delay must be a positive finite number, got {delay!r}")
    if dt is None:
        steps = np.diff(t)
        steps = steps[steps > 0]
        if steps.size == 0:
            raise ValueError("t has no positive time steps")
        dt = float(np.median(steps))
    shift = max(1, math.ceil(delay / dt - 1e-9))
    tg, xg = uniform_resample(t, x, delay / shift)
    if tg.size <= shift:
        raise ValueError("the signal is shorter than the delay")
    return tg[shift:], xg[:-shift], xg[shift:]


def _angle_scale(degrees: bool) -> float:
    return 180.0 / math.pi if degrees else 1.0


def plot_time_series(
    ax: Axes,
    sol: Solution,
    *,
    component: int = 0,
    degrees: bool = False,
    span: tuple[float, float] | None = None,
    time_unit: str = "periods",
    stop: bool = True,
    samples: bool = True,
    line_kw: dict[str, Any] | None = None,
    sample_kw: dict[str, Any] | None = None,
    stop_kw: dict[str, Any] | None = None,
) -> None:
    """Draw one state component of a simulated dense trajectory against time.

    Parameters
    ----------
    ax
        Axes to draw on.
    sol
        A solution with a dense trajectory (``simulate(..., trajectory=N)``).
    component
        Which state component (0: ``theta`` for the pendulum).
    degrees
        Convert the component from radians to degrees (and the stop angle).
    span
        ``(start, end)`` of the time window, in ``time_unit`` (default: all).
    time_unit
        ``"periods"``: abscissa ``t / T`` (forcing periods; ``tau / 2 pi``
        for the pendulum); ``"time"``: ``t`` itself.
    stop
        Draw the stop (``theta_hat``) as a horizontal line, if the model has a
        ``theta_hat`` parameter and ``component == 0``.
    samples
        Mark the stroboscopic samples ``sol.t, sol.samples``.
    line_kw, sample_kw, stop_kw
        Extra keyword arguments for the trajectory line, the sample markers and
        the stop line.

    Examples
    --------
    >>> import math, grazing
    >>> from matplotlib.figure import Figure
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> sol = grazing.simulate(m, [0.0, 0.0], transient=300, periods=10, trajectory=100)
    >>> ax = Figure().add_subplot()
    >>> plot_time_series(ax, sol, degrees=True)
    >>> len(ax.lines) >= 2
    True
    """
    if sol.trajectory is None or sol.trajectory_t is None:
        raise ValueError("the solution has no dense trajectory; simulate with trajectory=N")
    if time_unit not in ("periods", "time"):
        raise ValueError(f"time_unit must be 'periods' or 'time', got {time_unit!r}")
    tscale = 1.0 / sol.model.period if time_unit == "periods" else 1.0
    yscale = _angle_scale(degrees)
    t = sol.trajectory_t * tscale
    y = sol.trajectory[:, component] * yscale
    ts = sol.t * tscale
    ys = sol.samples[:, component] * yscale
    if span is not None:
        lo, hi = span
        sel = (t >= lo) & (t <= hi)
        t, y = t[sel], y[sel]
        sel_s = (ts >= lo) & (ts <= hi)
        ts, ys = ts[sel_s], ys[sel_s]
    ax.plot(t, y, **{"color": "tab:blue", "lw": 0.8, "label": "trajectory", **(line_kw or {})})
    if stop and component == 0 and "theta_hat" in sol.model.params:
        th = sol.model.params["theta_hat"] * yscale
        kw = {"color": "tab:red", "lw": 1.0, "ls": "--", "label": "stop θ̂", **(stop_kw or {})}
        ax.axhline(th, **kw)
    if samples:
        kw = {"color": "k", "marker": "o", "ms": 3.0, "ls": "none", "zorder": 3,
              "label": "stroboscopic samples", **(sample_kw or {})}  # fmt: skip
        ax.plot(ts, ys, **kw)
    if t.size:
        ax.set_xlim(t[0], t[-1])
    tname = _time_name(sol)
    ax.set_ylabel(f"{_state_name(sol, component)}{_unit(sol, component, degrees)}")
    if time_unit == "periods":
        period = "2π" if math.isclose(sol.model.period, 2 * math.pi) else "T"
        ax.set_xlabel(f"{tname} / {period} (forcing periods)")
    else:
        ax.set_xlabel(tname)


def plot_delay(
    ax: Axes,
    sol: Solution,
    delay: float | None = None,
    *,
    component: int = 0,
    degrees: bool = False,
    stop: bool = True,
    line_kw: dict[str, Any] | None = None,
) -> None:
    """Draw the delay plot ``x(t)`` against ``x(t - delay)`` of a dense trajectory.

    This is the Takens reconstruction the paper applies to its measured
    angles (fig 3(b),(d)), here from the simulated trajectory.

    Parameters
    ----------
    ax
        Axes to draw on.
    sol
        A solution with a dense trajectory.
    delay
        The delay in model time (default: a quarter forcing period, ``T/4``).
    component
        Which state component.
    degrees
        Convert radians to degrees.
    stop
        Draw the stop angle as a horizontal and a vertical line (pendulum only).
    line_kw
        Extra keyword arguments for the curve.

    Examples
    --------
    >>> import math, grazing
    >>> from matplotlib.figure import Figure
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> sol = grazing.simulate(m, [0.0, 0.0], transient=300, periods=10, trajectory=200)
    >>> ax = Figure().add_subplot()
    >>> plot_delay(ax, sol, degrees=True)
    >>> ax.get_xlabel()
    'θ(τ − π/2) (degrees)'
    """
    if sol.trajectory is None or sol.trajectory_t is None:
        raise ValueError("the solution has no dense trajectory; simulate with trajectory=N")
    T = sol.model.period
    if delay is None:
        delay = T / 4
    scale = _angle_scale(degrees)
    _, xd, xn = delay_embedding(sol.trajectory_t, sol.trajectory[:, component], delay)
    ax.plot(xd * scale, xn * scale, **{"color": "tab:blue", "lw": 0.6, **(line_kw or {})})
    if stop and component == 0 and "theta_hat" in sol.model.params:
        th = sol.model.params["theta_hat"] * scale
        ax.axhline(th, color="tab:red", lw=0.8, ls="--")
        ax.axvline(th, color="tab:red", lw=0.8, ls="--")
    name, unit, tname = _state_name(sol, component), _unit(sol, component, degrees), _time_name(sol)
    lag = _delay_label(delay, T)
    ax.set_xlabel(f"{name}({tname} − {lag}){unit}")
    ax.set_ylabel(f"{name}({tname}){unit}")


def _state_name(sol: Solution, component: int) -> str:
    labels = getattr(sol.model, "state_labels", None)
    return str(labels[component]) if labels else f"x{component + 1}"


def _time_name(sol: Solution) -> str:
    try:
        name = str(sol.model.symbolic.time)
    except AttributeError:  # pragma: no cover - a model without a symbolic form
        return "t"
    return {"tau": "τ"}.get(name, name)


def _unit(sol: Solution, component: int, degrees: bool) -> str:
    """Axis unit: angles of the pendulum-like models (those with a ``theta_hat``)."""
    if degrees:
        return " (degrees)" if component == 0 else " (degrees per unit time)"
    if component == 0 and "theta_hat" in sol.model.params:
        return " (rad)"
    return ""


def _delay_label(delay: float, T: float) -> str:
    """``π/2`` for a quarter of a 2π period, else a plain number."""
    if math.isclose(T, 2 * math.pi, rel_tol=1e-12):
        for num, den, text in ((1, 4, "π/2"), (1, 2, "π"), (1, 8, "π/4"), (1, 1, "2π")):
            if math.isclose(delay, T * num / den, rel_tol=1e-12):
                return text
    return f"{delay:.4g}"
