"""The hybrid model type and the solution type."""

from grazing.core.model import HybridModel, Parameter
from grazing.core.solution import Impacts, Solution
from grazing.core.symbolic import Mode, Stop, Surface, Transition

__all__ = ["HybridModel", "Impacts", "Mode", "Parameter", "Solution", "Stop", "Surface", "Transition"]
