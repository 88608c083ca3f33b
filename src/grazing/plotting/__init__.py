"""Matplotlib helpers: drawing only, labelled from the metadata of models and datasets.

matplotlib is imported lazily inside the functions that draw (``import
grazing`` never loads it and never selects a backend); the helpers draw on an
``Axes`` the caller supplies.  :mod:`~grazing.plotting.trajectories`:
:func:`plot_time_series`, :func:`plot_delay`.  :mod:`~grazing.plotting.diagrams`:
:func:`plot_bifurcation`, :func:`visible_windows`, :func:`label_windows`,
:func:`mark_grazings`, :func:`period_classes`, :func:`plot_period_map`.
:mod:`~grazing.plotting.attractors`: :func:`plot_basins`, :func:`plot_fractions`.
:mod:`~grazing.plotting.labels`: axis labels from parameter and state metadata.
:mod:`~grazing.plotting.palette`: the colours of detected periods, shared by the report, the docs
and ``grazing explore``.
The array helpers :func:`~grazing.experiment.signal.uniform_resample` and
:func:`~grazing.experiment.signal.delay_coordinates` live with the signal
processing.
"""

from grazing.plotting.attractors import plot_basins, plot_fractions
from grazing.plotting.diagrams import (
    label_windows,
    mark_grazings,
    period_classes,
    plot_bifurcation,
    plot_period_map,
    visible_windows,
)
from grazing.plotting.labels import param_label
from grazing.plotting.trajectories import plot_delay, plot_time_series
from grazing.sweeps.windows import Window, find_windows

__all__ = [
    "Window",
    "find_windows",
    "label_windows",
    "mark_grazings",
    "param_label",
    "period_classes",
    "plot_basins",
    "plot_bifurcation",
    "plot_delay",
    "plot_fractions",
    "plot_period_map",
    "plot_time_series",
    "visible_windows",
]
