"""Matplotlib helpers for simulation results.

matplotlib is imported lazily inside the functions that draw, so ``import
grazing`` never loads it and never selects a backend.  The helpers draw on an
``Axes`` the caller supplies, so they work with pyplot figures, with
``matplotlib.figure.Figure`` objects (no pyplot state, as the report uses) and
inside notebooks alike.

For brute-force sweeps (datasets of :func:`grazing.sweeps.sweep` and
:func:`grazing.sweeps.parameter_map`): :func:`plot_bifurcation` draws a
bifurcation diagram with its periodic windows labelled (:func:`find_windows`,
:func:`visible_windows`, :func:`label_windows`), :func:`mark_grazings` marks
grazing points, and :func:`plot_period_map` colours a two-parameter map by
period.

Two array helpers come with them: :func:`uniform_resample` puts a dense
trajectory (whose impact times appear twice, once per side of the impact) on a
uniform time grid, and :func:`delay_coordinates` builds the Takens delay
coordinates ``(x(t - delay), x(t))`` from it.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from grazing.sweeps.windows import Window, find_windows

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from grazing.core.solution import Solution

__all__ = [
    "Window",
    "delay_coordinates",
    "find_windows",
    "label_windows",
    "mark_grazings",
    "param_label",
    "period_classes",
    "plot_bifurcation",
    "plot_delay",
    "plot_period_map",
    "plot_time_series",
    "uniform_resample",
    "visible_windows",
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


def delay_coordinates(
    t: np.ndarray, x: np.ndarray, delay: float, *, dt: float | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Takens delay coordinates of a scalar signal sampled at any times: ``x(t - delay)`` and ``x(t)``.

    The signal is resampled on a uniform grid (see :func:`uniform_resample`)
    whose step divides ``delay`` exactly, then embedded with a whole number of
    grid steps by :func:`grazing.experiment.signal.delay_embedding`.

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
    >>> _, xd, xn = delay_coordinates(t, np.sin(t), np.pi / 2)
    >>> bool(np.allclose(xd**2 + xn**2, 1.0, atol=1e-3))
    True
    """
    from grazing.experiment.signal import delay_embedding

    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if x.ndim != 1:
        raise ValueError("delay_coordinates takes a scalar signal (1-d x)")
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
    vectors = delay_embedding(xg, shift, 2)
    return tg[shift:], vectors[:, 0], vectors[:, 1]


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
    _, xd, xn = delay_coordinates(sol.trajectory_t, sol.trajectory[:, component], delay)
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


# ----------------------------------------------------------------------------
# Brute-force bifurcation diagrams and period maps (datasets from grazing.sweeps)

ANGLE_PARAMS = frozenset({"theta_hat"})
"""Parameters that are angles in radians (shown in degrees when ``degrees=True``)."""

_PARAM_SYMBOLS = {"eta": "η", "theta_hat": "θ̂", "alpha": "α", "beta": "β", "r": "r"}


def _sweep_param(ds: Any) -> str:
    """The swept parameter's name (the first one for a two-parameter map)."""
    return str(ds.attrs.get("params", "value")).split(",")[0]


def _param_scale(name: str, degrees: bool) -> float:
    return 180.0 / math.pi if degrees and name in ANGLE_PARAMS else 1.0


def param_label(name: str, degrees: bool = True) -> str:
    """Axis label for a model parameter: ``"η"``, ``"θ̂ (degrees)"``, ``"θ̂ (rad)"``.

    Examples
    --------
    >>> param_label("eta"), param_label("theta_hat"), param_label("theta_hat", degrees=False)
    ('η', 'θ̂ (degrees)', 'θ̂ (rad)')
    """
    symbol = _PARAM_SYMBOLS.get(name, name)
    if name in ANGLE_PARAMS:
        return f"{symbol} (degrees)" if degrees else f"{symbol} (rad)"
    return symbol


