"""Every public function and class of the API reference documents its arguments and shows an example.

Run by ``make docs`` before Sphinx (and by ``tests/test_docs_site.py`` on the package):

    python docs/check_reference.py

prints one line per missing section and exits 1 if anything is missing, 0 otherwise.  The public
names are those of the reference (``docs/_ext/api_pages.py``: each module's ``__all__``, each
object once).  A function needs a ``Parameters`` section naming each of its parameters (when it
has any), a ``Returns`` or ``Yields`` section (unless it returns ``None``) and an ``Examples``
section with at least one ``>>>`` line; a class needs its constructor's parameters named under
``Parameters`` or ``Attributes`` and an ``Examples`` section.  The examples themselves are run by
the doctests (``pytest`` collects ``--doctest-modules`` over ``src/grazing``).
"""

from __future__ import annotations

import dataclasses
import enum
import importlib
import inspect
import sys
from collections.abc import Iterator
from pathlib import Path

from numpydoc.docscrape import ClassDoc, FunctionDoc

DOCS = Path(__file__).resolve().parent


def _public_objects() -> Iterator[tuple[str, object]]:
    """(qualified name, object) of every class and function the reference documents."""
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        import api_pages
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    for mod, _title, own, _again in api_pages.api_entries():
        module = importlib.import_module(mod)
        for name in own:
            obj = getattr(module, name)
            if inspect.isclass(obj) or inspect.isfunction(obj):
                yield f"{mod}.{name}", obj


def _parameters(obj: object) -> list[str]:
    """The names a caller passes: a function's parameters, a class's constructor's (not self)."""
    if inspect.isclass(obj):
        if issubclass(obj, enum.Enum) or issubclass(obj, BaseException):
            return []  # an enum's members and an error's message are not documented as parameters
        if not dataclasses.is_dataclass(obj) and obj.__init__ is object.__init__:
            return []
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [
        p.name
        for p in sig.parameters.values()
        if p.name not in ("self", "cls") and not p.name.startswith("_")
    ]


def _documented(section: list) -> set[str]:
    """The names of a numpydoc section's entries (``x, y : float`` names two; ``*args`` is args)."""
    names = set()
    for entry in section:
        for name in entry.name.split(","):
            names.add(name.strip().lstrip("*"))
    return names


def _returns_nothing(obj: object) -> bool:
    try:
        ann = inspect.signature(obj).return_annotation
    except (TypeError, ValueError):
        return False
    return ann is None or ann == "None"


def problems(name: str, obj: object) -> list[str]:
    """What the docstring of ``obj`` (published as ``name``) lacks, one line each; [] if nothing."""
    out = []
    if not inspect.getdoc(obj):
        return [f"{name}: no docstring"]
    is_class = inspect.isclass(obj)
    doc = ClassDoc(obj, config={"show_class_members": False}) if is_class else FunctionDoc(obj)
    params = _parameters(obj)
    if params:
        have = _documented(doc["Parameters"]) | (_documented(doc["Attributes"]) if is_class else set())
        missing = [p for p in params if p not in have]
        if not doc["Parameters"] and not (is_class and doc["Attributes"]):
            out.append(f"{name}: no Parameters section ({', '.join(params)})")
        elif missing:
            out.append(f"{name}: parameters not documented: {', '.join(missing)}")
    if not is_class and not _returns_nothing(obj) and not (doc["Returns"] or doc["Yields"]):
        out.append(f"{name}: no Returns section")
    if not any(line.lstrip().startswith(">>>") for line in doc["Examples"]):
        out.append(f"{name}: no Examples section (with a >>> example)")
    return out


def check() -> list[str]:
    """Every problem of every public name of the reference, one line each."""
    return [line for name, obj in _public_objects() for line in problems(name, obj)]


def main() -> int:
    found = check()
    for line in found:
        print(line, file=sys.stderr)
    if found:
        print(f"check_reference: {len(found)} missing docstring section(s)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
