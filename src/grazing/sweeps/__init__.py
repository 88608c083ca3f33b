"""Brute-force bifurcation diagrams, period detection and Lyapunov exponents."""

from grazing.sweeps.period import detect_period
from grazing.sweeps.sweep import SweepSpec, parameter_map, run_chunk, run_sweep, sweep

__all__ = ["SweepSpec", "detect_period", "parameter_map", "run_chunk", "run_sweep", "sweep"]
