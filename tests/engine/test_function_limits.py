"""No function of the engine longer than 150 lines or with more than 12 positional parameters (issue 29).

Counted on the source (``ast``): a function's lines from the first statement
after its docstring to its end, its positional parameters (``self`` included).
A function that has to break a limit for a while is listed in ``KNOWN`` with
its size: it may shrink, not grow, and leaves the list once it keeps the
limits (the test says so), so that the list only gets shorter.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ENGINE = Path(__file__).parents[2] / "src" / "grazing" / "engine"
MAX_LINES = 150
MAX_POSITIONAL = 12

KNOWN: dict[tuple[str, str], tuple[int, int]] = {
    # path, function -> (lines, positional parameters): a function over a limit today (none left).
}


def measure(node: ast.FunctionDef | ast.AsyncFunctionDef) -> tuple[int, int]:
    """``(lines, positional parameters)`` of a function, its docstring aside."""
    body = node.body
    first = body[0]
    start = first.lineno
    if (
        isinstance(first, ast.Expr)
        and isinstance(first.value, ast.Constant)
        and isinstance(first.value.value, str)
    ):
        start = body[1].lineno if len(body) > 1 else (first.end_lineno or first.lineno) + 1
    assert node.end_lineno is not None
    return node.end_lineno - start + 1, len(node.args.posonlyargs) + len(node.args.args)


def functions() -> dict[tuple[str, str], tuple[int, int]]:
    found = {}
    for path in sorted(ENGINE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                found[(path.relative_to(ENGINE).as_posix(), node.name)] = measure(node)
    return found


def test_measure_counts_lines_after_the_docstring_and_positional_parameters():
    text = 'def f(a, b, /, c, *d, e=1, **g):\n    """Doc.\n\n    More.\n    """\n    x = 1\n    return x\n'
    node = ast.parse(text).body[0]
    assert isinstance(node, ast.FunctionDef)
    assert measure(node) == (2, 3)


def test_engine_functions_keep_the_limits():
    found = functions()
    assert len(found) > 100  # (the engine's functions were found)
    over = {key: size for key, size in found.items() if size[0] > MAX_LINES or size[1] > MAX_POSITIONAL}
    new = sorted(set(over) - set(KNOWN))
    assert not new, f"functions over {MAX_LINES} lines or {MAX_POSITIONAL} positional parameters: {new}"
    grown = sorted(key for key in over if over[key][0] > KNOWN[key][0] or over[key][1] > KNOWN[key][1])
    assert not grown, f"functions that grew past their size in KNOWN: {grown}"
    fixed = sorted(set(KNOWN) - set(over))
    if fixed:
        pytest.fail(f"these now keep the limits: remove them from KNOWN: {fixed}")
