"""On a real NVIDIA GPU (``pytest --gpu``; deselected otherwise): the kernel compiles for the device and
its sweeps equal the CPU lanes'.

On a device the compiler fuses multiply-adds, so the GPU's arithmetic is not the CPU's to the bit: the
periods, impacts and statuses must still be equal at every point of these short sweeps, the samples of
the periodic points within :data:`DEVICE_SAMPLE_TOL`.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import grazing
from grazing.sweeps.run import run_parts
from grazing.sweeps.spec import map_spec, sweep_spec

pytestmark = pytest.mark.gpu

DEVICE_SAMPLE_TOL = 1e-8
"""Largest difference of the samples of a periodic point on a device and on the CPU lanes."""


@pytest.fixture(scope="module", autouse=True)
def device() -> None:
    from grazing.gpu.target import device_present

    if not device_present():
        pytest.fail("--gpu given but no CUDA device is usable (numba-cuda and a driver are needed)")


def _both(parts: list) -> tuple[list, list]:
    from grazing.gpu.batch import run_parts_gpu

    return run_parts(parts), run_parts_gpu(parts)


@pytest.mark.parametrize(
    "parts",
    [
        pytest.param(
            lambda: [(map_spec(grazing.models.pendulum("B"), "eta", np.linspace(0.44, 0.49, 16), "theta_hat",
                               np.radians([30.0, 40.0]), settings=grazing.SweepSettings(
                                   transient=500, periods=100, fresh=True, adaptive=False, lyapunov=False,
                                   tol=1e-10, chunk_size=0)), i) for i in range(2)],
            id="pendulum equal-work map",
        ),
        pytest.param(
            lambda: [(sweep_spec(grazing.models.impact_oscillator(), "omega", np.linspace(2.6, 3.0, 16),
                                 settings=grazing.SweepSettings(transient=200, periods=40, lyapunov=False,
                                                                fresh=True)), 0)],
            id="impact oscillator",
        ),
        pytest.param(
            lambda: [(sweep_spec(grazing.models.pendulum("C", theta_hat=math.radians(30)), "eta",
                                 np.linspace(0.40, 0.50, 12), settings=grazing.SweepSettings(
                                     transient=200, periods=40, lyapunov=False, chunk_size=0)), 0)],
            id="pendulum chained",
        ),
        pytest.param(
            lambda: [(sweep_spec(grazing.models.soft_impact_oscillator(), "omega", np.linspace(0.9, 1.5, 12),
                                 settings=grazing.SweepSettings(transient=200, periods=40, lyapunov=False,
                                                                fresh=True)), 0)],
            id="soft impact (switches)",
        ),
        pytest.param(
            lambda: [(sweep_spec(grazing.models.rocking_block(), "a", np.linspace(0.22, 0.32, 12),
                                 settings=grazing.SweepSettings(transient=200, periods=40, lyapunov=False,
                                                                fresh=True)), 0)],
            id="rocking block (mode-changing resets)",
        ),
        pytest.param(
            lambda: [(sweep_spec(grazing.models.friction_oscillator(), "a", np.linspace(0.6, 1.6, 12),
                                 settings=grazing.SweepSettings(transient=200, periods=40, lyapunov=False,
                                                                fresh=True)), 0)],
            id="friction oscillator (sliding)",
        ),
        pytest.param(
            lambda: [(sweep_spec(grazing.models.bouncing_ball(), "amplitude", np.linspace(1.05, 1.3, 12),
                                 x0=(0.0, 0.5), settings=grazing.SweepSettings(
                                     transient=200, periods=40, lyapunov=False, fresh=True)), 0)],
            id="bouncing ball (chattering and sticking)",
        ),
        pytest.param(
            lambda: [(sweep_spec(grazing.models.impact_oscillator(sigma=0.0, r=0.5), "omega",
                                 np.linspace(0.5, 0.7, 8), x0=(-1.0, 0.0), settings=grazing.SweepSettings(
                                     transient=200, periods=40, lyapunov=False, fresh=True)), 0)],
            id="impact oscillator (sticking)",
        ),
    ],
)  # fmt: skip
def test_the_device_equals_the_cpu_lanes(parts) -> None:
    cpu, gpu = _both(parts())
    for c, g in zip(cpu, gpu):
        assert g.period.tolist() == c.period.tolist()
        assert g.impacts_by_stop.tolist() == c.impacts_by_stop.tolist()
        assert g.status.tolist() == c.status.tolist()
        periodic = c.period > 0
        assert g.mode_final[periodic].tolist() == c.mode_final[periodic].tolist()  # (a chaotic one's: any)
        assert np.nanmax(np.abs(g.samples[periodic] - c.samples[periodic]), initial=0.0) <= DEVICE_SAMPLE_TOL


DEVICE_LYAPUNOV_TOL = 1e-6
"""Largest difference of the Lyapunov exponent of a periodic point on a device and on the CPU lanes (the
exponent of a stable orbit is an average over the sampled periods, insensitive to the last bits)."""


@pytest.mark.parametrize(
    "parts",
    [
        pytest.param(
            lambda: [(sweep_spec(grazing.models.pendulum("B", theta_hat=math.radians(40)), "eta",
                                 np.linspace(0.44, 0.46, 16), settings=grazing.SweepSettings(
                                     transient=200, periods=40, lyapunov=True, fresh=True)), 0)],
            id="pendulum B",
        ),
        pytest.param(
            lambda: [(sweep_spec(grazing.models.pendulum("C", theta_hat=math.radians(30)), "eta",
                                 np.linspace(0.40, 0.50, 12), settings=grazing.SweepSettings(
                                     transient=200, periods=40, lyapunov=True, chunk_size=0)), 0)],
            id="pendulum C chained",
        ),
        pytest.param(
            lambda: [(sweep_spec(grazing.models.impact_oscillator(), "omega", np.linspace(2.6, 3.0, 16),
                                 settings=grazing.SweepSettings(transient=200, periods=40, lyapunov=True,
                                                                fresh=True)), 0)],
            id="impact oscillator",
        ),
    ],
)  # fmt: skip
def test_the_devices_lyapunov_exponents_equal_the_cpu_lanes(parts) -> None:
    cpu, gpu = _both(parts())
    for c, g in zip(cpu, gpu):
        assert g.period.tolist() == c.period.tolist()
        assert g.status.tolist() == c.status.tolist()
        periodic = c.period > 0
        assert np.isfinite(g.lyapunov[periodic]).all()
        diff = np.nanmax(np.abs(g.lyapunov[periodic] - c.lyapunov[periodic]), initial=0.0)
        assert diff <= DEVICE_LYAPUNOV_TOL
