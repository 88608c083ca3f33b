"""Reproduction of the paper's numerical figures as an HTML report.

:func:`build_report` runs the figure modules in :data:`FIGURES` in order.
Each module exposes ``build(out_dir, progress) -> FigureResult``: it computes
what it shows, writes its PNG files into ``out_dir`` and returns a
:class:`FigureResult` (images, captions, the paper's statements beside ours,
notes).  :mod:`grazing.report.html` renders the page from those.  To add a
figure, write ``figNN.py`` with such a ``build`` and list it in
:data:`FIGURES`.

Examples
--------
>>> from grazing.report import FIGURES, PAPER_FIGURES
>>> [m.FIGURE_ID for m in FIGURES]
['2', '4', '6', '7', '8', '9', '10', '11', '12', 'map']
>>> set(PAPER_FIGURES) <= {m.FIGURE_ID for m in FIGURES}
True
"""

from __future__ import annotations

import os
import platform
import time
from datetime import datetime
from pathlib import Path

import grazing
from grazing.report import fig02, fig04, fig06, fig07, fig08, fig09, fig10, fig11, fig12, figmap
from grazing.report.base import Comparison, Dynamics, FigureResult, Image, Progress
from grazing.report.html import ReportMeta, render

__all__ = [
    "FIGURES",
    "PAPER_FIGURES",
    "Comparison",
    "Dynamics",
    "FigureResult",
    "Image",
    "ReportMeta",
    "build_report",
]

FIGURES = (fig02, fig04, fig06, fig07, fig08, fig09, fig10, fig11, fig12, figmap)
"""The figure modules, in the order the page shows them."""

PAPER_FIGURES = ("4", "6", "7", "8", "9", "10", "11", "12")
"""The paper's numerical figures, all of which the report is to reproduce."""

INDEX = "index.html"


def _precompile() -> None:
    """Compile the kernel variants the figures use, in parallel (a no-op when cached)."""
    from grazing.engine.runner import precompile

    model = grazing.models.pendulum("B")
    precompile([(model, ()), (model, ("eta",)), (model, ("eta", "theta_hat"))])


def build_report(out_dir: Path | str, progress: Progress | None = None) -> Path:
    """Compute every figure, write the PNGs and ``index.html`` into ``out_dir``.

    Parameters
    ----------
    out_dir
        Directory for the report (created if missing; files of the same name
        are overwritten, other files are left alone).
    progress
        Called with one-line messages as the build proceeds.

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
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    say("compiling the model's kernels (once per machine)")
    _precompile()
    results: list[FigureResult] = []
    for module in FIGURES:
        results.append(module.build(out, say))
        say(f"figure {module.FIGURE_ID} done in {results[-1].seconds:.1f} s")
    done = {r.figure_id for r in results}
    meta = ReportMeta(
        version=grazing.__version__,
        date=datetime.now().astimezone().isoformat(timespec="seconds"),
        seconds=time.perf_counter() - start,
        platform=f"Python {platform.python_version()} on {platform.platform(terse=True)}",
        pending=tuple(f for f in PAPER_FIGURES if f not in done),
    )
    index = out / INDEX
    tmp = out / f".{INDEX}.tmp"
    tmp.write_text(render(results, meta), encoding="utf-8")
    os.replace(tmp, index)
    say(f"report written to {index} in {meta.seconds:.1f} s")
    return index
