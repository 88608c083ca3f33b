"""A random sample of mutants of the structure code, run against the default test suite (cosmic-ray).

``make mutation`` (or ``python mutation/run.py``) draws ``--count`` mutants (default 150, seed
``--seed``) uniformly from every mutant cosmic-ray makes of ``src/grazing/orbits/``,
``src/grazing/attractors/`` and ``src/grazing/core/period.py``, runs each against the tests of its
group (a part of the default suite, ``-m "not slow"``, stopping at the first failure: a mutant killed
there is killed by the whole suite), and writes ``mutation/report.md`` (the score and every surviving
mutant, with its diff) and ``mutation/report.json``.  It mutates the files of the tree it runs in: run
it in a clean checkout (``git worktree add``), not in one you are editing.  Needs the ``mutation``
extra (``pip install -e ".[test,mutation]"``).  30 to 60 s a mutant on two cores.
"""

from __future__ import annotations

import argparse
import ast
import functools
import json
import random
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COSMIC_RAY = str(Path(sys.executable).with_name("cosmic-ray"))
PYTEST = f"{sys.executable} -m pytest -q -x -p no:cacheprovider -m 'not slow' -n 2 --dist loadfile"

GROUPS = {
    "orbits": (
        sorted(str(p.relative_to(ROOT)) for p in (ROOT / "src/grazing/orbits").glob("*.py")),
        "tests/orbits tests/cli/test_cli_orbits.py tests/cli/test_cli_curves.py tests/normalform",
    ),
    "attractors": (
        sorted(str(p.relative_to(ROOT)) for p in (ROOT / "src/grazing/attractors").glob("*.py")),
        "tests/attractors tests/cli/test_cli_attractors.py",
    ),
    "period": (["src/grazing/core/period.py"], "tests/core tests/sweeps tests/attractors tests/test_maps.py"),
}
"""Each group: the files mutated and the tests run against them."""

TIMEOUT = 600.0
"""A mutant whose tests run longer than this (seconds) is counted as killed by timeout (cosmic-ray's rule)."""


def _config(group: str, folder: Path) -> Path:
    files, tests = GROUPS[group]
    cfg = folder / f"{group}.toml"
    modules = ", ".join(json.dumps(f) for f in files)
    cfg.write_text(
        "[cosmic-ray]\n"
        f"module-path = [{modules}]\n"
        f"timeout = {TIMEOUT}\n"
        "excluded-modules = []\n"
        f'test-command = "{PYTEST} {tests}"\n'
        "[cosmic-ray.distributor]\n"
        'name = "local"\n'
    )
    return cfg


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=150)
    parser.add_argument("--seed", type=int, default=42)
    parser.add_argument("--groups", default=",".join(GROUPS))
    parser.add_argument("--out", default=str(ROOT / "mutation"))
    parser.add_argument(
        "--report-only", action="store_true", help="summarise the sessions already in --out (run or not)"
    )
    args = parser.parse_args(argv)
    if args.report_only:
        found = {g: (None, Path(args.out) / f"{g}.sqlite") for g in args.groups.split(",")}
        return _report({g: v for g, v in found.items() if v[1].exists()}, Path(args.out))
    from cosmic_ray.work_db import WorkDB, use_db
    from cosmic_ray.work_item import WorkerOutcome, WorkResult

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    groups = [g for g in args.groups.split(",") if g]
    sessions = {}
    population = []
    for g in groups:
        cfg = _config(g, out)
        session = out / f"{g}.sqlite"
        session.unlink(missing_ok=True)
        subprocess.run([COSMIC_RAY, "init", str(cfg), str(session)], check=True, cwd=ROOT)
        sessions[g] = (cfg, session)
        with use_db(str(session), WorkDB.Mode.open) as db:
            population += [(g, item.job_id) for item in db.work_items]
    rng = random.Random(args.seed)
    chosen = set(rng.sample(population, min(args.count, len(population))))
    print(f"{len(population)} mutants in {', '.join(groups)}; running {len(chosen)} of them")
    for g, (cfg, session) in sessions.items():
        with use_db(str(session), WorkDB.Mode.open) as db:
            skip = [job for (gg, job) in population if gg == g and (gg, job) not in chosen]
            db.set_multiple_results(skip, WorkResult(worker_outcome=WorkerOutcome.SKIPPED))
        start = time.time()
        subprocess.run([COSMIC_RAY, "exec", str(cfg), str(session)], check=True, cwd=ROOT)
        print(f"{g}: {time.time() - start:.0f} s")
    return _report(sessions, out)


