"""Reproduction of the paper's numerical figures as an HTML report, every comparison with its rule.

:func:`build_report` compiles the model's kernels (timed on its own), then
runs the figure modules in :data:`FIGURES` in order.  Each module exposes
``build(out_dir, progress) -> FigureResult``: it computes what it shows,
writes its PNG and data files into ``out_dir`` and returns a
:class:`FigureResult` (images, data files, comparison records, notes).  Each
result is kept as ``results/<id>.json``, so that ``only=`` rebuilds one figure
and re-renders the page from the others.  The page (``index.html``) and every
comparison (``comparisons.json``) are written last, through temporary files.
To add a figure, write ``figNN.py`` with such a ``build`` and list it in
:data:`FIGURES`; its paper numbers go into :mod:`grazing.report.paper`.

Examples
--------
>>> from grazing.report import FIGURES, PAPER_FIGURES
>>> [m.FIGURE_ID for m in FIGURES]
['2', '4', '6', '7', '8', '9', '10', '11', '12', 'map', 'adding', 'stops', 'attractors', 'switch', 'eq']
>>> set(PAPER_FIGURES) <= {m.FIGURE_ID for m in FIGURES}
True
>>> [m.FIGURE_ID for m in select(["fig07", "10", "figmap"])]
['7', '10', 'map']
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from datetime import datetime
from pathlib import Path
from types import ModuleType
from typing import Any

import grazing
from grazing.atomic import scratch_folder, write_bytes_atomic, write_text_atomic
from grazing.outputs import owned_folder
from grazing.report import (
    errata,
    fig02,
    fig04,
    fig06,
    fig07,
    fig08,
    fig09,
    fig10,
    fig11,
    fig12,
    figadding,  # issue 27
    figattractors,  # issue 28
    figmap,
    figstops,
    figswitch,  # issue 45
    paper,
)
from grazing.report.base import Comparison, DataFile, Dynamics, FigureResult, Image, Say
from grazing.report.folder import check_report_folder, claim_report_folder
from grazing.report.html import RULES_TEXT, ReportMeta, render, scoreboard
from grazing.report.provenance import collect, source_root
from grazing.report.schedule import RESULTS, build_figures

__all__ = [
    "FIGURES",
    "PAPER_FIGURES",
    "Comparison",
    "DataFile",
    "Dynamics",
    "FigureResult",
    "Image",
    "ReportMeta",
    "build_report",
    "select",
]

FIGURES: tuple[ModuleType, ...] = (
    fig02,
    fig04,
    fig06,
    fig07,
    fig08,
    fig09,
    fig10,
    fig11,
    fig12,
    figmap,
    figadding,  # issue 27
    figstops,
    figattractors,  # issue 28
    figswitch,  # issue 45
    errata,
)
"""The figure modules, in the order the page shows them."""

PAPER_FIGURES = ("4", "6", "7", "8", "9", "10", "11", "12")
"""The paper's numerical figures, all of which the report is to reproduce."""

INDEX = "index.html"
COMPARISONS = "comparisons.json"
DOCS = (
    ("the equations, units and the paper's errata", "equations.md"),
    ("the grazing normal form", "normal-form.md"),
    ("the experiment tools", "experiment.md"),
)
"""The documents linked from the top of the page (copied from the repository's ``docs/``, those it has)."""


def select(names: Sequence[str]) -> list[ModuleType]:
    """The figure modules named ``fig07``, ``fig7``, ``7``, ``figmap``/``map``, ``eq`` (in page order).

    Parameters
    ----------
    names
        Figure names, as ``grazing report --only`` takes them.

    Returns
    -------
    list of module
        The figure modules (each with its ``FIGURE_ID`` and ``build``), once each.

    Raises
    ------
    ValueError
        For a name that is no figure of the report.

    Examples
    --------
    >>> [m.FIGURE_ID for m in select(["fig07", "7", "eq", "map"])]
    ['7', 'map', 'eq']
    >>> select(["fig99"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: no figure 'fig99' in the report (known: fig02, fig04, ...)
    """
    by_id = {m.FIGURE_ID: m for m in FIGURES}
    wanted = set()
    for name in names:
        key = name.strip().lower().removeprefix("fig").lstrip("0") or "0"
        if key not in by_id:
            known = ", ".join(
                f"fig{m.FIGURE_ID.zfill(2)}" if m.FIGURE_ID.isdigit() else m.FIGURE_ID for m in FIGURES
            )
            raise ValueError(f"no figure {name!r} in the report (known: {known})")
        wanted.add(key)
    return [m for m in FIGURES if m.FIGURE_ID in wanted]


