"""Brute-force bifurcation diagrams: sweeps in one or two parameters (periods, impacts, Lyapunov exponents).

:func:`sweep` and :func:`parameter_map` (in :mod:`~grazing.sweeps.api`) build a
:class:`~grazing.sweeps.spec.SweepSpec`, whose chunks :mod:`~grazing.sweeps.run`
computes, :mod:`~grazing.sweeps.executor` distributes (local threads or a Dask
cluster) and :mod:`~grazing.sweeps.store` keeps (in memory, or in a resumable
Zarr store that grazing owns and locks).  :mod:`~grazing.sweeps.windows` finds
the periodic windows of a one-parameter diagram.
"""

from grazing.core.period import detect_period
from grazing.sweeps.api import parameter_map, run_sweep, run_sweeps, sweep
from grazing.sweeps.run import run_chunk
from grazing.sweeps.spec import SweepSpec, map_spec, sweep_spec

__all__ = [
    "SweepSpec",
    "detect_period",
    "map_spec",
    "parameter_map",
    "run_chunk",
    "run_sweep",
    "run_sweeps",
    "sweep",
    "sweep_spec",
]
