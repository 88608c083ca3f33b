"""The API reference's pages, written from each public module's ``__all__`` (``docs/conf.py``).

An object exported by several modules is documented once, under the first module of
:data:`API_MODULES` that exports it, and linked from the others.  :data:`INTERNAL` names the
packages and modules that are not part of the reference, each with the reason;
``tests/test_docs_site.py`` checks that every module of ``grazing`` is in one of the two.
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path


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
    ("grazing.explore", "The explorer (grazing explore)"),
)
"""Every module of the public API, in the order of the reference, with its page's title."""

INTERNAL = {
    "grazing.core": "its public names are grazing's (HybridModel, Parameter, Stop, Solution, Impacts)",
    "grazing.engine": "the integrator's machinery; grazing.simulate is its interface",
    "grazing.gpu": "the GPU backend's machinery; device= of sweep, parameter_map and basins is its interface",
    "grazing.cli": "the command line, documented by `grazing --help` and the README",
    "grazing.atomic": "files written all at once (used by outputs)",
    "grazing.parallel": "the pool of worker processes",
    "grazing.clib": "the C library, for the calls Python does not offer (used by atomic and parallel)",
    "grazing.plot_areas": "the record of a saved figure's plot areas, read by make check-report",
}
"""Modules of ``grazing`` left out of the reference, with the reason."""


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


def write_api_pages(api: Path) -> None:
    """Write ``<api>/<module>.rst`` (one per module of :data:`API_MODULES`) and ``<api>/index.rst``."""
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

