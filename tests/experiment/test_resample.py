"""Resampling on a uniform grid and delay coordinates (the embedding of figs 2 and 3)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import grazing
from grazing.experiment.signal import delay_coordinates, uniform_resample


def test_uniform_resample_drops_repeated_times_and_is_exact_on_lines() -> None:
    t = np.array([0.0, 0.3, 0.3, 1.0, 1.7, 2.0])
    x = np.column_stack([3 * t + 1, -t])
    tg, xg = uniform_resample(t, x, 0.25)
    assert np.allclose(tg, np.arange(9) * 0.25)
    assert np.allclose(xg[:, 0], 3 * tg + 1) and np.allclose(xg[:, 1], -tg)


def test_uniform_resample_start_and_errors() -> None:
    t = np.linspace(0.0, 1.0, 11)
    tg, xg = uniform_resample(t, t**2, 0.2, start=0.1)
    assert np.allclose(tg, [0.1, 0.3, 0.5, 0.7, 0.9])
    assert np.allclose(xg, np.interp(tg, t, t**2))
    with pytest.raises(ValueError, match="nondecreasing"):
        uniform_resample(t[::-1], t, 0.1)
    with pytest.raises(ValueError, match="dt"):
        uniform_resample(t, t, 0.0)
    with pytest.raises(ValueError, match="outside"):
        uniform_resample(t, t, 0.1, start=-1.0)


def test_delay_coordinates_of_a_sine_is_the_circle_with_the_right_phase() -> None:
    t = np.linspace(0.0, 6 * np.pi, 1201)  # dt = pi/200: a quarter period is 100 steps
    tn, xd, xn = delay_coordinates(t, np.sin(t), np.pi / 2)
    assert np.isclose(tn[0], np.pi / 2) and np.isclose(tn[-1], 6 * np.pi)
    assert np.allclose(xn, np.sin(tn), atol=1e-12)
    assert np.allclose(xd, -np.cos(tn), atol=1e-12)  # sin(t - pi/2)
    assert np.allclose(xd**2 + xn**2, 1.0, atol=1e-12)


def test_delay_coordinates_shrinks_the_step_to_divide_the_delay() -> None:
    t = np.linspace(0.0, 10.0, 301)  # dt = 1/30 does not divide 0.55
    a, w = 2.0, 1.3
    tn, xd, xn = delay_coordinates(t, a * np.cos(w * t), 0.55)
    assert np.allclose(np.diff(tn), 0.55 / math.ceil(0.55 * 30))
    assert np.allclose(xd, a * np.cos(w * (tn - 0.55)), atol=2e-3)
    # an ellipse: x(t) and x(t - d) satisfy the quadratic form of a phase-shifted pair
    c = math.cos(w * 0.55)
    s2 = math.sin(w * 0.55) ** 2
    assert np.allclose((xn**2 - 2 * c * xn * xd + xd**2) / (a**2 * s2), 1.0, atol=5e-3)
    with pytest.raises(ValueError, match="shorter"):
        delay_coordinates(t, t, 20.0)
    with pytest.raises(ValueError, match="scalar"):
        delay_coordinates(t, np.column_stack([t, t]), 1.0)


def test_delay_coordinates_of_a_trajectory_with_impacts(period5_trajectory: grazing.Solution) -> None:
    t, th = period5_trajectory.trajectory_t, period5_trajectory.trajectory[:, 0]
    assert np.any(np.diff(t) == 0), "impacts should appear twice in the dense output"
    tn, xd, xn = delay_coordinates(t, th, math.pi / 2)
    dt = np.diff(tn)
    assert np.allclose(dt, 2 * math.pi / 200)  # 50 steps per quarter period
    assert np.isclose(tn[0] - t[0], math.pi / 2)
    # on the grid the dense output is taken as is: the delayed copy is a pure shift
    assert np.array_equal(xd[50:], xn[:-50])
    on_grid = np.isin(t, tn)
    assert np.allclose(np.interp(t[on_grid], tn, xn), th[on_grid])
    assert xn.max() <= period5_trajectory.model.params["theta_hat"] + 1e-12
