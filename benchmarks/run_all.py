"""Run every benchmark that README.md and benchmarks/README.md quote, into one saved run.

One command (``make bench-all``)::

    python benchmarks/run_all.py                  # the full run (about 15 minutes on a quiet 2-core machine)
    python benchmarks/run_all.py --quick          # smaller problems (about 3 minutes): proves the pipeline
    python benchmarks/run_all.py --only equal-work,sweep --out /tmp/run.json --no-tables

Each benchmark runs as a script of its own (a fresh interpreter, ``--json``), one after the
other; their records, the machine (processor, cores, its widest vector instructions and the
lane widths grazing and heyoka chose), the versions, the git commit and the date go into one
JSON file, ``benchmarks/results/latest.json`` by default.  Every timing in it is the median
of repeated runs with their min-max spread.  Then ``tables.py`` rewrites the tables of
README.md and benchmarks/README.md from that file (between their ``<!-- bench:... -->``
markers; ``tests/test_benchmark_tables.py`` checks that they agree with it).

A run on a machine that is not quiet can be saved as provisional (``--provisional
"why"``): the tables then say so.
"""

from __future__ import annotations

import argparse
import datetime
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from _common import loadavg, log, machine_info

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
DEFAULT_OUT = HERE / "results" / "latest.json"


PARTS: dict[str, tuple[str, list[str], list[str]]] = {
    # name: (script, options of the full run, options of a --quick run)
    "equal-work": ("bench_equal_work.py", [], ["--quick", "--repeats", "3"]),
    "sweep": ("bench_sweep.py", [], ["--quick"]),
    "simulate": ("bench_simulate.py", [], ["--quick"]),
    "grazing-curve": ("bench_grazing_curve.py", [], []),
    "curves": ("bench_curves.py", [], []),
    "scaling": (
        "bench_scaling.py",
        ["--points", "8000", "32000", "--default", "--default-points", "8000", "--dask"],
        ["--points", "1000", "--runs", "2", "--dask"],
    ),
}
QUIET_WAIT_SCRIPTS = {"bench_equal_work.py", "bench_sweep.py", "bench_grazing_curve.py", "bench_curves.py"}
"""The scripts that wait for other processes to go quiet before each timed run (``--quiet-wait``)."""


def git_commit() -> str:
    """The commit of this tree, ``+dirty`` when it has uncommitted changes ("unknown" without git)."""
    try:
        from grazing.report.provenance import git_commit as commit

        return commit()
    except Exception:  # never fatal to a benchmark run
        return "unknown"


def run_part(name: str, quick: bool, quiet_wait: float | None) -> dict[str, Any]:
    """Run one benchmark script in a fresh interpreter; its JSON record and its wall time."""
    script, full, fast = PARTS[name]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / f"{name}.json"
        cmd = [sys.executable, str(HERE / script), *(fast if quick else full), "--json", str(out)]
        if quiet_wait is not None and script in QUIET_WAIT_SCRIPTS:
            cmd += ["--quiet-wait", str(quiet_wait)]
        log(f"== {name}: {' '.join(Path(c).name if c.startswith('/') else c for c in cmd[1:])}")
        start = time.perf_counter()
        subprocess.run(cmd, check=True, cwd=HERE, stdout=subprocess.DEVNULL)
        record = json.loads(out.read_text())
    record["wall_s"] = time.perf_counter() - start
    record["script"] = script
    return record


def shown_command(argv: list[str]) -> str:
    """The command as the record shows it (the reason of ``--provisional`` is a field of its own)."""
    shown, skip = ["python benchmarks/run_all.py"], False
    for arg in argv:
        if skip:
            shown.append("…")
            skip = False
        elif arg == "--provisional":
            shown.append(arg)
            skip = True
        else:
            shown.append("--provisional …" if arg.startswith("--provisional=") else arg)
    return " ".join(shown)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the scripts' --quick problems (smaller, noisier)")
    ap.add_argument(
        "--only", default=",".join(PARTS), help=f"comma-separated parts (default all: {','.join(PARTS)})"
    )
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT, help="the JSON file (default %(default)s)")
    ap.add_argument("--quiet-wait", type=float, default=None, metavar="S",
                    help="passed to the scripts that wait for a quiet machine (default: theirs)")  # fmt: skip
    ap.add_argument(
        "--provisional", default="", metavar="WHY", help="save the run as provisional, saying why"
    )
    ap.add_argument("--no-tables", action="store_true", help="do not rewrite the README tables")
    args = ap.parse_args(argv)
    names = [n.strip() for n in args.only.split(",") if n.strip()]
    unknown = [n for n in names if n not in PARTS]
    if unknown:
        ap.error(f"unknown part(s) {', '.join(unknown)}; known: {', '.join(PARTS)}")
    started = datetime.datetime.now(datetime.timezone.utc)
    machine = machine_info()
    parts = {name: run_part(name, args.quick, args.quiet_wait) for name in names}
    machine["loadavg_end"] = loadavg()
    record = {
        "date": started.strftime("%Y-%m-%d %H:%M UTC"),
        "command": shown_command(argv if argv is not None else sys.argv[1:]),
        "quick": args.quick,
        "provisional": args.provisional,
        "commit": git_commit(),
        "machine": machine,
        "wall_s": (datetime.datetime.now(datetime.timezone.utc) - started).total_seconds(),
        "parts": parts,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.out.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(record, indent=1, default=float) + "\n")
    tmp.replace(args.out)
    log(f"saved {args.out} ({record['wall_s']:.0f} s)")
    if not args.no_tables:
        import tables

        for path in tables.write(record):
            log(f"rewrote the tables of {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
