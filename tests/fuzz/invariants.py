"""What every run of ``grazing`` must satisfy, whatever it was given (issue 43).

- no traceback, no exception escaping the command line, no hang, no death by a signal;
- an exit status of its set: 0, 1, 2; 141 only for an output whose reader went away (and then nothing on
  stderr); 130 only after a Ctrl-C; 143 only after SIGTERM;
- a failure is one line (``grazing: error: ...``) and prints nothing on stdout; a success prints no error
  or warning; a certainly wrong input never succeeds;
- ``--json`` that succeeds prints one strict JSON object (no NaN, no Infinity), whole;
- an output a success names exists, whole (grazing's mark on it);
- no file it was not told to write is changed, made or removed; a file it was told to write that grazing
  did not write is replaced only with ``--overwrite``; a link stays a link; a folder is never replaced;
- nothing left behind: no hidden or temporary file of its own;
- a command whose last words could not be said (its standard output closed: 141; ``/dev/full``: one line,
  status 1) has finished its work: the outputs it wrote, whole, are its result and stay, as ``sweep
  --out``'s and ``map --out``'s do (they are written, atomically, before the summary that failed).
"""

from __future__ import annotations

import json
import os
import re
import signal
from pathlib import Path

from tests.fuzz.cases import Case
from tests.fuzz.runner import SERVING, Outcome
from tests.fuzz.workspace import PRINTED_BY_MODEL, Entry

GRAZINGS_FOLDERS = ("ours.zarr",)
"""Folders of the template that grazing wrote as a whole (a sweep store)."""

ERROR_WORDS = re.compile(r"error|warning|traceback|exception", re.IGNORECASE)


