"""The ``grazing`` command line.

Every analysis command takes the paper's parameter cases by name (``--case B``,
the default) and/or explicit parameters (``--alpha --beta --r --eta
--theta-hat``, the stop angle in degrees), prints a human-readable summary, or
one JSON object with ``--json``.  Bad input gets one line on stderr and a
non-zero exit status; nothing is written.
"""

from __future__ import annotations

import functools
import json
import math
import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click
import numpy as np

import grazing
from grazing.errors import GrazingError
from grazing.models.pendulum import CASES, DEFAULT_CASE, case_values

EXIT_USAGE = 2
EXIT_FAILURE = 1
EXIT_INTERRUPTED = 130


class _ErrorInput(click.ClickException):
    """A usage error reported as one line."""


# ----------------------------------------------------------------------------
# Shared options


def model_options(func: Callable[..., Any]) -> Callable[..., Any]:
    """Options selecting the pendulum's parameters: a named case plus overrides."""
    options = [
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
            type=float,
            default=40.0,
            show_default=True,
            metavar="DEG",
            help="Stop angle in degrees, in (-180, 180).",
        ),
    ]
    for opt in reversed(options):
        func = opt(func)
    return func


def build_pendulum(
    case: str, alpha: float | None, beta: float | None, r: float | None, eta: float, theta_hat: float
) -> grazing.HybridModel:
    """The pendulum model from command-line values (theta_hat in degrees)."""
    if not math.isfinite(theta_hat) or not -180.0 < theta_hat < 180.0:
        raise _ErrorInput(f"--theta-hat must be in (-180, 180) degrees, got {theta_hat:g}")
    values = case_values(case)
    for name, val in (("alpha", alpha), ("beta", beta), ("r", r)):
        if val is not None:
            values[name] = val
    values["eta"] = eta
    values["theta_hat"] = math.radians(theta_hat)
    return grazing.models.pendulum(None, **values)


def model_params_json(model: grazing.HybridModel, case: str) -> dict[str, Any]:
    p = dict(model.params)
    p["theta_hat_deg"] = math.degrees(p["theta_hat"])
    p["case"] = case
    return p


def _parse_pair(text: str) -> tuple[float, float]:
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        a, b = (float(s) for s in parts)
    except ValueError:
        raise _ErrorInput(f"--initial must be THETA,THETADOT in radians, got {text!r}") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise _ErrorInput(f"--initial must be finite numbers, got {text!r}")
    return a, b


class _Progress:
    """A progress bar on stderr that appears only if the work lasts over a second."""

    def __init__(self, label: str, enabled: bool):
        self.label = label
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
                TimeRemainingColumn(),
                console=Console(stderr=True),
                transient=True,
            )
            self._bar.start()
            self._task = self._bar.add_task(self.label, total=total)
        self._bar.update(self._task, completed=done)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.stop()


