"""The package's structure: one-way layers, no cycles, no pendulum in generic code, modules import alone.

The layers, bottom to top (docs/architecture.md): a module may import its own
layer and the layers below it, never one above.  Imports inside functions
count too.  The one exception is reading the package version
(``grazing.__version__``).
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = SRC / "grazing"

LAYERS = {
    "grazing.errors": 0,
    "grazing.atomic": 0,
    "grazing.outputs": 0,
    "grazing.plot_areas": 0,
    "grazing.parallel": 0,
    "grazing.clib": 0,
    "grazing.core": 1,
    "grazing.models": 2,
    "grazing.engine": 3,
    "grazing.maps": 4,
    "grazing.orbits": 5,
    "grazing.normalform": 6,
    "grazing.sweeps": 6,
    "grazing.gpu": 6,
    "grazing.experiment": 7,
    "grazing.attractors": 7,
    "grazing.plotting": 8,
    "grazing.report": 9,
    "grazing.cli": 10,
    "grazing.explore": 10,
}
"""The layer of every part of the package (the facade ``grazing/__init__`` is above them all)."""

GENERIC = ("grazing.core", "grazing.engine", "grazing.maps", "grazing.orbits", "grazing.sweeps",
           "grazing.normalform", "grazing.plotting", "grazing.parallel", "grazing.attractors",
           "grazing.gpu")  # fmt: skip
"""The layers that know no particular model."""

PENDULUM_NAMES = {"eta", "theta_hat", "theta", "dtheta", "tau", "alpha", "beta"}
"""Names of the pendulum's parameters, states and time."""


def modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def part(module: str) -> str | None:
    """The part of the package (a key of :data:`LAYERS`) a module belongs to."""
    for name in sorted(LAYERS, key=len, reverse=True):
        if module == name or module.startswith(name + "."):
            return name
    return None


def imports(path: Path, module: str) -> list[tuple[str, int]]:
    """The grazing modules a file imports (anywhere in it), with line numbers."""
    tree = ast.parse(path.read_text())
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, node.lineno) for a in node.names if a.name.split(".")[0] == "grazing"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative import
                base = module.split(".")[: -node.level or None]
                target = ".".join([*base, node.module] if node.module else base)
            else:
                target = node.module or ""
            if target.split(".")[0] != "grazing":
                continue
            for a in node.names:  # "from grazing.x import y" may import the module grazing.x.y
                sub = f"{target}.{a.name}"
                out.append((sub if sub in modules() else target, node.lineno))
    return out


def uses_only_the_version(path: Path) -> bool:
    """Does the file use the facade ``grazing`` only as ``grazing.__version__``?"""
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name)
            and node.value.id == "grazing"
        ):
            if node.attr != "__version__":
                return False
    return True


def test_every_part_of_the_package_has_a_layer():
    unplaced = [m for m in modules() if m not in ("grazing", "grazing.__main__") and part(m) is None]
    assert not unplaced


def test_no_import_runs_up_the_layers():
    problems = []
    for module, path in modules().items():
        here = part(module)
        if here is None:
            continue
        for target, line in imports(path, module):
            if target == "grazing":
                if LAYERS[here] < LAYERS["grazing.report"] and not uses_only_the_version(path):
                    problems.append(f"{path.relative_to(SRC)}:{line} uses the facade grazing")
                continue
            there = part(target)
            if there is not None and LAYERS[there] > LAYERS[here]:
                problems.append(
                    f"{path.relative_to(SRC)}:{line} imports {target} (layer {there} above {here})"
                )
    assert not problems, "\n".join(problems)


def test_no_import_cycles_between_files():
    mods = modules()
    graph = {m: {t for t, _ in imports(p, m) if t in mods and t != m} for m, p in mods.items()}
    # A package's __init__ re-exporting its modules is not a cycle with them: drop the edges
    # from a module to its own package (they only re-export).
    for m in graph:
        graph[m] = {t for t in graph[m] if not m.startswith(t + ".")}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    cycles: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:  # Tarjan's strongly connected components
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    assert not cycles, cycles


def _names_in_code(path: Path) -> set[str]:
    """Identifiers and string constants of a file, docstrings left out."""
    tree = ast.parse(path.read_text())
    docstrings = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                docstrings.add(id(body[0].value))
        elif isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
            docstrings.add(id(node.value))  # attribute docstrings
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name):
            found.add(node.id)
        elif isinstance(node, ast.Attribute):
            found.add(node.attr)
        elif isinstance(node, ast.arg):
            found.add(node.arg)
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
            found.add(node.value)
    return found