def strict_json(text: str) -> object:
    """``text`` parsed as JSON, refusing NaN and Infinity (Python's json module accepts them)."""

    def refuse(constant: str) -> None:
        raise ValueError(f"not strict JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def _stderr_lines(case: Case, text: str) -> list[str]:
    """stderr's lines, less what a model file printed as it loaded (its own text, passed on)."""
    return [line for line in text.splitlines() if line != PRINTED_BY_MODEL]


def allowed_codes(case: Case, sent: int | None = None) -> set[int]:
    """The exit statuses ``case`` may end with (``sent``: a signal the test sent it)."""
    codes = {0, 1, 2}
    if case.stdout in ("closed", "head"):
        codes.add(141)
    if sent == signal.SIGINT or "kbi.py:model" in case.argv:  # (a model file that raises KeyboardInterrupt)
        codes.add(130)
    if sent == signal.SIGTERM:
        codes.add(143)
    return codes


def status_violations(case: Case, outcome: Outcome, sent: int | None = None) -> list[str]:
    """What is wrong with the exit status, stderr and stdout of ``outcome`` (``sent``: a signal the test
    sent it, if not the case's own Ctrl-C)."""
    bad: list[str] = []
    sent = sent or outcome.sent
    err = outcome.stderr
    if outcome.hung:
        return [f"hung: still running after {case.timeout:g} s"]
    if outcome.escaped:
        return [f"an exception escaped main():\n{outcome.escaped}"]
    if "Traceback" in err:
        bad.append("a traceback on stderr")
    code = outcome.returncode
    if code < 0:
        if sent == signal.SIGKILL and code == -signal.SIGKILL:
            return bad
        return [*bad, f"killed by signal {-code} ({signal.Signals(-code).name})"]
    if code not in allowed_codes(case, sent):
        bad.append(f"exit status {code}")
    if case.invalid and case.command == "explore" and SERVING.decode() in outcome.stdout:
        bad.append("served its page for an input that is certainly wrong")  # (then Ctrl-C: runner.serves)
    lines = _stderr_lines(case, err)
    if case.command == "report":  # (it says on stderr what it builds: the error, if any, is the last line)
        if any(ERROR_WORDS.search(line) for line in lines[:-1]):
            bad.append("an error or warning among the report's progress lines")
        lines = lines[-1:]
    if case.family == "huge" and "out of memory" in err:
        bad.append("out of memory: the memory the size needs was not checked before the work")
    if code == 0:
        if case.invalid:
            bad.append("exit 0 for an input that is certainly wrong")
        if any(ERROR_WORDS.search(line) for line in lines):
            bad.append("exit 0 with an error or warning on stderr")
        bad += _json_violations(case, outcome)
    elif code == 141:
        if lines:
            bad.append("exit 141 (output closed) with text on stderr")
    else:
        prefix = "grazing: interrupted" if code == 130 else "grazing: " if code == 143 else "grazing: error: "
        if len(lines) != 1 or not lines[0].startswith(prefix) or not err.endswith("\n"):
            bad.append(f"stderr is not one line starting {prefix!r}")
        if outcome.stdout_read and outcome.stdout and not (code == 130 and case.command == "explore"):
            bad.append("a failure printed on stdout")  # (the explorer: its address, then Ctrl-C stopped it)
    return bad


def _json_violations(case: Case, outcome: Outcome) -> list[str]:
    if "--json" not in case.argv or not outcome.stdout_read or case.command == "explore":
        return []
    i = case.argv.index("--json")
    if i > 0 and case.argv[i - 1].startswith("--") and case.argv[i - 1] not in _flags(case):
        return []  # ("--alpha --json": the value of an option)
    try:
        obj = strict_json(outcome.stdout)
    except ValueError as exc:
        return [f"--json output is not one strict JSON object: {exc}"]
    return [] if isinstance(obj, dict) else ["--json output is not an object"]


def _flags(case: Case) -> set[str]:
    from tests.fuzz.cases import COMMANDS

    return {*COMMANDS[case.command].flags, "--json", "--overwrite"}


def _resolved(root: Path, name: str) -> str | None:
    """``name`` (an output path, maybe a link) as a path relative to ``root``, or None if outside it."""
    path = Path(os.path.realpath(root / name))
    try:
        return str(path.relative_to(os.path.realpath(root)))
    except ValueError:
        return None


def file_violations(
    case: Case,
    code: int,
    root: Path,
    before: dict[str, Entry],
    after: dict[str, Entry],
    grazings: set[str],
    interrupted: bool = False,
) -> list[str]:
    """What ``case``'s run changed in ``root`` that it must not have (``grazings``: the files of ``before``
    that grazing wrote; ``interrupted``: by a signal, which may leave its outputs unmade or part made, a
    store to resume)."""
    bad: list[str] = []
    outputs = {o for o in case.outputs() if o}
    if case.command == "synthesize":  # (a recording's sidecar: the same name, .json)
        outputs |= {str(Path(o).with_suffix(".json")) for o in outputs if o.endswith(".csv")}
    named = {r for o in outputs if (r := _resolved(root, o)) is not None and r != "."}

    def under_output(rel: str) -> bool:
        return any(rel == n or rel.startswith(n + os.sep) for n in named)

    if interrupted:
        code = 0
    kept = _summary_lost(case, code)
    if kept:  # (its outputs are a finished result: below, each one there must be whole; none may be missing)
        code = 0

    def may_change(rel: str) -> bool:
        if not under_output(rel) or code != 0:
            return False
        top = next(n for n in named if rel == n or rel.startswith(n + os.sep))
        was = before.get(top)
        if was is None:  # made by this run
            return True
        if (
            was.kind == "dir"
        ):  # a folder it writes into: a store of grazing's, a report's, a folder of recordings
            return top in GRAZINGS_FOLDERS or case.command in ("report", "synthesize")
        return rel in grazings or case.overwrite

    for rel, was in before.items():
        now = after.get(rel)
        if now == was:
            continue
        if was.kind == "link" or (now is not None and now.kind != was.kind and was.kind != "file"):
            bad.append(f"{rel}: a {was.kind} replaced by {now.kind if now else 'nothing'}")
        elif not may_change(rel):
            bad.append(f"{rel}: {'removed' if now is None else 'changed'} (not grazing's to change)")
    for rel in sorted(set(after) - set(before)):
        if under_output(rel) and code == 0:
            continue
        bad.append(f"{rel}: left behind" if code != 0 or _is_scratch(rel) else f"{rel}: made (not an output)")
    if code == 0 and not interrupted:
        bad += _outputs_whole(case, root, named if not kept else named & set(after), after)
    return bad


def _summary_lost(case: Case, code: int) -> bool:
    """Whether ``case`` failed only to print its summary: its standard output's reader went away (141) or
    the standard output is ``/dev/full`` (status 1).  Its work is done, and its outputs written whole may
    stay (or be missing: the first line printed, before the work, may have failed)."""
    return (case.stdout in ("closed", "head") and code == 141) or (case.stdout == "full" and code == 1)


def _is_scratch(rel: str) -> bool:
    name = Path(rel).name
    return name.startswith(".") or "partial" in name or name.endswith(".tmp")


def _outputs_whole(case: Case, root: Path, named: set[str], after: dict[str, Entry]) -> list[str]:
    from grazing.outputs import written_by_grazing

    bad = []
    for rel in named:
        entry = after.get(rel)
        if entry is None:
            bad.append(f"{rel}: the output of a success is missing")
        elif (
            entry.kind == "file"
            and rel.endswith((".csv", ".nc", ".png"))
            and not written_by_grazing(root / rel)
        ):
            bad.append(f"{rel}: the output of a success is not whole (no valid mark of grazing's)")
    return bad
