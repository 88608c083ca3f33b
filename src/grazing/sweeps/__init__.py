"""Brute-force bifurcation diagrams, period detection and Lyapunov exponents."""

from grazing.sweeps.brute_force import SweepSpec, parameter_map, run_chunk, run_sweep, sweep
from grazing.sweeps.period import detect_period

__all__ = ["SweepSpec", "detect_period", "parameter_map", "run_chunk", "run_sweep", "sweep"]
