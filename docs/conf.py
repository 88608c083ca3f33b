"""Sphinx configuration of grazing's documentation site (``make docs``).

The site is Sphinx with myst-nb (Markdown pages; tutorials are MyST notebooks executed at
build time, their outputs cached by jupyter-cache in ``docs/_build/.jupyter_cache``), numpydoc
(the docstrings are numpydoc) and the pydata theme.  The API reference is written from each
public module's ``__all__`` when the build starts (:func:`write_api_pages`), so a public name
added to a module appears in the reference without editing any page.  See contributing.md.
"""

from __future__ import annotations

import importlib
import inspect
import os
import shutil
from pathlib import Path

import grazing

DOCS = Path(__file__).resolve().parent

project = "grazing"
author = "The grazing developers"
copyright = "2026, The grazing developers"
version = release = grazing.__version__

extensions = [
    "myst_nb",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
]

exclude_patterns = ["_build", "_ext", "**/.ipynb_checkpoints"]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb"}
root_doc = "index"

# Markdown: $...$ maths, ::: fences, anchors for every heading down to level 3 (the pages link
# to their own sections, e.g. user-models.md#supported-functions).
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# Notebooks: executed at build time, each cell's outputs cached (jupyter-cache) so that a rebuild
# re-runs only the pages whose code changed; a cell that raises fails the build.
nb_execution_mode = os.environ.get("GRAZING_DOCS_EXECUTE", "cache")
nb_execution_cache_path = str(DOCS / "_build" / ".jupyter_cache")
nb_execution_timeout = 300
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True
# A cell that writes to stderr (a warning, a log line) is a build warning, hence an error: the
# tutorials must run cleanly, as scipy's examples must not warn.
nb_output_stderr = "warn"

# The kernels start with docs/_ext/ipython_startup.py, which reports a figure with an axes that
# shows no data on stderr (so a blank figure fails the build too).
_IPYTHON = DOCS / "_build" / "ipython"
(_IPYTHON / "profile_default" / "startup").mkdir(parents=True, exist_ok=True)
shutil.copyfile(DOCS / "_ext" / "ipython_startup.py", _IPYTHON / "profile_default" / "startup" / "00-grazing.py")
os.environ["IPYTHONDIR"] = str(_IPYTHON)
# ... and import the grazing this build documents (a kernel runs in the notebook's folder).
_SRC = str(Path(grazing.__file__).resolve().parents[1])
os.environ["PYTHONPATH"] = os.pathsep.join([_SRC, *filter(None, [os.environ.get("PYTHONPATH")])])

# API reference: numpydoc renders the docstrings; autosummary writes one page per object.
autosummary_generate = True
autosummary_imported_members = True
autodoc_typehints = "none"
autodoc_default_options = {"member-order": "bysource"}
numpydoc_show_class_members = True
numpydoc_class_members_toctree = False
numpydoc_show_inherited_class_members = False
numpydoc_xref_param_type = False

html_theme = "pydata_sphinx_theme"
html_title = f"grazing {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {"index": [], "installation": [], "platforms": []}
html_copy_source = False
html_show_sourcelink = False

nitpicky = False


# --------------------------------------------------------------------------------------------
# The API reference, from __all__.

API_MODULES = (
    ("grazing", "The package: models, simulation, options, errors"),
    ("grazing.models", "Built-in models"),
    ("grazing.maps", "Stroboscopic and impact maps"),
    ("grazing.orbits", "Periodic orbits, continuation, grazing and bifurcation curves"),
    ("grazing.normalform", "The grazing normal form"),
    ("grazing.sweeps", "Brute-force bifurcation diagrams"),
    ("grazing.attractors", "Coexisting attractors and basins"),
    ("grazing.experiment", "Experiment tools"),
    ("grazing.plotting", "Plots"),
    ("grazing.errors", "Errors and warnings"),
    ("grazing.outputs", "Output files"),
    ("grazing.report", "The report"),
)
"""Every module of the public API, in the order of the reference, with its page's title."""


def public_names(module_name: str) -> list[str]:
    """The public names of a module: its ``__all__``, else what it defines without a leading ``_``."""
    module = importlib.import_module(module_name)
    names = getattr(module, "__all__", None)
    if names is None:
        names = [
            n
            for n, obj in vars(module).items()
            if not n.startswith("_")
            and (inspect.isfunction(obj) or inspect.isclass(obj))
            and getattr(obj, "__module__", None) == module_name
        ]
    return [n for n in names if n != "__version__" and not inspect.ismodule(getattr(module, n))]


def api_entries() -> list[tuple[str, str, list[str], list[tuple[str, str]]]]:
    """(module, title, names documented there, (name, where it is documented) for re-exports).

    An object reachable from several modules (``grazing.detect_period`` is also
    ``grazing.sweeps.detect_period``) is documented once, under the first module of
    :data:`API_MODULES` that exports it.
    """
    seen: dict[int, str] = {}
    out = []
    for mod, title in API_MODULES:
        module = importlib.import_module(mod)
        own, again = [], []
        for name in public_names(mod):
            obj = getattr(module, name)
            key = id(obj)
            if (inspect.isclass(obj) or inspect.isfunction(obj)) and key in seen:
                again.append((name, seen[key]))
                continue
            if inspect.isclass(obj) or inspect.isfunction(obj):
                seen[key] = f"{mod}.{name}"
            own.append(name)
        out.append((mod, title, own, again))
    return out


def write_api_pages(app: object | None = None) -> None:
    """Write ``api/<module>.rst`` (one per module of :data:`API_MODULES`) and ``api/index.rst``."""
    api = DOCS / "api"
    api.mkdir(exist_ok=True)
    pages = []
    for mod, title, own, again in api_entries():
        heading = f"``{mod}``: {title}"
        lines = [heading, "=" * len(heading), "", f".. automodule:: {mod}", "   :no-members:", ""]
        lines += [f".. currentmodule:: {mod}", ""]
        if own:
            lines += [".. autosummary::", "   :toctree: generated", "   :nosignatures:", ""]
            lines += [f"   {n}" for n in sorted(own, key=str.lower)]
            lines.append("")
        if again:
            lines += ["Also exported here (documented once, where linked):", ""]
            lines += [f"- ``{mod}.{n}``: :obj:`{target}`" for n, target in again]
            lines.append("")
        text = "\n".join(lines)
        page = api / f"{mod}.rst"
        if not page.exists() or page.read_text() != text:  # unchanged pages keep their time stamp
            page.write_text(text)
        pages.append(mod)
    index = "\n".join(
        [
            "API reference",
            "=============",
            "",
            "Every public function and class, from its docstring (numpydoc).  The pages are written "
            "from each module's ``__all__`` when the site is built, so nothing public is left out.",
            "",
            ".. toctree::",
            "   :maxdepth: 1",
            "",
            *[f"   {m}" for m in pages],
            "",
        ]
    )
    if not (api / "index.rst").exists() or (api / "index.rst").read_text() != index:
        (api / "index.rst").write_text(index)


write_api_pages()  # before autosummary reads the pages (it runs on builder-inited)
