"""The ``grazing`` command's entry point, a module of its own outside the package.

Importing ``grazing.cli`` takes a few tenths of a second (numpy, click, the
commands); a Ctrl-C meanwhile would print Python's traceback.  This module
imports nothing before it can catch that, so a Ctrl-C at any moment ends the
command with one line and exit status 130 (:func:`grazing.cli.main` handles
the rest).
"""

from __future__ import annotations

import os
import sys

EXIT_INTERRUPTED = 130  # grazing.cli.common.EXIT_INTERRUPTED (not imported: that is the point)


BLAS_THREADS = "1"
"""OpenBLAS threads of a command, unless ``OPENBLAS_NUM_THREADS`` says otherwise: grazing computes in
threads of its own, and the BLAS library's threads, started when numpy is imported, spin for about
0.1 s of a core each before they sleep (measured: 0.08-0.1 s of CPU time per command); nothing a
command does is large linear algebra."""


EXIT_TERMINATED = 143  # grazing.cli.common.EXIT_TERMINATED


class _Terminated(KeyboardInterrupt):
    """SIGTERM while importing (grazing.engine.interrupts.Terminated is not imported yet)."""


def _raise_terminated(_signum: int, _frame: object) -> None:
    raise _Terminated


def main() -> int:
    """Import the command line and run it; a Ctrl-C or a SIGTERM while importing is one line."""
    import signal

    os.environ.setdefault("OPENBLAS_NUM_THREADS", BLAS_THREADS)  # (before numpy is imported)
    default_term = signal.getsignal(signal.SIGTERM) == signal.SIG_DFL
    try:
        if default_term:
            signal.signal(signal.SIGTERM, _raise_terminated)
        try:
            from grazing.cli import main as run
        finally:
            if default_term:  # (grazing.cli.main installs its own)
                signal.signal(signal.SIGTERM, signal.SIG_DFL)
    except _Terminated:
        print("grazing: terminated", file=sys.stderr)  # (cli.terminated_line)
        return EXIT_TERMINATED
    except KeyboardInterrupt:
        print(
            ("\n" if sys.stderr.isatty() else "") + "grazing: interrupted", file=sys.stderr
        )  # (cli.interrupted_line)
        return EXIT_INTERRUPTED
    return run()


def console() -> None:
    """The ``grazing`` console script: :func:`main`, then the process ends without Python's teardown
    (:func:`grazing.cli.quick_exit.quick_exit`, 15-30 ms of every command)."""
    code = main()
    if "grazing.cli" not in sys.modules:
        sys.exit(code)  # (interrupted while importing it: Python's exit, as quick_exit would import it)
    from grazing.cli.quick_exit import quick_exit

    quick_exit(code)


if __name__ == "__main__":  # pragma: no cover - the console script calls console()
    console()
