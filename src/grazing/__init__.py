"""grazing: simulation and analysis of impacting (vibro-impact) systems.

>>> import math, grazing
>>> model = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
>>> sol = grazing.simulate(model, [0.0, 0.0], transient=400, periods=10)
>>> sol.samples.shape
(10, 2)
"""

from __future__ import annotations

from types import ModuleType
from typing import TYPE_CHECKING, Any

from grazing import models
from grazing.core import HybridModel, Impacts, Mode, Parameter, Solution, Stop, Surface, Transition
from grazing.core.model import set_kernel_loader
from grazing.core.options import SaveAt, Solver, SweepSettings, Tangent
from grazing.core.period import detect_period
from grazing.errors import (
    ConvergenceError,
    GrazingError,
    InvalidParameterError,
    InvalidStateError,
    SimulationError,
    UnsupportedExpressionError,
)

if TYPE_CHECKING:
    from grazing.engine.simulate import simulate


def _load_engine(*args: Any) -> Any:
    # The engine (numba, about 0.2 s to import) is imported when a model first needs its
    # kernels or grazing.simulate is first used, not by ``import grazing``; importing it
    # registers its own kernel loader in place of this one.
    from grazing.engine import codegen

    return codegen.load_model_kernels(*args)


set_kernel_loader(_load_engine)


def __getattr__(name: str) -> Any:
    if name == "simulate":
        from grazing.engine.simulate import simulate

        return simulate
    # The version is looked up on first use: importlib.metadata costs ~50 ms at import.
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            found = version("grazing")
        except PackageNotFoundError:  # pragma: no cover - running from a source tree
            found = "0.0.0"
        globals()["__version__"] = found  # (looked up once: 2 ms a time, and a sweep's spec asks often)
        return found
    raise AttributeError(f"module 'grazing' has no attribute {name!r}")


def __dir__() -> list[str]:
    # What a user can reach: the public names (simulate, loaded lazily, included), the
    # subpackages imported so far; not the names used only to write this module (Any, ...).
    loaded = [
        name
        for name, value in globals().items()
        if isinstance(value, ModuleType) and not name.startswith("_")
    ]
    return sorted({*__all__, *loaded})


__all__ = [
    "ConvergenceError",
    "GrazingError",
    "HybridModel",
    "Impacts",
    "InvalidParameterError",
    "InvalidStateError",
    "Mode",
    "Parameter",
    "SaveAt",
    "SimulationError",
    "Solution",
    "Solver",
    "Stop",
    "Surface",
    "SweepSettings",
    "Tangent",
    "Transition",
    "UnsupportedExpressionError",
    "__version__",
    "detect_period",
    "models",
    "simulate",
]
