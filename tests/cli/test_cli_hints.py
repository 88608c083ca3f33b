"""The library's messages name Python arguments; the command line says its options instead (cli.hints)."""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import click
import pytest

from grazing.cli import COMMANDS
from grazing.cli.hints import FLAGS, flag_hints

PACKAGE = Path(__file__).resolve().parents[2] / "src" / "grazing"

ARGUMENT = re.compile(r"(?<![\w.=\[])([a-z_][a-z0-9_]*=(?:True)?)(?=[\s),;:])")
"""An argument named in a message the way the library names one (``(x0=)``, ``switch=True``); not a piece
of an f-string before its value (``f"period={n}"``)."""

PYTHON_ONLY = {
    "stops=": "HybridModel's: a model file, Python on the command line too",
    "contact_direction=": "HybridModel's, as stops=",
    "vector_field=": "HybridModel's, as stops=",
    "sliding=True": "Surface's, as stops=",
    "transitions=": "HybridModel's (a model with modes), as stops=",
    "surfaces=": "HybridModel's (a model with modes), as stops=",
    "initial_mode=": "HybridModel's (a model with modes), as stops=",
    "cell=": "find_attractors' cell sizes (the command line's --cell is cell_fraction=)",
}
"""Arguments the library's messages ask for that have no option: where they are given."""


def _options() -> set[str]:
    found = set()
    for where in COMMANDS.values():
        module, name = where.split(":")
        command = getattr(importlib.import_module(f"grazing.cli.{module}"), name)
        for param in command.params:
            if isinstance(param, click.Option):
                found.update(o for o in [*param.opts, *param.secondary_opts] if o.startswith("--"))
    return found


def _library_messages() -> list[tuple[str, str]]:
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if "cli" in path.relative_to(PACKAGE).parts[:1]:
            continue
        tree = ast.parse(path.read_text())
        docstrings = {id(n.value) for n in ast.walk(tree) if isinstance(n, ast.Expr)}
        out += [
            (f"{path.relative_to(PACKAGE)}:{n.lineno}", n.value)
            for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docstrings
        ]
    return out


def test_every_hint_is_an_option_of_a_command():
    options = _options()
    assert "--initial" in options and "--out" in options  # (the options were found)
    assert not {flag for flag in FLAGS.values() if flag not in options}


def test_every_argument_a_library_message_asks_for_has_its_option():
    messages = _library_messages()
    asked = {arg: where for where, text in messages for arg in ARGUMENT.findall(text)}
    assert {"x0=", "period=", "store=", "switch=True"} <= set(asked)  # (the scan sees the messages)
    missing = {arg: where for arg, where in asked.items() if arg not in FLAGS and arg not in PYTHON_ONLY}
    assert not missing, missing


@pytest.mark.parametrize("argument", sorted(FLAGS))
def test_an_argument_becomes_its_option_wherever_it_stands(argument):
    flag = FLAGS[argument]
    assert flag_hints(f"give it ({argument})") == f"give it ({flag})"
    assert flag_hints(f"give {argument} or not") == f"give {flag} or not"
    assert flag_hints(f"end: {argument}") == f"end: {flag}"
    assert flag_hints(f"a value: {argument}0.5, xx{argument} ") == f"a value: {argument}0.5, xx{argument} "
