"""Brute-force bifurcation diagrams, period detection and Lyapunov exponents."""

from grazing.core.period import detect_period
from grazing.sweeps.brute_force import SweepSpec, parameter_map, run_chunk, run_sweep, sweep

__all__ = ["SweepSpec", "detect_period", "parameter_map", "run_chunk", "run_sweep", "sweep"]
