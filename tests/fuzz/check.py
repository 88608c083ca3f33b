"""Run one fuzz case in a fresh copy of the workspace and check every invariant."""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

from tests.fuzz.cases import Case
from tests.fuzz.invariants import file_violations, status_violations
from tests.fuzz.runner import Outcome, run_in_process, run_process
from tests.fuzz.workspace import Entry, build_template, fresh_copy, grazings, snapshot


@dataclass(frozen=True)
class Template:
    """The workspace template, its snapshot and the files of it that grazing wrote."""

    root: Path
    entries: dict[str, Entry]
    grazings: set[str]


def make_template(root: Path) -> Template:
    """Build the template in ``root`` (an empty folder) and take its snapshot."""
    build_template(root)
    entries = snapshot(root)
    return Template(root, entries, grazings(root, entries))


def describe(case: Case, outcome: Outcome, problems: list[str]) -> str:
    """The failure message of a case: what is wrong, the command line, and what it printed."""
    cmd = " ".join(repr(a) if not a or " " in a else a for a in case.argv)
    env = " ".join(f"{k}={v!r}" for k, v in case.env)
    where = f"process ({case.entry}), stdout {case.stdout}" if case.process else "in process"
    limit = f", files limited to {case.fsize} B" if case.fsize is not None else ""
    return (
        f"{case.id}: " + "; ".join(problems) + f"\n  command: {env} grazing {cmd}   [{where}{limit}]"
        f"\n  exit {outcome.returncode} after {outcome.seconds:.2f} s"
        f"\n  stderr: {outcome.stderr[-2000:]!r}\n  stdout: {outcome.stdout[:500]!r}"
    )


def check_case(case: Case, template: Template, tmp: Path) -> Outcome:
    """Run ``case`` in a copy of ``template`` under ``tmp``; assert every invariant."""
    work = fresh_copy(template.root, tmp / "w")
    scratch = tmp / "scratch"
    scratch.mkdir()
    try:
        outcome = run_process(case, work, scratch) if case.process else run_in_process(case, work)
        after = snapshot(work)
        problems = status_violations(case, outcome)
        problems += file_violations(
            case, outcome.returncode, work, template.entries, after, template.grazings
        )
        assert not problems, describe(case, outcome, problems)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return outcome
