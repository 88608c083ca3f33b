"""Shared fixtures."""

from __future__ import annotations

import math
import os

import pytest
from hypothesis import HealthCheck, settings

import grazing

pytest_plugins = ["tests.recordings"]

# Property tests must not fail on a busy machine: no deadlines, no too-slow health
# check (the engine's examples compile and integrate), and on CI a fixed, derandomized
# profile so that a run is reproducible.
settings.register_profile(
    "dev", deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large]
)
settings.register_profile(
    "ci",
    deadline=None,
    derandomize=True,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
settings.load_profile("ci" if os.environ.get("CI") else "dev")


@pytest.fixture(scope="session")
def pendulum_b():
    """Case B at theta_hat = 40 deg, eta = 0.446 (paper fig 9b: period-5)."""
    return grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))


@pytest.fixture(scope="session")
def period5_orbit(pendulum_b):
    """A point on the stable period-5 impacting orbit of case B, and its time."""
    sol = grazing.simulate(pendulum_b, [0.0, 0.0], transient=600, periods=10)
    assert sol.period() == 5
    return sol.samples[-1].copy(), float(sol.t[-1])


@pytest.fixture(scope="session")
def period5_trajectory(pendulum_b) -> grazing.Solution:
    """Twenty periods of the period-5 orbit with dense output (200 points per period)."""
    return grazing.simulate(pendulum_b, [0.0, 0.0], transient=600, periods=20, trajectory=200)


def pytest_addoption(parser: pytest.Parser) -> None:
    """``--gpu``: also run the tests marked ``gpu`` (they need an NVIDIA GPU with numba-cuda)."""
    parser.addoption("--gpu", action="store_true", help="run the tests marked gpu (they need a CUDA device)")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Deselect the tests marked ``gpu`` unless ``--gpu`` is given (CI has no GPU)."""
    if config.getoption("--gpu"):
        return
    gpu = [item for item in items if item.get_closest_marker("gpu") is not None]
    if gpu:
        config.hook.pytest_deselected(items=gpu)
        items[:] = [item for item in items if item.get_closest_marker("gpu") is None]
