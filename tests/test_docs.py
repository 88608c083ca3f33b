"""Every Python example in the README and docs/ runs.

An example preceded by the line ``<!-- slow -->`` (it compiles kernels no other test needs)
runs in the slow suite (``make test-all``).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"(<!-- slow -->\n)?```python\n(.*?)```", re.S)


def _blocks():
    for path in DOCS:
        for i, (slow, code) in enumerate(BLOCK.findall(path.read_text())):
            marks = [pytest.mark.slow] if slow else []
            yield pytest.param(code, id=f"{path.name}-{i}", marks=marks)


@pytest.mark.parametrize("code", list(_blocks()))
def test_example_runs(code, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "<doc>", "exec"), {"__name__": "__doc_example__"})
