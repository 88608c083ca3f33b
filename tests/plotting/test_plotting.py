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


def test_time_series_shades_each_stay_in_its_mode() -> None:
    """One shaded band per stay, in its mode's colour, over the side of x = gap the trajectory is on."""
    from matplotlib.colors import to_rgb

    from grazing.plotting.palette import MODE_COLOURS

    m = grazing.models.soft_impact_oscillator()
    sol = grazing.simulate(m, [0.0, 0.0], transient=5, periods=3, trajectory=200)
    ax = Figure().add_subplot()
    plot_time_series(ax, sol, time_unit="time")
    bands = ax.patches
    assert len(bands) == len(sol.switches) + 1 >= 4
    labels = [b.get_label() for b in bands if not b.get_label().startswith("_")]
    assert sorted(labels) == ["mode 'contact'", "mode 'free'"]
    for band in bands:
        x0, x1 = band.get_x(), band.get_x() + band.get_width()
        inside = (sol.trajectory_t > x0 + 1e-9) & (sol.trajectory_t < x1 - 1e-9)
        contact = bool(np.all(sol.trajectory[inside, 0] > m.params["gap"]))
        assert contact or np.all(sol.trajectory[inside, 0] < m.params["gap"])
        assert np.allclose(band.get_facecolor()[:3], to_rgb(MODE_COLOURS[int(contact)]))
    ax = Figure().add_subplot()
    plot_time_series(ax, sol, modes=False)
    assert not ax.patches
    one = grazing.simulate(grazing.models.impact_oscillator(), [0.0, 0.0], periods=2, trajectory=50)
    ax = Figure().add_subplot()
    plot_time_series(ax, one)
    assert not ax.patches and len(ax.lines) == 3  # one mode: as before
