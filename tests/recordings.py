"""Synthetic recordings shared by the experiment and CLI tests (from the model, never the paper's data).

Loaded as a pytest plugin by ``tests/conftest.py``.
"""

from __future__ import annotations

import pytest

from grazing.experiment.synthetic import synthetic_recording, write_recording

FAST_RATE = 250.0
"""Sampling rate of most test recordings (the rig's 1 kHz is used where it matters)."""


@pytest.fixture(scope="session")
def period5_recording():
    """Case B, theta_hat = 40 deg, eta = 0.446: the stable period-5 orbit (paper fig 3 c, d; fig 9 b)."""
    return synthetic_recording(0.446, 40.0, periods=40, transient=600, sample_rate=1000.0, seed=11)


@pytest.fixture(scope="session")
def chaos_recording():
    """Case B, theta_hat = 40 deg, eta = 0.4504: chaos just past the primary grazing (positive exponent)."""
    return synthetic_recording(0.4504, 40.0, periods=60, transient=600, sample_rate=FAST_RATE, seed=12)


@pytest.fixture(scope="session")
def period5_csv(tmp_path_factory, period5_recording):
    """The period-5 recording written as CSV with trigger and sidecar."""
    path = tmp_path_factory.mktemp("rec") / "theta40_eta0446.csv"
    return write_recording(period5_recording, path)


@pytest.fixture
def cli():
    """``grazing.cli.main`` (which has the experiment commands)."""
    from grazing.cli import main

    return main
