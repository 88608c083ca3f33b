"""The explorer's basins: a grid around the clicked motion, less what lies beyond a stop."""

from __future__ import annotations

import math

import numpy as np
import pytest

import grazing
from grazing.attractors.grid import beyond_stops
from grazing.explore import View, compute_diagram, inspect_click
from grazing.explore.basins import CLIP_PROBE, basins_at, within_stops
from grazing.models import two_sided_oscillator


def test_the_pendulums_basins_end_at_its_stop():
    # The period-5 motion at eta = 0.446 spans theta -0.69 .. 0.70: twice that went to 1.4 rad, past the
    # stop at 40 deg (0.698 rad), where a third of the grid was "beyond a stop (not run)".
    model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    point = inspect_click(compute_diagram(View.of(model, {"eta": (0.44, 0.49)}, num=5)), [0.446])
    shown = basins_at(point, num=(12, 10))
    lo, hi = shown.x_range
    step = (hi - lo) / (CLIP_PROBE * 12 - 1)
    assert math.radians(40) - 2 * step < hi <= math.radians(40) + 1e-12
    assert lo < float(np.min(point.trajectory[:, 0]))  # (the other side is not clipped: no stop there)
    assert not any(line.startswith("beyond a stop") for line in shown.lines), shown.lines
    assert (shown.label > 0).all()
    assert shown.lines[0].startswith(f"attractor {shown.ids[0]}: periodic, period 5") and shown.ids[0] == 1
    # (an attractor's number is its basin's label, as in `grazing basins`: 0 is beyond a stop)


@pytest.mark.parametrize("gaps", [(1.0, 1.0), (0.5, 2.0)])
def test_a_grid_is_clipped_to_both_stops(gaps):
    model = two_sided_oscillator(gap_left=gaps[0], gap_right=gaps[1])
    (xlo, xhi), (ylo, yhi) = within_stops(model, [(-5.0, 5.0), (-3.0, 3.0)], (20, 20))
    assert -gaps[0] <= xlo < -gaps[0] + 0.1 and gaps[1] - 0.1 < xhi <= gaps[1]
    assert (ylo, yhi) == (-3.0, 3.0)  # (the stops limit the position only)
    corners = np.array([[xlo, ylo], [xlo, yhi], [xhi, ylo], [xhi, yhi]])
    assert not beyond_stops(model, corners, 0.0).any()


def test_a_grid_within_the_stops_or_beyond_them_all_is_kept():
    model = two_sided_oscillator()
    inside = [(-0.5, 0.5), (-1.0, 1.0)]
    assert within_stops(model, inside, (10, 10)) == inside
    beyond = [(2.0, 3.0), (-1.0, 1.0)]
    assert within_stops(model, beyond, (10, 10)) == beyond  # (then the basins say so: all beyond a stop)
