"""grazing: simulation and analysis of impacting (vibro-impact) systems.

>>> import math, grazing
>>> model = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
>>> sol = grazing.simulate(model, [0.0, 0.0], transient=400, periods=10)
>>> sol.samples.shape
(10, 2)
"""

from grazing import models
from grazing.core import HybridModel, Impacts, Parameter, Solution, Stop
from grazing.core.options import SaveAt, Solver, SweepSettings, Tangent
from grazing.core.period import detect_period
from grazing.engine.simulate import simulate
from grazing.errors import (
    ConvergenceError,
    GrazingError,
    InvalidParameterError,
    InvalidStateError,
    SimulationError,
)


def __getattr__(name: str) -> str:
    # The version is looked up on first use: importlib.metadata costs ~50 ms at import.
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            return version("grazing")
        except PackageNotFoundError:  # pragma: no cover - running from a source tree
            return "0.0.0"
    raise AttributeError(f"module 'grazing' has no attribute {name!r}")


__all__ = [
    "ConvergenceError",
    "GrazingError",
    "HybridModel",
    "Impacts",
    "InvalidParameterError",
    "InvalidStateError",
    "Parameter",
    "SaveAt",
    "SimulationError",
    "Solution",
    "Solver",
    "Stop",
    "SweepSettings",
    "Tangent",
    "__version__",
    "detect_period",
    "models",
    "simulate",
]