def test_no_generic_layer_names_a_pendulum_parameter():
    problems = []
    for module, path in modules().items():
        if part(module) in GENERIC and "driver" not in module:
            hits = _names_in_code(path) & PENDULUM_NAMES
            if module.startswith("grazing.plotting"):
                hits -= {"alpha"}  # matplotlib's transparency
            if hits:
                problems.append(f"{path.relative_to(SRC)}: {sorted(hits)}")
    assert not problems, "\n".join(problems)


def test_the_model_layer_imports_no_engine_orbit_sweep_report_or_cli():
    for module, path in modules().items():
        if part(module) == "grazing.core":
            for target, line in imports(path, module):
                assert part(target) in (None, "grazing.core", "grazing.errors"), (module, target, line)


def _import_alone(module: str) -> tuple[str, int, str]:
    proc = subprocess.run(
        [sys.executable, "-c", f"import {module}"], capture_output=True, text=True, timeout=300
    )
    return (
        module,
        proc.returncode,
        proc.stderr.strip().splitlines()[-1:] and proc.stderr.strip().splitlines()[-1],
    )


HEAVY = ("numba", "llvmlite", "xarray", "zarr", "dask", "matplotlib", "sympy", "scipy", "h5netcdf", "click")


def test_import_grazing_loads_no_heavy_dependency():
    """``import grazing`` is numpy and the package only; a run loads the engine's machine code, not numba."""
    code = (
        "import sys, math, grazing\n"
        f"print(','.join(m for m in {HEAVY!r} if m in sys.modules))\n"
        "m = grazing.models.pendulum('B', eta=0.446, theta_hat=math.radians(40))\n"
        "print(grazing.simulate(m, [0.0, 0.0], transient=1, periods=1).samples.shape)\n"
        "print('numba' in sys.modules)\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines() == ["", "(1, 2)", "False"]


@pytest.mark.parametrize("batch", [0, 1])
def test_every_module_imports_on_its_own_in_a_fresh_interpreter(batch):
    """Half of the modules per test (the two halves run as two tests), two interpreters at a time."""
    mods = [m for m in modules() if m != "grazing.__main__" and not m.endswith(".__main__")][batch::2]
    with ThreadPoolExecutor(2) as pool:
        failures = [r for r in pool.map(_import_alone, mods) if r[1] != 0]
    assert not failures, failures


def test_architecture_doc_lists_the_same_layers() -> None:
    """docs/architecture.md's table and :data:`LAYERS` say the same thing."""
    import re

    doc = (SRC.parent / "docs" / "architecture.md").read_text()
    documented = {}
    for layer, packages in re.findall(r"^\|\s*(\d+)\s*\|([^|]+)\|", doc, re.M):
        for name in re.findall(r"`([a-z_]+)(?:/|\.py)`", packages):
            documented[f"grazing.{name}"] = int(layer)
    assert documented == LAYERS


LIBRARY = [name for name in LAYERS if name != "grazing.cli"]
"""The parts of the package a Python user calls: all but the command line (the explorer too, which a
notebook shows)."""

PRINTS_COMMAND_LINES = {
    "grazing.explore.code": "copy as code: the command lines that reproduce the view",
    "grazing.explore.source": "the --model/--set options of those command lines",
    "grazing.report.html": "the page's reproduction commands",
    "grazing.report.browser": "its own command line, and Chromium's",
    "grazing.report.provenance": "the git command it runs",
}
"""The modules that print command lines by design, and what they print."""

FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")
"""A command-line option (``--initial``)."""


def _strings_in_code(path: Path) -> list[tuple[int, str]]:
    """String constants of a file with their lines, docstrings left out (f-strings' pieces included)."""
    tree = ast.parse(path.read_text())
    docstrings = {id(n.value) for n in ast.walk(tree) if isinstance(n, ast.Expr)}
    return [
        (node.lineno, node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings
    ]


def test_no_library_message_names_a_command_line_option():
    """A Python user reads about arguments (``x0=``), never about options they do not have (``--initial``):
    the command line turns the one into the other (``grazing.cli.hints``)."""
    problems = []
    for module, path in modules().items():
        if part(module) in LIBRARY and module not in PRINTS_COMMAND_LINES:
            for line, text in _strings_in_code(path):
                if FLAG.search(text):
                    problems.append(f"{path.relative_to(SRC)}:{line}: {FLAG.findall(text)} in {text!r}")
    assert not problems, "\n".join(problems)


def test_no_library_module_imports_the_command_line():
    """The explorer included: it is a library beside the command line, not a part of it."""
    problems = [
        f"{path.relative_to(SRC)}:{line} imports {target}"
        for module, path in modules().items()
        if part(module) in LIBRARY
        for target, line in imports(path, module)
        if part(target) == "grazing.cli"
    ]
    assert not problems, "\n".join(problems)
