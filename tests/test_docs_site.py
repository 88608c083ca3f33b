"""The documentation site (``make docs``): its API reference leaves nothing public out, its
checker finds what a reader would see broken, and (slow) the whole site builds with warnings as
errors.

The site's pages are Markdown run by ``tests/test_docs.py``; its tutorials are notebooks
executed by the build itself (``make docs``, which CI runs, or the slow test below).
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import inspect
import pkgutil
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import grazing
from grazing.report.browser import check_site, find_chromium, is_blank, main

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "_ext"))
import annotated_types  # noqa: E402
import api_pages  # noqa: E402

sys.path.remove(str(DOCS / "_ext"))
sys.path.insert(0, str(DOCS))
import check_reference  # noqa: E402

sys.path.remove(str(DOCS))

chromium = pytest.mark.skipif(find_chromium() is None, reason="no Chromium installed")


def _documented() -> dict[int, str]:
    """id of every class and function of the reference -> where it is documented."""
    out = {}
    for mod, _title, own, _again in api_pages.api_entries():
        module = importlib.import_module(mod)
        for name in own:
            out[id(getattr(module, name))] = f"{mod}.{name}"
    return out


def test_every_module_of_grazing_is_in_the_reference_or_said_to_be_internal() -> None:
    listed = {m for m, _ in api_pages.API_MODULES} | set(api_pages.INTERNAL)
    found = {f"grazing.{m.name}" for m in pkgutil.iter_modules(grazing.__path__) if m.name != "__main__"}
    assert found - listed == set(), "add these to API_MODULES or INTERNAL in docs/_ext/api_pages.py"
    assert listed - {"grazing"} <= found


def test_every_public_name_is_documented_once() -> None:
    documented = _documented()
    for mod, _title, own, again in api_pages.api_entries():
        module = importlib.import_module(mod)
        names = getattr(module, "__all__", None) or api_pages.public_names(mod)
        names = [n for n in names if n != "__version__" and not inspect.ismodule(getattr(module, n))]
        assert sorted(own + [n for n, _ in again]) == sorted(names), mod
        for name, target in again:  # a re-export links to the one page of that object
            assert documented[id(getattr(module, name))] == target
    # the internal packages' public names are documented where users import them from
    core = importlib.import_module("grazing.core")
    for name in core.__all__:
        assert id(getattr(core, name)) in documented, f"grazing.core.{name}"
    assert "grazing.simulate" in documented.values()  # lazily loaded, documented all the same


def test_the_pages_are_written_from_all(tmp_path: Path) -> None:
    api_pages.write_api_pages(tmp_path)
    orbits = (tmp_path / "grazing.orbits.rst").read_text()
    assert ".. autosummary::" in orbits
    for name in importlib.import_module("grazing.orbits").__all__:  # a page, or a link to one
        assert f"   {name}\n" in orbits or f"- ``grazing.orbits.{name}``: :obj:" in orbits
    sweeps = (tmp_path / "grazing.sweeps.rst").read_text()
    assert "``grazing.sweeps.detect_period``: :obj:`grazing.detect_period`" in sweeps
    index = (tmp_path / "index.rst").read_text()
    assert all(f"   {m}\n" in index for m, _ in api_pages.API_MODULES)


def test_every_public_function_and_class_documents_its_parameters_and_shows_an_example() -> None:
    """``make docs`` runs docs/check_reference.py first; CI runs this."""
    assert check_reference.check() == []


def _without_section(doc: str, section: str) -> str:
    """``doc`` with one numpydoc section (its heading, underline and body) taken out."""
    lines = doc.splitlines()
    start = next(i for i, line in enumerate(lines) if line.strip() == section)
    end = next(
        (i for i in range(start + 2, len(lines)) if set(lines[i].strip()) == {"-"} and i > start + 2),
        len(lines) + 1,
    )
    return "\n".join(lines[:start] + lines[end - 1 :])


@pytest.mark.parametrize("section", ["Parameters", "Returns", "Examples"])
def test_the_reference_check_finds_a_section_taken_out_of_a_real_docstring(section: str) -> None:
    from grazing.sweeps import parameter_map

    assert check_reference.problems("grazing.sweeps.parameter_map", parameter_map) == []

    @functools.wraps(parameter_map)
    def changed(*args, **kwargs):  # the same signature (functools.wraps), the docstring less a section
        return parameter_map(*args, **kwargs)

    changed.__doc__ = _without_section(inspect.getdoc(parameter_map), section)
    assert section not in changed.__doc__ and "Two-parameter" in changed.__doc__
    (found,) = check_reference.problems("grazing.sweeps.parameter_map", changed)
    assert found.startswith(f"grazing.sweeps.parameter_map: no {section} section")


def test_the_reference_check_names_an_undocumented_parameter_and_a_class_without_example() -> None:
    def f(a: int, b: float) -> int:
        """F.

        Parameters
        ----------
        a
            A.

        Returns
        -------
        int

        Examples
        --------
        >>> f(1, 2.0)
        1
        """
        return a

    @dataclasses.dataclass
    class Record:
        """A record.

        Attributes
        ----------
        x
            The x.
        """

        x: float

    assert check_reference.problems("f", f) == ["f: parameters not documented: b"]
    assert check_reference.problems("Record", Record) == ["Record: no Examples section (with a >>> example)"]


def test_the_types_shown_are_the_annotations() -> None:
    def f(x: float, ys: list[int] | None = None) -> None:
        """F.

        Parameters
        ----------
        x
            A number.
        ys : list of int, optional
            Kept as written.
        """

    lines = inspect.getdoc(f).splitlines()
    annotated_types.add_types(None, "function", "f", f, None, lines)
    assert lines[4:7] == ["x : float", "    A number.", "ys : list of int, optional"]


def _png(path: Path, painted: bool) -> None:
    from PIL import Image

    img = np.full((60, 80, 3), 255, np.uint8)
    if painted:
        img[10:40, 10:60] = (30, 90, 200)
    Image.fromarray(img).save(path)


def test_a_blank_image_is_blank(tmp_path: Path) -> None:
    _png(tmp_path / "white.png", painted=False)
    _png(tmp_path / "drawn.png", painted=True)
    assert is_blank(tmp_path / "white.png") and not is_blank(tmp_path / "drawn.png")
    assert not is_blank(tmp_path / "page.svg")  # not judged


@chromium
def test_the_site_check_finds_a_blank_image_a_missing_page_and_a_missing_anchor(
    tmp_path: Path,
) -> None:
    _png(tmp_path / "white.png", painted=False)
    _png(tmp_path / "drawn.png", painted=True)
    (tmp_path / "sub").mkdir()
    (tmp_path / "index.html").write_text(
        '<!DOCTYPE html><html><head><title>site</title></head><body><img src="drawn.png">'
        '<a href="sub/page.html#here">ok</a> <a href="sub/page.html#gone">anchor gone</a>'
        ' <a href="nowhere.html">missing</a></body></html>',
        encoding="utf-8",
    )
    (tmp_path / "sub" / "page.html").write_text(
        '<!DOCTYPE html><html><head><title>p</title></head><body><h2 id="here">x</h2>'
        '<img src="../white.png"><a href="../index.html">home</a></body></html>',
        encoding="utf-8",
    )
    res = check_site(tmp_path)
    index, page = res[(tmp_path / "index.html").resolve()], res[(tmp_path / "sub" / "page.html").resolve()]
    assert sorted(index.broken_links) == ["nowhere.html", "sub/page.html#gone"]
    assert index.blank_images == [] and page.blank_images == ["../white.png"]
    assert page.broken_links == [] and not page.ok
    assert main([str(tmp_path)]) == 1
    (tmp_path / "white.png").unlink()
    _png(tmp_path / "white.png", painted=True)
    (tmp_path / "index.html").write_text('<html><body><a href="sub/page.html#here">ok</a></body></html>')
    assert main([str(tmp_path)]) == 0


def test_a_folder_without_a_site_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    if find_chromium() is None:
        pytest.skip("no Chromium installed")
    assert main([str(tmp_path)]) == 2
    assert "index.html" in capsys.readouterr().err


@pytest.mark.slow
def test_the_site_builds_with_warnings_as_errors(tmp_path: Path) -> None:
    """The whole site, tutorials executed (about two to three minutes on two cores)."""
    pytest.importorskip("sphinx")
    pytest.importorskip("myst_nb")
    docs = tmp_path / "docs"
    shutil.copytree(DOCS, docs, ignore=shutil.ignore_patterns("_build", "api"))
    for name in ("CHANGELOG.md", "CITATION.cff"):  # (the changelog and citation pages are made from them)
        shutil.copyfile(ROOT / name, tmp_path / name)
    html = docs / "_build" / "html"
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "sphinx",
            "-b",
            "html",
            "-W",
            "--keep-going",
            "-q",
            str(docs),
            str(docs / "_build/html"),
        ],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stderr[-3000:]
    walk = (html / "tutorials" / "paper-walkthrough.html").read_text()
    assert walk.count("<img") >= 5
    assert (html / "api" / "generated" / "grazing.simulate.html").is_file()
    assert "piiroinen2004" in (html / "citation.html").read_text()  # the BibTeX from CITATION.cff
    assert "_static/mathjax/tex-chtml.js" in (html / "equations.html").read_text()  # served from the site
    assert (html / "_static" / "mathjax" / "tex-chtml.js").is_file()
    if find_chromium() is not None:
        assert main([str(html)]) == 0
