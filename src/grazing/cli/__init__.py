"""The ``grazing`` command line: one module per command group, the shared parts in :mod:`.common`.

Every analysis command takes the paper's parameter cases by name (``--case B``,
the default) and/or explicit parameters (``--alpha --beta --r --eta
--theta-hat``, the stop angle in degrees), prints a human-readable summary, or
one JSON object with ``--json``.  Bad input gets one line on stderr and a
non-zero exit status; nothing is written.
"""

from __future__ import annotations

import click

import grazing
from grazing.cli import attractors, curves, experiment, explore, normalform, orbits, report, simulate, sweeps
from grazing.cli.common import EXIT_FAILURE, EXIT_INTERRUPTED, EXIT_USAGE, error_line
from grazing.cli.limits import MEMORY_ENV
from grazing.errors import GrazingError

__all__ = ["cli", "main"]


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(grazing.__version__, prog_name="grazing")
def cli() -> None:
    """Simulate and analyse impacting systems (the inclined impacting pendulum of
    Piiroinen, Virgin & Champneys 2004 by default)."""


for _command in (
    simulate.simulate, orbits.orbit, orbits.graze, orbits.graze_curve, orbits.continue_, curves.curve,
    sweeps.sweep_cmd, normalform.normal_form_cmd, sweeps.map_cmd, report.report, *experiment.COMMANDS,
    *attractors.COMMANDS,  # issue 28
    explore.explore,  # issue 31
):  # fmt: skip
    cli.add_command(_command)


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; every error becomes one line on stderr and an exit status.

    Without arguments it prints the help, as ``grazing --help`` does.
    """
    import sys

    if not (sys.argv[1:] if argv is None else argv):
        argv = ["--help"]
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
        error_line(exc.format_message())
        return EXIT_USAGE
    except GrazingError as exc:
        error_line(str(exc))
        return EXIT_FAILURE
    except OSError as exc:
        error_line(f"{exc.strerror or exc}: {exc.filename or ''}".rstrip(": "))
        return EXIT_FAILURE
    except MemoryError:
        error_line(f"out of memory (the estimate before the run was too low; {MEMORY_ENV} lowers the bound)")
        return EXIT_FAILURE
    return 0
