"""The types of the API reference's parameters, from the annotations (a Sphinx extension).

numpydoc renders a ``Parameters`` entry ``name : type``; the docstrings of grazing name their
parameters and leave the type to the annotation (one place for it).  Before numpydoc reads a
docstring, :func:`add_types` writes each annotation after its parameter's name, in the
``Parameters`` section and, for a class, in ``Attributes`` (a dataclass's fields), where the
docstring gives no type of its own.  (autodoc's ``autodoc_typehints = "description"`` merges
types into ``:param:`` fields, which numpydoc does not write: it would add nothing.)

>>> def f(x: float, ys: list[int] | None = None) -> None:
...     '''F.
...
...     Parameters
...     ----------
...     x
...         A number.
...     ys : list of int, optional
...         Kept as written.
...     '''
>>> lines = inspect.getdoc(f).splitlines()
>>> add_types(None, "function", "f", f, None, lines)
>>> lines[4:7]
['x : float', '    A number.', 'ys : list of int, optional']
"""

from __future__ import annotations

import dataclasses
import inspect
import re
from typing import Any

SECTIONS = {"Parameters", "Other Parameters", "Attributes"}
ENTRY = re.compile(r"^(\*{0,2}[A-Za-z_][\w]*(?:\s*,\s*\*{0,2}[A-Za-z_][\w]*)*)\s*$")


def _text(annotation: Any) -> str | None:
    if annotation is inspect.Parameter.empty or annotation is None:
        return None
    if isinstance(annotation, str):
        return annotation
    from sphinx.util.typing import stringify_annotation

    return stringify_annotation(annotation, "smart").replace("~", "")


def annotations_of(obj: Any) -> dict[str, str]:
    """name -> annotation text of what a caller passes (a class: its constructor, its fields)."""
    out: dict[str, str] = {}
    if inspect.isclass(obj):
        if dataclasses.is_dataclass(obj):
            for f in dataclasses.fields(obj):
                text = _text(f.type)
                if text:
                    out[f.name] = text
        for name, ann in vars(obj).get("__annotations__", {}).items():
            text = _text(ann)
            if text and not name.startswith("_"):
                out.setdefault(name, text)
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return out
    for p in sig.parameters.values():
        text = _text(p.annotation)
        if text:
            out[p.name] = text
    return out


def add_types(app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]) -> None:
    """Write each parameter's annotation after its name where the docstring gives none (in place)."""
    if what not in ("function", "class", "method"):
        return
    types = annotations_of(obj)
    if not types:
        return
    section = None
    for i, line in enumerate(lines):
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        if line.strip() and set(nxt.strip()) == {"-"} and len(nxt.strip()) >= len(line.strip()):
            section = line.strip()
            continue
        if section not in SECTIONS or line.startswith((" ", "\t")) or set(line.strip()) == {"-"}:
            continue
        m = ENTRY.match(line)
        if not m:
            continue
        names = [n.strip().lstrip("*") for n in m.group(1).split(",")]
        found = {types.get(n) for n in names}
        if len(found) == 1 and None not in found:
            lines[i] = f"{line.rstrip()} : {found.pop()}"


def setup(app: Any) -> dict[str, Any]:
    app.connect("autodoc-process-docstring", add_types, priority=100)  # before numpydoc (500)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
