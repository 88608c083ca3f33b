"""Helpers shared by the benchmark scripts: command line, output, machine description, load average,
fresh-process timing."""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import subprocess
import sys
import time
from collections.abc import Callable
from importlib.metadata import PackageNotFoundError, version
from typing import Any

PACKAGES = ("numpy", "scipy", "numba", "heyoka", "grazing")


def bench_parser(doc: str, quiet_wait: float | None = None) -> argparse.ArgumentParser:
    """The options every benchmark has (``--markdown``, ``--json``; ``--quiet-wait`` given its default)."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="also print a Markdown table")
    parser.add_argument("--json", metavar="FILE", help="write all numbers to FILE")
    if quiet_wait is not None:
        parser.add_argument(
            "--quiet-wait",
            type=float,
            default=quiet_wait,
            metavar="S",
            help="before each timed run, wait up to S seconds for other processes to go quiet (0: never)",
        )
    return parser


def emit(
    args: argparse.Namespace,
    print_table: Callable[[], None],
    markdown: Callable[[], str],
    data: Callable[[], Any],
) -> None:
    """Print the table, then the Markdown table with ``--markdown``, and write ``data()`` to ``--json``."""
    print_table()
    if args.markdown:
        print()
        print(markdown())
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(data(), fh, indent=2, default=float)


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def loadavg() -> str:
    try:
        with open("/proc/loadavg") as fh:
            return " ".join(fh.read().split()[:3])
    except OSError:
        return "n/a"


def machine_info(packages: tuple[str, ...] = PACKAGES) -> dict[str, Any]:
    """CPU, core count, Python and package versions, and the load average now (``loadavg_start``)."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            cpu = next((ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")), cpu)
    except OSError:
        pass
    versions = {}
    for p in packages:
        try:
            versions[p] = version(p)
        except PackageNotFoundError:
            versions[p] = "n/a"
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        **versions,
        "loadavg_start": loadavg(),
    }


def versions_line(m: dict[str, Any], packages: tuple[str, ...] = PACKAGES) -> str:
    pkgs = ", ".join(f"{p} {m[p]}" for p in packages if p in m)
    return (
        f"{m['cpu']}, {m['cores']} cores; Python {m['python']}, {pkgs}; "
        f"load average {m['loadavg_start']} (start), {m.get('loadavg_end', 'n/a')} (end)"
    )


def command_seconds(cmd: list[str], repeats: int, **kwargs: Any) -> float:
    """Best wall time of running ``cmd`` (a fresh process) ``repeats`` times."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run(cmd, check=True, **kwargs)
        best = min(best, time.perf_counter() - start)
    return best


def process_seconds(code: str, repeats: int) -> float:
    """Best wall time of ``python -c code`` in a fresh interpreter."""
    return command_seconds([sys.executable, "-c", code], repeats)


# ----------------------------------------------------------------------------- other processes' load


def _busy_cpu_seconds() -> float:
    """CPU seconds spent busy (all processes, all cores) since boot, from /proc/stat; nan if unavailable."""
    try:
        with open("/proc/stat") as fh:
            fields = [int(v) for v in fh.readline().split()[1:]]
    except (OSError, ValueError):
        return math.nan
    user, nice, system, _idle, _iowait, irq, softirq, steal = (fields + [0] * 8)[:8]
    return (user + nice + system + irq + softirq + steal) / os.sysconf("SC_CLK_TCK")


def _own_cpu_seconds() -> float:
    """CPU seconds of this process and its waited-for children."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


class Meter:
    """Wall time of a block, and the cores other processes kept busy meanwhile (``others``).

    ``others`` = (busy CPU time of the machine - CPU time of this process and its children)
    / wall time, from /proc/stat; children count once they have been waited for (subprocess
    runs, process pools shut down inside the block).  nan where /proc/stat is unavailable.
    """

    def __enter__(self) -> Meter:
        self._busy, self._own, self._t = _busy_cpu_seconds(), _own_cpu_seconds(), time.perf_counter()
        return self

    def __exit__(self, *exc: object) -> None:
        self.seconds = time.perf_counter() - self._t
        busy = _busy_cpu_seconds() - self._busy
        own = _own_cpu_seconds() - self._own
        self.others = max(0.0, busy - own) / self.seconds if self.seconds > 0 else math.nan


def wait_quiet(max_seconds: float, threshold: float = 0.3, window: float = 1.0) -> float:
    """Wait (at most ``max_seconds``) until other processes use under ``threshold`` cores over ``window``.

    Returns the seconds waited.  Benchmarks on a shared machine call this before each timed
    run so that bursts of other work (tests, builds) do not land in the measurement.
    """
    start = time.perf_counter()
    while time.perf_counter() - start < max_seconds:
        with Meter() as m:
            time.sleep(window)
        if not m.others >= threshold:  # also stops when the load cannot be measured (nan)
            break
    return time.perf_counter() - start


def best_command(cmd: list[str], repeats: int, quiet: float = 0.0, **kwargs: Any) -> tuple[float, float]:
    """Best wall time of ``cmd`` (a fresh process) over ``repeats`` runs, and ``others`` during it.

    Before each run, waits up to ``quiet`` seconds for the machine to be quiet (:func:`wait_quiet`).
    """
    best = (math.inf, math.nan)
    for _ in range(repeats):
        wait_quiet(quiet)
        with Meter() as m:
            subprocess.run(cmd, check=True, **kwargs)
        best = min(best, (m.seconds, m.others))
    return best
