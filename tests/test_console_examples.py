"""Every console example in the README and docs/ prints what the page shows.

A ``console`` block is a list of ``$ grazing ...`` commands, each followed by the output shown
for it.  Each command is run (in-process, in a temporary folder; a model file named relative to the
repository's root is given by its absolute path) and its output compared line by line:

- timings are not compared (``3.3 s``, ``(301 points/s)``, ``in 1.0 s``), nor the number of
  points of a continuation (its steps depend on the processor's linear algebra; the special
  points it locates do not);
- a line ``...`` stands for any number of lines (the page shows a part of the output);
- a line ``{... "key": value, ...}`` shows part of a ``--json`` output: each key shown must be
  there with the value shown (a list ending in ``...`` is a prefix of the output's list);
- a command shown without output only has to succeed (it writes a file, or the page shows the
  command alone);
- an output that starts with ``grazing: error:`` must come with a non-zero exit status, any other
  with status 0.

A block preceded by the line ``<!-- slow -->`` runs in the slow suite (``make test-all``).
"""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pytest

from grazing.cli import main

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"(<!-- slow -->\n)?```console\n(.*?)```", re.S)
TIMING = [
    (re.compile(r"\(\d+(\.\d+)? points/s\)"), "(… points/s)"),
    (re.compile(r"\b\d+(\.\d+)? s\b"), "… s"),
    # a continuation's number of steps follows its step-size control, which follows how fast Newton's
    # method converges: the last bits of the linear algebra (the BLAS kernel) change it (43 or 40)
    (re.compile(r"^\d+ points of the "), "… points of the "),
]
JSON_KEY = re.compile(r'"([A-Za-z_][A-Za-z_0-9]*)": ')


def _examples():
    for page in PAGES:
        for i, (slow, block) in enumerate(BLOCK.findall(page.read_text())):
            command, shown = None, []
            for line in block.replace("\\\n", " ").splitlines():
                if line.startswith("$ "):
                    if command is not None:
                        yield page, i, command, shown, bool(slow)
                    command, shown = line[2:], []
                elif command is not None:
                    shown.append(line)
            if command is not None:
                yield page, i, command, shown, bool(slow)


def _params():
    seen: dict[str, int] = {}
    for page, i, command, shown, slow in _examples():
        base = f"{page.name}-{i}-{shlex.split(command)[1] if len(shlex.split(command)) > 1 else 'help'}"
        seen[base] = seen.get(base, 0) + 1
        marks = [pytest.mark.slow] if slow else []
        yield pytest.param(command, shown, id=f"{base}-{seen[base]}", marks=marks)


def _untimed(line: str) -> str:
    for pattern, replacement in TIMING:
        line = pattern.sub(replacement, line)
    return line.rstrip()


def _json_fragment_holds(shown: str, output: str) -> None:
    """Each ``"key": value`` of a ``{... ...}`` line is in the JSON output with that value."""
    data = json.loads(output)
    decoder = json.JSONDecoder()
    pos = 0
    while (match := JSON_KEY.search(shown, pos)) is not None:
        key, rest = match.group(1), shown[match.end() :]
        assert key in data, f"key {key!r} shown but not in the output"
        try:
            value, used = decoder.raw_decode(rest)
        except json.JSONDecodeError:
            # a list shown with its first items, then "...": a prefix of the output's list
            cut = rest.index("...")
            value = json.loads(rest[:cut].rstrip().rstrip(",") + "]")
            assert data[key][: len(value)] == value, (key, data[key], value)
            pos = match.end() + rest.index("]", cut) + 1
            continue
        assert data[key] == value, (key, data[key], value)
        pos = match.end() + used


def _output_matches(shown: list[str], printed: list[str]) -> None:
    i = 0  # the next printed line
    for k, expect in enumerate(shown):
        if expect.strip() == "...":
            following = shown[k + 1] if k + 1 < len(shown) else None
            if following is None:
                return
            while i < len(printed) and _untimed(printed[i]) != _untimed(following):
                i += 1
            continue
        assert i < len(printed), f"the page shows more than was printed: {expect!r}"
        if expect.startswith("{..."):
            _json_fragment_holds(expect, printed[i])
        else:
            assert _untimed(printed[i]) == _untimed(expect), f"\nprinted: {printed[i]}\nshown:   {expect}"
        i += 1
    assert i == len(printed), f"printed more than the page shows: {printed[i:]}"


def _absolute(arg: str) -> str:
    """``tests/orbits/m.py:obj`` -> its absolute path, when the file is in the repository."""
    path, sep, obj = arg.partition(":")
    return f"{ROOT / path}{sep}{obj}" if path.endswith(".py") and (ROOT / path).is_file() else arg


@pytest.mark.parametrize(("command", "shown"), list(_params()))
def test_console_example_prints_what_the_page_shows(command, shown, capsys, monkeypatch, tmp_path):
    argv = shlex.split(command)
    assert argv[0] == "grazing", command
    argv = [_absolute(arg) for arg in argv]
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("COLUMNS", "2000")  # the page shows whole lines
    code = main(argv[1:])
    out, err = capsys.readouterr()
    printed = (out + err).splitlines()
    if shown and shown[0].startswith("grazing: error:"):
        assert code != 0, printed
    else:
        assert code == 0, printed
    if shown:
        _output_matches(shown, printed)
