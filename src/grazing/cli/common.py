"""What every command shares: errors, options, progress, JSON, atomic writes, the pendulum's options.

Bad input is an :class:`InputError` (one line, exit 2); the work's own errors
are :class:`~grazing.errors.GrazingError` (one line, exit 1); :func:`main`
turns both into ``grazing: error: ...`` on stderr.  Every file a command
writes is written all at once with grazing's mark (:func:`write_table`,
:func:`save_dataset`, :mod:`grazing.outputs`), so a failed run leaves nothing
half-written; an output path is checked before any work (:func:`check_out`):
a file there that grazing did not write is refused unless ``--overwrite`` is
given.
"""

from __future__ import annotations

import dataclasses
import errno
import functools
import json
import math
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click
import numpy as np
import orjson

import grazing
from grazing.atomic import resolved
from grazing.cli.hints import flag_hints
from grazing.cli.validate import (
    ANGLE_DEG,
    InputError,
    path_type,
    refuse_set,
    refuse_unused,
)
from grazing.models.pendulum import CASES, DEFAULT_CASE, case_values

PENDULUM_UNFOLDING = ("eta", "theta_hat")
"""The parameters of the pendulum's normal-form unfolding vectors (the JSON reports both)."""

EXIT_USAGE = 2
EXIT_FAILURE = 1
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143
"""A command ended by SIGTERM (128 + 15), after the same clean-up as on Ctrl-C."""
EXIT_CLOSED_PIPE = 141
"""A command whose output's reader went away (``grazing sweep --json | head``): 128 + SIGPIPE, the status
of a Unix tool ended by that signal, and no message (nothing failed that the user asked for)."""


InputError = InputError
"""A usage error reported as one line (the name the command modules use)."""


# ----------------------------------------------------------------------------
# Shared options


json_option = click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
overwrite_option = click.option(
    "--overwrite",
    is_flag=True,
    help="Replace an output file that grazing did not write (a file grazing wrote is always replaced).",
)
OVERWRITE_HINT = "use another name, or --overwrite to replace it"
"""How a refusal to replace a file ends on the command line."""


def netcdf_out_option(func: Callable[..., Any]) -> Callable[..., Any]:
    """``--out FILE.nc`` and ``--overwrite``."""
    out = click.option("--out", type=path_type(dir_okay=False), metavar="FILE.nc", help="Save as NetCDF.")
    return out(overwrite_option(func))


PENDULUM_OPTIONS = ("case", "alpha", "beta", "r", "eta", "theta_hat")

PRINTED_SHOWN = 80
"""Characters of what a failing model file printed that its error line shows."""


def run_user_code(failed: str, call: Callable[[], Any]) -> Any:
    """``call()``, the user's code (a model file, its model function), as one line if it fails.

    What it prints to stdout goes to stderr (stdout stays clean for ``--json``);
    any exception it raises (any :class:`BaseException`: a ``GeneratorExit`` raised
    at the top of a file too), or a ``sys.exit``, becomes an :class:`InputError`
    starting with ``failed`` (``"--model: m.py failed to load"``) that shows the
    start of what it printed.  ``KeyboardInterrupt`` passes (Ctrl-C, SIGTERM).
    """
    import contextlib
    import io

    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed):
            result = call()
    except SystemExit as exc:
        reason = "it called sys.exit()" if exc.code is None else f"it called sys.exit({exc.code!r})"
    except KeyboardInterrupt:
        raise
    except grazing.GrazingError as exc:
        reason = flag_hints(str(exc))
    except BaseException as exc:  # the user's code: anything it raises is theirs, reported in one line
        reason = f"{type(exc).__name__}: {exc}".rstrip(": ")
    else:
        if printed.getvalue():
            click.echo(printed.getvalue(), err=True, nl=False)
        return result
    text = " ".join(printed.getvalue().split())
    if text:
        shown = text if len(text) <= PRINTED_SHOWN else text[: PRINTED_SHOWN - 3] + "..."
        reason += f" (it printed: {shown})"
    raise InputError(f"{failed}: {reason}") from None


