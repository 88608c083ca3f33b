"""The ``grazing`` command line: one module per command group, the shared parts in :mod:`.common`.

Every analysis command takes the paper's parameter cases by name (``--case B``,
the default) and/or explicit parameters (``--alpha --beta --r --eta
--theta-hat``, the stop angle in degrees), prints a human-readable summary, or
one JSON object with ``--json``.  Bad input gets one line on stderr and a
non-zero exit status; nothing is written.
"""

from __future__ import annotations

import importlib

import click

import grazing
from grazing.cli.common import (
    EXIT_CLOSED_PIPE,
    EXIT_FAILURE,
    EXIT_INTERRUPTED,
    EXIT_TERMINATED,
    EXIT_USAGE,
    buffered_stdout,
    discard_output,
    error_line,
    flush_or_discard_output,
    output_closed,
)
from grazing.cli.hints import flag_hints
from grazing.cli.limits import MEMORY_ENV
from grazing.engine.interrupts import Terminated, terminating_as_interrupted, was_interrupted, was_terminated
from grazing.errors import GrazingError

__all__ = ["COMMANDS", "cli", "main"]

COMMANDS: dict[str, str] = {
    "simulate": "simulate:simulate",
    "orbit": "orbits:orbit",
    "graze": "orbits:graze",
    "graze-curve": "orbits:graze_curve",
    "continue": "orbits:continue_",
    "curve": "curves:curve",
    "sweep": "sweeps:sweep_cmd",
    "normal-form": "normalform:normal_form_cmd",
    "map": "sweeps:map_cmd",
    "report": "report:report",
    "damping": "experiment:damping_cmd",
    "iso-damping": "experiment:iso_damping_cmd",
    "fit": "experiment:fit_cmd",
    "analyze": "experiment:analyze_cmd",
    "synthesize": "experiment:synthesize_cmd",
    "basins": "attractors:basins_cmd",  # issue 28
    "attractors": "attractors:attractors_cmd",
    "explore": "explore:explore",  # issue 31
}
"""Every command: its name and where it is (``module of grazing.cli:object``), imported when it is used.

A command's module is loaded only when that command runs (or ``--help`` lists
them all): ``grazing sweep`` does not import the orbits, curves or attractors
(about 60 ms of a process's start, a serial part of every sweep, issue 29).
"""


class _LazyGroup(click.Group):
    """A click group whose commands are imported on first use (:data:`COMMANDS`)."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted({*COMMANDS, *self.commands})

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        if name not in self.commands and name in COMMANDS:
            module, attr = COMMANDS[name].split(":")
            self.add_command(getattr(importlib.import_module(f"grazing.cli.{module}"), attr), name)
        return self.commands.get(name)


def _print_version(ctx: click.Context, _param: click.Parameter, value: bool) -> None:
    # (click.version_option wants the version when the command line is built: grazing.__version__
    # is then looked up by importlib.metadata, ~20-50 ms of every command's start-up)
    if value and not ctx.resilient_parsing:
        click.echo(f"grazing, version {grazing.__version__}")
        ctx.exit()


@click.group(cls=_LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.option(
    "--version", is_flag=True, expose_value=False, is_eager=True, callback=_print_version,
    help="Show the version and exit.",
)  # fmt: skip
def cli() -> None:
    """Simulate and analyse impacting systems (the inclined impacting pendulum of
    Piiroinen, Virgin & Champneys 2004 by default)."""


def interrupted_line() -> None:
    """Say on stderr that the command was interrupted, in one line (after a terminal's ``^C``, its own)."""
    import sys

    click.echo(("\n" if sys.stderr.isatty() else "") + "grazing: interrupted", err=True)


def terminated_line() -> None:
    """Say on stderr that the command was ended by SIGTERM, in one line."""
    click.echo("grazing: terminated", err=True)


def quiet_store_exit() -> None:
    """After an interrupt, end zarr's input-output thread quietly at exit.

    A Ctrl-C or SIGTERM during a store's write leaves zarr's event loop running a task; zarr's own exit
    hook then waits 0.2 s, logs "Thread did not finish cleanly" and raises closing the running loop (a
    traceback after the one line), and the tasks still pending when the loop is collected are logged by
    asyncio ("Task was destroyed but it is pending!", several lines).  The process is ending: its hook
    runs with its log silenced and its error dropped, and asyncio's log is silenced.
    """
    import atexit
    import logging
    import sys

    sync = sys.modules.get("zarr.core.sync")
    cleanup = getattr(sync, "cleanup_resources", None)
    if cleanup is None:
        return
    logging.getLogger("asyncio").disabled = True

    def quietly() -> None:
        logging.getLogger(sync.__name__).disabled = True
        try:
            cleanup()
        except RuntimeError:  # ("Cannot close a running event loop")
            pass

    atexit.unregister(cleanup)
    atexit.register(quietly)


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; every error becomes one line on stderr and an exit status.

    Output to a pipe whose reader has gone (``grazing sweep --json | head``)
    ends the command without a message, with status 141
    (:data:`~grazing.cli.common.EXIT_CLOSED_PIPE`), as a Unix tool ends.
    SIGTERM ends it as Ctrl-C does (its temporaries removed, its workers
    stopped), with one line and status 143
    (:data:`~grazing.cli.common.EXIT_TERMINATED`).

    Without arguments it prints the help, as ``grazing --help`` does.
    """
    import sys

    args = list(sys.argv[1:] if argv is None else argv) or ["--help"]
    buffered_stdout()
    try:
        # (not cli.main: on Ctrl-C it writes an empty line to stderr, whatever stderr is)
        with terminating_as_interrupted(), cli.make_context("grazing", args) as ctx:
            cli.invoke(ctx)
    except click.exceptions.Exit as exc:
        return int(exc.exit_code)
    except Terminated:
        quiet_store_exit()
        terminated_line()
        return EXIT_TERMINATED
    except (click.exceptions.Abort, KeyboardInterrupt, EOFError):
        quiet_store_exit()
        interrupted_line()
        return EXIT_INTERRUPTED
    except click.ClickException as exc:
        error_line(exc.format_message())
        return EXIT_USAGE
    except GrazingError as exc:
        error_line(flag_hints(str(exc)))
        return EXIT_FAILURE
    except OSError as exc:
        if isinstance(exc, BrokenPipeError) and output_closed():  # (``sweep --json | head``: read enough)
            discard_output()
            return EXIT_CLOSED_PIPE
        error_line(f"{exc.strerror or exc}: {exc.filename or ''}".rstrip(": "))
        flush_or_discard_output()  # (the standard output on a full disk: said once)
        return EXIT_FAILURE
    except MemoryError:
        error_line(f"out of memory (the estimate before the run was too low; {MEMORY_ENV} lowers the bound)")
        return EXIT_FAILURE
    except Exception:
        # (an extension module imported as the signal came: its own error, not ours)
        if was_terminated():
            quiet_store_exit()
            terminated_line()
            return EXIT_TERMINATED
        if was_interrupted():
            quiet_store_exit()
            interrupted_line()
            return EXIT_INTERRUPTED
        raise
    return 0
