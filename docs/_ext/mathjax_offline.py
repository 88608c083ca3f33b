"""MathJax served from the site itself: no network when a page with maths is read (a Sphinx extension).

The files come from the ``sphinx-mathjax-offline`` package (MathJax 3, in the ``docs`` extra); of
its 24 MB only what ``tex-chtml.js`` loads is copied into ``_static/mathjax`` (the component, its
CommonHTML fonts, the TeX extensions it may autoload and the menu), about 5 MB.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

from sphinx.util.fileutil import copy_asset

COPIED = ("tex-chtml.js", "output/chtml", "output/chtml.js", "input/tex", "ui", "a11y", "adaptors")
"""The parts of MathJax copied: the TeX-to-CommonHTML component and what it loads on demand."""


def mathjax_folder() -> Path:
    """The folder of MathJax's files in the installed ``sphinx-mathjax-offline`` package."""
    spec = importlib.util.find_spec("sphinx-mathjax-offline")
    if spec is None or spec.origin is None:
        raise RuntimeError("MathJax is missing: pip install -e '.[docs]' (sphinx-mathjax-offline)")
    return Path(spec.origin).parent / "static" / "mathjax"


def copy_mathjax(app: Any, exc: Exception | None) -> None:
    if exc is not None or app.builder.format != "html":
        return
    src, out = mathjax_folder(), Path(app.outdir) / "_static" / "mathjax"
    for part in COPIED:
        if (src / part).is_dir():
            copy_asset(str(src / part), str(out / part))
        else:
            out.mkdir(parents=True, exist_ok=True)
            (out / part).parent.mkdir(parents=True, exist_ok=True)
            (out / part).write_bytes((src / part).read_bytes())


def setup(app: Any) -> dict[str, Any]:
    mathjax_folder()  # fails the build at once when the package is missing
    app.config.mathjax_path = "mathjax/tex-chtml.js"
    app.connect("build-finished", copy_mathjax)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
