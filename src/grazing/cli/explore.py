"""``grazing explore``: the bifurcation diagram you can click, served on this machine."""

from __future__ import annotations

import click

import grazing
from grazing.cli.common import (
    InputError,
    check_mode,
    model_options,
    model_parameter,
    parse_pair,
    refuse_varied,
)
from grazing.cli.validate import count, refuse_unused

PENDULUM_DEFAULT = {"eta": (0.44, 0.49)}
"""What ``grazing explore`` shows of the pendulum without --param: the paper's period-adding cascade
(at the default θ̂ = 40°: figs 7 and 10)."""
MAX_NUM = {1: 20000, 2: 1000}
"""The most points per parameter: a diagram or a map the page can hold (20000 x 100 samples; 10^6 cells)."""


def explore_view(
    model: grazing.HybridModel,
    model_spec: str,
    param: str | None,
    params: str | None,
    ranges: tuple[str, ...],
    num: int | None,
    component: str | None,
) -> object:
    """The view the options describe (every check before any work: one line, exit 2)."""
    from grazing.explore import ModelSource, View

    refuse_unused(["params"], param is not None, "with --param (give one of them)")
    if param is None and params is None:
        if model.name != "pendulum" or model_spec != "pendulum" or ranges:
            raise InputError(
                "explore needs --param NAME --range LO,HI (or --params P1,P2 with a --range for each)"
                + ("" if model_spec == "pendulum" else f" for model {model_spec}")
            )
        named = dict(PENDULUM_DEFAULT)
        refuse_varied(list(named), "by explore: it shows eta in [0.44, 0.49] (give --param and --range)")
    else:
        names = [param] if param is not None else [p for p in (params or "").split(",")]
        if params is not None and len(names) != 2:
            raise InputError(f"--params must be P1,P2 (two parameters), got {params!r}")
        pars = [model_parameter(model, n, "--param" if param is not None else "--params") for n in names]
        if len(pars) == 2 and pars[0].name == pars[1].name:
            raise InputError(f"--params: the two parameters must differ, got {params!r}")
        if len(ranges) != len(pars):
            raise InputError(
                f"give one --range LO,HI for each explored parameter ({len(pars)}), got {len(ranges)}"
            )
        refuse_varied([p.name for p in pars], "with --param/--params: the explored values replace it")
        named = {}
        for par, text in zip(pars, ranges):
            lo, hi = parse_pair(text, "--range", "LO,HI")
            if not lo < hi:
                raise InputError(f"--range: LO must be below HI, got {text}")
            named[par.name] = (lo, hi)
    if num is not None and num > MAX_NUM[len(named)]:
        raise InputError(
            f"--num {num} is more than the page can show: at most {MAX_NUM[len(named)]} "
            + ("per parameter of a map" if len(named) == 2 else "for a diagram")
        )
    index = 0
    if component is not None:
        if component not in model.state_names:
            raise InputError(
                f"--component: model {model.name} has no state {component!r} "
                f"(states: {', '.join(model.state_names)})"
            )
        index = model.state_names.index(component)
        refuse_unused(["component"], len(named) == 2, "with a period map (--params)")
    try:
        return View.of(model, named, num=num, source=ModelSource.of(model, model_spec), component=index)
    except grazing.GrazingError as exc:
        raise InputError(f"--range: {exc}") from None


@click.command("explore")
@model_options(any_model=True, modes=True)
@click.option(
    "--param",
    "param",
    metavar="NAME",
    help="The parameter of a bifurcation diagram (any of the model's; angles in degrees).",
)
@click.option("--params", metavar="P1,P2", help="Two parameters: a period map (P1 horizontal).")
@click.option(
    "--range",
    "ranges",
    multiple=True,
    metavar="LO,HI",
    help="The range of each parameter, in its order (repeat for --params).",
)
@click.option(
    "--num",
    type=count(2),
    default=None,
    help="Points per parameter (default: 200 for a diagram, 40 for a map).",
)
@click.option(
    "--component", metavar="NAME", help="The state on the diagram's vertical axis (default: the first)."
)
@click.option(
    "--port",
    type=click.IntRange(0, 65535),
    default=5006,
    show_default=True,
    help="The port to listen on, on 127.0.0.1 (0: any free port).",
)
@click.option("--no-browser", is_flag=True, help="Do not open the page in a browser.")
@click.option(
    "--mode",
    default=None,
    metavar="NAME",
    help="A model with modes: the mode a click's simulation starts in, from the diagram's state there "
    "(default: the mode whose region that state lies in; the page's Start mode).",
)
def explore(
    model: grazing.HybridModel,
    case: str,
    param: str | None,
    params: str | None,
    ranges: tuple[str, ...],
    num: int | None,
    component: str | None,
    port: int,
    no_browser: bool,
    mode: str | None,
) -> None:
    """The bifurcation diagram you can click: a local web page (127.0.0.1) where a click on a
    point shows its orbit, continues it and finds the grazings; Ctrl-C stops it."""
    model_spec = click.get_current_context().params.get("model_spec", "pendulum")
    view = explore_view(model, model_spec, param, params, ranges, num, component)
    check_mode(model, mode)
    try:
        import bokeh  # noqa: F401
        import panel  # noqa: F401
    except ImportError:
        raise grazing.GrazingError(
            "grazing explore needs Panel and Bokeh: pip install 'grazing[explore]'"
        ) from None
    from grazing.explore.server import serve

    def ready(url: str) -> None:
        click.echo(f"grazing explore: {url} (Ctrl-C stops it)")

    serve(view, port=port, open_browser=not no_browser, ready=ready, mode=mode)  # type: ignore[arg-type]
