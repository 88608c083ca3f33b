"""What a new user waits for: the first compile on a fresh machine, and the whole report.

One run, saved as ``benchmarks/results/first_run.json`` (the date, the machine and its load, as
``run_all.py`` saves the others); ``tables.py`` writes the README's ``<!-- bench:first-run -->``
block from it.  Each step is a fresh ``grazing`` process with its own kernel cache
(``GRAZING_CACHE_DIR`` a new folder), so nothing compiled before counts::

    python benchmarks/bench_first_run.py                 # about 4 minutes on 2 cores
    python benchmarks/bench_first_run.py --no-report     # the compile steps only (a minute)

Steps: ``first_compile`` (``grazing simulate`` of the pendulum with an empty cache: numba compiles
the integration driver and the pendulum's kernels are generated and compiled), ``cached`` (the same
command again), ``new_model`` (another model's kernels, the driver cached) and ``report``
(``grazing report`` into a new folder, the cache of the first steps: its wall time, and the CPU
seconds of all its processes).
"""

from __future__ import annotations

import datetime
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from _common import bench_parser, grazing_exe, loadavg, log, machine_info

HERE = Path(__file__).resolve().parent
DEFAULT_OUT = HERE / "results" / "first_run.json"

SIMULATE = ["simulate", "--case", "B", "--eta", "0.446", "--theta-hat", "40", "--periods", "10", "--json"]
NEW_MODEL = ["simulate", "--model", "impact-oscillator", "--periods", "10", "--json"]


def timed(args: list[str], env: dict[str, str]) -> dict[str, float]:
    """Wall and CPU seconds (user + system, all child processes) of one ``grazing`` command."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([grazing_exe(), *args], check=True, env=env, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall_s": round(wall, 2), "cpu_s": round(cpu, 2)}


def main(argv: list[str] | None = None) -> int:
    parser = bench_parser(__doc__)
    parser.add_argument("--no-report", action="store_true", help="leave out the report (the longest step)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="where the run is saved")
    args = parser.parse_args(argv)
    record: dict[str, Any] = {
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "command": "python benchmarks/bench_first_run.py" + (" --no-report" if args.no_report else ""),
        "machine": {**machine_info(), "loadavg_start": loadavg()},
        "steps": {},
    }
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "GRAZING_CACHE_DIR": str(Path(tmp) / "cache")}
        steps = [("first_compile", SIMULATE), ("cached", SIMULATE), ("new_model", NEW_MODEL)]
        if not args.no_report:
            steps.append(("report", ["report", "--out", str(Path(tmp) / "report")]))
        for name, cmd in steps:
            log(f"== {name}: grazing {' '.join(cmd)}")
            record["steps"][name] = timed(cmd, env)
            log(f"   {record['steps'][name]}")
    record["machine"]["loadavg_end"] = loadavg()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=1) + "\n")
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1) + "\n")
    print(json.dumps(record["steps"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