def visible_windows(
    windows: list[Window],
    span: float,
    *,
    min_period: int = 2,
    min_points: int = 3,
    min_fraction: float = 0.005,
    impacting_one: bool = True,
) -> list[Window]:
    """The periodic windows wide enough to be labelled on a diagram.

    Parameters
    ----------
    windows
        From :func:`find_windows`.
    span
        Width of the parameter axis (same units as the windows).
    min_period
        Smallest period labelled (period 1 with impacts is added by
        ``impacting_one``; nonimpacting period 1 is never in the list).
    min_points
        Fewest sweep points a window must hold.
    min_fraction
        Smallest width of a window as a fraction of ``span``.
    impacting_one
        Also keep impacting period-1 windows.

    Examples
    --------
    >>> ws = [Window(4, True, 0, 9, 0.0, 0.9, 0.0, 0.95), Window(5, True, 10, 10, 1.0, 1.0, 0.95, 1.05)]
    >>> [w.period for w in visible_windows(ws, 10.0)]
    [4]
    """
    out = []
    for w in windows:
        keep = w.period >= max(min_period, 2) or (impacting_one and w.period == 1 and w.impacting)
        if keep and w.points >= min_points and w.width >= min_fraction * span:
            out.append(w)
    return out


def label_windows(
    ax: Axes,
    windows: list[Window],
    *,
    scale: float = 1.0,
    rows: tuple[float, ...] = (0.955, 0.895, 0.835),
    fontsize: float = 9.0,
    min_gap: float = 0.006,
    color: str = "tab:blue",
) -> list[Window]:
    """Write the period above each window, with a bar showing its extent, without collisions.

    The labels sit near the top of the axes (``rows`` in axes fractions).  Each
    label occupies its bar and its text (estimated from the font size and the
    axes width); the windows are placed widest first, each on the first row
    where it collides with nothing already placed there, ``min_gap`` (axes
    fraction) apart.  A window that fits on no row is left unlabelled: the
    caller lists the windows in a table anyway.  Draw the diagram and set the x
    limits first.

    Parameters
    ----------
    ax
        The diagram's axes.
    windows
        The windows to label (e.g. from :func:`visible_windows`).
    scale
        Factor from the windows' parameter units to the x axis (``180/pi``
        for an angle shown in degrees).
    rows
        Heights of the label rows, in axes fractions.
    fontsize
        Font size of the labels.
    min_gap
        Smallest distance between two labels' extents on one row, in axes fractions.
    color
        Colour of the labels and bars.

    Returns
    -------
    list of Window
        The windows labelled, in the order given.
    """
    x0, x1 = ax.get_xlim()
    trans = ax.get_xaxis_transform()  # x in data, y in axes fraction
    width_pt = max(ax.get_position().width * ax.figure.get_figwidth() * 72.0, 1.0)

    def extent(w: Window) -> tuple[float, float]:
        c = (w.center * scale - x0) / (x1 - x0)
        half_text = 0.5 * 0.62 * fontsize * len(w.label.split(" ")[0]) / width_pt
        lo = min((w.lo * scale - x0) / (x1 - x0), c - half_text)
        hi = max((w.hi * scale - x0) / (x1 - x0), c + half_text)
        return lo, hi

    taken: list[list[tuple[float, float]]] = [[] for _ in rows]
    placed: dict[int, int] = {}
    for k in sorted(range(len(windows)), key=lambda i: -windows[i].width):
        lo, hi = extent(windows[k])
        for r, row in enumerate(taken):
            if all(hi + min_gap <= a or lo - min_gap >= b for a, b in row):
                row.append((lo, hi))
                placed[k] = r
                break
    out = []
    for k, w in enumerate(windows):
        if k not in placed:
            continue
        y = rows[placed[k]]
        c = w.center * scale
        ax.plot([w.lo * scale, w.hi * scale], [y - 0.012, y - 0.012], transform=trans, color=color,
                lw=1.4, solid_capstyle="butt", clip_on=False)  # fmt: skip
        ax.text(c, y, w.label.split(" ")[0], transform=trans, ha="center", va="bottom",
                fontsize=fontsize, color=color, clip_on=False)  # fmt: skip
        out.append(w)
    return out