def load_model(spec: str) -> grazing.HybridModel:
    """The model a ``--model`` value names: a built-in name, or ``path/to/file.py:OBJECT``.

    ``OBJECT`` is a :class:`~grazing.HybridModel` or a function returning one
    (called without arguments).  Anything else is an :class:`InputError`, and
    so is a file that raises or exits while it loads (see :func:`run_user_code`).
    """
    from grazing.models import BUILT_IN

    if spec in BUILT_IN:
        return BUILT_IN[spec]()
    if ":" not in spec:
        raise InputError(f"unknown model {spec!r} (built-in: {', '.join(BUILT_IN)}; or FILE.py:OBJECT)")
    path_text, _, name = spec.rpartition(":")
    path = Path(path_text)
    if not path.is_file():
        raise InputError(f"--model: no such file {path_text!r}")
    import importlib.util

    module_spec = importlib.util.spec_from_file_location(f"grazing_user_model_{abs(hash(str(path)))}", path)
    if module_spec is None or module_spec.loader is None:
        raise InputError(f"--model: cannot load {path_text!r} as Python")
    module = importlib.util.module_from_spec(module_spec)
    loader = module_spec.loader
    run_user_code(f"--model: {path_text} failed to load", lambda: loader.exec_module(module))
    obj = getattr(module, name, None)
    if obj is None:
        raise InputError(f"--model: {path_text} defines no {name!r}")
    if callable(obj) and not isinstance(obj, grazing.HybridModel):
        obj = run_user_code(f"--model: {name}() in {path_text} failed", obj)
    if not isinstance(obj, grazing.HybridModel):
        raise InputError(
            f"--model: {name} in {path_text} is not a grazing.HybridModel (or a function returning one)"
        )
    return obj


def set_parameters(sets: tuple[str, ...]) -> dict[str, str]:
    """The parameter names ``--set NAME=VALUE`` gives, each with its (last) item.

    Examples
    --------
    >>> set_parameters(("eta=0.4", " r = 0.5", "eta=0.41"))
    {'eta': 'eta=0.41', 'r': ' r = 0.5'}
    """
    return {item.partition("=")[0].strip(): item for item in sets}


def apply_sets(model: grazing.HybridModel, sets: tuple[str, ...]) -> grazing.HybridModel:
    """``--set NAME=VALUE`` (repeatable, last wins): any parameter, angles in degrees."""
    changes: dict[str, float] = {}
    for item in sets:
        name, eq, text = item.partition("=")
        name = name.strip()
        if not eq or not name:
            raise InputError(f"--set {item!r}: expected NAME=VALUE")
        par = model.parameter(name)  # unknown names: one line naming the known ones
        try:
            value = float(text)
        except ValueError:
            raise InputError(f"--set {item!r}: {text!r} is not a number") from None
        if not math.isfinite(value):
            raise InputError(f"--set {item!r}: the value must be finite")
        changes[name] = par.from_display(value)
    return model.with_params(**changes) if changes else model


