"""The run's state outlives its records (issue 29).

numba compiles a record of a structured array as a pointer into the array
and frees the array after the last use of its name, whatever records of it
are still used: ``r = new_state(1)[0]`` in ``loop.integrate`` left ``r``
pointing into freed memory, which the growing tables reused (a dense
trajectory of 14815 rows came back with 18424, thousands never written).
The engine's numba functions that make a state array therefore keep its
name and read it again in their return statement, after every allocation.
"""

from __future__ import annotations

import ast
from pathlib import Path

ENGINE = Path(__file__).parents[2] / "src" / "grazing" / "engine"
MAKERS = {"new_state"}  # functions returning a structured array whose records are used as state


def is_maker(node: ast.AST) -> bool:
    return isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in MAKERS


def problems(source: str) -> list[str]:
    """Where a state array may be freed while its records are in use (empty: none)."""
    found = []
    for fn in ast.walk(ast.parse(source)):
        if not isinstance(fn, ast.FunctionDef):
            continue
        for node in ast.walk(fn):
            if isinstance(node, ast.Subscript) and is_maker(node.value):
                found.append(f"{fn.name}: a record of a temporary array (line {node.lineno})")
        names = {
            target.id
            for node in ast.walk(fn)
            if isinstance(node, ast.Assign) and is_maker(node.value)
            for target in node.targets
            if isinstance(target, ast.Name)
        }
        last = fn.body[-1]
        if names and isinstance(last, ast.Return) and last.value is not None:
            read = {node.id for node in ast.walk(last.value) if isinstance(node, ast.Name)}
            unread = sorted(names - read)
            found += [f"{fn.name}: {name} is not read in the return statement" for name in unread]
    return found


def test_the_check_finds_a_record_of_a_temporary_array_and_an_array_freed_before_the_return():
    assert problems("def f():\n    r = new_state(1)[0]\n    return r.k\n") == [
        "f: a record of a temporary array (line 2)"
    ]
    freed = "def f():\n    runs = new_state(1)\n    r = runs[0]\n    y = g()\n    return r.k, y\n"
    assert problems(freed) == ["f: runs is not read in the return statement"]
    assert problems("def f():\n    runs = new_state(1)\n    r = runs[0]\n    return g(r), runs[0].k\n") == []


def test_engine_state_arrays_outlive_their_records():
    sources = sorted(ENGINE.rglob("*.py"))
    assert any("new_state(" in path.read_text() for path in sources)  # (the check has something to check)
    found = [f"{path.name}: {p}" for path in sources for p in problems(path.read_text())]
    assert not found, found