def _write_atomic(path: Path, write: Callable[[Any], None]) -> None:
    """Write a file via a temporary in the same folder, so it is never half-written."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise _ErrorInput(f"folder {str(folder)!r} does not exist")
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", newline="") as fh:
            write(fh)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _emit_json(obj: dict[str, Any]) -> None:
    click.echo(json.dumps(obj, allow_nan=False, default=_json_default))


def _json_default(o: Any) -> Any:
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.generic):
        return o.item()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


# ----------------------------------------------------------------------------
# Commands


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(grazing.__version__, prog_name="grazing")
def cli() -> None:
    """Simulate and analyse impacting systems (the inclined impacting pendulum of
    Piiroinen, Virgin & Champneys 2004 by default)."""


@cli.command()
@model_options
@click.option("--initial", default="0,0", show_default=True, metavar="THETA,THETADOT",
              help="Initial state at tau = 0, radians.")  # fmt: skip
@click.option("--transient", type=click.IntRange(min=0), default=500, show_default=True,
              help="Forcing periods run and discarded first.")  # fmt: skip
@click.option("--periods", type=click.IntRange(min=1), default=100, show_default=True,
              help="Forcing periods sampled.")  # fmt: skip
@click.option("--phase", type=float, default=0.0, show_default=True, metavar="PHI",
              help="Stroboscopic phase in radians: samples at tau = PHI mod 2 pi.")  # fmt: skip
@click.option("--trajectory", type=click.Path(dir_okay=False, path_type=Path), metavar="FILE.csv",
              help="Write the dense trajectory of the sampled span to a CSV file.")  # fmt: skip
@click.option("--points-per-period", type=click.IntRange(min=4), default=100, show_default=True,
              help="Trajectory resolution (with --trajectory).")  # fmt: skip
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def simulate(
    case: str,
    alpha: float | None,
    beta: float | None,
    r: float | None,
    eta: float,
    theta_hat: float,
    initial: str,
    transient: int,
    periods: int,
    phase: float,
    trajectory: Path | None,
    points_per_period: int,
    as_json: bool,
) -> None:
    """Simulate the impacting pendulum; print stroboscopic samples, impacts, period."""
    model = build_pendulum(case, alpha, beta, r, eta, theta_hat)
    theta0, dtheta0 = _parse_pair(initial)
    if theta0 > model.params["theta_hat"]:
        raise _ErrorInput(
            f"initial angle {theta0:g} rad is beyond the stop at theta-hat = {theta_hat:g} deg "
            f"({model.params['theta_hat']:.6g} rad)"
        )
    if not math.isfinite(phase):
        raise _ErrorInput(f"--phase must be a finite number, got {phase}")
    if trajectory is not None and trajectory.suffix.lower() != ".csv":
        raise _ErrorInput(f"--trajectory must name a .csv file, got {str(trajectory)!r}")
    if trajectory is not None and not (trajectory.parent if str(trajectory.parent) else Path(".")).is_dir():
        raise _ErrorInput(f"folder {str(trajectory.parent)!r} does not exist")
    bar = _Progress("simulating", enabled=not as_json)
    t0 = time.perf_counter()
    try:
        sol = grazing.simulate(
            model,
            [theta0, dtheta0],
            transient=transient,
            periods=periods,
            phase=phase,
            trajectory=points_per_period if trajectory is not None else 0,
            progress=bar,
        )
    finally:
        bar.close()
    elapsed = time.perf_counter() - t0
    if trajectory is not None:
        _write_atomic(trajectory, functools.partial(_write_trajectory_csv, sol))
    period = sol.period()
    result = {
        "params": model_params_json(model, case),
        "initial": [theta0, dtheta0],
        "transient": transient,
        "periods": periods,
        "phase": phase,
        "samples": sol.samples,
        "impacts": sol.n_impacts,
        "impacts_sampled": len(sol.impacts),
        "impact_map": np.column_stack([sol.impacts.t, sol.impacts.phase, sol.impacts.speed]),
        "sticking_intervals": sol.sticking,
        "period": period,
        "t_final": sol.t_final,
        "x_final": sol.x_final,
        "steps": sol.n_steps,
        "elapsed_s": elapsed,
        "trajectory_file": str(trajectory) if trajectory is not None else None,
        "version": grazing.__version__,
    }
    if as_json:
        _emit_json(result)
        return
    _print_simulation(model, sol, period, elapsed, trajectory)


def _write_trajectory_csv(sol: grazing.Solution, fh: Any) -> None:
    fh.write("tau,theta,dtheta\n")
    assert sol.trajectory_t is not None and sol.trajectory is not None
    np.savetxt(fh, np.column_stack([sol.trajectory_t, sol.trajectory]), delimiter=",", fmt="%.17g")


def _print_simulation(
    model: grazing.HybridModel, sol: grazing.Solution, period: int, elapsed: float, trajectory: Path | None
) -> None:
    from rich.console import Console
    from rich.table import Table

    con = Console()
    p = model.params
    con.print(
        f"[bold]impacting pendulum[/bold]  alpha={p['alpha']:g} beta={p['beta']:g} r={p['r']:g} "
        f"eta={p['eta']:g} theta-hat={math.degrees(p['theta_hat']):g} deg"
    )
    n = sol.samples.shape[0]
    kind = f"period {period}" if period else "no period <= 64 (chaotic, quasi-periodic or not settled)"
    con.print(f"{n} sampled periods after {sol.info['transient']} transient: [bold]{kind}[/bold]")
    con.print(
        f"impacts: {sol.n_impacts} in the whole run, {len(sol.impacts)} in the sampled span; "
        f"sticking intervals: {len(sol.sticking)}; {sol.n_steps} steps in {elapsed:.3f} s"
    )
    table = Table("k", "tau", "theta [rad]", "theta' ", title="last stroboscopic samples")
    show = min(n, max(period, 5) if period else 8)
    for i in range(n - show, n):
        table.add_row(str(i), f"{sol.t[i]:.6f}", f"{sol.samples[i, 0]: .10f}", f"{sol.samples[i, 1]: .10f}")
    con.print(table)
    if trajectory is not None:
        con.print(f"trajectory written to {trajectory}")


@cli.command()
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=Path("report"),
              show_default=True, help="Output folder for index.html and figures.")  # fmt: skip
def report(out: Path) -> None:
    """Regenerate the paper's figures and tables into an HTML report."""
    from grazing.report import build_report

    t0 = time.perf_counter()
    index = build_report(out, progress=lambda msg: click.echo(msg, err=True))
    click.echo(f"report written to {index} in {time.perf_counter() - t0:.1f} s")


# ----------------------------------------------------------------------------
# Entry point


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; every error becomes one line on stderr and an exit status."""
    try:
        cli.main(args=argv, prog_name="grazing", standalone_mode=False)
    except click.exceptions.Exit as exc:
        return int(exc.exit_code)
    except click.exceptions.Abort:
        click.echo("grazing: interrupted", err=True)
        return EXIT_INTERRUPTED
    except KeyboardInterrupt:
        click.echo("grazing: interrupted", err=True)
        return EXIT_INTERRUPTED
    except click.ClickException as exc:
        click.echo(f"grazing: error: {exc.format_message()}", err=True)
        return EXIT_USAGE
    except GrazingError as exc:
        click.echo(f"grazing: error: {exc}", err=True)
        return EXIT_FAILURE
    except OSError as exc:
        click.echo(f"grazing: error: {exc.strerror or exc}: {exc.filename or ''}".rstrip(": "), err=True)
        return EXIT_FAILURE
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
