"""Brute-force bifurcation diagrams, period detection and Lyapunov exponents."""

from grazing.sweeps.period import detect_period

__all__ = ["detect_period"]
