"""The benchmark tables of README.md and benchmarks/README.md, rewritten from the saved run.

Every number the two READMEs (and docs/installation.md) quote about speed stands between a pair of
markers::

    <!-- bench:NAME -->
    ...generated text...
    <!-- /bench:NAME -->

and is generated here from ``benchmarks/results/latest.json`` (written by ``run_all.py``), the
first compile and the whole report from ``benchmarks/results/first_run.json`` (``bench_first_run.py``).
``python benchmarks/tables.py`` rewrites the blocks; ``--check`` only says whether they
agree with the saved run (``tests/test_benchmark_tables.py`` does the same without running
anything).  Text outside the markers is left alone.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SAVED_RUN = HERE / "results" / "latest.json"
FIRST_RUN = HERE / "results" / "first_run.json"
"""The saved run of ``bench_first_run.py`` (the first compile, the whole report): a run of its own."""
README = ROOT / "README.md"
BENCH_README = HERE / "README.md"
INSTALLATION = ROOT / "docs" / "installation.md"
LARGE = 100_000  # bench_simulate.py's long run

MARKER = re.compile(r"(<!-- bench:(?P<name>[a-z-]+) -->\n)(?P<body>.*?)(<!-- /bench:(?P=name) -->)", re.S)


# ----------------------------------------------------------------------------- formatting


def spread(d: dict[str, Any], fmt: str = ".2f", unit: str = " s") -> str:
    """'0.76 s (0.74–0.81)' from a record with median, min and max."""
    return f"{d['median']:{fmt}}{unit} ({d['min']:{fmt}}–{d['max']:{fmt}})"


def spread_of(median: float, lo: float, hi: float, fmt: str = ".2f", unit: str = " s") -> str:
    return spread({"median": median, "min": lo, "max": hi}, fmt, unit)


def source(record: dict[str, Any]) -> str:
    """Where the numbers come from: the saved run, its date, machine and command."""
    m = record["machine"]
    text = (
        f"Saved run of {record['date']} (`benchmarks/results/latest.json`, `{record['command']}`, commit "
        f"{record['commit'][:12] or 'unknown'}): {m['cpu']}, {m['cores']} cores, {m['vector_isa']} "
        f"({m['vector_doubles']} doubles per vector register; grazing's kernels {m['grazing_lanes']} lanes, "
        f"heyoka's recommended SIMD size {m['heyoka_simd_size']}); load average {m['loadavg_start']} at the "
        f"start, {m['loadavg_end']} at the end. Times: median of the repeated runs (min–max)."
    )
    if record["quick"]:
        text += " The scripts' `--quick` problems (smaller than the full run's)."
    if record["provisional"]:
        text = f"**Provisional** ({record['provisional']}). " + text
    return text


def same_run(record: dict[str, Any]) -> str:
    """The short form of :func:`source`, for a block after the first."""
    mark = "**Provisional**: " if record["provisional"] else ""
    return f"{mark}Saved run of {record['date']}, as above (medians, min–max)."


def part(record: dict[str, Any], name: str) -> dict[str, Any]:
    return record["parts"][name]


# ----------------------------------------------------------------------------- README.md


SIM_LABELS = {
    "grazing": "`grazing.simulate`",
    "heyoka-3d": "heyoka.py loop, paper's 3-D form (τ as a state)",
    "heyoka-t": "heyoka.py loop, explicit time",
    "scipy": "scipy `solve_ivp` loop (DOP853, rtol 1e-10)",
}


def sim_timing(sim: dict[str, Any], engine: str) -> dict[str, Any]:
    """The engine's timing over 100,000 periods, or its longest (scipy's in a ``--quick`` run)."""
    return max((t for t in sim["timings"] if t["engine"] == engine), key=lambda t: t["periods"])


def sim_deviation(sim: dict[str, Any], engine: str) -> str:
    """The deviation from the reference after the longest run, and an impact missed or out of phase."""
    t = max((t for t in sim["timings"] if t["engine"] == engine), key=lambda t: t["measured_periods"])
    text = f"{t['deviation']:.1e}"
    if t["measured_periods"] != LARGE:
        text += f" (after {t['measured_periods']:,} periods)"
    a = next(a for a in sim["agreement"] if a["engine"] == engine and a["periods"] == t["measured_periods"])
    if a["shift"] or a["impacts"] != a["impacts_grazing"]:
        text += f"; {a['impacts']:,} impacts to grazing's {a['impacts_grazing']:,}, first difference at "
        text += f"{a['first_mismatch']}"
    return text


def readme_simulate(record: dict[str, Any]) -> str:
    sim = part(record, "simulate")
    n_depths = len(sim["shallow_impacts"]["depths"])
    rows = [
        "| engine | µs per forcing period (100,000 periods) | whole process, 100,000 periods "
        f"| deviation from a long-double reference | shallow impacts missed (of {n_depths}) |",
        "|---|---:|---:|---:|---:|",
    ]
    extrapolated = shorter = False
    for engine, label in SIM_LABELS.items():
        t = sim_timing(sim, engine)
        p = next(p for p in sim["process_seconds"] if p["engine"] == engine)
        us = 1e6 / t["periods"]
        mark = "*" if t["extrapolated"] or p["extrapolated"] else ""
        extrapolated |= bool(mark)
        per_period = spread_of(t["seconds"] * us, t["seconds_min"] * us, t["seconds_max"] * us, ".1f", "")
        if t["periods"] != LARGE:
            per_period += f" (over {t['periods']:,} periods)"
            shorter = True
        rows.append(
            f"| {label} | {per_period}"
            f"{mark} | {spread_of(p['seconds'], p['seconds_min'], p['seconds_max'])}{mark} "
            f"| {sim_deviation(sim, engine)} | {sim['shallow_impacts']['missed'][engine]} |"
        )
    g, h3, ht, sc = (sim_timing(sim, e)["seconds"] / sim_timing(sim, e)["periods"] for e in SIM_LABELS)
    notes = [
        "",
        f"Per forcing period (medians) `grazing` takes {min(h3, ht) / g:.2f}× less time than the faster "
        f"heyoka loop and {sc / g:.0f}× less than scipy's.",
    ]
    if extrapolated:
        notes.append("\\* extrapolated from a shorter run (see benchmarks/README.md).")
    if shorter:
        notes.append("A `--quick` run times scipy over fewer periods only.")
    notes += ["", source(record)]
    return "\n".join(rows + notes)


SWEEP_ROWS = {
    "grazing": "`grazing.sweeps.sweep()`: all cores, SIMD lanes, adaptive transients, Lyapunov exponent "
    "at every point",
    "grazing-nolyap": "the same without Lyapunov exponents",
    "grazing-w1": "the same (with Lyapunov exponents) on one core",
    "heyoka-t": "heyoka.py loop, explicit time, default tolerance",
    "heyoka-3d": "heyoka.py loop, paper's 3-D form, default tolerance",
    "heyoka-t-1e-10": "heyoka.py loop, explicit time, tolerance 1e-10 (as ours)",
    "scipy": "scipy `solve_ivp` loop (DOP853; extrapolated from every 50th point)",
}


def sweep_timing(sw: dict[str, Any], key: str) -> dict[str, Any]:
    return next(t for t in sw["timings"] if t["key"] == key)


def readme_sweep(record: dict[str, Any]) -> str:
    sw = part(record, "sweep")
    ours = sweep_timing(sw, "grazing")["seconds"]
    same = sweep_timing(sw, "grazing-nolyap")["seconds"]
    rows = [
        f"| sweep ({sw['settings']['points']} points) | wall time | × ours (with Lyapunov) "
        "| × ours (same work: no Lyapunov) |",
        "|---|---:|---:|---:|",
    ]
    for key, label in SWEEP_ROWS.items():
        t = sweep_timing(sw, key)
        time = (
            f"{t['seconds']:.2f} s*"
            if t["extrapolated"]
            else spread_of(t["seconds"], t["seconds_min"], t["seconds_max"])
        )
        vs_same = "–" if key in ("grazing", "grazing-w1") else f"{t['seconds'] / same:.1f}"
        rows.append(f"| {label} | {time} | {t['seconds'] / ours:.1f} | {vs_same} |")
    lo, hi = sw["process_seconds_min_max"]
    rows.append(
        f"| the whole `grazing sweep ... --json` command (a fresh process: imports, kernel load, sweep) "
        f"| {spread_of(sw['process_seconds'], lo, hi)} | {sw['process_seconds'] / ours:.1f} | – |"
    )
    plain, loop = sweep_timing(sw, "grazing-plain")["seconds"], sweep_timing(sw, "heyoka-t-1e-10")["seconds"]
    one_core, no_adapt = (sweep_timing(sw, k)["seconds"] / ours for k in ("grazing-w1", "grazing-noadapt"))
    notes = [
        "",
        f"Where the speed comes from (medians): both cores (on one core the sweep takes {one_core:.1f}× as "
        f"long), adaptive transients (without them {no_adapt:.1f}× as long); the Lyapunov exponents cost "
        f"time (the default sweep takes {ours / same:.2f}× as long as without them); and the "
        f"engine: on one core, with one chain of points (one lane), full transients and no Lyapunov "
        f"exponents the sweep takes {plain:.2f} s, {loop / plain:.1f}× less than the heyoka loop at the same "
        "tolerance. \\* extrapolated.",
        "",
        same_run(record),
    ]
    return "\n".join(rows + notes)


EW_ROWS = {
    "whole_process": "whole processes (imports, kernel load or JIT compilation included), {p} cores",
    "in_process": "in-process (kernels loaded, integrators compiled), {p} cores",
    "in_process_one_core": "in-process, one core",
}


def equal_work_rows(ew: dict[str, Any]) -> list[str]:
    n, p = ew["settings"]["points"], ew["settings"]["processes"]
    rows = [
        f"| equal work, {n} points | grazing | heyoka.py batch mode, its best lane count | grazing's lead "
        "(medians) | periods agree |",
        "|---|---:|---:|---:|---:|",
    ]
    for key, label in EW_ROWS.items():
        d = ew[key]
        best = d["configs"][d["heyoka_best"]]
        lanes = d["heyoka_best"].split("-")[1]
        agree = best["periods"]
        rows.append(
            f"| {label.format(p=p)} | {spread(d['configs']['grazing']['seconds'])} "
            f"| {spread(best['seconds'])} ({lanes} lanes) | {d['speedup_median']:.2f}× "
            f"| {agree['agree']} of {agree['points']} |"
        )
    return rows


def readme_equal_work(record: dict[str, Any]) -> str:
    ew = part(record, "equal-work")
    s = ew["settings"]
    notes = [
        "",
        f"Every point from rest, {s['transient']} + {s['periods']} periods, tol {s['tol']:g}, no Lyapunov "
        f"exponents: `grazing sweep ... --fresh --no-lyapunov --no-adaptive --tol {s['tol']:g}` (a thread "
        f"per core) against `benchmarks/heyoka_batch_sweep.py` (batch mode, one SIMD lane per η value, "
        f"{', '.join(map(str, s['lanes_tried']))} lanes tried, a process per core; how it is tuned: "
        "[benchmarks/README.md](benchmarks/README.md#the-heyokapy-batch-peer)); "
        f"{s['repeats']} interleaved runs each.",
        "",
        same_run(record),
    ]
    return "\n".join(equal_work_rows(ew) + notes)


def readme_curve(record: dict[str, Any]) -> str:
    gc = part(record, "grazing-curve")
    lo, hi = gc["min_max_s"]
    plo, phi = gc["process_min_max_s"]
    return (
        f"The grazing curve of fig 6 (θ̂ = 5° over θ̂_max and down, {gc['points']} points with multipliers) "
        f"takes {spread_of(gc['median_s'], lo, hi)} in-process, {spread_of(gc['process_s'], plo, phi)} as a "
        f"whole `grazing graze-curve` process (saved run of {record['date']}, as above):"
    )


def readme_first_run(_record: dict[str, Any]) -> str:
    """The first compile and the whole report, from :data:`FIRST_RUN` (``bench_first_run.py``)."""
    run = json.loads(FIRST_RUN.read_text())
    st, m = run["steps"], run["machine"]
    text = (
        f"On a fresh machine the first command compiles the integration driver (numba, once per machine) "
        f"and the model's kernels: {st['first_compile']['wall_s']:.0f} s for the first `grazing simulate` "
        f"of the pendulum, {st['cached']['wall_s']:.1f} s for the same command once they are cached, and "
        f"{st['new_model']['wall_s']:.1f} s for a first run of another model (its kernels compiled, the "
        "driver cached)."
    )
    if "report" in st:
        rep = st["report"]
        text += (
            f" The whole report (`grazing report` after those steps, compiling the kernels it needs beyond "
            f"theirs) took {rep['wall_s']:.0f} s of wall time and {rep['cpu_s']:.0f} CPU-seconds over all "
            "its processes."
        )
    text += (
        f" Saved run of {run['date']} (`benchmarks/results/first_run.json`, `{run['command']}`): {m['cpu']}, "
        f"{m['cores']} cores, {m['vector_isa']}; load average {m['loadavg_start']} at the start, "
        f"{m['loadavg_end']} at the end."
    )
    if float(m["loadavg_start"].split()[0]) > 0.5 * m["cores"]:
        text += " Other programs kept the cores busy during the run: on a quiet machine expect less."
    return text


# ----------------------------------------------------------------------------- benchmarks/README.md


def bench_run(record: dict[str, Any]) -> str:
    parts = ", ".join(f"{name} {p['wall_s']:.0f} s" for name, p in record["parts"].items())
    return "\n".join([source(record), "", f"Wall time of the run: {record['wall_s']:.0f} s ({parts})."])


def bench_equal_work(record: dict[str, Any]) -> str:
    ew = part(record, "equal-work")
    n, p = ew["settings"]["points"], ew["settings"]["processes"]
    rows = [
        f"| {n} points | configuration | wall time, median (min–max) | × grazing "
        "| periods agree with grazing |",
        "|---|---|---:|---:|---:|",
    ]
    for key, label in EW_ROWS.items():
        d = ew[key]
        ours = d["configs"]["grazing"]["seconds"]["median"]
        for name, c in d["configs"].items():
            what = "grazing" if name == "grazing" else f"heyoka.py batch, {name.split('-')[1]} lanes"
            if name == d["heyoka_best"]:
                what += " (heyoka's best)"
            agree = c.get("periods")
            rows.append(
                f"| {label.format(p=p)} | {what} | {spread(c['seconds'], '.3f')} "
                f"| {c['seconds']['median'] / ours:.2f} | "
                + ("–" if agree is None else f"{agree['agree']} of {agree['points']}")
                + " |"
            )
    wp = ew["whole_process"]["configs"]
    notes = ["", "Commands (whole processes):", ""] + [f"- `{c['command']}`" for c in wp.values()]
    differ = wp[ew["whole_process"]["heyoka_best"]]["periods"]["first_differences"]
    if differ:
        notes += [
            "",
            "Points where the periods differ (index, grazing, heyoka): " + ", ".join(map(str, differ)),
        ]
    return "\n".join(rows + notes)


def stored_markdown(name: str) -> Callable[[dict[str, Any]], str]:
    """The Markdown table the benchmark script wrote into its record, and the run it is from."""
    return lambda record: (
        part(record, name)["markdown"].strip()
        + (f"\n\nFrom the saved run of {record['date']} ([above](#the-saved-run)).")
        if name in record["parts"]
        else f"Not in the saved run of {record['date']} (`run_all.py --only` left it out)."
    )


BLOCKS: dict[Path, dict[str, Callable[[dict[str, Any]], str]]] = {
    README: {
        "simulate": readme_simulate,
        "sweep": readme_sweep,
        "equal-work": readme_equal_work,
        "grazing-curve": readme_curve,
        "first-run": readme_first_run,
    },
    BENCH_README: {
        "run": bench_run,
        "equal-work-full": bench_equal_work,
        "simulate-full": stored_markdown("simulate"),
        "sweep-full": stored_markdown("sweep"),
        "grazing-curve-full": stored_markdown("grazing-curve"),
        "curves-full": stored_markdown("curves"),
        "scaling-full": stored_markdown("scaling"),
    },
    INSTALLATION: {"first-run": readme_first_run},
}


# ----------------------------------------------------------------------------- the blocks


def load(path: Path = SAVED_RUN) -> dict[str, Any]:
    return json.loads(path.read_text())


def blocks(text: str) -> dict[str, str]:
    """The generated blocks of a document: name -> text between its markers."""
    return {m["name"]: m["body"] for m in MARKER.finditer(text)}


def rendered(record: dict[str, Any], path: Path) -> dict[str, str]:
    """What the blocks of ``path`` should hold for ``record`` (each ending in a newline)."""
    return {name: render(record).rstrip("\n") + "\n" for name, render in BLOCKS[path].items()}


def rewrite(text: str, new: dict[str, str]) -> str:
    """``text`` with every block of ``new`` replaced; a block without its markers is an error."""
    missing = sorted(set(new) - set(blocks(text)))
    if missing:
        raise ValueError(f"no markers for block(s) {', '.join(missing)}")
    return MARKER.sub(lambda m: m[1] + new.get(m["name"], m["body"]) + m[4], text)


def write(record: dict[str, Any]) -> list[Path]:
    """Rewrite the blocks of both READMEs from ``record``; the files changed."""
    changed = []
    for path in BLOCKS:
        text = path.read_text()
        new = rewrite(text, rendered(record, path))
        if new != text:
            path.write_text(new)
            changed.append(path)
    return changed


def stale(record: dict[str, Any], texts: dict[Path, str] | None = None) -> list[str]:
    """The blocks that do not hold what ``record`` gives (``file: block``).

    ``texts``: the documents' texts (default: read from disk).
    """
    out = []
    for path in BLOCKS:
        have = blocks(texts[path] if texts else path.read_text())
        for name, text in rendered(record, path).items():
            if have.get(name) != text:
                out.append(f"{path.relative_to(ROOT)}: {name}")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, default=SAVED_RUN, help="the saved run (default %(default)s)")
    ap.add_argument("--check", action="store_true", help="only check that the blocks agree with the run")
    args = ap.parse_args(argv)
    record = load(args.run)
    if args.check:
        bad = stale(record)
        for line in bad:
            print(f"stale: {line}", file=sys.stderr)
        return 1 if bad else 0
    for path in write(record):
        print(f"rewrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