@functools.cache
def _annotation_spans(path: str) -> tuple[tuple[int, int, int, int], ...]:
    """The source spans of every annotation in a module (under ``from __future__ import annotations``,
    as every module of grazing's, they are never evaluated)."""
    tree = ast.parse((ROOT / path).read_text())
    spans = []
    for node in ast.walk(tree):
        notes = []
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            notes.append(node.returns)
            a = node.args
            notes += [x.annotation for x in (*a.posonlyargs, *a.args, *a.kwonlyargs, a.vararg, a.kwarg) if x]
        elif isinstance(node, ast.AnnAssign):
            notes.append(node.annotation)
        for n in notes:
            if n is not None:
                spans.append((n.lineno, n.col_offset, n.end_lineno or n.lineno, n.end_col_offset or 0))
    return tuple(spans)


def in_annotation(path: str, line: int, col: int) -> bool:
    """Is position ``(line, col)`` of module ``path`` inside an annotation (an equivalent mutant there)?"""
    return any((l0, c0) <= (line, col) < (l1, c1) for l0, c0, l1, c1 in _annotation_spans(path))


def _report(sessions: dict, out: Path) -> int:
    from cosmic_ray.work_db import WorkDB, use_db
    from cosmic_ray.work_item import TestOutcome, WorkerOutcome

    rows = []
    for g, (_, session) in sessions.items():
        with use_db(str(session), WorkDB.Mode.open) as db:
            for item, result in db.completed_work_items:
                if result.worker_outcome == WorkerOutcome.SKIPPED:
                    continue
                spec = item.mutations[0]
                rows.append(
                    {
                        "group": g,
                        "file": str(spec.module_path),
                        "line": spec.start_pos[0],
                        "operator": spec.operator_name,
                        "occurrence": spec.occurrence,
                        "annotation": in_annotation(str(spec.module_path), *spec.start_pos),
                        "outcome": str(result.test_outcome),
                        "worker": str(result.worker_outcome),
                        "diff": result.diff,
                    }
                )
    killed = [r for r in rows if r["outcome"] == str(TestOutcome.KILLED)]
    survived = [r for r in rows if r["outcome"] == str(TestOutcome.SURVIVED)]
    equivalent = [r for r in survived if r["annotation"]]
    score = len(killed) / len(rows) if rows else float("nan")
    effective = len(killed) / max(1, len(rows) - len(equivalent))
    stamp = time.strftime("%Y-%m-%d")
    summary = {"date": stamp, "score": score, "score_not_equivalent": effective, "mutants": rows}
    (out / "report.json").write_text(json.dumps(summary, indent=1))
    lines = [
        f"# Mutation sample, {stamp}",
        "",
        f"{len(rows)} mutants run, {len(killed)} killed, {len(survived)} survived, {len(equivalent)} of them "
        f"in annotations (never evaluated: equivalent): score {100 * score:.1f} %, "
        f"{100 * effective:.1f} % of the mutants that are not equivalent",
        "",
    ]
    for r in [r for r in survived if not r["annotation"]]:
        head = f"## {r['file']}:{r['line']} ({r['operator']})"
        lines += [head, "", "```diff", r["diff"].strip(), "```", ""]
    (out / "report.md").write_text("\n".join(lines))
    print(lines[2])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