def model_options(
    func: Callable[..., Any] | None = None, *, any_model: bool = False, modes: bool = False
) -> Any:
    """Options selecting the model: ``--model``, ``--set``, and the pendulum's case and overrides.

    The decorated command receives the validated model as ``model`` and the
    pendulum case name as ``case`` (for its JSON output).  Commands decorated
    with ``any_model=True`` take every model; the others refuse any model but
    the pendulum in one line.  A model with modes is refused in one line but
    by the commands decorated with ``modes=True``.
    """
    if func is None:
        return functools.partial(model_options, any_model=any_model, modes=modes)

    @functools.wraps(func)
    def wrapper(
        *args: Any, model_spec: str, sets: tuple[str, ...], case: str, alpha: float | None,
        beta: float | None, r: float | None, eta: float, theta_hat: float, **kwargs: Any,
    ) -> Any:  # fmt: skip
        named = set_parameters(sets)
        if model_spec == "pendulum":
            for name, item in named.items():  # the option and --set of one parameter: which one?
                if name in PENDULUM_OPTIONS[1:]:
                    refuse_unused([name], True, f"with --set {item} (give one of them)")
            options = {n for n, v in (("alpha", alpha), ("beta", beta), ("r", r)) if v is not None}
            refuse_unused(
                ["case"],
                {"alpha", "beta", "r"} <= options | set(named),
                "when --alpha, --beta and --r are all given"
                if len(options) == 3
                else "when alpha, beta and r are all given (by --alpha, --beta, --r or --set)",
            )
            model = build_pendulum(case, alpha, beta, r, eta, theta_hat)
        else:
            refuse_unused(
                PENDULUM_OPTIONS, True, "with a model other than the pendulum (use --set NAME=VALUE)"
            )
            model = load_model(model_spec)
            if model.has_modes and not modes:
                command = click.get_current_context().info_name
                raise InputError(
                    f"--model: {model.name} has modes ({', '.join(model.mode_names)}): {command} does not "
                    "support models with modes yet (simulate, orbit, continue, curve, graze, graze-curve, "
                    "sweep, map, normal-form, basins, attractors and explore do)"
                )
            if not any_model:
                raise InputError(
                    f"--model {model_spec}: this command works on the pendulum only so far "
                    "(simulate takes any model)"
                )
        return func(*args, model=apply_sets(model, sets), case=case, **kwargs)

    options = [
        click.option(
            "--model",
            "model_spec",
            default="pendulum",
            show_default=True,
            metavar="NAME|FILE.py:OBJECT",
            help="A built-in model (pendulum, two-sided-oscillator, impact-oscillator, bouncing-ball, "
            "impact-damper; with modes: soft-impact-oscillator, rocking-block, friction-oscillator) "
            "or a HybridModel (or a function returning one) in a Python file.",
        ),
        click.option(
            "--set",
            "sets",
            multiple=True,
            metavar="NAME=VALUE",
            help="Set any parameter of the model (repeatable; angles in degrees).",
        ),
        click.option(
            "--case",
            default=DEFAULT_CASE,
            show_default=True,
            metavar="NAME",
            help=f"Paper parameter case: {', '.join(CASES)} (sets r, beta, alpha).",
        ),
        click.option("--alpha", type=float, help="Forcing amplitude A/L (overrides the case)."),
        click.option("--beta", type=float, help="Linear damping (overrides the case)."),
        click.option("--r", "r", type=float, help="Coefficient of restitution in [0, 1]."),
        click.option("--eta", type=float, default=0.446, show_default=True, help="Frequency ratio."),
        click.option(
            "--theta-hat",
            "theta_hat",
            type=ANGLE_DEG,
            default=40.0,
            show_default=True,
            metavar="DEG",
            help="Stop angle in degrees, in (-180, 180).",
        ),
    ]
    for opt in reversed(options):
        wrapper = opt(wrapper)
    return wrapper


def build_pendulum(
    case: str, alpha: float | None, beta: float | None, r: float | None, eta: float, theta_hat: float
) -> grazing.HybridModel:
    """The pendulum model from command-line values (theta_hat in degrees, checked by its option type)."""
    values = case_values(case)
    for name, val in (("alpha", alpha), ("beta", beta), ("r", r)):
        if val is not None:
            values[name] = val
    values["eta"] = eta
    values["theta_hat"] = math.radians(theta_hat)
    return grazing.models.pendulum(None, **values)


def model_parameter(model: grazing.HybridModel, text: str, option: str = "--param") -> grazing.Parameter:
    """The parameter an option names (``theta-hat`` is ``theta_hat``); one line if the model has none such."""
    name = text.strip().replace("-", "_")
    try:
        return model.parameter(name)
    except grazing.InvalidParameterError as exc:
        raise InputError(f"{option}: {exc}") from None


def stop_option_index(model: grazing.HybridModel, name: str | None) -> int:
    """``--stop-name``: the index of the stop (default: the model's first)."""
    try:
        return model.stop_index(name)
    except grazing.InvalidParameterError as exc:
        raise InputError(f"--stop-name: {exc}") from None


mode_option = click.option(
    "--mode",
    default=None,
    metavar="NAME",
    help="A model with modes: the mode to start in (default: the one the initial state lies in, its "
    "initial mode where that is in its region).",
)


