"""On a real NVIDIA GPU (``pytest --gpu``; deselected otherwise): the kernel compiles for the device and
its sweeps equal the CPU lanes'.

On a device the compiler fuses multiply-adds, so the GPU's arithmetic is not the CPU's to the bit: the
periods, impacts and statuses must still be equal at every point of these short sweeps, the samples of
the periodic points within :data:`DEVICE_SAMPLE_TOL`.  The cases are the simulator's
(``simulator_cases.py``'s :data:`~tests.gpu.simulator_cases.BUILDERS`), at :data:`DEVICE` scale.
"""

from __future__ import annotations

import numpy as np
import pytest

from grazing.sweeps.run import run_parts
from tests.gpu.simulator_cases import BUILDERS, Scale

pytestmark = pytest.mark.gpu

DEVICE_SAMPLE_TOL = 1e-8
"""Largest difference of the samples of a periodic point on a device and on the CPU lanes."""
DEVICE = Scale(points=16, transient=200, periods=40)
"""The cases' scale on a device: 16 points over each case's range, 200 transient and 40 sampled periods."""
DEVICE_CASES = ("pendulum A map", "impact oscillator", "pendulum C chained", "soft impact modes",
                "rocking block", "friction sliding", "bouncing ball")  # fmt: skip
"""The simulator's cases run on a device (mode-changing resets, switches, sliding, sticking among them)."""
DEVICE_LYAPUNOV_CASES = ("lyapunov pendulum B", "lyapunov pendulum C chained", "lyapunov impact oscillator")
"""The simulator's cases with Lyapunov exponents run on a device."""


@pytest.fixture(scope="module", autouse=True)
def device() -> None:
    from grazing.gpu.target import device_present

    if not device_present():
        pytest.fail("--gpu given but no CUDA device is usable (numba-cuda and a driver are needed)")


def _both(parts: list) -> tuple[list, list]:
    from grazing.gpu.batch import run_parts_gpu

    return run_parts(parts), run_parts_gpu(parts)


@pytest.mark.parametrize("case", DEVICE_CASES)
def test_the_device_equals_the_cpu_lanes(case: str) -> None:
    cpu, gpu = _both(BUILDERS[case](DEVICE))
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


@pytest.mark.parametrize("case", DEVICE_LYAPUNOV_CASES)
def test_the_devices_lyapunov_exponents_equal_the_cpu_lanes(case: str) -> None:
    cpu, gpu = _both(BUILDERS[case](DEVICE))
    for c, g in zip(cpu, gpu):
        assert g.period.tolist() == c.period.tolist()
        assert g.status.tolist() == c.status.tolist()
        periodic = c.period > 0
        assert np.isfinite(g.lyapunov[periodic]).all()
        diff = np.nanmax(np.abs(g.lyapunov[periodic] - c.lyapunov[periodic]), initial=0.0)
        assert diff <= DEVICE_LYAPUNOV_TOL


def test_a_chain_of_several_chunks_on_the_device_is_the_cpus() -> None:
    """``run_sweep(device="gpu")`` on a carried sweep of two points a chunk, settled into its chain
    (``cases_chains.py``'s case C up, through periods 1, 3, 2): the CPU's periods and statuses, its samples
    at every point within :data:`DEVICE_SAMPLE_TOL`."""
    from grazing.sweeps.api import run_sweep
    from tests.gpu.cases_chains import case_c

    spec = case_c()
    cpu = run_sweep(spec, workers=1, device="cpu")
    gpu = run_sweep(spec, device="gpu")
    assert gpu.period.values.tolist() == cpu.period.values.tolist()
    assert gpu.status.values.tolist() == cpu.status.values.tolist()
    assert np.nanmax(np.abs(gpu.samples.values - cpu.samples.values), initial=0.0) <= DEVICE_SAMPLE_TOL
