"""Plots of simulated trajectories: a state against time, delay plots.

The helpers draw on an ``Axes`` the caller supplies, so they work with pyplot
figures, with ``matplotlib.figure.Figure`` objects (no pyplot state, as the
report uses) and inside notebooks alike; matplotlib itself is never imported
here.  Labels, units, angles and the stop come from the model's metadata.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from grazing.experiment.signal import delay_coordinates
from grazing.plotting.labels import period_text, state_scale, state_unit, with_unit
from grazing.plotting.palette import MODE_COLOURS

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from grazing.core.solution import Solution


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
    modes: bool = True,
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
        Which state component.
    degrees
        Show a component measured in radians (its unit in the model's
        ``state_units``) in degrees, and the stop with it.
    span
        ``(start, end)`` of the time window, in ``time_unit`` (default: all).
    time_unit
        ``"periods"``: abscissa ``t / T`` (forcing periods; ``tau / 2 pi``
        for the pendulum); ``"time"``: ``t`` itself.
    stop
        Draw the stop as a horizontal line where it is a level of this
        component (:meth:`~grazing.core.model.HybridModel.stop_level`).
    samples
        Mark the stroboscopic samples ``sol.t, sol.samples``.
    modes
        A model with modes: shade each stay in a mode (:meth:`~grazing.Solution.mode_spans`) in
        that mode's colour (:data:`~grazing.plotting.palette.MODE_COLOURS`), labelled with its
        name.  Nothing is drawn for a model of one mode.
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

    A model with modes: the stays in each mode shaded.

    >>> sol = grazing.simulate(grazing.models.soft_impact_oscillator(), [0, 0], periods=2, trajectory=100)
    >>> ax = Figure().add_subplot()
    >>> plot_time_series(ax, sol)
    >>> [p.get_label() for p in ax.patches][:3]
    ["mode 'free'", "mode 'contact'", '_nolegend_']
    """
    if sol.trajectory is None or sol.trajectory_t is None:
        raise ValueError("the solution has no dense trajectory; simulate with trajectory=N")
    if time_unit not in ("periods", "time"):
        raise ValueError(f"time_unit must be 'periods' or 'time', got {time_unit!r}")
    tscale = 1.0 / sol.model.period if time_unit == "periods" else 1.0
    unit = sol.model.state_units[component]
    yscale = state_scale(unit, degrees)
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
    if modes:
        _shade_modes(ax, sol, tscale, span)
    ax.plot(t, y, **{"color": "tab:blue", "lw": 0.8, "label": "trajectory", **(line_kw or {})})
    level = sol.model.stop_level(component) if stop else None
    if level is not None:
        kw = {"color": "tab:red", "lw": 1.0, "ls": "--", "label": "stop", **(stop_kw or {})}
        ax.axhline(level * yscale, **kw)
    if samples:
        kw = {"color": "k", "marker": "o", "ms": 3.0, "ls": "none", "zorder": 3,
              "label": "stroboscopic samples", **(sample_kw or {})}  # fmt: skip
        ax.plot(ts, ys, **kw)
    if t.size:
        ax.set_xlim(t[0], t[-1])
    tname = sol.model.time_label
    ax.set_ylabel(with_unit(sol.model.state_labels[component], state_unit(unit, degrees)))
    if time_unit == "periods":
        ax.set_xlabel(f"{tname} / {period_text(sol.model.period)} (forcing periods)")
    else:
        ax.set_xlabel(tname)


def _shade_modes(ax: Axes, sol: Solution, tscale: float, span: tuple[float, float] | None) -> None:
    """Shade the stays of ``sol`` in each mode (times scaled by ``tscale``, within ``span``)."""
    labelled: set[int] = set()
    for start, end, k in sol.mode_spans():
        lo, hi = start * tscale, end * tscale
        if span is not None:
            lo, hi = max(lo, span[0]), min(hi, span[1])
        if hi <= lo:
            continue
        label = f"mode {sol.mode_names[k]!r}" if k not in labelled else "_nolegend_"
        labelled.add(k)
        ax.axvspan(lo, hi, color=MODE_COLOURS[k % len(MODE_COLOURS)], alpha=0.15, lw=0, label=label, zorder=0)


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
        Show a component measured in radians in degrees.
    stop
        Draw the stop as a horizontal and a vertical line where it is a level
        of this component.
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
    unit = sol.model.state_units[component]
    scale = state_scale(unit, degrees)
    _, xd, xn = delay_coordinates(sol.trajectory_t, sol.trajectory[:, component], delay)
    ax.plot(xd * scale, xn * scale, **{"color": "tab:blue", "lw": 0.6, **(line_kw or {})})
    level = sol.model.stop_level(component) if stop else None
    if level is not None:
        ax.axhline(level * scale, color="tab:red", lw=0.8, ls="--")
        ax.axvline(level * scale, color="tab:red", lw=0.8, ls="--")
    name, tname = sol.model.state_labels[component], sol.model.time_label
    lag = _delay_label(delay, T)
    ax.set_xlabel(with_unit(f"{name}({tname} − {lag})", state_unit(unit, degrees)))
    ax.set_ylabel(with_unit(f"{name}({tname})", state_unit(unit, degrees)))


def _delay_label(delay: float, T: float) -> str:
    """``π/2`` for a quarter of a 2π period, else a plain number."""
    if math.isclose(T, 2 * math.pi, rel_tol=1e-12):
        for num, den, text in ((1, 4, "π/2"), (1, 2, "π"), (1, 8, "π/4"), (1, 1, "2π")):
            if math.isclose(delay, T * num / den, rel_tol=1e-12):
                return text
    return f"{delay:.4g}"
