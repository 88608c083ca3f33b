"""Sphinx configuration of grazing's documentation site (``make docs``).

The site is Sphinx with myst-nb (Markdown pages; tutorials are MyST notebooks executed at
build time, their outputs cached by jupyter-cache in ``docs/_build/.jupyter_cache``), numpydoc
(the docstrings are numpydoc; the types of the parameters and returns come from the annotations),
MathJax served from the site itself (``sphinx-mathjax-offline``: no network when a page is read)
and the pydata theme.  The changelog and citation pages are made from ``CHANGELOG.md`` and
``CITATION.cff`` at the root of the repository.  The API reference is written from each
public module's ``__all__`` when the build starts (:func:`write_api_pages`), so a public name
added to a module appears in the reference without editing any page.  See contributing.md.
"""

from __future__ import annotations

import os
import shutil
import sys
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
    "annotated_types",  # docs/_ext: the annotations as the parameters' types
    "changelog_citation",  # docs/_ext: changelog.md and citation.md from CHANGELOG.md, CITATION.cff
    "mathjax_offline",  # docs/_ext: MathJax from the sphinx-mathjax-offline package, into _static
]

exclude_patterns = ["_build", "_ext", "**/.ipynb_checkpoints"]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb"}
root_doc = "index"

# Markdown: ::: fences, anchors for every heading down to level 3 (the pages link to their own
# sections, e.g. user-models.md#supported-functions), TeX maths in $...$, $$...$$ and {math}.
myst_enable_extensions = ["colon_fence", "deflist", "dollarmath", "amsmath"]
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
# The types shown are the annotations', written into numpydoc's Parameters and Attributes entries
# (docs/_ext/annotated_types.py: autodoc's "description" mode writes :param: fields, which numpydoc
# does not use); the signatures stay short.
autodoc_typehints = "none"
autodoc_default_options = {"member-order": "bysource"}
numpydoc_show_class_members = True
numpydoc_class_members_toctree = False
numpydoc_show_inherited_class_members = False
numpydoc_xref_param_type = False

html_theme = "pydata_sphinx_theme"
html_title = f"grazing {release}"
html_static_path = ["_static"]
html_css_files = ["grazing.css"]
html_theme_options = {
    "navigation_with_keys": False,
    # every page of the top bar shown at 1300 px, the API reference among them (not under "More")
    "header_links_before_dropdown": 5,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {"index": [], "installation": [], "platforms": [], "changelog": [], "citation": []}
html_copy_source = False
html_show_sourcelink = False

nitpicky = False


# --------------------------------------------------------------------------------------------
# The API reference: one page per public module, written from its __all__ (docs/_ext/api_pages.py)
# before autosummary reads the pages.

sys.path.insert(0, str(DOCS / "_ext"))
import api_pages  # noqa: E402

api_pages.write_api_pages(DOCS / "api")