def mark_grazings(
    ax: Axes,
    values: list[float] | np.ndarray,
    *,
    scale: float = 1.0,
    labels: list[str] | None = None,
    color: str = "tab:red",
    fontsize: float = 9.0,
) -> None:
    """Mark grazing points as dashed vertical lines (labelled at the bottom).

    Parameters
    ----------
    ax
        Axes whose x axis is the swept parameter.
    values
        Parameter values of the grazings (in the units before ``scale``).
    scale
        Factor to the x axis units.
    labels
        One text per line (default: the value, e.g. ``"0.4451"``).
    color, fontsize
        Style of the lines and labels.
    """
    trans = ax.get_xaxis_transform()
    for k, v in enumerate(values):
        x = float(v) * scale
        ax.axvline(x, color=color, lw=0.9, ls="--", zorder=1)
        text = labels[k] if labels is not None else f"{x:.4g}"
        ax.text(x, 0.015, f" {text}", transform=trans, rotation=90, ha="right", va="bottom",
                fontsize=fontsize, color=color,
                bbox={"fc": "white", "ec": "none", "alpha": 0.75, "pad": 0.8})  # fmt: skip


def plot_bifurcation(
    ax: Axes,
    ds: Any,
    *,
    component: int = 0,
    degrees: bool = True,
    windows: bool = True,
    nonimpacting: bool = True,
    stop: bool = False,
    label: str | None = None,
    dot_kw: dict[str, Any] | None = None,
    window_kw: dict[str, Any] | None = None,
) -> list[Window]:
    """Draw a brute-force bifurcation diagram: the sampled states against the parameter.

    Every stroboscopic sample of every point is a small black dot, as in the
    paper's figs 2, 7, 8, 10 and 12.  Works for any one-parameter dataset of
    :func:`grazing.sweeps.sweep` (direct simulation or discontinuity map).

    Parameters
    ----------
    ax
        Axes to draw on.
    ds
        The sweep's dataset.
    component
        Which state component to plot (0: ``theta`` for the pendulum).
    degrees
        Show angles in degrees: the state component (as
        :func:`plot_time_series` does) and the parameter if it is an angle
        (``theta_hat``).
    windows
        Label the periodic windows (:func:`visible_windows` with its defaults,
        or ``window_kw`` passed to it) with :func:`label_windows`.
    nonimpacting
        Shade the parameter ranges where the motion has no impacts (and say so
        when the range is wide enough).
    stop
        Draw the stop: a horizontal line at a fixed ``theta_hat``, or the line
        ``theta = theta_hat`` when ``theta_hat`` is the swept parameter (off by
        default: the samples at a fixed forcing phase seldom come near it).
    label
        x-axis label (default: :func:`param_label`).
    dot_kw
        Extra keyword arguments for the dots (``ax.plot``).
    window_kw
        Keyword arguments for :func:`visible_windows` (``min_points``,
        ``min_fraction``, ...).

    Returns
    -------
    list of Window
        All the runs of the sweep (:func:`find_windows`), in parameter units.

    Examples
    --------
    >>> import math, numpy as np, grazing
    >>> from matplotlib.figure import Figure
    >>> from grazing.sweeps import sweep
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> ds = sweep(m, "eta", np.linspace(0.44, 0.46, 20), periods=20, workers=1, lyapunov=False)
    >>> ax = Figure().add_subplot()
    >>> runs = plot_bifurcation(ax, ds)
    >>> runs[0].label, ax.get_xlabel()
    ('1 (no impacts)', 'η')
    """
    name = _sweep_param(ds)
    xscale = _param_scale(name, degrees)
    yscale = _angle_scale(degrees)
    value = np.asarray(ds["value"].values, dtype=float)
    samples = np.asarray(ds["samples"].values, dtype=float)[:, :, component]  # (point, sample)
    x = np.repeat(value * xscale, samples.shape[1])
    y = samples.ravel() * yscale
    ok = np.isfinite(y)
    kw = {"ls": "none", "marker": ".", "ms": 1.2, "mew": 0.0, "color": "k", "rasterized": True}
    kw.update(dot_kw or {})
    ax.plot(x[ok], y[ok], **kw)
    lo, hi = float(value.min() * xscale), float(value.max() * xscale)
    pad = 0.005 * (hi - lo) if hi > lo else 0.5
    ax.set_xlim(lo - pad, hi + pad)
    ymin, ymax = (float(y[ok].min()), float(y[ok].max())) if ok.any() else (0.0, 1.0)
    fixed_stop = ds.attrs.get("param_theta_hat")
    if stop and component == 0 and fixed_stop is not None:
        th = float(fixed_stop) * yscale
        ax.axhline(th, color="tab:red", lw=0.8, ls="-", alpha=0.6, zorder=0)
        ymax = max(ymax, th)
    elif stop and component == 0 and name in ANGLE_PARAMS:
        ax.plot([lo - pad, hi + pad], [(lo - pad) / xscale * yscale, (hi + pad) / xscale * yscale],
                color="tab:red", lw=0.8, alpha=0.6, zorder=0)  # fmt: skip
    rng = max(ymax - ymin, 1e-9)
    ax.set_ylim(ymin - 0.04 * rng, ymax + 0.32 * rng)  # headroom for three rows of window labels
    runs = find_windows(ds)
    if nonimpacting:
        trans = ax.get_xaxis_transform()
        for w in runs:
            if w.period == 1 and not w.impacting:
                ax.axvspan(w.lo * xscale, w.hi * xscale, color="#dfe9f3", lw=0, zorder=-1)
                if w.width * xscale >= 0.12 * (hi - lo):
                    ax.text(w.center * xscale, 0.03, "period 1,\nno impacts", transform=trans,
                            ha="center", va="bottom", fontsize=9, color="#4a6b8a")  # fmt: skip
    if windows:
        shown = visible_windows(runs, (hi - lo) / xscale if hi > lo else 1.0, **(window_kw or {}))
        label_windows(ax, shown, scale=xscale)
    ax.set_xlabel(label if label is not None else param_label(name, degrees))
    comp = str(ds["component"].values[component]) if "component" in ds.coords else f"x{component + 1}"
    sym = {"theta": "θ", "dtheta": "θ′"}.get(comp, comp)
    unit = (" (degrees)" if component == 0 else " (degrees per unit τ)") if degrees else ""
    ax.set_ylabel(f"{sym}{unit} at τ = 2πk")
    return runs