def _copy_docs(out: Path) -> tuple[tuple[str, str], ...]:
    """Copy the linked documents into ``out/docs`` (when the source tree has them): ``(title, link)``."""
    src = source_root() / "docs"
    links = []
    for title, name in DOCS:
        if (src / name).is_file():
            (out / "docs").mkdir(exist_ok=True)
            write_bytes_atomic(out / "docs" / name, (src / name).read_bytes())
            links.append((title, f"docs/{name}"))
    return tuple(links)


def load_results(out: Path) -> list[FigureResult]:
    """The figure results kept in ``out/results``, in page order (figures never built are left out)."""
    found = []
    for m in FIGURES:
        path = out / RESULTS / f"{m.FIGURE_ID}.json"
        if path.is_file():
            found.append(FigureResult.from_json(json.loads(path.read_text(encoding="utf-8"))))
    return found


def comparisons_json(results: Sequence[FigureResult], meta: ReportMeta) -> dict[str, Any]:
    """Every comparison row of the page, with the scoreboard and the provenance."""
    rows = [r for f in results for r in f.comparisons]
    return {
        "paper": "Piiroinen, Virgin & Champneys, J. Nonlinear Sci. 14 (2004) 383-404",
        "doi": paper.DOI,
        "commit": meta.commit,
        "dirty": meta.dirty,
        "vector_width": meta.vector_width,
        "rendered": meta.date,
        "versions": meta.versions,
        "rules": RULES_TEXT,
        "scoreboard": scoreboard(rows),
        "rows": [r.to_json() for r in rows],
    }


def build_report(
    out_dir: Path | str,
    progress: Say | None = None,
    only: Sequence[str] | None = None,
    overwrite: bool = False,
) -> Path:
    """Compute the figures; write their PNGs, data, ``comparisons.json`` and ``index.html`` into ``out_dir``.

    Parameters
    ----------
    out_dir
        Folder for the report: a report folder of grazing's (files of the same
        names are replaced, other files are left alone), an empty folder, or a
        new folder (made with its parents; see :mod:`grazing.report.folder`).
    progress
        Called with one-line messages as the build proceeds.
    only
        Figure names (``["fig07"]``): rebuild these only, and render the page
        from them and the results of the other figures kept from earlier builds.
    overwrite
        Build into a folder that is not a report folder of grazing's, replacing
        the files of the report's names in it.

    Returns
    -------
    Path
        The path of ``index.html``.  The page is written last, through a
        temporary file, so a failed build never leaves a half-written page.

    Examples
    --------
    >>> import tempfile
    >>> index = build_report(tempfile.mkdtemp())  # doctest: +SKIP
    >>> index.name  # doctest: +SKIP
    'index.html'
    """
    import matplotlib

    matplotlib.use("Agg")
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    modules = list(FIGURES) if only is None else select(only)
    out = Path(out_dir)
    check_report_folder(out, overwrite=overwrite)
    claim_report_folder(out)
    (out / RESULTS).mkdir(exist_ok=True)
    prov = collect()
    say("compiling the model's kernels (once per machine; loading them when cached)")
    with owned_folder(out), scratch_folder(out):  # (a worker stopped while writing leaves nothing in out)
        compile_seconds = build_figures(modules, out, say, prov.commit)
    results = load_results(out)
    done = {r.figure_id for r in results}
    meta = ReportMeta(
        version=grazing.__version__,
        date=datetime.now().astimezone().isoformat(timespec="seconds"),
        seconds=time.perf_counter() - start,
        compile_seconds=compile_seconds,
        commit=prov.commit,
        versions=prov.versions,
        cpu=prov.cpu,
        cores=prov.cores,
        system=prov.system,
        vector_width=prov.vector_width,
        dirty=prov.dirty,
        docs=_copy_docs(out),
        pending=tuple(f for f in PAPER_FIGURES if f not in done),
    )
    text = json.dumps(comparisons_json(results, meta), ensure_ascii=False, indent=1)
    write_text_atomic(out / COMPARISONS, lambda fh: fh.write(text))
    index = out / INDEX
    page = render(results, meta)
    write_text_atomic(index, lambda fh: fh.write(page))
    return index
