"""Helpers shared by the benchmark scripts: command line, output, machine description, load average,
fresh-process timing."""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib.metadata import PackageNotFoundError, version
from typing import Any

EQUAL_WORK_TOL = 1e-10
"""The tolerance of the equal-work sweep (grazing's sweep tolerance; the heyoka peer's too)."""

EQUAL_WORK = ["--fresh", "--no-lyapunov", "--no-adaptive", "--tol", str(EQUAL_WORK_TOL)]
"""grazing's options for the peer's work: every point from rest, full transients, no Lyapunov exponents."""

PACKAGES = ("numpy", "scipy", "numba", "llvmlite", "heyoka", "grazing")
VECTOR_ISAS = (("avx512f", "AVX-512", 8), ("avx2", "AVX2", 4), ("avx", "AVX", 4), ("sse2", "SSE2", 2))
"""(/proc/cpuinfo flag, name, doubles per register), widest first."""


def grazing_exe() -> str:
    """The ``grazing`` command of this interpreter's environment (else the one on PATH)."""
    import shutil
    from pathlib import Path

    exe = Path(sys.executable).with_name("grazing")
    return str(exe) if exe.exists() else (shutil.which("grazing") or "grazing")


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
    """Print the table, then the Markdown table with ``--markdown``, and write ``data()`` to ``--json``.

    The JSON also holds the Markdown table (key ``markdown``): ``run_all.py`` keeps it in the
    saved run, and ``tables.py`` copies it into benchmarks/README.md.
    """
    print_table()
    if args.markdown:
        print()
        print(markdown())
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({**data(), "markdown": markdown()}, fh, indent=2, default=float)


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
        **vector_isa(),
        "python": platform.python_version(),
        **versions,
        "loadavg_start": loadavg(),
    }


def cpu_flags() -> set[str]:
    """The processor's feature flags from /proc/cpuinfo (empty where there is none)."""
    try:
        with open("/proc/cpuinfo") as fh:
            line = next((ln for ln in fh if ln.startswith("flags")), "")
    except OSError:
        return set()
    return set(line.partition(":")[2].split())


def vector_isa() -> dict[str, Any]:
    """The widest vector instructions the processor has, and the lane widths the engines chose.

    ``vector_isa`` / ``vector_doubles``: from /proc/cpuinfo's flags (AVX-512: 8 doubles per
    register, AVX2: 4, ...); ``grazing_lanes``: the lanes of grazing's sweep kernels on this
    machine; ``heyoka_simd_size``: heyoka's ``recommended_simd_size()`` (0: not installed).
    """
    flags = cpu_flags()
    isa, doubles = next(((name, n) for flag, name, n in VECTOR_ISAS if flag in flags), ("unknown", 0))
    try:
        from grazing.report.provenance import vector_width

        grazing_lanes = vector_width()
    except Exception:  # never fatal to a benchmark
        grazing_lanes = 0
    try:
        import heyoka as hy

        heyoka_simd = int(hy.recommended_simd_size())
    except ImportError:
        heyoka_simd = 0
    return {"vector_isa": isa, "vector_doubles": doubles, "grazing_lanes": grazing_lanes,
            "heyoka_simd_size": heyoka_simd}  # fmt: skip


def versions_line(m: dict[str, Any], packages: tuple[str, ...] = PACKAGES) -> str:
    pkgs = ", ".join(f"{p} {m[p]}" for p in packages if p in m)
    return (
        f"{m['cpu']}, {m['cores']} cores{isa_note(m)}; Python {m['python']}, {pkgs}; "
        f"load average {m['loadavg_start']} (start), {m.get('loadavg_end', 'n/a')} (end)"
    )


def isa_note(m: dict[str, Any]) -> str:
    """ ", AVX-512 (8 doubles; grazing 8 lanes, heyoka 8)" from :func:`vector_isa`'s keys, if present."""
    if "vector_isa" not in m:
        return ""
    return (
        f", {m['vector_isa']} ({m['vector_doubles']} doubles per register; lanes: grazing "
        f"{m['grazing_lanes']}, heyoka {m['heyoka_simd_size']})"
    )


@dataclass(frozen=True)
class Spread:
    """Repeated measurements of one quantity: their median, smallest and largest, and all of them."""

    median: float
    min: float
    max: float
    runs: tuple[float, ...]

    @classmethod
    def of(cls, values: Sequence[float]) -> Spread:
        """The spread of ``values`` (at least one).

        >>> Spread.of([3.0, 1.0, 2.0, 10.0]).median, Spread.of([3.0, 1.0, 2.0]).max
        (2.5, 3.0)
        """
        vals = tuple(float(v) for v in values)
        return cls(statistics.median(vals), min(vals), max(vals), vals)

    def scaled(self, factor: float) -> Spread:
        """The same runs times ``factor`` (e.g. seconds to µs per period)."""
        return Spread.of([v * factor for v in self.runs])

    def as_dict(self) -> dict[str, Any]:
        return {"median": self.median, "min": self.min, "max": self.max, "runs": list(self.runs)}


def command_seconds(cmd: list[str], repeats: int, **kwargs: Any) -> float:
    """Median wall time of running ``cmd`` (a fresh process) ``repeats`` times."""
    return command_spread(cmd, repeats, **kwargs).median


def command_spread(cmd: list[str], repeats: int, **kwargs: Any) -> Spread:
    """Wall times of running ``cmd`` (a fresh process) ``repeats`` times."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run(cmd, check=True, **kwargs)
        times.append(time.perf_counter() - start)
    return Spread.of(times)


def process_seconds(code: str, repeats: int) -> float:
    """Median wall time of ``python -c code`` in a fresh interpreter."""
    return command_seconds([sys.executable, "-c", code], repeats)


def process_spread(code: str, repeats: int) -> Spread:
    """Wall times of ``python -c code`` in a fresh interpreter, ``repeats`` times."""
    return command_spread([sys.executable, "-c", code], repeats)


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
    """Median wall time of ``cmd`` (a fresh process) over ``repeats`` runs, and the median ``others``.

    Before each run, waits up to ``quiet`` seconds for the machine to be quiet (:func:`wait_quiet`).
    (The name is historical: it took the best run until issue 29.)
    """
    spread, others = metered_command(cmd, repeats, quiet, **kwargs)
    return spread.median, others.median


def metered_command(cmd: list[str], repeats: int, quiet: float = 0.0, **kwargs: Any) -> tuple[Spread, Spread]:
    """Wall times of ``cmd`` (a fresh process) over ``repeats`` runs, and ``others`` during each."""
    seconds, others = [], []
    for _ in range(repeats):
        wait_quiet(quiet)
        with Meter() as m:
            subprocess.run(cmd, check=True, **kwargs)
        seconds.append(m.seconds)
        others.append(m.others)
    return Spread.of(seconds), Spread.of(others)