def period_classes(
    period: np.ndarray, impacts_per_period: np.ndarray, max_period: int = 8
) -> tuple[np.ndarray, list[str], list[str]]:
    """Map detected periods to the colour classes of :func:`plot_period_map`.

    Classes, in order: failed (period -1), aperiodic (0), period 1 without
    impacts, period 1 with impacts, periods 2 ... ``max_period``, and longer
    periods.

    Returns
    -------
    codes, labels, colors
        An integer class per point (same shape as ``period``), and the label
        and colour of every class.

    Examples
    --------
    >>> codes, labels, _ = period_classes(np.array([1, 1, 0, 3, 12]), np.array([0, 1, 1, 1, 1]), 4)
    >>> codes.tolist(), [labels[c] for c in codes]
    ([2, 3, 1, 5, 7], ['1, no impacts', '1, impacting', 'aperiodic', '3', '> 4'])
    """
    period = np.asarray(period, dtype=int)
    imp = np.asarray(impacts_per_period, dtype=float) > 0
    codes = np.where(period == 0, 1, 0)  # failed points (period -1) stay 0
    codes = np.where(period == 1, np.where(imp, 3, 2), codes)
    codes = np.where((period >= 2) & (period <= max_period), period + 2, codes)
    codes = np.where(period > max_period, max_period + 3, codes)
    labels = ["failed", "aperiodic", "1, no impacts", "1, impacting"]
    labels += [str(p) for p in range(2, max_period + 1)] + [f"> {max_period}"]
    palette = ["#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
               "#17becf", "#bcbd22", "#7f7f7f", "#aec7e8", "#ffbb78", "#98df8a"]  # fmt: skip
    colors = ["#ffffff", "#000000", "#e4e4e4", "#9ecae1"]
    colors += [palette[(p - 2) % len(palette)] for p in range(2, max_period + 1)] + ["#f7b6d2"]
    return codes, labels, colors


