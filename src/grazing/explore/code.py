"""Copy as code: the Python and the command lines that reproduce what the explorer shows.

Each text sets every parameter explicitly and gives every start state in full
(``repr`` of the floats), so that running it computes the same diagram, the same
point and the same branch as the page: the diagram with
:func:`grazing.sweeps.sweep` (``grazing sweep``) or
:func:`~grazing.sweeps.parameter_map` (``grazing map``) and the explorer's
settings; the clicked point with :func:`grazing.simulate` (``grazing
simulate``) from the diagram's state there, and its orbit with
:func:`~grazing.orbits.find_orbit` (``grazing orbit``); the branch with
:func:`~grazing.orbits.continue_orbit` (``grazing continue``), both ways.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grazing.explore.diagram import View
from grazing.explore.point import PointReport
from grazing.explore.source import command_line

__all__ = ["Code", "view_code"]


@dataclass(frozen=True)
class Code:
    """The view as Python (one script that prints what the page shows) and as command lines."""

    python: str
    cli: str


def _floats(x: np.ndarray) -> str:
    return "[" + ", ".join(repr(float(v)) for v in x) + "]"


def _state_arg(x: np.ndarray) -> str:
    return ",".join(repr(float(v)) for v in x)


def _linspace(lo: float, hi: float, num: int) -> str:
    return f"np.linspace({lo!r}, {hi!r}, {num})"


def view_code(view: View, point: PointReport | None = None, *, continued: bool = False) -> Code:
    """The code of the diagram, of the clicked ``point`` and (``continued``) of its continuation.

    The Python text imports what it uses and prints, for the point, ``period P
    impacts K`` (impacts per period of the motion) and then ``orbit P K`` (Newton's
    orbit); for the branch, one line per direction with its special points.
    Command lines need a model given by ``--model`` (a built-in name or a file):
    for a model object given in Python, :attr:`Code.cli` says so instead.
    """
    s = view.settings
    py = ["import numpy as np", *view.source.python_imports, "", "import grazing"]
    py += ["from grazing.orbits import continue_orbit, find_orbit"] if point is not None else []
    py += [f"from grazing.sweeps import {'sweep' if len(view.axes) == 1 else 'parameter_map'}", ""]
    py += view.source.python_lines(view.model)
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
    cli: list[str] = []
    try:
        model_args = view.source.cli_args(view.model, varied=view.names)
    except ValueError as exc:
        model_args = None
        cli.append(f"# {exc} (--model FILE.py:OBJECT)")
    if model_args is not None:
        shown = [view.parameter(i).to_display for i in range(len(view.axes))]
        if len(view.axes) == 1:
            cli.append(
                command_line(
                    [
                        "sweep",
                        *model_args,
                        "--param",
                        a.name,
                        "--start",
                        repr(shown[0](a.lo)),
                        "--stop",
                        repr(shown[0](a.hi)),
                        "--num",
                        str(a.num),
                        "--transient",
                        str(s.transient),
                        "--periods",
                        str(s.periods),
                        "--chunk-size",
                        str(s.chunk_size),
                    ]
                    + ([] if s.lyapunov else ["--no-lyapunov"])
                )
            )
        else:
            b = view.axes[1]
            cli.append(
                command_line(
                    [
                        "map",
                        *model_args,
                        "--param1",
                        a.name,
                        "--start1",
                        repr(shown[0](a.lo)),
                        "--stop1",
                        repr(shown[0](a.hi)),
                        "--num1",
                        str(a.num),
                        "--param2",
                        b.name,
                        "--start2",
                        repr(shown[1](b.lo)),
                        "--stop2",
                        repr(shown[1](b.hi)),
                        "--num2",
                        str(b.num),
                        "--transient",
                        str(s.transient),
                        "--periods",
                        str(s.periods),
                    ]
                    + ([] if s.lyapunov else ["--no-lyapunov"])
                )
            )
    if point is None:
        return Code("\n".join(py) + "\n", "\n".join(cli) + "\n")
    p = point.settings
    values = ", ".join(f"{k}={v!r}" for k, v in point.values.items())
    py += [
        "",
        "# the clicked point, from the diagram's state there",
        f"point = model.with_params({values})",
        f"sol = grazing.simulate(point, {_floats(point.x0)}, transient={p.transient}, periods={p.periods}, "
        'impacts="none")',
        "period = sol.period()",
        f"shown = period if period > 0 else {p.shown_periods}",
        "run = grazing.simulate(point, sol.x_final, t0=sol.t_final, periods=shown, "
        f"trajectory={p.points_per_period})",
        'print("period", period, "impacts", len(run.impacts) / (1 if period > 0 else shown))',
    ]
    point_args = None
    if model_args is not None:
        point_args = view.source.cli_args(point.model, varied=())
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
                ]
            )
        )
    if point.orbit_guess is None:
        return Code("\n".join(py) + "\n", "\n".join(cli) + "\n")
    py += [
        "orbit = find_orbit(point, run.x_final, period=period, t0=0.0)",
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
                ]
            )
        )
    if not continued or point.orbit is None:
        return Code("\n".join(py) + "\n", "\n".join(cli) + "\n")
    start = point.values[a.name]
    ends = [e for e in (a.lo, a.hi) if abs(e - start) > 1e-12 * max(1.0, abs(start))]
    py += [
        "",
        "# its branch, both ways to the ends of the range",
        f"for end in {ends!r}:",
        f"    branch = continue_orbit(point, {a.name!r}, {start!r}, end, x0=orbit.state, "
        "period=orbit.period)",
        '    print("branch", len(branch), [(s.kind, round(s.param, 8)) for s in branch.special])',
    ]
    if model_args is not None:
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
                    ]
                )
            )
    return Code("\n".join(py) + "\n", "\n".join(cli) + "\n")
