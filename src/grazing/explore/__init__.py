"""``grazing explore``: the bifurcation diagram you can click, in the browser or in Jupyter.

The computations are plain Python, testable without a browser: :mod:`.diagram` (what is
explored, :class:`View`, and its sweep, :class:`Diagram`), :mod:`.point` (a clicked point:
simulation, period, impacts, Newton's method and Floquet multipliers), :mod:`.branch`
(continuing the clicked orbit, its bifurcation curves on a period map, the grazings in the
range), :mod:`.code` ("copy as code": the Python and the command lines that reproduce the
view), :mod:`.jobs` (the page's requests in the background, newer ones superseding older).
The page itself (:mod:`.app`, Panel and Bokeh, the ``explore`` extra) is one component that
``grazing explore`` serves (:mod:`.server`) and that a Jupyter notebook displays
(:func:`explorer`).
"""

from __future__ import annotations

from typing import Any

from grazing.explore.branch import (
    Continued,
    Curves,
    Grazings,
    continue_click,
    follow_click_curves,
    grazings_in_view,
)
from grazing.explore.code import Code, view_code
from grazing.explore.diagram import Axis, Diagram, SupersededError, View, compute_diagram
from grazing.explore.point import InspectSettings, PointReport, inspect_click, inspect_point
from grazing.explore.source import ModelSource

__all__ = [
    "Axis",
    "Code",
    "Continued",
    "Curves",
    "Diagram",
    "Grazings",
    "InspectSettings",
    "ModelSource",
    "PointReport",
    "SupersededError",
    "View",
    "compute_diagram",
    "continue_click",
    "explorer",
    "follow_click_curves",
    "grazings_in_view",
    "inspect_click",
    "inspect_point",
    "view_code",
]


def explorer(model: Any, ranges: dict[str, tuple[float, float]] | None = None, **kwargs: Any) -> Any:
    """The explorer of ``model`` as a Panel component (display it in Jupyter; see :func:`.app.explorer`)."""
    from grazing.explore.app import explorer as make

    return make(model, ranges, **kwargs)