def plot_period_map(
    ax: Axes,
    ds: Any,
    *,
    max_period: int = 8,
    degrees: bool = True,
    colorbar: bool = True,
) -> Any:
    """Colour a two-parameter map by the detected period.

    Aperiodic points (no period up to the detection limit) are black,
    nonimpacting period 1 light grey, impacting period 1 light blue, periods
    2 ... ``max_period`` distinct colours (:func:`period_classes`).  Only the
    classes present get a colour-bar entry; the mesh's values index them.

    Parameters
    ----------
    ax
        Axes to draw on.
    ds
        A dataset from :func:`grazing.sweeps.parameter_map` (dimensions
        ``(param2, param1)``); param1 is on the x axis.
    max_period
        Longest period with a colour of its own.
    degrees
        Show angle parameters in degrees.
    colorbar
        Add a colour bar naming the classes.

    Returns
    -------
    matplotlib.collections.QuadMesh
        The mesh drawn.

    Examples
    --------
    >>> import xarray as xr
    >>> from matplotlib.figure import Figure
    >>> ds = xr.Dataset({"period": (("theta_hat", "eta"), [[1, 2], [0, 1]]),
    ...                  "impacts_per_period": (("theta_hat", "eta"), [[0, 1], [1, 1.0]])},
    ...                 coords={"theta_hat": [0.1, 0.2], "eta": [0.4, 0.5]},
    ...                 attrs={"params": "eta,theta_hat"})
    >>> mesh = plot_period_map(Figure().add_subplot(), ds, colorbar=False)
    >>> mesh.get_array().reshape(2, 2).tolist()  # classes present: aperiodic, 1 no impacts, 1 impacting, 2
    [[1, 3], [0, 2]]
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap

    p1, p2 = str(ds.attrs.get("params", "x,y")).split(",")[:2]
    codes, labels, colors = period_classes(ds["period"].values, ds["impacts_per_period"].values, max_period)
    codes = np.asarray(codes)
    if ds["period"].dims != (p2, p1):
        codes = codes.T
    present = np.unique(codes)  # only the classes that occur get a colour and a colour-bar entry
    index = np.searchsorted(present, codes)
    x = np.asarray(ds[p1].values, dtype=float) * _param_scale(p1, degrees)
    y = np.asarray(ds[p2].values, dtype=float) * _param_scale(p2, degrees)
    cmap = ListedColormap([colors[k] for k in present])
    norm = BoundaryNorm(np.arange(len(present) + 1) - 0.5, cmap.N)
    mesh = ax.pcolormesh(x, y, index, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
    ax.set_xlabel(param_label(p1, degrees))
    ax.set_ylabel(param_label(p2, degrees))
    if colorbar:
        cb = ax.figure.colorbar(mesh, ax=ax, ticks=np.arange(len(present)), fraction=0.04, pad=0.02)
        cb.ax.set_yticklabels([labels[k] for k in present], fontsize=8)
        cb.set_label("detected period", fontsize=9)
    return mesh
