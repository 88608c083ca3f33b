"""The drawing functions for trajectories."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.figure import Figure

import grazing
from grazing.plotting import plot_delay, plot_time_series


def test_plot_time_series_and_delay_draw(period5_trajectory: grazing.Solution) -> None:
    fig = Figure()
    ax1, ax2 = fig.subplots(1, 2)
    plot_time_series(ax1, period5_trajectory, degrees=True, span=(605, 615))
    line, stop, samples = ax1.lines
    assert line.get_xdata().min() >= 605 and line.get_xdata().max() <= 615
    assert np.isclose(stop.get_ydata()[0], 40.0)
    assert len(samples.get_xdata()) == 10  # samples at the ends of periods 606..615
    assert ax1.get_ylabel() == "θ (degrees)" and ax1.get_xlabel().startswith("τ / 2π")
    plot_delay(ax2, period5_trajectory)
    assert ax2.get_xlabel() == "θ(τ − π/2) (rad)" and ax2.get_ylabel() == "θ(τ) (rad)"
    assert len(ax2.lines) == 3  # curve, stop as horizontal and vertical line


def test_plot_needs_a_trajectory() -> None:
    m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    sol = grazing.simulate(m, [0.0, 0.0], periods=2)
    ax = Figure().add_subplot()
    with pytest.raises(ValueError, match="trajectory"):
        plot_time_series(ax, sol)
    with pytest.raises(ValueError, match="trajectory"):
        plot_delay(ax, sol)
