"""An axes that shows no data is found, whatever drew it; one that shows data is not."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

import grazing
from grazing.plotting import plot_time_series
from grazing.plotting.checks import empty_axes


def test_drawn_axes_pass() -> None:
    fig = Figure()
    a, b, c, d, e = fig.subplots(1, 5)
    a.plot([0, 1], [0, 1])
    b.scatter([0.5], [0.5])
    mesh = c.pcolormesh(np.arange(9.0).reshape(3, 3))
    fig.colorbar(mesh, ax=c)  # a colour bar is not judged
    d.imshow(np.eye(3))
    e.fill_between([0, 1], [0, 1])
    fig.add_subplot().axis("off")  # an axes turned off (text only) is not judged
    assert empty_axes(fig) == []


def test_data_outside_the_limits_reference_lines_only_and_nothing_are_empty() -> None:
    fig = Figure()
    radians_on_degrees, line_outside, reference_only, _nothing = fig.subplots(1, 4)
    # the report's blank map: a mesh in radians (0.17..1.05) on an axis set in degrees (10..60)
    radians_on_degrees.pcolormesh(np.linspace(0.4, 0.6, 4), np.radians([10, 30, 60]), np.ones((2, 3)))
    radians_on_degrees.set_ylim(10, 60)
    line_outside.plot([5, 6], [5, 6])
    line_outside.set(xlim=(0, 1), ylim=(0, 1), title="outside")
    reference_only.axhline(0.5)
    reference_only.axvspan(0.2, 0.4)
    found = empty_axes(fig)
    assert [line.split(":")[0] for line in found] == [
        "axes 1 of 4",
        "axes 2 of 4 ('outside')",
        "axes 3 of 4",
        "axes 4 of 4",
    ]
    assert "y in [10, 60]" in found[0]


def test_a_time_series_outside_the_recorded_span_is_empty(period5_trajectory: grazing.Solution) -> None:
    fig = Figure()
    before, during = fig.subplots(2, 1)
    plot_time_series(before, period5_trajectory, span=(0, 10))  # the trajectory starts after the transient
    plot_time_series(during, period5_trajectory, span=(605, 615))
    assert [line.split(":")[0] for line in empty_axes(fig)] == ["axes 1 of 2"]