def check_mode(model: grazing.HybridModel, mode: str | None) -> None:
    """``--mode``: one line unless it names a mode a run of ``model`` can start in."""
    if mode is not None:
        try:
            model.mode_index(mode)
        except grazing.InvalidParameterError as exc:
            raise InputError(f"--mode: {exc}") from None


stop_name_option = click.option(
    "--stop-name", default=None, metavar="NAME", help="The stop to look at (default: the model's first stop)."
)


def model_params_json(model: grazing.HybridModel, case: str) -> dict[str, Any]:
    """Every parameter by name; for the pendulum also ``theta_hat_deg`` and ``case``."""
    p: dict[str, Any] = dict(model.params)
    if model.name == "pendulum":
        p["theta_hat_deg"] = math.degrees(p["theta_hat"])
        p["case"] = case
    return p


def parse_state(text: str | None, model: grazing.HybridModel, mode: str | None = None) -> np.ndarray:
    """``--initial``: one number per state, comma-separated (default: zero), inside every stop (of ``mode``
    for a model with modes; by default of the mode it lies in, :meth:`~grazing.HybridModel.start_mode`)."""
    n = model.n_states
    if text is None:
        return np.zeros(n)
    form = "THETA,THETADOT in radians" if model.name == "pendulum" else ",".join(model.state_names).upper()
    try:
        values = np.array([float(t) for t in text.split(",")])
        if values.size != n:
            raise ValueError
    except ValueError:
        raise InputError(
            f"--initial must be {form}, got {text!r} (model {model.name} has {n} states)"
        ) from None
    if not np.all(np.isfinite(values)):
        raise InputError(f"--initial must be finite numbers, got {text!r}")
    if model.name == "pendulum" and values[0] > model.params["theta_hat"]:
        th = model.params["theta_hat"]
        raise InputError(
            f"initial angle {values[0]:g} rad is beyond the stop at theta-hat = {math.degrees(th):g} deg "
            f"({th:.6g} rad)"
        )
    try:
        model.check_state(values, mode=model.start_mode(values, 0.0, mode))
    except grazing.InvalidStateError as exc:
        raise InputError(f"--initial: {exc}") from None
    return values


def refuse_varied(names: list[str], why: str) -> None:
    """Refuse what would set a parameter that the command varies itself: ``--set NAME=...`` and the
    pendulum's own option (``--eta``...).  Only the pendulum's options are parameters: a model's
    parameter called ``out`` or ``period`` leaves ``--out`` and ``--period`` alone."""
    refuse_unused([n for n in names if n in PENDULUM_OPTIONS], True, why)
    refuse_set(names, why)


def search_range(
    model: grazing.HybridModel, command: str, gparam: str | None, prange: str | None, eta_min: float,
    eta_max: float,
) -> tuple[grazing.Parameter, float, float, bool]:  # fmt: skip
    """The parameter and interval a grazing search runs over: ``(parameter, lo, hi, pendulum_default)``.

    ``--param NAME --range LO,HI`` (display units), or for the pendulum by default eta in
    ``[--eta-min, --eta-max]`` (``pendulum_default`` then True).
    """
    if gparam is None and prange is None and model.name == "pendulum":
        refuse_varied(["eta"], f"by {command}: it searches eta in [--eta-min, --eta-max]")
        check_eta_range(eta_min, eta_max)
        return model.parameter("eta"), eta_min, eta_max, True
    refuse_unused(["eta_min", "eta_max"], True, "with --param/--range (use --range LO,HI)")
    if gparam is None or prange is None:
        raise InputError(f"{command} needs --param NAME and --range LO,HI (for this model)")
    par = model_parameter(model, gparam)
    refuse_varied([par.name], f"by {command}: it searches --param over --range")
    lo, hi = (par.from_display(v) for v in parse_pair(prange, "--range", "LO,HI"))
    if not lo < hi:
        raise InputError(f"--range: LO must be below HI, got {prange}")
    for v in (lo, hi):
        model.with_params(**{par.name: v})  # both ends inside the parameter's interval
    return par, lo, hi, False


