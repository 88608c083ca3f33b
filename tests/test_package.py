"""The facade ``grazing``: what ``dir(grazing)`` (and so tab completion) offers."""

from __future__ import annotations

import ast
import subprocess
import sys


def test_dir_lists_every_public_name_and_nothing_used_only_to_write_the_module() -> None:
    code = (
        "import grazing; before = dir(grazing); import grazing.orbits; "
        "print(sorted(before)); print('orbits' in dir(grazing)); print(sorted(grazing.__all__))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    before, orbits_after, public = out.splitlines()
    names = ast.literal_eval(before)
    assert set(ast.literal_eval(public)) <= set(names)
    assert "simulate" in names and "__version__" in names  # both loaded on first use
    assert not {"Any", "TYPE_CHECKING", "annotations", "ModuleType", "set_kernel_loader"} & set(names)
    assert "orbits" not in names and orbits_after == "True"  # a subpackage once imported
    import grazing

    for name in names:
        getattr(grazing, name)  # everything listed is there


def test_the_version_is_the_installed_packages_looked_up_once() -> None:
    from importlib.metadata import version

    import grazing

    assert grazing.__version__ == version("grazing")
    assert "__version__" in vars(grazing)  # (kept: not looked up again, 2 ms a time)


def test_the_citation_names_the_version_in_pyproject() -> None:
    """CITATION.cff (the docs' citation page, GitHub's "cite this repository") cites this version."""
    from importlib.metadata import version
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    project = version("grazing")  # (pyproject.toml's, as installed; tomllib needs Python 3.11)
    cited = [ln.split(":", 1)[1].strip() for ln in (root / "CITATION.cff").read_text().splitlines()
             if ln.startswith("version:")]  # fmt: skip
    assert cited == [project]
