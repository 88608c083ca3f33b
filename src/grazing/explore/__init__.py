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
    """The explorer of ``model`` as a Panel component (display it in Jupyter; see :func:`.app.explorer`).

    Parameters
    ----------
    model
        A :class:`~grazing.HybridModel`, its other parameters set.
    ranges
        ``{name: (lo, hi)}`` in display units (degrees for angles): one parameter
        (a bifurcation diagram) or two (a period map); default for the pendulum
        ``{"eta": (0.44, 0.49)}``.
    **kwargs
        ``num`` (points per parameter), ``component`` (the state on the
        vertical axis), ``source`` (the model as ``--model`` takes it) and, for a
        model with modes, ``mode`` (the mode a click starts in; default: the one
        the diagram's state there lies in).

    Returns
    -------
    panel.layout.Column
        The page, computing its diagram in the background (needs the
        ``explore`` extra: Panel and Bokeh).

    Examples
    --------
    In a notebook, ``pn.extension()`` first, then the component as a cell's value:

    >>> import math, grazing
    >>> model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> page = explorer(model, {"eta": (0.44, 0.46)}, num=5)
    >>> type(page).__name__
    'Column'
    >>> explorer(grazing.models.bouncing_ball())
    Traceback (most recent call last):
    ...
    grazing.errors.GrazingError: give the ranges explored: {name: (lo, hi)}
    """
    from grazing.explore.app import explorer as make

    return make(model, ranges, **kwargs)