def parse_pair(
    text: str, option: str = "--initial", form: str = "THETA,THETADOT in radians"
) -> tuple[float, float]:
    """Two comma-separated finite numbers (``--initial`` of the pendulum, ``--range LO,HI``)."""
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        a, b = (float(s) for s in parts)
    except ValueError:
        raise InputError(f"{option} must be {form}, got {text!r}") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise InputError(f"{option} must be finite numbers, got {text!r}")
    return a, b


def spaced_values(start: float, stop: float, num: int, options: str) -> np.ndarray:
    """``num`` values evenly spaced from ``start`` to ``stop`` (``np.linspace``); one line where the span
    between them overflows (``--start -1e308 --stop 1e308``), which numpy would warn about.

    Examples
    --------
    >>> spaced_values(0.0, 1.0, 3, "--start/--stop").tolist()
    [0.0, 0.5, 1.0]
    """
    check_span(start, stop, options)
    return np.linspace(start, stop, num)


def check_span(lo: float, hi: float, options: str) -> None:
    """One line if the distance from ``lo`` to ``hi`` is no finite float (a range or grid of them would
    overflow)."""
    if not math.isfinite(hi - lo):
        raise InputError(f"{options}: the range from {lo:g} to {hi:g} is wider than floats can hold")


class Progress:
    """A progress bar on stderr that appears only if the work lasts over a second."""

    def __init__(self, label: str, enabled: bool, unit: str = "items"):
        self.label = label
        self.unit = unit
        self.enabled = enabled and sys.stderr.isatty()
        self.start = time.perf_counter()
        self._bar: Any = None
        self._task: Any = None

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        if self._bar is None:
            if time.perf_counter() - self.start < 1.0 or done >= total:
                return
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeRemainingColumn,
            )

            self._bar = Progress(
                TextColumn(self.label),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn("{task.fields[rate]}"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
                transient=True,
            )
            self._bar.start()
            self._task = self._bar.add_task(self.label, total=total, rate="")
        elapsed = time.perf_counter() - self.start
        rate = f"{done / elapsed:,.0f} {self.unit}/s" if elapsed > 0 else ""
        self._bar.update(self._task, completed=done, rate=rate)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.stop()


def write_table(path: Path, write: Callable[[Any], None], overwrite: bool = False) -> None:
    """Write a CSV table all at once with grazing's mark (:func:`grazing.outputs.write_csv`)."""
    from grazing.outputs import write_csv

    write_csv(path, write, overwrite=overwrite, hint=OVERWRITE_HINT)


def emit_json(obj: dict[str, Any]) -> None:
    """Print ``obj`` as strict JSON on one line (every command's ``--json``): see :func:`json_text`.

    Written as the encoder's bytes, piece by piece (a 32000-point sweep's text
    is 60 MB: made one ``str`` and encoded again, it cost 0.2 s of the sweep's
    serial part).
    """
    pieces = json_pieces(obj, newline=True)
    stream = getattr(sys.stdout, "buffer", None)
    if stream is None:  # (a text stream without its bytes: a StringIO)
        click.echo(b"".join(pieces).decode(), nl=False)
        return
    sys.stdout.flush()
    for piece in pieces:
        stream.write(piece)
    stream.flush()


def json_text(obj: Any) -> str:
    """``obj`` as strict JSON: NaN and infinities become ``null``, numpy arrays and scalars plain values.

    Encoded by orjson, which writes a numpy array without first making it a
    list of Python floats (a 32000-point sweep's samples: 0.2 s instead of
    2.8 s, a serial part of every sweep); the numbers are the same (shortest
    round-trip form), the text compact.  What orjson cannot encode (an integer
    beyond 64 bits...) goes through :mod:`json`.  A :class:`JsonText` value of
    a dict is placed as it is.

    Examples
    --------
    >>> json_text({"a": [1.5, float("nan")], "b": np.array([[0.0, np.inf]]), "c": np.float32(2)})
    '{"a":[1.5,null],"b":[[0.0,null]],"c":2.0}'
    >>> json_text({"rows": JsonText((b"[[1.0],", b"[2.5]]")), "n": 2})
    '{"rows":[[1.0],[2.5]],"n":2}'
    """
    return b"".join(json_pieces(obj)).decode()


@dataclasses.dataclass(frozen=True)
class JsonText:
    """A value already encoded as JSON, in pieces (UTF-8 bytes to be written one after the other).

    :func:`json_text` and :func:`emit_json` place it as it is, a value of a dict
    (at any depth of dicts).  A sweep's samples are encoded so chunk by chunk
    while the threads compute the next ones (:mod:`grazing.cli.sweep_json`),
    not after the last one, and written without being joined first.
    """

    pieces: tuple[bytes, ...]


_MARK = b"\x00"
"""Where a :class:`JsonText` goes in orjson's text (a byte orjson never writes: it escapes it in strings)."""


def json_pieces(obj: Any, newline: bool = False) -> list[bytes]:
    """:func:`json_text` as UTF-8 bytes in pieces (ending with a newline with ``newline``)."""
    placed: list[JsonText] = []
    option = _ORJSON | (orjson.OPT_APPEND_NEWLINE if newline else 0)
    try:
        text = orjson.dumps(_placed(obj, placed), default=json_default, option=option)
    except (orjson.JSONEncodeError, TypeError):
        end = "\n" if newline else ""
        try:
            return [(json.dumps(obj, allow_nan=False, default=json_default) + end).encode()]
        except ValueError:  # a non-finite float outside an array (arrays are converted by json_default)
            return [(json.dumps(_finite_or_null(obj), allow_nan=False, default=json_default) + end).encode()]
    if not placed:
        return [text]
    between = text.split(_MARK)
    assert len(between) == len(placed) + 1
    pieces = [between[0]]
    for value, after in zip(placed, between[1:]):
        pieces += [*value.pieces, after]
    return pieces


def _placed(obj: Any, placed: list[JsonText]) -> Any:
    """``obj`` with each :class:`JsonText` of its dicts a mark (:data:`_MARK`), listed in ``placed``."""
    if isinstance(obj, dict):
        return {k: _placed(v, placed) for k, v in obj.items()}
    if isinstance(obj, JsonText):
        placed.append(obj)
        return orjson.Fragment(_MARK)
    return obj


_ORJSON = orjson.OPT_SERIALIZE_NUMPY | orjson.OPT_NON_STR_KEYS


def json_default(o: Any) -> Any:
    """The JSON value of a numpy array or scalar (non-finite floats as None), for ``json.dumps``."""
    if isinstance(o, np.ndarray):
        if o.dtype.kind == "f" and not np.isfinite(o).all():
            return np.where(np.isfinite(o), o, None).tolist()
        return o.tolist()
    if isinstance(o, np.generic):
        return _finite_or_null(o.item())
    if isinstance(o, JsonText):
        return json.loads(b"".join(o.pieces))
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def _finite_or_null(o: Any) -> Any:
    """``o`` with every non-finite float in its dicts, lists and tuples replaced by None."""
    if isinstance(o, float):
        return o if math.isfinite(o) else None
    if isinstance(o, dict):
        return {k: _finite_or_null(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_finite_or_null(v) for v in o]
    if isinstance(o, (np.ndarray, np.generic)):  # (an array of objects, a numpy scalar)
        return _finite_or_null(json_default(o))
    return o


def check_eta_range(eta_min: float, eta_max: float) -> None:
    """``--eta-min < --eta-max`` (each is positive by its option type)."""
    if not eta_min < eta_max:
        raise InputError(f"need 0 < --eta-min < --eta-max, got {eta_min:g} and {eta_max:g}")


def complex_list(mu: np.ndarray) -> list[list[float]]:
    return [[float(z.real), float(z.imag)] for z in np.asarray(mu, dtype=complex)]


def check_out(out: Path | None, suffix: str, option: str = "--out", overwrite: bool = False) -> None:
    """Check an output path before any work: its suffix, its folder, and what is there already.

    The folder must exist; a file there is replaced only if grazing wrote it
    or ``--overwrite`` is given (:func:`grazing.outputs.check_replaceable`; a
    symbolic link is followed).  ``--overwrite`` without the output is refused.
    """
    if out is None:
        refuse_unused(["overwrite"], True, f"without {option}")
        return
    if out.suffix.lower() != suffix:
        raise InputError(f"{option} must name a {suffix} file, got {str(out)!r}")
    check_folder(out)
    from grazing.outputs import check_replaceable

    check_replaceable(out, overwrite=overwrite, hint=OVERWRITE_HINT)


def check_folder(out: Path) -> None:
    """The folder an output goes into must exist (no command makes missing folders)."""
    folder = resolved(out).parent  # (of the file a symbolic link points to)
    if not folder.is_dir():
        raise InputError(f"folder {str(folder)!r} does not exist")


def save_dataset(ds: Any, out: Path, overwrite: bool = False) -> None:
    """Write a dataset to NetCDF all at once with grazing's mark (:func:`grazing.outputs.write_netcdf`)."""
    from grazing.outputs import write_netcdf

    write_netcdf(out, ds, overwrite=overwrite, hint=OVERWRITE_HINT)


def output_closed(fd: int = 1) -> bool:
    """Whether the reader of the pipe ``fd`` writes to has gone (``poll`` reports an error on it).

    Examples
    --------
    >>> import os
    >>> r, w = os.pipe()
    >>> output_closed(w)
    False
    >>> os.close(r); output_closed(w)
    True
    >>> os.close(w)
    """
    import select

    if not hasattr(select, "poll"):  # pragma: no cover - not on Linux or macOS
        return False
    poller = select.poll()
    poller.register(fd, 0)  # (no events asked: errors and hang-ups are reported anyway)
    return any(event & (select.POLLERR | select.POLLHUP | select.POLLNVAL) for _, event in poller.poll(0))


def buffered_stdout() -> None:
    """Give the standard output back a buffer where ``PYTHONUNBUFFERED`` (``python -u``) took it away.

    Unbuffered, Python writes the standard output straight to its file
    descriptor, and a ``write`` that the system takes only a part of (a pipe
    whose reader has left after a few bytes, a disk that filled up) loses the
    rest without an error: ``grazing simulate --json | head -c 100`` ended
    with status 0, ``> full-disk/out.json`` left a truncated file and status
    0.  A buffered writer writes everything or raises the error.  It is
    flushed at every line (and by every command after what it prints), so the
    output comes as promptly as unbuffered.  Nothing is changed where the
    standard output has a buffer already, or is no file (a test's capture).
    """
    import io

    stream = sys.stdout
    raw = getattr(stream, "buffer", None)
    if not isinstance(raw, io.RawIOBase):
        return
    stream.flush()
    writer = io.BufferedWriter(io.FileIO(raw.fileno(), "w", closefd=False))
    sys.stdout = io.TextIOWrapper(writer, encoding=stream.encoding, errors=stream.errors, line_buffering=True)


def flush_or_discard_output() -> None:
    """Flush the standard output; where it cannot take what is left (a full disk), drop that instead (the
    error has been said: the flush at the process's end must not report it again, in several lines)."""
    try:
        sys.stdout.flush()
    except (OSError, ValueError):
        discard_output()


def discard_output() -> None:
    """Send what is left of the standard output to ``/dev/null``: its reader has gone, and the flush at the
    process's end must not fail again (Python would print an "Exception ignored" message)."""
    import os
    import sys

    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    finally:
        os.close(devnull)


def stdout_console(**options: Any) -> Any:
    """A :class:`rich.console.Console` on the standard output whose closed pipe ends the command as any
    other's does (:data:`EXIT_CLOSED_PIPE`, by :func:`grazing.cli.main`; rich's own ends it with status 1).
    """
    from rich.console import Console

    class _Console(Console):
        def on_broken_pipe(self) -> None:
            self.quiet = True
            raise BrokenPipeError(errno.EPIPE, os.strerror(errno.EPIPE))

    return _Console(**options)


def error_line(message: str) -> None:
    """``grazing: error: MESSAGE`` as one line on stderr (click's multi-line messages are joined)."""
    click.echo(f"grazing: error: {' '.join(message.split())}", err=True)
