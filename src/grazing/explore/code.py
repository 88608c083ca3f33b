"""Copy as code: the Python and the command lines that reproduce what the explorer shows.

Each text sets every parameter explicitly and gives every start state in full
(``repr`` of the floats), so that running it computes the same diagram, the same
point and the same branch as the page: the diagram with
:func:`grazing.sweeps.sweep` (``grazing sweep``) or
:func:`~grazing.sweeps.parameter_map` (``grazing map``) and the explorer's
settings; the clicked point with :func:`grazing.simulate` (``grazing
simulate``) from the diagram's state there, and its orbit with
:func:`~grazing.orbits.find_orbit` (``grazing orbit``); the branch with
:func:`~grazing.orbits.continue_orbit` (``grazing continue``), both ways.  On a
model with modes every run, orbit and branch names the mode it starts in (``mode=``,
``--mode``), as the page started them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from grazing.explore.basins import BasinView
from grazing.explore.branch import Curves, Grazings, grazed_orbit
from grazing.explore.diagram import View
from grazing.explore.point import PointReport
from grazing.explore.source import command_line

__all__ = ["Code", "view_code"]


@dataclass(frozen=True)
class Code:
    """The view as Python (one script that prints what the page shows) and as command lines.

    Parameters
    ----------
    python
        The Python script.
    cli
        The command lines, one per line.

    Examples
    --------
    What :func:`view_code` writes:

    >>> import math, grazing
    >>> from grazing.explore import View, compute_diagram, inspect_click
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> view = View.of(m, {"eta": (0.44, 0.46)}, num=5)
    >>> point = inspect_click(compute_diagram(view, workers=1), [0.446])
    >>> code = view_code(view, point)
    >>> code.cli.splitlines()[0].split(" --set")[0], "find_orbit(point" in code.python
    ('grazing sweep --model pendulum', True)
    """

    python: str
    cli: str


def _floats(x: np.ndarray) -> str:
    return "[" + ", ".join(repr(float(v)) for v in x) + "]"


def _state_arg(x: np.ndarray) -> str:
    return ",".join(repr(float(v)) for v in x)


def _linspace(lo: float, hi: float, num: int) -> str:
    return f"np.linspace({lo!r}, {hi!r}, {num})"


def _mode_kw(mode: str | None) -> str:
    """``, mode='name'`` for a run of a model with modes starting in ``mode``; "" without modes."""
    return "" if mode is None else f", mode={mode!r}"


def _mode_arg(mode: str | None) -> list[str]:
    """``--mode NAME`` for a run of a model with modes starting in ``mode``; nothing without modes."""
    return [] if mode is None else ["--mode", mode]


def view_code(
    view: View,
    point: PointReport | None = None,
    *,
    continued: bool = False,
    basins: BasinView | None = None,
    grazings: Grazings | None = None,
    curves: Curves | None = None,
) -> Code:
    """The code of the diagram, of the clicked ``point``, of its continuation (``continued``), of the
    ``basins`` found at it and of the ``grazings`` sought over the range (the other explored parameter's
    value held there: :func:`~grazing.explore.branch.grazings_in_view`) and of the bifurcation ``curves``
    followed from the clicked point on a period map (:func:`~grazing.explore.branch.follow_click_curves`).

    The Python text imports what it uses and prints, for the point, ``period P
    impacts K`` (impacts per period of the motion) and then ``orbit P K`` (Newton's
    orbit); for the branch, one line per direction with its special points; for the
    basins, one line per attractor (``attractor KIND PERIOD FRACTION``); for the
    grazings, ``grazings [VALUE, ...]``; for each curve, ``curve KIND POINTS STATUS``.
    Command lines need a model given by ``--model`` (a built-in name or a file): for a
    model object given in Python, :attr:`Code.cli` says so instead.

    Parameters
    ----------
    view
        The diagram or map.
    point
        The clicked point, if any.
    continued
        Add the continuation of its orbit.
    basins
        The basins found at the point, if any.
    grazings
        The grazings sought over the range, if any.
    curves
        The bifurcation curves followed from the point, if any.

    Returns
    -------
    Code
        The Python script and the command lines.

    Examples
    --------
    The script runs as it is, and prints what the page shows:

    >>> import math, grazing
    >>> from grazing.explore import View, compute_diagram, inspect_click
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> view = View.of(m, {"eta": (0.44, 0.46)}, num=5)
    >>> point = inspect_click(compute_diagram(view, workers=1), [0.446])
    >>> code = view_code(view, point)
    >>> import contextlib, io
    >>> out = io.StringIO()
    >>> with contextlib.redirect_stdout(out):
    ...     exec(code.python, {})
    >>> out.getvalue().splitlines()[0]
    'period 5 impacts 1.0'
    """
    orbits = ["continue_orbit", "find_orbit"] if point is not None else []
    orbits += ["find_grazings"] if grazings is not None else []
    orbits += ["follow_curve"] if curves is not None and point is not None and point.orbit is not None else []
    py = ["import numpy as np", *view.source.python_imports, "", "import grazing"]
    py += ["from grazing.attractors import basins"] if basins is not None and point is not None else []
    py += [f"from grazing.orbits import {', '.join(sorted(orbits))}"] if orbits else []
    py += [f"from grazing.sweeps import {'sweep' if len(view.axes) == 1 else 'parameter_map'}", ""]
    py += view.source.python_lines(view.model)
    cli: list[str] = []
    try:
        model_args: list[str] | None = view.source.cli_args(view.model, varied=view.names)
    except ValueError as exc:
        model_args = None
        cli.append(f"# {exc} (--model FILE.py:OBJECT)")
    _diagram_code(view, model_args, py, cli)
    if point is not None:
        point_args = None if model_args is None else view.source.cli_args(point.model, varied=())
        _point_code(view, point, continued, point_args, py, cli)
        if basins is not None:
            _basins_code(basins, point_args, py, cli)
        if curves is not None and point.orbit is not None:
            _curves_code(view, point, curves, model_args is not None, py, cli)
    if grazings is not None:
        _grazings_code(view, grazings, model_args is not None, py, cli)
    return Code("\n".join(py) + "\n", "\n".join(cli) + "\n")


def _diagram_code(view: View, model_args: list[str] | None, py: list[str], cli: list[str]) -> None:
    """The diagram (or the period map): its Python, and its command line where ``model_args``."""
    s = view.settings
    common = f"transient={s.transient}, periods={s.periods}, lyapunov={s.lyapunov}"
    a = view.axes[0]
    if len(view.axes) == 1:
        py += [
            "# the diagram",
            f"ds = sweep(model, {a.name!r}, {_linspace(a.lo, a.hi, a.num)}, {common}, "
            f"chunk_size={s.chunk_size})",
        ]
    else:
        b = view.axes[1]
        py += [
            "# the period map",
            f"ds = parameter_map(model, {a.name!r}, {_linspace(a.lo, a.hi, a.num)}, {b.name!r}, "
            f"{_linspace(b.lo, b.hi, b.num)}, {common}, chunk_size={a.num})",
        ]
    if model_args is None:
        return
    axes = [(view.parameter(i).to_display, axis) for i, axis in enumerate(view.axes)]
    runs = ["--transient", str(s.transient), "--periods", str(s.periods)]
    no_lyapunov = [] if s.lyapunov else ["--no-lyapunov"]
    if len(view.axes) == 1:
        shown, _ = axes[0]
        ranges = _range_args("", shown, a.name, a.lo, a.hi, a.num)
        chunks = ["--chunk-size", str(s.chunk_size)]
        cli.append(command_line(["sweep", *model_args, *ranges, *runs, *chunks, *no_lyapunov]))
    else:
        ranges = [
            arg
            for k, (shown, ax) in enumerate(axes, 1)
            for arg in _range_args(str(k), shown, ax.name, ax.lo, ax.hi, ax.num)
        ]
        cli.append(command_line(["map", *model_args, *ranges, *runs, *no_lyapunov]))


def _range_args(
    suffix: str, shown: Callable[[float], float], name: str, lo: float, hi: float, num: int
) -> list[str]:
    """``--param NAME --start LO --stop HI --num N``, each option's name ending in ``suffix`` (display
    units)."""
    return [f"--param{suffix}", name, f"--start{suffix}", repr(shown(lo)), f"--stop{suffix}", repr(shown(hi)),
            f"--num{suffix}", str(num)]  # fmt: skip


def _point_code(
    view: View,
    point: PointReport,
    continued: bool,
    point_args: list[str] | None,
    py: list[str],
    cli: list[str],
) -> None:
    """The clicked point, its orbit and (``continued``) its branch: Python, and command lines where
    ``point_args``."""
    a = view.axes[0]
    p = point.settings
    m = point.modes
    first, then, guess = (None, None, None) if m is None else (m.start, m.shown_start, m.guess)
    values = ", ".join(f"{k}={v!r}" for k, v in point.values.items())
    py += [
        "",
        "# the clicked point, from the diagram's state there",
        f"point = model.with_params({values})",
        f"sol = grazing.simulate(point, {_floats(point.x0)}, transient={p.transient}, periods={p.periods}, "
        f'impacts="none"{_mode_kw(first)})',
        "period = sol.period()",
        f"shown = period if period > 0 else {p.shown_periods}",
        "run = grazing.simulate(point, sol.x_final, t0=sol.t_final, periods=shown, "
        f"trajectory={p.points_per_period}{_mode_kw(then)})",
        'print("period", period, "impacts", len(run.impacts) / (1 if period > 0 else shown))',
    ]
    if point_args is not None:
        cli.append(
            command_line(
                [
                    "simulate",
                    *point_args,
                    "--initial",
                    _state_arg(point.x0),
                    "--transient",
                    str(p.transient),
                    "--periods",
                    str(p.periods),
                    *_mode_arg(first),
                ]
            )
        )
    if point.orbit_guess is None:
        return
    py += [
        f"orbit = find_orbit(point, run.x_final, period=period, t0=0.0{_mode_kw(guess)})",
        'print("orbit", orbit.period, orbit.impacts, orbit.multipliers)',
    ]
    if point_args is not None:
        cli.append(
            command_line(
                [
                    "orbit",
                    *point_args,
                    "--initial",
                    _state_arg(point.orbit_guess),
                    "--period",
                    str(point.period),
                    *_mode_arg(guess),
                ]
            )
        )
    if not continued or point.orbit is None:
        return
    start = point.values[a.name]
    ends = [e for e in (a.lo, a.hi) if abs(e - start) > 1e-12 * max(1.0, abs(start))]
    py += [
        "",
        "# its branch, both ways to the ends of the range",
        f"for end in {ends!r}:",
        f"    branch = continue_orbit(point, {a.name!r}, {start!r}, end, x0=orbit.state, "
        f"period=orbit.period{', mode=orbit.mode' if m is not None else ''})",
        '    print("branch", len(branch), [(s.kind, round(s.param, 8)) for s in branch.special])',
    ]
    if point_args is not None:
        par = view.parameter(0)
        branch_args = view.source.cli_args(point.model, varied=(a.name,))
        for end in ends:
            cli.append(
                command_line(
                    [
                        "continue",
                        *branch_args,
                        "--param",
                        a.name,
                        "--start",
                        repr(par.to_display(start)),
                        "--stop",
                        repr(par.to_display(end)),
                        "--initial",
                        _state_arg(point.orbit.state),
                        "--period",
                        str(point.orbit.period),
                        *_mode_arg(point.orbit.mode),
                    ]
                )
            )


def _basins_code(found: BasinView, point_args: list[str] | None, py: list[str], cli: list[str]) -> None:
    """The basins found at the clicked point (:func:`~grazing.explore.basins.basins_at`)."""
    py += [
        "",
        "# the basins of attraction at the clicked parameters",
        f"found = basins(point, {found.x_range!r}, {found.y_range!r}, {found.num!r})",
        "for kind, p, fraction in zip(found.kind.values, found.period.values, found.fraction.values):",
        '    print("attractor", kind, int(p), round(float(fraction), 6))',
    ]
    if point_args is not None:
        pair = lambda r: f"{r[0]!r},{r[1]!r}"  # noqa: E731
        cli.append(
            command_line(
                [
                    "basins",
                    *point_args,
                    f"--x-range={pair(found.x_range)}",
                    f"--y-range={pair(found.y_range)}",
                    "--num",
                    f"{found.num[0]},{found.num[1]}",
                ]
            )
        )


def _grazings_code(view: View, found: Grazings, with_cli: bool, py: list[str], cli: list[str]) -> None:
    """The grazings of the nonimpacting period-1 orbit (through its modes on a model with modes) over the
    range they were sought in, the other explored parameter held
    (:func:`~grazing.explore.branch.grazings_in_view`)."""
    lo, hi = found.range
    held = ", ".join(f"{k}={v!r}" for k, v in found.fixed.items())
    stop_word = "transition" if view.model.has_modes else "stop"
    py += [
        "",
        f"# the grazings of {grazed_orbit(view.model)} over the range (every {stop_word}'s)",
        f"_, branch = find_grazings(model{f'.with_params({held})' if held else ''}, {found.param!r}, {lo!r}, "
        f"{hi!r}, period=1{_mode_kw(found.mode)})",
        'print("grazings", [round(s.param, 8) for s in branch.special if s.kind == "grazing"])',
    ]
    if not with_cli:
        return
    model = view.model.with_params(**found.fixed)
    args = view.source.cli_args(model, varied=(found.param,))
    shown = model.parameter(found.param).to_display
    for stop in model.stop_names:  # (the command looks at one stop: a line each)
        cli.append(
            command_line(
                ["graze", *args, "--param", found.param, f"--range={shown(lo)!r},{shown(hi)!r}"]
                + (["--stop-name", stop] if len(model.stop_names) > 1 else [])
                + _mode_arg(found.mode)
            )
        )


def _curves_code(
    view: View, point: PointReport, found: Curves, with_cli: bool, py: list[str], cli: list[str]
) -> None:
    """The bifurcation curves followed from the clicked point's branch on a period map
    (:func:`~grazing.explore.branch.follow_click_curves`): from its orbit, as the page followed them."""
    assert point.orbit is not None
    view = found.view or view  # (the map they were followed over, not a zoomed part of it)
    a, b = view.axes
    start, period = point.values[a.name], point.orbit.period
    asked = [(str(c.kind), c.stop) for c in found.curves]
    mode = point.orbit.mode
    start_at = "x0=x0" if mode is None else "orbit=orbit"  # (with modes: from the orbit, in its mode)
    py += [
        "",
        f"# the bifurcation curves through the branch's special points, in ({a.name}, {b.name})",
        f"x0 = {_floats(point.orbit.state)}",
        f"for kind, stop in {asked!r}:",
        f"    curve = follow_curve(point, kind, {a.name!r}, {start!r}, stop, {b.name!r}, {(b.lo, b.hi)!r}, "
        f"{start_at}, period={period})",
        '    print("curve", kind, len(curve.points), curve.status)',
    ]
    if not with_cli:
        return
    args = view.source.cli_args(point.model, varied=(a.name,))
    shown_a, shown_b = view.parameter(0).to_display, view.parameter(1).to_display
    for kind, stop in asked:
        cli.append(
            command_line(
                [
                    "curve",
                    *args,
                    "--kind",
                    kind,
                    "--param",
                    a.name,
                    "--start",
                    repr(shown_a(start)),
                    "--stop",
                    repr(shown_a(stop)),
                    "--param2",
                    b.name,
                    f"--range={shown_b(b.lo)!r},{shown_b(b.hi)!r}",
                    "--period",
                    str(period),
                    "--initial",
                    _state_arg(point.orbit.state),
                    *_mode_arg(mode),
                ]
            )
        )
